"""The Boulic walker as a motion source (kind ``boulic``).

The walker lives in its own frame (x forward from the origin, y left, z up); the scene's
``person`` section places it (``position``, ``heading_deg`` / ``aspect_deg``, ``motion``), so the
walker has no start point or heading of its own. Joint positions come from the MuJoCo model
(:class:`~mdf_mujoco.body_model.WalkerBody`) evaluated at the walker's own rate, ``nt`` samples
per gait cycle (``nt / Dc`` Hz, 380 Hz for the default ``nt = 512`` at ``rv = 1``); the
pipeline's spline resamples them to the pulse times. The ``mujoco_body`` scatterer model
re-evaluates the MuJoCo model at the pulse times themselves (see
:mod:`mdf_mujoco.scatterers`).

See :mod:`mdf_mujoco.gait` for the model and every difference between the corrected default and
``chen_compatible`` mode.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from pydantic import Field, model_validator

from mdframework import CANONICAL_JOINTS, Motion, MotionConfig, MotionSource, Skeleton, limits
from mdframework.physics.body import LEG_FRACTION
from mdframework.settings import SanityConfig

from .body_model import WalkerBody
from .gait import Gait, cycle_duration

#: Sanity options the walker sets unless the config gives them (see ``BoulicConfig``).
_WALKER_SANITY: dict[str, Any] = {"cadence": False, "size": "ignore"}


class BoulicConfig(MotionConfig):
    """Boulic's global walking model (as coded by V.C. Chen), built in MuJoCo."""

    kind: Literal["boulic"] = "boulic"
    height: float = Field(1.8, gt=0.5, lt=2.5, description="Body height H [m].")
    rv: float | None = Field(
        None,
        gt=0,
        le=3,
        description="Relative velocity v / H_t [1/s], 0 < rv <= 3 (H_t = 0.491 H). "
        "Give rv or speed, not both; default rv = 1.",
    )
    speed: float | None = Field(
        None,
        gt=0,
        le=limits.MAX_PERSON_SPEED_MPS,
        description="Walking speed [m/s]; sets rv = speed / H_t (chen_compatible: rv = speed, "
        "since Chen's base moves at rv m/s).",
    )
    n_cycles: int | None = Field(
        None,
        ge=1,
        le=10_000,
        description="Gait cycles to generate; default: enough for start + duration, else 3. "
        "The walk, from its start, is at most a day and 10 million frames (n_cycles nt).",
    )
    nt: int = Field(
        512,
        ge=32,
        le=65536,
        description="Samples per gait cycle (even); at least 32: fewer leave the pipeline's "
        "spline of the samples millimetres to centimetres off the walker's kinematics.",
    )
    chen_compatible: bool = Field(
        False,
        description="Reproduce the quirks of Chen's MATLAB code (speed scale, gait-a sign flip, "
        "elbow typo, frozen elbow height, linspace progression, origin at the hips, "
        "lower-leg ellipsoid) for side-by-side comparison.",
    )
    activity: str = Field("walk", description="Activity label recorded with the run.")
    sanity: SanityConfig = Field(
        default_factory=SanityConfig,  # the validator below gives the walker's
        description="Motion sanity checks, with the cadence and size checks off unless set "
        "here (cadence = false, size = 'ignore'): the walker's cadence and legs follow from rv "
        "and height.",
    )

    @model_validator(mode="before")
    @classmethod
    def _walker_sanity(cls, data: Any) -> Any:
        """The cadence and size sanity checks are off unless asked for: made to expose a wrong
        frame rate or length unit, they blamed the walker's exact time base outside rv
        0.62-2.8 (its cadence is the model's, 120 sqrt(rv) / 1.346 steps a minute) and its
        unit below a height of 0.82 m (its legs are 0.491 H long)."""
        if not isinstance(data, dict):
            return data
        given = data.get("sanity")
        if given is None:
            return {**data, "sanity": dict(_WALKER_SANITY)}
        if isinstance(given, dict):
            return {**data, "sanity": _WALKER_SANITY | given}
        if isinstance(given, SanityConfig):
            off = {k: v for k, v in _WALKER_SANITY.items() if k not in given.model_fields_set}
            return {**data, "sanity": given.model_copy(update=off)}
        return data

    @model_validator(mode="after")
    def _check(self) -> BoulicConfig:
        if self.nt % 2:
            raise ValueError(f"nt: must be even (the left side is the right rolled by nt/2), "
                             f"got {self.nt}")  # fmt: skip
        if self.rv is not None and self.speed is not None:
            raise ValueError("speed: give rv or speed, not both")
        rv = self.relative_velocity
        if not 0 < rv <= 3:
            raise ValueError(
                f"speed: {self.speed} m/s gives rv = {rv:.4g}, outside Boulic's 0 < rv <= 3 "
                f"(H_t = {LEG_FRACTION * self.height:.4g} m)"
            )
        dc = cycle_duration(rv)
        n = self.cycles(dc)
        end = self.start + (self.duration or 0.0)
        if self.n_cycles is not None and end > n * dc + 1e-9:
            raise ValueError(
                f"n_cycles: start + duration = {end:g} s is longer than the walk of n_cycles = {n} "
                f"cycle(s) of {dc:.4g} s (rv = {rv:.4g}): {n * dc:.4g} s; set n_cycles to at "
                f"least {math.ceil(end / dc - 1e-9)}, or leave it out (enough cycles for the "
                "window)"
            )
        if n * dc > limits.MAX_DURATION_S or n * self.nt + 1 > limits.MAX_FRAMES:
            # the field that set the number of cycles, else the cycle's length
            field = "n_cycles" if self.n_cycles is not None else "duration"
            if self.n_cycles is None and self.duration is None:
                field = "rv" if self.speed is None else "speed"
            raise ValueError(
                f"{field}: the walk is {n} cycle(s) of {dc:.4g} s (rv = {rv:.4g}) from its start, "
                f"{n * dc:.4g} s and {n * self.nt + 1:,} frames (nt = {self.nt} per cycle), "
                f"beyond the limits of {limits.MAX_DURATION_S:g} s and {limits.MAX_FRAMES:,} "
                "frames: walk fewer cycles (n_cycles, or an earlier start + duration), a smaller "
                "nt or a larger rv"
            )
        return self

    def cycles(self, cycle_duration: float) -> int:
        """Gait cycles to generate for a cycle of ``cycle_duration`` [s]: ``n_cycles``, else
        enough for ``start + duration``, else 3."""
        if self.n_cycles is not None:
            return self.n_cycles
        if self.duration is None:
            return 3
        return max(1, math.ceil((self.start + self.duration) / cycle_duration - 1e-9))

    @property
    def relative_velocity(self) -> float:
        """The rv the config asks for [1/s]."""
        if self.speed is not None:
            return self.speed if self.chen_compatible else self.speed / (LEG_FRACTION * self.height)
        return 1.0 if self.rv is None else self.rv


@dataclass(frozen=True)
class BoulicMotion(Motion):
    """A :class:`~mdframework.Motion` that also carries the walker's :class:`Gait`, so that the
    ``mujoco_body`` scatterer model can evaluate the MuJoCo model at the pulse times."""

    gait: Gait | None = None


class BoulicWalker(MotionSource):
    """Boulic walker (kind ``boulic``)."""

    name = "boulic"
    Config = BoulicConfig
    config: BoulicConfig

    def gait(self) -> Gait:
        """The walker described by the config."""
        c = self.config
        return Gait(c.height, c.relative_velocity, c.nt, c.chen_compatible)

    def n_cycles(self, gait: Gait) -> int:
        """Number of cycles to generate."""
        return self.config.cycles(gait.cycle_duration)

    def load(self) -> Motion:
        """Canonical joints at ``k Dc / nt`` s, ``k = 0 .. n_cycles nt`` (both ends)."""
        g = self.gait()
        n = self.n_cycles(g) * g.nt
        t = np.arange(n + 1, dtype=np.float64) * (g.cycle_duration / g.nt)
        frames = WalkerBody(g).frames(t, geoms=False)  # the joints alone
        meta = {
            "source": "boulic",
            "activity": self.config.activity,
            "height_m": g.height,
            "rv": g.rv,
            "gait_class": g.gait,
            "speed_mps": g.speed,
            "cycle_duration_s": g.cycle_duration,
            "support_fraction": g.support_fraction,
            "n_cycles": self.n_cycles(g),
            "nt": g.nt,
            "frame_rate_hz": g.nt / g.cycle_duration,
            "chen_compatible": g.chen_compatible,
        }
        skel = Skeleton(t, frames.joints, CANONICAL_JOINTS)
        return BoulicMotion(skel, meta, {j: j for j in CANONICAL_JOINTS}, gait=g)
