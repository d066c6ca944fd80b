"""Forward kinematics of a DeepMimic character, and repeating a cyclic clip.

Rotation matrices act on column vectors. A joint's world rotation is its parent's world
rotation times its own rotation (the root's is the clip's root rotation); its world position is
its parent's position plus the parent's world rotation applied to the joint's offset. Points
fixed in a joint's frame (head centre, toe tips) follow that joint the same way. All functions
are vectorised over frames and pure.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .character import Character

FloatArray = NDArray[np.float64]


def quaternion_matrices(q_wxyz: FloatArray) -> FloatArray:
    """Rotation matrices (n, 3, 3) of unit quaternions (n, 4) given as (w, x, y, z)."""
    from scipy.spatial.transform import Rotation

    q = np.asarray(q_wxyz, dtype=np.float64)
    return np.asarray(Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix(), dtype=np.float64)


def z_rotations(angle: FloatArray) -> FloatArray:
    """Rotation matrices (n, 3, 3) about the z axis by ``angle`` (n,) [rad], counter-clockwise
    seen from +z (the axis of DeepMimic's revolute joints)."""
    a = np.asarray(angle, dtype=np.float64)
    c, s = np.cos(a), np.sin(a)
    out = np.zeros((a.shape[0], 3, 3))
    out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1] = c, -s, s, c
    out[:, 2, 2] = 1.0
    return out


def forward_kinematics(
    character: Character, root_position: FloatArray, rotations: dict[str, FloatArray]
) -> tuple[tuple[str, ...], FloatArray]:
    """Positions of every joint and point of ``character`` in the clip's frame.

    Parameters
    ----------
    root_position : ndarray, shape (n, 3), float64
        Root position [m] per frame.
    rotations : dict
        Joint name -> (n, 4) unit quaternions (w, x, y, z) for the root and spherical joints,
        or (n,) angles [rad] for revolute joints (:class:`mdf_deepmimic.reader.Clip`).

    Returns
    -------
    names : tuple of str
        The character's joints in file order, then its points (``head_centre``, ...).
    positions : ndarray, shape (n, len(names), 3), float64
        [m], in the clip's frame (y up for DeepMimic's characters).
    """
    root = np.asarray(root_position, dtype=np.float64)
    n = root.shape[0]
    eye = np.broadcast_to(np.eye(3), (n, 3, 3))
    world_rot: list[FloatArray] = []
    world_pos: list[FloatArray] = []
    for j, (name, kind, parent) in enumerate(
        zip(character.names, character.types, character.parents, strict=True)
    ):
        if kind == "spherical" or parent < 0:
            local = quaternion_matrices(rotations[name])
        elif kind == "revolute":
            local = z_rotations(rotations[name])
        else:
            local = eye
        if parent < 0:
            world_rot.append(local)
            world_pos.append(root)
            continue
        world_rot.append(world_rot[parent] @ local)
        world_pos.append(world_pos[parent] + world_rot[parent] @ character.offsets[j])
    names = list(character.names)
    for point, joint, offset in character.points:
        j = character.names.index(joint)
        names.append(point)
        world_pos.append(world_pos[j] + world_rot[j] @ np.asarray(offset, dtype=np.float64))
    return tuple(names), np.stack(world_pos, axis=1)


def repeat_cycles(
    time: FloatArray, positions: FloatArray, cycles: int, base: int
) -> tuple[FloatArray, FloatArray, float]:
    """A cyclic clip repeated ``cycles`` times, each cycle starting where the last ended.

    DeepMimic plays a ``"wrap"`` clip again from its first frame once its last frame is
    reached, shifted by the clip's horizontal displacement of the root (DeepMimic's and
    pybullet's cycle offset; the heading is not changed). So each cycle after the first is the
    clip without its last frame, moved horizontally by the ``base`` joint's displacement from
    the first to the last frame.

    Parameters
    ----------
    time : ndarray, shape (n,), float64
        [s], from 0.
    positions : ndarray, shape (n, n_joints, 3), float64
        [m], z up.
    cycles : int
        How many times to play the clip (1: unchanged).
    base : int
        Joint index of the root (pelvis).

    Returns
    -------
    time : ndarray, shape (cycles * (n - 1) + 1,), float64
    positions : ndarray, shape (cycles * (n - 1) + 1, n_joints, 3), float64
    closure_m : float
        Largest distance between a joint of the last frame and the same joint of the first
        frame moved by one cycle [m]: how well the clip closes on itself, the jump at each
        seam (0 for a perfect cycle).
    """
    t = np.asarray(time, dtype=np.float64)
    p = np.asarray(positions, dtype=np.float64)
    shift = np.array([p[-1, base, 0] - p[0, base, 0], p[-1, base, 1] - p[0, base, 1], 0.0])
    closure = float(np.max(np.linalg.norm(p[0] + shift - p[-1], axis=1)))
    if cycles == 1:
        return t, p, closure
    period = t[-1] - t[0]
    k = np.arange(cycles)
    body_t = (t[:-1][None, :] + period * k[:, None]).reshape(-1)
    body_p = (p[:-1][None] + (k[:, None] * shift)[:, None, None, :]).reshape(-1, *p.shape[1:])
    end_t = t[-1:] + period * (cycles - 1)
    end_p = p[-1:] + shift * (cycles - 1)
    return np.concatenate([body_t, end_t]), np.concatenate([body_p, end_p]), closure
