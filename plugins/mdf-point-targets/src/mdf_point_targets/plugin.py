"""Entry point of the ``mdf-point-targets`` distribution."""

from __future__ import annotations

from mdframework import MotionSource, ScattererModel, hookimpl

from .source import IsotropicPoints, PointTargets


@hookimpl
def mdframework_register_motion_sources() -> list[type[MotionSource]]:
    """Register the point-target motion source."""
    return [PointTargets]


@hookimpl
def mdframework_register_scatterer_models() -> list[type[ScattererModel]]:
    """Register the isotropic point-scatterer model."""
    return [IsotropicPoints]
