"""Ground-bounce multipath effect for mdframework (kind ``multipath``)."""

from .multipath import GroundMultipath, mirror

__all__ = ["GroundMultipath", "mirror"]
