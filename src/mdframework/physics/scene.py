"""Placing a recording in the scene (pure functions on joint arrays).

Scene frame: right-handed, ``z`` up, metres. Headings are angles in the horizontal plane from
``+x`` toward ``+y`` [rad]. A body's facing direction is the horizontal unit vector 90 degrees
clockwise (seen from above) from its right-hip -> left-hip vector.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def rotation_z(angle: float) -> FloatArray:
    """Active rotation by ``angle`` [rad] about ``+z``, (3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def facing_heading(left_hip: FloatArray, right_hip: FloatArray) -> float:
    """Mean facing heading [rad] of a body from hip tracks (n_frames, 3) [m]."""
    left = np.nanmean(left_hip - right_hip, axis=0)
    if not np.all(np.isfinite(left)) or np.hypot(left[0], left[1]) < 1e-9:
        raise ValueError("cannot find the body's facing direction: the hips coincide")
    # forward = left rotated by -90 degrees about z: (lx, ly) -> (ly, -lx)
    return float(np.arctan2(-left[0], left[1]))


def travel_heading(base: FloatArray) -> tuple[float, float]:
    """Heading [rad] of the straight line from the first to the last hip-centre position
    (n_frames, 3) [m], and the horizontal distance [m] travelled along it."""
    d = base[-1, :2] - base[0, :2]
    return float(np.arctan2(d[1], d[0])), float(np.hypot(d[0], d[1]))


def body_heading(
    base: FloatArray,
    left_hip: FloatArray,
    right_hip: FloatArray,
    *,
    rule: str = "auto",
    min_travel: float = 0.5,
) -> float:
    """The direction [rad] a recording's body is taken to face.

    ``hips``: perpendicular to the hip line (:func:`facing_heading`); ``travel``: the direction
    of travel of the hip centre (:func:`travel_heading`); ``auto``: travel when the hip centre
    moves more than ``min_travel`` [m] over the recording (walking, running: the hip line of a
    Kinect seen from the side is unreliable), else the hips (boxing, jumping in place).
    """
    if rule not in ("auto", "hips", "travel"):
        raise ValueError(f"unknown facing rule {rule!r}")
    heading, distance = travel_heading(base)
    if rule == "travel" or (rule == "auto" and distance > min_travel):
        if distance < 1e-6:
            raise ValueError("cannot find the direction of travel: the hip centre does not move")
        return heading
    return facing_heading(left_hip, right_hip)


def linear_drift_rate(time: FloatArray, track: FloatArray) -> FloatArray:
    """Slope (2,) [m/s] of the least-squares straight-line fit of a horizontal track
    (n_frames, 2) [m] over ``time`` (n_frames,) [s]: the velocity a treadmill removes."""
    t = time - time[0]
    a = np.stack([np.ones_like(t), t], axis=1)
    coef, *_ = np.linalg.lstsq(a, track, rcond=None)
    return np.asarray(coef[1], dtype=np.float64)


@dataclass(frozen=True)
class Placement:
    """A recording's placement in the scene, affine in time (see :func:`placement`): joints
    at time ``t`` [s] go to ``R (x - origin) + offset + (t - t0) travel - (t - t0) drift``, the
    last three horizontal. ``rotation`` (3, 3); ``origin`` (3,) [m]; ``offset`` (2,) [m];
    ``drift`` and ``travel`` (2,) [m/s] or None; ``t0`` [s], the recording's first frame."""

    rotation: FloatArray
    origin: FloatArray
    offset: FloatArray
    t0: float
    drift: FloatArray | None = None
    travel: FloatArray | None = None

    def apply(self, time: FloatArray, joints: FloatArray) -> FloatArray:
        """Joints (n_frames, n_joints, 3) [m] at ``time`` (n_frames,) [s], any frames of the
        recording (a window alone gives the same positions as the whole, sliced), placed."""
        n, k = joints.shape[:2]
        moved = ((joints - self.origin).reshape(-1, 3) @ self.rotation.T).reshape(n, k, 3)
        since = (time - self.t0)[:, None, None]
        if self.drift is not None:
            moved[:, :, :2] -= since * self.drift
        if self.travel is not None:
            moved[:, :, :2] += since * self.travel
        moved[:, :, :2] += self.offset
        return np.asarray(moved, dtype=np.float64)


def placement(
    time: FloatArray,
    base: FloatArray,
    *,
    heading_now: float,
    heading: float,
    position: FloatArray,
    mode: str,
    speed: float = 0.0,
) -> Placement:
    """How to rotate and translate a recording into the scene.

    ``time`` (n_frames,) [s] and ``base`` (n_frames, 3) [m]: the whole recording's reference
    track (hip centre). The body is rotated about the vertical through its first base position
    so that ``heading_now`` becomes ``heading``; then, by ``mode``:

    - ``recorded``: its own translation is kept; the first base position moves to ``position``
      (x, y) [m] (its height is kept).
    - ``treadmill``: the straight-line horizontal drift of the base is removed (sway remains),
      and the base stays at ``position``.
    - ``straight``: as ``treadmill``, then the body moves along ``heading`` at ``speed`` [m/s].

    The drift is fitted to the whole recording, so any window of it is placed as the whole is.
    """
    if mode not in ("recorded", "treadmill", "straight"):
        raise ValueError(f"unknown motion mode {mode!r}")
    rot = rotation_z(heading - heading_now)
    origin = np.array([base[0, 0], base[0, 1], 0.0])
    drift = travel = None
    if mode in ("treadmill", "straight"):
        base_r = (base - origin) @ rot.T
        drift = linear_drift_rate(time, base_r[:, :2])
        if mode == "straight":
            travel = speed * np.array([np.cos(heading), np.sin(heading)])
    offset = np.asarray(position, dtype=np.float64)[:2]
    return Placement(rot, origin, offset, float(time[0]), drift, travel)
