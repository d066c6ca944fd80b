"""The `radhar` recording source on the shipped real recordings (mdf-radhar)."""

from __future__ import annotations

import gzip
import hashlib
import re
from pathlib import Path

import numpy as np
import pytest
from conftest import EXAMPLES
from mdf_radhar.source import RadharSource, npz_recordings, read_rostopic_text, text_recording

from mdframework.errors import DataFileError
from mdframework.pointcloud import IWR1443_BIN_WIDTH
from mdframework.testing import check_recording_source

DATA = EXAMPLES / "data" / "radhar"
TEXTS = {
    "boxing": "20_boxing_1.txt",
    "jump": "20_jump_1.txt",
    "walk": "__20_walk_1.txt",
}


def test_shipped_text_files_are_the_originals() -> None:
    """The decompressed text files have the sha256 that PROVENANCE.md states."""
    table = (DATA / "PROVENANCE.md").read_text()
    for name in TEXTS.values():
        stated = re.search(rf"`text/{re.escape(name)}\.gz` \|[^|]*\| ([0-9a-f]{{64}})", table)
        assert stated is not None, name
        digest = hashlib.sha256(gzip.decompress((DATA / "text" / f"{name}.gz").read_bytes()))
        assert digest.hexdigest() == stated.group(1)


@pytest.mark.parametrize("activity", sorted(TEXTS))
def test_text_and_npz_forms_of_a_recording_agree(activity: str) -> None:
    """The rostopic text (frames from point_id = 0) and the compact NPZ row subset of the same
    recording give the same points."""
    name = TEXTS[activity]
    text = text_recording(DATA / "text" / f"{name}.gz")
    [(got_name, npz)] = npz_recordings(DATA / f"radhar_{activity}_subset.npz", names=[name])
    assert got_name == name
    assert text.n_frames == npz.n_frames and 595 <= text.n_frames <= 605
    np.testing.assert_array_equal(text.frame, npz.frame)
    np.testing.assert_allclose(text.positions, npz.positions, atol=1e-6)
    np.testing.assert_allclose(text.velocity, npz.velocity, atol=1e-6)
    np.testing.assert_allclose(text.intensity, npz.intensity, atol=1e-4)


def test_frame_period_matches_the_header_stamps() -> None:
    """Frames counted from point_id = 0 at the configured 33.33 ms span the same time as the
    publish stamps (within 2 %; the stamps are bursty, their span is not)."""
    raw = gzip.decompress((DATA / "text" / "20_jump_1.txt.gz").read_bytes()).decode()
    secs = np.array(re.findall(r"secs: (\d+)\n\s+nsecs: (\d+)", raw), dtype=np.float64)
    stamps = secs[:, 0] + 1e-9 * secs[:, 1]
    cloud = text_recording(DATA / "text" / "20_jump_1.txt.gz")
    span = cloud.n_frames * cloud.frame_period
    assert span == pytest.approx(stamps[-1] - stamps[0], rel=0.02)


def test_velocities_are_the_sensor_bins_with_the_project_sign() -> None:
    """Velocities are whole Doppler bins of 0.6147 m/s; the driver's range rate (-4.92 ...
    +4.30 m/s, positive receding) becomes -4.30 ... +4.92 m/s positive approaching, and the
    fastest boxing punches (2.4 m/s and more) go toward the sensor."""
    cloud = text_recording(DATA / "text" / "20_boxing_1.txt.gz")
    k = cloud.velocity / IWR1443_BIN_WIDTH
    np.testing.assert_allclose(k, np.round(k), atol=1e-6)
    assert k.min() >= -7 and k.max() <= 8
    raw = read_rostopic_text(DATA / "text" / "20_boxing_1.txt.gz")
    np.testing.assert_array_equal(cloud.velocity, -raw["velocity"])
    near = (cloud.ranges > 0.5) & (cloud.ranges < 3.0)
    fast_in = np.sum(near & (cloud.velocity >= 2.4))
    fast_out = np.sum(near & (cloud.velocity <= -2.4))
    assert fast_in > 2 * fast_out > 0
    assert cloud.velocity.max() == pytest.approx(5 * IWR1443_BIN_WIDTH, rel=1e-6)


def test_walkers_range_changes_as_their_doppler_says() -> None:
    """Physics, not the driver's word: in every shipped walk the range of the moving points
    (the walker) shrinks while their radial velocity is positive (approaching) and grows while
    it is negative, and at about the rate the velocity gives with frames 1/30 s apart (a wrong
    sign, or a frame period off by half, fails this)."""
    slopes = []
    for name, cloud in npz_recordings(DATA / "radhar_walk_subset.npz"):
        r = cloud.ranges
        moving = (cloud.velocity != 0) & (r > 0.5) & (r < 3.0)
        block = 15  # frames: 0.5 s
        centre, velocity = [], []
        for first in range(0, cloud.n_frames - block, block):
            pick = moving & (cloud.frame >= first) & (cloud.frame < first + block)
            if np.sum(pick) >= 5:
                centre.append(np.median(r[pick]))
                velocity.append(np.mean(cloud.velocity[pick]))
            else:
                centre.append(np.nan)
                velocity.append(np.nan)
        approach = -np.gradient(np.array(centre)) / (block * cloud.frame_period)  # m/s
        v = np.array(velocity)
        ok = np.isfinite(approach) & np.isfinite(v)
        assert np.sum(ok) >= 10, name
        assert np.corrcoef(approach[ok], v[ok])[0, 1] > 0.8, name
        slopes.append(np.polyfit(v[ok], approach[ok], 1)[0])
    # the moving points' mean Doppler (legs and arms included) exceeds the walker's own speed
    assert 0.5 < np.median(slopes) < 1.0, slopes


def test_people_stand_in_front_of_the_sensor() -> None:
    """ROS axes (x forward) become sensor axes (y boresight): the moving points near the person
    lie ahead of the sensor, about 1-2 m along y."""
    cloud = text_recording(DATA / "text" / "__20_walk_1.txt.gz")
    moving = (cloud.velocity != 0) & (cloud.ranges > 0.5) & (cloud.ranges < 3.0)
    y = cloud.positions[moving, 1]
    assert 1.0 < np.median(y) < 2.0
    assert np.median(np.abs(cloud.positions[moving, 0])) < 0.6


def test_contract_and_config() -> None:
    source = RadharSource(
        RadharSource.Config.model_validate(
            {"kind": "radhar", "file": "radhar_jump_subset.npz"}, context={"base_dir": DATA}
        )
    )
    recs = check_recording_source(source)
    assert len(recs) == 12 and recs[0].name == "20_jump_1.txt"
    assert "RadHAR" in recs[0].metadata["citation"]


def _message(point_id: float, secs: int = 100, nsecs: int = 0, **values: object) -> str:
    """One RadarScan message as rostopic echo writes it (x 1 m ahead unless given)."""
    fields = {"x": 1.0, "y": 0.0, "z": 0.0, "velocity": 0.0, "intensity": 30.0, **values}
    head = f"header: \n  seq: 1\n  stamp: \n    secs: {secs}\n    nsecs: {nsecs}\n"
    body = "".join(f"{k}: {v}\n" for k, v in fields.items())
    return f'{head}  frame_id: "ti_mmwave"\npoint_id: {point_id}\n{body}---\n'


def test_bad_files_name_the_file_and_line(tmp_path: Path) -> None:
    bad = tmp_path / "bad.txt"
    bad.write_text(_message(0) + _message(1, x="abc"))
    with pytest.raises(DataFileError, match=r"bad\.txt:21: x: not a number"):
        read_rostopic_text(bad)
    bad.write_text("point_id: 0\nx: 1.0\ny: 0.0\nz: 0.0\nintensity: 3\n---\n")
    with pytest.raises(DataFileError, match=r"bad\.txt:1: message has no velocity, header\.stamp"):
        read_rostopic_text(bad)
    # a lost '---' would merge two points into one: the repeated key is refused
    bad.write_text(_message(0).removesuffix("---\n") + _message(1))
    with pytest.raises(DataFileError, match=r"bad\.txt:16: secs given twice .*first on line 4"):
        read_rostopic_text(bad)
    bad.write_text(_message(3) + _message(0, nsecs=5))
    with pytest.raises(DataFileError, match=r"bad\.txt:7: the first message has point_id 3, not 0"):
        text_recording(bad)
    npz = tmp_path / "bad.npz"
    np.savez(npz, files=np.array(["a"]), file_index=np.zeros(2, np.int16))
    with pytest.raises(DataFileError, match="missing arrays: frame"):
        npz_recordings(npz)
    with pytest.raises(DataFileError, match=r"no recording named 'nope\.txt'"):
        npz_recordings(DATA / "radhar_walk_subset.npz", names=["nope.txt"])


@pytest.mark.parametrize(
    ("values", "problem"),
    [
        ({"x": "1e308"}, r"x 1e\+308 is outside the sensor's range -10\.5021 \.\. 10\.5021 m"),
        ({"z": "nan"}, "z nan is not finite"),
        ({"y": "-inf"}, "y -inf is not finite"),
        ({"velocity": "5.0"}, r"velocity 5 is outside the sensor's range -4\.91735 \.\. 4\.30268"),
        ({"intensity": "-3"}, r"intensity -3 is outside the sensor's range 0 \.\. 48\.1648 dB"),
        ({"intensity": "1e9"}, "intensity 1e\\+09 is outside"),
    ],
)
def test_values_beyond_what_the_sensor_reports_name_their_line(
    tmp_path: Path, values: dict[str, str], problem: str
) -> None:
    """The IWR1443 configuration reports points within 10.46 m (240 range bins of 4.36 cm; one
    bin of slack), range rates in Doppler bins -8 .. +7 of 0.6147 m/s and intensities
    10 log10(peak + 1) of a 16-bit peak (0 .. 48.16 dB): anything else is a damaged file."""
    bad = tmp_path / "bad.txt"
    bad.write_text(_message(0) + _message(1, nsecs=10, **values))
    key = next(iter(values))
    line = 14 + ["x", "y", "z", "velocity", "intensity"].index(key) + 7
    with pytest.raises(DataFileError, match=rf"bad\.txt:{line}: {problem}"):
        read_rostopic_text(bad)


def test_points_beyond_the_maximum_range_and_broken_order_are_refused(tmp_path: Path) -> None:
    bad = tmp_path / "bad.txt"
    bad.write_text(_message(0) + _message(1, x=8.0, y=8.0))  # each within 10.5 m, 11.3 m away
    with pytest.raises(DataFileError, match=r"bad\.txt:14: point at 11\.31 m is beyond"):
        read_rostopic_text(bad)
    bad.write_text(_message(0) + _message(5) + _message(2))
    with pytest.raises(DataFileError, match=r"bad\.txt:33: point_id 2 after 5: point numbers rise"):
        read_rostopic_text(bad)
    bad.write_text(_message(0, secs=101) + _message(1, secs=100))
    with pytest.raises(DataFileError, match=r"bad\.txt:17: time stamp 100\.000000000 s is earlier"):
        read_rostopic_text(bad)
    bad.write_text(_message(0, nsecs=10**9))
    with pytest.raises(DataFileError, match=r"bad\.txt:5: nsecs 1e\+09 is outside"):
        read_rostopic_text(bad)
    bad.write_text(_message(0.5))
    with pytest.raises(DataFileError, match=r"bad\.txt:7: point_id 0\.5 is not a whole number"):
        read_rostopic_text(bad)


def test_a_recording_needs_two_frames_and_two_time_stamps(tmp_path: Path) -> None:
    bad = tmp_path / "one.txt"
    bad.write_text(_message(0) + _message(1))
    with pytest.raises(DataFileError, match=r"one\.txt: all 2 messages have the same time stamp"):
        read_rostopic_text(bad)
    bad.write_text(_message(0) + _message(1, nsecs=1) + _message(2, nsecs=2))
    with pytest.raises(DataFileError, match=r"one\.txt: only 1 frame\(s\): a recording needs"):
        text_recording(bad)
    bad.write_text(_message(0) + _message(0, nsecs=33_333_000))
    assert text_recording(bad).n_frames == 2


def test_crlf_line_ends_read_the_same(tmp_path: Path) -> None:
    """A text file whose line ends were converted to CRLF is the same recording."""
    raw = gzip.decompress((DATA / "text" / "20_jump_1.txt.gz").read_bytes())
    crlf = tmp_path / "20_jump_1.txt"
    crlf.write_bytes(raw.replace(b"\n", b"\r\n"))
    a, b = text_recording(crlf), text_recording(DATA / "text" / "20_jump_1.txt.gz")
    np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(a.frame, b.frame)


def _rewrite_npz(src: Path, dst: Path, **change: np.ndarray) -> None:
    with np.load(src) as data:
        arrays = {k: data[k] for k in data.files}
    arrays.update(change)
    np.savez(dst, **arrays)


def test_npz_sizes_are_checked_before_anything_is_allocated(tmp_path: Path) -> None:
    """A damaged or crafted NPZ may declare any array size: the declared size of every array is
    compared with the bytes the file holds before numpy allocates it."""
    src = DATA / "radhar_jump_subset.npz"
    bad = tmp_path / "bad.npz"
    raw = src.read_bytes()
    bad.write_bytes(raw[: len(raw) // 2])
    with pytest.raises(DataFileError, match=r"bad\.npz: not a readable NPZ file"):
        npz_recordings(bad)
    # an x array whose header declares 10^12 values but holds the real ones
    import zipfile

    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(bad, "w") as zout:
        for info in zin.infolist():
            data = zin.read(info)
            if info.filename == "x.npy":
                n = int(np.load(src)["x"].size)
                data = data.replace(f"({n},)".encode(), b"(1000000000000,)".ljust(len(f"({n},)")))
            zout.writestr(info, data)
    with pytest.raises(DataFileError, match=r"bad\.npz: x declares 1,000,000,000,000 values, more"):
        npz_recordings(bad)


def test_npz_values_and_frames_are_checked(tmp_path: Path) -> None:
    src = DATA / "radhar_walk_subset.npz"
    bad = tmp_path / "bad.npz"
    with np.load(src) as data:
        x, frame, index = data["x"].copy(), data["frame"].copy(), data["file_index"].copy()
        n_files = data["files"].size
    x[7] = np.inf
    _rewrite_npz(src, bad, x=x)
    with pytest.raises(DataFileError, match=r"bad\.npz: x\[7\]: x inf is not finite"):
        npz_recordings(bad)
    far = frame.copy()
    far[np.nonzero(index == 0)[0][-1]] = 2**31 - 1
    _rewrite_npz(src, bad, frame=far)
    with pytest.raises(
        DataFileError, match=r"recording '.*': frame 2147483647 .* beyond the 86400"
    ):
        npz_recordings(bad)
    wrong = index.copy()
    wrong[3] = n_files
    _rewrite_npz(src, bad, file_index=wrong)
    with pytest.raises(DataFileError, match=rf"file_index\[3\] = {n_files} does not name one"):
        npz_recordings(bad)
    single = frame.copy()
    single[index == 0] = 0
    _rewrite_npz(src, bad, frame=single)
    with pytest.raises(DataFileError, match=r"only 1 frame\(s\)"):
        npz_recordings(bad)


def test_the_numbers_on_the_sim_to_real_page() -> None:
    """docs/sim-to-real.md: within 0.5-3 m a frame holds about 8 static points and 3.1
    (boxing), 2.2 (walk) or 0.24 (jump) moving points; the fastest 1 % of the moving boxing points
    move at 3.1 m/s toward the sensor or faster."""
    moving = {"boxing": 3.1, "walk": 2.2, "jump": 0.24}
    for activity, expected in moving.items():
        frames = n_static = n_moving = 0
        fast: list[float] = []
        for _, c in npz_recordings(DATA / f"radhar_{activity}_subset.npz"):
            gate = (c.ranges >= 0.5) & (c.ranges <= 3.0)
            frames += c.n_frames
            n_static += int(np.sum(gate & (c.velocity == 0)))
            n_moving += int(np.sum(gate & (c.velocity != 0)))
            fast += c.velocity[gate & (c.velocity != 0)].tolist()
        assert 7.0 <= n_static / frames <= 9.1, (activity, n_static / frames)
        assert n_moving / frames == pytest.approx(expected, abs=0.05), activity
        if activity == "boxing":
            assert np.percentile(fast, 99) == pytest.approx(5 * IWR1443_BIN_WIDTH, abs=1e-6)


def test_the_input_rules_page_states_the_sensor_limits_of_the_reader() -> None:
    """docs/input-rules.md quotes the reader's bounds."""
    from conftest import ROOT
    from mdf_radhar import source

    page = " ".join((ROOT / "docs" / "input-rules.md").read_text().split())
    assert f"maximum range, 241 range bins of 0.043577 m ({source.MAX_RANGE_M:.2f} m" in page
    low, high = source.MIN_RANGE_RATE_MPS, source.MAX_RANGE_RATE_MPS
    assert f"-8 .. +7 bins ({low:.3f} .. +{high:.3f} m/s)" in page
    assert f"within 0 .. {source.MAX_INTENSITY_DB:.2f} dB" in page
    assert f"a whole number 0 .. {source.MAX_POINT_ID}" in page
