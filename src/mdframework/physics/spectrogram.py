"""Two-sided spectrogram of the complex slow-time return (``physics.md`` sections 1.7 and 6.3).

``S(m, k) = |sum_n y(n) w(n - mH) exp(-j 2 pi k n / N_fft)|^2``, bins ``k = -N/2 .. N/2 - 1``,
``f_k = k PRF / N_fft``. Positive frequencies are approaching targets.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.signal import get_window

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


class RecordTooShortError(ValueError):
    """The record has fewer samples than one STFT window."""


@dataclass(frozen=True)
class Spectrogram:
    """``power`` (n_doppler, n_frames) float64 [W-like, |signal|^2 units];
    ``doppler`` (n_doppler,) [Hz], ascending; ``time`` (n_frames,) [s], window centres relative
    to the first sample."""

    power: FloatArray
    doppler: FloatArray
    time: FloatArray


def spectrogram(
    signal: ComplexArray,
    sample_rate: float,
    *,
    window: str = "hann",
    window_length: int = 256,
    hop: int = 32,
    nfft: int | None = None,
) -> Spectrogram:
    """STFT power of a complex signal (n_samples,).

    ``window`` is any scipy window name; ``window_length`` and ``hop`` in samples; ``nfft`` >=
    ``window_length`` (default: the window length). Frame ``m`` covers samples
    ``mH .. mH + L - 1`` and its time is their midpoint ``(mH + (L - 1)/2) / fs``. A record shorter
    than one window raises :class:`RecordTooShortError`; the resolution never changes silently.
    """
    y = np.asarray(signal)
    n = y.shape[0]
    nfft = window_length if nfft is None else int(nfft)
    if window_length < 2 or hop < 1:
        raise ValueError("window_length must be >= 2 and hop >= 1")
    if nfft < window_length:
        raise ValueError(f"nfft ({nfft}) must be >= window_length ({window_length})")
    if n < window_length:
        raise RecordTooShortError(
            f"the record has {n} samples ({n / sample_rate:.4f} s) but the STFT window needs "
            f"{window_length}: use a longer record or a shorter window"
        )
    w = get_window(window, window_length, fftbins=True).astype(np.float64)
    frames = np.lib.stride_tricks.sliding_window_view(y, window_length)[::hop]
    spec = np.fft.fftshift(np.fft.fft(frames * w, n=nfft, axis=1), axes=1)
    power = (spec.real**2 + spec.imag**2).T
    doppler = np.arange(-(nfft // 2), nfft - nfft // 2, dtype=np.float64) * sample_rate / nfft
    time = np.asarray(
        (np.arange(frames.shape[0]) * hop + (window_length - 1) / 2.0) / sample_rate, np.float64
    )
    return Spectrogram(np.ascontiguousarray(power), doppler, time)


def power_to_db(power: FloatArray, floor_db: float = -60.0) -> FloatArray:
    """``10 log10(P / P_max)`` clipped below at ``floor_db`` (< 0): never -inf or NaN.

    An all-zero input gives ``floor_db`` everywhere (there is no peak to refer to)."""
    if floor_db >= 0:
        raise ValueError("floor_db must be negative")
    p = np.asarray(power, dtype=np.float64)
    p_max = float(np.max(p)) if p.size else 0.0
    if not np.isfinite(p_max):
        raise ValueError("the power has non-finite values")
    if p_max <= 0.0:
        return np.full(p.shape, float(floor_db))
    # relative to the peak first: for a peak near the smallest float the absolute floor
    # p_max * 10**(floor_db / 10) would underflow to 0 (and the log to -inf)
    floor = 10.0 ** (floor_db / 10.0)
    return np.asarray(10.0 * np.log10(np.maximum(p / p_max, floor)), dtype=np.float64)
