"""The seven features on spectrograms with known answers (physics.md section 4)."""

from __future__ import annotations

import numpy as np
import pytest

from mdframework.features import FEATURE_NAMES, envelopes, spectrogram_features
from mdframework.physics import radar
from mdframework.physics.spectrogram import spectrogram

FC, PRF = 15e9, 2400.0
LAMBDA = radar.wavelength(FC)


def tone_signal(velocity_of_t: list[tuple[np.ndarray, float]], t: np.ndarray) -> np.ndarray:
    """Complex slow-time signal whose components follow given radial velocities [m/s]."""
    y = np.zeros(t.size, complex)
    for v, amp in velocity_of_t:
        phase = 2 * np.pi * np.cumsum(2 * v / LAMBDA) / PRF
        y += amp * np.exp(1j * phase)
    return y


def synthetic_walk(
    window: int, hop: int = 32, nfft: int = 4096, length: float = 6.0, limb_amplitude: float = 0.3
) -> tuple[np.ndarray, np.ndarray, float]:
    """physics.md 4.2: torso 1.1 + 0.15 sin(2 pi 1.8 t), limb 1.1 + 2.6 sin(2 pi 0.9 t) at 0.3,
    ``length`` seconds at 15 GHz and PRF 2400 Hz."""
    t = np.arange(int(length * PRF)) / PRF
    torso = 1.1 + 0.15 * np.sin(2 * np.pi * 1.8 * t)
    limb = 1.1 + 2.6 * np.sin(2 * np.pi * 0.9 * t)
    y = tone_signal([(torso, 1.0), (limb, limb_amplitude)], t)
    s = spectrogram(y, PRF, window_length=window, hop=hop, nfft=nfft)
    vel = radar.doppler_to_velocity(s.doppler, FC)
    resolution = LAMBDA / 2 / (window / PRF)  # velocity resolution of the window [m/s]
    return s.power, vel, resolution


@pytest.mark.parametrize("window", [128, 256, 512])
def test_features_of_a_synthetic_walk(window: int) -> None:
    power, vel, res = synthetic_walk(window)
    f = dict(zip(FEATURE_NAMES, spectrogram_features(power, vel), strict=True))
    assert f["torso_mean"] == pytest.approx(1.1, abs=res / 2)
    assert f["torso_bandwidth"] == pytest.approx(0.30, abs=res)
    assert f["upper_max"] == pytest.approx(3.7, abs=2 * res)
    assert f["lower_min"] == pytest.approx(-1.5, abs=2 * res)
    assert f["total_bandwidth"] == pytest.approx(f["upper_max"] - f["lower_min"], abs=1e-12)
    assert f["lower_min"] <= f["lower_mean"] <= f["torso_mean"] <= f["upper_mean"]
    assert f["upper_mean"] <= f["upper_max"]


def test_percentile_method_on_the_synthetic_walk() -> None:
    power, vel, res = synthetic_walk(256)
    f = dict(
        zip(
            FEATURE_NAMES,
            spectrogram_features(power, vel, method="percentile", floor_db=-60.0),
            strict=True,
        )
    )
    assert f["torso_mean"] == pytest.approx(1.1, abs=res)
    assert f["total_bandwidth"] == pytest.approx(f["upper_max"] - f["lower_min"], abs=1e-12)
    assert f["upper_max"] == pytest.approx(3.7, abs=3 * res)
    assert f["lower_min"] == pytest.approx(-1.5, abs=3 * res)


def test_the_datasets_page_quotes_the_synthetic_walk() -> None:
    """docs/datasets.md gives features 1-4 of this walk for both envelope methods (it once
    gave numbers of an older spectrogram for the threshold method), with every setting a
    reader needs to get them (it once left out the FFT size, whose default gives others)."""
    import re

    from conftest import ROOT

    page = " ".join((ROOT / "docs" / "datasets.md").read_text().split())
    quoted = re.search(
        r"threshold method gives ([-\d. /]+) m/s for features 1-4 .*?the percentile method "
        r"([-\d. /]+):",
        page,
    )
    assert quoted is not None
    setup = re.search(
        r"On a synthetic walk \((\d+) s of a torso at 1\.1 \+ 0\.15 sin\(2 pi 1\.8 t\) m/s and a "
        r"limb at 1\.1 \+ 2\.6 sin\(2 pi 0\.9 t\) m/s of amplitude ([\d.]+), -([\d.]+) dB, at "
        r"15 GHz; Hann window of (\d+) pulses at 2400 Hz, hop (\d+), a (\d+)-point FFT",
        page,
    )
    assert setup is not None
    length, amplitude, below_db, window, hop, nfft = setup.groups()
    assert float(below_db) == pytest.approx(-20 * np.log10(float(amplitude)), abs=0.05)
    power, vel, _ = synthetic_walk(
        int(window), int(hop), int(nfft), float(length), float(amplitude)
    )
    for text, options in zip(
        quoted.groups(), [{}, {"method": "percentile", "floor_db": -60.0}], strict=True
    ):
        page_values = [float(v) for v in text.split("/")]
        computed = spectrogram_features(power, vel, **options)[:4]  # type: ignore[arg-type]
        np.testing.assert_allclose(page_values, computed, atol=5e-4)


def test_exact_envelopes_of_a_drawn_spectrogram() -> None:
    """A spectrogram drawn directly: torso at bin k0, limbs exactly at known bins."""
    vel = np.linspace(-5, 5, 201)  # 0.05 m/s bins
    n_frames = 40
    power = np.full((201, n_frames), 1e-9)
    torso_v = 1.0 + 0.2 * np.sin(np.linspace(0, 2 * np.pi, n_frames, endpoint=False))
    limb_hi = 2.0 + 1.5 * np.sin(np.linspace(0, 2 * np.pi, n_frames, endpoint=False)) ** 2
    for m in range(n_frames):
        power[np.argmin(np.abs(vel - torso_v[m])), m] = 1.0
        power[np.argmin(np.abs(vel - limb_hi[m])), m] = 0.05  # -13 dB: inside -20 dB
        power[np.argmin(np.abs(vel + 0.5)), m] = 0.02  # lower limb at -0.5 m/s, -17 dB
        power[np.argmin(np.abs(vel + 2.0)), m] = 0.001  # -30 dB: outside the threshold
    env = envelopes(power, vel)
    snap = vel[np.argmin(np.abs(vel[:, None] - limb_hi[None, :]), axis=0)]
    assert np.allclose(env.upper, snap)
    assert np.allclose(env.lower, -0.5)
    f = spectrogram_features(power, vel)
    assert f[2] == pytest.approx(3.5) and f[3] == pytest.approx(-0.5)
    assert f[0] == pytest.approx(1.0, abs=0.05)
    assert f[1] == pytest.approx(0.4, abs=0.1)
    # with a -35 dB threshold the -30 dB line at -2 m/s becomes the lower envelope
    assert spectrogram_features(power, vel, threshold_db=-35.0)[3] == pytest.approx(-2.0)


def test_silent_frames_are_ignored_and_all_silent_is_an_error() -> None:
    vel = np.linspace(-1, 1, 11)
    power = np.zeros((11, 6))
    power[8, :3] = 1.0  # frames 3..5 silent
    env = envelopes(power, vel)
    assert np.all(np.isnan(env.torso[3:])) and np.allclose(env.torso[:3], vel[8])
    with pytest.raises(ValueError, match="silent"):
        spectrogram_features(np.zeros((11, 6)), vel)


def test_torso_median_ignores_a_limb_that_briefly_outshines_the_torso() -> None:
    """A body whose energy sits around 1 m/s (torso plus arms) and a leg that is the single
    strongest bin in a few frames: the peak track jumps to the leg, the median does not."""
    vel = np.linspace(-5, 5, 401)  # 0.025 m/s bins
    n_frames = 30
    power = np.full((401, n_frames), 1e-12)
    k_torso = np.argmin(np.abs(vel - 1.0))
    power[k_torso, :] = 1.0
    power[k_torso - 8 : k_torso + 9, :] += 0.2  # arms and hips around the torso
    jump = [10, 11, 12]
    power[np.argmin(np.abs(vel - 3.5)), jump] = 1.5  # a leg, briefly the strongest bin
    peak = envelopes(power, vel, torso_method="peak").torso
    median = envelopes(power, vel, torso_method="median").torso
    assert np.allclose(peak[jump], 3.5, atol=0.03)
    assert np.allclose(median, 1.0, atol=0.03)
    f_peak = spectrogram_features(power, vel, torso_method="peak")
    f_median = spectrogram_features(power, vel)
    assert f_peak[1] == pytest.approx(2.5, abs=0.05)  # torso bandwidth inflated by the leg
    assert f_median[1] == pytest.approx(0.0, abs=0.03)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_threshold_envelopes_match_a_per_column_loop(seed: int) -> None:
    """The vectorised threshold envelopes against a plain loop over the columns: in each live
    column, the highest and the lowest bin within ``threshold_db`` of the column's peak and
    above ``floor_db`` below the spectrogram's peak; NaN in silent columns. Exact."""
    rng = np.random.default_rng(seed)
    n_bins, n_frames = 64, 50
    power = rng.random((n_bins, n_frames)) ** 12  # a few strong bins per column
    power[:, ::7] *= 1e-8  # some columns below the floor: silent
    vel = np.sort(rng.uniform(-4.0, 4.0, n_bins))
    vel += np.arange(n_bins) * 1e-9  # strictly ascending
    env = envelopes(power, vel, threshold_db=-20.0, floor_db=-40.0)
    floor = power.max() * 10.0 ** (-40.0 / 10.0)
    for m in range(n_frames):
        col = power[:, m]
        keep = [k for k in range(n_bins) if col[k] >= floor and col[k] >= col.max() * 0.01]
        if not any(col >= floor):
            assert np.isnan(env.upper[m]) and np.isnan(env.lower[m])
            continue
        assert env.upper[m] == vel[max(keep)]
        assert env.lower[m] == vel[min(keep)]


def test_a_threshold_above_the_peak_is_refused() -> None:
    vel = np.linspace(-1, 1, 11)
    power = np.ones((11, 4))
    with pytest.raises(ValueError, match="threshold_db must be <= 0"):
        envelopes(power, vel, threshold_db=3.0)


def test_envelopes_at_the_band_edge_are_named() -> None:
    """A tone 30 dB above a white noise floor keeps its -20 dB envelope on the tone; 10 dB
    above it, the envelope reaches the band's edge in most columns, and a run's features say so
    (their extremes are the band's, not the body's)."""
    from mdframework.output import band_edge_message

    rng = np.random.default_rng(3)
    v = np.linspace(-5.0, 5.0, 64)
    for snr_db, expect in ((30.0, None), (10.0, " of 40 frames")):
        power = rng.exponential(1.0, size=(64, 40))  # noise, mean 1
        power[40] += 10.0 ** (snr_db / 10.0)  # a tone at +1.35 m/s
        env = envelopes(power, v)
        message = band_edge_message(env, v)
        if expect is None:
            assert message is None
            assert np.all(env.upper < v[-1]) and np.all(env.lower > v[0])
        else:
            assert message is not None and expect in message
            assert "-5.00 to +5.00 m/s" in message
            edge = np.isclose(env.upper, v[-1]) | np.isclose(env.lower, v[0])
            assert f"in {int(edge.sum())} of 40 frames" in message and edge.sum() >= 30


def test_envelopes_of_a_long_record_take_little_memory_beside_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A 300 s record's spectrogram (1024 x 22500 float32, 88 MiB): its envelopes used to take
    about 30 bytes per cell at once (660 MiB beside the spectrogram, 3 times what `mdf check`
    predicts for the run); worked a few columns at a time they take a few MiB, and every track
    is the one worked on the whole spectrogram at once (floor from the whole one's peak)."""
    import tracemalloc

    from mdframework import features

    rng = np.random.default_rng(3)
    power = rng.exponential(1.0, (1024, 22500)).astype(np.float32)
    power[:, ::7] *= 1e-6  # columns below the -40 dB floor of the whole peak: silent
    v = np.linspace(-12.0, 12.0, 1024)
    tracemalloc.start()
    try:
        env = envelopes(power, v, torso_method="median")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 0.1 * power.nbytes
    assert np.isnan(env.torso[::7]).all() and np.isfinite(env.torso[1::7]).all()
    default = features.ENVELOPE_CELLS
    monkeypatch.setattr(features, "ENVELOPE_CELLS", power.size)  # all at once
    for method in ("threshold", "percentile"):
        for torso in ("median", "peak"):
            chunked = envelopes(power, v, method=method, torso_method=torso)  # type: ignore[arg-type]
            monkeypatch.setattr(features, "ENVELOPE_CELLS", default)
            whole = envelopes(power, v, method=method, torso_method=torso)  # type: ignore[arg-type]
            monkeypatch.setattr(features, "ENVELOPE_CELLS", power.size)
            for a, b in zip(chunked.__dict__.values(), whole.__dict__.values(), strict=True):
                np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("percentiles", [(25.0, 50.0), (10.0, 60.0), (3.0, 97.0)])
def test_percentile_envelopes_are_the_inverted_cdf_quantiles(
    percentiles: tuple[float, float],
) -> None:
    """The percentile method's lower and upper envelopes and its median torso are, per column,
    the first velocity where the cumulative power reaches the fraction: numpy's weighted
    quantile (inverted CDF) of the velocities with the column's power as weights, on random
    columns (all above the floor) and on a flat column of 64 equal bins, where 25 % is reached
    exactly at bin 15 and 50 % at bin 31. Asymmetric percentiles catch an upper envelope
    taken as 1 - the lower percentile."""
    rng = np.random.default_rng(11)
    v = np.linspace(-4.0, 4.0, 64)
    power = rng.uniform(0.5, 2.0, (64, 12))
    power[:, 0] = 1.0
    env = envelopes(power, v, method="percentile", percentiles=percentiles, floor_db=-60.0)
    for col in range(power.shape[1]):
        q = [p / 100.0 for p in (*percentiles, 50.0)]
        ref = [np.quantile(v, x, weights=power[:, col], method="inverted_cdf") for x in q]
        got = [env.lower[col], env.upper[col], env.torso[col]]
        np.testing.assert_array_equal(got, ref)
    if percentiles == (25.0, 50.0):
        assert (env.lower[0], env.upper[0]) == (v[15], v[31])
