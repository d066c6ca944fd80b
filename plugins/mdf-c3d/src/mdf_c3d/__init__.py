"""mdf-c3d: marker files, C3D (read through ezc3d) and TRC (OpenSim's text format), with a
marker-to-joint map onto the canonical body. See ``docs/motion-formats.md``."""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .source import C3dConfig, C3dSource, TrcConfig, TrcSource

if TYPE_CHECKING:
    from .markersets import MARKER_SETS, detect_marker_set
    from .reader import C3dHeader, C3dMarkers, read_c3d, read_c3d_header
    from .trc import TrcMarkers, read_trc

#: public names imported on first use: loading the plugin (every mdf command loads every
#: plugin) imports its source classes only, not the marker-set tables and the readers
_EXPORTS = {
    "MARKER_SETS": "markersets",
    "detect_marker_set": "markersets",
    "C3dHeader": "reader",
    "C3dMarkers": "reader",
    "read_c3d": "reader",
    "read_c3d_header": "reader",
    "TrcMarkers": "trc",
    "read_trc": "trc",
}

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


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})
