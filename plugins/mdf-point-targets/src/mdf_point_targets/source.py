"""Point scatterers at constant velocity, for calibration and tests.

The source places each target at ``position + velocity * t`` [m] for ``0 <= t <= length``,
sampled at ``frame_rate``. The motion is linear, so any interpolation of it is exact; the
source says so (``Motion.linear_tracks``) and the pipeline resamples it linearly, without a
spline. The ``points`` scatterer model turns each joint into an isotropic scatterer whose RCS is
the target's.
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import Field

from mdframework import (
    ConfigSection,
    Motion,
    MotionConfig,
    MotionSource,
    PluginConfig,
    ScattererModel,
    Scatterers,
    Skeleton,
    limits,
)
from mdframework.settings import FrameRate, Point3, PositiveSeconds, Rcs

#: A velocity component [m/s].
Speed = Annotated[float, Field(ge=-limits.MAX_TARGET_SPEED_MPS, le=limits.MAX_TARGET_SPEED_MPS)]


class Target(ConfigSection):
    """One point scatterer."""

    position: Point3 = Field(description="Position at t = 0 [m].")
    velocity: tuple[Speed, Speed, Speed] = Field(
        (0.0, 0.0, 0.0), description="Constant velocity [m/s]."
    )
    rcs: Rcs = Field(1.0, description="Radar cross section [m^2].")


class PointTargetsConfig(MotionConfig):
    """Point scatterers moving at constant velocity."""

    kind: Literal["point_targets"] = "point_targets"
    targets: list[Target] = Field(min_length=1, description="The scatterers.")
    length: PositiveSeconds = Field(description="Length of the generated recording [s].")
    frame_rate: FrameRate = Field(100.0, description="Sampling of the tracks [Hz].")
    label: str = Field("point_targets", description="Activity label recorded with the run.")

    def known_length(self) -> float | None:
        """The record's length [s]: ``duration``, else the generated length after ``start``."""
        return self.duration if self.duration is not None else self.length - self.start


class PointTargets(MotionSource):
    """Constant-velocity point targets."""

    name = "point_targets"
    Config = PointTargetsConfig
    config: PointTargetsConfig

    def load(self) -> Motion:
        """Tracks of all targets; joints are named ``target0``, ``target1``, ..."""
        c = self.config
        n = int(np.floor(c.length * c.frame_rate + 1e-9)) + 1
        t = np.arange(n) / c.frame_rate
        if t[-1] < c.length - 1e-12:
            t = np.append(t, c.length)
        p0 = np.array([tg.position for tg in c.targets], dtype=np.float64)
        v = np.array([tg.velocity for tg in c.targets], dtype=np.float64)
        pos = p0[None, :, :] + t[:, None, None] * v[None, :, :]
        names = tuple(f"target{i}" for i in range(len(c.targets)))
        meta = {"source": "point_targets", "activity": c.label, "n_targets": len(c.targets)}
        rcs = np.array([tg.rcs for tg in c.targets], dtype=np.float64)
        return Motion(Skeleton(t, pos, names), meta, None, rcs, linear_tracks=True)


class IsotropicPointsConfig(PluginConfig):
    """Every joint is an isotropic point scatterer."""

    kind: Literal["points"] = "points"
    rcs: Rcs | None = Field(
        None, description="RCS of every point [m^2]; default: the source's, else 1 m^2."
    )
    body: bool = Field(
        False,
        description="Use a human body's 17 canonical joints, placed in the scene like any body "
        "(the crudest body model: one isotropic point per joint).",
    )


class IsotropicPoints(ScattererModel):
    """Joints as isotropic point scatterers (angle-independent RCS)."""

    name = "points"
    Config = IsotropicPointsConfig
    config: IsotropicPointsConfig

    def __init__(self, config: IsotropicPointsConfig | None = None) -> None:
        super().__init__(config)
        self.needs_canonical = self.config.body

    def scatterers(
        self, motion: Motion, skeleton: Skeleton, radar_position: np.ndarray, wavelength: float
    ) -> Scatterers:
        """One scatterer per joint with constant RCS."""
        n_p, n_j = skeleton.positions.shape[:2]
        if self.config.rcs is not None:
            rcs = np.full(n_j, self.config.rcs)
        elif motion.point_rcs is not None and motion.point_rcs.shape == (n_j,):
            rcs = motion.point_rcs
        else:
            rcs = np.ones(n_j)
        return Scatterers(
            skeleton.positions, np.broadcast_to(rcs, (n_p, n_j)).copy(), skeleton.joint_names
        )
