"""Entry point of the ``mdf-multipath`` distribution."""

from __future__ import annotations

from mdframework import Effect, hookimpl

from .multipath import GroundMultipath


@hookimpl
def mdframework_register_effects() -> list[type[Effect]]:
    """Register ground-bounce multipath (kind ``multipath``)."""
    return [GroundMultipath]
