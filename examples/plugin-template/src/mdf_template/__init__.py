"""Template of a third-party mdframework plugin: a pendulum motion source (``kind =
"pendulum"``) and a receiver gain effect (``kind = "gain"``)."""

from .effect import Gain
from .source import Pendulum

__all__ = ["Gain", "Pendulum"]
