"""Motion augmentation: new, plausible motions from recorded ones (pure functions).

Each function returns a new :class:`~mdframework.skeleton.Skeleton` (or
:class:`~mdframework.interfaces.Motion`) and leaves its input alone. Skeletons are in the
source's own joints, z up, metres, seconds.

- :func:`scale_speed`: the same movement ``factor`` times faster (time stamps divided by
  ``factor`` from the first frame): every velocity, and so every Doppler shift, scales by
  ``factor``; positions (and stride lengths) are unchanged.
- :func:`scale_height`: a geometrically similar, taller or shorter person: positions scaled by
  ``factor`` about the floor point below the body's mean position (the lowest valid joint height,
  the horizontal mean of the first frame); at the same time stamps, velocities scale by
  ``factor`` too.
- :func:`mirror_motion`: the left-right mirror image (y -> -y, with left and right joints of the
  canonical map swapped, so the mirrored body still faces forward with its left on the left).
- :func:`time_warp`: a smooth, monotone re-timing ``t' = t0 + T g((t - t0) / T)`` with
  ``g(u) = u + sum_k c_k sin(pi k u) / (pi k)``; ``g(0) = 0``, ``g(1) = 1`` and
  ``g'(u) = 1 + sum_k c_k cos(pi k u) > 0`` when ``sum |c_k| < 1``: the movement speeds up and
  slows down within the record while its start, end and path stay the same.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import NDArray

from .interfaces import Motion
from .skeleton import Skeleton

FloatArray = NDArray[np.float64]


def scale_speed(skeleton: Skeleton, factor: float) -> Skeleton:
    """The movement ``factor`` (> 0) times faster: ``t' = t0 + (t - t0) / factor``."""
    if not factor > 0:
        raise ValueError(f"speed factor must be positive, got {factor}")
    t0 = skeleton.time[0]
    return Skeleton(
        t0 + (skeleton.time - t0) / factor,
        skeleton.positions,
        skeleton.joint_names,
        skeleton.valid,
    )


def scale_height(skeleton: Skeleton, factor: float) -> Skeleton:
    """A person ``factor`` (> 0) times as tall: positions scaled about the floor point below
    the body (see the module docstring)."""
    if not factor > 0:
        raise ValueError(f"height factor must be positive, got {factor}")
    pos = skeleton.positions
    valid = skeleton.valid
    first = pos[0][valid[0]]
    if first.size == 0 or not np.any(valid):
        raise ValueError("the skeleton has no valid joint to scale about")
    centre = np.array([first[:, 0].mean(), first[:, 1].mean(), pos[..., 2][valid].min()])
    scaled = np.where(valid[..., None], centre + factor * (pos - centre), pos)
    return skeleton.with_positions(scaled)


def mirror_skeleton(skeleton: Skeleton) -> Skeleton:
    """Positions mirrored in the x-z plane (y -> -y); joint names unchanged."""
    pos = np.array(skeleton.positions)
    pos[..., 1] *= -1.0
    return skeleton.with_positions(pos)


def _swap_side(name: str) -> str:
    for a, b in (("l_", "r_"), ("r_", "l_")):
        if name.startswith(a):
            return b + name[len(a) :]
    return name


def mirror_motion(motion: Motion) -> Motion:
    """The left-right mirror image of a motion: mirrored positions, and the canonical map's
    left and right joints swapped (a motion without a canonical map is only mirrored)."""
    mapping = motion.canonical_map
    swapped = None if mapping is None else {_swap_side(k): v for k, v in mapping.items()}
    return dataclasses.replace(
        motion, skeleton=mirror_skeleton(motion.skeleton), canonical_map=swapped
    )


def warp_function(u: FloatArray, coefficients: FloatArray) -> FloatArray:
    """``g(u) = u + sum_k c_k sin(pi k u) / (pi k)`` for ``u`` in [0, 1] (k = 1 ... K)."""
    c = np.asarray(coefficients, dtype=np.float64)
    if np.sum(np.abs(c)) >= 1.0:
        raise ValueError(f"warp coefficients must satisfy sum |c_k| < 1, got {c.tolist()}")
    k = np.arange(1, c.size + 1, dtype=np.float64)
    uu = np.asarray(u, dtype=np.float64)
    terms = np.sin(np.pi * k[:, None] * uu.ravel()[None, :]) / (np.pi * k[:, None])
    return np.asarray(uu + (c @ terms).reshape(uu.shape), dtype=np.float64)


def time_warp(skeleton: Skeleton, coefficients: FloatArray) -> Skeleton:
    """Re-time the whole skeleton by :func:`warp_function` over its duration."""
    t0, span = skeleton.time[0], skeleton.duration
    if span <= 0:
        raise ValueError("a single-frame skeleton cannot be warped")
    u = (skeleton.time - t0) / span
    return Skeleton(
        t0 + span * warp_function(u, coefficients),
        skeleton.positions,
        skeleton.joint_names,
        skeleton.valid,
    )


def augment_motion(
    motion: Motion,
    *,
    speed: float = 1.0,
    height: float = 1.0,
    mirror: bool = False,
    warp: FloatArray | None = None,
) -> Motion:
    """Apply the augmentations in a fixed order (mirror, height, warp, speed) to a motion."""
    out = mirror_motion(motion) if mirror else motion
    skel = out.skeleton
    if height != 1.0:
        skel = scale_height(skel, height)
    if warp is not None and np.any(np.asarray(warp) != 0):
        skel = time_warp(skel, warp)
    if speed != 1.0:
        skel = scale_speed(skel, speed)
    return dataclasses.replace(out, skeleton=skel)
