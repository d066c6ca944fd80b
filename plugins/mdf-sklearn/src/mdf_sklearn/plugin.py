"""Entry point of the ``mdf-sklearn`` distribution."""

from __future__ import annotations

from mdframework import Classifier, hookimpl

from .estimator import SklearnClassifier


@hookimpl
def mdframework_register_classifiers() -> list[type[Classifier]]:
    """Register the scikit-learn estimator wrapper."""
    return [SklearnClassifier]
