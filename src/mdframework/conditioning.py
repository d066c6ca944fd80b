"""Skeleton conditioning: making noisy (Kinect) joint tracks usable for radar simulation.

Pure functions on arrays plus one entry point, :func:`condition`. Arrays and units:
``time`` (n_frames,) float64 [s]; ``positions`` (n_frames, n_joints, 3) float64 [m];
``valid`` (n_frames, n_joints) bool. Nothing here changes data that need no change: every step
touches only the frames and joints it flags, and reports what it did.

Steps (each configurable through :class:`mdframework.settings.ConditioningConfig`):

1. time stamps (:func:`sort_timestamps`): stable sort, duplicates dropped (first kept). Sources
   call it before building a :class:`~mdframework.skeleton.Skeleton` (which must be strictly
   increasing); real time stamps are kept, so frame drops stay visible as longer steps.
2. gaps (:func:`untracked_mask`, :func:`find_gaps`, :func:`bridge_gaps`): exact (0, 0, 0), NaN and
   frames already marked invalid are gaps; gaps are bridged by a C2 cubic spline through the
   joint's valid frames (held constant before the first and after the last valid frame), and
   gaps longer than ``max_gap_s`` are flagged (or are an error).
3. foot outliers (:func:`foot_outliers`, :func:`correct_foot_outliers`), after Erol & Gurbuz:
   the segment vector (e.g. toe - ankle) deviating from its mean by more than an adaptive
   threshold, read from the histogram of the deviations (the first empty bin above the mode),
   is an outlier; it is replaced by a prediction from the past: the distal joint keeps its last
   good offset and moves with the proximal joint, forward or backward as that joint moves.
4. the knee-ankle-foot angle of eq. (7) (:func:`knee_ankle_foot_angle`), in the stable form
   ``atan2(|v1 x v2|, v1 . v2)``, and its periodicity (:func:`periodicity`) as a check for
   walking and running.
5. foot length (:func:`correct_foot_length`): the toe moved along the ankle-toe direction so that
   the foot has the subject's measured length.
6. speed limit and smoothing (:func:`limit_speed`, :func:`gaussian_smooth`): frames where a
   joint moves faster than a physical limit (spikes; raw Kinect feet jump at ~9 m/s) are
   replaced by interpolation from their neighbours; joints that needed it (or all) are then
   smoothed with a Gaussian kernel over real time.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from .settings import ConditioningConfig
from .skeleton import Skeleton

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
IntArray = NDArray[np.intp]

#: Segments checked for outliers, as (proximal, distal) canonical joints: the feet, as in the
#: paper (a shin swings too far in a gait cycle for a mean-based test).
DEFAULT_OUTLIER_SEGMENTS: tuple[tuple[str, str], ...] = (
    ("l_ankle", "l_toe"),
    ("r_ankle", "r_toe"),
)

# --------------------------------------------------------------------------- 1. time stamps


def sort_timestamps(
    time: FloatArray, positions: FloatArray, valid: BoolArray | None = None
) -> tuple[FloatArray, FloatArray, BoolArray, dict[str, int]]:
    """Sort frames by time (stable) and drop frames whose time repeats an earlier one.

    Parameters
    ----------
    time : (n_frames,) float64 [s]
    positions : (n_frames, n_joints, 3) float64 [m]
    valid : (n_frames, n_joints) bool, optional (default: finite positions)

    Returns
    -------
    time, positions, valid
        The kept frames, time strictly increasing.
    report : dict
        ``out_of_order`` (frames that were not in time order), ``duplicates_dropped``.
    """
    t = np.asarray(time, dtype=np.float64)
    pos = np.asarray(positions, dtype=np.float64)
    ok = np.all(np.isfinite(pos), axis=2) if valid is None else np.asarray(valid, dtype=bool)
    if not np.all(np.isfinite(t)):
        raise ValueError("time stamps must be finite")
    order = np.argsort(t, kind="stable")
    out_of_order = int(np.count_nonzero(order != np.arange(t.shape[0])))
    ts = t[order]
    keep = np.ones(ts.shape, dtype=bool)
    keep[1:] = np.diff(ts) > 0
    idx = order[keep]
    report = {"out_of_order": out_of_order, "duplicates_dropped": int(np.count_nonzero(~keep))}
    return t[idx], pos[idx], ok[idx], report


# --------------------------------------------------------------------------- 2. gaps


def untracked_mask(
    positions: FloatArray,
    valid: BoolArray | None = None,
    confidence: FloatArray | None = None,
    min_confidence: float = 0.0,
    zeros_untracked: bool = True,
) -> BoolArray:
    """Which joint samples are usable.

    Parameters
    ----------
    positions : (n_frames, n_joints, 3) float64 [m]
    valid : (n_frames, n_joints) bool, optional: samples already known to be untracked.
    confidence : (n_frames, n_joints) float64, optional; below ``min_confidence`` is untracked.
    zeros_untracked : bool
        Treat an exact (0, 0, 0) as untracked (what Kinect software writes for lost joints).

    Returns
    -------
    (n_frames, n_joints) bool: True where the sample is tracked.
    """
    ok = np.all(np.isfinite(positions), axis=2)
    if valid is not None:
        ok &= np.asarray(valid, dtype=bool)
    if zeros_untracked:
        ok &= ~np.all(positions == 0.0, axis=2)
    if confidence is not None:
        ok &= np.asarray(confidence) >= min_confidence
    return np.asarray(ok, dtype=bool)


def find_gaps(time: FloatArray, valid: BoolArray) -> list[tuple[int, int, int, float]]:
    """Runs of untracked samples.

    Returns a list of ``(joint, first_frame, last_frame, duration_s)``; the duration is the time
    between the valid samples around the gap (to the record's end where there is none).
    """
    out: list[tuple[int, int, int, float]] = []
    n = time.shape[0]
    for j in range(valid.shape[1]):
        bad = ~valid[:, j]
        if not bad.any():
            continue
        edges = np.diff(np.concatenate(([0], bad.astype(np.int8), [0])))
        starts = np.flatnonzero(edges == 1)
        ends = np.flatnonzero(edges == -1) - 1
        for s, e in zip(starts, ends, strict=True):
            t0 = time[s - 1] if s > 0 else time[s]
            t1 = time[e + 1] if e + 1 < n else time[e]
            out.append((j, int(s), int(e), float(t1 - t0)))
    return out


def bridge_gaps(time: FloatArray, positions: FloatArray, valid: BoolArray) -> FloatArray:
    """Fill untracked samples: cubic spline over each joint's valid samples inside its valid
    span, the nearest valid sample outside it (no extrapolation).

    Returns positions (n_frames, n_joints, 3) float64 [m]; valid samples are returned unchanged.
    Raises ``ValueError`` for a joint with no valid sample.
    """
    from scipy.interpolate import CubicSpline

    out = np.array(positions, dtype=np.float64, copy=True)
    for j in range(positions.shape[1]):
        ok = valid[:, j]
        if ok.all():
            continue
        k = np.flatnonzero(ok)
        if k.size == 0:
            raise ValueError(f"joint {j} is never tracked")
        if k.size == 1:
            out[:, j, :] = positions[k[0], j, :]
            continue
        tq = np.clip(time, time[k[0]], time[k[-1]])
        bc = "not-a-knot" if k.size >= 4 else "natural"
        spline = CubicSpline(time[k], positions[k, j, :], axis=0, bc_type=bc)
        fill = ~ok
        out[fill, j, :] = spline(tq[fill])
    return out


# --------------------------------------------------------------------------- 3. foot outliers


#: most bins of the deviation histogram of :func:`histogram_threshold` (8 MB of counts): a bin
#: width far below the deviations (``conditioning.outlier_bin_m``) would allocate gigabytes
MAX_HISTOGRAM_BINS = 1_000_000


def histogram_threshold(deviation: FloatArray, bin_width: float, minimum: float) -> float:
    """Adaptive outlier threshold from the histogram of deviations.

    The histogram of ``deviation`` (>= 0) [m] with bins of ``bin_width`` [m] is scanned upward
    from its most populated bin; the lower edge of the first empty bin is the threshold: the bulk
    of the data lies below it, isolated jumps above. Never below ``minimum`` [m]; infinite when
    the histogram has no empty bin (no separated outliers).
    """
    d = deviation[np.isfinite(deviation)]
    if d.size == 0:
        return float("inf")
    bins = np.ceil(float(d.max()) / bin_width) + 1  # float: inf for a denormal bin width
    if not bins <= MAX_HISTOGRAM_BINS:
        raise ValueError(
            f"outlier_bin_m: deviations up to {float(d.max()):.3g} m in bins of {bin_width:g} m "
            f"need {bins:.3g} histogram bins, more than {MAX_HISTOGRAM_BINS:,}: raise "
            "outlier_bin_m (0.01 m is the default)"
        )
    n_bins = max(int(bins), 1)
    counts, edges = np.histogram(d, bins=n_bins, range=(0.0, n_bins * bin_width))
    mode = int(np.argmax(counts))
    empty = np.flatnonzero(counts[mode:] == 0)
    if empty.size == 0:
        return float("inf")
    return max(float(edges[mode + int(empty[0])]), minimum)


def foot_outliers(
    proximal: FloatArray, distal: FloatArray, bin_width: float = 0.01, minimum: float = 0.05
) -> tuple[BoolArray, float, FloatArray]:
    """Frames where a segment (e.g. ankle -> toe) is an outlier.

    Parameters
    ----------
    proximal, distal : (n_frames, 3) float64 [m]
        The segment's joints.
    bin_width, minimum : float [m]
        See :func:`histogram_threshold`.

    Returns
    -------
    outlier : (n_frames,) bool
    threshold : float [m]
    deviation : (n_frames,) float64 [m], ``|v(t) - mean(v)|`` with ``v = distal - proximal``.
    """
    v = distal - proximal
    dev = np.asarray(np.linalg.norm(v - v.mean(axis=0), axis=1), dtype=np.float64)
    thr = histogram_threshold(dev, bin_width, minimum)
    out = dev > thr
    if out.any() and (~out).any():  # the mean of the inliers, once, so outliers do not bias it
        dev = np.asarray(np.linalg.norm(v - v[~out].mean(axis=0), axis=1), dtype=np.float64)
        thr = histogram_threshold(dev, bin_width, minimum)
        out = dev > thr
    return np.asarray(out, dtype=bool), thr, dev


def correct_foot_outliers(
    time: FloatArray,
    proximal: FloatArray,
    distal: FloatArray,
    outlier: BoolArray,
) -> tuple[FloatArray, list[dict[str, Any]]]:
    """Replace outlier positions of the distal joint by a prediction from past frames.

    At an outlier frame k the distal joint keeps the offset it had at the last good frame p and
    moves with the proximal joint: ``distal[k] = distal[p] + (proximal[k] - proximal[p])``, so a
    foot goes forward or backward as its ankle does. Before the first good frame, the next good
    frame is used instead.

    Returns the corrected distal track (n_frames, 3) [m] and one record per corrected frame
    (``frame``, ``time_s``, ``moved_m``, ``direction`` 'forward'/'backward'/'still' along the
    proximal joint's mean horizontal motion).
    """
    out = np.array(distal, dtype=np.float64, copy=True)
    good = np.flatnonzero(~outlier)
    if good.size == 0:
        return out, []
    travel = proximal[-1, :2] - proximal[0, :2]
    norm = float(np.hypot(*travel))
    heading = travel / norm if norm > 1e-9 else np.zeros(2)
    records: list[dict[str, Any]] = []
    for k in np.flatnonzero(outlier):
        before = good[good < k]
        p = int(before[-1]) if before.size else int(good[0])
        step = proximal[k] - proximal[p]
        new = out[p] + step
        along = float(step[:2] @ heading)
        direction = "still" if abs(along) < 1e-6 else ("forward" if along > 0 else "backward")
        records.append(
            {
                "frame": int(k),
                "time_s": float(time[k]),
                "moved_m": float(np.linalg.norm(new - distal[k])),
                "direction": direction,
            }
        )
        out[k] = new
    return out, records


# --------------------------------------------------------------------------- 4. eq. (7)


def knee_ankle_foot_angle(knee: FloatArray, ankle: FloatArray, foot: FloatArray) -> FloatArray:
    """The knee-ankle-foot angle of eq. (7) [rad], in [0, pi].

    ``theta = atan2(|v1 x v2|, v1 . v2)`` with ``v1 = knee - ankle`` and ``v2 = foot - ankle``:
    the arccos of the normalised dot product, without its loss of precision near 0 and pi.
    Inputs (..., 3) [m]; output (...) float64 [rad].
    """
    v1 = np.asarray(knee, dtype=np.float64) - ankle
    v2 = np.asarray(foot, dtype=np.float64) - ankle
    cross = np.linalg.norm(np.cross(v1, v2), axis=-1)
    dot = np.sum(v1 * v2, axis=-1)
    return np.asarray(np.arctan2(cross, dot), dtype=np.float64)


def lag_correlation(
    time: FloatArray, signal: FloatArray
) -> tuple[FloatArray, FloatArray, float] | None:
    """Autocorrelation of a signal sampled at (possibly uneven) times, two ways.

    The signal is resampled linearly to its mean rate ``dt`` [s] and its mean removed. At lag
    ``k`` the *biased* value is ``sum x[k:] x[:n-k] / sum x^2``: it falls with the overlap
    ``(n - k) / n``, so a long lag needs more evidence to stand out, but the peak of a short
    record moves towards lag 0 (a 1.1 s period in 3 s at 30 Hz peaks a frame early). The
    *normalised* value divides by ``sqrt(sum x[k:]^2 sum x[:n-k]^2)`` instead, the correlation
    coefficient of the overlapping parts: a periodic signal reaches 1 at its period however
    short the record.

    Returns (biased (n,), normalised (n,), both float64 [1] at lags 0 .. n-1; dt [s]), or None
    for fewer than 8 samples, no time span or a constant signal. Computed by FFT: n log n,
    also for long recordings.
    """
    t = np.asarray(time, dtype=np.float64)
    n = t.shape[0]
    if n < 8 or not t[-1] > t[0]:
        return None
    dt = float(t[-1] - t[0]) / (n - 1)
    x = np.interp(t[0] + dt * np.arange(n), t, np.asarray(signal, dtype=np.float64))
    x = x - x.mean()
    sq = x * x
    total = float(sq.sum())
    if not total > 0:
        return None
    n_fft = 1 << (2 * n - 1).bit_length()
    spectrum = np.fft.rfft(x, n_fft)
    product = np.fft.irfft(spectrum * spectrum.conj(), n_fft)[:n]
    head = np.cumsum(sq)[::-1]  # at lag k: sum x[:n-k]^2
    tail = np.cumsum(sq[::-1])[::-1]  # at lag k: sum x[k:]^2
    energy = np.sqrt(head * tail)
    normalised = np.divide(product, energy, out=np.zeros(n), where=energy > 0)
    return product / total, normalised, dt


def correlation_peaks(biased: FloatArray, normalised: FloatArray) -> list[tuple[float, float]]:
    """The peaks of :func:`lag_correlation`'s biased values after their first negative one,
    in lag order: (lag [samples]; the biased value there [1], as the top of a parabola through
    the peak and its neighbours, since a period between two lags lowers both).

    Each lag is the peak of the normalised values reached by climbing them from the biased
    peak, refined to a fraction by a parabola through it and its neighbours (so it is not
    drawn towards lag 0), or the biased peak's own parabola where that climb finds no peak. The
    biased value decides which peaks count and ranks them, as a measure of evidence.
    """
    n = biased.shape[0]
    negative = np.flatnonzero(biased < 0)
    if negative.size == 0:
        return []
    k = np.arange(max(int(negative[0]), 1), n - 1)
    at_peak = (biased[k] >= biased[k - 1]) & (biased[k] >= biased[k + 1])
    peaks = []
    for k0 in k[at_peak].tolist():
        curve = biased[k0 - 1] - 2 * biased[k0] + biased[k0 + 1]
        shift = 0.5 * (biased[k0 - 1] - biased[k0 + 1]) / curve if curve < 0 else 0.0
        top = float(biased[k0] - 0.25 * (biased[k0 - 1] - biased[k0 + 1]) * shift)
        j = k0  # climb the normalised values from the biased peak to their own peak
        while j < n - 2 and normalised[j + 1] > normalised[j]:
            j += 1
        while j > 1 and normalised[j - 1] > normalised[j]:
            j -= 1
        curve = normalised[j - 1] - 2 * normalised[j] + normalised[j + 1]
        if normalised[j] >= max(normalised[j - 1], normalised[j + 1]) and curve < 0:
            peaks.append((j + 0.5 * (normalised[j - 1] - normalised[j + 1]) / curve, top))
        else:
            peaks.append((k0 + shift, top))
    return peaks


def periodicity(time: FloatArray, signal: FloatArray) -> dict[str, float | None]:
    """Dominant period of a signal sampled at (possibly uneven) times.

    The first peak of the signal's biased autocorrelation after its first zero crossing that
    reaches 0.9 of the highest (on a long record every multiple of the period is about as
    high), located on the normalised one (:func:`lag_correlation`, :func:`correlation_peaks`).
    Returns ``period_s`` [s] (None if there is no positive peak) and ``strength`` (the biased
    autocorrelation there, which falls with the overlap: at most ``1 - period / duration``).
    """
    found = lag_correlation(time, signal)
    peaks = correlation_peaks(found[0], found[1]) if found is not None else []
    if found is None or not peaks:
        return {"period_s": None, "strength": 0.0}
    highest = max(p[1] for p in peaks)
    if highest <= 0:
        return {"period_s": None, "strength": highest}
    lag, value = next(p for p in peaks if p[1] >= 0.9 * highest)
    return {"period_s": float(lag * found[2]), "strength": value}


# --------------------------------------------------------------------------- 5. foot length


def correct_foot_length(ankle: FloatArray, toe: FloatArray, length: float) -> FloatArray:
    """Move the toe along the ankle -> toe direction so that the foot is ``length`` [m] long.

    ``ankle``, ``toe`` (n_frames, 3) [m]; returns the new toe track. Frames where toe and ankle
    coincide keep their toe (no direction to scale along).
    """
    v = toe - ankle
    n = np.linalg.norm(v, axis=1, keepdims=True)
    ok = n[:, 0] > 1e-9
    out = np.array(toe, dtype=np.float64, copy=True)
    out[ok] = ankle[ok] + v[ok] / n[ok] * length
    return out


# --------------------------------------------------------------------------- 6. speed limit


def speeds(time: FloatArray, track: FloatArray) -> FloatArray:
    """Speed between consecutive frames, (n_frames - 1,) float64 [m/s]; ``track`` (n, 3) [m]."""
    return np.asarray(
        np.linalg.norm(np.diff(track, axis=0), axis=1) / np.diff(time), dtype=np.float64
    )


def limit_speed(
    time: FloatArray, track: FloatArray, max_speed: float
) -> tuple[FloatArray, BoolArray]:
    """Remove spikes: frames reached or left faster than ``max_speed`` [m/s].

    Repeatedly, of the two frames of the fastest step above the limit, the one farther from the
    median of its 5-frame neighbourhood is dropped (the first and last frames are never dropped
    when an inner frame is available) and all dropped frames are re-interpolated (linear,
    so no overshoot) from the kept ones.

    Returns the new track (n_frames, 3) [m] and the replaced frames (n_frames,) bool.
    """
    n = track.shape[0]
    replaced = np.zeros(n, dtype=bool)
    cur = np.array(track, dtype=np.float64, copy=True)
    if n < 3:
        return cur, replaced
    for _ in range(n):
        sp = speeds(time, cur)
        k = int(np.argmax(sp))
        if sp[k] <= max_speed:
            break
        cands = [i for i in (k, k + 1) if 0 < i < n - 1 and not replaced[i]]
        if not cands:
            break

        def spread(i: int) -> float:
            lo, hi = max(0, i - 2), min(n, i + 3)
            med = np.median(cur[lo:hi], axis=0)
            return float(np.linalg.norm(cur[i] - med))

        worst = max(cands, key=spread)
        replaced[worst] = True
        keep = ~replaced
        for c in range(3):
            cur[replaced, c] = np.interp(time[replaced], time[keep], track[keep, c])
    return cur, replaced


def gaussian_smooth(time: FloatArray, track: FloatArray, sigma_s: float) -> FloatArray:
    """Gaussian kernel smoothing over real time (uneven steps allowed).

    ``track`` (n_frames, 3) [m]; kernel standard deviation ``sigma_s`` [s], cut at 3 sigma;
    each output is the kernel-weighted mean. ``sigma_s <= 0`` returns the track unchanged.
    """
    if sigma_s <= 0:
        return np.array(track, dtype=np.float64, copy=True)
    n = time.shape[0]
    lo = np.searchsorted(time, time - 3 * sigma_s, side="left")
    hi = np.searchsorted(time, time + 3 * sigma_s, side="right")
    reach = int(max(np.max(np.arange(n) - lo), np.max(hi - 1 - np.arange(n))))
    total = np.zeros_like(np.asarray(track, dtype=np.float64))
    weight = np.zeros(n)
    for k in range(-reach, reach + 1):  # O(n x frames within 3 sigma), not O(n^2)
        j = np.arange(n) + k
        inside = (j >= lo) & (j < hi)
        jj = np.clip(j, 0, n - 1)
        w = np.where(inside, np.exp(-0.5 * ((time[jj] - time) / sigma_s) ** 2), 0.0)
        total += w[:, None] * track[jj]
        weight += w
    return np.asarray(total / weight[:, None], dtype=np.float64)


# --------------------------------------------------------------------------- entry point


def condition(skeleton: Skeleton, config: ConditioningConfig) -> tuple[Skeleton, dict[str, Any]]:
    """Apply the enabled conditioning steps to a skeleton.

    Parameters
    ----------
    skeleton : Skeleton
        Any body; the foot steps need the canonical joint names (they are skipped, with a note,
        when the joints are absent).
    config : ConditioningConfig

    Returns
    -------
    skeleton : Skeleton
        Same time stamps and joint names; every sample valid (gaps bridged).
    report : dict
        What each step found and changed (JSON-serialisable).
    """
    time = skeleton.time
    names = skeleton.joint_names
    report: dict[str, Any] = {"enabled": True}

    valid = untracked_mask(skeleton.positions, skeleton.valid, None, 0.0, config.zeros_untracked)
    gaps = find_gaps(time, valid)
    long = [g for g in gaps if g[3] > config.max_gap_s]
    # frames the recording lacks (a tracker that lost the subject wrote no rows) are a gap of
    # every joint: the step between the frames around it
    frame_steps = np.diff(time)
    holes = [
        (int(k), float(frame_steps[k])) for k in np.flatnonzero(frame_steps > config.max_gap_s)
    ]
    if holes and config.long_gaps == "error":
        at, d = holes[0]
        raise ValueError(
            f"the recording has no frame for {d:.3f} s (after frame {at} at "
            f"{time[at] - time[0]:.3f} s), longer than conditioning.max_gap_s = "
            f"{config.max_gap_s:g} s"
        )
    if long and config.long_gaps == "error":
        j, s, e, d = long[0]
        raise ValueError(
            f"joint {names[j]!r} is untracked for {d:.3f} s (frames {s}..{e}), longer than "
            f"conditioning.max_gap_s = {config.max_gap_s:g} s"
        )
    for j in range(len(names)):
        if not valid[:, j].any():
            raise ValueError(f"joint {names[j]!r} is never tracked")
    pos = bridge_gaps(time, np.where(valid[..., None], skeleton.positions, 0.0), valid)
    report["gaps"] = {
        "samples_bridged": int(np.count_nonzero(~valid)),
        "n_gaps": len(gaps),
        "max_gap_s": config.max_gap_s,
        "long_gaps": [
            {"joint": names[j], "first_frame": s, "last_frame": e, "duration_s": d}
            for j, s, e, d in long
        ],
        "missing_frames": [
            {"after_frame": at, "after_s": float(time[at] - time[0]), "duration_s": d}
            for at, d in holes
        ],
    }

    index = {n: i for i, n in enumerate(names)}
    if config.foot_outliers:
        steps: dict[str, Any] = {}
        for prox, dist in DEFAULT_OUTLIER_SEGMENTS:
            if prox not in index or dist not in index:
                continue
            ip, idist = index[prox], index[dist]
            out, thr, _ = foot_outliers(
                pos[:, ip], pos[:, idist], config.outlier_bin_m, config.outlier_min_threshold_m
            )
            fixed, records = correct_foot_outliers(time, pos[:, ip], pos[:, idist], out)
            pos[:, idist] = fixed
            steps[f"{prox}->{dist}"] = {
                "threshold_m": thr if np.isfinite(thr) else None,
                "n_outliers": int(out.sum()),
                "corrected": records,
            }
        report["foot_outliers"] = steps or "skipped: no canonical leg joints"

    if config.foot_length_m is not None:
        lengths: dict[str, Any] = {}
        for side in ("l", "r"):
            a, t = f"{side}_ankle", f"{side}_toe"
            if a in index and t in index:
                before = np.linalg.norm(pos[:, index[t]] - pos[:, index[a]], axis=1)
                pos[:, index[t]] = correct_foot_length(
                    pos[:, index[a]], pos[:, index[t]], config.foot_length_m
                )
                lengths[side] = {"mean_before_m": float(before.mean())}
        report["foot_length"] = {"target_m": config.foot_length_m, **lengths}

    if config.speed_limit:
        limited: dict[str, Any] = {}
        for j, name in enumerate(names):
            before = float(speeds(time, pos[:, j]).max()) if time.shape[0] > 1 else 0.0
            track, replaced = limit_speed(time, pos[:, j], config.max_speed_mps)
            needs = bool(replaced.any())
            if config.smoothing == "all" or (config.smoothing == "violating" and needs):
                track = gaussian_smooth(time, track, config.smoothing_sigma_s)
            if needs or config.smoothing == "all":
                pos[:, j] = track
                after = float(speeds(time, track).max())
                limited[name] = {
                    "max_speed_before_mps": before,
                    "max_speed_after_mps": after,
                    "frames_replaced": int(replaced.sum()),
                }
        report["speed_limit"] = {
            "max_speed_mps": config.max_speed_mps,
            "smoothing": config.smoothing,
            "smoothing_sigma_s": config.smoothing_sigma_s,
            "joints": limited,
        }
    elif config.smoothing == "all":  # no limit, so no joint violates it: smoothing alone
        for j in range(len(names)):
            pos[:, j] = gaussian_smooth(time, pos[:, j], config.smoothing_sigma_s)
        report["smoothing"] = {
            "smoothing": "all",
            "smoothing_sigma_s": config.smoothing_sigma_s,
            "joints": list(names),
        }

    if config.angle_check:
        checks: dict[str, Any] = {}
        for side in ("l", "r"):
            k, a, t = f"{side}_knee", f"{side}_ankle", f"{side}_toe"
            if all(x in index for x in (k, a, t)):
                theta = knee_ankle_foot_angle(pos[:, index[k]], pos[:, index[a]], pos[:, index[t]])
                checks[side] = {
                    "mean_deg": float(np.degrees(theta.mean())),
                    "min_deg": float(np.degrees(theta.min())),
                    "max_deg": float(np.degrees(theta.max())),
                    **periodicity(time, theta),
                }
        report["knee_ankle_foot_angle"] = checks or "skipped: no canonical leg joints"

    return Skeleton(time, pos, names), report
