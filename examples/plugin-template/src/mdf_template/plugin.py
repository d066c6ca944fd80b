"""The entry point: registration hooks only. ``mdf --help`` imports this module, so it (and the
modules it imports) must not import heavy libraries at top level; import them inside the methods
that use them."""

from __future__ import annotations

from mdframework import Effect, MotionSource, hookimpl

from .effect import Gain
from .source import Pendulum


@hookimpl
def mdframework_register_motion_sources() -> list[type[MotionSource]]:
    """Register the pendulum (``[motion] kind = "pendulum"``)."""
    return [Pendulum]


@hookimpl
def mdframework_register_effects() -> list[type[Effect]]:
    """Register the receiver gain (``[[effects]] kind = "gain"``)."""
    return [Gain]
