"""Point-scatterer motion source (``point_targets``) and isotropic scatterers (``points``)."""

from .source import IsotropicPoints, PointTargets

__all__ = ["IsotropicPoints", "PointTargets"]
