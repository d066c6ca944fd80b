"""mdframework: radar micro-Doppler signatures of people in motion.

Public API for users and plugin authors::

    from mdframework import hookimpl, Skeleton, Motion, MotionSource, ...

See ``docs/plugins.md`` for writing a plugin distribution.
"""

from __future__ import annotations

import importlib
import warnings
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .errors import ConfigError, DataFileError, MdfError, SceneError
    from .hookspecs import hookimpl
    from .interfaces import (
        Classifier,
        ConfigSection,
        Effect,
        Motion,
        MotionSource,
        PluginConfig,
        PulseBlock,
        RadarConfig,
        RadarWaveform,
        Received,
        ReceiverInput,
        Recording,
        RecordingSource,
        ScattererModel,
        Scatterers,
        SceneContext,
        point_responses,
        receive_points,
    )
    from .interfaces import RecordingSource as RadarRecordingSource  # noqa: F401 (old name)
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
    "ConfigSection": "interfaces",
    "Effect": "interfaces",
    "Motion": "interfaces",
    "MotionSource": "interfaces",
    "PluginConfig": "interfaces",
    "PulseBlock": "interfaces",
    "RadarConfig": "interfaces",
    "RecordingSource": "interfaces",
    "RadarWaveform": "interfaces",
    "Received": "interfaces",
    "ReceiverInput": "interfaces",
    "Recording": "interfaces",
    "ScattererModel": "interfaces",
    "Scatterers": "interfaces",
    "SceneContext": "interfaces",
    "point_responses": "interfaces",
    "receive_points": "interfaces",
    "DataPath": "settings",
    "MotionConfig": "settings",
    "CANONICAL_JOINTS": "skeleton",
    "CANONICAL_SEGMENTS": "skeleton",
    "Skeleton": "skeleton",
    "to_canonical": "skeleton",
}


#: old public name -> current one (still importable, with a DeprecationWarning)
_OLD_EXPORTS = {"RadarRecordingSource": "RecordingSource"}


def __getattr__(name: str) -> Any:
    if name in _OLD_EXPORTS:  # not cached: every use warns
        new = _OLD_EXPORTS[name]
        warnings.warn(
            f"mdframework.{name} is deprecated: use mdframework.{new}",
            DeprecationWarning,
            stacklevel=2,
        )
        return __getattr__(new)
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})


__version__ = "0.2.2"

__all__ = [
    "CANONICAL_JOINTS",
    "CANONICAL_SEGMENTS",
    "Classifier",
    "ConfigError",
    "ConfigSection",
    "DataFileError",
    "DataPath",
    "Effect",
    "MdfError",
    "Motion",
    "MotionConfig",
    "MotionSource",
    "PluginConfig",
    "PulseBlock",
    "RadarConfig",
    "RadarWaveform",
    "Received",
    "ReceiverInput",
    "Recording",
    "RecordingSource",
    "ScattererModel",
    "Scatterers",
    "SceneContext",
    "SceneError",
    "Skeleton",
    "hookimpl",
    "point_responses",
    "receive_points",
    "to_canonical",
]
