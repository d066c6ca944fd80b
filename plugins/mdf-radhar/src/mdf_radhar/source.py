"""The ``radhar`` recording source: point clouds of a TI IWR1443 mmWave radar (RadHAR).

RadHAR (Singh, Sandha, Garcia, Srivastava, "RadHAR: Human Activity Recognition from Point
Clouds Generated through a Millimeter-wave Radar", mmNets 2019; BSD-3-Clause, (c) 2019 UCLA
Networked & Embedded Systems Laboratory) recorded people boxing, jumping, walking and more in
front of a TI IWR1443 sensor through the ``ti_mmwave_rospkg`` ROS driver. Two forms are read:

``rostopic`` text (``.txt``, or gzip-compressed ``.txt.gz``)
    The original files: ``rostopic echo`` of ``ti_mmwave_rospkg/RadarScan`` messages, one
    detected point per message, messages separated by ``---``. Top-level keys used:
    ``point_id``, ``x``, ``y``, ``z`` [m], ``velocity`` [m/s], ``intensity`` [dB] (``header``,
    ``range``, ``doppler_bin`` and ``bearing`` are read past). A frame starts at every
    ``point_id: 0``. The header stamps are publish times that arrive in bursts, so frame ``k``
    is placed at ``k * frame_period``. One file is one recording, named by the file name
    (without ``.gz``).

compact NPZ (``.npz``)
    Many recordings in one file, one row per point: ``files`` (n_recordings,) str (original
    file names, the recordings' names), ``file_index`` (n_points,) int (into ``files``),
    ``frame`` (n_points,) int (per recording, 0-based, from ``point_id`` = 0), ``x``, ``y``,
    ``z`` [m], ``velocity`` [m/s] (as in the text: range rate), ``intensity`` [dB]; optional
    ``doppler_bin``. Points of a recording are in frame order.

Both forms give ``velocity`` as the driver reports it, the RANGE RATE (positive receding); the
reader turns it into the project's radial velocity (positive approaching). The driver publishes
positions in the ROS convention (``x`` forward along the boresight, ``y`` left, ``z`` up; in
these files the people stand at x = 1.2-1.9 m); the reader turns them into the sensor frame of
:mod:`mdframework.pointcloud` (x right = -y_ros, y boresight = x_ros, z up).
"""

from __future__ import annotations

import gzip
import io
import zipfile
import zlib
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from mdframework import (
    DataFileError,
    DataPath,
    PluginConfig,
    Recording,
    RecordingSource,
    limits,
)
from mdframework.pointcloud import (
    IWR1443_BIN_WIDTH,
    PointCloud,
    frames_from_point_ids,
    range_rate_to_approaching,
)

#: Frame period of the sensor configuration ``1443es1_short_range_3d.cfg`` (frameCfg) [s].
FRAME_PERIOD_S = 0.033333
#: Citation recorded in every recording's metadata.
CITATION = (
    "A. D. Singh, S. S. Sandha, L. Garcia, M. Srivastava, 'RadHAR: Human Activity Recognition "
    "from Point Clouds Generated through a Millimeter-wave Radar', mmNets 2019"
)
SENSOR = "TI IWR1443, ti_mmwave_rospkg cfg 1443es1_short_range_3d (77 GHz, 30 frames/s)"
#: Keys of a text message that are read (all numeric).
TEXT_KEYS = ("point_id", "x", "y", "z", "velocity", "intensity")
#: Keys of the message header's time stamp (``header.stamp.secs``, ``.nsecs``).
STAMP_KEYS = ("secs", "nsecs")
NPZ_KEYS = ("files", "file_index", "frame", "x", "y", "z", "velocity", "intensity")
#: The array kinds (numpy ``dtype.kind``) each NPZ array may have; the others hold numbers.
_NPZ_KINDS = {
    "files": ("U", "text"),
    "file_index": ("iu", "whole numbers"),
    "frame": ("iu", "whole numbers"),
}

# What the sensor can report (docs/input-rules.md), checked before a recording is built:
#: Farthest point [m]: 240 range bins of 0.043577 m (the configuration's maximum range), plus
#: one bin for the angle estimates' rounding.
MAX_RANGE_M = 241 * 0.043577
#: Range rates [m/s]: Doppler bins -8 .. +7 of 0.61466867 m/s (16 chirp loops).
MIN_RANGE_RATE_MPS = -8 * IWR1443_BIN_WIDTH
MAX_RANGE_RATE_MPS = 7 * IWR1443_BIN_WIDTH
#: Intensity [dB]: the driver's ``10 log10(peak + 1)`` of a 16-bit peak value, 0 .. 48.2 dB.
MAX_INTENSITY_DB = 10.0 * float(np.log10(65536.0))
#: Point numbers within a frame (the driver's 16-bit object count).
MAX_POINT_ID = 65535
#: Slack for values written with 7-10 significant digits.
_TOLERANCE = 1e-4

_BOUNDS: dict[str, tuple[float, float, str]] = {
    "x": (-MAX_RANGE_M, MAX_RANGE_M, " m"),
    "y": (-MAX_RANGE_M, MAX_RANGE_M, " m"),
    "z": (-MAX_RANGE_M, MAX_RANGE_M, " m"),
    "velocity": (MIN_RANGE_RATE_MPS, MAX_RANGE_RATE_MPS, " m/s"),
    "intensity": (0.0, MAX_INTENSITY_DB, " dB"),
    "point_id": (0.0, MAX_POINT_ID, ""),
    "secs": (0.0, 2.0**32 - 1, " s"),
    "nsecs": (0.0, 999_999_999.0, " ns"),
}
_WHOLE = ("point_id", "secs", "nsecs")


def _problem(key: str, value: float) -> str | None:
    """What is wrong with ``value`` of ``key`` (None when it is within the sensor's range)."""
    lo, hi, unit = _BOUNDS[key]
    if not np.isfinite(value):
        return f"{key} {value!r} is not finite"
    if not lo - _TOLERANCE <= value <= hi + _TOLERANCE:
        return f"{key} {value:g} is outside the sensor's range {lo:g} .. {hi:g}{unit}"
    if key in _WHOLE and value != int(value):
        return f"{key} {value:g} is not a whole number"
    return None


def _open_text(path: Path) -> io.TextIOBase:
    if path.suffix == ".gz":
        return io.TextIOWrapper(gzip.open(path, "rb"), encoding="utf-8")
    return path.open(encoding="utf-8")


def read_rostopic_text(path: str | Path) -> dict[str, NDArray[np.float64]]:
    """The points of a ``rostopic echo`` text file, in file order, checked as they are read.

    Returns ``{key: (n_points,) float64}`` for every key of :data:`TEXT_KEYS`, ``"stamp"``
    (n_points,) [s] (the header's publish time) and ``"line"`` (n_points,) (the line of each
    message's ``point_id``). A :class:`DataFileError` names the file, the line and the problem:
    a message without one of the keys or without its time stamp, a value that is not a number or
    lies
    outside what the sensor reports (:data:`MAX_RANGE_M`, the Doppler bins' range rates,
    :data:`MAX_INTENSITY_DB`), point numbers that do not rise within a frame, time stamps that
    go back, fewer than two frames or two distinct time stamps, binary data.
    """
    p = Path(path)
    limits.check_regular_file(p)
    columns: dict[str, list[float]] = {k: [] for k in (*TEXT_KEYS, "stamp", "line")}
    current: dict[str, float] = {}
    at: dict[str, int] = {}  # the line of each value of the current message
    start_line = 1

    def flush() -> None:
        if not current:
            return
        missing = [k for k in (*TEXT_KEYS, *STAMP_KEYS) if k not in current]
        if missing:
            names = ", ".join(f"header.stamp.{k}" if k in STAMP_KEYS else k for k in missing)
            raise DataFileError(p, f"message has no {names}", start_line)
        far = float(np.sqrt(current["x"] ** 2 + current["y"] ** 2 + current["z"] ** 2))
        if far > MAX_RANGE_M:
            raise DataFileError(
                p,
                f"point at {far:.2f} m is beyond the sensor's maximum range {MAX_RANGE_M:.2f} m",
                start_line,
            )
        pid = current["point_id"]
        if pid != 0 and columns["point_id"] and pid <= columns["point_id"][-1]:
            raise DataFileError(
                p,
                f"point_id {pid:g} after {columns['point_id'][-1]:g}: point numbers rise within "
                "a frame, and a frame starts at point_id 0",
                at["point_id"],
            )
        stamp = current["secs"] + 1e-9 * current["nsecs"]
        if columns["stamp"] and stamp < columns["stamp"][-1]:
            raise DataFileError(
                p,
                f"time stamp {stamp:.9f} s is earlier than the previous message's "
                f"({columns['stamp'][-1]:.9f} s): the messages are out of order",
                at["secs"],
            )
        for k in TEXT_KEYS:
            columns[k].append(current[k])
        columns["stamp"].append(stamp)
        columns["line"].append(at["point_id"])
        current.clear()

    try:
        with _open_text(p) as fh:
            line_no = 0
            in_stamp = False
            for line_no, line in enumerate(fh, start=1):
                if "\0" in line:
                    raise DataFileError(p, "binary data (a NUL byte): not rostopic text", line_no)
                if line.startswith("---"):
                    flush()
                    start_line = line_no + 1
                    continue
                if ":" not in line:
                    continue  # blank lines
                key, _, value = line.partition(":")
                nested = line[:1] in (" ", "\t")
                key = key.strip()
                if nested:
                    if key == "stamp":
                        in_stamp = True
                        continue
                    if not (in_stamp and key in STAMP_KEYS):
                        continue  # seq, frame_id
                else:
                    in_stamp = False
                    if key not in TEXT_KEYS:
                        continue  # header, range, doppler_bin, bearing
                try:
                    number = float(value)
                except ValueError:
                    raise DataFileError(
                        p, f"{key}: not a number: {value.strip()!r}", line_no
                    ) from None
                problem = _problem(key, number)
                if problem is not None:
                    raise DataFileError(p, problem, line_no)
                if key in current:
                    raise DataFileError(
                        p,
                        f"{key} given twice in one message (first on line {at[key]}): is the "
                        "'---' line between two messages missing?",
                        line_no,
                    )
                current[key] = number
                at[key] = line_no
            flush()
    except OSError as exc:
        raise DataFileError(p, f"cannot read: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise DataFileError(p, f"not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    except (EOFError, gzip.BadGzipFile, zlib.error) as exc:
        raise DataFileError(p, f"the gzip data is truncated or damaged ({exc})") from None
    if not columns["point_id"]:
        raise DataFileError(p, "no point messages (expected rostopic text of RadarScan)")
    stamps = np.asarray(columns["stamp"])
    if stamps[-1] - stamps[0] > limits.MAX_DURATION_S:
        raise DataFileError(
            p,
            f"the time stamps span {stamps[-1] - stamps[0]:.0f} s, more than the "
            f"{limits.MAX_DURATION_S:g} s a recording may last",
        )
    if stamps[-1] == stamps[0]:
        raise DataFileError(
            p,
            f"all {stamps.size} messages have the same time stamp: a recording needs at least "
            "two distinct time stamps",
        )
    return {k: np.asarray(v, dtype=np.float64) for k, v in columns.items()}


def _cloud(
    frame: NDArray[np.int64],
    x: NDArray[Any],
    y: NDArray[Any],
    z: NDArray[Any],
    range_rate: NDArray[Any],
    intensity: NDArray[Any],
    frame_period: float,
) -> PointCloud:
    positions = np.column_stack([-np.asarray(y), x, z]).astype(np.float64)  # ROS -> sensor
    return PointCloud(
        frame.astype(np.int64),
        positions,
        range_rate_to_approaching(range_rate),
        np.asarray(intensity, dtype=np.float64),
        frame_period,
        int(frame.max()) + 1 if frame.size else 1,
    )


def _check_frames(
    path: Path, n_frames: int, frame_period: float, where: str, line: int | None = None
) -> None:
    """A recording holds at least two frames (two distinct frame times), and its frames fit
    within :data:`limits.MAX_DURATION_S` (no more frames are allocated than that)."""
    if n_frames < 2:
        raise DataFileError(
            path,
            f"{where}only {n_frames} frame(s): a recording needs at least two (two distinct "
            "frame times)",
            line,
        )
    if (n_frames - 1) * frame_period > limits.MAX_DURATION_S:
        raise DataFileError(
            path,
            f"{where}frame {n_frames - 1} at {frame_period:g} s per frame is beyond the "
            f"{limits.MAX_DURATION_S:g} s a recording may last",
            line,
        )


def text_recording(path: str | Path, frame_period: float = FRAME_PERIOD_S) -> PointCloud:
    """The point cloud of one rostopic text file (frames from ``point_id`` = 0)."""
    p = Path(path)
    cols = read_rostopic_text(p)
    ids = cols["point_id"]
    if ids[0] != 0:
        line = int(cols["line"][0])
        raise DataFileError(p, f"the first message has point_id {ids[0]:g}, not 0", line)
    frame = frames_from_point_ids(ids.astype(np.int64))
    _check_frames(p, int(frame[-1]) + 1, frame_period, "")
    return _cloud(
        frame, cols["x"], cols["y"], cols["z"], cols["velocity"], cols["intensity"], frame_period
    )


def _npz_members(path: Path) -> None:
    """Check every array's declared shape and type against the bytes the NPZ holds, before
    :func:`numpy.load` allocates anything (a damaged or crafted file can declare any size)."""
    limits.check_regular_file(path)
    try:
        with zipfile.ZipFile(path) as archive:
            infos = {i.filename: i for i in archive.infolist()}
            missing = [k for k in NPZ_KEYS if f"{k}.npy" not in infos]
            if missing:
                raise DataFileError(path, f"missing arrays: {', '.join(missing)}")
            for key in NPZ_KEYS:
                info = infos[f"{key}.npy"]
                with archive.open(info) as member:
                    version = np.lib.format.read_magic(member)
                    if version == (1, 0):
                        shape, _, dtype = np.lib.format.read_array_header_1_0(member)
                    elif version == (2, 0):
                        shape, _, dtype = np.lib.format.read_array_header_2_0(member)
                    else:
                        raise DataFileError(path, f"{key}: .npy format {version} is not read")
                    header = member.tell()
                n = int(np.prod(shape)) if len(shape) else 1
                if n > limits.MAX_FRAMES:
                    raise DataFileError(
                        path, f"{key} declares {n:,} values, more than {limits.MAX_FRAMES:,}"
                    )
                kinds, wanted = _NPZ_KINDS.get(key, ("iuf", "numbers"))
                if dtype.hasobject or dtype.kind not in kinds:
                    raise DataFileError(path, f"{key} holds {dtype} values, not {wanted}")
                if n * dtype.itemsize != info.file_size - header:
                    raise DataFileError(
                        path,
                        f"{key} declares {n:,} values of {dtype.itemsize} bytes but holds "
                        f"{info.file_size - header:,} bytes: the file is truncated or damaged",
                    )
    except (zipfile.BadZipFile, zlib.error, EOFError, ValueError) as exc:
        raise DataFileError(path, f"not a readable NPZ file: {exc}") from None


def _check_npz_values(path: Path, arrays: dict[str, NDArray[Any]], n_files: int) -> None:
    """Every point's values finite and within the sensor's range; file indices and frames whole
    numbers within range. The error names the array and the row."""
    for key in ("x", "y", "z", "velocity", "intensity"):
        values = np.asarray(arrays[key], dtype=np.float64)
        lo, hi, _ = _BOUNDS[key]
        with np.errstate(invalid="ignore"):
            bad = ~((values >= lo - _TOLERANCE) & (values <= hi + _TOLERANCE))
        if bad.any():
            row = int(np.argmax(bad))
            raise DataFileError(path, f"{key}[{row}]: {_problem(key, float(values[row]))}")
    far = np.sqrt(arrays["x"].astype(np.float64) ** 2 + arrays["y"] ** 2 + arrays["z"] ** 2)
    if far.size and far.max() > MAX_RANGE_M:
        row = int(np.argmax(far > MAX_RANGE_M))
        raise DataFileError(
            path,
            f"point {row} at {far[row]:.2f} m is beyond the sensor's maximum range "
            f"{MAX_RANGE_M:.2f} m",
        )
    index = arrays["file_index"]
    outside = (index < 0) | (index >= n_files)
    if outside.any():
        row = int(np.argmax(outside))
        raise DataFileError(
            path, f"file_index[{row}] = {index[row]} does not name one of the {n_files} files"
        )
    frame = arrays["frame"]
    if frame.size and frame.min() < 0:
        row = int(np.argmax(frame < 0))
        raise DataFileError(path, f"frame[{row}] = {frame[row]} is negative")


def npz_recordings(
    path: str | Path, frame_period: float = FRAME_PERIOD_S, names: list[str] | None = None
) -> list[tuple[str, PointCloud]]:
    """The recordings of a compact NPZ file, in the order of its ``files`` (or of ``names``).

    Before anything is allocated, every array's declared size is checked against the bytes in
    the file; then every value against the sensor's range (as for text files), and every
    recording for whole, ascending frames from 0 (at least two, within a day of frames)."""
    p = Path(path)
    _npz_members(p)
    try:
        with np.load(p, allow_pickle=False) as data:
            arrays = {k: data[k] for k in NPZ_KEYS}
    except (OSError, ValueError, zipfile.BadZipFile, zlib.error, EOFError) as exc:
        raise DataFileError(p, f"not a readable NPZ file: {exc}") from None
    files = [str(f) for f in arrays["files"]]
    n = arrays["file_index"].shape[0]
    for key in NPZ_KEYS[1:]:
        if arrays[key].shape != (n,):
            raise DataFileError(p, f"{key} must have one value per point ({n})")
    if arrays["files"].ndim != 1:
        raise DataFileError(p, "files must be a list of recording names")
    _check_npz_values(p, arrays, len(files))
    wanted = names if names is not None else files
    unknown = [w for w in wanted if w not in files]
    if unknown:
        raise DataFileError(p, f"no recording named {unknown[0]!r} (it has {len(files)})")
    out = []
    for name in wanted:
        sel = arrays["file_index"] == files.index(name)
        frame = arrays["frame"][sel].astype(np.int64)
        where = f"recording {name!r}: "
        if np.any(np.diff(frame) < 0):
            raise DataFileError(p, f"{where}frames must be ascending from 0")
        _check_frames(p, int(frame.max()) + 1 if frame.size else 0, frame_period, where)
        cloud = _cloud(
            frame,
            arrays["x"][sel],
            arrays["y"][sel],
            arrays["z"][sel],
            arrays["velocity"][sel],
            arrays["intensity"][sel],
            frame_period,
        )
        out.append((name, cloud))
    return out


class RadharSource(RecordingSource):
    """RadHAR point clouds of a TI IWR1443 radar (rostopic text, .txt.gz or compact NPZ)."""

    name = "radhar"

    class Config(PluginConfig):
        """Config of the ``radhar`` recording source."""

        kind: Literal["radhar"] = "radhar"
        file: DataPath = Field(description="A rostopic text file (.txt, .txt.gz) or an NPZ.")
        recordings: list[str] | None = Field(
            None, min_length=1, description="NPZ only: the recordings to read; default: all."
        )
        frame_period: float = Field(
            FRAME_PERIOD_S,
            ge=1.0 / limits.MAX_FRAME_RATE_HZ,
            le=1.0 / limits.MIN_FRAME_RATE_HZ,
            description="Sensor frame period [s] (frame k at k x this).",
        )

    config: Config

    def load(self) -> list[Recording]:
        """The named recordings; velocities converted to positive approaching."""
        cfg = self.config
        path = Path(cfg.file)
        meta = {
            "source": "radhar",
            "file": str(path),
            "sensor": SENSOR,
            "licence": "BSD-3-Clause",
            "citation": CITATION,
        }
        if path.suffix == ".npz":
            pairs = npz_recordings(path, cfg.frame_period, cfg.recordings)
        else:
            if cfg.recordings is not None:
                raise DataFileError(path, "`recordings` applies to NPZ files only")
            name = path.name.removesuffix(".gz")
            pairs = [(name, text_recording(path, cfg.frame_period))]
        return [Recording(name, cloud, {**meta, "recording": name}) for name, cloud in pairs]
