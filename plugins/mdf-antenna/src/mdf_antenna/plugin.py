"""Entry point of the ``mdf-antenna`` distribution."""

from __future__ import annotations

from mdframework import Effect, hookimpl

from .antenna import AntennaPattern


@hookimpl
def mdframework_register_effects() -> list[type[Effect]]:
    """Register the antenna gain pattern (kind ``antenna``)."""
    return [AntennaPattern]
