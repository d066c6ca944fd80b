"""Reading C3D files: the header checked in Python first, then the file through ezc3d.

C3D (www.c3d.org) is a binary file of 512-byte blocks: a header block, a parameter section
(groups such as ``POINT``, ``ANALOG``, ``EVENT``, ``SUBJECTS``) and the frames. Header words
(16-bit, the processor's byte order): byte 0 the parameter section's first block, byte 1 the
key ``0x50``, word 2 the 3D points per frame, word 3 the analog samples per frame, words 4-5
the first and last frame, words 7-8 the scale factor (a float; negative: the frames hold
floats, else 16-bit integers), word 9 the first data block, words 11-12 the frame rate [Hz]
(a float). The parameter section's fourth byte names the processor: 84 Intel (little-endian
IEEE), 85 DEC (little-endian words, DEC floats), 86 MIPS/SGI (big-endian IEEE).

:func:`read_c3d_header` checks those before anything is allocated (the key, the processor,
the frame count against ``limits.MAX_FRAMES``, and that the declared frames fit in the file);
:func:`read_c3d` then reads the file through ezc3d and checks what it gives: the point units
(``POINT:UNITS``), the frame rate, finite coordinates within ``limits.MAX_FILE_COORDINATE``.
Points whose residual is negative (not seen by the cameras) come back as NaN.

Arrays: ``C3dMarkers.positions`` (n_frames, n_markers, 3) float64 in the file's unit
(``unit_m`` metres per unit), NaN where a marker is not seen.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from mdframework import DataFileError, limits

#: Metres per C3D ``POINT:UNITS`` value.
UNIT_M: dict[str, float] = {"mm": 1e-3, "cm": 1e-2, "dm": 0.1, "m": 1.0, "in": 0.0254}

PROCESSORS = {84: "Intel", 85: "DEC", 86: "MIPS"}


@dataclass(frozen=True)
class C3dHeader:
    """The header block's counts (``n_points`` 3D points and ``n_analog`` analog samples per
    frame, ``first_frame`` and ``last_frame``), the processor, and whether frames hold floats."""

    n_points: int
    n_analog: int
    first_frame: int
    last_frame: int
    data_block: int
    processor: str
    floats: bool

    @property
    def n_frames(self) -> int:
        """Frames declared by the header."""
        return self.last_frame - self.first_frame + 1


@dataclass(frozen=True)
class C3dMarkers:
    """What :func:`read_c3d` returns. ``positions`` (n_frames, n_markers, 3) float64 in the
    file's unit, NaN where a marker is not seen; ``labels`` the marker names (``POINT:LABELS``
    then ``LABELS2``, ``LABELS3``... for files of more than 255 points; every point of the
    file); ``rate_hz`` the header's frame rate; ``units`` ``POINT:UNITS`` and ``unit_m`` metres
    per unit; ``subject`` the first of ``SUBJECTS:NAMES`` (or None); ``events`` (label, context,
    time [s]) from the ``EVENT`` group; ``first_frame`` the header's; ``software``
    ``MANUFACTURER:SOFTWARE`` (or None)."""

    path: Path
    labels: tuple[str, ...]
    positions: NDArray[np.float64]
    rate_hz: float
    units: str
    unit_m: float
    first_frame: int
    subject: str | None = None
    software: str | None = None
    events: tuple[tuple[str, str, float], ...] = field(default=())

    @property
    def n_frames(self) -> int:
        """Frames read."""
        return int(self.positions.shape[0])


def read_c3d_header(path: Path) -> C3dHeader:
    """Check a C3D file's header block before anything is read or allocated.

    Raises
    ------
    mdframework.DataFileError
        Not a C3D file (too short, wrong key byte, unknown processor), a frame count beyond
        ``limits.MAX_FRAMES`` or last frame before the first, or declared frames that do not
        fit in the file (truncated).
    """
    limits.check_regular_file(path)
    try:
        size = path.stat().st_size
        with path.open("rb") as f:
            head = f.read(512)
            if len(head) == 512 and 1 <= head[0]:
                f.seek((head[0] - 1) * 512)
                param = f.read(255 * 512)  # the parameter section: at most 255 blocks
            else:
                param = b""
    except OSError as exc:
        raise DataFileError(path, f"cannot read: {exc.strerror or exc}") from None
    if len(head) < 512:
        raise DataFileError(path, f"{len(head)} bytes: too short for the 512-byte C3D header")
    if head[1] != 0x50:
        raise DataFileError(
            path, f"not a C3D file: header byte 2 is {head[1]:#04x}, not the C3D key 0x50"
        )
    if len(param) < 4 or param[3] not in PROCESSORS:
        found = f"{param[3]}" if len(param) == 4 else "missing"
        raise DataFileError(
            path,
            f"not a C3D file: the parameter section (block {head[0]}) names processor type "
            f"{found}, not 84 (Intel), 85 (DEC) or 86 (MIPS)",
        )
    processor = PROCESSORS[param[3]]
    order = ">" if processor == "MIPS" else "<"
    n_points, n_analog, first, last = struct.unpack_from(order + "4H", head, 2)
    (data_block,) = struct.unpack_from(order + "H", head, 16)
    # the scale factor's sign bit: IEEE little-endian byte 15, DEC byte 13, big-endian byte 12
    sign_byte = {"Intel": 15, "DEC": 13, "MIPS": 12}[processor]
    floats = bool(head[sign_byte] & 0x80)
    if last < first:
        raise DataFileError(path, f"header: last frame {last} is before first frame {first}")
    n_frames = last - first + 1
    limits.check_declared_count(path, 1, "header frame count", n_frames)
    per_frame = (4 * n_points + n_analog) * (4 if floats else 2)
    need = max(data_block - 1, 0) * 512 + n_frames * per_frame
    if data_block < 2 or need > size:
        raise DataFileError(
            path,
            f"header declares {n_frames} frames of {n_points} points and {n_analog} analog "
            f"samples from block {data_block} ({need:,} bytes), but the file holds {size:,} "
            "bytes: the file is truncated or its header is wrong",
        )
    check_parameter_section(path, param, head[0], data_block, order)
    return C3dHeader(n_points, n_analog, first, last, data_block, processor, floats)


#: C3D parameter types: byte count per value (-1: characters)
_PARAM_TYPES = {-1: 1, 1: 1, 2: 2, 4: 4}


def check_parameter_section(
    path: Path, section: bytes, block: int, data_block: int, order: str
) -> None:
    """Walk the parameter section of ``path`` (``section``: the bytes from its 512-byte block
    ``block``, as read, up to the first data block ``data_block``; ``order`` ``"<"`` or
    ``">"``) as the C3D User Guide lays it out, before ezc3d reads it: ezc3d trusts its sizes
    and offsets, and a damaged section can crash the process instead of raising.

    Each record: the name's length (a signed byte; 0 ends the section) and the group id (a
    signed byte: negative for a group, positive for a parameter of that group), the name, and an
    unsigned 16-bit offset from itself to the next record (0: the last record). A group then
    holds its description (a length byte, then the text); a parameter its type (-1
    characters, 1 byte, 2 integer, 4 float), its number of dimensions (at most 7), the
    dimensions, the values and its description. Every record must lie inside the section's
    blocks and end before the next begins, and names must be printable ASCII.

    Raises
    ------
    mdframework.DataFileError
        Naming the byte offset of the first record that breaks these rules.
    """
    start = (block - 1) * 512

    def bad(at: int, what: str) -> DataFileError:
        return DataFileError(
            path, f"parameter section: the record at byte {start + at} {what}: the file is damaged"
        )

    beyond = "starts beyond the parameter section, which ends at the data"
    if len(section) < 4:
        raise bad(0, beyond)
    end = min(len(section), (data_block - block) * 512)
    # the first record's block is 1 (bytes 0, 1: 1 and the key 0x50; Qualisys writes 0, 0,
    # which ezc3d reads as 1, 0x50)
    pos = 3 + (1 if section[:2] == b"\x00\x00" else section[0])
    while True:
        if pos + 2 > end:
            raise bad(pos, beyond)
        n_chars, group_id = struct.unpack_from("bb", section, pos)
        if n_chars == 0:
            break
        name = section[pos + 2 : pos + 2 + abs(n_chars)]
        at = pos + 2 + abs(n_chars)  # the offset field
        if at + 2 > end:
            raise bad(pos, "runs past the parameter section's end")
        if group_id in (0, -128) or not all(0x20 <= c < 0x7F for c in name):
            raise bad(pos, f"has group id {group_id} and name {bytes(name)!r}")
        (offset,) = struct.unpack_from(order + "H", section, at)  # unsigned, as ezc3d reads it
        limit = end if offset == 0 else at + offset
        if offset != 0 and not at + 2 <= limit <= end:
            raise bad(pos, f"points to its next record at {start + limit}, outside the section")
        body = at + 2
        if group_id > 0:  # a parameter: type, dimensions, values
            if body + 2 > limit:
                raise bad(pos, "ends before its type")
            kind, n_dims = struct.unpack_from("bB", section, body)
            if kind not in _PARAM_TYPES or n_dims > 7 or body + 2 + n_dims > limit:
                raise bad(pos, f"has type {kind} and {n_dims} dimensions")
            count = math.prod(section[body + 2 : body + 2 + n_dims])
            body += 2 + n_dims + count * _PARAM_TYPES[kind]
        if body + 1 > limit or body + 1 + section[body] > limit:
            raise bad(pos, "holds more than fits before the next record")
        if offset == 0:
            break
        pos = limit


def _param(params: Any, group: str, name: str) -> Any:
    try:
        return params[group][name]["value"]
    except (KeyError, TypeError):
        return None


def point_labels(params: Any) -> tuple[str, ...]:
    """The points' labels: ``POINT:LABELS``, then ``LABELS2``, ``LABELS3``, ... in turn.

    A C3D parameter holds at most 255 entries, so a file of more points continues the labels
    in ``LABELS2`` (points 256-510), ``LABELS3`` and so on (the C3D User Guide; ezc3d writes
    them so).
    """
    labels: list[str] = []
    for k in range(1, 10_000):
        value = _param(params, "POINT", "LABELS" if k == 1 else f"LABELS{k}")
        if value is None:
            break
        labels += [str(s).strip() for s in value]
    return tuple(labels)


def read_c3d(path: Path, unit_m: float | None = None) -> C3dMarkers:
    """Read the 3D points of a C3D file through ezc3d (see the module docstring);
    ``unit_m`` [m per file unit] overrides ``POINT:UNITS``.

    Raises
    ------
    mdframework.DataFileError
        A bad header (:func:`read_c3d_header`); a file ezc3d cannot parse; unknown
        ``POINT:UNITS``; a frame rate outside the limits; coordinates not finite or beyond
        ``limits.MAX_FILE_COORDINATE``.
    """
    header = read_c3d_header(path)
    import ezc3d

    try:
        c = ezc3d.c3d(str(path))
    except Exception as exc:  # ezc3d raises plain RuntimeError/ValueError with C++ messages
        text = " ".join(str(exc).split()) or type(exc).__name__
        raise DataFileError(path, f"ezc3d cannot read this C3D file: {text}") from None
    params = c["parameters"]
    labels = point_labels(params)
    points = np.asarray(c["data"]["points"], dtype=np.float64)  # (4, n_markers, n_frames)
    if points.ndim != 3 or points.shape[1] != len(labels):
        raise DataFileError(
            path,
            f"{points.shape[1] if points.ndim == 3 else 0} points per frame but "
            f"{len(labels)} POINT:LABELS",
        )
    positions = np.ascontiguousarray(points[:3].transpose(2, 1, 0))
    units_value = _param(params, "POINT", "UNITS")
    units = str(units_value[0]).strip().lower() if units_value else ""
    if units not in UNIT_M and unit_m is None:
        raise DataFileError(
            path,
            f"POINT:UNITS is {units or 'missing'!r}, not one of {', '.join(UNIT_M)}: give "
            "motion.unit_m (metres per file unit)",
        )
    rate = float(c["header"]["points"]["frame_rate"])
    if not (math.isfinite(rate) and limits.MIN_FRAME_RATE_HZ <= rate <= limits.MAX_FRAME_RATE_HZ):
        raise DataFileError(
            path,
            f"header frame rate {rate!r} Hz is outside {limits.MIN_FRAME_RATE_HZ:g}.."
            f"{limits.MAX_FRAME_RATE_HZ:g} Hz: give motion.frame_rate",
        )
    limits.check_values(
        path, positions, limits.MAX_FILE_COORDINATE, "a marker coordinate", unit="", allow_nan=True
    )
    subjects = _param(params, "SUBJECTS", "NAMES")
    software = _param(params, "MANUFACTURER", "SOFTWARE")
    events: list[tuple[str, str, float]] = []
    times = _param(params, "EVENT", "TIMES")
    ev_labels = _param(params, "EVENT", "LABELS") or []
    contexts = _param(params, "EVENT", "CONTEXTS") or []
    if times is not None and len(ev_labels):
        t = np.asarray(times, dtype=np.float64).reshape(2, -1)
        for k, label in enumerate(ev_labels):
            if k < t.shape[1]:
                context = str(contexts[k]).strip() if k < len(contexts) else ""
                events.append((str(label).strip(), context, float(t[0, k] * 60 + t[1, k])))
    return C3dMarkers(
        path=path,
        labels=labels,
        positions=positions,
        rate_hz=rate,
        units=units,
        unit_m=unit_m if unit_m is not None else UNIT_M[units],
        first_frame=header.first_frame,
        subject=str(subjects[0]).strip() if subjects else None,
        software=str(software[0]).strip() if software else None,
        events=tuple(sorted(events, key=lambda e: e[2])),
    )
