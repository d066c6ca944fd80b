"""Entry point of the ``mdf-attenuation`` distribution."""

from __future__ import annotations

from mdframework import Effect, hookimpl

from .attenuation import Attenuation


@hookimpl
def mdframework_register_effects() -> list[type[Effect]]:
    """Register atmospheric/rain attenuation (kind ``attenuation``)."""
    return [Attenuation]
