"""BVH files from any rig: the ``bvh`` motion source and the loading shared with ``cmu``.

The rig is detected from the joint names (:mod:`mdf_cmu.rigs`) or named in the config
(``rig``), and a ``joint_map`` (canonical joint = file joint) overrides or completes it; a rig
that is neither known nor mapped stops with the file's joints and the nearest known rig.

Units: the rig's (CMU conversions: 1/0.45 inch; Mixamo and Biovision: centimetres) or the
config's ``unit_m`` (metres per file unit). Axes: BVH is y up; positions map as
(X, Y, Z)_file -> (Z, X, Y) metres, which puts a rig that faces +Z with its left at +X (all
four shipped rigs) facing +x with its left at +y; ``axes`` names other file axes (a z-up
export), as for the other sources (:func:`mdframework.skeleton.reorient`).

Frame rate, in order:

1. the config's ``frame_rate``;
2. for a file recognised as a CMU conversion (rig ``cmu-cgspeed`` or ``cmu-3dsmax``) whose
   file name gives a subject of CMU's index (``80_10.bvh``) whose header says cgspeed's
   120 Hz while CMU's index gives another rate (cgspeed wrote ``Frame Time: .0083333`` into
   every file, also for the subjects captured at 60 Hz): the index's rate, with a
   :class:`FrameRateWarning` naming both (``cmu_rate_correction = false`` turns this off); a
   header of any other rate (a trial resampled to 30 Hz) stands;
3. the header's ``Frame Time``: its inverse, rounded to a whole number of hertz when within
   0.05 % of one (headers write ``1 / rate`` to about six digits).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from pydantic import Field, model_validator

from mdframework import (
    CANONICAL_JOINTS,
    DataFileError,
    DataPath,
    Motion,
    MotionSource,
    Skeleton,
)
from mdframework.settings import FrameRate, MotionAxes, OrientedMotionConfig
from mdframework.skeleton import Axis, check_canonical_keys, reorient

if TYPE_CHECKING:
    from .rigs import Rig


class FrameRateWarning(UserWarning):
    """A file's own frame rate was replaced by a documented correction, or a file without one
    (AMC of an unknown subject) was given an assumed rate."""


#: The file axes that become the project's x (forward), y (left) and z (up): BVH is y up, and
#: every shipped rig faces +Z with its left at +X.
BVH_AXES: tuple[Axis, Axis, Axis] = ("z", "x", "y")

#: The rate cgspeed's conversions write into every header (``Frame Time: .0083333``), also for
#: the subjects CMU's index lists at 60 Hz: the only header :func:`choose_rate` corrects.
CGSPEED_HEADER_HZ = 120.0

RigName = Literal["auto", "cmu-cgspeed", "cmu-3dsmax", "mixamo", "biovision"]


def header_rate(frame_time: float) -> float:
    """``1 / frame_time`` [Hz], rounded to a whole number when within 0.05 % of one."""
    rate = 1.0 / frame_time
    whole = round(rate)
    return float(whole) if whole > 0 and abs(rate - whole) <= 5e-4 * rate else rate


def choose_rate(
    path: Path,
    frame_time: float,
    rig: Rig | None,
    *,
    config_rate: float | None,
    cmu_correction: bool,
    subject: int | None,
    trial: int | None,
) -> tuple[float, str]:
    """The frame rate [Hz] of a BVH file and where it came from (see the module docstring);
    warns (:class:`FrameRateWarning`) when CMU's index corrects the header."""
    from .source import CMU_SUBJECTS, subject_frame_rate

    if config_rate is not None:
        return float(config_rate), "config"
    rate = header_rate(frame_time)
    # only cgspeed's own header (120 Hz in every file) is known to be wrong; any other rate was
    # written by whatever resampled the trial (a 30 Hz re-export), and stands
    cgspeed_header = rate == CGSPEED_HEADER_HZ
    if (
        rig is not None
        and rig.cmu
        and cmu_correction
        and cgspeed_header
        and subject in CMU_SUBJECTS
    ):
        index = subject_frame_rate(subject, trial)
        if abs(index - rate) > 1e-3 * index:
            warnings.warn(
                f"{path}: its header says Frame Time {frame_time:g} s ({rate:.4g} Hz), known "
                f"to be wrong for CMU subject {subject}, captured at {index:g} Hz per CMU's "
                f"index; using {index:g} Hz (set motion.frame_rate to override, or "
                "motion.cmu_rate_correction = false to keep the header)",
                FrameRateWarning,
                stacklevel=4,
            )
            return index, "CMU index (header corrected)"
    return rate, "header"


def load_any_bvh(
    path: Path,
    *,
    rig_name: str = "auto",
    joint_map: dict[str, str] | None = None,
    unit_m: float | None = None,
    keep_first_frame: bool | None = None,
    axes: Sequence[str] = BVH_AXES,
) -> tuple[tuple[str, ...], np.ndarray, dict[str, str], dict[str, Any], Rig | None, float]:
    """Read a BVH file of any rig.

    Returns the joint names, positions (n_frames, n_joints, 3) float64 [m] in the project
    frame (``axes[i]`` the file axis that becomes project axis i, see
    :func:`mdframework.skeleton.reorient`; default BVH's y up, facing +Z), the canonical map,
    metadata, the rig (None when ``joint_map`` alone maps it) and the header's frame time [s].

    Raises
    ------
    mdframework.DataFileError
        Malformed file; no rig is recognised (none has a signature joint in the file and
        its other joints there or in ``joint_map``), or two are as likely, and no complete joint
        map is given (see :func:`mdf_cmu.rigs.detect_rig`); a mapped joint is not in the file.
    """
    # the BVH reader and the rigs are imported here: loading the plugin (every mdf command
    # loads every plugin) needs only the source classes
    from .bvh import bvh_forward_kinematics, read_bvh
    from .rigs import RIGS, RigMismatch, detect_rig, resolve

    bvh = read_bvh(path)
    names = bvh.joint_names
    rig: Rig | None = None
    mapping: dict[str, str] = {}
    if rig_name != "auto":
        rig = RIGS[rig_name]
        mapping, missing = resolve(rig, names)
        if missing and not set(m.split(" ")[0] for m in missing) <= set(joint_map or {}):
            raise DataFileError(
                path,
                f"motion.rig = {rig_name!r}, but the file lacks {', '.join(missing)}; "
                f"its joints are {', '.join(names)}",
            )
    elif not joint_map or set(joint_map) != set(CANONICAL_JOINTS):
        # detected; a partial user map completes the rig with most signature joints
        try:
            rig, mapping = detect_rig(names, joint_map or {})
        except RigMismatch as exc:
            raise DataFileError(path, str(exc)) from None
    if joint_map:
        for canon, joint in joint_map.items():
            if joint not in names:
                raise DataFileError(
                    path,
                    f"motion.joint_map: {canon} = {joint!r} is not a joint of this file; its "
                    f"joints are {', '.join(names)}",
                )
        mapping = {**mapping, **joint_map}
    drop_first = rig is not None and rig.added_first_frame
    if keep_first_frame is not None:
        drop_first = not keep_first_frame
    drop = 1 if drop_first else 0
    if bvh.n_frames - drop < 1:
        raise DataFileError(
            path,
            f"no frames left after dropping the added pose frame 0 ({bvh.n_frames} in the "
            "file); set keep_first_frame = true to keep it",
        )
    scale = unit_m if unit_m is not None else (rig.unit_m if rig is not None else None)
    if scale is None:
        raise DataFileError(path, "the file's unit is unknown: give motion.unit_m [m per unit]")
    pos = reorient(bvh_forward_kinematics(bvh, slice(drop, None)) * scale, axes)
    meta = {
        "rig": rig.name if rig is not None else "joint_map",
        "unit_m": scale,
        "unit_from": "config" if unit_m is not None else "rig",
        "bvh_frame_time_s": bvh.frame_time,
        "bvh_frames_in_file": bvh.n_frames,
        "frames_dropped_at_start": drop,
    }
    return names, pos, mapping, meta, rig, bvh.frame_time


class BvhConfig(OrientedMotionConfig):
    """A BVH file of any rig (CMU conversions, Mixamo, Biovision-named studio captures, or
    any rig with a joint map)."""

    kind: Literal["bvh"] = Field("bvh", description="Selects this source: 'bvh'.")
    file: DataPath = Field(description="The .bvh file; relative to the config file's folder.")
    rig: RigName = Field(
        "auto",
        description="Joint naming: auto (detected from the joint names), cmu-cgspeed, "
        "cmu-3dsmax, mixamo or biovision.",
    )
    joint_map: dict[str, str] | None = Field(
        None,
        description="Canonical joint -> file joint (e.g. {l_hand = 'LeftWrist'}): overrides "
        "the rig's, completes the recognised rig (the one with most signature joints in the "
        "file), or maps a rig that is not known (then all 17 canonical joints, and unit_m).",
    )
    unit_m: float | None = Field(
        None, gt=0, le=1000, description="Metres per file unit; default: the rig's."
    )
    frame_rate: FrameRate | None = Field(
        None,
        description="Capture rate [Hz]; default: the header's Frame Time (CMU conversions: "
        "corrected from CMU's index for subjects whose header is known to be wrong).",
    )
    cmu_rate_correction: bool = Field(
        True,
        description="CMU conversions: use CMU's index rate where the header is known to be "
        "wrong (with a warning naming both).",
    )
    keep_first_frame: bool | None = Field(
        None,
        description="Keep frame 0; default: dropped for the CMU conversions (an added pose), "
        "kept otherwise.",
    )
    axes: MotionAxes = Field(
        BVH_AXES,
        description="The file axis (with sign) that becomes x (forward), y (left) and z (up); "
        "default: BVH's y up with the subject facing +Z and its left at +X. A z-up file "
        "facing -Y: ['-y', 'x', 'z'].",
    )
    activity: str = Field("unknown", description="Activity label recorded in the metadata.")
    subject: str | None = Field(
        None,
        description="Subject id for the metadata; CMU conversions: default from the file "
        "name '<subject>_<trial>' (it selects CMU's index rate).",
    )

    @model_validator(mode="after")
    def _check(self) -> BvhConfig:
        if Path(self.file).suffix.lower() != ".bvh":
            raise ValueError(f"file must be a .bvh file, got {Path(self.file).name!r}")
        check_canonical_keys(self.joint_map, "joint_map")
        return self


class BvhSource(MotionSource):
    """A BVH file of any rig, in metres, z up, with the canonical 17-joint mapping."""

    name = "bvh"
    Config = BvhConfig
    config: BvhConfig

    def load(self) -> Motion:
        """Read the file, map its rig and run forward kinematics.

        Returns
        -------
        Motion
            ``skeleton``: time (n_frames,) [s] from 0; positions (n_frames, n_joints, 3) [m],
            z up; every joint and End Site (``<joint>_end``). ``metadata``: source, format,
            file, path, rig, unit_m, frame_rate_hz and frame_rate_from, subject, activity, the
            header's frame time.
        """
        from .source import ACKNOWLEDGEMENT, check_motion, parse_trial_name

        c = self.config
        path = Path(c.file)
        names, pos, mapping, meta, rig, frame_time = load_any_bvh(
            path,
            rig_name=c.rig,
            joint_map=c.joint_map,
            unit_m=c.unit_m,
            keep_first_frame=c.keep_first_frame,
            axes=c.axes,
        )
        subject: Any = c.subject
        trial = None
        if rig is not None and rig.cmu:
            s, trial = parse_trial_name(path)
            if subject is None:
                subject = s
            elif str(subject).isdigit():
                subject = int(subject)
        rate, rate_from = choose_rate(
            path,
            frame_time,
            rig,
            config_rate=c.frame_rate,
            cmu_correction=c.cmu_rate_correction,
            subject=subject if isinstance(subject, int) else None,
            trial=trial,
        )
        time = np.arange(pos.shape[0], dtype=np.float64) / rate
        check_motion(path, time, pos)
        meta.update(
            source="bvh",
            format="bvh",
            file=path.name,
            path=str(path),
            subject=subject,
            trial=trial,
            activity=c.activity,
            frame_rate_hz=rate,
            frame_rate_from=rate_from,
            n_frames=int(pos.shape[0]),
            units="m",
            axes=list(c.axes),
        )
        if rig is not None and rig.cmu:
            meta["acknowledgement"] = ACKNOWLEDGEMENT
        return Motion(Skeleton(time, pos, names), meta, mapping)
