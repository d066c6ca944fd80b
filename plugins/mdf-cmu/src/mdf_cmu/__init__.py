"""CMU Graphics Lab motion capture trials (ASF/AMC and BVH) and BVH files of any rig as
mdframework sources."""

from .anybvh import BvhConfig, BvhSource, FrameRateWarning, choose_rate, load_any_bvh
from .asfamc import AmcMotion, AsfBone, AsfSkeleton, asf_forward_kinematics, read_amc, read_asf
from .bvh import BvhData, BvhJoint, bvh_forward_kinematics, read_bvh
from .kinematics import CMU_UNIT_M, to_project_frame
from .rigs import RIGS, Rig, RigMismatch, detect_rig, resolve
from .source import (
    ACKNOWLEDGEMENT,
    ASF_CANONICAL_MAP,
    BVH_CANONICAL_MAP,
    CmuConfig,
    CmuSource,
    parse_trial_name,
    subject_frame_rate,
)

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
