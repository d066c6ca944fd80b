"""mdf-deepmimic: DeepMimic motion clips of the humanoid3d character, through forward
kinematics onto the canonical body. See ``docs/motion-formats.md``."""

from __future__ import annotations

from .character import CANONICAL_MAP, HUMANOID3D, Character, read_character
from .kinematics import forward_kinematics, repeat_cycles
from .reader import Clip, read_clip
from .source import DeepMimicConfig, DeepMimicSource

__all__ = [
    "CANONICAL_MAP",
    "HUMANOID3D",
    "Character",
    "Clip",
    "DeepMimicConfig",
    "DeepMimicSource",
    "forward_kinematics",
    "read_character",
    "read_clip",
    "repeat_cycles",
]
