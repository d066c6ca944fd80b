"""Entry point of the ``mdf-knn`` distribution."""

from __future__ import annotations

from mdframework import Classifier, hookimpl

from .knn import Knn


@hookimpl
def mdframework_register_classifiers() -> list[type[Classifier]]:
    """Register the kNN classifier."""
    return [Knn]
