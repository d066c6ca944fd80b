"""mdf-deepmimic: DeepMimic motion clips of the humanoid3d character, through forward
kinematics onto the canonical body. See ``docs/motion-formats.md``."""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .source import DeepMimicConfig, DeepMimicSource

if TYPE_CHECKING:
    from .character import CANONICAL_MAP, HUMANOID3D, Character, read_character
    from .kinematics import forward_kinematics, repeat_cycles
    from .reader import Clip, read_clip

#: public names imported on first use: loading the plugin (every mdf command loads every
#: plugin) imports its source classes only, not the character, kinematics and clip reader
_EXPORTS = {
    "CANONICAL_MAP": "character",
    "HUMANOID3D": "character",
    "Character": "character",
    "read_character": "character",
    "forward_kinematics": "kinematics",
    "repeat_cycles": "kinematics",
    "Clip": "reader",
    "read_clip": "reader",
}

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


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})
