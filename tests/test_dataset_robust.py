"""Robust dataset builds and experiments by record metadata, on real recordings.

Named hard case: CMU 02_01, a 2.85 s walk straight toward a radar 3.2 m ahead. Placing the
recording's start at the person's position (the default), the late records reach the radar
(closer than scene.min_range) and fail; placing each record's start there, none does.
"""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import numpy as np
import pytest
from conftest import EXAMPLES

import mdframework.experiment as exp
from mdframework.dataset import (
    SKIPPED,
    DatasetWarning,
    build_dataset,
    load_dataset,
    load_dataset_config,
    plan_records,
)
from mdframework.errors import MdfError

WALK = EXAMPLES / "data" / "cmu" / "asf-amc" / "02_01.amc"
MSR = EXAMPLES / "data" / "kinect" / "msr-action3d"


def walk_config(path: Path, extra: str = "") -> Path:
    path.write_text(f"""
seed = 1
{extra}
[[sources]]
label = "walk"
motion = {{ kind = "cmu", file = "{WALK}" }}
record_length = 1.0
hop = 0.5
[base.scene]
radar_position = [3.2, 0.0, 1.2]
person = {{ position = [0.0, 0.0], aspect_deg = 0.0 }}
[base.processing]
nfft = 256
""")
    return path


def test_a_failing_record_names_record_file_window_and_cause(tmp_path: Path) -> None:
    cfg, base = load_dataset_config(walk_config(tmp_path / "d.toml"))
    with pytest.raises(MdfError) as err:
        build_dataset(cfg, base, tmp_path / "ds", workers=1, progress=False)
    msg = str(err.value)
    assert msg.startswith("record 0000")
    assert "(walk; source file " in msg and "02_01.amc, window " in msg
    assert "comes within" in msg and "scene.min_range" in msg


def test_on_error_skip_lists_the_skipped_records_and_place_record_needs_none(
    tmp_path: Path,
) -> None:
    cfg, base = load_dataset_config(walk_config(tmp_path / "d.toml", 'on_error = "skip"'))
    with pytest.warns(DatasetWarning, match=r"record \S+ \(\S*02_01\.amc, window .* skipped: "):
        rows = build_dataset(cfg, base, tmp_path / "ds", workers=1, progress=False)
    manifest = json.loads((tmp_path / "ds" / "dataset.json").read_text())
    with (tmp_path / "ds" / SKIPPED).open() as fh:
        skipped = list(csv.DictReader(fh))
    n_plan = len(plan_records(cfg, base))
    assert manifest["n_skipped"] == len(skipped) > 0 and len(rows) + len(skipped) == n_plan
    assert manifest["n_records"] == len(rows) > 0
    # the early windows survive, the late ones (the walker at the radar) are the skipped ones
    assert max(float(r["start_s"]) for r in rows) < min(float(s["start_s"]) for s in skipped)
    assert all("comes within" in s["skipped"] for s in skipped)
    assert len(load_dataset(tmp_path / "ds", spectrograms=False).labels) == len(rows)

    placed, base = load_dataset_config(walk_config(tmp_path / "p.toml", 'place = "record"'))
    rows = build_dataset(placed, base, tmp_path / "placed", workers=1, progress=False)
    assert len(rows) == n_plan and not (tmp_path / "placed" / SKIPPED).exists()
    # every record now starts where the config puts the person: the gate (hip range to the
    # radar) at each record's first pulse is the same
    specs = plan_records(placed, base)
    firsts = [s.run_config["scene"]["person"]["position"][0] for s in specs]
    assert firsts[0] == pytest.approx(0.0, abs=1e-9) and firsts[-1] < -1.5
    # placing turns the aspect into a fixed heading; the table still says which aspect was
    # asked for (it used to be blank)
    assert [r["aspect_deg"] for r in rows] == [0.0] * len(rows)
    assert all("aspect_deg" not in s.run_config["scene"]["person"] for s in specs)


def test_records_carry_subject_recording_source_and_dataset(tmp_path: Path) -> None:
    MSR_JOG = MSR / "a16_s02_e01_skeleton3D.txt"
    p = tmp_path / "m.toml"
    p.write_text(f"""
[[sources]]
label = "jog"
motion = {{ kind = "kinect", format = "msr-action3d", file = "{MSR_JOG}" }}
max_records = 1
[[sources]]
label = "walk"
motion = {{ kind = "cmu", file = "{WALK}" }}
max_records = 1
subject = "two"
dataset = "cmu-mocap"
[record_lengths]
jog = 1.0
walk = 1.0
[base.processing]
nfft = 256
[base.scene]
radar_position = [8.0, 0.0, 1.2]
""")
    cfg, base = load_dataset_config(p)
    build_dataset(cfg, base, tmp_path / "ds", workers=1, progress=False)
    t = load_dataset(tmp_path / "ds", spectrograms=False).table
    assert list(t["subject"]) == ["s02", "two"]
    assert list(t["recording"]) == ["a16_s02_e01_skeleton3D.txt", "02_01.amc"]
    assert list(t["source"]) == ["kinect", "cmu"]
    assert list(t["dataset"]) == ["msr-action3d", "cmu-mocap"]


def test_group_splits_hold_out_whole_subjects() -> None:
    subjects = np.repeat(["s1", "s2", "s3", "s4"], 5)
    loo = exp.group_splits(subjects, None)
    assert len(loo) == 4
    for train, test in loo:
        assert len(set(subjects[test])) == 1 and not set(subjects[train]) & set(subjects[test])
    two = exp.group_splits(subjects, 2)
    assert len(two) == 2 and all(len(set(subjects[te])) == 2 for _, te in two)
    with pytest.raises(MdfError, match="needs two or more groups"):
        exp.group_splits(np.array(["s1"] * 3), None)


def msr_dataset(tmp_path: Path) -> Path:
    sources = []
    for action, label in (("a16", "jog"), ("a12", "boxing")):
        for subject in ("s01", "s02", "s03"):
            f = MSR / f"{action}_{subject}_e01_skeleton3D.txt"
            sources.append(
                f'[[sources]]\nlabel = "{label}"\nhop = 0.5\n'
                f'motion = {{ kind = "kinect", format = "msr-action3d", file = "{f}" }}\n'
            )
    p = tmp_path / "msr.toml"
    p.write_text(
        "\n".join(sources)
        + """
[record_lengths]
jog = 1.0
boxing = 1.0
[base.processing]
nfft = 256
[base.scene]
radar_position = [3.0, 0.0, 1.0]
"""
    )
    return p


def test_leave_subjects_out_and_train_test_by_metadata(tmp_path: Path) -> None:
    e = tmp_path / "e.toml"
    e.write_text(f"""
seed = 0
[dataset]
config = "{msr_dataset(tmp_path)}"
[selection]
method = "none"
optimistic = false
[evaluation]
split = "groups"
by = "subject"
[train_test]
train = {{ subject = ["s01", "s02"] }}
test = {{ subject = "s03" }}
""")
    cfg = exp.load_experiment_config(e)
    summary = exp.run_experiment(cfg, tmp_path / "out", progress=False)
    within = summary["within"]["kinect"]
    assert within["n_records"] == summary["n_records"]
    # three subjects: three folds, each tests one unseen subject; jogging and boxing differ
    assert len(within["subsets"]) == 3
    assert within["balanced_accuracy_mean"] > 0.6  # chance: 0.5 (measured 0.68)
    tt = summary["train_test"]
    data = load_dataset(tmp_path / "out" / "dataset", spectrograms=False)
    s3 = data.table["subject"] == "s03"
    assert sum(tt["test_counts"].values()) == int(s3.sum())
    assert sum(tt["train_counts"].values()) == int((~s3).sum())
    assert tt["balanced_accuracy"] > 0.7
    assert (tmp_path / "out" / "train_test_confusion.csv").exists()


def test_train_test_selection_errors(tmp_path: Path) -> None:
    table = {"subject": np.array(["s1", "s2"]), "source": np.array(["cmu", "kinect"])}
    with pytest.raises(MdfError, match="no column 'person'"):
        exp.select(table, {"person": "x"}, "train_test.train")
    assert list(exp.select(table, {"subject": ["s1", "s2"], "source": "cmu"}, "t")) == [
        True,
        False,
    ]


def test_an_empty_variation_list_is_refused(tmp_path: Path) -> None:
    """`aspect_deg = []` would silently mean "no variation" (the base scene's aspect): refused
    naming the field, like any value a build cannot use."""
    cfg = walk_config(tmp_path / "d.toml", "[variations]\naspect_deg = []\n")
    with pytest.raises(MdfError, match=r"variations\.aspect_deg: an empty list"):
        load_dataset_config(cfg)
    load_dataset_config(walk_config(tmp_path / "ok.toml", "[variations]\naspect_deg = [0, 90]\n"))


def test_place_record_with_a_motion_conditioning_refuses_is_one_clear_error(
    tmp_path: Path,
) -> None:
    """A real Kinect table whose left hand is lost for about 0.7 s, with conditioning told to stop
    on gaps over 0.2 s: placing each record (``place = "record"``) conditions the recording
    while planning, and that stop is one clear error, not an internal ValueError."""
    example = EXAMPLES / "table_utkinect_walk.toml"
    source = EXAMPLES / "data" / "kinect" / "utkinect" / "joints_s01_e01.txt"
    rows = source.read_text().splitlines()
    lost = []
    for row in rows:
        cells = row.split()
        if 300 <= int(cells[0]) < 340:  # frames at 60 per second
            cells[1 + 3 * 7 : 1 + 3 * 8] = ["0", "0", "0"]  # HandLeft, the 8th joint
        lost.append(" ".join(cells))
    table = tmp_path / "joints.txt"
    table.write_text("\n".join(lost) + "\n")
    motion = example.read_text().split("[motion]")[1].split("[scatterers]")[0]
    motion = motion.replace('"data/kinect/utkinect/joints_s01_e01.txt"', f'"{table}"')
    motion = motion.replace('activity = "walk"\n', "")
    config = tmp_path / "d.toml"
    config.write_text(f"""
seed = 1
place = "record"
[[sources]]
label = "walk"
record_length = 1.0
[sources.motion]
{motion}
[base.scene]
radar_position = [0.0, 0.0, 0.0]
person = {{ position = [2.3, 0.0], aspect_deg = 0.0 }}
[base.conditioning]
enabled = true
max_gap_s = 0.2
long_gaps = "error"
""")
    cfg, base = load_dataset_config(config)
    with pytest.raises(MdfError, match=r"conditioning: joint 'l_hand' is untracked for 0\.73"):
        plan_records(cfg, base)


def test_a_failing_record_is_named_once(tmp_path: Path) -> None:
    """The cause of a failing record follows its name, file and window, without the record's
    name again (the walk comes within scene.min_range of the radar)."""
    path = walk_config(tmp_path / "d.toml")
    cfg, base = load_dataset_config(path)
    with pytest.raises(MdfError) as err:
        build_dataset(cfg, base, tmp_path / "ds", workers=1, progress=False)
    msg = str(err.value)
    record = msg.split()[1]
    assert msg.startswith(f"record {record} (walk; source file ")
    assert msg.count(record) == 1, msg
    assert re.search(r"window [\d.]+-[\d.]+ s\): ", msg) and "comes within" in msg
