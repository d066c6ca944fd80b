"""The ``table`` plugin (``mdf-table``): plain joint-track tables, long or wide, CSV/TSV/text/NPZ.

The real file is UTKinect-Action3D's s01_e01 joints file (``examples/data/kinect``, see its
PROVENANCE.md), which is a plain whitespace table without a header: read through the generic
table reader it must give exactly what the Kinect plugin's own UTKinect reader gives (an
independent implementation), and its walk a plausible cadence. Layouts, units, axes, joint
maps and bad input are checked on tables written here from known tracks.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from mdf_kinect import KINECT_V1_JOINTS, read_utkinect, to_project_frame
from mdf_table import TableConfig, TableLayout, TableSource, read_table

from mdframework import CANONICAL_JOINTS, DataFileError
from mdframework.config import load_run_config
from mdframework.pipeline import build_stages, load_motion

ROOT = Path(__file__).parents[1]
UT = ROOT / "examples" / "data" / "kinect" / "utkinect" / "joints_s01_e01.txt"
EXAMPLE = ROOT / "examples" / "table_utkinect_walk.toml"


def test_utkinect_file_as_a_plain_table_equals_the_kinect_reader() -> None:
    spec = TableLayout(
        header=False, joints=tuple(KINECT_V1_JOINTS), time_column="frame", frame_rate=60.0
    )
    table = read_table(UT, spec)
    ref = read_utkinect(UT)
    assert table.names == tuple(KINECT_V1_JOINTS) and table.layout == "wide"
    assert np.array_equal(table.time, ref.time)
    assert np.array_equal(table.positions, ref.positions)
    # the file repeats some frame numbers: both readers keep the first and drop the rest
    assert table.duplicates_dropped == ref.metadata["duplicate_frames_dropped"] == 15


def test_example_walk_through_the_table_source_matches_the_kinect_source() -> None:
    cfg = load_run_config(EXAMPLE)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the depth camera's bone-length warning
        motion = load_motion(build_stages(cfg).source)
    body = motion.canonical()
    # the walk segment: frames 252..390 at 60 frame numbers per second
    assert body.time[0] == 0.0 and body.time[-1] == pytest.approx((390 - 252) / 60, abs=1 / 30)
    ref = read_utkinect(UT)
    sel = (ref.frame_numbers >= 252) & (ref.frame_numbers <= 390)
    want = to_project_frame(ref.positions[sel])
    idx = [KINECT_V1_JOINTS.index(motion.metadata["joints"][j][0]) for j in CANONICAL_JOINTS]
    assert np.allclose(body.positions, want[:, idx], equal_nan=True)
    # a walk across the sensor's view: the pelvis covers 1.6 m at a slow walking speed, and
    # the cadence found by the sanity checks is a walking one (about 102 steps a minute)
    base = body.joint("base")
    speed = np.linalg.norm(base[-1, :2] - base[0, :2]) / (body.time[-1] - body.time[0])
    assert speed == pytest.approx(0.70, abs=0.01)
    cad = motion.metadata["sanity"]["cadence"]
    assert cad["ok"] and cad["steps_per_min"] == pytest.approx(102, abs=1)


# --------------------------------------------------------------------------- written tables


def _tracks(n: int = 30, rate: float = 50.0) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    t = np.arange(n) / rate
    rng = np.random.default_rng(7)
    out = {}
    for k, j in enumerate(CANONICAL_JOINTS):
        out[j] = np.stack(
            [0.9 * t + 0.01 * k, 0.02 * k + 0 * t, 0.1 * k + 0.05 * np.sin(6 * t + k)], axis=1
        ) + rng.normal(0, 1e-3, (n, 3))
    return t, out


def _long_csv(path: Path, t: np.ndarray, tracks: dict[str, np.ndarray], scale: float) -> None:
    rows = ["time,joint,x,y,z,confidence"]
    for i, ti in enumerate(t):
        for j, p in tracks.items():
            x, y, z = p[i] / scale
            rows.append(f"{ti:.6f},{j},{x:.9g},{y:.9g},{z:.9g},1")
    path.write_text("\n".join(rows) + "\n")


@pytest.mark.parametrize(
    "units,scale", [("mm", 0.001), ("cm", 0.01), ("in", 0.0254), ("ft", 0.3048), ("m", 1.0)]
)
def test_long_csv_in_each_unit(tmp_path: Path, units: str, scale: float) -> None:
    """The same tracks written in mm, cm, inches (25.4 mm), feet (304.8 mm) and m read back."""
    t, tracks = _tracks()
    path = tmp_path / "long.csv"
    _long_csv(path, t, tracks, scale)
    m = TableSource(TableConfig(file=path, units=units)).load()
    body = m.canonical()
    assert m.metadata["layout"] == "long" and m.metadata["joint_set"] == "canonical"
    assert m.metadata["frame_rate_hz"] == pytest.approx(50.0)
    for j in CANONICAL_JOINTS:
        assert np.allclose(body.joint(j), tracks[j], atol=1e-6)


def test_wide_tsv_with_time_in_ms_axes_and_mean_joints(tmp_path: Path) -> None:
    t, tracks = _tracks()
    names = {j: j.replace("l_", "Left").replace("r_", "Right") for j in CANONICAL_JOINTS}
    # a y-up file: file (X, Y, Z) = project (y, z, x); the base is given as two hip markers
    cols = ["ms"] + [f"{names[j]}.{a}" for j in CANONICAL_JOINTS if j != "base" for a in "XYZ"]
    cols += [f"{h}.{a}" for h in ("PelvisL", "PelvisR") for a in "XYZ"]
    lines = ["\t".join(cols)]
    for i, ti in enumerate(t):
        vals = [f"{ti * 1000:.3f}"]
        for j in CANONICAL_JOINTS:
            if j != "base":
                vals += [f"{v:.9g}" for v in tracks[j][i][[1, 2, 0]]]
        for d in (0.1, -0.1):
            vals += [f"{v:.9g}" for v in (tracks["base"][i] + [0, d, 0])[[1, 2, 0]]]
        lines.append("\t".join(vals))
    path = tmp_path / "wide.tsv"
    path.write_text("\n".join(lines) + "\n")
    joint_map = {j: names[j] for j in CANONICAL_JOINTS if j != "base"}
    cfg = TableConfig(
        file=path,
        time_column="ms",
        time_unit_s=0.001,
        axes=("z", "x", "y"),
        joint_map={**joint_map, "base": ["PelvisL", "PelvisR"]},
    )
    m = TableSource(cfg).load()
    body = m.canonical()
    assert m.metadata["layout"] == "wide"
    for j in CANONICAL_JOINTS:
        assert np.allclose(body.joint(j), tracks[j], atol=1e-6), j
    assert np.allclose(body.time, t - t[0], atol=1e-9)


def test_npz_wide_and_long_agree(tmp_path: Path) -> None:
    t, tracks = _tracks()
    pos = np.stack([tracks[j] for j in CANONICAL_JOINTS], axis=1)
    wide = tmp_path / "wide.npz"
    np.savez(wide, time=t, positions=pos, joints=np.array(CANONICAL_JOINTS))
    long = tmp_path / "long.npz"
    n, nj = pos.shape[:2]
    np.savez(
        long,
        time=np.repeat(t, nj),
        joint=np.tile(np.array(CANONICAL_JOINTS), n),
        x=pos[..., 0].ravel(),
        y=pos[..., 1].ravel(),
        z=pos[..., 2].ravel(),
    )
    a = TableSource(TableConfig(file=wide)).load().canonical()
    b = TableSource(TableConfig(file=long)).load().canonical()
    assert np.array_equal(a.positions, b.positions) and np.allclose(a.positions, pos)


def test_missing_values_and_unsorted_rows(tmp_path: Path) -> None:
    t, tracks = _tracks(10)
    path = tmp_path / "gaps.csv"
    _long_csv(path, t, tracks, 1.0)
    lines = path.read_text().splitlines()
    head, rows = lines[0], lines[1:]
    # the head's row of frame 3 loses its coordinates; frames 5 and 6 swap places
    k = 3 * 17 + CANONICAL_JOINTS.index("head")
    rows[k] = ",".join([*rows[k].split(",")[:2], "", "", "", "0"])
    rows[5 * 17 : 7 * 17] = rows[6 * 17 : 7 * 17] + rows[5 * 17 : 6 * 17]
    path.write_text("\n".join([head, *rows]) + "\n")
    body = TableSource(TableConfig(file=path)).load().canonical()
    h = body.index("head")
    assert not body.valid[3, h] and body.valid[[2, 4], h].all()
    assert np.all(np.diff(body.time) > 0)
    assert np.allclose(body.joint("l_knee")[5:7], tracks["l_knee"][5:7])


# --------------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    "name,text,match",
    [
        (
            "ragged.csv",
            "time,joint,x,y,z\n0,head,1,2,3\n0.1,head,1,2\n",
            r"ragged\.csv:3: 4 fields",
        ),
        ("word.csv", "time,joint,x,y,z\n0,head,1,two,3\n", r"word\.csv:2: coordinate: 'two'"),
        (
            "inf.csv",
            "time,joint,x,y,z\n0,head,1,2,3\n1,head,1,-inf,3\n",
            r"inf\.csv:3: a joint coordinate -inf is not finite",
        ),
        (
            "far.tsv",
            "# a comment\ntime\thead_x\thead_y\thead_z\n0\t1\t2\t3\n1\t1\t2\t3e9\n",
            r"far\.tsv:4: a joint coordinate 3000000000\.0 is beyond",
        ),
        (
            "repeated.csv",
            "# a comment\ntime,head_x,head_y,head_z,head_x\n0,1,2,3,9\n1,1,2,3,9\n",
            r"repeated\.csv:2: column 'head_x' appears twice \(columns 2 and 5\)",
        ),
        (
            "case.csv",
            "time,head_X,head_y,head_z,head_x\n0,1,2,3,9\n1,1,2,3,9\n",
            r"case\.csv:1: columns 'head_X' and 'head_x' are the same coordinate",
        ),
        (
            "repeated_long.csv",
            "time,joint,x,y,z,time\n0,head,1,2,3,0\n",
            r"repeated_long\.csv:1: column 'time' appears twice",
        ),
        ("twice.csv", "time,joint,x,y,z\n0,head,1,2,3\n0,head,1,2,3\n", r"twice\.csv:3: joint"),
        ("one.csv", "time,joint,x,y,z\n0,head,1,2,3\n", r"one\.csv.*two"),
        ("nojoint.csv", "time,a,b\n0,1,2\n1,1,2\n", r"nojoint\.csv:1: no joint columns"),
        ("empty.csv", "\n\n", r"empty\.csv: the file is empty"),
    ],
)
def test_bad_tables_are_one_line_errors(tmp_path: Path, name: str, text: str, match: str) -> None:
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(DataFileError, match=match) as err:
        read_table(path)
    assert "\n" not in str(err.value)


def test_binary_files_and_missing_joints(tmp_path: Path) -> None:
    binary = tmp_path / "bin.csv"
    binary.write_bytes(b"time,joint,x,y,z\n\x00\x01")
    with pytest.raises(DataFileError, match=r"bin\.csv:2: binary data"):
        read_table(binary)
    pickled = tmp_path / "obj.npz"
    np.savez(pickled, positions=np.array([object()]), joints=np.array(["a"]))
    with pytest.raises(DataFileError, match=r"obj\.npz: array 'positions' holds Python objects"):
        read_table(pickled)
    t, tracks = _tracks(5)
    tracks.pop("l_toe")
    path = tmp_path / "notoe.csv"
    _long_csv(path, t, tracks, 1.0)
    with pytest.raises(DataFileError, match=r"notoe\.csv: the joint set 'canonical' lacks l_toe"):
        TableSource(TableConfig(file=path)).load()
    with pytest.raises(DataFileError, match=r"joint_map names joints not in the file: LeftToe"):
        TableSource(TableConfig(file=path, joint_map={"l_toe": "LeftToe"})).load()


def test_a_joint_or_column_named_twice_in_the_config_is_the_configs_error(tmp_path: Path) -> None:
    """`joints = ["HipCenter", "HipCenter", ...]` names columns twice: the error names the
    config field, not the data file (whose columns the config names)."""
    path = tmp_path / "t.csv"
    path.write_text("0,1,2,3,4,5,6\n1,1,2,3,4,5,6\n")
    with pytest.raises(ValueError, match=r"joints: 'head' named twice"):
        TableConfig(file=path, header=False, joints=["head", "head"], time_column="t")
    with pytest.raises(ValueError, match=r"columns: 't' named twice"):
        TableConfig(file=path, header=False, columns=["t", "t", "head_x"])


def _ut_table(path: Path, stamps: np.ndarray, long: bool) -> Path:
    """The real UTKinect track as a CSV with the time column ``stamps``."""
    rec = read_utkinect(UT)
    names, pos = rec.joint_names, rec.positions
    if long:
        rows = ["time,joint,x,y,z"] + [
            f"{stamps[k]:.17g},{n},{p[0]:.17g},{p[1]:.17g},{p[2]:.17g}"
            for k in range(len(stamps))
            for n, p in zip(names, pos[k], strict=True)
        ]
    else:
        rows = ["time," + ",".join(f"{n}_{a}" for n in names for a in "xyz")]
        rows += [
            f"{stamps[k]:.17g}," + ",".join(f"{v:.17g}" for v in pos[k].ravel())
            for k in range(len(stamps))
        ]
    path.write_text("\n".join(rows) + "\n")
    return path


@pytest.mark.parametrize("long", [False, True], ids=["wide", "long"])
@pytest.mark.parametrize(
    ("offset", "per_s", "options"),
    [
        (100_000.0, 1000.0, {"time_unit_s": 0.001}),  # a logger's milliseconds, 100 s in
        (1.7e9, 1.0, {}),  # Unix epoch seconds
        (90_000.0, 30.0, {"frame_rate": 30.0}),  # frame numbers at 30 Hz from 90000 (50 min)
    ],
    ids=["ms", "epoch", "frames"],
)
def test_times_far_from_zero_in_any_unit_count_from_the_first_frame(
    tmp_path: Path, long: bool, offset: float, per_s: float, options: dict[str, float]
) -> None:
    """The 86,400 s limit is on seconds, and on the span: a 35 s walk stamped 100,000 ms,
    1.7e9 s or frame 90,000 onward was refused (the values compared with 86,400 as they stand).
    Its times are the Kinect reader's, from 0; its speed the real walk's."""
    ref = read_utkinect(UT)
    seconds = ref.time - ref.time[0]
    stamps = offset + (np.round(seconds * 30) if "frame_rate" in options else seconds * per_s)
    path = _ut_table(tmp_path / "walk.csv", stamps, long)
    m = TableSource(TableConfig(file=path, joint_set="kinect-v1", axes=["z", "x", "y"], **options))
    motion = m.load()
    t = motion.skeleton.time
    want = np.unique(np.round(seconds * 30) / 30 if "frame_rate" in options else seconds)
    np.testing.assert_allclose(t, want, rtol=0, atol=1e-6)
    assert t[-1] == pytest.approx(35.0, abs=1e-6)
    base = motion.canonical().joint("base")
    speed = np.linalg.norm(base[-1, :2] - base[0, :2]) / t[-1]
    kin = to_project_frame(ref.positions)[:, KINECT_V1_JOINTS.index("HipCenter")]
    assert speed == pytest.approx(np.linalg.norm(kin[-1, :2] - kin[0, :2]) / 35.0, rel=1e-6)
    # a segment cut in the column's own unit (epoch seconds were refused above 1e9)
    per_unit = 30.0 if "frame_rate" in options else per_s
    cut = (offset + 10.0 * per_unit, offset + 20.0 * per_unit)
    config = TableConfig(
        file=path, joint_set="kinect-v1", axes=["z", "x", "y"], time_range=cut, **options
    )
    t = TableSource(config).load().skeleton.time
    assert t[-1] == pytest.approx(10.0, abs=0.1)  # within 3 frames (real Kinect stamps)


def test_time_limits_are_in_seconds_and_say_so(tmp_path: Path) -> None:
    """Microseconds read as seconds span 35e6 s: refused with the unit named and what to set;
    a time beyond 1e10 s (no clock) is refused as such."""
    ref = read_utkinect(UT)
    micro = _ut_table(tmp_path / "us.csv", (ref.time - ref.time[0]) * 1e6, long=False)
    with pytest.raises(DataFileError) as err:
        read_table(micro)
    assert str(err.value) == (
        f"{micro}: the times span 3.5e+07 s (motion.time_unit_s = 1 s per unit), more than "
        "86400 s: check the time column's unit (motion.time_unit_s or motion.frame_rate)"
    )
    assert read_table(micro, TableLayout(time_unit_s=1e-6)).time[-1] == pytest.approx(35.0)
    with pytest.raises(ValueError, match=r"time_range: 2e\+10 s is beyond \+-1e\+10 s"):
        TableConfig(file=micro, time_range=(0.0, 2e13), time_unit_s=1e-3)
    far = _ut_table(tmp_path / "far.csv", 2e10 + ref.time, long=False)
    with pytest.raises(DataFileError, match=r"far\.csv:2: time \[s\] \(motion\.time_unit_s = 1 s"):
        read_table(far)


def test_a_time_unit_that_makes_no_recording_rate_is_refused(tmp_path: Path) -> None:
    """The real 35 s UTKinect walk stamped in milliseconds but read as seconds (the default
    time_unit_s) was a 35,000 s motion at 0.015 frames a second, moving 1000 times too slowly,
    without a word. Like every recording's, a table's frame rate (from the median step) must
    lie within 1 .. 10,000 frames/s: refused naming the unit it was read in and what to set;
    with time_unit_s = 0.001 it is the walk, 35 s long. Its frame numbers read as seconds
    (frame_rate forgotten) and milliseconds read as microseconds are refused alike."""
    ref = read_utkinect(UT)
    ms = _ut_table(tmp_path / "ms.csv", (ref.time - ref.time[0]) * 1e3, long=False)
    with pytest.raises(DataFileError) as err:
        read_table(ms)
    assert str(err.value) == (
        f"{ms}: the frames are 66.67 s apart (the median step, motion.time_unit_s = 1 s per "
        "unit): 0.015 frames/s, below the 1 frames/s of a motion recording: check the time "
        "column's unit (motion.time_unit_s, 0.001 for milliseconds, or motion.frame_rate for "
        "frame numbers)"
    )
    walk = read_table(ms, TableLayout(time_unit_s=1e-3))
    assert walk.time[-1] - walk.time[0] == pytest.approx(35.0)
    frames = TableLayout(header=False, joints=tuple(KINECT_V1_JOINTS), time_column="frame")
    with pytest.raises(DataFileError, match=r"apart \(the median step, motion\.time_unit_s"):
        read_table(UT, frames)
    with pytest.raises(DataFileError, match=r"frames/s, above the 10000 frames/s"):
        read_table(ms, TableLayout(time_unit_s=1e-6))


def test_consecutive_frame_numbers_read_as_seconds_are_refused(tmp_path: Path) -> None:
    """The real UTKinect walk numbered frame by frame (0, 1, 2, ...) in its time column,
    frame_rate forgotten: read as seconds it was a 1 frame/s recording, at the lowest rate
    allowed, and ran 30 times too slowly without a word (the refusal caught only frame numbers
    with gaps). A time column read in seconds whose frames are a whole second apart holds
    frame numbers: refused naming frame_rate; given frame_rate = 30 it is the walk."""
    ref = read_utkinect(UT)
    numbered = _ut_table(tmp_path / "frames.csv", np.arange(ref.time.size, dtype=float), False)
    with pytest.raises(DataFileError) as err:
        read_table(numbered)
    assert "1 s apart" in str(err.value) and "motion.frame_rate for frame numbers" in str(err.value)
    walk = read_table(numbered, TableLayout(frame_rate=30.0))
    assert walk.time[-1] - walk.time[0] == pytest.approx((ref.time.size - 1) / 30.0)
    # frame numbers at a frame_rate of 1 Hz, given as such, are still a rate allowed
    rows = read_table(numbered, TableLayout(frame_rate=1.0))
    assert rows.time[1] - rows.time[0] == pytest.approx(1.0)


def test_time_unit_and_frame_rate_together_are_refused(tmp_path: Path) -> None:
    """The real walk stamped in milliseconds, configured with time_unit_s = 0.001 and the
    capture's frame_rate = 60 beside it: frame_rate won silently, reading the milliseconds as
    frame numbers, a 35 s walk stretched to 583 s. Both say how to read the time column:
    refused naming both; either alone reads the walk (35 s)."""
    ref = read_utkinect(UT)
    ms = _ut_table(tmp_path / "ms.csv", (ref.time - ref.time[0]) * 1e3, long=False)
    with pytest.raises(ValueError, match=r"time_unit_s \(0\.001 s per unit\) and frame_rate"):
        TableConfig(file=ms, time_unit_s=1e-3, frame_rate=60.0)
    walk = TableSource(TableConfig(file=ms, joint_set="kinect-v1", time_unit_s=1e-3)).load()
    assert walk.skeleton.duration == pytest.approx(35.0)
    # no time column: frame_rate is the rows' rate and time_unit_s reads nothing
    TableConfig(file=ms, time_column="", time_unit_s=1e-3, frame_rate=60.0)


def test_zero_is_missing_needs_all_three_coordinates_zero(tmp_path: Path) -> None:
    """With zero_is_missing, a joint at (0, 0, 0) is untracked, but one with a single
    coordinate exactly 0 (a joint on the y = 0 plane) is a real position and stays tracked."""
    t, tracks = _tracks()
    tracks["head"][3] = 0.0
    tracks["head"][5, 1] = 0.0
    path = tmp_path / "long.csv"
    _long_csv(path, t, tracks, 1.0)
    body = TableSource(TableConfig(file=path, zero_is_missing=True)).load().canonical()
    h = CANONICAL_JOINTS.index("head")
    assert not body.valid[3, h]
    assert body.valid[5, h] and body.joint("head")[5, 1] == 0.0
    assert body.valid[:, h].sum() == t.size - 1


def _npz_of_zeros(path: Path, shape: tuple[int, ...]) -> None:
    """A compressed NPZ whose ``positions`` (float64 zeros of ``shape``, written a MiB at a
    time) deflates to a small file, with 25 joint names."""
    import io
    import zipfile

    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        header, {"descr": "<f8", "fortran_order": False, "shape": shape}
    )
    names = io.BytesIO()
    np.save(names, np.array([f"j{i}" for i in range(shape[1])]))
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED, compresslevel=1) as z:
        z.writestr("joints.npy", names.getvalue())
        with z.open("positions.npy", "w", force_zip64=True) as f:
            f.write(header.getvalue())
            left, chunk = 8 * int(np.prod(shape)), bytes(1 << 20)
            while left > 0:
                f.write(chunk[: min(left, len(chunk))])
                left -= len(chunk)


def test_a_compressed_npz_member_beyond_the_size_limit_is_refused_before_it_expands(
    tmp_path: Path,
) -> None:
    """A compressed NPZ may declare up to 3e9 values per array: a 2.3 MB file of zeros
    expanded to 512 MiB (1.1 GiB of memory at its peak), and one of 24 GB ended in a
    MemoryError. A member whose uncompressed size is over limits.MAX_MOTION_ARRAY_BYTES is
    refused from the sizes the file declares (the archive's, or the shape in the member's
    header), naming the file and the member, before anything is decompressed; a small one is
    read."""
    import io
    import zipfile

    from helpers import data_error_and_peak

    from mdframework import limits

    frames = limits.MAX_MOTION_ARRAY_BYTES // (25 * 3 * 8) + 1  # just over the limit
    path = tmp_path / "zeros.npz"
    _npz_of_zeros(path, (frames, 25, 3))
    assert path.stat().st_size < 5e6
    spec = TableLayout(time_column="", frame_rate=120.0)
    error, peak = data_error_and_peak(lambda: read_table(path, spec))
    assert str(error) == (
        f"{path}: array 'positions' is {frames * 600 + 128:,} bytes uncompressed, beyond the "
        f"limit of {limits.MAX_MOTION_ARRAY_BYTES:,} bytes for an array of a motion file"
    )
    assert peak < 10 * 2**20
    # a member whose header declares more than it holds (the archive's size is its own)
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        header, {"descr": "<f8", "fortran_order": False, "shape": (10**6, 25, 3)}
    )
    forged = tmp_path / "forged.npz"
    with zipfile.ZipFile(forged, "w") as z:
        z.writestr("positions.npy", header.getvalue())
    with pytest.raises(DataFileError) as err:
        read_table(forged, spec)
    assert str(err.value) == (
        f"{forged}: array 'positions' is 600,000,000 bytes (shape (1000000, 25, 3) of float64) "
        f"uncompressed, beyond the limit of {limits.MAX_MOTION_ARRAY_BYTES:,} bytes for an "
        "array of a motion file"
    )
    # the limit itself is allowed ("at most"): a header declaring exactly that many bytes
    # is not refused for its size; its data, missing here, is what fails, naming the file and
    # the array (a bare ValueError of numpy's before)
    for n, refused in (
        (limits.MAX_MOTION_ARRAY_BYTES, False),
        (limits.MAX_MOTION_ARRAY_BYTES + 1, True),
    ):
        header = io.BytesIO()
        np.lib.format.write_array_header_1_0(
            header, {"descr": "|u1", "fortran_order": False, "shape": (n,)}
        )
        with zipfile.ZipFile(forged, "w") as z:
            z.writestr("positions.npy", header.getvalue())
        with pytest.raises(DataFileError) as err:
            read_table(forged, spec)
        assert ("beyond the limit" in str(err.value)) == refused, err.value
        if not refused:
            assert str(err.value).startswith(f"{forged}: array 'positions' cannot be read (")
    small = tmp_path / "small.npz"
    _npz_of_zeros(small, (240, 25, 3))
    assert read_table(small, spec).positions.shape == (240, 25, 3)
