"""Entry point of the ``mdf-fmcw`` distribution."""

from __future__ import annotations

from mdframework import RadarWaveform, hookimpl

from .waveform import FmcwRadar


@hookimpl
def mdframework_register_radar_waveforms() -> list[type[RadarWaveform]]:
    """Register the chirp-sequence FMCW radar."""
    return [FmcwRadar]
