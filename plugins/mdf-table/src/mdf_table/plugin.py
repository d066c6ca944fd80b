"""Entry point of the ``mdf-table`` distribution."""

from __future__ import annotations

from mdframework import MotionSource, hookimpl

from .source import TableSource


@hookimpl
def mdframework_register_motion_sources() -> list[type[MotionSource]]:
    """Register the joint-track table source (``kind = "table"``)."""
    return [TableSource]
