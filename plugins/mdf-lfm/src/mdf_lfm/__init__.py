"""LFM pulse-Doppler radar waveform plugin for mdframework (kind ``lfm``)."""

from .waveform import LfmPulseDoppler

__all__ = ["LfmPulseDoppler"]
