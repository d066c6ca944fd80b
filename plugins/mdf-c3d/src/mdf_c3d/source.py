"""The ``c3d`` motion source: a C3D marker file mapped onto the canonical 17-joint body.

Units from the file's ``POINT:UNITS`` (or ``unit_m``), frame rate from its header (or
``frame_rate``), axes as the file's (C3D labs are usually z up; ``axes`` reorients), canonical
joints as means of markers (:mod:`mdf_c3d.markersets`, or ``marker_map``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import Field, model_validator

from mdframework import (
    CANONICAL_JOINTS,
    DataFileError,
    DataPath,
    Motion,
    MotionConfig,
    MotionSource,
    Skeleton,
    limits,
)
from mdframework.settings import FrameRate
from mdframework.skeleton import check_axes, check_canonical_keys, group_means, reorient

Axis = Literal["x", "y", "z", "-x", "-y", "-z"]


class C3dConfig(MotionConfig):
    """A C3D marker file (Vicon, Qualisys, Motion Analysis, ...), mapped onto the body."""

    kind: Literal["c3d"] = Field("c3d", description="Selects this source: 'c3d'.")
    file: DataPath = Field(description="The .c3d file; relative to the config file's folder.")
    marker_set: Literal["auto", "plug-in-gait", "cmu"] = Field(
        "auto",
        description="Marker names: auto (detected from the labels), plug-in-gait or cmu.",
    )
    marker_map: dict[str, str | list[str]] | None = Field(
        None,
        description="Canonical joint -> marker or markers to average (e.g. {l_knee = "
        "['LKNE', 'LMKNE']}): overrides the set's, or maps all 17 joints of another set.",
    )
    unit_m: float | None = Field(
        None, gt=0, le=1000, description="Metres per file unit; default: from POINT:UNITS."
    )
    frame_rate: FrameRate | None = Field(
        None, description="Capture rate [Hz]; default: the file header's."
    )
    axes: tuple[Axis, Axis, Axis] = Field(
        ("x", "y", "z"),
        description="The file axis (with sign) that becomes x (forward), y (left) and z (up).",
    )
    activity: str = Field("unknown", description="Activity label recorded in the metadata.")
    subject: str | None = Field(
        None, description="Subject id for the metadata; default: the file's SUBJECTS:NAMES."
    )

    @model_validator(mode="after")
    def _check(self) -> C3dConfig:
        if Path(self.file).suffix.lower() != ".c3d":
            raise ValueError(f"file must be a .c3d file, got {Path(self.file).name!r}")
        check_canonical_keys(self.marker_map, "marker_map")
        check_axes(self.axes)
        return self


class C3dSource(MotionSource):
    """A C3D marker file as the canonical 17-joint body, in metres, z up."""

    name = "c3d"
    Config = C3dConfig
    config: C3dConfig

    def load(self) -> Motion:
        """Read the file and average markers into joints.

        Returns
        -------
        Motion
            ``skeleton``: time (n_frames,) [s] from 0 at the header's rate; positions
            (n_frames, 17, 3) [m] of the canonical joints (each the mean of its markers, NaN
            and invalid where one of them is not seen). ``metadata``: source, format, file,
            subject, activity, frame_rate_hz and frame_rate_from, units, unit_m, marker_set,
            markers (joint -> markers), n_frames, first_frame, software, events.

        Raises
        ------
        mdframework.DataFileError
            Malformed file (see :func:`mdf_c3d.read_c3d`); markers that do not make the body
            (the message lists the file's markers and what is missing).
        """
        from .markersets import MarkerMismatch, detect_marker_set, user_groups
        from .reader import read_c3d

        c = self.config
        path = Path(c.file)
        data = read_c3d(path, c.unit_m)
        try:
            set_name, mapping = detect_marker_set(
                data.labels, user_groups(c.marker_map or {}), c.marker_set
            )
        except MarkerMismatch as exc:
            raise DataFileError(path, str(exc)) from None
        try:
            means, valid = group_means(data.positions, data.labels, mapping)
        except KeyError as exc:  # pragma: no cover - resolve() only maps present labels
            raise DataFileError(path, f"marker(s) {exc} not in the file") from None
        unit_m = data.unit_m
        pos = reorient(means * unit_m, c.axes)
        if valid.any(axis=1).sum() < 2:
            raise DataFileError(
                path, "fewer than two frames where any mapped marker is seen: nothing to move"
            )
        rate = float(c.frame_rate) if c.frame_rate is not None else data.rate_hz
        time = np.arange(pos.shape[0], dtype=np.float64) / rate
        limits.check_time_stamps(path, time)
        limits.check_values(
            path, pos, limits.MAX_COORDINATE_M, "a joint coordinate", unit=" m", allow_nan=True
        )
        meta: dict[str, Any] = {
            "source": "c3d",
            "format": "c3d",
            "file": path.name,
            "subject": c.subject if c.subject is not None else data.subject,
            "activity": c.activity,
            "frame_rate_hz": rate,
            "frame_rate_from": "config" if c.frame_rate is not None else "header",
            "units": data.units,
            "unit_m": unit_m,
            "unit_from": "config" if c.unit_m is not None else "POINT:UNITS",
            "axes": list(c.axes),
            "marker_set": set_name,
            "markers": {j: list(m) for j, m in mapping.items()},
            "n_frames": int(pos.shape[0]),
            "first_frame": data.first_frame,
            "software": data.software,
            "events": len(data.events),
        }
        skeleton = Skeleton(time, np.where(valid[..., None], pos, np.nan), CANONICAL_JOINTS, valid)
        return Motion(skeleton, meta, {j: j for j in CANONICAL_JOINTS})
