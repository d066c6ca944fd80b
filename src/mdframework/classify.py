"""Classification helpers: standardisation, wrapper feature selection, confusion matrices.

Everything here works with any :class:`~mdframework.interfaces.Classifier` (fit/predict) through a
factory, so the selection and evaluation code never depends on a particular classifier.
"""

from __future__ import annotations

import itertools
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .interfaces import Classifier
from .plugins import blame

FloatArray = NDArray[np.float64]
ClassifierFactory = Callable[[], Classifier]


def fit_predict(
    classifier: Classifier, x_train: FloatArray, y_train: NDArray[Any], x_test: FloatArray
) -> NDArray[Any]:
    """``classifier`` fitted on ``x_train`` (n, n_features) and ``y_train`` (n,), and its
    labels (m,) of ``x_test`` (m, n_features), as an array. An exception from the plugin's
    ``fit`` or ``predict`` names it (:func:`mdframework.plugins.blame`), and so does a
    ``fit`` that returns no classifier, or a ``predict`` that gives other than one label per
    row or a label ``y_train`` does not hold (a wrong result, else scored without a word)."""
    with blame(classifier, "fit"):
        fitted = classifier.fit(x_train, y_train)
        if not isinstance(fitted, Classifier):
            raise TypeError(f"fit() returned {type(fitted).__name__}, not the classifier")
    with blame(classifier, "predict"):
        return _labels(fitted.predict(x_test), x_test.shape[0], y_train)


def _labels(predicted: Any, n_rows: int, y_train: NDArray[Any]) -> NDArray[Any]:
    """``predicted`` as an array when it is one label per row of the ``n_rows``, each one of
    the training labels ``y_train``; else a ``TypeError`` or ``ValueError`` saying what came."""
    if predicted is None:
        raise TypeError(f"predict() returned None, not {n_rows} labels")
    labels = np.asarray(predicted)
    if labels.shape != (n_rows,):
        raise ValueError(
            f"predict() returned labels of shape {labels.shape}, not ({n_rows},): one per row"
        )
    known = set(np.asarray(y_train).tolist())
    unknown = sorted({repr(v) for v in labels.tolist() if v not in known})
    if unknown:
        raise ValueError(
            f"predict() returned labels it was not trained on: {', '.join(unknown[:3])}"
            f"{' ...' if len(unknown) > 3 else ''} (trained on: "
            f"{', '.join(sorted(repr(v) for v in known))})"
        )
    return labels


@dataclass(frozen=True)
class Standardizer:
    """z-scores with statistics of the training data only.

    A feature whose training standard deviation is below ``1e-12 * max(1, |mean|)`` (e.g. the
    torso velocity on a treadmill) is only centred (its scale is set to 1), never divided by 0.
    """

    mean: FloatArray
    scale: FloatArray

    @classmethod
    def fit(cls, features: FloatArray) -> Standardizer:
        """Statistics of ``features`` (n_samples, n_features)."""
        x = np.asarray(features, dtype=np.float64)
        mean = x.mean(axis=0)
        std = x.std(axis=0)
        degenerate = std <= 1e-12 * np.maximum(1.0, np.abs(mean))
        return cls(mean, np.where(degenerate, 1.0, std))

    def transform(self, features: FloatArray) -> FloatArray:
        """Standardised features, same shape."""
        return np.asarray((np.asarray(features, np.float64) - self.mean) / self.scale)


def balanced_accuracy(y_true: NDArray[np.str_], y_pred: NDArray[np.str_]) -> float:
    """Mean over the true classes of the per-class recall (robust to unequal class sizes)."""
    classes = np.unique(y_true)
    return float(np.mean([np.mean(y_pred[y_true == c] == c) for c in classes]))


def confusion_counts(
    y_true: NDArray[Any], y_pred: NDArray[Any], classes: Sequence[str]
) -> NDArray[np.int64]:
    """The confusion matrix of counts (n_classes, n_classes), int64: row = true class, column =
    predicted class, each cell the number of test records (a prediction outside ``classes`` is
    not counted)."""
    idx = {c: i for i, c in enumerate(classes)}
    counts = np.zeros((len(classes), len(classes)), dtype=np.int64)
    for t, p in zip(np.asarray(y_true).tolist(), np.asarray(y_pred).tolist(), strict=True):
        if t in idx and p in idx:
            counts[idx[t], idx[p]] += 1
    return counts


def confusion_matrix(
    y_true: NDArray[np.str_], y_pred: NDArray[np.str_], classes: Sequence[str]
) -> FloatArray:
    """Row-normalised confusion matrix (n_classes, n_classes): row = true class, column =
    predicted class; rows of classes absent from ``y_true`` are NaN."""
    counts = confusion_counts(y_true, y_pred, classes).astype(np.float64)
    totals = np.array([np.sum(y_true == c) for c in classes], dtype=np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(counts / totals[:, None])


@dataclass(frozen=True)
class Selection:
    """Result of a feature-subset search: the chosen subset (feature indices), its score, and
    the score of every subset tried."""

    subset: tuple[int, ...]
    score: float
    scores: dict[tuple[int, ...], float] = field(default_factory=dict)


def _subsets(n_features: int, sizes: Sequence[int]) -> list[tuple[int, ...]]:
    out: list[tuple[int, ...]] = []
    for size in sizes:
        out += list(itertools.combinations(range(n_features), size))
    return out


def _best(scores: dict[tuple[int, ...], float]) -> tuple[tuple[int, ...], float]:
    # highest score; then fewer features; then the lexicographically first subset
    subset = min(scores, key=lambda s: (-scores[s], len(s), s))
    return subset, scores[subset]


def _checked(features: FloatArray, labels: NDArray[np.str_]) -> tuple[FloatArray, NDArray[Any]]:
    """Features as a finite (n_samples, n_features) float64 array with one label each: checked
    once, so that the selection loops can tell scikit-learn to skip its own repeated checks."""
    x = np.asarray(features, dtype=np.float64)
    y = np.asarray(labels)
    if x.ndim != 2 or x.shape[0] != y.shape[0]:
        raise ValueError("features must be (n_samples, n_features) with one label each")
    if not np.all(np.isfinite(x)):
        raise ValueError("features contain NaN or infinite values")
    return x, y


def _score_subsets(
    folds: Sequence[tuple[FloatArray, NDArray[Any], FloatArray, NDArray[Any]]],
    make_classifier: ClassifierFactory,
    subsets: Sequence[tuple[int, ...]],
) -> dict[tuple[int, ...], float]:
    """Mean balanced accuracy over ``folds`` (train x, train y, test x, test y) of every subset,
    with scikit-learn's per-call finiteness checks off (the inputs were checked once)."""
    from sklearn import config_context

    scores: dict[tuple[int, ...], float] = {}
    with config_context(assume_finite=True):
        for subset in subsets:
            cols = list(subset)
            accs = [
                balanced_accuracy(
                    y_te, fit_predict(make_classifier(), x_tr[:, cols], y_tr, x_te[:, cols])
                )
                for x_tr, y_tr, x_te, y_te in folds
            ]
            scores[subset] = float(np.mean(accs))
    return scores


def wrapper_select(
    features: FloatArray,
    labels: NDArray[np.str_],
    make_classifier: ClassifierFactory,
    *,
    sizes: Sequence[int] = (4,),
    folds: int = 5,
    seed: int = 0,
    groups: NDArray[Any] | None = None,
) -> Selection:
    """Wrapper feature selection by cross-validation on the given (training) data only: every
    subset of the given sizes is scored by its mean balanced accuracy over the folds. The caller
    passes only training data, so the test split is never seen.

    Without ``groups``: stratified k-fold over records (``folds``, at most the smallest class's
    record count). With ``groups`` (n_samples,), e.g. each record's subject or recording: the
    folds hold out whole groups (scikit-learn's ``StratifiedGroupKFold``, at most one fold per
    group), so that records of one group are never on both sides; a fold scores only the
    classes it also trains on (a class whose every group is held out is left out of that fold,
    not counted as 0)."""
    x, y = _checked(features, labels)
    if groups is None:
        from sklearn.model_selection import StratifiedKFold

        n_folds = min(int(folds), int(np.unique(y, return_counts=True)[1].min()))
        if n_folds < 2:
            raise ValueError("wrapper selection needs at least two training samples per class")
        splits = StratifiedKFold(n_folds, shuffle=True, random_state=seed).split(x, y)
    else:
        from sklearn.model_selection import StratifiedGroupKFold

        g = np.asarray(groups)
        if g.shape != y.shape:
            raise ValueError("groups must hold one value per training sample")
        n_folds = min(int(folds), len(np.unique(g)))
        if n_folds < 2:
            raise ValueError("grouped wrapper selection needs at least two groups")
        with warnings.catch_warnings():  # a class in fewer groups is in fewer folds, as meant
            warnings.filterwarnings("ignore", "The least populated class", UserWarning)
            splits = list(
                StratifiedGroupKFold(n_folds, shuffle=True, random_state=seed).split(x, y, g)
            )
    data = []
    for train, test in splits:
        scored = test[np.isin(y[test], y[train])]  # classes this fold also trains on
        if scored.size:
            data.append((x[train], y[train], x[scored], y[scored]))
    if not data:
        raise ValueError("no fold of the wrapper's cross-validation tests a class it trains on")
    scores = _score_subsets(data, make_classifier, _subsets(x.shape[1], sizes))
    subset, score = _best(scores)
    return Selection(subset, score, scores)


def optimistic_select(
    train_features: FloatArray,
    train_labels: NDArray[np.str_],
    test_features: FloatArray,
    test_labels: NDArray[np.str_],
    make_classifier: ClassifierFactory,
    *,
    sizes: Sequence[int] = (4,),
) -> Selection:
    """The paper's variant: the subset scoring best **on the test data**. Its accuracy is an
    optimistic upper bound and is reported separately, clearly labelled."""
    x_tr, y_tr = _checked(train_features, train_labels)
    x_te, y_te = _checked(test_features, test_labels)
    scores = _score_subsets(
        [(x_tr, y_tr, x_te, y_te)], make_classifier, _subsets(x_tr.shape[1], sizes)
    )
    subset, score = _best(scores)
    return Selection(subset, score, scores)
