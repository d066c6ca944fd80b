"""BVH reader and forward kinematics (numpy, vectorised over frames).

The reader follows the Biovision layout::

    HIERARCHY
    ROOT Hips
    {
        OFFSET x y z
        CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
        JOINT ... { ... }
        End Site { OFFSET x y z }
    }
    MOTION
    Frames: n
    Frame Time: dt
    <one line of channel values per frame>

The hierarchy may be laid out freely (it is read as a stream of tokens); the motion section must
hold one frame per line. CRLF, LF and mixed line endings are accepted. Every problem raises
:class:`mdframework.DataFileError` with the file and the 1-based line number.

Kinematics: a joint's local rotation is the product of its rotation channels in the order the file
lists them (intrinsic rotations: ``Zrotation Yrotation Xrotation`` gives ``Rz @ Ry @ Rx``). Its
local translation is its ``OFFSET``, with any position channel replacing the matching offset
component (the usual reading of root channels). World rotation ``W = W_parent @ R_local`` and
world position ``p = p_parent + W_parent @ t_local``. End sites are joints without channels.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from mdframework import DataFileError, limits

from .kinematics import intrinsic_rotation

FloatArray = NDArray[np.float64]

_CHANNELS = {
    "xposition": "Xposition",
    "yposition": "Yposition",
    "zposition": "Zposition",
    "xrotation": "Xrotation",
    "yrotation": "Yrotation",
    "zrotation": "Zrotation",
}


@dataclass(frozen=True)
class BvhJoint:
    """One joint of a BVH hierarchy (end sites included, with no channels).

    ``offset`` (3,) float64 is in file units and axes; ``parent`` is the index of the parent joint
    in :attr:`BvhData.joints` (-1 for the root); ``channels`` are the channel names as listed;
    ``first_channel`` is the column of the first one in :attr:`BvhData.values`.
    """

    name: str
    parent: int
    offset: FloatArray
    channels: tuple[str, ...]
    first_channel: int
    end_site: bool
    line: int


@dataclass(frozen=True)
class BvhData:
    """A parsed BVH file.

    ``values`` has shape (n_frames, n_channels), float64: every frame of the file (frame 0
    included), channel values in file units and degrees. ``frame_time`` [s] is the header's
    ``Frame Time``.
    """

    path: Path
    joints: tuple[BvhJoint, ...]
    values: FloatArray
    frame_time: float

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Names of all joints, end sites included, in file order."""
        return tuple(j.name for j in self.joints)

    @property
    def n_frames(self) -> int:
        """Number of frames in the file."""
        return int(self.values.shape[0])


def read_lines(path: Path, what: str = "a motion-capture text file") -> list[str]:
    """The lines of a text file without their line ends (LF, CRLF, CR or mixed) and without a
    UTF-8 byte-order mark.

    Raises :class:`DataFileError` if the file cannot be read or is longer than
    ``limits.MAX_MOTION_TEXT_BYTES`` (``what`` names what it should be: ``"a BVH file"``).
    """
    limits.check_file_size(path, what, limits.MAX_MOTION_TEXT_BYTES)
    raw = limits.read_file_bytes(path)
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = raw.removeprefix(b"\xef\xbb\xbf").decode("latin-1")
    return text.replace("\r\n", "\n").replace("\r", "\n").split("\n")


class _Tokens:
    """Token stream over the hierarchy lines, remembering each token's line number."""

    def __init__(self, path: Path, lines: list[str]) -> None:
        self.path = path
        self.lines = lines
        self._items: Iterator[tuple[str, int]] = self._gen()
        self._peeked: tuple[str, int] | None = None
        self.last_line = 1

    def _gen(self) -> Iterator[tuple[str, int]]:
        for i, line in enumerate(self.lines):
            for tok in line.split():
                yield tok, i + 1

    def peek(self) -> tuple[str, int] | None:
        if self._peeked is None:
            self._peeked = next(self._items, None)
        return self._peeked

    def next(self, what: str) -> tuple[str, int]:
        item = self.peek()
        if item is None:
            raise DataFileError(
                self.path, f"file ends inside the hierarchy; expected {what}", self.last_line
            )
        self._peeked = None
        self.last_line = item[1]
        return item

    def expect(self, word: str) -> int:
        tok, line = self.next(repr(word))
        if tok != word:
            raise DataFileError(self.path, f"expected {word!r}, found {tok!r}", line)
        return line

    def number(self, what: str) -> float:
        tok, line = self.next(what)
        try:
            value = float(tok)
        except ValueError:
            raise DataFileError(self.path, f"bad number {tok!r} in {what}", line) from None
        if not np.isfinite(value):
            raise DataFileError(self.path, f"non-finite number {tok!r} in {what}", line)
        return value


def _parse_joint(
    tok: _Tokens, name: str, line: int, parent: int, joints: list[BvhJoint], n_channels: int
) -> int:
    """Parse one joint block after its name; append it and its children. Returns channel count."""
    path = tok.path
    tok.expect("{")
    key, kline = tok.next("OFFSET")
    if key != "OFFSET":
        raise DataFileError(
            path, f"expected OFFSET after {{ of joint {name!r}, found {key!r}", kline
        )
    offset = np.array([tok.number(f"the OFFSET of {name!r}") for _ in range(3)])
    key, kline = tok.next("CHANNELS")
    if key != "CHANNELS":
        raise DataFileError(path, f"expected CHANNELS for joint {name!r}, found {key!r}", kline)
    count_tok, cline = tok.next("the channel count")
    if not count_tok.isdigit():
        raise DataFileError(path, f"bad channel count {count_tok!r} for joint {name!r}", cline)
    channels: list[str] = []
    for _ in range(int(count_tok)):
        ch, chline = tok.next(f"a channel name of joint {name!r}")
        canon = _CHANNELS.get(ch.lower())
        if canon is None:
            raise DataFileError(path, f"unknown channel {ch!r} of joint {name!r}", chline)
        if canon in channels:
            raise DataFileError(path, f"channel {ch!r} listed twice for joint {name!r}", chline)
        channels.append(canon)
    index = len(joints)
    joints.append(BvhJoint(name, parent, offset, tuple(channels), n_channels, False, line))
    n_channels += len(channels)
    while True:
        key, kline = tok.next(f"JOINT, End Site or }} closing joint {name!r}")
        if key == "}":
            return n_channels
        if key == "JOINT":
            child, cline = tok.next("a joint name")
            n_channels = _parse_joint(tok, child, cline, index, joints, n_channels)
        elif key == "End":
            tok.expect("Site")
            tok.expect("{")
            key2, k2line = tok.next("OFFSET")
            if key2 != "OFFSET":
                raise DataFileError(path, f"expected OFFSET in the End Site of {name!r}", k2line)
            end_off = np.array([tok.number(f"the End Site OFFSET of {name!r}") for _ in range(3)])
            tok.expect("}")
            joints.append(BvhJoint(f"{name}_end", index, end_off, (), n_channels, True, kline))
        else:
            raise DataFileError(
                path,
                f"unknown keyword {key!r} in joint {name!r} (expected JOINT, End Site or }})",
                kline,
            )


def read_bvh(path: str | Path) -> BvhData:
    """Read a BVH file.

    Parameters
    ----------
    path : str or Path
        The ``.bvh`` file.

    Returns
    -------
    BvhData
        Hierarchy (joints and end sites, end sites named ``<joint>_end``) and all frames' channel
        values, shape (n_frames, n_channels), float64, file units and degrees.

    Raises
    ------
    mdframework.DataFileError
        For any malformed content (unknown keyword, bad number, wrong number of values in a frame,
        truncated file, zero frames), naming the file and the 1-based line.
    """
    p = Path(path)
    lines = read_lines(p, "a BVH file")
    # The hierarchy ends at the line starting with MOTION.
    motion_at = next((i for i, ln in enumerate(lines) if ln.split()[:1] == ["MOTION"]), None)
    head = lines if motion_at is None else lines[:motion_at]
    tok = _Tokens(p, head)
    first = tok.peek()
    if first is None:
        raise DataFileError(p, "empty file (expected HIERARCHY)", 1)
    tok.expect("HIERARCHY")
    key, kline = tok.next("ROOT")
    if key != "ROOT":
        raise DataFileError(p, f"expected ROOT after HIERARCHY, found {key!r}", kline)
    root_name, rline = tok.next("the root's name")
    joints: list[BvhJoint] = []
    n_channels = _parse_joint(tok, root_name, rline, -1, joints, 0)
    extra = tok.peek()
    if extra is not None:
        raise DataFileError(p, f"unexpected {extra[0]!r} after the hierarchy", extra[1])
    if motion_at is None:
        raise DataFileError(p, "file ends after the hierarchy; no MOTION section", len(head))
    names = [j.name for j in joints]
    for j in joints:
        if names.count(j.name) > 1:
            raise DataFileError(p, f"joint name {j.name!r} is used twice", j.line)

    # MOTION header: "Frames: n" and "Frame Time: dt" on the next non-blank lines.
    i = motion_at + 1
    header: list[tuple[list[str], int]] = []
    while len(header) < 2:
        while i < len(lines) and not lines[i].strip():
            i += 1
        if i >= len(lines):
            what = "Frames:" if not header else "Frame Time:"
            raise DataFileError(p, f"file ends before the {what} line", len(lines))
        header.append((lines[i].split(), i + 1))
        i += 1
    (ftoks, fline), (ttoks, tline) = header
    if len(ftoks) != 2 or ftoks[0] != "Frames:":
        raise DataFileError(p, f"expected 'Frames: <count>', found {' '.join(ftoks)!r}", fline)
    if not re.fullmatch(r"\d+", ftoks[1]):
        raise DataFileError(p, f"bad frame count {ftoks[1]!r}", fline)
    n_frames = int(ftoks[1])
    if n_frames == 0:
        raise DataFileError(p, "the file holds zero frames (Frames: 0)", fline)
    if len(ttoks) != 3 or ttoks[:2] != ["Frame", "Time:"]:
        raise DataFileError(
            p, f"expected 'Frame Time: <seconds>', found {' '.join(ttoks)!r}", tline
        )
    try:
        frame_time = float(ttoks[2])
    except ValueError:
        raise DataFileError(p, f"bad frame time {ttoks[2]!r}", tline) from None
    if not (np.isfinite(frame_time) and frame_time > 0):
        raise DataFileError(p, f"frame time must be positive, got {ttoks[2]!r}", tline)

    _check_frame_time(p, frame_time, tline)
    values = np.empty((_frames_to_allocate(p, n_frames, lines, i, fline), n_channels))
    k = 0
    last_line = tline
    for li in range(i, len(lines)):
        parts = lines[li].split()
        if not parts:
            continue
        if k >= n_frames:
            raise DataFileError(
                p,
                f"more frame lines than the {n_frames} that 'Frames:' (line {fline}) announces",
                li + 1,
            )
        if len(parts) != n_channels:
            raise DataFileError(
                p,
                f"frame {k} has {len(parts)} values, expected {n_channels} (one per channel)",
                li + 1,
            )
        try:
            row = [float(v) for v in parts]
        except ValueError:
            bad = next(v for v in parts if not _is_float(v))
            raise DataFileError(p, f"bad number {bad!r} in frame {k}", li + 1) from None
        values[k] = row
        if not np.all(np.isfinite(values[k])):
            raise DataFileError(p, f"non-finite value in frame {k}", li + 1)
        k += 1
        last_line = li + 1
    if k < n_frames:
        raise DataFileError(
            p,
            f"file truncated: {k} frames found, 'Frames:' (line {fline}) announces {n_frames}",
            last_line,
        )
    _check_values(p, joints, values, lines, i)
    return BvhData(p, tuple(joints), values, frame_time)


# ----------------------------------------------------------------- checks before allocating


def _frames_to_allocate(p: Path, n_frames: int, lines: list[str], first: int, fline: int) -> int:
    """Rows to allocate for the frames: the declared count must be within
    ``limits.MAX_FRAMES``, and no more rows than the file has data lines are allocated (a
    truncated file is then reported by the reader's frame loop)."""
    limits.check_declared_count(p, fline, "'Frames:'", n_frames)
    available = sum(1 for ln in lines[first:] if ln.strip())
    return min(n_frames, available)


def _check_frame_time(p: Path, frame_time: float, tline: int) -> None:
    """The header's frame time within 1/MAX_FRAME_RATE_HZ .. 1/MIN_FRAME_RATE_HZ."""
    lo, hi = 1.0 / limits.MAX_FRAME_RATE_HZ, 1.0 / limits.MIN_FRAME_RATE_HZ
    if not lo <= frame_time <= hi:
        raise DataFileError(p, f"frame time {frame_time:g} s is outside {lo:g} .. {hi:g} s", tline)


def _check_values(
    p: Path, joints: list[BvhJoint], values: FloatArray, lines: list[str], first: int
) -> None:
    """Offsets and position channels within +-``limits.MAX_FILE_COORDINATE`` file units,
    rotation channels within +-``limits.MAX_ANGLE_DEG``; errors name the line."""
    for j in joints:
        limits.check_values(
            p, j.offset[None], limits.MAX_FILE_COORDINATE, f"OFFSET of {j.name!r}", [j.line]
        )
    data_lines = [k + 1 for k in range(first, len(lines)) if lines[k].strip()]
    for j in joints:
        for k, ch in enumerate(j.channels):
            limit = limits.MAX_FILE_COORDINATE if ch.endswith("position") else limits.MAX_ANGLE_DEG
            limits.check_values(
                p, values[:, j.first_channel + k], limit, f"{ch} of {j.name!r}", data_lines
            )


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def bvh_forward_kinematics(bvh: BvhData, frames: slice | None = None) -> FloatArray:
    """World positions of every joint and end site.

    Parameters
    ----------
    bvh : BvhData
        Parsed file.
    frames : slice, optional
        Frames to compute (default: all).

    Returns
    -------
    ndarray, shape (n_frames, n_joints, 3), float64
        Positions in file units and file axes (CMU: y up), joints in :attr:`BvhData.joints`
        order.
    """
    values = bvh.values if frames is None else bvh.values[frames]
    n = values.shape[0]
    n_j = len(bvh.joints)
    world_rot = np.empty((n, n_j, 3, 3), dtype=np.float64)
    world_pos = np.empty((n, n_j, 3), dtype=np.float64)
    for idx, joint in enumerate(bvh.joints):
        trans = np.broadcast_to(joint.offset, (n, 3)).copy()
        rot_axes = ""
        rot_cols: list[int] = []
        for k, ch in enumerate(joint.channels):
            col = joint.first_channel + k
            if ch.endswith("position"):
                trans[:, "XYZ".index(ch[0])] = values[:, col]
            else:
                rot_axes += ch[0]
                rot_cols.append(col)
        local = intrinsic_rotation(rot_axes, values[:, rot_cols])
        if joint.parent < 0:
            world_rot[:, idx] = local
            world_pos[:, idx] = trans
        else:
            parent_rot = world_rot[:, joint.parent]
            world_rot[:, idx] = parent_rot @ local
            world_pos[:, idx] = world_pos[:, joint.parent] + np.einsum(
                "nij,nj->ni", parent_rot, trans
            )
    return world_pos
