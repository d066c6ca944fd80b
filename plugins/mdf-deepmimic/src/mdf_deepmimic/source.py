"""The ``deepmimic`` motion source: a DeepMimic motion clip of the ``humanoid3d`` character.

The clip (:mod:`mdf_deepmimic.reader`) gives the root's position and rotation and each joint's
rotation per frame; forward kinematics over the character's joint tree
(:mod:`mdf_deepmimic.character`, :mod:`mdf_deepmimic.kinematics`) gives every joint's position.
Axes: DeepMimic's world is y up and the character faces +x with its right side at +z in the
rest pose; ``axes = ["x", "-z", "y"]`` (the default) maps that onto the project's x forward,
y left, z up (a rotation, not a mirror). Time: the frames' durations summed (the last frame's
is not used). A ``"wrap"`` clip can be played ``cycles`` times, each cycle shifted by the
clip's root displacement, as DeepMimic plays it.

The canonical body takes the character's joints where it has them (root as the base, neck,
shoulders, elbows, hips, knees, ankles) and, where it has none, points of its body shapes: the
head is the centre of the head sphere, each hand the wrist joint (the centre of the hand
sphere), each toe the front of the foot box (the metadata's ``estimated`` lists them).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import Field

from mdframework import (
    DataFileError,
    DataPath,
    Motion,
    MotionSource,
    Skeleton,
    limits,
)
from mdframework.settings import MotionAxes, OrientedMotionConfig
from mdframework.skeleton import reorient

#: Most cycles a ``"wrap"`` clip may be played.
MAX_CYCLES = 10_000


class DeepMimicConfig(OrientedMotionConfig):
    """A DeepMimic motion clip (JSON text) of the humanoid3d character."""

    kind: Literal["deepmimic"] = Field("deepmimic", description="Selects this source: 'deepmimic'.")
    file: DataPath = Field(
        description="The clip (DeepMimic's data/motions/*.txt, JSON); relative to the config file."
    )
    character: DataPath | None = Field(
        None,
        description="A DeepMimic character file (JSON) whose joints carry humanoid3d's names, "
        "for clips of a resized humanoid; default: DeepMimic's humanoid3d.",
    )
    cycles: int = Field(
        1,
        ge=1,
        le=MAX_CYCLES,
        description='Play a cyclic clip ("Loop": "wrap") this many times, each cycle '
        "shifted by the clip's root displacement; other clips play once.",
    )
    axes: MotionAxes = Field(
        ("x", "-z", "y"),
        description="The clip's axis (with sign) that becomes x (forward), y (left) and z (up); "
        "DeepMimic's world is y up with the character facing +x and its right at +z.",
    )
    activity: str | None = Field(
        None,
        description="Activity label recorded in the metadata. Default: the file name without "
        "'humanoid3d_' ('humanoid3d_walk.txt': 'walk').",
    )
    subject: str | None = Field(None, description="Subject id for the metadata.")


class DeepMimicSource(MotionSource):
    """A DeepMimic clip as the character's joints in metres, z up, with the canonical map."""

    name = "deepmimic"
    Config = DeepMimicConfig
    config: DeepMimicConfig

    def load(self) -> Motion:
        """Read the clip and run forward kinematics.

        Returns
        -------
        Motion
            ``skeleton``: time (n_frames,) [s] from 0; positions (n_frames, n_joints + 3, 3)
            [m], z up: the character's joints (15 for ``humanoid3d``) and the points
            ``head_centre``, ``right_toe_tip``, ``left_toe_tip``. ``canonical_map`` maps all
            17 canonical joints. ``metadata``: source, format, file, path, character,
            character_file, loop, cycles, activity, subject, frame_rate_hz (median),
            n_frames, clip_frames, clip_duration_s, loop_closure_m, axes, estimated
            (canonical joints placed from body shapes), quaternions_renormalised,
            quaternion_norm_range.

        Raises
        ------
        mdframework.DataFileError
            A malformed clip (see :func:`mdf_deepmimic.read_clip`) or character file (see
            :func:`mdf_deepmimic.read_character`), or ``cycles`` above 1 for a clip that does
            not loop.
        """
        from .character import CANONICAL_MAP, HUMANOID3D, estimated, read_character
        from .kinematics import forward_kinematics, repeat_cycles
        from .reader import read_clip

        c = self.config
        path = Path(c.file)
        character = HUMANOID3D if c.character is None else read_character(Path(c.character))
        clip = read_clip(path, character)
        if c.cycles > 1 and clip.loop != "wrap":
            why = {
                "none": "it is not a cycle",
                "mirror": "its repetitions alternate with their mirror image, which this "
                "source does not play",
            }[clip.loop]
            raise DataFileError(
                path,
                f'motion.cycles = {c.cycles}, but the clip\'s "Loop" is "{clip.loop}": {why}; '
                "set cycles = 1",
            )
        total = c.cycles * (clip.n_frames - 1) + 1
        if total > limits.MAX_FRAMES or c.cycles * clip.time[-1] > limits.MAX_DURATION_S:
            raise DataFileError(
                path,
                f"motion.cycles = {c.cycles} of this {clip.n_frames}-frame, "
                f"{clip.time[-1]:.4g} s clip is {total:,} frames and "
                f"{c.cycles * clip.time[-1]:.4g} s, beyond the limits of {limits.MAX_FRAMES:,} "
                f"frames and {limits.MAX_DURATION_S:g} s: play fewer cycles",
            )
        names, pos_file = forward_kinematics(character, clip.root_position, clip.rotations)
        pos = reorient(pos_file, c.axes)
        time, pos, closure = repeat_cycles(clip.time, pos, c.cycles, names.index("root"))
        limits.check_time_stamps(path, time)
        limits.check_values(
            path, pos, limits.MAX_COORDINATE_M, "a joint coordinate after forward kinematics",
            unit=" m",
        )  # fmt: skip
        activity = c.activity
        if activity is None:
            activity = path.stem.removeprefix("humanoid3d_") or "unknown"
        meta: dict[str, Any] = {
            "source": "deepmimic",
            "format": "DeepMimic clip (JSON)",
            "file": path.name,
            "path": str(path),
            "character": character.name,
            "character_file": None if c.character is None else Path(c.character).name,
            "loop": clip.loop,
            "cycles": c.cycles,
            "activity": activity,
            "subject": c.subject,
            "frame_rate_hz": float(1.0 / np.median(clip.durations[:-1])),
            "n_frames": int(time.shape[0]),
            "clip_frames": clip.n_frames,
            "clip_duration_s": float(clip.time[-1]),
            "loop_closure_m": closure,
            "axes": list(c.axes),
            "estimated": estimated(character),
            "quaternions_renormalised": clip.renormalised,
            "quaternion_norm_range": [clip.min_norm, clip.max_norm],
        }
        return Motion(Skeleton(time, pos, names), meta, dict(CANONICAL_MAP))
