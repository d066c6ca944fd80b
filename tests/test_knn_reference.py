"""The vectorised kNN against the per-query implementation it replaced, on real feature data.

The reference below is the plugin's previous algorithm, kept verbatim in spirit: scikit-learn's
``NearestNeighbors`` (a k-d tree here), a stable ranking by (distance, training index) and a
per-query vote with ``np.unique``. The features are those of the CMU example dataset
(``tests/data/cmu_features.csv``, see PROVENANCE.md there): envelope features sit on the
velocity-bin grid, so exact distance ties and vote ties occur often, and single features or
pairs of them tie more still.
"""

from __future__ import annotations

import csv
import itertools
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from mdf_knn import Knn
from numpy.typing import NDArray
from sklearn.model_selection import StratifiedKFold
from sklearn.neighbors import NearestNeighbors

from mdframework.classify import Standardizer
from mdframework.features import FEATURE_NAMES

DATA = Path(__file__).parent / "data" / "cmu_features.csv"


def reference_predict(
    x_train: NDArray[np.float64],
    y_train: NDArray[Any],
    x_test: NDArray[np.float64],
    k: int,
    tie_rule: str,
) -> NDArray[Any]:
    """The previous per-query kNN (scikit-learn neighbours, np.unique votes)."""
    scaler = Standardizer.fit(x_train)
    nn = NearestNeighbors(algorithm="auto").fit(scaler.transform(x_train))
    n_train = len(y_train)
    k = min(k, n_train)
    z = scaler.transform(x_test)
    dist, idx = nn.kneighbors(z, n_neighbors=n_train)  # every candidate, then a stable rank
    order = np.lexsort((idx, dist), axis=1)[:, :k]
    idx = np.take_along_axis(idx, order, 1)
    out = []
    for row in idx:
        votes = y_train[row]
        classes, counts = np.unique(votes, return_counts=True)
        tied = classes[counts == counts.max()]
        if tied.size == 1 or tie_rule == "lowest":
            out.append(tied[0])
        else:
            out.append(next(v for v in votes if v in set(tied)))
    return np.asarray(out)


@pytest.fixture(scope="module")
def cmu() -> tuple[NDArray[np.float64], NDArray[np.str_]]:
    with DATA.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    x = np.array([[float(r[n]) for n in FEATURE_NAMES] for r in rows])
    return x, np.array([r["label"] for r in rows])


@pytest.mark.parametrize("tie_rule", ["nearest", "lowest"])
@pytest.mark.parametrize("k", [1, 4, 5, 8])
def test_identical_predictions_on_real_features(
    cmu: tuple[NDArray[np.float64], NDArray[np.str_]], k: int, tie_rule: str
) -> None:
    x, y = cmu
    assert len(y) == 280
    subsets = [
        *itertools.combinations(range(7), 1),
        *itertools.combinations(range(7), 2),
        *list(itertools.combinations(range(7), 4))[::5],
        tuple(range(7)),
    ]
    folds = list(StratifiedKFold(3, shuffle=True, random_state=k).split(x, y))
    n_vote_ties = n_distance_ties = 0
    for cols in subsets:
        for train, test in folds:
            xt, xs = x[train][:, list(cols)], x[test][:, list(cols)]
            model = Knn(Knn.Config(k=k, tie_rule=tie_rule)).fit(xt, y[train])  # type: ignore[arg-type]
            got = model.predict(xs)
            want = reference_predict(xt, y[train], xs, k, tie_rule)
            np.testing.assert_array_equal(got, want)
            # ties at the cut (k-th and (k+1)-th neighbour equidistant): training order decides
            wider = Knn(Knn.Config(k=k + 1)).fit(xt, y[train])  # type: ignore[arg-type]
            dist, idx = wider.neighbours(xs)
            n_distance_ties += int(np.sum(dist[:, k - 1] == dist[:, k]))
            votes = y[train][idx[:, :k]]
            counts = np.sort(np.stack([np.sum(votes == c, axis=1) for c in np.unique(y)]), 0)
            n_vote_ties += int(np.sum(counts[-1] == counts[-2]))
    # the hard cases were exercised, not only clear majorities
    assert n_distance_ties > 100
    if k > 1:
        assert n_vote_ties > 100


@pytest.mark.parametrize("algorithm", ["brute", "kd_tree"])
@pytest.mark.parametrize("k", [1, 5])
def test_lowest_rule_equals_scikit_learn_except_at_distance_ties(
    cmu: tuple[NDArray[np.float64], NDArray[np.str_]], k: int, algorithm: str
) -> None:
    """``tie_rule = "lowest"`` predicts what scikit-learn's KNeighborsClassifier predicts on the
    same standardised inputs (its vote ties go to the first class in sorted order too), except
    where the k-th and (k+1)-th neighbours are equidistant: scikit-learn keeps either of them,
    depending on its algorithm, the plugin the earlier training record."""
    from sklearn.neighbors import KNeighborsClassifier

    x, y = cmu
    n_same = n_differ = 0
    for cols in [*itertools.combinations(range(7), 2), tuple(range(7))]:
        for train, test in StratifiedKFold(3, shuffle=True, random_state=k).split(x, y):
            xt, xs = x[train][:, list(cols)], x[test][:, list(cols)]
            scaler = Standardizer.fit(xt)
            sk = KNeighborsClassifier(k, algorithm=algorithm).fit(scaler.transform(xt), y[train])
            want = sk.predict(scaler.transform(xs))
            got = Knn(Knn.Config(k=k, tie_rule="lowest")).fit(xt, y[train]).predict(xs)  # type: ignore[arg-type]
            dist, _ = Knn(Knn.Config(k=k + 1)).fit(xt, y[train]).neighbours(xs)  # type: ignore[arg-type]
            at_cut = np.isclose(dist[:, k - 1], dist[:, k], rtol=1e-9, atol=1e-12)
            np.testing.assert_array_equal(got[~at_cut], want[~at_cut])
            n_same += int(np.sum(~at_cut))
            n_differ += int(np.sum(got[at_cut] != want[at_cut]))
    assert n_same > 5000 and n_differ > 0  # the rule differs where it is documented to


def test_nearest_columns_equal_a_whole_stable_sort() -> None:
    """The partial ranking gives the first k columns of a stable sort of every row, whatever
    the ties (at the cut, below it, whole rows equal), NaN and infinite values."""
    from mdf_knn.knn import nearest_columns

    rng = np.random.default_rng(7)
    n_cut_ties = 0
    for trial in range(2000):
        n_rows, n_cols = int(rng.integers(1, 30)), int(rng.integers(1, 50))
        k = int(rng.integers(1, n_cols + 1))
        d = np.round(rng.random((n_rows, n_cols)) * rng.integers(1, 6))  # few distinct values
        if trial % 3 == 0:
            d = rng.random((n_rows, n_cols))
        if trial % 7 == 0:
            d[rng.random(d.shape) < 0.2] = np.nan
        if trial % 11 == 0:
            d[rng.random(d.shape) < 0.2] = np.inf
        if trial % 13 == 0:
            d[:] = 1.0
        want = np.argsort(d, axis=1, kind="stable")[:, :k]
        np.testing.assert_array_equal(nearest_columns(d, k), want)
        if k < n_cols:
            ordered = np.sort(d, axis=1)
            n_cut_ties += int(np.sum(ordered[:, k - 1] == ordered[:, k]))
    assert n_cut_ties > 1000


@pytest.mark.parametrize("metric", ["euclidean", "manhattan"])
@pytest.mark.parametrize("k", [1, 5, 8])
def test_neighbours_in_blocks_equal_one_whole_sort(
    cmu: tuple[NDArray[np.float64], NDArray[np.str_]],
    k: int,
    metric: str,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Neighbours found block by block of queries (a block of a few queries here) are those of
    one stable sort of the whole (queries, training records) distance matrix, distances and
    indices, on the CMU features' single features and pairs, where ties at the cut abound."""
    import mdf_knn.knn

    x, y = cmu
    train, test = np.arange(0, len(y), 3), np.setdiff1d(np.arange(len(y)), np.arange(0, len(y), 3))
    n_cut_ties = 0
    for cols in [*itertools.combinations(range(7), 1), *itertools.combinations(range(3), 2)]:
        xt, xs = x[train][:, list(cols)], x[test][:, list(cols)]
        model = Knn(Knn.Config(k=k, metric=metric)).fit(xt, y[train])  # type: ignore[arg-type]
        whole = model._distances(model.scaler_.transform(xs))  # (n_test, n_train)
        order = np.argsort(whole, axis=1, kind="stable")
        monkeypatch.setattr(mdf_knn.knn, "_BLOCK_ELEMENTS", 7 * len(train) * len(cols))
        dist, idx = model.neighbours(xs)
        np.testing.assert_array_equal(idx, order[:, :k])
        np.testing.assert_array_equal(dist, np.take_along_axis(whole, order[:, :k], 1))
        ranked = np.take_along_axis(whole, order[:, : k + 1], 1)
        n_cut_ties += int(np.sum(ranked[:, k - 1] == ranked[:, k]))
    assert n_cut_ties > 50


def test_neighbours_memory_follows_the_block_not_the_query_count() -> None:
    """The queries go in blocks of about 4 MiB of (queries x training samples x features)
    float64, so 6,000 queries against 3,000 training samples of 7 features (a whole distance
    matrix of 137 MiB) allocate under 6 MiB at their peak (measured 2.5 MiB; blocks eight
    times larger, or sized without the feature count, take 13 to 15 MiB), with the neighbours
    of one stable sort of each query's distances."""
    import tracemalloc

    rng = np.random.default_rng(0)
    xt = rng.normal(size=(3000, 7))
    y = np.array(["a", "b", "c"])[rng.integers(0, 3, 3000)]
    xs = rng.normal(size=(6000, 7))
    model = Knn(Knn.Config(k=5)).fit(xt, y)  # type: ignore[arg-type]
    tracemalloc.start()
    try:
        dist, idx = model.neighbours(xs)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 6 * 2**20
    few = model._distances(model.scaler_.transform(xs[:50]))
    order = np.argsort(few, axis=1, kind="stable")[:, :5]
    np.testing.assert_array_equal(idx[:50], order)
    np.testing.assert_array_equal(dist[:50], np.take_along_axis(few, order, 1))
