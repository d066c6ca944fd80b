"""The ``c3d`` plugin (``mdf-c3d``): C3D marker files through ezc3d.

Physics on the real treadmill walk shipped in ``examples/data/c3d`` (see its PROVENANCE.md):
the cadence from the markers against the gait events the lab marked in the file, the belt
speed from the stance heel, stride length, and the shank's constant length. The mapping onto
the canonical body is checked on files written here with ezc3d (the real file has no arm or
head markers, and the source must say so), and the bad-input rules on damaged copies.
"""

from __future__ import annotations

import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import EXAMPLES
from helpers import pig_markers, write_c3d
from mdf_c3d import C3dConfig, C3dSource, read_c3d, read_c3d_header

from mdframework import CANONICAL_JOINTS, DataFileError
from mdframework.sanity import cadence_spm
from mdframework.skeleton import group_means

REAL = Path(__file__).parents[1] / "examples" / "data" / "c3d" / "treadmill_events.c3d"

KNEES_ANKLES = {
    "l_knee": ["LLEK", "LMEK"],
    "r_knee": ["RLEK", "RMEK"],
    "l_ankle": ["LLM", "LMM"],
    "r_ankle": ["RLM", "RMM"],
    "l_heel": ["LHEE"],
    "r_heel": ["RHEE"],
    "pelvis": ["LASIS", "RASIS", "LPSIS", "RPSIS"],
}


@pytest.fixture(scope="module")
def real() -> tuple[np.ndarray, np.ndarray, object]:
    m = read_c3d(REAL)
    p, ok = group_means(m.positions * m.unit_m, m.labels, KNEES_ANKLES)
    assert ok.all()
    t = np.arange(m.n_frames) / m.rate_hz
    return t, p, m


def _j(name: str) -> int:
    return list(KNEES_ANKLES).index(name)


def test_real_file_header_units_and_events() -> None:
    h = read_c3d_header(REAL)
    assert (h.processor, h.floats, h.n_points, h.n_frames) == ("Intel", True, 124, 1206)
    m = read_c3d(REAL)
    assert m.rate_hz == 100.0 and m.units == "mm" and m.unit_m == 1e-3
    assert m.subject == "SI02" and m.software == "Vicon Nexus"
    assert m.positions.shape == (1206, 124, 3)
    labels = {e[0] for e in m.events}
    assert labels == {"Foot Strike", "Foot Off"} and len(m.events) == 43
    # z up: the pelvis about a metre above the floor, the heels within 30 cm of it
    z = m.positions[..., 2] * m.unit_m
    assert 0.85 < np.nanmedian(z[:, m.labels.index("LASIS")]) < 1.1
    assert np.nanmin(z[:, m.labels.index("LHEE")]) < 0.1


def test_real_cadence_from_markers_matches_the_labs_gait_events(real) -> None:
    t, p, m = real
    strikes = np.array([e[2] for e in m.events if e[0] == "Foot Strike"])
    # the lab's events: steps per minute over the span they cover
    from_events = (strikes.size - 1) / (strikes.max() - strikes.min()) * 60
    from_markers = cadence_spm(t, p[:, _j("l_ankle")], p[:, _j("r_ankle")])
    assert from_markers is not None
    assert from_markers == pytest.approx(from_events, rel=0.02)
    assert from_events == pytest.approx(105.8, abs=0.05)  # an ordinary walking cadence


def test_real_treadmill_belt_speed_and_stride_length(real) -> None:
    t, p, m = real
    speeds = {}
    for side, ctx in (("l_heel", "Left"), ("r_heel", "Right")):
        strikes = sorted(e[2] for e in m.events if e[0] == "Foot Strike" and e[1] == ctx)
        offs = sorted(e[2] for e in m.events if e[0] == "Foot Off" and e[1] == ctx)
        v = np.gradient(p[:, _j(side), 1], t)
        mid = []
        for a in strikes:
            b = next((f for f in offs if f > a), None)
            if b is None:
                continue
            # middle half of stance; event times count from the file's frame 1
            i0 = round((a + 0.25 * (b - a)) * m.rate_hz) - (m.first_frame - 1)
            i1 = round((a + 0.75 * (b - a)) * m.rate_hz) - (m.first_frame - 1)
            mid.append(np.median(v[max(i0, 0) : i1]))
        assert len(mid) >= 8
        # the stance foot rides the belt: the same speed in every stride (within 2 %)
        assert np.std(mid) < 0.02 * abs(np.mean(mid))
        speeds[ctx] = abs(float(np.mean(mid)))
        stride_s = float(np.median(np.diff(strikes)))
        assert stride_s == pytest.approx(1.135, abs=0.01)
        stride_m = speeds[ctx] * stride_s
        assert stride_m == pytest.approx(1.24, abs=0.02)  # an ordinary walking stride
    assert speeds["Left"] == pytest.approx(speeds["Right"], rel=0.02)
    assert speeds["Left"] == pytest.approx(1.09, abs=0.01)  # a comfortable walking speed
    # on a treadmill the pelvis stays put: its mean speed along the belt is under 1 % of it
    pelvis_v = np.gradient(p[:, _j("pelvis"), 1], t)
    assert abs(np.mean(pelvis_v)) < 0.01 * speeds["Left"]


def test_real_shank_length_is_constant(real) -> None:
    _, p, _ = real
    for s in "lr":
        shank = np.linalg.norm(p[:, _j(f"{s}_knee")] - p[:, _j(f"{s}_ankle")], axis=1)
        # knee and ankle centres from medial and lateral markers: a rigid bone within 1 %
        assert shank.mean() == pytest.approx(0.405, abs=0.005)
        assert shank.std() / shank.mean() == pytest.approx(0.007, abs=0.001)


def test_real_file_without_arms_is_refused_naming_its_markers() -> None:
    with pytest.raises(DataFileError) as err:
        C3dSource(C3dConfig(file=REAL)).load()
    msg = str(err.value)
    assert msg.startswith(str(REAL))
    assert "lacks head (LFHD + RFHD + LBHD + RBHD), l_shoulder (LSHO)" in msg
    assert "LASIS, RASIS, LPSIS" in msg and "marker_map" in msg and "\n" not in msg


# --------------------------------------------------------------------------- written files


def _body(n: int, rate: float) -> dict[str, np.ndarray]:
    """Joint tracks [m] of a body stepping forward at 1.2 m/s with swinging limbs."""
    t = np.arange(n) / rate
    base = np.stack([1.2 * t, 0.0 * t, 1.0 + 0.02 * np.sin(2 * np.pi * 1.8 * t)], axis=1)
    off = {
        "neck": (0, 0, 0.5),
        "head": (0, 0, 0.7),
        "l_shoulder": (0, 0.2, 0.45),
        "r_shoulder": (0, -0.2, 0.45),
        "l_elbow": (0, 0.22, 0.15),
        "r_elbow": (0, -0.22, 0.15),
        "l_hand": (0, 0.22, -0.1),
        "r_hand": (0, -0.22, -0.1),
        "l_hip": (0, 0.1, -0.05),
        "r_hip": (0, -0.1, -0.05),
        "l_knee": (0, 0.1, -0.5),
        "r_knee": (0, -0.1, -0.5),
        "l_ankle": (0, 0.1, -0.92),
        "r_ankle": (0, -0.1, -0.92),
        "l_toe": (0.15, 0.1, -0.98),
        "r_toe": (0.15, -0.1, -0.98),
    }
    out = {"base": base}
    for j, o in off.items():
        swing = (0.0 if j in ("neck", "head") else 0.2) * np.sin(2 * np.pi * 0.9 * t)
        sign = 1 if j.startswith("l_") else -1
        out[j] = base + np.array(o) + np.stack([sign * swing, 0 * t, 0 * t], axis=1)
    return out


def test_plug_in_gait_file_gives_the_joints_as_marker_means(tmp_path: Path) -> None:
    body = _body(120, 60.0)
    path = tmp_path / "walk.c3d"
    write_c3d(path, pig_markers(body), 60.0, "cm", 0.01)
    m = C3dSource(C3dConfig(file=path, activity="walk")).load()
    assert m.metadata["marker_set"] == "plug-in-gait" and m.metadata["unit_m"] == 0.01
    assert m.metadata["frame_rate_hz"] == 60.0 and m.metadata["frame_rate_from"] == "header"
    c = m.canonical()
    assert c.joint_names == CANONICAL_JOINTS
    assert np.allclose(np.diff(c.time), 1 / 60)
    # base: the mean of the four pelvis markers is the mean of the two hips here
    truth = dict(body, base=(body["l_hip"] + body["r_hip"]) / 2)
    for j in CANONICAL_JOINTS:
        assert np.allclose(c.joint(j), truth[j], atol=1e-5), j  # ezc3d stores float32
    assert m.metadata["markers"]["head"] == ["LFHD", "RFHD", "LBHD", "RBHD"]


def test_axes_units_rate_and_marker_map_from_the_config(tmp_path: Path) -> None:
    body = _body(60, 50.0)
    markers = pig_markers(body)
    markers["LMKNE"] = body["l_knee"] + np.array([0.0, -0.05, 0.0])
    markers["LKNE"] = body["l_knee"] + np.array([0.0, 0.05, 0.0])
    # a y-up lab: file (X, Y, Z) = project (y, z, x)
    yup = {k: v[:, [1, 2, 0]] for k, v in markers.items()}
    path = tmp_path / "yup.c3d"
    write_c3d(path, yup, 50.0, "mm", 0.001)
    m = C3dSource(
        C3dConfig(
            file=path,
            axes=("z", "x", "y"),
            frame_rate=100.0,
            marker_map={"l_knee": ["LKNE", "LMKNE"]},
        )
    ).load()
    c = m.canonical()
    assert np.allclose(c.joint("l_knee"), body["l_knee"], atol=1e-4)
    assert np.allclose(c.joint("head"), body["head"], atol=1e-4)
    assert np.allclose(np.diff(c.time), 0.01) and m.metadata["frame_rate_from"] == "config"
    assert m.metadata["markers"]["l_knee"] == ["LKNE", "LMKNE"]


def test_unseen_markers_make_their_joints_invalid(tmp_path: Path) -> None:
    body = _body(40, 50.0)
    markers = pig_markers(body)
    markers["LWRA"][10:15] = np.nan  # ezc3d writes NaN points as not seen (residual -1)
    path = tmp_path / "gap.c3d"
    write_c3d(path, markers, 50.0, "m", 1.0)
    m = C3dSource(C3dConfig(file=path)).load()
    assert m.metadata["zero_points"] == 0  # a marker not seen, not one at the origin
    c = m.canonical()
    hand = c.index("l_hand")
    assert not c.valid[10:15, hand].any() and c.valid[:10, hand].all()
    assert c.valid[:, c.index("r_hand")].all()


def test_a_file_of_two_subjects_reads_one_subjects_markers_only(tmp_path: Path) -> None:
    """Vicon and Qualisys prefix each subject's markers (``S1:LASI``, ``S2:LASI``). A joint the
    first subject lacks markers for must not be taken from the second (whose head, 2 m to the
    side, was read as the first's head): with several subjects ``subject`` chooses whose
    markers are read, and without it the file is refused naming them."""
    body = _body(60, 60.0)
    other = {j: v + np.array([0.0, 2.0, 0.0]) for j, v in body.items()}
    first = {f"S1:{k}": v for k, v in pig_markers(body).items() if k[1:] != "FHD"}
    second = {f"S2:{k}": v for k, v in pig_markers(other).items()}
    prop = {f"Box:Corner{k}": body["base"] + np.array([1.0, 0.0, k / 10]) for k in range(4)}
    path = tmp_path / "two.c3d"
    write_c3d(path, {**first, **second, **prop}, 60.0, "mm", 0.001)
    with pytest.raises(DataFileError, match=r"2 subjects \(S1, S2\): give motion.subject"):
        C3dSource(C3dConfig(file=path)).load()
    with pytest.raises(DataFileError, match=r"lacks head"):
        C3dSource(C3dConfig(file=path, subject="S1")).load()
    with pytest.raises(DataFileError, match=r"'S3' is not one of the file's 2 subjects"):
        C3dSource(C3dConfig(file=path, subject="S3")).load()
    # a prop's prefix is no subject either (its markers were read, and refused as a body)
    with pytest.raises(DataFileError, match=r"'Box' is not one of the file's 2 subjects"):
        C3dSource(C3dConfig(file=path, subject="Box")).load()
    # a prop's markers (prefixed too) are no subject's: one person and a box need no subject
    alone = tmp_path / "one.c3d"
    write_c3d(alone, {**second, **prop}, 60.0, "mm", 0.001)
    assert np.allclose(
        C3dSource(C3dConfig(file=alone)).load().canonical().joint("head"), other["head"], atol=1e-4
    )
    m = C3dSource(C3dConfig(file=path, subject="S2")).load()
    assert m.metadata["subject"] == "S2"
    assert all(mk.startswith("S2:") for ms in m.metadata["markers"].values() for mk in ms)
    c = m.canonical()
    for j in CANONICAL_JOINTS:
        truth = (other["l_hip"] + other["r_hip"]) / 2 if j == "base" else other[j]
        assert np.allclose(c.joint(j), truth, atol=1e-4), j


def test_subjects_of_marker_map_names_alone_are_told_apart(tmp_path: Path) -> None:
    """A subject's markers named in motion.marker_map only (no marker set's names) still make
    the prefix a subject's: two such subjects without motion.subject are refused, and S2 is
    read when chosen."""
    body = _body(30, 60.0)
    other = {j: v + np.array([0.0, 2.0, 0.0]) for j, v in body.items()}
    markers = {f"S1:J_{j}": body[j] for j in CANONICAL_JOINTS}
    markers |= {f"S2:J_{j}": other[j] for j in CANONICAL_JOINTS}
    path = tmp_path / "custom.c3d"
    write_c3d(path, markers, 60.0, "mm", 0.001)
    mapping = {j: f"J_{j}" for j in CANONICAL_JOINTS}
    with pytest.raises(DataFileError, match=r"2 subjects \(S1, S2\): give motion.subject"):
        C3dSource(C3dConfig(file=path, marker_map=mapping)).load()
    c = C3dSource(C3dConfig(file=path, marker_map=mapping, subject="S2")).load().canonical()
    assert np.allclose(c.joint("head"), other["head"], atol=1e-4)


@pytest.mark.parametrize("seen", [0, 1])
def test_a_joint_whose_marker_is_never_seen_is_named_with_the_marker(
    tmp_path: Path, seen: int
) -> None:
    """A marker the file names but never saw (not labelled in any frame, or in one only) left
    its joint untracked throughout; the run then stopped saying to choose a record where the
    joint is tracked, which no record is. The load names the joint, the marker and the marker
    map."""
    markers = pig_markers(_body(60, 60.0))
    markers["LELB"][seen:] = np.nan
    path = tmp_path / "noelbow.c3d"
    write_c3d(path, markers, 60.0, "mm", 0.001)
    with pytest.raises(DataFileError) as err:
        C3dSource(C3dConfig(file=path)).load()
    assert str(err.value) == (
        f"{path}: joint l_elbow is seen in fewer than two frames: its marker(s) LELB are seen in "
        "fewer than two frames; give motion.marker_map for l_elbow (markers of the file that are "
        "seen)"
    )


# --------------------------------------------------------------------------- bad input


def _patched(tmp_path: Path, name: str, offset: int, data: bytes) -> Path:
    raw = bytearray(REAL.read_bytes())
    raw[offset : offset + len(data)] = data
    out = tmp_path / name
    out.write_bytes(bytes(raw))
    return out


def test_bad_files_are_one_line_errors_naming_the_file(tmp_path: Path) -> None:
    cut = tmp_path / "cut.c3d"
    cut.write_bytes(REAL.read_bytes()[:200_000])
    cut_msg = (
        r"cut\.c3d: header declares 1206 frames of 124 points and 240 analog samples from block "
        r"62 \(3,581,696 bytes\), but the file holds 200,000 bytes: the file is truncated"
    )
    with pytest.raises(DataFileError, match=cut_msg):
        read_c3d(cut)
    bad_key = _patched(tmp_path, "key.c3d", 1, b"\x51")
    with pytest.raises(DataFileError, match=r"key\.c3d: not a C3D file: header byte 2 is 0x51"):
        read_c3d(bad_key)
    # a header claiming 65535 frames: refused from the header, before anything is allocated
    huge = _patched(tmp_path, "huge.c3d", 8, struct.pack("<H", 65535))
    with pytest.raises(DataFileError, match=r"huge\.c3d: header declares 65491 frames"):
        read_c3d(huge)
    short = tmp_path / "short.c3d"
    short.write_bytes(b"\x02\x50" + bytes(100))
    with pytest.raises(DataFileError, match=r"short\.c3d: 102 bytes: too short"):
        read_c3d(short)
    garbage = tmp_path / "garbage.c3d"
    garbage.write_bytes(np.random.default_rng(3).integers(0, 256, 5000, dtype=np.uint8).tobytes())
    with pytest.raises(DataFileError, match=r"garbage\.c3d: not a C3D file"):
        read_c3d(garbage)


def test_unknown_units_ask_for_unit_m(tmp_path: Path) -> None:
    path = tmp_path / "feet.c3d"
    write_c3d(path, pig_markers(_body(20, 50.0)), 50.0, "ft", 0.3048)
    with pytest.raises(DataFileError, match=r"feet\.c3d: POINT:UNITS is 'ft'.*motion\.unit_m"):
        C3dSource(C3dConfig(file=path)).load()
    m = C3dSource(C3dConfig(file=path, unit_m=0.3048)).load()
    assert m.metadata["unit_from"] == "config"


def test_more_than_255_markers_take_their_labels_from_labels2(tmp_path: Path) -> None:
    """C3D parameters hold at most 255 entries: a file of 300 markers (written by ezc3d) names
    points 256-300 in POINT:LABELS2. Here 259 static lab markers come first and OpenSim's real
    41 gait markers last (4 of them in LABELS, 37 in LABELS2): the body is the TRC file's."""
    import ezc3d
    from mdf_c3d import TrcConfig, TrcSource, read_trc

    trc = EXAMPLES / "data" / "trc" / "opensim_subject01_walk.trc"
    m = read_trc(trc)
    tracks = {f"LAB{k:03d}": np.full((m.n_frames, 3), 0.01 * k) for k in range(259)}
    tracks.update({name: m.positions[:, k] * m.unit_m for k, name in enumerate(m.labels)})
    path = tmp_path / "many.c3d"
    write_c3d(path, tracks, 60.0, "mm", 0.001)
    raw = ezc3d.c3d(str(path))["parameters"]["POINT"]
    assert len(raw["LABELS"]["value"]) == 255 and len(raw["LABELS2"]["value"]) == 45
    data = read_c3d(path)
    assert data.labels == tuple(tracks) and len(data.labels) == 300
    np.testing.assert_allclose(data.positions[:, 299] * 1e-3, tracks["Top.Head"], atol=1e-6)
    body = C3dSource(C3dConfig(file=path, axes=("x", "-z", "y"))).load()
    ref = TrcSource(TrcConfig(file=trc)).load()
    assert body.metadata["marker_set"] == "opensim-gait"
    np.testing.assert_allclose(body.skeleton.positions, ref.skeleton.positions, atol=1e-6)


#: a child process that reads a C3D file: exit 2 with the error's line, 0 when it reads
READ_IN_CHILD = """
import sys
from pathlib import Path
from mdframework import DataFileError
from mdf_c3d import read_c3d
try:
    read_c3d(Path(sys.argv[1]))
except DataFileError as exc:
    print(exc, file=sys.stderr)
    sys.exit(2)
"""


@pytest.mark.parametrize(
    ("where", "value", "message"),
    [
        # found by benchmarks/fuzz_motion.py: MOMENT_UNITS' group id made negative (a group
        # record then) crashed ezc3d with a segmentation fault
        (1048, 200, "the record at byte 1047 holds more than fits before the next record"),
        # POINT:LABELS said 255 labels of 30 characters where 124 fit before the next record
        (1132, 255, "the record at byte 1120 holds more than fits before the next record"),
        # POINT:LABELS' offset to the next record pointing far beyond the parameter section
        (
            1129,
            0x7F,
            "the record at byte 1120 points to its next record at 33783, outside the section",
        ),
        # POINT:UNITS with type 3, which is none of -1, 1, 2, 4
        (999, 3, "the record at byte 990 has type 3 and 1 dimensions"),
    ],
)
def test_a_damaged_parameter_section_is_one_line_not_a_crash(
    tmp_path: Path, where: int, value: int, message: str
) -> None:
    """The parameter section is walked in Python before ezc3d trusts its sizes and offsets;
    each damage is read in a child process, so a crash would show as its exit code."""
    raw = bytearray(REAL.read_bytes())
    raw[where] = value
    path = tmp_path / "damaged.c3d"
    path.write_bytes(bytes(raw))
    done = subprocess.run(
        [sys.executable, "-c", READ_IN_CHILD, str(path)], capture_output=True, text=True
    )
    assert done.returncode == 2, done.stderr[-500:]
    assert done.stderr == f"{path}: parameter section: {message}: the file is damaged\n"


def test_a_parameter_section_starting_with_two_zero_bytes_reads_as_qualisys_writes_it(
    tmp_path: Path,
) -> None:
    """Qualisys writes 0, 0 where the C3D User Guide has the first record's block (1) and the
    key 0x50; ezc3d reads such a file as if they were 1, 0x50, and so must the walk that runs
    before it (it refused the file as damaged)."""
    raw = bytearray(REAL.read_bytes())
    start = (raw[0] - 1) * 512
    assert raw[start : start + 2] == b"\x01\x50"
    raw[start : start + 2] = b"\x00\x00"
    path = tmp_path / "qualisys.c3d"
    path.write_bytes(bytes(raw))
    got, ref = read_c3d(path), read_c3d(REAL)
    assert got.labels == ref.labels
    np.testing.assert_array_equal(got.positions, ref.positions)


def test_a_parameter_of_more_than_32_kib_is_read(tmp_path: Path) -> None:
    """A record's offset to the next is 16 bits that ezc3d reads unsigned: a parameter of 50 KB
    (250 notes of 200 characters, which ezc3d writes and reads) is no damage (the walk read the
    offset signed and refused the file)."""
    import ezc3d

    c3d = ezc3d.c3d(str(REAL))
    c3d.add_parameter("NOTES", "TEXT", ["x" * 200] * 250)
    path = tmp_path / "big.c3d"
    c3d.write(str(path))
    got, ref = read_c3d(path), read_c3d(REAL)
    assert got.labels == ref.labels
    np.testing.assert_array_equal(got.positions, ref.positions)


def test_event_times_count_the_minutes(tmp_path: Path) -> None:
    """C3D EVENT:TIMES holds minutes in its first row and seconds in its second: an event at
    1 min 5.5 s is 65.5 s into the recording (the shipped file's events all lie in its first
    minute, so its minutes are all 0)."""
    import ezc3d

    path = tmp_path / "events.c3d"
    write_c3d(path, {"A": np.tile([0.1, 0.2, 0.3], (5, 1))}, 100.0, "mm", 0.001)
    c = ezc3d.c3d(str(path))
    c.add_parameter("EVENT", "USED", [2])
    c.add_parameter("EVENT", "LABELS", ["Foot Strike", "Foot Off"])
    c.add_parameter("EVENT", "CONTEXTS", ["Left", "Right"])
    c.add_parameter("EVENT", "TIMES", np.array([[1.0, 0.0], [5.5, 0.25]]))
    c.write(str(path))
    events = {label: (context, t) for label, context, t in read_c3d(path).events}
    assert events == {"Foot Strike": ("Left", 65.5), "Foot Off": ("Right", 0.25)}
