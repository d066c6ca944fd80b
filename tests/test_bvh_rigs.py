"""BVH from any rig (``kind = "bvh"`` and the ``cmu`` source's BVH path), on real files.

- Mixamo: ``examples/data/bvh/test_freebvh.bvh`` (a ``mixamorig:`` character, cm, 30 Hz);
  forward kinematics checked against the independent ``bvhio`` library.
- Biovision naming: ``examples/data/bvh/test_mocapbank.bvh`` (a MocapBank studio capture of
  sitting down and standing up, cm, 30 Hz).
- CMU 3ds Max-friendly naming: the real cgspeed 16_21 walk with its joints renamed by cgspeed's
  published renaming template (READMEFIRST of the 3ds Max release; ASF bone -> Max name, here
  applied through the MotionBuilder names the same bones carry): the same body must come out.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from mdf_cmu import BvhConfig, BvhSource, CmuConfig, CmuSource, FrameRateWarning, read_bvh

from mdframework import CANONICAL_JOINTS, ConfigError, DataFileError

DATA = Path(__file__).parents[1] / "examples" / "data"
MIXAMO = DATA / "bvh" / "test_freebvh.bvh"
MOCAPBANK = DATA / "bvh" / "test_mocapbank.bvh"
CMU_BVH = DATA / "cmu" / "bvh"

#: cgspeed MotionBuilder name -> cgspeed 3ds Max name, both from CMU's ASF bone names
#: (hip -> Hips, lfemur -> LeftUpLeg / LeftHip, ...), per cgspeed's two READMEFIRST files.
MB_TO_MAX = {
    "LeftUpLeg": "LeftHip",
    "LeftLeg": "LeftKnee",
    "LeftFoot": "LeftAnkle",
    "LeftToeBase": "LeftToe",
    "LowerBack": "lowerback",
    "Spine": "Chest",
    "Spine1": "Chest2",
    "Neck": "lowerneck",
    "Neck1": "Neck",
    "LeftShoulder": "LeftCollar",
    "LeftArm": "LeftShoulder",
    "LeftForeArm": "LeftElbow",
    "LeftHand": "LeftWrist",
    "LeftFingerBase": "lhand",
    "LeftHandIndex1": "LFingers",
}
MB_TO_MAX.update(
    {k.replace("Left", "Right"): v.replace("Left", "Right") for k, v in MB_TO_MAX.items()}
)
MB_TO_MAX.update({"RightFingerBase": "rhand", "RightHandIndex1": "RFingers"})


def bvh(path: Path, **kw: object):
    """Load through the ``bvh`` source."""
    return BvhSource(BvhConfig(file=path, **kw)).load()


def renamed_copy(
    src: Path, dst: Path, names: dict[str, str], frame_time: str | None = None
) -> Path:
    """A copy of a BVH file with JOINT/ROOT names replaced (and optionally its Frame Time)."""
    text = src.read_text()

    def sub(m: re.Match[str]) -> str:
        return f"{m.group(1)} {names.get(m.group(2), m.group(2))}"

    text = re.sub(r"\b(ROOT|JOINT) (\S+)", sub, text)
    if frame_time is not None:
        text = re.sub(r"Frame Time:\s*\S+", f"Frame Time: {frame_time}", text)
    dst.write_text(text)
    return dst


def test_mixamo_detected_in_cm_at_the_header_rate_and_matches_bvhio() -> None:
    m = bvh(MIXAMO)
    md = m.metadata
    assert (md["rig"], md["unit_m"], md["frame_rate_hz"], md["frame_rate_from"]) == (
        "mixamo",
        0.01,
        30.0,
        "header",
    )
    assert m.skeleton.n_frames == 69 and md["frames_dropped_at_start"] == 0
    assert m.canonical_map is not None and m.canonical_map["l_hand"] == "mixamorig:LeftHand"
    body = m.canonical()
    assert 0.9 < np.median(body.joint("base")[:, 2]) < 1.05  # hips of a standing adult
    assert np.all(body.joint("head")[:, 2] > body.joint("neck")[:, 2])
    # independent forward kinematics (bvhio): hips and left foot, cm -> m, (X,Y,Z) -> (Z,X,Y)
    bvhio = pytest.importorskip("bvhio")
    raw = bvhio.readAsHierarchy(str(MIXAMO))
    for joint, canon in (("mixamorig:Hips", "base"), ("mixamorig:LeftFoot", "l_ankle")):
        node = raw.filter(joint)[0]
        for frame in (0, 34, 68):
            raw.loadPose(frame)
            p = np.array(node.PositionWorld, dtype=float)
            expected = np.array([p[2], p[0], p[1]]) * 0.01
            np.testing.assert_allclose(body.joint(canon)[frame], expected, atol=1e-5)


def test_biovision_studio_capture_sits_down_and_stands_up() -> None:
    m = bvh(MOCAPBANK, activity="sit down, stand up")
    assert m.metadata["rig"] == "biovision" and m.metadata["frame_rate_hz"] == 30.0
    assert m.skeleton.n_frames == 455
    assert m.canonical_map is not None and m.canonical_map["l_toe"] == "LeftAnkle_end"
    base_z = m.canonical().joint("base")[:, 2]
    assert 0.9 < base_z[0] < 1.0 and 0.9 < base_z[-1] < 1.0  # standing at both ends
    assert 0.4 < base_z.min() < 0.55  # seated hips near chair height
    left = m.canonical().joint("l_hip") - m.canonical().joint("r_hip")
    forward = m.canonical().joint("l_toe") - m.canonical().joint("l_ankle")
    # left hip on the subject's left of the feet's forward direction (z up: cross > 0)
    cross = forward[:, 0] * left[:, 1] - forward[:, 1] * left[:, 0]
    assert np.median(cross) > 0


def test_3dsmax_names_give_the_same_body_as_the_motionbuilder_conversion(tmp_path: Path) -> None:
    src = CMU_BVH / "16_21.bvh"
    names = set(read_bvh(src).joint_names)
    assert set(MB_TO_MAX) <= names
    copy = renamed_copy(src, tmp_path / "16_21.bvh", MB_TO_MAX)
    mx = bvh(copy)
    mb = CmuSource(CmuConfig(file=src)).load()
    assert mx.metadata["rig"] == "cmu-3dsmax" and mb.metadata["rig"] == "cmu-cgspeed"
    np.testing.assert_allclose(mx.canonical().positions, mb.canonical().positions, atol=1e-12)
    np.testing.assert_allclose(mx.skeleton.time, mb.skeleton.time)
    # the cmu source reads it as well
    assert CmuSource(CmuConfig(file=copy)).load().metadata["rig"] == "cmu-3dsmax"


def test_unknown_rig_lists_the_files_joints_and_the_nearest_rig(tmp_path: Path) -> None:
    odd = renamed_copy(MOCAPBANK, tmp_path / "odd.bvh", {"LeftWrist": "L_Wrist"})
    with pytest.raises(DataFileError) as err:
        bvh(odd)
    msg = str(err.value)
    assert msg.startswith(f"{odd}: no known BVH rig fits this file's joints (Hips, Chest")
    assert "L_Wrist" in msg and "nearest is 'biovision'" in msg
    assert "lacks l_hand (LeftWrist)" in msg and "motion.joint_map" in msg
    # a user map completes it
    m = bvh(odd, joint_map={"l_hand": "L_Wrist"})
    ref = bvh(MOCAPBANK)
    np.testing.assert_allclose(m.canonical().positions, ref.canonical().positions)
    with pytest.raises(DataFileError, match="l_hand = 'Nope' is not a joint of this file"):
        bvh(MOCAPBANK, joint_map={"l_hand": "Nope"})


def test_full_user_map_and_units_from_the_config(tmp_path: Path) -> None:
    plain = {n: f"J{i}" for i, n in enumerate(read_bvh(MOCAPBANK).joint_names)}
    plain = {k: v for k, v in plain.items() if not k.endswith("_end")}
    odd = renamed_copy(MOCAPBANK, tmp_path / "numbered.bvh", plain)
    ref = bvh(MOCAPBANK)
    full = {c: plain.get(j, j) for c, j in ref.canonical_map.items()}  # type: ignore[union-attr]
    full = {c: (j if not j.endswith("_end") else plain[j[:-4]] + "_end") for c, j in full.items()}
    with pytest.raises(DataFileError, match=r"the file's unit is unknown: give motion\.unit_m"):
        bvh(odd, joint_map=full)
    m = bvh(odd, joint_map=full, unit_m=0.01)
    assert m.metadata["rig"] == "joint_map" and set(m.canonical_map) == set(CANONICAL_JOINTS)  # type: ignore[arg-type]
    np.testing.assert_allclose(m.canonical().positions, ref.canonical().positions)
    inches = bvh(MOCAPBANK, unit_m=0.0254)
    np.testing.assert_allclose(inches.canonical().positions, ref.canonical().positions * 2.54)


def test_frame_rate_header_config_and_cmu_correction(tmp_path: Path) -> None:
    # a 60 Hz header under a name that is no CMU trial: the header rules
    sixty = renamed_copy(CMU_BVH / "16_21.bvh", tmp_path / "walk.bvh", {}, ".0166667")
    m = bvh(sixty)
    assert (m.metadata["frame_rate_hz"], m.metadata["frame_rate_from"]) == (60.0, "header")
    assert np.allclose(np.diff(m.skeleton.time), 1 / 60)
    # CMU subject 80 (60 Hz per CMU's index; cgspeed's header says 120 Hz): corrected, warned
    with pytest.warns(FrameRateWarning, match=r"\(120 Hz\), known to be wrong .* 60 Hz"):
        c = bvh(CMU_BVH / "80_10.bvh")
    assert c.metadata["frame_rate_hz"] == 60.0 and c.metadata["subject"] == 80
    # an explicit rate wins, silently
    with warnings.catch_warnings():
        warnings.simplefilter("error", FrameRateWarning)
        forced = bvh(CMU_BVH / "80_10.bvh", frame_rate=50.0)
    assert (forced.metadata["frame_rate_hz"], forced.metadata["frame_rate_from"]) == (
        50.0,
        "config",
    )


def test_amc_with_another_subjects_asf_is_an_error() -> None:
    amc = DATA / "cmu" / "asf-amc" / "02_01.amc"
    other = DATA / "cmu" / "asf-amc" / "09.asf"
    with pytest.raises(ConfigError, match=r"09.asf is subject 9's skeleton, but the motion is "):
        CmuSource(CmuConfig(file=amc, asf=other)).load()
    ok = CmuSource(CmuConfig(file=amc, asf=other, allow_other_subject_asf=True)).load()
    assert ok.metadata["asf_file"] == "09.asf"


def test_cli_unknown_rig_is_one_line_and_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from mdframework import cli

    odd = renamed_copy(MOCAPBANK, tmp_path / "odd.bvh", {"LeftWrist": "L_Wrist"})
    cfg = tmp_path / "run.toml"
    cfg.write_text(f'[motion]\nkind = "bvh"\nfile = "{odd}"\n')
    out = tmp_path / "out"
    assert cli.main(["run", str(cfg), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"mdf: error: {odd}: no known BVH rig fits")
    assert not out.exists()
