"""The Dask clusters a dataset build runs on: the scheduler's address and connection, the
checks of a cluster of one's own (its workers, their versions, the paths they see), and the
quiet logs of a build on Dask.

A build runs on Dask when a scheduler is given (``mdf dataset build --scheduler``, or the
:data:`SCHEDULER_ENV` environment variable): ``local`` starts a local cluster in this process
(:data:`LOCAL_DASK_CONFIG`), an address connects to a cluster started elsewhere, whose workers
must run this mdframework and its plugins and see the data and the output folder at the same
paths (docs/datasets.md). Dask is imported only inside these functions.
"""

from __future__ import annotations

import os
import threading
import time
import warnings
from collections.abc import Callable, Iterator
from concurrent.futures import CancelledError
from contextlib import contextmanager
from typing import Any

from .errors import SettingError
from .plugins import versions

#: Environment variables that choose a Dask scheduler (when --scheduler is not given) and its
#: connection timeout [s].
SCHEDULER_ENV = "MDF_DASK_SCHEDULER"
SCHEDULER_TIMEOUT_ENV = "MDF_DASK_TIMEOUT"
#: Default connection timeout to a Dask scheduler [s].
SCHEDULER_TIMEOUT_S = 10.0


def scheduler_address(given: str | None) -> str | None:
    """The Dask scheduler: ``given`` (the command line), else the :data:`SCHEDULER_ENV`
    environment variable, else ``None`` (local processes). Never a config file: a shared config
    must not send work, or data, to a machine of its author's choosing."""
    return given or os.environ.get(SCHEDULER_ENV) or None


def check_scheduler_address(address: str | None) -> None:
    """Refuse a malformed scheduler address (``HOST:PORT``, ``SCHEME://HOST:PORT``,
    ``inproc://...`` or ``local``), or a malformed connection timeout, before any folder is
    made or process started; the timeout is for addresses that are well formed but do not
    answer."""
    if address is None or address == "local":
        return
    try:
        from distributed.comm.addressing import parse_address, parse_host_port
        from distributed.comm.registry import get_backend
    except ImportError:
        raise SettingError("a Dask scheduler needs `pip install mdframework[dask]`") from None
    try:
        scheme, location = parse_address(address)
        get_backend(scheme)  # a scheme misspelt (tpc://) was found out after planning
        if scheme != "inproc":
            parse_host_port(location)
    except ValueError as exc:
        raise SettingError(
            f"Dask scheduler {address!r}: not an address ({' '.join(str(exc).split())}); give "
            f"HOST:PORT, tcp://HOST:PORT or 'local' with --scheduler or {SCHEDULER_ENV}"
        ) from None
    scheduler_timeout()


def scheduler_timeout() -> float:
    """Connection timeout to a Dask scheduler [s]: :data:`SCHEDULER_TIMEOUT_ENV`, else
    :data:`SCHEDULER_TIMEOUT_S`."""
    text = os.environ.get(SCHEDULER_TIMEOUT_ENV)
    if text is None:
        return SCHEDULER_TIMEOUT_S
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 < value <= 3600:
        raise SettingError(
            f"{SCHEDULER_TIMEOUT_ENV}={text!r}: give a timeout in seconds, 0 < t <= 3600"
        )
    return value


def connect(client_cls: Any, cluster: Any, address: str) -> Any:
    """A Dask client of the local cluster or of the scheduler at ``address``; an unreachable
    scheduler is a one-line error after the connection timeout."""
    if cluster is not None:
        return client_cls(cluster)
    timeout = scheduler_timeout()
    try:
        return client_cls(address, timeout=timeout)
    except (OSError, TimeoutError, ValueError, TypeError) as exc:
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise SettingError(
            f"cannot connect to the Dask scheduler {address!r} within {timeout:g} s ({reason}); "
            f"check --scheduler or {SCHEDULER_ENV}, or set {SCHEDULER_TIMEOUT_ENV}"
        ) from None
    except Exception as exc:  # whatever answers there is not a Dask scheduler
        reason = f"{type(exc).__name__}: {' '.join(str(exc).split())}"
        raise SettingError(
            f"the Dask scheduler {address!r} gave an answer Dask cannot read ({reason[:200]}): "
            f"it is not a Dask scheduler, or not of this version; check --scheduler or "
            f"{SCHEDULER_ENV}"
        ) from None


#: Dask settings of the local cluster a build starts (its scheduler and nannies run in this
#: process; its workers inherit the settings; a cluster started elsewhere is configured by its
#: owner, docs/datasets.md). The statistical profiler samples every worker thread every 10 ms
#: and nothing reads its profiles. Dask starts its workers with MALLOC_TRIM_THRESHOLD_ set,
#: which turns off glibc's adaptive mmap threshold: every array over 128 KiB is then mapped and
#: unmapped afresh, and a record took 2.4 times as long as in a local worker. The event-loop
#: health check (every 20 ms), the system monitor (500 ms; it feeds the dashboard, which is
#: off), the memory monitor (100 ms) and the cluster's widget text (500 ms) cost an idle
#: one-worker cluster 38 ms CPU a second between its two processes; at the intervals below,
#: 7 ms. The memory limits still hold (checked every 0.5 s instead of 0.1 s), and an event
#: loop blocked for over 3 s is still reported.
LOCAL_DASK_CONFIG: dict[str, Any] = {
    "distributed.worker.profile.enabled": False,
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.worker.memory.monitor-interval": "500ms",
    "distributed.deploy.cluster-repr-interval": "10s",
}


def check_workers(client: Any, address: str, category: type[Warning] = UserWarning) -> None:
    """:class:`SettingError` unless the cluster at ``address`` has a worker within the
    connection timeout (a build on a scheduler without workers waited forever, silently), and
    every worker runs this mdframework and these plugins (a worker without a plugin failed
    every record of it as the config's error; one of another version computed records that
    a local build would not). Other versions of Python, NumPy or SciPy are a warning: records
    may differ from a local build's in the last bits, and each names the versions it ran
    (a warning of ``category``)."""
    timeout = scheduler_timeout()
    try:
        client.wait_for_workers(1, timeout=timeout)
    except TimeoutError:
        raise SettingError(
            f"the Dask scheduler {address!r} has no workers (waited {timeout:g} s for one); "
            f"start them (`dask worker {address}`), or set {SCHEDULER_TIMEOUT_ENV}"
        ) from None
    ours = versions()
    numeric = ("python", "numpy", "scipy", "scikit-learn")
    others: set[str] = set()
    for worker, theirs in sorted(client.run(versions, on_error="return").items()):
        if isinstance(theirs, (OSError, TimeoutError)):
            continue  # a worker that left meanwhile (killed, restarting): Dask does without it
        if isinstance(theirs, BaseException):  # no mdframework there, or one without versions
            reason = " ".join(str(theirs).split())  # a function it cannot unpickle: Dask's
            # Exception('ModuleNotFoundError(...)'), not the error itself
            if type(theirs) is not Exception:
                reason = f"{type(theirs).__name__}: {reason}"
            reason = reason[:200]
            raise SettingError(
                f"Dask worker {worker} cannot run mdframework ({reason}); every worker needs "
                "the build's mdframework and plugins installed"
            )
        missing = sorted(set(ours["plugins"]) - set(theirs.get("plugins", ())))
        diff = [f"mdframework {theirs.get('mdframework')!r}, not {ours['mdframework']!r}"] * (
            theirs.get("mdframework") != ours["mdframework"]
        )
        diff += [f"no {', '.join(missing)}"] * bool(missing)
        if diff:
            raise SettingError(
                f"Dask worker {worker} has {'; '.join(diff)}: every worker needs the build's "
                "mdframework and plugins, of the same versions"
            )
        others |= {f"{k} {theirs.get(k)!r}" for k in numeric if theirs.get(k) != ours[k]}
    if others:
        warnings.warn(
            f"Dask workers run {', '.join(sorted(others))}, not this process's versions: their "
            "records may differ in the last bits from a local build's",
            category,
            stacklevel=2,
        )


class Workerless(threading.Thread):
    """Watches a Dask build's cluster for the connection timeout without a worker (every
    worker killed: Dask waits for new ones, and the build waited forever, silently); then
    cancels the build's ``futures``, and :attr:`error` says why. Stopped by :meth:`stop`.
    A thread of the build's process (Dask's own loop runs in another): a loop waiting on the
    futures with a timeout cost the build's process 0.7 s of CPU more for 1260 records."""

    def __init__(self, client: Any, futures: list[Any], address: str) -> None:
        super().__init__(name="mdf-dask-workers", daemon=True)
        self.client, self.futures, self.address = client, futures, address
        self.timeout = scheduler_timeout()
        self.error: SettingError | None = None
        self._done = threading.Event()

    def run(self) -> None:
        alone_since = None
        while not self._done.wait(1.0):
            try:
                workers = bool(self.client.nthreads())
            except Exception:  # the scheduler lost: the futures are cancelled by Dask
                return
            if workers:
                alone_since = None
            elif alone_since is None:
                alone_since = time.monotonic()
            elif time.monotonic() - alone_since > self.timeout:
                self.error = SettingError(
                    f"the Dask scheduler {self.address!r} has had no workers for "
                    f"{self.timeout:g} s (they were killed, or left); the records finished "
                    "stay, and the same command, run again when it has workers, resumes from "
                    f"them (or set {SCHEDULER_TIMEOUT_ENV} to wait longer)"
                )
                self.client.cancel(self.futures)
                return

    def stop(self) -> None:
        self._done.set()
        self.join()


def _missing_paths(paths: list[str]) -> list[str]:
    """Those of ``paths`` that this process (a Dask worker) does not see."""
    return [path for path in paths if not os.path.exists(path)]


def check_paths(client: Any, paths: list[str]) -> None:
    """:class:`SettingError` naming a Dask worker that does not see one of ``paths``, the
    records folder and the data files, before any record: the workers read the data and write
    the records themselves (a worker on a machine without them failed every record, as the
    config's error 'file not found' or an internal error)."""
    for worker, missing in sorted(client.run(_missing_paths, paths, on_error="return").items()):
        if isinstance(missing, BaseException) or not missing:
            continue  # a worker that left meanwhile: Dask does without it
        more = f" (and {len(missing) - 1} more)" if len(missing) > 1 else ""
        raise SettingError(
            f"Dask worker {worker} does not see {missing[0]}{more}: the workers read the "
            "data files and write the records by the paths of this machine, so the data and "
            "--out must be on a file system they share, at the same paths"
        )


def cluster_failure(exc: BaseException, address: str, record: str, out: str) -> SettingError:
    """The one line for a Dask cluster that failed under a build: the scheduler lost, or
    the workers running a task all died (killed, out of memory); the records finished stay."""
    if isinstance(exc, CancelledError):  # Dask cancels every task when the scheduler is lost
        what = f"lost the Dask scheduler {address!r} (record {record} and others cancelled)"
    else:
        what = (
            f"Dask workers died while building record {record} and the records after it in "
            f"its task, on every worker Dask tried (killed, or out of memory: see the workers' "
            "logs)"
        )
    return SettingError(
        f"{what}; the records finished stay in {out}, and the same command, run again, "
        "resumes from them"
    )


@contextmanager
def quiet_dask_logs() -> Iterator[None]:
    """Silence Dask's own log in this process (a local cluster's nannies and scheduler live
    here; the client of a cluster of one's own too) while a build runs on Dask: a record's
    error, or the cluster's failure, reaches the user as one line, and Dask's log of it (the
    client's traceback of a lost scheduler), of the tasks cancelled after it or of Ctrl-C
    would only surround it.
    Tornado's too, whose event loop runs Dask's: a Ctrl-C that lands while the client waits
    on the loop can make Dask's cancelling callback fail there, and tornado logged that with
    its traceback (now and then, on a busy machine)."""
    import logging

    logs = [logging.getLogger(name) for name in ("distributed", "distributed.client", "tornado")]
    levels = [log.level for log in logs]
    for log in logs:
        log.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for log, level in zip(logs, levels, strict=True):
            log.setLevel(level)


def quiet_dask_worker(show: Callable[..., None], filters: list[tuple[Any, ...]]) -> bool:
    """:func:`quiet_dask_logs` in a local cluster's worker process, for its lifetime, and
    Ctrl-C ignored there, as in the process pool's workers: the build's process handles it
    and closes the cluster (the worker's own KeyboardInterrupt printed a traceback). The
    worker also takes the build process's warning handling, which the pool's workers inherit
    as copies of it: ``show`` prints a warning (``mdf: warning: ...`` under ``mdf``; Python's
    own format, with the file and line, was printed) and ``filters``
    (:func:`~mdframework.workers.warning_filters`) decide which warnings are errors (``mdf``
    stops at a numerical warning rather than write a record it cannot trust; a Dask build
    wrote it). Whether Ctrl-C could be ignored (only from
    the worker's main thread)."""
    import logging
    import signal

    from .workers import take_warnings

    logging.getLogger("distributed").setLevel(logging.CRITICAL)
    take_warnings(show, filters)
    if threading.current_thread() is not threading.main_thread():
        return False
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    return True
