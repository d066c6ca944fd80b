"""Wrap a scikit-learn classifier, chosen by its import path in the config::

    [classifier]
    kind = "sklearn"
    estimator = "sklearn.svm.SVC"
    params = { C = 10.0, gamma = "scale" }

Only scikit-learn's own classifiers are accepted (the ones ``sklearn.utils.all_estimators``
lists as classifiers, named by a public ``sklearn.`` module path): importing a module runs its
code, so a config shared by someone else must not be able to name any module it likes. Another
import path needs the command-line flag ``mdf experiment --allow-import`` (passed to validation as
the context key ``allow_import``).

Features are standardised with training statistics (zero-variance guarded) unless
``standardize = false``. An estimator that takes ``random_state`` gets the experiment's seed
(:attr:`mdframework.Classifier.seed`) there, unless ``params`` sets ``random_state`` itself.
"""

from __future__ import annotations

import importlib
import inspect
import math
from functools import lru_cache
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, ValidationInfo, field_validator, model_validator

from mdframework import Classifier, PluginConfig
from mdframework.classify import Standardizer

#: Validation-context key that allows any import path (set by ``--allow-import``).
ALLOW_IMPORT = "allow_import"
#: How a Python caller allows it (the refusals' messages say so).
_IN_PYTHON = (
    f" (in Python: SklearnClassifier.Config.model_validate(..., context={{'{ALLOW_IMPORT}': True}})"
    ", or classifier_factory(..., allow_import=True))"
)


def _import(path: str) -> Any:
    module, _, name = path.rpartition(".")
    if not module:
        raise ValueError(f"{path!r} is not a dotted import path such as 'sklearn.svm.SVC'")
    try:
        return getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError) as exc:
        raise ValueError(f"cannot import {path!r}: {exc}") from None


@lru_cache(maxsize=1)
def sklearn_classifiers() -> frozenset[type]:
    """scikit-learn's own classifier classes (the allowlist)."""
    from sklearn.utils import all_estimators

    return frozenset(cls for _, cls in all_estimators(type_filter="classifier"))


def check_estimator_path(path: str, allow_import: bool = False) -> Any:
    """The estimator class at ``path``: a scikit-learn classifier, or (with ``allow_import``)
    any class with ``fit`` and ``predict``. Raises ``ValueError`` naming the problem; a path
    outside ``sklearn.`` is not imported at all unless ``allow_import`` is set."""
    parts = path.split(".")
    if not allow_import and (parts[0] != "sklearn" or any(p.startswith("_") for p in parts)):
        raise ValueError(
            f"{path!r} is not a scikit-learn classifier path such as 'sklearn.svm.SVC'; other "
            "import paths run code from wherever they point and need the command-line flag "
            f"--allow-import{_IN_PYTHON}"
        )
    est = _import(path)
    if not allow_import and est not in sklearn_classifiers():
        raise ValueError(
            f"{path!r} is not one of scikit-learn's classifiers; other estimators need the "
            f"command-line flag --allow-import{_IN_PYTHON}"
        )
    if not (hasattr(est, "fit") and hasattr(est, "predict")):
        raise ValueError(f"{path!r} has no fit/predict: not a classifier")
    return est


class SklearnConfig(PluginConfig):
    """A scikit-learn estimator."""

    kind: Literal["sklearn"] = "sklearn"
    estimator: str = Field(
        description="A scikit-learn classifier's public path, e.g. "
        "'sklearn.ensemble.RandomForestClassifier' (other import paths need "
        "`mdf experiment --allow-import`)."
    )
    params: dict[str, Any] = Field(default_factory=dict, description="Constructor arguments.")
    standardize: bool = Field(True, description="z-score features with training statistics.")

    @field_validator("estimator")
    @classmethod
    def _check(cls, value: str, info: ValidationInfo) -> str:
        check_estimator_path(value, bool((info.context or {}).get(ALLOW_IMPORT, False)))
        return value

    @model_validator(mode="after")
    def _check_params(self) -> SklearnConfig:
        """Every number in ``params`` finite, and the estimator accepts them (its own parameter
        check, where it has one), so that a bad parameter stops before any fit."""
        _finite_numbers(self.params, "params")
        try:
            estimator = _import(self.estimator)(**self.params)
        except TypeError as exc:
            raise ValueError(f"params: {exc}") from None
        validate = getattr(estimator, "_validate_params", None)  # scikit-learn >= 1.2
        if callable(validate):
            try:
                validate()
            except (TypeError, ValueError) as exc:
                raise ValueError(f"params: {exc}") from None
        return self


def _finite_numbers(value: Any, where: str) -> None:
    """Refuse an infinite or NaN number anywhere in ``value`` (nested lists and tables)."""
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError(f"{where}: must be a finite number (got {value})")
    if isinstance(value, dict):
        for key, item in value.items():
            _finite_numbers(item, f"{where}.{key}")
    elif isinstance(value, list | tuple):
        for i, item in enumerate(value):
            _finite_numbers(item, f"{where}.{i}")


class SklearnClassifier(Classifier):
    """Any scikit-learn classifier (SVM, random forest, ...) behind the Classifier interface."""

    name = "sklearn"
    Config = SklearnConfig
    config: SklearnConfig

    def fit(self, features: NDArray[np.float64], labels: NDArray[Any]) -> SklearnClassifier:
        """Fit the estimator on (optionally standardised) features."""
        x = np.asarray(features, dtype=np.float64)
        self.scaler_ = Standardizer.fit(x) if self.config.standardize else None
        self.model_ = _import(self.config.estimator)(**self.estimator_params())
        self.model_.fit(self._scale(x), np.asarray(labels))
        return self

    def estimator_params(self) -> dict[str, Any]:
        """The estimator's constructor arguments: ``params``, plus ``random_state`` = the
        experiment's seed where the estimator takes one and ``params`` does not set it."""
        params = dict(self.config.params)
        estimator = _import(self.config.estimator)
        if (
            self.seed is not None
            and "random_state" not in params
            and "random_state" in inspect.signature(estimator).parameters
        ):
            params["random_state"] = self.seed
        return params

    def _scale(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        return self.scaler_.transform(x) if self.scaler_ is not None else x

    def predict(self, features: NDArray[np.float64]) -> NDArray[Any]:
        """Predicted labels."""
        return np.asarray(self.model_.predict(self._scale(np.asarray(features, np.float64))))
