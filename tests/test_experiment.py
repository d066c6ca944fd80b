"""Experiments: configs parse, selection never sees the test split, reports are consistent."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import EXAMPLES
from sklearn.model_selection import StratifiedShuffleSplit

from mdframework import experiment as exp
from mdframework.dataset import load_dataset_config
from mdframework.errors import ConfigError


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


def test_bad_experiment_config(tmp_path: Path) -> None:
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
    with pytest.raises(exp.MdfError, match="class 'a' has only one recording"):
        exp.recording_splits(labels, np.where(labels == "a", "one", recordings), 1, 0.4, 0)
