"""Chirp-sequence FMCW radar with time-division MIMO (kind ``fmcw``).

The physics is :mod:`mdframework.physics.fmcw`; this plugin holds the config, the sensor presets
and the wiring:

- ``pulse_times``: the chirp timing (idle time, TDM slots, frame gaps); ``block_multiple``: the
  chirps of one frame, so a frame never straddles two blocks.
- ``receive(block)``, frame by frame: the range profiles of every chirp and receive antenna
  (``path = "raw"``: sampled de-chirped IF with exact delays per antenna, then the range FFT;
  ``"analytic"``: the same profile in closed form near the scatterers), optional receiver noise,
  then the slow-time signal (first RX, summed over the range bins within ``gate_width / 2`` of the
  gate), the range-Doppler map and the point cloud. Products: ``range_doppler`` (n_frames,
  n_doppler, n_range) float32 [W], the power summed over the virtual antennas, and ``points``
  (n_points, 7) float64 with columns frame, t [s from the first chirp], x, y, z [m, sensor
  frame], v [m/s, + approaching], intensity [dB over the CFAR noise estimate].
- ``spectrogram``: from the first TDM slot's chirps (one sample per loop): an STFT when the frames
  follow each other without gaps, else one Doppler spectrum per frame.

The sensor frame: x to the right, y along boresight, z up (the TI convention). The boresight
points at ``boresight_azimuth_deg``/``boresight_elevation_deg``, by default horizontally toward
the scene origin (the default person position), or along +x for a radar above the origin.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, Annotated, Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, model_validator

from mdframework import ConfigSection, RadarWaveform, Received, limits
from mdframework.constants import SPEED_OF_LIGHT
from mdframework.errors import SceneError
from mdframework.physics import fmcw
from mdframework.settings import (
    AngleDeg,
    Bandwidth,
    Decibels,
    Distance,
    LossDb,
    RadarPowerConfig,
    Seed,
)

from .presets import PRESETS

if TYPE_CHECKING:
    from collections.abc import Sequence

    from mdframework.interfaces import PulseBlock, ReceiverInput
    from mdframework.physics.spectrogram import Spectrogram, SpectrogramGeometry
    from mdframework.settings import ProcessingConfig

FloatArray = NDArray[np.float64]

#: Boltzmann constant x 290 K [W/Hz]: thermal noise density at the reference temperature.
KT0 = 1.380649e-23 * 290.0

# Bounds of the chirp and frame settings: physical, and generous beside the single-chip sensors
# they describe (TI's mmWaveLink profile and frame limits in brackets; docs/input-rules.md).
#: Steepest chirp [Hz/s], 1000 MHz/us (TI: 100 MHz/us at 77 GHz, 250 MHz/us at 60 GHz).
MAX_SLOPE_HZ_PER_S = 1e15
#: Shallowest chirp [Hz/s], 1 MHz/s (1e-6 MHz/us), far below any sensor's; a slope near 1e-300
#: Hz/s made the maximum range ``sample_rate c / (2 slope)`` infinite.
MIN_SLOPE_HZ_PER_S = 1e6
#: Longest idle time, ADC start and ramp [s], 10 ms (TI: 5.24 ms, 41 us and 5 ms).
MAX_CHIRP_TIME_S = 10e-3
#: Fastest complex ADC [Hz], 1 GHz (TI: 37.5 Msps real or complex 2x, 18.75 Msps complex 1x).
MAX_ADC_RATE_HZ = 1e9
#: Most ADC samples per chirp (TI: 1024 complex samples with 4 RX, 4096 with 2 RX real).
MAX_SAMPLES = 16384
#: Most loops per frame (TI: 255).
MAX_LOOPS = 4096
#: Most TX slots per loop and antennas of each kind (TI: 3 TX, 4 RX; 12 TX, 16 RX cascaded).
MAX_ANTENNAS = 64
#: Largest antenna coordinate, in units of ``antenna_spacing`` (a 77 GHz array spans tens).
MAX_ANTENNA_UNITS = 1000.0
#: Largest range and Doppler FFT [bins].
MAX_FFT = 65536

AntennaUnits = Annotated[float, Field(ge=-MAX_ANTENNA_UNITS, le=MAX_ANTENNA_UNITS)]


class CfarConfig(ConfigSection):
    """CFAR along one axis of the range-Doppler map."""

    mode: Literal["ca", "so", "go"] = Field(
        "ca", description="ca: cell averaging; so: smallest of the two sides; go: greatest of."
    )
    train: int = Field(8, ge=1, le=1024, description="Training cells on each side.")
    guard: int = Field(2, ge=0, le=1024, description="Guard cells on each side.")
    threshold_db: Decibels = Field(15.0, description="Detection threshold over the noise [dB].")


class FmcwConfig(RadarPowerConfig):
    """Chirp-sequence FMCW radar with TDM-MIMO. ``preset`` fills every field it names unless the
    config gives it. Without a preset the defaults are a generic 77 GHz sensor with the
    IWR1443's antennas and a 25 m range (30 MHz/us, 256 samples at 5 Msps, 32 loops of three
    chirps every 50 ms); the presets are the vendors' demo configurations."""

    kind: Literal["fmcw"] = "fmcw"
    preset: Literal["iwr1443_short_range_3d", "iwr6843isk_people_counting_6m"] | None = Field(
        None, description="Sensor preset (see docs/fmcw.md); explicit fields override it."
    )
    start_frequency: float = Field(
        77e9,
        ge=limits.MIN_CARRIER_HZ,
        le=limits.MAX_CARRIER_HZ,
        description="Chirp start frequency f0 [Hz].",
    )
    slope: float = Field(
        30e12, ge=MIN_SLOPE_HZ_PER_S, le=MAX_SLOPE_HZ_PER_S, description="Chirp slope S [Hz/s]."
    )
    idle_time: float = Field(
        10e-6, ge=0, le=MAX_CHIRP_TIME_S, description="Idle time before each ramp [s]."
    )
    adc_start_time: float = Field(
        6e-6, ge=0, le=MAX_CHIRP_TIME_S, description="ADC start after the ramp start [s]."
    )
    ramp_end_time: float = Field(60e-6, gt=0, le=MAX_CHIRP_TIME_S, description="Ramp length [s].")
    sample_rate: float = Field(
        5e6, gt=0, le=MAX_ADC_RATE_HZ, description="Complex ADC sample rate [Hz]."
    )
    n_samples: int = Field(256, ge=2, le=MAX_SAMPLES, description="ADC samples per chirp.")
    n_loops: int = Field(32, ge=1, le=MAX_LOOPS, description="Loops (chirps per TX) per frame.")
    tdm_order: list[Annotated[int, Field(ge=1, le=MAX_ANTENNAS)]] = Field(
        [1, 3, 2],
        min_length=1,
        max_length=MAX_ANTENNAS,
        description="TX (1-based) of each chirp of a loop, in order.",
    )
    frame_period: float = Field(
        50e-3, gt=0, le=1.0 / limits.MIN_FRAME_RATE_HZ, description="Frame period [s]."
    )
    max_bandwidth: Bandwidth = Field(
        4e9, description="The sensor's largest sweep, slope x ramp_end_time [Hz]."
    )
    tx_positions: list[tuple[AntennaUnits, AntennaUnits]] = Field(
        [(0.0, 0.0), (2.0, 1.0), (4.0, 0.0)],
        min_length=1,
        max_length=MAX_ANTENNAS,
        description="TX antennas (x right, z up) in units of antenna_spacing.",
    )
    rx_positions: list[tuple[AntennaUnits, AntennaUnits]] = Field(
        [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (3.0, 0.0)],
        min_length=1,
        max_length=MAX_ANTENNAS,
        description="RX antennas (x right, z up) in units of antenna_spacing.",
    )
    antenna_spacing: float | None = Field(
        None,
        gt=0,
        le=1.0,
        description="Unit of the antenna positions [m]; default lambda/2 at the "
        "centre of the sampled band.",
    )
    boresight_azimuth_deg: AngleDeg | None = Field(
        None,
        description="Boresight azimuth, degrees from +x toward +y; default: toward the "
        "scene origin.",
    )
    boresight_elevation_deg: AngleDeg = Field(0.0, description="Boresight elevation [deg].")
    path: Literal["analytic", "raw"] = Field(
        "analytic",
        description="analytic: closed-form range profiles near the scatterers (far-field "
        "array phases); raw: sampled IF with exact delays per antenna and range FFTs.",
    )
    analytic_margin: int = Field(
        8,
        ge=1,
        le=MAX_FFT,
        description="Analytic path: range bins kept on each side of a scatterer.",
    )
    range_window: Literal["rect", "hann", "hamming", "blackman"] = Field(
        "hann", description="Window of the range FFT."
    )
    doppler_window: Literal["rect", "hann", "hamming", "blackman"] = Field(
        "hann", description="Window of the Doppler FFT."
    )
    range_fft_size: int | None = Field(
        None, ge=2, le=MAX_FFT, description="Range FFT size (>= n_samples); default n_samples."
    )
    doppler_fft_size: int | None = Field(
        None, ge=1, le=MAX_FFT, description="Doppler FFT size (>= n_loops); default n_loops."
    )
    receiver_noise: bool = Field(
        False,
        description="Add the receiver's thermal noise to the IF samples (the presets do; "
        "without it, CFAR works on the map plus the receiver's mean noise).",
    )
    noise_figure_db: LossDb = Field(
        15.0,
        description="Receiver noise figure F [dB]: complex white noise of power k T0 F fs per "
        "ADC sample.",
    )
    noise_seed: Seed | None = Field(
        None,
        description="Seed of the receiver noise (per frame); default: the run's seed (each "
        "dataset record's own).",
    )
    gate_width: float = Field(
        2.0,
        gt=0,
        le=limits.MAX_COORDINATE_M,
        description="Range window around the gate summed into the slow-time signal [m].",
    )
    beyond_max_range: Literal["error", "alias"] = Field(
        "error",
        description="A scatterer beyond the maximum range (beat frequency above sample_rate): "
        "stop, or let it alias in the IF as a real sensor does.",
    )
    clutter_removal: bool = Field(
        False, description="Subtract each range bin's mean over the frame (static clutter)."
    )
    points: bool = Field(True, description="Extract a point cloud from every frame.")
    save_range_doppler: bool = Field(True, description="Keep every frame's range-Doppler map.")
    cfar_range: CfarConfig | None = Field(
        CfarConfig(mode="so", train=8, guard=4, threshold_db=15.0),
        description="CFAR along range (null: none).",
    )
    cfar_doppler: CfarConfig | None = Field(None, description="CFAR along Doppler (null: none).")
    peak_grouping: list[Literal["doppler", "range"]] = Field(
        ["doppler"], description="Keep only detections that are local maxima along these axes."
    )
    detect_min_range: float = Field(
        0.1, ge=0, le=limits.MAX_COORDINATE_M, description="Nearest range searched [m]."
    )
    detect_max_range: Distance | None = Field(
        None, description="Farthest range searched [m]; default the maximum range."
    )
    multi_object_threshold: float | None = Field(
        0.5,
        gt=0,
        le=1,
        description="A second direction per cell when its beam power reaches this fraction "
        "of the strongest (TI's multi-object beamforming); null: one direction per cell.",
    )
    tdm_compensation: bool = Field(
        True, description="Correct the phase a moving target gains between TDM slots."
    )

    @model_validator(mode="before")
    @classmethod
    def _apply_preset(cls, data: Any) -> Any:
        if isinstance(data, dict) and data.get("preset") is not None:
            preset = PRESETS.get(str(data["preset"]))
            if preset is not None:
                return {**preset, **data}
        return data

    @model_validator(mode="after")
    def _check(self) -> FmcwConfig:
        problems = self.sequence().problems(self.max_bandwidth)
        if problems:
            raise ValueError(problems[0])
        n_tx = len(self.tx_positions)
        bad = [t for t in self.tdm_order if not 1 <= t <= n_tx]
        if bad:
            raise ValueError(f"tdm_order: TX {bad[0]} does not exist (tx_positions has {n_tx})")
        if len(set(self.tdm_order)) != len(self.tdm_order):
            raise ValueError("tdm_order: each TX may appear once per loop")
        if self.range_fft_size is not None and self.range_fft_size < self.n_samples:
            raise ValueError(
                f"range_fft_size: {self.range_fft_size} is below n_samples ({self.n_samples})"
            )
        if self.doppler_fft_size is not None and self.doppler_fft_size < self.n_loops:
            raise ValueError(
                f"doppler_fft_size: {self.doppler_fft_size} is below n_loops ({self.n_loops})"
            )
        for field, what, shape in self.frame_arrays():
            limits.check_frame_cells(shape, what, field)
        return self

    def frame_arrays(self) -> list[tuple[str, str, tuple[int, ...]]]:
        """The largest arrays one frame needs (complex values): the IF samples or range
        profiles of every chirp and RX, and the range-Doppler cube of every virtual antenna,
        each as (the field that sizes it most, what it is, its axes' lengths)."""
        n_rx = len(self.rx_positions)
        n_range = max(self.range_fft_size or 0, self.n_samples)
        n_doppler = max(self.doppler_fft_size or 0, self.n_loops)
        by_range = "range_fft_size" if n_range > self.n_samples else "n_samples"
        by_doppler = "doppler_fft_size" if n_doppler > self.n_loops else "n_loops"
        profiles = (len(self.tdm_order) * self.n_loops, n_rx, n_range)
        cube = (len(self.tx_positions) * n_rx, n_doppler, n_range)
        return [
            (by_range, "chirps x RX x range bins", profiles),
            (by_doppler, "virtual antennas x Doppler bins x range bins", cube),
        ]

    def pulse_rate(self) -> float:
        """Chirps per second over whole frames [Hz]: the rate of the pulse budget."""
        return len(self.tdm_order) * self.n_loops / self.frame_period

    def sequence(self) -> fmcw.ChirpSequence:
        """The chirp timing of this config."""
        return fmcw.ChirpSequence(
            start_frequency=self.start_frequency,
            slope=self.slope,
            idle_time=self.idle_time,
            adc_start_time=self.adc_start_time,
            ramp_end_time=self.ramp_end_time,
            sample_rate=self.sample_rate,
            n_samples=self.n_samples,
            n_loops=self.n_loops,
            tdm_order=tuple(t - 1 for t in self.tdm_order),
            frame_period=self.frame_period,
        )


def _cfar(c: CfarConfig | None) -> fmcw.Cfar | None:
    return None if c is None else fmcw.Cfar(c.mode, c.train, c.guard, c.threshold_db)


#: The slow-time signal's range gate is flat (every scatterer well inside it weighed alike, to
#: about 2 %) when it spans at least this many range resolutions ``c / (2 B)``, with the default
#: Hann range window (the rectangular window's ripple is +-8 % even at eight).
FLAT_GATE_RESOLUTIONS = 4.0

#: A scatterer farther than this many range resolutions from the range bins the gate reads
#: reaches the slow-time signal through the range window's sidelobes only (beyond the main
#: lobe: 2 resolutions for Hann and Hamming, 3 for Blackman), at -20 dB or less.
GATE_MARGIN_RESOLUTIONS = 3.0


class FmcwRadar(RadarWaveform):
    """Chirp-sequence FMCW radar (TDM-MIMO): slow-time signal, range-Doppler maps, points."""

    name = "fmcw"
    Config = FmcwConfig
    config: FmcwConfig

    def __init__(self, config: FmcwConfig | None = None) -> None:  # type: ignore[override]
        super().__init__(config)
        self.sequence = self.config.sequence()
        #: bytes of the record's kept range-Doppler maps (set by start_record)
        self._maps_bytes = 0
        #: the record's received-stage effects simulated in the IF (set_receiver_inputs)
        self._inputs: list[ReceiverInput] = []
        #: the static scatterers' range profiles of one frame, by radar position
        self._static: tuple[tuple[float, ...], NDArray[np.complex128] | None] | None = None
        #: blocks hold whole frames
        self.block_multiple = self.sequence.chirps_per_frame
        #: ``c / (2 B)`` [m] over the sampled part of the ramp (``B`` = slope x n_samples /
        #: sample_rate)
        self.range_resolution = self.sequence.range_resolution

    # ----------------------------------------------------------------- derived quantities

    @property
    def carrier_frequency(self) -> float:
        """Centre of the sampled band [Hz]: Doppler and angles refer to it."""
        return self.sequence.centre_frequency

    @property
    def prf(self) -> float:
        """Slow-time rate of one virtual channel [Hz]: one chirp per loop, ``1 / (n_tx T_c)``."""
        return 1.0 / self.sequence.loop_period

    def unambiguous_range(self) -> float:
        """The maximum range ``c sample_rate / (2 slope)`` [m]: a farther scatterer's beat
        frequency is above the complex ADC's rate."""
        return self.sequence.max_range

    @property
    def n_range(self) -> int:
        """Range bins."""
        return self.config.range_fft_size or self.config.n_samples

    @property
    def n_doppler(self) -> int:
        """Doppler bins."""
        return self.config.doppler_fft_size or self.config.n_loops

    @property
    def antennas(self) -> fmcw.Antennas:
        """TX and RX offsets [m] in the sensor plane, the virtual array centred on the sensor."""
        d = self.config.antenna_spacing or self.sequence.wavelength / 2.0
        return fmcw.Antennas(
            np.asarray(self.config.tx_positions, np.float64) * d,
            np.asarray(self.config.rx_positions, np.float64) * d,
        ).centred()

    def axes(self) -> dict[str, FloatArray]:
        """Axes of the products: ``range_m`` (n_range,), ``doppler_hz`` and ``velocity_mps``
        (n_doppler,) ascending (+ approaching)."""
        doppler = fmcw.doppler_axis(self.sequence, self.n_doppler)
        return {
            "range_m": fmcw.range_axis(self.sequence, self.n_range),
            "doppler_hz": doppler,
            "velocity_mps": doppler * self.sequence.wavelength / 2.0,
        }

    def product_axes(self) -> dict[str, FloatArray]:
        """Axes of the ``range_doppler`` product: ``range_doppler_range_m`` (n_range,),
        ``range_doppler_doppler_hz`` and ``range_doppler_velocity_mps`` (n_doppler,)."""
        return {f"range_doppler_{k}": v for k, v in self.axes().items()}

    @property
    def max_unambiguous_velocity(self) -> float:
        """``lambda_c / (4 n_tx T_chirp)`` [m/s]: one sample per loop on each virtual antenna."""
        return self.sequence.max_velocity

    def faster_sampling(self, rate: float) -> str:
        """The loop rate ``1 / (n_tx (idle_time + ramp_end_time))`` is the slow-time rate: the
        chirp period that reaches ``rate`` [Hz] with this TDM order, and what bounds it (the
        ramp must outlast the ADC samples)."""
        seq = self.sequence
        period = 1.0 / (rate * seq.n_tx)
        adc = seq.adc_start_time + seq.n_samples / seq.sample_rate
        advice = (
            f"raise the loop rate to at least {np.ceil(rate):.0f} Hz: shorten radar.idle_time "
            f"+ radar.ramp_end_time from {seq.chirp_period * 1e6:.2f} us to at most "
            f"{np.floor(period * 1e8) / 100:.2f} us"
        )
        if period < adc:
            advice += (
                f" (the ramp must outlast the ADC's adc_start_time + n_samples / sample_rate "
                f"= {adc * 1e6:.2f} us: take fewer n_samples or raise sample_rate)"
            )
        if seq.n_tx > 1:
            advice += f", or use fewer than {seq.n_tx} TX in radar.tdm_order"
        return advice

    @property
    def shortest_record(self) -> float:
        """One frame's chirps, ``chirps_per_frame (idle_time + ramp_end_time)`` [s]: a record
        holds whole frames only."""
        return self.sequence.frame_active_time

    def start_record(self, times: FloatArray, range_span: tuple[float, float]) -> None:
        """Stop before any block when the body's farthest joint is beyond the maximum range,
        or when the record's range-Doppler maps would not fit the product limit; warn when the
        range gate is narrower than :data:`FLAT_GATE_RESOLUTIONS` range resolutions."""
        self._check_ranges(np.asarray([range_span[1]]))
        resolution = self.sequence.range_resolution
        if self.config.gate_width < FLAT_GATE_RESOLUTIONS * resolution:
            warnings.warn(
                f"radar.gate_width: {self.config.gate_width:g} m spans "
                f"{self.config.gate_width / resolution:.1f} range resolutions of "
                f"{resolution:.3g} m; the gate weighs scatterers evenly only over "
                f"{FLAT_GATE_RESOLUTIONS:g} or more, with the Hann range window (narrower, it "
                "weighs the body unevenly and its level steps as the gate moves): widen it to "
                "at least "
                f"{FLAT_GATE_RESOLUTIONS * resolution:.2f} m",
                UserWarning,
                stacklevel=2,
            )
        self._maps_bytes = 0
        if self.config.save_range_doppler:
            n_frames = times.shape[0] // self.sequence.chirps_per_frame
            size = 4.0 * n_frames * self.n_doppler * self.n_range  # float32 maps
            limits.check_product_bytes(
                size,
                f"the range-Doppler maps of {n_frames} frames ({self.n_doppler} x "
                f"{self.n_range} each)",
                "radar.save_range_doppler",
            )
            self._maps_bytes = int(size)

    def working_memory(self) -> dict[str, int]:
        """The record's range-Doppler maps (``radar.save_range_doppler``), twice: the blocks'
        maps and their join into one array at the record's end."""
        return {"range-Doppler maps": 2 * self._maps_bytes} if self._maps_bytes else {}

    def sensor_axes(self, radar_position: FloatArray) -> FloatArray:
        """Sensor axes (rows x right, y boresight, z up) in the scene frame."""
        c = self.config
        if c.boresight_azimuth_deg is None:
            at_origin = np.hypot(radar_position[0], radar_position[1]) < 1e-9
            az = 0.0 if at_origin else float(np.arctan2(-radar_position[1], -radar_position[0]))
        else:
            az = float(np.deg2rad(c.boresight_azimuth_deg))
        return fmcw.sensor_axes(az, float(np.deg2rad(c.boresight_elevation_deg)))

    # ----------------------------------------------------------------- the streaming interface

    def pulse_times(self, start: float, end: float) -> FloatArray:
        """Ramp-start times of the chirps of every whole frame in ``[start, end]`` [s]."""
        return fmcw.chirp_times(self.sequence, start, end)

    def receive(self, block: PulseBlock) -> Received:
        """Range profiles, slow-time signal, range-Doppler maps and points of whole frames."""
        return self._receive(block, products=True)

    def receive_signal(self, block: PulseBlock) -> NDArray[np.complex128]:
        """The slow-time signal of whole frames alone (no range-Doppler maps, no points: the
        angle scans of a point cloud cost several times the signal itself)."""
        return self._receive(block, products=False).signal

    def receive_each(self, block: PulseBlock) -> NDArray[np.complex128]:
        """Each scatterer's slow-time signal alone, without receiver noise, (K, n_pulses): on
        the analytic path all scatterers in one pass over the frames
        (:func:`~mdframework.physics.fmcw.gate_responses`), on the raw path one scatterer
        after another."""
        seq, c = self.sequence, self.config
        if c.path != "analytic":
            return super().receive_each(block)
        ranges = np.asarray(block.ranges, np.float64)
        self._check_ranges(ranges)
        n_frames = fmcw.split_frames(ranges.shape[0], seq)
        amp = c.amplitudes(block.scatterers.rcs, ranges, seq.wavelength)
        radar_position = np.asarray(block.radar_position, np.float64)
        sensor = self.sensor_axes(radar_position)
        out = np.empty((ranges.shape[1], ranges.shape[0]), dtype=np.complex128)
        for f in range(n_frames):
            sl = slice(f * seq.chirps_per_frame, (f + 1) * seq.chirps_per_frame)
            out[:, sl] = fmcw.gate_responses(
                block.scatterers.positions[sl],
                amp[sl],
                radar_position,
                sensor,
                seq,
                self.antennas,
                block.gate_range[sl],
                c.gate_width,
                window_name=c.range_window,
                n_fft=self.n_range,
            )
        return out

    def gate_gain(self, ranges: FloatArray, gate_range: FloatArray) -> FloatArray:
        """Whether each scatterer reaches the slow-time signal's gate, (n_pulses, K): 1 when
        its range (folded into ``[0, max_range)`` as its beat frequency is, cyclically as the
        range FFT is) lies within :data:`GATE_MARGIN_RESOLUTIONS` range resolutions of the
        range bins the gate reads (those within ``gate_width / 2`` of the gate, or the bin
        nearest to it), else 0: beyond that only the range window's sidelobes reach the gate.
        For the empty-result check (a fixed gate away from the target)."""
        seq = self.sequence
        raxis = fmcw.range_axis(seq, self.n_range)
        gate = np.asarray(gate_range, np.float64)[:, None]
        half = self.config.gate_width / 2.0
        lo = np.maximum(gate - half, raxis[0])
        hi = np.minimum(gate + half, raxis[-1])
        nearest = np.clip(gate, raxis[0], raxis[-1])
        lo, hi = np.where(lo > hi, nearest, lo), np.where(lo > hi, nearest, hi)
        r = np.mod(np.asarray(ranges, np.float64), seq.max_range)
        off = np.full(r.shape, np.inf)
        for turn in (-seq.max_range, 0.0, seq.max_range):  # the range FFT is cyclic
            off = np.minimum(off, np.maximum(np.maximum(lo - (r + turn), r + turn - hi), 0.0))
        near = off <= GATE_MARGIN_RESOLUTIONS * seq.range_resolution
        return np.asarray(near, dtype=np.float64)

    def _receive(self, block: PulseBlock, products: bool) -> Received:
        """:meth:`receive`, with the configured products or (``products`` False) none."""
        seq, c = self.sequence, self.config
        want_points = products and c.points
        want_maps = products and c.save_range_doppler
        ranges = np.asarray(block.ranges, np.float64)
        self._check_ranges(ranges)
        n_frames = fmcw.split_frames(ranges.shape[0], seq)
        first_frame = block.start // seq.chirps_per_frame
        positions = block.scatterers.positions
        amp = c.amplitudes(block.scatterers.rcs, ranges, seq.wavelength)
        radar_position = np.asarray(block.radar_position, np.float64)
        sensor = self.sensor_axes(radar_position)
        antennas = self.antennas
        axes = self.axes()
        raxis = axes["range_m"]
        # the angles from the virtual antennas of the TXs the TDM order uses, not the zero
        # channels of an unused TX
        used = antennas.used_virtual(seq)
        every = used.size == antennas.virtual.shape[0]
        grid = fmcw.angle_grid(antennas.virtual[used], seq.wavelength)
        slots = antennas.slot_of_virtual(seq)[used]
        detection = self.detection()
        signal = np.empty(ranges.shape[0], dtype=np.complex128)
        maps: list[NDArray[np.float32]] = []
        frames: list[tuple[int, float, FloatArray]] = []
        for f in range(n_frames):
            sl = slice(f * seq.chirps_per_frame, (f + 1) * seq.chirps_per_frame)
            index = first_frame + f
            gate = block.gate_range[sl]
            step = seq.range_resolution / 2
            extra = np.arange(gate.min() - c.gate_width / 2, gate.max() + c.gate_width / 2, step)
            profiles = fmcw.chirp_profiles(
                positions[sl],
                amp[sl],
                radar_position,
                sensor,
                seq,
                antennas,
                window_name=c.range_window,
                n_fft=self.n_range,
                path=c.path,
                margin=c.analytic_margin,
                extra_ranges=extra,
                noise=self._noise(index, antennas.rx.shape[0]) if block.receiver_noise else None,
            )
            static = self._static_profiles(radar_position, sensor) if block.receiver_noise else None
            if static is not None:
                profiles += static
            signal[sl] = fmcw.gate_signal(
                profiles, raxis, gate, c.gate_width, c.range_window, c.n_samples
            )
            if not (want_points or want_maps):
                continue
            cube = fmcw.virtual_cube(profiles, seq, antennas.tx.shape[0])
            rd = fmcw.range_doppler(cube, c.doppler_window, self.n_doppler, c.clutter_removal)
            if want_maps:
                maps.append(fmcw.detection_map(rd).astype(np.float32))
            if want_points:
                pts = fmcw.detect_points(
                    rd if every else rd[used],
                    raxis,
                    axes["doppler_hz"],
                    grid,
                    slots,
                    seq.chirp_period,
                    seq.wavelength,
                    detection,
                )
                frames.append((index, index * seq.frame_period, pts))
        out: dict[str, NDArray[Any]] = {}
        if want_maps:
            out["range_doppler"] = (
                np.stack(maps) if maps else np.zeros((0, self.n_doppler, self.n_range), np.float32)
            )
        if want_points:
            out["points"] = fmcw.as_points(frames)
        return Received(signal, products=out)

    def _gapless(self) -> bool:
        """Whether the frames follow each other without gaps (then the spectrogram is an STFT
        over the record, else one spectrum per frame)."""
        seq = self.sequence
        return seq.frame_period <= seq.chirps_per_frame * seq.chirp_period * (1 + 1e-9)

    def spectrogram_geometry(
        self, n_pulses: int, processing: ProcessingConfig
    ) -> SpectrogramGeometry:
        """The geometry of :meth:`spectrogram` for ``n_pulses`` chirps (whole frames): the
        STFT's over the first slot's ``ceil(n_pulses / n_tx)`` chirps at :attr:`prf`, or one
        spectrum per frame of its ``n_loops`` chirps, one frame period apart, with
        ``max(processing.nfft, n_loops)`` bins."""
        from mdframework.physics.spectrogram import (
            RecordTooShortError,
            SpectrogramGeometry,
            stft_geometry,
        )

        seq, p = self.sequence, processing
        if self._gapless():
            n = -(-n_pulses // seq.n_tx)
            return stft_geometry(n, self.prf, p.window_length, p.hop, p.nfft)
        n_frames = n_pulses // seq.chirps_per_frame
        if n_frames < 1:
            raise RecordTooShortError(
                f"the record has {n_pulses} chirps but one frame needs {seq.chirps_per_frame}"
            )
        hop = seq.frame_period * self.prf
        return SpectrogramGeometry(self.prf, seq.n_loops, hop, max(p.nfft, seq.n_loops), n_frames)

    def smaller_spectrogram(self, processing: ProcessingConfig) -> tuple[str, str]:
        """The STFT's fields (the default's) when the frames follow each other without gaps;
        else one spectrum per frame of ``max(processing.nfft, n_loops)`` bins:
        ``radar.frame_period`` and ``processing.nfft`` (``n_loops`` bins per frame stay under
        the pulse limit)."""
        if self._gapless():
            return super().smaller_spectrogram(processing)
        return (
            "radar.frame_period",
            "raise radar.frame_period, lower processing.nfft or shorten the record",
        )

    def spectrogram(
        self, signal: NDArray[np.complex128], times: FloatArray, processing: ProcessingConfig
    ) -> Spectrogram:
        """Micro-Doppler spectrogram from the first TDM slot's chirps (one sample per loop):
        an STFT (``processing`` window, length, hop, FFT size) when the frames follow each other
        without gaps, else one Doppler spectrum per frame (window over the frame's loops, FFT
        size ``max(processing.nfft, n_loops)``), at its window's centre (``n_loops / 2`` loops
        after the frame's first chirp with the Hann window); the power in
        ``processing.precision`` (float32 by default). :meth:`spectrogram_geometry` gives its
        geometry. ``times`` is not needed: the config fixes the chirp timing."""
        from mdframework.physics.spectrogram import Spectrogram
        from mdframework.pipeline import processing_stft

        seq = self.sequence
        p = processing
        if self._gapless():
            return processing_stft(np.asarray(signal)[:: seq.n_tx], self.prf, p)
        power, doppler, time = fmcw.frame_spectrogram(
            np.asarray(signal), seq, p.window, max(p.nfft, seq.n_loops), p.precision
        )
        return Spectrogram(power, doppler, time)

    # ----------------------------------------------------------------- helpers

    def detection(self) -> fmcw.Detection:
        """The detection settings of this config."""
        c = self.config
        return fmcw.Detection(
            cfar_range=_cfar(c.cfar_range),
            cfar_doppler=_cfar(c.cfar_doppler),
            group_doppler="doppler" in c.peak_grouping,
            group_range="range" in c.peak_grouping,
            min_range=c.detect_min_range,
            max_range=c.detect_max_range or self.sequence.max_range,
            multi_peak=c.multi_object_threshold,
            tdm_compensation=c.tdm_compensation,
            noise_floor=0.0 if self._if_noise() else self.map_noise_power(),
        )

    @property
    def takes_receiver_inputs(self) -> bool:
        """True when the radar makes range-Doppler maps or points (``points``,
        ``save_range_doppler``): the received-stage effects that can (noise, static clutter)
        then go into its IF samples, so that the maps, the points and the spectrogram all
        carry them; without either, they act on the slow-time signal as with every radar."""
        return self.config.points or self.config.save_range_doppler

    @property
    def max_static_range(self) -> float | None:
        """The maximum range [m]: static scatterers at or beyond it are left out of the IF
        samples; ``None`` with ``beyond_max_range = "alias"`` (they fold back in)."""
        return None if self.config.beyond_max_range == "alias" else self.sequence.max_range

    def set_receiver_inputs(self, inputs: Sequence[ReceiverInput]) -> None:
        """The record's effects in the IF samples: white noise per frame seeded by (the
        input's ``noise_key``, frame index), static scatterers along the boresight."""
        self._inputs = list(inputs)
        self._static = None

    def _if_noise(self) -> bool:
        """Whether the IF samples carry noise (``receiver_noise`` or a noise effect)."""
        return self.config.receiver_noise or any(i.noise_power > 0 for i in self._inputs)

    def _static_profiles(
        self, radar_position: FloatArray, sensor: FloatArray
    ) -> NDArray[np.complex128] | None:
        """The range profiles (chirps_per_frame, n_rx, n_range) of the static scatterers of the
        receiver inputs (e.g. clutter patches), at their ranges along the boresight, the same
        in every frame (they do not move: zero Doppler); None without any. Those at or beyond
        the maximum range are left out, unless ``beyond_max_range = "alias"``. Made once per
        record and radar position."""
        key = tuple(float(v) for v in radar_position)
        if self._static is not None and self._static[0] == key:
            return self._static[1]
        seq, c = self.sequence, self.config
        ranges = np.concatenate([np.zeros(0), *(i.static_ranges for i in self._inputs)])
        rcs = np.concatenate([np.zeros(0), *(i.static_rcs for i in self._inputs)])
        far = self.max_static_range
        if far is not None:
            keep = ranges < far
            ranges, rcs = ranges[keep], rcs[keep]
        out = None
        if ranges.size:
            n = seq.n_tx  # one loop: every TDM slot once
            positions = radar_position + ranges[:, None] * sensor[1]  # (P, 3) [m]
            profiles = fmcw.chirp_profiles(
                np.broadcast_to(positions, (n, *positions.shape)),
                np.broadcast_to(c.amplitudes(rcs, ranges, seq.wavelength), (n, ranges.size)),
                radar_position,
                sensor,
                seq,
                self.antennas,
                window_name=c.range_window,
                n_fft=self.n_range,
                path=c.path,
                margin=c.analytic_margin,
            )
            out = np.tile(profiles, (seq.n_loops, 1, 1))
        self._static = (key, out)
        return out

    def thermal_noise_power(self) -> float:
        """The receiver's noise power per complex ADC sample, ``k T0 F fs`` [W], whether it is
        added (``receiver_noise``) or not."""
        c = self.config
        return KT0 * 10.0 ** (c.noise_figure_db / 10.0) * c.sample_rate

    @property
    def adds_receiver_noise(self) -> bool:
        """True with ``receiver_noise``: the IF samples carry the receiver's thermal noise."""
        return self.config.receiver_noise

    def noise_power(self) -> float:
        """The radar's own receiver noise power added per complex ADC sample, ``k T0 F fs``
        [W] (0 without ``receiver_noise``); a noise effect's in the IF samples is not counted
        (its :class:`~mdframework.ReceiverInput`'s ``noise_power``)."""
        return self.thermal_noise_power() if self.config.receiver_noise else 0.0

    def map_noise_power(self) -> float:
        """Mean receiver noise [W] in one cell of the point detection's map (the virtual
        antennas of the TXs in ``tdm_order``), :func:`mdframework.physics.fmcw.map_noise_power`;
        without receiver noise, the floor of the CFAR noise estimates."""
        c = self.config
        n_virt = self.antennas.used_virtual(self.sequence).size
        return fmcw.map_noise_power(
            self.thermal_noise_power(),
            n_virt,
            c.range_window,
            c.n_samples,
            c.doppler_window,
            c.n_loops,
        )

    def _noise(self, frame: int, n_rx: int) -> NDArray[np.complex64] | None:
        """Complex white noise of one frame, (chirps_per_frame, n_rx, n_samples) complex64:
        the receiver's (``receiver_noise``), seeded by (``noise_seed``, else the run's seed,
        frame index), plus each noise effect's in the IF, seeded by (its key, frame index): the
        same whatever the blocks."""
        shape = (self.sequence.chirps_per_frame, n_rx, self.config.n_samples)
        draws = [(i.noise_power, i.noise_key) for i in self._inputs if i.noise_power > 0]
        if self.config.receiver_noise:
            own = self.config.noise_seed
            run_seed = getattr(self, "seed", None)  # (an mdframework without the attribute)
            key = own if own is not None else (run_seed or 0)
            draws.insert(0, (self.thermal_noise_power(), key))
        noise: NDArray[np.complex64] | None = None
        for power, key in draws:
            one = complex_noise(np.random.default_rng([key, frame]), shape, power)
            noise = one if noise is None else noise + one
        return noise

    def _check_ranges(self, ranges: FloatArray) -> None:
        if self.config.beyond_max_range == "alias" or ranges.size == 0:
            return
        far = float(np.max(ranges))
        seq = self.sequence
        if far >= seq.max_range:
            beat = 2.0 * seq.slope * far / SPEED_OF_LIGHT
            raise SceneError(
                f"radar.sample_rate: the farthest scatterer at {far:.2f} m beats at "
                f"{beat / 1e6:.3f} MHz, above the ADC rate {seq.sample_rate / 1e6:.3f} MHz "
                f"(maximum range {seq.max_range:.2f} m): raise sample_rate, lower slope, or "
                "set beyond_max_range = 'alias'"
            )


def complex_noise(
    rng: np.random.Generator, shape: tuple[int, ...], power: float
) -> NDArray[np.complex64]:
    """Circular complex white Gaussian noise of ``power`` [W] per sample, complex64: float32
    draws (real and imaginary parts of each sample in turn) straight into the complex64 buffer:
    about 0.8 times the time of float64 draws into complex128 (docs/fmcw.md, Costs)."""
    n = int(np.prod(shape))
    out = rng.standard_normal(2 * n, dtype=np.float32).view(np.complex64).reshape(shape)
    out *= np.float32(np.sqrt(power / 2.0))
    return out
