"""The ``trc`` source (plugin ``mdf-c3d``): TRC marker files, OpenSim's text format.

Physics on the real file shipped in ``examples/data/trc`` (2.5 s of OpenSim's subject01 walking
on a treadmill, 41 markers from head to toes, see its PROVENANCE.md): the belt speed from the
stance feet, the cadence from the markers against the heel strikes, rigid segments, and the
radar signature of ``examples/trc_walk.toml`` against the speeds the raw markers give. The
reader's bad-input rules on damaged copies of the real file.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from conftest import EXAMPLES
from helpers import write_c3d
from mdf_c3d import C3dConfig, C3dSource, TrcConfig, TrcSource, read_trc

from mdframework import CANONICAL_JOINTS, DataFileError
from mdframework.config import load_run_config
from mdframework.features import envelopes
from mdframework.pipeline import simulate
from mdframework.sanity import cadence_spm

REAL = EXAMPLES / "data" / "trc" / "opensim_subject01_walk.trc"
BELT_SPEED = 1.12  # examples/trc_walk.toml's person.speed: checked against the markers below


@pytest.fixture(scope="module")
def real() -> tuple[np.ndarray, np.ndarray, list[str]]:
    m = read_trc(REAL)
    return m.time, m.positions * m.unit_m, list(m.labels)


def _group(p: np.ndarray, labels: list[str], *names: str) -> np.ndarray:
    return p[:, [labels.index(n) for n in names]].mean(axis=1)


def _foot(p: np.ndarray, labels: list[str], side: str) -> np.ndarray:
    markers = ("Heel", "Midfoot.Sup", "Midfoot.Lat", "Toe.Lat", "Toe.Med")
    return _group(p, labels, *(f"{side}.{m}" for m in markers))


def _stances(t: np.ndarray, foot: np.ndarray) -> list[np.ndarray]:
    """Frames of each stance: the foot (or heel) within 1.5 cm of its lowest (Y is up)."""
    low = np.flatnonzero(foot[:, 1] < foot[:, 1].min() + 0.015)
    return np.split(low, np.flatnonzero(np.diff(low) > 1) + 1)


def test_real_file_header_units_and_time_base() -> None:
    m = read_trc(REAL)
    assert (m.n_frames, m.rate_hz, m.units, m.unit_m) == (151, 60.0, "mm", 1e-3)
    assert len(m.labels) == 41 and m.labels[:3] == ("R.ASIS", "L.ASIS", "V.Sacral")
    assert m.labels[-3:] == ("R.Temple", "L.Temple", "Top.Head")
    assert m.header["CameraRate"] == "60.00" and m.header["OrigNumFrames"] == "151"
    # the time base is Frame# / DataRate; the file's Time column (rounded to 1 ms) agrees
    assert m.time[-1] == pytest.approx(2.5) and np.all(np.diff(m.frames) == 1)
    assert np.isfinite(m.positions).all()
    # Y up: the top of the head 1.74-1.81 m above the floor, the heels within 6 cm of it
    head = m.positions[:, m.labels.index("Top.Head"), 1] * 1e-3
    assert 1.74 < head.min() < head.max() < 1.81
    assert m.positions[:, m.labels.index("R.Heel"), 1].min() * 1e-3 < 0.06


def test_real_treadmill_belt_speed_from_both_feet(real) -> None:
    """On a treadmill the stance foot rides the belt backwards (-X) at the belt speed, the same
    in every stance of both feet, while the pelvis stays put."""
    t, p, labels = real
    speeds = []
    for side in "RL":
        foot = _foot(p, labels, side)
        vx = np.gradient(foot[:, 0], t)
        for frames in _stances(t, foot):
            if frames.size >= 20:  # whole stances (the first is cut by the start)
                speeds.append(-float(np.median(vx[frames])))
    assert len(speeds) == 4
    assert np.ptp(speeds) < 0.02  # four stances within 2 cm/s of each other
    assert np.mean(speeds) == pytest.approx(BELT_SPEED, abs=0.01)
    pelvis = _group(p, labels, "R.ASIS", "L.ASIS", "V.Sacral")
    drift = np.polyfit(t, pelvis[:, 0], 1)[0]
    assert abs(drift) < 0.01  # m/s
    assert np.ptp(pelvis[:, 0]) < 0.06  # sways by a few cm only


def test_real_cadence_from_markers_matches_the_heel_strikes(real) -> None:
    """The sanity check's cadence (from the ankles the source maps) against the strides the heel
    strikes give: each frame where a heel comes down to within 1.5 cm of the belt."""
    t, p, labels = real
    strikes = {}
    for side in "RL":
        heel = _group(p, labels, f"{side}.Heel")
        strikes[side] = [t[f[0]] for f in _stances(t, heel) if f[0] > 0]
    assert len(strikes["R"]) == len(strikes["L"]) == 2
    stride = np.mean([b - a for a, b in strikes.values()])
    from_strikes = 2 * 60 / stride
    motion = TrcSource(TrcConfig(file=REAL, activity="walk")).load()
    sk = motion.skeleton
    from_markers = cadence_spm(sk.time, sk.joint("l_ankle"), sk.joint("r_ankle"))
    assert from_markers is not None
    assert from_markers == pytest.approx(from_strikes, rel=0.02)
    assert stride == pytest.approx(1.217, abs=0.001)
    assert from_strikes == pytest.approx(98.6, abs=0.1)  # an ordinary walking cadence
    # a stride on the belt: belt speed x stride time, an ordinary stride of a 1.8 m adult
    assert BELT_SPEED * stride == pytest.approx(1.36, abs=0.01)


def test_real_file_makes_the_whole_body_z_up_facing_forward(real) -> None:
    motion = TrcSource(TrcConfig(file=REAL, activity="walk")).load()
    sk, meta = motion.skeleton, motion.metadata
    assert meta["marker_set"] == "opensim-gait" and meta["frame_rate_hz"] == 60.0
    assert sk.joint_names == CANONICAL_JOINTS and sk.valid.all()
    z = {j: np.median(sk.joint(j)[:, 2]) for j in CANONICAL_JOINTS}
    assert z["head"] > z["neck"] > z["base"] > z["l_knee"] > z["l_ankle"] > 0
    assert 1.55 < z["head"] < 1.7 and 0.9 < z["base"] < 1.1
    for side, sign in (("l", 1), ("r", -1)):  # left is +y
        assert sign * np.median(sk.joint(f"{side}_shoulder")[:, 1]) > 0.1
        assert sign * np.median(sk.joint(f"{side}_hip")[:, 1]) > 0.03
    # facing +x: the toes are ahead of the ankles, the stance foot moves backwards
    assert np.median(sk.joint("l_toe")[:, 0] - sk.joint("l_ankle")[:, 0]) > 0.08
    assert np.median(np.gradient(sk.joint("r_ankle")[:, 0], sk.time)) < -0.5


def test_real_segments_are_rigid(real) -> None:
    """Bone lengths of the mapped body: the arm segments from single markers vary by under 1 %;
    the legs, whose knees and ankles are means of markers on two segments, by under 2.5 %."""
    motion = TrcSource(TrcConfig(file=REAL, activity="walk")).load()
    sk = motion.skeleton
    for s in "lr":
        for a, b, cv_max in (
            ("shoulder", "elbow", 0.01),
            ("elbow", "hand", 0.01),
            ("hip", "knee", 0.025),
            ("knee", "ankle", 0.025),
        ):
            d = np.linalg.norm(sk.joint(f"{s}_{a}") - sk.joint(f"{s}_{b}"), axis=1)
            assert d.std() / d.mean() < cv_max, (s, a, b)


def test_example_signature_torso_and_feet_match_the_raw_markers(real) -> None:
    """examples/trc_walk.toml walks the treadmill trial toward the radar at the belt speed.
    The spectrogram's strongest line sits at the pelvis's speed computed from the raw markers
    (belt speed plus the pelvis's own motion on the belt), and its upper envelope reaches the
    foot's top speed: between the heel's and the toe tip's."""
    t, p, labels = real
    res = simulate(load_run_config(EXAMPLES / "trc_walk.toml"))
    assert res.metadata["placement"]["speed"] == BELT_SPEED
    sanity = res.metadata["motion"]["sanity"]
    assert sanity["warnings"] == [] and sanity["glitches"]["count"] == 0
    assert sanity["cadence"]["ok"] and sanity["bones"]["cv_max"] < 0.03
    pelvis = _group(p, labels, "R.ASIS", "L.ASIS", "V.Sacral")
    vx = np.gradient(pelvis[:, 0], t)
    drift = np.polyfit(t, pelvis[:, 0], 1)[0]
    pelvis_speed = BELT_SPEED + float(np.median(vx)) - drift
    v = res.velocity
    dv = v[1] - v[0]
    v_peak = v[np.argmax(res.spectrogram.power, axis=0)]
    assert pelvis_speed == pytest.approx(1.10, abs=0.005)
    assert np.median(v_peak) == pytest.approx(pelvis_speed, abs=2 * dv)
    top = float(np.nanmax(envelopes(res.spectrogram.power, v).upper))
    fastest = {
        n: BELT_SPEED + np.gradient(p[:, labels.index(n), 0], t).max()
        for n in ("R.Heel", "L.Heel", "R.Toe.Tip", "L.Toe.Tip")
    }
    assert 3.6 < fastest["L.Heel"] < fastest["R.Heel"] < 3.7 < top
    assert top == pytest.approx(3.86, abs=0.01)
    assert top < 4.05 < min(fastest["R.Toe.Tip"], fastest["L.Toe.Tip"]) < 4.15


# --------------------------------------------------------------------------- bad input


@pytest.fixture(scope="module")
def lines() -> list[str]:
    return REAL.read_text().splitlines(keepends=True)


def _write(tmp_path: Path, lines: list[str], name: str = "walk.trc") -> Path:
    path = tmp_path / name
    path.write_text("".join(lines))
    return path


def _header(lines: list[str], key: str, value: str) -> list[str]:
    keys = lines[1].split("\t")
    values = lines[2].rstrip("\n").split("\t")
    values[[k.strip() for k in keys].index(key)] = value
    return [lines[0], lines[1], "\t".join(values) + "\n", *lines[3:]]


def test_truncated_file_message_as_documented(tmp_path, lines) -> None:
    path = _write(tmp_path, list(lines[:60]))
    with pytest.raises(DataFileError) as err:
        read_trc(path)
    assert str(err.value) == (
        f"{path}:3: the header's NumFrames is 151, but the file holds 54 data row(s) (last at "
        "line 60): the file is truncated or NumFrames is wrong"
    )


@pytest.mark.parametrize(
    ("change", "expect"),
    [
        (lambda ls: ls[:60], r"walk.trc:3: the header's NumFrames is 151, but the file holds 54"),
        (lambda ls: [*ls[:59], ls[59][:300] + "\n", *ls[60:]], r"walk.trc:60: \d+ field\(s\)"),
        (lambda ls: _header(ls, "NumFrames", "1000000000"), r"NumFrames 1000000000 is outside"),
        (lambda ls: _header(ls, "NumMarkers", "40"), r"walk.trc:4: line 4 names 41 marker"),
        (lambda ls: _header(ls, "NumMarkers", "1e12"), r"NumMarkers 1000000000000 is outside"),
        (lambda ls: _header(ls, "Units", "furlongs"), r"Units 'furlongs' is not one of mm"),
        (lambda ls: _header(ls, "DataRate", "nan"), r"DataRate nan Hz is outside"),
        (lambda ls: _header(ls, "DataRate", "120"), r"walk.trc:8: Time 0.017 s disagrees"),
        (lambda ls: ["Hello\n", *ls[1:]], r"walk.trc:1: not a TRC file"),
        (lambda ls: [*ls[:9], ls[9].replace("621.540410", "1e308", 1), *ls[10:]], r":10: .*beyond"),
        (lambda ls: [*ls[:9], ls[9].replace("621.540410", "inf", 1), *ls[10:]], r":10: .*finite"),
        (lambda ls: [*ls[:9], ls[9].replace("621.540410", "up", 1), *ls[10:]], r":10: 'up'"),
        (lambda ls: [*ls[:9], ls[9].replace("4\t", "3\t", 1), *ls[10:]], r":10: Frame# 3 does"),
        (lambda ls: [*ls[:3], ls[3].replace("L.ASIS", "R.ASIS"), *ls[4:]], r"named twice"),
    ],
)
def test_damaged_real_file_is_one_clear_error(tmp_path, lines, change, expect) -> None:
    path = _write(tmp_path, change(list(lines)))
    with pytest.raises(DataFileError, match=expect) as err:
        TrcSource(TrcConfig(file=path)).load()
    assert str(err.value).startswith(str(path)) and "\n" not in str(err.value)


def test_missing_markers_are_nan_and_the_joint_is_invalid_there(tmp_path, lines) -> None:
    """An empty field (how OpenSim writes a marker not seen) is missing: that frame's joint is
    invalid, the others are kept."""
    fields = lines[20].split("\t")
    k = 2 + 3 * 40  # Top.Head, the last marker
    fields[k : k + 3] = ["", "", ""]
    path = _write(tmp_path, [*lines[:20], "\t".join(fields), *lines[21:]])
    m = read_trc(path)
    assert np.isnan(m.positions[14, 40]).all() and np.isfinite(m.positions[15]).all()
    sk = TrcSource(TrcConfig(file=path)).load().skeleton
    head = CANONICAL_JOINTS.index("head")
    assert not sk.valid[14, head] and sk.valid[14].sum() == 16 and sk.valid[15].all()


def test_a_marker_at_exactly_the_origin_is_missing_in_trc_and_c3d(tmp_path, lines) -> None:
    """Writers that mark no gap otherwise leave a marker not seen at (0, 0, 0). Averaged into
    its joint, the lab's origin threw the left ankle of the real walk about 0.2 m for those
    frames, 10 m/s between frames, with no finding: such a marker is missing, in TRC files and
    (residual 0, not -1) in C3D files alike, and every other frame is read as before."""
    heel = 2 + 3 * 19  # L.Heel, one of the left ankle's three markers
    edited = list(lines)
    for k in range(31, 41):  # data rows 25..34 (the data start at line 7)
        fields = edited[k].split("\t")
        fields[heel : heel + 3] = ["0.000000", "0.000000", "0.000000"]
        edited[k] = "\t".join(fields)
    ankle = CANONICAL_JOINTS.index("l_ankle")
    reference = TrcSource(TrcConfig(file=REAL)).load().skeleton
    zeros = read_trc(_write(tmp_path, edited))
    assert (zeros.positions[25:35, 19] == 0).all()
    c3d = tmp_path / "walk.c3d"
    write_c3d(
        c3d,
        dict(zip(zeros.labels, np.moveaxis(zeros.positions, 1, 0), strict=True)),
        60.0,
        "mm",
        1.0,
    )
    for motion in (
        TrcSource(TrcConfig(file=_write(tmp_path, edited))).load(),
        C3dSource(C3dConfig(file=c3d, axes=("x", "-z", "y"))).load(),
    ):
        sk = motion.skeleton
        assert not sk.valid[25:35, ankle].any() and motion.metadata["zero_points"] == 10
        keep = np.ones(sk.valid.shape, dtype=bool)
        keep[25:35, ankle] = False
        assert sk.valid[keep].all()
        np.testing.assert_allclose(sk.positions[keep], reference.positions[keep], atol=1e-4)


def _keypoint_trc(path: Path, keypoints: dict[str, np.ndarray], rate: float) -> Path:
    """A TRC file as Pose2Sim writes one: metres, OpenSim's frame (Y up, Z right), from
    keypoint tracks (n, 3) [m] in the project's frame."""
    names = list(keypoints)
    n = len(next(iter(keypoints.values())))
    head = [
        "PathFileType\t4\t(X/Y/Z)\tkeypoints.trc",
        "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame\tOrigNumFrames",
        f"{rate}\t{rate}\t{n}\t{len(names)}\tm\t{rate}\t0\t{n}",
        "Frame#\tTime\t" + "\t\t\t".join(names),
        "\t\t" + "\t".join(f"{a}{k + 1}" for k in range(len(names)) for a in "XYZ"),
        "",
    ]
    rows = []
    for f in range(n):
        xyz = [
            v for m in names for v in (keypoints[m][f, 0], keypoints[m][f, 2], -keypoints[m][f, 1])
        ]
        rows.append("\t".join([str(f), f"{f / rate:.6f}", *(f"{v:.7f}" for v in xyz)]))
    path.write_text("\n".join(head + rows) + "\n")
    return path


def test_markerless_keypoints_as_pose2sim_writes_them_make_the_body(tmp_path) -> None:
    """Pose2Sim (markerless capture) writes TRC files of keypoints named as HALPE_26 or
    OpenPose's BODY_25 (Hip or MidHip, LHip, LKnee, LAnkle, LBigToe, LSmallToe, Neck, Head or
    the ears, Nose, LShoulder, LElbow, LWrist, ...): no marker set fitted them, so every user
    had to map all 17 joints. The keypoints set maps them: the real walk written as keypoints
    (in metres, Y up) comes back as the same body."""
    body = TrcSource(TrcConfig(file=REAL)).load().skeleton
    j = {name: body.positions[:, k] for k, name in enumerate(body.joint_names)}
    side = np.array([0.0, 0.02, 0.0])
    halpe = {"Hip": j["base"], "Neck": j["neck"], "Head": j["head"], "Nose": j["head"] + 0.08}
    for s, c in (("L", "l"), ("R", "r")):
        for name, joint in (
            ("Hip", "hip"),
            ("Knee", "knee"),
            ("Ankle", "ankle"),
            ("Shoulder", "shoulder"),
            ("Elbow", "elbow"),
            ("Wrist", "hand"),
        ):
            halpe[s + name] = j[f"{c}_{joint}"]
        halpe[s + "BigToe"], halpe[s + "SmallToe"] = j[f"{c}_toe"] + side, j[f"{c}_toe"] - side
        halpe[s + "Heel"] = j[f"{c}_ankle"] - np.array([0.05, 0.0, 0.05])
    body25 = {k: v for k, v in halpe.items() if k not in ("Hip", "Head")}
    body25 |= {"MidHip": j["base"], "LEar": j["head"] + side, "REar": j["head"] - side}
    # a set without the small toes: the big toe alone is the toe
    big = {k: v for k, v in body25.items() if "SmallToe" not in k}
    big |= {"LBigToe": j["l_toe"], "RBigToe": j["r_toe"]}
    for name, keypoints in (("halpe", halpe), ("body25", body25), ("big toes", big)):
        motion = TrcSource(
            TrcConfig(file=_keypoint_trc(tmp_path / f"{name}.trc", keypoints, 60.0))
        ).load()
        assert motion.metadata["marker_set"] == "keypoints", name
        np.testing.assert_allclose(motion.skeleton.positions, body.positions, atol=1e-6)
        np.testing.assert_allclose(motion.skeleton.time, body.time)


def test_rows_left_out_and_renumbered_are_named_as_such(tmp_path, lines) -> None:
    """A writer that leaves out 30 rows (0.5 s at 60 Hz) and renumbers Frame# keeps the gap in
    Time only. The error said to correct DataRate or give motion.frame_rate, which reads the
    motion without the gap; it names the jump and says to number the frames as Time does."""
    data = lines[6:66] + lines[96:]
    renumbered = [f"{k + 1}\t" + row.split("\t", 1)[1] for k, row in enumerate(data)]
    path = _write(tmp_path, _header([*lines[:6], *renumbered], "NumFrames", str(len(data))))
    with pytest.raises(DataFileError) as err:
        read_trc(path)
    assert str(err.value) == (
        f"{path}:67: Time jumps 0.517 s from the row before while Frame# steps by 1 (0.01667 s at "
        "DataRate 60 Hz): rows were left out and the frames renumbered; the time base is "
        "Frame# / DataRate, so number the frames as Time says (motion.frame_rate would read the "
        "motion without the gap)"
    )


def test_one_row_left_out_and_renumbered_is_named_too(tmp_path, lines) -> None:
    """A single row left out (a step of two frames, more than 1.5 median steps) is a jump as
    well; a Frame# that also jumps, by other than Time does, is no renumbering: that file's
    Time and Frame# disagree, as a wrong DataRate's do."""
    data = lines[6:66] + lines[67:]
    renumbered = [f"{k + 1}\t" + row.split("\t", 1)[1] for k, row in enumerate(data)]
    path = _write(tmp_path, _header([*lines[:6], *renumbered], "NumFrames", str(len(data))))
    with pytest.raises(DataFileError, match=r":67: Time jumps 0.034 s from the row before"):
        read_trc(path)
    data = lines[6:66] + lines[96:]
    skipped = [
        f"{k + 1 + (10 if k >= 60 else 0)}\t" + row.split("\t", 1)[1] for k, row in enumerate(data)
    ]
    path = _write(tmp_path, _header([*lines[:6], *skipped], "NumFrames", str(len(data))))
    with pytest.raises(DataFileError, match=r":67: Time 1.5 s disagrees with Frame# 71"):
        read_trc(path)


def test_units_and_frame_rate_overrides(tmp_path, lines) -> None:
    path = _write(tmp_path, _header(list(lines), "Units", "furlongs"))
    motion = TrcSource(TrcConfig(file=path, unit_m=1e-3, frame_rate=120.0)).load()
    assert (
        motion.metadata["unit_from"] == "config" and motion.metadata["frame_rate_from"] == "config"
    )
    assert motion.skeleton.time[-1] == pytest.approx(150 / 120)
    metres = TrcSource(TrcConfig(file=REAL)).load().skeleton.positions
    np.testing.assert_allclose(motion.skeleton.positions, metres)


def test_whitespace_separated_rows_are_read_like_tabs(tmp_path, lines) -> None:
    spaced = [*lines[:5], *[" ".join(s.split()) + "\n" for s in lines[5:]]]
    a, b = read_trc(REAL), read_trc(_write(tmp_path, spaced))
    np.testing.assert_array_equal(a.positions, b.positions)


def test_config_refuses_another_extension_and_bad_axes(tmp_path) -> None:
    (tmp_path / "walk.c3d").write_bytes(REAL.read_bytes())
    with pytest.raises(ValueError, match=r"must be a \.trc file, got 'walk.c3d'"):
        TrcConfig(file=tmp_path / "walk.c3d")
    with pytest.raises(ValueError, match="axes must name x, y and z"):
        TrcConfig(file=REAL, axes=("x", "x", "y"))


def test_binary_and_latin1_files(tmp_path, lines) -> None:
    """A NUL byte is binary data, refused naming its line; a header line written in Latin-1 (an
    old writer's Windows path) is read."""
    path = tmp_path / "walk.trc"
    path.write_bytes("".join(lines[:8]).encode() + b"\x00\x01")
    with pytest.raises(DataFileError, match=r"walk.trc:9: binary data \(a NUL byte\)"):
        read_trc(path)
    latin = [lines[0].replace("subject01_walk1.trc", "C:\\Données\\walk.trc"), *lines[1:]]
    path.write_bytes("".join(latin).encode("latin-1"))
    assert read_trc(path).n_frames == 151


def test_the_same_real_markers_in_a_c3d_file_give_the_same_body(tmp_path) -> None:
    """The real TRC's markers written into a C3D file through ezc3d (OpenSim's frame, y up):
    the c3d source, given the same axes, finds the same marker set and makes the same body, to
    the float32 precision C3D stores (well under a micrometre here)."""
    m = read_trc(REAL)
    tracks = {name: m.positions[:, k] * m.unit_m for k, name in enumerate(m.labels)}
    write_c3d(tmp_path / "walk.c3d", tracks, 60.0, "mm", 0.001)
    a = TrcSource(TrcConfig(file=REAL)).load()
    b = C3dSource(C3dConfig(file=tmp_path / "walk.c3d", axes=("x", "-z", "y"))).load()
    assert a.metadata["marker_set"] == b.metadata["marker_set"] == "opensim-gait"
    assert a.metadata["markers"] == b.metadata["markers"]
    np.testing.assert_allclose(b.skeleton.time, a.skeleton.time)
    np.testing.assert_allclose(b.skeleton.positions, a.skeleton.positions, rtol=0, atol=1e-6)


def test_skipped_frame_numbers_keep_their_time(tmp_path, lines) -> None:
    """A tracker that lost the subject for Frame# 31..60 (0.5 s at 60 Hz) writes no rows for
    them: each kept frame stays at (Frame# - 1) / 60 s, so the body is where the full
    recording has it at that time, and the run is warned about the gap."""
    rows = [r for r in lines[6:] if not 31 <= int(r.split("\t")[0]) <= 60]
    head = _header(list(lines[:6]), "NumFrames", str(len(rows)))
    path = _write(tmp_path, [*head, *rows])
    with pytest.warns(UserWarning) as caught:
        gap = TrcSource(TrcConfig(file=path)).load()
    # as docs/motion-formats.md shows it
    assert [str(w.message) for w in caught] == [
        f"{path}: Frame# skips 30 frame(s) (the longest gap 0.5167 s, after Frame# 30 at "
        "0.4833 s): the time base keeps the gaps, and the motion is interpolated across them"
    ]
    frame_numbers = np.array([int(r.split("\t")[0]) for r in rows])
    t = gap.skeleton.time
    np.testing.assert_allclose(t, (frame_numbers - 1) / 60.0, rtol=0, atol=1e-12)
    assert t[30] == pytest.approx(1.0) and t[-1] == pytest.approx(2.5)
    assert gap.skeleton.duration == pytest.approx(2.5) and gap.metadata["frames_skipped"] == 30
    full = TrcSource(TrcConfig(file=REAL)).load().skeleton
    np.testing.assert_array_equal(gap.skeleton.positions, full.positions[frame_numbers - 1])


def test_missing_frames_are_a_gap_for_conditioning(tmp_path, lines) -> None:
    """Frames a tracker did not write (Frame# 31..60: 0.517 s between the frames around them)
    are a gap of every joint: conditioning flags them in its report, and with
    long_gaps = "error" stops, as it does for a joint lost that long (they were bridged
    silently: no joint is untracked in the frames that are there)."""
    from mdframework.conditioning import condition
    from mdframework.settings import ConditioningConfig

    rows = [r for r in lines[6:] if not 31 <= int(r.split("\t")[0]) <= 60]
    head = _header(list(lines[:6]), "NumFrames", str(len(rows)))
    path = _write(tmp_path, [*head, *rows])
    with pytest.warns(UserWarning, match="Frame# skips 30"):
        body = TrcSource(TrcConfig(file=path)).load().canonical()
    _, report = condition(body, ConditioningConfig(enabled=True))
    assert report["gaps"]["n_gaps"] == 0
    [hole] = report["gaps"]["missing_frames"]
    assert hole["after_frame"] == 29 and hole["after_s"] == pytest.approx(29 / 60)
    assert hole["duration_s"] == pytest.approx(31 / 60)
    _, report = condition(body, ConditioningConfig(enabled=True, max_gap_s=0.6))
    assert report["gaps"]["missing_frames"] == []
    stop = ConditioningConfig(enabled=True, long_gaps="error")
    with pytest.raises(ValueError) as err:
        condition(body, stop)
    assert str(err.value) == (
        "the recording has no frame for 0.517 s (after frame 29 at 0.483 s), longer than "
        "conditioning.max_gap_s = 0.2 s"
    )


def _blank(row: str, labels: tuple[str, ...], names: tuple[str, ...]) -> str:
    """A data row with the named markers' fields emptied (not seen in that frame)."""
    fields = row.rstrip("\n").split("\t")
    for name in names:
        k = 2 + 3 * labels.index(name)
        fields[k : k + 3] = ["", "", ""]
    return "\t".join(fields) + "\n"


def test_the_frames_beside_a_gap_are_not_glitches(tmp_path, lines) -> None:
    """Two gaps cut into the real walk: the tracker wrote no rows for Frame# 60..75 (0.283 s
    between the frames around them), and the right foot's markers are blank in Frame#
    101..110. Beside a gap a frame's neighbour is missing or a gap away, so its deviation says
    nothing about a spike: the real frames there are neither flagged nor repaired, at the
    default 2 cm (which the dropped rows tripped) nor at 3 mm (which the blank foot tripped;
    the intact walk at 60 Hz deviates by at most 5.6 mm and is clean at 3 mm too). A 5 cm
    one-frame spike of the left elbow marker at Frame# 30 is still found, and only it."""
    from mdframework.pipeline import load_motion
    from mdframework.settings import SanityConfig

    labels = read_trc(REAL).labels
    foot = ("R.Heel", "R.Midfoot.Sup", "R.Midfoot.Lat", "R.Toe.Lat", "R.Toe.Med")
    rows = []
    for row in lines[6:]:
        frame = int(row.split("\t")[0])
        if 60 <= frame <= 75:
            continue
        if 101 <= frame <= 110:
            row = _blank(row, labels, foot)
        if frame == 30:
            fields = row.split("\t")
            k = 2 + 3 * labels.index("L.Elbow")
            fields[k] = f"{float(fields[k]) + 50.0:.6f}"
            row = "\t".join(fields)
        rows.append(row)
    path = _write(tmp_path, [*_header(list(lines[:6]), "NumFrames", str(len(rows))), *rows])

    def load(file: Path, **sanity: object) -> tuple[list[tuple[str, int]], np.ndarray]:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            motion = load_motion(TrcSource(TrcConfig(file=file, sanity=SanityConfig(**sanity))))
        items = motion.metadata["sanity"]["glitches"]["items"]
        return [(it["joint"], it["frame"]) for it in items], motion.skeleton.positions

    assert load(REAL, glitch_min_m=0.003)[0] == []
    spike = [("l_elbow", 29)]
    assert load(path)[0] == spike
    found, raw = load(path, glitch_min_m=0.003, glitches="ignore")
    assert found == spike
    _, repaired = load(path, glitch_min_m=0.003, glitches="repair")
    changed = np.any(np.nan_to_num(repaired) != np.nan_to_num(raw), axis=2)
    assert np.argwhere(changed).tolist() == [[29, CANONICAL_JOINTS.index("l_elbow")]]


@pytest.mark.parametrize("unit,per_mm", [("in", 1 / 25.4), ("cm", 0.1), ("m", 1e-3)])
def test_the_real_walk_in_other_units_is_the_same_body(tmp_path: Path, unit: str, per_mm: float):
    """The shipped walk (mm) rewritten in inches (25.4 mm each), cm and m: every joint where the
    mm file puts it (to 1e-9 m), so each unit's metres per unit is right."""
    lines = REAL.read_text().split("\n")
    assert lines[2].split("\t")[4] == "mm"
    head = lines[2].split("\t")
    head[4] = unit
    out = [*lines[:2], "\t".join(head), *lines[3:5]]
    for ln in lines[5:]:
        cells = ln.split("\t")
        if len(cells) > 2:
            cells = cells[:2] + [f"{float(c) * per_mm!r}" if c else c for c in cells[2:]]
        out.append("\t".join(cells))
    path = tmp_path / "walk.trc"
    path.write_text("\n".join(out))
    want = TrcSource(TrcConfig(file=REAL)).load().skeleton.positions
    got = TrcSource(TrcConfig(file=path)).load().skeleton.positions
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
    assert np.nanmax(np.abs(want)) > 0.5
