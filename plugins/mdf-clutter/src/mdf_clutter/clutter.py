"""Ground clutter: stationary returns plus wind-blown clutter (effect kind ``clutter``, stage
``received``).

The ground is a row of clutter patches at fixed ranges ``r_k`` covering the range gate's whole
span over the record plus ``margin_m`` on either side, spaced ``patch_spacing_m`` (default half
the range resolution ``c/(2B)``) with a random position inside each spacing (which also makes
each patch's carrier phase uniformly random). Each patch's echo goes through the scene's own
waveform (``waveform.receive_each``: each unit-RCS patch's response alone, without receiver
noise), so it carries the waveform's gate response ``g_k(n)``: with a fixed gate the patches
near the gate dominate; with a tracking gate the patches in the gate change as the person moves
(the clutter decorrelates on the time the gate takes to cross a resolution cell) but each patch
stays at zero Doppler.

Patch ``k`` contributes ``g_k(n) (alpha_k + beta_k u_k(n))``:

- **stationary** part ``alpha_k``: a complex Gaussian constant (Rayleigh amplitude), zero Doppler;
- **wind-blown** part ``beta_k u_k(n)``: an independent complex Gaussian process per patch with a
  Gaussian Doppler power spectrum centred on 0 Hz,
  ``S(f) ∝ exp(-f^2 / (2 s_f^2))``, ``s_f = 2 spread_mps / lambda``: ``spread_mps`` is the
  standard deviation of the wind-blown clutter's radial-velocity spectrum [m/s] (about 0.05 m/s
  in light air to 0.3 m/s in gale for trees). It is made by shaping white noise in the frequency
  domain, with unit mean power, on a uniform grid at the shortest pulse interval that spans the
  record and is lengthened to a fast FFT length (a process circular over that grid, not over
  the record), and read at the pulse times: at the pulses themselves for evenly
  spaced pulses, at each chirp's own instant for an FMCW radar (several transmitters in turn,
  gaps between frames), so each virtual antenna's slow time has the requested spread.

Power: the summed clutter ``c(n)`` is scaled so that its mean power over the record,
``P_c = mean_n |c(n)|^2``, is exactly ``(1 - wind_fraction) P_c`` for the stationary part and
``wind_fraction P_c`` for the wind-blown part, with ``P_c`` given by

- ``power = "csr"``: the clutter-to-signal ratio ``csr_db`` = ``P_c`` over the mean power of the
  compressed return at the gate (the same reference as the ``noise`` effect's SNR), the
  received signal as the radar gave it (``SceneContext.echo``: before any received-stage
  effect, so the ``noise`` effect, listed before or after this one, does not count; with a
  radar that adds receiver noise itself, the FMCW radar's ``receiver_noise``, that noise is
  part of it);
- ``power = "rcs"``: ``rcs_m2``, the clutter RCS of one range-resolution cell (``sigma_0`` times
  the illuminated ground area of the cell); each patch carries ``rcs_m2 x spacing/resolution``
  and ``P_c = sum_k sigma_k mean_n |g_k(n)|^2`` through the waveform's range equation.

The patches cross the same medium as the target: with an ``attenuation`` effect in the scene
each patch loses the two-way loss of its own range (:meth:`GroundClutter.path_loss`). The
antenna pattern is not applied: a patch has a range, not a direction, and ``rcs_m2`` is the
clutter RCS the radar sees in a cell (``sigma_0`` times the cell's area weighted by the two-way
pattern over it); a gain on top would count the beam twice.

The clutter is added to ``Received.signal``; a range-time map, if any, is passed on unchanged.
A radar that simulates the clutter in its raw samples (``RadarWaveform.takes_receiver_inputs``:
the FMCW radar making maps or points) gets the stationary patches as static point scatterers
instead (:meth:`GroundClutter.receiver_input`; ``power = "rcs"`` and no wind only).
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Iterator, Sequence
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from mdframework import (
    Effect,
    PluginConfig,
    RadarWaveform,
    Received,
    ReceiverInput,
    Scatterers,
    SceneContext,
    SceneError,
    point_responses,
)
from mdframework.physics import radar
from mdframework.settings import Decibels, Rcs

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


class ClutterConfig(PluginConfig):
    """Stationary ground clutter plus wind-blown clutter with a Gaussian Doppler spectrum."""

    kind: Literal["clutter"] = "clutter"
    power: Literal["csr", "rcs"] = Field(
        "csr", description="csr: set by csr_db relative to the signal; rcs: set by rcs_m2."
    )
    csr_db: Decibels = Field(
        0.0,
        description="power csr: clutter-to-signal ratio, mean clutter power over mean "
        "compressed signal power at the gate [dB].",
    )
    rcs_m2: Rcs = Field(
        0.1, description="power rcs: clutter RCS of one range-resolution cell [m^2]."
    )
    wind_fraction: float = Field(
        0.3, ge=0, le=1, description="Fraction of the clutter power that is wind-blown."
    )
    spread_mps: float = Field(
        0.1,
        gt=0,
        le=100,
        description="Standard deviation of the wind-blown clutter's radial-velocity "
        "spectrum [m/s] (Gaussian, centred on zero).",
    )
    patch_spacing_m: float | None = Field(
        None,
        gt=0,
        le=1000,
        description="Spacing of the clutter patches [m]; default: resolution/2.",
    )
    margin_m: float | None = Field(
        None,
        ge=0,
        le=10_000,
        description="Patches beyond the gate's range span [m]; default: 4 cells.",
    )
    range_resolution: float | None = Field(
        None, gt=0, le=10_000, description="c/(2B) [m]; default: the radar's own (none for CW)."
    )


def gaussian_doppler_process(
    rng: np.random.Generator, n_series: int, n_samples: int, prf: float, spread_hz: float
) -> ComplexArray:
    """Independent complex Gaussian processes (n_series, n_samples) with unit mean power and a
    Gaussian power spectrum of standard deviation ``spread_hz`` [Hz] about 0 Hz, sampled at
    ``prf`` [Hz] (spectrum shaping of white noise; circular over the record)."""
    white = rng.standard_normal((n_series, n_samples)) + 1j * rng.standard_normal(
        (n_series, n_samples)
    )
    return _shaped(white, prf, spread_hz)


def _shaped(white: ComplexArray, prf: float, spread_hz: float) -> ComplexArray:
    """Rows of complex white noise (n, n_samples) shaped to the Gaussian spectrum and scaled to
    unit mean power (:func:`gaussian_doppler_process`)."""
    f = np.fft.fftfreq(white.shape[1], d=1.0 / prf)
    psd = np.exp(-0.5 * (f / spread_hz) ** 2)
    shaped = np.fft.ifft(np.fft.fft(white, axis=1) * np.sqrt(psd), axis=1)
    power = np.mean(np.abs(shaped) ** 2, axis=1, keepdims=True)
    return np.asarray(shaped / np.sqrt(np.where(power > 0, power, 1.0)), dtype=np.complex128)


#: Grid values of the wind-blown processes made at a time: :func:`wind_process_groups` yields
#: groups of at most this many (at least one series), so their memory does not grow with the
#: patches; pulses with gaps are drawn in calls of this many (or of all the series at the
#: pulses, if more), which fixes their draws.
WIND_GRID_VALUES = 1 << 22

#: Patches whose responses one call of the waveform makes (their positions, (n_pulses, n, 3),
#: are made for the call): a radar with a cost per call (the FMCW radar's pass over the frames)
#: pays it once for so many.
PATCHES_PER_CALL = 16

#: Pulses of one call of the waveform in :meth:`GroundClutter.apply` (rounded down to a multiple
#: of the radar's ``block_multiple``, at least one): the patches' positions, responses and the
#: radar's own working arrays (the raw path's range-time rows) span so many pulses, not the
#: record (a 10-minute record at 2400 Hz held 0.5 GB of positions per call on the analytic path
#: and 1 GB more of range-time rows on the raw path).
PULSES_PER_CALL = 1 << 16


def wind_processes(
    rng: np.random.Generator, n_series: int, times: FloatArray, prf: float, spread_hz: float
) -> ComplexArray:
    """:func:`gaussian_doppler_process` read at the pulse ``times`` (n_pulses,) [s]: made on a
    uniform grid at the shortest pulse interval from the first pulse, each pulse taking the grid
    point nearest to it. Pulses evenly spaced (a pulse-Doppler or CW radar) are the grid's
    first points; an FMCW radar's chirps (several transmitters in turn, gaps between frames) get
    the process at their own instants, so the slow time of each virtual antenna (every
    ``n_tx``-th chirp) sees the requested spread and frames apart in time are as decorrelated as
    that time makes them. The grid is lengthened to the next length whose FFT is fast (the
    process is circular over the grid, not over the record: up to 5x faster than a length of
    large prime factors).
    ``prf`` [Hz] serves fewer than two pulses. Returns (n_series, n_pulses)."""
    t = np.asarray(times, dtype=np.float64)
    out = np.empty((n_series, t.size), dtype=np.complex128)
    for lo, hi, u in wind_process_groups(rng, n_series, t, prf, spread_hz):
        out[lo:hi] = u
    return out


def wind_process_groups(
    rng: np.random.Generator,
    n_series: int,
    times: FloatArray,
    prf: float,
    spread_hz: float,
    group_values: int | None = None,
) -> Iterator[tuple[int, int, ComplexArray]]:
    """:func:`wind_processes` a group of series at a time: yields ``(lo, hi, u)`` with ``u``
    the series ``lo:hi`` (hi - lo, n_pulses), in order, each group at most ``group_values``
    grid values (default :data:`WIND_GRID_VALUES`; at least one series), so their memory does
    not grow with ``n_series``. The values, and the draws from ``rng`` (its state after the
    last group included), are those of :func:`wind_processes` made at once."""
    t = np.asarray(times, dtype=np.float64)
    step = float(np.min(np.diff(t))) if t.size > 1 else 0.0
    idx: NDArray[np.int64] | slice = slice(None)
    if step > 0.0:
        from scipy.fft import next_fast_len

        # half-way rounds up, always: np.rint's half to even would give two chirps of a frame
        # that sits half a step off the grid one sample, and the next two samples 2 steps apart
        grid = np.floor((t - t[0]) / step + 0.5).astype(np.int64)
        # evenly spaced pulses are the grid's first samples
        idx = slice(0, t.size) if int(grid[-1]) + 1 == t.size else grid
        # a grid of a length whose FFT is fast (factors 2, 3, 5): 4.6x faster for a 10 min
        # record at 2400 Hz (1,440,001 = 337 x 4273 samples)
        n_grid, rate = next_fast_len(int(grid[-1]) + 1), 1.0 / step
        per_call = max(1, max(WIND_GRID_VALUES, n_series * t.size) // n_grid)
    else:
        n_grid, rate, per_call = t.size, prf, max(n_series, 1)
    rows = max(1, (WIND_GRID_VALUES if group_values is None else group_values) // max(n_grid, 1))
    for lo in range(0, n_series, per_call):
        hi = min(lo + per_call, n_series)
        if hi - lo <= rows:
            u = gaussian_doppler_process(rng, hi - lo, n_grid, rate, spread_hz)
            yield lo, hi, u[:, idx]
            del u  # not held beside the next group
            continue
        # the draw of the series lo:hi takes all their real parts, then all their imaginary
        # parts: a copy of the generator reads the real parts while rng, moved past them,
        # reads the imaginary parts (and ends where the draw at once would leave it)
        real = copy.deepcopy(rng)
        for a in range(lo, hi, rows):  # skip the real parts, a group at a time
            rng.standard_normal((min(a + rows, hi) - a, n_grid))
        for a in range(lo, hi, rows):
            b = min(a + rows, hi)
            white = real.standard_normal((b - a, n_grid)) + 1j * rng.standard_normal(
                (b - a, n_grid)
            )
            u = _shaped(white, rate, spread_hz)
            del white
            yield a, b, u[:, idx]
            del u


class GroundClutter(Effect):
    """Adds ground clutter at zero Doppler plus wind-blown clutter to the compressed return."""

    name = "clutter"
    Config = ClutterConfig
    config: ClutterConfig
    stage = "received"

    def __init__(self, config: PluginConfig | None = None) -> None:
        super().__init__(config)
        self._stats: dict[str, Any] = {}
        self._attenuation: tuple[Effect, ...] = ()

    def check_effects(self, effects: Sequence[Effect]) -> None:
        """Keep the scene's ``attenuation`` effects: the patches lose what their own range
        loses (:meth:`path_loss`), as the target's scatterers do."""
        self._attenuation = tuple(e for e in effects if e.name == "attenuation")

    def path_loss(self, context: SceneContext, ranges: FloatArray) -> FloatArray:
        """Two-way power factor (<= 1) of the scene's ``attenuation`` effects for patches at
        ``ranges`` (n,) [m] (1 without them): each effect's own ``apply`` on point scatterers
        at those ranges (its loss depends on the range alone)."""
        r = np.asarray(ranges, dtype=np.float64)
        if not self._attenuation:
            return np.ones(r.shape)
        radar_at = np.asarray(context.radar_position, dtype=np.float64)
        positions = radar_at + r[None, :, None] * np.array([1.0, 0.0, 0.0])
        names = tuple(f"clutter{k}" for k in range(r.size))
        patches = Scatterers(positions, np.ones((1, r.size)), names)
        for effect in self._attenuation:
            patches = effect.apply(patches, context)
        return np.asarray(patches.rcs[0], dtype=np.float64)

    def check_radar(self, waveform: RadarWaveform) -> None:
        """A radar without a range resolution (CW: ``RadarWaveform.range_resolution`` None) needs
        ``range_resolution``: refused when the run is built, before any pulse. A radar that
        simulates the clutter in its raw samples (the FMCW radar making maps or points) takes
        static patches of given RCS only: ``power = "csr"`` (set from the record's mean echo,
        known only after the maps) and wind-blown clutter are refused."""
        self._resolution(waveform)
        if not waveform.takes_receiver_inputs:
            return
        why = f"the {waveform.name!r} radar makes its maps and points from IF samples, which "
        if self.config.power == "csr":
            raise SceneError(
                f"effects.clutter.power: {why}must carry the clutter before the record's mean "
                "echo that 'csr' refers to is known: use power = 'rcs' with rcs_m2, or "
                "radar.points = false and radar.save_range_doppler = false for a spectrogram alone"
            )
        if self.config.wind_fraction > 0.0:
            raise SceneError(
                f"effects.clutter.wind_fraction: {why}take the clutter as static patches at "
                "zero Doppler: set wind_fraction = 0, or radar.points = false and "
                "radar.save_range_doppler = false for wind-blown clutter in a spectrogram alone"
            )

    def resolution(self, context: SceneContext) -> float:
        """Range resolution c/(2B) [m]."""
        return self._resolution(context.waveform)

    def _resolution(self, waveform: RadarWaveform) -> float:
        if self.config.range_resolution is not None:
            return float(self.config.range_resolution)
        resolution = waveform.range_resolution
        if resolution is None:
            raise SceneError(
                f"effects.clutter: the {waveform.name!r} radar has no range resolution (no "
                "bandwidth); set range_resolution"
            )
        return float(resolution)

    def _spacing(self, resolution: float) -> float:
        """Patch spacing [m]: ``patch_spacing_m``, default half the range resolution [m]."""
        spacing = self.config.patch_spacing_m
        return float(spacing) if spacing is not None else resolution / 2.0

    def patch_ranges(self, context: SceneContext) -> FloatArray:
        """Patch ranges (n_patches,) [m], a random position inside each spacing (drawn from
        ``context.rng``)."""
        c = self.config
        res = self.resolution(context)
        spacing = self._spacing(res)
        margin = c.margin_m if c.margin_m is not None else 4.0 * res
        gate = np.asarray(context.gate_range, dtype=np.float64)
        lo = max(float(gate.min()) - margin, spacing)
        hi = float(gate.max()) + margin
        n_patch = max(int(np.ceil((hi - lo) / spacing)), 1)
        return np.asarray(lo + (np.arange(n_patch) + context.rng.uniform(size=n_patch)) * spacing)

    def responses(self, context: SceneContext, ranges: FloatArray) -> ComplexArray:
        """The return at the gate of a unit-RCS patch at each of ``ranges`` (n,) [m], each alone
        (:func:`~mdframework.point_responses`; no receiver noise):
        (n, n_pulses) [sqrt(W) per sqrt(m^2)]."""
        gate = np.asarray(context.gate_range, dtype=np.float64)
        n_p = gate.shape[0]
        resp = np.empty((ranges.size, n_p), dtype=np.complex128)
        for lo in range(0, ranges.size, PATCHES_PER_CALL):  # positions of a few patches at once
            r = np.asarray(ranges[lo : lo + PATCHES_PER_CALL], np.float64)
            resp[lo : lo + r.size] = point_responses(
                context.waveform,
                np.broadcast_to(r, (n_p, r.size)),
                np.ones((n_p, r.size)),
                gate,
                context.radar_position,
                context.pulse_times,
            )
        return resp

    def patch_responses(self, context: SceneContext) -> tuple[FloatArray, ComplexArray]:
        """Patch ranges (n_patches,) [m] and each unit-RCS patch's return at the gate
        (n_patches, n_pulses) [sqrt(W) per sqrt(m^2)] (the whole record's: :meth:`apply`
        makes them a group of patches at a time)."""
        ranges = self.patch_ranges(context)
        return ranges, self.responses(context, ranges)

    def _patches(self, context: SceneContext) -> tuple[FloatArray, float, ComplexArray]:
        """The record's patches, drawn from ``context.rng``: their ranges (n_patches,) [m]
        (:meth:`patch_ranges`), each patch's mean RCS ``rcs_m2 spacing / resolution`` [m^2]
        and their complex Gaussian amplitudes of unit mean power (n_patches,) (Rayleigh)."""
        res = self.resolution(context)
        ranges = self.patch_ranges(context)
        n = ranges.size
        alpha = (context.rng.standard_normal(n) + 1j * context.rng.standard_normal(n)) / np.sqrt(2)
        return ranges, float(self.config.rcs_m2 * self._spacing(res) / res), alpha

    def receiver_input(self, context: SceneContext) -> ReceiverInput | None:
        """For a radar that simulates the clutter in its raw samples (:meth:`check_radar`:
        ``power = "rcs"``, no wind): the stationary patches as static point scatterers at
        :meth:`patch_ranges`, patch ``k`` of RCS ``rcs_m2 (spacing / resolution) |alpha_k|^2``
        times its :meth:`path_loss` (``alpha_k`` complex Gaussian of unit mean power: a Rayleigh
        amplitude; the carrier phase follows from the patch's random range). Patches at or
        beyond the radar's :attr:`~mdframework.RadarWaveform.max_static_range` are left out
        (drawn all the same):
        ``n_patches``, ``patch_range_m`` and ``clutter_rcs_m2`` of :meth:`describe` are those
        of the patches simulated, ``n_patches_beyond_max_range`` counts the others."""
        ranges, sigma_k, alpha = self._patches(context)
        rcs = sigma_k * np.abs(alpha) ** 2 * self.path_loss(context, ranges)
        far = context.waveform.max_static_range
        n_all = ranges.size
        if far is not None:
            keep = ranges < far
            ranges, rcs = ranges[keep], rcs[keep]
        self._stats = {
            "n_patches": int(ranges.size),
            "n_patches_beyond_max_range": int(n_all - ranges.size),
            "patch_range_m": [float(ranges.min()), float(ranges.max())] if ranges.size else None,
            "clutter_rcs_m2": float(np.sum(rcs)),
            "in_receiver": True,
        }
        return ReceiverInput(self.name, static_ranges=ranges, static_rcs=rcs)

    def apply(self, data: Received, context: SceneContext) -> Received:
        """The received data plus clutter. The patches' wind-blown processes are made a group
        of patches at a time (:func:`wind_process_groups`), their responses a few patches and
        :data:`PULSES_PER_CALL` pulses at a time, and summed, so memory grows with the pulses
        (a few slow-time signals), not with the pulses times the patches."""
        c = self.config
        ranges, sigma_k, alpha = self._patches(context)
        n_patch = ranges.size
        rng = context.rng
        lam = radar.wavelength(context.carrier_frequency)
        spread_hz = 2.0 * c.spread_mps / lam
        n_p = np.shape(context.gate_range)[0]
        stationary = np.zeros(n_p, dtype=np.complex128)
        wind = np.zeros(n_p, dtype=np.complex128)
        patch_power = np.empty(n_patch)  # mean_n |g_k(n)|^2 of each unit-RCS patch
        groups = wind_process_groups(rng, n_patch, context.pulse_times, context.prf, spread_hz)
        loss = np.sqrt(self.path_loss(context, ranges))  # amplitude
        multiple = max(1, int(context.waveform.block_multiple))
        step = max(multiple, PULSES_PER_CALL - PULSES_PER_CALL % multiple)
        for lo, hi, u in groups:
            energy = np.zeros(hi - lo)
            for a in range(0, n_p, step):  # a few patches' responses over a part of the record
                b = min(a + step, n_p)
                part = dataclasses.replace(
                    context,
                    pulse_times=np.asarray(context.pulse_times)[a:b],
                    gate_range=np.asarray(context.gate_range)[a:b],
                )
                resp = self.responses(part, ranges[lo:hi]) * loss[lo:hi, None]
                energy += np.sum(np.abs(resp) ** 2, axis=1)
                for k in range(hi - lo):  # patch after patch: the sums of all patches at once
                    stationary[a:b] += alpha[lo + k] * resp[k]
                    wind[a:b] += resp[k] * u[k, a:b]
                del resp
            patch_power[lo:hi] = energy / n_p
            del u
        if c.power == "csr":  # relative to the echo, whatever the order of the effects
            echo = context.echo if context.echo is not None else data.signal
            p_sig = float(np.mean(np.abs(echo) ** 2))
            p_c = p_sig * 10.0 ** (c.csr_db / 10.0)
        else:
            p_c = float(sigma_k * np.sum(patch_power))
        clutter = _scaled(stationary, (1.0 - c.wind_fraction) * p_c) + _scaled(
            wind, c.wind_fraction * p_c
        )
        self._stats = {
            "n_patches": int(n_patch),
            "patch_range_m": [float(ranges.min()), float(ranges.max())],
            "clutter_power_w": p_c,
            "spread_hz": spread_hz,
        }
        return dataclasses.replace(data, signal=data.signal + clutter)

    def describe(self) -> dict[str, Any]:
        """The config plus the patches' extent and the clutter power [W]."""
        return {**self.config.model_dump(), **self._stats}


def _scaled(x: ComplexArray, power: float) -> ComplexArray:
    """``x`` scaled to mean power ``power`` (zero stays zero)."""
    p = float(np.mean(np.abs(x) ** 2)) if x.size else 0.0
    if p <= 0.0 or power <= 0.0:
        return np.zeros_like(x)
    return np.asarray(x * np.sqrt(power / p), dtype=np.complex128)
