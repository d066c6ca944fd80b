"""The seven spectrogram features of Erol & Gurbuz (2015), Table 2.

All features are radial velocities in m/s (positive = approaching):

1. ``torso_mean``: time-mean of the torso velocity ``v_torso(m)``;
2. ``torso_bandwidth``: peak-to-peak of ``v_torso(m)``;
3. ``upper_max``: maximum of the upper envelope ``U(m)``;
4. ``lower_min``: minimum of the lower envelope ``L(m)``;
5. ``total_bandwidth``: ``upper_max - lower_min``;
6. ``upper_mean``: mean of ``U(m)``;
7. ``lower_mean``: mean of ``L(m)``.

The paper only says the envelopes are "curves connecting the maxima and minima of the
spectrogram", so the method is an option:

- ``threshold`` (default): per time column, the highest and lowest velocity bins whose power is
  within ``threshold_db`` (default -20 dB) of that column's peak, ignoring bins more than
  ``floor_db`` (default -40 dB) below the whole spectrogram's peak.
- ``percentile`` (van Dorp & Groen 2008): per column, the velocities where the cumulative power
  (above the floor) reaches ``percentiles`` (default 3 % and 97 %).

The torso track is an option too (``torso_method``): ``median`` (default), the velocity that
splits the column's power (above the floor) in half, or ``peak``, the column's strongest bin.
The peak jumps to a leg whenever a leg outshines the torso for a moment (on CMU 02_01 it spans
0.16-2.51 m/s while the hip centre's radial speed spans 0.79-1.58 m/s, which inflates the torso
bandwidth); the median follows the bulk of the body (0.30-1.52 m/s there).

Columns with no bin above the floor (silence) are left out of every statistic.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

#: Feature names, in the paper's order.
FEATURE_NAMES: tuple[str, ...] = (
    "torso_mean",
    "torso_bandwidth",
    "upper_max",
    "lower_min",
    "total_bandwidth",
    "upper_mean",
    "lower_mean",
)

#: Spectrogram cells :func:`envelopes` works on at once (whole columns, at least one).
ENVELOPE_CELLS = 1 << 18

EnvelopeMethod = Literal["threshold", "percentile"]
TorsoMethod = Literal["median", "peak"]


@dataclass(frozen=True)
class Envelopes:
    """Per-frame tracks [m/s], each (n_frames,), NaN in silent frames."""

    upper: FloatArray
    lower: FloatArray
    torso: FloatArray


def envelopes(
    power: NDArray[np.floating[Any]],
    velocity: FloatArray,
    *,
    method: EnvelopeMethod = "threshold",
    threshold_db: float = -20.0,
    floor_db: float = -40.0,
    percentiles: tuple[float, float] = (3.0, 97.0),
    torso_method: TorsoMethod = "median",
) -> Envelopes:
    """Upper and lower envelopes and the torso track of a spectrogram.

    ``power`` (n_doppler, n_frames), linear (not dB), >= 0; ``velocity`` (n_doppler,) [m/s],
    ascending. See the module docstring for the methods. ``ValueError`` for a negative value (a
    map in dB, such as ``spectrogram_db``: pass ``10 ** (db / 10)``) or a NaN or infinite one.
    """
    p_all = np.asarray(power)
    if p_all.dtype not in (np.float32, np.float64):
        p_all = p_all.astype(np.float64)
    v = np.asarray(velocity, dtype=np.float64)
    if p_all.ndim != 2 or p_all.shape[0] != v.shape[0]:
        raise ValueError(f"power must be (n_doppler={v.shape[0]}, n_frames), got {p_all.shape}")
    if np.any(np.diff(v) <= 0):
        raise ValueError("velocity must be strictly ascending")
    if not threshold_db <= 0.0:  # a column's peak must pass its own threshold
        raise ValueError(f"threshold_db must be <= 0 dB (below the peak), got {threshold_db}")
    if method not in ("threshold", "percentile"):
        raise ValueError(f"unknown envelope method {method!r}")
    if torso_method not in ("median", "peak"):
        raise ValueError(f"unknown torso method {torso_method!r}")
    n_frames = p_all.shape[1]
    p_max = float(p_all.max()) if p_all.size else 0.0
    p_min = float(p_all.min()) if p_all.size else 0.0
    if not (np.isfinite(p_max) and np.isfinite(p_min)):
        raise ValueError("power has NaN or infinite values")
    if p_min < 0.0:
        raise ValueError(
            f"power must be linear (>= 0), not dB: its lowest value is {p_min:g}; for a map in "
            "dB (such as spectrogram_db) pass 10 ** (db / 10)"
        )
    upper = np.full(n_frames, np.nan)
    lower = np.full(n_frames, np.nan)
    torso = np.full(n_frames, np.nan)
    if p_max <= 0.0:
        return Envelopes(upper, lower, torso)
    floor = p_max * 10.0 ** (floor_db / 10.0)
    # the columns a few at a time: a long record's float64 copies and masks would otherwise
    # take about 30 bytes per spectrogram cell at once
    step = max(1, ENVELOPE_CELLS // max(v.size, 1))
    for lo in range(0, n_frames, step):
        cols = slice(lo, lo + step)
        p = np.asarray(p_all[:, cols], dtype=np.float64)
        up, low, mid = upper[cols], lower[cols], torso[cols]  # views: filled in place
        above_floor = p >= floor
        live = np.any(above_floor, axis=0)
        if method == "threshold":
            col_peak = p.max(axis=0)
            mask = above_floor & (p >= col_peak * 10.0 ** (threshold_db / 10.0))
            # the first and the last bin of each column in the mask (a live column has its
            # peak in it); argmax of a boolean array is the first True
            first = np.argmax(mask, axis=0)
            last = v.size - 1 - np.argmax(mask[::-1], axis=0)
            up[live] = v[last[live]]
            low[live] = v[first[live]]
        else:
            low[live] = _quantile_velocity(p, above_floor, v, percentiles[0] / 100.0)[live]
            up[live] = _quantile_velocity(p, above_floor, v, percentiles[1] / 100.0)[live]
        if torso_method == "peak":
            mid[live] = v[np.argmax(p, axis=0)[live]]
        else:
            mid[live] = _quantile_velocity(p, above_floor, v, 0.5)[live]
    return Envelopes(upper, lower, torso)


def _quantile_velocity(
    power: FloatArray, mask: NDArray[np.bool_], velocity: FloatArray, q: float
) -> FloatArray:
    """Per column, the first velocity where the cumulative masked power reaches fraction q."""
    cum = np.cumsum(np.where(mask, power, 0.0), axis=0)
    total = cum[-1]
    with np.errstate(invalid="ignore", divide="ignore"):
        reached = cum >= q * total[None, :]
    idx = np.minimum(np.argmax(reached, axis=0), velocity.size - 1)
    return np.asarray(velocity[idx], dtype=np.float64)


def features_from_envelopes(env: Envelopes) -> FloatArray:
    """The seven features (7,) [m/s] from envelope tracks (NaN frames ignored)."""
    live = np.isfinite(env.torso)
    if not np.any(live):
        raise ValueError("the spectrogram is silent: no frame rises above the floor")
    t, u, lo = env.torso[live], env.upper[live], env.lower[live]
    upper_max, lower_min = float(u.max()), float(lo.min())
    return np.array(
        [
            t.mean(),
            t.max() - t.min(),
            upper_max,
            lower_min,
            upper_max - lower_min,
            u.mean(),
            lo.mean(),
        ]
    )


def band_edge_frames(env: Envelopes, velocity: FloatArray) -> int:
    """Frames whose upper envelope reaches the last bin of ``velocity`` (n_doppler,) [m/s] or
    whose lower envelope reaches the first: there the envelope stops at the Doppler band, not
    at the body (the body's Doppler aliases, or the frame's column stands less than the
    envelope threshold above the noise), and the extremes of the features are the band's."""
    v = np.asarray(velocity, dtype=np.float64)
    live = np.isfinite(env.upper) & np.isfinite(env.lower)
    return int(np.sum(live & ((env.upper >= v[-1]) | (env.lower <= v[0]))))


def spectrogram_features(
    power: NDArray[np.floating[Any]],
    velocity: FloatArray,
    *,
    method: EnvelopeMethod = "threshold",
    threshold_db: float = -20.0,
    floor_db: float = -40.0,
    percentiles: tuple[float, float] = (3.0, 97.0),
    torso_method: TorsoMethod = "median",
) -> FloatArray:
    """The seven features (7,) [m/s] of a spectrogram, in :data:`FEATURE_NAMES` order.

    ``power`` (n_doppler, n_frames) linear (not dB: for ``spectrogram_db`` pass
    ``10 ** (db / 10)``); ``velocity`` (n_doppler,) [m/s] ascending.
    """
    env = envelopes(
        power,
        velocity,
        method=method,
        threshold_db=threshold_db,
        floor_db=floor_db,
        percentiles=percentiles,
        torso_method=torso_method,
    )
    return features_from_envelopes(env)
