"""Entry point of the ``mdf-cw`` distribution."""

from __future__ import annotations

from mdframework import RadarWaveform, hookimpl

from .waveform import CwDoppler


@hookimpl
def mdframework_register_radar_waveforms() -> list[type[RadarWaveform]]:
    """Register the CW Doppler radar."""
    return [CwDoppler]
