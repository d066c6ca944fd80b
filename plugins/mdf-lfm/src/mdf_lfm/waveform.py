"""LFM pulse-Doppler radar (``physics.md`` sections 1.1-1.5).

Two receive paths:

- ``analytic`` (default): the compressed return at the range gate in closed form (eq. 4), with the
  exact LFM matched-filter response, its large-TB sinc limit, or the phase-only limit.
- ``raw``: samples fast time, builds every scatterer's chirp echo (eq. 1-2), pulse-compresses with
  the matched filter, reads the gate at its exact delay, and returns a range-time map.

Both are normalised by the pulse width, so a lone scatterer at the gate gives its range-equation
amplitude.

``precision = "float32"`` (analytic path only; for the accuracy ladder, ``benchmarks/
bench_accuracy.py``): the carrier phase is still reduced to a fraction of a cycle in float64 from
float64 ranges (``physics.md`` section 6.1), then the phasor, the gate weights, the amplitudes and
the sum over scatterers are float32 / complex64; the result is returned as complex128. The
default ``float64`` is the reference.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from mdframework import RadarWaveform, Received, limits
from mdframework.constants import SPEED_OF_LIGHT
from mdframework.physics import radar
from mdframework.settings import Bandwidth, RadarPowerConfig

#: Pulses per block on the raw path (bounds memory to ~ block x n_fast complex samples).
RAW_BLOCK = 1024


class LfmConfig(RadarPowerConfig):
    """LFM pulse-Doppler radar. Defaults: the paper's radar (15 GHz, 150 MHz, PRF 2400 Hz)."""

    kind: Literal["lfm"] = "lfm"
    carrier_frequency: float = Field(
        15e9,
        ge=limits.MIN_CARRIER_HZ,
        le=limits.MAX_CARRIER_HZ,
        description="Band-centre frequency [Hz], 1 MHz .. 1 THz.",
    )
    bandwidth: Bandwidth = Field(150e6, description="Chirp bandwidth [Hz] (< 2 x carrier).")
    prf: float = Field(
        2400.0,
        ge=limits.MIN_PRF_HZ,
        le=limits.MAX_PRF_HZ,
        description="Pulse repetition frequency [Hz], 1 Hz .. 10 MHz.",
    )
    pulse_width: float = Field(
        1e-6, gt=0, le=0.1, description="Pulse length tau [s] (at most 1/PRF)."
    )
    path: Literal["analytic", "raw"] = Field(
        "analytic", description="analytic: closed-form compressed return; raw: sampled chirps."
    )
    gate_response: Literal["exact", "sinc", "phase_only"] = Field(
        "exact",
        description="Analytic path: range weighting of scatterers in the gate (exact LFM "
        "response, its sinc limit, or none).",
    )
    precision: Literal["float64", "float32"] = Field(
        "float64",
        description="Analytic path: arithmetic after the float64 phase reduction (float32: "
        "complex64 phasors and sums).",
    )
    sample_rate: Bandwidth | None = Field(
        None, description="Raw path: fast-time sample rate [Hz]; default 2 x bandwidth."
    )
    range_margin: float = Field(
        3.0, ge=0, le=1000, description="Raw path: range-time window beyond the scatterers [m]."
    )

    @model_validator(mode="after")
    def _check(self) -> LfmConfig:
        if self.bandwidth >= 2 * self.carrier_frequency:
            raise ValueError(
                f"bandwidth ({self.bandwidth:g} Hz) must be below twice the carrier frequency "
                f"({self.carrier_frequency:g} Hz): the band cannot reach 0 Hz"
            )
        if self.pulse_width * self.prf > 1.0:
            raise ValueError(
                f"pulse_width ({self.pulse_width:g} s) must not exceed the pulse interval "
                f"1/prf ({1.0 / self.prf:g} s)"
            )
        if self.bandwidth * self.pulse_width < 1.0:
            raise ValueError("bandwidth x pulse_width must be >= 1 for a pulse-compression radar")
        if self.precision == "float32" and self.path == "raw":
            raise ValueError("precision 'float32' is implemented for the analytic path only")
        if self.sample_rate is not None and self.sample_rate < self.bandwidth:
            raise ValueError("sample_rate must be >= bandwidth (complex sampling)")
        return self


class LfmPulseDoppler(RadarWaveform):
    """Monostatic LFM pulse-Doppler radar with stop-and-hop returns."""

    name = "lfm"
    Config = LfmConfig
    config: LfmConfig

    @property
    def carrier_frequency(self) -> float:
        """Band-centre frequency [Hz]."""
        return self.config.carrier_frequency

    @property
    def prf(self) -> float:
        """Pulse repetition frequency [Hz]."""
        return self.config.prf

    def amplitudes(self, ranges: np.ndarray, rcs: np.ndarray) -> np.ndarray:
        """Scatterer amplitudes [sqrt(W)] (range equation or sqrt(rcs), ``amplitude``), same
        shape as ``ranges``."""
        return self.config.amplitudes(rcs, ranges, radar.wavelength(self.config.carrier_frequency))

    def receive(self, ranges: np.ndarray, rcs: np.ndarray, gate_range: np.ndarray) -> Received:
        """Compressed slow-time return at the gate (and a range-time map on the raw path)."""
        amp = self.amplitudes(ranges, rcs)
        c = self.config
        if c.path == "analytic" and c.precision == "float32":
            return Received(self._receive_float32(ranges, amp, gate_range))
        if c.path == "analytic":
            signal = radar.compressed_return_at_gate(
                ranges,
                amp,
                gate_range,
                carrier_frequency=c.carrier_frequency,
                pulse_width=c.pulse_width,
                bandwidth=c.bandwidth,
                response=c.gate_response,
            )
            return Received(signal)
        return self._receive_raw(ranges, amp, gate_range)

    def _receive_float32(
        self, ranges: np.ndarray, amp: np.ndarray, gate_range: np.ndarray
    ) -> np.ndarray:
        """The analytic return with complex64 arithmetic after a float64 phase reduction."""
        c = self.config
        w = radar.gate_weights(
            ranges,
            gate_range,
            pulse_width=c.pulse_width,
            bandwidth=c.bandwidth,
            response=c.gate_response,
        ).astype(np.float32)
        frac = radar.carrier_cycles_fraction(ranges, c.carrier_frequency)
        phase = ((-2.0 * np.pi) * frac).astype(np.float32)
        phasor = np.empty(phase.shape, dtype=np.complex64)
        phasor.real = np.cos(phase)
        phasor.imag = np.sin(phase)
        total = np.sum((amp.astype(np.float32) * w) * phasor, axis=1, dtype=np.complex64)
        return np.asarray(total, dtype=np.complex128)

    def fast_time_grid(self, ranges: np.ndarray) -> np.ndarray:
        """Fast-time samples [s] covering every echo of the record plus the range margin."""
        c = self.config
        fs = c.sample_rate or 2.0 * c.bandwidth
        lo = 2.0 * (float(np.min(ranges)) - c.range_margin) / SPEED_OF_LIGHT - c.pulse_width / 2
        hi = 2.0 * (float(np.max(ranges)) + c.range_margin) / SPEED_OF_LIGHT + c.pulse_width / 2
        k0 = np.floor(lo * fs)
        return (k0 + np.arange(int(np.ceil(hi * fs) - k0) + 1)) / fs

    def _receive_raw(self, ranges: np.ndarray, amp: np.ndarray, gate: np.ndarray) -> Received:
        c = self.config
        fs = c.sample_rate or 2.0 * c.bandwidth
        fast = self.fast_time_grid(ranges)
        rng_axis = fast * SPEED_OF_LIGHT / 2.0
        keep = (rng_axis >= np.min(ranges) - c.range_margin) & (
            rng_axis <= np.max(ranges) + c.range_margin
        )
        n = ranges.shape[0]
        signal = np.empty(n, dtype=np.complex128)
        range_time = np.empty((n, int(keep.sum())), dtype=np.complex128)
        kw = dict(pulse_width=c.pulse_width, bandwidth=c.bandwidth)
        for lo in range(0, n, RAW_BLOCK):
            sl = slice(lo, min(lo + RAW_BLOCK, n))
            echoes = radar.raw_pulse_returns(
                ranges[sl], amp[sl], fast, carrier_frequency=c.carrier_frequency, **kw
            )
            delay = 2.0 * gate[sl] / SPEED_OF_LIGHT
            signal[sl] = radar.compress_at_delay(echoes, fast, delay, **kw) / c.pulse_width
            compressed = radar.matched_filter(echoes, fs, **kw) / c.pulse_width
            range_time[sl] = compressed[:, keep]
        return Received(signal, range_time, rng_axis[keep])
