"""Entry point of the ``mdf-deepmimic`` distribution."""

from __future__ import annotations

from mdframework import MotionSource, hookimpl

from .source import DeepMimicSource


@hookimpl
def mdframework_register_motion_sources() -> list[type[MotionSource]]:
    """Register the DeepMimic clip source (``kind = "deepmimic"``)."""
    return [DeepMimicSource]
