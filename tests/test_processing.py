"""Resampling and spectrogram, including the hard cases of physics.md 6.3, 6.4 and 6.8."""

from __future__ import annotations

import numpy as np
import pytest

from mdframework.conditioning import sort_timestamps
from mdframework.physics import interpolation, spectrogram
from mdframework.skeleton import Skeleton, SkeletonError


def _swing(t: np.ndarray) -> np.ndarray:
    """1 Hz, 0.4 m swing on a 1.1 m/s walk (physics.md 6.4)."""
    return 1.1 * t + 0.2 * np.sin(2 * np.pi * t)


def test_cubic_spline_accuracy_at_kinect_rate() -> None:
    t = np.arange(0, 6.0 + 1e-9, 1 / 18)
    y = _swing(t)[:, None, None] * np.ones((1, 1, 3))
    tq = interpolation.pulse_times(t[0], t[-1], 2400.0)
    out = interpolation.resample_tracks(t, y, np.ones((t.size, 1), bool), tq, "cubic")
    err = np.abs(out[:, 0, 0] - _swing(tq))
    assert err.max() < 0.2e-3  # section 6.4: about 0.1 mm for a cubic spline
    lin = interpolation.resample_tracks(t, y, np.ones((t.size, 1), bool), tq, "linear")
    # linear interpolation is an order of magnitude worse (kinks: spurious Doppler lines)
    assert np.abs(lin[:, 0, 0] - _swing(tq)).max() > 10 * err.max()


@pytest.mark.parametrize("n_frames", [2, 3, 4, 5, 240])
def test_cubic_resampling_is_the_interpolating_spline(n_frames: int) -> None:
    """The resampler's B-spline is the not-a-knot cubic interpolating spline (natural ends
    below 4 frames): scipy's CubicSpline, an independent construction (piecewise polynomials
    from the tridiagonal slope system), agrees to 1e-12 m on uneven frame times, per joint
    with a gap, and the spline passes through every valid frame."""
    from scipy.interpolate import CubicSpline

    rng = np.random.default_rng(n_frames)
    t = np.cumsum(rng.uniform(1 / 150, 1 / 90, n_frames))
    pos = rng.uniform(-2.0, 2.0, (n_frames, 2, 3))
    valid = np.ones((n_frames, 2), bool)
    if n_frames > 10:
        valid[100:104, 1] = False  # one joint untracked for 4 frames: its own spline
        pos[100:104, 1] = np.nan
    tq = interpolation.pulse_times(t[0], t[-1], 2400.0)
    out = interpolation.resample_tracks(t, pos, valid, tq, "cubic")
    for j in range(2):
        ok = valid[:, j]
        bc = "natural" if ok.sum() < 4 else "not-a-knot"
        ref = CubicSpline(t[ok], pos[ok, j], axis=0, bc_type=bc)(tq)
        assert np.max(np.abs(out[:, j] - ref)) < 1e-12
    at_frames = interpolation.resample_tracks(t, pos, valid, t, "cubic")
    assert np.max(np.abs(at_frames[valid] - pos[valid])) < 1e-12


def test_pulse_times_never_extrapolate_and_use_time() -> None:
    tq = interpolation.pulse_times(0.25, 1.0, 2400.0)
    assert tq[0] == 0.25 and tq[-1] <= 1.0
    assert tq.size == 1801
    with pytest.raises(ValueError, match="never extrapolates"):
        interpolation.resample_tracks(
            np.array([0.0, 1.0, 2.0]),
            np.zeros((3, 1, 3)),
            np.ones((3, 1), bool),
            np.array([0.0, 2.5]),
        )


def test_nan_gap_is_bridged() -> None:
    t = np.arange(0, 3.0, 1 / 18)
    y = _swing(t)
    pos = np.repeat(y[:, None, None], 3, axis=2)
    valid = np.ones((t.size, 1), bool)
    valid[20:24] = False  # a 4-frame (0.22 s) gap
    pos[20:24] = np.nan
    tq = interpolation.pulse_times(t[0], t[-1], 2400.0)
    out = interpolation.resample_tracks(t, pos, valid, tq)
    assert np.all(np.isfinite(out))
    assert np.abs(out[:, 0, 0] - _swing(tq)).max() < 0.013  # section 6.4: 12.8 mm


def test_non_increasing_time_stamps_refused_and_sortable() -> None:
    t = np.array([0.0, 0.05, 0.05, 0.04, 0.2])
    pos = np.arange(15, dtype=float).reshape(5, 1, 3)
    with pytest.raises(SkeletonError, match="strictly increasing"):
        Skeleton(t, pos, ("a",))
    ts, ps, _, report = sort_timestamps(t, pos)
    assert np.all(np.diff(ts) > 0)
    assert np.array_equal(ps, pos[[0, 3, 1, 4]])
    assert report == {"out_of_order": 3, "duplicates_dropped": 1}
    Skeleton(ts, ps, ("a",))


def test_spectrogram_axes_and_frame_centres() -> None:
    fs = 2400.0
    y = np.exp(2j * np.pi * 300.0 * np.arange(4800) / fs)
    s = spectrogram.spectrogram(y, fs, window_length=256, hop=64, nfft=512)
    assert s.doppler[0] == -fs / 2 and s.doppler[-1] == pytest.approx(fs / 2 - fs / 512)
    assert s.time[0] == pytest.approx(128 / fs)  # the periodic Hann window's centre, L/2
    assert np.allclose(np.diff(s.time), 64 / fs)
    assert s.doppler[np.argmax(s.power[:, 3])] == pytest.approx(300.0, abs=fs / 512 / 2)
    # Parseval per frame: sum over bins of |X|^2 / nfft = sum |w y|^2 (nfft >= window)
    from scipy.signal import get_window

    w = get_window("hann", 256)
    assert s.power[:, 0].sum() / 512 == pytest.approx(np.sum(w**2), rel=1e-10)


def test_record_shorter_than_window_is_an_error() -> None:
    with pytest.raises(spectrogram.RecordTooShortError, match="needs 256"):
        spectrogram.spectrogram(np.ones(100, complex), 2400.0, window_length=256)


def test_db_floor_never_inf_or_nan() -> None:
    p = np.array([[0.0, 1.0], [1e-30, 0.0]])
    db = spectrogram.power_to_db(p, -60.0)
    assert np.all(np.isfinite(db)) and db.max() == 0.0 and db.min() == -60.0
    zero = spectrogram.power_to_db(np.zeros((4, 3)), -50.0)
    assert np.all(zero == -50.0)
    with pytest.raises(ValueError):
        spectrogram.power_to_db(np.array([np.inf]), -60.0)


def test_db_stored_in_float32_block_by_block_is_the_whole_computation_rounded(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """float64 power converted to a float32 dB map a block of rows at a time (3 rows a block
    here, so the peak and the floor fall in different blocks) equals the float64 map of the
    whole array, rounded to float32, exactly; also for a tiny peak (relative floor), all-zero
    power, no rows and one dimension."""
    monkeypatch.setattr(spectrogram, "DB_BLOCK_VALUES", 3 * 50)
    rng = np.random.default_rng(4)
    cases = [
        rng.exponential(1.0, (31, 50)) * np.where(rng.random((31, 50)) < 0.1, 0.0, 1.0),
        rng.exponential(1e-305, (10, 50)),
        np.zeros((7, 50)),
        np.zeros((0, 50)),
        rng.exponential(1.0, 200),
    ]
    for p in cases:
        whole = spectrogram.power_to_db(p, -60.0)
        stored = spectrogram.power_to_db(p, -60.0, dtype=np.float32)
        assert whole.dtype == np.float64 and stored.dtype == np.float32
        np.testing.assert_array_equal(stored, whole.astype(np.float32))


@pytest.mark.parametrize("name", sorted(spectrogram.COSINE_WINDOWS))
@pytest.mark.parametrize("length", [1, 2, 7, 64, 256, 1000])
def test_numpy_windows_equal_scipys_periodic_windows(name: str, length: int) -> None:
    from scipy.signal import get_window

    expected = get_window(name, length, fftbins=True)
    assert np.allclose(spectrogram.stft_window(name, length), expected, rtol=0, atol=1e-14)


def test_other_windows_come_from_scipy_and_unknown_names_fail() -> None:
    from scipy.signal import get_window

    w = spectrogram.stft_window("flattop", 128)
    assert np.array_equal(w, get_window("flattop", 128, fftbins=True))
    with pytest.raises(ValueError):
        spectrogram.stft_window("nosuchwindow", 8)


def _reversal(t: np.ndarray, t_rev: float, f0: float) -> np.ndarray:
    """A tone at +f0 [Hz] until ``t_rev`` [s], then at -f0, its phase continuous: the slow-time
    return of a point that approaches, turns at ``t_rev`` and recedes at the same speed."""
    return np.exp(2j * np.pi * f0 * (t_rev - np.abs(t - t_rev)))


def _half_power_time(power: np.ndarray, doppler: np.ndarray, time: np.ndarray) -> float:
    """The time [s] at which a spectrogram's power above 0 Hz falls to half of the power off
    0 Hz, interpolated linearly between its columns."""
    up = power[doppler > 0].sum(axis=0)
    share = up / (up + power[doppler < 0].sum(axis=0))
    i = int(np.flatnonzero((share[:-1] >= 0.5) & (share[1:] < 0.5))[0])
    return float(time[i] + (share[i] - 0.5) / (share[i] - share[i + 1]) * (time[i + 1] - time[i]))


@pytest.mark.parametrize(
    ("window", "length", "nfft"),
    [("hann", 256, 256), ("hann", 255, 511), ("blackman", 128, 128), ("boxcar", 64, 128)],
)
def test_a_frame_is_stamped_at_its_windows_centre(window: str, length: int, nfft: int) -> None:
    """A return whose Doppler flips from +300 to -300 Hz at t_rev: the frame whose power splits
    evenly between them is the one whose window is centred on t_rev, and its time says t_rev
    to 0.02 samples (hop 1). The periodic windows (Hann, Blackman) are symmetric about their
    L/2-th sample, the boxcar about (L - 1)/2: stamping every window at the middle sample
    (L - 1)/2 put the flip half a sample (0.2 ms at 2400 Hz) after its true time."""
    assert _flip_stamp_error(window, length, nfft) == pytest.approx(0.0, abs=0.02)


def _flip_stamp_error(window: str, length: int, nfft: int) -> float:
    """How far [samples] the half-power time of a +300 Hz to -300 Hz flip at sample 600.3
    (2400 Hz, 1200 samples) is from the flip, in a spectrogram of hop 1."""
    fs = 2400.0
    t = np.arange(1200) / fs
    t_rev = 600.3 / fs
    s = spectrogram.spectrogram(
        _reversal(t, t_rev, 300.0),
        fs,
        window=window,
        window_length=length,
        hop=1,
        nfft=nfft,
        precision="float64",
    )
    return (_half_power_time(s.power, s.doppler, s.time) - t_rev) * fs


@pytest.mark.parametrize("nfft", [255, 257])
def test_odd_fft_size_puts_a_tone_on_its_own_bin(nfft: int) -> None:
    """An odd FFT size (bins -(N-1)/2 .. (N-1)/2, centred by fftshift): tones on bins +-17 and
    a tone at 0 Hz peak on the Doppler axis at their own frequencies, k fs / N, in every frame
    (ifftshift instead of fftshift would move them one bin)."""
    fs = 2400.0
    n = np.arange(3000)
    for k in (17, -17, 0):
        f = k * fs / nfft
        s = spectrogram.spectrogram(
            np.exp(2j * np.pi * f * n / fs), fs, window_length=255, nfft=nfft
        )
        assert s.doppler.size == nfft and s.doppler[(nfft - 1) // 2] == 0.0
        np.testing.assert_allclose(s.doppler[np.argmax(s.power, axis=0)], f, atol=1e-9)


def test_window_centre_is_the_centroid_of_the_windows_energy() -> None:
    """window_centre is sum n w(n)^2 / sum w(n)^2 samples from the first: 1.8 for the ramp
    (0, 1, 2) (its amplitude's centroid would say 5/3), L/2 for the periodic Hann and
    Blackman windows, within 0.01 sample of L/2 for the periodic Hamming, (L - 1)/2 for the
    boxcar, and the middle sample for a window without energy. With the Hamming window the
    frame whose power splits evenly between the two sides of a Doppler flip is stamped within
    0.04 samples of the flip (its amplitude's centroid is 0.066 samples earlier)."""
    assert spectrogram.window_centre(np.array([0.0, 1.0, 2.0])) == pytest.approx(1.8, abs=1e-12)
    assert spectrogram.window_centre(np.array([2.0, 1.0, 0.0])) == pytest.approx(0.2, abs=1e-12)
    for length in (7, 64, 255):
        for name in ("hann", "blackman"):
            w = spectrogram.stft_window(name, length)
            assert spectrogram.window_centre(w) == pytest.approx(length / 2, abs=1e-9)
        hamming = spectrogram.stft_window("hamming", length)
        assert abs(spectrogram.window_centre(hamming) - length / 2) < 0.01
        boxcar = spectrogram.stft_window("boxcar", length)
        assert spectrogram.window_centre(boxcar) == pytest.approx((length - 1) / 2, abs=1e-9)
    assert spectrogram.window_centre(np.zeros(6)) == 2.5
    assert _flip_stamp_error("hamming", 256, 256) == pytest.approx(0.0, abs=0.04)
