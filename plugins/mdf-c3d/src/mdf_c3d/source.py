"""The ``c3d`` and ``trc`` motion sources: marker files mapped onto the canonical 17-joint body.

Units from the file (C3D ``POINT:UNITS``, TRC ``Units``; or ``unit_m``), frame rate from its
header (or ``frame_rate``), axes as the file's (``axes`` reorients: C3D labs are usually z up,
TRC files from OpenSim y up), canonical joints as means of markers (:mod:`mdf_c3d.markersets`,
or ``marker_map``).
"""

from __future__ import annotations

import warnings
from collections.abc import Collection
from itertools import chain
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import NDArray
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

MarkerSetName = Literal["auto", "plug-in-gait", "cmu", "opensim-gait", "keypoints"]


class MarkerFileConfig(OrientedMotionConfig):
    """Fields shared by the marker-file sources (``c3d``, ``trc``)."""

    file: DataPath = Field(description="The marker file; relative to the config file's folder.")
    marker_set: MarkerSetName = Field(
        "auto",
        description="Marker names: auto (detected from the labels), plug-in-gait, cmu, "
        "opensim-gait or keypoints (markerless: Pose2Sim's HALPE_26 or BODY_25 names).",
    )
    marker_map: dict[str, str | list[str]] | None = Field(
        None,
        description="Canonical joint -> marker or markers to average (e.g. {l_knee = "
        "['LKNE', 'LMKNE']}): overrides the set's, or maps all 17 joints of another set.",
    )
    unit_m: float | None = Field(
        None, gt=0, le=1000, description="Metres per file unit; default: from the file's units."
    )
    frame_rate: FrameRate | None = Field(
        None, description="Capture rate [Hz]; default: the file header's."
    )
    activity: str = Field("unknown", description="Activity label recorded in the metadata.")

    #: the file name's extension this source reads
    suffix: ClassVar[str] = ""

    @model_validator(mode="after")
    def _check_marker_file(self) -> MarkerFileConfig:
        if Path(self.file).suffix.lower() != self.suffix:
            raise ValueError(f"file must be a {self.suffix} file, got {Path(self.file).name!r}")
        check_canonical_keys(self.marker_map, "marker_map")
        return self


class C3dConfig(MarkerFileConfig):
    """A C3D marker file (Vicon, Qualisys, Motion Analysis, ...), mapped onto the body."""

    kind: Literal["c3d"] = Field("c3d", description="Selects this source: 'c3d'.")
    axes: MotionAxes = Field(
        ("x", "y", "z"),
        description="The file axis (with sign) that becomes x (forward), y (left) and z (up).",
    )
    subject: str | None = Field(
        None,
        description="Subject id for the metadata; default: the file's SUBJECTS:NAMES. In a "
        "file holding several subjects' markers (labels prefixed 'S1:', 'S2:'), the subject "
        "whose markers are read.",
    )

    suffix: ClassVar[str] = ".c3d"


class TrcConfig(MarkerFileConfig):
    """A TRC marker file (OpenSim's track-row-column text), mapped onto the body."""

    kind: Literal["trc"] = Field("trc", description="Selects this source: 'trc'.")
    axes: MotionAxes = Field(
        ("x", "-z", "y"),
        description="The file axis (with sign) that becomes x (forward), y (left) and z (up); "
        "default: OpenSim's lab frame (X forward, Y up, Z right).",
    )
    subject: str | None = Field(
        None,
        description="Subject id for the metadata. In a file holding several subjects' markers "
        "(labels prefixed 'S1:', 'S2:'), the subject whose markers are read.",
    )

    suffix: ClassVar[str] = ".trc"


def markers_motion(
    path: Path,
    config: C3dConfig | TrcConfig,
    labels: tuple[str, ...],
    positions: NDArray[np.float64],
    unit_m: float,
    rate: float,
    time: NDArray[np.float64],
    meta: dict[str, Any],
) -> Motion:
    """The canonical body from a marker file's tracks.

    ``positions`` (n_frames, n_markers, 3) in the file's unit (``unit_m`` metres each), NaN
    or exactly (0, 0, 0) where a marker is not seen (``zero_points`` in the metadata counts
    the latter); ``labels`` their names; ``rate`` [Hz] the frames' rate;
    ``time`` (n_frames,) float64 [s] from 0, each frame's time (not uniform where the file
    skips frames). The
    marker set is detected (or taken from ``config``), each canonical joint is the mean of its
    markers, the frame is turned by ``config.axes``. ``meta`` (the format's own entries) is
    completed with the marker set and the markers of each joint.

    Raises
    ------
    mdframework.DataFileError
        Markers that do not make the body (the message lists the file's markers and what is
        missing); several subjects' markers without ``config.subject`` choosing one (see
        :func:`subject_markers`); fewer than two frames with a marker seen; joints beyond the
        limits.
    """
    from .markersets import (
        MARKER_SETS,
        MarkerMismatch,
        detect_marker_set,
        strip_prefix,
        user_groups,
    )

    c = config
    groups = user_groups(c.marker_map or {})
    known = {m for mset in MARKER_SETS.values() for g in mset.joints.values() for m in chain(*g)}
    known |= {strip_prefix(m) for g in groups.values() for m in chain(*g)}
    keep = subject_markers(path, labels, c.subject, known)
    if keep is not None:
        labels = tuple(labels[i] for i in keep)
        positions = positions[:, keep]
    try:
        set_name, mapping = detect_marker_set(labels, groups, c.marker_set)
    except MarkerMismatch as exc:
        raise DataFileError(path, str(exc)) from None
    # a marker at exactly (0, 0, 0) is one not seen: writers that do not mark a gap otherwise
    # (a C3D point's residual -1, a TRC's empty fields) leave zeros, and a mean with the lab's
    # origin would throw the joint metres across the room for those frames
    zeros = np.all(positions == 0.0, axis=2)
    seen = np.isfinite(positions).all(2) & ~zeros  # (n_frames, n_markers)
    try:
        means, valid = group_means(positions, labels, mapping, seen)
    except KeyError as exc:  # pragma: no cover - resolve() only maps present labels
        raise DataFileError(path, f"marker(s) {exc} not in the file") from None
    pos = reorient(means * unit_m, c.axes)
    if valid.any(axis=1).sum() < 2:
        raise DataFileError(
            path, "fewer than two frames where any mapped marker is seen: nothing to move"
        )
    index = {lab: k for k, lab in enumerate(labels)}
    for k, (joint, members) in enumerate(mapping.items()):  # canonical order, as means
        if valid[:, k].sum() < 2:
            unseen = [m for m in members if seen[:, index[m]].sum() < 2]
            where = "fewer than two frames" if unseen else "fewer than two frames together"
            raise DataFileError(
                path,
                f"joint {joint} is seen in fewer than two frames: its marker(s) "
                f"{', '.join(unseen or members)} are seen in {where}; give motion.marker_map "
                f"for {joint} (markers of the file that are seen)",
            )
    limits.check_time_stamps(path, time)
    limits.check_values(
        path, pos, limits.MAX_COORDINATE_M, "a joint coordinate", unit=" m", allow_nan=True
    )
    meta = {
        **meta,
        "file": path.name,
        "path": str(path),
        "activity": c.activity,
        "frame_rate_hz": rate,
        "frame_rate_from": "config" if c.frame_rate is not None else "header",
        "unit_m": unit_m,
        "axes": list(c.axes),
        "marker_set": set_name,
        "markers": {j: list(m) for j, m in mapping.items()},
        "n_frames": int(pos.shape[0]),
        "zero_points": int(np.count_nonzero(zeros)),
    }
    skeleton = Skeleton(time, np.where(valid[..., None], pos, np.nan), CANONICAL_JOINTS, valid)
    return Motion(skeleton, meta, {j: j for j in CANONICAL_JOINTS})


def subject_markers(
    path: Path, labels: tuple[str, ...], subject: str | None, body_markers: Collection[str]
) -> list[int] | None:
    """The indices of the markers of ``subject`` when the labels carry the prefixes of more
    than one subject (``S1:LASI``, ``S2:LASI``: Vicon and Qualisys label each subject's markers
    so), else None (every marker is the one subject's). A prefix counts as a subject's when one
    of its markers is among ``body_markers`` (the names the marker sets and the marker map
    use), so the prefixes of props (``Box:Corner1``) do not.

    Raises
    ------
    mdframework.DataFileError
        Several subjects and ``subject`` not given, or not one of them (the message names them).
    """
    from .markersets import strip_prefix

    by_prefix: dict[str, list[int]] = {}
    for i, lab in enumerate(labels):
        if ":" in lab:
            by_prefix.setdefault(lab.rsplit(":", 1)[0], []).append(i)
    people = [
        prefix
        for prefix, members in by_prefix.items()
        if any(strip_prefix(labels[i]) in body_markers for i in members)
    ]
    if len(people) < 2:
        return None
    shown = ", ".join(people)
    if subject is None:
        raise DataFileError(
            path,
            f"the file holds the markers of {len(people)} subjects ({shown}): give "
            "motion.subject to choose whose markers to read",
        )
    if subject not in people:
        raise DataFileError(
            path,
            f"motion.subject {subject!r} is not one of the file's {len(people)} subjects ({shown})",
        )
    return by_prefix[subject]


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
            and invalid where one of them is not seen). ``metadata``: source, format, file, path,
            subject, activity, frame_rate_hz and frame_rate_from, units, unit_m, unit_from,
            axes, marker_set, markers (joint -> markers), n_frames, first_frame, software,
            events.

        Raises
        ------
        mdframework.DataFileError
            Malformed file (see :func:`mdf_c3d.read_c3d`); markers that do not make the body
            (see :func:`markers_motion`).
        """
        from .reader import read_c3d

        c = self.config
        path = Path(c.file)
        data = read_c3d(path, c.unit_m)
        meta: dict[str, Any] = {
            "source": "c3d",
            "format": "c3d",
            "subject": c.subject if c.subject is not None else data.subject,
            "units": data.units,
            "unit_from": "config" if c.unit_m is not None else "POINT:UNITS",
            "first_frame": data.first_frame,
            "software": data.software,
            "events": len(data.events),
        }
        rate = float(c.frame_rate) if c.frame_rate is not None else data.rate_hz
        time = np.arange(data.n_frames, dtype=np.float64) / rate
        return markers_motion(path, c, data.labels, data.positions, data.unit_m, rate, time, meta)


class TrcSource(MotionSource):
    """A TRC marker file as the canonical 17-joint body, in metres, z up."""

    name = "trc"
    Config = TrcConfig
    config: TrcConfig

    def load(self) -> Motion:
        """Read the file and average markers into joints.

        Returns
        -------
        Motion
            ``skeleton``: time (n_frames,) [s] ``(Frame# - first Frame#) / DataRate`` (or
            ``/ frame_rate``), so frames the file skips leave a gap in time; positions
            (n_frames, 17, 3) [m] of the canonical joints (each the mean of its markers, NaN and
            invalid where one of them is not seen). ``metadata``: source, format, file, path,
            subject, activity, frame_rate_hz and frame_rate_from, units, unit_m, unit_from, axes,
            marker_set, markers (joint -> markers), n_frames, first_frame (the first ``Frame#``),
            frames_skipped (frame numbers missing between the first and last), camera_rate_hz
            (``CameraRate``, when given).

        Raises
        ------
        mdframework.DataFileError
            Malformed file (see :func:`mdf_c3d.read_trc`); markers that do not make the body
            (see :func:`markers_motion`).
        """
        from .trc import read_trc

        c = self.config
        path = Path(c.file)
        data = read_trc(path, c.unit_m, c.frame_rate)
        camera = data.header.get("CameraRate")
        skipped = int(data.frames[-1] - data.frames[0] + 1 - data.n_frames)
        if skipped:
            k = int(np.argmax(np.diff(data.frames)))
            warnings.warn(
                f"{path}: Frame# skips {skipped} frame(s) (the longest gap "
                f"{data.time[k + 1] - data.time[k]:.4g} s, after Frame# {data.frames[k]} at "
                f"{data.time[k]:.4g} s): the time base keeps the gaps, and the motion is "
                "interpolated across them",
                stacklevel=2,
            )
        meta: dict[str, Any] = {
            "source": "trc",
            "format": "trc",
            "subject": c.subject,
            "units": data.units,
            "unit_from": "config" if c.unit_m is not None else "Units",
            "first_frame": int(data.frames[0]),
            "camera_rate_hz": _number(camera),
            # frames the file skips (Frame# steps over them): the time base keeps the gap
            "frames_skipped": skipped,
        }
        return markers_motion(
            path, c, data.labels, data.positions, data.unit_m, data.rate_hz, data.time, meta
        )


def _number(text: str | None) -> float | None:
    """A header value as a finite number, or None."""
    try:
        value = float(text) if text is not None else float("nan")
    except ValueError:
        return None
    return value if np.isfinite(value) else None
