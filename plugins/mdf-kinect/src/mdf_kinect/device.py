"""OpenNI2 devices and ``.oni`` recordings, and NiTE2 skeleton tracking, through the ``openni``
binding and the system libraries.

- OpenNI2 (Debian ``libopenni2-0``): the library folder comes from ``OPENNI2_REDIST`` or the
  Debian location ``/usr/lib/x86_64-linux-gnu``; the binding wants byte-string paths.
- NiTE2 (proprietary, not in any package registry): its ``Redist`` folder (holding
  ``libNiTE2.so`` and ``NiTE2/``) comes from the ``nite2_redist`` argument, else the
  ``NITE2_REDIST64`` environment variable (NiTE 2.2's install.sh exports only this one on x86_64),
  else ``NITE2_REDIST``. Without it, skeleton tracking stops with :class:`NiteMissingError`;
  there is no fallback. NiTE2 loads its data (``NiTE2/s.dat``...) relative to the current
  directory when a user tracker is created: create it there (``contextlib.chdir``).

``.oni`` files are checked in Python first (:func:`scan_oni`: the 24-byte ``NI10`` header, then
records with a 28-byte header, ``NIR\\0`` magic, type, node id, fields size (header included),
payload size, 64-bit undo position; 24 bytes and 32-bit positions before file version 1.0.1.0),
so that a bad file gets an error naming the record rather than the library's bare
``ONI_STATUS_ERROR``; frames are then read through OpenNI2, in order (seeking is unreliable in
that library).
"""

from __future__ import annotations

import os
import struct
from collections.abc import Iterator
from contextlib import closing, contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from mdframework import DataFileError, MdfError, limits

#: Where Debian installs libOpenNI2.so.
DEBIAN_OPENNI2 = "/usr/lib/x86_64-linux-gnu"

#: Record types of the .oni format (OpenNI2 OniDataRecords / OpenNI 1 DataRecords).
RECORD_TYPES: dict[int, str] = {
    2: "node added (1.0.0.4)",
    3: "int property",
    4: "real property",
    5: "string property",
    6: "general property",
    7: "node removed",
    8: "node data begin",
    9: "node state ready",
    10: "new data",
    11: "end",
    12: "node added (1.0.0.5)",
    13: "node added",
    14: "seek table",
}
NEW_DATA = 10
NODE_ADDED = (2, 12, 13)
NODE_REMOVED = 7
END = 11
SEEK_TABLE = 14
#: Node types OpenNI2's file player plays (XnProductionNodeType): device, depth, image, IR.
NODE_TYPES: dict[int, str] = {1: "device", 2: "depth", 3: "image", 5: "IR"}
#: Codecs of recorded streams (XnCodecIDs).
CODECS = (b"NONE", b"16zP", b"16zT", b"Im8z", b"JPEG")
FILE_HEADER = struct.Struct(
    "<4sBBHIQI"
)  # magic, version (major, minor, maint, build), max ts, max node
RECORD_HEADER = struct.Struct("<4sIIIIQ")
#: The record header of files before version 1.0.1.0 (a 32-bit undo position).
OLD_RECORD_HEADER = struct.Struct("<4sIIIII")


class DeviceError(MdfError):
    """OpenNI2 cannot be loaded or no device can be opened."""


class NiteMissingError(MdfError):
    """Skeleton tracking was asked for but NiTE2 is not installed or not found."""


NITE_HELP = (
    "skeleton tracking needs NiTE2 (PrimeSense's proprietary user tracker; it is not in any "
    "package registry): install NiTE 2.2 from your vendor's download and point to its Redist "
    "folder (the one holding libNiTE2.so) with the environment variable NITE2_REDIST64 or "
    "NITE2_REDIST or the --nite2 option of mdf capture"
)


@dataclass(frozen=True)
class OniScan:
    """What :func:`scan_oni` found: record counts by type, frames per node id, node names."""

    n_records: int
    by_type: dict[str, int]
    frames_per_node: dict[int, int]
    nodes: dict[int, str]
    #: node id -> node type (:data:`NODE_TYPES`: 2 is depth)
    node_types: dict[int, int] = field(default_factory=dict)

    def depth_frames(self) -> int:
        """Frames of the depth stream(s)."""
        return sum(n for node, n in self.frames_per_node.items() if self.node_types.get(node) == 2)


def scan_oni(path: Path) -> OniScan:
    """Check an ``.oni`` file's structure (header and record chain) without the library.

    Raises :class:`~mdframework.DataFileError` naming the file and record (number and byte
    offset) for a wrong magic, a truncated record, an unknown record type, a node-added record
    that does not hold a name, a known node type and codec and (for a stream with frames) the
    place of its seek table, a file without any frame, or a file that ends without the records
    a complete recording closes with (an end record and a node-removed record for every node,
    in either order: OpenNI2's recorder writes the end last, OpenNI 1.x's first). Files before
    version 1.0.1.0 have 24-byte record headers and 32-bit positions, later ones 28 and 64 (as
    OpenNI2's player reads them). After the end record only node-removed records and seek tables
    may follow (OpenNI2 plays nothing after it).
    """
    data = limits.read_file_bytes(path)  # a named pipe or a device: refused unread
    if len(data) < FILE_HEADER.size:
        raise DataFileError(path, f"{len(data)} bytes: too short for the 24-byte .oni header")
    magic = data[:4]
    if magic != b"NI10":
        raise DataFileError(path, f"not an OpenNI recording: header magic {magic!r}, not b'NI10'")
    version = FILE_HEADER.unpack_from(data, 0)[1:5]
    layout = OLD_RECORD_HEADER if version < (1, 0, 1, 0) else RECORD_HEADER
    header = layout.size
    pos = FILE_HEADER.size
    n = 0
    by_type: dict[str, int] = {}
    frames: dict[int, int] = {}
    nodes: dict[int, str] = {}
    node_types: dict[int, int] = {}
    seek_at: dict[int, tuple[int, int]] = {}  # node -> (its seek table's byte, record number)
    records: dict[int, tuple[int, int]] = {}  # byte -> (type, node)
    removed: set[int] = set()
    last = "the header"
    ended = False
    while pos < len(data):
        if ended and data[pos : pos + 4] != b"NIR\0":
            break  # bytes after the end record that are no record: not read, as by OpenNI2
        n += 1
        if pos + header > len(data):
            raise DataFileError(path, f"record {n} at byte {pos}: truncated record header")
        rmagic, rtype, node, fsize, psize, _undo = layout.unpack_from(data, pos)
        if rmagic != b"NIR\0":
            raise DataFileError(
                path, f"record {n} at byte {pos}: record magic {rmagic!r}, not b'NIR\\x00'"
            )
        if fsize < header or pos + fsize + psize > len(data):
            raise DataFileError(
                path, f"record {n} at byte {pos}: truncated (sizes run past the end)"
            )
        if rtype not in RECORD_TYPES:
            raise DataFileError(
                path, f"record {n} at byte {pos}: unknown record type {rtype} (after {last})"
            )
        name = RECORD_TYPES[rtype]
        if ended and rtype not in (NODE_REMOVED, SEEK_TABLE):
            raise DataFileError(
                path,
                f"record {n} ({name}) at byte {pos} follows the end record (after {last}): "
                "OpenNI2 plays nothing after it",
            )
        by_type[name] = by_type.get(name, 0) + 1
        records[pos] = (rtype, node)
        if rtype in NODE_ADDED:
            nodes[node], node_types[node], seek = _node_added(path, data, pos, n, fsize, header)
            if seek is not None:
                seek_at[node] = (seek, n)
        if rtype == NEW_DATA:
            frames[node] = frames.get(node, 0) + 1
        if rtype == NODE_REMOVED:
            removed.add(node)
        last = f"record {n} ({name}) at byte {pos}"
        ended = ended or rtype == END
        pos += fsize + psize
    if not frames:
        raise DataFileError(
            path,
            f"the recording holds no frame: {n} records ({', '.join(sorted(by_type))}) with the "
            "header and stream properties only",
        )
    if not ended or set(nodes) - removed:
        raise DataFileError(
            path,
            f"the recording ends after {last} without the records a complete recording closes "
            "with (node removed for every stream, seek tables, end): cut short?",
        )
    for node, (seek, k) in seek_at.items():
        if node in frames and records.get(seek) != (SEEK_TABLE, node):
            raise DataFileError(
                path,
                f"record {k} (node added, {nodes[node]!r}): its seek table at byte {seek} is "
                "not a seek table record of that stream",
            )
    return OniScan(n, by_type, frames, nodes, node_types)


def _node_added(
    path: Path, data: bytes, pos: int, n: int, fsize: int, header: int = RECORD_HEADER.size
) -> tuple[str, int, int | None]:
    """A node-added record's node name, node type and (newest layout, type 13) the byte of its
    seek table (None before, or where it is 0: no seek table); a record that does not hold them
    is an error naming it. ``header``: the record header's size (24 or 28 bytes)."""
    end = pos + fsize
    where = f"record {n} (node added) at byte {pos}"
    at = pos + header + 4  # the name, after its length
    (ln,) = struct.unpack_from("<I", data, at - 4) if at <= end else (0,)
    if not 0 < ln <= end - at - 8:
        raise DataFileError(path, f"{where}: node name length {ln} does not fit the record")
    name = data[at : at + ln].rstrip(b"\0").decode("latin-1")
    ntype, codec = struct.unpack_from("<I4s", data, at + ln)
    if ntype not in NODE_TYPES or codec not in CODECS:
        raise DataFileError(
            path,
            f"{where}: node {name!r} of type {ntype} with codec {codec!r} (a recording holds "
            f"types {sorted(NODE_TYPES)} with codecs {', '.join(c.decode() for c in CODECS)})",
        )
    rtype = struct.unpack_from("<I", data, pos + 4)[0]
    wide = header == RECORD_HEADER.size  # 64-bit positions (else 32-bit, before 1.0.1.0)
    if rtype != 13 or at + ln + (36 if wide else 32) > end:
        return name, ntype, None
    seek = struct.unpack_from("<Q" if wide else "<I", data, at + ln + 28)[0]
    return name, ntype, int(seek) or None


def initialize_openni(redist: str | None = None) -> Any:
    """Load OpenNI2 (``redist``, else ``OPENNI2_REDIST``, else the Debian folder); the module."""
    try:
        from openni import openni2
    except ImportError as exc:  # a dependency of this distribution, uninstalled or broken
        raise DeviceError(
            f"mdf-kinect needs the Python package 'openni', which cannot be imported ({exc}): "
            "pip install openni"
        ) from None
    folder = redist or os.environ.get("OPENNI2_REDIST") or DEBIAN_OPENNI2
    try:
        openni2.initialize(folder)
    except Exception as exc:
        raise DeviceError(
            f"OpenNI2 could not be loaded from {folder} ({' '.join(str(exc).split())}); install "
            "it (Debian: apt-get install libopenni2-0 libopenni2-dev) or set OPENNI2_REDIST"
        ) from None
    return openni2


def nite_redist(redist: str | None = None) -> str | None:
    """NiTE2's Redist folder: ``redist``, else ``NITE2_REDIST64`` (what NiTE 2.2's install.sh
    exports on x86_64, and what the ``openni`` binding reads first), else ``NITE2_REDIST``;
    None when none is set."""
    return redist or os.environ.get("NITE2_REDIST64") or os.environ.get("NITE2_REDIST") or None


def initialize_nite(redist: str | None = None) -> Any:
    """Load NiTE2 from :func:`nite_redist`'s folder; :class:`NiteMissingError` otherwise."""
    folder = nite_redist(redist)
    if not folder:
        raise NiteMissingError(NITE_HELP + " (neither is set)")
    lib = Path(folder) / "libNiTE2.so"
    if not lib.is_file():
        raise NiteMissingError(f"{NITE_HELP} ({lib} does not exist)")
    initialize_openni()
    from openni import nite2

    try:
        nite2.initialize(folder)
    except Exception as exc:
        raise NiteMissingError(f"{NITE_HELP} (loading {lib} failed: {exc})") from None
    return nite2


def open_device(openni2: Any, uri: str | None = None) -> Any:
    """Open ``uri`` (a device URI or an ``.oni`` path) or the first device."""
    try:
        if uri is None:
            uris = [u for u in openni2.Device.enumerate_uris() if not Path(u.decode()).is_file()]
            if not uris:
                raise DeviceError(
                    "cannot open the first OpenNI2 device: no device is connected (is a Kinect "
                    "plugged in, powered and readable by this user?)"
                )
            return openni2.Device(uris[0])
        return openni2.Device.open_file(uri.encode())
    except DeviceError:
        raise
    except Exception as exc:
        what = uri or "the first OpenNI2 device"
        hint = (
            " (OpenNI2 cannot play this recording)"
            if uri is not None and Path(uri).is_file()
            else " (is a Kinect connected, powered and readable by this user?)"
        )
        raise DeviceError(
            f"cannot open {what}: {' '.join(str(exc).split()) or type(exc).__name__}{hint}"
        ) from None


@dataclass(frozen=True)
class DepthFrame:
    """One depth frame: ``depth`` (height, width) uint16 [mm]; ``timestamp_us``; ``index``."""

    index: int
    timestamp_us: int
    depth: NDArray[np.uint16]


def _sensor(openni2: Any, kind: str) -> Any:
    return {"depth": openni2.SENSOR_DEPTH, "color": openni2.SENSOR_COLOR, "ir": openni2.SENSOR_IR}[
        kind
    ]


#: Linux system call numbers (x86-64 and arm64) of the sleeps an idle file player thread is in.
_SLEEP_SYSCALLS = {"35", "230", "101", "115"}


def _task_ids() -> set[str]:
    """Ids of this process's threads (Linux ``/proc``; empty elsewhere)."""
    try:
        return set(os.listdir("/proc/self/task"))
    except OSError:
        return set()


def _wait_until_sleeping(tids: set[str], timeout_s: float = 3.0) -> None:
    """Wait until every thread in ``tids`` is in a sleep system call (or has ended), for at
    most ``timeout_s``; without ``/proc``, wait 50 ms."""
    import time

    if not tids:
        time.sleep(0.05)
        return

    def sleeping(tid: str) -> bool:
        try:
            with open(f"/proc/self/task/{tid}/syscall", encoding="utf-8") as f:
                return f.read().split(" ", 1)[0] in _SLEEP_SYSCALLS
        except OSError:  # the thread has ended
            return True

    end = time.monotonic() + timeout_s
    while not all(sleeping(t) for t in tids) and time.monotonic() < end:
        time.sleep(0.001)


@contextmanager
def _playback(path: Path, stream: str | None) -> Iterator[tuple[Any, Any, Any, str]]:
    """An ``.oni`` file opened through OpenNI2 with one stream created (not started):
    ``(openni2, device, stream, kind)``, torn down in the only order that is safe.
    ``stream`` None takes the first of depth, colour and IR that the recording holds.

    Why the teardown waits: OpenNI2's file driver (``libOniFile``, ``PlayerDevice``) runs a
    player thread per opened file. Between frames it walks the device's list of streams
    without a lock (``MainLoop``: is any stream started?), busily once the file is at its end,
    and it hands frames to streams from inside ``ReadNext``; destroying a stream
    (``oniStreamDestroy`` -> ``PlayerDevice::destroyStream``) unlinks and frees it without that
    lock, and closing the device while a stream exists frees objects the thread may still
    deliver to. Both race the player thread and crash it now and then (a segfault while
    ``oniDeviceClose`` waits for the thread). Here the stream is stopped and the playback
    switched to full speed (so a thread waiting for the next frame's trigger runs through the
    rest of the file), then the teardown waits until the player thread sleeps in its idle loop
    (no stream started: it sleeps 10 ms between checks), and only then destroys the stream and
    closes the device.
    """
    scan_oni(path)
    openni2 = initialize_openni()
    before = _task_ids()
    dev = open_device(openni2, str(path))
    player = _task_ids() - before  # the file player's thread, started by the open
    s = None
    try:
        kinds = [stream] if stream is not None else ["depth", "color", "ir"]
        kind = next((k for k in kinds if dev.has_sensor(_sensor(openni2, k))), None)
        if kind is None:
            raise DataFileError(path, f"no {' or '.join(kinds)} stream in this recording")
        dev.playback.set_repeat_enabled(False)
        dev.playback.set_speed(-1.0)  # manual: one frame per read, none dropped
        s = dev.create_stream(_sensor(openni2, kind))
        yield openni2, dev, s, kind
    finally:
        if s is not None:
            s.stop()
            dev.playback.set_speed(0.0)  # fastest: no more waiting for a read
            _wait_until_sleeping(player)
            s.close()
        dev.close()


def _frames(openni2: Any, s: Any, path: Path, kind: str, timeout_s: float) -> Iterator[Any]:
    """Start ``s`` and yield its frames in order, each closed before the next is read."""
    n = s.get_number_of_frames()
    s.start()
    for k in range(n):
        if openni2.wait_for_any_stream([s], timeout_s) is None:
            raise DataFileError(path, f"{kind} frame {k + 1} of {n}: OpenNI2 delivered no frame")
        frame = s.read_frame()
        try:
            yield frame
        finally:
            frame.close()


def iter_oni_frames(path: Path, stream: str = "depth", timeout_s: float = 2.0) -> Iterator[Any]:
    """Frames of one stream of an ``.oni`` file through OpenNI2, in order, as the binding's
    ``VideoFrame`` objects (valid until the next one is read).

    Close the generator when stopping early (``contextlib.closing``): the recording stays open
    until it is exhausted or closed."""
    with _playback(path, stream) as (openni2, _dev, s, kind):
        yield from _frames(openni2, s, path, kind, timeout_s)


def read_oni_depth(path: Path) -> list[DepthFrame]:
    """Every depth frame of an ``.oni`` file, (height, width) uint16 [mm] with time stamps."""
    out: list[DepthFrame] = []
    with closing(iter_oni_frames(path, "depth")) as frames:
        for f in frames:
            buf = np.frombuffer(bytes(f.get_buffer_as_uint8()), dtype="<u2")
            if buf.size != f.height * (f.stride // 2):  # a damaged frame decodes short
                raise DataFileError(
                    path,
                    f"depth frame {int(f.frameIndex)} decodes to {buf.size} pixels, not "
                    f"{f.height} x {f.stride // 2}: the recording is damaged",
                )
            depth = buf.reshape(f.height, f.stride // 2)[:, : f.width].copy()
            out.append(DepthFrame(int(f.frameIndex), int(f.timestamp), depth))
    return out


def _stream_info(frames: Iterator[Any]) -> dict[str, Any]:
    """Resolution, pixel format, frame count, time stamps and measured rate of one stream."""
    stamps: list[int] = []
    mode: dict[str, Any] = {}
    for f in frames:
        stamps.append(int(f.timestamp))
        if not mode:
            vm = f.videoMode
            mode = {
                "width": int(f.width),
                "height": int(f.height),
                "pixel_format": str(vm.pixelFormat).split(".")[-1].replace("ONI_PIXEL_FORMAT_", ""),
                "nominal_fps": int(vm.fps),
                "bytes_per_frame": int(f.dataSize),
            }
    rate = (len(stamps) - 1) / ((stamps[-1] - stamps[0]) * 1e-6) if len(stamps) > 1 else None
    return {
        **mode,
        "frames": len(stamps),
        "first_timestamp_us": stamps[0] if stamps else None,
        "last_timestamp_us": stamps[-1] if stamps else None,
        "measured_fps": rate,
        "timestamps_increasing": bool(np.all(np.diff(stamps) > 0)),
    }


def oni_info_isolated(path: Path, timeout_s: float = 2.0) -> dict[str, Any]:
    """:func:`oni_info` in a child process, as ``mdf kinect info`` reads a recording: OpenNI2
    crashes the whole process (a segmentation fault) on some damaged recordings that pass
    :func:`scan_oni` (a damaged property name, for one), and a crash of the child is one
    :class:`~mdframework.DataFileError` here. Errors the child raises come back as raised."""
    from concurrent.futures.process import BrokenProcessPool

    from mdframework.workers import worker_pool

    scan_oni(path)  # the structural checks here first: one line each, no process started
    try:
        with worker_pool(1) as pool:  # a worker that ends with this process, as a build's
            info: dict[str, Any] = pool.submit(oni_info, path, timeout_s).result()
            return info
    except BrokenProcessPool:
        raise DataFileError(
            path,
            "OpenNI2 crashed while playing this recording (its structure is sound, so a "
            "record's contents are damaged)",
        ) from None


def oni_info(path: Path, timeout_s: float = 2.0) -> dict[str, Any]:
    """Streams of an ``.oni`` file: resolution, pixel format, frame count, first and last time
    stamps [us] and measured frame rate [Hz], read through OpenNI2.

    The device is only ever opened with a stream to read (the first session also reads the
    device's name and sensors): a file device closed before its player thread has started
    would keep that thread spinning until the driver's 3 s join timeout kills it."""
    scan = scan_oni(path)
    with _playback(path, None) as (openni2, dev, s, first):
        info = dev.get_device_info()
        device = {
            "name": info.name.decode(errors="replace"),
            "vendor": info.vendor.decode(errors="replace"),
        }
        has = {k: dev.has_sensor(_sensor(openni2, k)) for k in ("depth", "color", "ir")}
        streams = {first: _stream_info(_frames(openni2, s, path, first, timeout_s))}
    for kind in (k for k, present in has.items() if present and k != first):
        with closing(iter_oni_frames(path, kind, timeout_s)) as frames:
            streams[kind] = _stream_info(frames)
    order = ("depth", "color", "ir")
    streams = {k: streams[k] for k in order if k in streams}
    return {"file": str(path), "device": device, "records": scan.n_records, "streams": streams}
