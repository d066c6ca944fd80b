"""Any scikit-learn estimator as an mdframework classifier (kind ``sklearn``)."""

from .estimator import SklearnClassifier

__all__ = ["SklearnClassifier"]
