"""A synthetic walking body, registered by hand as a motion source for tests.

The body is the canonical 17-point skeleton of a standing 1.8 m person built from the segment
table, translated at a constant velocity with the legs and arms swinging about the hips and
shoulders. Options collapse joints (zero-length segments) for the hard cases.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field

from mdframework import CANONICAL_JOINTS, Motion, MotionConfig, MotionSource, Skeleton, hookimpl
from mdframework.physics import body

J = {n: i for i, n in enumerate(CANONICAL_JOINTS)}


def standing(height: float = 1.8) -> np.ndarray:
    """Canonical joints (17, 3) [m] of a person standing at the origin facing +x."""
    f = body.SEGMENT_FRACTIONS
    z_hip = (f["upper_leg"] + f["lower_leg"]) * height
    top = z_hip + f["torso"] * height
    p = {"base": (0, 0, z_hip), "neck": (0, 0, top), "head": (0, 0, top + f["head"] * height)}
    for s, y in (("l", 1.0), ("r", -1.0)):
        sh, hp = y * f["shoulder"] * height, y * f["hip"] * height
        p[f"{s}_shoulder"] = (0, sh, top)
        p[f"{s}_elbow"] = (0, sh, top - f["upper_arm"] * height)
        p[f"{s}_hand"] = (0, sh, top - (f["upper_arm"] + f["lower_arm"]) * height)
        p[f"{s}_hip"] = (0, hp, z_hip)
        p[f"{s}_knee"] = (0, hp, z_hip - f["upper_leg"] * height)
        p[f"{s}_ankle"] = (0, hp, 0.0)
        p[f"{s}_toe"] = (f["foot"] * height, hp, 0.0)
    return np.array([p[j] for j in CANONICAL_JOINTS], dtype=float)


class SyntheticConfig(MotionConfig):
    """Synthetic walker."""

    kind: Literal["synthetic_walker"] = "synthetic_walker"
    speed: float = 1.0
    swing_deg: float = 25.0
    cadence_hz: float = 0.9
    length: float = Field(3.0, gt=0)
    frame_rate: float = 30.0
    collapse: Literal["none", "l_forearm", "all"] = "none"


class SyntheticWalker(MotionSource):
    """A rigid body moving forward with swinging limbs (tests only)."""

    name = "synthetic_walker"
    Config = SyntheticConfig
    config: SyntheticConfig

    def load(self) -> Motion:
        c = self.config
        t = np.arange(0, c.length + 1e-9, 1 / c.frame_rate)
        base = standing()
        pos = np.repeat(base[None], t.size, axis=0)
        ang = np.deg2rad(c.swing_deg) * np.sin(2 * np.pi * c.cadence_hz * t)
        for s, sign in (("l", 1.0), ("r", -1.0)):
            for pivot, limb in (("hip", ("knee", "ankle", "toe")), ("shoulder", ("elbow", "hand"))):
                a = sign * ang * (1 if pivot == "hip" else -1)
                piv = base[J[f"{s}_{pivot}"]]
                for name in limb:
                    d = base[J[f"{s}_{name}"]] - piv
                    x = d[0] * np.cos(a) - d[2] * np.sin(a)
                    z = d[0] * np.sin(a) + d[2] * np.cos(a)
                    pos[:, J[f"{s}_{name}"]] = piv + np.stack([x, np.full_like(x, d[1]), z], 1)
        pos[:, :, 0] += c.speed * t[:, None]
        if c.collapse == "l_forearm":
            pos[t.size // 3 :, J["l_hand"]] = pos[t.size // 3 :, J["l_elbow"]]
        elif c.collapse == "all":  # every joint but the hips onto the base
            others = [i for n, i in J.items() if n not in ("l_hip", "r_hip")]
            pos[:, others] = pos[:, :1]
        mapping = {j: j for j in CANONICAL_JOINTS}
        meta = {"source": "synthetic", "activity": "walk"}
        return Motion(Skeleton(t, pos, CANONICAL_JOINTS), meta, mapping)


@hookimpl
def mdframework_register_motion_sources() -> list[type[MotionSource]]:
    """Register the synthetic walker."""
    return [SyntheticWalker]
