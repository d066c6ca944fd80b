"""mdframework: radar micro-Doppler signatures of people in motion.

Public API for users and plugin authors::

    from mdframework import hookimpl, Skeleton, Motion, MotionSource, ...

See ``docs/plugins.md`` for writing a plugin distribution.
"""

from __future__ import annotations

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
