"""k-nearest neighbours with explicit, deterministic rules for every degenerate case.

- **Standardisation**: z-scores with the training data's mean and standard deviation only; a
  zero-variance feature is only centred (``mdframework.classify.Standardizer``).
- **Neighbours**: scikit-learn's ``NearestNeighbors`` (tree or brute search, Euclidean by
  default). Candidates are ranked by distance with a stable sort, so **distance ties** are
  broken by training order (the earlier sample wins), documented and repeatable.
- **Vote ties**: among the classes with the most votes, the one whose closest member among the
  k neighbours is nearest wins (``tie_rule = "nearest"``, the default); ``"lowest"`` picks the
  alphabetically first class, as ``argmax`` over sorted labels would.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field
from sklearn.neighbors import NearestNeighbors

from mdframework import Classifier, PluginConfig
from mdframework.classify import Standardizer


class KnnConfig(PluginConfig):
    """k-nearest-neighbour classifier."""

    kind: Literal["knn"] = "knn"
    k: int = Field(5, ge=1, le=10_000, description="Number of neighbours.")
    metric: str = Field("euclidean", description="Distance (any scikit-learn metric name).")
    tie_rule: Literal["nearest", "lowest"] = Field(
        "nearest",
        description="Vote ties: the tied class with the nearest member, or the first label.",
    )


class Knn(Classifier):
    """k-nearest neighbours on standardised features (k = 5 by default)."""

    name = "knn"
    Config = KnnConfig
    config: KnnConfig

    def fit(self, features: NDArray[np.float64], labels: NDArray[Any]) -> Knn:
        """Store the standardised training data (n_samples, n_features) and labels."""
        x = np.asarray(features, dtype=np.float64)
        if x.ndim != 2 or x.shape[0] != len(labels):
            raise ValueError("features must be (n_samples, n_features) with one label each")
        self.scaler_ = Standardizer.fit(x)
        self.labels_ = np.asarray(labels)
        self.nn_ = NearestNeighbors(algorithm="auto", metric=self.config.metric)
        self.nn_.fit(self.scaler_.transform(x))
        return self

    def neighbours(self, features: NDArray[np.float64]) -> tuple[NDArray[Any], NDArray[Any]]:
        """Distances and training indices of the k nearest neighbours, (n_queries, k) each,
        ordered by distance, ties by training order."""
        n_train = self.labels_.shape[0]
        k = min(self.config.k, n_train)
        z = self.scaler_.transform(features)
        # a few spare neighbours reveal distance ties at the k-th place; rows whose ties reach
        # past the spares are searched again over the whole training set
        n_ask = min(n_train, k + 8)
        dist, idx = self.nn_.kneighbors(z, n_neighbors=n_ask, return_distance=True)
        if n_ask < n_train:
            redo = np.flatnonzero(dist[:, k - 1] >= dist[:, -1])
            if redo.size:
                d_all, i_all = self.nn_.kneighbors(z[redo], n_neighbors=n_train)
                order = np.lexsort((i_all, d_all), axis=1)[:, :n_ask]
                dist[redo] = np.take_along_axis(d_all, order, 1)
                idx[redo] = np.take_along_axis(i_all, order, 1)
        order = np.lexsort((idx, dist), axis=1)[:, :k]
        return np.take_along_axis(dist, order, 1), np.take_along_axis(idx, order, 1)

    def predict(self, features: NDArray[np.float64]) -> NDArray[Any]:
        """Majority vote of the k nearest neighbours with the documented tie rule."""
        _, idx = self.neighbours(np.asarray(features, dtype=np.float64))
        out = []
        for row in idx:
            votes = self.labels_[row]
            classes, counts = np.unique(votes, return_counts=True)
            tied = classes[counts == counts.max()]
            if tied.size == 1 or self.config.tie_rule == "lowest":
                out.append(tied[0])
            else:  # the first neighbour (nearest) whose class is among the tied
                out.append(next(v for v in votes if v in set(tied)))
        return np.asarray(out)
