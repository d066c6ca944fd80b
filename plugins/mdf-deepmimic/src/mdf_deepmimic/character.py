"""The DeepMimic ``humanoid3d`` character: its joint tree, offsets and the body shapes used to
place the points the joints do not give (head centre, toe tips).

DeepMimic (Peng, Abbeel, Levine and van de Panne, "DeepMimic: Example-Guided Deep Reinforcement
Learning of Physics-Based Character Skills", ACM Transactions on Graphics 37(4), 2018) defines
its characters in JSON files; ``humanoid3d`` is in ``data/characters/humanoid3d.txt`` of the
DeepMimic repository (xbpeng/DeepMimic, commit 3ca04d38285ec3556dc0423f466477e96d934787). The
numbers below are that file's ``Skeleton.Joints`` (``Parent``, ``Type``, ``AttachX/Y/Z``: the
joint's origin in its parent's frame [m]; every ``AttachTheta`` is 0) and the ``BodyDefs`` of
the neck (the head: a sphere of diameter 0.205 m centred 0.175 m above the neck joint) and of the
ankles (the feet: boxes of 0.177 x 0.055 x 0.09 m centred at (0.045, -0.0225, 0) m in the ankle's
frame). The pybullet port of DeepMimic ships the same character as ``humanoid/humanoid.urdf``,
scaled by 4 (``examples/data/deepmimic/humanoid.urdf``); ``tests/test_deepmimic.py`` checks the
offsets here against that file.

Frames: the character's frame is y up; in the rest pose (every rotation the identity) it faces
+x and its right side is +z (the right hip is at z = +0.0849 m). Spherical joints turn by a
quaternion, revolute joints (knees, elbows) by an angle about their own z axis (the knee's range
is [-3.14, 0] rad: a negative angle swings the shin backwards; the elbow's is [0, 3.14]: a
positive angle lifts the forearm forwards), fixed joints (wrists) not at all.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

JointType = Literal["none", "spherical", "revolute", "fixed"]

#: Values a joint of each type takes in a frame of a clip.
DOF: dict[str, int] = {"none": 0, "spherical": 4, "revolute": 1, "fixed": 0}


@dataclass(frozen=True)
class Character:
    """A DeepMimic character: joints in file order (parents before children).

    ``names``, ``types`` and ``parents`` (index of the parent joint, -1 for the root) have one
    entry per joint; ``offsets`` (n_joints, 3) float64 [m] is each joint's origin in its
    parent's frame (the root's is unused: the clip gives the root's position). ``points`` are
    named points fixed in a joint's frame, (joint name, (x, y, z) [m]), for parts of the body
    the joints do not mark.
    """

    name: str
    names: tuple[str, ...]
    types: tuple[JointType, ...]
    parents: tuple[int, ...]
    offsets: FloatArray
    points: tuple[tuple[str, str, tuple[float, float, float]], ...]

    @property
    def frame_width(self) -> int:
        """Values in one frame of a clip: the duration, the root position (3) and rotation
        (4), then each non-root joint's values (4 spherical, 1 revolute, 0 fixed)."""
        return 1 + 3 + 4 + sum(DOF[t] for t in self.types[1:])

    def layout(self) -> list[tuple[str, str, int, int]]:
        """``(what, joint, first column, width)`` of every value group of a frame, in file
        order: the duration, the root position and rotation, then each moving joint's
        rotation (``what`` is ``"spherical"`` or ``"revolute"`` for those)."""
        out: list[tuple[str, str, int, int]] = [
            ("duration", "", 0, 1),
            ("position", self.names[0], 1, 3),
            ("spherical", self.names[0], 4, 4),
        ]
        col = 8
        for name, kind in zip(self.names[1:], self.types[1:], strict=True):
            if DOF[kind]:
                out.append((kind, name, col, DOF[kind]))
                col += DOF[kind]
        return out


#: Head centre: the centre of the neck's body (a sphere of diameter 0.205 m), 0.175 m above the
#: neck joint. Toe tip: the front face of the foot box at its mid-height, x = 0.045 + 0.177 / 2.
_FOOT_FRONT = (0.045 + 0.177 / 2.0, -0.0225, 0.0)

HUMANOID3D = Character(
    name="humanoid3d",
    names=(
        "root",
        "chest",
        "neck",
        "right_hip",
        "right_knee",
        "right_ankle",
        "right_shoulder",
        "right_elbow",
        "right_wrist",
        "left_hip",
        "left_knee",
        "left_ankle",
        "left_shoulder",
        "left_elbow",
        "left_wrist",
    ),
    types=(
        "none",
        "spherical",
        "spherical",
        "spherical",
        "revolute",
        "spherical",
        "spherical",
        "revolute",
        "fixed",
        "spherical",
        "revolute",
        "spherical",
        "spherical",
        "revolute",
        "fixed",
    ),
    parents=(-1, 0, 1, 0, 3, 4, 1, 6, 7, 0, 9, 10, 1, 12, 13),
    offsets=np.array(
        [
            [0.0, 0.0, 0.0],
            [0.0, 0.236151, 0.0],
            [0.0, 0.223894, 0.0],
            [0.0, 0.0, 0.084887],
            [0.0, -0.421546, 0.0],
            [0.0, -0.409870, 0.0],
            [-0.02405, 0.24350, 0.18311],
            [0.0, -0.274788, 0.0],
            [0.0, -0.258947, 0.0],
            [0.0, 0.0, -0.084887],
            [0.0, -0.421546, 0.0],
            [0.0, -0.409870, 0.0],
            [-0.02405, 0.24350, -0.18311],
            [0.0, -0.274788, 0.0],
            [0.0, -0.258947, 0.0],
        ]
    ),
    points=(
        ("head_centre", "neck", (0.0, 0.175, 0.0)),
        ("right_toe_tip", "right_ankle", _FOOT_FRONT),
        ("left_toe_tip", "left_ankle", _FOOT_FRONT),
    ),
)

#: Canonical joint -> the character's joint or point (see ``docs/motion-formats.md``).
CANONICAL_MAP: dict[str, str] = {
    "base": "root",
    "neck": "neck",
    "head": "head_centre",
    "l_shoulder": "left_shoulder",
    "r_shoulder": "right_shoulder",
    "l_elbow": "left_elbow",
    "r_elbow": "right_elbow",
    "l_hand": "left_wrist",
    "r_hand": "right_wrist",
    "l_hip": "left_hip",
    "r_hip": "right_hip",
    "l_knee": "left_knee",
    "r_knee": "right_knee",
    "l_ankle": "left_ankle",
    "r_ankle": "right_ankle",
    "l_toe": "left_toe_tip",
    "r_toe": "right_toe_tip",
}

#: What the canonical body gets that the character's joints do not mark, recorded in the metadata.
ESTIMATED: dict[str, str] = {
    "head": "centre of the head sphere (diameter 0.205 m), 0.175 m above the neck joint",
    "l_toe": "front of the foot box, 0.1335 m ahead of and 0.0225 m below the ankle",
    "r_toe": "front of the foot box, 0.1335 m ahead of and 0.0225 m below the ankle",
    "l_hand": "the wrist joint, the centre of the hand sphere (diameter 0.08 m)",
    "r_hand": "the wrist joint, the centre of the hand sphere (diameter 0.08 m)",
}
