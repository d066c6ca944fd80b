"""Chirp-sequence FMCW radar plugin for mdframework (kind ``fmcw``)."""

from .presets import PRESETS
from .waveform import FmcwRadar

__all__ = ["PRESETS", "FmcwRadar"]
