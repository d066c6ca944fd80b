"""``mdf kinect info FILE.oni`` and ``mdf capture`` (the paper's capture interface)."""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import math
import signal
import time
from pathlib import Path
from typing import Any

import numpy as np

from mdframework import DataFileError
from mdframework.cli import add_command
from mdframework.outdir import atomic_write_text, check_output_file


def add_commands(subparsers: argparse._SubParsersAction[Any]) -> None:
    """Register ``kinect info`` and ``capture``."""
    kinect = add_command(
        subparsers,
        "kinect",
        "Kinect / OpenNI2 utilities",
        "Kinect and OpenNI2 utilities (see docs/kinect.md).",
        ["mdf kinect info examples/data/kinect/oni/test.oni"],
    )
    ksub = kinect.add_subparsers(dest="kinect_command", required=True, metavar="SUBCOMMAND")
    info = add_command(
        ksub,
        "info",
        "streams, resolutions, frames and rate of an .oni file",
        "Print the device, and for every stream of an OpenNI recording (.oni) its resolution, "
        "pixel format, number of frames and measured frame rate.",
        [
            "mdf kinect info examples/data/kinect/oni/test.oni",
            "mdf kinect info examples/data/kinect/oni/test.oni --json",
        ],
    )
    info.add_argument("file", help="an OpenNI recording (.oni)")
    info.add_argument("--json", action="store_true", help="print JSON")
    info.set_defaults(func=cmd_info)

    cap = add_command(
        subparsers,
        "capture",
        "record NiTE2 skeletons from a Kinect (needs OpenNI2 and NiTE2)",
        "Track skeletons with NiTE2 from a live Kinect (or an .oni recording) and write them "
        "as a skeleton recording that the kinect motion source reads. Needs the OpenNI2 "
        "library and NiTE2 (see docs/kinect.md).",
        [
            "mdf capture --out walk.nite.txt --duration 10",
            "mdf capture --out walk.nite.txt --device examples/data/kinect/oni/test.oni",
        ],
    )
    cap.add_argument("--out", required=True, help="skeleton recording to write (.nite.txt)")
    cap.add_argument(
        "--duration",
        type=_seconds,
        default=None,
        help="seconds to record (default: until Ctrl-C)",
    )
    cap.add_argument("--device", default=None, help="device URI or .oni file (default: first)")
    cap.add_argument(
        "--nite2",
        default=None,
        help="NiTE2 Redist folder (else $NITE2_REDIST64, else $NITE2_REDIST)",
    )
    cap.set_defaults(func=cmd_capture)


def _seconds(text: str) -> float:
    """A recording length: a finite number of seconds > 0, at most a day."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0.0 < value <= 86400.0:  # NaN fails too
        raise argparse.ArgumentTypeError(f"must be a number of seconds in (0, 86400], got {text!r}")
    return value


def cmd_info(args: argparse.Namespace) -> int:
    """Print what an .oni recording holds."""
    from .device import oni_info_isolated  # when used: loading the plugin adds the commands

    path = Path(args.file)
    if not path.exists():
        raise DataFileError(path, "file not found")
    info = oni_info_isolated(path)
    if args.json:
        print(json.dumps(info, indent=2))
        return 0
    print(f"{info['file']}: {info['device']['vendor']} {info['device']['name']}")
    for name, s in info["streams"].items():
        fps = f"{s['measured_fps']:.2f}" if s["measured_fps"] else "n/a"
        print(
            f"  {name}: {s['width']}x{s['height']} {s['pixel_format']}, {s['frames']} frames, "
            f"t = {s['first_timestamp_us']} .. {s['last_timestamp_us']} us, {fps} fps measured "
            f"({s['nominal_fps']} nominal)"
        )
    return 0


def cmd_capture(args: argparse.Namespace) -> int:
    """Record skeletons until the duration is over, Ctrl-C, or the end of an ``.oni`` file;
    write the NiTE file (checked before the device starts, written whole or not at all)."""
    from .device import (
        DeviceError,
        initialize_nite,
        initialize_openni,
        nite_redist,
        open_device,
        scan_oni,
    )
    from .nitefile import nite_frames_to_arrays, write_nite

    # absolute first: the user tracker is created inside NiTE2's Redist folder
    out = check_output_file(Path(args.out).absolute())
    device = args.device
    n_file_frames = None
    if device is not None and Path(device).is_file():
        device = str(Path(device).absolute())
        n_file_frames = scan_oni(Path(device)).depth_frames()
    nite2 = initialize_nite(args.nite2)
    openni2 = initialize_openni()
    dev = open_device(openni2, device)
    try:
        if n_file_frames is not None:
            dev.playback.set_repeat_enabled(False)  # OpenNI2 plays a file in a loop by default
        try:
            # NiTE2 loads NiTE2/s.dat... relative to the current directory when it starts
            with contextlib.chdir(str(nite_redist(args.nite2))):
                tracker = nite2.UserTracker(dev)
        except Exception as exc:
            raise DeviceError(f"NiTE2 cannot track on this device: {exc}") from None
    except BaseException:
        dev.close()
        raise
    from openni import _nite2

    frames: list[tuple[int, int, list[Any]]] = []
    stop = {"now": False}
    old = signal.signal(signal.SIGINT, lambda *_: stop.__setitem__("now", True))
    t0 = time.monotonic()
    print("recording; Ctrl-C to stop" if args.duration is None else f"recording {args.duration} s")
    try:
        while not stop["now"] and (args.duration is None or time.monotonic() - t0 < args.duration):
            f = tracker.read_frame()
            users = []
            for u in f.users:
                if u.is_new():
                    tracker.start_skeleton_tracking(u.id)
                users.append(_nite2.NiteUserData.from_buffer_copy(u._userdata))
            frames.append((int(f.timestamp), int(f.frameIndex), users))
            f.close()
            # the file's last depth frame (NiTE2 tracks on depth; OpenNI2 numbers a recorded
            # stream's frames 1..n, and NiTE2 may skip some)
            if n_file_frames is not None and max(len(frames), frames[-1][1]) >= n_file_frames:
                break
    finally:
        signal.signal(signal.SIGINT, old)
        wall = time.monotonic() - t0
        dev_info = dev.get_device_info()
        # the tracker (and its depth stream) first: closing the device under a live stream
        # crashes OpenNI2's file player
        tracker.close()
        dev.close()
    if len(frames) < 2:
        raise DeviceError(f"only {len(frames)} frame(s) recorded")
    t, pos, conf, idx, user = nite_frames_to_arrays(frames)
    if user is None:
        raise DeviceError("no user's skeleton was tracked; stand 2-3 m in front of the sensor")
    # frames before NiTE found the user and after it lost them for good hold no joint (as the
    # readers trim them)
    tracked = np.flatnonzero(np.any(np.isfinite(pos), axis=(1, 2)))
    if tracked.size < 2:
        raise DeviceError(f"user {user}'s skeleton was tracked in {tracked.size} frame(s) only")
    span = slice(int(tracked[0]), int(tracked[-1]) + 1)
    t, pos, conf, idx = t[span] - t[span][0], pos[span], conf[span], idx[span]
    info = {
        "device": f"{dev_info.vendor.decode()} {dev_info.name.decode()} ({dev_info.uri.decode()})",
        "software": f"mdf-kinect 0.1.0, OpenNI {openni2.get_version()}, NiTE {nite2.get_version()}",
        "units": "m; axes: Kinect SDK camera space (x to the sensor's left, y up, z away)",
        "started": time.strftime("%Y-%m-%dT%H:%M:%S%z", time.localtime(time.time() - wall)),
    }
    text = io.StringIO()
    write_nite(text, t, idx, user, pos, conf, info)
    atomic_write_text(out, text.getvalue())
    rate = (len(t) - 1) / t[-1] if t[-1] > 0 else float("nan")
    n_tracked = int(np.all(np.isfinite(pos), axis=(1, 2)).sum())
    print(
        f"{out}: {len(t)} frames ({n_tracked} with user {user} tracked; {len(frames) - len(t)} "
        f"untracked at the ends left out), {t[-1]:.3f} s measured, {rate:.2f} Hz actual "
        "sampling frequency"
    )
    return 0
