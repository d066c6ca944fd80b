"""Entry point of the ``mdf-cmu`` distribution."""

from __future__ import annotations

from mdframework import MotionSource, hookimpl

from .anybvh import BvhSource
from .source import CmuSource


@hookimpl
def mdframework_register_motion_sources() -> list[type[MotionSource]]:
    """Register the CMU motion capture source (``kind = "cmu"``) and the any-rig BVH source
    (``kind = "bvh"``)."""
    return [CmuSource, BvhSource]
