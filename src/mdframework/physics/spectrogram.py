"""Two-sided spectrogram of the complex slow-time return.

``S(m, k) = |sum_n y(n) w(n - mH) exp(-j 2 pi k n / N_fft)|^2``, bins ``k = -N/2 .. N/2 - 1``,
``f_k = k PRF / N_fft``. Positive frequencies are approaching targets.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import scipy.fft as sfft
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: Periodic (DFT-even) cosine-sum windows computed here with numpy, as coefficients ``a_k`` of
#: ``w(n) = sum_k (-1)^k a_k cos(2 pi k n / L)``: the same values as
#: ``scipy.signal.get_window(name, L, fftbins=True)`` (a test compares them), without importing
#: scipy.signal (over a second of start-up). Any other scipy window name goes to scipy.
COSINE_WINDOWS: dict[str, tuple[float, ...]] = {
    "boxcar": (1.0,),
    "hann": (0.5, 0.5),
    "hamming": (0.54, 0.46),
    "blackman": (0.42, 0.5, 0.08),
}


def precision_dtypes(
    precision: Literal["float32", "float64"],
) -> tuple[np.dtype[Any], np.dtype[Any]]:
    """The (real, complex) dtypes of a ``processing.precision``."""
    single = precision == "float32"
    return np.dtype(np.float32 if single else np.float64), np.dtype(
        np.complex64 if single else np.complex128
    )


def stft_window(name: str, length: int) -> FloatArray:
    """The periodic STFT window ``name`` (any ``scipy.signal.get_window`` name), (length,)
    float64. ``ValueError`` for an unknown name."""
    if length == 1:
        return np.ones(1)  # scipy's one-sample window, whatever its name
    if name in COSINE_WINDOWS:
        phase = 2.0 * np.pi * np.arange(length) / length
        w = np.zeros(length)
        for k, a in enumerate(COSINE_WINDOWS[name]):
            w += (-1) ** k * a * np.cos(k * phase)
        return w
    from scipy.signal import get_window

    return np.asarray(get_window(name, length, fftbins=True), dtype=np.float64)


def window_centre(window: FloatArray) -> float:
    """The time centre of a window ``w`` (L,), in samples from its first: the centroid of its
    energy, ``sum_n n w(n)^2 / sum_n w(n)^2``. A spectrum taken through the window measures
    the signal around that instant: a tone that changes at it puts half of the spectrum's
    energy on either side. ``L / 2`` for the periodic (DFT-even) Hann and Blackman windows of
    :func:`stft_window` (their first sample, 0, pairs with the missing ``L``-th: they are
    symmetric about ``L / 2``, not about the middle sample ``(L - 1) / 2``), within 0.01 sample
    of it for the periodic Hamming window, ``(L - 1) / 2`` for the boxcar. A window without
    energy counts from its middle sample."""
    w2 = np.square(np.asarray(window, dtype=np.float64))
    total = float(np.sum(w2))
    if not total > 0.0:
        return float(w2.shape[0] - 1) / 2.0
    return float(np.dot(np.arange(w2.shape[0], dtype=np.float64), w2) / total)


class RecordTooShortError(ValueError):
    """The record has fewer samples than one STFT window."""


@dataclass(frozen=True)
class SpectrogramGeometry:
    """The spectrogram a radar makes of a record, known before any pulse is simulated.

    ``sample_rate`` [Hz]: the rate of the slow-time samples the spectra are taken of;
    ``window``: samples per spectrum; ``hop``: samples from one spectrum to the next (at
    ``sample_rate``; a whole number for an STFT, one frame period for FMCW frames); ``nfft``:
    the FFT size (the number of Doppler bins); ``n_frames``: the spectra. The power is
    ``(nfft, n_frames)``."""

    sample_rate: float
    window: int
    hop: float
    nfft: int
    n_frames: int

    @property
    def shape(self) -> tuple[int, int]:
        """``(nfft, n_frames)``: the shape of the spectrogram's power."""
        return self.nfft, self.n_frames

    @property
    def doppler_bin(self) -> float:
        """Spacing of the Doppler bins, ``sample_rate / nfft`` [Hz]."""
        return self.sample_rate / self.nfft

    @property
    def window_resolution(self) -> float:
        """Doppler resolution of the window, ``sample_rate / window`` [Hz]."""
        return self.sample_rate / self.window


def stft_geometry(
    n_samples: int, sample_rate: float, window_length: int, hop: int, nfft: int | None = None
) -> SpectrogramGeometry:
    """The geometry of :func:`spectrogram` for ``n_samples`` samples at ``sample_rate`` [Hz]:
    ``1 + (n_samples - window_length) // hop`` frames of ``nfft`` bins (default: the window
    length). ``ValueError`` for a window shorter than 2, a hop below 1 or ``nfft`` below the
    window; :class:`RecordTooShortError` for a record shorter than one window."""
    nfft = window_length if nfft is None else int(nfft)
    if window_length < 2 or hop < 1:
        raise ValueError("window_length must be >= 2 and hop >= 1")
    if nfft < window_length:
        raise ValueError(f"nfft ({nfft}) must be >= window_length ({window_length})")
    if n_samples < window_length:
        raise RecordTooShortError(
            f"the record has {n_samples} samples ({n_samples / sample_rate:.4f} s) but the STFT "
            f"window needs {window_length}: use a longer record or a shorter window"
        )
    n_frames = 1 + (n_samples - window_length) // hop
    return SpectrogramGeometry(float(sample_rate), window_length, hop, nfft, n_frames)


@dataclass(frozen=True)
class Spectrogram:
    """``power`` (n_doppler, n_frames) float32 (float64 with ``precision = "float64"``)
    [W-like, |signal|^2 units];
    ``doppler`` (n_doppler,) [Hz], ascending; ``time`` (n_frames,) [s], window centres
    (:func:`window_centre`) relative to the first sample."""

    power: NDArray[np.floating[Any]]
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
    precision: Literal["float32", "float64"] = "float32",
) -> Spectrogram:
    """STFT power of a complex signal (n_samples,).

    ``window`` is any scipy window name; ``window_length`` and ``hop`` in samples; ``nfft`` >=
    ``window_length`` (default: the window length). Frame ``m`` covers samples
    ``mH .. mH + L - 1`` and its time is its window's centre ``(mH + c) / fs``, ``c`` the
    :func:`window_centre` (``L / 2`` for the periodic Hann window). A record shorter
    than one window raises :class:`RecordTooShortError`; the resolution never changes silently
    (``ValueError`` for a signal of more than one dimension: one channel at a time).
    ``precision``: ``float32`` (complex64 FFTs, float32 power; the accuracy ladder in
    ``docs/accuracy.md`` measures its cost) or ``float64``. Frames are transformed a few
    thousand at a time, so the only record-sized array is the power itself.
    """
    y = np.asarray(signal)
    if y.ndim != 1:
        raise ValueError(f"signal must be one channel, (n_samples,), got shape {y.shape}")
    geometry = stft_geometry(y.shape[0], sample_rate, window_length, hop, nfft)
    nfft, n_frames = geometry.shape
    real, cplx = precision_dtypes(precision)
    w = stft_window(window, window_length)
    if nfft % 2 == 0:
        # (-1)^m moves bin k to frequency (k - N/2) PRF/N: ascending bins without fftshift
        w = w * np.where(np.arange(window_length) % 2 == 0, 1.0, -1.0)
    weights = w.astype(real)
    frames = np.lib.stride_tricks.sliding_window_view(y.astype(cplx, copy=False), window_length)
    frames = frames[::hop]
    # (n_frames, nfft) C-ordered; returned transposed: (n_doppler, n_frames) without a copy
    power = np.empty((n_frames, nfft), dtype=real)
    chunk = min(n_frames, max(1, (1 << 20) // nfft))  # frames per FFT call: a few MiB
    buf = np.zeros((chunk, nfft), dtype=cplx)  # zero-padded beyond the window
    for lo in range(0, n_frames, chunk):
        hi = min(lo + chunk, n_frames)
        m = hi - lo
        np.multiply(frames[lo:hi], weights, out=buf[:m, :window_length])
        spec = sfft.fft(buf[:m], axis=1)
        if nfft % 2:
            spec = sfft.fftshift(spec, axes=1)
        np.square(spec.real, out=power[lo:hi])
        power[lo:hi] += np.square(spec.imag)
    doppler = np.arange(-(nfft // 2), nfft - nfft // 2, dtype=np.float64) * sample_rate / nfft
    centre = window_centre(w)  # of the window itself: the (-1)^n above leaves w^2 as it is
    time = np.asarray((np.arange(n_frames) * hop + centre) / sample_rate, np.float64)
    return Spectrogram(power.T, doppler, time)


def power_to_db(
    power: NDArray[np.floating[Any]],
    floor_db: float = -60.0,
    *,
    dtype: type[np.floating[Any]] | None = None,
) -> NDArray[Any]:
    """``10 log10(P / P_max)`` clipped below at ``floor_db`` (< 0): never -inf or NaN. Computed
    in the input's precision (float32 or float64; other types in float64) and returned in it,
    or stored as ``dtype`` (e.g. float64 power into a float32 map: computed a block of rows at a
    time, so the record is never held in both precisions; each value is the one the whole
    computation gives, rounded to ``dtype``).

    An all-zero input gives ``floor_db`` everywhere (there is no peak to refer to)."""
    if floor_db >= 0:
        raise ValueError("floor_db must be negative")
    p = np.asarray(power)
    if p.dtype not in (np.float32, np.float64):
        p = p.astype(np.float64)
    p_max = float(np.max(p)) if p.size else 0.0
    if not np.isfinite(p_max):
        raise ValueError("the power has non-finite values")
    if dtype is None or np.dtype(dtype) == p.dtype or p.size == 0 or p.ndim == 0:
        out = _db(p, p_max, floor_db)
        return out if dtype is None else out.astype(dtype, copy=False)
    stored = np.empty(p.shape, dtype=dtype)
    rows = max(1, DB_BLOCK_VALUES // max(1, p[0].size))
    for lo in range(0, p.shape[0], rows):
        stored[lo : lo + rows] = _db(p[lo : lo + rows], p_max, floor_db)
    return stored


#: Values converted at a time by :func:`power_to_db` when it stores another precision.
DB_BLOCK_VALUES = 1 << 20


def _db(p: NDArray[Any], p_max: float, floor_db: float) -> NDArray[Any]:
    """:func:`power_to_db` of ``p`` (float32 or float64) with the peak ``p_max`` given."""
    if p_max <= 0.0:
        return np.full(p.shape, float(floor_db), dtype=p.dtype)
    floor = p_max * 10.0 ** (floor_db / 10.0)
    if floor >= np.finfo(p.dtype).tiny:
        out = np.maximum(p, p.dtype.type(floor))
        out *= p.dtype.type(1.0 / p_max)
    else:
        # a peak near the smallest float: relative to the peak first, since the absolute floor
        # would underflow to 0 (and the log to -inf)
        out = np.divide(p, p.dtype.type(p_max))
        np.maximum(out, p.dtype.type(10.0 ** (floor_db / 10.0)), out=out)
    np.log10(out, out=out)
    out *= p.dtype.type(10.0)
    return np.asarray(out)
