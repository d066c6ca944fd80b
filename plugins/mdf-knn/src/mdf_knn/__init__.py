"""k-nearest-neighbour classifier plugin for mdframework (kind ``knn``)."""

from .knn import Knn

__all__ = ["Knn"]
