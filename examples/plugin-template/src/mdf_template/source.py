"""A point target swinging on a pendulum, in the vertical plane that contains the x axis."""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field

from mdframework import Motion, MotionConfig, MotionSource, Skeleton

GRAVITY = 9.80665  # [m/s^2], standard gravity


class PendulumConfig(MotionConfig):
    """A point on a pendulum (small-angle motion)."""

    kind: Literal["pendulum"] = "pendulum"
    pivot: tuple[float, float, float] = Field((10.0, 0.0, 2.0), description="Pivot [m].")
    length: float = Field(1.0, gt=0, description="Pendulum length [m].")
    amplitude_deg: float = Field(10.0, gt=0, le=30, description="Swing amplitude [deg].")
    record_length: float = Field(4.0, gt=0, description="Length of the recording [s].")
    frame_rate: float = Field(200.0, gt=0, description="Track sampling rate [Hz].")
    rcs: float = Field(1.0, ge=0, description="RCS of the bob [m^2].")


class Pendulum(MotionSource):
    """A point target swinging on a pendulum along x (small angles: theta = A cos(w t),
    w = sqrt(g / L)). Not a human body: use ``[scatterers] kind = "points"``."""

    name = "pendulum"
    Config = PendulumConfig
    config: PendulumConfig

    def load(self) -> Motion:
        """The bob's track: (n_frames, 1, 3) [m] at ``frame_rate``."""
        c = self.config
        t = np.arange(0.0, c.record_length + 1e-9, 1.0 / c.frame_rate)
        theta = np.deg2rad(c.amplitude_deg) * np.cos(np.sqrt(GRAVITY / c.length) * t)
        xyz = np.stack(
            [c.length * np.sin(theta), np.zeros_like(t), -c.length * np.cos(theta)], axis=1
        )
        positions = (xyz + np.asarray(c.pivot))[:, None, :]
        metadata = {"source": "pendulum", "activity": "swing", "length_m": c.length}
        return Motion(Skeleton(t, positions, ("bob",)), metadata, point_rcs=np.array([c.rcs]))
