"""Progress on stderr for steps that take more than a second (interactive use only).

Shown when stderr is a terminal; a pipe or a log keeps the one-line-per-error rule of the
command line. The environment variable ``MDF_PROGRESS`` overrides that: ``1`` shows every
step, however short, even when stderr is not a terminal (for logs and tests); ``0`` shows
nothing. A command's ``--no-progress`` hides it whatever the environment says.

Two kinds of report, both on stderr:

- a *step* (:meth:`Progress.step`): ``mdf: MESSAGE ...`` printed once the step has lasted
  :data:`DELAY_S` (a step that ends sooner prints nothing);
- a *bar* (:meth:`Progress.bar`) over counted work (pulses, animation frames), drawn by tqdm
  once it has lasted :data:`DELAY_S`, and removed when the work is done.

tqdm is imported only when a bar is shown.

A step's or note's line is a status line: when the command then fails before anything else is
printed on stderr (a bad input found after it), :func:`retract` erases it, so that the error is
the only line the command leaves on the terminal.
"""

from __future__ import annotations

import io
import os
import sys
import threading
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from typing import Any

from .errors import stop_if_interrupted

#: Environment variable: ``1`` forces progress on (every step, no delay), ``0`` off (also
#: ``true``/``yes``/``on`` and ``false``/``no``/``off``, in any case; empty is unset; anything
#: else is refused by the ``mdf`` commands that report progress, :func:`check_progress_setting`,
#: and left to the terminal by library calls).
PROGRESS_ENV = "MDF_PROGRESS"
_ON = ("1", "true", "yes", "on")
_OFF = ("0", "false", "no", "off")
#: A step or bar appears once it has lasted this long [s].
DELAY_S = 1.0
#: ANSI: cursor one line up, to its start, and clear that line.
_ERASE_LINE = "\x1b[1A\r\x1b[2K"


class _State:
    """Whether a status line (a note or step) is the last line printed on stderr."""

    open = False


def _forced() -> bool | None:
    value = os.environ.get(PROGRESS_ENV, "").strip().lower()
    if value in _ON:
        return True
    if value in _OFF:
        return False
    return None


def check_progress_setting() -> None:
    """Refuse a :data:`PROGRESS_ENV` that is neither on, off nor empty: a
    :class:`~mdframework.errors.SettingError` naming the variable and the values it takes."""
    from .errors import SettingError

    text = os.environ.get(PROGRESS_ENV, "")
    if text.strip() and _forced() is None:
        raise SettingError(
            f"{PROGRESS_ENV}={text!r}: not a progress setting; use {', '.join(_ON[:-1])} or "
            f"{_ON[-1]} to show progress, {', '.join(_OFF[:-1])} or {_OFF[-1]} to hide it "
            "(any case), or leave it unset"
        )


def progress_enabled(wanted: bool = True) -> bool:
    """Whether progress is shown: ``wanted`` (a command's ``--no-progress`` turns it off),
    then ``MDF_PROGRESS`` (``1`` on, ``0`` off), else whether stderr is a terminal."""
    if not wanted:
        return False
    forced = _forced()
    if forced is not None:
        return forced
    return stderr_is_terminal()


def stderr_is_terminal() -> bool:
    """Whether stderr is a terminal (False when it is closed or gone: ``2>&-``)."""
    try:
        return sys.stderr is not None and bool(sys.stderr.isatty())
    except (OSError, ValueError):
        return False


class SafeStream(io.TextIOBase):
    """A text stream in front of ``stream`` (stderr) that never fails: writes to a closed
    stream (``None``: ``2>&-``) go nowhere, and a write or flush that fails (``2>/dev/full``, a
    reader gone) loses its text, never the command. For tqdm's bars and every other writer."""

    def __init__(self, stream: Any) -> None:
        super().__init__()
        self.stream = stream

    def write(self, text: str) -> int:
        if self.stream is not None:
            try:
                self.stream.write(text)
            except (OSError, ValueError):
                pass
        return len(text)

    def flush(self) -> None:
        if self.stream is not None:
            try:
                self.stream.flush()
            except (OSError, ValueError):
                pass

    def isatty(self) -> bool:
        try:
            return self.stream is not None and bool(self.stream.isatty())
        except (OSError, ValueError):
            return False

    def fileno(self) -> int:
        if self.stream is None:
            raise OSError("stderr is closed")
        return int(self.stream.fileno())

    @property
    def encoding(self) -> str:  # type: ignore[override]
        return str(getattr(self.stream, "encoding", None) or "utf-8")


@contextmanager
def safe_stderr() -> Iterator[None]:
    """``sys.stderr`` is a :class:`SafeStream` for the block (a command's lifetime)."""
    saved = sys.stderr
    if isinstance(saved, SafeStream):
        yield
        return
    sys.stderr = SafeStream(saved)
    try:
        yield
    finally:
        sys.stderr = saved


def say(line: str) -> None:
    """Print ``line`` on stderr, never failing: a closed stderr (``2>&-``), a full disk
    (``2>/dev/full``) or a reader gone loses the line, never the command."""
    stream = sys.stderr
    if stream is None:
        return
    try:
        stream.write(line + "\n")
        stream.flush()
    except (OSError, ValueError):
        pass


def note(message: str, enabled: bool = True) -> None:
    """Print ``mdf: MESSAGE ...`` on stderr now, when progress is shown
    (:func:`progress_enabled`)."""
    if progress_enabled(enabled):
        _print(message)


def printed() -> None:
    """Something else is shown on stderr (a warning, a bar that stays): the last status line
    is kept."""
    _State.open = False


def retract() -> None:
    """Erase the last status line if nothing was printed on stderr after it and stderr is a
    terminal (called before an error line)."""
    if _State.open and stderr_is_terminal():
        try:
            sys.stderr.write(_ERASE_LINE)
            sys.stderr.flush()
        except (OSError, ValueError):
            pass
    _State.open = False


class Progress:
    """Progress of one command's steps (see the module docstring). ``enabled=False`` (or
    stderr not a terminal, without ``MDF_PROGRESS=1``) makes every report silent; ``delay``
    [s]: how long a step or bar runs before it appears (default :data:`DELAY_S`, 0 with
    ``MDF_PROGRESS=1``)."""

    def __init__(self, enabled: bool = True, *, delay: float | None = None) -> None:
        self.enabled = progress_enabled(enabled)
        if delay is None:
            delay = 0.0 if _forced() else DELAY_S
        self.delay = float(delay)
        self._timer: threading.Timer | None = None

    def stage(self, message: str) -> None:
        """Start a step (ending the previous one): ``mdf: MESSAGE ...`` appears if it lasts
        :attr:`delay` seconds, i.e. if :meth:`stage` or :meth:`end` is not called sooner.
        A Ctrl-C that a library swallowed stops the command here
        (:func:`~mdframework.errors.stop_if_interrupted`), as at every block of :meth:`counted`."""
        self.end()
        stop_if_interrupted()
        if not self.enabled:
            return
        if self.delay <= 0:
            _print(message)
            return
        self._timer = threading.Timer(self.delay, _print, (message,))
        self._timer.daemon = True
        self._timer.start()

    def end(self) -> None:
        """End the current step (its message, if not shown yet, never is)."""
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    @contextmanager
    def step(self, message: str) -> Iterator[None]:
        """The enclosed work as one step (:meth:`stage`), ended however it ends."""
        self.stage(message)
        try:
            yield
        finally:
            self.end()

    def counted(
        self, blocks: Iterable[tuple[int, int]], total: int, label: str, unit: str
    ) -> Iterator[tuple[int, int]]:
        """The ``(lo, hi)`` blocks of ``total`` units of work, as given, with a :meth:`bar`
        that advances by ``hi - lo`` as each block is done."""
        with self.bar(total, label, unit) as advance:
            for lo, hi in blocks:
                stop_if_interrupted()
                yield lo, hi
                advance(hi - lo)

    @contextmanager
    def bar(self, total: int, label: str, unit: str) -> Iterator[Callable[[int], None]]:
        """A bar over ``total`` units of work labelled ``mdf: LABEL``; yields ``advance(n)``,
        to call as ``n`` more units are done. Ends the current step."""
        self.end()
        if not self.enabled:
            yield _ignore
            return
        bar: Any = tqdm_bar(
            total=total,
            desc=f"mdf: {label}",
            unit=unit,
            delay=self.delay,
            leave=False,
            file=sys.stderr,
            dynamic_ncols=True,
        )
        try:
            yield bar.update
        finally:
            bar.close()


_BAR_CLASS: Any = None


def tqdm_bar(*args: Any, **kwargs: Any) -> Any:
    """``tqdm(*args, **kwargs)`` without tqdm's monitor thread (which every bar starts, even
    a disabled one, and which lives on for a while after it): a thread that holds a lock when
    the worker processes of a build are forked would leave it held in them, and Python 3.12
    and later warn of it ("This process is multi-threaded, use of fork() may lead to
    deadlocks in the child"). The monitor only adjusts how often a bar that has stalled is
    redrawn."""
    global _BAR_CLASS
    if _BAR_CLASS is None:
        from tqdm import tqdm

        _BAR_CLASS = type("MdfBar", (tqdm,), {"monitor_interval": 0})
    return _BAR_CLASS(*args, **kwargs)


#: Progress that reports nothing (the default of library calls).
QUIET = Progress(False)


def _print(message: str) -> None:
    say(f"mdf: {message} ...")
    _State.open = True


def _ignore(n: int) -> None:
    """``advance`` of a silent bar."""
