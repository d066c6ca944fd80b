"""Entry point of the ``mdf-radhar`` distribution."""

from __future__ import annotations

from mdframework import RadarRecordingSource, hookimpl

from .source import RadharSource


@hookimpl
def mdframework_register_recordings() -> list[type[RadarRecordingSource]]:
    """Register the RadHAR point-cloud reader (``kind = "radhar"``)."""
    return [RadharSource]
