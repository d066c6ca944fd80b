"""User-facing errors. The CLI prints any :class:`MdfError` as one line and exits with code 2."""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any


def unnameable(path: str | Path) -> str | None:
    """Why this system cannot name the file ``path``: a character its file names cannot hold
    (a UTF-8 config naming a non-ASCII file, under an ASCII or Latin-1 locale without Python's
    UTF-8 mode, or a NUL character); None if it can."""
    if "\0" in str(path):
        return "a file name cannot hold a NUL character"
    try:
        os.fsencode(path)
    except UnicodeEncodeError:
        return (
            "the name has characters that this system's file names cannot hold "
            f"({sys.getfilesystemencoding()}); set a UTF-8 locale, or PYTHONUTF8=1"
        )
    return None


class MdfError(Exception):
    """An error caused by the user's input (config, data file, scene), with a one-line message."""


class ConfigError(MdfError):
    """A config file cannot be read or is invalid; the message names the file and field."""


class DataFileError(MdfError):
    """A data file is malformed; the message names the file and, where known, the line."""

    def __init__(self, path: str | Path, message: str, line: int | None = None) -> None:
        self.path = Path(path)
        self.line = line
        self.message = message
        self._named = str(path)  # as given: the message names it so
        where = f"{path}:{line}" if line is not None else f"{path}"
        super().__init__(f"{where}: {message}")

    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]:
        """Pickled with its own arguments (an error raised in a worker process reaches the
        command as it was raised)."""
        return type(self), (self._named, self.message, self.line)


class SceneError(MdfError):
    """The scene cannot be simulated as described (target at the radar, aliasing when strict,
    a record shorter than the STFT window, ...)."""


class SettingError(MdfError):
    """A setting of how a command runs, not of what it computes, cannot be used (an environment
    variable such as ``MDF_START_METHOD``, a Dask scheduler); the message names the setting."""


class OutputError(MdfError):
    """An output folder cannot be used as given (a file, not writable, another command's or the
    user's files, in use by another command); the message names ``--out`` and what to do."""


_interrupt_seen = False


def note_interrupt(seen: bool = True) -> None:
    """Record that Ctrl-C reached this process (the CLI's SIGINT handler calls it; each
    command starts with ``seen=False``)."""
    global _interrupt_seen
    _interrupt_seen = seen


def stop_if_interrupted() -> None:
    """Raise KeyboardInterrupt if Ctrl-C reached this process and was swallowed on its way:
    raised in a finaliser (Python then reports it as unraisable and goes on), or caught by a
    library as an exception (Python wraps one raised while a class is being created). The
    command's progress reports call this at every step and block, so such a Ctrl-C stops the
    command at its next step instead of at its end."""
    if _interrupt_seen:
        raise KeyboardInterrupt


def interrupt_seen() -> bool:
    """Whether Ctrl-C has reached this process (see :func:`note_interrupt`)."""
    return _interrupt_seen


def caused_by_interrupt(exc: BaseException) -> bool:
    """Whether Ctrl-C is behind ``exc``: a KeyboardInterrupt in its chain (Python wraps one
    raised at some points, e.g. while a class is being created during an import, in another
    exception), or any exception after Ctrl-C reached the process (pydantic turns one raised
    while it builds a schema into a ``SchemaError`` that does not chain it)."""
    if _interrupt_seen:
        return True
    seen: set[int] = set()
    cause: BaseException | None = exc
    while cause is not None and id(cause) not in seen:
        if isinstance(cause, KeyboardInterrupt):
            return True
        seen.add(id(cause))
        cause = cause.__cause__ or cause.__context__
    return False
