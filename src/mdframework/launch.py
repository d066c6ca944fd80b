"""The ``mdf`` console script: imports the command line under the same Ctrl-C rule as the
commands themselves.

Importing :mod:`mdframework.cli` loads pluggy, numpy and pydantic, which takes a noticeable
moment; a Ctrl-C in that moment would otherwise end in a traceback. This module imports only the
standard library, so what is left before the rule applies is the interpreter's own start.

It also spares the process work of Python's cyclic garbage collector that frees nothing: the
objects made while importing (modules, classes, pydantic's validators) live until the process
ends, yet each collection of the oldest generation walks them all again, and so do the
collections at exit. The collector is off while the command line is imported, and those objects
are then frozen (:func:`gc.freeze`: kept out of every later collection; the few cycles the
imports leave behind, about 0.3 MB, are kept with them). The command itself runs with the
collector on as usual, and what is alive when it has returned is frozen too, so that the exit
does not walk it (the command has written and closed its files; nothing of the project's relies
on a finaliser at exit).
"""

from __future__ import annotations

import gc
import sys


def run() -> None:
    """Import the command line and run it; Ctrl-C while importing prints one line, exit 130."""
    gc.disable()
    try:
        from .cli import main
    except KeyboardInterrupt:
        try:
            print("mdf: interrupted", file=sys.stderr or sys.__stderr__)
        except (OSError, ValueError, AttributeError):  # stderr closed or full
            pass
        sys.exit(130)
    finally:
        gc.freeze()
        gc.enable()
    code = main()
    gc.freeze()
    sys.exit(code)
