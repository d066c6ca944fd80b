"""Point clouds -> per-frame Doppler histograms -> features (mdframework.pointcloud)."""

from __future__ import annotations

import numpy as np
import pytest

from mdframework.features import FEATURE_NAMES
from mdframework.pointcloud import (
    HistogramSettings,
    PointCloud,
    cloud_histograms,
    doppler_histograms,
    frames_from_point_ids,
    histogram_features,
    histogram_vector,
    point_weights,
    range_rate_to_approaching,
    velocity_bins,
)

W = 0.61466867


def test_bins_are_centred_on_multiples_of_the_width() -> None:
    centres, edges = velocity_bins(W, 17)
    assert centres[8] == 0.0
    np.testing.assert_allclose(centres, (np.arange(17) - 8) * W, rtol=0, atol=1e-12)
    np.testing.assert_allclose(edges[1:] - edges[:-1], W, rtol=1e-12)
    np.testing.assert_allclose(0.5 * (edges[1:] + edges[:-1]), centres, atol=1e-12)
    with pytest.raises(ValueError, match="odd"):
        velocity_bins(W, 16)


def test_histograms_match_numpy_histogram_frame_by_frame(rng: np.random.Generator) -> None:
    n_frames, n = 20, 3000
    frame = np.sort(rng.integers(0, n_frames, n))
    velocity = rng.uniform(-7.0, 7.0, n)  # some beyond the outer bins
    weights = rng.uniform(0.0, 3.0, n)
    _, edges = velocity_bins(W, 17)
    hist = doppler_histograms(frame, velocity, n_frames, edges, weights)
    for f in range(n_frames):
        sel = frame == f
        ref, _ = np.histogram(velocity[sel], bins=edges, weights=weights[sel])
        np.testing.assert_allclose(hist[f], ref, rtol=1e-12, atol=1e-12)


def test_quantised_sensor_velocities_fall_in_their_own_bins() -> None:
    """A sensor's velocities are whole multiples of its bin: each lands in the bin centred on
    it, also for the extreme bins and with float32 rounding."""
    k = np.arange(-8, 9)
    v = (k * W).astype(np.float32).astype(np.float64)
    _, edges = velocity_bins(W, 17)
    hist = doppler_histograms(np.zeros(17, np.int64), v, 1, edges)
    np.testing.assert_array_equal(hist[0], np.ones(17))


def test_a_point_on_an_inner_edge_goes_up_and_outside_points_are_dropped() -> None:
    _, edges = velocity_bins(1.0, 3)  # edges -1.5, -0.5, 0.5, 1.5
    hist = doppler_histograms(np.zeros(4, np.int64), np.array([0.5, -0.5, 1.5, -1.6]), 1, edges)
    np.testing.assert_array_equal(hist[0], [0.0, 1.0, 1.0])


def test_empty_frames_stay_zero_and_frames_from_point_ids() -> None:
    ids = np.array([0, 1, 2, 0, 1, 0])
    np.testing.assert_array_equal(frames_from_point_ids(ids), [0, 0, 0, 1, 1, 2])
    with pytest.raises(ValueError, match="first point"):
        frames_from_point_ids(np.array([1, 0]))
    _, edges = velocity_bins(W, 5)
    hist = doppler_histograms(np.array([0, 3]), np.array([0.0, W]), 5, edges)
    assert hist.shape == (5, 5) and hist[[1, 2, 4]].sum() == 0.0
    assert hist[0, 2] == 1.0 and hist[3, 3] == 1.0


def test_weights_and_sign() -> None:
    db = np.array([-3.0, 0.0, 10.0, 20.0])
    np.testing.assert_allclose(point_weights(db, "power"), [10**-0.3, 1.0, 10.0, 100.0])
    np.testing.assert_array_equal(point_weights(db, "intensity"), [0.0, 0.0, 10.0, 20.0])
    np.testing.assert_array_equal(point_weights(db, "count"), np.ones(4))
    # a range rate of -1 m/s (closing in) is +1 m/s approaching
    np.testing.assert_array_equal(range_rate_to_approaching(np.array([-1.0, 2.0])), [1.0, -2.0])


def _cloud(frame: list[int], pos: list[list[float]], vel: list[float], n_frames: int) -> PointCloud:
    n = len(frame)
    return PointCloud(
        np.array(frame, np.int64),
        np.array(pos, np.float64),
        np.array(vel, np.float64),
        np.zeros(n),
        0.05,
        n_frames,
    )


def test_range_gate_and_window_renumbering() -> None:
    cloud = _cloud(
        [0, 0, 1, 2, 2],
        [[0, 1, 0], [0, 5, 0], [0, 2, 0], [0.3, 0, 0], [0, 1.5, 0.5]],
        [0.0, W, -W, 0.0, 2 * W],
        3,
    )
    hist = cloud_histograms(cloud, HistogramSettings(n_bins=5, min_range=0.5, max_range=3.0))
    # the point at 5 m and the one at 0.3 m are outside the gate
    np.testing.assert_array_equal(hist.sum(axis=1), [1, 1, 1])
    assert hist[0, 2] == 1 and hist[1, 1] == 1 and hist[2, 4] == 1
    sub = cloud.frames(1, 2)
    np.testing.assert_array_equal(sub.frame, [0, 1, 1])
    assert sub.n_frames == 2
    with pytest.raises(ValueError, match="outside"):
        cloud.frames(2, 2)


def test_features_of_a_hand_built_window() -> None:
    """Every frame: 10 static points and one point at +k bins (k = 1, 2, 3, 2, 1, ...), and in
    frame 4 one point at -2 bins. The static points hold the torso (median) at 0; the upper
    envelope follows the moving point (within -20 dB of 10 points: 1/10 = -10 dB)."""
    centres, _ = velocity_bins(W, 17)
    ks = [1, 2, 3, 2, 1, 2]
    hist = np.zeros((6, 17))
    for f, k in enumerate(ks):
        hist[f, 8] = 10.0
        hist[f, 8 + k] = 1.0
    hist[4, 6] = 1.0
    feats = dict(zip(FEATURE_NAMES, histogram_features(hist, centres), strict=True))
    assert feats["torso_mean"] == 0.0 and feats["torso_bandwidth"] == 0.0
    assert feats["upper_max"] == pytest.approx(3 * W)
    assert feats["lower_min"] == pytest.approx(-2 * W)
    assert feats["total_bandwidth"] == pytest.approx(5 * W)
    assert feats["upper_mean"] == pytest.approx(np.mean(ks) * W)
    assert feats["lower_mean"] == pytest.approx(-2 * W / 6)
    with pytest.raises(ValueError, match="silent"):
        histogram_features(np.zeros((4, 17)), centres)


def test_histogram_vector_normalises_each_live_frame() -> None:
    hist = np.array([[2.0, 2.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1.0, 3.0]])
    vec = histogram_vector(hist)
    shares = np.array([[0.5, 0.5, 0.0], [0.0, 0.25, 0.75]])  # the empty frame is left out
    np.testing.assert_allclose(vec[:3], shares.mean(axis=0))
    np.testing.assert_allclose(vec[3:], shares.std(axis=0))
    # scaling a frame's counts changes nothing (shares)
    np.testing.assert_allclose(histogram_vector(hist * np.array([[3.0], [1.0], [7.0]])), vec)
    np.testing.assert_array_equal(histogram_vector(np.zeros((2, 3))), np.zeros(6))
