"""Plain joint-track tables: CSV, TSV, whitespace-separated text, or NPZ; long or wide form.

**Long form**: one row per joint and frame, with columns for the time, the joint's name and
its x, y, z (default names ``time``, ``joint``, ``x``, ``y``, ``z``; other columns are
ignored)::

    time,joint,x,y,z
    0.000,Head,0.10,0.02,1.71
    0.000,LeftKnee,0.08,0.11,0.52
    ...

**Wide form**: one row per frame, a time column and three columns per joint, named
``<joint>_x``, ``<joint>_y``, ``<joint>_z`` (the separator may also be ``.``, ``:``, ``-``, a
space or nothing, and the axis letter upper case: ``Head.X``, ``HeadX``); other columns (a
confidence, a frame counter) are ignored::

    time,Head_x,Head_y,Head_z,LeftKnee_x,...

A file without a header row gives its column names in the config (``columns``), or, for the
wide form, the joints in column order after the time column (``joints``: three columns each).

**NPZ** (``numpy.savez``; read without pickles): the wide form as arrays ``time`` (n,),
``positions`` (n, n_joints, 3) and ``joints`` (n_joints,) strings; the long form as arrays
named like the long form's columns, each (n_rows,).

**Time**: the time column in ``time_unit_s`` seconds per unit, or, with ``frame_rate``, frame
numbers at that rate; with no time column (``time_column = ""``) the rows are consecutive
frames at ``frame_rate``. Frames out of order are sorted, frames repeating a time are dropped
(the first is kept; both counted in the metadata). A missing value (an empty field, ``nan``)
marks that joint as not tracked in that frame.

Checks before anything is allocated for the data: text is UTF-8 (a NUL byte means binary); an
NPZ member's uncompressed size, as the archive declares it and as the shape in its header
makes it, is at most ``limits.MAX_MOTION_ARRAY_BYTES`` (checked before it is decompressed),
and its shape stays within ``limits.MAX_FRAMES`` frames and :data:`MAX_JOINTS` joints; then
every number is finite (or missing) and within ``limits.MAX_FILE_COORDINATE``; every time, in
seconds (after ``time_unit_s`` or ``frame_rate``), within ``limits.MAX_CLOCK_TIME_S`` (clock
times such as Unix epoch seconds pass: the motion counts from its first frame), and the times
spanning at most ``limits.MAX_DURATION_S``; and the frame rate (the inverse of the median step
between frames) within ``limits.MIN_FRAME_RATE_HZ .. MAX_FRAME_RATE_HZ``, as for every
recording (milliseconds read as seconds are not a 0.12 Hz recording).

Arrays: :class:`Table` ``positions`` (n_frames, n_joints, 3) float64 in the file's unit, NaN
where missing; ``time`` (n_frames,) float64 [s], strictly increasing.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from mdframework import DataFileError, limits
from mdframework.conditioning import sort_timestamps

FloatArray = NDArray[np.float64]

#: Most joints (or markers) a table may hold.
MAX_JOINTS = 10_000

#: Canonical joint -> names of common skeleton exports (first present wins).
JOINT_SETS: dict[str, dict[str, tuple[str, ...]]] = {
    "canonical": {},  # filled below: every canonical joint by its own name
    "kinect-v1": {
        "base": ("HipCenter",),
        "neck": ("ShoulderCenter",),
        "head": ("Head",),
    },
    "kinect-v2": {
        "base": ("SpineBase",),
        "neck": ("SpineShoulder",),
        "head": ("Head",),
    },
}


def _fill_sets() -> None:
    from mdframework import CANONICAL_JOINTS

    JOINT_SETS["canonical"].update({j: (j,) for j in CANONICAL_JOINTS})
    for key in ("kinect-v1", "kinect-v2"):
        for side, name in (("l", "Left"), ("r", "Right")):
            for canon, kinect in (
                ("shoulder", "Shoulder"),
                ("elbow", "Elbow"),
                ("hand", "Hand"),
                ("hip", "Hip"),
                ("knee", "Knee"),
                ("ankle", "Ankle"),
                ("toe", "Foot"),
            ):
                JOINT_SETS[key][f"{side}_{canon}"] = (f"{kinect}{name}",)


_fill_sets()

Delimiter = Literal["auto", ",", ";", "tab", "whitespace"]

_WIDE = re.compile(r"^(?P<joint>.+?)[ _.:-]?(?P<axis>[xyzXYZ])$")


@dataclass(frozen=True)
class TableLayout:
    """How a table is laid out (see the module docstring); the config's fields of the same
    names."""

    layout: Literal["auto", "long", "wide"] = "auto"
    delimiter: Delimiter = "auto"
    header: bool = True
    columns: tuple[str, ...] | None = None
    joints: tuple[str, ...] | None = None
    time_column: str = "time"
    time_unit_s: float = 1.0
    frame_rate: float | None = None
    joint_column: str = "joint"
    xyz: tuple[str, str, str] = ("x", "y", "z")


@dataclass(frozen=True)
class Table:
    """A table as read: ``names`` of the joints in the file's order, ``time`` (n,) [s],
    ``positions`` (n, n_joints, 3) in the file's unit (NaN where missing), ``layout`` ("long"
    or "wide"), and how many frames were out of order or dropped as repeated times."""

    names: tuple[str, ...]
    time: FloatArray
    positions: FloatArray
    layout: str
    rows: int
    out_of_order: int = 0
    duplicates_dropped: int = 0
    extra: dict[str, Any] = field(default_factory=dict)


def read_table(path: Path, spec: TableLayout | None = None) -> Table:
    """Read a joint-track table (see the module docstring).

    Raises
    ------
    mdframework.DataFileError
        Unreadable, binary or empty file; a missing column; a row of the wrong length; a value
        that is not a number, not finite or beyond the limits; a joint given twice for one
        time (long form); an NPZ member of the wrong shape or beyond the limits.
    """
    spec = spec or TableLayout()
    if path.suffix.lower() == ".npz":
        time, names, pos, layout, rows = _read_npz(path, spec)
        limits.check_values(
            path, pos, limits.MAX_FILE_COORDINATE, "a joint coordinate", allow_nan=True
        )
    else:  # text: checked row by row as it is read (the error names the line)
        time, names, pos, layout, rows = _read_text(path, spec)
    # times count from the first frame: a clock time (epoch seconds) is checked by its span
    limits.check_time_stamps(path, time - (time.min() if time.size else 0.0))
    t, p, _ok, report = sort_timestamps(time, pos)
    if t.shape[0] < 2:
        raise DataFileError(path, "fewer than two distinct time stamps: a motion needs two")
    _check_frame_rate(path, t, spec)
    return Table(names, t, p, layout, rows, report["out_of_order"], report["duplicates_dropped"])


# --------------------------------------------------------------------------- text


def _lines(path: Path) -> list[tuple[int, str]]:
    """Non-empty, non-comment lines with their 1-based numbers."""
    text = limits.read_text_file(path, "a text table", limits.MAX_MOTION_TEXT_BYTES)
    out = [(i, s) for i, s in enumerate(text.splitlines(), start=1) if s.strip()]
    out = [(i, s) for i, s in out if not s.lstrip().startswith("#")]
    if not out:
        raise DataFileError(path, "the file is empty")
    return out


def _split(path: Path, lines: list[tuple[int, str]], delimiter: Delimiter) -> list[list[str]]:
    if delimiter == "auto":
        delimiter = {".csv": ",", ".tsv": "tab"}.get(path.suffix.lower(), "whitespace")
    if delimiter == "whitespace":
        return [s.split() for _, s in lines]
    import csv

    sep = "\t" if delimiter == "tab" else delimiter
    return [[f.strip() for f in row] for row in csv.reader((s for _, s in lines), delimiter=sep)]


def _column_names(path: Path, spec: TableLayout, first: list[str]) -> list[str]:
    if spec.columns is not None:
        return list(spec.columns)
    if spec.joints is not None:
        lead = [spec.time_column] if spec.time_column else []
        return lead + [f"{j}_{a}" for j in spec.joints for a in "xyz"]
    if not spec.header:
        raise DataFileError(
            path, "a table without a header row needs motion.columns or motion.joints"
        )
    return first


def _numbers(path: Path, cells: list[str], line: int, what: str) -> FloatArray:
    out = np.empty(len(cells))
    for k, c in enumerate(cells):
        if c == "" or c.lower() in ("nan", "na", "null"):
            out[k] = np.nan
            continue
        try:
            out[k] = float(c)
        except ValueError:
            raise DataFileError(path, f"{what}: {c!r} is not a number", line) from None
    return out


def _columns(
    path: Path, rows: list[list[str]], line_of: list[int], cols: list[int], what: str
) -> FloatArray:
    """The numbers in columns ``cols`` of every row, (n_rows, len(cols))."""
    return np.array(
        [
            _numbers(path, [r[k] for k in cols], ln, what)
            for r, ln in zip(rows, line_of, strict=True)
        ]
    ).reshape(len(rows), len(cols))


def _coordinates(
    path: Path, rows: list[list[str]], line_of: list[int], cols: list[int]
) -> FloatArray:
    """:func:`_columns` of joint coordinates, each within the file limit (NaN: not seen); the
    error names the row's line."""
    out = _columns(path, rows, line_of, cols, "coordinate")
    limits.check_values(
        path, out, limits.MAX_FILE_COORDINATE, "a joint coordinate", line_of, allow_nan=True
    )
    return out


def _read_text(
    path: Path, spec: TableLayout
) -> tuple[FloatArray, tuple[str, ...], FloatArray, str, int]:
    lines = _lines(path)
    rows = _split(path, lines, spec.delimiter)
    names = _column_names(path, spec, rows[0])
    # the line that names the columns (None where the config names them)
    named_at = lines[0][0] if spec.header and names is rows[0] else None
    if spec.header:
        lines, rows = lines[1:], rows[1:]
    limits.check_declared_count(path, lines[0][0] if lines else 1, "rows", len(rows))
    if not rows:
        raise DataFileError(path, "a header but no data rows")
    col: dict[str, int] = {}
    for k, n in enumerate(names):
        if n in col:
            raise DataFileError(
                path, f"column {n!r} appears twice (columns {col[n] + 1} and {k + 1})", named_at
            )
        col[n] = k
    layout = spec.layout
    if layout == "auto":
        layout = "long" if spec.joint_column in col else "wide"
    for (line, _), row in zip(lines, rows, strict=True):
        if len(row) != len(names):
            raise DataFileError(
                path, f"{len(row)} fields, but the header names {len(names)} columns", line
            )
    line_of = [ln for ln, _ in lines]
    if layout == "long":
        return _long_text(path, spec, names, col, rows, line_of, named_at)
    return _wide_text(path, spec, names, col, rows, line_of, named_at)


def _time_of(
    path: Path,
    spec: TableLayout,
    values: FloatArray | None,
    n_rows: int,
    line_of: Sequence[int] | None = None,
) -> FloatArray:
    """Seconds from a time column's values (or the row order, without one): frame numbers at
    ``spec.frame_rate``, else values times ``spec.time_unit_s``.

    Checked in seconds: every time finite and within +-``limits.MAX_CLOCK_TIME_S`` (clock times
    such as epoch seconds pass; the motion counts from its first frame), and the span from the
    earliest to the latest at most ``limits.MAX_DURATION_S``.
    """
    if values is None:
        if spec.frame_rate is None:
            raise DataFileError(
                path, "no time column: give motion.time_column or motion.frame_rate"
            )
        return np.arange(n_rows, dtype=np.float64) / spec.frame_rate
    limits.check_values(path, values, float("inf"), "time", line_of)  # finite, in any unit
    seconds = values / spec.frame_rate if spec.frame_rate is not None else values * spec.time_unit_s
    unit = _time_unit(spec)
    limits.check_values(path, seconds, limits.MAX_CLOCK_TIME_S, f"time [s] ({unit})", line_of, " s")
    span = float(seconds.max() - seconds.min()) if seconds.size else 0.0
    if span > limits.MAX_DURATION_S:
        raise DataFileError(
            path,
            f"the times span {span:g} s ({unit}), more than {limits.MAX_DURATION_S:g} s: check "
            "the time column's unit (motion.time_unit_s or motion.frame_rate)",
        )
    return seconds


def _time_unit(spec: TableLayout) -> str:
    """How the time column was read, for messages."""
    if not spec.time_column:
        return f"rows at motion.frame_rate = {spec.frame_rate:g} Hz"
    if spec.frame_rate is not None:
        return f"frame numbers at motion.frame_rate = {spec.frame_rate:g} Hz"
    return f"motion.time_unit_s = {spec.time_unit_s:g} s per unit"


def _check_frame_rate(path: Path, time: FloatArray, spec: TableLayout) -> None:
    """The frame rate the times give (the inverse of the median step between frames, which
    gaps do not move) within ``limits.MIN_FRAME_RATE_HZ .. MAX_FRAME_RATE_HZ``, as every
    recording's: milliseconds read as seconds (0.12 frames a second at 120 Hz) or frame
    numbers read as seconds are refused with the unit they were read in. A time column read as
    times whose frames are a whole second apart (1 frame/s, the lowest rate) holds frame numbers
    (0, 1, 2, ...): refused too, unless ``frame_rate`` says they are frame numbers."""
    step = float(np.median(np.diff(time)))
    rate = 1.0 / step
    stamped = bool(spec.time_column) and spec.frame_rate is None  # times, not frame numbers
    if stamped and rate == limits.MIN_FRAME_RATE_HZ:
        why = "as frame numbers read as seconds give"
    elif rate < limits.MIN_FRAME_RATE_HZ:
        why = f"below the {limits.MIN_FRAME_RATE_HZ:g} frames/s of a motion recording"
    elif rate > limits.MAX_FRAME_RATE_HZ:
        why = f"above the {limits.MAX_FRAME_RATE_HZ:g} frames/s of a motion recording"
    else:
        return
    raise DataFileError(
        path,
        f"the frames are {step:.4g} s apart (the median step, {_time_unit(spec)}): "
        f"{rate:.4g} frames/s, {why}: "
        "check the time column's unit (motion.time_unit_s, 0.001 for milliseconds, or "
        "motion.frame_rate for frame numbers)",
    )


def _need(path: Path, col: dict[str, int], name: str, what: str, named_at: int | None) -> int:
    if name not in col:
        raise DataFileError(
            path,
            f"no column {name!r} ({what}); the columns are {', '.join(col)}: name it in the config",
            named_at,
        )
    return col[name]


def _long_text(
    path: Path,
    spec: TableLayout,
    names: list[str],
    col: dict[str, int],
    rows: list[list[str]],
    line_of: list[int],
    named_at: int | None,
) -> tuple[FloatArray, tuple[str, ...], FloatArray, str, int]:
    jcol = _need(path, col, spec.joint_column, "the joint names", named_at)
    xyz = [_need(path, col, c, "a coordinate", named_at) for c in spec.xyz]
    tcol = _need(path, col, spec.time_column, "the time", named_at) if spec.time_column else None
    if tcol is None:
        raise DataFileError(path, "a long table needs a time column (motion.time_column)")
    raw_t = _columns(path, rows, line_of, [tcol], "time")[:, 0]
    coords = _coordinates(path, rows, line_of, xyz)
    return _long_assemble(path, spec, raw_t, [r[jcol] for r in rows], coords, line_of)


def _long_assemble(
    path: Path,
    spec: TableLayout,
    raw_t: FloatArray,
    joint_of_row: list[str],
    coords: FloatArray,
    line_of: Sequence[int] | None,
) -> tuple[FloatArray, tuple[str, ...], FloatArray, str, int]:
    """Frames x joints from long-form rows: times (n_rows,) in the column's unit, the joint
    of each row, coordinates (n_rows, 3). Returns the frames' times [s] (sorted), the joint
    names, positions (n_frames, n_joints, 3), the layout and the row count."""
    row_time = _time_of(path, spec, raw_t, len(raw_t), line_of)
    joint_names = list(dict.fromkeys(joint_of_row))
    if len(joint_names) > MAX_JOINTS:
        raise DataFileError(path, f"{len(joint_names)} joints: more than {MAX_JOINTS}")
    times, t_index = np.unique(row_time, return_inverse=True)
    j_index = {n: k for k, n in enumerate(joint_names)}
    pos = np.full((times.shape[0], len(joint_names), 3), np.nan)
    seen = np.zeros((times.shape[0], len(joint_names)), dtype=bool)
    for r, name in enumerate(joint_of_row):
        i, j = int(t_index[r]), j_index[name]
        if seen[i, j]:
            line = None if line_of is None else int(line_of[r])
            raise DataFileError(path, f"joint {name!r} appears twice at time {raw_t[r]:g}", line)
        seen[i, j] = True
        pos[i, j] = coords[r]
    n_rows = len(joint_of_row)
    return times, tuple(joint_names), pos, "long", n_rows


def _wide_text(
    path: Path,
    spec: TableLayout,
    names: list[str],
    col: dict[str, int],
    rows: list[list[str]],
    line_of: list[int],
    named_at: int | None,
) -> tuple[FloatArray, tuple[str, ...], FloatArray, str, int]:
    tcol = _need(path, col, spec.time_column, "the time", named_at) if spec.time_column else None
    groups: dict[str, dict[str, int]] = {}
    for k, n in enumerate(names):
        m = _WIDE.match(n)
        if k == tcol or m is None:
            continue
        group = groups.setdefault(m.group("joint"), {})
        axis = m.group("axis").lower()
        if axis in group:
            raise DataFileError(
                path,
                f"columns {names[group[axis]]!r} and {n!r} are the same coordinate "
                f"(columns {group[axis] + 1} and {k + 1})",
                named_at,
            )
        group[axis] = k
    joints = [j for j, g in groups.items() if set(g) == {"x", "y", "z"}]
    if not joints:
        raise DataFileError(
            path,
            f"no joint columns: a wide table names three per joint (<joint>_x, <joint>_y, "
            f"<joint>_z); the columns are {', '.join(names[:30])}",
            named_at,
        )
    idx = [groups[j][a] for j in joints for a in "xyz"]
    data = _coordinates(path, rows, line_of, idx)
    values = None
    if tcol is not None:
        values = _columns(path, rows, line_of, [tcol], "time")[:, 0]
    time = _time_of(path, spec, values, len(rows), line_of)
    return time, tuple(joints), data.reshape(len(rows), len(joints), 3), "wide", len(rows)


# --------------------------------------------------------------------------- NPZ


def _npz_shapes(path: Path) -> dict[str, tuple[tuple[int, ...], np.dtype[Any]]]:
    """Each member's shape and dtype from its .npy header, without reading its data; a member
    whose uncompressed size (as the archive declares it, or as its shape and dtype make it) is
    over ``limits.MAX_MOTION_ARRAY_BYTES`` is refused before it is decompressed."""
    import zipfile

    limits.check_regular_file(path)
    out: dict[str, tuple[tuple[int, ...], np.dtype[Any]]] = {}
    biggest = limits.MAX_MOTION_ARRAY_BYTES

    def too_big(key: str, size: str) -> DataFileError:
        return DataFileError(
            path,
            f"array {key!r} is {size} uncompressed, beyond the limit of {biggest:,} bytes for "
            "an array of a motion file",
        )

    try:
        with zipfile.ZipFile(path) as z:
            for info in z.infolist():
                if not info.filename.endswith(".npy"):
                    continue
                if info.file_size > biggest:
                    raise too_big(info.filename[:-4], f"{info.file_size:,} bytes")
                with z.open(info) as f:
                    version = np.lib.format.read_magic(f)
                    reader = (
                        np.lib.format.read_array_header_1_0
                        if version == (1, 0)
                        else np.lib.format.read_array_header_2_0
                    )
                    shape, _fortran, dtype = reader(f)
                n = int(np.prod(shape, dtype=object)) if shape else 1
                if n * dtype.itemsize > biggest:  # (the archive's size may be forged)
                    size = f"{n * dtype.itemsize:,} bytes (shape {tuple(shape)} of {dtype})"
                    raise too_big(info.filename[:-4], size)
                out[info.filename[:-4]] = (tuple(shape), dtype)
    except (OSError, zipfile.BadZipFile, ValueError) as exc:
        raise DataFileError(path, f"not a readable .npz file ({exc})") from None
    return out


def _read_npz(
    path: Path, spec: TableLayout
) -> tuple[FloatArray, tuple[str, ...], FloatArray, str, int]:
    import zipfile
    import zlib

    shapes = _npz_shapes(path)
    for key, (_shape, dtype) in shapes.items():
        if dtype.hasobject:
            raise DataFileError(path, f"array {key!r} holds Python objects: not read (pickles)")
    layout = spec.layout
    if layout == "auto":
        layout = "wide" if "positions" in shapes else "long"
    with np.load(path, allow_pickle=False) as z:

        def get(key: str, what: str) -> NDArray[Any]:
            if key not in shapes:
                raise DataFileError(
                    path, f"no array {key!r} ({what}); the arrays are {', '.join(shapes)}"
                )
            try:
                return np.asarray(z[key])
            except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error) as exc:
                # a member that holds less than its header declares, or damaged compressed data
                raise DataFileError(path, f"array {key!r} cannot be read ({exc})") from None

        if layout == "wide":
            pos = get("positions", "(n_frames, n_joints, 3) positions").astype(np.float64)
            names = tuple(str(s) for s in get("joints", "the joint names"))
            if pos.ndim != 3 or pos.shape[2] != 3 or pos.shape[1] != len(names):
                raise DataFileError(
                    path,
                    f"positions has shape {pos.shape}; with {len(names)} joint names it must be "
                    f"(n_frames, {len(names)}, 3)",
                )
            limits.check_declared_count(path, 1, "frames", pos.shape[0])
            values = (
                get(spec.time_column, "the time").astype(np.float64).ravel()
                if spec.time_column
                else None
            )
            if values is not None and values.shape[0] != pos.shape[0]:
                raise DataFileError(
                    path, f"{values.shape[0]} time stamps for {pos.shape[0]} frames of positions"
                )
            return _time_of(path, spec, values, pos.shape[0]), names, pos, "wide", pos.shape[0]
        tv = get(spec.time_column, "the time").astype(np.float64).ravel()
        jn = [str(s) for s in get(spec.joint_column, "the joint names").ravel()]
        xyz = [get(c, "a coordinate").astype(np.float64).ravel() for c in spec.xyz]
        if not all(a.shape[0] == tv.shape[0] for a in xyz) or len(jn) != tv.shape[0]:
            raise DataFileError(path, "the long-form arrays differ in length")
        return _long_assemble(path, spec, tv, jn, np.stack(xyz, axis=1), None)


def canonical_groups(
    names: Sequence[str], joint_set: str, joint_map: dict[str, tuple[str, ...]]
) -> tuple[str, dict[str, tuple[str, ...]], list[str]]:
    """Canonical joint -> the file joints to average: the joint set's names (``joint_set``, or
    the set matching most names when ``"auto"``) completed or overridden by ``joint_map``.
    Returns the set's name, the map, and the canonical joints left without a file joint."""
    from mdframework import CANONICAL_JOINTS

    have = set(names)
    candidates = list(JOINT_SETS) if joint_set == "auto" else [joint_set]
    best: tuple[int, str, dict[str, tuple[str, ...]], list[str]] | None = None
    for set_name in candidates:
        groups: dict[str, tuple[str, ...]] = {}
        missing: list[str] = []
        for j in CANONICAL_JOINTS:
            if j in joint_map:
                groups[j] = joint_map[j]
                continue
            found = next((n for n in JOINT_SETS[set_name].get(j, ()) if n in have), None)
            if found is None:
                want = " or ".join(JOINT_SETS[set_name].get(j, ())) or "none"
                missing.append(f"{j} ({want})")
            else:
                groups[j] = (found,)
        score = -len(missing)
        if best is None or score > best[0]:
            best = (score, set_name, groups, missing)
    assert best is not None
    return best[1], best[2], best[3]
