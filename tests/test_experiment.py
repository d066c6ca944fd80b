"""Experiments: configs parse, selection never sees the test split, reports are consistent."""

from __future__ import annotations

import csv
import hashlib
import json
import os
from contextlib import nullcontext
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import EXAMPLES
from sklearn.metrics import balanced_accuracy_score
from sklearn.model_selection import StratifiedShuffleSplit

from mdframework import experiment as exp
from mdframework.dataset import load_dataset_config
from mdframework.errors import ConfigError, MdfError


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("experiment_*.toml")), ids=lambda p: p.stem)
def test_experiment_examples_parse(path: Path) -> None:
    cfg = exp.load_experiment_config(path)
    if cfg.dataset.config is not None:
        load_dataset_config(cfg.dataset.config)


@pytest.mark.parametrize(
    "path", sorted((EXAMPLES / "datasets").glob("*.toml")), ids=lambda p: p.stem
)
def test_dataset_examples_parse(path: Path) -> None:
    load_dataset_config(path)


def test_bad_experiment_config(tmp_path: Path, only_our_plugins: None) -> None:
    p = tmp_path / "e.toml"
    p.write_text('[dataset]\npath = "x"\n[classifier]\nkind = "knn"\nk = 0\n')
    cfg = exp.load_experiment_config(p)
    with pytest.raises(ConfigError, match=r"e\.toml: classifier\.k: must be at least 1 \(got 0\)"):
        exp.classifier_factory(cfg.classifier, str(p))
    p.write_text('[dataset]\npath = "x"\n[selection]\nsizes = [9]\n')
    with pytest.raises(ConfigError, match=r"selection\.sizes\.0: must be at most 7 \(got 9\)"):
        exp.load_experiment_config(p)
    p.write_text('[dataset]\npath = "x"\nconfig = "y"\n')
    with pytest.raises(ConfigError, match=r"exactly one of dataset\.config and dataset\.path"):
        exp.load_experiment_config(p)
    # the same group on both sides would test on the training records themselves
    p.write_text('[dataset]\npath = "x"\n[cross_source]\ntrain = "cmu"\ntest = "cmu"\n')
    with pytest.raises(
        ConfigError, match=r"e\.toml: cross_source: train and test are the same group 'cmu';"
    ):
        exp.load_experiment_config(p)
    # a [classifier] without kind is not a plugin named 'None'
    with pytest.raises(
        ConfigError, match=r"^t: classifier\.kind: required \(installed: knn, sklearn"
    ):
        exp.classifier_factory({"k": 3}, "t")


def _toy(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    y = np.repeat(["a", "b", "c"], 20)
    x = rng.normal(size=(60, 7))
    x[:, 3] += np.repeat([0.0, 5.0, 10.0], 20)
    return x, y


def test_wrapper_in_the_experiment_gets_only_the_training_split(
    rng: np.random.Generator, monkeypatch: pytest.MonkeyPatch
) -> None:
    x, y = _toy(rng)
    seen: list[np.ndarray] = []
    real = exp.wrapper_select

    def spy(features: np.ndarray, labels: np.ndarray, *a: Any, **k: Any) -> Any:
        seen.append(features.copy())
        return real(features, labels, *a, **k)

    monkeypatch.setattr(exp, "wrapper_select", spy)
    cfg = exp.ExperimentConfig.model_validate(
        {
            "dataset": {"path": "unused"},
            "evaluation": {"repeats": 3},
            "selection": {"sizes": [1], "folds": 3, "optimistic": False},
        }
    )
    res = exp.within_source(cfg, exp.classifier_factory({"kind": "knn"}, "t"), x, y)
    splits = StratifiedShuffleSplit(3, test_size=0.4, random_state=0).split(x, y)
    assert len(seen) == 3
    for got, (train, test) in zip(seen, splits, strict=True):
        assert np.array_equal(got, x[train])
        rows = {r.tobytes() for r in got}
        assert not any(r.tobytes() in rows for r in x[test])
    assert all(s == ["lower_min"] for s in res["subsets"])  # feature 3 separates the classes
    assert np.allclose(res["confusion_mean"].sum(axis=1), 1.0)


@pytest.mark.parametrize("inner", ["evaluation", "record"])
def test_wrapper_folds_hold_out_what_the_evaluation_holds_out(
    rng: np.random.Generator, monkeypatch: pytest.MonkeyPatch, inner: str
) -> None:
    """Leave-subjects-out with ``selection.inner_split = 'evaluation'``: the wrapper's folds
    hold out whole subjects of the training records too; 'record' (the default) folds records."""
    x, y = _toy(rng)
    subjects = np.array([f"s{i % 4}" for i in range(60)])
    got: list[Any] = []
    real = exp.wrapper_select

    def spy(features: np.ndarray, labels: np.ndarray, *a: Any, **k: Any) -> Any:
        got.append((features.copy(), k["groups"]))
        return real(features, labels, *a, **k)

    monkeypatch.setattr(exp, "wrapper_select", spy)
    cfg = exp.ExperimentConfig.model_validate(
        {
            "dataset": {"path": "unused"},
            "evaluation": {"split": "groups", "by": "subject"},
            "selection": {"sizes": [1], "folds": 3, "optimistic": False, "inner_split": inner},
        }
    )
    exp.within_source(cfg, exp.classifier_factory({"kind": "knn"}, "t"), x, y, subjects)
    assert len(got) == 4  # one fold per subject
    for features, groups in got:
        if inner == "record":
            assert groups is None
        else:
            train = [int(np.flatnonzero((x == row).all(axis=1))[0]) for row in features]
            assert np.array_equal(groups, subjects[train])
            assert len(set(groups.tolist())) == 3


def test_grouped_wrapper_needs_two_subjects_of_each_class(rng: np.random.Generator) -> None:
    """A class the evaluation scores but with one subject among a split's training records
    (two subjects, one held out) cannot be both trained and tested by folds holding out whole
    subjects: one line naming the class and the option."""
    x, y = _toy(rng)
    subjects = np.array([f"s{i % 4}" for i in range(60)])
    subjects[y == "c"] = np.where(np.arange(20) < 10, "s8", "s9")  # class c: two subjects
    cfg = exp.ExperimentConfig.model_validate(
        {
            "dataset": {"path": "unused"},
            "evaluation": {"split": "groups", "by": "subject"},
            "selection": {"sizes": [1], "optimistic": False, "inner_split": "evaluation"},
        }
    )
    with pytest.raises(ConfigError, match=r"inner_split = 'evaluation': class 'c' has one subj"):
        exp.within_source(cfg, exp.classifier_factory({"kind": "knn"}, "t"), x, y, subjects)


@pytest.mark.parametrize("split", ["groups", "recording"])
def test_grouped_wrapper_leaves_out_a_class_the_evaluation_leaves_out(
    rng: np.random.Generator, split: str
) -> None:
    """A class of one subject (leave-subjects-out) or of one recording (split = 'recording')
    is not evaluated, and the wrapper's folds, holding out what the evaluation holds out, leave
    it out of their scores as well, instead of stopping the experiment: the other classes are
    evaluated as with inner_split = 'record'."""
    x, y = _toy(rng)
    units = np.array([f"s{i % 4}" for i in range(60)])
    units[y == "c"] = "s9"  # class c: one subject or recording only
    results = {}
    for inner in ("evaluation", "record"):
        cfg = exp.ExperimentConfig.model_validate(
            {
                "dataset": {"path": "unused"},
                "evaluation": {"split": split, "by": "subject", "repeats": 3},
                "selection": {"sizes": [1], "optimistic": False, "inner_split": inner},
            }
        )
        factory = exp.classifier_factory({"kind": "knn"}, "t")
        results[inner] = exp.within_source(cfg, factory, x, y, units, exp.FEATURE_NAMES)
    for res in results.values():
        assert list(res["not_evaluated"]) == ["c"]
        assert res["balanced_accuracy_mean"] > 0.9  # a and b: feature 3 tells them apart
    best = [exp.FEATURE_NAMES[3]]  # the one feature that separates a and b
    assert all(s == best for s in results["evaluation"]["subsets"])


def test_experiment_on_shipped_cmu_data(tmp_path: Path) -> None:
    cfg = exp.load_experiment_config(EXAMPLES / "experiment_cmu.toml")
    cfg = cfg.model_copy(
        update={
            "evaluation": cfg.evaluation.model_copy(update={"repeats": 2}),
            "selection": cfg.selection.model_copy(update={"folds": 3}),
        }
    )
    out = tmp_path / "exp"
    summary = exp.run_experiment(cfg, out, progress=False)
    cm = np.array(summary["within"]["cmu"]["confusion_mean"])
    assert cm.shape == (4, 4)
    assert np.allclose(cm.sum(axis=1), 1.0)
    with (out / "within_cmu_confusion.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert [r["true"] for r in rows] == ["boxing", "jump", "run", "walk"]
    for r in rows:
        assert sum(float(r[c]) for c in ["boxing", "jump", "run", "walk"]) == pytest.approx(1.0)
    # walking and running are told apart from boxing far better than chance
    assert summary["within"]["cmu"]["balanced_accuracy_mean"] > 0.6
    stats = (out / "feature_stats.md").read_text()
    assert "torso_mean" in stats and "walk (cmu" in stats
    for name in ("report.md", "within_cmu_confusion.png", "scatter_torso_mean_upper_max.png"):
        assert (out / name).stat().st_size > 100
    assert json.loads((out / "summary.json").read_text())["n_records"] == 280
    # the report says which features the selection chose in each split
    subsets = summary["within"]["cmu"]["subsets"]
    report = (out / "report.md").read_text()
    assert "\n".join(exp.selected_features_markdown(subsets, "wrapper")) in report
    assert "Selected features (times chosen in 2 splits): " in report


def test_a_classifier_config_error_fails_the_experiment(tmp_path: Path) -> None:
    """An error of the config (k above the records a fold trains on) ends the experiment; it
    is not reported as one source that could not be evaluated, with an exit code of success."""
    cfg = exp.load_experiment_config(EXAMPLES / "experiment_cmu.toml")
    cfg = cfg.model_copy(update={"classifier": {"kind": "knn", "k": 500}})
    with pytest.raises(ConfigError, match=r"classifier\.k: 500 neighbours"):
        exp.run_experiment(cfg, tmp_path / "exp", progress=False)


def test_selected_features_are_counted_over_splits() -> None:
    subsets = [["a", "b"], ["a", "c"], ["a", "b"]]
    line = exp.selected_features_markdown(subsets, "wrapper")[0]
    assert line == (
        "Selected features (times chosen in 3 splits): a 3, b 2, c 1; most frequent subset: "
        "a, b (2 of 3)."
    )
    assert exp.selected_features_markdown([], "none")[0] == "Inputs: all (no feature selection)."


def test_recording_split_holds_out_whole_recordings(rng: np.random.Generator) -> None:
    labels = np.repeat(["a", "b"], 30)
    recordings = np.array([f"{lab}{i // 10}" for lab, i in zip(labels, range(60), strict=True)])
    splits = exp.recording_splits(labels, recordings, repeats=5, test_fraction=0.4, seed=3)
    for train, test in splits:
        assert not set(recordings[train]) & set(recordings[test])
        assert set(labels[test]) == {"a", "b"} and set(labels[train]) == {"a", "b"}
        assert len(np.concatenate([train, test])) == 60
    x = rng.normal(size=(60, 7))
    x[:, 0] += np.repeat([0.0, 6.0], 30)
    cfg = exp.ExperimentConfig.model_validate(
        {
            "dataset": {"path": "unused"},
            "evaluation": {"repeats": 3, "split": "recording"},
            "selection": {"method": "none", "optimistic": False},
        }
    )
    res = exp.within_source(
        cfg, exp.classifier_factory({"kind": "knn"}, "t"), x, labels, recordings
    )
    assert np.allclose(res["confusion_mean"].sum(axis=1), 1.0)
    # 40 % of 3 recordings is 1.2: one is held out (33 %), and the report says so
    assert res["recordings_held_out"] == {"a": [1, 3], "b": [1, 3]}
    assert all(len(set(recordings[te])) == 2 for _, te in splits)
    assert (
        exp._held_out_markdown(res)[0] == "Recordings held out in every split: a 1 of 3, b 1 of 3."
    )
    assert [exp.recordings_held_out(n, 0.4) for n in (2, 3, 5, 12)] == [1, 1, 2, 5]
    with pytest.raises(exp.MdfError, match="class 'a' has only one recording"):
        exp.recording_splits(labels, np.where(labels == "a", "one", recordings), 1, 0.4, 0)


def test_two_recordings_of_one_name_are_held_out_as_two(tmp_path: Path) -> None:
    """alice/walk.bvh and bob/walk.bvh are two recordings: split = 'recording' holds out one
    of them (the class used to count one recording and was not evaluated)."""
    import shutil

    from mdframework.dataset import build_dataset

    bvh = EXAMPLES / "data" / "cmu" / "bvh"
    for person, walk, box in (("alice", "16_21", "13_41"), ("bob", "09_03", "80_10")):
        (tmp_path / person).mkdir()
        shutil.copyfile(bvh / f"{walk}.bvh", tmp_path / person / "walk.bvh")
        shutil.copyfile(bvh / f"{box}.bvh", tmp_path / person / "box.bvh")
    sources = "".join(
        f'[[sources]]\nlabel = "{label}"\nmax_records = 3\nhop = 0.05\n'
        f'motion = {{ kind = "cmu", file = "{person}/{name}.bvh" }}\n'
        for person in ("alice", "bob")
        for label, name in (("walk", "walk"), ("boxing", "box"))
    )
    (tmp_path / "d.toml").write_text(
        sources + "[record_lengths]\nwalk = 0.5\nboxing = 0.5\n[base.processing]\nnfft = 256\n"
    )
    build_dataset(*load_dataset_config(tmp_path / "d.toml"), tmp_path / "ds", progress=False)
    with (tmp_path / "ds" / "index.csv").open() as fh:
        recordings = sorted({r["recording"] for r in csv.DictReader(fh)})
    assert recordings == ["alice/box.bvh", "alice/walk.bvh", "bob/box.bvh", "bob/walk.bvh"]
    e = _experiment(
        tmp_path / "ds",
        tmp_path,
        '[selection]\nmethod = "none"\n[classifier]\nkind = "knn"\nk = 1\n'
        '[evaluation]\nsplit = "recording"\nrepeats = 2\n',
    )
    summary = exp.run_experiment(exp.load_experiment_config(e), tmp_path / "o", progress=False)
    within = summary["within"]["cmu"]
    assert within["not_evaluated"] == {}
    assert within["splits_scored"] == {"boxing": 2, "walk": 2}


def test_one_file_given_in_two_ways_is_one_recording(tmp_path: Path) -> None:
    """Beside bob/walk.bvh, alice/walk.bvh cut into two spans by two sources, given once as
    ./alice/walk.bvh, is still one recording (it was two, so split = 'recording' could train
    on one span of the file and test on the other)."""
    import shutil
    from collections import Counter

    from mdframework.dataset import plan_records

    bvh = EXAMPLES / "data" / "cmu" / "bvh"
    for person, walk in (("alice", "16_21"), ("bob", "09_03")):
        (tmp_path / person).mkdir()
        shutil.copyfile(bvh / f"{walk}.bvh", tmp_path / person / "walk.bvh")
    spans = (("alice/walk.bvh", "duration = 1.0"), ("./alice/walk.bvh", "start = 1.0"))
    sources = "".join(
        f'[[sources]]\nlabel = "walk"\nmax_records = 2\n'
        f'motion = {{ kind = "cmu", file = "{file}", {span} }}\n'
        for file, span in (*spans, ("bob/walk.bvh", "start = 0.0"))
    )
    (tmp_path / "d.toml").write_text(sources + "[record_lengths]\nwalk = 0.5\n")
    specs = plan_records(*load_dataset_config(tmp_path / "d.toml"))
    assert Counter(s.recording for s in specs) == {"alice/walk.bvh": 4, "bob/walk.bvh": 2}


# --------------------------------------------------------------------------- evaluation protocols

MSR = EXAMPLES / "data" / "kinect" / "msr-action3d"


@pytest.fixture(scope="module")
def kinect_dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Built once: MSR jogging and side-boxing of subjects s01-s03 (records of 1 s every
    0.5 s), and 2 records of forward punches of s01 only (a small class of one subject)."""
    from mdframework.dataset import build_dataset

    root = tmp_path_factory.mktemp("kinect")
    sources = []
    for action, label, subjects in (
        ("a16", "jog", ("s01", "s02", "s03")),
        ("a12", "boxing", ("s01", "s02", "s03")),
        ("a05", "punch", ("s01",)),
    ):
        for subject in subjects:
            f = MSR / f"{action}_{subject}_e01_skeleton3D.txt"
            cap = "max_records = 2\n" if label == "punch" else ""
            sources.append(
                f'[[sources]]\nlabel = "{label}"\nhop = 0.5\n{cap}'
                f'motion = {{ kind = "kinect", format = "msr-action3d", file = "{f}" }}\n'
            )
    p = root / "msr.toml"
    p.write_text(
        "\n".join(sources)
        + "[record_lengths]\njog = 1.0\nboxing = 1.0\npunch = 1.0\n"
        + "[base.processing]\nnfft = 256\n[base.scene]\nradar_position = [3.0, 0.0, 1.0]\n"
    )
    build_dataset(*load_dataset_config(p), root / "dataset", progress=False)
    return root / "dataset"


def _experiment(dataset: Path, tmp_path: Path, body: str) -> Path:
    p = tmp_path / "e.toml"
    p.write_text(f'seed = 0\n[dataset]\npath = "{dataset}"\n{body}')
    return p


def _groups_and_train_test(dataset: Path, tmp_path: Path) -> dict[str, Any]:
    """Leave-subjects-out on ``dataset`` (kinect_dataset's) and a train/test of subjects s01,
    s02 -> s03, all features, reported into ``tmp_path / "o"``; returns the summary."""
    body = (
        '[selection]\nmethod = "none"\n[evaluation]\nsplit = "groups"\n'
        '[train_test]\ntrain = { subject = ["s01", "s02"] }\ntest = { subject = "s03" }\n'
    )
    e = _experiment(dataset, tmp_path, body)
    with pytest.warns(exp.ExperimentWarning):  # punch: one subject
        return exp.run_experiment(exp.load_experiment_config(e), tmp_path / "o", progress=False)


def _one_class_per_subject() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One feature; class a: subjects s1-s3 at 0 (each recognised when held out); class b: s4
    at 10 and s5 at 3. Held out, s4 is still nearest to s5's b records (recall 1); held out,
    s5 is nearest to a (recall 0). Per-class recall: a 1, b 0.5, so the mean per-class recall
    is 0.75; the mean of the five folds' balanced accuracies weights a by its three subjects:
    (3 * 1 + 1 + 0) / 5 = 0.8."""
    subjects = np.repeat(["s1", "s2", "s3", "s4", "s5"], 4)
    labels = np.repeat(["a", "a", "a", "b", "b"], 4)
    centre = np.repeat([0.0, 0.1, -0.1, 10.0, 3.0], 4)
    x = np.zeros((20, 7))
    x[:, 0] = centre + np.tile([0.0, 0.01, 0.02, 0.03], 5)
    return x, labels, subjects


def _cfg(evaluation: dict[str, Any], classifier: dict[str, Any] | None = None) -> Any:
    return exp.ExperimentConfig.model_validate(
        {
            "dataset": {"path": "unused"},
            "evaluation": evaluation,
            "selection": {"method": "none", "optimistic": False},
            "classifier": classifier or {"kind": "knn", "k": 1},
        }
    )


def test_leave_subjects_out_accuracy_is_the_mean_recall_of_the_matrix() -> None:
    x, y, subjects = _one_class_per_subject()
    cfg = _cfg({"split": "groups", "by": "subject"})
    res = exp.within_source(cfg, exp.classifier_factory(cfg.classifier, "t"), x, y, subjects)
    cm = res["confusion_mean"]
    assert np.allclose(np.diagonal(cm), [1.0, 0.5])
    assert res["balanced_accuracy_mean"] == pytest.approx(0.75, abs=1e-12)
    assert res["balanced_accuracy_mean"] == pytest.approx(np.mean(np.diagonal(cm)), abs=1e-12)
    # every fold holds one class: the spread is over the classes' recalls, and says so
    assert res["balanced_accuracy_std_over"] == "classes"
    assert res["balanced_accuracy_std"] == pytest.approx(0.25, abs=1e-12)
    assert res["splits_tested"] == {"a": 3, "b": 2} and res["not_evaluated"] == {}
    # each row's mean ± std is over the folds that score its class (3 and 2), not over all 5:
    # the caption and the report say so (they said "mean ± std over 5 ... folds")
    splits = exp._splits_words(cfg.evaluation, res["n_splits"])
    words = " (each row over the folds that score its class: a 3, b 2)"
    assert exp._rows_scored_words(res, cfg.evaluation) == words
    assert exp._spread_words(res, splits, words).endswith(f"mean ± std over {splits}{words}")


def test_the_optimistic_bound_is_scored_as_the_result_is() -> None:
    """Leave-subjects-out with a class of one subject (c): the optimistic variant leaves out,
    as the result does, the rows of classes a fold tests without training on them. It used to
    average each fold's balanced accuracy, counting c's fold as 0 and weighting a by its three
    subjects: (1 + 1 + 1 + 1 + 0 + 0) / 6 = 0.667, an 'upper bound' below the result (0.75)."""
    x, y, subjects = _one_class_per_subject()
    x = np.concatenate([x, np.full((4, 7), 0.0)])
    x[-4:, 0] = -20.0 + np.arange(4) * 0.01
    y = np.concatenate([y, ["c"] * 4])
    subjects = np.concatenate([subjects, ["s6"] * 4])
    cfg = exp.ExperimentConfig.model_validate(
        {
            "dataset": {"path": "unused"},
            "evaluation": {"split": "groups", "by": "subject"},
            "selection": {"method": "wrapper", "sizes": [1], "folds": 2, "optimistic": True},
            "classifier": {"kind": "knn", "k": 1},
        }
    )
    res = exp.within_source(cfg, exp.classifier_factory(cfg.classifier, "t"), x, y, subjects)
    assert list(res["not_evaluated"]) == ["c"]
    assert res["balanced_accuracy_mean"] == pytest.approx(0.75, abs=1e-12)
    assert res["optimistic_accuracy_mean"] == pytest.approx(0.75, abs=1e-12)


@pytest.mark.parametrize("split", ["record", "recording"])
def test_stratified_splits_keep_the_mean_of_per_split_scores(
    rng: np.random.Generator, split: str
) -> None:
    """Where every split tests every class, the mean per-class recall of the matrix is the mean
    of the splits' balanced accuracies (the result before the protocols were told apart), and
    its spread is the standard deviation over the splits."""
    x, y = _toy(rng)
    x[:, 3] += rng.normal(0, 4.0, 60)  # overlapping classes: the splits differ
    recordings = np.array([f"{lab}{i // 5}" for lab, i in zip(y, range(60), strict=True)])
    cfg = _cfg({"repeats": 6, "split": split})
    factory = exp.classifier_factory(cfg.classifier, "t")
    res = exp.within_source(cfg, factory, x, y, recordings)
    if split == "record":
        splits = StratifiedShuffleSplit(6, test_size=0.4, random_state=0).split(x, y)
    else:
        splits = exp.recording_splits(y, recordings, 6, 0.4, 0)
    scores = [
        balanced_accuracy_score(y[te], factory().fit(x[tr], y[tr]).predict(x[te]))
        for tr, te in splits
    ]
    assert 0.4 < np.mean(scores) < 0.95 and np.std(scores) > 0.01
    assert res["balanced_accuracy_mean"] == pytest.approx(np.mean(scores), rel=0, abs=1e-12)
    assert res["balanced_accuracy_std"] == pytest.approx(np.std(scores), rel=0, abs=1e-12)
    assert res["balanced_accuracy_std_over"] == "splits"


def test_a_class_of_one_subject_is_not_evaluated_not_scored_zero() -> None:
    x, y, subjects = _one_class_per_subject()
    x = np.concatenate([x, np.full((4, 7), 50.0)])
    y = np.concatenate([y, ["c"] * 4])
    subjects = np.concatenate([subjects, ["s6"] * 4])
    cfg = _cfg({"split": "groups", "by": "subject"})
    res = exp.within_source(cfg, exp.classifier_factory(cfg.classifier, "t"), x, y, subjects)
    assert list(res["not_evaluated"]) == ["c"]
    assert "one subject ('s6')" in res["not_evaluated"]["c"]
    assert np.all(np.isnan(res["confusion_mean"][2]))
    assert res["balanced_accuracy_mean"] == pytest.approx(0.75, abs=1e-12)  # a and b only
    # a class of one recording under split = "recording": trained on, never tested, listed
    labels = np.repeat(["a", "b", "c"], 20)
    recordings = np.array([f"{lab}{i // 5}" for lab, i in zip(labels, range(60), strict=True)])
    recordings[labels == "c"] = "c-only"
    xr = np.zeros((60, 7))
    xr[:, 0] = np.repeat([0.0, 5.0, 10.0], 20)
    cfg = _cfg({"split": "recording", "repeats": 3})
    res = exp.within_source(
        cfg, exp.classifier_factory(cfg.classifier, "t"), xr, labels, recordings
    )
    assert list(res["not_evaluated"]) == ["c"] and "one recording only" in res["not_evaluated"]["c"]
    assert res["balanced_accuracy_mean"] == 1.0


def test_leave_subjects_out_report_states_the_protocol(
    kinect_dataset: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import mdframework.figures as figures

    captions: list[str] = []
    real = figures.plot_confusion

    def spy(*args: Any, **kwargs: Any) -> None:
        captions.append(kwargs.get("caption", ""))
        real(*args, **kwargs)

    monkeypatch.setattr(figures, "plot_confusion", spy)
    e = _experiment(
        kinect_dataset,
        tmp_path,
        '[selection]\nmethod = "none"\n[evaluation]\nsplit = "groups"\nby = "subject"\n',
    )
    with pytest.warns(exp.ExperimentWarning, match=r"class 'punch' not evaluated: .*one subject"):
        summary = exp.run_experiment(exp.load_experiment_config(e), tmp_path / "o", progress=False)
    report = (tmp_path / "o" / "report.md").read_text()
    assert "evaluation: leave-subjects-out cross-validation (one fold per subject" in report
    assert "stratified" not in report and "60/40" not in report
    assert "over 3 leave-subjects-out folds" in report
    assert "Not evaluated: punch (all its records are of one subject ('s01')" in report
    assert captions and captions[0].endswith("mean ± std over 3 leave-subjects-out folds")
    within = summary["within"]["kinect"]
    assert within["balanced_accuracy_mean"] == pytest.approx(
        np.nanmean(np.diagonal(np.array(within["confusion_mean"]))), abs=1e-12
    )
    with (tmp_path / "o" / "within_kinect_per_class.csv").open() as fh:
        rows = {r["class"]: r for r in csv.DictReader(fh)}
    assert rows["punch"]["rate_mean"] == "nan" and rows["punch"]["splits_scored"] == "0"
    # summary.json is strict JSON: the class not evaluated reads null, not NaN
    text = (tmp_path / "o" / "summary.json").read_text()
    written = json.loads(text, parse_constant=lambda c: pytest.fail(f"{c} in summary.json"))
    punch = written["within"]["kinect"]["classes"].index("punch")
    assert written["within"]["kinect"]["confusion_mean"][punch] == [None, None, None]
    # leave-subjects-out makes one fold per subject, whatever evaluation.repeats says (10)
    assert written["within"]["kinect"]["repeats"] == written["within"]["kinect"]["n_splits"] == 3


@pytest.mark.parametrize(
    ("split", "repeats", "words"),
    [
        ("record", 3, "mean ± std over 3 random splits of the records"),
        ("recording", 3, "mean ± std over 3 random splits holding out whole recordings"),
        ("recording", 10, "mean ± std over all 9 distinct splits holding out whole recordings"),
    ],
)
def test_the_within_source_caption_names_the_split_protocol(
    kinect_dataset: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    split: str,
    repeats: int,
    words: str,
) -> None:
    """A within-source figure's caption says how the records were split, as docs/experiments.md
    promises: a figure of whole recordings held out and one of records split at random (which
    flatters the score) read alike, 'mean ± std over 3 splits', before. Where fewer distinct
    splits exist than ``repeats`` (9 here), each is made once, none drawn
    at random (the caption said "9 random splits")."""
    import mdframework.figures as figures

    captions: list[str] = []
    monkeypatch.setattr(
        figures, "plot_confusion", lambda *a, caption="", **k: captions.append(caption)
    )
    e = _experiment(
        kinect_dataset,
        tmp_path,
        f'[selection]\nmethod = "none"\n[evaluation]\nsplit = "{split}"\nrepeats = {repeats}\n',
    )
    with pytest.warns(exp.ExperimentWarning) if split == "recording" else nullcontext():
        exp.run_experiment(exp.load_experiment_config(e), tmp_path / "o", progress=False)
    assert captions and captions[0].endswith(words), captions
    header = {
        "record": f"evaluation: {repeats} stratified random splits of the records, 60/40.",
        "recording": f"evaluation: up to {repeats} distinct random splits holding out 40 % of "
        "every class's recordings (rounded, at least one, never all).",
    }[split]
    assert header in (tmp_path / "o" / "report.md").read_text()


def test_per_record_predictions_match_the_matrices(kinect_dataset: Path, tmp_path: Path) -> None:
    """within_<group>_predictions.csv: every record once under leave-subjects-out, each fold
    one subject, and the folds' matrices from its rows average to the reported matrix;
    train_test_predictions.csv gives the train/test matrix."""
    body = (
        '[selection]\nmethod = "none"\n[evaluation]\nsplit = "groups"\n'
        '[train_test]\ntrain = { subject = ["s01", "s02"] }\ntest = { subject = "s03" }\n'
    )
    e = _experiment(kinect_dataset, tmp_path, body)
    with pytest.warns(exp.ExperimentWarning):  # punch: one subject
        summary = exp.run_experiment(exp.load_experiment_config(e), tmp_path / "o", progress=False)
    with (kinect_dataset / "index.csv").open() as fh:
        subject = {r["id"]: r["subject"] for r in csv.DictReader(fh)}
    with (tmp_path / "o" / "within_kinect_predictions.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert sorted(r["id"] for r in rows) == sorted(subject)  # each record tested once
    within = summary["within"]["kinect"]
    classes = within["classes"]
    mats = []
    for split in sorted({r["split"] for r in rows}):
        fold = [r for r in rows if r["split"] == split]
        assert len({subject[r["id"]] for r in fold}) == 1  # a fold holds out one subject
        mat = exp.confusion_matrix(
            np.array([r["true"] for r in fold]), np.array([r["predicted"] for r in fold]), classes
        )
        mat[classes.index("punch")] = np.nan  # tested only when its one subject is held out
        mats.append(mat)
    mean = np.nanmean(np.stack(mats)[:, :2], axis=0)  # boxing, jog
    assert np.allclose(mean, np.array(within["confusion_mean"])[:2])
    with (tmp_path / "o" / "train_test_predictions.csv").open() as fh:
        tt = list(csv.DictReader(fh))
    assert {subject[r["id"]] for r in tt} == {"s03"}
    got = exp.confusion_matrix(
        np.array([r["true"] for r in tt]),
        np.array([r["predicted"] for r in tt]),
        summary["train_test"]["classes"],
    )
    assert np.allclose(got, summary["train_test"]["confusion"])
    assert "predicted" not in summary["train_test"] and "predictions" not in within
    # the counts too (a results section gives both), and the accuracy they make
    tt_classes = summary["train_test"]["classes"]
    counts = np.zeros((len(tt_classes), len(tt_classes)), dtype=int)
    for r in tt:
        counts[tt_classes.index(r["true"]), tt_classes.index(r["predicted"])] += 1
    assert np.array_equal(summary["train_test"]["confusion_counts"], counts)
    assert summary["train_test"]["accuracy"] == pytest.approx(np.trace(counts) / len(tt))
    # summary.json holds them as numbers (an array left in would be written as its text), and
    # the within-source spread as within_<group>_confusion_std.csv does
    written = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert written["train_test"]["confusion_counts"] == counts.tolist()
    with (tmp_path / "o" / "within_kinect_confusion_std.csv").open() as fh:
        std = [[float(r[c]) for c in classes] for r in csv.DictReader(fh)]
    assert np.allclose(
        np.array(written["within"]["kinect"]["confusion_std"], dtype=float),
        std,
        atol=1e-6,
        equal_nan=True,
    )


def test_more_folds_than_subjects_warns_on_stderr(
    kinect_dataset: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from mdframework.cli import main

    body = '[selection]\nmethod = "none"\n[evaluation]\nsplit = "groups"\nfolds = 5\n'
    tt = '[train_test]\ntrain = { subject = ["s01", "s02"] }\ntest = { subject = "s03" }\n'
    e = _experiment(kinect_dataset, tmp_path, body + tt)
    assert main(["experiment", str(e), "--out", str(tmp_path / "o")]) == 0
    err = capsys.readouterr().err
    assert "warning: within-source kinect: not evaluated: evaluation.folds = 5 exceeds" in err
    assert "Not evaluated: evaluation.folds = 5" in (tmp_path / "o" / "report.md").read_text()


def test_a_feature_that_is_not_a_number_names_the_index_line(
    kinect_dataset: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An index.csv edited by hand with an empty or NaN feature: one line naming the file,
    line and record, exit 2 (it was an internal error from the wrapper's input check)."""
    import shutil

    data = tmp_path / "data"
    shutil.copytree(kinect_dataset, data)
    lines = (data / "index.csv").read_text().splitlines()
    header = lines[0].split(",")
    cells = lines[3].split(",")
    cells[header.index("upper_max")] = ""
    lines[3] = ",".join(cells)
    (data / "index.csv").write_text("\n".join(lines) + "\n")
    # a dataset built before dataset.json held the index's digest (which now refuses any edit)
    manifest = json.loads((data / "dataset.json").read_text())
    del manifest["index_sha256"]
    (data / "dataset.json").write_text(json.dumps(manifest))
    e = _experiment(data, tmp_path, '[selection]\nmethod = "none"\n[evaluation]\nrepeats = 2\n')
    _fails_with_one_line(
        e,
        tmp_path / "o",
        capsys,
        f"mdf: error: {data / 'index.csv'}:4: record {cells[0]}: upper_max is nan, not a finite "
        "number (1 such values); rebuild the dataset or remove the record",
    )


def _fails_with_one_line(
    config: Path, out: Path, capsys: pytest.CaptureFixture[str], line: str
) -> None:
    """``mdf experiment config --out out`` exits 2 with ``line`` as its only stderr line and
    leaves nothing in ``out``."""
    from mdframework.cli import main

    assert main(["experiment", str(config), "--out", str(out), "--no-progress"]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [line]
    assert not out.exists() or not any(out.iterdir())  # nothing half-written


def test_an_experiment_that_evaluates_nothing_is_an_error(
    kinect_dataset: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every group skipped and no cross-source or train/test part: one error line, exit 2,
    no report (it used to write an empty report and exit 0)."""
    body = '[selection]\nmethod = "none"\n[evaluation]\nsplit = "groups"\nfolds = 5\n'
    e = _experiment(kinect_dataset, tmp_path, body)
    _fails_with_one_line(
        e,
        tmp_path / "o",
        capsys,
        f"mdf: error: {e}: evaluation.split = 'groups': nothing could be evaluated (within-source "
        "kinect: evaluation.folds = 5 exceeds the 3 groups ['s01', 's02', 's03']: lower "
        "evaluation.folds, or leave it out for one fold per group)",
    )


def test_leave_subjects_out_refuses_records_without_a_subject() -> None:
    """Records of unknown subjects are not held out together as if they were one person."""
    x, y, subjects = _one_class_per_subject()
    subjects[-4:] = ""  # s5's records lost their subject
    cfg = _cfg({"split": "groups", "by": "subject"})
    factory = exp.classifier_factory(cfg.classifier, "t")
    with pytest.raises(
        MdfError, match=r"^evaluation.by = 'subject': 4 of 20 records have no subject; give"
    ):
        exp.within_source(cfg, factory, x, y, subjects)


@pytest.mark.parametrize(
    ("body", "message"),
    [
        (
            '[selection]\nmethod = "wrapper"\nsizes = [1]\n[evaluation]\nrepeats = 2\n',
            "selection.method = 'wrapper': class 'punch' has 1 training record of 2 records; "
            "the wrapper's cross-validation needs at least 2 training records of every class: "
            "build more records of it, or set selection.method = 'none'",
        ),
    ],
)
def test_a_class_too_small_to_split_is_a_config_error(
    kinect_dataset: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    body: str,
    message: str,
) -> None:
    from mdframework.cli import main

    e = _experiment(kinect_dataset, tmp_path, body)
    out = tmp_path / "o"
    assert main(["experiment", str(e), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == f"mdf: error: {e}: {message}"
    assert not out.exists() or not any(out.iterdir())  # nothing half-written


def test_a_class_of_one_record_is_a_config_error_for_record_splits(
    rng: np.random.Generator,
) -> None:
    x, y = _toy(rng)
    y = np.array(["lonely", *y[1:]])
    cfg = _cfg({"repeats": 2})
    with pytest.raises(
        ConfigError, match=r"evaluation.split = 'record': class 'lonely' has 1 record; every class"
    ):
        exp.within_source(cfg, exp.classifier_factory(cfg.classifier, "t"), x, y)
    cfg = _cfg({"repeats": 2, "test_fraction": 0.03})  # 2 test records for 3 classes
    with pytest.raises(ConfigError, match=r"^evaluation.test_fraction = 0.03: "):
        exp.within_source(cfg, exp.classifier_factory(cfg.classifier, "t"), *_toy(rng))


def test_the_experiment_seed_reaches_the_classifier(rng: np.random.Generator) -> None:
    from mdf_sklearn import SklearnClassifier

    rf = {"kind": "sklearn", "estimator": "sklearn.ensemble.RandomForestClassifier"}
    assert exp.classifier_factory(rf, "t", seed=7)().seed == 7
    assert exp.classifier_factory(rf, "t")().seed is None  # no experiment: no seed
    make = exp.classifier_factory(rf, "t", seed=7)
    clf = make()
    assert isinstance(clf, SklearnClassifier)
    assert clf.estimator_params() == {"random_state": 7}
    own = exp.classifier_factory({**rf, "params": {"random_state": 3}}, "t", seed=7)()
    assert isinstance(own, SklearnClassifier) and own.estimator_params() == {"random_state": 3}
    knn = {"kind": "sklearn", "estimator": "sklearn.neighbors.KNeighborsClassifier"}
    other = exp.classifier_factory(knn, "t", seed=7)()
    assert isinstance(other, SklearnClassifier) and other.estimator_params() == {}
    x, y = _toy(rng)
    assert clf.fit(x, y).model_.random_state == 7


def test_a_random_forest_experiment_repeats_exactly(kinect_dataset: Path, tmp_path: Path) -> None:
    e = _experiment(
        kinect_dataset,
        tmp_path,
        '[classifier]\nkind = "sklearn"\nestimator = "sklearn.ensemble.RandomForestClassifier"\n'
        'params = { n_estimators = 3, max_features = 1 }\n[selection]\nmethod = "none"\n'
        '[evaluation]\nsplit = "groups"\n',
    )
    cfg = exp.load_experiment_config(e)
    runs = []
    for i in range(2):
        with pytest.warns(exp.ExperimentWarning):  # punch: one subject
            exp.run_experiment(cfg, tmp_path / f"o{i}", progress=False)
        runs.append([(tmp_path / f"o{i}" / n).read_text() for n in ("summary.json", "report.md")])
    assert runs[0] == runs[1]


def test_every_confusion_matrix_is_captioned(
    kinect_dataset: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Within-source and train/test confusion matrices both carry the dataset, the classifier's
    input (features or Doppler histograms), the classifier and the selection in their captions
    (the train/test one had none), and the train/test title names the selections in words."""
    from mdframework import figures

    captions: dict[str, str] = {}
    titles: dict[str, str] = {}

    def record(path: Path, *args: object, caption: str = "", title: str = "", **_: object) -> None:
        captions[Path(path).name] = caption
        titles[Path(path).name] = title

    monkeypatch.setattr(figures, "plot_confusion", record)
    _groups_and_train_test(kinect_dataset, tmp_path)
    assert set(captions) == {"within_kinect_confusion.png", "train_test_confusion.png"}
    for name, caption in captions.items():
        parts = (
            "dataset dataset (",
            "input features",
            'classifier {"kind": "knn"',
            "selection none",
        )
        for part in parts:
            assert part in caption, (name, caption)
    # the selections in words, not as Python dictionaries
    assert titles["train_test_confusion.png"] == (
        "train subject = s01 or s02 -> test subject = s03"
    )


def test_summary_json_holds_what_repeats_the_experiment(
    kinect_dataset: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """summary.json names the experiment's config (seed, classifier, selection, evaluation),
    the versions of the software and the SHA-256 of the dataset's index.csv: the config read
    back from it repeats the experiment exactly (the seed was nowhere in the report folder, and
    no version anywhere; nothing said which dataset a folder named by `path` held then)."""
    import importlib.metadata

    e = _experiment(
        kinect_dataset,
        tmp_path,
        '[classifier]\nkind = "sklearn"\nestimator = "sklearn.ensemble.RandomForestClassifier"\n'
        'params = { n_estimators = 3, max_features = 1 }\n[selection]\nmethod = "none"\n'
        "[evaluation]\nrepeats = 3\n",
    )
    relative = os.path.relpath(kinect_dataset, tmp_path)  # to the config's folder
    e.write_text(
        e.read_text().replace("seed = 0", "seed = 11").replace(str(kinect_dataset), relative)
    )
    monkeypatch.chdir(tmp_path.parent)  # the dataset's path is read from the config's folder
    cfg = exp.load_experiment_config(Path(tmp_path.name) / e.name)  # as given: relative
    exp.run_experiment(cfg, tmp_path / "a", progress=False)
    written = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert written["config"]["seed"] == 11
    assert written["config"]["dataset"]["path"] == str(kinect_dataset)  # read from anywhere
    assert written["config"]["classifier"]["params"] == {"n_estimators": 3, "max_features": 1}
    # which dataset: its index.csv (ids, which digest what makes each record, and features)
    index = (kinect_dataset / "index.csv").read_bytes()
    assert written["dataset_index_sha256"] == hashlib.sha256(index).hexdigest()
    versions = written["versions"]
    assert versions["mdframework"] == importlib.metadata.version("mdframework")
    assert versions["scikit-learn"] == importlib.metadata.version("scikit-learn")
    assert versions["matplotlib"] == importlib.metadata.version("matplotlib")  # drew the figures
    assert f"mdf-sklearn {importlib.metadata.version('mdf-sklearn')}" in versions["plugins"]
    monkeypatch.chdir(kinect_dataset)
    again = exp.ExperimentConfig.model_validate(written["config"])
    exp.run_experiment(again, tmp_path / "b", progress=False)
    repeated = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert repeated.pop("dataset") == str(kinect_dataset)  # the path the config gave, as given
    assert written.pop("dataset") == os.path.join(tmp_path.name, relative)
    assert repeated == written
    predictions = "within_kinect_predictions.csv"
    assert (tmp_path / "a" / predictions).read_text() == (tmp_path / "b" / predictions).read_text()


def test_a_recording_split_never_holds_out_all_of_a_class() -> None:
    """test_fraction = 0.9 of a class's 2 (or 3) recordings rounds to all of them: one (two)
    is held out, so every split still trains on every class."""
    from mdframework.experiment import recording_splits, recordings_held_out

    assert recordings_held_out(2, 0.9) == 1 and recordings_held_out(3, 0.9) == 2
    assert recordings_held_out(10, 0.4) == 4 and recordings_held_out(10, 0.01) == 1
    labels = np.array(["a"] * 4 + ["b"] * 6)
    recs = np.array(["a1", "a1", "a2", "a2", "b1", "b1", "b2", "b2", "b3", "b3"])
    for train, test in recording_splits(labels, recs, 5, 0.9, seed=3):
        assert set(labels[train]) == {"a", "b"} and set(labels[test]) == {"a", "b"}
        assert not set(recs[train]) & set(recs[test])
        assert len(set(recs[test])) == 3


def test_a_class_of_one_side_only_is_named_in_the_train_test_report(
    kinect_dataset: Path, tmp_path: Path
) -> None:
    """punch is recorded by s01 only. Trained on s02 and s03 and tested on s01, its 2 test
    records cannot be scored (no training record of it); trained on s01 and s02 and tested on
    s03, it is left out of training (so no s03 record can be called punch). Either way the
    score is over jog and boxing only: the report, stderr and summary.json say which class was
    left out and how many records, instead of scoring a subset of the records in silence."""
    from mdframework.dataset import load_dataset

    data = load_dataset(kinect_dataset, spectrograms=False)
    n_punch = int(np.sum(data.labels == "punch"))
    for train, test, words in (
        (["s02", "s03"], "s01", f"{n_punch} test records not scored: no training record of it"),
        (["s01", "s02"], "s03", f"{n_punch} training records left out of training"),
    ):
        cfg = exp.ExperimentConfig.model_validate(
            {
                "dataset": {"path": str(kinect_dataset)},
                "selection": {"method": "none"},
                "train_test": {"train": {"subject": train}, "test": {"subject": test}},
            }
        )
        res = exp.train_test(cfg, exp.classifier_factory(cfg.classifier, "t"), data)
        assert res["classes"] == ["boxing", "jog"]
        assert list(res["left_out"]) == ["punch"] and res["left_out"]["punch"].startswith(words)
    body = (
        '[selection]\nmethod = "none"\n[evaluation]\nsplit = "groups"\n'
        '[train_test]\ntrain = { subject = ["s02", "s03"] }\ntest = { subject = "s01" }\n'
    )
    e = _experiment(kinect_dataset, tmp_path, body)
    with pytest.warns(exp.ExperimentWarning, match=r"train_test: class 'punch' left out"):
        summary = exp.run_experiment(exp.load_experiment_config(e), tmp_path / "o", progress=False)
    report = (tmp_path / "o" / "report.md").read_text()
    line = "Left out (on one side only; the score is over the classes both sides hold): punch"
    assert f"{line} ({n_punch} test records not scored" in report
    assert summary["train_test"]["left_out"] == {
        "punch": f"{n_punch} test records not scored: no training record of it"
    }


def test_recording_splits_are_distinct_and_all_made_when_fewer_exist() -> None:
    """Three classes of two recordings allow 2 * 2 * 2 = 8 splits holding out one recording
    per class. Ten random draws of them repeated some (seed 0: 6 distinct, one split drawn 4
    times, so it weighed 40 % in the mean and the walk recording 02_01 was held out in 8 of 10):
    now each of the 8 is made once, and the report says so. Where more splits exist than are
    asked for, the splits are still distinct."""
    files = {"boxing": ["13_18", "80_10"], "run": ["09_03", "09_06"], "walk": ["02_01", "16_21"]}
    labels = np.array([c for c, names in files.items() for _ in names for _ in range(4)])
    recordings = np.array([n for names in files.values() for n in names for _ in range(4)])
    splits = exp.recording_splits(labels, recordings, 10, 0.4, 0)
    held = [frozenset(recordings[te].tolist()) for _, te in splits]
    assert len(held) == len(set(held)) == 8
    assert exp.distinct_recording_splits(labels, recordings, 0.4) == 8
    for train, test in splits:
        assert not set(recordings[train]) & set(recordings[test])
        assert set(labels[test]) == set(labels[train]) == set(files)
    many = np.array([f"{c}{i // 2}" for c, i in zip(labels, range(24), strict=True)])  # 4 per class
    drawn = [
        frozenset(many[te].tolist()) for _, te in exp.recording_splits(labels, many, 50, 0.4, 1)
    ]
    assert len(drawn) == len(set(drawn)) == 50  # of 6 ** 3 = 216
    x = np.zeros((24, 7))
    x[:, 0] = np.repeat([0.0, 5.0, 10.0], 8)
    cfg = _cfg({"split": "recording", "repeats": 10})
    res = exp.within_source(cfg, exp.classifier_factory(cfg.classifier, "t"), x, labels, recordings)
    assert res["n_splits"] == 8 and res["balanced_accuracy_mean"] == 1.0
    assert exp._held_out_markdown(res)[0] == (
        "Recordings held out in every split: boxing 1 of 2, run 1 of 2, walk 1 of 2. These allow "
        "8 distinct splits only, and each is made once (not 10 splits, some of them repeated)."
    )


def test_recording_splits_hold_out_several_recordings_of_a_class_once_each() -> None:
    """Classes of 4 and 5 recordings at test_fraction 0.4 hold out 2 of each: C(4, 2) x
    C(5, 2) = 6 x 10 = 60 distinct splits. Asked for 70, each of the 60 is made once, each
    holding out 2 recordings of each class; asked for 30, 30 distinct ones are drawn."""
    labels = np.array(["a"] * 8 + ["b"] * 10)
    index = [*range(8), *range(10)]
    recordings = np.array([f"{c}{i // 2}" for c, i in zip(labels, index, strict=True)])
    assert exp.distinct_recording_splits(labels, recordings, 0.4) == 60
    for repeats, n in ((70, 60), (30, 30)):
        splits = exp.recording_splits(labels, recordings, repeats, 0.4, 2)
        held = [frozenset(recordings[te].tolist()) for _, te in splits]
        assert len(held) == len(set(held)) == n
        for h in held:
            assert sorted(r[0] for r in h) == ["a", "a", "b", "b"]


def test_generated_walkers_of_other_parameters_are_other_recordings(tmp_path: Path) -> None:
    """Boulic walkers read from no file were all one recording, 'boulic': a class of five
    walkers was 'not evaluated: it has one recording only' under split = 'recording', and
    leave-recordings-out held all walkers of every class out together. Each walker is now the
    recording of its parameters; two spans of one walker (start, duration) stay one."""
    from mdframework.dataset import plan_records

    p = tmp_path / "d.toml"
    sources = [
        ("walk", "rv = 0.7, n_cycles = 3"),
        ("walk", "rv = 0.7, n_cycles = 3, start = 1.0"),
        ("walk", "rv = 0.9, n_cycles = 3"),
        ("brisk", "rv = 2.0, n_cycles = 3"),
        ("brisk", "rv = 1.5, n_cycles = 3, start = 0.5, duration = 1.5"),
        ("brisk", ""),
    ]
    p.write_text(
        "[record_lengths]\nwalk = 1.0\nbrisk = 1.0\n[base.radar]\nkind = 'lfm'\n"
        + "".join(
            f'[[sources]]\nlabel = "{label}"\nmax_records = 1\n'
            f'motion = {{ kind = "boulic"{", " if params else ""}{params} }}\n'
            for label, params in sources
        )
    )
    specs = plan_records(*load_dataset_config(p))
    assert [s.recording for s in specs] == [
        "boulic(n_cycles=3 rv=0.7)",
        "boulic(n_cycles=3 rv=0.7)",
        "boulic(n_cycles=3 rv=0.9)",
        "boulic(n_cycles=3 rv=2.0)",
        "boulic(n_cycles=3 rv=1.5)",  # a span of it names it as the whole walker does
        "boulic",  # every parameter its default
    ]


def test_one_walker_written_in_two_ways_is_one_recording(tmp_path: Path) -> None:
    """Two sources of one class whose motion sections differ in what does not change the
    walker (its activity label, a default written out, 1 for 1.0) read the same motion: they
    are one recording, not two (split = 'recording' would train on the walker it tests on).
    A walker of other data stays another recording."""
    from mdframework.dataset import plan_records

    p = tmp_path / "d.toml"
    sources = [
        "rv = 1.0, n_cycles = 3",
        'rv = 1, n_cycles = 3, height = 1.8, activity = "stroll"',
        "n_cycles = 3",  # rv = 1 by default
        "rv = 1.0, n_cycles = 3, height = 1.7",
    ]
    p.write_text(
        "[record_lengths]\nwalk = 1.0\n[base.radar]\nkind = 'lfm'\n"
        + "".join(
            f'[[sources]]\nlabel = "walk"\nmax_records = 1\nmotion = {{ kind = "boulic", {s} }}\n'
            for s in sources
        )
    )
    names = [s.recording for s in plan_records(*load_dataset_config(p))]
    assert names[0] == names[1] == names[2] == "boulic(n_cycles=3 rv=1.0)"
    assert names[3] == "boulic(height=1.7 n_cycles=3 rv=1.0)"


def test_the_largest_experiment_seed_runs_and_a_larger_one_is_a_config_error(
    rng: np.random.Generator, tmp_path: Path
) -> None:
    """scikit-learn takes random states below 2**32 only: the seed 2**32 - 1 ran into an
    internal error ('Seed must be between 0 and 2**32 - 1') in the wrapper's folds of the
    second split (seeded seed + split), and a seed of 2**32 or more in the first. The largest
    seed runs, the folds' seeds wrapping around, as the random forest does; a larger one is
    refused naming the field."""
    x, y = _toy(rng)
    cfg = exp.ExperimentConfig.model_validate(
        {
            "seed": 2**32 - 1,
            "dataset": {"path": "unused"},
            "evaluation": {"repeats": 3},
            "selection": {"method": "wrapper", "sizes": [2], "folds": 2},
            "classifier": {
                "kind": "sklearn",
                "estimator": "sklearn.ensemble.RandomForestClassifier",
                "params": {"n_estimators": 3},
            },
        }
    )
    factory = exp.classifier_factory(cfg.classifier, "t", seed=cfg.seed)
    res = exp.within_source(cfg, factory, x, y, None)
    assert res["balanced_accuracy_mean"] > 0.9  # the toy's classes are well apart
    p = tmp_path / "e.toml"
    p.write_text(f'seed = {2**32}\n[dataset]\npath = "x"\n')
    with pytest.raises(ConfigError, match=r"e\.toml: seed: must be at most 4294967295"):
        exp.load_experiment_config(p)
    p.write_text('seed = -1\n[dataset]\npath = "x"\n')  # nor a negative one
    with pytest.raises(ConfigError, match=r"e\.toml: seed: must be at least 0 \(got -1\)"):
        exp.load_experiment_config(p)


def test_an_error_in_the_dataset_config_names_that_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A motion kind that is not installed (mdf-cmu uninstalled) in the dataset config an
    experiment builds is named in that file, as its field errors are: it was
    `mdf: error: e.toml: sources[0].motion.kind: no motion plugin named 'cmux' ...`, which sent
    the user looking in the experiment's config for a `sources` it does not have."""
    from mdframework import cli

    data = EXAMPLES / "data" / "cmu" / "asf-amc" / "02_01.amc"
    (tmp_path / "d.toml").write_text(
        f'[[sources]]\nlabel = "walk"\nmotion = {{ kind = "cmux", file = "{data}" }}\n'
        '[record_lengths]\nwalk = 1.0\n[base.radar]\nkind = "lfm"\n'
        '[base.scatterers]\nkind = "ellipsoid"\nplacement = "joints17"\n'
    )
    (tmp_path / "e.toml").write_text('[dataset]\nconfig = "d.toml"\n[classifier]\nkind = "knn"\n')
    code = cli.main(["experiment", str(tmp_path / "e.toml"), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.startswith(
        f"mdf: error: {tmp_path / 'e.toml'}: {tmp_path / 'd.toml'}: sources[0].motion.kind: no "
        "motion plugin named 'cmux' (did you mean 'cmu'?)"
    ), err


def test_counts_precision_recall_f1_agree_with_the_predictions(
    kinect_dataset: Path, tmp_path: Path
) -> None:
    """A results section needs the confusion counts and per-class precision, recall and F1, not
    only the row-normalised rates: within_<group>_confusion_counts.csv sums every split's
    scored test predictions (recomputed here from within_<group>_predictions.csv with
    scikit-learn), per_class.csv gives the pooled precision, recall and F1 of those counts, and
    summary.json the counts and the pooled accuracy (trace over total)."""
    from sklearn.metrics import confusion_matrix as sk_confusion
    from sklearn.metrics import precision_recall_fscore_support

    e = _experiment(
        kinect_dataset,
        tmp_path,
        '[selection]\nmethod = "none"\n[evaluation]\nsplit = "groups"\nby = "subject"\n',
    )
    with pytest.warns(exp.ExperimentWarning):  # punch: one subject, not evaluated
        summary = exp.run_experiment(exp.load_experiment_config(e), tmp_path / "o", progress=False)
    within = summary["within"]["kinect"]
    classes = within["classes"]
    with (tmp_path / "o" / "within_kinect_predictions.csv").open() as fh:
        rows = [r for r in csv.DictReader(fh) if r["true"] != "punch"]  # never scored
    truth, pred = [r["true"] for r in rows], [r["predicted"] for r in rows]
    expected = sk_confusion(truth, pred, labels=classes)
    counts = np.array(within["confusion_counts"])
    assert counts.dtype.kind == "i" and np.array_equal(counts, expected)
    assert counts.sum() == len(rows)
    assert within["accuracy"] == pytest.approx(np.trace(expected) / len(rows), abs=1e-12)
    with (tmp_path / "o" / "within_kinect_confusion_counts.csv").open() as fh:
        written = list(csv.DictReader(fh))
    assert [r["true"] for r in written] == classes
    assert np.array_equal([[int(r[c]) for c in classes] for r in written], expected)
    scored = ["boxing", "jog"]
    p, r, f, support = precision_recall_fscore_support(truth, pred, labels=scored, zero_division=0)
    with (tmp_path / "o" / "within_kinect_per_class.csv").open() as fh:
        per = {row["class"]: row for row in csv.DictReader(fh)}
    for i, c in enumerate(scored):
        assert int(per[c]["test_records"]) == support[i]
        for key, value in (("precision", p[i]), ("recall", r[i]), ("f1", f[i])):
            assert float(per[c][key]) == pytest.approx(value, abs=1e-12), (c, key)
    assert per["punch"]["test_records"] == "0" and per["punch"]["f1"] == "nan"


def test_summary_config_names_the_classifiers_defaults(
    kinect_dataset: Path, tmp_path: Path
) -> None:
    """summary.json's config has "every default filled in" (docs/experiments.md), the
    classifier's too: a [classifier] of kind = "knn" alone still records k, the metric and the
    tie rule the run used, which a paper's methods section must state."""
    e = _experiment(
        kinect_dataset,
        tmp_path,
        '[classifier]\nkind = "knn"\n[selection]\nmethod = "none"\n[evaluation]\nrepeats = 2\n',
    )
    exp.run_experiment(exp.load_experiment_config(e), tmp_path / "o", progress=False)
    written = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert written["config"]["classifier"] == {
        "kind": "knn",
        "k": 5,
        "metric": "euclidean",
        "tie_rule": "nearest",
    }
    exp.ExperimentConfig.model_validate(written["config"])  # still a config that repeats it
    header = 'Classifier: `{"kind": "knn", "k": 5, "metric": "euclidean", "tie_rule": "nearest"}`'
    assert header in (tmp_path / "o" / "report.md").read_text()  # the report too


def test_feature_statistics_name_the_variances_unit(kinect_dataset: Path, tmp_path: Path) -> None:
    """feature_stats.md gives each mean in m/s and each variance in (m/s)^2: its header said
    '[m/s]' over both."""
    e = _experiment(
        kinect_dataset, tmp_path, '[selection]\nmethod = "none"\n[evaluation]\nrepeats = 2\n'
    )
    exp.run_experiment(exp.load_experiment_config(e), tmp_path / "o", progress=False)
    md = (tmp_path / "o" / "feature_stats.md").read_text()
    assert md.startswith("mean [m/s] (variance [(m/s)²])\n")
    assert "| feature |" in md and "feature [m/s]" not in md


def test_every_output_key_and_column_is_documented(kinect_dataset: Path, tmp_path: Path) -> None:
    """docs/experiments.md names every key of summary.json (top level, a within-source result,
    a train/test result) and every column of the per-class and feature-statistics CSV files:
    a results section cites them without reading the code (splits_tested, repeats, subsets...
    were named nowhere)."""
    doc = (Path(__file__).parents[1] / "docs" / "experiments.md").read_text(encoding="utf-8")
    _groups_and_train_test(kinect_dataset, tmp_path)
    out = tmp_path / "o"
    written = json.loads((out / "summary.json").read_text())
    keys = {*written, *written["within"]["kinect"], *written["train_test"]}
    with (out / "within_kinect_per_class.csv").open() as fh:
        keys |= set(next(csv.reader(fh)))
    missing = sorted(k for k in keys if f"`{k}`" not in doc)
    assert not missing, f"not in docs/experiments.md: {missing}"
    with (out / "feature_stats.csv").open() as fh:
        columns = next(csv.reader(fh))
    assert {c for c in columns if c.endswith(("_mean", "_var"))} == {
        f"{f}_{s}" for f in exp.FEATURE_NAMES for s in ("mean", "var")
    }
    assert "`<feature>_mean` [m/s]" in doc and "`<feature>_var` [(m/s)²]" in doc


def test_figures_also_in_vector_formats_for_print(kinect_dataset: Path, tmp_path: Path) -> None:
    """[report] figure_formats = ["png", "pdf", "svg"] writes every figure of the report also as
    a PDF and an SVG (vector, for print: the PNGs are 110 dpi), with their text as text (no
    Type 3 fonts, which publishers refuse); the default writes PNGs only, and a list without
    "png" (the report shows the PNGs) is a config error naming the field."""
    body = (
        '[selection]\nmethod = "none"\n[evaluation]\nrepeats = 2\n'
        '[report]\nscatter_pairs = [["torso_mean", "upper_max"]]\n'
        'figure_formats = ["png", "pdf", "svg"]\n'
    )
    e = _experiment(kinect_dataset, tmp_path, body)
    exp.run_experiment(exp.load_experiment_config(e), tmp_path / "o", progress=False)
    out = tmp_path / "o"
    for stem in ("within_kinect_confusion", "scatter_torso_mean_upper_max"):
        assert (out / f"{stem}.png").read_bytes().startswith(b"\x89PNG")
        pdf = (out / f"{stem}.pdf").read_bytes()
        assert pdf.startswith(b"%PDF") and b"/Type3" not in pdf  # TrueType: publishers take it
        svg = (out / f"{stem}.svg").read_text()
        assert "<svg" in svg and ("predicted" in svg or "torso_mean" in svg)
        assert "<text" in svg  # text as text, not glyph paths (whose comments name it too)
    e.write_text(e.read_text().replace('["png", "pdf", "svg"]', '["pdf"]'))
    with pytest.raises(ConfigError, match=r"report\.figure_formats.*png"):
        exp.load_experiment_config(e)
    with pytest.raises(ValueError, match="must include 'png'"):
        exp.ReportConfig(figure_formats=[])
    assert exp.ReportConfig(figure_formats=["png", "svg", "png"]).figure_formats == ["png", "svg"]
    e.write_text(e.read_text().replace('figure_formats = ["pdf"]\n', ""))
    exp.run_experiment(exp.load_experiment_config(e), tmp_path / "p", progress=False)
    assert not list((tmp_path / "p").glob("*.pdf")) and not list((tmp_path / "p").glob("*.svg"))


def test_per_split_scores_and_counts_are_written(kinect_dataset: Path, tmp_path: Path) -> None:
    """summary.json gives each split's balanced accuracy and its training and test records per
    class, so that a paper can state the records per split and compute its own uncertainty: here
    recomputed with scikit-learn from within_<group>_predictions.csv; their mean and population
    standard deviation are the reported balanced accuracy and its spread."""
    e = _experiment(
        kinect_dataset,
        tmp_path,
        '[selection]\nmethod = "none"\n[evaluation]\nrepeats = 4\n',
    )
    summary = exp.run_experiment(exp.load_experiment_config(e), tmp_path / "o", progress=False)
    written = json.loads((tmp_path / "o" / "summary.json").read_text())["within"]["kinect"]
    with (tmp_path / "o" / "within_kinect_predictions.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    per_split = written["balanced_accuracy_per_split"]
    counts = written["split_counts"]
    assert len(per_split) == len(counts) == written["n_splits"] == 4
    for k in range(4):
        fold = [r for r in rows if r["split"] == str(k)]
        truth, pred = [r["true"] for r in fold], [r["predicted"] for r in fold]
        assert per_split[k] == pytest.approx(balanced_accuracy_score(truth, pred), abs=1e-12)
        assert counts[k]["test"] == {c: truth.count(c) for c in written["classes"]}
        for c in written["classes"]:
            assert counts[k]["train"][c] + counts[k]["test"][c] == written["class_counts"][c]
    assert np.mean(per_split) == pytest.approx(written["balanced_accuracy_mean"], abs=1e-12)
    assert np.std(per_split) == pytest.approx(written["balanced_accuracy_std"], abs=1e-12)
    assert summary["within"]["kinect"]["balanced_accuracy_std_over"] == "splits"


def test_pooled_scores_of_classes_never_predicted_never_right_or_never_tested() -> None:
    """per_class.csv's pooled precision, recall and F1 are scikit-learn's with
    ``zero_division=0`` for every class with test records: b is never predicted (precision 0,
    not NaN), c is predicted but never right (0); a class without test records (d, though
    predicted) reads NaN in all three, as docs/experiments.md says. A prediction outside the
    classes is not counted."""
    from sklearn.metrics import precision_recall_fscore_support

    classes = ["a", "b", "c", "d"]
    truth = np.array(["a"] * 4 + ["b"] * 2 + ["c"] * 3)
    pred = np.array(["a", "a", "a", "c", "a", "d", "a", "a", "a"])
    counts = exp.confusion_counts(truth, pred, classes)
    assert counts.tolist() == [[3, 0, 1, 0], [1, 0, 0, 1], [3, 0, 0, 0], [0, 0, 0, 0]]
    precision, recall, f1 = exp.pooled_scores(counts)
    p, r, f, _ = precision_recall_fscore_support(truth, pred, labels=classes[:3], zero_division=0)
    assert np.allclose(precision[:3], p, rtol=0, atol=1e-12)
    assert np.allclose(recall[:3], r, rtol=0, atol=1e-12)
    assert np.allclose(f1[:3], f, rtol=0, atol=1e-12)
    assert precision[1] == 0.0 and f1[1] == 0.0 and precision[2] == 0.0
    assert np.isnan([precision[3], recall[3], f1[3]]).all()
    outside = exp.confusion_counts(np.array(["a", "b"]), np.array(["a", "z"]), ["a", "b"])
    assert outside.tolist() == [[1, 0], [0, 0]]


def test_per_split_scores_and_counts_of_folds_of_one_class() -> None:
    """Leave-subjects-out where every fold holds one class (_one_class_per_subject, plus c of
    one subject, s6, never scored): each fold's balanced accuracy is the recall of the class it
    scores (a's folds 1, s4's 1, s5's 0), the fold of c alone scores nothing (null in
    summary.json), and the pooled counts hold a's and b's 20 test records only: accuracy
    16 / 20, precision of a 12 / 16."""
    x, y, subjects = _one_class_per_subject()
    x = np.concatenate([x, np.full((4, 7), 0.0)])
    x[-4:, 0] = -20.0 + np.arange(4) * 0.01
    y = np.concatenate([y, ["c"] * 4])
    subjects = np.concatenate([subjects, ["s6"] * 4])
    cfg = _cfg({"split": "groups", "by": "subject"})
    res = exp.within_source(cfg, exp.classifier_factory(cfg.classifier, "t"), x, y, subjects)
    assert list(res["not_evaluated"]) == ["c"]
    per = res["balanced_accuracy_per_split"]
    assert len(per) == res["n_splits"] == 6
    assert sum(np.isnan(per)) == 1 and sorted(v for v in per if not np.isnan(v)) == [
        0.0,
        1.0,
        1.0,
        1.0,
        1.0,
    ]
    assert None in exp._strict_json(per)  # written as null
    assert res["confusion_counts"].tolist() == [[12, 0, 0], [4, 4, 0], [0, 0, 0]]
    assert res["accuracy"] == pytest.approx(16 / 20, abs=1e-12)
    precision, recall, _ = exp.pooled_scores(res["confusion_counts"])
    assert precision[:2] == pytest.approx([12 / 16, 1.0]) and recall[:2] == pytest.approx([1, 0.5])


def test_rows_scored_words_name_each_class_where_some_split_leaves_one_out() -> None:
    """The caption's '(each row over the splits that score its class: ...)' appears as soon as
    one evaluated class is not scored in every split, though another is."""
    res = {"splits_scored": {"a": 5, "b": 3, "c": 0}, "not_evaluated": {"c": "x"}, "n_splits": 5}
    ev = exp.EvaluationConfig(split="groups", by="subject")
    words = " (each row over the folds that score its class: a 5, b 3)"
    assert exp._rows_scored_words(res, ev) == words
    res["splits_scored"]["b"] = 5
    assert exp._rows_scored_words(res, ev) == ""
