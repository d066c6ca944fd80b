"""CMU Graphics Lab motion capture trials (ASF/AMC and BVH) and BVH files of any rig as
mdframework sources."""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .anybvh import BvhConfig, BvhSource, FrameRateWarning, choose_rate, load_any_bvh
from .source import (
    ACKNOWLEDGEMENT,
    ASF_CANONICAL_MAP,
    BVH_CANONICAL_MAP,
    CmuConfig,
    CmuSource,
    parse_trial_name,
    subject_frame_rate,
)

if TYPE_CHECKING:
    from .asfamc import AmcMotion, AsfBone, AsfSkeleton, asf_forward_kinematics, read_amc, read_asf
    from .bvh import BvhData, BvhJoint, bvh_forward_kinematics, read_bvh
    from .kinematics import CMU_UNIT_M, to_project_frame
    from .rigs import RIGS, Rig, RigMismatch, detect_rig, resolve

#: public names imported on first use: loading the plugin (every mdf command loads every
#: plugin) imports its source classes only, not the ASF/AMC and BVH readers and the rigs
_EXPORTS = {
    "AmcMotion": "asfamc",
    "AsfBone": "asfamc",
    "AsfSkeleton": "asfamc",
    "asf_forward_kinematics": "asfamc",
    "read_amc": "asfamc",
    "read_asf": "asfamc",
    "BvhData": "bvh",
    "BvhJoint": "bvh",
    "bvh_forward_kinematics": "bvh",
    "read_bvh": "bvh",
    "CMU_UNIT_M": "kinematics",
    "to_project_frame": "kinematics",
    "RIGS": "rigs",
    "Rig": "rigs",
    "RigMismatch": "rigs",
    "detect_rig": "rigs",
    "resolve": "rigs",
}

__all__ = [
    "ACKNOWLEDGEMENT",
    "ASF_CANONICAL_MAP",
    "BVH_CANONICAL_MAP",
    "CMU_UNIT_M",
    "RIGS",
    "AmcMotion",
    "AsfBone",
    "AsfSkeleton",
    "BvhConfig",
    "BvhData",
    "BvhJoint",
    "BvhSource",
    "CmuConfig",
    "CmuSource",
    "FrameRateWarning",
    "Rig",
    "RigMismatch",
    "asf_forward_kinematics",
    "bvh_forward_kinematics",
    "choose_rate",
    "detect_rig",
    "load_any_bvh",
    "parse_trial_name",
    "read_amc",
    "read_asf",
    "read_bvh",
    "resolve",
    "subject_frame_rate",
    "to_project_frame",
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
