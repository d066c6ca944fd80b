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


def test_bad_files_name_the_file_and_line(tmp_path: Path) -> None:
    bad = tmp_path / "bad.txt"
    bad.write_text(
        "point_id: 0\nx: 1.0\ny: 0.0\nz: 0.0\nvelocity: 0.0\nintensity: 3\n---\n"
        "point_id: 1\nx: abc\n"
    )
    with pytest.raises(DataFileError, match=r"bad\.txt:9: x: not a number"):
        read_rostopic_text(bad)
    bad.write_text("point_id: 0\nx: 1.0\ny: 0.0\nz: 0.0\nintensity: 3\n---\n")
    with pytest.raises(DataFileError, match=r"bad\.txt:1: message has no velocity"):
        read_rostopic_text(bad)
    bad.write_text("point_id: 3\nx: 1.0\ny: 0.0\nz: 0.0\nvelocity: 0\nintensity: 3\n---\n")
    with pytest.raises(DataFileError, match="point_id 3, not 0"):
        text_recording(bad)
    npz = tmp_path / "bad.npz"
    np.savez(npz, files=np.array(["a"]), file_index=np.zeros(2, np.int16))
    with pytest.raises(DataFileError, match="missing arrays: frame"):
        npz_recordings(npz)
    with pytest.raises(DataFileError, match=r"no recording named 'nope\.txt'"):
        npz_recordings(DATA / "radhar_walk_subset.npz", names=["nope.txt"])


def test_the_numbers_on_the_sim_to_real_page() -> None:
    """docs/sim-to-real.md: within 0.5-3 m a frame holds about 8 static points and 3.1
    (boxing), 2.2 (walk) or 0.24 (jump) moving points; the fastest 1 % of the boxing points
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
