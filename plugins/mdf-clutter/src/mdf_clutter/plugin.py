"""Entry point of the ``mdf-clutter`` distribution."""

from __future__ import annotations

from mdframework import Effect, hookimpl

from .clutter import GroundClutter


@hookimpl
def mdframework_register_effects() -> list[type[Effect]]:
    """Register ground clutter (kind ``clutter``)."""
    return [GroundClutter]
