"""Output folders that never lose a user's files.

Every command that writes a folder (``mdf run``, ``mdf dataset build``, ``mdf experiment``) opens
it through :func:`output_folder`, before any work starts:

- ``--out`` may be missing (it is created, with its parents), an empty folder, or a folder that
  holds an earlier output of the same command, recognised only by its marker file
  ``.mdf-<command>.json`` (a folder of files that merely have the command's names is the
  user's). Anything else (a file, a non-empty folder without the marker, another command's
  output) is refused with one line, unless ``force``: then the command writes its own files
  into the folder, replacing files of the same names, and deletes nothing.
- The marker lists the files the command wrote, each with its inode, size and modification
  time: a rerun removes only those that still match, never a user's file.
- One lock file (``.mdf.lock``) per folder: a second command on the same folder is refused and
  told the holder's process id and start time. The lock is an advisory ``flock`` on that file, so
  the kernel drops it when its holder dies, however it dies: a lock left by a killed process is
  stale by construction and the next command takes it over. A file system without locks
  (``flock`` fails with ENOLCK) gets a warning, and the command goes on unlocked.
- Files are staged in a ``.mdf-staging-*`` folder inside ``--out`` (or in a folder the user
  chooses on the same file system), locked by its command while it lives, and moved into place
  in one swap (:meth:`OutputFolder.commit`) once every new file is complete. A command killed
  before the swap leaves the earlier output as it was and a staging folder that the next
  command removes; a swap killed half done is recorded in the marker and undone by the next
  command on the folder.
- New files get the permissions the user's umask gives any new file.

POSIX only (``fcntl``).
"""

from __future__ import annotations

import errno
import fcntl
import fnmatch
import json
import os
import re
import shutil
import socket
import stat
import tempfile
import threading
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager, suppress
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .errors import OutputError

LOCK = ".mdf.lock"
STAGING_PREFIX = ".mdf-staging-"
#: the note a failed write's error gets, before the path it was writing
WRITING_NOTE = "while writing "
MARKER_PREFIX = ".mdf-"
MARKER_SUFFIX = ".json"
#: a marker being written (a command killed then leaves it; the next one removes it)
MARKER_TMP = ".mdf-tmp-"
#: names a command never counts as user content (its lock, markers, staging folders)
_INTERNAL = re.compile(r"^\.mdf(\.lock|-.+\.json|-staging-.*|-tmp-.*)$")


#: the most bytes :func:`read_marker_text` reads (a dataset's marker holds up to a few configs)
MAX_MARKER_BYTES = 64 * 1024 * 1024


def read_marker_text(path: Path) -> str:
    """The text of a small file a command wrote (a marker, a lock's details, a dataset's
    manifest), never through a link nor from a pipe or a device, and at most
    :data:`MAX_MARKER_BYTES`: a received folder's marker that links to ``/dev/zero`` would
    otherwise be read until the memory runs out, one that is a pipe waited on forever. Raises
    ``OSError`` or ``ValueError`` (``UnicodeDecodeError``) for anything else, as a damaged
    marker does."""
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    with os.fdopen(fd, "rb") as fh:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise OSError(errno.EINVAL, "not a regular file", str(path))
        raw = fh.read(MAX_MARKER_BYTES + 1)
    if len(raw) > MAX_MARKER_BYTES:
        raise ValueError(f"{path}: more than {MAX_MARKER_BYTES} bytes")
    return raw.decode("utf-8")


def marker_name(command: str) -> str:
    """The marker file of ``command``'s outputs, e.g. ``.mdf-run.json``."""
    return f"{MARKER_PREFIX}{command}{MARKER_SUFFIX}"


def _umask() -> int:
    """The process's umask, read without changing it where the system allows."""
    try:
        with open("/proc/self/status", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except OSError:
        pass
    mask = os.umask(0o022)  # elsewhere: set and restore (not thread-safe, brief)
    os.umask(mask)
    return mask


def new_file_mode() -> int:
    """Permission bits the user's umask gives a new regular file (``0o666 & ~umask``)."""
    return 0o666 & ~_umask()


def _fsync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def atomic_write_bytes(path: Path, data: bytes, *, prefix: str = ".tmp-") -> None:
    """Write ``path`` through a temporary file beside it (named ``prefix``...) and a rename: it
    is either the old file or the complete new one. The file gets the umask's permissions."""
    fh, tmp = _write_temporary(path, lambda fh: fh.write(data), prefix=prefix)
    _put_in_place(fh, tmp, path, new_file_mode())


def _write_temporary(
    path: Path, write: Callable[[Any], object], suffix: str = "", prefix: str = ".tmp-"
) -> tuple[Any, str]:
    """A temporary file beside ``path`` (``prefix`` + ``*`` + ``suffix``), written by
    ``write(fh)`` and left open for :func:`_put_in_place`: the open file and its path. Removed
    if writing fails; the error then names ``path`` (a note ``while writing PATH``: a full disk
    otherwise names no file, or the temporary one)."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=suffix, dir=path.parent)
        try:
            fh = os.fdopen(fd, "wb")
        except BaseException:
            os.close(fd)
            Path(tmp).unlink(missing_ok=True)
            raise
        try:
            write(fh)
        except BaseException:
            with suppress(OSError):
                fh.close()  # a full disk can fail this too
            Path(tmp).unlink(missing_ok=True)
            raise
    except BaseException as exc:
        exc.add_note(f"{WRITING_NOTE}{path}")
        raise
    return fh, tmp


def atomic_write_text(path: Path, text: str, *, prefix: str = ".tmp-") -> None:
    """:func:`atomic_write_bytes` of UTF-8 text."""
    atomic_write_bytes(path, text.encode("utf-8"), prefix=prefix)


def atomic_savez(path: Path, *, in_background: bool = False, **arrays: Any) -> None:
    """``numpy.savez`` into ``path`` atomically (temporary file + rename), umask permissions.

    The data are written to a temporary file beside ``path`` at once. Flushing it to the disk
    (``fsync``) and renaming it into place wait for the disk: ``in_background`` leaves them to
    a thread, and the caller computes on meanwhile; :func:`wait_for_files`, called later by the
    same thread, waits until every such file of that thread is on the disk and in place. A
    dataset worker writes its records so and waits at the end of each task, before it reports
    the task's records (``docs/benchmarks.md`` has what this saves)."""
    import numpy as np

    mode = new_file_mode()  # here: the fallback that reads the umask is not thread-safe
    # the partial file must not look like a record (*.npz) to a reader or a resumed build
    fh, tmp = _write_temporary(path, lambda fh: np.savez(fh, **arrays), ".part")
    if not in_background:
        _put_in_place(fh, tmp, path, mode)
        return
    flush = _Flush(fh, tmp, path, mode)
    try:
        flush.start()
    except RuntimeError:  # no thread to be had (e.g. at interpreter shutdown): do it here
        _put_in_place(fh, tmp, path, mode)
        return
    _pending().append(flush)


def _put_in_place(fh: Any, tmp: str, path: Path, mode: int) -> None:
    """Flush the open temporary file ``fh`` (at ``tmp``) to the disk, close it, give it the
    permission bits ``mode`` and rename it to ``path``; on failure the temporary file is
    removed and the error names ``path``."""
    try:
        with fh:
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException as exc:
        Path(tmp).unlink(missing_ok=True)
        exc.add_note(f"{WRITING_NOTE}{path}")
        raise


class _Flush(threading.Thread):
    """One file's flush and rename (:func:`_put_in_place`), in its own short-lived thread: no
    idle thread outlives a task, so a process that forks later forks no thread of ours."""

    def __init__(self, fh: Any, tmp: str, path: Path, mode: int) -> None:
        super().__init__(name="mdf-flush")
        self._work = (fh, tmp, path, mode)
        self.path = path
        self.error: BaseException | None = None

    def run(self) -> None:
        try:
            _put_in_place(*self._work)
        except BaseException as exc:  # handed to wait_for_files
            self.error = exc


_LOCAL = threading.local()


def _pending() -> list[_Flush]:
    """The files this thread wrote in the background and has not waited for yet."""
    files: list[_Flush] | None = getattr(_LOCAL, "files", None)
    if files is None:
        files = _LOCAL.files = []
    return files


def _forget_pending() -> None:
    """In a forked child: the parent's flush threads do not exist here."""
    global _LOCAL
    _LOCAL = threading.local()


os.register_at_fork(after_in_child=_forget_pending)


def wait_for_files(*, raise_errors: bool = True) -> None:
    """Wait until every file this thread wrote with :func:`atomic_savez` ``in_background`` is
    on the disk and renamed into place, and flush the folders that hold them (so that the
    renames are on the disk too). Raises the first error, after waiting for every file (a file
    that failed leaves no temporary file); ``raise_errors=False`` only waits (for a caller that
    is already raising an error of its own)."""
    files = _pending()
    first: BaseException | None = None
    folders: set[Path] = set()
    while files:
        flush = files.pop(0)
        flush.join()
        if flush.error is None:
            folders.add(flush.path.parent)
        elif first is None:
            first = flush.error
    for folder in folders:
        _fsync_dir(folder)
    if first is not None and raise_errors:
        raise first


def check_output_file(path: str | Path, option: str = "--out") -> Path:
    """Check, before any work starts, that a command can write the single file ``path`` (given
    with ``option``): not a folder, inside an existing folder it may write into. Write it with
    :func:`atomic_write_bytes` (never half-written). Raises :class:`OutputError`."""
    p = Path(path)
    if p.is_dir():
        raise OutputError(f"{option} {p}: is a folder; give the name of a file to write")
    parent = p.parent
    if not parent.exists():
        raise OutputError(f"{option} {p}: the folder {parent} does not exist; create it first")
    if not parent.is_dir():
        raise OutputError(f"{option} {p}: {parent} is a file, not a folder; choose another path")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputError(f"{option} {p}: cannot write into {parent}; choose another folder")
    return p


_UNSAFE = re.compile(r"[^A-Za-z0-9_-]+")


def safe_name(text: str) -> str:
    """A file-name part made from a name taken from a config or data (a group, a label): ASCII
    letters, digits, ``_`` and ``-`` only, so it can never name a path outside its folder. A name
    that had to be changed gets a short digest of the original, so two names never collide
    (``"a/b"`` -> ``"a_b-1e4a"``, ``"../../x"`` -> ``"x-9c3f"``)."""
    import hashlib

    clean = _UNSAFE.sub("_", text).strip("_")[:60]
    if clean == text and clean:
        return clean
    digest = hashlib.sha1(text.encode("utf-8")).hexdigest()[:4]
    return f"{clean}-{digest}" if clean else f"unnamed-{digest}"


# --------------------------------------------------------------------------- the lock


def _process_start(pid: int) -> str:
    """When the process started (UTC, from /proc where available; else now)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="utf-8") as fh:
            ticks = int(fh.read().rsplit(")", 1)[1].split()[19])
        with open("/proc/stat", encoding="utf-8") as fh:
            btime = next(int(line.split()[1]) for line in fh if line.startswith("btime"))
        started = btime + ticks / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError, StopIteration):
        started = time.time()
    return time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime(started))


def _read_holder(path: Path) -> dict[str, Any]:
    for _ in range(20):  # the holder writes its details right after taking the lock
        try:
            info = json.loads(read_marker_text(path))
            if isinstance(info, dict) and "pid" in info:
                return info
        except (OSError, ValueError):
            pass
        time.sleep(0.01)
    return {}


#: what ``flock`` raises when another process holds the lock
_BUSY = (errno.EAGAIN, errno.EACCES, errno.EWOULDBLOCK)


def describe_holder(info: dict[str, Any]) -> str:
    """A lock holder as :func:`lock_holder` gives it, in words: ``process 4242 (mdf run,
    started ..., host ...)``, or ``another process`` when its details are unknown."""
    if not info:
        return "another process"
    return (
        f"process {info.get('pid')} ({info.get('command', 'mdf')}, started "
        f"{info.get('started', '?')}, host {info.get('host', '?')})"
    )


def lock_holder(folder: Path) -> dict[str, Any] | None:
    """The details of the command that holds ``folder``'s lock now (``{}`` when it wrote none),
    or None when no command holds it, for a reader of an output (``load_dataset``) that must
    not read one a command is writing. Reads only: nothing is created, and the lock is tried
    for an instant (shared), not kept."""
    path = folder / LOCK
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)  # (a pipe: no wait)
    except OSError:
        return None  # no lock file (or a link, which no command holds): no command holds it
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except OSError as exc:  # held, or a file system without locks: nothing to tell
        return _read_holder(path) if exc.errno in _BUSY else None
    finally:
        os.close(fd)  # (releases the lock taken, if any)
    return None


class LockWarning(UserWarning):
    """The file system of an output folder has no working file locks (an NFS mount without its
    lock service, some network or FUSE file systems): the command goes on unlocked."""


def _warn_no_locks(folder: Path, exc: OSError) -> None:
    warnings.warn(
        f"--out {folder}: cannot lock the folder ({exc.strerror or exc}: its file system does "
        "not support file locks); nothing keeps another command from writing into it at the "
        "same time, so run one command at a time on it",
        LockWarning,
        stacklevel=3,
    )


def _write_holder(fd: int, command: str, folder: Path) -> int:
    """Write this process's details into the lock file ``fd`` of ``folder``; returns ``fd``.
    When they cannot be written (a full disk), the lock file is removed and ``fd`` closed, and
    :class:`OutputError` names the folder."""
    info = {
        "pid": os.getpid(),
        "command": command,
        "started": _process_start(os.getpid()),
        "host": socket.gethostname(),
    }
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, (json.dumps(info) + "\n").encode(), 0)
    except OSError as exc:
        release_lock(folder, fd)
        raise OutputError(
            f"--out {folder}: cannot write the lock file ({exc.strerror or exc}); free some "
            "space or choose another folder"
        ) from None
    return fd


def acquire_lock(folder: Path, command: str) -> int:
    """Take the folder's lock; returns its file descriptor. Raises :class:`OutputError` naming
    the holder when another process holds it. A lock file left by a dead process is taken
    over (the kernel released its ``flock`` when it died)."""
    path = folder / LOCK
    for _ in range(10):
        try:  # never through a link (a received folder's lock must not name a file elsewhere)
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK, 0o666)
        except OSError as exc:
            if exc.errno == errno.ELOOP or os.path.islink(path):
                raise _not_a_lock(folder) from None
            raise OutputError(
                f"--out {folder}: cannot write into the folder ({exc.strerror}); choose a "
                "folder you can write to"
            ) from None
        if not stat.S_ISREG(os.fstat(fd).st_mode):  # a pipe or a device, never written
            os.close(fd)
            raise _not_a_lock(folder)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            if exc.errno not in _BUSY:
                _warn_no_locks(folder, exc)
                return _write_holder(fd, command, folder)  # removed at the end, as a lock is
            os.close(fd)
            who = describe_holder(_read_holder(path))
            raise OutputError(
                f"--out {folder}: in use by {who}; wait for it to finish or choose another folder"
            ) from None
        # the file may have been removed (released) between open and flock: lock the one there
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(path))
        except FileNotFoundError:
            same = False
        if not same:
            os.close(fd)
            continue
        return _write_holder(fd, command, folder)
    raise OutputError(f"--out {folder}: could not take the lock {path}; try again")


def _not_a_lock(folder: Path) -> OutputError:
    return OutputError(
        f"--out {folder}: holds {LOCK} as a link or a special file, not the lock file mdf "
        "writes (a folder from elsewhere?); remove it, or choose another folder"
    )


def release_lock(folder: Path, fd: int) -> None:
    """Remove the lock file (while still holding it) and release the lock."""
    try:
        (folder / LOCK).unlink(missing_ok=True)
    finally:
        os.close(fd)


# --------------------------------------------------------------------------- the folder


@dataclass
class OutputFolder:
    """An output folder held (locked) by one command.

    ``previous``: the folder holds an earlier output of this command (so the command may
    replace its own files there); ``marker``: that output's marker (``{}`` for outputs written
    before markers existed); ``created``: the folder did not exist before.
    """

    path: Path
    command: str
    patterns: tuple[str, ...]
    previous: bool
    marker: dict[str, Any]
    created: bool
    staging_dir: Path | None = None
    force: bool = False
    _stages: list[Path] = field(default_factory=list)
    _stage_locks: list[int] = field(default_factory=list)

    def own(self, name: str) -> bool:
        """Whether ``name`` is a file this command writes."""
        return any(fnmatch.fnmatchcase(name, p) for p in self.patterns)

    def stage(self) -> Path:
        """A new, empty staging folder on the output's file system, locked (``flock`` on the
        folder itself) while this process lives, so that a sweep of ``--staging-dir`` can tell
        a live command's staging folder from one a killed command left."""
        where = self.staging_dir or self.path
        stage = Path(tempfile.mkdtemp(prefix=f"{STAGING_PREFIX}{self.command}-", dir=where))
        self._stages.append(stage)
        fd = os.open(stage, os.O_RDONLY)
        self._stage_locks.append(fd)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # new: nobody else holds it
        except OSError:  # no locks here (warned when --out was locked): never swept as stale
            pass
        return stage

    def previous_files(self) -> list[str]:
        """The earlier output's own files: those its marker lists, and only while each is still
        the very file the command wrote (same inode, size and modification time, recorded in
        the marker), never a file of the user's that merely has one of the command's names."""
        if not self.previous:
            return []
        listed = self.marker.get("files")
        stamps = self.marker.get("stamps")
        if not isinstance(listed, list):
            return []
        names = [n for n in listed if isinstance(n, str) and self.own(n) and "/" not in n]
        if not isinstance(stamps, dict):  # markers of earlier versions listed names only
            return [n for n in names if (self.path / n).is_file()]
        return [n for n in names if _stamp(self.path / n) == stamps.get(n)]

    def write_marker(self, **extra: Any) -> None:
        """Write this command's marker (which makes the folder a previous output next time)."""
        marker = {"command": self.command, **extra}
        atomic_write_text(
            self.path / marker_name(self.command), json.dumps(marker, indent=2), prefix=MARKER_TMP
        )
        self.marker = marker
        self.previous = True

    def commit(self, stage: Path, *, keep: Sequence[str] = ()) -> list[Path]:
        """Move every file of ``stage`` into the folder, once all of them are complete, and
        remove the earlier output's own files (:meth:`previous_files`) that were not made again
        (never the names in ``keep``, never anything else). Returns the new files' paths.

        The swap is all or nothing: the files it replaces are first moved aside into the
        staging folder, and the marker records the swap (``"swap"``) before the first rename.
        An error or Ctrl-C during the swap moves everything back at once (and Ctrl-C or SIGTERM
        arriving during the swap is held until it ends); a process killed outright leaves the
        record, and the next command on the folder moves everything back before it starts
        (:func:`_undo_swap`): the earlier output as it was. Without ``force`` a file the
        command would replace that it did not write (a file of the user's with one of its
        names) is refused, before anything moves."""
        names = sorted(p.name for p in stage.iterdir())
        for name in names:
            if not self.own(name):
                raise RuntimeError(f"{name!r} is not one of the files `{self.command}` writes")
        ours = set(self.previous_files())
        folders = [n for n in names if (self.path / n).is_dir() and n not in ours]
        if folders:
            raise OutputError(
                f"--out {self.path}: holds the folder {_describe(folders)}, where `mdf "
                f"{self.command}` writes a file; move it away or choose another folder"
            )
        if not self.force:
            foreign = [n for n in names if os.path.lexists(self.path / n) and n not in ours]
            if foreign:
                raise OutputError(
                    f"--out {self.path}: holds {_describe(foreign)}, which `mdf {self.command}` "
                    "writes, but not the very files it wrote there (edited, replaced, or copied "
                    "from elsewhere, as a copied output folder's are); move it away, or add "
                    "--force to replace it"
                )
        stale = [n for n in sorted(ours) if n not in names and n not in keep]
        aside = stage / _ASIDE
        aside.mkdir()
        marker_path = self.path / marker_name(self.command)
        try:
            before: str | None = read_marker_text(marker_path)
        except (OSError, ValueError):
            before = None
        journal = {"stage": str(stage), "new": names, "previous_marker": before}
        with _signals_held():
            self.write_marker(swap=journal)  # from here on a kill is undone by the next command
            moved_in: list[str] = []
            moved_aside: list[str] = []
            try:
                for name in names:
                    if os.path.lexists(self.path / name):
                        os.replace(self.path / name, aside / name)
                        moved_aside.append(name)
                    os.replace(stage / name, self.path / name)
                    moved_in.append(name)
                for name in stale:
                    os.replace(self.path / name, aside / name)
                    moved_aside.append(name)
                files = sorted({*names, *(k for k in keep if (self.path / k).exists())})
                self.write_marker(files=files, stamps={n: _stamp(self.path / n) for n in names})
            except BaseException:
                for name in reversed(moved_in):
                    os.replace(self.path / name, stage / name)
                for name in moved_aside:
                    os.replace(aside / name, self.path / name)
                _restore_marker(marker_path, before)
                self.marker = json.loads(before) if before else {}
                raise
        _fsync_dir(self.path)
        shutil.rmtree(stage, ignore_errors=True)  # with the replaced files
        return [self.path / name for name in names]

    def user_entries(self) -> list[str]:
        """Entries of the folder other than the lock, markers and staging folders."""
        return sorted(p.name for p in self.path.iterdir() if not _INTERNAL.match(p.name))


#: the folder inside a staging folder that holds the files a commit replaces, until it ends
_ASIDE = ".mdf-aside"


def _stamp(path: Path) -> list[int] | None:
    """What identifies the file a command wrote: inode, size, modification time [ns] (a rename
    keeps all three; a user's edit or a new file changes them); None for no regular file."""
    try:
        st = os.lstat(path)
    except OSError:
        return None
    if not stat.S_ISREG(st.st_mode):
        return None
    return [st.st_ino, st.st_size, st.st_mtime_ns]


def _restore_marker(path: Path, text: str | None) -> None:
    """Put back the marker a commit started from (``None``: there was none)."""
    if text is None:
        path.unlink(missing_ok=True)
    else:
        atomic_write_text(path, text, prefix=MARKER_TMP)


@contextmanager
def _signals_held() -> Iterator[None]:
    """Hold Ctrl-C and SIGTERM for the block (a swap of files lasts milliseconds): one that
    arrives meanwhile is delivered, to the handler that was in place, when the block ends. Only
    in the main thread (elsewhere signals cannot be handled and the block runs as it is)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    import signal

    held: list[int] = []
    wanted = (signal.SIGINT, signal.SIGTERM)
    previous: dict[int, Any] = {}
    for sig in wanted:
        previous[sig] = signal.signal(sig, lambda signum, frame: held.append(signum))
    try:
        yield
    finally:
        for sig in wanted:
            signal.signal(sig, previous[sig])
        for num in dict.fromkeys(held):
            handler = previous[num]
            if callable(handler):
                handler(num, None)
            elif handler == signal.SIG_DFL:
                signal.raise_signal(num)


def _undo_swap(folder: Path, command: str) -> None:
    """If a command was killed while it moved its files into ``folder`` (its marker still holds
    the swap's record), move everything back: the earlier output as it was, with its marker.
    Called with the folder's lock held, before staging folders are swept."""
    path = folder / marker_name(command)
    try:
        marker = json.loads(read_marker_text(path))
    except (OSError, ValueError):
        return
    swap = marker.get("swap") if isinstance(marker, dict) else None
    if not isinstance(swap, dict):
        return
    stage = Path(str(swap.get("stage", "")))
    new = swap.get("new")
    before = swap.get("previous_marker")
    aside = stage / _ASIDE
    if (
        not stage.name.startswith(STAGING_PREFIX)
        or not _real_folder(stage)
        or (os.path.lexists(aside) and not _real_folder(aside))
        or not isinstance(new, list)
    ):
        # the staging folder is gone (another command swept its --staging-dir), or is not
        # one a command made (a link): what moved in stays, as files the earlier output did
        # not write
        _restore_marker(path, before if isinstance(before, str) else None)
        return
    for name in new:
        if (
            isinstance(name, str)
            and "/" not in name
            and not (stage / name).exists()
            and not _real_folder(folder / name)  # a command moves in files only
        ):
            (folder / name).unlink(missing_ok=True)  # moved in: the new output's
    if aside.is_dir():
        for old in aside.iterdir():
            os.replace(old, folder / old.name)
    _restore_marker(path, before if isinstance(before, str) else None)
    shutil.rmtree(stage, ignore_errors=True)
    _fsync_dir(folder)


def _real_folder(path: Path) -> bool:
    """A folder, not a link to one (a received folder's marker may name any path: a swap is
    undone only between real staging folders, never moving files from where a link points)."""
    return path.is_dir() and not path.is_symlink()


def _sweep_stale_stages(where: Path) -> None:
    """Remove the staging folders in ``where`` that killed commands left: those no live
    process holds (a command holds each of its staging folders' ``flock`` while it lives)."""
    for leftover in where.glob(f"{STAGING_PREFIX}*"):
        if not leftover.is_dir() or leftover.is_symlink():
            continue
        try:
            fd = os.open(leftover, os.O_RDONLY)
        except OSError:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            continue  # a live command's
        finally:
            os.close(fd)  # (releases the lock taken, if any)
        shutil.rmtree(leftover, ignore_errors=True)


def _check_staging_dir(staging_dir: Path, out: Path) -> Path:
    try:
        st = os.stat(staging_dir)
    except OSError as exc:
        raise OutputError(f"--staging-dir {staging_dir}: {exc.strerror}") from None
    if not staging_dir.is_dir():
        raise OutputError(f"--staging-dir {staging_dir}: not a folder")
    if st.st_dev != os.stat(out).st_dev:
        raise OutputError(
            f"--staging-dir {staging_dir}: on another file system than --out {out}; files are "
            "moved into place by renames, so choose a folder on the same file system"
        )
    if not os.access(staging_dir, os.W_OK | os.X_OK):
        raise OutputError(f"--staging-dir {staging_dir}: cannot write into the folder")
    return staging_dir


def _describe(entries: list[str]) -> str:
    shown = ", ".join(repr(e) for e in entries[:3])
    return shown + (f" and {len(entries) - 3} more" if len(entries) > 3 else "")


def _inspect(out: Path, command: str, patterns: tuple[str, ...], force: bool) -> OutputFolder:
    """Classify an existing folder (called with its lock held). Only the command's marker makes
    a folder an earlier output: a folder of files with the command's names but no marker is
    the user's (or an output of a version before markers, 2026-11), refused without ``force``."""
    folder = OutputFolder(
        out, command, patterns, previous=False, marker={}, created=False, force=force
    )
    entries = folder.user_entries()
    markers = sorted(
        p.name
        for p in out.iterdir()
        if p.name.startswith(MARKER_PREFIX) and p.name.endswith(MARKER_SUFFIX)
    )
    mine = marker_name(command)
    if mine in markers:
        try:
            marker = json.loads(read_marker_text(out / mine))
        except (OSError, ValueError):
            marker = {}
        folder.marker = marker if isinstance(marker, dict) else {}
        folder.previous = True
        return folder
    others = [m[len(MARKER_PREFIX) : -len(MARKER_SUFFIX)] for m in markers]
    if not entries and not others:
        return folder
    if force:
        return folder
    what = (
        f"holds the output of `mdf {others[0]}`"
        if others
        else f"is not empty ({_describe(entries)}) and holds no earlier `mdf {command}` output"
    )
    raise OutputError(
        f"--out {out}: the folder {what}; choose a new or empty folder, or add --force to "
        f"write `mdf {command}`'s files into it (replacing files of the same names, deleting "
        "nothing else)"
    )


@contextmanager
def output_folder(
    out: str | Path,
    command: str,
    patterns: Sequence[str],
    *,
    force: bool = False,
    staging_dir: str | Path | None = None,
) -> Iterator[OutputFolder]:
    """Check, create and lock ``out`` for ``command`` (whose files match ``patterns``), before any
    work starts; see the module docstring for the rules. On leaving, staging folders are removed
    and the lock released; when the block fails and the folder was created here and holds
    nothing of the user's or the command's, it is removed again."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise OutputError(f"--out {out}: is a file, not a folder; choose a folder")
    created = False
    if not out.exists():
        missing = [p for p in (out, *out.parents) if not p.exists()]
        try:
            out.mkdir(parents=True)
        except FileExistsError:
            if not out.is_dir():
                raise OutputError(f"--out {out}: is a file, not a folder") from None
        except OSError as exc:
            for p in missing[1:]:  # folders made on the way, innermost first
                try:
                    p.rmdir()
                except OSError:
                    pass
            raise OutputError(
                f"--out {out}: cannot create the folder ({exc.strerror}); choose a folder you "
                "can write to"
            ) from None
        created = True
    else:
        missing = []
    lock = None
    folder = None
    ok = False
    try:
        with _signals_held():  # a Ctrl-C comes after the lock is taken and kept for release
            lock = acquire_lock(out, f"mdf {command}")
        for partial in out.glob(f"{MARKER_TMP}*"):  # markers a killed command was writing
            partial.unlink(missing_ok=True)
        for marker in out.glob(f"{MARKER_PREFIX}*{MARKER_SUFFIX}"):  # swaps killed half done
            _undo_swap(out, marker.name[len(MARKER_PREFIX) : -len(MARKER_SUFFIX)])
        folder = _inspect(out, command, tuple(patterns), force)
        folder.created = created
        if staging_dir is not None:
            folder.staging_dir = _check_staging_dir(Path(staging_dir), out)
            _sweep_stale_stages(folder.staging_dir)
        _sweep_stale_stages(out)  # from a killed command
        yield folder
        ok = True
    finally:
        with _signals_held():  # a Ctrl-C comes after the clean-up: the lock is always released
            if folder is not None:
                for stage in folder._stages:
                    shutil.rmtree(stage, ignore_errors=True)
                for fd in folder._stage_locks:
                    os.close(fd)
            if not ok and created:
                _remove_if_empty(out, missing)  # while still holding the lock
            if lock is not None:
                release_lock(out, lock)


def _empty_folder(path: Path) -> bool:
    """A folder (not a link to one) that holds nothing."""
    return path.is_dir() and not path.is_symlink() and not any(path.iterdir())


def _remove_if_empty(out: Path, made: list[Path]) -> None:
    """Remove a folder this command created (and the parents it made), if it holds nothing but
    the command's internals and empty folders (a dataset's ``records/`` before its first
    record)."""
    try:
        entries = list(out.iterdir())
        if any(not _INTERNAL.match(p.name) and not _empty_folder(p) for p in entries):
            return
    except OSError:
        return
    shutil.rmtree(out, ignore_errors=True)
    for parent in made[1:]:
        try:
            parent.rmdir()
        except OSError:
            return
