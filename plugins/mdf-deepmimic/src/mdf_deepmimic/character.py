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

:func:`read_character` reads another character file of that format whose joints carry the
humanoid3d names (a resized humanoid).

Frames: the character's frame is y up; in the rest pose (every rotation the identity) it faces
+x and its right side is +z (the right hip is at z = +0.0849 m). Spherical joints turn by a
quaternion, revolute joints (knees, elbows) by an angle about their own z axis (the knee's range
is [-3.14, 0] rad: a negative angle swings the shin backwards; the elbow's is [0, 3.14]: a
positive angle lifts the forearm forwards), fixed joints (wrists) not at all.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from mdframework import DataFileError, limits

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


def estimated(character: Character) -> dict[str, str]:
    """What the canonical body takes from the character's body shapes rather than its joints
    (recorded in the metadata as ``estimated``)."""
    at = {name: (joint, p) for name, joint, p in character.points}

    def where(point: str) -> str:
        joint, p = at[point]
        return f"({p[0]:.4g}, {p[1]:.4g}, {p[2]:.4g}) m in the {joint} joint's frame"

    out = {"head": f"centre of the head (the neck body), {where('head_centre')}"}
    for side, name in (("l", "left"), ("r", "right")):
        out[f"{side}_hand"] = f"the {name} wrist joint (the centre of the hand; no hand joint)"
        out[f"{side}_toe"] = f"front of the {name} foot box, {where(f'{name}_toe_tip')}"
    return out


#: Joints a character file must name for the canonical body (the humanoid3d names).
REQUIRED_JOINTS = tuple(
    j for j in CANONICAL_MAP.values() if j not in ("head_centre", "left_toe_tip", "right_toe_tip")
)


def _number(path: Path, item: dict[str, Any], key: str, where: str) -> float:
    value = item.get(key, 0.0)
    if not isinstance(value, int | float) or isinstance(value, bool) or not math.isfinite(value):
        raise DataFileError(path, f"{where}: {key} {value!r} is not a finite number")
    if abs(value) > limits.MAX_COORDINATE_M:
        raise DataFileError(
            path, f"{where}: {key} {value!r} is beyond +-{limits.MAX_COORDINATE_M:g}"
        )
    return float(value)


def read_json(path: Path, what: str, max_bytes: int) -> tuple[str, Any]:
    """The text of a JSON file and what it holds; ``DataFileError`` naming the file (and line)
    for a file beyond ``max_bytes``, binary, not UTF-8, empty or not JSON (a truncated file is
    said to end early)."""
    import json

    text = limits.read_text_file(path, what, max_bytes)
    if not text.strip():
        raise DataFileError(path, "the file is empty")
    try:
        return text, json.loads(text)
    except json.JSONDecodeError as exc:
        end = exc.pos >= len(text.rstrip())
        hint = ": the file ends early (truncated?)" if end else ""
        raise DataFileError(
            path, f"not valid JSON: {exc.msg} at column {exc.colno}{hint}", exc.lineno
        ) from None
    except RecursionError:
        raise DataFileError(path, f"JSON nested too deeply: not {what}") from None


def read_character(path: Path) -> Character:
    """A DeepMimic character file (``data/characters/*.txt``, JSON) whose joints carry the
    humanoid3d names (a resized humanoid, for instance).

    Reads ``Skeleton.Joints`` (``Name``, ``Type``: none for the root, spherical, revolute or
    fixed; ``Parent``; ``AttachX/Y/Z`` [m]; every ``AttachTheta`` must be 0) and, from
    ``BodyDefs``, the ``neck`` body (its centre: the head centre) and the ``right_ankle`` and
    ``left_ankle`` boxes (the middle of their front faces: the toe tips).

    Raises
    ------
    mdframework.DataFileError
        Not a character file, a joint of another type or with a turned attachment, parents
        after their children, missing joints or bodies (the message lists what is missing).
    """
    _, doc = read_json(path, "a DeepMimic character file", 16 * 1024 * 1024)
    joints = doc.get("Skeleton", {}).get("Joints") if isinstance(doc, dict) else None
    if not isinstance(joints, list) or not joints or not all(isinstance(j, dict) for j in joints):
        raise DataFileError(path, 'not a DeepMimic character: no "Skeleton": {"Joints": [...]}')
    names: list[str] = []
    types: list[JointType] = []
    parents: list[int] = []
    offsets = []
    for k, j in enumerate(joints):
        name = str(j.get("Name", f"joint {k}"))
        where = f"joint {k} ({name})"
        kind, parent = j.get("Type"), j.get("Parent")
        if kind not in DOF:
            raise DataFileError(
                path, f"{where}: type {kind!r} is not one of {', '.join(DOF)}: not supported"
            )
        if not isinstance(parent, int) or not -1 <= parent < k or (parent == -1) != (k == 0):
            raise DataFileError(
                path, f"{where}: Parent {parent!r} must be an earlier joint (-1 for the first)"
            )
        if (kind == "none") != (k == 0):
            raise DataFileError(path, f"{where}: only the root (the first joint) has type none")
        for axis in "XYZ":
            if _number(path, j, f"AttachTheta{axis}", where) != 0.0:
                raise DataFileError(
                    path, f"{where}: a turned attachment (AttachTheta{axis}) is not supported"
                )
        names.append(name)
        types.append(kind)
        parents.append(parent)
        offsets.append([_number(path, j, f"Attach{a}", where) for a in "XYZ"])
    bodies = {str(b.get("Name")): b for b in doc.get("BodyDefs", []) if isinstance(b, dict)}
    missing = [n for n in REQUIRED_JOINTS if n not in names]
    shapes = {"neck": "sphere", "right_ankle": "box", "left_ankle": "box"}
    missing += [
        f"a {shape} body {n!r}"
        for n, shape in shapes.items()
        if bodies.get(n, {}).get("Shape") != shape
    ]
    if missing:
        raise DataFileError(
            path,
            f"the character lacks {', '.join(missing)} (the humanoid3d joints and bodies the "
            f"canonical body needs); its joints are {', '.join(names)}",
        )

    def attach(name: str) -> tuple[float, float, float]:
        x, y, z = (_number(path, bodies[name], f"Attach{a}", f"body {name}") for a in "XYZ")
        return x, y, z

    points = [("head_centre", "neck", attach("neck"))]
    for side in ("right", "left"):
        x, y, z = attach(f"{side}_ankle")
        length = _number(path, bodies[f"{side}_ankle"], "Param0", f"body {side}_ankle")
        points.append((f"{side}_toe_tip", f"{side}_ankle", (x + length / 2.0, y, z)))
    return Character(
        name=path.stem,
        names=tuple(names),
        types=tuple(types),
        parents=tuple(parents),
        offsets=np.array(offsets, dtype=np.float64),
        points=tuple(points),
    )
