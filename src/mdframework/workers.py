"""Worker processes that never outlive the command that started them.

A dataset build runs records in local worker processes (a process pool, or a local Dask
cluster whose workers end with their parent by themselves). If the command is killed (``kill
-9``, a closed terminal, an out-of-memory kill), its pool workers must not linger: each asks the
kernel to kill it when its parent process dies (Linux ``PR_SET_PDEATHSIG``) and, as a fallback on
other systems, watches its parent from a thread and exits when it is gone. Ctrl-C is the
command's to handle: workers ignore it, and the command stops them (:func:`stop_pool`) and
prints one line.

Start methods: on Linux the pool's workers are forked (whatever Python's default, which is
``forkserver`` from Python 3.14): a forked worker starts at once and inherits what the command
loaded (plugins, motions) and its warning handling. Elsewhere (macOS, where forking a process
that has used system frameworks is unsafe) they start with the platform's default method, and
``MDF_START_METHOD`` (``fork``, ``spawn`` or ``forkserver``) chooses one anywhere. A worker that
starts afresh is given the command's warning filters and warning printer, and whatever
the pool's ``setup`` hands over (:func:`worker_pool`), so that it works as a forked one does.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import multiprocessing
import os
import pickle
import signal
import sys
import threading
import time
import warnings
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from typing import Any

from .errors import SettingError

#: the environment variable that chooses how worker processes start
START_METHOD_ENV = "MDF_START_METHOD"

_PR_SET_PDEATHSIG = 1
#: how often the fallback watcher looks at the parent [s]
WATCH_INTERVAL_S = 0.5


def _parent_death_signal(sig: int) -> bool:
    """Ask Linux to send ``sig`` to this process when its parent dies; False elsewhere."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        return int(libc.prctl(_PR_SET_PDEATHSIG, sig, 0, 0, 0)) == 0
    except (OSError, AttributeError):
        return False


def _watch(parent: int) -> None:
    while True:
        time.sleep(WATCH_INTERVAL_S)
        if os.getppid() != parent:  # re-parented: the parent has died
            os._exit(1)


def _watch_creator(sentinel: int) -> None:
    from multiprocessing.connection import wait

    wait([sentinel])  # ready when the process that created this one has ended
    os._exit(1)


def die_with_parent(parent_pid: int | None = None, *, ignore_interrupt: bool = True) -> None:
    """Make this (worker) process end when its parent process ends.

    Call it first thing in a worker (a process pool's ``initializer``). ``parent_pid``: the
    process expected to be the parent (a worker started after its parent died exits at once).
    ``ignore_interrupt``: ignore Ctrl-C (SIGINT), which the parent handles; only possible from a
    process's main thread, so it is skipped elsewhere. A Ctrl-C that came while the worker
    started with SIGINT blocked (:func:`worker_pool`) is dropped, and SIGINT unblocked.

    A worker started by :mod:`multiprocessing` watches the process that started it (the
    pool's), whichever process is its parent: a fork server's workers are its children, and it
    lives as long as they do.
    """
    parent = os.getppid()
    if threading.current_thread() is threading.main_thread():
        if ignore_interrupt:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        # SIGTERM ends a worker (the pool's way to stop one), not the handler of the command
        # it was forked from
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    _parent_death_signal(signal.SIGKILL)
    if (parent_pid is not None and parent != parent_pid) or os.getppid() != parent:
        os._exit(1)  # the parent died before the request above took effect
    creator = multiprocessing.parent_process()
    if creator is not None:
        watch, args = _watch_creator, (creator.sentinel,)
    else:
        watch, args = _watch, (parent,)  # type: ignore[assignment]
    threading.Thread(target=watch, args=args, name="die-with-parent", daemon=True).start()


@contextmanager
def _interrupt_blocked() -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) back from this thread while the block runs: a process started
    meanwhile starts with it blocked (and :func:`die_with_parent` drops it there); this thread
    gets it when the block ends."""
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


class _Pool(ProcessPoolExecutor):
    """A process pool whose workers start with Ctrl-C blocked until they ignore it: a spawned
    worker takes a while to import what it runs, and a Ctrl-C then printed its traceback."""

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Any:
        with _interrupt_blocked():  # submit() starts the workers
            return super().submit(fn, *args, **kwargs)


def stop_pool(pool: ProcessPoolExecutor) -> None:
    """Stop a process pool now: cancel queued work and end its workers (for Ctrl-C and
    errors, where waiting for the queued work is wrong)."""
    terminate = getattr(pool, "terminate_workers", None)  # Python >= 3.14
    if terminate is not None:
        terminate()
        return
    processes: dict[int, Any] = dict(getattr(pool, "_processes", None) or {})
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in processes.values():
        proc.terminate()
    for proc in processes.values():
        proc.join(timeout=5)


#: Size of the block :func:`keep_freed_memory` allocates and frees [bytes]: just under glibc's
#: largest dynamic mmap threshold (32 MiB on 64-bit systems), with room for the chunk header.
FREED_BLOCK_BYTES = (32 << 20) - (1 << 16)


def keep_freed_memory() -> None:
    """Let this process reuse the memory of freed arrays instead of returning it to the system
    and faulting it in again.

    glibc's malloc serves blocks over its mmap threshold (128 KiB at first) with fresh mappings,
    and hands freed heap memory back above its trim threshold; it raises both (up to 32 MiB and
    twice that) whenever it unmaps a block larger than the threshold. A worker forked from a
    process that freed large arrays inherits raised thresholds; one forked from a process that
    did not (the planner, when the motions were loaded in other processes) mapped and faulted
    in about 14 MB afresh for every 6 s record: 3,600 page faults and up to a third more CPU.
    Allocating and freeing one block of :data:`FREED_BLOCK_BYTES` raises the thresholds at
    once (numpy's ``empty`` asks malloc for it and touches no page of it). Elsewhere than glibc
    it allocates and frees one block."""
    import numpy as np

    block = np.empty(FREED_BLOCK_BYTES, dtype=np.uint8)
    del block


def limit_blas_threads(n_workers: int) -> None:
    """Give this worker's BLAS/OpenMP libraries an equal share of the CPUs (at least one
    thread) when ``n_workers`` processes run side by side: otherwise each library starts a
    thread per CPU and their threads contend (OpenBLAS's spin on a busy core: a 3x3 matrix
    product over a recording took 17-21 ms instead of 5 on 2 cores). Dask's nanny sets the
    same limit for its workers through the environment."""
    from threadpoolctl import threadpool_limits  # imported when used

    threadpool_limits(max(1, (os.cpu_count() or 1) // max(1, n_workers)))


def start_method() -> str:
    """How worker processes start: ``MDF_START_METHOD`` if set, else ``fork`` on Linux, else
    the platform's default (``spawn`` on macOS). Raises :class:`SettingError` for a method this
    platform lacks."""
    chosen = os.environ.get(START_METHOD_ENV, "").strip()
    available = multiprocessing.get_all_start_methods()
    if chosen:
        if chosen not in available:
            raise SettingError(
                f"{START_METHOD_ENV}={chosen!r}: not a start method of this platform; "
                f"use one of {', '.join(available)}"
            )
        return chosen
    if sys.platform.startswith("linux") and "fork" in available:
        return "fork"
    return multiprocessing.get_start_method()


def warning_filters() -> list[tuple[Any, ...]]:
    """This process's warning filters, newest first, as arguments of
    :func:`warnings.filterwarnings` (a filter holds its patterns compiled or as text)."""

    def text(pattern: Any) -> str:
        return str(getattr(pattern, "pattern", pattern) or "")

    return [(f[0], text(f[1]), f[2], text(f[3]), f[4]) for f in warnings.filters]


def take_warnings(show: Callable[..., None] | None, filters: list[tuple[Any, ...]]) -> None:
    """Handle warnings in this process as another does: its ``filters``
    (:func:`warning_filters`) and its printer ``show`` (``warnings.showwarning``; None keeps
    this process's)."""
    warnings.resetwarnings()
    for action, message, category, module, lineno in reversed(filters):
        warnings.filterwarnings(action, message, category, module, lineno)
    if show is not None:
        warnings.showwarning = show


def _picklable(value: Any) -> bool:
    try:
        pickle.dumps(value)
    except Exception:
        return False
    return True


def _warning_state() -> tuple[Callable[..., None] | None, list[tuple[Any, ...]]]:
    """This process's warning printer and filters, as far as another process can be given
    them (a printer or a warning class defined inside a function cannot)."""
    show = warnings.showwarning
    return (show if _picklable(show) else None), [f for f in warning_filters() if _picklable(f)]


def _start_worker(parent_pid: int | None, n_workers: int, fresh: tuple[Any, ...] | None) -> None:
    die_with_parent(parent_pid)
    if fresh is not None:  # not forked: take what a forked worker inherits
        show, filters, setup, setup_args = fresh
        take_warnings(show, filters)
        if setup is not None:
            setup(*setup_args)
    keep_freed_memory()
    limit_blas_threads(n_workers)


@contextmanager
def worker_pool(
    n: int,
    setup: Callable[..., None] | None = None,
    setup_args: tuple[Any, ...] = (),
) -> Iterator[ProcessPoolExecutor]:
    """A process pool of ``n`` workers that end with this process (:func:`die_with_parent`),
    reuse freed memory (:func:`keep_freed_memory`) and share the CPUs' BLAS threads
    (:func:`limit_blas_threads`), started as :func:`start_method` says. Workers that are not
    forked take this process's warning handling (:func:`take_warnings`) and run
    ``setup(*setup_args)`` (a module-level function; to hand over what a forked worker would
    inherit). Leaving the block normally waits for the work submitted; an error, Ctrl-C or a
    closed generator around it stops the workers at once (:func:`stop_pool`)."""
    method = start_method()
    # a forkserver's workers are the children of its server, not of this process
    parent = None if method == "forkserver" else os.getpid()
    fresh = None if method == "fork" else (*_warning_state(), setup, setup_args)
    pool = _Pool(
        max_workers=n,
        mp_context=multiprocessing.get_context(method),
        initializer=_start_worker,
        initargs=(parent, n, fresh),
    )
    try:
        yield pool
    except BaseException:
        stop_pool(pool)
        raise
    pool.shutdown()
