"""The ``mdf`` console script: imports the command line under the same Ctrl-C rule as the
commands themselves.

Importing :mod:`mdframework.cli` loads pluggy, numpy and pydantic, which takes a noticeable
moment; a Ctrl-C in that moment would otherwise end in a traceback. This module imports only the
standard library, so what is left before the rule applies is the interpreter's own start.
"""

from __future__ import annotations

import sys


def run() -> None:
    """Import the command line and run it; Ctrl-C while importing prints one line, exit 130."""
    try:
        from .cli import main
    except KeyboardInterrupt:
        try:
            print("mdf: interrupted", file=sys.stderr or sys.__stderr__)
        except (OSError, ValueError, AttributeError):  # stderr closed or full
            pass
        sys.exit(130)
    sys.exit(main())
