"""Radar equations: range equation, carrier phase, LFM pulse compression, Doppler bookkeeping.

Sign convention: the slow-time return is proportional to
``exp(-j 4 pi f_c R / c)``, so an approaching target (R falling) has positive Doppler
``f_D = 2 v_r / lambda`` with ``v_r > 0`` when approaching.

Numerics: ranges stay float64 and the carrier phase is reduced to a fraction of a
cycle in float64 before any complex exponential is formed, so 10 km ranges keep the same Doppler as
10 m ranges.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..constants import SPEED_OF_LIGHT

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

GateResponse = Literal["exact", "sinc", "phase_only"]
AmplitudeModel = Literal["range_equation", "sqrt_rcs"]


def distances(points: ArrayLike, origin: ArrayLike) -> FloatArray:
    """Distance [m] of ``points`` (..., 3) [m] to ``origin`` (3,) [m], (...,) float64. Summed
    per coordinate: a norm over a last axis of 3 would be several times slower."""
    d = np.asarray(points, dtype=np.float64) - np.asarray(origin, dtype=np.float64)
    r = d[..., 0] ** 2
    r += d[..., 1] ** 2
    r += d[..., 2] ** 2
    return np.asarray(np.sqrt(r, out=r), dtype=np.float64)


def wavelength(carrier_frequency: float) -> float:
    """Wavelength [m] of a carrier [Hz], with the exact speed of light."""
    return SPEED_OF_LIGHT / float(carrier_frequency)


def doppler_to_velocity(doppler: ArrayLike, carrier_frequency: float) -> FloatArray:
    """Radial velocity [m/s] (positive approaching) for Doppler [Hz]: ``v = f lambda / 2``."""
    return np.asarray(doppler, dtype=np.float64) * wavelength(carrier_frequency) / 2.0


def velocity_to_doppler(velocity: ArrayLike, carrier_frequency: float) -> FloatArray:
    """Doppler [Hz] of a radial velocity [m/s] (positive approaching): ``f = 2 v / lambda``."""
    return 2.0 * np.asarray(velocity, dtype=np.float64) / wavelength(carrier_frequency)


def max_unambiguous_velocity(carrier_frequency: float, prf: float) -> float:
    """Largest |radial velocity| [m/s] that complex slow-time samples at ``prf`` [Hz] represent
    without aliasing: ``lambda * PRF / 4``."""
    return wavelength(carrier_frequency) * float(prf) / 4.0


def min_prf_for_velocity(speed: float, carrier_frequency: float) -> float:
    """The smallest PRF [Hz] whose unambiguous velocity ``lambda * PRF / 4`` reaches ``speed``
    [m/s]: ``4 |v| / lambda`` (the inverse of :func:`max_unambiguous_velocity`)."""
    return 4.0 * abs(float(speed)) / wavelength(carrier_frequency)


def alias_frequency(doppler: ArrayLike, prf: float) -> FloatArray:
    """The frequency [Hz] at which a true Doppler [Hz] is observed after sampling at ``prf``:
    ``((f + PRF/2) mod PRF) - PRF/2``."""
    f = np.asarray(doppler, dtype=np.float64)
    return np.asarray(np.mod(f + prf / 2.0, prf) - prf / 2.0, dtype=np.float64)


def max_range_rate(ranges: FloatArray, t: FloatArray) -> float:
    """The fastest radial speed [m/s] between consecutive pulses: ``ranges`` (n, n_scatterers)
    [m] at times ``t`` (n,) [s], n >= 2. Pulses evenly spaced to 1e-9 (every waveform's) take
    the largest range step over the shortest interval (at most 1e-9 above the exact value,
    without a pass per pulse); others divide each pulse's largest step by its interval."""
    step = ranges[1:] - ranges[:-1]
    dt = np.diff(t)
    dt_min, dt_max = float(dt.min()), float(dt.max())
    if dt_max - dt_min <= 1e-9 * dt_min:
        return max(float(step.max()), -float(step.min())) / dt_min
    return float(np.max(np.maximum(step.max(axis=1), -step.min(axis=1)) / dt))


def range_equation_amplitude(
    rcs: ArrayLike,
    ranges: ArrayLike,
    *,
    wavelength: float,
    transmit_power: float = 1.0,
    gain: float = 1.0,
    system_loss: float = 1.0,
    atmospheric_loss: float = 1.0,
) -> FloatArray:
    """Received amplitude [sqrt(W)] from the monostatic radar range equation (eq. 3).

    ``a = sqrt(P_t G^2 lambda^2 sigma / ((4 pi)^3 R^4 L_s L_a))``, with ``rcs`` [m^2] and
    ``ranges`` [m] broadcast together; gains and losses are linear power ratios (>= 1 for losses).
    Ranges must be positive.
    """
    r = np.asarray(ranges, dtype=np.float64)
    sigma = np.asarray(rcs, dtype=np.float64)
    if np.any(~(r > 0)):
        raise ValueError("ranges must be positive and finite for the range equation")
    num = transmit_power * gain**2 * wavelength**2 * sigma
    den = (4.0 * np.pi) ** 3 * r**4 * system_loss * atmospheric_loss
    return np.asarray(np.sqrt(num / den), dtype=np.float64)


def scatterer_amplitudes(
    rcs: ArrayLike,
    ranges: ArrayLike,
    *,
    model: AmplitudeModel,
    wavelength: float,
    transmit_power: float = 1.0,
    gain: float = 1.0,
    system_loss: float = 1.0,
    atmospheric_loss: float = 1.0,
) -> FloatArray:
    """Amplitude of each scatterer's return [sqrt(W)], shaped like ``ranges``.

    ``range_equation``: :func:`range_equation_amplitude`. ``sqrt_rcs``: ``sqrt(sigma)`` with no
    range dependence (Chen's MATLAB walker and the paper's amplitude model); the other arguments
    are then unused.
    """
    if model == "sqrt_rcs":
        shape = np.broadcast_shapes(np.shape(rcs), np.shape(ranges))
        return np.asarray(np.broadcast_to(np.sqrt(np.asarray(rcs, np.float64)), shape), np.float64)
    if model == "range_equation":
        return range_equation_amplitude(
            rcs,
            ranges,
            wavelength=wavelength,
            transmit_power=transmit_power,
            gain=gain,
            system_loss=system_loss,
            atmospheric_loss=atmospheric_loss,
        )
    raise ValueError(f"unknown amplitude model {model!r}")


def carrier_cycles_fraction(ranges: ArrayLike, carrier_frequency: float) -> FloatArray:
    """Fractional part of the two-way carrier cycles ``2 f_c R / c``, in [0, 1), float64.

    The reduction happens in float64 on float64 ranges, so the result keeps its precision at any
    range a float64 can hold to the nanometre (about 1e8 m)."""
    r = np.asarray(ranges, dtype=np.float64)
    cycles = (2.0 * float(carrier_frequency) / SPEED_OF_LIGHT) * r
    return np.asarray(cycles - np.floor(cycles), dtype=np.float64)


def carrier_phasor(ranges: ArrayLike, carrier_frequency: float) -> ComplexArray:
    """``exp(-j 4 pi f_c R / c)`` for ranges [m], computed from the float64 fraction of a cycle."""
    phase = (-2.0 * np.pi) * carrier_cycles_fraction(ranges, carrier_frequency)
    out = np.empty(phase.shape, dtype=np.complex128)
    out.real = np.cos(phase)  # cos + j sin is several times faster than a complex exp
    out.imag = np.sin(phase)
    return out


def lfm_chirp(fast_time: ArrayLike, pulse_width: float, bandwidth: float) -> ComplexArray:
    """The symmetric baseband LFM pulse ``p(t) = rect(t/tau) exp(j pi gamma t^2)``, sweeping
    ``-B/2 .. +B/2`` over ``|t| <= tau/2``; ``gamma = B / tau``. ``fast_time`` [s]."""
    t = np.asarray(fast_time, dtype=np.float64)
    gamma = bandwidth / pulse_width
    inside = np.abs(t) <= pulse_width / 2.0
    return np.asarray(np.where(inside, np.exp(1j * np.pi * gamma * t * t), 0.0), np.complex128)


def lfm_compressed_envelope(
    delay_offset: ArrayLike, pulse_width: float, bandwidth: float
) -> FloatArray:
    """Matched-filter output of the symmetric LFM pulse versus delay offset (real-valued) [s].

    ``chi(D) = (tau - |D|) sinc(gamma D (tau - |D|))`` for ``|D| < tau``, else 0 (the
    LFM ambiguity function on the zero-Doppler cut); its peak ``chi(0) = tau``.
    ``delay_offset`` [s]."""
    d = np.abs(np.asarray(delay_offset, dtype=np.float64))
    gamma = bandwidth / pulse_width
    rem = np.clip(pulse_width - d, 0.0, None)
    return np.asarray(rem * np.sinc(gamma * d * rem), dtype=np.float64)


def gate_weights(
    ranges: FloatArray,
    gate_range: FloatArray,
    *,
    pulse_width: float,
    bandwidth: float,
    response: GateResponse = "exact",
) -> FloatArray:
    """Range weighting of each scatterer in the range gate, normalised to 1 at the gate.

    ``ranges`` (n_pulses, n_scatterers) [m], ``gate_range`` (n_pulses,) [m].
    ``exact``: ``chi(2 (R_0 - R_i)/c) / tau``; ``sinc``: ``sinc(2 B (R_0 - R_i)/c)`` (large TB
    limit); ``phase_only``: 1 (flat range response, the paper's and Chen's model).
    """
    if response == "phase_only":
        return np.ones_like(ranges)
    delta = 2.0 * (np.asarray(gate_range)[:, None] - ranges) / SPEED_OF_LIGHT
    if response == "sinc":
        return np.asarray(np.sinc(bandwidth * delta), dtype=np.float64)
    if response == "exact":
        return lfm_compressed_envelope(delta, pulse_width, bandwidth) / pulse_width
    raise ValueError(f"unknown gate response {response!r}")


def compressed_return_at_gate(
    ranges: FloatArray,
    amplitudes: FloatArray,
    gate_range: FloatArray,
    *,
    carrier_frequency: float,
    pulse_width: float,
    bandwidth: float,
    response: GateResponse = "exact",
) -> ComplexArray:
    """Analytic pulse-compressed slow-time return at the range gate (eq. 4), divided by ``tau``.

    ``y(n) = sum_i a_i w_i(n) exp(-j 4 pi f_c R_i(n)/c)`` with ``w`` from :func:`gate_weights`.
    ``ranges``, ``amplitudes``: (n_pulses, n_scatterers) [m], [sqrt(W)]; ``gate_range``
    (n_pulses,) [m]. Returns (n_pulses,) complex128 [sqrt(W)].
    """
    weighted = amplitudes * gate_weights(
        ranges, gate_range, pulse_width=pulse_width, bandwidth=bandwidth, response=response
    )
    # sum the real and imaginary parts separately: no complex temporaries
    phase = (-2.0 * np.pi) * carrier_cycles_fraction(ranges, carrier_frequency)
    out = np.empty(ranges.shape[0], dtype=np.complex128)
    out.real = np.einsum("ps,ps->p", weighted, np.cos(phase))
    out.imag = np.einsum("ps,ps->p", weighted, np.sin(phase))
    return out


def raw_pulse_returns(
    ranges: FloatArray,
    amplitudes: FloatArray,
    fast_time: FloatArray,
    *,
    carrier_frequency: float,
    pulse_width: float,
    bandwidth: float,
) -> ComplexArray:
    """Baseband received pulses sampled in fast time (eq. 1-2), stop-and-hop.

    ``s(n, t') = sum_i a_i rect((t' - t_d)/tau) exp(j[-2 pi f_c t_d + pi gamma (t' - t_d)^2])``
    with ``t_d = 2 R_i(n)/c``. ``ranges``, ``amplitudes``: (n_pulses, n_scatterers);
    ``fast_time`` (n_fast,) [s] after transmission. Returns (n_pulses, n_fast) complex128.
    """
    out = np.zeros((ranges.shape[0], fast_time.shape[0]), dtype=np.complex128)
    for i in range(ranges.shape[1]):
        delay = 2.0 * ranges[:, i] / SPEED_OF_LIGHT
        pulse = lfm_chirp(fast_time[None, :] - delay[:, None], pulse_width, bandwidth)
        carrier = carrier_phasor(ranges[:, i], carrier_frequency)
        out += (amplitudes[:, i] * carrier)[:, None] * pulse
    return out


def matched_filter(
    received: ComplexArray, sample_rate: float, *, pulse_width: float, bandwidth: float
) -> ComplexArray:
    """Pulse compression of sampled fast-time data with the matched filter ``p*(-t)``.

    ``received`` (n_pulses, n_fast) sampled at ``sample_rate`` [Hz]. Output (n_pulses, n_fast):
    sample ``k`` is the correlation ``integral s(t) p*(t - t_k) dt`` [s x input unit] with the
    replica centred on sample ``k``, so a point target at delay ``t_d`` peaks at ``t_k = t_d``
    with value ``a tau``.
    """
    from scipy.signal import fftconvolve

    half = int(np.floor(pulse_width / 2.0 * sample_rate))
    lags = np.arange(-half, half + 1) / sample_rate
    replica = lfm_chirp(lags, pulse_width, bandwidth)
    kernel = np.conj(replica[::-1])[None, :]
    full = fftconvolve(received, kernel, mode="full", axes=1) / sample_rate
    return np.asarray(full[:, half : half + received.shape[1]], dtype=np.complex128)


def compress_at_delay(
    received: ComplexArray,
    fast_time: FloatArray,
    delay: FloatArray,
    *,
    pulse_width: float,
    bandwidth: float,
) -> ComplexArray:
    """Matched-filter output of each pulse at an exact (off-grid) delay, e.g. a tracking gate.

    ``received`` (n_pulses, n_fast) sampled at the uniform ``fast_time`` (n_fast,) [s];
    ``delay`` (n_pulses,) [s]. Returns (n_pulses,) ``integral s(t) p*(t - delay) dt``.
    """
    dt = float(fast_time[1] - fast_time[0])
    replica = lfm_chirp(fast_time[None, :] - delay[:, None], pulse_width, bandwidth)
    return np.asarray(np.sum(received * np.conj(replica), axis=1) * dt, dtype=np.complex128)
