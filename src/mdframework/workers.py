"""Worker processes that never outlive the command that started them.

A dataset build runs records in local worker processes (a process pool, or a local Dask
cluster whose workers end with their parent by themselves). If the command is killed (``kill
-9``, a closed terminal, an out-of-memory kill), its pool workers must not linger: each asks the
kernel to kill it when its parent process dies (Linux ``PR_SET_PDEATHSIG``) and, as a fallback on
other systems, watches its parent from a thread and exits when it is gone. Ctrl-C is the
command's to handle: workers ignore it, and the command stops them (:func:`stop_pool`) and
prints one line.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from typing import Any

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


def die_with_parent(parent_pid: int | None = None, *, ignore_interrupt: bool = True) -> None:
    """Make this (worker) process end when its parent process ends.

    Call it first thing in a worker (a process pool's ``initializer``). ``parent_pid``: the
    process expected to be the parent (a worker started after its parent died exits at once).
    ``ignore_interrupt``: ignore Ctrl-C (SIGINT), which the parent handles; only possible from a
    process's main thread, so it is skipped elsewhere.
    """
    parent = os.getppid()
    if threading.current_thread() is threading.main_thread():
        if ignore_interrupt:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        # SIGTERM ends a worker (the pool's way to stop one), not the handler of the command
        # it was forked from
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _parent_death_signal(signal.SIGKILL)
    if (parent_pid is not None and parent != parent_pid) or os.getppid() != parent:
        os._exit(1)  # the parent died before the request above took effect
    threading.Thread(target=_watch, args=(parent,), name="die-with-parent", daemon=True).start()


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


def _start_worker(parent_pid: int, n_workers: int) -> None:
    die_with_parent(parent_pid)
    keep_freed_memory()
    limit_blas_threads(n_workers)


@contextmanager
def worker_pool(n: int) -> Iterator[ProcessPoolExecutor]:
    """A process pool of ``n`` workers that end with this process (:func:`die_with_parent`),
    reuse freed memory (:func:`keep_freed_memory`) and share the CPUs' BLAS threads
    (:func:`limit_blas_threads`). Leaving the block normally waits for the
    work submitted; an error, Ctrl-C or a closed generator around it stops the workers at once
    (:func:`stop_pool`)."""
    pool = ProcessPoolExecutor(max_workers=n, initializer=_start_worker, initargs=(os.getpid(), n))
    try:
        yield pool
    except BaseException:
        stop_pool(pool)
        raise
    pool.shutdown()
