"""LFM pulse-Doppler radar.

Two receive paths:

- ``analytic`` (default): the compressed return at the range gate in closed form (eq. 4), with the
  exact LFM matched-filter response, its large-TB sinc limit, or the phase-only limit.
- ``raw``: samples fast time, builds every scatterer's chirp echo (eq. 1-2), pulse-compresses with
  the matched filter, reads the gate at its exact delay, and returns a range-time map.

Both are normalised by the pulse width, so a lone scatterer at the gate gives its range-equation
amplitude.

``precision`` (analytic path; the raw path always computes in float64): the carrier phase is
always reduced to a fraction of a cycle in float64 from float64 ranges (large ranges keep their
Doppler), then the phasor, the gate weights, the range-equation amplitudes and the sum over
scatterers are computed in ``float32`` (the default: the accuracy ladder in ``docs/accuracy.md``
measures its cost in the spectrogram at under 0.001 dB) or ``float64`` (the reference); the
result is returned as complex128.
"""

from __future__ import annotations

import warnings
from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from mdframework import PulseBlock, RadarWaveform, Received, limits
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
        "float32",
        description="Analytic path: arithmetic after the float64 phase reduction (float32: "
        "float32 amplitudes, weights and phasors; float64: the reference). The raw path is "
        "float64.",
    )
    sample_rate: Bandwidth | None = Field(
        None, description="Raw path: fast-time sample rate [Hz]; default 2 x bandwidth."
    )
    range_margin: float = Field(
        3.0, ge=0, le=1000, description="Raw path: range-time window beyond the scatterers [m]."
    )

    def pulse_rate(self) -> float:
        """One pulse per 1/PRF [Hz]: the rate of the pulse budget."""
        return self.prf

    @model_validator(mode="after")
    def _check(self) -> LfmConfig:
        if self.bandwidth >= 2 * self.carrier_frequency:
            raise ValueError(
                f"bandwidth: {self.bandwidth:g} Hz must be below twice the carrier frequency "
                f"({self.carrier_frequency:g} Hz): the band cannot reach 0 Hz"
            )
        if self.pulse_width * self.prf > 1.0:
            raise ValueError(
                f"pulse_width: {self.pulse_width:g} s is longer than the pulse interval "
                f"1/prf ({1.0 / self.prf:g} s): shorten it or lower prf"
            )
        if self.bandwidth * self.pulse_width < 1.0:
            raise ValueError(
                f"bandwidth: bandwidth x pulse_width is {self.bandwidth * self.pulse_width:g}, "
                "below 1: a pulse-compression radar needs at least 1"
            )
        if self.sample_rate is not None and self.sample_rate < self.bandwidth:
            raise ValueError(
                f"sample_rate: {self.sample_rate:g} Hz is below the bandwidth "
                f"({self.bandwidth:g} Hz; complex sampling needs at least that)"
            )
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

    def unambiguous_range(self) -> float:
        """``c / (2 prf)`` [m]: an echo from farther arrives after the next pulse has gone out."""
        return SPEED_OF_LIGHT / (2.0 * self.config.prf)

    def start_record(self, times: np.ndarray, range_span: tuple[float, float]) -> None:
        """Fix the raw path's range-time window for the record: the joints' range span plus
        ``range_margin`` on either side. Warn, naming ``radar.prf``, when the farthest joint
        is beyond the unambiguous range ``c / (2 prf)``: its echo arrives after the next
        pulse has gone out (a real radar sees it nearer, at its range modulo that one)."""
        self._span = range_span
        prf, far = self.config.prf, range_span[1]
        unambiguous = self.unambiguous_range()
        if far > unambiguous:
            warnings.warn(
                f"radar.prf: the farthest joint at {far:.4g} m is beyond the unambiguous range "
                f"c / (2 prf) = {unambiguous:.4g} m of the {prf / 1e3:.4g} kHz PRF: its echo "
                "arrives after the next pulse has gone out, where a real radar sees it at "
                f"{far % unambiguous:.4g} m (the simulation gates it at its true range); lower "
                f"prf to at most {SPEED_OF_LIGHT / (2.0 * far) / 1e3:.4g} kHz",
                UserWarning,
                stacklevel=2,
            )

    def working_memory(self) -> dict[str, int]:
        """The raw path's fast-time arrays of :data:`RAW_BLOCK` pulses: the sampled echoes, the
        chirp's terms and the matched filter's FFTs, about four complex arrays of (fast-time
        samples + filter length) per pulse (measured with ``tracemalloc``); none on the
        analytic path."""
        c = self.config
        if c.path != "raw" or not hasattr(self, "_span"):
            return {}
        fs = c.sample_rate or 2.0 * c.bandwidth
        n_fast = self.fast_time_grid(*self._span).size
        n_filter = 2 * int(np.floor(c.pulse_width / 2.0 * fs)) + 1
        return {"fast time": 4 * RAW_BLOCK * (n_fast + n_filter) * 16}

    def receive(self, block: PulseBlock) -> Received:
        """Compressed slow-time return at the gate (and a range-time map on the raw path)."""
        c = self.config
        if c.path == "analytic":
            return Received(
                self._receive_analytic(block.ranges, block.scatterers.rcs, block.gate_range)
            )
        amp = self.amplitudes(block.ranges, block.scatterers.rcs)
        return self._receive_raw(block.ranges, amp, block.gate_range)

    def gate_gain(self, ranges: np.ndarray, gate_range: np.ndarray) -> np.ndarray:
        """Power gain of each scatterer in the range gate: the squared gate weight of the
        analytic path's response (the raw path reads the exact compressed envelope)."""
        c = self.config
        w = radar.gate_weights(
            ranges,
            gate_range,
            pulse_width=c.pulse_width,
            bandwidth=c.bandwidth,
            response=c.gate_response if c.path == "analytic" else "exact",
        )
        return np.asarray(w * w, dtype=np.float64)

    def _receive_analytic(
        self, ranges: np.ndarray, rcs: np.ndarray, gate_range: np.ndarray
    ) -> np.ndarray:
        """Eq. (4) in one pass: ``y(n) = sum_i a_i w_i exp(-j 4 pi f_c R_i / c)``, with the
        carrier phase reduced to a fraction of a cycle in float64 from float64 ranges and the
        rest (amplitude by the ``amplitude`` model, gate weight, phasor, sum) in ``precision``."""
        c = self.config
        real = np.float32 if c.precision == "float32" else np.float64
        if not np.all(ranges > 0):
            raise ValueError("ranges must be positive and finite for the range equation")
        cycles = ranges * (2.0 * c.carrier_frequency / SPEED_OF_LIGHT)
        cycles -= np.floor(cycles)  # the fraction of a cycle, in float64
        phase = cycles.astype(real, copy=False)
        phase *= real(-2.0 * np.pi)
        amp = rcs.astype(real)  # a copy: amplitudes are built in place
        if c.amplitude == "range_equation":
            lam = radar.wavelength(c.carrier_frequency)
            gain = 10.0 ** (c.gain_dbi / 10.0)
            loss = 10.0 ** ((c.system_loss_db + c.atmospheric_loss_db) / 10.0)
            amp *= real(c.transmit_power * gain**2 * lam**2 / ((4.0 * np.pi) ** 3 * loss))
        np.sqrt(amp, out=amp)
        r = ranges.astype(real, copy=False)
        if c.amplitude == "range_equation":
            amp /= r * r
        if c.gate_response != "phase_only":
            amp *= self._gate_weights(r, gate_range.astype(real, copy=False), real)
        out = np.empty(ranges.shape[0], dtype=np.complex128)
        out.real = np.einsum("ps,ps->p", amp, np.cos(phase))
        out.imag = np.einsum("ps,ps->p", amp, np.sin(phase))
        return out

    def _gate_weights(self, r: np.ndarray, gate: np.ndarray, real: type) -> np.ndarray:
        """The gate response (``radar.gate_weights``) in the given float type."""
        c = self.config
        d = gate[:, None] - r
        np.abs(d, out=d)
        d *= real(2.0 / SPEED_OF_LIGHT)
        if c.gate_response == "sinc":
            x = d * real(np.pi * c.bandwidth)
        else:  # exact: chi(D) / tau = (1 - |D|/tau) sinc(gamma |D| (tau - |D|))
            rem = real(c.pulse_width) - d
            np.maximum(rem, 0, out=rem)
            x = d * rem
            x *= real(np.pi * c.bandwidth / c.pulse_width)
            rem *= real(1.0 / c.pulse_width)
        x += real(1e-30)  # x >= 0; sin(x)/x is then exactly 1 at x = 0, unchanged elsewhere
        w = np.sin(x)
        w /= x
        if c.gate_response != "sinc":
            w *= rem
        return w

    def fast_time_grid(self, lo_range: float, hi_range: float) -> np.ndarray:
        """Fast-time samples [s] on the record's sample grid (multiples of ``1/fs``) covering
        echoes from ``lo_range`` to ``hi_range`` [m] plus the range margin and half a pulse."""
        c = self.config
        fs = c.sample_rate or 2.0 * c.bandwidth
        lo = 2.0 * (lo_range - c.range_margin) / SPEED_OF_LIGHT - c.pulse_width / 2
        hi = 2.0 * (hi_range + c.range_margin) / SPEED_OF_LIGHT + c.pulse_width / 2
        k0 = np.floor(lo * fs)
        return (k0 + np.arange(int(np.ceil(hi * fs) - k0) + 1)) / fs

    def _receive_raw(self, ranges: np.ndarray, amp: np.ndarray, gate: np.ndarray) -> Received:
        """Sampled echoes of the block on a fast-time grid covering its scatterers; the
        range-time rows are cut to the record's fixed window (``start_record``)."""
        c = self.config
        fs = c.sample_rate or 2.0 * c.bandwidth
        fast = self.fast_time_grid(float(np.min(ranges)), float(np.max(ranges)))
        lo_r, hi_r = getattr(self, "_span", (float(np.min(ranges)), float(np.max(ranges))))
        grid = self.fast_time_grid(lo_r, hi_r) * SPEED_OF_LIGHT / 2.0
        window = grid[(grid >= lo_r - c.range_margin) & (grid <= hi_r + c.range_margin)]
        # the record window's columns (same 1/fs grid) that this block's grid covers
        k_block = np.rint(fast * fs).astype(np.int64)
        k_window = np.rint(window * 2.0 / SPEED_OF_LIGHT * fs).astype(np.int64)
        n = ranges.shape[0]
        signal = np.empty(n, dtype=np.complex128)
        range_time = np.zeros((n, k_window.size), dtype=np.complex128)
        src = np.searchsorted(k_block, k_window)
        inside = (src < k_block.size) & (k_block[np.minimum(src, k_block.size - 1)] == k_window)
        kw = dict(pulse_width=c.pulse_width, bandwidth=c.bandwidth)
        for lo in range(0, n, RAW_BLOCK):
            sl = slice(lo, min(lo + RAW_BLOCK, n))
            echoes = radar.raw_pulse_returns(
                ranges[sl], amp[sl], fast, carrier_frequency=c.carrier_frequency, **kw
            )
            delay = 2.0 * gate[sl] / SPEED_OF_LIGHT
            signal[sl] = radar.compress_at_delay(echoes, fast, delay, **kw) / c.pulse_width
            compressed = radar.matched_filter(echoes, fs, **kw) / c.pulse_width
            range_time[sl, inside] = compressed[:, src[inside]]
        return Received(signal, range_time, window)
