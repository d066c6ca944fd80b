"""The ``cmu`` motion source: CMU Graphics Lab motion capture trials, BVH or ASF/AMC.

Reads a trial of the CMU Motion Capture Database (http://mocap.cs.cmu.edu) either in CMU's
original ASF/AMC format or in the widespread 'cgspeed' BVH conversion, runs forward kinematics
(:mod:`mdf_cmu.asfamc`, :mod:`mdf_cmu.bvh`) and returns the joints in metres, in the project's
right-handed z-up frame ((X, Y, Z)_cmu -> (Z, X, Y)), with time stamps ``frame / rate`` [s]
starting at 0.

Joints of the skeleton
----------------------
- ASF/AMC: ``root`` (the TX TY TZ position) and the end point of every bone, named by the bone
  (``lfemur`` is the knee, the end of the femur).
- BVH: every joint's origin, named as in the file, and every End Site, named ``<joint>_end``.

Canonical body (``canonical_map``)
----------------------------------
==========  ==========================  ===============================================
canonical   ASF/AMC joint (bone end)     BVH joint (cgspeed names)
==========  ==========================  ===============================================
base        ``root``                     ``Hips`` (the pelvis / hip centre)
neck        ``thorax`` (top of thorax,   ``Neck`` origin (the cgspeed skeleton starts its
            base of the lower neck)      neck, and the clavicles, at the top of the spine)
head        ``head`` (top of the head)   ``Head_end`` (End Site of Head: top of the head)
l_shoulder  ``lclavicle`` (clavicle end  ``LeftArm`` origin (the shoulder joint)
            = shoulder joint)
l_elbow     ``lhumerus``                 ``LeftForeArm``
l_hand      ``lradius`` (the wrist)      ``LeftHand`` (origin = the wrist)
l_hip       ``lhipjoint`` (= femur       ``LeftUpLeg`` (the hip joint, femur start)
            start, the hip joint)
l_knee      ``lfemur``                   ``LeftLeg``
l_ankle     ``ltibia``                   ``LeftFoot``
l_toe       ``ltoes`` (toe tip)          ``LeftToeBase_end`` (toe tip)
==========  ==========================  ===============================================

and the same with ``r``/``Right`` on the right. CMU's ``l``/``Left`` bones are the subject's left:
in the ASF rest pose the subject faces +Z_cmu with the left side at +X_cmu, which the axis mapping
turns into facing +x with the left at +y, as in the project's body axes; ``tests/test_cmu.py``
checks on real frames that the mapped left hip, shoulder and hand lie on the subject's left of the
facing direction given by the feet.

Frame rate
----------
ASF/AMC holds no rate: it comes from the subject and trial numbers in the file name
(``80_10.amc``: subject 80, trial 10) through :data:`SUBJECT_60HZ` and :data:`TRIAL_RATES`
(from CMU's index; its part that matters here is shipped as
``examples/data/cmu/cmu-index-rates.csv``), or from the config's ``frame_rate``; for a subject that
is not in CMU's index (or no subject) :data:`DEFAULT_RATE_HZ` is assumed, with a
:class:`~mdf_cmu.anybvh.FrameRateWarning` saying so. BVH: the header's
``Frame Time``, except that cgspeed wrote ``.0083333`` (120 Hz) into every file, also for the
subjects captured at 60 Hz: for those the index's rate is used, with a warning naming both
rates (:func:`mdf_cmu.anybvh.choose_rate`); ``frame_rate`` in the config wins over both.

BVH files of other rigs of the CMU database (cgspeed's 3ds Max-friendly conversion) are
recognised by their joint names (:mod:`mdf_cmu.rigs`). BVH frame 0 of the cgspeed files is an
added pose, not capture; it is dropped unless ``keep_first_frame`` is set.

An AMC file read with another subject's ASF (``80_10.amc`` with ``02.asf``) is an error: the
bone lengths would be the other subject's.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import Field, model_validator

from mdframework import (
    ConfigError,
    DataPath,
    Motion,
    MotionConfig,
    MotionSource,
    Skeleton,
    limits,
)
from mdframework.settings import FrameRate

from .anybvh import FrameRateWarning, choose_rate, load_any_bvh

#: CMU's requested acknowledgement, recorded in every motion's metadata.
ACKNOWLEDGEMENT = (
    "The data used in this project was obtained from mocap.cs.cmu.edu. "
    "The database was created with funding from NSF EIA-0196217."
)

#: Subjects captured at 60 Hz; every other subject at 120 Hz. From the ``framerate`` column of
#: CMU's index of its 2435 trials of 109 subjects, whose subject, trial and rate columns the
#: repository ships as ``examples/data/cmu/cmu-index-rates.csv`` (provenance beside it; the
#: tests check these tables against it). Subject 136 is not here: the index gives 120 Hz for
#: all of its trials except 136_19 (see :data:`TRIAL_RATES`).
SUBJECT_60HZ: frozenset[int] = frozenset({33, 34, 42, 60, 61, 62, 74, 75, 77, 79, 80, 87, 88, 89})

#: The subjects of CMU's index (``examples/data/cmu/cmu-index-rates.csv``): 109 numbers from 1
#: to 144.
CMU_SUBJECTS: frozenset[int] = frozenset(range(1, 145)) - frozenset(
    {4, 44, 48, 50, 51, 52, 53, 57, 58, 59, 65, 66, 67, 68, 71, 72, 73, 84, 92, 95, 96, 97}
    | {98, 99, 100, 101, 109, 110, 112, 116, 117, 119, 121, 129, 130}
)

#: Trials whose rate differs from their subject's (the index): (subject, trial) -> Hz.
TRIAL_RATES: dict[tuple[int, int], float] = {(136, 19): 60.0}

#: Default rate of the database [Hz].
DEFAULT_RATE_HZ = 120.0

#: Activity labels of the trials shipped in ``examples/data/cmu`` and a few more
#: (CMU index descriptions), by (subject, trial).
ACTIVITIES: dict[tuple[int, int], str] = {
    (2, 1): "walk",
    (35, 1): "walk",
    (16, 21): "walk",
    (9, 3): "run",
    (9, 6): "run",
    (13, 18): "boxing",
    (80, 10): "boxing",
    (13, 41): "jump",
    (131, 4): "start, hop, stop",
}

#: Canonical joint -> ASF/AMC joint (bone end points; see the module docstring).
ASF_CANONICAL_MAP: dict[str, str] = {
    "base": "root",
    "neck": "thorax",
    "head": "head",
    "l_shoulder": "lclavicle",
    "r_shoulder": "rclavicle",
    "l_elbow": "lhumerus",
    "r_elbow": "rhumerus",
    "l_hand": "lradius",
    "r_hand": "rradius",
    "l_hip": "lhipjoint",
    "r_hip": "rhipjoint",
    "l_knee": "lfemur",
    "r_knee": "rfemur",
    "l_ankle": "ltibia",
    "r_ankle": "rtibia",
    "l_toe": "ltoes",
    "r_toe": "rtoes",
}

#: Canonical joint -> BVH joint of the cgspeed conversion (see the module docstring).
BVH_CANONICAL_MAP: dict[str, str] = {
    "base": "Hips",
    "neck": "Neck",
    "head": "Head_end",
    "l_shoulder": "LeftArm",
    "r_shoulder": "RightArm",
    "l_elbow": "LeftForeArm",
    "r_elbow": "RightForeArm",
    "l_hand": "LeftHand",
    "r_hand": "RightHand",
    "l_hip": "LeftUpLeg",
    "r_hip": "RightUpLeg",
    "l_knee": "LeftLeg",
    "r_knee": "RightLeg",
    "l_ankle": "LeftFoot",
    "r_ankle": "RightFoot",
    "l_toe": "LeftToeBase_end",
    "r_toe": "RightToeBase_end",
}

_TRIAL_NAME = re.compile(r"^0*(\d+)_0*(\d+)")


def parse_trial_name(path: str | Path) -> tuple[int | None, int | None]:
    """Subject and trial numbers from a CMU file name (``"80_10.bvh"`` -> ``(80, 10)``).

    Returns ``(None, None)`` for names that do not start with ``<subject>_<trial>``.
    """
    m = _TRIAL_NAME.match(Path(path).name)
    if m is None:
        return None, None
    return int(m.group(1)), int(m.group(2))


def subject_frame_rate(subject: int, trial: int | None = None) -> float:
    """Capture rate [Hz] of a CMU subject (and trial), from CMU's index (:data:`SUBJECT_60HZ`,
    :data:`TRIAL_RATES`)."""
    if trial is not None and (subject, trial) in TRIAL_RATES:
        return TRIAL_RATES[(subject, trial)]
    return 60.0 if subject in SUBJECT_60HZ else DEFAULT_RATE_HZ


class CmuConfig(MotionConfig):
    """A CMU motion capture trial (BVH or ASF/AMC)."""

    kind: Literal["cmu"] = Field("cmu", description="Selects this source: 'cmu'.")
    file: DataPath = Field(
        description="The trial: a .bvh file (cgspeed conversion) or a .amc file (CMU original); "
        "relative to the config file's folder."
    )
    asf: DataPath | None = Field(
        None,
        description="For a .amc file: its skeleton (.asf). Default: <subject>.asf next to the "
        "AMC file (02.asf for 02_01.amc).",
    )
    frame_rate: FrameRate | None = Field(
        None,
        description="Capture rate [Hz]. Default: AMC from the subject number (120 Hz, or 60 Hz "
        "for the subjects CMU's index lists at 60 Hz; 120 Hz with a warning for a subject "
        "not in the index); BVH from the header's Frame Time, "
        "corrected from CMU's index where the header is known to be wrong.",
    )
    cmu_rate_correction: bool = Field(
        True,
        description="BVH: use CMU's index rate where the header is known to be wrong (with a "
        "warning naming both rates).",
    )
    allow_other_subject_asf: bool = Field(
        False,
        description="AMC: accept an ASF whose subject number differs from the AMC's (the "
        "bones would be another person's).",
    )
    activity: str | None = Field(
        None,
        description="Activity label recorded in the metadata. Default: CMU's label for the "
        "shipped trials, else 'unknown'.",
    )
    subject: str | None = Field(
        None,
        description="Subject number (e.g. '80'). Default: from the file name '<subject>_<trial>'; "
        "it selects the frame rate.",
    )
    keep_first_frame: bool = Field(
        False,
        description="BVH only: keep frame 0, which in the cgspeed files is an added T-pose "
        "rather than capture (dropped by default).",
    )

    @model_validator(mode="after")
    def _check(self) -> CmuConfig:
        suffix = Path(self.file).suffix.lower()
        if suffix not in (".bvh", ".amc"):
            raise ValueError(f"file must be a .bvh or .amc file, got {Path(self.file).name!r}")
        if self.asf is not None and suffix != ".amc":
            raise ValueError("asf is used only with a .amc file")
        if self.keep_first_frame and suffix != ".bvh":
            raise ValueError("keep_first_frame applies only to .bvh files")
        if self.subject is not None and not re.fullmatch(r"\d+", self.subject.strip()):
            raise ValueError(f"subject must be a CMU subject number, got {self.subject!r}")
        return self


def check_motion(path: Path, time: np.ndarray, positions_m: np.ndarray) -> None:
    """After forward kinematics: at least two distinct time stamps within the limits, and every
    joint within +-``limits.MAX_COORDINATE_M`` of the origin."""
    limits.check_time_stamps(path, time)
    limits.check_values(
        path,
        positions_m,
        limits.MAX_COORDINATE_M,
        "a joint coordinate after forward kinematics",
        unit=" m",
    )


class CmuSource(MotionSource):
    """CMU motion capture trial: skeleton in metres, z up, with the canonical 17-joint mapping."""

    name = "cmu"
    Config = CmuConfig
    config: CmuConfig

    def load(self) -> Motion:
        """Read the trial and run forward kinematics.

        Returns
        -------
        Motion
            ``skeleton``: time (n_frames,) [s] from 0; positions (n_frames, n_joints, 3) [m],
            z up; every source joint (see the module docstring). ``canonical_map`` maps all 17
            canonical joints. ``metadata``: source, format, file, path, subject, trial, activity,
            frame_rate_hz, frame_rate_from, n_frames, units, acknowledgement, and the format's
            details.

        Raises
        ------
        mdframework.DataFileError
            Malformed file (names the file and line).
        mdframework.ConfigError
            The ASF of an AMC file is not given and not found next to it.
        """
        c = self.config
        path = Path(c.file)
        subject, trial = parse_trial_name(path)
        if c.subject is not None:
            subject = int(c.subject)
        meta: dict[str, Any] = {"source": "cmu", "file": path.name, "path": str(path)}
        if path.suffix.lower() == ".bvh":
            names, pos_m, canonical, extra, rig, frame_time = load_any_bvh(
                path, keep_first_frame=c.keep_first_frame
            )
            n_dropped = int(extra.pop("frames_dropped_at_start"))
            meta["format"] = "bvh"
            rate, rate_from = choose_rate(
                path,
                frame_time,
                rig,
                config_rate=c.frame_rate,
                cmu_correction=c.cmu_rate_correction,
                subject=subject,
                trial=trial,
            )
        else:
            names, pos_m, extra = self._load_asf_amc(path, subject)
            n_dropped = 0
            canonical = dict(ASF_CANONICAL_MAP)
            meta["format"] = "asf/amc"
            if c.frame_rate is not None:
                rate, rate_from = float(c.frame_rate), "config"
            elif subject in CMU_SUBJECTS:
                rate, rate_from = subject_frame_rate(subject, trial), "subject table"
            else:
                rate, rate_from = DEFAULT_RATE_HZ, "default (subject unknown)"
                who = (
                    "no subject is given"
                    if subject is None
                    else f"subject {subject} is not in CMU's index"
                )
                warnings.warn(
                    f"{path}: an AMC file holds no frame rate and {who}: assuming "
                    f"CMU's usual {DEFAULT_RATE_HZ:g} Hz; set motion.frame_rate to the capture "
                    "rate (or motion.subject to a CMU subject number)",
                    FrameRateWarning,
                    stacklevel=2,
                )
        n = pos_m.shape[0]
        time = np.arange(n, dtype=np.float64) / rate
        check_motion(path, time, pos_m)
        activity = c.activity
        if activity is None:
            key = (subject, trial) if subject is not None and trial is not None else None
            activity = ACTIVITIES.get(key, "unknown") if key is not None else "unknown"
        meta.update(
            subject=subject,
            trial=trial,
            activity=activity,
            frame_rate_hz=rate,
            frame_rate_from=rate_from,
            n_frames=int(n),
            frames_dropped_at_start=int(n_dropped),
            units="m",
            axes="x = CMU Z, y = CMU X, z = CMU Y (up)",
            acknowledgement=ACKNOWLEDGEMENT,
            **extra,
        )
        return Motion(Skeleton(time, pos_m, names), meta, dict(canonical))

    def _load_asf_amc(
        self, path: Path, subject: int | None
    ) -> tuple[tuple[str, ...], np.ndarray, dict[str, Any]]:
        asf_path = self.config.asf
        if asf_path is not None and subject is not None:
            m = re.match(r"^0*(\d+)$", Path(asf_path).stem)
            if (
                m is not None
                and int(m.group(1)) != subject
                and not (self.config.allow_other_subject_asf)
            ):
                raise ConfigError(
                    f"{path}: motion.asf {Path(asf_path).name} is subject {int(m.group(1))}'s "
                    f"skeleton, but the motion is subject {subject}'s; give {subject:02d}.asf "
                    "(or set allow_other_subject_asf = true to use another body on purpose)"
                )
        if asf_path is None:
            prefix = path.stem.split("_")[0]
            asf_path = path.with_name(f"{prefix}.asf")
            if not asf_path.exists():
                raise ConfigError(
                    f"{path}: its skeleton {asf_path.name} is not next to it; "
                    "give the ASF file as motion.asf"
                )
        # the ASF/AMC reader when used (loading the plugin needs only the source classes)
        from .asfamc import asf_forward_kinematics, read_amc, read_asf
        from .kinematics import to_project_frame

        asf = read_asf(asf_path)
        amc = read_amc(path, asf)
        names, pos = asf_forward_kinematics(asf, amc)
        extra = {
            "asf_file": Path(asf_path).name,
            "amc_first_frame_number": int(amc.frame_numbers[0]),
            "unit_m": asf.unit_m,
        }
        return names, to_project_frame(pos, asf.unit_m), extra
