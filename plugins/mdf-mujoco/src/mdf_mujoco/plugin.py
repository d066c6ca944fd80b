"""Entry point of the ``mdf-mujoco`` distribution."""

from __future__ import annotations

from mdframework import Effect, MotionSource, ScattererModel, hookimpl

from .scatterers import MujocoBody
from .shadowing import Shadowing
from .source import BoulicWalker


@hookimpl
def mdframework_register_motion_sources() -> list[type[MotionSource]]:
    """Register the Boulic walker (kind ``boulic``)."""
    return [BoulicWalker]


@hookimpl
def mdframework_register_scatterer_models() -> list[type[ScattererModel]]:
    """Register the MuJoCo body-part ellipsoids (kind ``mujoco_body``)."""
    return [MujocoBody]


@hookimpl
def mdframework_register_effects() -> list[type[Effect]]:
    """Register body self-shadowing (kind ``shadowing``)."""
    return [Shadowing]
