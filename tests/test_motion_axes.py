"""A motion source's ``axes`` option, the same rule in every source that has one.

``axes`` names the file axis (with sign) that becomes x (forward), y (left) and z (up). A
rotation of the file's frame keeps the body as it is, only turned; a mirror (determinant -1)
would turn the person's left into their right, so every source refuses it with the same one
line naming ``motion.axes`` (only DeepMimic did). Each kind is checked on its shipped real
file (C3D: the TRC's markers written as C3D): the default's left axis with its sign changed is
refused; the default turned 180 degrees about the up axis is accepted and gives the default body
turned, joint for joint. A file declared left-handed (``handedness = "left"``) is the other way
round: a mirror reads it, a rotation is refused.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import EXAMPLES
from helpers import write_c3d
from mdf_c3d import read_trc

from mdframework.config import validate_run_config
from mdframework.errors import ConfigError
from mdframework.pipeline import build_stages

SECTIONS: dict[str, dict[str, Any]] = {
    "table": {
        "kind": "table",
        "file": "data/kinect/utkinect/joints_s01_e01.txt",
        "header": False,
        "delimiter": "whitespace",
        "time_column": "frame",
        "frame_rate": 60.0,
        "joints": [
            *("HipCenter", "Spine", "ShoulderCenter", "Head", "ShoulderLeft", "ElbowLeft"),
            *("WristLeft", "HandLeft", "ShoulderRight", "ElbowRight", "WristRight", "HandRight"),
            *("HipLeft", "KneeLeft", "AnkleLeft", "FootLeft", "HipRight", "KneeRight"),
            *("AnkleRight", "FootRight"),
        ],
        "joint_set": "kinect-v1",
        "zero_is_missing": True,
        "time_range": [252, 390],
    },
    # the TRC's markers written into a C3D file (see c3d_walk): OpenSim's frame, y up
    "c3d": {"kind": "c3d", "axes": ["x", "-z", "y"]},
    "trc": {"kind": "trc", "file": "data/trc/opensim_subject01_walk.trc"},
    "bvh": {"kind": "bvh", "file": "data/bvh/test_freebvh.bvh"},
    "deepmimic": {"kind": "deepmimic", "file": "data/deepmimic/humanoid3d_walk.txt"},
}


def _validate(section: dict[str, Any]) -> Any:
    return validate_run_config({"motion": section}, source="t.toml", base_dir=EXAMPLES)


def _flip(axis: str) -> str:
    return axis[1:] if axis.startswith("-") else f"-{axis}"


@pytest.fixture(scope="module")
def c3d_walk(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The shipped TRC walk's 41 markers as a C3D file (the shipped C3D has no upper body)."""
    m = read_trc(EXAMPLES / SECTIONS["trc"]["file"])
    path = tmp_path_factory.mktemp("c3d") / "walk.c3d"
    tracks = {name: m.positions[:, k] * m.unit_m for k, name in enumerate(m.labels)}
    write_c3d(path, tracks, m.rate_hz, "mm", 0.001)
    return path


@pytest.mark.parametrize("kind", sorted(SECTIONS))
def test_mirrored_axes_are_refused_and_rotations_turn_the_body(kind: str, c3d_walk: Path) -> None:
    section = SECTIONS[kind] if kind != "c3d" else {**SECTIONS[kind], "file": str(c3d_walk)}
    config = _validate(section)
    default = list(config.motion.axes)
    # every source that has the option
    mirror = [default[0], _flip(default[1]), default[2]]
    with pytest.raises(ConfigError) as err:
        _validate({**section, "axes": mirror})
    assert str(err.value) == (
        f"t.toml: motion.axes: {mirror} mirror the body (its left would become its right): "
        f"change the sign of one axis, e.g. of the one that becomes y (left): {default}; or, if "
        "the file's frame is left-handed (as Unity's is), declare it with handedness = 'left'"
    )
    # x and y both flipped: a half turn about z, a rotation
    turned = [_flip(default[0]), _flip(default[1]), default[2]]
    body = build_stages(config).source.load().canonical()
    half = build_stages(_validate({**section, "axes": turned})).source.load().canonical()
    assert np.array_equal(half.valid, body.valid)
    ok = body.valid
    np.testing.assert_allclose(half.positions[ok], body.positions[ok] * [-1.0, -1.0, 1.0])


@pytest.mark.parametrize("kind", sorted(SECTIONS))
def test_a_left_handed_frame_is_read_through_a_mirror_and_only_one(
    kind: str, c3d_walk: Path
) -> None:
    """handedness = "left" declares the file's frame left-handed (a Unity export, say): its
    axes must then be a mirror, which reads the body as the file's mirror image of it; the
    default axes, a rotation, are refused with it, naming the mirror to give."""
    section = SECTIONS[kind] if kind != "c3d" else {**SECTIONS[kind], "file": str(c3d_walk)}
    config = _validate(section)
    default = list(config.motion.axes)
    mirror = [default[0], _flip(default[1]), default[2]]
    left = _validate({**section, "handedness": "left", "axes": mirror})
    assert left.motion.handedness == "left" and config.motion.handedness == "right"
    body = build_stages(config).source.load().canonical()
    flipped = build_stages(left).source.load().canonical()
    ok = body.valid
    assert np.array_equal(flipped.valid, ok)
    np.testing.assert_allclose(flipped.positions[ok], body.positions[ok] * [1.0, -1.0, 1.0])
    with pytest.raises(ConfigError) as err:
        _validate({**section, "handedness": "left"})
    assert str(err.value) == (
        "t.toml: motion: handedness = 'left' declares the file's frame left-handed, which only "
        f"a mirror turns into the project's right-handed frame, but axes {default} are a "
        f"rotation: change the sign of one axis, e.g. of the one that becomes y (left): {mirror}"
    )
