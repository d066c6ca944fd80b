"""Radar point clouds -> per-frame Doppler histograms -> classifier inputs (pure functions).

One representation for real and simulated radars that output point clouds (a single-chip FMCW
sensor's detections, real or simulated): every frame's detected points become a histogram of
radial velocity, optionally weighted by the points' intensity, and a window of frames becomes

- the seven features of :mod:`mdframework.features`, computed on the histograms as if they were
  a spectrogram (velocity bins x frames), and
- a fixed-length histogram vector (:func:`histogram_vector`).

Conventions (binding for every caller):

- ``frame`` (n_points,) int64: frame index of each point, 0-based, ascending within a record;
- ``positions`` (n_points, 3) float64 [m] in the sensor frame (x right, y boresight, z up);
- ``velocity`` (n_points,) float64 [m/s]: radial velocity, **positive approaching** (a sensor
  that reports range rate, positive receding, is converted by its reader with
  :func:`range_rate_to_approaching`);
- ``intensity`` (n_points,) float64 [dB]: the sensor's per-point signal level (for the TI
  driver, the detection's SNR-like peak value in dB).

A histogram array is ``(n_frames, n_bins)`` float64: per frame, the count (or weight sum) of the
points in each velocity bin; bins are centred on multiples of ``bin_width`` (0 in the middle, so
static returns fall in the centre bin) and points beyond the outer bins are dropped.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from .features import FEATURE_NAMES, spectrogram_features

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

Weighting = Literal["count", "intensity", "power"]

#: Velocity bin of the TI IWR1443 ``1443es1_short_range_3d`` configuration [m/s]
#: (16 chirp loops per frame at a 79.21 GHz centre frequency, as the driver scales it).
IWR1443_BIN_WIDTH = 0.61466867


@dataclass(frozen=True)
class PointCloud:
    """Detected points of one recording (see the module docstring for the arrays).

    ``frame_period`` [s] is the sensor's frame period; frame ``k`` is at ``k * frame_period``
    from the start of the recording. ``n_frames`` counts every frame, including frames without a
    point, so it may exceed ``frame.max() + 1``.
    """

    frame: IntArray
    positions: FloatArray
    velocity: FloatArray
    intensity: FloatArray
    frame_period: float
    n_frames: int

    def __post_init__(self) -> None:
        n = self.frame.shape[0]
        if self.positions.shape != (n, 3):
            raise ValueError(f"positions must be ({n}, 3), got {self.positions.shape}")
        if self.velocity.shape != (n,) or self.intensity.shape != (n,):
            raise ValueError("frame, velocity and intensity must have one value per point")
        if n and (self.frame.min() < 0 or self.frame.max() >= self.n_frames):
            raise ValueError(f"frame indices must lie in [0, {self.n_frames})")
        if not self.frame_period > 0:
            raise ValueError("frame_period must be positive")

    @property
    def ranges(self) -> FloatArray:
        """Distance of every point to the sensor, (n_points,) float64 [m]."""
        return np.asarray(np.linalg.norm(self.positions, axis=1), dtype=np.float64)

    def select(self, mask: NDArray[np.bool_]) -> PointCloud:
        """The points where ``mask`` (n_points,) is true (same frames)."""
        return PointCloud(
            self.frame[mask],
            self.positions[mask],
            self.velocity[mask],
            self.intensity[mask],
            self.frame_period,
            self.n_frames,
        )

    def frames(self, first: int, count: int) -> PointCloud:
        """Frames ``first .. first + count - 1``, renumbered from 0."""
        if first < 0 or count < 1 or first + count > self.n_frames:
            raise ValueError(f"frames {first}..{first + count - 1} outside 0..{self.n_frames - 1}")
        mask = (self.frame >= first) & (self.frame < first + count)
        sub = self.select(mask)
        return PointCloud(
            sub.frame - first,
            sub.positions,
            sub.velocity,
            sub.intensity,
            self.frame_period,
            count,
        )


def range_rate_to_approaching(range_rate: FloatArray) -> FloatArray:
    """Radial velocity positive approaching [m/s] from a range rate (positive receding)."""
    return np.asarray(-np.asarray(range_rate, dtype=np.float64), dtype=np.float64)


def frames_from_point_ids(point_id: NDArray[np.integer]) -> IntArray:
    """Frame index of every point of a stream in which each frame's points are numbered from 0.

    ``point_id`` (n_points,) int, in stream order. A new frame starts at every ``point_id == 0``
    (the first point must have id 0). Returns (n_points,) int64, 0-based.
    """
    ids = np.asarray(point_id)
    if ids.size == 0:
        return np.zeros(0, dtype=np.int64)
    if ids[0] != 0:
        raise ValueError(f"the first point has point_id {int(ids[0])}, not 0")
    return np.asarray(np.cumsum(ids == 0) - 1, dtype=np.int64)


def velocity_bins(bin_width: float, n_bins: int) -> tuple[FloatArray, FloatArray]:
    """Centres (n_bins,) and edges (n_bins + 1,) [m/s] of ``n_bins`` (odd) velocity bins of
    width ``bin_width`` centred on 0, ascending."""
    if n_bins < 1 or n_bins % 2 == 0:
        raise ValueError(f"n_bins must be odd and positive, got {n_bins}")
    if not bin_width > 0:
        raise ValueError(f"bin_width must be positive, got {bin_width}")
    half = n_bins // 2
    centres = np.arange(-half, half + 1, dtype=np.float64) * bin_width
    edges = np.arange(-half - 0.5, half + 1.0, dtype=np.float64) * bin_width
    return centres, edges


def point_weights(intensity: FloatArray, weighting: Weighting) -> FloatArray:
    """Weight of each point: 1 (``count``), its intensity in dB clipped at 0 (``intensity``),
    or its linear power ``10^(dB/10)`` (``power``). (n_points,) float64."""
    level = np.asarray(intensity, dtype=np.float64)
    if weighting == "count":
        return np.ones_like(level)
    if weighting == "intensity":
        return np.clip(level, 0.0, None)
    if weighting == "power":
        return np.asarray(10.0 ** (level / 10.0), dtype=np.float64)
    raise ValueError(f"unknown weighting {weighting!r}")


def doppler_histograms(
    frame: IntArray,
    velocity: FloatArray,
    n_frames: int,
    edges: FloatArray,
    weights: FloatArray | None = None,
) -> FloatArray:
    """Per-frame velocity histograms, (n_frames, n_bins) float64.

    ``frame`` (n_points,) 0-based frame indices < ``n_frames``; ``velocity`` (n_points,) [m/s];
    ``edges`` (n_bins + 1,) ascending [m/s]; ``weights`` (n_points,) or None (counts). A point
    on an inner edge goes to the upper bin; points outside ``[edges[0], edges[-1])`` are dropped.
    """
    f = np.asarray(frame, dtype=np.int64)
    v = np.asarray(velocity, dtype=np.float64)
    e = np.asarray(edges, dtype=np.float64)
    n_bins = e.size - 1
    b = np.searchsorted(e, v, side="right") - 1
    keep = (b >= 0) & (b < n_bins)
    w = np.ones(v.shape) if weights is None else np.asarray(weights, dtype=np.float64)
    flat = np.bincount(f[keep] * n_bins + b[keep], weights=w[keep], minlength=n_frames * n_bins)
    return np.asarray(flat.reshape(n_frames, n_bins), dtype=np.float64)


@dataclass(frozen=True)
class HistogramSettings:
    """How point clouds become histograms: bins, weighting and the range gate [m] (points
    closer than ``min_range`` or farther than ``max_range`` from the sensor are ignored)."""

    bin_width: float = IWR1443_BIN_WIDTH
    n_bins: int = 17
    weighting: Weighting = "count"
    min_range: float = 0.0
    max_range: float = float("inf")


def cloud_histograms(cloud: PointCloud, settings: HistogramSettings) -> FloatArray:
    """Per-frame histograms (n_frames, n_bins) of a point cloud within the range gate."""
    r = cloud.ranges
    gate = (r >= settings.min_range) & (r <= settings.max_range)
    _, edges = velocity_bins(settings.bin_width, settings.n_bins)
    return doppler_histograms(
        cloud.frame[gate],
        cloud.velocity[gate],
        cloud.n_frames,
        edges,
        point_weights(cloud.intensity[gate], settings.weighting),
    )


def window_starts(n_frames: int, length: int, hop: int) -> IntArray:
    """First frames of the windows of ``length`` frames every ``hop`` frames that fit."""
    if length < 1 or hop < 1:
        raise ValueError("window length and hop must be at least one frame")
    return np.arange(0, n_frames - length + 1, hop, dtype=np.int64)


def histogram_features(
    histograms: FloatArray,
    centres: FloatArray,
    *,
    method: Literal["threshold", "percentile"] = "threshold",
    threshold_db: float = -20.0,
    floor_db: float = -40.0,
    percentiles: tuple[float, float] = (3.0, 97.0),
    torso_method: Literal["median", "peak"] = "median",
) -> FloatArray:
    """The seven features (7,) [m/s] of a window of histograms (n_frames, n_bins): the
    histograms read as a spectrogram (bins x frames, weight as power) by
    :func:`mdframework.features.spectrogram_features`. Frames without points are skipped; a
    window without any point raises ``ValueError``."""
    return spectrogram_features(
        np.asarray(histograms, dtype=np.float64).T,
        centres,
        method=method,
        threshold_db=threshold_db,
        floor_db=floor_db,
        percentiles=percentiles,
        torso_method=torso_method,
    )


def histogram_vector(histograms: FloatArray) -> FloatArray:
    """A fixed-length classifier input from a window of histograms (n_frames, n_bins).

    Each frame's histogram is normalised to sum 1 (frames without points are left out); the
    vector is the mean over frames of those normalised histograms followed by their standard
    deviation over frames, (2 * n_bins,) float64 (dimensionless shares). All zeros when no
    frame holds a point.
    """
    h = np.asarray(histograms, dtype=np.float64)
    totals = h.sum(axis=1)
    live = totals > 0
    if not np.any(live):
        return np.zeros(2 * h.shape[1])
    shares = h[live] / totals[live, None]
    return np.concatenate([shares.mean(axis=0), shares.std(axis=0)])


def histogram_vector_names(centres: FloatArray) -> tuple[str, ...]:
    """Column names of :func:`histogram_vector` for bins at ``centres`` [m/s]."""
    return tuple(f"mean_{c:+.2f}" for c in centres) + tuple(f"std_{c:+.2f}" for c in centres)


__all__ = [
    "FEATURE_NAMES",
    "IWR1443_BIN_WIDTH",
    "HistogramSettings",
    "PointCloud",
    "cloud_histograms",
    "doppler_histograms",
    "frames_from_point_ids",
    "histogram_features",
    "histogram_vector",
    "histogram_vector_names",
    "point_weights",
    "range_rate_to_approaching",
    "velocity_bins",
    "window_starts",
]
