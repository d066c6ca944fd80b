"""Digests of loaded motions and recordings: a dataset record's id includes its input's, so a
digest that changes between versions makes every record of a resumed dataset computed afresh."""

from __future__ import annotations

import numpy as np

from mdframework.fingerprint import motion_fingerprint, recording_fingerprint
from mdframework.interfaces import Motion, Recording
from mdframework.pointcloud import PointCloud
from mdframework.skeleton import Skeleton


def test_a_motions_digest_is_the_one_earlier_versions_gave() -> None:
    """The digest of a small motion, pinned: 0.3's digests (arrays hashed through tobytes()),
    which the records' ids of datasets built since hold."""
    pos = np.arange(24, dtype=float).reshape(4, 2, 3) / 10
    motion = Motion(
        Skeleton(np.arange(4) * 0.01, pos, ("head", "pelvis")),
        canonical_map={"head": "head", "pelvis": "pelvis"},
        point_rcs=np.array([0.1, 0.2]),
    )
    assert motion_fingerprint(motion) == "2119f4d19c545883e7bd953d8f26e1cdc2266f46"


def test_a_recordings_digest_of_columns_of_one_table_is_that_of_its_copies() -> None:
    """A reader may give a recording's positions, velocities and intensities as columns of
    one table (views that are not contiguous): the digest is that of the same values in arrays
    of their own, and the one earlier versions gave (pinned)."""
    table = np.arange(24, dtype=float).reshape(4, 6) / 8
    frame = np.array([0, 0, 1, 3])

    def recording(pos: np.ndarray, vel: np.ndarray, intensity: np.ndarray) -> Recording:
        return Recording("r", PointCloud(frame, pos, vel, intensity, 0.05, 5))

    views = recording(table[:, :3], table[:, 3], table[:, 4])
    assert not views.cloud.positions.flags.c_contiguous
    copies = recording(table[:, :3].copy(), table[:, 3].copy(), table[:, 4].copy())
    assert recording_fingerprint(views) == recording_fingerprint(copies)
    assert recording_fingerprint(copies) == "9e19f0c7dd05c5a493657a29339cd5819a1c2932"
