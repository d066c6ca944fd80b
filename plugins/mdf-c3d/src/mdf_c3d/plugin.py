"""Entry point of the ``mdf-c3d`` distribution."""

from __future__ import annotations

from mdframework import MotionSource, hookimpl

from .source import C3dSource, TrcSource


@hookimpl
def mdframework_register_motion_sources() -> list[type[MotionSource]]:
    """Register the marker-file sources (``kind = "c3d"`` and ``kind = "trc"``)."""
    return [C3dSource, TrcSource]
