"""CW Doppler radar waveform plugin for mdframework (kind ``cw``)."""

from .waveform import CwDoppler

__all__ = ["CwDoppler"]
