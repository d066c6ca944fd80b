"""Tests of the ``cmu`` motion source (plugin ``mdf-cmu``) on real CMU trials.

The data are the copies shipped in ``examples/data/cmu`` (see its PROVENANCE.md). Oracles:

- BVH: the independent ``bvhio`` library (its own parser, Euler -> quaternion conversion and
  hierarchy transforms, in PyGLM float32, hence agreement to 1e-6 m rather than 1e-12).
- ASF/AMC: a small per-frame implementation below, with its own parsing and scipy's ``Rotation``.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from mdf_cmu import (
    ACKNOWLEDGEMENT,
    CMU_UNIT_M,
    CmuConfig,
    CmuSource,
    FrameRateWarning,
    bvh_forward_kinematics,
    read_asf,
    read_bvh,
)
from scipy.spatial.transform import Rotation

from mdframework import CANONICAL_JOINTS, ConfigError, DataFileError
from mdframework.physics.body import estimate_height

DATA = Path(__file__).parents[1] / "examples" / "data" / "cmu"
AMC = DATA / "asf-amc"
BVH = DATA / "bvh"
UNIT = (1 / 0.45) * 2.54 / 100


def load(path: Path, **kw: object):
    """Load a trial through the plugin."""
    return CmuSource(CmuConfig(file=path, **kw)).load()


def cmu_to_project(p: np.ndarray) -> np.ndarray:
    """(X, Y, Z) CMU units -> (Z, X, Y) metres, written independently of the plugin."""
    p = np.asarray(p, dtype=float)
    return np.stack([p[..., 2], p[..., 0], p[..., 1]], axis=-1) * UNIT


# --------------------------------------------------------------------------- BVH vs bvhio


def bvhio_world_positions(path: Path) -> dict[str, np.ndarray]:
    """World positions of every joint and end site from bvhio, (n_frames, 3) CMU units each."""
    bvhio = pytest.importorskip("bvhio")
    glm = pytest.importorskip("glm")
    raw = bvhio.readAsBvh(str(path))
    # bvhio's hierarchy rotates each joint's local space so that its bone points along +y (the
    # rest rotation from BvhJoint.getRotation); an End Site offset must be rotated the same way.
    ends = {
        j.Name: glm.inverse(j.getRotation()) * j.EndSite
        for j, _, _ in raw.Root.layout()
        if not j.Children
    }
    root = bvhio.readAsHierarchy(str(path))
    joints = [j for j, _, _ in root.layout()]
    out: dict[str, list[list[float]]] = {}
    for frame in range(raw.FrameCount):
        root.loadPose(frame, recursive=True)
        for j in joints:
            out.setdefault(j.Name, []).append(list(j.PositionWorld))
            if j.Name in ends:
                out.setdefault(f"{j.Name}_end", []).append(list(j.pointToWorld(ends[j.Name])))
    return {k: np.asarray(v) for k, v in out.items()}


@pytest.mark.parametrize("trial", ["16_21", "09_03", "80_10"])
def test_bvh_forward_kinematics_matches_bvhio(trial: str) -> None:
    path = BVH / f"{trial}.bvh"
    motion = load(path, keep_first_frame=True, frame_rate=120.0)
    ref = bvhio_world_positions(path)
    sk = motion.skeleton
    assert set(ref) == set(sk.joint_names)
    assert len(sk.joint_names) == 38  # 31 joints + 7 end sites
    worst = 0.0
    for name, track in ref.items():
        assert track.shape == (sk.n_frames, 3)
        worst = max(worst, float(np.abs(cmu_to_project(track) - sk.joint(name)).max()))
    assert worst < 1e-6, f"max deviation from bvhio {worst:.3g} m"


def test_bvh_rotation_order_matters() -> None:
    """The oracle comparison can fail: the wrong Euler order moves joints by centimetres."""
    bvh = read_bvh(BVH / "09_03.bvh")
    good = bvh_forward_kinematics(bvh)
    swapped = tuple(
        type(j)(
            j.name,
            j.parent,
            j.offset,
            tuple(reversed(j.channels)) if len(j.channels) == 3 else j.channels,
            j.first_channel,
            j.end_site,
            j.line,
        )
        for j in bvh.joints
    )
    bad = bvh_forward_kinematics(type(bvh)(bvh.path, swapped, bvh.values, bvh.frame_time))
    assert np.abs(bad - good).max() * CMU_UNIT_M > 0.01


# --------------------------------------------------------------------------- ASF/AMC oracle


def simple_asf(path: Path) -> tuple[dict[str, dict], dict[str, str], list[str]]:
    """Bones (direction, length, axis, dof), parent of each bone, and bone order from an ASF."""
    text = path.read_text().replace("\r", "")
    bonedata = text.split(":bonedata")[1].split(":hierarchy")[0]
    bones: dict[str, dict] = {}
    for block in re.findall(r"begin(.*?)\n\s*end", bonedata, flags=re.S):
        fields = {ln.split()[0]: ln.split()[1:] for ln in block.strip().splitlines() if ln.split()}
        bones[fields["name"][0]] = {
            "direction": np.array(fields["direction"], dtype=float),
            "length": float(fields["length"][0]),
            "axis": np.array(fields["axis"][:3], dtype=float),
            "dof": fields.get("dof", []),
        }
    parent: dict[str, str] = {}
    order: list[str] = []
    hierarchy = text.split(":hierarchy")[1].split("begin")[1].split("end")[0]
    for ln in hierarchy.strip().splitlines():
        first, *kids = ln.split()
        for k in kids:
            parent[k] = first
            order.append(k)  # the CMU hierarchy lists parents before children
    return bones, parent, order


def simple_amc_frames(path: Path, wanted: set[int]) -> dict[int, dict[str, list[float]]]:
    """The values of the wanted frame numbers of an AMC file."""
    frames: dict[int, dict[str, list[float]]] = {}
    current = None
    for ln in path.read_text().replace("\r", "").splitlines():
        parts = ln.split()
        if not parts or parts[0].startswith((":", "#")):
            continue
        if len(parts) == 1 and parts[0].isdigit():
            current = int(parts[0])
            continue
        if current in wanted:
            frames.setdefault(current, {})[parts[0]] = [float(v) for v in parts[1:]]
    return frames


def oracle_asf_positions(
    asf: Path, amc: Path, frame_numbers: list[int], root_orientation: tuple = (0, 0, 0)
) -> dict[int, dict]:
    """Per-frame forward kinematics with scipy rotations ('xyz' extrinsic = Rz Ry Rx); the
    root's rotation is ``C M C^-1`` with ``C`` from ``root_orientation`` [deg]."""
    bones, parent, order = simple_asf(asf)
    frames = simple_amc_frames(amc, set(frame_numbers))
    c_root = Rotation.from_euler("xyz", root_orientation, degrees=True)
    result = {}
    for fno in frame_numbers:
        vals = frames[fno]
        root = vals["root"]
        rot = {"root": c_root * Rotation.from_euler("xyz", root[3:6], degrees=True) * c_root.inv()}
        pos = {"root": np.array(root[:3])}
        for name in order:
            b = bones[name]
            c = Rotation.from_euler("xyz", b["axis"], degrees=True)
            angles = dict(zip(b["dof"], vals.get(name, []), strict=True))
            m = Rotation.from_euler(
                "xyz",
                [angles.get("rx", 0.0), angles.get("ry", 0.0), angles.get("rz", 0.0)],
                degrees=True,
            )
            rot[name] = rot[parent[name]] * c * m * c.inv()
            pos[name] = pos[parent[name]] + b["length"] * rot[name].apply(b["direction"])
        result[fno] = pos
    return result


@pytest.mark.parametrize("trial", ["02_01", "09_06"])
def test_asf_amc_matches_independent_implementation(trial: str) -> None:
    subject = trial.split("_")[0]
    motion = load(AMC / f"{trial}.amc")
    sk = motion.skeleton
    first = int(motion.metadata["amc_first_frame_number"])
    picks = [0, 1, 37, sk.n_frames // 2, sk.n_frames - 1]
    ref = oracle_asf_positions(
        AMC / f"{subject}.asf", AMC / f"{trial}.amc", [first + k for k in picks]
    )
    assert set(ref[first]) == set(sk.joint_names)
    for k in picks:
        for name, p in ref[first + k].items():
            np.testing.assert_allclose(
                sk.positions[k, sk.index(name)], cmu_to_project(p), atol=1e-9
            )


# --------------------------------------------------------------------------- rigid bones


def test_asf_bone_lengths_are_constant_and_equal_the_asf() -> None:
    for trial in ("02_01", "09_06"):
        motion = load(AMC / f"{trial}.amc")
        asf = read_asf(AMC / f"{trial.split('_')[0]}.asf")
        sk = motion.skeleton
        for bone in asf.bones:
            seg = np.linalg.norm(sk.joint(bone.name) - sk.joint(bone.parent), axis=1)
            assert np.ptp(seg) < 1e-9, bone.name
            # directions are unit vectors to the file's 6 digits
            assert seg[0] == pytest.approx(bone.length * UNIT, rel=1e-5), bone.name


def test_bvh_bone_lengths_are_constant_and_equal_the_offsets() -> None:
    for trial in ("16_21", "80_10"):
        bvh = read_bvh(BVH / f"{trial}.bvh")
        sk = load(BVH / f"{trial}.bvh").skeleton
        for j in bvh.joints:
            if j.parent < 0:
                continue
            seg = np.linalg.norm(sk.joint(j.name) - sk.joint(bvh.joints[j.parent].name), axis=1)
            assert np.ptp(seg) < 1e-9, j.name
            assert seg[0] == pytest.approx(np.linalg.norm(j.offset) * UNIT, abs=1e-9), j.name


# --------------------------------------------------------------------------- speeds, frames


@pytest.mark.parametrize(("trial", "expected"), [("02_01", 1.2), ("09_06", 3.6)])
def test_hip_speed(trial: str, expected: float) -> None:
    """Mean horizontal speed of the base over the whole trial: walk ~1.2 m/s, run ~3.6 m/s
    (measured 1.18 and 3.64 m/s); tolerance +/-15 %."""
    motion = load(AMC / f"{trial}.amc")
    base = motion.canonical().joint("base")
    rate = motion.metadata["frame_rate_hz"]
    assert rate == 120.0
    speed = np.linalg.norm(np.diff(base[:, :2], axis=0), axis=1) * rate
    assert speed.mean() == pytest.approx(expected, rel=0.15)
    # height of the hip centre is that of a standing adult (z is up)
    assert 0.8 < np.median(base[:, 2]) < 1.2


def test_bvh_tpose_dropped_and_rates() -> None:
    header = int(re.search(r"Frames:\s*(\d+)", (BVH / "16_21.bvh").read_text())[1])
    dropped = load(BVH / "16_21.bvh")
    kept = load(BVH / "16_21.bvh", keep_first_frame=True)
    assert dropped.skeleton.n_frames == header - 1
    assert kept.skeleton.n_frames == header
    np.testing.assert_array_equal(kept.skeleton.positions[1:], dropped.skeleton.positions)
    assert dropped.skeleton.time[0] == 0.0
    assert np.allclose(np.diff(dropped.skeleton.time), 1 / 120)
    # frame 0 is the T-pose: arms out (hands within 0.1 m of shoulder height), while in the
    # walk the hands hang well below the shoulders
    idx = {n: i for i, n in enumerate(CANONICAL_JOINTS)}
    for sk, lo, hi in ((kept.canonical(), -0.1, 0.1), (dropped.canonical(), -0.7, -0.35)):
        drop = sk.positions[0, idx["l_hand"], 2] - sk.positions[0, idx["l_shoulder"], 2]
        assert lo < drop < hi

    assert dropped.metadata["frame_rate_hz"] == 120.0  # the header's .0083333, rounded
    assert dropped.metadata["frame_rate_from"] == "header"
    # cgspeed's header says 120 Hz for subject 80 too; CMU's index says 60 Hz
    with pytest.warns(FrameRateWarning, match=r"Frame Time 0.0083333 s \(120 Hz\).* 60 Hz"):
        m80 = load(BVH / "80_10.bvh")
    assert m80.metadata["frame_rate_hz"] == 60.0
    assert m80.metadata["frame_rate_from"] == "CMU index (header corrected)"
    kept_header = load(BVH / "80_10.bvh", cmu_rate_correction=False)
    assert kept_header.metadata["frame_rate_hz"] == 120.0
    assert m80.metadata["bvh_frame_time_s"] == pytest.approx(1 / 120, rel=1e-3)
    assert np.allclose(np.diff(m80.skeleton.time), 1 / 60)
    assert m80.skeleton.duration == pytest.approx((m80.skeleton.n_frames - 1) / 60)
    forced = load(BVH / "80_10.bvh", frame_rate=30.0)
    assert forced.metadata["frame_rate_from"] == "config"
    assert forced.skeleton.time[1] == pytest.approx(1 / 30)


def test_metadata() -> None:
    m = load(AMC / "02_01.amc")
    md = m.metadata
    assert md["source"] == "cmu" and md["format"] == "asf/amc" and md["units"] == "m"
    assert (md["subject"], md["trial"], md["activity"]) == (2, 1, "walk")
    assert md["n_frames"] == m.skeleton.n_frames
    assert md["acknowledgement"] == ACKNOWLEDGEMENT
    assert "mocap.cs.cmu.edu" in ACKNOWLEDGEMENT and "EIA-0196217" in ACKNOWLEDGEMENT
    b = load(BVH / "13_41.bvh", activity="jumping jacks")
    assert (b.metadata["format"], b.metadata["activity"]) == ("bvh", "jumping jacks")
    import json

    json.dumps(dict(md))
    json.dumps(dict(b.metadata))


def test_subjects_and_rates_are_cmus_index() -> None:
    """CMU_SUBJECTS and the rate of every trial are those of CMU's index (its subject, trial and
    framerate columns, shipped as examples/data/cmu/cmu-index-rates.csv; see PROVENANCE.md):
    2435 trials of 109 subjects numbered 1 to 144."""
    import csv

    from mdf_cmu.source import CMU_SUBJECTS, subject_frame_rate

    with (DATA / "cmu-index-rates.csv").open(newline="", encoding="utf-8") as fh:
        index = [
            (int(r["subject"]), int(r["trial"]), float(r["framerate"])) for r in csv.DictReader(fh)
        ]
    assert len(index) == 2435 and len({(s, t) for s, t, _ in index}) == 2435
    assert CMU_SUBJECTS == {s for s, _, _ in index} and len(CMU_SUBJECTS) == 109
    wrong = [(s, t, hz) for s, t, hz in index if subject_frame_rate(s, t) != hz]
    assert wrong == []


def test_frame_rate_table() -> None:
    """Rates from CMU's index (the framerate column, checked against it above): 60 Hz subjects,
    120 Hz otherwise; subject 136 is 120 Hz except trial 19."""
    from mdf_cmu.source import subject_frame_rate

    sixty = {33, 34, 42, 60, 61, 62, 74, 75, 77, 79, 80, 87, 88, 89}
    for subject in range(1, 145):
        expected = 60.0 if subject in sixty else 120.0
        assert subject_frame_rate(subject, 1) == expected, subject
    assert subject_frame_rate(136, 19) == 60.0
    assert subject_frame_rate(136, 20) == 120.0


# --------------------------------------------------------------------------- canonical body


TRIALS = [AMC / "02_01.amc", AMC / "09_06.amc", AMC / "13_18.amc", *sorted(BVH.glob("*.bvh"))]


@pytest.mark.parametrize("path", TRIALS, ids=lambda p: p.name)
def test_canonical_body_is_anatomical(path: Path) -> None:
    motion = load(path)
    assert set(motion.canonical_map) == set(CANONICAL_JOINTS)
    c = motion.canonical()
    j = {n: c.joint(n) for n in CANONICAL_JOINTS}
    # facing direction from the feet (ankle -> toe), independent of the left/right labels' sides
    fwd = (j["l_toe"] - j["l_ankle"] + j["r_toe"] - j["r_ankle"])[:, :2]
    fwd /= np.linalg.norm(fwd, axis=1, keepdims=True)
    left = np.stack([-fwd[:, 1], fwd[:, 0]], axis=1)  # z x forward
    for part in ("hip", "shoulder"):
        side = np.einsum("ij,ij->i", (j[f"l_{part}"] - j[f"r_{part}"])[:, :2], left)
        assert np.all(side > 0), part

    def length(a: str, b: str) -> float:
        return float(np.median(np.linalg.norm(j[a] - j[b], axis=1)))

    for s in ("l", "r"):
        assert 0.35 < length(f"{s}_hip", f"{s}_knee") < 0.5
        assert 0.35 < length(f"{s}_knee", f"{s}_ankle") < 0.5
        assert 0.24 < length(f"{s}_shoulder", f"{s}_elbow") < 0.36
        assert 0.17 < length(f"{s}_elbow", f"{s}_hand") < 0.3
        assert 0.12 < length(f"{s}_ankle", f"{s}_toe") < 0.25
    assert 0.14 < length("l_hip", "r_hip") < 0.25
    assert 0.3 < length("l_shoulder", "r_shoulder") < 0.45
    # head above neck above base, by plausible amounts
    assert 0.15 < np.median(j["neck"][:, 2] - j["base"][:, 2]) < 0.45
    assert 0.2 < np.median(j["head"][:, 2] - j["neck"][:, 2]) < 0.35
    assert 1.5 < estimate_height(c.positions) < 2.0


# --------------------------------------------------------------------------- malformed files


def write(path: Path, lines: list[str], eol: str = "\n") -> Path:
    path.write_bytes((eol.join(lines) + eol).encode())
    return path


def bvh_lines() -> list[str]:
    return (BVH / "09_03.bvh").read_bytes().decode().replace("\r\n", "\n").split("\n")[:-1]


def first_frame_line(lines: list[str]) -> int:
    """1-based line number of frame 0."""
    return next(i for i, ln in enumerate(lines) if ln.startswith("Frame Time")) + 2


def test_truncated_bvh(tmp_path: Path) -> None:
    lines = bvh_lines()
    f0 = first_frame_line(lines)
    # cut in the middle of frame 20's line
    cut = [*lines[: f0 + 19], lines[f0 + 19][: len(lines[f0 + 19]) // 2]]
    path = write(tmp_path / "09_03.bvh", cut)
    with pytest.raises(DataFileError) as err:
        load(path)
    assert err.value.path == path and err.value.line == f0 + 20
    assert f"09_03.bvh:{f0 + 20}:" in str(err.value) and "frame 20" in str(err.value)
    # cut at a line end: fewer frames than the header says
    path = write(tmp_path / "09_03.bvh", lines[: f0 + 9])
    with pytest.raises(DataFileError, match="truncated") as err:
        load(path)
    assert err.value.line == f0 + 9
    # cut inside the hierarchy
    path = write(tmp_path / "09_03.bvh", lines[:40])
    with pytest.raises(DataFileError, match="ends inside the hierarchy") as err:
        load(path)
    assert err.value.line == 40


def test_bvh_frame_with_missing_value(tmp_path: Path) -> None:
    lines = bvh_lines()
    f0 = first_frame_line(lines)
    bad = list(lines)
    bad[f0 + 49] = " ".join(bad[f0 + 49].split()[:-1])
    path = write(tmp_path / "09_03.bvh", bad, eol="\r\n")
    with pytest.raises(DataFileError, match="frame 50 has 95 values, expected 96") as err:
        load(path)
    assert err.value.path == path and err.value.line == f0 + 50


def test_bvh_bad_number_keyword_and_zero_frames(tmp_path: Path) -> None:
    lines = bvh_lines()
    f0 = first_frame_line(lines)
    bad = list(lines)
    bad[f0 + 3] = bad[f0 + 3].replace(" ", " 1.2.3 ", 1).rsplit(" ", 1)[0]
    with pytest.raises(DataFileError, match=re.escape("bad number '1.2.3' in frame 4")) as err:
        load(write(tmp_path / "a_1.bvh", bad))
    assert err.value.line == f0 + 4
    bad = list(lines)
    bad[11] = bad[11].replace("OFFSET", "OFFSETS")
    with pytest.raises(DataFileError, match=r"expected OFFSET .* found 'OFFSETS'") as err:
        load(write(tmp_path / "b_1.bvh", bad))
    assert err.value.line == 12
    bad = list(lines)
    bad.insert(21, "\t\t\t\tMUSCLE Soleus")  # before "JOINT LeftToeBase"
    with pytest.raises(DataFileError, match="unknown keyword 'MUSCLE'") as err:
        load(write(tmp_path / "c_1.bvh", bad))
    assert err.value.line == 22
    zero = [*lines[: f0 - 4], "MOTION", "Frames: 0", "Frame Time: .0083333"]
    with pytest.raises(DataFileError, match="zero frames") as err:
        load(write(tmp_path / "d_1.bvh", zero))
    assert err.value.line == f0 - 2


def test_crlf_bvh_parses_like_original(tmp_path: Path) -> None:
    path = write(tmp_path / "09_03.bvh", bvh_lines(), eol="\r\n")
    a = load(path).skeleton
    b = load(BVH / "09_03.bvh").skeleton
    np.testing.assert_array_equal(a.positions, b.positions)


def amc_sample(n_frames: int) -> list[str]:
    """Header and the first n_frames frames of 02_01.amc."""
    lines = (AMC / "02_01.amc").read_text().split("\n")
    end = next(i for i, ln in enumerate(lines) if ln.strip() == str(n_frames + 1))
    return lines[:end]


def test_amc_unknown_bone(tmp_path: Path) -> None:
    (tmp_path / "02.asf").write_bytes((AMC / "02.asf").read_bytes())
    lines = amc_sample(3)
    k = next(i for i, ln in enumerate(lines) if ln.startswith("ltibia"))
    lines[k] = lines[k].replace("ltibia", "lshin")
    path = write(tmp_path / "02_01.amc", lines)
    with pytest.raises(
        DataFileError, match=re.escape("bone 'lshin' is not in the skeleton 02.asf")
    ) as err:
        load(path)
    assert err.value.path == path and err.value.line == k + 1


def test_amc_value_count_and_frame_numbers(tmp_path: Path) -> None:
    (tmp_path / "02.asf").write_bytes((AMC / "02.asf").read_bytes())
    lines = amc_sample(3)
    k = next(i for i, ln in enumerate(lines) if ln.startswith("lfemur"))
    lines[k] = "lfemur 1.0 2.0"
    with pytest.raises(DataFileError, match="needs 3 numbers, found 2") as err:
        load(write(tmp_path / "02_01.amc", lines))
    assert err.value.line == k + 1
    lines = amc_sample(3)
    k = next(i for i, ln in enumerate(lines) if ln.strip() == "3")
    lines[k] = "4"
    with pytest.raises(DataFileError, match="frame number 4 follows 2") as err:
        load(write(tmp_path / "02_01.amc", lines))
    assert err.value.line == k + 1
    with pytest.raises(DataFileError, match="zero frames"):
        load(write(tmp_path / "02_01.amc", amc_sample(3)[:3]))


def _bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64).view(np.int64)


@pytest.mark.parametrize("trial", ["02_01", "09_06", "13_18"])
def test_amc_whole_file_parse_is_the_line_by_line_parse(trial: str, tmp_path: Path) -> None:
    """CMU files (every frame the same bones in the same order) are parsed in one pass over the
    whole file; a comment between two frames makes a file irregular, so the line-by-line parse
    reads it. Both give the same values bit for bit, in degrees and in radians."""
    from mdf_cmu.asfamc import _read_regular_amc, read_amc, read_lines

    asf = read_asf(AMC / f"{trial.split('_')[0]}.asf")
    lines = (AMC / f"{trial}.amc").read_text().split("\n")
    second = next(i for i, ln in enumerate(lines) if ln.strip() == "2")
    for unit in (":DEGREES", ":RADIANS"):
        text = [unit if ln.strip() == ":DEGREES" else ln for ln in lines]
        regular = write(tmp_path / f"r{trial}.amc", text)
        irregular = write(
            tmp_path / f"i{trial}.amc", [*text[:second], "# a comment", *text[second:]]
        )
        assert _read_regular_amc(regular, read_lines(regular), asf) is not None
        assert _read_regular_amc(irregular, read_lines(irregular), asf) is None
        whole, by_line = read_amc(regular, asf), read_amc(irregular, asf)
        assert list(whole.values) == list(by_line.values)
        for bone, values in whole.values.items():
            assert np.array_equal(_bits(values), _bits(by_line.values[bone])), bone
        assert np.array_equal(whole.frame_numbers, by_line.frame_numbers)


def test_amc_errors_late_in_a_regular_file_name_their_line(tmp_path: Path) -> None:
    """A bad number, an angle beyond the limit, a missing value or a repeated bone deep inside
    13_18.amc: the same one-line error naming the line as the line-by-line parse gives."""
    lines = (AMC / "13_18.amc").read_text().split("\n")
    (tmp_path / "13.asf").write_bytes((AMC / "13.asf").read_bytes())
    frame = next(i for i, ln in enumerate(lines) if ln.strip() == "2500")
    k = next(i for i in range(frame, len(lines)) if lines[i].startswith("lfemur"))
    fields = lines[k].split()
    after = lines[k + 1].split()
    cases = [
        (k, [fields[0], fields[1], "1.2.3", fields[3]], "bad number '1.2.3'"),
        (k, [fields[0], fields[1], "5e5", fields[3]], "angle of bone 'lfemur': 500000.0"),
        (k, [fields[0], fields[1], "inf", fields[3]], "non-finite number"),
        (k, fields[:3], "needs 3 numbers, found 2"),
        (k + 1, ["lfemur", *after[1:]], "bone 'lfemur' appears twice in frame 2500"),
    ]
    for at, bad, message in cases:
        path = write(tmp_path / "13_18.amc", [*lines[:at], " ".join(bad), *lines[at + 1 :]])
        with pytest.raises(DataFileError, match=re.escape(message)) as err:
            load(path)
        assert err.value.path == path and err.value.line == at + 1, (bad, err.value)


def test_crlf_asf_amc_parse(tmp_path: Path) -> None:
    """02.asf and 02_01.amc have LF endings; the same content with CRLF gives the same motion."""
    lf = (AMC / "02.asf").read_text().split("\n")
    write(tmp_path / "02.asf", lf[:-1] if lf[-1] == "" else lf, eol="\r\n")
    path = write(tmp_path / "02_01.amc", amc_sample(5), eol="\r\n")
    assert b"\r\n" in path.read_bytes()
    crlf = load(path).skeleton
    full = load(AMC / "02_01.amc").skeleton
    assert crlf.n_frames == 5
    np.testing.assert_array_equal(crlf.positions, full.positions[:5])


def _asf_in_radians(lines: list[str]) -> list[str]:
    """02.asf rewritten with ``angle rad``: the root orientation and every bone axis in radians
    (17 significant digits, so the only change is the unit)."""
    out = []
    for ln in lines:
        toks = ln.split()
        if toks[:1] == ["angle"]:
            ln = "  angle rad"
        elif toks[:1] == ["orientation"]:
            ln = "   orientation " + " ".join(repr(math.radians(float(t))) for t in toks[1:])
        elif toks[:1] == ["axis"] and len(toks) == 5:
            angles = " ".join(repr(math.radians(float(t))) for t in toks[1:4])
            ln = f"     axis {angles} {toks[4]}"
        out.append(ln)
    return out


def test_asf_angles_in_radians(tmp_path: Path) -> None:
    """An ASF whose ``:units`` say ``angle rad`` gives its root orientation and bone axes in
    radians: the same body as the degree file (the AMC keeps its own ``:DEGREES``). A root
    orientation of 30 deg about z makes the root's term count too."""
    lines = (AMC / "02.asf").read_text().split("\n")
    lines = ["   orientation 0 0 30" if ln.split()[:1] == ["orientation"] else ln for ln in lines]
    (tmp_path / "deg").mkdir()
    (tmp_path / "rad").mkdir()
    write(tmp_path / "deg" / "02.asf", lines)
    write(tmp_path / "rad" / "02.asf", _asf_in_radians(lines))
    assert "angle rad" in (tmp_path / "rad" / "02.asf").read_text()
    deg = load(write(tmp_path / "deg" / "02_01.amc", amc_sample(20))).skeleton
    rad = load(write(tmp_path / "rad" / "02_01.amc", amc_sample(20))).skeleton
    np.testing.assert_allclose(rad.positions, deg.positions, rtol=0, atol=1e-12)
    full = load(AMC / "02_01.amc").skeleton  # the root orientation moved the body
    assert np.max(np.abs(deg.positions - full.positions[:20])) > 0.05


def test_root_orientation_length_unit_and_radian_amc_match_the_oracle(tmp_path: Path) -> None:
    """An ASF with a root ``orientation`` (10, 20, 30) deg and ``length 1`` (one unit = 1 inch =
    0.0254 m) and its AMC in ``:RADIANS`` (root translations stay in length units): the joints
    are the independent oracle's with ``C_root M C_root^-1`` at the root, in 0.0254 m units."""
    lines = (AMC / "02.asf").read_text().split("\n")
    lines = ["   orientation 10 20 30" if ln.split()[:1] == ["orientation"] else ln for ln in lines]
    lines = ["  length 1.0" if ln.strip() == "length 0.45" else ln for ln in lines]
    write(tmp_path / "02.asf", lines)
    deg = write(tmp_path / "deg.amc", amc_sample(10))
    rad = []
    for ln in amc_sample(10):
        toks = ln.split()
        if toks == [":DEGREES"]:
            ln = ":RADIANS"
        elif toks and not toks[0].startswith((":", "#")) and not toks[0].isdigit():
            vals = [float(t) for t in toks[1:]]
            keep = 3 if toks[0] == "root" else 0  # TX TY TZ are lengths
            vals = vals[:keep] + [math.radians(v) for v in vals[keep:]]
            ln = " ".join([toks[0], *(repr(v) for v in vals)])
        rad.append(ln)
    assert ":RADIANS" in rad
    sk = load(write(tmp_path / "02_01.amc", rad)).skeleton
    ref = oracle_asf_positions(tmp_path / "02.asf", deg, list(range(1, 11)), (10, 20, 30))
    for k in range(10):
        for name, p in ref[k + 1].items():
            want = cmu_to_project(p) / UNIT * 0.0254
            np.testing.assert_allclose(sk.positions[k, sk.index(name)], want, atol=1e-9)


def test_asf_unit_given_twice_or_bad_mass(tmp_path: Path) -> None:
    """A second ``length`` (or a second ``:units`` section repeating one) would silently change
    the body's size; a mass unit that is not a positive number breaks the input rules."""
    lines = (AMC / "02.asf").read_text().split("\n")
    k = next(i for i, ln in enumerate(lines) if ln.strip() == "length 0.45")
    m = next(i for i, ln in enumerate(lines) if ln.strip() == "mass 1.0")
    path = write(tmp_path / "02_01.amc", amc_sample(2))
    cases = [
        ([*lines[: k + 1], "  length 1.0", *lines[k + 1 :]], k + 2, "unit 'length' given twice"),
        ([*lines[: k + 2], ":units", "  length 1", *lines[k + 2 :]], k + 4, "given twice"),
        ([*lines[:m], "  mass nan", *lines[m + 1 :]], m + 1, "non-finite number"),
        ([*lines[:m], "  mass 0", *lines[m + 1 :]], m + 1, "mass unit must be positive"),
    ]
    for text, line, message in cases:
        write(tmp_path / "02.asf", text)
        with pytest.raises(DataFileError, match=re.escape(message)) as err:
            load(path)
        assert err.value.line == line, (message, err.value)


@pytest.mark.parametrize("eol", ["\r", "\r\n"])
def test_byte_order_mark_and_old_mac_line_ends(eol: str, tmp_path: Path) -> None:
    """BVH, ASF and AMC files that start with a UTF-8 byte-order mark and end their lines with
    CR alone (or CRLF) read exactly as the plain LF files."""
    bvh = tmp_path / "09_03.bvh"
    bvh.write_bytes(b"\xef\xbb\xbf" + (eol.join(bvh_lines()) + eol).encode())
    np.testing.assert_array_equal(
        load(bvh).skeleton.positions, load(BVH / "09_03.bvh").skeleton.positions
    )
    asf = (AMC / "02.asf").read_text().split("\n")
    (tmp_path / "02.asf").write_bytes(b"\xef\xbb\xbf" + eol.join(asf).encode())
    amc = tmp_path / "02_01.amc"
    amc.write_bytes(b"\xef\xbb\xbf" + (eol.join(amc_sample(5)) + eol).encode())
    np.testing.assert_array_equal(
        load(amc).skeleton.positions, load(AMC / "02_01.amc").skeleton.positions[:5]
    )
    # a mark before Latin-1 text (a comment in another encoding): skipped there too
    latin1 = b"\xef\xbb\xbf# caf\xe9" + eol.encode() + eol.join(asf).encode()
    (tmp_path / "02.asf").write_bytes(latin1)
    np.testing.assert_array_equal(
        load(amc).skeleton.positions, load(AMC / "02_01.amc").skeleton.positions[:5]
    )


def test_asf_unknown_keyword(tmp_path: Path) -> None:
    lines = (AMC / "02.asf").read_text().split("\n")
    k = next(i for i, ln in enumerate(lines) if ln.strip().startswith("length 7.59371"))
    lines[k] = "     lenght 7.59371"
    (tmp_path / "02.asf").write_text("\n".join(lines))
    path = write(tmp_path / "02_01.amc", amc_sample(2))
    with pytest.raises(DataFileError, match="unknown keyword 'lenght'") as err:
        load(path)
    assert err.value.path == tmp_path / "02.asf" and err.value.line == k + 1


def test_missing_asf_is_a_clear_error(tmp_path: Path) -> None:
    path = write(tmp_path / "02_01.amc", amc_sample(2))
    with pytest.raises(ConfigError, match=re.escape("02.asf")):
        load(path)
    ok = load(path, asf=AMC / "02.asf")
    assert ok.skeleton.n_frames == 2


def test_config_validation(tmp_path: Path) -> None:
    from pydantic import ValidationError

    other = write(tmp_path / "x.txt", ["hello"])
    with pytest.raises(ValidationError, match=r"\.bvh or \.amc"):
        CmuConfig(file=other)
    with pytest.raises(ValidationError, match="file not found"):
        CmuConfig.model_validate({"file": "nope.bvh"}, context={"base_dir": tmp_path})
    cfg = CmuConfig.model_validate({"file": "bvh/80_10.bvh"}, context={"base_dir": DATA})
    assert cfg.file == DATA / "bvh" / "80_10.bvh"
    for name, field in CmuConfig.model_fields.items():
        assert field.description, name


def test_registered_in_plugin_registry() -> None:
    from mdframework.plugins import default_registry

    assert default_registry().get("motion", "cmu") is CmuSource


def test_amc_of_an_unknown_subject_assumes_120_hz_and_says_so(tmp_path: Path) -> None:
    """An AMC file holds no rate: a name that gives no subject of CMU's index gets CMU's usual
    120 Hz with a warning naming it and the option; its frames are 1/120 s apart."""
    import warnings

    ref = load(AMC / "02_01.amc")
    asf = AMC / "02.asf"
    for name, who in (
        ("walk.amc", "no subject is given"),
        ("200_01.amc", "subject 200 is not in CMU's index"),
    ):
        path = tmp_path / name
        path.write_bytes((AMC / "02_01.amc").read_bytes())
        with pytest.warns(FrameRateWarning) as caught:
            m = load(path, asf=asf, allow_other_subject_asf=True)
        assert [str(w.message) for w in caught] == [
            f"{path}: an AMC file holds no frame rate and {who}: assuming CMU's usual 120 Hz; "
            "set motion.frame_rate to the capture rate (or motion.subject to a CMU subject "
            "number)"
        ]
        assert m.metadata["frame_rate_from"] == "default (subject unknown)"
        np.testing.assert_allclose(np.diff(m.skeleton.time), 1 / 120, rtol=1e-12)
        np.testing.assert_array_equal(m.skeleton.positions, ref.skeleton.positions)
    # a known subject or a given rate: no warning
    with warnings.catch_warnings():
        warnings.simplefilter("error", FrameRateWarning)
        assert load(path, asf=asf, subject="80", allow_other_subject_asf=True).metadata[
            "frame_rate_hz"
        ] == pytest.approx(60.0)
        assert (
            load(path, asf=asf, frame_rate=100.0, allow_other_subject_asf=True).metadata[
                "frame_rate_from"
            ]
            == "config"
        )


def test_bvh_root_position_channels_replace_its_offset(tmp_path: Path) -> None:
    """The root's Xposition/Yposition/Zposition give its position; its OFFSET (CMU's are 0) is
    replaced by them, not added: a root OFFSET of (10, 20, 30) leaves every joint in place."""
    lines = bvh_lines()
    k = next(i for i, ln in enumerate(lines) if ln.strip().startswith("OFFSET"))
    assert lines[k].split()[1:] == ["0.00000"] * 3
    lines[k] = "\tOFFSET 10.0 20.0 30.0"
    moved = load(write(tmp_path / "09_03.bvh", lines)).skeleton.positions
    np.testing.assert_array_equal(moved, load(BVH / "09_03.bvh").skeleton.positions)
