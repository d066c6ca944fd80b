"""Entry point of the ``mdf-radhar`` distribution."""

from __future__ import annotations

from mdframework import RecordingSource, hookimpl

from .source import RadharSource


@hookimpl
def mdframework_register_recording_sources() -> list[type[RecordingSource]]:
    """Register the RadHAR point-cloud reader (``kind = "radhar"``)."""
    return [RadharSource]
