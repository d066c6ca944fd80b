"""The ``kinect`` motion source: Kinect skeleton recordings (one ``kind`` with a ``format``).

Formats (:mod:`mdf_kinect.formats`, :mod:`mdf_kinect.nitefile`): ``utkinect``, ``msr-action3d``,
``precog`` (Kinect v1, 20 joints), ``nite`` (NiTE2, 15 joints, written by ``mdf capture``) and
``ntu`` (Kinect v2, 25 joints, NTU RGB+D ``.skeleton``).

Frames and units: the Kinect camera space (X to the sensor's left, Y up, Z away from the sensor)
becomes the project's frame by x = Z (distance from the sensor), y = X, z = Y; the sensor is at
x = y = 0. Heights are then shifted so that the floor is at z = 0: ``floor = "auto"`` takes the
floor at the 1st percentile of the lowest foot joint, a number gives the floor's Kinect Y [m];
the sensor's height above the floor (if it was level) is recorded as ``sensor_height_m``.

Canonical body: HipCenter -> base, ShoulderCenter (v2: SpineShoulder) -> neck,
Head, Shoulder/Elbow/Hand, Hip/Knee/Ankle, Foot -> toe; Spine and both wrists (v2 also the hand
tips, thumbs, SpineMid and Neck) are not used. NiTE: see :mod:`mdf_kinect.nitefile`.

Part of a recording: ``segment`` selects a labelled segment (UTKinect's ``actionLabel.txt``
actions such as ``walk``; PRECOG's action names such as ``right punch``), then ``start`` and
``duration`` cut a window from it. Times start at 0 at the first selected frame.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal

import numpy as np
from pydantic import Field, model_validator

from mdframework import (
    DataFileError,
    DataPath,
    Motion,
    MotionConfig,
    MotionSource,
    Skeleton,
    limits,
)
from mdframework.settings import FrameRate, Seconds

if TYPE_CHECKING:
    from .formats import Recording


class TrackingWarning(UserWarning):
    """A recording's frames before the tracker found the person were left out."""


#: A coordinate in the Kinect's camera space [m].
SensorCoordinate = Annotated[
    float, Field(ge=-limits.MAX_SENSOR_COORDINATE_M, le=limits.MAX_SENSOR_COORDINATE_M)
]

Format = Literal["utkinect", "msr-action3d", "precog", "nite", "ntu"]

#: MSR Action3D action numbers -> labels (the ones shipped, and the rest of the set).
MSR_ACTIONS: dict[int, str] = {
    1: "high arm wave", 2: "horizontal arm wave", 3: "hammer", 4: "hand catch",
    5: "forward punch", 6: "high throw", 7: "draw x", 8: "draw tick", 9: "draw circle",
    10: "hand clap", 11: "two hand wave", 12: "side-boxing", 13: "bend", 14: "forward kick",
    15: "side kick", 16: "jogging", 17: "tennis swing", 18: "tennis serve", 19: "golf swing",
    20: "pick up & throw",
}  # fmt: skip


class KinectConfig(MotionConfig):
    """A Kinect skeleton recording."""

    kind: Literal["kinect"] = Field("kinect", description="Selects this source: 'kinect'.")
    format: Format = Field(
        description="utkinect, msr-action3d, precog (Kinect v1, 20 joints), nite (mdf capture, "
        "15 joints) or ntu (NTU RGB+D .skeleton, Kinect v2, 25 joints)."
    )
    file: DataPath = Field(description="The recording, relative to the config file's folder.")
    start: Seconds = Field(
        0.0,
        description="Start of the window [s], from the first frame in which a joint is tracked "
        "(the frames before it are left out, with a warning), within a segment from its first "
        "tracked frame.",
    )
    segment: str | None = Field(
        None,
        description="A labelled segment: a UTKinect action (e.g. 'walk') or a PRECOG action "
        "(e.g. 'right punch'); start and duration then apply within it.",
    )
    labels: DataPath | None = Field(
        None, description="UTKinect: the actionLabel.txt file (default: next to the file)."
    )
    sequence: str | None = Field(
        None,
        description="UTKinect: the sequence in actionLabel.txt (default from the file "
        "name, joints_s01_e01.txt -> s01_e01).",
    )
    frame_rate: FrameRate | None = Field(
        None,
        description="Rate [Hz] for formats without time stamps (MSR 15, PRECOG 25, NTU 30 by "
        "default); for UTKinect, frame numbers per second (60 by default: two per 30 Hz "
        "frame); NiTE files carry their own time stamps.",
    )
    floor: Literal["auto"] | SensorCoordinate = Field(
        "auto",
        description="Floor height in the Kinect's Y [m], or 'auto' (1st percentile of the "
        "lowest foot joint); the floor becomes z = 0.",
    )
    activity: str | None = Field(None, description="Activity label for the metadata.")
    foot_length: float = Field(
        0.2,
        gt=0,
        le=0.5,
        description="NiTE: distance of the derived toe point ahead of the foot [m].",
    )
    min_confidence: float = Field(
        0.5, ge=0, le=1, description="NiTE: joints below this position confidence are gaps."
    )
    min_tracking: int = Field(
        1,
        ge=0,
        le=2,
        description="NTU: joints below this trackingState (1 inferred, 2 tracked) are gaps.",
    )

    body: int | None = Field(
        None,
        ge=1,
        le=limits.MAX_FRAMES,
        description="NTU: the body to read, numbered 1, 2, ... in the order the file first "
        "shows them; default: the one in most frames (with a warning when there are several).",
    )

    @model_validator(mode="after")
    def _check(self) -> KinectConfig:
        if self.segment is not None and self.format not in ("utkinect", "precog"):
            raise ValueError("segment applies to the utkinect and precog formats only")
        if (self.labels is not None or self.sequence is not None) and self.format != "utkinect":
            raise ValueError("labels and sequence apply to the utkinect format only")
        if self.body is not None and self.format != "ntu":
            raise ValueError("body applies to the ntu format only")
        if self.frame_rate is not None and self.format == "nite":
            raise ValueError("NiTE recordings carry their own time stamps; frame_rate is unused")
        return self


class KinectSource(MotionSource):
    """Kinect skeleton recordings (UTKinect, MSR Action3D, PRECOG, NiTE2, NTU RGB+D)."""

    name = "kinect"
    Config = KinectConfig
    config: KinectConfig

    def read(self) -> Recording:
        """The recording in Kinect axes, before segment selection."""
        # the readers when used (loading the plugin needs only the source classes)
        from .formats import (
            MSR_RATE_HZ,
            NTU_RATE_HZ,
            PRECOG_RATE_HZ,
            UTKINECT_RATE_HZ,
            read_msr,
            read_ntu,
            read_precog,
            read_utkinect,
        )
        from .nitefile import read_nite

        c = self.config
        path = Path(c.file)
        if c.format == "utkinect":
            return read_utkinect(path, c.frame_rate or UTKINECT_RATE_HZ)
        if c.format == "msr-action3d":
            return read_msr(path, c.frame_rate or MSR_RATE_HZ)
        if c.format == "precog":
            return read_precog(path, c.frame_rate or PRECOG_RATE_HZ)
        if c.format == "ntu":
            return read_ntu(path, c.frame_rate or NTU_RATE_HZ, c.min_tracking, c.body)
        return read_nite(path, c.foot_length, c.min_confidence)

    def load(self) -> Motion:
        """Read the recording, select the segment, convert to the project frame.

        Returns
        -------
        Motion
            ``skeleton``: time (n,) [s] from 0; positions (n, n_joints, 3) [m], z up, floor at
            z = 0, sensor at x = y = 0; ``valid`` from the format's tracking information.
            ``canonical_map``: the 17 canonical joints. ``metadata``: source, format, file, path,
            activity, frame rate, frames, segment, floor and sensor height, format details.

        Raises
        ------
        mdframework.DataFileError
            Malformed file, or an unknown segment (names the file and line).
        """
        from .formats import to_project_frame

        c = self.config
        path = Path(c.file)
        rec = self.read()
        meta: dict[str, Any] = {
            "source": "kinect",
            "file": path.name,
            "path": str(path),
            **rec.metadata,
        }
        keep = np.ones(rec.time.shape, dtype=bool)
        if c.segment is not None:
            first, last = self._segment(rec, path)
            keep = (rec.frame_numbers >= first) & (rec.frame_numbers <= last)
            if keep.sum() < 2:
                raise DataFileError(
                    path,
                    f"segment {c.segment!r} (frames {first}..{last}) holds < 2 frames of this "
                    "recording: check its labels against the file",
                )
            meta["segment"] = {"label": c.segment, "first_frame": first, "last_frame": last}
            kept = int(rec.frame_numbers[keep][0])
            # the file's untracked first frames (left out) reach into the segment
            if (
                rec.metadata.get("untracked_frames_leading", 0)
                and int(rec.frame_numbers[0]) > first
            ):
                warnings.warn(
                    f"{path}: segment {c.segment!r} starts at frame {first}, but its first "
                    f"tracked frame is {kept}: time 0 (what motion.start counts from) is that "
                    "frame",
                    TrackingWarning,
                    stacklevel=2,
                )
        t = rec.time[keep]
        pos = to_project_frame(rec.positions[keep])
        valid = rec.valid[keep]
        floor_from = "config"
        if c.floor == "auto":
            feet = [rec.joint_names.index(rec.canonical_map[k]) for k in ("l_toe", "r_toe")]
            fz = np.where(valid[:, feet], pos[:, feet, 2], np.inf).min(axis=1)
            fz = fz[np.isfinite(fz)]
            if fz.size == 0:
                raise DataFileError(path, "no tracked foot joint: the floor cannot be found")
            floor = float(np.percentile(fz, 1.0))
            floor_from = "1st percentile of the lowest foot joint"
        else:
            floor = float(c.floor)
        pos = pos.copy()
        pos[..., 2] -= floor
        pos[~valid] = np.nan
        who = re.search(r"_s(\d+)_e(\d+)", path.stem)  # UTKinect and MSR: ..._s01_e02
        meta.update(
            activity=c.activity or self._activity(path),
            subject=f"s{who.group(1)}" if who else None,
            episode=int(who.group(2)) if who else None,
            n_frames=int(t.shape[0]),
            time_offset_s=float(t[0]),
            floor_kinect_y_m=floor,
            floor_from=floor_from,
            sensor_height_m=-floor,
            untracked_samples=int((~valid).sum()),
            units="m",
            axes="x = Kinect Z (away from the sensor), y = Kinect X, z = Kinect Y (up)",
        )
        leading = int(rec.metadata.get("untracked_frames_leading", 0))
        if leading and c.segment is None:
            warnings.warn(
                f"{path}: its first {leading} frame(s) track no body and are left out, so time "
                f"0 (what motion.start counts from) is its first tracked frame, "
                f"{rec.metadata['first_tracked_s']:.3f} s into the file",
                TrackingWarning,
                stacklevel=2,
            )
        skeleton = Skeleton(t - t[0], pos, rec.joint_names, valid)
        return Motion(skeleton, meta, dict(rec.canonical_map))

    def _segment(self, rec: Recording, path: Path) -> tuple[int, int]:
        c = self.config
        assert c.segment is not None
        if c.format == "precog":
            if c.segment not in rec.segments:
                raise DataFileError(
                    path, f"no segment {c.segment!r}; this file has {sorted(rec.segments)}"
                )
            return rec.segments[c.segment]
        labels = Path(c.labels) if c.labels is not None else path.with_name("actionLabel.txt")
        if not labels.exists():
            raise DataFileError(path, f"segment {c.segment!r}: no label file {labels}")
        from .formats import read_utkinect_labels

        table = read_utkinect_labels(labels)
        seq = c.sequence
        if seq is None:
            m = re.search(r"(s\d+_e\d+)", path.name)
            if m is None:
                raise DataFileError(path, "give motion.sequence (not in the file name)")
            seq = m.group(1)
        if seq not in table:
            raise DataFileError(labels, f"no sequence {seq!r}")
        if c.segment not in table[seq]:
            raise DataFileError(
                labels, f"sequence {seq} has no segment {c.segment!r}; it has {sorted(table[seq])}"
            )
        return table[seq][c.segment]

    def _activity(self, path: Path) -> str:
        c = self.config
        if c.segment is not None:
            return c.segment
        if c.format == "msr-action3d":
            m = re.match(r"a(\d+)_", path.name)
            if m:
                return MSR_ACTIONS.get(int(m.group(1)), "unknown")
        return "unknown"
