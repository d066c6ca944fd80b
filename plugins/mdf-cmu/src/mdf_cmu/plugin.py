"""Entry point of the ``mdf-cmu`` distribution."""

from __future__ import annotations

from mdframework import MotionSource, hookimpl

from .source import CmuSource


@hookimpl
def mdframework_register_motion_sources() -> list[type[MotionSource]]:
    """Register the CMU motion capture source (``kind = "cmu"``)."""
    return [CmuSource]
