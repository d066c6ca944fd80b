"""pluggy hook specifications: one registration hook per interface.

The hook of each interface is named after its base class (``RadarWaveform`` ->
``mdframework_register_radar_waveforms``); see :mod:`mdframework.plugins` for the table.

A plugin distribution declares an entry point in the ``mdframework`` group whose object is a module
(or class) implementing some of these hooks with ``@mdframework.hookimpl``. Each hook returns a list
of plugin classes; their ``name`` is the ``kind`` used in config files.

Example ``pyproject.toml`` of a third-party plugin::

    [project.entry-points.mdframework]
    my_source = "my_package.plugin"

and in ``my_package/plugin.py``::

    from mdframework import hookimpl

    @hookimpl
    def mdframework_register_motion_sources():
        return [MySource]
"""

from __future__ import annotations

import argparse
from typing import Any

import pluggy

from .interfaces import (
    Classifier,
    Effect,
    MotionSource,
    RadarWaveform,
    RecordingSource,
    ScattererModel,
)

PROJECT = "mdframework"
hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)


@hookspec
def mdframework_register_motion_sources() -> list[type[MotionSource]]:  # type: ignore[empty-body]
    """Return the :class:`~mdframework.interfaces.MotionSource` classes this plugin provides."""


@hookspec
def mdframework_register_scatterer_models() -> list[type[ScattererModel]]:  # type: ignore[empty-body]
    """Return the :class:`~mdframework.interfaces.ScattererModel` classes this plugin provides."""


@hookspec
def mdframework_register_radar_waveforms() -> list[type[RadarWaveform]]:  # type: ignore[empty-body]
    """Return the :class:`~mdframework.interfaces.RadarWaveform` classes this plugin provides
    (the ``[radar]`` section)."""


@hookspec(
    warn_on_impl=DeprecationWarning(
        "the hook mdframework_register_waveforms is deprecated: rename it to "
        "mdframework_register_radar_waveforms"
    )
)
def mdframework_register_waveforms() -> list[type[RadarWaveform]]:  # type: ignore[empty-body]
    """Deprecated spelling of :func:`mdframework_register_radar_waveforms`."""


@hookspec
def mdframework_register_classifiers() -> list[type[Classifier]]:  # type: ignore[empty-body]
    """Return the :class:`~mdframework.interfaces.Classifier` classes this plugin provides."""


@hookspec
def mdframework_register_effects() -> list[type[Effect]]:  # type: ignore[empty-body]
    """Return the :class:`~mdframework.interfaces.Effect` classes this plugin provides (the
    ``[[effects]]`` entries)."""


@hookspec
def mdframework_register_recording_sources() -> list[type[RecordingSource]]:  # type: ignore[empty-body]
    """Return the :class:`~mdframework.interfaces.RecordingSource` classes (readers of real
    radar recordings, the ``recording`` entry of a dataset source) this plugin provides."""


@hookspec(
    warn_on_impl=DeprecationWarning(
        "the hook mdframework_register_recordings is deprecated: rename it to "
        "mdframework_register_recording_sources"
    )
)
def mdframework_register_recordings() -> list[type[RecordingSource]]:  # type: ignore[empty-body]
    """Deprecated spelling of :func:`mdframework_register_recording_sources`."""


# --------------------------------------------------------------------------- command line


@hookspec
def mdframework_add_cli_commands(subparsers: argparse._SubParsersAction[Any]) -> None:
    """Add ``mdf`` sub-commands (e.g. ``mdf capture``).

    Call ``subparsers.add_parser(name, help=..., description=..., epilog=...,
    formatter_class=argparse.RawDescriptionHelpFormatter)`` with a one-line ``help``, a
    ``description`` and an ``epilog`` of examples, and ``set_defaults(func=handler)``; the handler
    takes the parsed ``argparse.Namespace`` and returns an exit code. Raise
    :class:`~mdframework.errors.MdfError` for bad input: the CLI prints it as one line and exits
    with code 2.

    ``mdf --help`` calls this hook, so the module that implements it must import nothing heavy
    (import inside the handler instead).
    """
