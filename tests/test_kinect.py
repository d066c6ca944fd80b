"""The ``kinect`` plugin (``mdf-kinect``): .oni files through the real OpenNI2 library, NiTE2
structures, and the Kinect skeleton readers on the real recordings shipped in
``examples/data/kinect`` (see its PROVENANCE.md).

Mocked, because they cannot exist here: NiTE2 itself (proprietary, not installable) and a Kinect
device. The NiTE structures below are the binding's own ctypes classes, filled by the test.
"""

from __future__ import annotations

import re
import struct
import subprocess
import sys
import warnings
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
from mdf_kinect import (
    KINECT_V1_JOINTS,
    MSR_JOINTS,
    NITE_JOINTS,
    DeviceError,
    KinectConfig,
    KinectSource,
    NiteMissingError,
    initialize_nite,
    initialize_openni,
    nite_frames_to_arrays,
    oni_info,
    open_device,
    read_msr,
    read_nite,
    read_ntu,
    read_oni_depth,
    read_precog,
    read_utkinect,
    scan_oni,
    write_nite,
)
from mdf_kinect.source import TrackingWarning

from mdframework import CANONICAL_SEGMENTS, DataFileError, cli

DATA = Path(__file__).parents[1] / "examples" / "data" / "kinect"
ONI = DATA / "oni" / "test.oni"
UT = DATA / "utkinect" / "joints_s01_e01.txt"
# one recording per action for the strict geometry checks (the other shipped episodes feed the
# cross-source dataset; a few of them have noisier heads than the 0.2 tolerance allows)
MSR = sorted((DATA / "msr-action3d").glob("a??_s01_e01_skeleton3D.txt"))
MSR_ALL = sorted((DATA / "msr-action3d").glob("*.txt"))
PRECOG = DATA / "precog" / "Seq1_1.csv"


# --------------------------------------------------------------------------- .oni, real library


def test_real_oni_through_openni2() -> None:
    frames = read_oni_depth(ONI)
    assert len(frames) == 12
    assert all(f.depth.shape == (480, 640) and f.depth.dtype == np.uint16 for f in frames)
    stamps = np.array([f.timestamp_us for f in frames])
    assert np.all(np.diff(stamps) > 0)
    # a Kinect v1 at 30 Hz: 33.3 ms steps
    assert np.allclose(np.diff(stamps), 1e6 / 30, rtol=0.01)
    # real depth: mostly in the Kinect's 0.5-4 m range
    valid = frames[0].depth[frames[0].depth > 0]
    assert 500 < np.median(valid) < 4000


def test_the_python_scan_counts_the_frames_openni2_reads() -> None:
    """scan_oni walks the record chain without the library; its frames per stream agree with
    what OpenNI2 itself reports for the same real recording (12 depth, 12 colour)."""
    scan = scan_oni(ONI)
    by_name = {scan.nodes[node]: n for node, n in scan.frames_per_node.items()}
    streams = oni_info(ONI)["streams"]  # frame counts from OpenNI2
    assert by_name == {"Depth1": streams["depth"]["frames"], "Image1": streams["color"]["frames"]}
    assert by_name["Depth1"] == len(read_oni_depth(ONI)) == 12
    assert scan.by_type["new data"] == sum(scan.frames_per_node.values())
    assert scan.by_type["end"] == 1 and scan.n_records == sum(scan.by_type.values())


def test_oni_reads_survive_repeated_fresh_processes() -> None:
    """Regression: OpenNI2's file player thread walks its list of streams without a lock, so
    destroying a stream (or closing the device with a stream alive) while it runs crashed it
    now and then, most often in a process's first playback: 6 of 50 runs of this file's .oni
    tests segfaulted before the teardown waited for the thread to go idle
    (``device._playback``), and about one fresh process in six reading test.oni. Here 16
    fresh processes (4 at a time) each read the file's info and depth frames; a crash kills
    only the child."""
    code = (
        "from pathlib import Path\n"
        "from mdf_kinect import oni_info, read_oni_depth\n"
        f"p = Path({str(ONI)!r})\n"
        "assert len(read_oni_depth(p)) == 12\n"
        "assert set(oni_info(p)['streams']) == {'depth', 'color'}\n"
    )
    failures = []
    for _ in range(4):
        children = [
            subprocess.Popen(
                [sys.executable, "-c", code], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
            )
            for _ in range(4)
        ]
        for child in children:
            _, err = child.communicate(timeout=120)
            if child.returncode != 0:
                failures.append((child.returncode, err.decode(errors="replace")[-500:]))
    assert not failures, failures


#: a child process that reads a recording's depth frames: exit 2 with the error's line
READ_DEPTH = """
import sys
from pathlib import Path
from mdframework import DataFileError
from mdf_kinect import read_oni_depth
try:
    read_oni_depth(Path(sys.argv[1]))
except DataFileError as exc:
    print(exc, file=sys.stderr)
    sys.exit(2)
"""


def _damaged(tmp_path: Path, where: int, value: int) -> Path:
    raw = bytearray(ONI.read_bytes())
    raw[where] = value
    path = tmp_path / "damaged.oni"
    path.write_bytes(bytes(raw))
    return path


def test_a_recording_that_crashes_openni2_is_one_line(tmp_path: Path) -> None:
    """Found by benchmarks/fuzz_motion.py's kind of damage: one byte of a property's name
    (PhysicalDeviceName, 'c' -> 0xE0) leaves the record chain sound, and OpenNI2 crashes the
    process (a segmentation fault) playing it. `mdf kinect info` plays it in a child process,
    so the crash is one line naming the file (run here in a child too, so that a regression
    fails this test instead of killing the test process)."""
    path = _damaged(tmp_path, 375, 0xE0)
    scan_oni(path)  # the structure is sound: the Python checks cannot see this damage
    done = subprocess.run(
        [sys.executable, "-m", "mdframework.cli", "kinect", "info", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2, (done.returncode, done.stderr[-500:])
    assert done.stderr == (
        f"mdf: error: {path}: OpenNI2 crashed while playing this recording (its structure is "
        "sound, so a record's contents are damaged)\n"
    )


def test_a_depth_frame_that_decodes_short_is_one_line(tmp_path: Path) -> None:
    """One byte of frame 8's compressed depth changed (0xE2 -> 0xD8): OpenNI2 decodes it to 2
    pixels fewer than 480 x 640, which was an internal error (a reshape's ValueError)."""
    path = _damaged(tmp_path, 1395424, 0xD8)
    done = subprocess.run(
        [sys.executable, "-c", READ_DEPTH, str(path)], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 2, (done.returncode, done.stderr[-500:])
    assert done.stderr == (
        f"{path}: depth frame 8 decodes to 307198 pixels, not 480 x 640: the recording is damaged\n"
    )


def _s(text: str) -> bytes:
    b = text.encode() + b"\0"
    return struct.pack("<I", len(b)) + b


def _rec(typ: int, node: int, fields: bytes = b"", payload: bytes = b"", undo: int = 0) -> bytes:
    head = struct.pack("<4sIIIIQ", b"NIR\0", typ, node, 28 + len(fields), len(payload), undo)
    return head + fields + payload


def write_oni(path: Path, frames: np.ndarray, stamps_us: list[int], fps: int = 30) -> None:
    """A minimal uncompressed depth-only .oni: header, node added, the stream properties
    OpenNI2 needs, one 'new data' record per frame, node removed, seek table, end."""
    n, h, w = frames.shape
    out = bytearray(b"NI10" + struct.pack("<BBHIQI", 1, 0, 1, 0, stamps_us[-1], 1))
    node_pos = len(out)

    def node_added(seek: int) -> bytes:
        f = _s("Depth1") + struct.pack("<I", 2) + b"NONE"
        return _rec(13, 1, f + struct.pack("<IQQQ", n, stamps_us[0], stamps_us[-1], seek))

    out += node_added(0)
    out += _rec(3, 1, _s("xnBytesPerPixel") + struct.pack("<Iq", 8, 2))
    out += _rec(6, 1, _s("xnMapOutputMode") + struct.pack("<I3I", 12, w, h, fps))
    out += _rec(6, 1, _s("xnCropping") + struct.pack("<I", 12) + bytes(12))
    out += _rec(3, 1, _s("xnDeviceMaxDepth") + struct.pack("<Iq", 8, 10000))
    out += _rec(9, 1) + _rec(8, 1, bytes(12))
    seek = [(0, 0, 0)]
    prev = 0
    for i in range(n):
        seek.append((stamps_us[i], 0, len(out)))
        rec = _rec(
            10, 1, struct.pack("<QI", stamps_us[i], i + 1), frames[i].astype("<u2").tobytes(), prev
        )
        prev = len(out)
        out += rec
    out += _rec(7, 1, undo=node_pos)
    seek_pos = len(out)
    out += _rec(14, 1, payload=b"".join(struct.pack("<QIQ", *e) for e in seek))
    out += _rec(11, 0xFFFFFFFF)
    out[node_pos : node_pos + len(node_added(0))] = node_added(seek_pos)
    path.write_bytes(bytes(out))


@pytest.mark.parametrize("n,h,w", [(2, 4, 6), (7, 48, 64), (5, 120, 160)])
def test_written_oni_read_back_bit_exactly(tmp_path: Path, n: int, h: int, w: int) -> None:
    rng = np.random.default_rng(n * h)
    frames = rng.integers(0, 65535, (n, h, w), dtype=np.uint16)
    stamps = list(np.cumsum(rng.integers(20_000, 50_000, n)))  # uneven steps: frame drops
    path = tmp_path / "written.oni"
    write_oni(path, frames, [int(s) for s in stamps])
    back = read_oni_depth(path)
    assert len(back) == n
    for k, f in enumerate(back):
        assert f.timestamp_us == stamps[k]
        assert np.array_equal(f.depth, frames[k])


def test_oni_wrong_magic_and_zero_frames(tmp_path: Path) -> None:
    bad = tmp_path / "bad.oni"
    bad.write_bytes(b"NI11" + ONI.read_bytes()[4:4000])
    with pytest.raises(DataFileError, match=r"bad\.oni.*magic b'NI11'"):
        read_oni_depth(bad)
    with pytest.raises(DataFileError, match=r"zero-frames\.oni.*holds no frame"):
        read_oni_depth(DATA / "oni" / "zero-frames.oni")
    cut = tmp_path / "cut.oni"
    cut.write_bytes(ONI.read_bytes()[:50_000])
    with pytest.raises(DataFileError, match=r"cut\.oni: record \d+ at byte \d+: truncated"):
        scan_oni(cut)
    garbage = tmp_path / "garbage.oni"
    garbage.write_bytes(np.random.default_rng(1).integers(0, 256, 5000, dtype=np.uint8).tobytes())
    with pytest.raises(DataFileError, match="not an OpenNI recording"):
        read_oni_depth(garbage)


def test_mdf_kinect_info_on_real_oni(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["kinect", "info", str(ONI)]) == 0
    out = capsys.readouterr().out
    assert "depth: 640x480 DEPTH_1_MM, 12 frames" in out
    info = oni_info(ONI)
    d = info["streams"]["depth"]
    assert d["timestamps_increasing"] and d["measured_fps"] == pytest.approx(30, rel=0.01)
    assert cli.main(["kinect", "info", str(DATA / "oni" / "zero-frames.oni")]) == 2
    assert "holds no frame" in capsys.readouterr().err


def test_no_device_is_a_clear_error() -> None:
    openni2 = initialize_openni()
    with pytest.raises(DeviceError, match="cannot open the first OpenNI2 device"):
        open_device(openni2, None)


# --------------------------------------------------------------------------- NiTE2


def test_nite_missing_message(monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys) -> None:
    monkeypatch.delenv("NITE2_REDIST", raising=False)
    with pytest.raises(NiteMissingError, match=r"skeleton tracking needs NiTE2.*NITE2_REDIST"):
        initialize_nite()
    with pytest.raises(NiteMissingError, match=r"libNiTE2\.so does not exist"):
        initialize_nite(str(tmp_path))
    assert cli.main(["capture", "--out", str(tmp_path / "x.txt"), "--duration", "1"]) == 2
    assert "skeleton tracking needs NiTE2" in capsys.readouterr().err


#: The Kinect v1 joints that stand for NiTE's 15 (NITE_JOINTS order).
PICK_V1 = ["Head", "ShoulderCenter", "ShoulderLeft", "ShoulderRight", "ElbowLeft", "ElbowRight",
           "HandLeft", "HandRight", "Spine", "HipLeft", "HipRight", "KneeLeft", "KneeRight",
           "AnkleLeft", "AnkleRight"]  # fmt: skip


def _nite_user(user_id: int, joints_mm: np.ndarray, conf: float, tracked: bool = True):
    """A binding NiteUserData as NiTE2 would fill it (NiTE2 itself cannot be installed here)."""
    from openni import _nite2

    u = _nite2.NiteUserData()
    u.id = user_id
    u.skeleton.state = 2 if tracked else 1
    for j in range(15):
        u.skeleton.joints[j].jointType = j
        u.skeleton.joints[j].position = _nite2.NitePoint3f(*joints_mm[j])
        u.skeleton.joints[j].positionConfidence = conf
    return u


def test_nite_structures_to_skeleton(tmp_path: Path) -> None:
    body = read_utkinect(UT)  # a real Kinect body to fill the NiTE joints with
    v1 = {n: i for i, n in enumerate(KINECT_V1_JOINTS)}
    pick = PICK_V1
    frames = []
    for k in range(10):
        p = body.positions[k, [v1[n] for n in pick]]
        mm = np.stack([-p[:, 0], p[:, 1], p[:, 2]], 1) * 1000.0  # NiTE: mm, x to the right
        users = [_nite_user(7, mm + 500.0, 0.3, tracked=False), _nite_user(3, mm, 1.0)]
        frames.append((1_000_000 + int(body.time[k] * 1e6), k + 1, users))
    t, pos, conf, idx, user = nite_frames_to_arrays(frames)
    assert user == 3 and list(idx) == list(range(1, 11))
    assert np.allclose(t, body.time[:10] - body.time[0], atol=1e-6)
    expect = body.positions[:10, [v1[n] for n in pick]]
    assert np.allclose(pos, expect, atol=1e-4)  # float32 in the structures
    assert np.all(conf == 1.0)
    # and through the documented file format into a Motion
    path = tmp_path / "rec.nite.txt"
    with path.open("w") as fh:
        write_nite(fh, t, idx, user, pos, conf, {"device": "test", "software": "test"})
    rec = read_nite(path)
    assert rec.joint_names[:15] == NITE_JOINTS and rec.positions.shape == (10, 18, 3)
    motion = KinectSource(KinectConfig(format="nite", file=path)).load()
    c = motion.canonical()
    assert c.n_joints == 17 and np.all(np.isfinite(c.positions))
    # a file is one person: a line of another user is refused, naming it
    lines = path.read_text().splitlines()
    k = len(lines) - 3
    fields = lines[k].split()
    lines[k] = " ".join([*fields[:2], "4", *fields[3:]])
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(DataFileError, match="user id 4 differs from the first frame's 3") as err:
        read_nite(path)
    assert err.value.line == k + 1


# --------------------------------------------------------------------------- readers, real data


def bone_lengths(sk) -> dict[tuple[str, str], np.ndarray]:
    return {
        (a, b): np.linalg.norm(sk.joint(a) - sk.joint(b), axis=1) for a, b in CANONICAL_SEGMENTS
    }


def check_body(motion, n_source_joints: int, max_rel_spread: float) -> None:
    assert motion.skeleton.n_joints == n_source_joints
    c = motion.canonical()
    assert c.n_joints == 17
    for (a, b), length in bone_lengths(c).items():
        med = float(np.median(length))
        assert 0.03 < med < 0.7, (a, b, med)
        # rigid bones: constant within the Kinect's noise (a robust spread)
        q25, q75 = np.percentile(length, [25, 75])
        assert (q75 - q25) / med < max_rel_spread, (a, b, med, q75 - q25)
    base = c.joint("base")
    assert np.all((base[:, 0] > 1.8) & (base[:, 0] < 3.2))  # 2-3 m from the sensor
    head, toe = c.joint("head")[:, 2], c.joint("l_toe")[:, 2]
    assert np.median(head - toe) > 1.2  # upright, z up


def test_utkinect_real() -> None:
    rec = read_utkinect(UT)
    # time from the frame numbers (steps of 2-10, repeats dropped), not a fixed rate; the
    # numbers count 60 per second: all even, and the dataset's "about 15 frames per second"
    assert np.allclose(rec.time, rec.frame_numbers / 60.0)
    assert np.all(rec.frame_numbers % 2 == 0)
    kept_per_s = rec.time.size / (rec.time[-1] - rec.time[0])
    assert 14.0 < kept_per_s < 18.0
    steps = np.diff(rec.frame_numbers)
    assert steps.min() >= 1 and len(set(steps)) > 1
    assert rec.metadata["duplicate_frames_dropped"] > 0
    m = KinectSource(KinectConfig(format="utkinect", file=UT, segment="walk")).load()
    assert m.metadata["segment"] == {"label": "walk", "first_frame": 252, "last_frame": 390}
    assert m.skeleton.duration == pytest.approx((390 - 252) / 60, abs=4 / 60)
    check_body(m, 20, 0.35)


@pytest.mark.parametrize(
    "text,line,match",
    [
        ("s01_e01\nwalk: 252 1e300\n", 2, "frame number 1e+300 is not a whole number"),
        ("s01_e01\nwalk: -50 390\n", 2, "frame number -50.0 is not a whole number"),
        ("s01_e01\nwalk: 252.7 390\n", 2, "frame number 252.7 is not a whole number"),
        ("s01_e01\nwalk: 390 252\n", 2, "'walk' ends at frame 252, before its first 390"),
        ("s01_e01\nwalk: 252 390\n\nwalk: 572 686\n", 4, "action 'walk' of s01_e01 given twice"),
        ("s01_e01\nwalk: 252 390\ns01_e01\nwalk: 572 686\n", 3, "sequence 's01_e01' given twice"),
    ],
)
def test_utkinect_labels_are_checked(tmp_path: Path, text: str, line: int, match: str) -> None:
    """A segment label that is not a frame number, runs backwards, or is given twice would cut
    the wrong part of the recording without a word: each is an error naming the label line."""
    labels = tmp_path / "actionLabel.txt"
    labels.write_text(text)
    with pytest.raises(DataFileError, match=re.escape(match)) as err:
        KinectSource(KinectConfig(format="utkinect", file=UT, segment="walk", labels=labels)).load()
    assert err.value.path == labels and err.value.line == line
    # the same action in another sequence, and an absent one (NaN NaN), are fine
    labels.write_text("s01_e01\nwalk: 252 390\ncarry: NaN NaN\ns01_e02\nwalk: 10 20\n")
    m = KinectSource(KinectConfig(format="utkinect", file=UT, segment="walk", labels=labels))
    assert m.load().metadata["segment"]["last_frame"] == 390


@pytest.mark.parametrize("path", MSR, ids=[p.stem for p in MSR])
def test_msr_real_and_joint_order_geometry(path: Path) -> None:
    m = KinectSource(KinectConfig(format="msr-action3d", file=path)).load()
    assert np.allclose(np.diff(m.skeleton.time), 1 / 15)
    check_body(m, 20, 0.2)
    c = m.canonical()
    z = {j: np.median(c.joint(j)[:, 2]) for j in ("head", "neck", "base", "l_knee", "l_ankle")}
    assert z["head"] > z["neck"] > z["base"] > z["l_knee"] > z["l_ankle"]
    # left joints on the subject's left: facing the sensor (-x), left is -y in Kinect X mapped
    # to y... checked against the hips' and shoulders' consistency instead of a convention:
    side = lambda a, b: np.median(c.joint(a)[:, 1] - c.joint(b)[:, 1])  # noqa: E731
    # (shoulders and hips only: in side-boxing the legs cross, e.g. a12_s02_e01)
    signs = {np.sign(side(f"l_{j}", f"r_{j}")) for j in ("shoulder", "hip")}
    assert len(signs) == 1
    # the neck sits between the shoulders, the hip centre between the hips
    mid = 0.5 * (c.joint("l_shoulder") + c.joint("r_shoulder"))
    assert np.median(np.linalg.norm(mid - c.joint("neck"), axis=1)) < 0.15
    # with the SDK order instead, the 'head' would be MSR's left shoulder: not the top joint
    raw = read_msr(path)
    assert MSR_JOINTS[int(np.argmax(np.median(raw.positions[:, :, 1], 0)))] == "Head"


@pytest.mark.parametrize("path", MSR_ALL, ids=[p.stem for p in MSR_ALL])
def test_every_shipped_msr_recording_reads(path: Path) -> None:
    m = KinectSource(KinectConfig(format="msr-action3d", file=path)).load()
    c = m.canonical()
    assert np.allclose(np.diff(m.skeleton.time), 1 / 15)
    assert np.median(c.joint("head")[:, 2]) > np.median(c.joint("base")[:, 2])
    assert 1.5 < np.median(np.linalg.norm(c.joint("base")[:, :2], axis=1)) < 3.5


def test_precog_real() -> None:
    rec = read_precog(PRECOG)
    assert rec.positions.shape[1:] == (20, 3)
    assert rec.segments  # action segments found
    m = KinectSource(KinectConfig(format="precog", file=PRECOG)).load()
    assert np.allclose(np.diff(m.skeleton.time), 1 / 25)
    check_body(m, 20, 0.35)
    label = sorted(rec.segments)[0]
    seg = KinectSource(KinectConfig(format="precog", file=PRECOG, segment=label)).load()
    assert seg.skeleton.n_frames < m.skeleton.n_frames


def ntu_text(rec, bodies: int = 1, drop_frame: int | None = None) -> str:
    """An NTU .skeleton file from a real Kinect v1 recording (v2 extra joints from v1 ones)."""
    v1 = {n: i for i, n in enumerate(KINECT_V1_JOINTS)}
    alias = {"SpineBase": "HipCenter", "SpineMid": "Spine", "Neck": "ShoulderCenter",
             "SpineShoulder": "ShoulderCenter", "HandTipLeft": "HandLeft", "ThumbLeft": "HandLeft",
             "HandTipRight": "HandRight", "ThumbRight": "HandRight"}  # fmt: skip
    from mdf_kinect import KINECT_V2_JOINTS

    lines = [str(rec.time.shape[0])]
    for k in range(rec.time.shape[0]):
        lines.append(str(0 if k == drop_frame else bodies))
        if k == drop_frame:
            continue
        for b in range(bodies):
            lines.append(f"{72057594037931101 + b} 0 1 1 1 1 0 0.1 0.2 2")
            lines.append("25")
            for name in KINECT_V2_JOINTS:
                x, y, z = rec.positions[k, v1[alias.get(name, name)]] + b * 0.5
                lines.append(f"{x:.6f} {y:.6f} {z:.6f} 250.1 180.2 900.3 500.4 0.1 0.2 0.3 0.9 2")
    return "\n".join(lines) + "\n"


def test_ntu_layout(tmp_path: Path) -> None:
    rec = read_utkinect(UT)
    path = tmp_path / "S001C001P001R001A001.skeleton"
    path.write_text(ntu_text(rec, bodies=2, drop_frame=5))
    with pytest.warns(UserWarning, match=r"reading body 1, the first one in most frames"):
        m = KinectSource(KinectConfig(format="ntu", file=path)).load()
    assert m.skeleton.n_joints == 25
    assert not m.skeleton.valid[5].any() and m.skeleton.valid[6].all()
    assert np.allclose(np.diff(m.skeleton.time), 1 / 30)
    back = read_ntu(path)
    v1 = {n: i for i, n in enumerate(KINECT_V1_JOINTS)}
    assert np.allclose(back.positions[0, 0], rec.positions[0, v1["HipCenter"]], atol=1e-6)


def test_ntu_reads_the_body_in_most_frames_and_names_every_body(tmp_path: Path) -> None:
    """NTU's Kinect v2 sometimes reports a short false body before the person (and two-person
    actions hold two). The first body seen was read: here 15 frames of a false body, and the
    person walking through all 100 frames was dropped without a word. The default is the body
    in most frames, with a warning naming every body; motion.body chooses one."""
    rec = read_utkinect(UT)
    person = ntu_text(rec, bodies=1).splitlines()
    n = int(person[0])
    lines = [str(n)]
    for k in range(n):
        frame = person[1 + 28 * k + 1 : 1 + 28 * (k + 1)]  # the body line, "25", 25 joints
        false = ["72057594037931000 0 0 0 0 0 0 0 0 1", "25"] + [
            "0.5 0.2 3.0 1 1 1 1 1 0 0 0 1"
        ] * 25
        lines += [str(2 if k < 15 else 1), *(false if k < 15 else []), *frame]
    path = tmp_path / "S001C001P001R001A060.skeleton"
    path.write_text("\n".join(lines) + "\n")
    with pytest.warns(
        UserWarning,
        match=r"2 bodies \(body 1 \(id 72057594037931000, 15 frames\), "
        r"body 2 \(id 72057594037931101, \d+ frames\)\); reading body 2.*motion.body",
    ):
        m = KinectSource(KinectConfig(format="ntu", file=path)).load()
    assert m.metadata["body_id"] == "72057594037931101" and m.metadata["bodies"] == 2
    assert m.metadata["body"] == 2
    v1 = {name: i for i, name in enumerate(KINECT_V1_JOINTS)}
    back = read_ntu(path)
    assert back.time.shape[0] == rec.time.shape[0]
    np.testing.assert_allclose(back.positions[:, 0], rec.positions[:, v1["HipCenter"]], atol=1e-6)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the body chosen: nothing to warn of
        false_body = read_ntu(path, body=1)
        chosen = KinectSource(KinectConfig(format="ntu", file=path, body=1)).load()
    assert chosen.metadata["body"] == 1 and chosen.metadata["body_id"] == "72057594037931000"
    assert false_body.time.shape[0] == 15 and np.allclose(
        false_body.positions[:, 0], [0.5, 0.2, 3.0]
    )
    with pytest.raises(DataFileError, match=r"motion.body is 3, but the file holds 2 bodies"):
        read_ntu(path, body=3)
    with pytest.raises(ValueError, match="body applies to the ntu format only"):
        KinectConfig(format="utkinect", file=UT, body=1)


# --------------------------------------------------------------------------- bad input


def bad_files(tmp_path: Path) -> dict[str, list[tuple[str, bytes, str]]]:
    ut = UT.read_bytes().splitlines(keepends=True)
    msr = MSR[0].read_bytes().splitlines(keepends=True)
    pc = PRECOG.read_bytes().splitlines(keepends=True)
    rec = read_utkinect(UT)
    ntu = ntu_text(rec).encode().splitlines(keepends=True)
    nite_path = tmp_path / "ok.nite.txt"
    with nite_path.open("w") as fh:
        t = np.arange(3) / 30.0
        write_nite(fh, t, [1, 2, 3], 1, np.ones((3, 15, 3)), np.ones((3, 15)), {"device": "x"})
    nite = nite_path.read_bytes().splitlines(keepends=True)
    garbage = b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\xff\xfe" * 20
    common = [("empty", b"", "empty"), ("garbage", garbage, "binary data")]

    def trunc(lines: list[bytes], k: int) -> bytes:
        return b"".join(lines[:k]) + lines[k][: len(lines[k]) // 2]

    def nonnum(lines: list[bytes], k: int, new: bytes) -> bytes:
        """Line k with its first decimal number replaced by ``new``."""
        bad = re.sub(rb"-?\d+\.\d+", new, lines[k], count=1)
        return b"".join(lines[:k]) + bad + b"".join(lines[k + 1 :])

    return {
        "utkinect": [
            *common,
            ("truncated", trunc(ut, 5), ":6: .*fields"),
            ("columns", b"".join(ut[:3]) + b"300 1 2 3\n", ":4: 4 fields"),
            ("nonnumeric", nonnum(ut, 2, b"abc"), ":3: field \\d+ is not a number: 'abc'"),
            # a frame number within its own limit whose time (/ 60 per s) is beyond a day
            ("frame 1e9", b"".join([*ut[:4], b"1000000000" + ut[4][3:], *ut[5:]]),
             ":5: time stamp .* is beyond"),
        ],
        "msr-action3d": [
            *common,
            ("truncated", b"".join(msr[:30]), ":30: .*ends inside frame 2"),
            ("columns", b"".join(msr[:3]) + b"1 2 3\n", ":4: 3 fields"),
            ("nonnumeric", nonnum(msr, 7, b"x1y"), ":8: field \\d+ is not a number"),
        ],
        "precog": [
            *common,
            ("truncated", trunc(pc, 3), ":4: .*fields"),
            ("columns", b"".join(pc[:2]) + b"1 2 3;4 5 6;0\n", ":3: 3 ';'-separated fields"),
            ("nonnumeric", nonnum(pc, 2, b"nope"), ":3: joint \\d+ value \\d+ is not a number"),
        ],
        "ntu": [
            *common,
            ("truncated", b"".join(ntu[:20]), r":1: the frame count \d+ needs at least \d+ more"),
            ("columns", b"".join(ntu[:5]) + b"1 2 3\n" + b"".join(ntu[6:]), ":6: 3 fields"),
            ("nonnumeric", nonnum(ntu, 4, b"bad"), ":5: .*not a number"),
        ],
        "nite": [
            *common,
            ("truncated", trunc(nite, len(nite) - 1), f":{len(nite)}: \\d+ fields"),
            ("columns", b"".join(nite[:-1]) + b"0.1 2 3\n", f":{len(nite)}: 3 fields"),
            ("nonnumeric", nonnum(nite, len(nite) - 1, b"one"), "not a number: 'one'"),
        ],
    }  # fmt: skip


READERS = {"utkinect": read_utkinect, "msr-action3d": read_msr, "precog": read_precog,
           "ntu": read_ntu, "nite": read_nite}  # fmt: skip


@pytest.mark.parametrize("fmt", sorted(READERS))
def test_bad_input_one_clear_error(fmt: str, tmp_path: Path, capsys) -> None:
    for case, data, pattern in bad_files(tmp_path)[fmt]:
        path = tmp_path / f"{fmt}-{case}.txt"
        path.write_bytes(data)
        with pytest.raises(DataFileError, match=pattern) as exc:
            READERS[fmt](path)
        assert str(path) in str(exc.value), (fmt, case, str(exc.value))
    # and through the CLI: one line, exit 2
    cfg = tmp_path / "run.toml"
    cfg.write_text(f'[motion]\nkind = "kinect"\nformat = "{fmt}"\nfile = "{fmt}-garbage.txt"\n')
    assert cli.main(["run", str(cfg), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "garbage.txt" in err[0]


# --------------------------------------------------------------------------- handedness


def test_utkinect_walk_is_not_mirrored() -> None:
    """Left and right survive the Kinect -> project frame conversion (a mirrored y passed every
    other test). Project frame: right-handed, z up, so for a person walking along v with the
    right -> left shoulder vector L, (v x L) points up. On the real UTKinect walk (a person
    walking across the room, checked on the data: 35 of 39 moving frames) most frames where
    the hip centre moves faster than 0.3 m/s have (v x L)_z > 0; mirrored, most would be < 0."""
    c = KinectSource(KinectConfig(format="utkinect", file=UT, segment="walk")).load().canonical()
    v = np.gradient(c.joint("base")[:, :2], c.time, axis=0)
    left = (c.joint("l_shoulder") - c.joint("r_shoulder"))[:, :2]
    up = v[:, 0] * left[:, 1] - v[:, 1] * left[:, 0]
    moving = np.hypot(v[:, 0], v[:, 1]) > 0.3
    assert moving.sum() > 30
    assert np.mean(up[moving] > 0) > 0.8


def test_msr_punching_hand_is_the_right_one_on_the_right() -> None:
    """MSR Action3D a05 (forward punch, subject 1, facing the sensor): the right hand moves most
    (path 3.0 m against 1.2 m for the left on this file) and sits on the subject's right. The
    sensor is at the origin and the subject at +x facing it (-x), so with z up the subject's
    right is +y: the right hand's median y lies 0.1-0.3 m above the hip centre's (0.20 m on the
    data), the left hand's as far below; mirrored, both would swap sides."""
    path = DATA / "msr-action3d" / "a05_s01_e01_skeleton3D.txt"
    c = KinectSource(KinectConfig(format="msr-action3d", file=path)).load().canonical()
    base = c.joint("base")
    assert np.median(base[:, 0]) > 1.5  # in front of the sensor, along +x

    def path_length(j: str) -> float:
        return float(np.sum(np.linalg.norm(np.diff(c.joint(j), axis=0), axis=1)))

    assert path_length("r_hand") > 2 * path_length("l_hand")
    assert 0.1 < np.median(c.joint("r_hand")[:, 1] - base[:, 1]) < 0.3
    assert -0.3 < np.median(c.joint("l_hand")[:, 1] - base[:, 1]) < -0.1


# --------------------------------------------------------------------------- untracked frames


def utkinect_as_nite_users(n_untracked: int = 0) -> list[tuple[int, int, list]]:
    """NiTE user-tracker frames (the binding's structures) of the real UTKinect recording,
    after ``n_untracked`` frames (33.3 ms apart) where NiTE sees the user but does not track
    the skeleton, as a capture starts."""
    body = read_utkinect(UT)
    v1 = {n: i for i, n in enumerate(KINECT_V1_JOINTS)}
    frames = [
        (k * 33_333, k + 1, [_nite_user(1, np.zeros((15, 3)), 0.0, tracked=False)])
        for k in range(n_untracked)
    ]
    for k in range(body.time.size):
        p = body.positions[k, [v1[n] for n in PICK_V1]]
        mm = np.stack([-p[:, 0], p[:, 1], p[:, 2]], 1) * 1000.0  # NiTE: mm, x to the right
        stamp = n_untracked * 33_333 + int(body.time[k] * 1e6)
        frames.append((stamp, n_untracked + k + 1, [_nite_user(1, mm, 1.0)]))
    return frames


RUN_CONFIG = """[motion]
kind = "kinect"
format = "{fmt}"
file = "{file}"
[scatterers]
kind = "ellipsoid"
placement = "joints17"
[radar]
kind = "lfm"
[scene]
radar_position = [0.0, 0.0, 1.0]
person = {{ motion = "recorded", position = [2.3, 0.0], aspect_deg = 0.0 }}
"""


def test_capture_starting_untracked_runs(tmp_path: Path, capsys) -> None:
    """A real capture starts with frames where NiTE has not tracked anyone yet: 20 such frames
    before the real UTKinect walk crashed ``mdf run`` (internal error: the placement's origin
    came from the first frame, NaN). The reader leaves the untracked frames at the ends out,
    and the run works (saying that time 0 is now the first tracked frame); so does an NTU file
    whose first frame has no body."""
    t, pos, conf, idx, user = nite_frames_to_arrays(utkinect_as_nite_users(20))
    assert user == 1 and np.all(np.isnan(pos[:20]))
    path = tmp_path / "late.nite.txt"
    with path.open("w") as fh:
        write_nite(fh, t, idx, user, pos, conf, {"device": "test"})
    rec = read_nite(path)
    n = read_utkinect(UT).time.size
    assert rec.time.size == n and rec.metadata["untracked_frames_trimmed"] == 20
    assert rec.frame_numbers[0] == 21 and rec.valid[0].all()
    cfg = tmp_path / "nite.toml"
    cfg.write_text(RUN_CONFIG.format(fmt="nite", file=path))
    capsys.readouterr()
    assert cli.main(["run", str(cfg), "--out", str(tmp_path / "out"), "--no-figures"]) == 0
    # time 0 moved to the first tracked frame: said, since motion.start counts from it
    said = capsys.readouterr().err
    assert "its first 20 frame(s) track no body" in said
    assert f"{t[20] - t[0]:.3f} s into the file" in said
    ntu = tmp_path / "S001C001P001R001A001.skeleton"
    ntu.write_text(ntu_text(read_utkinect(UT), drop_frame=0))
    cfg.write_text(RUN_CONFIG.format(fmt="ntu", file=ntu))
    assert cli.main(["run", str(cfg), "--out", str(tmp_path / "out2"), "--no-figures"]) == 0
    # no frame tracked at all: one line naming the file
    with path.open("w") as fh:
        write_nite(fh, t[:20], idx[:20], user, pos[:20], conf[:20], {"device": "test"})
    cfg.write_text(RUN_CONFIG.format(fmt="nite", file=path))
    capsys.readouterr()
    assert cli.main(["run", str(cfg), "--out", str(tmp_path / "out3"), "--no-figures"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "late.nite.txt" in err[0] and "no joint is tracked" in err[0]


# --------------------------------------------------------------------------- mdf capture


class FakeUserTracker:
    """Stands in for ``nite2.UserTracker`` (NiTE2 cannot be installed here; the real path in
    ``cmd_capture`` stays as it is). Like NiTE2 it loads ``NiTE2/s.dat`` relative to the
    current directory when it is created, and tracks on the device's depth stream, read here
    through the real OpenNI2 from the real test.oni: each depth frame gives the user frame of
    the same index from :func:`utkinect_as_nite_users` (the binding's own ctypes structures),
    3 untracked, then the UTKinect body."""

    events: ClassVar[list[str]] = []

    def __init__(self, dev) -> None:
        from openni import openni2

        if not Path("NiTE2/s.dat").is_file():
            raise RuntimeError("(OniStatus.ONI_STATUS_ERROR, 'Could not find data file', None)")
        self.cwd = Path.cwd()
        self.openni2, self.dev = openni2, dev
        self.stream = dev.create_stream(openni2.SENSOR_DEPTH)
        self.stream.start()
        self.users = utkinect_as_nite_users(3)
        self.seen: set[int] = set()
        self.read: list[int] = []
        FakeUserTracker.events.append("tracker created")
        FakeUserTracker.last = self

    def read_frame(self):
        from types import SimpleNamespace

        if self.openni2.wait_for_any_stream([self.stream], 2.0) is None:
            raise RuntimeError("no depth frame in 2 s")  # NiTE2 would wait for ever
        f = self.stream.read_frame()
        index, stamp = int(f.frameIndex), int(f.timestamp)
        f.close()
        self.read.append(index)
        users = []
        for ud in self.users[(index - 1) % len(self.users)][2]:
            new = ud.id not in self.seen
            self.seen.add(ud.id)
            users.append(SimpleNamespace(id=ud.id, _userdata=ud, is_new=lambda new=new: new))
        return SimpleNamespace(timestamp=stamp, frameIndex=index, users=users, close=lambda: None)

    def start_skeleton_tracking(self, user_id: int) -> None:
        pass

    def close(self) -> None:
        """Stopped and closed as device._playback does with its streams."""
        from mdf_kinect.device import _wait_until_sleeping

        self.stream.stop()
        self.dev.playback.set_speed(0.0)
        _wait_until_sleeping(FakeUserTracker.player)
        self.stream.close()
        FakeUserTracker.events.append("tracker closed")


@pytest.fixture
def fake_nite(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> Path:
    """``mdf capture`` with :class:`FakeUserTracker` for NiTE2; a Redist folder holding
    NiTE2/s.dat (returned); the device's closing is recorded in FakeUserTracker.events."""
    from types import SimpleNamespace

    import mdf_kinect.device as kdevice  # mdf capture imports its device layer when it runs
    from mdf_kinect.device import _task_ids
    from openni import openni2

    redist = tmp_path / "Redist"
    (redist / "NiTE2").mkdir(parents=True)
    (redist / "NiTE2" / "s.dat").write_bytes(b"fake")
    fake = SimpleNamespace(UserTracker=FakeUserTracker, get_version=lambda: "2.2 (fake)")
    monkeypatch.setattr(kdevice, "initialize_nite", lambda redist=None: fake)
    real_open = kdevice.open_device

    def open_device(o, uri=None):
        before = _task_ids()
        dev = real_open(o, uri)
        FakeUserTracker.player = _task_ids() - before
        return dev

    monkeypatch.setattr(kdevice, "open_device", open_device)
    real_close = openni2.Device.close

    def close(self):
        if self:  # an open handle (the binding also closes on opening)
            FakeUserTracker.events.append("device closed")
        real_close(self)

    monkeypatch.setattr(openni2.Device, "close", close)
    FakeUserTracker.events = []
    return redist


def test_capture_from_oni_file(fake_nite: Path, tmp_path: Path, monkeypatch, capsys) -> None:
    """``mdf capture --device rec.oni`` (NiTE2 faked, see FakeUserTracker; OpenNI2 and the file
    real), run from another folder with relative paths:

    - the user tracker is created inside NiTE2's Redist folder (NiTE2 loads NiTE2/s.dat from
      the current directory; elsewhere it failed as "cannot track on this device"), and the
      relative --out and --device still mean the user's folder, which is restored;
    - the file is played once: 12 depth frames, then the capture stops (OpenNI2 repeats a file
      by default: the capture looped until --duration);
    - the 3 leading untracked frames are left out: 9 frames at 30 Hz;
    - the tracker is closed before the device."""
    work = tmp_path / "work"
    work.mkdir()
    (work / "rec.oni").write_bytes(ONI.read_bytes())
    monkeypatch.chdir(work)
    args = ["capture", "--out", "walk.nite.txt", "--device", "rec.oni", "--duration", "3"]
    assert cli.main([*args, "--nite2", str(fake_nite)]) == 0
    assert Path.cwd() == work and FakeUserTracker.last.cwd == fake_nite
    # played once, in order, to the last frame; at the recorded speed a slow reader (a busy
    # machine) misses frames, as NiTE2 does: on an idle one it reads all 12
    read = FakeUserTracker.last.read
    assert read == sorted(set(read)) and set(read) <= set(range(1, 13)) and read[-1] == 12
    tracked = [i for i in read if i >= 4]
    rec = read_nite(work / "walk.nite.txt")
    assert list(rec.frame_numbers) == tracked and len(tracked) >= 2
    assert rec.metadata["untracked_frames_trimmed"] == 0
    out = capsys.readouterr().out
    n, left = len(tracked), len(read) - len(tracked)
    assert f"{n} frames ({n} with user 1 tracked; {left} untracked at the ends left out)" in out
    measured = re.search(r"([\d.]+) s measured, ([\d.]+) Hz actual", out)
    assert measured is not None, out
    assert abs(float(measured.group(1)) - (tracked[-1] - tracked[0]) / 30.0) < 0.005, out
    assert FakeUserTracker.events == ["tracker created", "tracker closed", "device closed"]
    # no NiTE2 data where the tracker is created: the error, the device closed, cwd restored
    (fake_nite / "NiTE2" / "s.dat").unlink()
    FakeUserTracker.events = []
    assert cli.main([*args, "--nite2", str(fake_nite)]) == 2
    assert "NiTE2 cannot track on this device" in capsys.readouterr().err
    assert Path.cwd() == work and FakeUserTracker.events == ["device closed"]


def test_nite2_redist64_is_read(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """NiTE 2.2's install.sh exports only NITE2_REDIST64 on x86_64: it is read (before
    NITE2_REDIST, as the openni binding does). An empty libNiTE2.so there fails to load,
    naming that folder; it was '(neither is set)'."""
    (tmp_path / "r64").mkdir()
    (tmp_path / "r64" / "libNiTE2.so").write_bytes(b"")
    monkeypatch.delenv("NITE2_REDIST", raising=False)
    monkeypatch.setenv("NITE2_REDIST64", str(tmp_path / "r64"))
    with pytest.raises(NiteMissingError, match=r"loading .*r64/libNiTE2\.so failed"):
        initialize_nite()
    monkeypatch.setenv("NITE2_REDIST", str(tmp_path / "other"))
    with pytest.raises(NiteMissingError, match=r"loading .*r64/libNiTE2\.so failed"):
        initialize_nite()


# --------------------------------------------------------------------------- bad .oni files


def oni_records(data: bytes) -> list[tuple[int, int]]:
    """(byte, record type) of every record of an .oni file."""
    out, pos = [], 24
    while pos < len(data):
        _, typ, _, fsize, psize, _ = struct.unpack_from("<4sIIIIQ", data, pos)
        out.append((pos, typ))
        if typ == 11:
            break
        pos += fsize + psize
    return out


def test_oni_in_openni1_record_order_is_played(tmp_path: Path, capsys) -> None:
    """OpenNI 1.x's recorder writes the end record before the node-removed records and seek
    tables (OpenNI2's after them), and OpenNI2 plays both: the shipped test.oni rewritten in
    1.x order (the end record moved before the first node-removed record, the seek tables'
    positions in the node-added records moved with it) passes scan_oni with the same frames,
    and the real OpenNI2 reads it (mdf kinect info). A node-added record whose seek table
    position is 0 (OpenNI2: none) is no error either."""
    data = ONI.read_bytes()
    recs = oni_records(data)
    end = next(p for p, t in recs if t == 11)
    first_removed = next(p for p, t in recs if t == 7)  # node removed
    size = 28  # the end record is a bare record header
    assert end + size == len(data)
    moved = bytearray(data[:first_removed] + data[end:] + data[first_removed:end])
    zero_seek = bytearray(data)
    for p, t in recs:
        if t == 13:
            ln = struct.unpack_from("<I", data, p + 28)[0]
            at = p + 32 + ln + 28
            seek = struct.unpack_from("<Q", data, at)[0]
            if seek:
                struct.pack_into("<Q", moved, at, seek + size)
                struct.pack_into("<Q", zero_seek, at, 0)
    want = scan_oni(ONI)
    for case, content in {"openni1": moved, "zero_seek": zero_seek}.items():
        path = tmp_path / f"{case}.oni"
        path.write_bytes(bytes(content))
        got = scan_oni(path)
        assert (got.frames_per_node, got.nodes) == (want.frames_per_node, want.nodes)
    capsys.readouterr()
    assert cli.main(["kinect", "info", str(tmp_path / "openni1.oni")]) == 0
    assert "depth: 640x480 DEPTH_1_MM, 12 frames" in capsys.readouterr().out


def as_old_oni(data: bytes) -> bytes:
    """An .oni file rewritten as file version 1.0.0.6, the layout before 1.0.1.0: 24-byte record
    headers with a 32-bit undo position, a 32-bit seek-table position in node-added records,
    16-byte seek-table entries (64-bit time stamp, 32-bit frame and position); every position
    moved to the new layout."""
    recs = [(p, *struct.unpack_from("<4sIIIIQ", data, p)[1:]) for p, _ in oni_records(data)]
    moved, at = {}, 24
    for pos, typ, _, fsize, psize, _ in recs:
        moved[pos] = at
        at += 24 + fsize - 28 - (4 if typ == 13 else 0) + (psize // 20 * 16 if typ == 14 else psize)
    out = bytearray(
        struct.pack("<4sBBHIQI", b"NI10", 1, 0, 0, 6, *struct.unpack_from("<QI", data, 12))
    )
    for pos, typ, node, fsize, psize, undo in recs:
        fields = data[pos + 28 : pos + fsize]
        if typ == 13:
            ln = struct.unpack_from("<I", fields, 0)[0]
            seek = struct.unpack_from("<Q", fields, 4 + ln + 28)[0]
            fields = fields[: 4 + ln + 28] + struct.pack("<I", moved.get(seek, 0))
        payload = data[pos + fsize : pos + fsize + psize]
        if typ == 14:
            entries = [struct.unpack_from("<QIQ", payload, 20 * i) for i in range(psize // 20)]
            payload = b"".join(struct.pack("<QII", t, f, moved.get(p, 0)) for t, f, p in entries)
        header = struct.pack(
            "<4sIIIII", b"NIR\0", typ, node, 24 + len(fields), len(payload), moved.get(undo, 0)
        )
        out += header + fields + payload
    return bytes(out)


def test_old_oni_versions_are_scanned_with_their_own_layout(tmp_path: Path, capsys) -> None:
    """A recording in the layout before file version 1.0.1.0 (24-byte record headers, 32-bit
    positions), which OpenNI2 plays: scan_oni finds the same frames and streams as in the shipped
    file, and the real OpenNI2 reads all 12 depth frames (mdf kinect info). A frame after an end
    record (OpenNI2 plays nothing after it) is refused, naming the record."""
    old = tmp_path / "old.oni"
    old.write_bytes(as_old_oni(ONI.read_bytes()))
    want, got = scan_oni(ONI), scan_oni(old)
    assert (got.frames_per_node, got.nodes) == (want.frames_per_node, want.nodes)
    capsys.readouterr()
    assert cli.main(["kinect", "info", str(old)]) == 0
    assert "depth: 640x480 DEPTH_1_MM, 12 frames" in capsys.readouterr().out
    data = ONI.read_bytes()
    recs = oni_records(data)
    end = next(p for p, t in recs if t == 11)
    ninth = [p for p, t in recs if t == 10][8]
    early = tmp_path / "early_end.oni"
    early.write_bytes(data[:ninth] + data[end:] + data[ninth:end])
    with pytest.raises(
        DataFileError,
        match=r"early_end\.oni: record \d+ \(new data\) at byte \d+ follows the end record",
    ):
        scan_oni(early)


def test_bad_oni_named_before_openni2(tmp_path: Path, capsys) -> None:
    """Files OpenNI2 refuses with its bare ONI_STATUS_ERROR are refused by scan_oni first,
    naming the file and record: cut exactly at a record boundary (the end, node-removed and
    seek-table records missing), a record of unknown type 99, a node-added record whose name
    length is garbage or whose codec is unknown, a seek table missing. Through the CLI: one
    line, exit 2, no 'is a Kinect connected' hint for a file."""
    data = ONI.read_bytes()
    recs = oni_records(data)
    frames = [p for p, t in recs if t == 10]
    depth_added = [p for p, t in recs if t == 13][1]
    seek = next(p for p, t in recs if t == 14)
    type99 = bytearray(data)
    struct.pack_into("<I", type99, recs[5][0] + 4, 99)
    name = bytearray(data)
    struct.pack_into("<I", name, depth_added + 28, 1000)
    codec = bytearray(data)
    codec[depth_added + 32 + 7 + 4 : depth_added + 32 + 7 + 8] = b"XXXX"
    no_seek = data[:seek] + data[seek + 28 + 260 :]
    cases = {
        "cut": (data[: frames[10]], r"ends after record \d+ \(new data\) at byte \d+ without"),
        "type99": (bytes(type99), r"record 6 at byte \d+: unknown record type 99"),
        "name": (bytes(name), r"record \d+ \(node added\) at byte 1587: node name length 1000"),
        "codec": (bytes(codec), r"node 'Depth1' of type 2 with codec b'XXXX'"),
        "noseek": (no_seek, r"'Depth1'\): its seek table at byte \d+ is not a seek table"),
    }
    for case, (content, pattern) in cases.items():
        path = tmp_path / f"{case}.oni"
        path.write_bytes(content)
        with pytest.raises(DataFileError, match=rf"{case}\.oni: .*{pattern}"):
            scan_oni(path)
        assert cli.main(["kinect", "info", str(path)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and f"{case}.oni" in err[0] and "Kinect" not in err[0], err
    # the library's own error on a file: no hint about a Kinect
    with pytest.raises(DeviceError, match=r"type99\.oni.*cannot play") as exc:
        open_device(initialize_openni(), str(tmp_path / "type99.oni"))
    assert "Kinect connected" not in str(exc.value)


def test_a_segment_whose_first_frames_are_untracked_says_where_time_0_is(tmp_path: Path) -> None:
    """UTKinect's walk segment with the file's frames before 262 untracked (all joints zero):
    the reader leaves them out, so the segment (labelled from 252) starts at frame 262, and a
    warning says so (motion.start counts from there); the shipped file itself gives none."""
    lines = UT.read_text().splitlines()
    cut = []
    for line in lines:
        cells = line.split()
        if int(cells[0]) < 262:
            cells[1:] = ["0"] * (len(cells) - 1)
        cut.append(" ".join(cells))
    late = tmp_path / "joints_s01_e01.txt"
    late.write_text("\n".join(cut) + "\n")
    (tmp_path / "actionLabel.txt").write_bytes((UT.parent / "actionLabel.txt").read_bytes())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        KinectSource(KinectConfig(format="utkinect", file=UT, segment="walk")).load()
        assert not [w for w in caught if issubclass(w.category, TrackingWarning)]
        m = KinectSource(KinectConfig(format="utkinect", file=late, segment="walk")).load()
    said = [str(w.message) for w in caught if issubclass(w.category, TrackingWarning)]
    assert said == [
        f"{late}: segment 'walk' starts at frame 252, but its first tracked frame is 262: time 0 "
        "(what motion.start counts from) is that frame"
    ]
    assert m.metadata["segment"]["first_frame"] == 252


def test_utkinect_walk_segment_frames_time_base_and_floor() -> None:
    """The labelled walk (frames 252..390, both ends included) keeps exactly the file's frames
    in that range, 390 among them; its time runs from 0 at frame 252 in frame numbers / 60 s;
    and the floor puts the lowest foot joint on z = 0 (1st percentile): feet stand on it, they
    do not sink through it (fewer than 5 % of frames more than 2 cm below)."""
    rec = read_utkinect(UT)
    inside = rec.frame_numbers[(rec.frame_numbers >= 252) & (rec.frame_numbers <= 390)]
    assert inside[0] == 252 and inside[-1] == 390
    m = KinectSource(KinectConfig(format="utkinect", file=UT, segment="walk")).load()
    assert m.skeleton.n_frames == inside.size
    np.testing.assert_allclose(m.skeleton.time, (inside - 252) / 60.0, rtol=0, atol=1e-12)
    c = m.canonical()
    lowest = np.nanmin(np.stack([c.joint("l_toe")[:, 2], c.joint("r_toe")[:, 2]]), axis=0)
    assert np.mean(lowest < -0.02) < 0.05
    assert np.nanmin(lowest) > -0.1


def test_ntu_tracking_state_threshold(tmp_path: Path) -> None:
    """NTU trackingState 0 (not tracked) is untracked, 1 (inferred) is kept by default
    (min_tracking = 1) and dropped with min_tracking = 2, 2 (tracked) is always kept."""
    rec = read_utkinect(UT)
    lines = ntu_text(rec).split("\n")
    # frame 1's joints follow "1" (frame count), "1" (bodies), body line, "25": lines 4..28
    assert lines[3] == "25" and lines[4].endswith(" 2")
    lines[4] = lines[4][:-1] + "1"  # SpineBase inferred
    lines[5] = lines[5][:-1] + "0"  # SpineMid not tracked
    path = tmp_path / "S001C001P001R001A001.skeleton"
    path.write_text("\n".join(lines))
    default = read_ntu(path).valid[0]
    strict = read_ntu(path, min_tracking=2).valid[0]
    assert default[0] and not default[1] and default[2:].all()
    assert not strict[0] and not strict[1] and strict[2:].all()


def _mdf_without(args: list[str], hide: str | None, env: dict[str, str]) -> tuple[int, str]:
    """``mdf ARGS`` in a child process where the Python package ``hide`` cannot be imported (as
    where it is not installed): exit status and stderr."""
    import os

    code = (
        "import sys\n"
        + (f"sys.modules[{hide!r}] = None\n" if hide is not None else "")
        + "from mdframework import cli\n"
        "sys.exit(cli.main(sys.argv[1:]))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code, *args],
        capture_output=True,
        text=True,
        env={**os.environ, **env},
        timeout=120,
    )
    return done.returncode, done.stderr


def test_a_missing_openni_package_says_what_to_pip_install() -> None:
    """Without the ``openni`` binding, ``mdf kinect info`` is one line naming the package and
    the command that installs it, exit 2 (it named the package and Python's import error only)."""
    code, err = _mdf_without(["kinect", "info", str(ONI)], "openni", {})
    assert code == 2
    assert len(err.splitlines()) == 1, err
    assert err.startswith("mdf: error: mdf-kinect needs the Python package 'openni'"), err
    assert err.rstrip().endswith(": pip install openni"), err


def test_a_missing_openni2_library_says_what_to_apt_get_install(tmp_path: Path) -> None:
    """Where the system OpenNI2 library is not found, ``mdf kinect info`` is one line naming the
    folder it looked in and the Debian packages that install it, exit 2."""
    code, err = _mdf_without(["kinect", "info", str(ONI)], None, {"OPENNI2_REDIST": str(tmp_path)})
    assert code == 2
    assert len(err.splitlines()) == 1, err
    assert err.startswith(f"mdf: error: OpenNI2 could not be loaded from {tmp_path} "), err
    assert "apt-get install libopenni2-0 libopenni2-dev" in err, err
