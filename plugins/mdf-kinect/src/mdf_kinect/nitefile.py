"""NiTE2 skeletons: the 15-joint recording file of ``mdf capture`` and the conversion from the
``openni`` binding's NiTE structures.

File format (``.nite.txt``, text, UTF-8)
----------------------------------------
::

    # mdf-nite-skeleton 1
    # device: PrimeSense / Kinect (uri ...)
    # software: mdf-kinect 0.1.0, OpenNI 2.2.0, NiTE 2.2
    # units: m; axes: Kinect SDK camera space (x to the sensor's left, y up, z away)
    # ... any further '# key: value' lines
    time_s frame user HEAD_x HEAD_y HEAD_z HEAD_c NECK_x ... RIGHT_FOOT_c
    0.000000 1 1 0.0123 0.6012 2.4001 1.00 ...

The first line identifies the format and version. ``#`` lines are ``key: value`` metadata.
The column line names the 63 columns: time [s] from the device's frame time stamp (relative to the
first frame), NiTE frame index, user id (the same on every line: one person a file), then the
15 NiTE joints (:data:`NITE_JOINTS`, NiTE's order) as x, y, z [m] and NiTE's position confidence
(0..1). NiTE's real-world coordinates
(millimetres, x to the sensor's right) are converted to metres with x negated, giving the Kinect
SDK's camera space used by every other Kinect reader. Untracked joints are written as ``nan``.

Canonical body
--------------
NiTE has no hip centre and a single foot point. The reader adds ``HIP_CENTER`` (mean of the hips)
and ``LEFT_TOE``/``RIGHT_TOE``, placed ``foot_length`` (default 0.2 m) ahead of the foot point,
horizontally, along the facing direction (normal to the hip line); the foot point serves as the
ankle.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from mdframework import DataFileError

from .formats import (
    FloatArray,
    Recording,
    _finish,
    check_frame_number,
    check_joint_values,
    parse_floats,
    read_text,
)

MAGIC = "# mdf-nite-skeleton 1"

#: NiTE2 joint order (NiteJointType 0..14).
NITE_JOINTS: tuple[str, ...] = (
    "HEAD",
    "NECK",
    "LEFT_SHOULDER",
    "RIGHT_SHOULDER",
    "LEFT_ELBOW",
    "RIGHT_ELBOW",
    "LEFT_HAND",
    "RIGHT_HAND",
    "TORSO",
    "LEFT_HIP",
    "RIGHT_HIP",
    "LEFT_KNEE",
    "RIGHT_KNEE",
    "LEFT_FOOT",
    "RIGHT_FOOT",
)

#: Joints of a NiTE recording after reading (with the derived ones).
NITE_READ_JOINTS: tuple[str, ...] = (*NITE_JOINTS, "HIP_CENTER", "LEFT_TOE", "RIGHT_TOE")

NITE_CANONICAL: dict[str, str] = {
    "base": "HIP_CENTER",
    "neck": "NECK",
    "head": "HEAD",
    "l_shoulder": "LEFT_SHOULDER",
    "r_shoulder": "RIGHT_SHOULDER",
    "l_elbow": "LEFT_ELBOW",
    "r_elbow": "RIGHT_ELBOW",
    "l_hand": "LEFT_HAND",
    "r_hand": "RIGHT_HAND",
    "l_hip": "LEFT_HIP",
    "r_hip": "RIGHT_HIP",
    "l_knee": "LEFT_KNEE",
    "r_knee": "RIGHT_KNEE",
    "l_ankle": "LEFT_FOOT",
    "r_ankle": "RIGHT_FOOT",
    "l_toe": "LEFT_TOE",
    "r_toe": "RIGHT_TOE",
}

COLUMNS: tuple[str, ...] = (
    "time_s",
    "frame",
    "user",
    *(f"{j}_{c}" for j in NITE_JOINTS for c in ("x", "y", "z", "c")),
)


def nite_frames_to_arrays(
    frames: Iterable[tuple[int, int, Any]], user_id: int | None = None
) -> tuple[FloatArray, FloatArray, FloatArray, np.ndarray, int | None]:
    """Convert NiTE user-tracker output to arrays.

    Parameters
    ----------
    frames : iterable of (timestamp_us, frame_index, users)
        ``users``: the ``NiteUserData`` structures of one ``UserTrackerFrame`` (``.users`` of the
        binding, or ``pUser[i]``): each has ``id``, ``skeleton.state`` and ``skeleton.joints``
        (15 ``NiteSkeletonJoint`` with ``position`` [mm] and ``positionConfidence``).
    user_id : int, optional
        The user to keep; default: the first user whose skeleton is tracked.

    Returns
    -------
    time_s (n,) [s] from the first frame; positions (n, 15, 3) [m] Kinect SDK axes (NaN where the
    user's skeleton is not tracked); confidence (n, 15); frame indices (n,); the user id kept.
    """
    ts: list[float] = []
    idx: list[int] = []
    pos: list[FloatArray] = []
    conf: list[FloatArray] = []
    for stamp, index, users in frames:
        p = np.full((15, 3), np.nan)
        c = np.zeros(15)
        for u in users:
            tracked = int(u.skeleton.state) == 2  # NITE_SKELETON_TRACKED
            if user_id is None and tracked:
                user_id = int(u.id)
            if user_id is not None and int(u.id) == user_id and tracked:
                for j in range(15):
                    jt = u.skeleton.joints[j]
                    p[j] = (-jt.position.x / 1000.0, jt.position.y / 1000.0, jt.position.z / 1000.0)
                    c[j] = float(jt.positionConfidence)
        ts.append(float(stamp) * 1e-6)
        idx.append(int(index))
        pos.append(p)
        conf.append(c)
    t = np.asarray(ts)
    t = t - t[0] if t.size else t
    return (
        t,
        np.asarray(pos).reshape(-1, 15, 3),
        np.asarray(conf).reshape(-1, 15),
        np.asarray(idx, dtype=np.int64),
        user_id,
    )


def write_nite(
    out: TextIO,
    time: FloatArray,
    frames: Sequence[int],
    user: int,
    positions: FloatArray,
    confidence: FloatArray,
    info: Mapping[str, str],
) -> None:
    """Write a NiTE recording (see the module docstring); ``positions`` (n, 15, 3) [m]."""
    out.write(MAGIC + "\n")
    for k, v in info.items():
        out.write(f"# {k}: {' '.join(str(v).split())}\n")
    out.write(" ".join(COLUMNS) + "\n")
    for k in range(time.shape[0]):
        vals = np.concatenate([positions[k], confidence[k][:, None]], axis=1).ravel()
        row = " ".join("nan" if not np.isfinite(v) else f"{v:.6f}" for v in vals)
        out.write(f"{time[k]:.6f} {int(frames[k])} {user} {row}\n")


def _check_row(path: Path, row: FloatArray, line: int) -> None:
    """One frame line: frame index and user id whole numbers, joints within the sensor limit
    (NaN: untracked), confidences in 0..1 (or NaN); time stamps are checked with the
    recording."""
    check_frame_number(path, row[1], line)
    check_frame_number(path, row[2], line, "user id")
    joints = row[3:].reshape(15, 4)
    check_joint_values(path, joints[:, :3].ravel(), line, nan=True)
    conf = joints[:, 3]
    if np.any((conf < 0) | (conf > 1)):
        bad = float(conf[(conf < 0) | (conf > 1)][0])
        raise DataFileError(path, f"confidence {bad!r} is outside 0..1", line)


def read_nite(path: Path, foot_length: float = 0.2, min_confidence: float = 0.5) -> Recording:
    """Read a NiTE recording written by ``mdf capture`` (see the module docstring)."""
    lines = read_text(path)
    if lines[0].strip() != MAGIC:
        raise DataFileError(
            path, f"not a NiTE skeleton recording: the first line is not {MAGIC!r}", 1
        )
    info: dict[str, str] = {}
    rows: list[np.ndarray] = []
    seen_columns = False
    for i, line in enumerate(lines[1:], start=2):
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            key, _, value = s[1:].partition(":")
            info[key.strip()] = value.strip()
            continue
        if not seen_columns:
            if tuple(s.split()) != COLUMNS:
                raise DataFileError(path, "the column line does not name the 63 NiTE columns", i)
            seen_columns = True
            continue
        f = s.split()
        if len(f) != len(COLUMNS):
            raise DataFileError(
                path,
                f"{len(f)} fields; a NiTE frame holds {len(COLUMNS)} (time, frame, user, "
                "15 joints x (x, y, z, c))",
                i,
            )
        rows.append(parse_floats(path, f, i))
        _check_row(path, rows[-1], i)
        if rows[-1][2] != rows[0][2]:
            raise DataFileError(
                path,
                f"user id {rows[-1][2]:g} differs from the first frame's {rows[0][2]:g}: a NiTE "
                "recording holds one person (write each user to a file of their own)",
                i,
            )
    if not rows:
        raise DataFileError(path, "no frame")
    a = np.asarray(rows)
    t = a[:, 0]
    raw = a[:, 3:].reshape(-1, 15, 4)
    pos = raw[:, :, :3]
    conf = raw[:, :, 3]
    valid = np.all(np.isfinite(pos), axis=2) & (conf >= min_confidence)
    hip_c = 0.5 * (pos[:, 9] + pos[:, 10])
    across = pos[:, 9] - pos[:, 10]  # right hip -> left hip
    up = np.array([0.0, 1.0, 0.0])
    fwd = np.cross(across, up)  # Kinect axes: facing direction for a person's left at +x
    fwd[:, 1] = 0.0
    norm = np.linalg.norm(fwd, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        fwd = fwd / norm
    toes = [pos[:, 13] + foot_length * fwd, pos[:, 14] + foot_length * fwd]
    all_pos = np.concatenate([pos, hip_c[:, None], toes[0][:, None], toes[1][:, None]], axis=1)
    v_hip = valid[:, 9] & valid[:, 10]
    all_valid = np.concatenate(
        [valid, v_hip[:, None], (valid[:, 13] & v_hip)[:, None], (valid[:, 14] & v_hip)[:, None]],
        axis=1,
    )
    meta: dict[str, Any] = {
        "format": "nite",
        "time_from": "time stamps in the file",
        "header": info,
        "derived_joints": "HIP_CENTER = mean of hips; *_TOE = foot + foot_length ahead",
        "foot_length_m": foot_length,
        "min_confidence": min_confidence,
        "user": int(a[0, 2]),
    }
    return _finish(
        path,
        NITE_READ_JOINTS,
        t,
        all_pos,
        a[:, 1].astype(np.int64),
        all_valid,
        NITE_CANONICAL,
        meta,
    )
