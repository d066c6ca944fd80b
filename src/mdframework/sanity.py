"""Motion sanity checks: is a recording humanly possible, and is its time base plausible?

Pure functions on arrays plus one entry point, :func:`check_motion`, which the motion-loading
helper (:func:`mdframework.pipeline.load_motion`) runs on every human motion right after its
source reads it, with the source config's ``sanity`` section
(:class:`mdframework.settings.SanityConfig`). Arrays and units: ``time`` (n_frames,) float64
[s]; ``positions`` (n_frames, n_joints, 3) float64 [m]; ``valid`` (n_frames, n_joints) bool.

Checks, on the canonical 17-joint body:

1. **Single-frame glitches** (:func:`find_glitches`): a frame whose position lies far off the
   line between its two neighbours (the deviation ``e``, :func:`deviations`) while the
   neighbours do not, and while the frames around it move smoothly, and after which the joint
   comes back to its path: its velocity after the frame (frame f+1 to f+2) is the one before it
   (f-2 to f-1). A one-frame spike of size ``d`` gives ``e = d`` at the frame, ``d / 2`` at
   each neighbour and no change of velocity; a real change of velocity made within one frame
   period (a foot leaving or striking the floor, 30-50 ms, is one frame at 30 Hz) gives a lone
   deviation too, but the velocity stays changed: the change times ``dt1 dt2 / (dt1 + dt2)``
   (:func:`turns`) equals ``e`` there, and exceeds it when the change is spread over several
   frames. Thresholds: ``glitch_min_m`` (2 cm), ``glitch_ratio`` (1.6 x the neighbours),
   ``glitch_local_ratio`` (5 x the median of the 13 frames around) and
   ``glitch_return_ratio`` (the velocity change at most 0.3 x ``e``). The first three alone
   held at 120 Hz only, where a foot's change of velocity spreads over several frames; the
   last, a ratio of two distances of one frame, holds at any frame rate. Flagged in the
   metadata and warned about by default; ``glitches = "repair"`` replaces the frame by linear
   interpolation from the unflagged frames (:func:`repair_glitches`). Only frames with two
   valid frames on either side, one frame period apart (no step longer than
   :data:`GAP_STEP_RATIO` times the median step), are judged, and the local median is taken
   over such measured deviations: beside a gap (missing samples or missing frames) a
   neighbour's deviation is unknown or spans the gap, and a real frame there would look like
   a spike.
2. **Human limits**: the frame-to-frame speed and the acceleration
   implied by ``e`` (``2 e / (dt1 dt2)``) against :data:`SPEED_LIMITS_MPS` and
   :data:`ACCEL_LIMITS_MPS2` (times ``speed_scale``).
3. **Bone lengths** (:func:`bone_lengths`): the coefficient of variation of each limb bone's
   length over the valid frames. A rigid rig (BVH, ASF/AMC) gives 0 to rounding; optical and
   depth-camera tracks vary (a Kinect's limbs by several per cent); above ``bone_tolerance``
   (10 %) the motion is flagged.
4. **Cadence** (:func:`cadence_estimate`): for motions labelled walk or run/jog, steps per
   minute from the clearest period among the distance between the ankles (a step) and the
   left-right height alternation of the ankles, knees and hands (a stride: what running on the
   spot shows); outside ``walk_cadence`` (70-150) or ``run_cadence`` (130-230) the motion is
   flagged: usually a wrong frame rate.
5. **Upright** (:func:`head_rise`): the median height of the head above the pelvis over the
   frames; below ``upright_min_m`` (0.2 m; the shipped recordings, boxing and sitting down
   included, give 0.45-0.8 m) the body lies flat or stands on its head, which a file read with
   the wrong up axis gives: the message names the sources' ``axes`` option.
6. **Size** (:func:`leg_length`): the median length of a leg, hip to knee to ankle; outside
   ``leg_length_m`` (0.4-1.5 m; the shipped recordings give 0.76-1.04 m) the file was read in
   the wrong length unit. A body of the wrong size is not judged upright or not.
7. **Mirrored** (:func:`foot_facing_cosine`), on an upright body: the median cosine between
   where the feet point (toes ahead of ankles) and the facing direction the left and right
   joints give; below 0 the body is a mirror image (a left-handed file, which a source's
   ``handedness = "left"`` reads, or left and right joints named the other way round), whose
   left lies on its right.
"""

from __future__ import annotations

import dataclasses
import warnings
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .conditioning import correlation_peaks, lag_correlation
from .errors import DataFileError
from .interfaces import Motion
from .settings import SanityConfig
from .skeleton import CANONICAL_JOINTS, Skeleton

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

_TRUNK = ("base", "neck", "head", "l_shoulder", "r_shoulder", "l_hip", "r_hip")
_MIDDLE = ("l_elbow", "r_elbow", "l_knee", "r_knee")
_DISTAL = ("l_hand", "r_hand", "l_ankle", "r_ankle", "l_toe", "r_toe")

#: Largest plausible speed of each canonical joint [m/s]: the trunk moves with the body (a
#: sprinter peaks near 10-12 m/s); elbows and knees a little faster; hands and feet swing at up
#: to about twice the body speed.
SPEED_LIMITS_MPS: dict[str, float] = {
    **dict.fromkeys(_TRUNK, 12.0),
    **dict.fromkeys(_MIDDLE, 16.0),
    **dict.fromkeys(_DISTAL, 25.0),
}

#: Largest plausible acceleration of each canonical joint [m/s^2], as seen in frame-to-frame
#: second differences of clean optical captures at 120 Hz (the shipped CMU runs reach about
#: 500 m/s^2 at the trunk, 630 at a boxer's shoulder, and 900 m/s^2 at the toes at foot strike).
ACCEL_LIMITS_MPS2: dict[str, float] = {
    **dict.fromkeys(_TRUNK, 800.0),
    **dict.fromkeys(_MIDDLE, 1000.0),
    **dict.fromkeys(_DISTAL, 1500.0),
}

#: Limb bones whose length a body cannot change, as (proximal, distal) canonical joints.
LIMB_BONES: tuple[tuple[str, str], ...] = (
    ("l_shoulder", "l_elbow"),
    ("r_shoulder", "r_elbow"),
    ("l_elbow", "l_hand"),
    ("r_elbow", "r_hand"),
    ("l_hip", "l_knee"),
    ("r_hip", "r_knee"),
    ("l_knee", "l_ankle"),
    ("r_knee", "r_ankle"),
)

_MAX_LISTED = 50

#: A step between frames longer than this many times the median step is a gap (frames the
#: recording lacks): a dropped frame gives 2, timing jitter of a depth camera under 1.2.
GAP_STEP_RATIO = 1.5

#: Frames in the window of the local median of :func:`find_glitches`.
_LOCAL_FRAMES = 13


class MotionSanityWarning(UserWarning):
    """A motion looks physically implausible (glitch, limit, bone length, cadence)."""


# --------------------------------------------------------------------------- building blocks


def motion_file(motion: Motion) -> str:
    """The motion's file as the config resolves it (``metadata['path']``), else its name or
    source: how messages about a motion name it."""
    md = motion.metadata
    return str(md.get("path") or md.get("file") or md.get("source", "motion"))


def deviations(
    time: FloatArray, positions: FloatArray, valid: BoolArray | None = None
) -> tuple[FloatArray, FloatArray]:
    """Each frame's distance from the line between its two neighbours.

    Returns ``e`` (n_frames, n_joints) [m] and the implied acceleration
    ``2 e / (dt1 dt2)`` (n_frames, n_joints) [m/s^2]; both are 0 at the first and last frame
    and wherever one of the three frames is invalid.
    """
    t = np.asarray(time, dtype=np.float64)
    p = np.asarray(positions, dtype=np.float64)
    n, nj = p.shape[:2]
    e = np.zeros((n, nj))
    acc = np.zeros((n, nj))
    if n < 3:
        return e, acc
    dt1 = t[1:-1] - t[:-2]
    dt2 = t[2:] - t[1:-1]
    w = (dt1 / (dt1 + dt2))[:, None, None]
    pred = p[:-2] + (p[2:] - p[:-2]) * w
    inner = np.linalg.norm(p[1:-1] - pred, axis=2)
    if valid is not None:
        ok = valid[:-2] & valid[1:-1] & valid[2:]
        inner = np.where(ok, inner, 0.0)
    inner = np.nan_to_num(inner, nan=0.0)
    e[1:-1] = inner
    acc[1:-1] = 2.0 * inner / (dt1 * dt2)[:, None]
    return e, acc


def find_glitches(
    time: FloatArray,
    positions: FloatArray,
    valid: BoolArray | None = None,
    *,
    min_m: float = 0.02,
    ratio: float = 1.6,
    local_ratio: float = 5.0,
    return_ratio: float = 0.3,
) -> BoolArray:
    """Single-frame glitches, (n_frames, n_joints) bool (see the module docstring)."""
    e, _ = deviations(time, positions, valid)
    measured = _measured(time, valid, e.shape)
    back = e * return_ratio >= turns(time, positions)
    return _glitch_mask(e, measured, back, min_m, ratio, local_ratio)


def turns(time: FloatArray, positions: FloatArray) -> FloatArray:
    """How far each frame's velocity changes across it, as a distance comparable with
    :func:`deviations`: ``|v_after - v_before| dt1 dt2 / (dt1 + dt2)``, (n_frames, n_joints)
    [m], with ``v_before`` from frame f-2 to f-1, ``v_after`` from f+1 to f+2 and ``dt1``,
    ``dt2`` the steps either side of frame f.

    A real change of velocity made at frame f gives its deviation ``e`` exactly, one spread
    over several frames more; a one-frame spike on a steady path 0 (the joint comes back).
    Infinite at the first and last two frames and where a position is not finite.
    """
    t = np.asarray(time, dtype=np.float64)
    p = np.asarray(positions, dtype=np.float64)
    out = np.full(p.shape[:2], np.inf)
    if t.shape[0] < 5:
        return out
    before = (p[1:-3] - p[:-4]) / (t[1:-3] - t[:-4])[:, None, None]
    after = (p[4:] - p[3:-1]) / (t[4:] - t[3:-1])[:, None, None]
    dt1, dt2 = t[2:-2] - t[1:-3], t[3:-1] - t[2:-2]
    change = np.linalg.norm(after - before, axis=2) * (dt1 * dt2 / (dt1 + dt2))[:, None]
    out[2:-2] = np.nan_to_num(change, nan=np.inf)
    return out


def _measured(time: FloatArray, valid: BoolArray | None, shape: tuple[int, ...]) -> BoolArray:
    """Where :func:`deviations` measures a frame, (n_frames, n_joints) bool: the frame and
    both its neighbours valid, each step between them at most :data:`GAP_STEP_RATIO` times the
    median step. ``shape`` is (n_frames, n_joints); ``valid`` None: every sample valid."""
    t = np.asarray(time, dtype=np.float64)
    ok = np.zeros(shape[:2], dtype=bool)
    if t.shape[0] < 3:
        return ok
    step = np.diff(t)
    regular = step <= GAP_STEP_RATIO * float(np.median(step))
    v = np.ones(shape[:2], dtype=bool) if valid is None else np.asarray(valid, dtype=bool)
    ok[1:-1] = v[:-2] & v[1:-1] & v[2:] & (regular[:-1] & regular[1:])[:, None]
    return ok


def long_gaps(time: FloatArray, valid: BoolArray, max_gap_s: float) -> list[dict[str, Any]]:
    """Gaps longer than ``max_gap_s`` [s] that interpolation bridges, longest first: a joint
    untracked between two tracked frames (``joint`` its name index), or a step between frames
    (``joint`` None: frames the recording lacks). ``time`` (n_frames,) [s]; ``valid``
    (n_frames, n_joints) bool. A step between frames counts when also longer than
    :data:`GAP_STEP_RATIO` times the median step. Each item: joint, from_s and to_s (the
    frames around the gap, from the first frame), duration_s."""
    t = np.asarray(time, dtype=np.float64)
    out: list[dict[str, Any]] = []
    step = np.diff(t)
    # frames the recording lacks: a step longer than max_gap_s and than a frame period (a
    # recording of 4 frames a second is coarse, not gapped)
    longest = max(max_gap_s, GAP_STEP_RATIO * float(np.median(step))) if step.size else max_gap_s
    for k in np.flatnonzero(step > longest):
        out.append({"joint": None, "from_s": t[k] - t[0], "to_s": t[k + 1] - t[0]})
    for j in range(valid.shape[1]):
        seen = np.flatnonzero(valid[:, j])
        # with frames inside, all untracked (a long step alone is a frame gap, above)
        for k in np.flatnonzero((np.diff(t[seen]) > max_gap_s) & (np.diff(seen) > 1)):
            out.append({"joint": j, "from_s": t[seen[k]] - t[0], "to_s": t[seen[k + 1]] - t[0]})
    for g in out:
        g["from_s"], g["to_s"] = round(float(g["from_s"]), 6), round(float(g["to_s"]), 6)
        g["duration_s"] = round(g["to_s"] - g["from_s"], 6)
    return sorted(out, key=lambda g: -g["duration_s"])


def _glitch_mask(
    e: FloatArray,
    measured: BoolArray,
    back: BoolArray,
    min_m: float,
    ratio: float,
    local_ratio: float,
) -> BoolArray:
    """:func:`find_glitches` from the deviations ``e`` (n_frames, n_joints) [m], where they
    are measured (:func:`_measured`) and where the joint comes back to its path (``back``, from
    :func:`turns`): a frame is judged only where it and both neighbours are measured, against
    the median of the measured deviations around it."""
    from scipy.ndimage import maximum_filter, median_filter

    mask = np.zeros(e.shape, dtype=bool)
    if e.shape[0] < 5:
        return mask
    judged = np.zeros(e.shape, dtype=bool)
    judged[1:-1] = measured[:-2] & measured[1:-1] & measured[2:]
    neighbours = np.zeros(e.shape)
    neighbours[1:-1] = np.maximum(e[:-2], e[2:])
    mask = judged & back & (e >= min_m) & (e >= ratio * neighbours)
    local = median_filter(e, size=(_LOCAL_FRAMES, 1), mode="nearest")
    # a window that reaches an unmeasured deviation (a gap, the record's ends): the median of
    # the measured ones in it
    half = _LOCAL_FRAMES // 2
    holes = maximum_filter(~measured, size=(_LOCAL_FRAMES, 1), mode="constant", cval=True)
    for f, j in zip(*np.nonzero(mask & holes), strict=True):
        lo, hi = max(f - half, 0), f + half + 1
        local[f, j] = np.median(e[lo:hi, j][measured[lo:hi, j]])
    return np.asarray(mask & (e >= local_ratio * local))


def repair_glitches(
    time: FloatArray, positions: FloatArray, mask: BoolArray, valid: BoolArray | None = None
) -> FloatArray:
    """Positions with every flagged (frame, joint) replaced by linear interpolation in time
    from that joint's unflagged valid frames; (n_frames, n_joints, 3) [m]."""
    out = np.array(positions, dtype=np.float64, copy=True)
    for j in np.flatnonzero(mask.any(axis=0)):
        bad = mask[:, j]
        keep = ~bad if valid is None else ~bad & valid[:, j]
        if not keep.any():
            continue
        for c in range(3):
            out[bad, j, c] = np.interp(time[bad], time[keep], positions[keep, j, c])
    return out


def joint_speeds(time: FloatArray, positions: FloatArray) -> FloatArray:
    """Speed between consecutive frames, (n_frames - 1, n_joints) [m/s]."""
    step = np.linalg.norm(np.diff(positions, axis=0), axis=2)
    return np.asarray(step / np.diff(time)[:, None], dtype=np.float64)


def _limit_violations(
    skeleton: Skeleton, acc: FloatArray, scale: float, exclude: BoolArray | None
) -> list[dict[str, Any]]:
    """Joints of a canonical skeleton over the speed or acceleration limits, with the implied
    accelerations ``acc`` (n_frames, n_joints) [m/s^2] of :func:`deviations`.

    ``exclude`` (n_frames, n_joints) marks frames already reported as glitches (their implied
    acceleration is not counted twice). Returns one entry per offending joint and quantity:
    ``joint``, ``quantity`` ('speed' [m/s] or 'acceleration' [m/s^2]), ``max``, ``limit``,
    ``frames`` (count over the limit) and ``first_time_s``.
    """
    t, p, valid = skeleton.time, skeleton.positions, skeleton.valid
    out: list[dict[str, Any]] = []
    if skeleton.n_frames < 3:
        return out
    speed = joint_speeds(t, p)
    speed = np.where(valid[1:] & valid[:-1], np.nan_to_num(speed, nan=0.0), 0.0)
    if exclude is not None:
        acc = np.where(exclude, 0.0, acc)
    for j, name in enumerate(skeleton.joint_names):
        for quantity, values, limits, times in (
            ("speed", speed[:, j], SPEED_LIMITS_MPS, t[1:]),
            ("acceleration", acc[:, j], ACCEL_LIMITS_MPS2, t),
        ):
            limit = limits.get(name)
            if limit is None:
                continue
            over = values > limit * scale
            if over.any():
                out.append(
                    {
                        "joint": name,
                        "quantity": quantity,
                        "max": float(values.max()),
                        "limit": limit * scale,
                        "frames": int(over.sum()),
                        "first_time_s": float(times[np.argmax(over)] - t[0]),
                    }
                )
    return out


def bone_lengths(skeleton: Skeleton) -> dict[str, dict[str, float]]:
    """Mean length [m] and coefficient of variation (std / mean) of each limb bone
    (:data:`LIMB_BONES`) of a canonical skeleton, over the frames where both ends are valid."""
    out: dict[str, dict[str, float]] = {}
    for a, b in LIMB_BONES:
        ia, ib = skeleton.index(a), skeleton.index(b)
        ok = skeleton.valid[:, ia] & skeleton.valid[:, ib]
        if ok.sum() < 2:
            continue
        length = np.linalg.norm(skeleton.positions[ok, ib] - skeleton.positions[ok, ia], axis=1)
        mean = float(length.mean())
        out[f"{a}-{b}"] = {
            "mean_m": mean,
            "cv": float(length.std() / mean) if mean > 0 else 0.0,
        }
    return out


def _period_strength(
    time: FloatArray, signal: FloatArray, min_strength: float = 0.3
) -> tuple[float, float] | None:
    """(period [s], autocorrelation there) of the signal's shortest clear period, or None:
    the first peak of its biased autocorrelation (after the first zero crossing) that reaches
    ``min_strength``, located on the normalised autocorrelation to a fraction of a sample
    (:func:`~mdframework.conditioning.correlation_peaks`; at 15 frames per second a
    whole-sample lag is 10 % off).

    The first such peak rather than the highest one: in a short clip the autocorrelation at a
    multiple of the period can be higher than at the period itself.
    """
    found = lag_correlation(time, signal)
    if found is None:
        return None
    peaks = correlation_peaks(found[0], found[1])
    lag, value = next((p for p in peaks if p[1] >= min_strength), (None, 0.0))
    return None if lag is None else (lag * found[2], value)


def cadence_estimate(
    time: FloatArray,
    l_ankle: FloatArray,
    r_ankle: FloatArray,
    pairs: dict[str, tuple[FloatArray, FloatArray]] | None = None,
) -> tuple[float, str] | None:
    """Steps per minute and the signal it came from, or None if no signal has a clear period.

    Candidates (positions (n_frames, 3) [m], z up):

    - ``ankle distance``: the distance between the ankles peaks once per step (feet apart at
      double support in a walk), so steps per minute = 60 / its period;
    - ``<pair> alternation``: for each pair in ``pairs`` (e.g. knees, hands), the signed
      height difference left minus right swings once per stride (two steps), so steps per
      minute = 120 / its period. This is what a run on the spot shows: the feet stay side by
      side (their distance has no clear period), while the knees and feet rise in turn and the
      arms swing against them.

    The candidate whose autocorrelation peak is strongest wins. Every candidate scales with the
    time base, so a wrong frame rate still shows as an implausible cadence.
    """
    t = np.asarray(time, dtype=np.float64)
    found: list[tuple[float, float, str]] = []  # (strength, steps/min, signal)
    dist = np.linalg.norm(np.asarray(l_ankle, dtype=np.float64) - r_ankle, axis=1)
    ok = np.isfinite(dist)
    if ok.sum() >= 8:
        ps = _period_strength(t[ok], dist[ok])
        if ps is not None:
            found.append((ps[1], 60.0 / ps[0], "ankle distance"))
    for name, (left, right) in (pairs or {}).items():
        dz = np.asarray(left, dtype=np.float64)[:, 2] - np.asarray(right, dtype=np.float64)[:, 2]
        ok = np.isfinite(dz)
        if ok.sum() < 8:
            continue
        ps = _period_strength(t[ok], dz[ok])
        if ps is not None:
            found.append((ps[1], 120.0 / ps[0], f"{name} alternation"))
    if not found:
        return None
    best = max(found, key=lambda f: f[0])
    return best[1], best[2]


def cadence_spm(
    time: FloatArray,
    l_ankle: FloatArray,
    r_ankle: FloatArray,
    pairs: dict[str, tuple[FloatArray, FloatArray]] | None = None,
) -> float | None:
    """Steps per minute (:func:`cadence_estimate`), or None if nothing has a clear period.

    With the ankles alone: the distance between them peaks once per step (feet apart at double
    support for a walk) whichever foot leads, so the cadence is ``60 / period`` (the first
    clear period of its autocorrelation, strength 0.3 or more). A recording shorter than about
    two steps gives None.
    """
    found = cadence_estimate(time, l_ankle, r_ankle, pairs)
    return None if found is None else found[0]


def head_rise(body: Skeleton) -> float | None:
    """Median over the frames of the head's height above the pelvis [m] (canonical ``head``
    z minus ``base`` z, frames where both are valid); None without such a frame."""
    rise = body.joint("head")[:, 2] - body.joint("base")[:, 2]
    ok = np.isfinite(rise) & body.valid[:, body.index("head")] & body.valid[:, body.index("base")]
    return float(np.median(rise[ok])) if ok.any() else None


def leg_length(body: Skeleton) -> float | None:
    """Median over the frames and both sides of a leg's length [m], hip to knee plus knee to
    ankle (frames where the three joints are valid); None without such a frame. The shipped
    recordings give 0.76-1.04 m; a file read in the wrong length unit scales it by the units'
    ratio (2.54 for inches and centimetres, 10, 100, 1000)."""
    lengths = []
    for side in ("l", "r"):
        names = [f"{side}_{j}" for j in ("hip", "knee", "ankle")]
        hip, knee, ankle = (body.joint(n) for n in names)
        ok = np.all(body.valid[:, [body.index(n) for n in names]], axis=1)
        thigh = np.linalg.norm(hip - knee, axis=1)
        shin = np.linalg.norm(knee - ankle, axis=1)
        lengths.append((thigh + shin)[ok])
    both = np.concatenate(lengths)
    return float(np.median(both)) if both.size else None


def foot_facing_cosine(body: Skeleton) -> float | None:
    """Median over the frames of the cosine between where the feet point and where the left
    and right joints say the body faces, both horizontal: the feet ``(l_toe - l_ankle) +
    (r_toe - r_ankle)``, the facing ``L x z`` with ``L = (l_hip - r_hip) + (l_shoulder -
    r_shoulder)`` (a body's left at +y faces +x). Near +1 for a real body (the shipped
    recordings give 0.73-1.00); near -1 for a mirror image, whose left joints lie on its right.
    None without a frame where all of these joints are valid and both directions are
    nonzero."""
    names = ("l_toe", "l_ankle", "r_toe", "r_ankle", "l_hip", "r_hip", "l_shoulder", "r_shoulder")
    p = {n: body.joint(n) for n in names}
    ok = np.all(body.valid[:, [body.index(n) for n in names]], axis=1)
    feet = (p["l_toe"] - p["l_ankle"] + p["r_toe"] - p["r_ankle"])[ok, :2]
    left = (p["l_hip"] - p["r_hip"] + p["l_shoulder"] - p["r_shoulder"])[ok, :2]
    facing = np.stack([left[:, 1], -left[:, 0]], axis=1)  # (L x z) in the horizontal plane
    norms = np.linalg.norm(feet, axis=1) * np.linalg.norm(facing, axis=1)
    keep = norms > 0
    if not keep.any():
        return None
    return float(np.median(np.sum(feet * facing, axis=1)[keep] / norms[keep]))


def _activity_kind(activity: str) -> str | None:
    a = activity.lower()
    if "walk" in a:
        return "walk"
    if "run" in a or "jog" in a:
        return "run"
    return None


# --------------------------------------------------------------------------- entry point


def check_motion(motion: Motion, config: SanityConfig) -> Motion:
    """Run the checks on a motion; return it with ``metadata["sanity"]`` (and repaired
    positions when ``glitches = "repair"``).

    Motions without a canonical body (point targets) are returned unchanged. Findings are
    warned about (:class:`MotionSanityWarning`) unless their option says ``ignore``; an
    option set to ``error`` raises :class:`mdframework.DataFileError` naming the file.
    """
    if not config.enabled or motion.canonical_map is None:
        return motion
    body = motion.canonical()
    where = motion_file(motion)  # as the config resolves it, as the sources' warnings name it
    report: dict[str, Any] = {}
    notes: list[tuple[str, str]] = []  # (option, message)

    e, acc = deviations(body.time, body.positions, body.valid)  # once for the checks below
    measured = _measured(body.time, body.valid, e.shape)
    back = e * config.glitch_return_ratio >= turns(body.time, body.positions)
    mask = _glitch_mask(
        e, measured, back, config.glitch_min_m, config.glitch_ratio, config.glitch_local_ratio
    )
    frames, joints = np.nonzero(mask)
    items = [
        {
            "joint": body.joint_names[j],
            "frame": int(f),
            "time_s": round(float(body.time[f] - body.time[0]), 6),
            "deviation_m": round(float(e[f, j]), 4),
        }
        for f, j in zip(frames[:_MAX_LISTED], joints[:_MAX_LISTED], strict=True)
    ]
    skeleton = motion.skeleton
    repaired = False
    if frames.size and config.glitches == "repair":
        skeleton = _repair_source(motion, mask)
        repaired = True
    report["glitches"] = {"count": int(frames.size), "repaired": repaired, "items": items}
    if frames.size:
        listed = ", ".join(f"{it['joint']} at {it['time_s']:.3f} s" for it in items[:4])
        more = f" and {frames.size - 4} more" if frames.size > 4 else ""
        action = "repaired" if repaired else "set motion.sanity.glitches = 'repair' to repair"
        notes.append(
            (
                config.glitches,
                f"{frames.size} single-frame glitch(es): {listed}{more} ({action})",
            )
        )

    over = _limit_violations(body, acc, config.speed_scale, mask)
    report["limits"] = over
    if over:
        worst = over[0]
        unit = "m/s" if worst["quantity"] == "speed" else "m/s^2"
        notes.append(
            (
                config.limits,
                f"{len(over)} joint limit(s) exceeded, e.g. {worst['joint']} {worst['quantity']} "
                f"{worst['max']:.3g} {unit} > {worst['limit']:.3g} at "
                f"{worst['first_time_s']:.3f} s",
            )
        )

    gaps = long_gaps(body.time, body.valid, config.max_gap_s)
    for g in gaps:
        g["joint"] = None if g["joint"] is None else body.joint_names[g["joint"]]
    report["gaps"] = {
        "count": len(gaps),
        "max_gap_s": config.max_gap_s,
        "items": gaps[:_MAX_LISTED],
    }
    if gaps:
        g = gaps[0]
        what = "the recording has no frame" if g["joint"] is None else f"{g['joint']} is untracked"
        more = f" (and {len(gaps) - 1} more such gap(s))" if len(gaps) > 1 else ""
        notes.append(
            (
                config.gaps,
                f"{what} for {g['duration_s']:.3f} s ({g['from_s']:.3f}-{g['to_s']:.3f} s), "
                f"longer than motion.sanity.max_gap_s = {config.max_gap_s:g} s{more}: the "
                "simulation interpolates across such gaps in the records that span them; fill "
                "them in the file, or cut records without them (motion.start, motion.duration) "
                "and set motion.sanity.gaps = 'ignore' (the check reads the whole file)",
            )
        )

    bones = bone_lengths(body)
    cv_max = max((b["cv"] for b in bones.values()), default=0.0)
    report["bones"] = {"cv_max": cv_max, "tolerance": config.bone_tolerance, "bones": bones}
    if cv_max > config.bone_tolerance:
        name = max(bones, key=lambda k: bones[k]["cv"])
        notes.append(
            (
                "warn",
                f"bone {name} varies in length by {100 * cv_max:.0f} % (std/mean; tolerance "
                f"{100 * config.bone_tolerance:.0f} %): the joints are not tracked consistently",
            )
        )

    activity = str(motion.metadata.get("activity", ""))
    kind = _activity_kind(activity)
    if config.cadence and kind is not None:
        pairs = {
            side: (body.joint(f"l_{side[:-1]}"), body.joint(f"r_{side[:-1]}"))
            for side in ("ankles", "knees", "hands")
        }
        est = cadence_estimate(body.time, body.joint("l_ankle"), body.joint("r_ankle"), pairs)
        spm = None if est is None else est[0]
        lo, hi = config.walk_cadence if kind == "walk" else config.run_cadence
        rate = motion.metadata.get("frame_rate_hz")
        report["cadence"] = {
            "activity": activity,
            "steps_per_min": spm,
            "from": None if est is None else est[1],
            "plausible": [lo, hi],
            "ok": spm is None or lo <= spm <= hi,
        }
        if spm is not None and not lo <= spm <= hi:
            at = f" at the assumed {rate:g} Hz" if isinstance(rate, int | float) else ""
            notes.append(
                (
                    "warn",
                    f"labelled {activity!r} but steps {spm:.0f} times a minute{at} (plausible "
                    f"{lo:g}-{hi:g}): check the frame rate or time base",
                )
            )

    leg = leg_length(body)
    lo_leg, hi_leg = config.leg_length_m
    sized = leg is None or lo_leg <= leg <= hi_leg
    report["size"] = {"median_leg_m": leg, "plausible": [lo_leg, hi_leg], "ok": sized}
    if not sized:
        assert leg is not None
        notes.append(
            (
                config.size,
                f"the legs are {leg:.3g} m long (hip to knee to ankle, median over the frames; "
                f"people's {lo_leg:g}-{hi_leg:g} m): the file's length unit is likely not the "
                "one it was read in: check its unit (motion.unit_m, or motion.units for a table)",
            )
        )

    rise = head_rise(body)
    # judged at human size only: a body scaled by a wrong unit is the size check's finding
    upright = rise is None or rise >= config.upright_min_m or not sized
    report["upright"] = {"median_head_rise_m": rise, "min_m": config.upright_min_m, "ok": upright}
    if not upright:
        assert rise is not None
        notes.append(
            (
                config.upright,
                f"the body is not upright: the head is {rise:.2f} m above the pelvis (median "
                f"over the frames; upright bodies {config.upright_min_m:g} m or more): if the "
                "file's up axis is not the one its source assumes, set motion.axes",
            )
        )

    # judged on an upright body only: lying down, the horizontal plane holds its length
    cos = foot_facing_cosine(body) if upright else None
    report["mirrored"] = {"median_foot_facing_cos": cos, "ok": cos is None or cos >= 0.0}
    if cos is not None and cos < 0.0:
        notes.append(
            (
                config.mirrored,
                f"the body looks mirrored: its feet point backwards from the way its left and "
                f"right joints face (median cosine {cos:.2f}; real bodies near +1), so its left "
                "is on its right: the file's frame is left-handed (a mirror image, which the "
                "sources that have motion.axes read with motion.handedness = 'left') or its left "
                "and right joints are named the other way round",
            )
        )

    report["warnings"] = [msg for option, msg in notes if option != "ignore"]
    for option, msg in notes:
        if option == "error":
            raise DataFileError(where, f"motion sanity: {msg}")
    for option, msg in notes:
        if option in ("warn", "repair"):
            warnings.warn(f"{where}: {msg}", MotionSanityWarning, stacklevel=3)
    meta = {**dict(motion.metadata), "sanity": report}
    return dataclasses.replace(motion, skeleton=skeleton, metadata=meta)


def _repair_source(motion: Motion, mask: BoolArray) -> Skeleton:
    """The source skeleton with the glitches of canonical joints repaired in the joints they
    map to."""
    assert motion.canonical_map is not None
    sk = motion.skeleton
    src_mask = np.zeros((sk.n_frames, sk.n_joints), dtype=bool)
    for j, name in enumerate(CANONICAL_JOINTS):
        src_mask[:, sk.index(motion.canonical_map[name])] |= mask[:, j]
    return sk.with_positions(repair_glitches(sk.time, sk.positions, src_mask, sk.valid))
