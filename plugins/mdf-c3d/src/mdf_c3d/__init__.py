"""mdf-c3d: C3D marker files, read through ezc3d, with a marker-to-joint map onto the canonical
body. See ``docs/motion-formats.md``."""

from __future__ import annotations

from .markersets import MARKER_SETS, detect_marker_set
from .reader import C3dHeader, C3dMarkers, read_c3d, read_c3d_header
from .source import C3dConfig, C3dSource

__all__ = [
    "MARKER_SETS",
    "C3dConfig",
    "C3dHeader",
    "C3dMarkers",
    "C3dSource",
    "detect_marker_set",
    "read_c3d",
    "read_c3d_header",
]
