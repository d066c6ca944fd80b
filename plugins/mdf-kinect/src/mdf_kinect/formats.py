"""Readers of Kinect skeleton recordings.

Every reader returns a :class:`Recording` in the Kinect camera frame as the file gives it
(metres; X toward the sensor's left, Y up, Z away from the sensor, as in the Kinect SDK), with time
stamps [s] from the data and per-joint validity. :func:`to_project_frame` turns it into the
project's z-up frame. Every error is a :class:`~mdframework.DataFileError` naming the file and the
line (or frame / record).

Formats
-------
``utkinect``
    UTKinect-Action3D ``joints_sXX_eYY.txt``: one frame per line, a frame number then
    20 joints x (x, y, z) in Kinect SDK v1 order; time = frame number / 60 (repeated frames
    are dropped, the first kept). The dataset says it was captured at 30 frames per second,
    that only frames with a tracked skeleton were kept, and that the final rate is about
    15 frames per second. The numbers in the files are all even and step by 2-10 (mostly 4):
    read as 30 per second they give about 8 kept frames per second and walks of 50 steps a
    minute; read as 60 per second (two numbers per 30 Hz frame) they give 16 kept frames per
    second and about 100 steps a minute, as the dataset's note and a normal walk require.
    ``actionLabel.txt`` gives each sequence's segments as ``action: first_frame last_frame``.
``msr-action3d``
    MSR Action3D ``aAA_sSS_eEE_skeleton3D.txt``: 20 lines of ``x y z c`` per frame in MSR's own
    joint order (:data:`MSR_JOINTS`); 15 frames per second. The 4th column is not a tracking
    confidence (it is 0 for the neck and hip centre in whole recordings whose positions are
    sound), so it is kept in the metadata but not used for validity.
``precog``
    PRECOG ``SeqN_M.csv``: a header naming the 20 joints, then per frame 20 ``x y z`` fields
    separated by ``;`` and an action id; 25 frames per second by default (the rate of the
    dataset's viewer; the capture rate is not stated).
``nite``
    The NiTE2 15-joint recordings written by ``mdf capture`` (:mod:`mdf_kinect.nitefile`).
``ntu``
    NTU RGB+D ``.skeleton`` (Kinect v2, 25 joints): frame count; per frame a body count and per
    body a line of 10 body values, a joint count and one line of 12 values per joint
    (x y z depthX depthY colorX colorY qw qx qy qz trackingState); 30 frames per second. One
    body is read (:func:`read_ntu`).
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from mdframework import DataFileError, limits
from mdframework.conditioning import sort_timestamps, untracked_mask

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: Kinect SDK v1 joint order (UTKinect, PRECOG).
KINECT_V1_JOINTS: tuple[str, ...] = (
    "HipCenter",
    "Spine",
    "ShoulderCenter",
    "Head",
    "ShoulderLeft",
    "ElbowLeft",
    "WristLeft",
    "HandLeft",
    "ShoulderRight",
    "ElbowRight",
    "WristRight",
    "HandRight",
    "HipLeft",
    "KneeLeft",
    "AnkleLeft",
    "FootLeft",
    "HipRight",
    "KneeRight",
    "AnkleRight",
    "FootRight",
)

#: MSR Action3D's joint order (its own, not the SDK's), named with the SDK names.
MSR_JOINTS: tuple[str, ...] = (
    "ShoulderLeft",
    "ShoulderRight",
    "ShoulderCenter",
    "Spine",
    "HipLeft",
    "HipRight",
    "HipCenter",
    "ElbowLeft",
    "ElbowRight",
    "WristLeft",
    "WristRight",
    "HandLeft",
    "HandRight",
    "KneeLeft",
    "KneeRight",
    "AnkleLeft",
    "AnkleRight",
    "FootLeft",
    "FootRight",
    "Head",
)

#: Kinect v2 joint order (NTU RGB+D): the v1 order with the spine renamed (base, mid, neck)
#: and five joints appended.
KINECT_V2_JOINTS: tuple[str, ...] = (
    "SpineBase",
    "SpineMid",
    "Neck",
    *KINECT_V1_JOINTS[3:],
    "SpineShoulder",
    "HandTipLeft",
    "ThumbLeft",
    "HandTipRight",
    "ThumbRight",
)


def _limb_map(hip_centre: str, neck: str) -> dict[str, str]:
    m = {"base": hip_centre, "neck": neck, "head": "Head"}
    for side, name in (("l", "Left"), ("r", "Right")):
        m.update(
            {
                f"{side}_shoulder": f"Shoulder{name}",
                f"{side}_elbow": f"Elbow{name}",
                f"{side}_hand": f"Hand{name}",
                f"{side}_hip": f"Hip{name}",
                f"{side}_knee": f"Knee{name}",
                f"{side}_ankle": f"Ankle{name}",
                f"{side}_toe": f"Foot{name}",
            }
        )
    return m


#: Canonical joint -> Kinect v1 joint (Spine and both wrists are not used).
KINECT_V1_CANONICAL: dict[str, str] = _limb_map("HipCenter", "ShoulderCenter")
#: Canonical joint -> Kinect v2 joint (SpineShoulder is v1's ShoulderCenter).
KINECT_V2_CANONICAL: dict[str, str] = _limb_map("SpineBase", "SpineShoulder")

#: Rates [Hz] where the files hold no time stamps. UTKinect: frame numbers per second (two
#: per 30 Hz Kinect frame; see the module docstring).
UTKINECT_RATE_HZ = 60.0
MSR_RATE_HZ = 15.0
PRECOG_RATE_HZ = 25.0
NTU_RATE_HZ = 30.0

#: PRECOG action ids.
PRECOG_ACTIONS: dict[int, str] = {
    0: "none",
    1: "right punch",
    2: "left punch",
    3: "front-right kick",
    4: "front-left kick",
    5: "side-right kick",
    6: "side-left kick",
    7: "back fist",
    8: "elbow strike",
}


@dataclass
class Recording:
    """A skeleton recording in the Kinect camera frame.

    ``time`` (n,) [s] strictly increasing; ``positions`` (n, n_joints, 3) [m], Kinect axes;
    ``valid`` (n, n_joints) bool; ``frame_numbers`` (n,) int as in the file (or the frame index);
    ``segments``: label -> (first, last) frame number; ``metadata``: format details.
    """

    joint_names: tuple[str, ...]
    time: FloatArray
    positions: FloatArray
    valid: BoolArray
    frame_numbers: NDArray[np.int64]
    canonical_map: dict[str, str]
    metadata: dict[str, Any] = field(default_factory=dict)
    segments: dict[str, tuple[int, int]] = field(default_factory=dict)


# --------------------------------------------------------------------------- helpers


def read_text(path: Path) -> list[str]:
    """The file's lines; clear errors for unreadable, empty or binary files."""
    text = limits.read_text_file(path, "a text skeleton file", limits.MAX_MOTION_TEXT_BYTES)
    if not text.strip():
        raise DataFileError(path, "the file is empty")
    return text.splitlines()


def parse_floats(path: Path, fields: Sequence[str], line: int, what: str = "field") -> FloatArray:
    """Fields -> float64; a non-numeric one is an error naming the line and field."""
    out = np.empty(len(fields), dtype=np.float64)
    for k, f in enumerate(fields):
        try:
            out[k] = float(f)
        except ValueError:
            raise DataFileError(path, f"{what} {k + 1} is not a number: {f[:40]!r}", line) from None
    return out


def check_joint_values(
    path: Path, values: FloatArray, line: int, what: str = "joint coordinate", nan: bool = False
) -> None:
    """Joint coordinates [m] of one line within +-``limits.MAX_SENSOR_COORDINATE_M`` (``nan``:
    NaN marks an untracked joint)."""
    limits.check_values(
        path, values[None], limits.MAX_SENSOR_COORDINATE_M, what, [line], " m", allow_nan=nan
    )


def check_frame_number(path: Path, value: float, line: int, what: str = "frame number") -> None:
    """A frame number (or id) that is a whole number within 0 .. ``limits.MAX_FRAME_NUMBER``."""
    if not (0 <= value <= limits.MAX_FRAME_NUMBER and value == int(value)):
        raise DataFileError(
            path,
            f"{what} {float(value)!r} is not a whole number in 0 .. {limits.MAX_FRAME_NUMBER:,}",
            line,
        )


def _finish(
    path: Path,
    names: tuple[str, ...],
    time: FloatArray,
    pos: FloatArray,
    frames: NDArray[np.int64],
    valid: BoolArray | None,
    canonical: dict[str, str],
    meta: dict[str, Any],
) -> Recording:
    limits.check_time_stamps(path, time)
    order = np.argsort(time, kind="stable")
    t, p, ok, rep = sort_timestamps(time, pos, valid)
    keep = order[np.concatenate(([True], np.diff(time[order]) > 0))]
    ok = untracked_mask(p, ok)
    # frames before the tracker found the person and after it lost them for good hold no
    # body (a capture records from the sensor's first frame): trimmed
    tracked = np.flatnonzero(ok.any(axis=1))
    if tracked.size == 0:
        raise DataFileError(path, f"no joint is tracked in any of the {t.shape[0]} frames")
    span = slice(int(tracked[0]), int(tracked[-1]) + 1)
    meta.update(
        frames_in_file=int(time.shape[0]),
        frames_out_of_order=rep["out_of_order"],
        duplicate_frames_dropped=rep["duplicates_dropped"],
        untracked_frames_trimmed=int(t.shape[0] - (span.stop - span.start)),
        untracked_frames_leading=span.start,
        first_tracked_s=float(t[span.start] - t[0]),
    )
    return Recording(names, t[span], p[span], ok[span], frames[keep][span], dict(canonical), meta)


# --------------------------------------------------------------------------- UTKinect


def read_utkinect(path: Path, rate_hz: float = UTKINECT_RATE_HZ) -> Recording:
    """Read a UTKinect-Action3D joints file (see the module docstring)."""
    lines = read_text(path)
    rows: list[FloatArray] = []
    frames: list[int] = []
    line_numbers: list[int] = []
    for i, line in enumerate(lines, start=1):
        fields = line.split()
        if not fields:
            continue
        if len(fields) != 61:
            raise DataFileError(
                path,
                f"{len(fields)} fields; a UTKinect frame is a frame number and 20 joints x "
                "(x, y, z) = 61 fields",
                i,
            )
        vals = parse_floats(path, fields, i)
        check_frame_number(path, vals[0], i)
        check_joint_values(path, vals[1:], i)
        frames.append(int(vals[0]))
        rows.append(vals[1:])
        line_numbers.append(i)
    fr = np.asarray(frames, dtype=np.int64)
    # the time a frame number stands for, checked per line (a frame number passes its own
    # check up to limits.MAX_FRAME_NUMBER, far beyond a day at this rate)
    limits.check_values(path, fr / rate_hz, limits.MAX_DURATION_S, "time stamp", line_numbers, " s")
    pos = np.asarray(rows, dtype=np.float64).reshape(-1, 20, 3)
    meta = {
        "format": "utkinect",
        "frame_rate_hz": rate_hz,
        "time_from": f"frame numbers / {rate_hz:g} (frame numbers per second)",
    }
    return _finish(path, KINECT_V1_JOINTS, fr / rate_hz, pos, fr, None, KINECT_V1_CANONICAL, meta)


def read_utkinect_labels(path: Path) -> dict[str, dict[str, tuple[int, int]]]:
    """``actionLabel.txt``: sequence -> action -> (first, last) frame number.

    Each frame number is a whole number within 0 .. ``limits.MAX_FRAME_NUMBER``, the first at
    most the last; ``NaN NaN`` marks an action missing from the sequence. A sequence, or an
    action within one, given twice is an error naming the line (either would silently replace
    the other).
    """
    out: dict[str, dict[str, tuple[int, int]]] = {}
    seen: dict[str, int] = {}  # sequence, or sequence/action -> its line
    current: dict[str, tuple[int, int]] | None = None
    sequence = ""
    for i, line in enumerate(read_text(path), start=1):
        s = line.strip()
        if not s:
            continue
        m = re.fullmatch(r"(\w+)\s*:\s*(\S+)\s+(\S+)", s)
        key = s if m is None else f"{sequence}/{m.group(1)}"
        if key in seen:
            what = f"sequence {s!r}" if m is None else f"action {m.group(1)!r} of {sequence}"
            raise DataFileError(path, f"{what} given twice (first on line {seen[key]})", i)
        if m is None:
            if re.fullmatch(r"s\d+_e\d+", s):
                current, sequence, seen[key] = out.setdefault(s, {}), s, i
                continue
            raise DataFileError(path, f"expected 'sXX_eYY' or 'action: first last': {s!r}", i)
        if current is None:
            raise DataFileError(path, "an action line before any sequence name", i)
        seen[key] = i
        a, b = parse_floats(path, [m.group(2), m.group(3)], i, "frame number")
        if np.isnan(a) and np.isnan(b):  # the action is not in the sequence
            continue
        check_frame_number(path, a, i)
        check_frame_number(path, b, i)
        if a > b:
            raise DataFileError(
                path, f"action {m.group(1)!r} ends at frame {b:g}, before its first {a:g}", i
            )
        current[m.group(1)] = (int(a), int(b))
    return out


# --------------------------------------------------------------------------- MSR Action3D


def read_msr(path: Path, rate_hz: float = MSR_RATE_HZ) -> Recording:
    """Read an MSR Action3D ``*_skeleton3D.txt`` file (see the module docstring)."""
    lines = read_text(path)
    rows: list[FloatArray] = []
    last = 0
    for i, line in enumerate(lines, start=1):
        fields = line.split()
        if not fields:
            continue
        if len(fields) != 4:
            raise DataFileError(
                path, f"{len(fields)} fields; MSR Action3D joint lines hold x y z c", i
            )
        rows.append(parse_floats(path, fields, i))
        check_joint_values(path, rows[-1], i, "joint value")
        last = i
    if len(rows) % 20:
        raise DataFileError(
            path,
            f"{len(rows)} joint lines is not a whole number of 20-joint frames: the file ends "
            f"inside frame {len(rows) // 20 + 1} ({len(rows) % 20} of 20 joints)",
            last,
        )
    a = np.asarray(rows, dtype=np.float64).reshape(-1, 20, 4)
    n = a.shape[0]
    fr = np.arange(n, dtype=np.int64)
    meta = {
        "format": "msr-action3d",
        "frame_rate_hz": rate_hz,
        "time_from": "frame index / rate (MSR Action3D paper: 15 frames per second)",
        "column4_mean": [float(x) for x in a[:, :, 3].mean(axis=0)],
    }
    return _finish(path, MSR_JOINTS, fr / rate_hz, a[:, :, :3], fr, None, KINECT_V1_CANONICAL, meta)


# --------------------------------------------------------------------------- PRECOG


def read_precog(path: Path, rate_hz: float = PRECOG_RATE_HZ) -> Recording:
    """Read a PRECOG ``.csv`` file (see the module docstring)."""
    lines = read_text(path)
    header = [h.strip() for h in lines[0].split(";")]
    if header[:20] != list(KINECT_V1_JOINTS):
        raise DataFileError(
            path, "the header must name the 20 Kinect v1 joints separated by ';'", 1
        )
    rows: list[FloatArray] = []
    actions: list[int] = []
    for i, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        parts = line.split(";")
        if len(parts) != 21:
            raise DataFileError(
                path,
                f"{len(parts)} ';'-separated fields; a PRECOG row holds 20 joints and "
                "an action id = 21",
                i,
            )
        xyz: list[float] = []
        for k, p in enumerate(parts[:20]):
            f = p.split()
            if len(f) != 3:
                raise DataFileError(
                    path, f"joint {k + 1} ({KINECT_V1_JOINTS[k]}) has {len(f)} values, not 3", i
                )
            xyz.extend(parse_floats(path, f, i, f"joint {k + 1} value"))
        act = parts[20].strip()
        if not re.fullmatch(r"\d+", act):
            raise DataFileError(path, f"the action id {act[:40]!r} is not a whole number", i)
        rows.append(np.asarray(xyz))
        check_joint_values(path, rows[-1], i)
        check_frame_number(path, float(act), i, "action id")
        actions.append(int(act))
    if not rows:
        raise DataFileError(path, "a header but no frame")
    pos = np.asarray(rows).reshape(-1, 20, 3)
    fr = np.arange(pos.shape[0], dtype=np.int64)
    act_arr = np.asarray(actions)
    segments: dict[str, tuple[int, int]] = {}
    for a in np.unique(act_arr):
        if a == 0:
            continue
        idx = np.flatnonzero(act_arr == a)
        run_end = idx[0] + int(np.argmax(np.diff(np.append(idx, -1)) != 1))
        segments[PRECOG_ACTIONS.get(int(a), f"action {a}")] = (int(idx[0]), int(run_end))
    meta = {
        "format": "precog",
        "frame_rate_hz": rate_hz,
        "time_from": "row index / rate (assumed: the dataset's viewer plays at 25 fps)",
        "actions_present": sorted(segments),
    }
    rec = _finish(path, KINECT_V1_JOINTS, fr / rate_hz, pos, fr, None, KINECT_V1_CANONICAL, meta)
    rec.segments = segments
    return rec


# --------------------------------------------------------------------------- NTU RGB+D


def read_ntu(
    path: Path, rate_hz: float = NTU_RATE_HZ, min_tracking: int = 1, body: int | None = None
) -> Recording:
    """Read an NTU RGB+D ``.skeleton`` file (Kinect v2): one body, followed by its body id;
    frames without it are untracked. ``min_tracking``: joints whose trackingState is below it
    (0 not tracked, 1 inferred, 2 tracked) are untracked. ``body``: the body to read, numbered
    1, 2, ... in the order the file first shows them; default: the one in most frames (the
    first of those), with a warning naming every body when the file holds several (a second
    person, or one of the short false bodies the Kinect sometimes reports).

    Raises
    ------
    mdframework.DataFileError
        A malformed file (naming the line), or ``body`` beyond the bodies the file holds.
    """
    lines = read_text(path)
    pos_i = 0
    # non-blank lines from each line on: declared counts are checked against them before
    # anything is allocated
    left = [*np.cumsum([bool(ln.strip()) for ln in reversed(lines)])[::-1].tolist(), 0]

    def take(n_fields: int | None, what: str) -> tuple[list[str], int]:
        nonlocal pos_i
        while pos_i < len(lines) and not lines[pos_i].strip():
            pos_i += 1
        if pos_i >= len(lines):
            raise DataFileError(path, f"the file ends where {what} was expected", len(lines))
        f = lines[pos_i].split()
        pos_i += 1
        if n_fields is not None and len(f) != n_fields:
            raise DataFileError(
                path, f"{len(f)} fields where {what} ({n_fields} fields) was expected", pos_i
            )
        return f, pos_i

    def count(what: str, lines_per_item: int) -> int:
        f, ln = take(1, what)
        v = parse_floats(path, f, ln)[0]
        if not np.isfinite(v) or v != int(v) or v < 0:
            raise DataFileError(path, f"{what} {f[0]!r} is not a count", ln)
        limits.check_declared_count(path, ln, what, int(v), left[pos_i], lines_per_item)
        return int(v)

    n_frames = count("the frame count", 1)
    seen: dict[str, list[tuple[int, FloatArray]]] = {}  # body id -> (frame, its 25 x 12 values)
    for k in range(n_frames):
        n_bodies = count(f"the body count of frame {k + 1}", 27)
        for _ in range(n_bodies):
            info, _ln = take(10, f"a body line of frame {k + 1}")
            n_joints = count(f"the joint count of frame {k + 1}", 1)
            if n_joints != 25:
                raise DataFileError(path, f"{n_joints} joints; Kinect v2 bodies have 25", pos_i)
            vals = np.empty((25, 12))
            for j in range(25):
                f, ln = take(12, f"joint {j + 1} of frame {k + 1}")
                vals[j] = parse_floats(path, f, ln)
                check_joint_values(path, vals[j, :3], ln)
                limits.check_values(
                    path, vals[j, None, 3:], limits.MAX_FILE_COORDINATE, "joint value", [ln]
                )
            seen.setdefault(info[0], []).append((k, vals))
    rest = [ln for ln in lines[pos_i:] if ln.strip()]
    if rest:
        raise DataFileError(path, f"{len(rest)} line(s) after the last frame", pos_i + 1)
    ids = list(seen)
    listed = ", ".join(f"body {i + 1} (id {b}, {len(seen[b])} frames)" for i, b in enumerate(ids))
    if body is not None and body > len(ids):
        raise DataFileError(
            path, f"motion.body is {body}, but the file holds {len(ids)} bodies ({listed})"
        )
    index = (
        body - 1
        if body is not None
        else max(range(len(ids)), key=lambda i: len(seen[ids[i]]), default=0)
    )
    body_id = ids[index] if ids else None
    tie = sum(len(seen[b]) == len(seen[body_id]) for b in ids) > 1 if body_id else False
    if body is None and len(ids) > 1:
        warnings.warn(
            f"{path}: the file holds {len(ids)} bodies ({listed}); reading body {index + 1}, "
            f"the {'first ' if tie else ''}one in most frames: set motion.body to read another",
            stacklevel=2,
        )
    pos = np.full((n_frames, 25, 3), np.nan)
    state = np.zeros((n_frames, 25))
    for k, vals in seen.get(body_id, []) if body_id is not None else []:
        pos[k] = vals[:, :3]
        state[k] = vals[:, 11]
    fr = np.arange(n_frames, dtype=np.int64)
    valid = np.all(np.isfinite(pos), axis=2) & (state >= min_tracking)
    meta = {
        "format": "ntu",
        "frame_rate_hz": rate_hz,
        "body_id": body_id,
        "body": index + 1,
        "bodies": len(ids),
    }
    return _finish(path, KINECT_V2_JOINTS, fr / rate_hz, pos, fr, valid, KINECT_V2_CANONICAL, meta)


# --------------------------------------------------------------------------- frames


def to_project_frame(kinect: FloatArray) -> FloatArray:
    """Kinect camera axes (X sensor's left, Y up, Z away) -> project (x away, y left, z up).

    A cyclic permutation (Z, X, Y), so handedness is kept; (..., 3) [m] in and out."""
    return np.stack([kinect[..., 2], kinect[..., 0], kinect[..., 1]], axis=-1)
