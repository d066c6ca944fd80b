"""CMU Graphics Lab motion capture trials (ASF/AMC and cgspeed BVH) as an mdframework source."""

from .asfamc import AmcMotion, AsfBone, AsfSkeleton, asf_forward_kinematics, read_amc, read_asf
from .bvh import BvhData, BvhJoint, bvh_forward_kinematics, read_bvh
from .kinematics import CMU_UNIT_M, to_project_frame
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
    "AmcMotion",
    "AsfBone",
    "AsfSkeleton",
    "BvhData",
    "BvhJoint",
    "CmuConfig",
    "CmuSource",
    "asf_forward_kinematics",
    "bvh_forward_kinematics",
    "parse_trial_name",
    "read_amc",
    "read_asf",
    "read_bvh",
    "subject_frame_rate",
    "to_project_frame",
]
