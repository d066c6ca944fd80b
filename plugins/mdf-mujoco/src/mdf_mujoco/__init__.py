"""MuJoCo Boulic walker (``boulic``), body-part ellipsoids with their true frames
(``mujoco_body``) and body self-shadowing (``shadowing``) for mdframework."""

from .body_model import WalkerBody
from .gait import Gait, chain_positions
from .scatterers import MujocoBody
from .shadowing import Shadowing
from .source import BoulicWalker

__all__ = ["BoulicWalker", "Gait", "MujocoBody", "Shadowing", "WalkerBody", "chain_positions"]
