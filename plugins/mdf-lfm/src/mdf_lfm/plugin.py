"""Entry point of the ``mdf-lfm`` distribution."""

from __future__ import annotations

from mdframework import RadarWaveform, hookimpl

from .waveform import LfmPulseDoppler


@hookimpl
def mdframework_register_radar_waveforms() -> list[type[RadarWaveform]]:
    """Register the LFM pulse-Doppler waveform."""
    return [LfmPulseDoppler]
