"""The ``deepmimic`` plugin (``mdf-deepmimic``): DeepMimic motion clips of the humanoid3d
character, through forward kinematics.

Physics on the real clips shipped in ``examples/data/deepmimic`` (see its PROVENANCE.md): the
character's offsets and body shapes against pybullet's copy of the character (its URDF, scaled
by 4), bones of constant length equal to the offsets in every frame, the walk's speed and
cadence against the raw root track and the feet's ground contacts, a hand-computed pose, the
left side on the left, and ``mdf run`` of the example whose torso Doppler follows the root.
Bad input: clips written here from the real walk, damaged.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import EXAMPLES
from mdf_deepmimic import (
    CANONICAL_MAP,
    HUMANOID3D,
    DeepMimicConfig,
    DeepMimicSource,
    forward_kinematics,
    read_character,
    read_clip,
)
from pydantic import ValidationError

from mdframework import DataFileError, cli
from mdframework.interfaces import Motion
from mdframework.sanity import cadence_spm

DATA = EXAMPLES / "data" / "deepmimic"
WALK = DATA / "humanoid3d_walk.txt"
RUN = DATA / "humanoid3d_run.txt"
PUNCH = DATA / "humanoid3d_punch.txt"
URDF = DATA / "humanoid.urdf"


def load(file: Path, **config: Any) -> Motion:
    return DeepMimicSource(DeepMimicConfig(file=file, **config)).load()


def joint(m: Motion, name: str) -> np.ndarray:
    return m.skeleton.joint(name)


def raw_frames(path: Path) -> np.ndarray:
    """The clip's numbers as the file has them (no reader involved)."""
    return np.array(json.loads(path.read_text())["Frames"], dtype=float)


# ----------------------------------------------------------------------------- the files


def test_shipped_files_are_the_ones_in_the_provenance() -> None:
    provenance = (DATA / "PROVENANCE.md").read_text()
    for f in (WALK, RUN, PUNCH, URDF, DATA / "LICENSE"):
        digest = hashlib.sha256(f.read_bytes()).hexdigest()
        assert f"`{digest}`" in provenance, f.name
        assert f"| `{f.name}` | {f.stat().st_size:,} |" in provenance, f.name
    assert "zlib" in (DATA / "LICENSE").read_text()


def _urdf() -> tuple[dict[str, dict[str, Any]], dict[str, list[tuple[np.ndarray, Any]]]]:
    root = ET.fromstring(URDF.read_text().rstrip("\0"))  # the file ends in a NUL byte
    joints = {}
    for j in root.iter("joint"):
        origin = j.find("origin")
        axis, lim = j.find("axis"), j.find("limit")
        joints[j.get("name")] = {
            "type": j.get("type"),
            "parent": j.find("parent").get("link"),  # type: ignore[union-attr]
            "xyz": np.array(origin.get("xyz").split(), dtype=float),  # type: ignore[union-attr]
            "axis": None if axis is None else np.array(axis.get("xyz").split(), dtype=float),
            "limit": None if lim is None else (float(lim.get("lower")), float(lim.get("upper"))),
        }
    shapes = {}
    for link in root.iter("link"):
        shapes[link.get("name")] = [
            (np.array(c.find("origin").get("xyz").split(), dtype=float), c.find("geometry")[0])
            for c in link.iter("collision")
        ]
    return joints, shapes


def test_character_matches_pybullets_copy_of_it() -> None:
    """pybullet's humanoid.urdf is DeepMimic's humanoid3d with every length times 4: the same
    tree, joint types, offsets, revolute axes (z) and limits of the knees and elbows."""
    joints, shapes = _urdf()
    c = HUMANOID3D
    for j in range(1, len(c.names)):
        u = joints[c.names[j]]
        assert u["parent"] == c.names[c.parents[j]]
        assert u["type"] == c.types[j]
        np.testing.assert_allclose(u["xyz"] / 4.0, c.offsets[j], atol=1e-12)
        if c.types[j] == "revolute":
            np.testing.assert_array_equal(u["axis"], [0, 0, 1])
    assert joints["right_knee"]["limit"] == (-3.14, 0.0) == joints["left_knee"]["limit"]
    # the points placed from body shapes: the head sphere of the neck, the foot boxes
    (centre, sphere), *_ = shapes["neck"]
    np.testing.assert_allclose(centre / 4, [0, 0.175, 0], atol=1e-12)
    assert float(sphere.get("radius")) / 4 == pytest.approx(0.205 / 2)
    for side in ("right", "left"):
        (centre, box), *_ = shapes[f"{side}_ankle"]
        size = np.array(box.get("size").split(), dtype=float) / 4
        np.testing.assert_allclose(size, [0.177, 0.055, 0.09], atol=1e-12)
        tip = centre / 4 + [size[0] / 2, 0, 0]
        point = next(p for name, _, p in c.points if name == f"{side}_toe_tip")
        np.testing.assert_allclose(point, tip, atol=1e-12)


# ----------------------------------------------------------------------------- kinematics


def test_forward_kinematics_of_a_hand_computed_pose() -> None:
    """Root 1 m up and turned 90 degrees about y (facing -z of the clip, the project's +y);
    right knee bent -90 degrees, right shoulder +90 degrees about its z, left elbow +90
    degrees; everything else at rest. Positions worked out by hand in the clip's frame."""
    c, s = math.cos(math.pi / 4), math.sin(math.pi / 4)
    rest = np.array([[1.0, 0.0, 0.0, 0.0]])
    rot = {
        n: rest for n, k in zip(HUMANOID3D.names, HUMANOID3D.types, strict=True) if k == "spherical"
    }
    rot |= {
        n: np.zeros(1)
        for n, k in zip(HUMANOID3D.names, HUMANOID3D.types, strict=True)
        if k == "revolute"
    }
    rot["root"] = np.array([[c, 0.0, s, 0.0]])  # 90 degrees about y: x -> -z, z -> x
    rot["right_shoulder"] = np.array([[c, 0.0, 0.0, s]])  # 90 degrees about z
    rot["right_knee"] = np.array([-math.pi / 2])
    rot["left_elbow"] = np.array([math.pi / 2])
    names, pos = forward_kinematics(HUMANOID3D, np.array([[0.0, 1.0, 0.0]]), rot)
    got = dict(zip(names, pos[0], strict=True))
    expected = {
        "right_hip": (0.084887, 1.0, 0.0),
        "right_knee": (0.084887, 0.578454, 0.0),
        "right_ankle": (0.084887, 0.578454, 0.40987),  # the shin points backwards: +z
        "right_toe_tip": (0.084887, 0.578454 - 0.1335, 0.40987 + 0.0225),  # foot down
        "chest": (0.0, 1.236151, 0.0),
        "neck": (0.0, 1.460045, 0.0),
        "head_centre": (0.0, 1.635045, 0.0),
        "right_shoulder": (0.18311, 1.479651, 0.02405),
        "right_elbow": (0.18311, 1.479651, 0.02405 - 0.274788),  # arm forward: -z
        "right_wrist": (0.18311, 1.479651, 0.02405 - 0.274788 - 0.258947),
        "left_shoulder": (-0.18311, 1.479651, 0.02405),
        "left_elbow": (-0.18311, 1.479651 - 0.274788, 0.02405),
        "left_wrist": (-0.18311, 1.479651 - 0.274788, 0.02405 - 0.258947),
    }
    for name, p in expected.items():
        np.testing.assert_allclose(got[name], p, atol=1e-12, err_msg=name)


def test_bones_keep_the_characters_lengths_in_every_frame_of_every_clip() -> None:
    c = HUMANOID3D
    for path in (WALK, RUN, PUNCH):
        sk = load(path).skeleton
        for j in range(1, len(c.names)):
            bone = np.linalg.norm(sk.joint(c.names[j]) - sk.joint(c.names[c.parents[j]]), axis=1)
            np.testing.assert_allclose(bone, np.linalg.norm(c.offsets[j]), atol=1e-12)
        foot = np.linalg.norm(sk.joint("left_toe_tip") - sk.joint("left_ankle"), axis=1)
        np.testing.assert_allclose(foot, math.hypot(0.1335, 0.0225), atol=1e-12)


def test_axes_left_is_left_and_up_is_up() -> None:
    """Walking along +x (the clip's +x), the left hip and shoulder are at +y, the head above
    the pelvis above the ankles; the canonical map gives the 17 joints."""
    m = load(WALK)
    sk = m.canonical()
    base = sk.joint("base")
    assert np.all(np.diff(base[:, 0]) > 0)  # forward
    for left, right in (("l_hip", "r_hip"), ("l_shoulder", "r_shoulder")):
        assert np.all(sk.joint(left)[:, 1] > base[:, 1] + 0.05)
        assert np.all(sk.joint(right)[:, 1] < base[:, 1] - 0.05)
    assert np.all(sk.joint("head")[:, 2] > sk.joint("neck")[:, 2])
    assert np.all(sk.joint("neck")[:, 2] > base[:, 2] + 0.4)
    assert np.min(sk.joint("l_toe")[:, 2]) < 0.05  # the feet reach the floor (z = 0)
    assert set(CANONICAL_MAP.values()) <= set(m.skeleton.joint_names)


# ----------------------------------------------------------------------------- the real clips


def test_walk_speed_and_cadence_from_the_raw_root_track_and_the_feet() -> None:
    """The walk clip is one gait cycle. Independently of the reader: its raw root track gives
    0.978 m/s straight ahead, and the root's height bobs twice per cycle (all of its
    oscillation in the second harmonic), two steps in 1.2666 s: 94.7 steps a minute. The
    reader's motion, three cycles long, gives the same speed from the pelvis, the same cadence
    from the feet's ground contacts and within 1 % from the core's cadence estimate."""
    raw = raw_frames(WALK)
    period = raw[:-1, 0].sum()
    speed = (raw[-1, 1] - raw[0, 1]) / period
    assert period == pytest.approx(38 * 0.033332, abs=1e-12)
    assert speed == pytest.approx(0.9779, abs=1e-4)
    assert raw[-1, 1] - raw[0, 1] == pytest.approx(1.239, abs=1e-3)
    assert raw[-1, 3] == pytest.approx(raw[0, 3], abs=1e-12)  # no sideways drift
    assert raw.shape == (39, 44) and raw[-1, 0] == 0.0
    assert 0.845 < raw[:, 2].min() and raw[:, 2].max() < 0.875  # root height
    bob = np.abs(np.fft.rfft(raw[:-1, 2] - raw[:-1, 2].mean()))
    assert np.argmax(bob) == 2 and bob[1] < 1e-3 * bob[2]
    spm = 2 * 60 / period
    assert spm == pytest.approx(94.74, abs=0.01)

    m = load(WALK, cycles=3)
    sk = m.canonical()
    t, base = sk.time, sk.joint("base")
    assert t[-1] == pytest.approx(3 * period, abs=1e-12)
    assert (base[-1, 0] - base[0, 0]) / t[-1] == pytest.approx(speed, abs=1e-9)
    assert np.ptp(base[:, 1]) < 0.05  # straight along +x
    # ground contacts: a foot is down while its ankle is within 1.5 cm of the lowest it gets
    # (in swing it stays 2.6 cm above that); contacts begin alternately, left and right
    onsets = []
    for side in ("l", "r"):
        ankle = sk.joint(f"{side}_ankle")[:, 2]
        down = ankle < ankle.min() + 0.015
        starts = np.flatnonzero(down[1:] & ~down[:-1]) + 1
        onsets += [(t[i], side) for i in starts]
    onsets.sort()
    sides = [s for _, s in onsets]
    assert all(a != b for a, b in itertools.pairwise(sides)) and len(onsets) >= 5
    step = np.diff([x for x, _ in onsets])
    assert 60 / step.mean() == pytest.approx(spm, rel=0.02)
    core = cadence_spm(t, sk.joint("l_ankle"), sk.joint("r_ankle"))
    assert core == pytest.approx(spm, rel=0.01)


def test_run_speed_and_cadence() -> None:
    """The run clip: one running cycle of 0.8 s, the root covering 2.845 m (3.56 m/s), 150
    steps a minute by the raw clip and by the core's estimate on four cycles."""
    raw = raw_frames(RUN)
    assert raw.shape == (25, 44)
    period = raw[:-1, 0].sum()
    assert period == pytest.approx(0.79997, abs=1e-5)
    assert raw[-1, 1] - raw[0, 1] == pytest.approx(2.845, abs=1e-3)
    assert (raw[-1, 1] - raw[0, 1]) / period == pytest.approx(3.557, abs=1e-3)
    sk = load(RUN, cycles=4).canonical()
    core = cadence_spm(sk.time, sk.joint("l_ankle"), sk.joint("r_ankle"))
    assert core == pytest.approx(2 * 60 / period, rel=0.01)
    assert 2 * 60 / period == pytest.approx(150.0, abs=0.01)
    # flight: in a run both feet are off the floor at times, never in the walk
    for path, flies in ((RUN, True), (WALK, False)):
        s = load(path).canonical()
        lowest = np.minimum(s.joint("l_toe")[:, 2], s.joint("r_toe")[:, 2])
        assert (lowest.max() > 0.1) == flies


def test_punch_is_a_right_hand_punch() -> None:
    """The punch clip: the right fist reaches 0.78 m from the pelvis at 6.83 m/s (the left hand
    stays under 3 m/s); its neck quaternions, of norm down to 0.917, are normalised."""
    m = load(PUNCH)
    sk = m.canonical()
    t = sk.time
    assert m.metadata["loop"] == "none" and sk.n_frames == 65
    assert t[-1] == pytest.approx(64 * 0.0333333015, abs=1e-9)
    speed = {
        h: np.linalg.norm(np.gradient(sk.joint(h), t, axis=0), axis=1) for h in ("l_hand", "r_hand")
    }
    assert speed["r_hand"].max() == pytest.approx(6.83, abs=0.01)
    assert speed["l_hand"].max() < 3.0
    reach = np.linalg.norm(sk.joint("r_hand")[:, :2] - sk.joint("base")[:, :2], axis=1)
    assert reach.max() == pytest.approx(0.78, abs=0.005)
    # it turns about 110 degrees to the left (hips) and back
    across = sk.joint("l_hip") - sk.joint("r_hip")
    heading = np.degrees(np.arctan2(-across[:, 0], across[:, 1]))
    assert heading.max() == pytest.approx(110, abs=3) and abs(heading[-1]) < 3
    assert m.metadata["quaternions_renormalised"] == 10
    raw = raw_frames(PUNCH)
    norms = {
        j: np.linalg.norm(raw[:, c : c + 4], axis=1)
        for k, j, c, _ in HUMANOID3D.layout()
        if k == "spherical"
    }
    off = {j for j, n in norms.items() if np.any(np.abs(n - 1) > 1e-3)}
    assert off == {"neck"}
    neck = norms["neck"][np.abs(norms["neck"] - 1) > 1e-3]
    assert neck.size == 10 and 0.91 < neck.min() < 0.92 and 0.98 < neck.max() < 0.99
    assert m.metadata["quaternion_norm_range"][0] == pytest.approx(0.917, abs=1e-3)


def test_cycles_repeat_the_clip_shifted_by_its_root_displacement() -> None:
    one, three = load(WALK), load(WALK, cycles=3)
    p1, p3 = one.skeleton.positions, three.skeleton.positions
    n = p1.shape[0]
    assert p3.shape[0] == 3 * (n - 1) + 1 == three.metadata["n_frames"]
    assert np.allclose(np.diff(three.skeleton.time), 0.033332, atol=1e-12)
    shift = p1[-1, 0] - p1[0, 0]
    shift[2] = 0.0
    np.testing.assert_allclose(p3[: n - 1], p1[:-1], atol=1e-12)
    np.testing.assert_allclose(p3[n - 1 : 2 * n - 2], p1[:-1] + shift, atol=1e-12)
    np.testing.assert_allclose(p3[-1], p1[-1] + 2 * shift, atol=1e-12)
    # the seam: the clip's last frame against its first moved by a cycle
    closure = np.linalg.norm(p1[0] + shift - p1[-1], axis=1).max()
    assert three.metadata["loop_closure_m"] == pytest.approx(closure, abs=1e-12)
    assert closure == pytest.approx(0.085, abs=0.001)
    assert load(RUN).metadata["loop_closure_m"] == pytest.approx(0.262, abs=0.001)
    # each seam's jump is within one frame's movement of the clip's fastest joint
    for path in (WALK, RUN):
        m = load(path)
        step = np.linalg.norm(np.diff(m.skeleton.positions, axis=0), axis=2).max()
        assert m.metadata["loop_closure_m"] < step
    with pytest.raises(DataFileError, match='"Loop" is "none"'):
        load(PUNCH, cycles=2)


def test_metadata_and_default_activity() -> None:
    m = load(WALK)
    meta = m.metadata
    assert meta["activity"] == "walk" and load(PUNCH).metadata["activity"] == "punch"
    assert meta["frame_rate_hz"] == pytest.approx(1 / 0.033332)
    assert meta["clip_frames"] == 39 and meta["clip_duration_s"] == pytest.approx(1.266616)
    assert set(meta["estimated"]) == {"head", "l_toe", "r_toe", "l_hand", "r_hand"}
    json.dumps(meta)


def test_mirrored_axes_are_refused() -> None:
    with pytest.raises(ValidationError, match="mirror"):
        DeepMimicConfig(file=WALK, axes=("x", "z", "y"))
    DeepMimicConfig(file=WALK, axes=("-x", "z", "y"))  # turned 180 degrees: fine


# ----------------------------------------------------------------------------- mdf run


def test_mdf_run_of_the_example_torso_doppler_follows_the_root(tmp_path: Path) -> None:
    """``mdf run examples/deepmimic_walk.toml``: a finite spectrogram whose torso line is the
    pelvis's radial speed toward the radar (10 m ahead at 2 m height), within a Doppler bin."""
    out = tmp_path / "out"
    assert cli.main(["run", str(EXAMPLES / "deepmimic_walk.toml"), "--out", str(out)]) == 0
    with np.load(out / "result.npz") as d:
        spec, vel, torso = d["spectrogram_db"], d["velocity_mps"], d["torso_velocity_mps"]
        frames = d["time_s"]
    assert np.all(np.isfinite(spec)) and np.all(np.isfinite(torso))
    meta = json.loads((out / "metadata.json").read_text())
    assert meta["motion"]["source"] == "deepmimic"
    sk = load(EXAMPLES / "data" / "deepmimic" / "humanoid3d_walk.txt", cycles=3).canonical()
    radar = np.array([10.0, 0.0, 2.0])
    distance = np.linalg.norm(sk.joint("base") - radar, axis=1)
    radial = -np.gradient(distance, sk.time)  # approaching: positive
    expected = np.interp(frames, sk.time, radial)
    bin_width = float(np.median(np.diff(vel)))
    assert bin_width == pytest.approx(0.023, abs=5e-4)
    assert abs(float(np.mean(torso)) - float(np.mean(expected))) < bin_width
    assert float(np.mean(torso)) == pytest.approx(0.95, abs=0.005)
    assert float(np.mean(expected)) == pytest.approx(0.96, abs=0.005)


def test_documented_offsets_and_time_limits() -> None:
    length = {
        n: float(np.linalg.norm(o))
        for n, o in zip(HUMANOID3D.names, HUMANOID3D.offsets, strict=True)
    }
    documented = {"chest": 0.236, "neck": 0.224, "right_knee": 0.422, "right_ankle": 0.410,
                  "right_elbow": 0.275, "right_wrist": 0.259}  # fmt: skip
    for name, value in documented.items():
        assert length[name] == pytest.approx(value, abs=5e-4), name
    page = (Path(__file__).parents[1] / "docs" / "motion-formats.md").read_text()
    assert "between 0.1 ms and 1 s" in page
    from mdframework import limits

    assert (1 / limits.MAX_FRAME_RATE_HZ, 1 / limits.MIN_FRAME_RATE_HZ) == (1e-4, 1.0)


def test_the_documented_error_is_the_real_message(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    page = (Path(__file__).parents[1] / "docs" / "motion-formats.md").read_text()
    documented = next(ln for ln in page.splitlines() if ln.startswith("mdf: error: walk.txt:15:"))
    lines = WALK.read_text().splitlines(keepends=True)
    head, body = lines[14].split("[", 1)
    values = body.split(",")
    del values[7]
    lines[14] = head + "[" + ",".join(values)
    (tmp_path / "walk.txt").write_text("".join(lines))
    cfg = tmp_path / "run.toml"
    cfg.write_text('[motion]\nkind = "deepmimic"\nfile = "walk.txt"\n')
    assert cli.main(["run", str(cfg), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith(documented.removeprefix("mdf: error: "))


@pytest.mark.parametrize(
    ("duration", "ok"), [(0.5, True), (1.0, True), (1.5, False), (1e-5, False), (0.0, False)]
)
def test_frame_durations_are_bounded(tmp_path: Path, duration: float, ok: bool) -> None:
    frames = raw_frames(WALK)
    frames[3, 0] = duration
    path = tmp_path / "clip.txt"
    path.write_text(json.dumps({"Loop": "wrap", "Frames": frames.tolist()}))
    if ok:
        clip = read_clip(path)
        assert clip.time[4] - clip.time[3] == duration
    else:
        with pytest.raises(DataFileError, match="frame 3: duration"):
            read_clip(path)


@pytest.mark.parametrize(("norm", "ok"), [(0.05, False), (0.5, True), (9.0, True), (11.0, False)])
def test_quaternion_norms_are_bounded(tmp_path: Path, norm: float, ok: bool) -> None:
    frames = raw_frames(WALK)
    frames[6, 8:12] *= norm / np.linalg.norm(frames[6, 8:12])
    path = tmp_path / "clip.txt"
    path.write_text(json.dumps({"Loop": "wrap", "Frames": frames.tolist()}))
    if ok:  # normalised: the same pose as the file's own
        clip = read_clip(path)
        np.testing.assert_allclose(clip.rotations["chest"], read_clip(WALK).rotations["chest"])
        assert clip.renormalised == 1
    else:
        with pytest.raises(DataFileError, match="frame 6: the chest quaternion"):
            read_clip(path)


def test_a_mirror_clip_plays_once(tmp_path: Path) -> None:
    path = tmp_path / "walk.txt"
    path.write_text(WALK.read_text().replace('"wrap"', '"mirror"'))
    assert load(path).metadata["loop"] == "mirror"
    with pytest.raises(DataFileError, match="mirror image"):
        load(path, cycles=2)


def test_cycles_beyond_the_limits_are_refused_before_anything_is_built(tmp_path: Path) -> None:
    """1001 frames played 10,000 times would be 10,000,001 frames: refused, naming the field."""
    frames = raw_frames(WALK)
    long = np.concatenate([frames[:-1]] * 27)[:1001]
    long[:, 0] = 0.001
    path = tmp_path / "long.txt"
    path.write_text(json.dumps({"Loop": "wrap", "Frames": long.tolist()}))
    with pytest.raises(DataFileError, match=r"motion.cycles = 10000 .* 10,000,001 frames"):
        load(path, cycles=10_000)
    assert load(path, cycles=2).skeleton.n_frames == 2001
    from mdframework import limits

    assert (limits.MAX_FRAMES, limits.MAX_DURATION_S) == (10_000_000, 86_400)
    with pytest.raises(ValidationError, match="less than or equal to 10000"):
        DeepMimicConfig(file=WALK, cycles=10_001)


# ----------------------------------------------------------------------------- character files


def character_file(path: Path, scale: float = 1.0, **change: Any) -> Path:
    """A DeepMimic character file written here from the humanoid3d numbers (the format of
    DeepMimic's data/characters/humanoid3d.txt), lengths times ``scale``; ``change`` replaces
    fields of joints by name ({"left_knee": {"Type": "planar"}})."""
    c = HUMANOID3D
    joints = []
    for k, name in enumerate(c.names):
        x, y, z = (float(v) * scale for v in c.offsets[k])
        joint = {"ID": k, "Name": name, "Type": c.types[k], "Parent": c.parents[k],
                 "AttachX": x, "AttachY": y, "AttachZ": z,
                 "AttachThetaX": 0, "AttachThetaY": 0, "AttachThetaZ": 0}  # fmt: skip
        joints.append({**joint, **change.get(name, {})})
    bodies = [{"ID": 2, "Name": "neck", "Shape": "sphere", "AttachX": 0, "AttachY": 0.175 * scale,
               "AttachZ": 0, "Param0": 0.205 * scale}]  # fmt: skip
    for k, side in ((5, "right"), (11, "left")):
        bodies.append({"ID": k, "Name": f"{side}_ankle", "Shape": "box", "AttachX": 0.045 * scale,
                       "AttachY": -0.0225 * scale, "AttachZ": 0, "Param0": 0.177 * scale,
                       "Param1": 0.055 * scale, "Param2": 0.09 * scale})  # fmt: skip
    path.write_text(json.dumps({"Skeleton": {"Joints": joints}, "BodyDefs": bodies}, indent=1))
    return path


def test_a_character_file_gives_its_own_lengths(tmp_path: Path) -> None:
    """The humanoid3d numbers written as a character file give the built-in character's poses;
    the same character 10 % larger gives every bone, head and toe point 10 % longer."""
    same = read_character(character_file(tmp_path / "humanoid3d.txt"))
    assert same.names == HUMANOID3D.names and same.types == HUMANOID3D.types
    np.testing.assert_allclose(same.offsets, HUMANOID3D.offsets, atol=1e-15)
    for (n1, j1, p1), (n2, j2, p2) in zip(same.points, HUMANOID3D.points, strict=True):
        assert (n1, j1) == (n2, j2) and np.allclose(p1, p2, atol=1e-15)
    built_in = load(WALK).skeleton.positions
    np.testing.assert_allclose(
        load(WALK, character=tmp_path / "humanoid3d.txt").skeleton.positions, built_in, atol=1e-12
    )
    m = load(WALK, character=character_file(tmp_path / "big.txt", scale=1.1))
    assert m.metadata["character"] == "big" and m.metadata["character_file"] == "big.txt"
    sk = m.skeleton
    for j in range(1, len(HUMANOID3D.names)):
        parent = HUMANOID3D.names[HUMANOID3D.parents[j]]
        bone = np.linalg.norm(sk.joint(HUMANOID3D.names[j]) - sk.joint(parent), axis=1)
        np.testing.assert_allclose(bone, 1.1 * np.linalg.norm(HUMANOID3D.offsets[j]), atol=1e-12)
    head = np.linalg.norm(sk.joint("head_centre") - sk.joint("neck"), axis=1)
    np.testing.assert_allclose(head, 1.1 * 0.175, atol=1e-12)
    assert "(0.1469, -0.02475, 0) m in the left_ankle" in m.metadata["estimated"]["l_toe"]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"left_knee": {"Type": "planar"}}, "joint 10 (left_knee): type 'planar'"),
        ({"neck": {"AttachThetaZ": 0.3}}, "turned attachment"),
        ({"left_elbow": {"Name": "l_elbow"}}, "lacks left_elbow"),
        ({"chest": {"Parent": 5}}, "must be an earlier joint"),
        ({"right_hip": {"AttachY": float("nan")}}, "not a finite number"),
    ],
)
def test_bad_character_files(tmp_path: Path, change: dict[str, Any], message: str) -> None:
    path = character_file(tmp_path / "c.txt", **change)
    with pytest.raises(DataFileError, match=re.escape(message)):
        load(WALK, character=path)


def test_cycles_shift_only_horizontally() -> None:
    """A clip whose root ends 3 cm lower than it starts (z up) is repeated with the horizontal
    displacement only: every cycle keeps the clip's heights (no drift into or out of the
    floor), and the seam's jump is that 3 cm."""
    from mdf_deepmimic.kinematics import repeat_cycles

    t = np.arange(5) * 0.1
    p = np.zeros((5, 2, 3))
    p[:, 0] = np.stack([0.3 * t, 0.1 * t, 0.9 - 0.075 * t], axis=1)  # root: 3 cm drop over 0.4 s
    p[:, 1] = p[:, 0] + [0.0, 0.0, 0.5]
    time, pos, closure = repeat_cycles(t, p, 3, 0)
    assert time.shape == (13,) and np.allclose(np.diff(time), 0.1)
    np.testing.assert_allclose(pos[4:8, :, 2], p[:4, :, 2], atol=1e-12)
    np.testing.assert_allclose(pos[-1, :, 2], p[-1, :, 2], atol=1e-12)
    np.testing.assert_allclose(pos[-1, 0, :2], 3 * p[-1, 0, :2], atol=1e-12)
    assert closure == pytest.approx(0.03, abs=1e-12)
