"""mdframework: radar micro-Doppler signatures of people in motion.

Public API for users and plugin authors::

    from mdframework import hookimpl, Skeleton, Motion, MotionSource, ...

See ``docs/plugins.md`` for writing a plugin distribution.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .errors import ConfigError, DataFileError, MdfError, SceneError
    from .hookspecs import hookimpl
    from .interfaces import (
        Classifier,
        Effect,
        Motion,
        MotionSource,
        PluginConfig,
        PulseBlock,
        RadarRecordingSource,
        RadarWaveform,
        Received,
        Recording,
        ScattererModel,
        Scatterers,
        SceneContext,
        receive_points,
    )
    from .settings import DataPath, MotionConfig
    from .skeleton import CANONICAL_JOINTS, CANONICAL_SEGMENTS, Skeleton, to_canonical

#: where each public name lives; imported on first use, so that ``import mdframework`` (and the
#: start of ``mdf``) stays fast and Ctrl-C during start-up is handled by the command line
_EXPORTS = {
    "ConfigError": "errors",
    "DataFileError": "errors",
    "MdfError": "errors",
    "SceneError": "errors",
    "hookimpl": "hookspecs",
    "Classifier": "interfaces",
    "Effect": "interfaces",
    "Motion": "interfaces",
    "MotionSource": "interfaces",
    "PluginConfig": "interfaces",
    "PulseBlock": "interfaces",
    "RadarRecordingSource": "interfaces",
    "RadarWaveform": "interfaces",
    "Received": "interfaces",
    "Recording": "interfaces",
    "ScattererModel": "interfaces",
    "Scatterers": "interfaces",
    "SceneContext": "interfaces",
    "receive_points": "interfaces",
    "DataPath": "settings",
    "MotionConfig": "settings",
    "CANONICAL_JOINTS": "skeleton",
    "CANONICAL_SEGMENTS": "skeleton",
    "Skeleton": "skeleton",
    "to_canonical": "skeleton",
}


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})


__version__ = "0.1.0"

__all__ = [
    "CANONICAL_JOINTS",
    "CANONICAL_SEGMENTS",
    "Classifier",
    "ConfigError",
    "DataFileError",
    "DataPath",
    "Effect",
    "MdfError",
    "Motion",
    "MotionConfig",
    "MotionSource",
    "PluginConfig",
    "PulseBlock",
    "RadarRecordingSource",
    "RadarWaveform",
    "Received",
    "Recording",
    "ScattererModel",
    "Scatterers",
    "SceneContext",
    "SceneError",
    "Skeleton",
    "hookimpl",
    "receive_points",
    "to_canonical",
]
