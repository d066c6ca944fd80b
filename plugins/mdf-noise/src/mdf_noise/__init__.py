"""Receiver noise effect for mdframework (kind ``noise``)."""

from .noise import ReceiverNoise, noise_power

__all__ = ["ReceiverNoise", "noise_power"]
