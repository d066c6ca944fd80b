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


def facing_heading(left_hip: FloatArray, right_hip: FloatArray) -> float:
    """Mean facing heading [rad] of a body from hip tracks (n_frames, 3) [m]."""
    left = np.nanmean(left_hip - right_hip, axis=0)
    if not np.all(np.isfinite(left)) or np.hypot(left[0], left[1]) < 1e-9:
        raise ValueError("cannot find the body's facing direction: the hips coincide")
    # forward = left rotated by -90 degrees about z: (lx, ly) -> (ly, -lx)
    return float(np.arctan2(-left[0], left[1]))


def travel_heading(base: FloatArray) -> tuple[float, float]:
    """Heading [rad] of the straight line from the first to the last hip-centre position
    (n_frames, 3) [m] that is tracked (finite), and the horizontal distance [m] travelled
    along it (0 when no two frames are tracked)."""
    tracked = base[np.all(np.isfinite(base[:, :2]), axis=1), :2]
    if tracked.shape[0] < 2:
        return 0.0, 0.0
    d = tracked[-1] - tracked[0]
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


def scene_heading_deg(
    position: FloatArray,
    radar_position: FloatArray,
    *,
    aspect_deg: float | None = None,
    heading_deg: float | None = None,
) -> float:
    """The heading [deg] a person at horizontal ``position`` (2,) [m] is given: ``heading_deg``
    when set; else the direction from the person to the radar (``radar_position`` (3,) [m],
    its horizontal part) turned by ``aspect_deg`` (0: facing the radar, 180: facing away).
    Raises ValueError when an aspect is asked of a radar straight above the person."""
    if heading_deg is not None:
        return float(heading_deg)
    to_radar = np.asarray(radar_position, dtype=np.float64)[:2] - np.asarray(position)
    if np.hypot(to_radar[0], to_radar[1]) < 1e-9:
        raise ValueError("the radar is straight above the person; give heading_deg instead")
    return float(np.degrees(np.arctan2(to_radar[1], to_radar[0])) + (aspect_deg or 0.0))


def linear_drift_rate(time: FloatArray, track: FloatArray) -> FloatArray:
    """Slope (2,) [m/s] of the least-squares straight-line fit of a horizontal track
    (n_frames, 2) [m] over ``time`` (n_frames,) [s]: the velocity a treadmill removes (zero
    for a single frame). The closed form ``sum(dt dy) / sum(dt^2)`` about the means."""
    dt = time - np.mean(time)
    denom = float(np.sum(dt * dt))
    if denom <= 0.0:
        return np.zeros(track.shape[1])
    return np.asarray(np.sum(dt[:, None] * (track - np.mean(track, axis=0)), axis=0) / denom)


@dataclass(frozen=True)
class Placement:
    """A recording's placement in the scene, affine in time (see :func:`placement`): a joint
    ``x`` at time ``t`` [s] goes to ``Rz(turn) (x - origin) + offset + (t - t0) velocity``,
    the last two horizontal. ``turn`` [rad] about +z; ``origin`` (3,) [m]; ``offset`` (2,)
    [m]; ``velocity`` (2,) [m/s] (the treadmill's drift removed and a straight path's travel
    added; zero for a recorded path); ``t0`` [s], the recording's first frame whose base is
    tracked."""

    turn: float
    origin: FloatArray
    offset: FloatArray
    t0: float
    velocity: FloatArray

    def apply(self, time: FloatArray, joints: FloatArray) -> FloatArray:
        """Joints (n_frames, ..., 3) [m] at ``time`` (n_frames,) [s], any frames of the
        recording (a window alone gives the same positions as the whole, sliced), placed.
        Written out per coordinate (a turn about z leaves z alone): no BLAS call, whose threads
        would contend with other work on a busy machine."""
        c, s = np.cos(self.turn), np.sin(self.turn)
        x = joints[..., 0] - self.origin[0]
        y = joints[..., 1] - self.origin[1]
        since = (time - self.t0).reshape(time.shape + (1,) * (joints.ndim - 2))
        out = np.empty(joints.shape, dtype=np.float64)
        out[..., 0] = c * x - s * y + (self.offset[0] + since * self.velocity[0])
        out[..., 1] = s * x + c * y + (self.offset[1] + since * self.velocity[1])
        out[..., 2] = joints[..., 2]
        return out


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
    Frames whose base is not tracked (NaN: a capture's first frames before the tracker found
    the person) are left out: "first" means the first tracked frame, and the drift is fitted
    to the tracked frames. Raises ValueError when no frame's base is tracked.
    """
    if mode not in ("recorded", "treadmill", "straight"):
        raise ValueError(f"unknown motion mode {mode!r}")
    tracked = np.flatnonzero(np.all(np.isfinite(base[:, :2]), axis=1))
    if tracked.size == 0:
        raise ValueError("the hip centre (base) is not tracked in any frame")
    first = int(tracked[0])
    origin = np.array([base[first, 0], base[first, 1], 0.0])
    velocity = np.zeros(2)
    t0 = float(time[first])
    turned = Placement(heading - heading_now, origin, np.zeros(2), t0, velocity)
    if mode in ("treadmill", "straight"):
        t_ok = time[tracked]
        velocity = -linear_drift_rate(t_ok, turned.apply(t_ok, base[tracked])[:, :2])
        if mode == "straight":
            velocity += speed * np.array([np.cos(heading), np.sin(heading)])
    offset = np.asarray(position, dtype=np.float64)[:2]
    return Placement(heading - heading_now, origin, offset, t0, velocity)
