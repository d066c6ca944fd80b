"""Chirp-sequence FMCW radar: timing, de-chirped IF, range and Doppler processing, CFAR
detection, angle estimation and point clouds. Pure functions on arrays.

Chirp model. Chirp ``n`` starts its ramp at ``t_n``; over the ramp the transmitted frequency is
``f0 + S t`` (``t`` from the ramp start). The ADC takes ``N`` complex samples at ``fs`` from
``adc_start_time``: ``t_m = adc_start_time + m / fs``. An echo with round-trip delay ``tau`` mixes
down to the de-chirped IF

    ``y(m) = a exp(-j 2 pi (f0 tau + S tau t_m - S tau^2 / 2))``                      (IF)

(stop-and-hop: ``tau`` held at its value at ``t_n``). This is the conjugate of the mixer product
``TX x RX*``, chosen so that the slow-time phase is ``-4 pi f R / c`` like every other radar of the
project: an approaching target has positive Doppler. Its beat frequency ``S tau = 2 S R / c``
therefore sits at ``-f_b``; the range profile evaluates the spectrum there,

    ``X_k = sum_m w_m y_m exp(+j 2 pi k m / K) / sum_m w_m``                           (range FFT)

with a window ``w`` and ``K >= N`` bins, so a lone target of amplitude ``a`` on a bin peaks at
``|X| = a``, range bin ``k`` is at ``k c fs / (2 S K)`` [m], and complex sampling maps beat
frequencies ``[0, fs)`` to ranges ``[0, c fs / (2 S))``: a farther target aliases (wraps) in the IF.

Frames. A frame is ``n_loops`` loops of ``n_tx`` chirps (time-division MIMO: chirp slot ``s`` of
every loop transmits on TX ``tdm_order[s]``); chirps follow each other every ``idle_time +
ramp_end_time``; frames start every ``frame_period``. Each virtual channel (TX, RX) is sampled in
slow time once per loop, so the unambiguous velocity is ``lambda / (4 n_tx T_chirp)``.

Frames of the sensor: ``x`` to the right (looking along boresight), ``y`` along boresight, ``z``
up (the convention of the TI mmWave sensors' point clouds). Antenna positions lie in the ``x-z``
plane. Directions are given by their cosines ``u_x = sin(az) cos(el)``, ``u_z = sin(el)``.

Array shapes are in each docstring: ``n_chirps`` chirps, ``n_scat`` scatterers, ``n_rx`` receive
antennas, ``n_virt = n_tx n_rx`` virtual antennas, ``n_bins`` range bins, ``n_doppler`` Doppler
bins.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from ..constants import SPEED_OF_LIGHT

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]
BoolArray = NDArray[np.bool_]
IntArray = NDArray[np.int64]

WindowName = Literal["rect", "hann", "hamming", "blackman"]
CfarMode = Literal["ca", "so", "go"]

#: Cosine-sum coefficients ``a_c`` of ``w_m = sum_c (-1)^c a_c cos(2 pi c m / N)`` (periodic).
WINDOWS: dict[str, tuple[float, ...]] = {
    "rect": (1.0,),
    "hann": (0.5, 0.5),
    "hamming": (0.54, 0.46),
    "blackman": (0.42, 0.5, 0.08),
}

#: Columns of a point cloud array (``n_points``, 7).
POINT_COLUMNS = ("frame", "t", "x", "y", "z", "v", "intensity")


# --------------------------------------------------------------------------- chirp timing


@dataclass(frozen=True)
class ChirpSequence:
    """The timing of a chirp-sequence FMCW radar (TI ``profileCfg``/``frameCfg`` terms).

    ``start_frequency`` f0 [Hz]; ``slope`` S [Hz/s]; ``idle_time``, ``adc_start_time``,
    ``ramp_end_time`` [s]; ``sample_rate`` fs [Hz] of the complex ADC; ``n_samples`` N per chirp;
    ``n_loops`` per frame; ``tdm_order``: the TX index of each chirp slot of a loop;
    ``frame_period`` [s].
    """

    start_frequency: float
    slope: float
    idle_time: float
    adc_start_time: float
    ramp_end_time: float
    sample_rate: float
    n_samples: int
    n_loops: int
    tdm_order: tuple[int, ...]
    frame_period: float

    @property
    def n_tx(self) -> int:
        """Chirps per loop (transmitters in the TDM order)."""
        return len(self.tdm_order)

    @property
    def chirp_period(self) -> float:
        """Time from one chirp's start to the next [s]: idle plus ramp."""
        return self.idle_time + self.ramp_end_time

    @property
    def loop_period(self) -> float:
        """Slow-time sample interval of one virtual channel [s]: ``n_tx`` chirp periods."""
        return self.n_tx * self.chirp_period

    @property
    def chirps_per_frame(self) -> int:
        """Chirps in one frame."""
        return self.n_loops * self.n_tx

    @property
    def frame_active_time(self) -> float:
        """From a frame's start to the end of its last ramp [s]: ``chirps_per_frame T_chirp``
        (the shortest span :func:`chirp_times` finds a frame in)."""
        return self.chirps_per_frame * self.chirp_period

    @property
    def sampled_bandwidth(self) -> float:
        """Bandwidth swept while the ADC samples [Hz]: ``S N / fs``."""
        return self.slope * self.n_samples / self.sample_rate

    @property
    def centre_frequency(self) -> float:
        """Frequency at the middle of the ADC samples [Hz]; Doppler and angles refer to it."""
        mid = self.adc_start_time + (self.n_samples - 1) / (2.0 * self.sample_rate)
        return self.start_frequency + self.slope * mid

    @property
    def wavelength(self) -> float:
        """Wavelength at :attr:`centre_frequency` [m]."""
        return SPEED_OF_LIGHT / self.centre_frequency

    @property
    def range_resolution(self) -> float:
        """``c / (2 B)`` with the sampled bandwidth [m]."""
        return SPEED_OF_LIGHT / (2.0 * self.sampled_bandwidth)

    @property
    def max_range(self) -> float:
        """Largest range whose beat frequency is below ``fs`` (complex sampling) [m]."""
        return SPEED_OF_LIGHT * self.sample_rate / (2.0 * self.slope)

    @property
    def max_velocity(self) -> float:
        """Unambiguous radial velocity of the TDM scheme, ``lambda / (4 n_tx T_chirp)`` [m/s]."""
        return self.wavelength / (4.0 * self.loop_period)

    @property
    def velocity_resolution(self) -> float:
        """``lambda / (2 n_loops n_tx T_chirp)`` [m/s]."""
        return self.wavelength / (2.0 * self.n_loops * self.loop_period)

    def problems(self, max_bandwidth: float | None = None) -> list[str]:
        """What makes this timing impossible, one line per problem naming the field and the
        limit (empty when it is consistent). ``max_bandwidth`` [Hz]: the device's sweep limit."""
        out: list[str] = []
        for name in ("slope", "sample_rate", "ramp_end_time", "frame_period"):
            if not getattr(self, name) > 0:
                out.append(f"{name} must be positive")
        for name in ("idle_time", "adc_start_time"):
            if not getattr(self, name) >= 0:
                out.append(f"{name} must be >= 0")
        if self.n_samples < 2 or self.n_loops < 1 or self.n_tx < 1:
            out.append("n_samples must be >= 2, n_loops and tdm_order must not be empty")
        if out:
            return out
        adc_end = self.adc_start_time + self.n_samples / self.sample_rate
        if adc_end > self.ramp_end_time * (1 + 1e-9):
            out.append(
                f"ramp_end_time: the ADC samples until {adc_end * 1e6:.3f} us "
                f"(adc_start_time + n_samples / sample_rate) but the ramp ends at "
                f"{self.ramp_end_time * 1e6:.3f} us: lengthen the ramp, raise sample_rate or "
                "take fewer samples"
            )
        busy = self.frame_active_time
        if busy > self.frame_period * (1 + 1e-9):
            out.append(
                f"frame_period: {self.chirps_per_frame} chirps of "
                f"{self.chirp_period * 1e6:.3f} us need {busy * 1e3:.4f} ms, more than the "
                f"frame period {self.frame_period * 1e3:.4f} ms: lengthen frame_period or use "
                "fewer loops, shorter chirps or fewer TX slots"
            )
        swept = self.slope * self.ramp_end_time
        if max_bandwidth is not None and swept > max_bandwidth * (1 + 1e-9):
            out.append(
                f"slope: slope x ramp_end_time sweeps {swept / 1e9:.4f} GHz, more than the "
                f"sensor's {max_bandwidth / 1e9:.4f} GHz max_bandwidth: lower slope or "
                "ramp_end_time"
            )
        return out


def chirp_times(seq: ChirpSequence, start: float, end: float) -> FloatArray:
    """Ramp-start times [s] of every chirp of every whole frame in ``[start, end]``.

    Frame ``f`` starts at ``start + f T_frame``; its chirp ``j`` ramps from
    ``start + f T_frame + j T_chirp + idle_time``. A frame is kept only if its last chirp's ramp
    ends by ``end``. Returns (n_frames * chirps_per_frame,) float64.
    """
    per_frame = seq.idle_time + np.arange(seq.chirps_per_frame) * seq.chirp_period
    last = per_frame[-1] + seq.ramp_end_time
    n_frames = int(np.floor((end - start - last) / seq.frame_period * (1 + 1e-12))) + 1
    n_frames = max(n_frames, 0)
    frames = start + np.arange(n_frames, dtype=np.float64) * seq.frame_period
    return np.asarray((frames[:, None] + per_frame[None, :]).ravel(), dtype=np.float64)


def beat_frequency(ranges: FloatArray | float, slope: float) -> FloatArray:
    """Beat frequency ``2 S R / c`` [Hz] of targets at ``ranges`` [m]."""
    return np.asarray(2.0 * slope * np.asarray(ranges, np.float64) / SPEED_OF_LIGHT, np.float64)


# --------------------------------------------------------------------------- windows


def window(name: WindowName, n: int) -> FloatArray:
    """Periodic cosine-sum window ``w_m = sum_c (-1)^c a_c cos(2 pi c m / n)``, (n,).

    A one-sample window is ``[1]`` whatever its name (as scipy's and the STFT's): the formula
    would give a periodic Hann ``[0]``, which would null the only sample (``n_loops = 1``: the
    Doppler FFT of one loop is the identity). Each call returns a fresh copy of a table made
    once per name and length (every frame needs the same few)."""
    return _window_table(name, n).copy()


@lru_cache(maxsize=64)
def _window_table(name: WindowName, n: int) -> FloatArray:
    """:func:`window`, computed (read-only: shared by every call)."""
    if n == 1:
        w = np.ones(1, dtype=np.float64)
    else:
        m = np.arange(n, dtype=np.float64)
        w = np.zeros(n, dtype=np.float64)
        for c, a in enumerate(WINDOWS[name]):
            w += (-1) ** c * a * np.cos(2.0 * np.pi * c * m / n)
    w.flags.writeable = False
    return w


def dirichlet(nu: FloatArray, n: int) -> ComplexArray:
    """``D_n(nu) = sum_{m=0}^{n-1} exp(j 2 pi m nu)`` in closed form (any shape of ``nu``)."""
    nu = np.asarray(nu, dtype=np.float64)
    s = np.sin(np.pi * nu)
    near = np.abs(s) < 1e-12
    ratio = np.where(near, float(n), np.sin(np.pi * n * nu) / np.where(near, 1.0, s))
    # at integer nu the sum is n; the phase factor there is (-1)^((n-1) nu) and cancels the sign
    # of the sine ratio's limit, so use the exact value n with zero phase
    phase = np.where(near, 0.0, np.pi * (n - 1) * nu)
    out = np.empty(nu.shape, dtype=np.complex128)
    out.real = ratio * np.cos(phase)
    out.imag = ratio * np.sin(phase)
    return out


def window_transform(name: WindowName, n: int, nu: FloatArray) -> ComplexArray:
    """``W(nu) = sum_m w_m exp(j 2 pi m nu)`` of :func:`window` in closed form: a sum of shifted
    Dirichlet kernels (any shape of ``nu`` [cycles per sample])."""
    nu = np.asarray(nu, dtype=np.float64)
    if n == 1:  # the one-sample window is [1] (:func:`window`)
        return np.ones(nu.shape, dtype=np.complex128)
    out = np.zeros(nu.shape, dtype=np.complex128)
    for c, a in enumerate(WINDOWS[name]):
        if c == 0:
            out += a * dirichlet(nu, n)
        else:
            out += (-1) ** c * a / 2.0 * (dirichlet(nu + c / n, n) + dirichlet(nu - c / n, n))
    return out


# --------------------------------------------------------------------------- IF and range


def _nonzero(mask: BoolArray) -> tuple[IntArray, ...]:
    """``np.nonzero`` of a many-dimensional ``mask``, the same indices in the same order, found in
    its flattened form (several times faster when few entries are set)."""
    return tuple(
        np.asarray(i, np.int64) for i in np.unravel_index(np.flatnonzero(mask), mask.shape)
    )


@dataclass(frozen=True)
class _KernelOnBins:
    """The Dirichlet kernel ``D_n(k / n - x)`` of an unpadded FFT at the integer bins ``ext``
    (n_ext,) for beat frequencies ``x`` (n_chirps, n_scat) [cycles per sample], factored as

        ``D[c, s, k] = factor[c, s] * q[k] * inv_sine[c, s, k]``

    except at the entries ``near`` (indices of chirp, scatterer and position in ``ext``, where
    ``inv_sine`` is 0), whose value divided by ``factor`` is ``near_value``. See
    :func:`_kernel_on_bins`."""

    factor: ComplexArray  # (n_chirps, n_scat)
    q: ComplexArray  # (n_ext,)
    inv_sine: FloatArray  # (n_chirps, n_scat, n_ext)
    near: tuple[IntArray, IntArray, IntArray]  # (n_near,) each
    near_value: ComplexArray  # (n_near,)

    def weighted_sum(self, weights: ComplexArray) -> ComplexArray:
        """``sum_s weights[c, i, s] D[c, s, k] / factor[c, s]`` (the weights carry the factor)
        for ``weights`` (n_chirps, m, n_scat): (n_chirps, m, n_ext). Two real matrix products
        (``q`` does not depend on the summed index), then the near entries."""
        re = np.matmul(np.ascontiguousarray(weights.real), self.inv_sine)
        out = np.empty(re.shape, dtype=np.complex128)
        out.real = re
        out.imag = np.matmul(np.ascontiguousarray(weights.imag), self.inv_sine)
        out *= self.q
        if self.near_value.size:
            chirp, scat, pos = self.near
            # a view with the bins before the channels; add.at sums repeated (chirp, bin) pairs
            by_bin = out.transpose(0, 2, 1)
            np.add.at(by_bin, (chirp, pos), weights[chirp, :, scat] * self.near_value[:, None])
        return out


def _kernel_on_bins(n: int, x: FloatArray, ext: IntArray) -> _KernelOnBins:
    """The Dirichlet kernel ``D_n(k / n - x)`` of an unpadded FFT at the integer bins ``ext``
    (n_ext,) for ``x`` (n_chirps, n_scat), factored (:class:`_KernelOnBins`) so that the
    factor of each ``x`` multiplies the scatterer's coefficient and the factor of each bin the
    sum, leaving a real matrix of inverse sines to sum over the scatterers.

    On bins, ``D_n(k/n - x) = f(x) q_k / sin(pi (k/n - x))`` with ``f(x) = -sin(pi n x)
    exp(-j pi (n-1) x)`` and ``q_k = (-1)^k exp(j pi (n-1) k / n)``; the sine of the difference
    is expanded (``sin(pi k/n) cos(pi x) - cos(pi k/n) sin(pi x)``), so the only transcendental
    functions are per bin and per ``x``. Within 1e-3 of a bin the ratio of two small sines
    taken of differently rounded arguments loses precision: there ``D`` is evaluated directly
    from ``nu = k/n - x`` (``n`` on the bin). ``x`` exactly 0 (``f`` = 0): ``D`` is ``n`` on
    bin 0 and 0 elsewhere, with ``f`` taken as 1."""
    xe = np.asarray(x, np.float64)
    arg = np.pi * xe
    f = -np.sin(n * arg) * np.exp(-1j * (n - 1) * arg)
    zero = f == 0
    f = np.where(zero, 1.0 + 0j, f)
    e_arg = np.pi * ext / n
    inv = np.multiply.outer(np.cos(arg), np.sin(e_arg))
    inv -= np.multiply.outer(np.sin(arg), np.cos(e_arg))
    near = np.abs(inv) < 1e-3
    q = np.where(ext % 2 == 0, 1.0, -1.0) * np.exp(1j * (n - 1) * e_arg)
    idx = _nonzero(near)
    inv[idx] = 1.0
    np.divide(1.0, inv, out=inv)
    inv[idx] = 0.0
    if zero.any():
        inv[zero] = 0.0
    nu = ext[idx[-1]] / n - xe[idx[:-1]]
    nu = nu - np.round(nu)  # D is periodic in nu with period 1
    s_nu = np.sin(np.pi * nu)
    on = s_nu == 0.0
    ratio = np.where(on, float(n), np.sin(np.pi * n * nu) / np.where(on, 1.0, s_nu))
    value = ratio * np.exp(1j * np.pi * (n - 1) * nu) / f[idx[:-1]]
    chirp, scat, k = idx
    return _KernelOnBins(f, q, inv, (chirp, scat, k), np.asarray(value, np.complex128))


def _window_bins(name: WindowName, n: int, bins: IntArray) -> IntArray:
    """The bins a cosine-sum window's transform at ``bins`` needs (each bin and its neighbours
    up to the window's order), sorted, (n_ext,)."""
    reach = len(WINDOWS[name]) - 1
    return _distinct_bins(bins[:, None] + np.arange(-reach, reach + 1)[None, :], n)


def _window_combine(
    name: WindowName, n: int, values: ComplexArray, ext: IntArray, bins: IntArray
) -> ComplexArray:
    """Apply a cosine-sum window to Dirichlet-kernel values on the bins ``ext`` (last axis):
    ``W(k/n - x) = sum_c (-1)^c a_c / 2 (D(k+c) + D(k-c))`` (``a_0`` once), at ``bins``."""
    coeffs = WINDOWS[name]
    out = coeffs[0] * np.take(values, np.searchsorted(ext, bins), axis=-1)
    for c in range(1, len(coeffs)):
        up = np.take(values, np.searchsorted(ext, (bins + c) % n), axis=-1)
        down = np.take(values, np.searchsorted(ext, (bins - c) % n), axis=-1)
        out += (-1) ** c * coeffs[c] / 2.0 * (up + down)
    return np.asarray(out, np.complex128)


def _if_cycles0(delays: FloatArray, seq: ChirpSequence) -> FloatArray:
    """Fractional cycles of ``f0 tau + S tau t_0 - S tau^2 / 2`` (the IF phase at the first ADC
    sample), reduced in float64."""
    tau = np.asarray(delays, dtype=np.float64)
    cyc = seq.start_frequency * tau
    cyc = cyc - np.floor(cyc)
    cyc = cyc + seq.slope * tau * seq.adc_start_time - 0.5 * seq.slope * tau * tau
    return np.asarray(cyc - np.floor(cyc), dtype=np.float64)


def if_samples(delays: FloatArray, amplitudes: FloatArray, seq: ChirpSequence) -> ComplexArray:
    """De-chirped IF samples (eq. IF of the module docstring) summed over scatterers.

    ``delays`` (n_chirps, n_scat) round-trip delays [s]; ``amplitudes`` (n_chirps, n_scat)
    [sqrt(W)]. Returns (n_chirps, n_samples) complex128 [sqrt(W)].

    The phase is linear in the sample index ``m = 16 a + b``, so each scatterer's samples are
    the products of two short tables of complex exponentials, over ``a`` (with the start phase,
    reduced in float64) and over ``b`` (0..15): one exponential per 16 samples instead of a
    cosine and a sine per sample (4x faster; within 1e-13 of the direct evaluation).
    """
    n_chirps, n_samples = delays.shape[0], seq.n_samples
    n_lo = min(16, n_samples)
    n_hi = -(-n_samples // n_lo)
    b = np.arange(n_lo, dtype=np.float64)
    a = np.arange(n_hi, dtype=np.float64) * n_lo
    out = np.zeros((n_chirps, n_hi * n_lo), dtype=np.complex128)
    cyc0 = _if_cycles0(delays, seq)
    step = seq.slope * np.asarray(delays, np.float64) / seq.sample_rate  # cycles per sample
    for i in range(delays.shape[1]):
        k = step[:, i : i + 1]
        lo = np.exp((-2j * np.pi) * (k * b))  # (n_chirps, n_lo)
        cycles = cyc0[:, i : i + 1] + k * a
        hi = amplitudes[:, i : i + 1] * np.exp((-2j * np.pi) * (cycles - np.floor(cycles)))
        out += (hi[:, :, None] * lo[:, None, :]).reshape(n_chirps, -1)
    return np.ascontiguousarray(out[:, :n_samples])


def range_profile(
    samples: ComplexArray | NDArray[np.complex64], name: WindowName, n_fft: int
) -> ComplexArray:
    """Windowed range FFT of IF samples (..., n_samples) -> (..., n_fft), normalised so that a
    lone on-bin target of amplitude ``a`` peaks at ``|X| = a`` (the range FFT of the module
    docstring; bin ``k`` is range ``k c fs / (2 S n_fft)``)."""
    n = samples.shape[-1]
    w = window(name, n)
    spec = np.fft.ifft(samples * w, n=n_fft, axis=-1)
    spec *= n_fft / float(np.sum(w))
    return np.asarray(spec, dtype=np.complex128)


def analytic_range_profile(
    delays: FloatArray,
    amplitudes: FloatArray,
    seq: ChirpSequence,
    name: WindowName,
    n_fft: int,
    bins: IntArray,
    phasors: ComplexArray | None = None,
    separate: bool = False,
) -> ComplexArray:
    """The range profile of :func:`range_profile` applied to :func:`if_samples`, in closed form
    at the bins ``bins`` (n_sel,) only: ``X_k = sum_i a_i exp(-j 2 pi c0_i) W(k / K - S tau_i /
    fs) / sum w`` (``c0`` the IF phase at the first sample, ``W`` :func:`window_transform`).
    Exact at those bins. ``delays``, ``amplitudes`` (n_chirps, n_scat). Without ``phasors``
    returns (n_chirps, n_sel); with ``phasors`` (n_chirps, n_ch, n_scat), one profile per
    channel with scatterer ``i`` multiplied by its phasor, (n_chirps, n_ch, n_sel). With
    ``separate``, each scatterer's profile alone, (n_chirps, n_scat, n_sel), each times its
    phasor when ``phasors`` (n_chirps, n_scat) are given.
    """
    c0 = _if_cycles0(delays, seq)
    x = seq.slope * delays / seq.sample_rate  # beat frequency in cycles per sample
    phase = (-2.0 * np.pi) * c0
    coef = np.empty(c0.shape, dtype=np.complex128)
    coef.real = amplitudes * np.cos(phase)
    coef.imag = amplitudes * np.sin(phase)
    scale = 1.0 / float(np.sum(window(name, seq.n_samples)))
    if separate and phasors is not None:
        coef = coef * phasors
    if n_fft == seq.n_samples:
        # the window is a combination of Dirichlet kernels on neighbouring bins, a linear map
        # that commutes with the sum over scatterers: sum first, combine the bins after
        sel = np.asarray(bins, np.int64)
        ext = _window_bins(name, seq.n_samples, sel)
        kernel = _kernel_on_bins(seq.n_samples, x, ext)
        if separate:
            each = kernel.inv_sine * kernel.q  # D / factor on the bins, (n_chirps, n_scat, n_ext)
            chirp, scat, pos = kernel.near
            each[chirp, scat, pos] = kernel.near_value
            each *= (coef * kernel.factor)[:, :, None]
            return _window_combine(name, seq.n_samples, each, ext, sel) * scale
        coef = coef * kernel.factor
        weights = coef[:, None, :] if phasors is None else phasors * coef[:, None, :]
        summed = kernel.weighted_sum(weights)
        if phasors is None:
            summed = summed[:, 0, :]
        total = _window_combine(name, seq.n_samples, summed, ext, sel)
        return np.asarray(total * scale, np.complex128)
    sel_bins = np.asarray(bins, np.float64)
    if separate:
        nu = sel_bins[None, None, :] / n_fft - x[:, :, None]
        kern = window_transform(name, seq.n_samples, nu)
        return np.asarray(coef[:, :, None] * kern * scale, np.complex128)
    weights = coef if phasors is None else phasors * coef[:, None, :]
    out = np.empty((*weights.shape[:-1], sel_bins.size), dtype=np.complex128)
    # the kernel (n_chirps, n_scat, bins) a block of bins at a time: every bin of a 65536-point
    # FFT (a wide analytic_margin) for every chirp and scatterer would take gigabytes
    step = max(1, _KERNEL_CELLS // max(1, x.size))
    for lo in range(0, sel_bins.size, step):
        nu = sel_bins[None, None, lo : lo + step] / n_fft - x[:, :, None]
        kern = window_transform(name, seq.n_samples, nu)
        if phasors is None:
            out[..., lo : lo + step] = np.einsum("cs,csk->ck", weights, kern)
        else:
            out[..., lo : lo + step] = np.einsum("crs,csk->crk", weights, kern)
    out *= scale
    return out


#: most values of the kernel of :func:`analytic_range_profile` computed at once (64 MiB)
_KERNEL_CELLS = 2**22


def range_axis(seq: ChirpSequence, n_fft: int) -> FloatArray:
    """Range of each range bin [m], (n_fft,): ``k c fs / (2 S n_fft)``."""
    return np.arange(n_fft, dtype=np.float64) * seq.max_range / n_fft


def bins_near(ranges: FloatArray, seq: ChirpSequence, n_fft: int, margin: int) -> IntArray:
    """Range bins within ``margin`` bins of any of ``ranges`` [m] (after IF aliasing), sorted."""
    pos = np.mod(np.asarray(ranges, np.float64).ravel() / seq.max_range * n_fft, n_fft)
    base = np.floor(pos).astype(np.int64)
    return _bins_around(base, -margin, margin + 1, n_fft)


def _bins_around(base: IntArray, lo: int, hi: int, n: int) -> IntArray:
    """The distinct values of ``(base + d) % n`` for every ``d`` in ``lo..hi``, sorted: each
    base's run of bins marked as an interval, so that memory grows with ``base`` and ``n``, not
    with ``hi - lo`` (a margin of 65536 bins around thousands of ranges)."""
    width = hi - lo + 1
    if width >= n:
        return np.arange(n, dtype=np.int64)
    start = np.mod(base + lo, n)
    end = start + width  # exclusive; past n the run wraps to bin 0
    wrapped = end[end > n] - n
    edges = np.bincount(start, minlength=n + 1) - np.bincount(np.minimum(end, n), minlength=n + 1)
    edges[0] += wrapped.size
    edges -= np.bincount(wrapped, minlength=n + 1)
    return np.flatnonzero(np.cumsum(edges[:n]) > 0).astype(np.int64)


def _distinct_bins(bins: IntArray, n: int) -> IntArray:
    """The distinct values of ``bins % n``, sorted (like ``np.unique``, by marking them in a
    table of the ``n`` bins instead of sorting)."""
    mark = np.zeros(n, dtype=np.bool_)
    mark[np.mod(bins, n).ravel()] = True
    return np.flatnonzero(mark).astype(np.int64)


# --------------------------------------------------------------------------- Doppler


def doppler_axis(seq: ChirpSequence, n_doppler: int) -> FloatArray:
    """Doppler of each bin of :func:`range_doppler` [Hz], ascending, (n_doppler,):
    ``(d - (n - 1) // 2) / (n T_loop)``; positive = approaching. With an even ``n`` the bin at
    ``n/2`` (``+-1 / (2 T_loop)``, approaching and receding alike) is read as approaching, last:
    the axis is TI's range-rate axis (``-n/2 .. n/2 - 1`` bins, positive receding) negated, so
    simulated points and a TI sensor's negated points fall on the same velocities."""
    k = np.arange(-((n_doppler - 1) // 2), n_doppler - (n_doppler - 1) // 2, dtype=np.float64)
    return np.asarray(k / (n_doppler * seq.loop_period), np.float64)


def doppler_order(spectrum: NDArray[Any], axis: int) -> NDArray[Any]:
    """An FFT's bins along ``axis`` (``n`` of them, in FFT order) in the ascending order of
    :func:`doppler_axis`: zero Doppler at index ``(n - 1) // 2``."""
    n = spectrum.shape[axis]
    return np.roll(spectrum, (n - 1) // 2, axis=axis)


def virtual_cube(profiles: ComplexArray, seq: ChirpSequence, n_tx_total: int) -> ComplexArray:
    """Rearrange one frame's range profiles into the virtual-array cube.

    ``profiles`` (chirps_per_frame, n_rx, n_bins), chirps in time order. Returns
    (n_tx_total * n_rx, n_loops, n_bins): virtual antenna ``tx * n_rx + rx`` (by TX index, not
    slot); TXs that the TDM order never uses stay zero.
    """
    n_rx, n_bins = profiles.shape[1], profiles.shape[2]
    by_slot = profiles.reshape(seq.n_loops, seq.n_tx, n_rx, n_bins)
    cube = np.zeros((n_tx_total, n_rx, seq.n_loops, n_bins), dtype=np.complex128)
    for slot, tx in enumerate(seq.tdm_order):
        cube[tx] = np.moveaxis(by_slot[:, slot], 0, 1)
    return cube.reshape(n_tx_total * n_rx, seq.n_loops, n_bins)


def range_doppler(
    cube: ComplexArray, name: WindowName, n_doppler: int, clutter_removal: bool = False
) -> ComplexArray:
    """Doppler FFT over loops: (n_virt, n_loops, n_bins) -> (n_virt, n_doppler, n_bins),
    rows in the order of :func:`doppler_axis` (zero Doppler at ``(n_doppler - 1) // 2``),
    normalised so that a lone on-bin target of amplitude ``a`` peaks at ``a``.
    ``clutter_removal`` subtracts each channel's and bin's mean over the loops first (static
    clutter removal)."""
    x = cube - cube.mean(axis=1, keepdims=True) if clutter_removal else cube
    w = window(name, cube.shape[1])
    spec = np.fft.fft(x * w[None, :, None], n=n_doppler, axis=1)
    # numpy divides a complex by a real as a complex by ``(s, 0)``, which for finite values is
    # the product with ``1 / s``: the same values, several times faster
    spec *= 1.0 / float(np.sum(w))
    return np.asarray(doppler_order(spec, 1), dtype=np.complex128)


def detection_map(rd: ComplexArray) -> FloatArray:
    """Non-coherent sum of ``|RD|^2`` over virtual antennas, (n_doppler, n_bins) [W]."""
    return np.asarray(np.sum(rd.real**2 + rd.imag**2, axis=0), dtype=np.float64)


# --------------------------------------------------------------------------- detection


@dataclass(frozen=True)
class Cfar:
    """One-dimensional CFAR along an axis: ``mode`` ca (cell averaging), so (smallest of the
    two sides' means), go (greatest of); ``train`` and ``guard`` cells on each side; a cell is
    detected when its power exceeds ``10^(threshold_db / 10)`` times the noise estimate."""

    mode: CfarMode = "ca"
    train: int = 8
    guard: int = 4
    threshold_db: float = 15.0


def cfar(
    power: FloatArray, settings: Cfar, *, axis: int, cyclic: bool
) -> tuple[BoolArray, FloatArray]:
    """CFAR detection of ``power`` (any shape, linear) along ``axis``.

    ``cyclic``: the axis wraps (Doppler); otherwise a cell near an edge uses only the training
    cells that exist (one side only at the very edge). Returns the detections (bool, same shape)
    and the noise estimate (same shape, linear; NaN where no training cell exists).
    """
    x = np.moveaxis(np.asarray(power, np.float64), axis, -1)
    n = x.shape[-1]
    g, t = settings.guard, settings.train
    pad = g + t
    ones = np.ones(n)
    if cyclic:
        xp = np.concatenate([x[..., n - pad :], x, x[..., :pad]], axis=-1) if pad <= n else None
        cp = np.concatenate([ones[n - pad :], ones, ones[:pad]]) if pad <= n else None
        if xp is None or cp is None:
            idx = np.arange(-pad, n + pad) % n
            xp, cp = x[..., idx], ones[idx]
    else:
        zeros = np.zeros((*x.shape[:-1], pad))
        xp = np.concatenate([zeros, x, zeros], axis=-1)
        cp = np.concatenate([np.zeros(pad), ones, np.zeros(pad)])
    cs = np.concatenate([np.zeros((*x.shape[:-1], 1)), np.cumsum(xp, axis=-1)], axis=-1)
    cc = np.concatenate([[0.0], np.cumsum(cp)])

    # cell j sits at pad + j in the padded arrays: its training sums as differences of
    # cumulative sums, each a slice of n
    def at(a: FloatArray, offset: int) -> FloatArray:
        return a[..., pad + offset : pad + offset + n]

    left_sum = at(cs, -g) - at(cs, -g - t)
    right_sum = at(cs, g + t + 1) - at(cs, g + 1)
    left_n = at(cc, -g) - at(cc, -g - t)
    right_n = at(cc, g + t + 1) - at(cc, g + 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        left = np.where(left_n > 0, left_sum / np.maximum(left_n, 1), np.nan)
        right = np.where(right_n > 0, right_sum / np.maximum(right_n, 1), np.nan)
        if settings.mode == "ca":
            total = left_n + right_n
            noise = np.where(total > 0, (left_sum + right_sum) / np.maximum(total, 1), np.nan)
        elif settings.mode == "so":
            noise = np.where(
                np.isnan(left), right, np.where(np.isnan(right), left, np.minimum(left, right))
            )
        elif settings.mode == "go":
            noise = np.where(
                np.isnan(left), right, np.where(np.isnan(right), left, np.maximum(left, right))
            )
        else:
            raise ValueError(f"unknown CFAR mode {settings.mode!r}")
        alpha = 10.0 ** (settings.threshold_db / 10.0)
        detected = np.where(np.isnan(noise), False, x > alpha * np.nan_to_num(noise))
    return np.moveaxis(detected, -1, axis), np.moveaxis(noise, -1, axis)


def peak_grouping(power: FloatArray, mask: BoolArray, *, doppler: bool, range_: bool) -> BoolArray:
    """Keep a detection of a (n_doppler, n_bins) map only where its power is at least that of
    its neighbours along Doppler (cyclic) and/or range (TI's peak grouping)."""
    keep = mask.copy()
    if doppler:
        keep &= (power >= np.roll(power, 1, axis=0)) & (power >= np.roll(power, -1, axis=0))
    if range_:
        left = np.concatenate([np.full((power.shape[0], 1), -np.inf), power[:, :-1]], axis=1)
        right = np.concatenate([power[:, 1:], np.full((power.shape[0], 1), -np.inf)], axis=1)
        keep &= (power >= left) & (power >= right)
    return keep


# --------------------------------------------------------------------------- angles


def virtual_positions(tx: FloatArray, rx: FloatArray) -> FloatArray:
    """Virtual antenna positions ``p_tx + p_rx``, (n_tx * n_rx, 2) as (x, z) [m], virtual index
    ``tx * n_rx + rx``. ``tx`` (n_tx, 2), ``rx`` (n_rx, 2) [m] in the sensor's x-z plane."""
    return np.asarray((tx[:, None, :] + rx[None, :, :]).reshape(-1, 2), dtype=np.float64)


def steering(
    positions: FloatArray, ux: FloatArray, uz: FloatArray, wavelength: float
) -> ComplexArray:
    """Steering vectors ``exp(+j 2 pi (x u_x + z u_z) / lambda)`` for directions (n_dir,),
    (n_dir, n_virt): a path shorter by ``p . u`` on the way out and back advances the phase."""
    arg = (2.0 * np.pi / wavelength) * (
        np.outer(ux, positions[:, 0]) + np.outer(uz, positions[:, 1])
    )
    return np.asarray(np.exp(1j * arg), dtype=np.complex128)


@dataclass(frozen=True)
class AngleGrid:
    """A beam-scan grid of direction cosines: ``ux`` (n_x,), ``uz`` (n_z,) (``uz = [0]`` for
    an array without vertical extent) and the conjugated steering vectors of the visible ones,
    ``weights`` (n_virt, n_visible) (contiguous, for one matrix product per frame), with their
    grid indices ``ix``, ``iz`` (n_visible,)."""

    ux: FloatArray
    uz: FloatArray
    weights: ComplexArray
    ix: IntArray
    iz: IntArray


def angle_grid(positions: FloatArray, wavelength: float, n_x: int = 65, n_z: int = 33) -> AngleGrid:
    """The beam-scan grid for an array: ``u_x`` over [-1, 1] in ``n_x`` steps, ``u_z`` likewise
    when the array has vertical extent (else only 0); directions with ``u_x^2 + u_z^2 > 1`` are
    left out."""
    ux = np.linspace(-1.0, 1.0, n_x)
    has_z = np.ptp(positions[:, 1]) > 1e-9 * max(1.0, float(np.ptp(positions[:, 0])))
    uz = np.linspace(-1.0, 1.0, n_z) if has_z else np.zeros(1)
    gx, gz = np.meshgrid(np.arange(ux.size), np.arange(uz.size), indexing="ij")
    visible = ux[gx] ** 2 + uz[gz] ** 2 <= 1.0 + 1e-12
    ix, iz = gx[visible].astype(np.int64), gz[visible].astype(np.int64)
    weights = np.ascontiguousarray(steering(positions, ux[ix], uz[iz], wavelength).conj().T)
    return AngleGrid(ux, uz, weights, ix, iz)


def _refine(
    maps: FloatArray, d: IntArray, i: IntArray, k: IntArray, axis: FloatArray, along: int
) -> FloatArray:
    """Parabolic interpolation of peaks ``maps[d, i, k]`` along grid axis ``along`` (1: u_x,
    2: u_z) on the grid ``axis``; a peak at the grid's edge or beside a non-visible direction
    stays on its grid point."""
    idx = i if along == 1 else k
    n = maps.shape[along]
    out = axis[idx].astype(np.float64)
    if n < 3:
        return out
    lo, hi = np.clip(idx - 1, 0, n - 1), np.clip(idx + 1, 0, n - 1)
    if along == 1:
        a, b, c = maps[d, lo, k], maps[d, i, k], maps[d, hi, k]
    else:
        a, b, c = maps[d, i, lo], maps[d, i, k], maps[d, i, hi]
    ok = (idx > 0) & (idx < n - 1) & np.isfinite(a) & np.isfinite(c)
    with np.errstate(invalid="ignore", divide="ignore"):
        den = np.where(ok, a - 2 * b + c, -1.0)
        off = np.where(ok & (den < 0), 0.5 * (np.where(ok, a - c, 0.0)) / den, 0.0)
    return np.asarray(out + np.clip(off, -0.5, 0.5) * (axis[1] - axis[0] if n > 1 else 0.0))


def _second_peaks(maps: FloatArray, best: IntArray, fraction: float) -> tuple[IntArray, IntArray]:
    """For each beam map of ``maps`` (n_det, n_x, n_z) (``-inf`` off the visible grid) whose
    strongest cell is ``best`` (n_det,) (flat index), its strongest other local maximum (at
    least its 8 neighbours) of at least ``fraction`` of that cell's power, if any: the
    detections that have one and its flat index, (n_found,) each. Ties go to the lower flat
    index. Only cells inside the visible region count: a cell with a neighbour off the grid or
    not visible (``u_x^2 + u_z^2 > 1``) is on its edge, where a beam map may still rise toward
    a lobe at directions that do not exist (beyond +-90 deg), so it is no target. (An array
    without vertical extent has one ``u_z`` row, and only ``u_x`` has edges.) Only the cells
    above the threshold are tested, not the whole map."""
    n_det, n_x, n_z = maps.shape
    peak = maps.reshape(n_det, n_x * n_z)[np.arange(n_det), best]
    with np.errstate(invalid="ignore"):  # 0 x an overflowed peak: NaN, no cell above it
        d, i, k = _nonzero(maps >= (fraction * peak)[:, None, None])
    value = maps[d, i, k]
    inner = np.isfinite(value) & (i > 0) & (i < n_x - 1)
    if n_z > 1:
        inner &= (k > 0) & (k < n_z - 1)
    d, index, value = d[inner], (i * n_z + k)[inner], value[inner]
    # each neighbour in turn, on the cells that passed the ones before (most fail the first
    # two, along u_x); an array without vertical extent has no neighbours along u_z
    flat = maps.reshape(-1)
    for di, dk in ((-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (-1, 1), (1, -1), (1, 1)):
        if dk and n_z == 1:
            continue
        other = flat[d * (n_x * n_z) + index + (di * n_z + dk)]
        keep = np.isfinite(other) & (value >= other)
        d, index, value = d[keep], index[keep], value[keep]
    keep = index != best[d]
    d, index, value = d[keep], index[keep], value[keep]
    order = np.lexsort((-value, d))  # by detection, strongest first; stable: lower index first
    d, index = d[order], index[order]
    first = np.ones(d.size, dtype=np.bool_)
    first[1:] = d[1:] != d[:-1]
    return d[first].astype(np.int64), index[first].astype(np.int64)


#: Detections whose beam maps :func:`estimate_angles` makes at once (64 x 2145 directions
#: of the three-TX array's grid: 1 MiB a map array).
ANGLE_CHUNK = 64


def estimate_angles(
    snapshots: ComplexArray, grid: AngleGrid, multi_peak: float | None = None
) -> tuple[IntArray, FloatArray, FloatArray, FloatArray]:
    """Bartlett beam scan of each detection's virtual-array snapshot.

    ``snapshots`` (n_det, n_virt). For each detection the direction of the beam map's maximum,
    refined by parabolic interpolation along ``u_x`` and ``u_z``; with ``multi_peak`` (0..1),
    also the strongest other local maximum of at least that fraction of the maximum (TI's
    multi-object beamforming). Returns the detection index of each direction (n_out,), its
    ``u_x``, ``u_z`` (n_out,) and beam power (n_out,) [|snapshot|^2 units x n_virt].
    """
    n_det = snapshots.shape[0]
    if n_det == 0:
        e = np.zeros(0)
        return np.zeros(0, np.int64), e, e.copy(), e.copy()
    if n_det > ANGLE_CHUNK:  # each detection alone: chunks keep the beam maps in the cache
        parts = [
            estimate_angles(snapshots[lo : lo + ANGLE_CHUNK], grid, multi_peak)
            for lo in range(0, n_det, ANGLE_CHUNK)
        ]
        starts = range(0, n_det, ANGLE_CHUNK)
        det = np.concatenate([p[0] + lo for p, lo in zip(parts, starts, strict=True)])
        ux_all, uz_all, power = (np.concatenate([p[j] for p in parts]) for j in (1, 2, 3))
        return det.astype(np.int64), ux_all, uz_all, power
    product = snapshots @ grid.weights
    beams = (product.real**2 + product.imag**2) / snapshots.shape[1]
    maps = np.full((n_det, grid.ux.size, grid.uz.size), -np.inf)
    maps.reshape(n_det, -1)[:, grid.ix * grid.uz.size + grid.iz] = beams
    flat = maps.reshape(n_det, -1)
    det = np.arange(n_det)
    best = np.argmax(flat, axis=1)
    if multi_peak is not None:
        d2, second = _second_peaks(maps, best, multi_peak)
        det = np.concatenate([det, d2])
        best = np.concatenate([best, second])
        order = np.argsort(det, kind="stable")
        det, best = det[order], best[order]
    i, k = np.divmod(best, grid.uz.size)
    ux = _refine(maps, det, i, k, grid.ux, 1)
    uz = _refine(maps, det, i, k, grid.uz, 2) if grid.uz.size > 1 else np.zeros(det.size)
    return det.astype(np.int64), ux, uz, flat[det, best]


def tdm_compensation(
    snapshots: ComplexArray, doppler: FloatArray, slot_of_virtual: IntArray, chirp_period: float
) -> ComplexArray:
    """Remove the phase a moving target gains between the TDM slots of one loop:
    multiply virtual antenna ``v`` by ``exp(-j 2 pi f_D s_v T_chirp)``, ``s_v`` its TX's slot.
    ``snapshots`` (n_det, n_virt), ``doppler`` (n_det,) [Hz], ``slot_of_virtual`` (n_virt,)."""
    phase = -2.0 * np.pi * np.outer(doppler, slot_of_virtual) * chirp_period
    return np.asarray(snapshots * np.exp(1j * phase), dtype=np.complex128)


# --------------------------------------------------------------------------- point clouds


@dataclass(frozen=True)
class Detection:
    """Detection settings of :func:`detect_points`: CFAR along range and/or Doppler (both must
    detect a cell when both are given), peak grouping along Doppler and/or range, the range
    interval searched ``[min_range, max_range]`` [m], multi-object beamforming threshold (or
    None), velocity-induced TDM phase compensation, and ``noise_floor`` [W in the detection
    map]: the mean receiver noise added to the map before CFAR (:func:`map_noise_power`, for a
    simulation without receiver noise, whose training cells hold only window sidelobes or
    nothing; 0: none)."""

    cfar_range: Cfar | None = Cfar("so", 8, 4, 15.0)
    cfar_doppler: Cfar | None = None
    group_doppler: bool = True
    group_range: bool = False
    min_range: float = 0.1
    max_range: float = float("inf")
    multi_peak: float | None = 0.5
    tdm_compensation: bool = True
    noise_floor: float = 0.0


def map_noise_power(
    noise_power: float,
    n_virt: int,
    range_window: WindowName,
    n_samples: int,
    doppler_window: WindowName,
    n_loops: int,
) -> float:
    """Mean power [W] of complex white IF noise of ``noise_power`` [W per ADC sample] in one cell
    of the :func:`detection_map`: ``n_virt`` antennas, each through the range and the Doppler
    FFTs normalised by their window sums, ``n_virt P_n (sum w_r^2 / (sum w_r)^2)
    (sum w_d^2 / (sum w_d)^2)`` (zero-padding does not change it)."""
    wr, wd = window(range_window, n_samples), window(doppler_window, n_loops)
    gain_r = float(np.sum(wr**2) / np.sum(wr) ** 2)
    gain_d = float(np.sum(wd**2) / np.sum(wd) ** 2)
    return n_virt * noise_power * gain_r * gain_d


def detect_points(
    rd: ComplexArray,
    ranges: FloatArray,
    doppler: FloatArray,
    grid: AngleGrid,
    slot_of_virtual: IntArray,
    chirp_period: float,
    wavelength: float,
    settings: Detection,
) -> FloatArray:
    """One frame's point cloud from its range-Doppler cube.

    ``rd`` (n_virt, n_doppler, n_bins) complex from :func:`range_doppler`; ``ranges`` (n_bins,)
    [m]; ``doppler`` (n_doppler,) [Hz]. CFAR on the :func:`detection_map`, peak grouping, angle
    estimation of each detected cell. Returns (n_points, 5) float64: ``x, y, z`` [m] in the
    sensor frame, radial velocity ``v`` [m/s] (positive approaching) and intensity [dB]: the
    cell's power over its CFAR noise estimate (the range CFAR's, else the Doppler CFAR's;
    without CFAR, the cell's power in dB re 1 W). A cell without power is never a detection.
    With ``settings.noise_floor`` P_n > 0 (a noise-free simulation, whose training cells hold
    only window sidelobes or nothing) CFAR and intensity work on the map plus P_n, the mean
    of what a receiver with that noise would measure in each cell: a lone target then stands
    at ``1 + SNR`` over its estimate, as with noise. A noise estimate of 0 (no floor) counts as
    the smallest positive float, so the intensity stays finite.
    """
    power = detection_map(rd)
    mask = power > 0
    level = power + settings.noise_floor if settings.noise_floor > 0 else power
    noise = np.full(power.shape, np.nan)
    if settings.cfar_doppler is not None:
        det, noise = cfar(level, settings.cfar_doppler, axis=0, cyclic=True)
        mask &= det
    if settings.cfar_range is not None:
        det, noise = cfar(level, settings.cfar_range, axis=1, cyclic=False)
        mask &= det
    mask &= ((ranges >= settings.min_range) & (ranges <= settings.max_range))[None, :]
    mask = peak_grouping(power, mask, doppler=settings.group_doppler, range_=settings.group_range)
    di, ri = _nonzero(mask)
    snaps = np.ascontiguousarray(rd[:, di, ri].T)
    fd = doppler[di]
    if settings.tdm_compensation:
        snaps = tdm_compensation(snaps, fd, slot_of_virtual, chirp_period)
    which, ux, uz, _ = estimate_angles(snaps, grid, settings.multi_peak)
    r = ranges[ri][which]
    uy = np.sqrt(np.clip(1.0 - ux**2 - uz**2, 0.0, None))
    v = fd[which] * wavelength / 2.0
    ref = np.maximum(np.nan_to_num(noise[di, ri], nan=1.0), np.finfo(np.float64).tiny)
    snr = 10.0 * (np.log10(level[di, ri]) - np.log10(ref))[which]
    return np.column_stack([r * ux, r * uy, r * uz, v, snr]).astype(np.float64)


# --------------------------------------------------------------------------- geometry


def sensor_axes(azimuth: float, elevation: float) -> FloatArray:
    """Rows ``x_s`` (right), ``y_s`` (boresight), ``z_s`` (up) of a sensor whose boresight points
    at ``azimuth`` (from +x toward +y) and ``elevation`` (up) [rad], in the scene frame (z up).
    (3, 3) float64, orthonormal and right-handed."""
    ca, sa, ce, se = np.cos(azimuth), np.sin(azimuth), np.cos(elevation), np.sin(elevation)
    y = np.array([ce * ca, ce * sa, se])
    x = np.array([sa, -ca, 0.0])
    z = np.cross(x, y)
    return np.asarray(np.stack([x, y, z]), dtype=np.float64)


def antenna_positions(
    offsets: FloatArray, radar_position: FloatArray, axes: FloatArray
) -> FloatArray:
    """Scene positions [m] of antennas at sensor-plane ``offsets`` (n, 2) as (x, z) [m], (n, 3)."""
    return np.asarray(
        radar_position[None, :] + offsets[:, :1] * axes[0] + offsets[:, 1:2] * axes[2],
        dtype=np.float64,
    )


def channel_delays(
    positions: FloatArray, tx_position: FloatArray, rx_positions: FloatArray
) -> FloatArray:
    """Round-trip delays [s] TX -> scatterer -> each RX, exact (spherical).

    ``positions`` (n, n_scat, 3); ``tx_position`` (n, 3) per chirp; ``rx_positions`` (n_rx, 3).
    Returns (n, n_rx, n_scat)."""
    out_leg = np.linalg.norm(positions - tx_position[:, None, :], axis=-1)
    back = np.linalg.norm(positions[:, None, :, :] - rx_positions[None, :, None, :], axis=-1)
    return np.asarray((out_leg[:, None, :] + back) / SPEED_OF_LIGHT, dtype=np.float64)


def split_frames(n_chirps: int, seq: ChirpSequence) -> int:
    """Number of whole frames in ``n_chirps`` chirps; ``ValueError`` when it is not whole."""
    if n_chirps % seq.chirps_per_frame:
        raise ValueError(
            f"{n_chirps} chirps are not a whole number of frames of {seq.chirps_per_frame}"
        )
    return n_chirps // seq.chirps_per_frame


def as_points(frames: Sequence[tuple[int, float, FloatArray]]) -> FloatArray:
    """Stack per-frame points (frame index, frame time [s], (n, 5) array) into the point-cloud
    array (n_points, 7) with columns :data:`POINT_COLUMNS`."""
    rows = [
        np.column_stack([np.full(len(p), f, np.float64), np.full(len(p), t), p])
        for f, t, p in frames
        if len(p)
    ]
    return np.concatenate(rows) if rows else np.zeros((0, len(POINT_COLUMNS)))


# --------------------------------------------------------------------------- a block of chirps


@dataclass(frozen=True)
class Antennas:
    """Antenna offsets in the sensor's x-z plane [m]: ``tx`` (n_tx, 2), ``rx`` (n_rx, 2)."""

    tx: FloatArray
    rx: FloatArray

    def centred(self) -> Antennas:
        """The same array moved so that its virtual array is centred on the sensor's position
        (the TX and the RX offsets each centred on their mean)."""
        return Antennas(self.tx - self.tx.mean(axis=0), self.rx - self.rx.mean(axis=0))

    @property
    def virtual(self) -> FloatArray:
        """Virtual antenna positions, (n_tx * n_rx, 2) [m] (:func:`virtual_positions`)."""
        return virtual_positions(self.tx, self.rx)

    def slot_of_virtual(self, seq: ChirpSequence) -> IntArray:
        """The TDM slot of each virtual antenna's TX (n_virt,); -1 for a TX never used."""
        slot = np.full(self.tx.shape[0], -1, dtype=np.int64)
        for s, tx in enumerate(seq.tdm_order):
            slot[tx] = s
        return np.repeat(slot, self.rx.shape[0])

    def used_virtual(self, seq: ChirpSequence) -> IntArray:
        """Indices (n_used,) of the virtual antennas whose TX the TDM order uses: only these
        hold signal (:func:`virtual_cube` leaves the others zero), so only these may take part
        in the angle estimation (a zero channel beside real ones distorts every beam)."""
        return np.flatnonzero(self.slot_of_virtual(seq) >= 0).astype(np.int64)


def chirp_profiles(
    positions: FloatArray,
    amplitudes: FloatArray,
    radar_position: FloatArray,
    axes: FloatArray,
    seq: ChirpSequence,
    antennas: Antennas,
    *,
    window_name: WindowName,
    n_fft: int,
    path: Literal["raw", "analytic"],
    margin: int = 8,
    extra_ranges: FloatArray | None = None,
    noise: ComplexArray | NDArray[np.complex64] | None = None,
) -> ComplexArray:
    """Range profiles of every chirp and receive antenna, (n_chirps, n_rx, n_fft) complex128.

    ``positions`` (n_chirps, n_scat, 3) [m] scene frame at each chirp (the first chirp is slot 0
    of a loop); ``amplitudes`` (n_chirps, n_scat) [sqrt(W)]; ``axes`` from :func:`sensor_axes`.

    ``raw``: exact spherical delays TX -> scatterer -> each RX, IF samples (:func:`if_samples`)
    and the range FFT. ``analytic``: the closed-form profile (:func:`analytic_range_profile`)
    at the bins within ``margin`` of the scatterers (and of ``extra_ranges`` [m]), with the
    far-field delay to the chirp's TX and the receive array's centre
    ``(2 R - (p_tx + p_rx_mean) . u) / c``, times the far-field phase of each RX's offset from
    that centre ``exp(+j 2 pi f_c (p_rx - p_rx_mean) . u / c)``; other bins are 0 (the dropped
    window sidelobes).
    ``noise`` (n_chirps, n_rx, n_samples) complex128 or complex64: IF noise added before the
    range FFT (both paths).
    """
    n = positions.shape[0]
    n_rx = antennas.rx.shape[0]
    if path == "raw":
        tx_pos = antenna_positions(antennas.tx, radar_position, axes)[_chirp_tx(seq, n)]
        rx_pos = antenna_positions(antennas.rx, radar_position, axes)
        delays = channel_delays(positions, tx_pos, rx_pos)
        samples = np.empty((n, n_rx, seq.n_samples), dtype=np.complex128)
        for r in range(n_rx):
            samples[:, r] = if_samples(delays[:, r], amplitudes, seq)
        if noise is not None:
            samples += noise
        return range_profile(samples, window_name, n_fft)
    dist, delays, phasors = _far_field(positions, radar_position, axes, seq, antennas)
    near = (
        np.concatenate([dist.ravel(), np.asarray(extra_ranges, np.float64).ravel()])
        if extra_ranges is not None
        else dist
    )
    bins = bins_near(near, seq, n_fft, margin)
    # the noise's profile first (a fresh array), the scatterers' bins added to it
    out = (
        range_profile(noise, window_name, n_fft)
        if noise is not None
        else np.zeros((n, n_rx, n_fft), dtype=np.complex128)
    )
    out[:, :, bins] += analytic_range_profile(
        delays, amplitudes, seq, window_name, n_fft, bins, phasors
    )
    return out


def _chirp_tx(seq: ChirpSequence, n: int) -> IntArray:
    """The TX of each of ``n`` chirps from a loop's first, (n,) int64 (the TDM order)."""
    return np.asarray(seq.tdm_order, dtype=np.int64)[np.arange(n) % seq.n_tx]


def _far_field(
    positions: FloatArray,
    radar_position: FloatArray,
    axes: FloatArray,
    seq: ChirpSequence,
    antennas: Antennas,
) -> tuple[FloatArray, FloatArray, ComplexArray]:
    """The analytic path's geometry: ranges (n_chirps, n_scat) [m], delays (n_chirps, n_scat)
    [s] to the chirp's TX (:func:`_chirp_tx`) and the receive array's centre, and each RX's
    phasor (n_chirps, n_rx, n_scat) (:func:`chirp_profiles`)."""
    tx_index = _chirp_tx(seq, positions.shape[0])
    rel = positions - radar_position[None, None, :]
    dist = np.sqrt(np.sum(rel * rel, axis=-1))
    u = rel / dist[..., None]
    ux, uz = u @ axes[0], u @ axes[2]
    # envelope: the delay to the chirp's TX and the receive array's centre (far field);
    # phase: each RX's offset from that centre, at the centre frequency
    centre = antennas.tx[tx_index] + antennas.rx.mean(axis=0)[None, :]  # (n, 2)
    delays = (2.0 * dist - (centre[:, 0:1] * ux + centre[:, 1:2] * uz)) / SPEED_OF_LIGHT
    off = antennas.rx - antennas.rx.mean(axis=0)[None, :]  # (n_rx, 2)
    arg = (2.0 * np.pi * seq.centre_frequency / SPEED_OF_LIGHT) * (
        off[None, :, 0:1] * ux[:, None, :] + off[None, :, 1:2] * uz[:, None, :]
    )
    return dist, delays, np.exp(1j * arg)


def gate_responses(
    positions: FloatArray,
    amplitudes: FloatArray,
    radar_position: FloatArray,
    axes: FloatArray,
    seq: ChirpSequence,
    antennas: Antennas,
    gate_range: FloatArray,
    width: float,
    *,
    window_name: WindowName,
    n_fft: int,
) -> ComplexArray:
    """Each scatterer's slow-time signal alone on the analytic path, (n_scat, n_chirps)
    complex128 [sqrt(W)]: :func:`gate_signal` of the :func:`chirp_profiles` of a lone
    scatterer (no noise), for all scatterers at once. Only the gate's bins are computed, the
    ones the gate signal sums. Arguments as for :func:`chirp_profiles` and
    :func:`gate_signal`."""
    _, delays, phasors = _far_field(positions, radar_position, axes, seq, antennas)
    raxis = range_axis(seq, n_fft)
    weights = gate_weights(raxis, gate_range, width, window_name, seq.n_samples)
    bins = np.flatnonzero(np.any(weights != 0, axis=0))
    each = analytic_range_profile(
        delays, amplitudes, seq, window_name, n_fft, bins, phasors[:, 0, :], separate=True
    )  # (n_chirps, n_scat, n_bins)
    return np.asarray(np.einsum("csk,ck->sc", each, weights[:, bins]), np.complex128)


def gate_signal(
    profiles: ComplexArray,
    ranges: FloatArray,
    gate_range: FloatArray,
    width: float,
    window_name: WindowName,
    n_samples: int,
) -> ComplexArray:
    """Slow-time signal of each chirp from the first receive antenna: its range profile
    band-limited to the bins within ``width / 2`` of the gate (at least the bin nearest to it)
    and read at the middle ADC sample
    ``m0 = n_samples // 2``,

        ``y = sum_{k in gate} X_k exp(-j 2 pi k m0 / K) sum_m w_m / (K w_m0)``.

    Summed over every bin this is exactly the IF sample ``y(m0)``; over the gate's bins, every
    scatterer well inside the gate contributes its amplitude with the phase of that sample
    (a flat range response, falling off over a few bins at the gate's edges), and scatterers
    outside hardly at all. (A plain sum of the bins would not do: neighbouring bins of a
    windowed profile partly cancel.) ``profiles`` (n_chirps, n_rx, K); ``ranges`` (K,) [m];
    ``gate_range`` (n_chirps,) [m]. Returns (n_chirps,) complex128 [sqrt(W)].
    """
    weights = gate_weights(ranges, gate_range, width, window_name, n_samples)
    return np.asarray(np.sum(profiles[:, 0, :] * weights, axis=1), dtype=np.complex128)


def gate_weights(
    ranges: FloatArray,
    gate_range: FloatArray,
    width: float,
    window_name: WindowName,
    n_samples: int,
) -> ComplexArray:
    """The weights of :func:`gate_signal` on the range bins, (n_chirps, K) complex128:
    ``exp(-j 2 pi k m0 / K) sum_m w_m / (K w_m0)`` on the gate's bins, 0 elsewhere."""
    n_fft = ranges.shape[0]
    m0 = n_samples // 2
    w = window(window_name, n_samples)
    k = np.arange(n_fft)
    rot = np.exp(-2j * np.pi * k * m0 / n_fft) * (float(np.sum(w)) / (n_fft * w[m0]))
    off = np.abs(ranges[None, :] - gate_range[:, None])
    inside = off <= width / 2.0
    inside[np.arange(off.shape[0]), np.argmin(off, axis=1)] = True  # a gate narrower than a bin
    return np.asarray(inside * rot, dtype=np.complex128)


#: Frames transformed at a time by :func:`frame_spectrogram`.
FRAMES_PER_BLOCK = 256


def frame_spectrogram(
    signal: ComplexArray,
    seq: ChirpSequence,
    window_name: str,
    nfft: int,
    precision: Literal["float32", "float64"] = "float32",
) -> tuple[NDArray[np.floating[Any]], FloatArray, FloatArray]:
    """One Doppler spectrum per frame of the slow-time signal of the first TDM slot.

    ``signal`` (n_frames * chirps_per_frame,) one value per chirp. Each frame's ``n_loops``
    samples of slot 0 are windowed (any scipy window, :func:`stft_window`) and transformed with
    ``nfft`` >= n_loops points, in ``precision`` (as the STFT's ``processing.precision``:
    float32 is complex64 FFTs and float32 power). Returns power (nfft, n_frames) [|signal|^2]
    float32 or float64, Doppler (nfft,) [Hz] ascending, ``(k - nfft // 2) / (nfft T_loop)`` as
    in every radar's spectrogram (not :func:`doppler_axis`), and the time of each frame's
    window centre (n_frames,) [s from the first chirp]: ``f T_frame + c T_loop``, ``c`` the
    :func:`~mdframework.physics.spectrogram.window_centre` of the window over the loops
    (``n_loops / 2`` for the periodic Hann window: half a loop after the middle loop).
    """
    # the cosine windows without importing scipy.signal
    from .spectrogram import precision_dtypes, stft_window, window_centre

    real, cplx = precision_dtypes(precision)
    frames = np.asarray(signal).reshape(-1, seq.chirps_per_frame)[:, :: seq.n_tx]
    w64 = stft_window(window_name, seq.n_loops)
    w = w64.astype(real)
    n_frames = frames.shape[0]
    power = np.empty((nfft, n_frames), dtype=real)
    for lo in range(0, n_frames, FRAMES_PER_BLOCK):  # memory set by the block, not the record
        hi = min(lo + FRAMES_PER_BLOCK, n_frames)
        x = frames[lo:hi].astype(cplx) * w
        spec = np.fft.fftshift(np.fft.fft(x, n=nfft, axis=1), axes=1)
        power[:, lo:hi] = (spec.real**2 + spec.imag**2).T
    time = np.arange(n_frames) * seq.frame_period + window_centre(w64) * seq.loop_period
    # the micro-Doppler axis of every radar's spectrogram (ambiguous bin first, as receding),
    # not the range-Doppler map's TI order: FMCW and pulse-Doppler spectrograms compare bin by bin
    doppler = np.arange(-(nfft // 2), nfft - nfft // 2) / (nfft * seq.loop_period)
    return power, np.asarray(doppler, np.float64), np.asarray(time, np.float64)
