"""Entry point of the ``mdf-kinect`` distribution."""

from __future__ import annotations

import argparse
from typing import Any

from mdframework import MotionSource, hookimpl

from .cli import add_commands
from .source import KinectSource


@hookimpl
def mdframework_register_motion_sources() -> list[type[MotionSource]]:
    """Register the Kinect skeleton-recording source (``kind = "kinect"``)."""
    return [KinectSource]


@hookimpl
def mdframework_add_cli_commands(subparsers: argparse._SubParsersAction[Any]) -> None:
    """Add ``mdf capture`` and ``mdf kinect info``."""
    add_commands(subparsers)
