"""User-facing errors. The CLI prints any :class:`MdfError` as one line and exits with code 2."""

from __future__ import annotations

from pathlib import Path


class MdfError(Exception):
    """An error caused by the user's input (config, data file, scene), with a one-line message."""


class ConfigError(MdfError):
    """A config file cannot be read or is invalid; the message names the file and field."""


class DataFileError(MdfError):
    """A data file is malformed; the message names the file and, where known, the line."""

    def __init__(self, path: str | Path, message: str, line: int | None = None) -> None:
        self.path = Path(path)
        self.line = line
        where = f"{path}:{line}" if line is not None else f"{path}"
        super().__init__(f"{where}: {message}")


class SceneError(MdfError):
    """The scene cannot be simulated as described (target at the radar, aliasing when strict,
    a record shorter than the STFT window, ...)."""


class OutputError(MdfError):
    """An output folder cannot be used as given (a file, not writable, another command's or the
    user's files, in use by another command); the message names ``--out`` and what to do."""
