"""Atmospheric and rain attenuation effect for mdframework (kind ``attenuation``)."""

from .attenuation import Attenuation, specific_attenuation, two_way_loss

__all__ = ["Attenuation", "specific_attenuation", "two_way_loss"]
