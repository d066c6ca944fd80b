"""Joint maps from common BVH rigs to the canonical 17-joint body, and rig detection.

A BVH joint's position is its origin (the proximal end of the bone it starts); an End Site is
named ``<joint>_end`` by the reader. Joint names are matched without any namespace prefix
(``mixamorig:LeftArm`` matches ``LeftArm``). Each canonical joint lists one or more accepted
names, the first present wins.

==============  ==============================================================================
rig             what
==============  ==============================================================================
cmu-cgspeed     CMU database, cgspeed's MotionBuilder-friendly BVH conversion (``LHipJoint``,
                ``LowerBack``, ``Neck1``; ``LeftUpLeg``, ``LeftArm``...). Units: CMU's
                (1/0.45 inch). Frame 0 is an added T-pose.
cmu-3dsmax      CMU database, cgspeed's 3ds Max-friendly BVH conversion (``LHipJoint``,
                ``lowerneck``, ``Chest2``; ``LeftHip``, ``LeftShoulder``...; named per its
                READMEFIRST's joint renaming template). Units: CMU's. Frame 0 is an added pose.
mixamo          Adobe Mixamo characters (``mixamorig:`` prefix; ``LeftUpLeg``, ``LeftArm``,
                ``HeadTop_End``...). Units: centimetres.
biovision       Studio captures in the Biovision naming (as exported by MocapBank and many
                research capture labs): ``Chest``, ``Chest2``, ``LeftCollar``, ``LeftShoulder``,
                ``LeftElbow``, ``LeftWrist``, ``LeftHip``, ``LeftKnee``, ``LeftAnkle`` and the
                ankle's End Site as the toe. Units: centimetres.
==============  ==============================================================================

Detection (:func:`detect_rig`): a rig fits when every canonical joint has one of its names in the
file (or in a user's partial joint map) and at least one of its signature joints is in the file;
among fitting rigs the one with the most signature joints present wins, and a tie is refused.
When none fits, :class:`RigMismatch` names the file's joints, the rigs tried and the nearest rig
with its missing joints (or, when joints would map but no signature joint is there, every rig's
signature), and says to give ``motion.rig`` or ``motion.joint_map``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from mdframework import CANONICAL_JOINTS

from .kinematics import CMU_UNIT_M


@dataclass(frozen=True)
class Rig:
    """A BVH rig: canonical joint -> accepted joint names, signature joints, unit, origin."""

    name: str
    description: str
    joints: Mapping[str, tuple[str, ...]]
    signature: tuple[str, ...]
    unit_m: float
    #: a conversion of the CMU database (its frame rates may be corrected from CMU's index)
    cmu: bool = False
    #: frame 0 is a pose added by the converter, not capture
    added_first_frame: bool = False


def _sides(left: dict[str, tuple[str, ...]]) -> dict[str, tuple[str, ...]]:
    """Left-side entries plus their right-side mirror (Left -> Right, L -> R)."""
    out = dict(left)
    for key, names in left.items():
        if key.startswith("l_"):
            out["r_" + key[2:]] = tuple(
                n.replace("Left", "Right") if "Left" in n else "R" + n[1:] for n in names
            )
    return out


RIGS: dict[str, Rig] = {
    "cmu-cgspeed": Rig(
        "cmu-cgspeed",
        "CMU, cgspeed MotionBuilder-friendly BVH",
        {
            "base": ("Hips",),
            "neck": ("Neck",),
            "head": ("Head_end",),
            **_sides(
                {
                    "l_shoulder": ("LeftArm",),
                    "l_elbow": ("LeftForeArm",),
                    "l_hand": ("LeftHand",),
                    "l_hip": ("LeftUpLeg",),
                    "l_knee": ("LeftLeg",),
                    "l_ankle": ("LeftFoot",),
                    "l_toe": ("LeftToeBase_end",),
                }
            ),
        },
        ("LHipJoint", "RHipJoint", "LowerBack", "Neck1", "LeftFingerBase"),
        CMU_UNIT_M,
        cmu=True,
        added_first_frame=True,
    ),
    "cmu-3dsmax": Rig(
        "cmu-3dsmax",
        "CMU, cgspeed 3ds Max-friendly BVH",
        {
            "base": ("Hips",),
            "neck": ("lowerneck",),
            "head": ("Head_end",),
            **_sides(
                {
                    "l_shoulder": ("LeftShoulder",),
                    "l_elbow": ("LeftElbow",),
                    "l_hand": ("LeftWrist",),
                    "l_hip": ("LeftHip",),
                    "l_knee": ("LeftKnee",),
                    "l_ankle": ("LeftAnkle",),
                    "l_toe": ("LeftToe_end",),
                }
            ),
        },
        ("LHipJoint", "RHipJoint", "lowerback", "lowerneck", "lhand", "LFingers"),
        CMU_UNIT_M,
        cmu=True,
        added_first_frame=True,
    ),
    "mixamo": Rig(
        "mixamo",
        "Adobe Mixamo",
        {
            "base": ("Hips",),
            "neck": ("Neck",),
            "head": ("HeadTop_End", "Head_end"),
            **_sides(
                {
                    "l_shoulder": ("LeftArm",),
                    "l_elbow": ("LeftForeArm",),
                    "l_hand": ("LeftHand",),
                    "l_hip": ("LeftUpLeg",),
                    "l_knee": ("LeftLeg",),
                    "l_ankle": ("LeftFoot",),
                    "l_toe": ("LeftToe_End", "LeftToeBase_end"),
                }
            ),
        },
        ("Spine2", "HeadTop_End", "LeftHandIndex1", "LeftToe_End"),
        0.01,
    ),
    "biovision": Rig(
        "biovision",
        "Biovision naming (MocapBank and other studio captures)",
        {
            "base": ("Hips",),
            "neck": ("Neck",),
            "head": ("Head_end",),
            **_sides(
                {
                    "l_shoulder": ("LeftShoulder",),
                    "l_elbow": ("LeftElbow",),
                    "l_hand": ("LeftWrist",),
                    "l_hip": ("LeftHip",),
                    "l_knee": ("LeftKnee",),
                    "l_ankle": ("LeftAnkle",),
                    "l_toe": ("LeftAnkle_end", "LeftToe_end"),
                }
            ),
        },
        ("Chest", "Chest2", "LeftCollar", "RightCollar"),
        0.01,
    ),
}


def strip_namespace(name: str) -> str:
    """``"mixamorig:LeftArm"`` -> ``"LeftArm"`` (names without a prefix are unchanged)."""
    return name.rsplit(":", 1)[-1]


class RigMismatch(ValueError):
    """No rig fits a file's joints; the message lists them and the nearest rig."""


def resolve(rig: Rig, names: Iterable[str]) -> tuple[dict[str, str], list[str]]:
    """Map a rig onto a file's joint names.

    Returns the canonical -> file joint map (file names as written, prefix included) and the
    canonical joints the file lacks (with the names the rig accepts for them).
    """
    by_plain: dict[str, str] = {}
    for n in names:
        by_plain.setdefault(strip_namespace(n), n)
    mapping: dict[str, str] = {}
    missing: list[str] = []
    for joint in CANONICAL_JOINTS:
        found = next((by_plain[a] for a in rig.joints[joint] if a in by_plain), None)
        if found is None:
            missing.append(f"{joint} ({' or '.join(rig.joints[joint])})")
        else:
            mapping[joint] = found
    return mapping, missing


def signature_count(rig: Rig, names: Iterable[str]) -> int:
    """How many of ``rig``'s signature joints are among ``names`` (namespace prefixes ignored)."""
    plain = {strip_namespace(n) for n in names}
    return sum(s in plain for s in rig.signature)


def detect_rig(names: Iterable[str], mapped: Iterable[str] = ()) -> tuple[Rig, dict[str, str]]:
    """The rig a file's joints are recognised as, and its canonical map.

    A rig is a candidate when every canonical joint not in ``mapped`` (the canonical joints a
    user's partial joint map gives) has one of its names in the file and at least one of its
    signature joints is there; the candidate with the most signature joints wins.

    Raises
    ------
    RigMismatch
        No candidate (the message names the file's joints, the rigs tried and, for the nearest,
        what it lacks), or two candidates with as many signature joints (a tie). Each message
        says what to give: ``motion.rig`` or ``motion.joint_map``.
    """
    names = tuple(names)
    given = set(mapped)
    fits: list[tuple[int, Rig, dict[str, str]]] = []
    unsigned: list[Rig] = []
    nearest: tuple[Rig, list[str]] | None = None
    for rig in RIGS.values():
        mapping, missing = resolve(rig, names)
        missing = [m for m in missing if m.split(" ")[0] not in given]
        count = signature_count(rig, names)
        if missing:
            if nearest is None or len(missing) < len(nearest[1]):
                nearest = (rig, missing)
        elif count == 0:
            unsigned.append(rig)
        else:
            fits.append((count, rig, mapping))
    todo = (
        f"give motion.rig ({', '.join(RIGS)}) if the file is one of them, or "
        "motion.joint_map (canonical joint = file joint) for the joints a rig lacks, or for "
        "all 17 with motion.unit_m"
    )
    joints = f"this file's joints ({', '.join(names)})"
    fits.sort(key=lambda f: -f[0])
    if len(fits) > 1 and fits[0][0] == fits[1][0]:
        tied = [f[1].name for f in fits if f[0] == fits[0][0]]
        raise RigMismatch(
            f"{joints} fit the rigs {' and '.join(repr(t) for t in tied)} with "
            f"{fits[0][0]} signature joint(s) each: the rig is ambiguous; give motion.rig"
        )
    if fits:
        return fits[0][1], fits[0][2]
    signatures = "; ".join(f"{r.name}: {', '.join(r.signature)}" for r in RIGS.values())
    if unsigned:
        reason = (
            f"the joints of {', '.join(repr(r.name) for r in unsigned)} would map, but none "
            f"of any rig's signature joints is there ({signatures})"
        )
    else:
        assert nearest is not None
        reason = (
            f"the nearest is {nearest[0].name!r} ({nearest[0].description}), which lacks "
            f"{', '.join(nearest[1])}"
        )
    raise RigMismatch(f"no known BVH rig fits {joints}; tried {', '.join(RIGS)}: {reason}; {todo}")
