"""Wrap any scikit-learn classifier, chosen by its import path in the config::

    [classifier]
    kind = "sklearn"
    estimator = "sklearn.svm.SVC"
    params = { C = 10.0, gamma = "scale" }

Features are standardised with training statistics (zero-variance guarded) unless
``standardize = false``.
"""

from __future__ import annotations

import importlib
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, field_validator

from mdframework import Classifier, PluginConfig
from mdframework.classify import Standardizer


def _import(path: str) -> Any:
    module, _, name = path.rpartition(".")
    if not module:
        raise ValueError(f"{path!r} is not a dotted import path such as 'sklearn.svm.SVC'")
    try:
        return getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError) as exc:
        raise ValueError(f"cannot import {path!r}: {exc}") from None


class SklearnConfig(PluginConfig):
    """A scikit-learn estimator."""

    kind: Literal["sklearn"] = "sklearn"
    estimator: str = Field(
        description="Import path, e.g. 'sklearn.ensemble.RandomForestClassifier'."
    )
    params: dict[str, Any] = Field(default_factory=dict, description="Constructor arguments.")
    standardize: bool = Field(True, description="z-score features with training statistics.")

    @field_validator("estimator")
    @classmethod
    def _check(cls, value: str) -> str:
        est = _import(value)
        if not (hasattr(est, "fit") and hasattr(est, "predict")):
            raise ValueError(f"{value!r} has no fit/predict: not a classifier")
        return value


class SklearnClassifier(Classifier):
    """Any scikit-learn classifier (SVM, random forest, ...) behind the Classifier interface."""

    name = "sklearn"
    Config = SklearnConfig
    config: SklearnConfig

    def fit(self, features: NDArray[np.float64], labels: NDArray[Any]) -> SklearnClassifier:
        """Fit the estimator on (optionally standardised) features."""
        x = np.asarray(features, dtype=np.float64)
        self.scaler_ = Standardizer.fit(x) if self.config.standardize else None
        self.model_ = _import(self.config.estimator)(**self.config.params)
        self.model_.fit(self._scale(x), np.asarray(labels))
        return self

    def _scale(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        return self.scaler_.transform(x) if self.scaler_ is not None else x

    def predict(self, features: NDArray[np.float64]) -> NDArray[Any]:
        """Predicted labels."""
        return np.asarray(self.model_.predict(self._scale(np.asarray(features, np.float64))))
