"""k-nearest neighbours with explicit, deterministic rules for every degenerate case.

- **Standardisation**: z-scores with the training data's mean and standard deviation only; a
  zero-variance feature is only centred (``mdframework.classify.Standardizer``).
- **Neighbours**: an exact brute-force search over all training samples, vectorised over the
  queries. Euclidean distances are summed feature by feature in column order and square-rooted,
  as a k-d tree does; other metrics go through scikit-learn's ``pairwise_distances``. Candidates
  are ranked by distance as a stable sort ranks them, so **distance ties** are broken by training
  order (the earlier sample wins), documented and repeatable; only the k nearest are sorted
  (:func:`nearest_columns`), and the queries go in blocks, so that time grows as
  n_queries x n_samples and memory with the block, not with n_queries x n_samples.
- **Vote ties**: among the classes with the most votes, the one whose closest member among the
  k neighbours is nearest wins (``tie_rule = "nearest"``, the default); ``"lowest"`` picks the
  alphabetically first class, as ``argmax`` over sorted labels would.
- **NaN or infinite features** (in ``fit`` or ``predict``): ``ValueError`` naming the first such
  row (they would make every distance NaN).
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, field_validator

from mdframework import Classifier, ConfigError, PluginConfig
from mdframework.classify import Standardizer

#: Queries per block: queries x training samples x features stays near this many (4 MiB of
#: float64), so that a block's (queries, training samples) arrays, summed feature by feature,
#: stay small enough for the processor's cache (a quarter less time than 32 MiB blocks at 12,000
#: training samples of 7 features).
_BLOCK_ELEMENTS = 1 << 19


def _finite(features: NDArray[np.float64]) -> NDArray[np.float64]:
    """``features`` as float64; ``ValueError`` naming the first row with a NaN or infinite
    value (one would make every distance NaN, and every answer the first class)."""
    x = np.asarray(features, dtype=np.float64)
    bad = ~np.isfinite(x)
    if np.any(bad):
        row = int(np.argwhere(bad)[0][0])
        raise ValueError(f"features have NaN or infinite values (first in row {row})")
    return x


def nearest_columns(d: NDArray[np.float64], k: int) -> NDArray[np.intp]:
    """The columns of the ``k`` smallest values of every row of ``d`` (n_rows, n_columns), in
    order, equal values by column: ``np.argsort(d, axis=1, kind="stable")[:, :k]``, without
    sorting whole rows. A partition finds each row's k-th smallest value; a row with exactly k
    values at most that large keeps them (sorted stably among themselves), and a row with more
    (values equal to the k-th: a tie at the cut) or with NaN among its k smallest is sorted
    whole, as before."""
    n_rows, n_columns = d.shape
    if k >= n_columns or n_rows == 0:
        return np.argsort(d, axis=1, kind="stable")[:, :k]
    kth = np.partition(d, k - 1, axis=1)[:, k - 1 : k]  # (n_rows, 1)
    near = d <= kth  # False at NaN: a row whose k-th is NaN has fewer than k
    exact = np.count_nonzero(near, axis=1) == k
    out = np.empty((n_rows, k), dtype=np.intp)
    if np.any(exact):
        cols = np.nonzero(near[exact])[1].reshape(-1, k)  # in column order
        rank = np.argsort(np.take_along_axis(d[exact], cols, 1), axis=1, kind="stable")
        out[exact] = np.take_along_axis(cols, rank, 1)
    if not np.all(exact):
        out[~exact] = np.argsort(d[~exact], axis=1, kind="stable")[:, :k]
    return out


class KnnConfig(PluginConfig):
    """k-nearest-neighbour classifier."""

    kind: Literal["knn"] = "knn"
    k: int = Field(5, ge=1, le=10_000, description="Number of neighbours.")
    metric: str = Field(
        "euclidean",
        description="Distance: a scikit-learn metric name that needs no parameters and takes "
        "real values (not seuclidean, mahalanobis, precomputed, haversine or the metrics of "
        "boolean data such as jaccard).",
    )
    tie_rule: Literal["nearest", "lowest"] = Field(
        "nearest",
        description="Vote ties: the tied class with the nearest member, or the first label.",
    )

    @field_validator("metric")
    @classmethod
    def _known_metric(cls, value: str) -> str:
        """A metric scikit-learn computes between queries and training samples without more
        parameters, so that a misspelt name stops before any fit (not as an error of the
        plugin at its first prediction)."""
        if value == "euclidean":
            return value
        from sklearn.metrics.pairwise import PAIRWISE_BOOLEAN_FUNCTIONS
        from sklearn.neighbors import VALID_METRICS

        # seuclidean and mahalanobis need variances the plugin does not take, precomputed a
        # distance matrix, haversine two columns of angles; the boolean metrics (jaccard...)
        # would turn the standardised features into booleans, all of them True
        unusable = {"seuclidean", "mahalanobis", "precomputed", "haversine"}
        usable = sorted(set(VALID_METRICS["brute"]) - unusable - set(PAIRWISE_BOOLEAN_FUNCTIONS))
        if value not in usable:
            raise ValueError(f"{value!r} is not one of the metrics {', '.join(usable)}")
        return value


class Knn(Classifier):
    """k-nearest neighbours on standardised features (k = 5 by default)."""

    name = "knn"
    Config = KnnConfig
    config: KnnConfig

    def fit(self, features: NDArray[np.float64], labels: NDArray[Any]) -> Knn:
        """Store the standardised training data (n_samples, n_features) and labels."""
        x = _finite(features)
        if x.ndim != 2 or x.shape[0] != len(labels):
            raise ValueError("features must be (n_samples, n_features) with one label each")
        if self.config.k > x.shape[0]:  # every record would vote: the largest class wins
            raise ConfigError(
                f"classifier.k: {self.config.k} neighbours, but this fit has only {x.shape[0]} "
                "training records (cross-validation folds hold fewer than the whole training "
                "split): lower k"
            )
        self.scaler_ = Standardizer.fit(x)
        self.labels_ = np.asarray(labels)
        # classes in sorted order; codes_ (n_samples,) indexes them
        self.classes_, self.codes_ = np.unique(self.labels_, return_inverse=True)
        self.train_ = self.scaler_.transform(x)
        return self

    def _distances(self, z: NDArray[np.float64]) -> NDArray[np.float64]:
        """Distances (n_queries, n_samples) of standardised queries to the training set."""
        train = self.train_
        if self.config.metric != "euclidean":
            from sklearn.metrics import pairwise_distances

            return np.asarray(pairwise_distances(z, train, metric=self.config.metric))
        sq = np.zeros((z.shape[0], train.shape[0]))
        diff = np.empty_like(sq)
        for j in range(train.shape[1]):  # column by column, in order (as a k-d tree sums)
            np.subtract(z[:, j, None], train[None, :, j], out=diff)
            np.multiply(diff, diff, out=diff)
            sq += diff
        return np.sqrt(sq, out=sq)

    def neighbours(self, features: NDArray[np.float64]) -> tuple[NDArray[Any], NDArray[Any]]:
        """Distances and training indices of the k nearest neighbours, (n_queries, k) each,
        ordered by distance, ties by training order."""
        n_train, n_feat = self.train_.shape
        k = self.config.k  # at most n_train (checked by fit)
        z = self.scaler_.transform(_finite(features))
        step = max(1, _BLOCK_ELEMENTS // max(1, n_train * n_feat))
        dist = np.empty((z.shape[0], k))
        idx = np.empty((z.shape[0], k), dtype=np.intp)
        for lo in range(0, z.shape[0], step):
            d = self._distances(z[lo : lo + step])
            order = nearest_columns(d, k)
            idx[lo : lo + step] = order
            dist[lo : lo + step] = np.take_along_axis(d, order, 1)
        return dist, idx

    def predict(self, features: NDArray[np.float64]) -> NDArray[Any]:
        """Majority vote of the k nearest neighbours with the documented tie rule."""
        _, idx = self.neighbours(features)
        votes = self.codes_[idx]  # (n_queries, k) class codes, nearest first
        n_q, n_classes = votes.shape[0], self.classes_.shape[0]
        counts = np.zeros((n_q, n_classes), dtype=np.intp)
        np.add.at(counts, (np.arange(n_q)[:, None], votes), 1)
        tied = counts == counts.max(axis=1, keepdims=True)  # (n_queries, n_classes)
        if self.config.tie_rule == "lowest":
            winner = np.argmax(tied, axis=1)  # the first tied class in sorted order
        else:  # the class of the first (nearest) neighbour whose class is among the tied
            first = np.argmax(np.take_along_axis(tied, votes, 1), axis=1)
            winner = votes[np.arange(n_q), first]
        return np.asarray(self.classes_[winner])
