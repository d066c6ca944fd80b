"""Digests of what a simulation reads: a loaded motion and a real radar's recording.

A digest covers the contents as loaded (time stamps, positions, validity, names; a
recording's points), whatever the files' paths, times or copies. Equal digests mean equal
inputs to the simulation. A dataset record's id includes its motion's or recording's digest,
and a run's ``metadata.json`` records its motion's (``motion.fingerprint``).
"""

from __future__ import annotations

import hashlib
import json
from typing import Any

import numpy as np

from .interfaces import Motion, Recording


def _hash_arrays(digest: Any, *arrays: Any) -> None:
    """Feed arrays into ``digest``: dtype, shape and bytes of each (None as a marker)."""
    for a in arrays:
        if a is None:
            digest.update(b"none;")
            continue
        arr = np.ascontiguousarray(a)
        digest.update(f"{arr.dtype.str}{arr.shape};".encode())
        digest.update(arr.data)  # its bytes in C order, as tobytes() gives, without a copy


def motion_fingerprint(motion: Motion) -> str:
    """A digest (40 hex digits) of everything a loaded motion gives the simulation: its time
    stamps, joint positions and validity, joint names, canonical map, point RCS and whether its
    tracks are linear. It covers what was read from every file behind the motion (an ``.asf``
    beside its ``.amc`` included), whatever their paths, times or copies."""
    sk = motion.skeleton
    digest = hashlib.sha1()
    _hash_arrays(digest, sk.time, sk.positions, sk.valid, motion.point_rcs)
    cmap = None if motion.canonical_map is None else sorted(motion.canonical_map.items())
    digest.update(json.dumps([list(sk.joint_names), cmap, bool(motion.linear_tracks)]).encode())
    return digest.hexdigest()


def recording_fingerprint(recording: Recording) -> str:
    """A digest (40 hex digits) of a real radar's recording: its name, frame period, frame
    count and every point (frame, position, velocity, intensity)."""
    cloud = recording.cloud
    digest = hashlib.sha1()
    digest.update(json.dumps([recording.name, cloud.frame_period, cloud.n_frames]).encode())
    _hash_arrays(digest, cloud.frame, cloud.positions, cloud.velocity, cloud.intensity)
    return digest.hexdigest()
