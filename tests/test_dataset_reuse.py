"""What a rebuilt or resumed dataset keeps: a record is reused only when everything it stores is
what the config now asks for (label, group, subject and dataset are rewritten, the arrays kept)
and only when the motion or recording it is cut from has the same contents."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import EXAMPLES
from test_dataset import assert_same
from test_dataset import records as stored

from mdframework import dataset
from mdframework.dataset import (
    MANIFEST,
    build_dataset,
    load_dataset,
    load_dataset_config,
    plan_records,
)

AMC = EXAMPLES / "data" / "cmu" / "asf-amc"
RADHAR = EXAMPLES / "data" / "radhar"


def walk_and_box(
    path: Path,
    walk_amc: Path = AMC / "02_01.amc",
    *,
    box: str = "boxing",
    extra: str = "",
) -> Path:
    """Two real CMU sources, one 1 s record each at one aspect (small FFT)."""
    path.write_text(f"""
seed = 1
[[sources]]
label = "walk"
motion = {{ kind = "cmu", file = "{walk_amc}" }}
max_records = 1
record_length = 1.0
[[sources]]
label = "{box}"
motion = {{ kind = "cmu", file = "{AMC / "13_18.amc"}", sanity = {{ glitches = "repair" }} }}
max_records = 1
{extra}
record_length = 1.0
[variations]
aspect_deg = [30.0]
[base.processing]
nfft = 256
""")
    return path


def build(cfg_path: Path, out: Path, *, force: bool = False) -> list[dict[str, Any]]:
    cfg, base = load_dataset_config(cfg_path)
    return build_dataset(cfg, base, out, workers=1, progress=False, force=force)


def assert_same_dataset(a: Path, b: Path) -> None:
    """Same record files (arrays and metadata), the same index and the same manifest."""
    assert_same(a, b)
    ma, mb = (json.loads((d / MANIFEST).read_text()) for d in (a, b))
    assert ma == mb


def test_a_relabelled_source_is_relabelled_everywhere_without_recomputing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Renaming a label, giving a group, a subject and a dataset name, then --force: index.csv,
    dataset.json, load_dataset and every record's metadata carry the new names, exactly as a
    fresh build's, and no record is simulated again (the old label stayed everywhere)."""
    out = tmp_path / "ds"
    build(walk_and_box(tmp_path / "a.toml"), out)
    before = stored(out)
    assert sorted(m["label"] for _, m in before.values()) == ["boxing", "walk"]
    renamed = walk_and_box(
        tmp_path / "b.toml",
        box="box",
        extra='group = "lab"\nsubject = "alice"\ndataset = "mine"',
    )
    real_build = dataset._build_record

    def no_simulation(spec: Any, out_dir: str) -> Any:
        raise AssertionError(f"record {spec.record_id} was simulated again")

    monkeypatch.setattr(dataset, "_build_record", no_simulation)
    rows = build(renamed, out, force=True)
    monkeypatch.setattr(dataset, "_build_record", real_build)
    assert [(r["label"], r["group"], r["subject"], r["dataset"]) for r in rows] == [
        ("walk", "cmu", "2", "asf/amc"),
        ("box", "lab", "alice", "mine"),
    ]
    data = load_dataset(out)
    assert list(data.labels) == ["walk", "box"] and list(data.groups) == ["cmu", "lab"]
    assert json.loads((out / MANIFEST).read_text())["labels"] == ["box", "walk"]
    after = stored(out)
    assert list(after) == list(before)  # the same records, their arrays untouched
    for name in after:
        for key, array in after[name][0].items():
            np.testing.assert_array_equal(array, before[name][0][key])
    fresh = tmp_path / "fresh"
    build(renamed, fresh)
    assert_same_dataset(out, fresh)
    # and back: the old names return (the records are relabelled once more)
    build(tmp_path / "a.toml", out, force=True)
    assert sorted(m["label"] for _, m in stored(out).values()) == ["boxing", "walk"]
    assert list(load_dataset(out, spectrograms=False).groups) == ["cmu", "cmu"]


def test_a_motion_file_whose_contents_changed_is_simulated_again(tmp_path: Path) -> None:
    """The same file names with other contents (a CMU walk replaced by a run, .amc and .asf):
    the rerun, in the same process, simulates the records afresh (it kept the walk's
    torso_mean of 1.11 m/s); then only the skeleton file, which the config does not name,
    changes: the records are simulated again too."""
    mc = tmp_path / "mc"
    mc.mkdir()
    shutil.copy(AMC / "02_01.amc", mc / "02_01.amc")
    shutil.copy(AMC / "02.asf", mc / "02.asf")
    cfg = walk_and_box(tmp_path / "d.toml", mc / "02_01.amc")
    out = tmp_path / "ds"
    walk = build(cfg, out)[0]
    shutil.copy(AMC / "09_06.amc", mc / "02_01.amc")  # a run, 1.2 s
    shutil.copy(AMC / "09.asf", mc / "02.asf")
    run = build(cfg, out)[0]  # the same config: resumed
    assert run["id"] != walk["id"]
    assert run["torso_mean"] > walk["torso_mean"] + 1.0  # running vs walking [m/s]
    fresh = tmp_path / "fresh"
    build(cfg, fresh)
    assert_same_dataset(out, fresh)
    # the run's motion on subject 2's skeleton: another body, another record
    shutil.copy(AMC / "02.asf", mc / "02.asf")
    other = build(cfg, out)[0]
    assert other["id"] != run["id"] and other["torso_mean"] != run["torso_mean"]
    shutil.rmtree(fresh)
    build(cfg, fresh)
    assert_same_dataset(out, fresh)


def test_a_motion_file_drawn_through_params_whose_contents_changed_is_simulated_again(
    tmp_path: Path,
) -> None:
    """A record whose motion file is drawn (randomize.params."motion.file") is cut from that
    file, so its id covers that file's contents, not only the source's own file's: the drawn
    walk replaced by a run is simulated afresh when the same config is built again."""
    mc = tmp_path / "mc"
    mc.mkdir()
    shutil.copy(AMC / "02_01.amc", mc / "02_01.amc")
    shutil.copy(AMC / "02.asf", mc / "02.asf")
    cfg = tmp_path / "d.toml"
    cfg.write_text(f"""
seed = 1
[[sources]]
label = "walk"
motion = {{ kind = "cmu", file = "{AMC / "02_01.amc"}" }}
max_records = 1
record_length = 1.0
[randomize.params]
"motion.file" = {{ choice = ["{mc / "02_01.amc"}"] }}
[base.processing]
nfft = 256
""")
    out = tmp_path / "ds"
    [walk] = build(cfg, out)
    shutil.copy(AMC / "09_06.amc", mc / "02_01.amc")  # a run, 1.2 s
    shutil.copy(AMC / "09.asf", mc / "02.asf")
    [run] = build(cfg, out)  # the same config: resumed
    assert run["id"] != walk["id"]
    assert run["torso_mean"] > walk["torso_mean"] + 1.0  # running vs walking [m/s]
    fresh = tmp_path / "fresh"
    build(cfg, fresh)
    assert_same_dataset(out, fresh)


def test_a_recording_whose_points_changed_is_recomputed(tmp_path: Path) -> None:
    """A RadHAR NPZ rewritten with the boxing recording's velocities reversed (same file
    name): its records are recomputed on the rerun, as a fresh build makes them, while a
    recording of the same file that did not change keeps its records."""
    npz = tmp_path / "radhar.npz"
    shutil.copy(RADHAR / "radhar_boxing_subset.npz", npz)
    with np.load(npz) as data:
        arrays = {k: data[k] for k in data.files}
    names = [str(f) for f in arrays["files"]]
    changed, kept = names[0], names[1]
    cfg = tmp_path / "real.toml"
    cfg.write_text(f"""
[[sources]]
label = "boxing"
record_length = 2.0
max_records = 1
[sources.recording]
kind = "radhar"
file = "{npz}"
recordings = ["{changed}", "{kept}"]
""")
    out = tmp_path / "ds"
    first = build(cfg, out)
    own = arrays["file_index"] == 0
    arrays["velocity"] = np.where(own, -arrays["velocity"], arrays["velocity"])
    np.savez(npz, **arrays)
    second = build(cfg, out)
    assert second[0]["id"] != first[0]["id"] and second[1]["id"] == first[1]["id"]
    assert second[0]["upper_max"] == pytest.approx(-first[0]["lower_min"])
    fresh = tmp_path / "fresh"
    build(cfg, fresh)
    assert_same_dataset(out, fresh)


def test_record_ids_cover_the_motions_contents_not_its_file_times(tmp_path: Path) -> None:
    """Planning twice from an untouched file, or after only its modification time changed,
    gives the same ids; another skeleton file beside the same .amc gives other ids."""
    mc = tmp_path / "mc"
    mc.mkdir()
    shutil.copy(AMC / "02_01.amc", mc / "02_01.amc")
    shutil.copy(AMC / "02.asf", mc / "02.asf")
    cfg_path = walk_and_box(tmp_path / "d.toml", mc / "02_01.amc")

    def ids() -> list[str]:
        dataset._forget_loaded()
        return [s.record_id for s in plan_records(*load_dataset_config(cfg_path))]

    first = ids()
    (mc / "02.asf").touch()
    assert ids() == first
    shutil.copy(AMC / "09.asf", mc / "02.asf")
    other = ids()
    assert other[0] != first[0] and other[1] == first[1]  # the boxing source is untouched


def _marker(out: Path) -> dict[str, Any]:
    return dict(json.loads((out / ".mdf-dataset.json").read_text()))


class _Killed(KeyboardInterrupt):
    """A build stopped at a chosen moment (as Ctrl-C or a kill would stop it there)."""


@pytest.mark.parametrize("moment", ["records", "before index", "after index", "cleanup"])
def test_a_stopped_rebuild_leaves_a_folder_that_either_config_resumes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, moment: str
) -> None:
    """A --force rebuild with another config, stopped while computing its records, just before
    or just after writing its index, or while removing the old records: the config in the
    folder's dataset.json is always one its marker lists as the index's, and both the old
    config and the new one are then accepted without --force, each finishing the dataset a
    fresh build makes (the old config was refused as `different` after a stop before the
    index)."""
    old_cfg = walk_and_box(tmp_path / "old.toml")
    new_cfg = walk_and_box(tmp_path / "new.toml")
    new_cfg.write_text(new_cfg.read_text().replace("aspect_deg = [30.0]", "aspect_deg = [0.0]"))
    fresh_old, fresh_new = tmp_path / "fresh_old", tmp_path / "fresh_new"
    build(old_cfg, fresh_old)
    build(new_cfg, fresh_new)
    out = tmp_path / "ds"
    shutil.copytree(fresh_old, out)
    calls = {"n": 0}

    def kill_on(n: int) -> None:
        calls["n"] += 1
        if calls["n"] == n:
            raise _Killed

    with monkeypatch.context() as m:
        if moment == "records":
            real_records = dataset.build_records
            m.setattr(dataset, "build_records", lambda *a: kill_on(2) or real_records(*a))
        elif moment == "before index":
            m.setattr(dataset, "_write_index", lambda *a: kill_on(1))
        elif moment == "after index":
            real_index = dataset._write_index
            m.setattr(dataset, "_write_index", lambda *a: real_index(*a) or kill_on(1))
        else:
            pattern = dataset._RECORD_NAME

            class Stop:
                def fullmatch(self, name: str) -> Any:
                    kill_on(2)
                    return pattern.fullmatch(name)

            m.setattr(dataset, "_RECORD_NAME", Stop())
        with pytest.raises(_Killed):
            build(new_cfg, out, force=True)
    marker = _marker(out)
    assert marker["complete"] is False
    manifest = json.loads((out / MANIFEST).read_text())["config"]
    for option in dataset.BUILD_OPTIONS:
        manifest.pop(option, None)
    assert manifest in marker["indexed"]
    assert len((out / "index.csv").read_text().splitlines()) == 3  # header and 2 records
    again = tmp_path / "again"
    shutil.copytree(out, again)
    build(old_cfg, out)  # no --force: the folder's complete dataset is of this config
    assert_same_dataset(out, fresh_old)
    assert _marker(out)["complete"] is True
    build(new_cfg, again)  # no --force: the build under way is of this config
    assert_same_dataset(again, fresh_new)
    # a third config is still refused
    third = tmp_path / "third.toml"
    third.write_text(new_cfg.read_text().replace("aspect_deg = [0.0]", "aspect_deg = [60.0]"))
    with pytest.raises(dataset.OutputError, match="different config"):
        build(third, again)


def two_subjects(path: Path, subjects: tuple[str, str], data_name: str) -> Path:
    """Two real RadHAR boxing recordings as two sources, each with its subject and a dataset
    name, one 2 s record each."""
    sources = "".join(
        f"""
[[sources]]
label = "boxing"
subject = "{subject}"
dataset = "{data_name}"
record_length = 2.0
max_records = 1
[sources.recording]
kind = "radhar"
file = "{RADHAR / "radhar_boxing_subset.npz"}"
recordings = ["{name}"]
"""
        for subject, name in zip(subjects, ("20_boxing_3.txt", "boxing_20_2.txt"), strict=True)
    )
    path.write_text(sources)
    return path


def test_a_recording_source_records_its_subject_and_dataset(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A real radar's recordings carry their source's `subject` and `dataset` into every
    record, index.csv and load_dataset (they were left empty and 'radhar', so a
    leave-subjects-out experiment had one subject); the recording column names the recording.
    Renaming them and rebuilding with --force relabels the records without recomputing them,
    exactly as a fresh build would."""
    from mdframework.experiment import group_splits

    out = tmp_path / "ds"
    rows = build(two_subjects(tmp_path / "a.toml", ("p1", "p2"), "radhar-lab"), out)
    assert [(r["subject"], r["dataset"], r["recording"], r["source"]) for r in rows] == [
        ("p1", "radhar-lab", "20_boxing_3.txt", "radhar"),
        ("p2", "radhar-lab", "boxing_20_2.txt", "radhar"),
    ]
    data = load_dataset(out, spectrograms=False)
    assert list(data.table["subject"]) == ["p1", "p2"]
    assert [te.tolist() for _, te in group_splits(data.table["subject"], None)] == [[0], [1]]
    for _, meta in stored(out).values():
        assert meta["subject"] in ("p1", "p2") and meta["dataset"] == "radhar-lab"
    renamed = two_subjects(tmp_path / "b.toml", ("alice", "bob"), "mine")

    def no_computing(spec: Any, out_dir: str) -> Any:
        raise AssertionError(f"record {spec.record_id} was computed again")

    real_build = dataset._build_record
    monkeypatch.setattr(dataset, "_build_record", no_computing)
    rows = build(renamed, out, force=True)
    monkeypatch.setattr(dataset, "_build_record", real_build)
    assert [(r["subject"], r["dataset"]) for r in rows] == [("alice", "mine"), ("bob", "mine")]
    fresh = tmp_path / "fresh"
    build(renamed, fresh)
    assert_same_dataset(out, fresh)
