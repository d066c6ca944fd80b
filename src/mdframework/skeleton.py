"""Skeletons: joint tracks over time, and the canonical 17-point body.

A :class:`Skeleton` is the common currency between motion sources and the rest of the pipeline.
Arrays and units:

- ``time``: shape ``(n_frames,)``, float64, seconds, strictly increasing.
- ``positions``: shape ``(n_frames, n_joints, 3)``, float64, metres, in a right-handed frame with
  ``z`` up (sources convert at their boundary, e.g. CMU's y-up to z-up).
- ``valid``: shape ``(n_frames, n_joints)``, bool; ``False`` marks a joint that was not tracked in
  that frame (its position must then not be used).
- ``joint_names``: tuple of ``n_joints`` strings.

A skeleton's arrays are read-only: stages share skeletons (and datasets cache them across
records), so a stage that wants different positions builds a new skeleton
(:meth:`Skeleton.with_positions`) instead of changing one in place. An array given that can
still be written (the caller's own) is copied, so that the caller keeps a writeable array and a
later write to it cannot change a checked skeleton; a read-only one (another skeleton's) is
shared.

The canonical body is Chen's 17-point set used with the Boulic walking model (V. C. Chen, "The
Micro-Doppler Effect in Radar", 2011): base (hip centre), neck, head, left/right shoulder, elbow,
hand, hip, knee, ankle, toe.
Body axes: ``x`` forward, ``y`` to the subject's left, ``z`` up.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: Canonical joint names, in Chen's order.
CANONICAL_JOINTS: tuple[str, ...] = (
    "base",
    "neck",
    "head",
    "l_shoulder",
    "r_shoulder",
    "l_elbow",
    "r_elbow",
    "l_hand",
    "r_hand",
    "l_hip",
    "r_hip",
    "l_knee",
    "r_knee",
    "l_ankle",
    "r_ankle",
    "l_toe",
    "r_toe",
)

#: The 16 segments of the canonical tree as (proximal, distal) joint names.
CANONICAL_SEGMENTS: tuple[tuple[str, str], ...] = (
    ("base", "neck"),
    ("neck", "head"),
    ("neck", "l_shoulder"),
    ("neck", "r_shoulder"),
    ("l_shoulder", "l_elbow"),
    ("r_shoulder", "r_elbow"),
    ("l_elbow", "l_hand"),
    ("r_elbow", "r_hand"),
    ("base", "l_hip"),
    ("base", "r_hip"),
    ("l_hip", "l_knee"),
    ("r_hip", "r_knee"),
    ("l_knee", "l_ankle"),
    ("r_knee", "r_ankle"),
    ("l_ankle", "l_toe"),
    ("r_ankle", "r_toe"),
)


class SkeletonError(ValueError):
    """A skeleton's arrays are inconsistent (shapes, time stamps, NaN where valid)."""


@dataclass(frozen=True)
class Skeleton:
    """Joint positions over time. See the module docstring for shapes and units."""

    time: FloatArray
    positions: FloatArray
    joint_names: tuple[str, ...]
    valid: BoolArray = field(default=None)  # type: ignore[arg-type]

    def __post_init__(self) -> None:
        time = np.asarray(self.time, dtype=np.float64)
        pos = np.asarray(self.positions, dtype=np.float64)
        names = tuple(self.joint_names)
        if time.ndim != 1:
            raise SkeletonError(f"time must have shape (n_frames,), got {time.shape}")
        if pos.ndim != 3 or pos.shape[2] != 3:
            raise SkeletonError(
                f"positions must have shape (n_frames, n_joints, 3), got {pos.shape}"
            )
        if pos.shape[0] != time.shape[0]:
            raise SkeletonError(
                f"{time.shape[0]} time stamps but {pos.shape[0]} frames of positions"
            )
        if pos.shape[1] != len(names):
            raise SkeletonError(f"{pos.shape[1]} joints but {len(names)} joint names")
        if len(set(names)) != len(names):
            raise SkeletonError("joint names must be unique")
        if time.size and not np.all(np.isfinite(time)):
            raise SkeletonError("time stamps must be finite")
        if time.size > 1 and not np.all(np.diff(time) > 0):
            bad = int(np.argmax(~(np.diff(time) > 0)))
            raise SkeletonError(
                f"time stamps must be strictly increasing (frame {bad + 1}: "
                f"{float(time[bad + 1])!r} s after {float(time[bad])!r} s); sort them and drop "
                "duplicates first"
            )
        finite = np.isfinite(pos)
        if self.valid is None:
            valid = finite[:, :, 0] & finite[:, :, 1] & finite[:, :, 2]
        else:
            valid = np.asarray(self.valid, dtype=bool)
            if valid.shape != pos.shape[:2]:
                raise SkeletonError(f"valid must have shape {pos.shape[:2]}, got {valid.shape}")
            if not np.all(finite | ~valid[:, :, None]):
                raise SkeletonError("positions marked valid must be finite")
        # shared between stages (and cached): never mutated, and the caller's arrays, which
        # stay theirs to write, are not held
        time = _frozen(time, fresh=time is not self.time)
        pos = _frozen(pos, fresh=pos is not self.positions)
        valid = _frozen(valid, fresh=valid is not self.valid)
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "positions", pos)
        object.__setattr__(self, "joint_names", names)
        object.__setattr__(self, "valid", valid)

    @classmethod
    def resampled(
        cls, time: FloatArray, positions: FloatArray, joint_names: tuple[str, ...]
    ) -> Skeleton:
        """A skeleton resampled from a checked one, every joint valid (the pipeline's pulse
        blocks): ``time`` (n,) [s] strictly increasing and ``positions`` (n, n_joints, 3)
        float64 [m] finite by construction (interpolation within a checked skeleton's frames
        never extrapolates), so they are not checked again; the checks would cost a pass over
        every block."""
        return cls._trusted(time, positions, joint_names, np.ones(positions.shape[:2], dtype=bool))

    @classmethod
    def _trusted(
        cls,
        time: FloatArray,
        positions: FloatArray,
        joint_names: tuple[str, ...],
        valid: BoolArray,
    ) -> Skeleton:
        """A skeleton whose arrays hold every invariant by construction (made from a checked
        one), not checked again."""
        skeleton = object.__new__(cls)
        for name, value in (
            ("time", time),
            ("positions", positions),
            ("joint_names", joint_names),
            ("valid", valid),
        ):
            if isinstance(value, np.ndarray):
                value = _read_only(value)
            object.__setattr__(skeleton, name, value)
        return skeleton

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return int(self.time.shape[0])

    @property
    def n_joints(self) -> int:
        """Number of joints."""
        return len(self.joint_names)

    @property
    def duration(self) -> float:
        """Time from the first to the last frame [s]."""
        return float(self.time[-1] - self.time[0]) if self.n_frames else 0.0

    def index(self, name: str) -> int:
        """Index of joint ``name``; raises ``KeyError`` naming the known joints."""
        try:
            return self.joint_names.index(name)
        except ValueError:
            raise KeyError(f"no joint {name!r}; joints are {', '.join(self.joint_names)}") from None

    def joint(self, name: str) -> FloatArray:
        """Track of one joint, shape ``(n_frames, 3)`` [m]."""
        return self.positions[:, self.index(name), :]

    def select(self, names: Sequence[str]) -> Skeleton:
        """A skeleton with only the named joints, in the given order (sharing this one's arrays
        when those are all its joints in its order: no copy of a long recording)."""
        idx = [self.index(n) for n in names]
        if idx == list(range(self.n_joints)):
            return Skeleton(self.time, self.positions, tuple(names), self.valid)
        return Skeleton(self.time, self.positions[:, idx], tuple(names), self.valid[:, idx])

    def window(self, start: float | None = None, duration: float | None = None) -> Skeleton:
        """Frames with ``start <= t - time[0] <= start + duration`` (times relative to the first
        frame, seconds). Raises ``ValueError`` if the window holds fewer than two frames."""
        t_rel = self.time - self.time[0]
        lo = 0.0 if start is None else float(start)
        hi = np.inf if duration is None else lo + float(duration)
        keep = (t_rel >= lo - 1e-9) & (t_rel <= hi + 1e-9)
        if int(keep.sum()) < 2:
            raise ValueError(
                f"the window start={lo} s, duration={duration} s holds fewer than two frames "
                f"of a {self.duration:.3f} s recording"
            )
        return Skeleton(self.time[keep], self.positions[keep], self.joint_names, self.valid[keep])

    def select_frames(self, frames: slice) -> Skeleton:
        """The frames ``frames`` (a slice of frame indices, a positive step). The frames of a
        checked skeleton are not checked again."""
        if frames.step is not None and frames.step < 1:
            raise ValueError("select_frames needs a slice with a positive step")
        return Skeleton._trusted(
            self.time[frames], self.positions[frames], self.joint_names, self.valid[frames]
        )

    def renamed(self, names: Sequence[str]) -> Skeleton:
        """Same data with new joint names (same count and order)."""
        return Skeleton(self.time, self.positions, tuple(names), self.valid)

    def with_positions(self, positions: FloatArray) -> Skeleton:
        """Same time stamps, names and validity with new positions."""
        return Skeleton(self.time, positions, self.joint_names, self.valid)


def _frozen(array: NDArray[Any], fresh: bool) -> NDArray[Any]:
    """``array`` made read-only: itself when ``fresh`` (made here) or when nothing can write it
    (it and every array it views are read-only), else a read-only copy."""
    if not fresh:
        seen: Any = array
        while isinstance(seen, np.ndarray):
            if seen.flags.writeable:
                array = array.copy()
                break
            seen = seen.base
        else:
            return array
    array.flags.writeable = False
    return array


def _read_only(array: NDArray[Any]) -> NDArray[Any]:
    """A read-only view of ``array`` (the array itself, the caller's, is left as it was)."""
    view = array.view()
    view.flags.writeable = False
    return view


def to_canonical(skeleton: Skeleton, mapping: Mapping[str, str]) -> Skeleton:
    """Map a source skeleton to the canonical 17 joints.

    ``mapping`` maps every canonical joint name to a source joint name. The result has
    ``joint_names == CANONICAL_JOINTS``.
    """
    missing = [j for j in CANONICAL_JOINTS if j not in mapping]
    if missing:
        raise KeyError(f"joint mapping lacks canonical joints: {', '.join(missing)}")
    return skeleton.select([mapping[j] for j in CANONICAL_JOINTS]).renamed(CANONICAL_JOINTS)


def group_means(
    positions: FloatArray,
    names: Sequence[str],
    groups: Mapping[str, Sequence[str]],
    valid: BoolArray | None = None,
) -> tuple[FloatArray, BoolArray]:
    """Joints as the mean of groups of source points (markers or joints).

    ``positions`` (n_frames, n_points, 3) [any length unit], ``names`` the n_points names,
    ``groups`` output joint -> the source names to average (one name copies that point);
    ``valid`` (n_frames, n_points) bool, default: where the positions are finite. Returns the
    means (n_frames, len(groups), 3) in the same unit, in the order of ``groups``, NaN where a
    member is invalid, and their validity (n_frames, len(groups)): a joint is valid in a frame
    only when every member is (a mean of the markers that happen to be seen would jump).

    Raises ``KeyError`` naming a group member that is not among ``names``.
    """
    p = np.asarray(positions, dtype=np.float64)
    ok = np.asarray(np.isfinite(p).all(axis=2) if valid is None else valid, dtype=np.bool_)
    index = {n: i for i, n in enumerate(names)}
    out = np.full((p.shape[0], len(groups), 3), np.nan)
    out_ok = np.zeros((p.shape[0], len(groups)), dtype=bool)
    for j, members in enumerate(groups.values()):
        missing = [m for m in members if m not in index]
        if missing:
            raise KeyError(", ".join(missing))
        idx = [index[m] for m in members]
        both = ok[:, idx].all(axis=1)
        out[both, j] = p[both][:, idx].mean(axis=1)
        out_ok[:, j] = both
    return out, out_ok


#: An axis of a file's frame with a sign, as config files name it.
AXES = ("x", "y", "z", "-x", "-y", "-z")


#: A file axis as a signed world axis, for source configs' ``axes`` (see :func:`reorient`).
Axis = Literal["x", "y", "z", "-x", "-y", "-z"]


def check_axes(axes: Sequence[str]) -> None:
    """``ValueError`` unless ``axes`` names x, y and z once each, each one of :data:`AXES`."""
    letters = [a.lstrip("-") for a in axes]
    if len(axes) != 3 or sorted(letters) != ["x", "y", "z"] or any(a not in AXES for a in axes):
        raise ValueError(
            f"axes must name x, y and z once each (with an optional '-'), got {list(axes)}"
        )


def check_motion_axes(axes: Sequence[str], left_handed: bool = False) -> None:
    """A motion source's ``axes`` option (:func:`reorient`): :func:`check_axes`, and
    ``ValueError`` for a mirror (a determinant of -1), which would turn the body's left into
    its right: motion files (BVH, C3D, TRC, Kinect, DeepMimic) use right-handed axes, as the
    project frame does, so only a rotation maps one onto the other. A file whose frame is
    declared left-handed (``left_handed``, a source's ``handedness = "left"``) is the other way
    round: only a mirror maps it onto the project's frame, and a rotation is refused."""
    check_axes(axes)
    m = np.zeros((3, 3))
    for row, a in enumerate(axes):
        m[row, "xyz".index(a[-1])] = -1.0 if a.startswith("-") else 1.0
    mirror = bool(np.linalg.det(m) < 0)
    if mirror == left_handed:
        return
    left = axes[1][1:] if axes[1].startswith("-") else f"-{axes[1]}"
    other = [axes[0], left, axes[2]]
    if left_handed:
        raise ValueError(
            f"handedness = 'left' declares the file's frame left-handed, which only a mirror "
            f"turns into the project's right-handed frame, but axes {list(axes)} are a "
            f"rotation: change the sign of one axis, e.g. of the one that becomes y (left): "
            f"{other}"
        )
    raise ValueError(
        f"{list(axes)} mirror the body (its left would become its right): change the sign "
        f"of one axis, e.g. of the one that becomes y (left): {other}; or, if the file's frame "
        "is left-handed (as Unity's is), declare it with handedness = 'left'"
    )


def check_canonical_keys(mapping: Mapping[str, Any] | None, field: str) -> None:
    """``ValueError`` naming ``field`` unless every key of ``mapping`` (a user's joint or
    marker map) is a canonical joint."""
    bad = sorted(set(mapping or {}) - set(CANONICAL_JOINTS))
    if bad:
        raise ValueError(
            f"{field}: {', '.join(bad)} are not canonical joints ({', '.join(CANONICAL_JOINTS)})"
        )


def reorient(positions: FloatArray, axes: Sequence[str]) -> FloatArray:
    """Positions (..., 3) in the project frame from a file's frame: ``axes[i]`` names the file
    axis (with a sign, one of :data:`AXES`) that becomes project axis i (x forward, y left,
    z up). ``("x", "y", "z")`` keeps the positions; ``("z", "x", "y")`` turns a y-up file whose
    subject faces +z into the project frame. ``ValueError`` unless the three name three
    different axes."""
    check_axes(axes)
    p = np.asarray(positions, dtype=np.float64)
    cols = [p[..., "xyz".index(a[-1])] * (-1.0 if a.startswith("-") else 1.0) for a in axes]
    return np.stack(cols, axis=-1)
