"""Entry point of the ``mdf-noise`` distribution."""

from __future__ import annotations

from mdframework import Effect, hookimpl

from .noise import ReceiverNoise


@hookimpl
def mdframework_register_effects() -> list[type[Effect]]:
    """Register receiver noise (kind ``noise``)."""
    return [ReceiverNoise]
