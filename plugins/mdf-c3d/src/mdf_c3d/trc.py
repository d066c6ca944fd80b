"""Reading TRC marker files (OpenSim's "track row column" text format).

A TRC file is tab-separated text::

    PathFileType  4  (X/Y/Z)  walk.trc
    DataRate  CameraRate  NumFrames  NumMarkers  Units  OrigDataRate  OrigDataStartFrame  ...
    60.00     60.00       151        41          mm     60.00         1                   ...
    Frame#  Time  R.ASIS        L.ASIS        ...
                  X1  Y1  Z1    X2  Y2  Z2    ...
    (blank line)
    1       0.000  617.2  1055.3  170.8  639.6  ...

Line 1 names the format, lines 2-3 are a header of keys and values (``DataRate`` [Hz],
``NumFrames``, ``NumMarkers`` and ``Units`` are required), line 4 the markers (one name every
three columns after ``Frame#`` and ``Time``), line 5 the coordinate labels, then one row per
frame: the frame number, the time [s] and x, y, z of every marker. An empty field (or ``nan``)
marks a marker not seen in that frame.

Checks, in this order and before the positions array is allocated: UTF-8 (or Latin-1) text
without NUL bytes; line 1 starts with ``PathFileType``; the header's keys and values; a
``DataRate`` within ``limits.MIN_FRAME_RATE_HZ .. MAX_FRAME_RATE_HZ``; ``NumMarkers`` in
1..:data:`MAX_MARKERS` and ``NumFrames`` at most ``limits.MAX_FRAMES``; ``Units`` one of
``mm cm dm m in`` (or ``unit_m`` given); as many marker names as ``NumMarkers``, none twice;
as many data rows as ``NumFrames`` (fewer: truncated; more: the count is wrong). Then every row:
``2 + 3 * NumMarkers`` fields, increasing integer frame numbers, every value a number (or
missing) within ``limits.MAX_FILE_COORDINATE``, and the ``Time`` column within half a frame of
``(Frame# - first Frame#) / DataRate`` (TRC writers round it, OpenSim to 1 ms). At least two
frames.

Time base: the frame numbers over ``DataRate`` (or ``frame_rate``), not the rounded ``Time``
column: at 60 Hz a time written to 1 ms is off by up to 0.5 ms, 3 % of a frame, which would
put 3 % noise on every velocity.

Arrays: :class:`TrcMarkers` ``positions`` (n_frames, n_markers, 3) float64 in the file's unit
(``unit_m`` metres per unit), NaN where a marker is not seen; ``time`` (n_frames,) float64 [s]
from 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from mdframework import DataFileError, limits

from .reader import UNIT_M

#: Most markers a TRC file may declare.
MAX_MARKERS = 10_000

#: Header keys a TRC file must give (line 2), with their values on line 3.
REQUIRED_KEYS = ("DataRate", "NumFrames", "NumMarkers", "Units")

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class TrcMarkers:
    """What :func:`read_trc` returns: ``labels`` the marker names (line 4); ``positions``
    (n_frames, n_markers, 3) float64 in the file's unit, NaN where not seen; ``time``
    (n_frames,) [s] from 0 at ``rate_hz``; ``rate_hz`` the ``DataRate`` (or the override);
    ``units`` the header's ``Units`` and ``unit_m`` metres per unit; ``frames`` (n_frames,) the
    ``Frame#`` column; ``header`` every key of lines 2-3 with its value (text)."""

    path: Path
    labels: tuple[str, ...]
    positions: FloatArray
    time: FloatArray
    rate_hz: float
    units: str
    unit_m: float
    frames: NDArray[np.int64]
    header: dict[str, str] = field(default_factory=dict)

    @property
    def n_frames(self) -> int:
        """Frames read."""
        return int(self.positions.shape[0])


def _header(path: Path, lines: list[str]) -> dict[str, str]:
    if not lines or not lines[0].lstrip().startswith("PathFileType"):
        first = lines[0].strip()[:40] if lines else ""
        raise DataFileError(
            path, f"not a TRC file: line 1 should start with PathFileType, not {first!r}", 1
        )
    if len(lines) < 5:
        raise DataFileError(
            path, f"{len(lines)} line(s): a TRC file has 5 header lines before its data"
        )
    keys, values = lines[1].split(), lines[2].split()
    missing = [k for k in REQUIRED_KEYS if k not in keys]
    if missing:
        raise DataFileError(
            path,
            f"header line 2 lacks {', '.join(missing)} (it names {', '.join(keys) or 'nothing'})",
            2,
        )
    if len(values) < len(keys):
        raise DataFileError(
            path, f"header line 3 has {len(values)} value(s) for the {len(keys)} keys of line 2", 3
        )
    return dict(zip(keys, values, strict=False))


def _int(path: Path, header: dict[str, str], key: str, low: int, high: int) -> int:
    text = header[key]
    try:
        value = float(text)
    except ValueError:
        raise DataFileError(path, f"header {key} {text!r} is not a number", 3) from None
    if not (math.isfinite(value) and value == int(value)):
        raise DataFileError(path, f"header {key} {text!r} is not a whole number", 3)
    n = int(value)
    if not low <= n <= high:
        raise DataFileError(path, f"header {key} {n} is outside {low}..{high:,}", 3)
    return n


def _rate(path: Path, header: dict[str, str]) -> float:
    text = header["DataRate"]
    try:
        rate = float(text)
    except ValueError:
        raise DataFileError(path, f"header DataRate {text!r} is not a number", 3) from None
    if not (math.isfinite(rate) and limits.MIN_FRAME_RATE_HZ <= rate <= limits.MAX_FRAME_RATE_HZ):
        raise DataFileError(
            path,
            f"header DataRate {text} Hz is outside {limits.MIN_FRAME_RATE_HZ:g}.."
            f"{limits.MAX_FRAME_RATE_HZ:g} Hz: give motion.frame_rate",
            3,
        )
    return rate


def _marker_names(path: Path, line: str, n_markers: int) -> tuple[str, ...]:
    names = [f.strip() for f in line.split("\t")[2:] if f.strip()]
    if len(names) != n_markers:
        raise DataFileError(
            path,
            f"line 4 names {len(names)} marker(s), but the header's NumMarkers is {n_markers}",
            4,
        )
    seen: set[str] = set()
    for name in names:
        if name in seen:
            raise DataFileError(path, f"marker {name!r} is named twice", 4)
        seen.add(name)
    return tuple(names)


def _fields(line: str) -> list[str]:
    """A data row's fields: tab-separated (empty fields are missing values), or, for files
    written with spaces, whitespace-separated."""
    return [f.strip() for f in line.split("\t")] if "\t" in line else line.split()


def read_trc(
    path: Path, unit_m: float | None = None, frame_rate: float | None = None
) -> TrcMarkers:
    """Read a TRC marker file (see the module docstring); ``unit_m`` [m per file unit]
    overrides ``Units``, ``frame_rate`` [Hz] overrides ``DataRate`` (and the ``Time`` column is
    then not checked against it).

    Raises
    ------
    mdframework.DataFileError
        Naming the file and line: not a TRC file, a bad header value, a count that does not
        match the data (truncated file), a short row, a value that is not a number or beyond
        the limits, frame numbers out of order, a ``Time`` column that disagrees with the frame
        rate, fewer than two frames.
    """
    # old writers put Windows paths in line 1: text that is not UTF-8 is read as Latin-1
    lines = limits.read_text_file(
        path, "a TRC text file", limits.MAX_MOTION_TEXT_BYTES, latin1=True
    ).splitlines()
    header = _header(path, lines)
    rate = float(frame_rate) if frame_rate is not None else _rate(path, header)
    n_markers = _int(path, header, "NumMarkers", 1, MAX_MARKERS)
    n_frames = _int(path, header, "NumFrames", 0, limits.MAX_FRAMES)
    units = header["Units"].strip().lower()
    if units not in UNIT_M and unit_m is None:
        raise DataFileError(
            path,
            f"header Units {header['Units']!r} is not one of {', '.join(UNIT_M)}: give "
            "motion.unit_m (metres per file unit)",
            3,
        )
    labels = _marker_names(path, lines[3], n_markers)
    rows = [(i, s) for i, s in enumerate(lines[5:], start=6) if s.strip()]
    if len(rows) < n_frames:
        where = rows[-1][0] if rows else len(lines)
        raise DataFileError(
            path,
            f"the header's NumFrames is {n_frames}, but the file holds {len(rows)} data row(s) "
            f"(last at line {where}): the file is truncated or NumFrames is wrong",
            3,
        )
    if len(rows) > n_frames:
        raise DataFileError(
            path,
            f"the header's NumFrames is {n_frames}, but the file holds {len(rows)} data rows: "
            "correct NumFrames",
            3,
        )
    if n_frames < 2:
        raise DataFileError(path, f"{n_frames} frame(s): a motion needs at least two", 3)
    width = 2 + 3 * n_markers
    values = np.empty((n_frames, width))
    for k, (line_no, text) in enumerate(rows):
        cells = _fields(text)
        if len(cells) < width:
            raise DataFileError(
                path,
                f"{len(cells)} field(s), but Frame#, Time and x, y, z of {n_markers} markers "
                f"are {width}: the row is cut short",
                line_no,
            )
        extra = [c for c in cells[width:] if c]
        if extra:
            raise DataFileError(
                path, f"{len(cells)} fields, more than the {width} of {n_markers} markers", line_no
            )
        for j, cell in enumerate(cells[:width]):
            if cell == "" or cell.lower() == "nan":
                values[k, j] = np.nan
                continue
            try:
                values[k, j] = float(cell)
            except ValueError:
                raise DataFileError(path, f"{cell!r} is not a number", line_no) from None
    line_of = [r[0] for r in rows]
    frames_f = values[:, 0]
    if not np.all(np.isfinite(frames_f)) or np.any(frames_f != np.round(frames_f)):
        k = int(np.flatnonzero(~np.isfinite(frames_f) | (frames_f != np.round(frames_f)))[0])
        raise DataFileError(path, "Frame# must be a whole number", line_of[k])
    limits.check_values(path, frames_f, limits.MAX_FRAME_NUMBER, "a frame number", line_of)
    frames = frames_f.astype(np.int64)
    steps = np.diff(frames)
    if np.any(steps <= 0):
        k = int(np.flatnonzero(steps <= 0)[0]) + 1
        raise DataFileError(path, f"Frame# {frames[k]} does not follow {frames[k - 1]}", line_of[k])
    positions = np.ascontiguousarray(values[:, 2:].reshape(n_frames, n_markers, 3))
    limits.check_values(
        path, positions, limits.MAX_FILE_COORDINATE, "a marker coordinate", line_of, allow_nan=True
    )
    time = (frames - frames[0]).astype(np.float64) / rate
    limits.check_time_stamps(path, time)
    if frame_rate is None:
        _check_time_column(path, values[:, 1], time, rate, frames, line_of)
    return TrcMarkers(
        path=path,
        labels=labels,
        positions=positions,
        time=time,
        rate_hz=rate,
        units=units,
        unit_m=unit_m if unit_m is not None else UNIT_M[units],
        frames=frames,
        header=header,
    )


def _check_time_column(
    path: Path,
    column: FloatArray,
    time: FloatArray,
    rate: float,
    frames: NDArray[np.int64],
    line_of: list[int],
) -> None:
    """The ``Time`` column must agree with the frame numbers at ``DataRate`` to half a frame
    (writers round it; a bigger gap means the header's rate is wrong)."""
    limits.check_values(path, column, limits.MAX_DURATION_S, "a Time value", line_of, unit=" s")
    off = np.abs((column - column[0]) - time)
    tolerance = 0.5 / rate + 1e-6
    if np.any(off > tolerance):
        k = int(np.argmax(off > tolerance))
        steps, frame_steps = np.diff(column), np.diff(frames)
        # the rows skip time that Frame# does not (renumbered frames), as opposed to a wrong
        # DataRate, whose every Time step disagrees alike
        if (
            k
            and steps[k - 1] > 1.5 * np.median(steps)
            and frame_steps[k - 1] <= np.median(frame_steps)
        ):
            raise DataFileError(
                path,
                f"Time jumps {steps[k - 1]:.4g} s from the row before while Frame# steps by "
                f"{frame_steps[k - 1]} ({frame_steps[k - 1] / rate:.4g} s "
                f"at DataRate {rate:g} Hz): rows were left out and the frames renumbered; the "
                "time base is Frame# / DataRate, so number the frames as Time says "
                "(motion.frame_rate would read the motion without the gap)",
                line_of[k],
            )
        raise DataFileError(
            path,
            f"Time {column[k]:g} s disagrees with Frame# {frames[k]} at the header's DataRate "
            f"{rate:g} Hz ({time[k] + column[0]:g} s): correct DataRate or give "
            "motion.frame_rate",
            line_of[k],
        )
