"""mdf-kinect: Kinect skeleton recordings, OpenNI2 devices and .oni files, NiTE2 capture.

See ``docs/kinect.md``.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .source import KinectConfig, KinectSource

if TYPE_CHECKING:
    from .device import (
        DeviceError,
        NiteMissingError,
        initialize_nite,
        initialize_openni,
        iter_oni_frames,
        oni_info,
        oni_info_isolated,
        open_device,
        read_oni_depth,
        scan_oni,
    )
    from .formats import (
        KINECT_V1_CANONICAL,
        KINECT_V1_JOINTS,
        KINECT_V2_CANONICAL,
        KINECT_V2_JOINTS,
        MSR_JOINTS,
        Recording,
        read_msr,
        read_ntu,
        read_precog,
        read_utkinect,
        read_utkinect_labels,
        to_project_frame,
    )
    from .nitefile import NITE_CANONICAL, NITE_JOINTS, nite_frames_to_arrays, read_nite, write_nite

#: public names imported on first use: loading the plugin (every mdf command loads every
#: plugin) imports its source classes and command-line hook only, not the readers and the
#: device layer
_EXPORTS = {
    "DeviceError": "device",
    "NiteMissingError": "device",
    "initialize_nite": "device",
    "initialize_openni": "device",
    "iter_oni_frames": "device",
    "oni_info": "device",
    "oni_info_isolated": "device",
    "open_device": "device",
    "read_oni_depth": "device",
    "scan_oni": "device",
    "KINECT_V1_CANONICAL": "formats",
    "KINECT_V1_JOINTS": "formats",
    "KINECT_V2_CANONICAL": "formats",
    "KINECT_V2_JOINTS": "formats",
    "MSR_JOINTS": "formats",
    "Recording": "formats",
    "read_msr": "formats",
    "read_ntu": "formats",
    "read_precog": "formats",
    "read_utkinect": "formats",
    "read_utkinect_labels": "formats",
    "to_project_frame": "formats",
    "NITE_CANONICAL": "nitefile",
    "NITE_JOINTS": "nitefile",
    "nite_frames_to_arrays": "nitefile",
    "read_nite": "nitefile",
    "write_nite": "nitefile",
}

__all__ = [
    "KINECT_V1_CANONICAL",
    "KINECT_V1_JOINTS",
    "KINECT_V2_CANONICAL",
    "KINECT_V2_JOINTS",
    "MSR_JOINTS",
    "NITE_CANONICAL",
    "NITE_JOINTS",
    "DeviceError",
    "KinectConfig",
    "KinectSource",
    "NiteMissingError",
    "Recording",
    "initialize_nite",
    "initialize_openni",
    "iter_oni_frames",
    "nite_frames_to_arrays",
    "oni_info",
    "oni_info_isolated",
    "open_device",
    "read_msr",
    "read_nite",
    "read_ntu",
    "read_oni_depth",
    "read_precog",
    "read_utkinect",
    "read_utkinect_labels",
    "scan_oni",
    "to_project_frame",
    "write_nite",
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
