"""The paper's experiments as config-file runs (``mdf experiment CONFIG --out DIR``).

- **Within-source**: for every source group, repeated stratified train/test splits (60/40 by
  default), splits holding out whole recordings, or leave-subjects-out folds
  (``evaluation.split``); optional wrapper feature selection by cross-validation on the
  training split only; the confusion matrix's mean and spread over the splits, the per-class
  rates, and the balanced accuracy as the mean per-class recall of that matrix (a class no
  split can test on unseen data is reported as not evaluated, not scored 0). The paper's
  optimistic variant (feature subset chosen on the test split) is reported separately and
  labelled as such.
- **Cross-source**: train on one group (e.g. Kinect-derived records), test on another (e.g.
  CMU-derived) over the classes they share, after an optional label map (``jog -> run``).
- **Inputs**: the seven features (``input = "features"``), or, for datasets of per-frame Doppler
  histograms (real radar recordings, simulated point clouds), the window's histogram vector
  (``input = "histogram"``, :func:`mdframework.pointcloud.histogram_vector`). Trained on a
  simulated group and tested on a real one (``cross_source``), the within-source result of the
  real group on the same input and classifier is the real-to-real reference in the same report.
- **Feature statistics**: mean and variance of every feature per group and label (like Table 2),
  and scatter plots of feature pairs (like Figure 12).

Outputs in DIR: ``report.md``; ``within_<group>_confusion.csv/png`` (mean and std);
``within_<group>_per_class.csv``; ``within_<group>_predictions.csv`` (split, record id, true and
predicted label of every test record); ``cross_confusion.csv/png``, ``cross_predictions.csv``;
``train_test_confusion.csv/png``, ``train_test_predictions.csv``; ``feature_stats.csv/md``;
``scatter_<f1>_<f2>.png``; ``summary.json``; and ``dataset/`` when the experiment built it.
"""

from __future__ import annotations

import csv
import hashlib
import io
import itertools
import json
import os
import warnings
from collections import Counter
from collections.abc import Callable, Collection, Sequence
from functools import partial
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, ValidationError, field_validator, model_validator

from . import limits
from .classify import (
    Selection,
    balanced_accuracy,
    confusion_counts,
    confusion_matrix,
    fit_predict,
    optimistic_select,
    wrapper_select,
)
from .config import blaming_overrides, format_validation_error, read_config_file
from .dataset import (
    INDEX,
    Dataset,
    build_dataset,
    load_dataset,
    load_dataset_config,
    record_arrays,
)
from .errors import ConfigError, DataFileError, MdfError, unnameable
from .features import FEATURE_NAMES
from .interfaces import Classifier
from .outdir import output_folder, safe_name
from .plugins import Registry, blame, default_registry, versions
from .pointcloud import histogram_vector, histogram_vector_names, velocity_bins
from .progress import note, progress_enabled, tqdm_bar
from .settings import StrictModel, Workers

#: every name an experiment writes in its folder (group names are made safe by ``safe_name``)
EXPERIMENT_FILES = (
    "report.md",
    "summary.json",
    "within_*",
    "cross_confusion.*",
    "cross_predictions.csv",
    "train_test_predictions.csv",
    "train_test_confusion.*",
    "feature_stats.*",
    "scatter_*.png",
    "scatter_*.pdf",
    "scatter_*.svg",
    "dataset",
)


class DatasetRef(StrictModel):
    """Which data: a dataset config to build (into DIR/dataset), or a built dataset."""

    config: Path | None = Field(None, description="Dataset config file to build.")
    path: Path | None = Field(None, description="Folder of an already built dataset.")

    @field_validator("config", "path")
    @classmethod
    def _nameable(cls, value: Path | None) -> Path | None:
        why = None if value is None else unnameable(value)
        if why is not None:
            raise ValueError(why)
        return value

    @model_validator(mode="after")
    def _one(self) -> DatasetRef:
        if (self.config is None) == (self.path is None):
            raise ValueError("give exactly one of dataset.config and dataset.path")
        return self


class SelectionConfig(StrictModel):
    """Feature selection."""

    method: Literal["wrapper", "none"] = Field(
        "wrapper", description="wrapper: subsets scored by CV on the training split; none: all."
    )
    sizes: list[Annotated[int, Field(ge=1, le=len(FEATURE_NAMES))]] = Field(
        [4], min_length=1, description="Subset sizes to try (the paper: 4 of 7)."
    )
    folds: int = Field(
        5,
        ge=2,
        le=100,
        description="The wrapper's cross-validation folds, at most: fewer where the smallest "
        "class has fewer training records (or, with inner_split = 'evaluation', where there "
        "are fewer recordings or groups).",
    )
    inner_split: Literal["record", "evaluation"] = Field(
        "record",
        description="What the wrapper's folds hold out: record: stratified folds of records; "
        "evaluation: what evaluation.split holds out (whole recordings with 'recording', whole "
        "evaluation.by values with 'groups'), so that no recording or subject is on both sides "
        "of a fold (needs two or more of them in every training split of each class it "
        "evaluates).",
    )
    optimistic: bool = Field(
        True, description="Also report the paper's optimistic selection on the test split."
    )


class EvaluationConfig(StrictModel):
    """How a group's records are split into training and test records: stratified random
    splits of the records (`record`), held-out recordings (`recording`), or cross-validation that
    holds out whole groups such as subjects (`groups`)."""

    repeats: int = Field(
        10,
        ge=1,
        le=10_000,
        description="Number of random splits (split = 'record', 'recording'; with 'recording' "
        "distinct splits, all of them, each once, where fewer exist).",
    )
    test_fraction: float = Field(
        0.4, gt=0, lt=1, description="Test share (the paper: 40 %; not used by split = 'groups')."
    )
    split: Literal["record", "recording", "groups"] = Field(
        "record",
        description="record: records are split at random (windows of one recording can land "
        "on both sides, which flatters the score); recording: whole recordings (source files) "
        "are held out, per class; groups: cross-validation that holds out whole values of the "
        "column `by` (e.g. leave-subjects-out).",
    )
    by: Literal["subject", "recording", "source", "dataset", "group", "file"] = Field(
        "subject", description="split = 'groups': the record column whose values are held out."
    )
    folds: int | None = Field(
        None,
        ge=2,
        le=10_000,
        description="split = 'groups': number of folds (GroupKFold); default: one fold per "
        "value (leave-one-out).",
    )


class CrossSourceConfig(StrictModel):
    """Train on one source group, test on another."""

    train: str = Field(description="Group used for training (e.g. 'kinect').")
    test: str = Field(description="Group used for testing (e.g. 'cmu').")
    label_map: dict[str, str] = Field(
        default_factory=dict, description="Rename labels before matching (e.g. jog = 'run')."
    )


Selector = dict[str, str | list[str]]


def selector_words(selector: Selector) -> str:
    """A record selector in words for titles and the report: ``{source = 'kinect', subject =
    ['s01', 's02']}`` -> ``source = kinect, subject = s01 or s02``."""
    return ", ".join(
        f"{column} = {' or '.join(value) if isinstance(value, list) else value}"
        for column, value in selector.items()
    )


class TrainTestConfig(StrictModel):
    """Train on one selection of records and test on another, selected by any record column
    (subject, recording, source, dataset, group, file, label)."""

    train: Selector = Field(
        description="Column -> value or list of values, e.g. {source = 'kinect'}; a record is "
        "selected when it matches every column."
    )
    test: Selector = Field(description="The same for the test records, e.g. {source = 'cmu'}.")
    label_map: dict[str, str] = Field(
        default_factory=dict, description="Rename labels before matching (e.g. jog = 'run')."
    )


class ReportConfig(StrictModel):
    """Plots."""

    scatter_pairs: list[tuple[str, str]] = Field(
        [("torso_mean", "upper_max"), ("lower_min", "total_bandwidth")],
        description="Feature pairs to scatter-plot.",
    )
    figure_formats: list[Literal["png", "pdf", "svg"]] = Field(
        ["png"],
        description="Formats of every figure: 'png' (shown in report.md), and also 'pdf' or "
        "'svg' (vector, text as text, for print).",
    )

    @field_validator("figure_formats")
    @classmethod
    def _png_included(cls, value: list[str]) -> list[str]:
        """report.md shows the PNGs: they are always written."""
        if "png" not in value:
            raise ValueError("must include 'png' (report.md shows the PNGs), e.g. ['png', 'pdf']")
        return list(dict.fromkeys(value))


class ExperimentConfig(StrictModel):
    """An experiment."""

    seed: int = Field(
        0,
        ge=0,
        le=2**32 - 1,
        description="Seed of the random splits, the wrapper's folds and the classifier "
        "(scikit-learn takes random states of 32 bits).",
    )
    dataset: DatasetRef
    input: Literal["features", "histogram"] = Field(
        "features",
        description="Classifier input: the seven features, or the per-frame Doppler histogram "
        "vector (histogram datasets only; feature selection must then be 'none').",
    )
    classifier: dict[str, Any] = Field(
        default_factory=lambda: {"kind": "knn"}, description="A [classifier] section."
    )
    selection: SelectionConfig = Field(default_factory=SelectionConfig)
    evaluation: EvaluationConfig = Field(default_factory=EvaluationConfig)
    cross_source: CrossSourceConfig | None = None
    train_test: TrainTestConfig | None = Field(
        None, description="Train on one selection of records, test on another."
    )
    report: ReportConfig = Field(default_factory=ReportConfig)
    workers: Workers | None = Field(None, description="Processes for building the dataset.")


def load_experiment_config(path: str | Path, overrides: Sequence[str] = ()) -> ExperimentConfig:
    """Read and validate an experiment config, with ``overrides`` (``KEY=VALUE``, the command
    line's ``--set``) applied; relative paths become relative to its folder."""
    p = Path(path)
    data = read_config_file(p, "experiment", overrides)
    with blaming_overrides(str(p), overrides):
        return _experiment_config(p, data)


def _experiment_config(p: Path, data: dict[str, Any]) -> ExperimentConfig:
    ds = data.get("dataset")
    if isinstance(ds, dict):
        data["dataset"] = {
            k: (str(p.parent / v) if k in ("config", "path") and isinstance(v, str) else v)
            for k, v in ds.items()
        }
    try:
        cfg = ExperimentConfig.model_validate(data)
    except ValidationError as exc:
        raise ConfigError(format_validation_error(exc, str(p), data, ExperimentConfig)) from None
    cs = cfg.cross_source
    if cs is not None and cs.train == cs.test:  # it would test on its own training records
        raise ConfigError(
            f"{p}: cross_source: train and test are the same group {cs.train!r}; name two "
            "groups (a within-source result of one group is always in the report)"
        )
    if cfg.input == "histogram" and cfg.selection.method != "none":
        raise ConfigError(f"{p}: input = 'histogram' needs selection.method = 'none'")
    for pair in cfg.report.scatter_pairs:
        for name in pair:
            if name not in FEATURE_NAMES:
                raise ConfigError(f"{p}: report.scatter_pairs: unknown feature {name!r}")
    return cfg


def classifier_factory(
    section: dict[str, Any],
    source: str,
    registry: Registry | None = None,
    *,
    allow_import: bool = False,
    seed: int | None = None,
) -> Callable[[], Classifier]:
    """A factory of fresh classifiers from a [classifier] section (validated once).

    ``allow_import`` (the command line's ``--allow-import``) lets a plugin accept import paths
    outside its allowlist (the validation context key ``allow_import``). ``seed`` (the
    experiment's seed) is set as :attr:`Classifier.seed` on every classifier made."""
    reg = registry or default_registry()
    kind = section.get("kind")
    if kind is None:
        installed = ", ".join(reg.names("classifier"))
        raise ConfigError(f"{source}: classifier.kind: required (installed: {installed})")
    try:
        cls = reg.get("classifier", str(kind))
    except KeyError as exc:
        raise ConfigError(f"{source}: classifier.kind: {exc.args[0]}") from None
    # a validator's exception other than pydantic's is the plugin's bug, named
    with blame(cls, "Config.model_validate"):
        try:
            cfg = cls.Config.model_validate(section, context={"allow_import": allow_import})
        except ValidationError as exc:
            raise ConfigError(
                format_validation_error(exc, source, section, cls.Config).replace(
                    f"{source}: ", f"{source}: classifier.", 1
                )
            ) from None

    def make() -> Classifier:
        with blame(cls, "__init__"):  # an exception there is the plugin's bug, named
            classifier: Classifier = cls(cfg)  # type: ignore[assignment]
        classifier.seed = seed
        return classifier

    return make


def _fit_predict(
    factory: Callable[[], Classifier],
    x_train: NDArray[np.float64],
    y_train: NDArray[Any],
    x_test: NDArray[np.float64],
    cols: tuple[int, ...],
) -> NDArray[Any]:
    return fit_predict(factory(), x_train[:, list(cols)], y_train, x_test[:, list(cols)])


def _select(
    cfg: ExperimentConfig,
    factory: Callable[[], Classifier],
    x: NDArray[np.float64],
    y: NDArray[Any],
    seed: int,
    counts: dict[str, int] | None = None,
    units: NDArray[Any] | None = None,
    unevaluated: Collection[str] = (),
) -> Selection:
    """The feature subset for training records ``x``, ``y``; ``counts``: each class's records
    in the whole source (for the error when a class has too few training records); ``units``
    (n_train,): what the evaluation holds out, per training record (its recording or its
    ``evaluation.by`` value), or None (records); ``unevaluated``: classes the evaluation does
    not evaluate (of one recording or ``by`` value), which the wrapper's folds holding out
    ``units`` leave out of their scores too instead of refusing them."""
    if cfg.selection.method == "none":
        return Selection(tuple(range(x.shape[1])), float("nan"))
    groups = None
    if cfg.selection.inner_split == "evaluation" and cfg.evaluation.split != "record":
        groups = units
    if groups is not None:
        what = "recording" if cfg.evaluation.split == "recording" else cfg.evaluation.by
        for label in sorted(set(y.tolist()) - set(unevaluated)):
            held = sorted(set(groups[y == label].tolist()))
            if len(held) < 2:
                raise ConfigError(
                    f"selection.inner_split = 'evaluation': class {label!r} has one {what} "
                    f"({held[0]!r}) among the training records of a split, so no fold of the "
                    f"wrapper that holds out whole {what}s can both train and test it: build "
                    f"records of more {what}s, or set selection.inner_split = 'record'"
                )
    labels, n_train = np.unique(y, return_counts=True)
    if n_train.min() < 2:
        small = str(labels[np.argmin(n_train)])
        total = (counts or {}).get(small, int(n_train.min()))
        raise ConfigError(
            f"selection.method = 'wrapper': class {small!r} has {n_train.min()} training "
            f"record of {total} records; the wrapper's cross-validation needs at least 2 "
            "training records of every class: build more records of it, or set "
            "selection.method = 'none'"
        )
    return wrapper_select(
        x,
        y,
        factory,
        sizes=cfg.selection.sizes,
        folds=cfg.selection.folds,
        seed=seed,
        groups=groups,
    )


def recording_splits(
    labels: NDArray[Any], recordings: NDArray[Any], repeats: int, test_fraction: float, seed: int
) -> list[tuple[NDArray[np.intp], NDArray[np.intp]]]:
    """Train/test index splits that hold out whole recordings: for every class, a random
    ``test_fraction`` of its recordings (at least one, and never all) goes to the test side.

    The splits are distinct: a draw that repeats an earlier split is drawn again, so that no
    split weighs twice in the mean. Where fewer than ``repeats`` distinct splits exist (3
    classes of 2 recordings: 2 * 2 * 2 = 8), every one of them is made, once
    (:func:`distinct_recording_splits` counts them)."""
    rng = np.random.default_rng(seed)
    classes = sorted(set(labels.tolist()))
    files = {c: sorted(set(recordings[labels == c].tolist())) for c in classes}
    for label, held in files.items():
        if len(held) < 2:
            raise MdfError(
                f"evaluation.split = 'recording': class {label!r} has only one recording"
            )
    n_test = {c: recordings_held_out(len(files[c]), test_fraction) for c in classes}

    def split(held: Sequence[Sequence[str]]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
        """The split holding out ``held[i]``, recordings of class ``classes[i]``."""
        test_mask = np.zeros(labels.shape[0], dtype=bool)
        for label, names in zip(classes, held, strict=True):
            test_mask |= (labels == label) & np.isin(recordings, list(names))
        return np.flatnonzero(~test_mask), np.flatnonzero(test_mask)

    if repeats >= distinct_recording_splits(labels, recordings, test_fraction):  # every one
        every = itertools.product(*(itertools.combinations(files[c], n_test[c]) for c in classes))
        return [split(chosen) for chosen in every]
    splits: list[tuple[NDArray[np.intp], NDArray[np.intp]]] = []
    seen: set[tuple[int, ...]] = set()
    while len(splits) < repeats:
        train, test = split([rng.permutation(files[c])[: n_test[c]].tolist() for c in classes])
        if tuple(test.tolist()) not in seen:
            seen.add(tuple(test.tolist()))
            splits.append((train, test))
    return splits


def distinct_recording_splits(
    labels: NDArray[Any], recordings: NDArray[Any], test_fraction: float
) -> int:
    """How many distinct splits :func:`recording_splits` can make: the product over the classes
    of the ways to choose the held-out recordings among each class's recordings."""
    from math import comb, prod

    counts = [len(set(recordings[labels == c].tolist())) for c in sorted(set(labels.tolist()))]
    return prod(comb(n, recordings_held_out(n, test_fraction)) for n in counts)


def recordings_held_out(n_recordings: int, test_fraction: float) -> int:
    """How many of a class's ``n_recordings`` a split holds out: ``test_fraction`` of them,
    rounded, at least one and never all."""
    return min(n_recordings - 1, max(1, round(test_fraction * n_recordings)))


def group_splits(
    groups: NDArray[Any], folds: int | None
) -> list[tuple[NDArray[np.intp], NDArray[np.intp]]]:
    """Cross-validation splits that hold out whole groups (e.g. subjects): one fold per group
    (leave-one-group-out) or ``folds`` folds of whole groups (GroupKFold)."""
    from sklearn.model_selection import GroupKFold, LeaveOneGroupOut

    values = sorted(set(groups.tolist()))
    if len(values) < 2:
        raise MdfError(f"split = 'groups' needs two or more groups, have {values}")
    if folds is not None and folds > len(values):
        raise MdfError(
            f"evaluation.folds = {folds} exceeds the {len(values)} groups {values}: lower "
            "evaluation.folds, or leave it out for one fold per group"
        )
    splitter = LeaveOneGroupOut() if folds is None else GroupKFold(n_splits=folds)
    x = np.zeros((groups.shape[0], 1))
    return [(tr, te) for tr, te in splitter.split(x, groups=groups)]


def select(table: dict[str, NDArray[Any]], selector: Selector, name: str) -> NDArray[np.bool_]:
    """Records matching every column of a selector (value or list of values)."""
    n = len(next(iter(table.values())))
    mask = np.ones(n, dtype=bool)
    for column, wanted in selector.items():
        if column not in table:
            raise MdfError(
                f"{name}: the dataset has no column {column!r} (have {', '.join(table)}); "
                "rebuild it to get subject, recording and dataset columns"
            )
        values = [wanted] if isinstance(wanted, str) else list(wanted)
        col = np.array([_text(v) for v in table[column]])
        mask &= np.isin(col, [str(v) for v in values])
    return mask


def _text(value: Any) -> str:
    """A table cell as text (numbers that are whole print without '.0')."""
    if isinstance(value, float | np.floating) and float(value).is_integer():
        return str(int(value))
    return str(value)


def held_out_units(ev: EvaluationConfig, data: Dataset) -> NDArray[np.str_]:
    """What ``ev.split`` holds out, per record (n_records,): its ``ev.by`` value with split =
    'groups', else its recording (the ``file`` column of a dataset built before the
    ``recording`` column)."""
    column = ev.by if ev.split == "groups" else "recording"
    if column == "recording" and column not in data.table:  # built before the column
        column = "file"
    if column not in data.table:
        raise MdfError(f"evaluation.by = {column!r}: the dataset has no such column; rebuild it")
    return np.array([_text(v) for v in data.table[column]])


def _units(cfg: ExperimentConfig, data: Dataset) -> NDArray[np.str_] | None:
    """:func:`held_out_units` where the wrapper's folds hold them out (``selection.inner_split
    = 'evaluation'`` beside a split of recordings or groups), else None (record folds)."""
    grouped = cfg.selection.method == "wrapper" and cfg.selection.inner_split == "evaluation"
    return held_out_units(cfg.evaluation, data) if grouped else None


def train_test(
    cfg: ExperimentConfig,
    factory: Callable[[], Classifier],
    data: Dataset,
    x: NDArray[np.float64] | None = None,
    names: Sequence[str] = FEATURE_NAMES,
) -> dict[str, Any]:
    """Train on one selection of records and test on another, over the shared (mapped)
    classes; records in both selections are an error. ``x``: the classifier input
    (n_records, n_columns) named by ``names``; default: the seven features."""
    tt = cfg.train_test
    assert tt is not None
    labels = np.array([tt.label_map.get(lab, lab) for lab in data.labels])
    train = select(data.table, tt.train, "train_test.train")
    test = select(data.table, tt.test, "train_test.test")
    for name, mask in (("train", train), ("test", test)):
        if not np.any(mask):
            raise MdfError(f"train_test.{name}: no record matches {getattr(tt, name)}")
    if np.any(train & test):
        raise MdfError(f"train_test: {int(np.sum(train & test))} records are in both selections")
    x = data.features if x is None else x
    return _train_then_test(
        cfg, factory, x, labels, train, test, names, "train_test: the selections", _units(cfg, data)
    )


class ExperimentWarning(UserWarning):
    """Something the experiment could not evaluate (shown on stderr; the report says it too)."""


def protocol(ev: EvaluationConfig) -> str:
    """The evaluation protocol in words, for the report's header."""
    pct = round(100 * ev.test_fraction)
    if ev.split == "groups":
        folds = f"one fold per {ev.by}" if ev.folds is None else f"{ev.folds} folds"
        return f"leave-{ev.by}s-out cross-validation ({folds}, each testing unseen {ev.by}s)"
    if ev.split == "recording":
        return (
            f"up to {ev.repeats} distinct random splits holding out {pct} % of every class's "
            "recordings (rounded, at least one, never all)"
        )
    return f"{ev.repeats} stratified random splits of the records, {100 - pct}/{pct}"


def _splits_words(ev: EvaluationConfig, n: int) -> str:
    """``n`` splits of the protocol, in words ('5 leave-subjects-out folds', '10 splits')."""
    if ev.split == "groups":
        return f"{n} leave-{ev.by}s-out fold" + ("s" if n != 1 else "")
    return f"{n} split" + ("s" if n != 1 else "")


def _caption_splits(ev: EvaluationConfig, n: int) -> str:
    """``n`` splits of the protocol for a figure's caption, which has no report header beside
    it to say how the records were split ('10 random splits holding out whole recordings')."""
    if ev.split == "groups":
        return _splits_words(ev, n)
    if ev.split == "recording" and n < ev.repeats:  # fewer exist: each made once, none drawn
        return f"all {n} distinct splits holding out whole recordings"
    how = "holding out whole recordings" if ev.split == "recording" else "of the records"
    return f"{n} random split" + ("s " if n != 1 else " ") + how


def _record_splits(
    ev: EvaluationConfig, x: NDArray[np.float64], y: NDArray[Any], seed: int
) -> list[tuple[NDArray[np.intp], NDArray[np.intp]]]:
    """``evaluation.split = 'record'``: stratified random splits; a class too small to be on
    both sides is a :class:`ConfigError` naming it."""
    from sklearn.model_selection import StratifiedShuffleSplit

    labels, counts = np.unique(y, return_counts=True)
    if counts.min() < 2:
        small = str(labels[np.argmin(counts)])
        raise ConfigError(
            f"evaluation.split = 'record': class {small!r} has {counts.min()} record; every "
            "class needs at least 2 (one to train on, one to test); build more records of it "
            "(its dataset source) or leave it out"
        )
    splitter = StratifiedShuffleSplit(
        n_splits=ev.repeats, test_size=ev.test_fraction, random_state=seed
    )
    try:
        return list(splitter.split(x, y))
    except ValueError as exc:  # e.g. fewer test records than classes
        raise ConfigError(
            f"evaluation.test_fraction = {ev.test_fraction}: {exc} ({len(y)} records of "
            f"{len(labels)} classes)"
        ) from None


def _not_testable(
    ev: EvaluationConfig, classes: list[str], y: NDArray[Any], held: NDArray[Any]
) -> dict[str, str]:
    """Classes that no split can test on an unseen recording or group (``held``, (n_records,):
    each record's recording or ``by`` value), and why."""
    if ev.split == "record":
        return {}
    what = "recording" if ev.split == "recording" else ev.by
    out = {}
    for c in classes:
        values = sorted(set(held[y == c].tolist()))
        if len(values) < 2 and ev.split == "recording":
            out[c] = (
                f"it has one recording only ({values[0]!r}), which cannot be held out: it is "
                "only trained on"
            )
        elif len(values) < 2:
            out[c] = (
                f"all its records are of one {what} ({values[0]!r}): every fold that tests it "
                "has no training record of it"
            )
    return out


def _too_few_classes(untested: dict[str, str]) -> MdfError:
    """The error of a source in which fewer than two classes can be scored (``untested``:
    class -> why not)."""
    return MdfError(
        "fewer than two classes can be evaluated: "
        + "; ".join(f"{c}: {why}" for c, why in untested.items())
    )


def pooled_scores(
    counts: NDArray[np.int64],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Per-class precision, recall and F1 (each (n_classes,)) of a matrix of counts (rows:
    true class, columns: predicted): the diagonal over the column sum, over the row sum, and
    their harmonic mean; NaN for a class with no test record (an empty row), 0 where the
    class is never predicted or never right (scikit-learn's ``zero_division=0``)."""
    c = counts.astype(np.float64)
    diag, tested, called = np.diagonal(c), c.sum(axis=1), c.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        precision = np.where(called > 0, diag / called, 0.0)
        recall = np.where(tested > 0, diag / tested, np.nan)
        total = precision + recall
        f1 = np.where(total > 0, 2 * precision * recall / total, 0.0)
    precision[tested == 0] = np.nan
    f1[tested == 0] = np.nan
    return precision, recall, f1


def within_source(
    cfg: ExperimentConfig,
    factory: Callable[[], Classifier],
    x: NDArray[np.float64],
    y: NDArray[Any],
    recordings: NDArray[Any] | None = None,
    names: Sequence[str] = FEATURE_NAMES,
    progress: str | None = None,
) -> dict[str, Any]:
    """Splits of one group's records by ``cfg.evaluation``; returns matrices and scores.
    ``recordings`` (n_records,) names each record's source file (``split = 'recording'``) or
    its ``by`` value (``split = 'groups'``); ``names`` the columns of ``x``; ``progress``: a
    progress bar with this label over the splits (on stderr), or none.

    A class is scored in a split only when the split both tests it and trains on it: the row of
    a class tested without a training record of it (its only subject held out) is left out of
    that split, not counted as 0. A class no split can score is listed in ``not_evaluated``
    with the reason; fewer than two scored classes is an :class:`MdfError`.

    ``balanced_accuracy_mean`` is the mean per-class recall of the reported matrix (the mean of
    the diagonal of ``confusion_mean`` over the scored classes). Its spread
    ``balanced_accuracy_std`` is the standard deviation over splits of each split's balanced
    accuracy when every split scores every class (then the mean of those equals
    ``balanced_accuracy_mean``), else (e.g. leave-subjects-out folds that hold one class only)
    the standard deviation over the scored classes of their recall;
    ``balanced_accuracy_std_over`` says which ("splits" or "classes");
    ``balanced_accuracy_per_split`` gives each split's (NaN: it scores no class).
    ``confusion_counts`` (int64) sums the splits' scored rows of counts; ``accuracy`` is its
    trace over its total; ``split_counts`` gives each split's training and test records per
    class."""
    classes = sorted(set(y.tolist()))
    ev = cfg.evaluation
    untested: dict[str, str] = {}
    held: dict[str, tuple[int, int]] = {}  # split = 'recording': class -> (held out, of)
    if ev.split == "groups":
        if recordings is None:
            raise MdfError(f"evaluation.split = 'groups' needs each record's {ev.by}")
        blank = int(np.sum(recordings == ""))
        if blank:  # records of unknown people would be held out together as one subject
            raise MdfError(
                f"evaluation.by = {ev.by!r}: {blank} of {len(recordings)} records have no "
                f"{ev.by}; give their dataset sources a {ev.by}"
            )
        splits = group_splits(recordings, ev.folds)
        untested = _not_testable(ev, classes, y, recordings)
    elif ev.split == "recording":
        if recordings is None:
            raise MdfError("evaluation.split = 'recording' needs each record's recording")
        untested = _not_testable(ev, classes, y, recordings)
        only_trained = np.isin(y, list(untested))
        testable, always = np.flatnonzero(~only_trained), np.flatnonzero(only_trained)
        some = recording_splits(
            y[testable], recordings[testable], ev.repeats, ev.test_fraction, cfg.seed
        )
        splits = [
            (np.sort(np.concatenate([testable[tr], always])), testable[te]) for tr, te in some
        ]
        for c in sorted(set(y[testable].tolist())):
            n = len(set(recordings[y == c].tolist()))
            held[c] = (recordings_held_out(n, ev.test_fraction), n)
    else:
        splits = _record_splits(ev, x, y, cfg.seed)
    if len(classes) - len(untested) < 2:
        raise _too_few_classes(untested)
    mats, optimistic, subsets, tested, tallies = [], [], [], [], []
    split_counts: list[dict[str, dict[str, int]]] = []  # per split: train/test records per class
    predictions: list[tuple[int, NDArray[np.intp], NDArray[Any]]] = []
    bar = tqdm_bar(
        splits,
        desc=progress,
        unit="split",
        disable=progress is None or not progress_enabled(),
        leave=False,
    )
    counts = {c: int(np.sum(y == c)) for c in classes}
    for rep, (train, test) in enumerate(bar):
        units = None if recordings is None else recordings[train]
        fold_seed = (cfg.seed + rep) % 2**32  # scikit-learn's random states are 32-bit
        sel = _select(cfg, factory, x[train], y[train], fold_seed, counts, units, untested)
        pred = _fit_predict(factory, x[train], y[train], x[test], sel.subset)
        predictions.append((rep, test, pred))
        trained = set(y[train].tolist())
        untrained = [i for i, c in enumerate(classes) if c not in trained]
        mat = confusion_matrix(y[test], pred, classes)
        mat[untrained] = np.nan
        mats.append(mat)
        split_counts.append(
            {
                side: {c: int(np.sum(y[idx] == c)) for c in classes}
                for side, idx in (("train", train), ("test", test))
            }
        )
        tally = confusion_counts(y[test], pred, classes)
        tally[untrained] = 0  # not scored, as the matrix's row
        tallies.append(tally)
        tested.append(np.isin(classes, y[test]))
        subsets.append([names[i] for i in sel.subset])
        if cfg.selection.optimistic and cfg.selection.method == "wrapper":
            opt = optimistic_select(
                x[train], y[train], x[test], y[test], factory, sizes=cfg.selection.sizes
            )
            # scored as the result is: its matrix, rows of classes not trained on left out
            best = _fit_predict(factory, x[train], y[train], x[test], opt.subset)
            opt_mat = confusion_matrix(y[test], best, classes)
            opt_mat[untrained] = np.nan
            optimistic.append(opt_mat)
    stack = np.stack(mats)  # (n_splits, n_classes, n_classes); NaN rows: class not scored
    scored: NDArray[np.bool_] = ~np.isnan(stack[:, :, 0])  # (n_splits, n_classes)
    rows: NDArray[np.bool_] = np.any(scored, axis=0)
    for i, c in enumerate(classes):
        if not rows[i] and c not in untested:
            untested[c] = (
                f"no split both trained on it and tested it ({_splits_words(ev, len(splits))})"
                + ("; raise evaluation.folds" if ev.split == "groups" else "")
            )
    if int(rows.sum()) < 2:
        raise _too_few_classes(untested)
    mean = np.full(stack.shape[1:], np.nan)
    std = np.full(stack.shape[1:], np.nan)
    mean[rows] = np.nanmean(stack[:, rows], axis=0)
    std[rows] = np.nanstd(stack[:, rows], axis=0)
    recall = np.diagonal(mean)[rows]
    opt_mean = None
    if optimistic:  # the same measure as the result: mean per-class recall of the mean matrix
        opt_stack = np.stack(optimistic)[:, rows]
        opt_mean = float(np.mean(np.diagonal(np.nanmean(opt_stack, axis=0)[:, rows])))
    diagonals = np.diagonal(stack, axis1=1, axis2=2)[:, rows]  # (n_splits, evaluated classes)
    per_split = np.full(len(stack), np.nan)  # each split's mean recall of the classes it scores
    some = ~np.all(np.isnan(diagonals), axis=1)
    per_split[some] = np.nanmean(diagonals[some], axis=1)
    if scored[:, rows].all():  # every split scores every class: spread over splits
        spread, over = float(np.std(per_split)), "splits"
    else:
        spread, over = float(np.std(recall)), "classes"
    counts_sum = np.sum(tallies, axis=0)
    counts_sum[~rows] = 0  # a class never scored: its row is not counted
    return {
        "classes": classes,
        "confusion_mean": mean,
        "confusion_std": std,
        "confusion_counts": counts_sum,
        "accuracy": float(np.trace(counts_sum) / counts_sum.sum()),
        "balanced_accuracy_mean": float(np.mean(recall)),
        "balanced_accuracy_std": spread,
        "balanced_accuracy_std_over": over,
        "balanced_accuracy_per_split": per_split.tolist(),
        "split_counts": split_counts,
        "n_splits": len(splits),
        "splits_tested": {c: int(n) for c, n in zip(classes, np.sum(tested, axis=0), strict=True)},
        "splits_scored": {c: int(scored[:, i].sum()) for i, c in enumerate(classes)},
        "not_evaluated": {c: untested[c] for c in classes if c in untested},
        "optimistic_accuracy_mean": opt_mean,
        "subsets": subsets,
        "n_records": len(y),
        "class_counts": counts,
        "predictions": predictions,
        "recordings_held_out": {c: list(v) for c, v in held.items()},
        "repeats": ev.repeats if ev.split != "groups" else len(splits),
    }


def cross_source(
    cfg: ExperimentConfig,
    factory: Callable[[], Classifier],
    data: Dataset,
    x: NDArray[np.float64] | None = None,
    names: Sequence[str] = FEATURE_NAMES,
) -> dict[str, Any]:
    """Train on one group, test on another, over the shared (mapped) classes. ``x``: the
    classifier input (n_records, n_columns) named by ``names``; default: the seven features."""
    cs = cfg.cross_source
    assert cs is not None
    labels = np.array([cs.label_map.get(lab, lab) for lab in data.labels])
    train = data.groups == cs.train
    test = data.groups == cs.test
    for name, mask in (("train", train), ("test", test)):
        if not np.any(mask):
            groups = ", ".join(sorted(set(data.groups.tolist())))
            group = getattr(cs, name)
            raise MdfError(f"cross_source.{name}: no records of group {group!r} (have {groups})")
    x = data.features if x is None else x
    return _train_then_test(
        cfg, factory, x, labels, train, test, names, "cross_source: the groups", _units(cfg, data)
    )


def _train_then_test(
    cfg: ExperimentConfig,
    factory: Callable[[], Classifier],
    x: NDArray[np.float64],
    labels: NDArray[Any],
    train: NDArray[np.bool_],
    test: NDArray[np.bool_],
    names: Sequence[str],
    who: str,
    units: NDArray[Any] | None,
) -> dict[str, Any]:
    """Select features and fit on the ``train`` records (mask), predict the ``test`` records,
    over the classes both hold (``who`` names the two sides in the error when they share
    fewer than two). ``x`` (n_records, n_columns) named by ``names``; ``labels`` (n_records,);
    ``units`` (n_records,): what the wrapper's folds hold out (:func:`held_out_units`), or None.
    ``left_out``: each class of one side only, with its record count (its test records are not
    scored; its training records are not trained on, so no test record can be called it)."""
    shared = sorted(set(labels[train].tolist()) & set(labels[test].tolist()))
    if len(shared) < 2:
        raise MdfError(f"{who} share fewer than two classes ({shared})")
    left_out = {}
    for c in sorted(set(labels[train | test].tolist()) - set(shared)):
        n_train, n_test = int(np.sum(labels[train] == c)), int(np.sum(labels[test] == c))
        left_out[c] = (
            f"{n_test} test record{'s' if n_test != 1 else ''} not scored: no training record of it"
            if n_test
            else f"{n_train} training record{'s' if n_train != 1 else ''} left out of "
            "training: no test record of it"
        )
    train = train & np.isin(labels, shared)
    test = test & np.isin(labels, shared)
    sel = _select(
        cfg,
        factory,
        x[train],
        labels[train],
        cfg.seed,
        units=None if units is None else units[train],
    )
    pred = _fit_predict(factory, x[train], labels[train], x[test], sel.subset)
    counts = confusion_counts(labels[test], pred, shared)
    return {
        "classes": shared,
        "confusion": confusion_matrix(labels[test], pred, shared),
        "confusion_counts": counts,
        "accuracy": float(np.trace(counts) / counts.sum()),
        "balanced_accuracy": balanced_accuracy(labels[test], pred),
        "subset": [names[i] for i in sel.subset],
        "train_counts": {c: int(np.sum(labels[train] == c)) for c in shared},
        "test_counts": {c: int(np.sum(labels[test] == c)) for c in shared},
        "left_out": left_out,
        "test_index": np.flatnonzero(test),
        "true": labels[test],
        "predicted": pred,
    }


def feature_statistics(data: Dataset) -> list[dict[str, Any]]:
    """Mean and variance of each feature per (group, label), like the paper's Table 2."""
    rows = []
    for group in sorted(set(data.groups.tolist())):
        for label in sorted(set(data.labels[data.groups == group].tolist())):
            sel = (data.groups == group) & (data.labels == label)
            f = data.features[sel]
            row: dict[str, Any] = {"group": group, "label": label, "n": int(sel.sum())}
            for i, name in enumerate(FEATURE_NAMES):
                row[f"{name}_mean"] = float(f[:, i].mean())
                row[f"{name}_var"] = float(f[:, i].var(ddof=1)) if len(f) > 1 else float("nan")
            rows.append(row)
    return rows


def _csv(rows: list[dict[str, Any]]) -> str:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue()


def _matrix_rows(classes: list[str], matrix: NDArray[np.float64]) -> list[dict[str, Any]]:
    return [
        {"true": c, **{p: round(float(v), 6) for p, v in zip(classes, row, strict=True)}}
        for c, row in zip(classes, matrix, strict=True)
    ]


def _stats_markdown(rows: list[dict[str, Any]]) -> str:
    cols = [f"{r['label']} ({r['group']}, n={r['n']})" for r in rows]
    lines = [
        "| feature | " + " | ".join(cols) + " |",
        "|---|" + "---|" * len(cols),
    ]
    for name in FEATURE_NAMES:
        cells = [f"{r[f'{name}_mean']:.4g} ({r[f'{name}_var']:.3g})" for r in rows]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "mean [m/s] (variance [(m/s)²])\n\n" + "\n".join(lines) + "\n"


def classifier_inputs(
    cfg: ExperimentConfig, data_dir: Path
) -> tuple[Dataset, NDArray[np.float64], list[str]]:
    """The dataset, the classifier input (n_records, n_columns) and the columns' names."""
    if cfg.input == "features":
        data = load_dataset(data_dir, spectrograms=False)
        bad = np.argwhere(~np.isfinite(data.features))
        if bad.size:  # an index.csv edited by hand: one line naming it, not an internal error
            row, col = (int(v) for v in bad[0])
            raise DataFileError(
                Path(data_dir) / INDEX,
                f"record {data.table['id'][row]}: {FEATURE_NAMES[col]} is "
                f"{data.features[row, col]}, not a finite number ({len(bad)} such values); "
                "rebuild the dataset or remove the record",
                row + 2,
            )
        return data, data.features, list(FEATURE_NAMES)
    data = load_dataset(data_dir, spectrograms=False)  # the index; the records one by one:
    ids = data.table["id"]
    widths: set[int] = set()  # each record reduced to its vector, never all histograms at once
    vectors, velocity = [], None
    read = record_arrays(Path(data_dir), ids, ("velocity_mps", "histograms"))
    for rid, arrays in zip(ids, read, strict=True):
        h = arrays.get("histograms")
        if h is None:
            raise MdfError(
                f"input = 'histogram': record {rid} has no histograms (build simulated "
                "records with representation = 'histogram')"
            )
        velocity = arrays["velocity_mps"] if velocity is None else velocity
        widths.add(h.shape[1])
        vectors.append(histogram_vector(h.astype(np.float64)))
    if len(widths) != 1:
        raise MdfError(f"input = 'histogram': records have different bin counts {widths}")
    x = np.stack(vectors)
    assert velocity is not None
    n_bins = widths.pop()
    width = float(velocity[1] - velocity[0]) if n_bins > 1 else 1.0
    centres, _ = velocity_bins(width, n_bins)
    return data, x, list(histogram_vector_names(centres))


def selected_features_markdown(subsets: Sequence[Sequence[str]], method: str) -> list[str]:
    """Report lines saying which inputs feature selection chose: how often each was chosen over
    the splits, and the most frequent subset."""
    if method == "none" or not subsets:
        return ["Inputs: all (no feature selection).", ""]
    counts = Counter(name for subset in subsets for name in subset)
    per_feature = ", ".join(f"{name} {n}" for name, n in counts.most_common())
    best, times = Counter(tuple(s) for s in subsets).most_common(1)[0]
    return [
        f"Selected features (times chosen in {len(subsets)} splits): {per_feature}; most "
        f"frequent subset: {', '.join(best)} ({times} of {len(subsets)}).",
        "",
    ]


def run_experiment(
    cfg: ExperimentConfig,
    out_dir: Path,
    *,
    source: str = "<experiment>",
    progress: bool = True,
    registry: Registry | None = None,
    force: bool = False,
    staging_dir: Path | str | None = None,
    allow_import: bool = False,
    scheduler: str | None = None,
) -> dict[str, Any]:
    """Build or load the dataset, run the experiments, write the report. ``out_dir`` follows
    the rules of :mod:`mdframework.outdir` (``force``, ``staging_dir``); a dataset the
    experiment builds goes to ``out_dir/dataset`` (resumable, see :func:`build_dataset`, with
    the config's ``workers`` and the Dask ``scheduler``). ``allow_import``: see
    :func:`classifier_factory`."""
    with output_folder(
        out_dir, "experiment", EXPERIMENT_FILES, force=force, staging_dir=staging_dir
    ) as folder:
        factory = classifier_factory(
            cfg.classifier, source, registry, allow_import=allow_import, seed=cfg.seed
        )
        if cfg.dataset.config is not None:
            dcfg, base = load_dataset_config(cfg.dataset.config)
            data_dir = folder.path / "dataset"
            if not folder.previous:  # a rerun after a stop (a full disk, a time limit) is ours
                folder.write_marker()  # and resumes the build; the report's files come later
            try:
                build_dataset(
                    dcfg,
                    base,
                    data_dir,
                    workers=cfg.workers,
                    scheduler=scheduler,
                    progress=progress,
                    force=force,
                )
            except ConfigError as exc:  # a field of the dataset config: named in its file
                named = str(cfg.dataset.config)
                if str(exc).startswith(named):
                    raise
                raise ConfigError(f"{named}: {exc}") from exc
        else:
            assert cfg.dataset.path is not None
            data_dir = cfg.dataset.path
        note(f"loading the dataset {data_dir}", progress)
        data, x_all, names = classifier_inputs(cfg, data_dir)
        stage = folder.stage()
        summary = _report(cfg, factory, data, x_all, names, data_dir, stage, progress, registry)
        folder.commit(stage, keep=("dataset",))  # a built dataset is never deleted
    return summary


def _report(
    cfg: ExperimentConfig,
    factory: Callable[[], Classifier],
    data: Dataset,
    x_all: NDArray[np.float64],
    names: list[str],
    data_dir: Path,
    out: Path,
    progress: bool = True,
    registry: Registry | None = None,
) -> dict[str, Any]:
    """Run the experiments on ``data`` (classifier inputs ``x_all`` named ``names``) and write
    every report file into ``out``. The figures are drawn together at the end, once every number
    is computed (matplotlib loads only then). ``summary.json`` ends with the experiment's config
    (``config``, every default filled in, the dataset's path absolute: it repeats the
    experiment) and the software's ``versions`` (:func:`mdframework.plugins.versions` of
    ``registry``)."""
    from .figures import plot_confusion, plot_feature_scatter

    figures: list[Callable[[], None]] = []  # drawn at the end
    extra = tuple(f for f in cfg.report.figure_formats if f != "png")  # also written

    index = limits.read_file_bytes(Path(data_dir) / INDEX)
    settings = _classifier_settings(factory, cfg.classifier)  # every default filled in
    summary: dict[str, Any] = {
        "dataset": str(data_dir),
        # which dataset: its index names every record (an id digests what makes its arrays)
        "dataset_index_sha256": hashlib.sha256(index).hexdigest(),
        "n_records": len(data.labels),
        "within": {},
        "cross": None,
    }
    report = [
        "# Experiment report",
        "",
        f"Dataset: `{data_dir}` ({len(data.labels)} records).",
        f"Input: {cfg.input}. Classifier: `{json.dumps(settings)}`; selection: "
        f"{cfg.selection.method} (sizes {cfg.selection.sizes}); "
        f"evaluation: {protocol(cfg.evaluation)}.",
        "",
    ]
    source = cfg.dataset.config.name if cfg.dataset.config is not None else Path(data_dir).name
    caption = (
        f"dataset {source} ({len(data.labels)} records); input {cfg.input}; classifier "
        f"{json.dumps(cfg.classifier)}; selection {cfg.selection.method}"
    )
    skipped: list[str] = []  # warnings, given once something else is evaluated
    for group in sorted(set(data.groups.tolist())):
        mask = data.groups == group
        if len(set(data.labels[mask].tolist())) < 2:
            continue
        try:
            res = within_source(
                cfg,
                factory,
                x_all[mask],
                data.labels[mask],
                held_out_units(cfg.evaluation, data)[mask],
                names,
                progress=f"within {group}" if progress else None,
            )
        except ConfigError:  # the config is wrong for every source: the experiment fails
            raise
        except MdfError as exc:  # e.g. more folds than subjects
            skipped.append(f"within-source {group}: not evaluated: {exc}")
            report += [f"## Within-source: {group}", "", f"Not evaluated: {exc}.", ""]
            summary["within"][group] = {"skipped": str(exc)}
            continue
        classes = res["classes"]
        splits = _splits_words(cfg.evaluation, res["n_splits"])
        rows = _rows_scored_words(res, cfg.evaluation)
        for c, why in res["not_evaluated"].items():
            warnings.warn(
                f"within-source {group}: class {c!r} not evaluated: {why}",
                ExperimentWarning,
                stacklevel=2,
            )
        stem = f"within_{safe_name(group)}"
        (out / f"{stem}_confusion.csv").write_text(
            _csv(_matrix_rows(classes, res["confusion_mean"])),
            encoding="utf-8",
        )
        (out / f"{stem}_confusion_std.csv").write_text(
            _csv(_matrix_rows(classes, res["confusion_std"])),
            encoding="utf-8",
        )
        counts = res["confusion_counts"]
        (out / f"{stem}_confusion_counts.csv").write_text(
            _csv(
                [
                    {"true": c, **dict(zip(classes, map(int, row), strict=True))}
                    for c, row in zip(classes, counts, strict=True)
                ]
            ),
            encoding="utf-8",
        )
        precision, recall, f_score = pooled_scores(counts)
        (out / f"{stem}_per_class.csv").write_text(
            _csv(
                [
                    {
                        "class": c,
                        "n": res["class_counts"][c],
                        "rate_mean": float(res["confusion_mean"][i, i]),
                        "rate_std": float(res["confusion_std"][i, i]),
                        "splits_scored": res["splits_scored"][c],
                        "test_records": int(counts[i].sum()),
                        "precision": float(precision[i]),
                        "recall": float(recall[i]),
                        "f1": float(f_score[i]),
                    }
                    for i, c in enumerate(classes)
                ]
            ),
            encoding="utf-8",
        )
        figures.append(
            partial(
                plot_confusion,
                out / f"{stem}_confusion.png",
                classes,
                res["confusion_mean"],
                res["confusion_std"],
                title=f"{group}: within-source",
                caption=f"{caption}; mean ± std over "
                f"{_caption_splits(cfg.evaluation, res['n_splits'])}{rows}",
                also=extra,
            )
        )
        ids, truth = data.table["id"][mask], data.labels[mask]
        (out / f"{stem}_predictions.csv").write_text(
            _csv(
                [
                    {"split": split, "id": ids[i], "true": truth[i], "predicted": p}
                    for split, test, pred in res["predictions"]
                    for i, p in zip(test, pred, strict=True)
                ]
            ),
            encoding="utf-8",
        )
        summary["within"][group] = {
            k: v
            for k, v in res.items()
            if k not in ("confusion_mean", "confusion_std", "confusion_counts", "predictions")
        }
        summary["within"][group]["confusion_mean"] = res["confusion_mean"].tolist()
        summary["within"][group]["confusion_std"] = res["confusion_std"].tolist()
        summary["within"][group]["confusion_counts"] = counts.tolist()
        opt = res["optimistic_accuracy_mean"]
        report += [
            f"## Within-source: {group}",
            "",
            f"Balanced accuracy {res['balanced_accuracy_mean']:.3f} "
            f"({_spread_words(res, splits, rows)}); classes and records: "
            f"{res['class_counts']}.",
            "",
            *_not_evaluated_markdown(res, splits),
            *_held_out_markdown(res),
            _markdown_matrix(classes, res["confusion_mean"], res["confusion_std"]),
            "",
            *selected_features_markdown(res["subsets"], cfg.selection.method),
        ]
        if opt is not None:
            report += [
                f"Optimistic (paper's method, subset chosen on the test split, an upper "
                f"bound, not a fair estimate): {opt:.3f}.",
                "",
            ]
        report += [f"![confusion]({stem}_confusion.png)", ""]
    if cfg.cross_source is not None:
        res = cross_source(cfg, factory, data, x_all, names)
        (out / "cross_confusion.csv").write_text(
            _csv(_matrix_rows(res["classes"], res["confusion"])),
            encoding="utf-8",
        )
        figures.append(
            partial(
                plot_confusion,
                out / "cross_confusion.png",
                res["classes"],
                res["confusion"],
                None,
                title=f"train {cfg.cross_source.train} -> test {cfg.cross_source.test}",
                caption=f"{caption}; features {res['subset']}",
                also=extra,
            )
        )
        _write_predictions(out / "cross_predictions.csv", data, res)
        summary["cross"] = _without_predictions(res)
        report += [
            f"## Cross-source: train {cfg.cross_source.train}, test {cfg.cross_source.test}",
            "",
            f"Balanced accuracy {res['balanced_accuracy']:.3f}; inputs {res['subset']}; "
            f"training {res['train_counts']}, test {res['test_counts']}.",
            "",
            *_left_out_markdown(res, "cross-source"),
            "Per-class rates (test records of each class classified correctly): "
            + ", ".join(f"{c} {res['confusion'][i, i]:.2f}" for i, c in enumerate(res["classes"]))
            + ".",
            "",
            _markdown_matrix(res["classes"], res["confusion"], None),
            "",
            "![cross](cross_confusion.png)",
            "",
        ]
    if cfg.train_test is not None:
        res = train_test(cfg, factory, data, x_all, names)
        (out / "train_test_confusion.csv").write_text(
            _csv(_matrix_rows(res["classes"], res["confusion"])),
            encoding="utf-8",
        )
        plot_confusion(
            out / "train_test_confusion.png",
            res["classes"],
            res["confusion"],
            None,
            title=f"train {selector_words(cfg.train_test.train)} -> test "
            f"{selector_words(cfg.train_test.test)}",
            caption=f"{caption}; features {res['subset']}",
            also=extra,
        )
        _write_predictions(out / "train_test_predictions.csv", data, res)
        summary["train_test"] = _without_predictions(res)
        report += [
            f"## Train on {selector_words(cfg.train_test.train)}, test on "
            f"{selector_words(cfg.train_test.test)}",
            "",
            f"Balanced accuracy {res['balanced_accuracy']:.3f}; features {res['subset']}; "
            f"training {res['train_counts']}, test {res['test_counts']}.",
            "",
            *_left_out_markdown(res, "train_test"),
            _markdown_matrix(res["classes"], res["confusion"], None),
            "",
            "![train/test](train_test_confusion.png)",
            "",
        ]
    evaluated = [g for g, res in summary["within"].items() if "skipped" not in res]
    if not evaluated and cfg.cross_source is None and cfg.train_test is None:
        raise ConfigError(_nothing_evaluated(cfg.evaluation, summary["within"]))
    for message in skipped:
        warnings.warn(message, ExperimentWarning, stacklevel=2)
    note("feature statistics and figures", progress)
    stats = feature_statistics(data)
    (out / "feature_stats.csv").write_text(_csv(stats), encoding="utf-8")
    md = _stats_markdown(stats)
    (out / "feature_stats.md").write_text(md, encoding="utf-8")
    report += ["## Feature statistics", "", md, ""]
    for f1, f2 in cfg.report.scatter_pairs:
        name = f"scatter_{f1}_{f2}.png"
        figures.append(
            partial(
                plot_feature_scatter,
                out / name,
                data.features[:, FEATURE_NAMES.index(f1)],
                data.features[:, FEATURE_NAMES.index(f2)],
                data.labels,
                data.groups,
                f1,
                f2,
                title=f"{f1} vs {f2}",
                caption=caption,
                also=extra,
            )
        )
        report += [f"![{f1} vs {f2}]({name})", ""]
    for draw in figures:
        draw()
    (out / "report.md").write_text("\n".join(report), encoding="utf-8")
    config = cfg.model_dump(mode="json")  # its dataset read from any folder, not only this one
    config["dataset"] = {k: v and os.path.abspath(v) for k, v in config["dataset"].items()}
    config["classifier"] = settings
    summary["config"] = config
    import importlib.metadata

    # the figures' renderer too (the numbers do not depend on it)
    summary["versions"] = {
        **versions(registry),
        "matplotlib": importlib.metadata.version("matplotlib"),
    }
    (out / "summary.json").write_text(
        json.dumps(_strict_json(summary), indent=2, default=str, allow_nan=False) + "\n",
        encoding="utf-8",
    )
    return summary


def _classifier_settings(
    factory: Callable[[], Classifier], section: dict[str, Any]
) -> dict[str, Any]:
    """The [classifier] section with every default of its plugin filled in (the validated
    plugin config a classifier holds as ``config``), so that summary.json names the
    hyper-parameters the run used; ``section`` as given for a plugin that keeps no such
    config."""
    from pydantic import BaseModel

    settings = getattr(factory(), "config", None)
    if isinstance(settings, BaseModel):
        return {**section, **settings.model_dump(mode="json")}
    return section


def _write_predictions(path: Path, data: Dataset, res: dict[str, Any]) -> None:
    """One row per test record of a train/test result: its id, true (mapped) and predicted
    label."""
    ids = data.table["id"][res["test_index"]]
    rows = [
        {"id": i, "true": t, "predicted": p}
        for i, t, p in zip(ids, res["true"], res["predicted"], strict=True)
    ]
    path.write_text(_csv(rows), encoding="utf-8")


def _without_predictions(res: dict[str, Any]) -> dict[str, Any]:
    """A train/test result for summary.json: the matrix as lists, the per-record predictions
    left to their CSV file."""
    kept = {k: v for k, v in res.items() if k not in ("test_index", "true", "predicted")}
    return {
        **kept,
        "confusion": res["confusion"].tolist(),
        "confusion_counts": res["confusion_counts"].tolist(),
    }


def _strict_json(value: Any) -> Any:
    """``value`` with every NaN or infinite number (a matrix row of a class not evaluated) as
    None, so that summary.json is JSON that every reader takes (null), not Python's NaN."""
    if isinstance(value, float):
        return value if np.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _strict_json(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_strict_json(v) for v in value]
    return value


def _nothing_evaluated(ev: EvaluationConfig, within: dict[str, dict[str, Any]]) -> str:
    """The error of an experiment with nothing to report: no group could be evaluated within
    its source (``within``: group -> its result or its reason), and there is no cross-source or
    train/test part."""
    if not within:
        return (
            "nothing to evaluate: no group of the dataset has two or more classes, and there is "
            "no [cross_source] or [train_test]"
        )
    reasons = "; ".join(f"{g}: {res['skipped']}" for g, res in within.items())
    return f"evaluation.split = {ev.split!r}: nothing could be evaluated (within-source {reasons})"


def _rows_scored_words(res: dict[str, Any], ev: EvaluationConfig) -> str:
    """Words to follow 'mean ± std over N splits' where some evaluated class is not scored in
    every split: each row of the matrix is over the splits that score its class, so many."""
    scored = {c: k for c, k in res["splits_scored"].items() if c not in res["not_evaluated"]}
    if all(k == res["n_splits"] for k in scored.values()):
        return ""
    what = "folds" if ev.split == "groups" else "splits"
    counts = ", ".join(f"{c} {k}" for c, k in scored.items())
    return f" (each row over the {what} that score its class: {counts})"


def _spread_words(res: dict[str, Any], splits: str, rows: str = "") -> str:
    """What a within-source balanced accuracy is and what its spread is, in words; ``rows``:
    :func:`_rows_scored_words`."""
    std = res["balanced_accuracy_std"]
    if res["balanced_accuracy_std_over"] == "splits":
        return f"std {std:.3f} over {splits}; the mean per-class recall of the matrix below"
    return (
        f"std {std:.3f} over the classes' recalls, as not every split scores every class; the "
        f"mean per-class recall of the matrix below, mean ± std over {splits}{rows}"
    )


def _left_out_markdown(res: dict[str, Any], part: str) -> list[str]:
    """Report lines naming the classes a train/test result leaves out (of one side only: the
    score is over the shared classes), each also a warning on stderr naming ``part``."""
    left = res["left_out"]
    for c, why in left.items():
        warnings.warn(
            f"{part}: class {c!r} left out (not on both sides): {why}",
            ExperimentWarning,
            stacklevel=3,
        )
    if not left:
        return []
    words = "; ".join(f"{c} ({why})" for c, why in left.items())
    return [
        f"Left out (on one side only; the score is over the classes both sides hold): {words}.",
        "",
    ]


def _held_out_markdown(res: dict[str, Any]) -> list[str]:
    """The report line saying how many recordings of each class a split held out (the share
    ``test_fraction`` asks for, rounded, at least one and never all)."""
    held = res.get("recordings_held_out") or {}
    if not held:
        return []
    words = ", ".join(f"{c} {k} of {n}" for c, (k, n) in held.items())
    n, repeats = res["n_splits"], res.get("repeats", res["n_splits"])
    every = (
        f" These allow {n} distinct splits only, and each is made once (not {repeats} splits, "
        "some of them repeated)."
        if n < repeats
        else ""
    )
    return [f"Recordings held out in every split: {words}.{every}", ""]


def _not_evaluated_markdown(res: dict[str, Any], splits: str) -> list[str]:
    """Report lines naming the classes a within-source result does not score (and why), and
    those scored in only some of the splits that tested them."""
    lines = [f"Not evaluated: {c} ({why})." for c, why in res["not_evaluated"].items()]
    tested = res["splits_tested"]
    partial = {
        c: k
        for c, k in res["splits_scored"].items()
        if 0 < k < tested[c] and c not in res["not_evaluated"]
    }
    if partial:
        lines.append(
            f"Not scored in every split that tests them (of {splits}; a split that tests a "
            "class without training on it does not score it): "
            + ", ".join(f"{c} scored in {k} of {tested[c]}" for c, k in partial.items())
            + "."
        )
    return [*lines, ""] if lines else []


def _markdown_matrix(
    classes: list[str], mean: NDArray[np.float64], std: NDArray[np.float64] | None
) -> str:
    lines = ["| true \\ predicted | " + " | ".join(classes) + " |", "|---|" + "---|" * len(classes)]
    for i, c in enumerate(classes):
        cells = [
            "n/a"
            if np.isnan(mean[i, j])
            else f"{mean[i, j]:.2f}" + (f" ± {std[i, j]:.2f}" if std is not None else "")
            for j in range(len(classes))
        ]
        lines.append(f"| {c} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
