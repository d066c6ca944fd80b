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


# --------------------------------------------------------------------------- other rigs


#: A studio rig that is none of the four: the real CMU 16_21 walk with every signature joint of
#: the CMU rig renamed (as other exporters name them), written in centimetres from its first
#: captured frame (cgspeed's added pose dropped).
OTHER_NAMES = {
    "LHipJoint": "LeftHipJoint",
    "RHipJoint": "RightHipJoint",
    "LowerBack": "Waist",
    "Neck1": "Neck2",
    "LeftFingerBase": "LeftHandEnd",
    "RightFingerBase": "RightHandEnd",
    "LeftHandIndex1": "LeftIndex",
    "RightHandIndex1": "RightIndex",
}


def other_rig_copy(dst: Path, frame_time: str, names: dict[str, str] = OTHER_NAMES) -> Path:
    """16_21.bvh renamed by ``names``, in cm, without frame 0, at ``frame_time`` [s]."""
    from mdf_cmu.kinematics import CMU_UNIT_M

    src = CMU_BVH / "16_21.bvh"
    b = read_bvh(src)
    hier = renamed_copy(src, dst, names).read_text().split("MOTION")[0]
    cm = CMU_UNIT_M * 100

    def offset(m: re.Match[str]) -> str:
        return "OFFSET " + " ".join(f"{float(v) * cm:.6f}" for v in m.group(1).split())

    hier = re.sub(r"OFFSET ([^\n]*)", offset, hier)
    values = b.values[1:].copy()
    values[:, :3] *= cm
    rows = "\n".join(" ".join(f"{v:.6f}" for v in r) for r in values)
    dst.write_text(f"{hier}MOTION\nFrames: {len(values)}\nFrame Time: {frame_time}\n{rows}\n")
    return dst


@pytest.fixture(scope="module")
def cmu_walk():
    """The real walk as the cmu source reads it: the reference body, in metres."""
    return CmuSource(CmuConfig(file=CMU_BVH / "16_21.bvh")).load()


def test_a_file_no_rig_signature_fits_is_refused_not_read_as_cmu(tmp_path: Path) -> None:
    """Its joints would map onto the CMU and the Mixamo rigs, but it has neither's signature:
    read as CMU it came out 5.6 times too large, lost its first frame and, named like a CMU
    trial, got CMU's 120 Hz instead of its own 30 Hz."""
    path = other_rig_copy(tmp_path / "2024_03_take.bvh", "0.0333333")
    with pytest.raises(DataFileError) as err:
        bvh(path)
    msg = str(err.value)
    assert msg.startswith(f"{path}: no known BVH rig fits this file's joints (Hips, LeftHipJoint")
    assert "tried cmu-cgspeed, cmu-3dsmax, mixamo, biovision: the joints of 'cmu-cgspeed', " in msg
    assert "'mixamo' would map, but none of any rig's signature joints is there" in msg
    assert "give motion.rig (cmu-cgspeed, cmu-3dsmax, mixamo, biovision)" in msg
    assert "\n" not in msg
    with pytest.raises(DataFileError, match="no known BVH rig fits"):
        CmuSource(CmuConfig(file=path)).load()


def test_other_rig_named_read_in_its_units_rate_and_frames(tmp_path: Path, cmu_walk) -> None:
    """Named (rig = mixamo: cm, every frame, the header's rate) the body is the real walk: the
    same positions in metres, 1.4-1.9 m tall, at 30 Hz a quarter of the real speed."""
    path = other_rig_copy(tmp_path / "2024_03_take.bvh", "0.0333333")
    with warnings.catch_warnings():
        warnings.simplefilter("error", FrameRateWarning)
        m = bvh(path, rig="mixamo")
    md = m.metadata
    assert (md["unit_m"], md["frames_dropped_at_start"], md["frame_rate_hz"]) == (0.01, 0, 30.0)
    assert md["subject"] is None and md["frame_rate_from"] == "header"
    ref = cmu_walk.canonical()
    body = m.canonical()
    assert body.n_frames == ref.n_frames
    np.testing.assert_allclose(body.positions, ref.positions, atol=2e-5)
    height = body.joint("head")[:, 2].max() - body.joint("l_toe")[:, 2].min()
    assert 1.4 < height < 1.9
    assert m.skeleton.time[-1] == pytest.approx((ref.n_frames - 1) / 30.0)
    base = body.joint("base")
    speed = np.linalg.norm(base[-1, :2] - base[0, :2]) / m.skeleton.time[-1]
    ref_base = ref.joint("base")
    ref_speed = np.linalg.norm(ref_base[-1, :2] - ref_base[0, :2]) / cmu_walk.skeleton.time[-1]
    assert speed == pytest.approx(ref_speed * 30.0 / 120.0, rel=1e-6)


def test_partial_map_completes_the_rig_with_most_signature_joints(tmp_path: Path, cmu_walk):
    """A LAFAN-like rig: toes named LeftToe, a Spine2. The user's map gives the toes; of the two
    rigs it completes, Mixamo has a signature joint there (Spine2) and the CMU rig none: cm, all
    frames, the true body (it came out 8.4 m tall through the CMU rig)."""
    names = {**OTHER_NAMES, "LowerBack": "Spine2", "LeftToeBase": "LeftToe"}
    names["RightToeBase"] = "RightToe"
    path = other_rig_copy(tmp_path / "lafan_like.bvh", "0.0333333", names)
    with pytest.raises(DataFileError, match="the nearest is 'cmu-cgspeed'"):
        bvh(path)
    m = bvh(path, joint_map={"l_toe": "LeftToe_end", "r_toe": "RightToe_end"})
    assert m.metadata["rig"] == "mixamo" and m.metadata["frames_dropped_at_start"] == 0
    np.testing.assert_allclose(m.canonical().positions, cmu_walk.canonical().positions, atol=2e-5)
    # one signature joint each for the CMU rig (Neck1) and Mixamo (Spine2): a tie is refused
    tie = other_rig_copy(tmp_path / "tie.bvh", "0.0333333", {**names, "Neck1": "Neck1"})
    with pytest.raises(DataFileError) as err:
        bvh(tie, joint_map={"l_toe": "LeftToe_end", "r_toe": "RightToe_end"})
    assert "fit the rigs 'cmu-cgspeed' and 'mixamo' with 1 signature joint(s) each: the rig " in (
        str(err.value)
    )
    assert str(err.value).endswith("is ambiguous; give motion.rig")


def test_cmu_rate_correction_only_for_cmu_subjects(tmp_path: Path) -> None:
    """Subject 80 is a 60 Hz subject of CMU's index (corrected, warned, elsewhere); 200 is no
    CMU subject: its 120 Hz header stands."""
    from mdf_cmu.source import CMU_SUBJECTS

    assert len(CMU_SUBJECTS) == 109 and min(CMU_SUBJECTS) == 1 and max(CMU_SUBJECTS) == 144
    assert 80 in CMU_SUBJECTS and 4 not in CMU_SUBJECTS and 200 not in CMU_SUBJECTS
    copy = renamed_copy(CMU_BVH / "80_10.bvh", tmp_path / "200_10.bvh", {})
    with warnings.catch_warnings():
        warnings.simplefilter("error", FrameRateWarning)
        m = bvh(copy)
    assert (m.metadata["frame_rate_hz"], m.metadata["frame_rate_from"]) == (120.0, "header")
    assert np.allclose(np.diff(m.skeleton.time), 1 / 120)


def test_docs_rig_table_lists_each_rigs_signature_and_joints() -> None:
    """docs/motion-formats.md's rig table says exactly what mdf_cmu.rigs detects and maps."""
    from mdf_cmu.rigs import RIGS

    doc = (Path(__file__).parents[1] / "docs" / "motion-formats.md").read_text()
    rows = {
        m.group(1): m.group(2, 3)
        for m in re.finditer(r"^\| `([a-z0-9-]+)`[^|]*\| ([^|]+) \| ([^|]+) \|", doc, re.M)
    }
    assert set(RIGS) <= set(rows)
    for name, rig in RIGS.items():
        signature, joints = rows[name]
        assert re.findall(r"`([^`]+)`", signature) == list(rig.signature), name
        left = ["base", "neck", "head", "l_shoulder", "l_elbow", "l_hand", "l_hip", "l_knee"]
        left += ["l_ankle", "l_toe"]
        expected = [n for j in left for n in rig.joints[j]]
        assert re.findall(r"`([^`]+)`", joints) == expected, name


def z_up_copy(tmp_path: Path) -> Path:
    """The real 16_21 walk exported z up: the root turned +90 degrees about X (file Y up -> Z
    up), the subject facing -Y."""
    from scipy.spatial.transform import Rotation

    src = CMU_BVH / "16_21.bvh"
    b = read_bvh(src)
    turn = Rotation.from_euler("x", 90, degrees=True)
    v = b.values.copy()
    v[:, :3] = turn.apply(v[:, :3])
    v[:, 3:6] = (turn * Rotation.from_euler("ZYX", v[:, 3:6], degrees=True)).as_euler(
        "ZYX", degrees=True
    )
    hier = src.read_text().split("MOTION")[0]
    rows = "\n".join(" ".join(f"{x:.9f}" for x in r) for r in v)
    path = tmp_path / "16_21.bvh"
    path.write_text(f"{hier}MOTION\nFrames: {len(v)}\nFrame Time: 0.0083333\n{rows}\n")
    return path


def test_z_up_file_with_axes_gives_the_upright_walk(tmp_path: Path, cmu_walk) -> None:
    """The real walk exported z up (the root turned +90 degrees about X: file Y up -> Z up, the
    subject facing -Y). Read with the default (BVH's y up) the person lies flat, head level with
    the pelvis; with axes = ['-y', 'x', 'z'] it is the real walk, head 0.5-0.7 m above the
    pelvis and the same positions."""
    path = z_up_copy(tmp_path)
    flat = bvh(path).canonical()
    rise = flat.joint("head")[:, 2] - flat.joint("base")[:, 2]
    assert np.all(np.abs(rise) < 0.1)
    m = bvh(path, axes=["-y", "x", "z"])
    assert m.metadata["axes"] == ["-y", "x", "z"]
    body, ref = m.canonical(), cmu_walk.canonical()
    np.testing.assert_allclose(body.positions, ref.positions, atol=1e-6)
    rise = body.joint("head")[:, 2] - body.joint("base")[:, 2]
    assert np.all((rise > 0.5) & (rise < 0.7))
    # the default is unchanged, and axes are validated as for the other sources
    assert bvh(CMU_BVH / "16_21.bvh").metadata["axes"] == ["z", "x", "y"]
    with pytest.raises(ValueError, match=r"axes must name x, y and z once each"):
        BvhConfig(file=path, axes=["x", "x", "z"])


def test_lying_body_from_a_wrong_up_axis_is_warned_naming_axes(tmp_path: Path) -> None:
    """Every run's sanity checks: the z-up export of the real walk read as y up lies flat, its
    head 0.0 m above the pelvis (the upright walk: 0.52 m): warned, naming motion.axes; as
    'error' it stops; the upright walk is not flagged."""
    from mdframework.sanity import MotionSanityWarning, check_motion, head_rise
    from mdframework.settings import SanityConfig

    src = CMU_BVH / "16_21.bvh"
    upright = bvh(src, activity="walk")
    assert head_rise(upright.canonical()) == pytest.approx(0.52, abs=0.01)
    with warnings.catch_warnings():
        warnings.simplefilter("error", MotionSanityWarning)
        report = check_motion(upright, SanityConfig(cadence=False)).metadata["sanity"]
    assert report["upright"]["ok"]
    path = z_up_copy(tmp_path)
    flat = bvh(path, activity="walk")  # read as y up
    rise = head_rise(flat.canonical())
    assert rise is not None and abs(rise) < 0.1
    with pytest.warns(MotionSanityWarning) as caught:
        report = check_motion(flat, SanityConfig(cadence=False)).metadata["sanity"]
    assert not report["upright"]["ok"]
    # as docs/motion-formats.md shows it, naming the file as the config resolves it
    assert [str(w.message) for w in caught] == [
        f"{path}: the body is not upright: the head is -0.01 m above the pelvis (median over "
        "the frames; upright bodies 0.2 m or more): if the file's up axis is not the one its "
        "source assumes, set motion.axes"
    ]
    with pytest.raises(DataFileError, match=r"16_21\.bvh: motion sanity: the body is not upright"):
        check_motion(flat, SanityConfig(cadence=False, upright="error"))


def test_a_resampled_cmu_trial_keeps_its_header_rate(tmp_path: Path) -> None:
    """CMU's index corrects only cgspeed's known-wrong header (120 Hz for a 60 Hz subject). The
    real 16_21 walk resampled to 30 Hz (every 4th frame, T-pose frame 0 kept, Frame Time
    .0333333, as a re-export writes it) under its own name is read at 30 Hz, silently: the hips
    keep the original's 1.70 m/s and 2.59 s (read at the index's 120 Hz they ran at 6.8 m/s)."""
    lines = (CMU_BVH / "16_21.bvh").read_text().splitlines()
    motion = next(i for i, line in enumerate(lines) if line.strip() == "MOTION")
    frames = lines[motion + 3 :][::4]
    head = [*lines[: motion + 1], f"Frames: {len(frames)}", "Frame Time: .0333333"]
    path = tmp_path / "16_21.bvh"
    path.write_text("\n".join([*head, *frames]) + "\n")
    full = bvh(CMU_BVH / "16_21.bvh")
    with warnings.catch_warnings():
        warnings.simplefilter("error", FrameRateWarning)
        resampled = bvh(path)
    assert (resampled.metadata["frame_rate_hz"], resampled.metadata["frame_rate_from"]) == (
        30.0,
        "header",
    )

    def hip_speed(m) -> float:
        base = m.canonical().joint("base")
        return float(np.linalg.norm(np.diff(base, axis=0), axis=1).sum() / m.skeleton.duration)

    assert resampled.skeleton.duration == pytest.approx(full.skeleton.duration, abs=1 / 30)
    assert hip_speed(full) == pytest.approx(1.70, abs=0.01)
    assert hip_speed(resampled) == pytest.approx(hip_speed(full), rel=0.02)
