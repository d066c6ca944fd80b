"""Progress notes on stderr for steps that take more than a second (interactive use only).

A note is a status line: when the command then fails before anything else is printed on stderr
(a bad input found after the note), :func:`retract` erases it, so that the error is the only
line the command leaves on the terminal.
"""

from __future__ import annotations

import sys

#: ANSI: cursor one line up, to its start, and clear that line.
_ERASE_LINE = "\x1b[1A\r\x1b[2K"


class _State:
    """Whether a note is the last line printed on stderr (and so may be erased)."""

    open = False


def note(message: str, enabled: bool = True) -> None:
    """Print ``mdf: MESSAGE ...`` on stderr when ``enabled`` and stderr is a terminal (a pipe or
    a log keeps the one-line-per-error rule of the command line)."""
    stream = sys.stderr
    if enabled and stream.isatty():
        print(f"mdf: {message} ...", file=stream, flush=True)
        _State.open = True


def printed() -> None:
    """Something else is shown on stderr (a warning, a progress bar): the last note stays."""
    _State.open = False


def retract() -> None:
    """Erase the last note if nothing was printed on stderr after it (before an error)."""
    if _State.open and sys.stderr.isatty():
        sys.stderr.write(_ERASE_LINE)
        sys.stderr.flush()
    _State.open = False
