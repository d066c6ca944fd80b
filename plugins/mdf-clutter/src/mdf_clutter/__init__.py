"""Ground clutter effect for mdframework (kind ``clutter``)."""

from .clutter import GroundClutter, gaussian_doppler_process

__all__ = ["GroundClutter", "gaussian_doppler_process"]
