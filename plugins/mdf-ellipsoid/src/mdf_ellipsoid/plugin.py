"""Entry point of the ``mdf-ellipsoid`` distribution."""

from __future__ import annotations

from mdframework import ScattererModel, hookimpl

from .model import EllipsoidBody


@hookimpl
def mdframework_register_scatterer_models() -> list[type[ScattererModel]]:
    """Register the sphere/ellipsoid body model."""
    return [EllipsoidBody]
