"""Rotation matrices, CMU units and the CMU -> project axis mapping, shared by both readers.

All functions are vectorised over frames. Angles are in degrees (as in the files) unless a name
says otherwise; rotation matrices act on column vectors (``v_parent = R @ v_child``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

#: ASF/BVH length unit in metres: CMU's ASF files say ``length 0.45`` (the data were scaled by
#: 0.45 from inches), so one unit is (1 / 0.45) inch = (1 / 0.45) * 2.54 / 100 m = 0.056444 m.
CMU_UNIT_M: float = (1.0 / 0.45) * 2.54 / 100.0

#: CMU is y-up; the project's frame is right-handed z-up. Positions map as
#: (X, Y, Z)_cmu -> (Z, X, Y) (a cyclic permutation, i.e. a proper rotation): CMU's forward (+Z for
#: the T-pose) becomes +x, CMU's +X (the subject's left in the T-pose) becomes +y, up becomes +z.
CMU_TO_PROJECT: tuple[int, int, int] = (2, 0, 1)


def axis_rotation(axis: str, degrees: FloatArray) -> FloatArray:
    """Rotation matrices about one coordinate axis.

    Parameters
    ----------
    axis : str
        ``"X"``, ``"Y"`` or ``"Z"`` (case-insensitive).
    degrees : ndarray, shape (n,), float64
        Angles [deg], positive counter-clockwise (right-hand rule).

    Returns
    -------
    ndarray, shape (n, 3, 3), float64
        ``R[k]`` rotates by ``degrees[k]`` about ``axis``.
    """
    a = np.deg2rad(np.asarray(degrees, dtype=np.float64))
    c, s = np.cos(a), np.sin(a)
    one, zero = np.ones_like(a), np.zeros_like(a)
    ax = axis.upper()
    if ax == "X":
        rows = ((one, zero, zero), (zero, c, -s), (zero, s, c))
    elif ax == "Y":
        rows = ((c, zero, s), (zero, one, zero), (-s, zero, c))
    elif ax == "Z":
        rows = ((c, -s, zero), (s, c, zero), (zero, zero, one))
    else:
        raise ValueError(f"unknown rotation axis {axis!r}")
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def intrinsic_rotation(axes: str, degrees: FloatArray) -> FloatArray:
    """Rotation from Euler angles applied about moving axes in the listed order.

    For ``axes = "ZYX"`` the result is ``Rz @ Ry @ Rx`` (BVH's convention: the channel order as
    listed, each rotation about the axes already rotated by the previous ones).

    Parameters
    ----------
    axes : str
        Axis letters, e.g. ``"ZYX"``; may be empty (identity).
    degrees : ndarray, shape (n, len(axes)), float64
        Angle [deg] of each listed axis, per frame.

    Returns
    -------
    ndarray, shape (n, 3, 3), float64
    """
    deg = np.asarray(degrees, dtype=np.float64)
    out = np.broadcast_to(np.eye(3), (deg.shape[0], 3, 3)).copy()
    for k, ax in enumerate(axes):
        out = out @ axis_rotation(ax, deg[:, k])
    return out


def fixed_axis_rotation(order: str, degrees_xyz: FloatArray) -> FloatArray:
    """Rotation from Euler angles applied about fixed (parent) axes in the given order.

    For ``order = "XYZ"`` the result is ``Rz @ Ry @ Rx`` (rotate about x first, then the fixed y,
    then the fixed z), the convention of ASF ``axis`` angles and AMC ``dof`` values.

    Parameters
    ----------
    order : str
        A permutation of ``"XYZ"``.
    degrees_xyz : ndarray, shape (n, 3), float64
        Angles about x, y, z [deg] (in that column order, whatever ``order`` is).

    Returns
    -------
    ndarray, shape (n, 3, 3), float64
    """
    deg = np.asarray(degrees_xyz, dtype=np.float64)
    out = np.broadcast_to(np.eye(3), (deg.shape[0], 3, 3)).copy()
    for ax in order.upper():
        out = axis_rotation(ax, deg[:, "XYZ".index(ax)]) @ out
    return out


def to_project_frame(positions_cmu: FloatArray, unit_m: float = CMU_UNIT_M) -> FloatArray:
    """CMU positions (ASF units, y up) to project positions (metres, z up).

    Parameters
    ----------
    positions_cmu : ndarray, shape (..., 3), float64
        Positions in ASF units, CMU axes.
    unit_m : float
        Metres per ASF unit.

    Returns
    -------
    ndarray, shape (..., 3), float64
        ``(Z, X, Y)_cmu * unit_m`` [m].
    """
    p = np.asarray(positions_cmu, dtype=np.float64)
    return np.ascontiguousarray(p[..., list(CMU_TO_PROJECT)] * unit_m)
