"""The ``table`` motion source: a plain joint-track table mapped onto the canonical body.

Layout, time base and missing values as :mod:`mdf_table.reader` describes; units from
``units`` (or ``unit_m``); axes from ``axes``; the canonical joints from a joint set
(``canonical``: the 17 names themselves; ``kinect-v1``/``kinect-v2``: Kinect SDK names;
``auto``: the set matching most names) completed or overridden by ``joint_map``, where a joint
may be the mean of several file joints or markers.
"""

from __future__ import annotations

import dataclasses
from collections import Counter
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, model_validator

from mdframework import (
    CANONICAL_JOINTS,
    DataFileError,
    DataPath,
    Motion,
    MotionSource,
    Skeleton,
    limits,
)
from mdframework.settings import FrameRate, MotionAxes, OrientedMotionConfig
from mdframework.skeleton import check_canonical_keys, group_means, reorient

#: A value of a time column in its own unit (frame numbers, milliseconds, seconds); in seconds
#: it must lie within +-``limits.MAX_CLOCK_TIME_S``, as the column's times do (checked with the
#: unit, by :class:`TableConfig`; the bound here only keeps it a number of reasonable size).
ColumnTime = Annotated[float, Field(ge=-1e16, le=1e16)]

#: Metres per unit of ``units``.
UNITS_M = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254, "ft": 0.3048}


class TableConfig(OrientedMotionConfig):
    """A plain joint-track table (CSV, TSV, whitespace text or NPZ; long or wide form)."""

    kind: Literal["table"] = Field("table", description="Selects this source: 'table'.")
    file: DataPath = Field(
        description="The table (.csv, .tsv, .txt, .dat or .npz); relative to the config file."
    )
    layout: Literal["auto", "long", "wide"] = Field(
        "auto",
        description="long: a row per joint and frame (time, joint, x, y, z); wide: a row per "
        "frame (time, <joint>_x, <joint>_y, <joint>_z, ...); auto: long when there is a joint "
        "column.",
    )
    delimiter: Literal["auto", ",", ";", "tab", "whitespace"] = Field(
        "auto", description="Field separator; auto: ',' for .csv, tab for .tsv, else blanks."
    )
    header: bool = Field(True, description="The first row names the columns.")
    columns: list[str] | None = Field(
        None, max_length=100_000, description="Column names of a file without a header row."
    )
    joints: list[str] | None = Field(
        None,
        max_length=10_000,
        description="Wide table without a header: the joints in column order after the time "
        "column, three columns (x, y, z) each.",
    )
    time_column: str = Field(
        "time", description="Column of the time stamps; '' for none (rows at frame_rate)."
    )
    time_unit_s: float = Field(
        1.0, gt=0, le=3600, description="Seconds per unit of the time column (0.001: ms)."
    )
    frame_rate: FrameRate | None = Field(
        None,
        description="The time column holds frame numbers at this rate [Hz] (or, with no time "
        "column, the rows are frames at this rate).",
    )
    time_range: tuple[ColumnTime, ColumnTime] | None = Field(
        None,
        description="Keep the frames whose time column lies in [first, last], in the column's "
        "own unit (e.g. frame numbers): a segment of a longer recording. Within "
        f"+-{limits.MAX_CLOCK_TIME_S:g} s once converted to seconds.",
    )
    joint_column: str = Field("joint", description="Long form: the column of joint names.")
    xyz: tuple[str, str, str] = Field(
        ("x", "y", "z"), description="Long form: the coordinate columns."
    )
    units: Literal["m", "cm", "mm", "in", "ft"] = Field("m", description="Length unit.")
    unit_m: float | None = Field(
        None, gt=0, le=1000, description="Metres per file unit (overrides units)."
    )
    axes: MotionAxes = Field(
        ("x", "y", "z"),
        description="The file axis (with sign) that becomes x (forward), y (left) and z (up); "
        "a Kinect camera table is ['z', 'x', 'y'].",
    )
    zero_is_missing: bool = Field(
        False, description="An exact (0, 0, 0) marks a joint as not tracked (Kinect exports)."
    )
    joint_set: Literal["auto", "canonical", "kinect-v1", "kinect-v2"] = Field(
        "auto", description="Names of the file's joints: canonical, kinect-v1, kinect-v2."
    )
    joint_map: dict[str, str | list[str]] | None = Field(
        None,
        description="Canonical joint -> file joint, or joints to average (e.g. {base = "
        "['LeftHip', 'RightHip']}); overrides or completes the joint set.",
    )
    activity: str = Field("unknown", description="Activity label recorded in the metadata.")
    subject: str | None = Field(None, description="Subject id for the metadata.")

    @model_validator(mode="after")
    def _check(self) -> TableConfig:
        suffix = Path(self.file).suffix.lower()
        if suffix not in (".csv", ".tsv", ".txt", ".dat", ".npz"):
            raise ValueError(
                f"file must be a .csv, .tsv, .txt, .dat or .npz table, got {Path(self.file).name!r}"
            )
        check_canonical_keys(self.joint_map, "joint_map")
        if self.time_column and self.frame_rate is not None and self.time_unit_s != 1.0:
            # frame_rate would win silently: milliseconds at 120 Hz read as frame numbers run
            # 8.3 times too slowly (the default 1 s per unit says nothing, and a dumped config
            # repeats it)
            raise ValueError(
                f"time_unit_s ({self.time_unit_s:g} s per unit) and frame_rate "
                f"({self.frame_rate:g} Hz: the time column holds frame numbers) both say how to "
                f"read the time column {self.time_column!r}: give one"
            )
        if self.time_range is not None:
            if self.time_range[0] > self.time_range[1]:
                raise ValueError(f"time_range: first {self.time_range[0]:g} is after last")
            per_unit = 1.0 / self.frame_rate if self.frame_rate is not None else self.time_unit_s
            far = max(abs(v) * per_unit for v in self.time_range)
            if far > limits.MAX_CLOCK_TIME_S:
                raise ValueError(
                    f"time_range: {far:g} s is beyond +-{limits.MAX_CLOCK_TIME_S:g} s (in the "
                    "time column's unit: time_unit_s, or frame numbers at frame_rate)"
                )
        for name in ("columns", "joints"):
            counts = Counter(getattr(self, name) or [])
            twice = sorted(n for n, k in counts.items() if k > 1)
            if twice:
                raise ValueError(f"{name}: {', '.join(map(repr, twice))} named twice")
        if not self.header and self.columns is None and self.joints is None:
            raise ValueError("a table without a header row needs columns or joints")
        return self


class TableSource(MotionSource):
    """A joint-track table as the canonical 17-joint body, in metres, z up."""

    name = "table"
    Config = TableConfig
    config: TableConfig

    def load(self) -> Motion:
        """Read the table and map its joints onto the canonical body.

        Returns
        -------
        Motion
            ``skeleton``: time (n_frames,) [s] from 0; positions (n_frames, 17, 3) [m] of the
            canonical joints (each the mean of its file joints; NaN and invalid where one is
            missing). ``metadata``: source, format, file, path, layout, subject, activity,
            frame_rate_hz (median), time_from, units, unit_m, axes, joint_set, joints
            (canonical -> file joints), n_frames, rows, frames_out_of_order,
            duplicate_frames_dropped.

        Raises
        ------
        mdframework.DataFileError
            A malformed table (see :func:`mdf_table.read_table`), or file joints that do not
            make the body (the message lists the file's joints and what is missing).
        """
        from .reader import TableLayout, canonical_groups, read_table

        c = self.config
        path = Path(c.file)
        spec = TableLayout(
            layout=c.layout,
            delimiter=c.delimiter,
            header=c.header,
            columns=tuple(c.columns) if c.columns is not None else None,
            joints=tuple(c.joints) if c.joints is not None else None,
            time_column=c.time_column,
            time_unit_s=c.time_unit_s,
            frame_rate=c.frame_rate,
            joint_column=c.joint_column,
            xyz=c.xyz,
        )
        table = read_table(path, spec)
        if c.time_range is not None:
            scale = 1.0 / c.frame_rate if c.frame_rate is not None else c.time_unit_s
            lo, hi = (v * scale for v in c.time_range)
            keep = (table.time >= lo - 1e-9) & (table.time <= hi + 1e-9)
            if keep.sum() < 2:
                raise DataFileError(
                    path,
                    f"motion.time_range {list(c.time_range)} holds {int(keep.sum())} frame(s); "
                    f"the file's times run {table.time[0] / scale:g}..{table.time[-1] / scale:g}",
                )
            table = dataclasses.replace(
                table, time=table.time[keep], positions=table.positions[keep]
            )
        user = {j: (m,) if isinstance(m, str) else tuple(m) for j, m in (c.joint_map or {}).items()}
        set_name, groups, missing = canonical_groups(table.names, c.joint_set, user)
        absent = sorted({n for g in groups.values() for n in g} - set(table.names))
        if missing or absent:
            what = (
                f"joint_map names joints not in the file: {', '.join(absent)}"
                if absent
                else f"the joint set {set_name!r} lacks {', '.join(missing)}"
            )
            raise DataFileError(
                path,
                f"{what}; the file's joints are {', '.join(table.names[:60])}; give "
                "motion.joint_map (canonical joint = file joint or list of joints to average)",
            )
        positions = table.positions
        valid = np.isfinite(positions).all(axis=2)
        if c.zero_is_missing:
            valid &= ~np.all(positions == 0.0, axis=2)
        means, ok = group_means(positions, table.names, groups, valid)
        unit_m = c.unit_m if c.unit_m is not None else UNITS_M[c.units]
        pos = reorient(means * unit_m, c.axes)
        if ok.any(axis=1).sum() < 2:
            raise DataFileError(path, "fewer than two frames with a tracked joint")
        time = table.time - table.time[0]
        limits.check_values(
            path, pos, limits.MAX_COORDINATE_M, "a joint coordinate", unit=" m", allow_nan=True
        )
        meta: dict[str, Any] = {
            "source": "table",
            "format": "npz" if path.suffix.lower() == ".npz" else "text table",
            "file": path.name,
            "path": str(path),
            "layout": table.layout,
            "subject": c.subject,
            "activity": c.activity,
            "frame_rate_hz": float(1.0 / np.median(np.diff(time))),
            "time_from": ("row order" if not c.time_column else f"column {c.time_column!r}")
            + (f" at {c.frame_rate:g} frames/s" if c.frame_rate is not None else ""),
            "units": c.units if c.unit_m is None else "config unit_m",
            "unit_m": unit_m,
            "axes": list(c.axes),
            "joint_set": set_name,
            "joints": {j: list(g) for j, g in groups.items()},
            "n_frames": int(time.shape[0]),
            "rows": table.rows,
            "time_range": list(c.time_range) if c.time_range is not None else None,
            "frames_out_of_order": table.out_of_order,
            "duplicate_frames_dropped": table.duplicates_dropped,
        }
        skeleton = Skeleton(time, np.where(ok[..., None], pos, np.nan), CANONICAL_JOINTS, ok)
        return Motion(skeleton, meta, {j: j for j in CANONICAL_JOINTS})
