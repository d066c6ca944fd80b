"""Antenna gain pattern effect for mdframework (kind ``antenna``)."""

from .antenna import AntennaPattern, one_way_gain

__all__ = ["AntennaPattern", "one_way_gain"]
