"""mdf-kinect: Kinect skeleton recordings, OpenNI2 devices and .oni files, NiTE2 capture.

See ``docs/kinect.md``.
"""

from __future__ import annotations

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
from .source import KinectConfig, KinectSource

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
