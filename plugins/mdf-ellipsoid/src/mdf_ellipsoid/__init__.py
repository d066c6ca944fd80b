"""Sphere/ellipsoid body-part scatterer model for mdframework (kind ``ellipsoid``)."""

from .model import EllipsoidBody

__all__ = ["EllipsoidBody"]
