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
from mdframework.pointcloud import PointCloud, frames_from_point_ids, range_rate_to_approaching

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
NPZ_KEYS = ("files", "file_index", "frame", "x", "y", "z", "velocity", "intensity")


def _open_text(path: Path) -> io.TextIOBase:
    if path.suffix == ".gz":
        return io.TextIOWrapper(gzip.open(path, "rb"), encoding="utf-8")
    return path.open(encoding="utf-8")


def read_rostopic_text(path: str | Path) -> dict[str, NDArray[np.float64]]:
    """The points of a ``rostopic echo`` text file, in file order.

    Returns ``{key: (n_points,) float64}`` for every key of :data:`TEXT_KEYS`. A message without
    one of them, or with a value that is not a number, is a :class:`DataFileError` naming the
    file and the line.
    """
    p = Path(path)
    columns: dict[str, list[float]] = {k: [] for k in TEXT_KEYS}
    current: dict[str, float] = {}
    start_line = 1

    def flush(line_no: int) -> None:
        if not current:
            return
        missing = [k for k in TEXT_KEYS if k not in current]
        if missing:
            raise DataFileError(p, f"message has no {', '.join(missing)}", start_line)
        for k in TEXT_KEYS:
            columns[k].append(current[k])
        current.clear()

    try:
        with _open_text(p) as fh:
            line_no = 0
            for line_no, line in enumerate(fh, start=1):
                if line.startswith("---"):
                    flush(line_no)
                    start_line = line_no + 1
                    continue
                if line[:1] in (" ", "\t") or ":" not in line:
                    continue  # nested header fields, blank lines
                key, _, value = line.partition(":")
                if key in TEXT_KEYS:
                    try:
                        current[key] = float(value)
                    except ValueError:
                        raise DataFileError(
                            p, f"{key}: not a number: {value.strip()!r}", line_no
                        ) from None
            flush(line_no)
    except OSError as exc:
        raise DataFileError(p, f"cannot read: {exc.strerror or exc}") from None
    except (UnicodeDecodeError, EOFError, gzip.BadGzipFile) as exc:
        raise DataFileError(p, f"not a text file: {exc}") from None
    if not columns["point_id"]:
        raise DataFileError(p, "no point messages (expected rostopic text of RadarScan)")
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


def text_recording(path: str | Path, frame_period: float = FRAME_PERIOD_S) -> PointCloud:
    """The point cloud of one rostopic text file (frames from ``point_id`` = 0)."""
    p = Path(path)
    cols = read_rostopic_text(p)
    ids = cols["point_id"]
    if ids[0] != 0:
        raise DataFileError(p, f"the first message has point_id {ids[0]:g}, not 0", 1)
    frame = frames_from_point_ids(ids.astype(np.int64))
    return _cloud(
        frame, cols["x"], cols["y"], cols["z"], cols["velocity"], cols["intensity"], frame_period
    )


def npz_recordings(
    path: str | Path, frame_period: float = FRAME_PERIOD_S, names: list[str] | None = None
) -> list[tuple[str, PointCloud]]:
    """The recordings of a compact NPZ file, in the order of its ``files`` (or of ``names``)."""
    p = Path(path)
    try:
        with np.load(p, allow_pickle=False) as data:
            missing = [k for k in NPZ_KEYS if k not in data.files]
            if missing:
                raise DataFileError(p, f"missing arrays: {', '.join(missing)}")
            arrays = {k: data[k] for k in NPZ_KEYS}
    except (OSError, ValueError) as exc:
        raise DataFileError(p, f"not a readable NPZ file: {exc}") from None
    files = [str(f) for f in arrays["files"]]
    n = arrays["file_index"].shape[0]
    for key in NPZ_KEYS[1:]:
        if arrays[key].shape != (n,):
            raise DataFileError(p, f"{key} must have one value per point ({n})")
    wanted = names if names is not None else files
    unknown = [w for w in wanted if w not in files]
    if unknown:
        raise DataFileError(p, f"no recording named {unknown[0]!r} (it has {len(files)})")
    out = []
    for name in wanted:
        sel = arrays["file_index"] == files.index(name)
        frame = arrays["frame"][sel].astype(np.int64)
        if np.any(np.diff(frame) < 0) or (frame.size and frame.min() < 0):
            raise DataFileError(p, f"recording {name!r}: frames must be ascending from 0")
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
