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
from mdframework.testing import standing_body, walking_positions

J = {n: i for i, n in enumerate(CANONICAL_JOINTS)}


def standing(height: float = 1.8) -> np.ndarray:
    """Canonical joints (17, 3) [m] of a person standing at the origin facing +x."""
    return standing_body(height)


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
        pos = walking_positions(t, c.speed, c.swing_deg, c.cadence_hz)
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
