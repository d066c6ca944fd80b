"""mdf-c3d: marker files, C3D (read through ezc3d) and TRC (OpenSim's text format), with a
marker-to-joint map onto the canonical body. See ``docs/motion-formats.md``."""

from __future__ import annotations

from .markersets import MARKER_SETS, detect_marker_set
from .reader import C3dHeader, C3dMarkers, read_c3d, read_c3d_header
from .source import C3dConfig, C3dSource, TrcConfig, TrcSource
from .trc import TrcMarkers, read_trc

__all__ = [
    "MARKER_SETS",
    "C3dConfig",
    "C3dHeader",
    "C3dMarkers",
    "C3dSource",
    "TrcConfig",
    "TrcMarkers",
    "TrcSource",
    "detect_marker_set",
    "read_c3d",
    "read_c3d_header",
    "read_trc",
]
