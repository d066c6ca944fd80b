"""Example third-party plugin: one point target moving on a horizontal circle.

Seen from a radar at the circle's centre its range never changes (zero Doppler); seen from
outside, its radial velocity swings between +-(2 pi radius / period). Install with
``pip install -e examples/plugin-example`` and use ``kind = "circle"`` in a config's
``[motion]`` section.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field

from mdframework import Motion, MotionConfig, MotionSource, Skeleton, hookimpl


class CircleConfig(MotionConfig):
    """A point on a horizontal circle."""

    kind: Literal["circle"] = "circle"
    centre: tuple[float, float, float] = Field((0.0, 0.0, 1.0), description="Centre [m].")
    radius: float = Field(1.0, gt=0, description="Radius [m].")
    period: float = Field(2.0, gt=0, description="Time per revolution [s].")
    length: float = Field(4.0, gt=0, description="Record length [s].")
    frame_rate: float = Field(100.0, gt=0, description="Track sampling rate [Hz].")


class Circle(MotionSource):
    """A point target moving on a circle (not a human body: use scatterers kind "points")."""

    name = "circle"
    Config = CircleConfig
    config: CircleConfig

    def load(self) -> Motion:
        """The track of the point, one joint named ``target``."""
        c = self.config
        t = np.arange(0.0, c.length + 1e-9, 1.0 / c.frame_rate)
        phase = 2.0 * np.pi * t / c.period
        xyz = np.stack(
            [c.radius * np.cos(phase), c.radius * np.sin(phase), np.zeros_like(t)], axis=1
        ) + np.asarray(c.centre)
        skeleton = Skeleton(t, xyz[:, None, :], ("target",))
        return Motion(skeleton, {"source": "circle", "activity": "circle"})


@hookimpl
def mdframework_register_motion_sources() -> list[type[MotionSource]]:
    """Register the circle source."""
    return [Circle]
