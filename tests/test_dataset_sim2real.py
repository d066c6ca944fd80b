"""Datasets with real radar recordings, per-record random draws and motion augmentation."""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import pytest
from conftest import EXAMPLES
from helpers import traced_peak
from mdf_radhar.source import npz_recordings

from mdframework.dataset import (
    RECORDS,
    DatasetWarning,
    build_dataset,
    load_dataset,
    load_dataset_config,
    plan_records,
    read_record,
)
from mdframework.errors import ConfigError, MdfError
from mdframework.features import FEATURE_NAMES

RADHAR = EXAMPLES / "data" / "radhar"
T = TypeVar("T")
CMU_WALK = EXAMPLES / "data" / "cmu" / "asf-amc" / "02_01.amc"
CMU_BOXING = EXAMPLES / "data" / "cmu" / "asf-amc" / "13_18.amc"


def test_real_recordings_become_windows_of_histograms(tmp_path: Path) -> None:
    """Two 2 s records of one real recording: 60 frames each; the stored histograms and
    features equal an independent count of the recording's points (np.histogram per frame)."""
    cfg_path = tmp_path / "real.toml"
    cfg_path.write_text(f"""
[[sources]]
label = "boxing"
record_length = 2.0
max_records = 2
hop = 1.0
[sources.recording]
kind = "radhar"
file = "{RADHAR / "radhar_boxing_subset.npz"}"
recordings = ["20_boxing_3.txt"]
[histogram]
min_range = 0.5
max_range = 3.0
""")
    cfg, base = load_dataset_config(cfg_path)
    out = tmp_path / "ds"
    rows = build_dataset(cfg, base, out, workers=1, progress=False)
    assert [r["file"] for r in rows] == ["20_boxing_3.txt"] * 2
    assert [r["start_s"] for r in rows] == pytest.approx([0.0, 30 * 0.033333])
    assert rows[0]["aspect_deg"] == "" and rows[0]["radar_z_m"] == ""
    [(_, cloud)] = npz_recordings(RADHAR / "radhar_boxing_subset.npz", names=["20_boxing_3.txt"])
    edges = (np.arange(18) - 8.5) * 0.61466867
    for row, first in zip(rows, (0, 30), strict=True):
        arrays, meta = read_record(out / RECORDS / f"{row['id']}.npz")
        assert meta["first_frame"] == first and meta["histogram"]["n_bins"] == 17
        h = arrays["histograms"]
        assert h.shape == (60, 17)
        for f in range(60):
            sel = (cloud.frame == first + f) & (cloud.ranges >= 0.5) & (cloud.ranges <= 3.0)
            ref, _ = np.histogram(cloud.velocity[sel], bins=edges)
            np.testing.assert_array_equal(h[f], ref)
        # static returns dominate: most points at 0 m/s
        assert h[:, 8].sum() > 0.5 * h.sum()
    data = load_dataset(out, histograms=True)
    assert data.histograms is not None and data.histograms[0] is not None
    assert np.all(np.isfinite(data.features))
    upper = data.features[:, FEATURE_NAMES.index("upper_max")]
    assert np.all(upper >= 0.61466867)  # punches show up as approaching points


def write_walk(path: Path, randomize: str, seed: int = 11) -> Path:
    """One 1 s record of a CMU walk (small FFT) with the given [randomize] lines."""
    path.write_text(f"""
seed = {seed}
[[sources]]
label = "walk"
motion = {{ kind = "cmu", file = "{CMU_WALK}" }}
record_length = 1.0
max_records = 1
[base.processing]
nfft = 256
[base.scene]
radar_position = [10.0, 0.0, 1.0]
[randomize]
{randomize}
""")
    return path


def write_random(path: Path) -> Path:
    return write_walk(
        path,
        """draws = 3
radar_height = { uniform = [0.8, 1.6] }
aspect_deg = { choice = [0.0, 30.0] }
[randomize.params]
"radar.carrier_frequency" = { uniform = [9e9, 11e9] }""",
    )


def test_random_draws_are_seeded_recorded_and_applied(tmp_path: Path) -> None:
    cfg, base = load_dataset_config(write_random(tmp_path / "r.toml"))
    specs = plan_records(cfg, base)
    again = plan_records(cfg, base)
    assert len(specs) == 3
    assert [s.draws for s in specs] == [s.draws for s in again]
    heights = [s.draws["radar_height"] for s in specs if s.draws]
    assert len(set(heights)) == 3 and all(0.8 <= h <= 1.6 for h in heights)
    for s in specs:
        assert s.draws is not None
        assert s.run_config["scene"]["radar_position"][2] == s.draws["radar_height"]
        assert s.run_config["scene"]["person"]["aspect_deg"] == s.draws["aspect_deg"]
        assert s.run_config["radar"]["carrier_frequency"] == s.draws["radar.carrier_frequency"]
    rows = build_dataset(cfg, base, tmp_path / "ds", workers=1, progress=False)
    data = load_dataset(tmp_path / "ds", spectrograms=False)
    np.testing.assert_allclose(data.table["draw.radar_height"], heights)
    np.testing.assert_allclose(data.table["radar_z_m"], heights)
    _, meta = read_record(tmp_path / "ds" / RECORDS / f"{rows[0]['id']}.npz")
    assert (
        meta["run_config"]["radar"]["carrier_frequency"]
        == specs[0].draws["radar.carrier_frequency"]
    )  # type: ignore[index]


def test_grid_and_draw_of_one_parameter_is_an_error(tmp_path: Path) -> None:
    path = write_random(tmp_path / "r.toml")
    path.write_text(path.read_text() + "\n[variations]\nradar_height = [1.0]\n")
    cfg, base = load_dataset_config(path)
    with pytest.raises(ConfigError, match="radar_height: give it as a variation or"):
        plan_records(cfg, base)


def test_speed_augmentation_scales_the_doppler_spread(tmp_path: Path) -> None:
    """A walk played 1.6 times faster: every body-part velocity scales by 1.6, and so do the
    torso velocity and the upper envelope (within the spectrogram's bin and envelope noise)."""
    results = {}
    for name, speed in (("slow", 1.0), ("fast", 1.6)):
        path = write_walk(
            tmp_path / f"{name}.toml", f"speed = {{ uniform = [{speed}, {speed}] }}", 1
        )
        cfg, base = load_dataset_config(path)
        build_dataset(cfg, base, tmp_path / name, workers=1, progress=False)
        results[name] = load_dataset(tmp_path / name, spectrograms=False)
    slow, fast = results["slow"].features[0], results["fast"].features[0]
    i, j = FEATURE_NAMES.index("torso_mean"), FEATURE_NAMES.index("upper_max")
    assert fast[i] / slow[i] == pytest.approx(1.6, rel=0.12)
    assert fast[j] / slow[j] == pytest.approx(1.6, rel=0.15)
    assert results["fast"].table["draw.speed"][0] == 1.6


def test_bad_recording_config_is_one_line_exit_2(tmp_path: Path) -> None:
    path = tmp_path / "bad.toml"
    path.write_text("""
[[sources]]
label = "walk"
recording = { kind = "radhar", file = "missing.npz" }
""")
    out = tmp_path / "out"
    proc = subprocess.run(
        [sys.executable, "-m", "mdframework.cli", "dataset", "build", str(path), "--out", str(out)],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2
    assert proc.stderr.strip().count("\n") == 0
    assert "sources[0].recording: file: " in proc.stderr and "missing.npz" in proc.stderr
    assert not out.exists()


def test_real_to_real_reference_on_histograms(tmp_path: Path) -> None:
    """The shipped example: held-out real recordings are recognised from their histogram
    vectors well above chance (measured 0.915 with 10 splits; three classes: chance 0.33)."""
    from mdframework import experiment as exp

    cfg = exp.load_experiment_config(EXAMPLES / "experiment_radhar.toml")
    cfg = cfg.model_copy(update={"evaluation": cfg.evaluation.model_copy(update={"repeats": 3})})
    summary = exp.run_experiment(cfg, tmp_path / "exp", progress=False)
    within = summary["within"]["radhar"]
    assert within["classes"] == ["boxing", "jump", "walk"]
    assert within["balanced_accuracy_mean"] > 0.85
    report = (tmp_path / "exp" / "report.md").read_text()
    assert "Input: histogram" in report


def test_histogram_input_needs_histogram_records_and_no_selection(tmp_path: Path) -> None:
    from mdframework import experiment as exp

    p = tmp_path / "e.toml"
    p.write_text('input = "histogram"\n[dataset]\npath = "x"\n')
    with pytest.raises(ConfigError, match=r"needs selection\.method = 'none'"):
        exp.load_experiment_config(p)


def test_a_source_can_have_its_own_draws(tmp_path: Path) -> None:
    path = write_random(tmp_path / "r.toml")
    text = path.read_text().replace(
        "[base.processing]",
        '[[sources]]\nlabel = "slow walk"\nmotion = { kind = "cmu", file = "'
        + str(CMU_WALK)
        + '" }\nrecord_length = 1.0\nmax_records = 1\n'
        "randomize = { speed = { uniform = [0.5, 0.6] } }\n[base.processing]",
    )
    path.write_text(text)
    cfg, base = load_dataset_config(path)
    specs = plan_records(cfg, base)
    assert [s.label for s in specs] == ["walk"] * 3 + ["slow walk"] * 3
    # the source's speed range, and the dataset's scene draws (and number of draws)
    own = [s.draws or {} for s in specs[3:]]
    assert len(own) == 3 and all(0.5 <= d["speed"] <= 0.6 for d in own)
    assert all({"radar_height", "aspect_deg"} <= set(d) for d in own)
    assert "speed" not in (specs[0].draws or {})


def test_simulated_point_clouds_become_the_same_histograms(tmp_path: Path) -> None:
    """A simulated FMCW record (IWR1443 preset) with representation = 'histogram': its stored
    per-frame histograms equal an independent count of the run's own point cloud, frame by
    frame, with the same bins and range gate as real records."""
    pytest.importorskip("mdf_fmcw")
    from mdframework.config import validate_run_config
    from mdframework.pipeline import simulate

    path = tmp_path / "sim.toml"
    path.write_text(
        f"""
representation = "histogram"
[[sources]]
label = "boxing"
motion = {{ kind = "cmu", file = "{CMU_BOXING}", start = 5.0 }}
record_length = 0.5
max_records = 1
[base.radar]
kind = "fmcw"
preset = "iwr1443_short_range_3d"
save_range_doppler = false
[base.scene]
radar_position = [1.6, 0.0, 1.0]
min_range = 0.25
"""
    )
    cfg, base = load_dataset_config(path)
    [spec] = plan_records(cfg, base)
    rows = build_dataset(cfg, base, tmp_path / "ds", workers=1, progress=False)
    arrays, meta = read_record(tmp_path / "ds" / RECORDS / f"{rows[0]['id']}.npz")
    result = simulate(validate_run_config(spec.run_config, base_dir=base))
    points = result.received.products["points"]
    r = np.linalg.norm(points[:, 2:5], axis=1)
    gate = (r >= 0.5) & (r <= 3.0)
    edges = (np.arange(18) - 8.5) * 0.61466867
    h = arrays["histograms"]
    assert h.shape == (15, 17) and h.dtype == np.float32  # 0.5 s of 33.33 ms frames
    for f in range(15):
        sel = gate & (points[:, 0] == f)
        ref, _ = np.histogram(points[sel, 5], bins=edges)
        np.testing.assert_array_equal(h[f], ref)
    assert h[:, 8].sum() > 0 and h.sum() > h[:, 8].sum()  # static body and moving fists
    assert meta["label"] == "boxing"
    assert meta["units"]["histograms"] == "points (or weights) per bin and frame"


def test_a_simulated_cloud_holds_every_frame_of_its_record() -> None:
    """A 1.02 s record of 50 ms frames (6.7 ms of chirps each) holds 21 frames, the last from
    1.00 s: its cloud has 21 frames, frame times 0 to 1 s, also when the last frame has no
    point (it had 20 then, floor(1.02 / 0.05): a record's histograms and times lost their
    last frame whenever it held no point)."""
    from types import SimpleNamespace

    from mdf_fmcw.waveform import FmcwConfig

    from mdframework.dataset import _simulated_cloud
    from mdframework.physics import fmcw

    seq = FmcwConfig().sequence()
    t = fmcw.chirp_times(seq, 0.0, 1.02)
    assert t.size == 21 * seq.chirps_per_frame
    points = np.zeros((20, 7))
    points[:, 0] = np.arange(20)  # one point in each frame but the last
    points[:, 1] = points[:, 0] * seq.frame_period
    result = SimpleNamespace(
        received=SimpleNamespace(products={"points": points}), pulse_times=t - t[0]
    )
    config = SimpleNamespace(
        radar=SimpleNamespace(frame_period=seq.frame_period),
        motion=SimpleNamespace(duration=1.02),
    )
    cloud = _simulated_cloud(result, config, "r")
    assert cloud.n_frames == 21 and cloud.frame_period == 0.05


def test_the_sim_to_real_dataset_plan() -> None:
    """docs/sim-to-real.md: 45 simulated records of 2 s (16 boxing, 15 jump, 14 walk) beside
    360 real ones (120 per activity), every simulated one with its own draws."""
    pytest.importorskip("mdf_fmcw")
    from collections import Counter

    cfg, base = load_dataset_config(EXAMPLES / "datasets" / "sim2real.toml")
    specs = plan_records(cfg, base)
    counts = Counter((s.group, s.label) for s in specs)
    assert counts == {
        ("sim", "boxing"): 16,
        ("sim", "jump"): 15,
        ("sim", "walk"): 14,
        ("radhar", "boxing"): 120,
        ("radhar", "jump"): 120,
        ("radhar", "walk"): 120,
    }
    sim = [s for s in specs if s.group == "sim"]
    assert all(s.draws and "radar_height" in s.draws for s in sim)
    assert len({s.draws["radar_height"] for s in sim if s.draws}) == len(sim)


def write_recorded(path: Path, length: float, extra: str = "", lo: float = 0.5) -> Path:
    """One real RadHAR recording (20_boxing_3.txt) cut into records of ``length`` s given by
    ``record_lengths.boxing``; histograms of the points ``lo``..``lo + 2.5`` m."""
    path.write_text(f"""
{extra}
[record_lengths]
boxing = {length}
[[sources]]
label = "boxing"
max_records = 1
[sources.recording]
kind = "radhar"
file = "{RADHAR / "radhar_boxing_subset.npz"}"
recordings = ["20_boxing_3.txt"]
[histogram]
min_range = {lo}
max_range = {lo + 2.5}
""")
    return path


def test_a_record_length_below_one_frame_of_a_recording_names_the_field(tmp_path: Path) -> None:
    """10 ms is under one 33.3 ms frame of the IWR1443 recordings: refused naming
    record_lengths.boxing and the frame, not as "0 frames do not fit 601 frames"."""
    cfg, base = load_dataset_config(write_recorded(tmp_path / "r.toml", 0.01))
    with pytest.raises(ConfigError) as info:
        plan_records(cfg, base)
    assert str(info.value) == (
        "record_lengths.boxing: 0.01 s is shorter than one 33.3 ms frame of 20_boxing_3.txt: "
        "give at least 0.03333 s"
    )
    # one frame is the shortest record
    cfg, base = load_dataset_config(write_recorded(tmp_path / "one.toml", 0.0334))
    [spec] = plan_records(cfg, base)
    assert spec.run_config["frames"] == 1


def test_a_failing_recorded_record_names_its_recording_and_window(tmp_path: Path) -> None:
    """A recorded record's error names its recording file and window (frames 0-59 of a 30 Hz
    recording: 0-2 s), and with on_error = "skip" its index row does too."""
    cfg, base = load_dataset_config(write_recorded(tmp_path / "r.toml", 2.0, lo=8.0))
    with pytest.raises(MdfError) as info:
        build_dataset(cfg, base, tmp_path / "stop", workers=1, progress=False)
    assert "(boxing; source file 20_boxing_3.txt, window 0.000-2.000 s)" in str(info.value)
    assert "no point within 8-10.5 m in any frame" in str(info.value)
    path = write_recorded(tmp_path / "skip.toml", 2.0, 'on_error = "skip"', lo=8.0)
    cfg, base = load_dataset_config(path)
    # the skipped row's file and window (read from the warning: every record failed)
    skipped = r"\(20_boxing_3.txt, window 0.000 s \+ 1.9999\d* s\) skipped: .*no point within"
    with pytest.warns(UserWarning, match=skipped), pytest.raises(MdfError, match="every record"):
        build_dataset(cfg, base, tmp_path / "skip", workers=1, progress=False)


def test_a_simulated_record_shorter_than_one_fmcw_frame_names_record_lengths(
    tmp_path: Path,
) -> None:
    """2 ms records with the IWR1443 preset, whose frame takes 48 chirps x 64.14 us = 3.079 ms:
    the build stops naming record_lengths.walk and the minimum (not an IndexError)."""
    path = tmp_path / "short.toml"
    path.write_text(f"""
[record_lengths]
walk = 0.002
[[sources]]
label = "walk"
motion = {{ kind = "cmu", file = "{CMU_WALK}" }}
max_records = 1
[base.radar]
kind = "fmcw"
preset = "iwr1443_short_range_3d"
[base.scene]
radar_position = [4.0, 0.0, 1.0]
""")
    cfg, base = load_dataset_config(path)
    with pytest.raises(MdfError) as info:
        build_dataset(cfg, base, tmp_path / "ds", workers=1, progress=False)
    text = str(info.value)
    assert "record_lengths.walk: the 2.000 ms record holds no pulse of the fmcw radar" in text
    assert "at least 3.079 ms" in text and "motion.duration" not in text


def test_a_recording_shorter_than_the_record_length_is_skipped_with_a_warning(
    tmp_path: Path,
) -> None:
    """As a motion source shorter than its record length is: 20.1 s is 603 frames, which 3 of
    the 12 shipped walk recordings hold (the others have 600-602); the 9 are skipped, each
    named, and the build goes on. Only when no recording is left is it an error."""
    path = tmp_path / "w.toml"
    path.write_text(f"""
[record_lengths]
walk = 20.1
[[sources]]
label = "walk"
recording = {{ kind = "radhar", file = "{RADHAR / "radhar_walk_subset.npz"}" }}
""")
    cfg, base = load_dataset_config(path)
    with pytest.warns(DatasetWarning) as caught:
        specs = plan_records(cfg, base)
    assert [s.run_config["frames"] for s in specs] == [603] * 3
    assert {s.run_config["name"] for s in specs} == {
        "___walk_20_2.txt",
        "___walk_20_4.txt",
        "__walk_20_4.txt",
    }
    texts = [str(w.message) for w in caught if w.category is DatasetWarning]
    assert len(texts) == 9
    assert "sources[0] (__20_walk_1.txt): the 600 frames" in texts[0]
    assert "603 frames" in texts[0] and texts[0].endswith("skipped")
    path.write_text(path.read_text().replace("20.1", "21.0"))
    cfg, base = load_dataset_config(path)
    with pytest.warns(DatasetWarning), pytest.raises(ConfigError, match="no records: every "):
        plan_records(cfg, base)


def test_recordings_of_one_name_in_two_files_are_two_recordings(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two copies of a RadHAR file (two sessions whose recordings the sensor named alike) give
    records of two recordings, ``<file>:<name>``, so a split holding out recordings keeps them
    apart; one file given twice stays one recording under its own name, ``~/...`` (expanded,
    as the config's paths are) included."""
    import shutil

    for name in ("a", "b"):
        (tmp_path / name).mkdir()
        shutil.copy(RADHAR / "radhar_boxing_subset.npz", tmp_path / name / "boxing.npz")

    def recordings(files: list[str]) -> set[str]:
        cfg_path = tmp_path / "real.toml"
        cfg_path.write_text(
            "".join(
                f"""
[[sources]]
label = "boxing"
record_length = 2.0
max_records = 1
[sources.recording]
kind = "radhar"
file = "{file}"
recordings = ["20_boxing_3.txt"]
"""
                for file in files
            )
        )
        cfg, base = load_dataset_config(cfg_path)
        return {s.recording for s in plan_records(cfg, base)}

    assert recordings(["a/boxing.npz", "b/boxing.npz"]) == {
        "a/boxing.npz:20_boxing_3.txt",
        "b/boxing.npz:20_boxing_3.txt",
    }
    assert recordings(["a/boxing.npz", "./a/boxing.npz"]) == {"20_boxing_3.txt"}
    # and so does the built dataset's index.csv, which experiments split on (it gave both
    # records the recording's own name, one recording to split = 'recording'), also when a
    # dataset built before is resumed
    recordings(["a/boxing.npz", "b/boxing.npz"])
    cfg, base = load_dataset_config(tmp_path / "real.toml")
    two = ["a/boxing.npz:20_boxing_3.txt", "b/boxing.npz:20_boxing_3.txt"]
    build_dataset(cfg, base, tmp_path / "ds", progress=False)
    assert list(load_dataset(tmp_path / "ds", spectrograms=False).table["recording"]) == two
    for path in (tmp_path / "ds" / RECORDS).glob("*.npz"):  # records of a build before the fix
        arrays, meta = read_record(path)
        del meta["recording_name"]
        np.savez(path, **arrays, meta=np.array(json.dumps(meta)))
    build_dataset(cfg, base, tmp_path / "ds", progress=False)
    assert list(load_dataset(tmp_path / "ds", spectrograms=False).table["recording"]) == two
    monkeypatch.setenv("HOME", str(tmp_path))
    assert recordings(["a/boxing.npz", "~/a/boxing.npz"]) == {"20_boxing_3.txt"}


@pytest.mark.parametrize("on_error", ["stop", "skip"])
def test_histograms_of_a_radar_without_point_clouds_are_refused_when_planned(
    tmp_path: Path, on_error: str
) -> None:
    """representation = 'histogram' with the paper's LFM radar (no point clouds) is refused
    before any record is simulated, naming the source, also with on_error = 'skip' (every
    record was simulated, then skipped, then the build failed)."""
    walk = EXAMPLES / "data" / "cmu" / "asf-amc" / "02_01.amc"
    cfg_path = tmp_path / "d.toml"
    cfg_path.write_text(f"""
representation = "histogram"
on_error = "{on_error}"
[[sources]]
label = "walk"
motion = {{ kind = "cmu", file = "{walk}" }}
record_length = 1.0
[base.radar]
kind = "lfm"
carrier_frequency = 15e9
bandwidth = 150e6
prf = 2400.0
""")
    cfg, base = load_dataset_config(cfg_path)
    with pytest.raises(ConfigError, match=r"sources\[0\] \(kind = 'lfm'\) gives no point clouds"):
        plan_records(cfg, base)


def _histogram_dataset(
    folder: Path, n: int, without: int | None = None, label_group: Any = None
) -> list[Any]:
    """A built dataset of ``n`` histogram records (60 frames of 17 bins) written directly in
    the dataset format; record ``without`` has no histograms; ``label_group(i)``: record i's
    label and group (default: 'a' or 'b' by turns, group 'g'). Returns the histograms."""
    import csv
    import hashlib
    import io

    rng = np.random.default_rng(3)
    (folder / RECORDS).mkdir(parents=True)
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(["id", "label", "group", "recording", *FEATURE_NAMES])
    hists = []
    for i in range(n):
        h = rng.integers(0, 5, (60, 17)).astype(np.float32)
        hists.append(h)
        arrays = {"histograms": h} if i != without else {}
        np.savez(
            folder / RECORDS / f"r{i:03d}.npz",
            spectrogram_db=h.T.copy(),
            velocity_mps=np.linspace(-2.0, 2.0, 17),
            time_s=np.arange(60) / 30.0,
            features=np.zeros(7),
            meta=np.array("{}"),
            **arrays,
        )
        label, group = ("ab"[i % 2], "g") if label_group is None else label_group(i)
        writer.writerow([f"r{i:03d}", label, group, f"rec{i // 10}", *[0.0] * 7])
    index = buf.getvalue()
    (folder / "index.csv").write_text(index)
    digest = hashlib.sha256(index.encode()).hexdigest()
    (folder / "dataset.json").write_text(json.dumps({"index_sha256": digest}))
    return hists


def _histogram_config(folder: Path) -> Any:
    from mdframework import experiment as exp

    return exp.ExperimentConfig.model_validate(
        {"input": "histogram", "dataset": {"path": str(folder)}, "selection": {"method": "none"}}
    )


def second_read_peak(read: Callable[[], T]) -> tuple[T, int]:
    """What ``read`` returns and the peak of the memory traced while it ran [bytes], the lower
    of two runs after a first one: a read puts the names of the dataset's record files in the
    interpreter's table of interned strings (they leave it when they die), which now and then
    resized then, a 3.7 MB block counted in the peak (whether it did depended on every test the
    process ran before: the 1.2 MB bounds below failed so now and then)."""
    return traced_peak(read, warm_up=read, runs=2)


def test_histogram_input_holds_one_record_at_a_time(tmp_path: Path) -> None:
    """``input = "histogram"`` reduces each record to its histogram vector as it reads it: the
    experiment's input is every record's vector, in index order, while the memory it takes
    stays below the size of all histograms together (before, every record's histograms and its
    dB map were held at once, twice that)."""
    from mdframework import experiment as exp
    from mdframework.pointcloud import histogram_vector

    hists = _histogram_dataset(tmp_path / "ds", 300)
    config = _histogram_config(tmp_path / "ds")
    (_, x, names), peak = second_read_peak(lambda: exp.classifier_inputs(config, tmp_path / "ds"))
    want = np.stack([histogram_vector(h.astype(np.float64)) for h in hists])
    np.testing.assert_array_equal(x, want)
    assert len(names) == 2 * 17
    # named by the records' velocity bins, 0.25 m/s apart from -2 to 2 m/s
    assert (names[0], names[8], names[16]) == ("mean_-2.00", "mean_+0.00", "mean_+2.00")
    assert names[17:] == [n.replace("mean_", "std_") for n in names[:17]]
    assert peak < 300 * 60 * 17 * 4  # all histograms: 1.2 MB


def test_loading_only_histograms_keeps_no_db_maps(tmp_path: Path) -> None:
    """load_dataset(spectrograms=False, histograms=True) keeps every record's histograms but
    not its dB map (as large as its histograms here, 1.2 MB for all 300 together): its memory
    stays below that of both together."""
    hists = _histogram_dataset(tmp_path / "ds", 300)
    data, peak = second_read_peak(
        lambda: load_dataset(tmp_path / "ds", spectrograms=False, histograms=True)
    )
    assert data.spectrograms is None and data.histograms is not None
    for got, want in zip(data.histograms, hists, strict=True):
        np.testing.assert_array_equal(got, want)
    assert peak < 1.5 * 300 * 60 * 17 * 4


def test_a_record_id_that_is_not_a_plain_name_is_refused_naming_its_line(
    tmp_path: Path,
) -> None:
    """A record id of index.csv names a file inside records/ only: '../r001' (a path out of
    the folder) is refused, naming index.csv and the id's line, before any file is read."""
    import hashlib

    from mdframework.errors import DataFileError

    _histogram_dataset(tmp_path / "ds", 3)
    index = tmp_path / "ds" / "index.csv"
    text = index.read_text().replace("\nr001,", "\n../r001,")
    index.write_text(text)
    digest = hashlib.sha256(text.encode()).hexdigest()
    (tmp_path / "ds" / "dataset.json").write_text(json.dumps({"index_sha256": digest}))
    with pytest.raises(DataFileError, match=r"index\.csv:3: record id '\.\./r001' is not a plain"):
        load_dataset(tmp_path / "ds", spectrograms=False, histograms=True)


def test_histogram_input_names_the_first_record_without_histograms(tmp_path: Path) -> None:
    from mdframework import experiment as exp

    _histogram_dataset(tmp_path / "ds", 30, without=12)
    with pytest.raises(MdfError, match=r"record r012 has no histograms"):
        exp.classifier_inputs(_histogram_config(tmp_path / "ds"), tmp_path / "ds")


def test_histogram_input_names_a_missing_or_damaged_record_file(tmp_path: Path) -> None:
    from mdframework import experiment as exp
    from mdframework.errors import DataFileError

    _histogram_dataset(tmp_path / "ds", 30)
    cfg = _histogram_config(tmp_path / "ds")
    damaged = tmp_path / "ds" / RECORDS / "r007.npz"
    damaged.write_bytes(damaged.read_bytes()[:-100])  # cut short: its zip directory is gone
    with pytest.raises(DataFileError, match=r"r007\.npz.*not a complete record file"):
        exp.classifier_inputs(cfg, tmp_path / "ds")
    (tmp_path / "ds" / RECORDS / "r003.npz").unlink()
    with pytest.raises(DataFileError, match=r"r003\.npz.*missing"):
        exp.classifier_inputs(cfg, tmp_path / "ds")


def test_a_class_of_one_source_only_is_named_in_the_cross_source_report(tmp_path: Path) -> None:
    """Cross-source, a class that only the training group holds ('c', 4 records of g1) is
    left out of training and named: in the report, as a warning and in summary.json (the
    score is over a and b, which both groups hold)."""
    from mdframework import experiment as exp

    def label_group(i: int) -> tuple[str, str]:
        return ("c", "g1") if i >= 40 else ("ab"[i % 2], ("g1", "g2")[(i // 2) % 2])

    _histogram_dataset(tmp_path / "ds", 44, label_group=label_group)
    cfg = exp.ExperimentConfig.model_validate(
        {
            "input": "histogram",
            "dataset": {"path": str(tmp_path / "ds")},
            "selection": {"method": "none"},
            "evaluation": {"split": "record", "repeats": 2},
            "cross_source": {"train": "g1", "test": "g2"},
        }
    )
    with pytest.warns(exp.ExperimentWarning, match=r"cross-source: class 'c' left out"):
        summary = exp.run_experiment(cfg, tmp_path / "o", progress=False)
    why = "4 training records left out of training: no test record of it"
    assert summary["cross"]["left_out"] == {"c": why}
    report = (tmp_path / "o" / "report.md").read_text()
    assert f"over the classes both sides hold): c ({why})." in report
