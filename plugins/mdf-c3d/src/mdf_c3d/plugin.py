"""Entry point of the ``mdf-c3d`` distribution."""

from __future__ import annotations

from mdframework import MotionSource, hookimpl

from .source import C3dSource


@hookimpl
def mdframework_register_motion_sources() -> list[type[MotionSource]]:
    """Register the C3D marker-file source (``kind = "c3d"``)."""
    return [C3dSource]
