"""Body dimensions and scatterer placement.

Segment lengths are Boulic's proportions of the height ``H`` as coded by Chen; each body part is a
spheroid (``a = b``) whose long semi-axis ``c`` is half the segment length and whose axis follows
the segment. Two placements are offered (a modelling choice the paper leaves open):

- ``chen16``: Chen's 16 parts, placed as in ``RadarReturnsFromWalkingHuman.m`` (the lower leg uses
  its own length, not the upper leg's as Chen's code does).
- ``joints17``: one scatterer per canonical joint (the paper's "K = 17"), each with the RCS of the
  segment that ends at it; the base takes the pelvis (hip to hip).

In both, the head can be a sphere of radius 0.1 m (the paper) or Chen's spheroid.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from ..skeleton import CANONICAL_JOINTS

FloatArray = NDArray[np.float64]

#: Segment lengths as fractions of the height (Chen's ``HumanWalkingModel.m``).
SEGMENT_FRACTIONS: dict[str, float] = {
    "head": 0.130,
    "shoulder": 0.259 / 2,
    "torso": 0.288,
    "hip": 0.191 / 2,
    "upper_leg": 0.245,
    "lower_leg": 0.246,
    "foot": 0.143,
    "upper_arm": 0.188,
    "lower_arm": 0.152,
}
#: Leg length (hip height) as a fraction of the height, H_t = 0.491 H.
LEG_FRACTION = 0.491

#: Spheroid radii a = b [m] (Chen's ``RadarReturnsFromWalkingHuman.m``).
PART_RADII: dict[str, float] = {
    "head": 0.10,
    "torso": 0.15,
    "shoulder": 0.06,
    "upper_arm": 0.06,
    "lower_arm": 0.05,
    "hip": 0.07,
    "upper_leg": 0.07,
    "lower_leg": 0.06,
    "foot": 0.05,
}

Placement = Literal["chen16", "joints17"]

_J = {name: i for i, name in enumerate(CANONICAL_JOINTS)}


@dataclass(frozen=True)
class BodyPart:
    """One scatterer: where it sits, how its axis is found, and its size.

    ``position``: ((joint, weight), ...) whose weighted sum is the scatterer's position.
    ``axis``: (tail, head) joints; the axis vector is ``head - tail``.
    ``segment``: key of :data:`SEGMENT_FRACTIONS` and :data:`PART_RADII`.
    ``sphere``: True if the part is a sphere of radius ``PART_RADII[segment]``.
    """

    name: str
    position: tuple[tuple[str, float], ...]
    axis: tuple[str, str]
    segment: str
    sphere: bool = False
    half_length_scale: float = 0.5


def _side(
    side: str, parts: list[tuple[str, tuple[tuple[str, float], ...], tuple[str, str], str]]
) -> list[BodyPart]:
    out = []
    for name, pos, axis, seg in parts:
        fix = {"S": side}
        out.append(
            BodyPart(
                f"{side}_{name}",
                tuple((j.format(**fix), w) for j, w in pos),
                (axis[0].format(**fix), axis[1].format(**fix)),
                seg,
            )
        )
    return out


def body_parts(
    placement: Placement, head: Literal["sphere", "spheroid"] = "sphere"
) -> tuple[BodyPart, ...]:
    """The scatterers of a placement, in a fixed order."""
    sphere_head = head == "sphere"
    if placement == "chen16":
        parts = [
            BodyPart("head", (("head", 1.0),), ("neck", "head"), "head", sphere_head),
            BodyPart("torso", (("neck", 0.5), ("base", 0.5)), ("base", "neck"), "torso"),
        ]
        limb = [
            ("shoulder", (("{S}_shoulder", 1.0),), ("neck", "{S}_shoulder"), "shoulder"),
            (
                "upper_arm",
                (("{S}_shoulder", 0.5), ("{S}_elbow", 0.5)),
                ("{S}_elbow", "{S}_shoulder"),
                "upper_arm",
            ),
            ("lower_arm", (("{S}_hand", 1.0),), ("{S}_hand", "{S}_elbow"), "lower_arm"),
            ("hip", (("{S}_hip", 1.0),), ("base", "{S}_hip"), "hip"),
            (
                "upper_leg",
                (("{S}_hip", 0.5), ("{S}_knee", 0.5)),
                ("{S}_hip", "{S}_knee"),
                "upper_leg",
            ),
            (
                "lower_leg",
                (("{S}_knee", 0.5), ("{S}_ankle", 0.5)),
                ("{S}_knee", "{S}_ankle"),
                "lower_leg",
            ),
            ("foot", (("{S}_toe", 1.0),), ("{S}_toe", "{S}_ankle"), "foot"),
        ]
        for side in ("l", "r"):
            parts += _side(side, limb)
        return tuple(parts)
    if placement == "joints17":
        segment_of = {
            "neck": (("base", "neck"), "torso"),
            "head": (("neck", "head"), "head"),
            "shoulder": (("neck", "{S}_shoulder"), "shoulder"),
            "elbow": (("{S}_shoulder", "{S}_elbow"), "upper_arm"),
            "hand": (("{S}_elbow", "{S}_hand"), "lower_arm"),
            "hip": (("base", "{S}_hip"), "hip"),
            "knee": (("{S}_hip", "{S}_knee"), "upper_leg"),
            "ankle": (("{S}_knee", "{S}_ankle"), "lower_leg"),
            "toe": (("{S}_ankle", "{S}_toe"), "foot"),
        }
        parts = []
        for joint in CANONICAL_JOINTS:
            if joint == "base":
                # pelvis: the hip-to-hip segment, twice the half width long
                parts.append(
                    BodyPart(
                        "base", (("base", 1.0),), ("r_hip", "l_hip"), "hip", half_length_scale=1.0
                    )
                )
                continue
            side, _, kind = joint.partition("_") if "_" in joint else ("", "", joint)
            (tail, tip), seg = segment_of[kind]
            parts.append(
                BodyPart(
                    joint,
                    ((joint, 1.0),),
                    (tail.format(S=side), tip.format(S=side)),
                    seg,
                    sphere=(kind == "head" and sphere_head),
                )
            )
        return tuple(parts)
    raise ValueError(f"unknown placement {placement!r}")


def part_semi_axes(parts: tuple[BodyPart, ...], height: float) -> tuple[FloatArray, FloatArray]:
    """Semi-axes ``a`` (= b) and ``c`` [m] of each part, (n_parts,) each, for height [m].
    Spheres get ``c = a``."""
    a = np.array([PART_RADII[p.segment] for p in parts])
    c = np.array(
        [
            PART_RADII[p.segment]
            if p.sphere
            else p.half_length_scale * SEGMENT_FRACTIONS[p.segment] * height
            for p in parts
        ]
    )
    return a, c


@functools.cache
def _part_index(
    parts: tuple[BodyPart, ...],
) -> tuple[NDArray[np.intp], FloatArray, list[int], list[int], bool]:
    """Joint indices and weights of the parts' positions, their axes' tail and tip joints, and
    whether the positions are exactly the 17 joints in order."""
    n_terms = max(len(p.position) for p in parts)
    index = np.zeros((n_terms, len(parts)), dtype=np.intp)
    weight = np.zeros((n_terms, len(parts)))
    for i, p in enumerate(parts):
        for k, (joint, w) in enumerate(p.position):
            index[k, i], weight[k, i] = _J[joint], w
    identity = n_terms == 1 and bool(np.all(weight[0] == 1.0))
    identity = identity and index[0].tolist() == list(range(len(CANONICAL_JOINTS)))
    tail = [_J[p.axis[0]] for p in parts]
    tip = [_J[p.axis[1]] for p in parts]
    return index, weight, tail, tip, identity


def part_geometry(
    parts: tuple[BodyPart, ...], joints: FloatArray, joint_axis: int = 1
) -> tuple[FloatArray, FloatArray]:
    """Positions and axis vectors of the parts from canonical joints.

    ``joints`` (n_pulses, 17, 3) [m], or any layout with the 17 joints along ``joint_axis``:
    e.g. coordinates first, (3, n_pulses, 17) with ``joint_axis=-1``, where every later
    product over the coordinates runs over whole contiguous planes. Returns ``positions`` and
    ``axes`` in the same layout with the parts along ``joint_axis`` [m]; axes are not
    normalised and may be zero for coincident joints. Positions may share memory with
    ``joints`` (when the parts are the joints themselves).
    """
    if joints.shape[joint_axis] != len(CANONICAL_JOINTS):
        raise ValueError(
            f"joints: {joints.shape[joint_axis]} along axis {joint_axis}, not the "
            f"{len(CANONICAL_JOINTS)} canonical joints"
        )
    index, weight, tail, tip, identity = _part_index(parts)
    # mode "clip": the indices are the canonical joints' own (checked above), and numpy's
    # default ("raise") gathers through a buffer, a fifth slower here
    axes = np.take(joints, tip, axis=joint_axis, mode="clip")
    axes -= np.take(joints, tail, axis=joint_axis, mode="clip")
    if identity:
        return joints, axes
    shape = [1] * joints.ndim
    shape[joint_axis] = len(parts)
    positions = np.take(joints, index[0], axis=joint_axis, mode="clip")
    if not np.all(weight[0] == 1.0):
        positions *= weight[0].reshape(shape)
    for k in range(1, index.shape[0]):
        positions += weight[k].reshape(shape) * np.take(
            joints, index[k], axis=joint_axis, mode="clip"
        )
    return positions, axes


def estimate_height(joints: FloatArray) -> float:
    """Height [m] estimated from canonical joints (n_frames, 17, 3): the median over frames and
    both legs of (thigh + shank) divided by their height fraction 0.491 (Boulic's H_t ratio)."""
    legs = []
    for s in ("l", "r"):
        hip, knee, ankle = (
            joints[:, _J[f"{s}_hip"]],
            joints[:, _J[f"{s}_knee"]],
            joints[:, _J[f"{s}_ankle"]],
        )
        legs.append(np.linalg.norm(hip - knee, axis=-1) + np.linalg.norm(knee - ankle, axis=-1))
    leg = np.concatenate(legs)
    leg = leg[np.isfinite(leg) & (leg > 0)]
    if leg.size == 0:
        raise ValueError("cannot estimate the height: no frame has valid hip, knee and ankle")
    return float(np.median(leg) / (SEGMENT_FRACTIONS["upper_leg"] + SEGMENT_FRACTIONS["lower_leg"]))
