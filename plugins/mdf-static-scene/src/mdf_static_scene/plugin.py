"""Entry point of the ``mdf-static-scene`` distribution."""

from __future__ import annotations

from mdframework import Effect, hookimpl

from .static import StaticScene


@hookimpl
def mdframework_register_effects() -> list[type[Effect]]:
    """Register the static scene effect (``kind = "static_scene"``)."""
    return [StaticScene]
