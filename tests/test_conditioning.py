"""Skeleton conditioning (``mdframework.conditioning``): time stamps, gaps, foot outliers, eq. (7),
foot length, speed limit. Synthetic bodies with known truth, plus real Kinect walking data."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mdframework import CANONICAL_JOINTS, Skeleton
from mdframework import conditioning as cond
from mdframework.sanity import _period_strength
from mdframework.settings import ConditioningConfig

DATA = Path(__file__).parents[1] / "examples" / "data" / "kinect"


def walking_body(n: int = 90, rate: float = 30.0) -> Skeleton:
    """A smooth canonical body: legs swinging at 1 Hz, feet 0.2 m long, walking at 1 m/s."""
    t = np.arange(n) / rate
    pos = np.zeros((n, 17, 3))
    for j, name in enumerate(CANONICAL_JOINTS):
        side = 0.1 if name.startswith("l_") else -0.1 if name.startswith("r_") else 0.0
        height = {"head": 1.7, "neck": 1.45, "base": 0.95}.get(name[2:] if side else name, 1.0)
        pos[:, j] = [0.0, side, height]
    phase = 2 * np.pi * t
    for side, sign in (("l", 1.0), ("r", -1.0)):
        swing = 0.3 * sign * np.sin(phase)
        idx = {k: CANONICAL_JOINTS.index(f"{side}_{k}") for k in ("hip", "knee", "ankle", "toe")}
        pos[:, idx["hip"], 2] = 0.95
        pos[:, idx["knee"]] = np.stack(
            [0.45 * np.sin(swing), pos[:, idx["knee"], 1], 0.95 - 0.45 * np.cos(swing)], 1
        )
        pos[:, idx["ankle"]] = pos[:, idx["knee"]] + np.stack(
            [0.45 * np.sin(swing), 0 * t, -0.45 * np.cos(swing)], 1
        )
        pos[:, idx["toe"]] = pos[:, idx["ankle"]] + np.stack(
            [0.2 * np.cos(swing), 0 * t, 0.2 * np.sin(swing) - 0.05], 1
        )
    pos[:, :, 0] += t[:, None] * 1.0
    return Skeleton(t, pos, CANONICAL_JOINTS)


def test_sort_timestamps_non_monotonic_and_duplicates() -> None:
    t = np.array([0.0, 0.1, 0.05, 0.1, 0.2, 0.15])
    pos = np.arange(6 * 2 * 3, dtype=float).reshape(6, 2, 3)
    ts, ps, ok, rep = cond.sort_timestamps(t, pos)
    assert np.all(np.diff(ts) > 0)
    assert list(ts) == [0.0, 0.05, 0.1, 0.15, 0.2]
    # the first of the duplicated 0.1 s frames (index 1) is kept, with its own positions
    assert np.array_equal(ps[2], pos[1]) and np.array_equal(ps[1], pos[2])
    assert rep["duplicates_dropped"] == 1 and rep["out_of_order"] > 0 and ok.all()


def test_nan_and_zero_gaps_bridged_and_long_gaps_flagged() -> None:
    body = walking_body()
    pos = body.positions.copy()
    k = CANONICAL_JOINTS.index("l_toe")
    pos[30:33, k] = np.nan  # 0.1 s: short
    pos[50:60, k] = 0.0  # exact zeros = untracked; 0.37 s: long
    valid = cond.untracked_mask(pos)
    assert not valid[31, k] and not valid[55, k] and valid[40, k]
    gaps = cond.find_gaps(body.time, valid)
    assert [(g[1], g[2]) for g in gaps] == [(30, 32), (50, 59)]
    sk = Skeleton(body.time, np.where(valid[..., None], pos, np.nan), CANONICAL_JOINTS, valid)
    out, rep = cond.condition(sk, ConditioningConfig(enabled=True, max_gap_s=0.2))
    assert np.all(np.isfinite(out.positions)) and out.valid.all()
    assert [g["first_frame"] for g in rep["gaps"]["long_gaps"]] == [50]
    assert np.max(np.abs(out.positions[30:33, k] - body.positions[30:33, k])) < 0.01
    with pytest.raises(ValueError, match="untracked for"):
        cond.condition(sk, ConditioningConfig(enabled=True, long_gaps="error"))


def test_planted_foot_outlier_found_and_corrected() -> None:
    body = walking_body()
    pos = body.positions.copy()
    k = CANONICAL_JOINTS.index("r_toe")
    truth = pos[40, k].copy()
    pos[40, k] += [0.35, 0.1, 0.2]  # a Kinect foot jump
    sk = body.with_positions(pos)
    out, rep = cond.condition(sk, ConditioningConfig(enabled=True, speed_limit=False))
    fixed = rep["foot_outliers"]["r_ankle->r_toe"]
    assert [c["frame"] for c in fixed["corrected"]] == [40]
    assert fixed["corrected"][0]["direction"] in ("forward", "backward")
    # predicted from the past: close to the truth (the foot turns a little in one frame)
    assert np.linalg.norm(out.positions[40, k] - truth) < 0.05
    # everything else untouched, bit for bit
    mask = np.ones(pos.shape[:2], bool)
    mask[40, k] = False
    assert np.array_equal(out.positions[mask], pos[mask])
    assert rep["foot_outliers"]["l_ankle->l_toe"]["n_outliers"] == 0


def test_clean_data_untouched() -> None:
    body = walking_body()
    out, rep = cond.condition(body, ConditioningConfig(enabled=True))
    assert np.array_equal(out.positions, body.positions)
    assert rep["speed_limit"]["joints"] == {}
    assert rep["gaps"]["samples_bridged"] == 0
    period = rep["knee_ankle_foot_angle"]["l"]["period_s"]
    assert period == pytest.approx(1.0, abs=0.05)


def test_histogram_threshold_separates_jumps() -> None:
    rng = np.random.default_rng(3)
    dev = np.abs(rng.normal(0, 0.01, 200))
    assert cond.histogram_threshold(dev, 0.01, 0.05) == float("inf") or np.all(
        dev <= cond.histogram_threshold(dev, 0.01, 0.05)
    )
    thr = cond.histogram_threshold(np.append(dev, [0.4, 0.5]), 0.01, 0.05)
    assert dev.max() <= thr < 0.4


@pytest.mark.parametrize("angle", [0.0, 1e-8, 1e-4, np.pi / 3, np.pi - 1e-8, np.pi])
def test_eq7_angle_parallel_and_near_parallel(angle: float) -> None:
    ankle = np.array([0.3, -0.2, 0.1])
    knee = ankle + 0.4 * np.array([0.0, 0.0, 1.0])
    foot = ankle + 0.2 * np.array([np.sin(angle), 0.0, np.cos(angle)])
    theta = cond.knee_ankle_foot_angle(knee, ankle, foot)
    assert theta == pytest.approx(angle, rel=1e-6, abs=1e-15)
    if angle == 0.0:  # arccos would give ~1.5e-8 here; atan2 gives exactly 0
        assert theta == 0.0


def test_eq7_angle_of_a_typical_leg_agrees_with_arccos() -> None:
    """Section 5: on a typical standing leg (the foot at 101.4914390881 deg to the shank) the
    stable atan2 form and the paper's arccos form agree to 1e-10 deg, and both give the angle
    the leg was built with."""
    want = np.deg2rad(101.4914390881)
    ankle = np.array([0.12, 0.31, 0.08])
    knee = ankle + 0.42 * np.array([0.05, -0.02, 1.0]) / np.linalg.norm([0.05, -0.02, 1.0])
    shank = (knee - ankle) / np.linalg.norm(knee - ankle)
    side = np.cross(shank, [1.0, 0.0, 0.0])
    side /= np.linalg.norm(side)
    foot = ankle + 0.21 * (np.cos(want) * shank + np.sin(want) * np.cross(side, shank))
    theta = float(cond.knee_ankle_foot_angle(knee, ankle, foot))
    v1, v2 = knee - ankle, foot - ankle
    by_arccos = float(np.arccos(v1 @ v2 / (np.linalg.norm(v1) * np.linalg.norm(v2))))
    assert abs(np.rad2deg(theta - by_arccos)) < 1e-10
    assert np.rad2deg(theta) == pytest.approx(101.4914390881, abs=1e-10)


def test_foot_length_correction() -> None:
    body = walking_body()
    a, t = body.joint("l_ankle"), body.joint("l_toe")
    new = cond.correct_foot_length(a, t, 0.26)
    assert np.allclose(np.linalg.norm(new - a, axis=1), 0.26)
    unit_old = (t - a) / np.linalg.norm(t - a, axis=1, keepdims=True)
    assert np.allclose((new - a) / 0.26, unit_old)


def test_speed_limit_removes_spike_only() -> None:
    t = np.cumsum(np.r_[0, np.full(59, 1 / 30)])
    track = np.stack([np.sin(2 * np.pi * t) * 0.2, 0 * t, 0 * t], 1)
    spiked = track.copy()
    spiked[20] += [0.3, 0.0, 0.0]  # 9 m/s in and out
    assert cond.speeds(t, spiked).max() > 8.5
    out, replaced = cond.limit_speed(t, spiked, 6.0)
    assert list(np.flatnonzero(replaced)) == [20]
    assert cond.speeds(t, out).max() < 6.0
    assert np.array_equal(out[~replaced], spiked[~replaced])


def test_real_kinect_walk_feet_slower_after_conditioning() -> None:
    from mdf_kinect import KinectConfig, KinectSource

    motion = KinectSource(
        KinectConfig(
            format="utkinect", file=DATA / "utkinect" / "joints_s01_e01.txt", segment="walk"
        )
    ).load()
    body = motion.canonical()
    out, _ = cond.condition(body, ConditioningConfig(enabled=True, max_speed_mps=4.0))
    for toe in ("l_toe", "r_toe"):
        before = cond.speeds(body.time, body.joint(toe)).max()
        after = cond.speeds(out.time, out.joint(toe)).max()
        assert after <= min(before, 4.0) + 1e-9


def test_smoothing_all_smooths_with_or_without_the_speed_limit() -> None:
    """`smoothing = "all"` smooths every joint also when `speed_limit = false` (it was silently
    skipped). Jitter of 1 cm, white, at 30 Hz on a still body: a Gaussian of 0.1 s (3 frames)
    leaves sqrt(sum w_k^2) of its standard deviation (w the normalised kernel, cut at 3 sigma:
    0.307), computed here from the kernel alone; the same as with a limit no joint reaches;
    `"none"` leaves the body as it was."""
    rng = np.random.default_rng(0)
    t = np.arange(400) / 30.0
    still = np.ones((t.size, len(CANONICAL_JOINTS), 3))
    jitter = rng.normal(0.0, 0.01, still.shape)
    body = Skeleton(t, still + jitter, CANONICAL_JOINTS)

    def conditioned(**kw: object) -> tuple[np.ndarray, dict[str, object]]:
        cfg = ConditioningConfig(
            enabled=True, foot_outliers=False, angle_check=False, smoothing_sigma_s=0.1, **kw
        )
        out, report = cond.condition(body, cfg)
        return out.positions, report

    smoothed, report = conditioned(speed_limit=False, smoothing="all")
    k = np.arange(-9, 10)
    w = np.exp(-0.5 * (k / 3.0) ** 2)
    expected = np.sqrt(np.sum((w / w.sum()) ** 2))
    inner = slice(9, -9)  # away from the ends, where the kernel is cut
    ratio = np.std(smoothed[inner] - still[inner]) / np.std(jitter[inner])
    assert ratio == pytest.approx(expected, rel=0.05)
    assert report["smoothing"] == {
        "smoothing": "all",
        "smoothing_sigma_s": 0.1,
        "joints": list(CANONICAL_JOINTS),
    }
    limited, _ = conditioned(speed_limit=True, max_speed_mps=100.0, smoothing="all")
    assert np.allclose(smoothed, limited, rtol=0, atol=1e-15)
    untouched, _ = conditioned(speed_limit=False, smoothing="none")
    assert np.array_equal(untouched, body.positions)


def test_gap_duration_spans_the_valid_frames_around_it() -> None:
    """A joint untracked in frames 10..19 at 100 Hz: the gap lasts from frame 9 to frame 20,
    0.11 s (what max_gap_s is compared with); one at the record's start runs from frame 0."""
    time = np.arange(50) / 100.0
    valid = np.ones((50, 2), dtype=bool)
    valid[10:20, 1] = False
    valid[0:5, 0] = False
    gaps = cond.find_gaps(time, valid)
    assert [(j, s, e) for j, s, e, _ in gaps] == [(0, 0, 4), (1, 10, 19)]
    assert gaps[0][3] == pytest.approx(0.05, abs=1e-12)
    assert gaps[1][3] == pytest.approx(0.11, abs=1e-12)


def test_bridging_holds_the_nearest_sample_outside_the_valid_span() -> None:
    """Untracked first and last frames take the first / last valid sample (no spline
    extrapolation); an inner gap of a straight line at constant speed is filled exactly."""
    time = np.arange(20) / 10.0
    pos = np.zeros((20, 1, 3))
    pos[:, 0, 0] = 1.0 + 2.0 * time
    pos[:, 0, 2] = (time - 1.0) ** 2  # curved: an extrapolated spline would leave 1.0 .. 0.25
    valid = np.ones((20, 1), dtype=bool)
    valid[:3] = valid[-3:] = valid[8:11] = False
    out = cond.bridge_gaps(time, pos, valid)
    np.testing.assert_allclose(out[:3, 0], np.repeat(pos[3:4, 0], 3, axis=0), atol=1e-12)
    np.testing.assert_allclose(out[-3:, 0], np.repeat(pos[16:17, 0], 3, axis=0), atol=1e-12)
    np.testing.assert_allclose(out[8:11, 0], pos[8:11, 0], atol=1e-12)


def test_histogram_threshold_is_the_lower_edge_of_the_first_empty_bin() -> None:
    """Deviations filling bins [0, 0.01) and [0.01, 0.02), jumps at 0.2: the threshold is
    0.02 (minimum 0), or the minimum when that is higher."""
    dev = np.concatenate([np.full(50, 0.005), np.full(30, 0.015), [0.2, 0.21]])
    assert cond.histogram_threshold(dev, 0.01, 0.0) == pytest.approx(0.02, abs=1e-12)
    assert cond.histogram_threshold(dev, 0.01, 0.05) == pytest.approx(0.05, abs=1e-12)


def test_foot_outliers_are_judged_against_the_inliers_mean() -> None:
    """70 frames of a 20 cm foot, 15 with the toe 7 cm up and 15 with it 50 cm up: against the
    mean of all frames (pulled up 8.6 cm) only the 50 cm jumps stand out; against the inliers'
    mean, as the outliers must not bias it, the 7 cm jumps are outliers too."""
    n = 100
    ankle = np.zeros((n, 3))
    toe = np.tile([0.2, 0.0, 0.0], (n, 1))
    toe[70:85, 2] = 0.07
    toe[85:, 2] = 0.5
    out, thr, dev = cond.foot_outliers(ankle, toe)
    assert not out[:70].any() and out[70:].all()
    assert thr == pytest.approx(0.05)
    np.testing.assert_allclose(dev[:70], 0.07 * 15 / 85, atol=1e-12)


def test_periodicity_of_a_sinusoid() -> None:
    """A 1 s sinusoid sampled at 50 Hz for 3 s: period 1.0 s (lag 50 frames of 20 ms, to a
    fiftieth of a frame); the autocorrelation there is the overlap, 2 s of 3."""
    time = np.arange(151) / 50.0
    found = cond.periodicity(time, np.sin(2 * np.pi * time))
    assert found["period_s"] == pytest.approx(1.0, abs=0.02 / 50)
    assert found["strength"] == pytest.approx(101 / 151, abs=0.01)


@pytest.mark.parametrize("rate", [15.0, 30.0, 120.0])
@pytest.mark.parametrize("duration", [2.0, 2.5, 3.0, 10.0])
@pytest.mark.parametrize("period", [0.9, 1.1])
def test_the_period_of_a_short_record_is_not_drawn_towards_lag_0(
    rate: float, duration: float, period: float
) -> None:
    """A gait-like signal (a fundamental and its second harmonic) whose period is not a whole
    number of frames, in records of two to eleven periods: the period to 0.5 %, from the
    dominant period (conditioning) and from the first clear period (the sanity checks'
    cadence), and the autocorrelation there near the overlap 1 - period / duration. The
    autocorrelation divided by the whole record's energy falls with the overlap, which moved
    its peak: a 1.1 s period in 3 s at 30 Hz came out at 1.067 s (a frame early), at 120 Hz
    at 1.078 s."""
    time = np.arange(0.0, duration, 1.0 / rate)
    signal = np.sin(2 * np.pi * time / period) + 0.3 * np.sin(4 * np.pi * time / period + 1.0)
    dominant = cond.periodicity(time, signal)
    assert dominant["period_s"] == pytest.approx(period, rel=0.005)
    assert dominant["strength"] == pytest.approx(1 - period / duration, abs=0.05)
    first = _period_strength(time, signal)
    assert first is not None
    assert first[0] == pytest.approx(period, rel=0.005)
    assert first[1] == pytest.approx(1 - period / duration, abs=0.05)


def test_the_dominant_period_of_a_long_noisy_record_is_not_a_multiple() -> None:
    """Ten minutes at 120 Hz of a 1.1 s sinusoid in white noise of its own amplitude: the
    autocorrelation is about 0.33 at every multiple of the period, within its noise (about
    1/sqrt(n) = 0.004) of each other; the highest was at 2.2 s. The first peak within 0.9 of
    the highest is the period (to 5 %: the noise moves the peak by a few lags)."""
    time = np.arange(72000) / 120.0
    noise = np.random.default_rng(0).normal(0.0, 1.0, time.size)
    found = cond.periodicity(time, np.sin(2 * np.pi * time / 1.1) + noise)
    assert found["period_s"] == pytest.approx(1.1, rel=0.05)
    assert found["strength"] == pytest.approx(1 / 3, abs=0.02)


def test_a_signal_without_a_zero_crossing_has_no_period() -> None:
    """A constant has no autocorrelation and a slow swell of less than half a period never
    correlates negatively with itself: no period."""
    time = np.arange(0.0, 2.0, 1.0 / 15.0)
    none = {"period_s": None, "strength": 0.0}
    assert cond.periodicity(time, np.full_like(time, 3.0)) == none
    assert cond.periodicity(time, np.sin(np.pi * time / 5.0)) == none
    assert _period_strength(time, np.sin(np.pi * time / 5.0)) is None
    assert _period_strength(time, np.full_like(time, 3.0)) is None


def test_a_peak_of_exactly_min_strength_is_a_clear_period() -> None:
    """The first peak counts when its autocorrelation equals ``min_strength``."""
    time = np.arange(0.0, 3.0, 1.0 / 30.0)
    signal = np.sin(2 * np.pi * time / 1.1)
    found = _period_strength(time, signal)
    assert found is not None
    assert _period_strength(time, signal, min_strength=found[1]) == found


def test_a_missing_stretch_just_over_max_gap_s_is_refused() -> None:
    """Frames missing for 0.3 s (the step between the frames around the hole) with
    max_gap_s = 0.2 and long_gaps = "error": refused, naming the hole."""
    time = np.concatenate([np.arange(20) / 100.0, 0.49 + np.arange(20) / 100.0])
    pos = np.zeros((40, len(CANONICAL_JOINTS), 3)) + 1.0 + np.arange(len(CANONICAL_JOINTS))[:, None]
    sk = Skeleton(time, pos, CANONICAL_JOINTS)
    with pytest.raises(ValueError, match=r"no frame for 0\.300 s \(after frame 19 at 0\.190 s\)"):
        cond.condition(sk, ConditioningConfig(enabled=True, max_gap_s=0.2, long_gaps="error"))
    cond.condition(sk, ConditioningConfig(enabled=True, max_gap_s=0.35, long_gaps="error"))


def test_skeleton_window_counts_from_the_first_frame_and_includes_both_ends() -> None:
    """A recording whose clock starts at 10 s: window(start=0.2, duration=0.3) keeps the frames
    0.2 .. 0.5 s after its first frame, both ends included (4 frames at 10 Hz)."""
    time = 10.0 + np.arange(11) / 10.0
    sk = Skeleton(time, np.zeros((11, 1, 3)) + time[:, None, None], ("a",))
    w = sk.window(0.2, 0.3)
    np.testing.assert_allclose(w.time, [10.2, 10.3, 10.4, 10.5], atol=1e-12)
    assert sk.window(0.5).n_frames == 6


def test_the_motion_formats_page_quotes_the_bias_it_removed() -> None:
    """docs/motion-formats.md: a 1.1 s period in 3 s at 30 frames per second "read a frame
    early, 3 % short" from the biased autocorrelation's highest whole lag, and the estimator
    now reads it to 0.5 %."""
    from conftest import ROOT

    time = np.arange(0.0, 3.0, 1.0 / 30.0)
    signal = np.sin(2 * np.pi * time / 1.1) + 0.3 * np.sin(4 * np.pi * time / 1.1 + 1.0)
    found = cond.lag_correlation(time, signal)
    assert found is not None
    biased = found[0]
    start = int(np.flatnonzero(biased < 0)[0])
    old_lag = start + int(np.argmax(biased[start:]))  # the estimator before
    assert old_lag == 32 and round(1.1 * 30) - old_lag == 1  # a frame early
    short = 100 * (1.1 - old_lag / 30) / 1.1
    page = " ".join((ROOT / "docs" / "motion-formats.md").read_text().split())
    assert (
        f"a 1.1 s period in 3 s at 30 frames per second read a frame early, {short:.0f} % short"
        in page
    )
    assert cond.periodicity(time, signal)["period_s"] == pytest.approx(1.1, rel=0.005)


def test_lag_correlation_needs_eight_samples_over_a_rising_clock() -> None:
    """Eight samples are enough, seven are not; a clock that runs backwards has no time span."""
    time = np.arange(8) / 10.0
    signal = np.sin(7.0 * time)
    assert cond.lag_correlation(time, signal) is not None
    assert cond.lag_correlation(time[:7], signal[:7]) is None
    assert cond.lag_correlation(time[::-1], signal) is None


def test_correlation_peaks_fall_back_on_the_biased_parabola() -> None:
    """Hand-made correlations. Where the normalised values rise to the last lag or fall all the
    way from lag 0 (no peak to climb to), the lag is the top of the biased peak's parabola:
    3 + 0.5 (b2 - b4) / (b2 - 2 b3 + b4), also for a peak at the last inner lag n - 2."""
    biased = np.array([1.0, -0.5, 0.0, 0.2, 0.1])
    rising = np.array([1.0, -0.5, 0.0, 0.6, 0.9])
    top = 0.2 - 0.25 * (0.0 - 0.1) * (0.5 * (0.0 - 0.1) / -0.3)
    assert cond.correlation_peaks(biased, rising) == [pytest.approx((3 + 1 / 6, top))]
    biased = np.array([1.0, -0.2, 0.1, 0.3, 0.2, -0.1, 0.0])
    falling = np.linspace(1.0, 0.4, 7)
    assert cond.correlation_peaks(biased, falling) == [pytest.approx((3 + 1 / 6, 0.30417), 1e-4)]


def test_correlation_peaks_climb_down_to_an_earlier_normalised_peak() -> None:
    """The normalised peak one lag before the biased one (lag 3, parabola to 3.3): the climb
    goes down to it."""
    biased = np.array([1.0, -0.2, 0.1, 0.2, 0.3, 0.1, 0.0])
    normalised = np.array([1.0, -0.2, 0.5, 0.9, 0.8, 0.4, 0.0])
    assert cond.correlation_peaks(biased, normalised)[0][0] == pytest.approx(3.3)


def test_correlation_peaks_of_a_flat_top_are_finite() -> None:
    """Three equal values at lags 2..4, in both correlations: no parabola (no division by its
    zero curvature); every peak found lies on the plateau."""
    biased = np.array([1.0, -0.2, 0.3, 0.3, 0.3, 0.1, 0.0])
    normalised = np.array([1.0, -0.2, 0.5, 0.5, 0.5, 0.4, 0.0])
    lags = [lag for lag, _ in cond.correlation_peaks(biased, normalised)]
    assert lags and all(2.0 <= lag <= 4.0 for lag in lags)


def test_the_dominant_period_is_not_a_strong_harmonic_and_its_strength_is_its_own() -> None:
    """20 s at 30 Hz. A 1 s sinusoid plus a stronger 0.25 s one (power 1.5): the
    autocorrelation peaks at 0.25 s at 0.6 of the 1 s peak, short of 0.9: period 1 s. A 1 s
    sinusoid plus a 2 s one of amplitude 0.2: the 2 s peak is the highest (0.9 = the
    overlap), the 1 s one reaches (1 - 0.04) / 1.04 x 0.95 = 0.877 and is the period, and
    its strength is its own value, not the highest."""
    time = np.arange(0.0, 20.0, 1 / 30.0)
    harmonic = np.sin(2 * np.pi * time) + np.sqrt(1.5) * np.sin(8 * np.pi * time)
    assert cond.periodicity(time, harmonic)["period_s"] == pytest.approx(1.0, abs=0.005)
    found = cond.periodicity(time, np.sin(2 * np.pi * time) + 0.2 * np.sin(np.pi * time))
    assert found["period_s"] == pytest.approx(1.0, abs=0.005)
    assert found["strength"] == pytest.approx(0.96 / 1.04 * 0.95, abs=0.005)
