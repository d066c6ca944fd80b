"""Progress notes on stderr for steps that take more than a second (interactive use only)."""

from __future__ import annotations

import sys


def note(message: str, enabled: bool = True) -> None:
    """Print ``mdf: MESSAGE ...`` on stderr when ``enabled`` and stderr is a terminal (a pipe or
    a log keeps the one-line-per-error rule of the command line)."""
    stream = sys.stderr
    if enabled and stream.isatty():
        print(f"mdf: {message} ...", file=stream, flush=True)
