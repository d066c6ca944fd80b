"""The bad-input corpus: bad and awkward inputs made from the real files in ``examples/data``.

Every case is a command line of ``mdf`` on a generated input (a motion file of every supported
format truncated, corrupted, re-encoded, with absurd values or huge declared counts; config files
that cannot be decoded, nest too deep or are too large; an absurd value in every config section;
dataset and experiment configs that reach outside the process). ``tests/test_bad_input_corpus.py``
runs every case and asserts the rule for bad input: exit code 2, one line on stderr naming the
file (and line) or the config field, no traceback, and nothing written to ``--out``.

Run on its own to look at the corpus::

    python tests/corpus/make_corpus.py OUT_DIR    # writes the cases and lists them
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "examples" / "data"
BVH = DATA / "cmu" / "bvh" / "16_21.bvh"
AMC = DATA / "cmu" / "asf-amc" / "02_01.amc"
ASF = DATA / "cmu" / "asf-amc" / "02.asf"
UTK = DATA / "kinect" / "utkinect" / "joints_s01_e01.txt"
UTK_LABELS = DATA / "kinect" / "utkinect" / "actionLabel.txt"
MSR = DATA / "kinect" / "msr-action3d" / "a16_s01_e01_skeleton3D.txt"
PRECOG = DATA / "kinect" / "precog" / "Seq1_1.csv"
ONI = DATA / "kinect" / "oni" / "test.oni"
RADHAR_TEXT = DATA / "radhar" / "text" / "20_jump_1.txt.gz"
RADHAR_NPZ = DATA / "radhar" / "radhar_walk_subset.npz"
C3D = DATA / "c3d" / "treadmill_events.c3d"
TRC = DATA / "trc" / "opensim_subject01_walk.trc"
DEEPMIMIC_WALK = DATA / "deepmimic" / "humanoid3d_walk.txt"
DEEPMIMIC_PUNCH = DATA / "deepmimic" / "humanoid3d_punch.txt"


@dataclass(frozen=True)
class Case:
    """One bad input: ``argv`` for ``mdf``; ``expect``: texts the one error line must contain
    (the file and line, or the config field); ``out``: the folder that must stay empty."""

    name: str
    argv: tuple[str, ...]
    expect: tuple[str, ...]
    out: Path


class _Corpus:
    def __init__(self, root: Path) -> None:
        self.root = root
        self.cases: list[Case] = []

    def folder(self, name: str) -> Path:
        d = self.root / name
        d.mkdir(parents=True, exist_ok=False)
        return d

    def run(self, name: str, config: Path, *expect: str) -> None:
        out = config.parent / "out"
        self.cases.append(Case(name, ("run", str(config), "--out", str(out)), expect, out))

    def command(self, name: str, argv: list[str], out: Path, *expect: str) -> None:
        self.cases.append(Case(name, tuple(argv), expect, out))


# ----------------------------------------------------------------------------- file helpers


def _lines(path: Path) -> list[str]:
    return path.read_text(encoding="utf-8").splitlines(keepends=True)


def _json_config(folder: Path, config: dict[str, Any], name: str = "run.json") -> Path:
    path = folder / name
    path.write_text(json.dumps(config, indent=1), encoding="utf-8")  # inf/nan as Infinity/NaN
    return path


def _replace_field(line: str, index: int, value: str) -> str:
    """A whitespace-separated line with field ``index`` replaced (line end kept)."""
    end = line[len(line.rstrip("\r\n")) :]
    fields = line.split()
    fields[index] = value
    return " ".join(fields) + end


def _bvh_motion_start(lines: list[str]) -> int:
    """Index of the first frame line of a BVH file."""
    return next(i for i, ln in enumerate(lines) if ln.startswith("MOTION")) + 3


# ------------------------------------------------------------------- motion files, per format


def _motion_cases(c: _Corpus) -> None:
    bvh = _lines(BVH)
    first = _bvh_motion_start(bvh)
    rng = np.random.default_rng(10)

    def bvh_case(name: str, text: str | bytes, *expect: str, keep_first: bool = False) -> None:
        d = c.folder(f"bvh-{name}")
        f = d / "16_21.bvh"
        f.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8"))
        motion: dict[str, Any] = {"kind": "cmu", "file": f.name}
        if keep_first:
            motion["keep_first_frame"] = True
        c.run(f"bvh-{name}", _json_config(d, {"motion": motion}), f.name, *expect)

    def with_line(lines: list[str], index: int, new: str) -> str:
        return "".join([*lines[:index], new, *lines[index + 1 :]])

    bvh_case("truncated-hierarchy", "".join(bvh[:40]), "ends inside the hierarchy")
    bvh_case("truncated-frames", "".join(bvh[: first + 20]), "truncated")
    bvh_case("truncated-mid-line", "".join(bvh[: first + 20]) + bvh[first + 20][:25], "values")
    frames_line = first - 2
    bvh_case(
        "huge-frame-count",
        with_line(bvh, frames_line, "Frames: 1000000000000\n"),
        f":{frames_line + 1}:",
        "exceeds the limit",
    )
    bvh_case(
        "frame-count-beyond-data",
        with_line(bvh, frames_line, "Frames: 5000000\n"),
        "truncated",
    )
    k = first + 7
    bvh_case(
        "coordinate-1e308", with_line(bvh, k, _replace_field(bvh[k], 0, "1e308")), f":{k + 1}:"
    )
    bvh_case("angle-1e30", with_line(bvh, k, _replace_field(bvh[k], 5, "1e30")), f":{k + 1}:")
    bvh_case("nan-value", with_line(bvh, k, _replace_field(bvh[k], 3, "nan")), f":{k + 1}:")
    bvh_case("inf-value", with_line(bvh, k, _replace_field(bvh[k], 1, "-inf")), f":{k + 1}:")
    bvh_case("bad-number", with_line(bvh, k, _replace_field(bvh[k], 2, "1.2.3")), f":{k + 1}:")
    off = next(i for i, ln in enumerate(bvh) if "OFFSET" in ln)
    root = next(i for i, ln in enumerate(bvh) if ln.split()[:1] == ["ROOT"])
    bvh_case(
        "offset-1e300",
        with_line(bvh, off, "OFFSET 1e300 0 0\n"),
        f":{root + 1}:",  # the joint's line
        "OFFSET of 'Hips'",
    )
    bvh_case(
        "crlf-truncated",
        "".join(ln.rstrip("\n") + "\r\n" for ln in bvh[: first + 10]),
        "truncated",
    )
    bvh_case(
        "frame-time-zero", with_line(bvh, first - 1, "Frame Time: 0\n"), f":{first}:", "frame time"
    )
    bvh_case(
        "frame-time-1e300",
        with_line(bvh, first - 1, "Frame Time: 1e300\n"),
        f":{first}:",
        "frame time",
    )
    one = "".join(bvh[: first - 2]) + "Frames: 2\n" + bvh[first - 1] + bvh[first] + bvh[first + 1]
    bvh_case("one-frame-after-t-pose", one, "frame")
    same = "".join(bvh[: first - 2]) + "Frames: 1\n" + bvh[first - 1] + bvh[first]
    bvh_case("single-frame", same, "at least two", keep_first=True)
    bvh_case("empty", "", "empty")
    bvh_case("random-bytes", rng.integers(0, 256, 4000, dtype=np.uint8).tobytes(), "16_21.bvh")
    bvh_case("utf16", "".join(bvh).encode("utf-16"), "16_21.bvh")
    bvh_case("nul-bytes", "".join(bvh[:first]).encode() + b"\0" * 100, "16_21.bvh")

    # ASF/AMC
    amc = _lines(AMC)
    asf = _lines(ASF)

    def amc_case(name: str, amc_text: str | bytes, asf_text: str, bad: str, *expect: str) -> None:
        d = c.folder(f"amc-{name}")
        (d / "02_01.amc").write_bytes(
            amc_text if isinstance(amc_text, bytes) else amc_text.encode("utf-8")
        )
        (d / "02.asf").write_text(asf_text, encoding="utf-8")
        motion = {"kind": "cmu", "file": "02_01.amc"}
        c.run(f"amc-{name}", _json_config(d, {"motion": motion}), bad, *expect)

    asf_text = "".join(asf)
    root_line = next(i for i, ln in enumerate(amc) if ln.startswith("root"))
    amc_case(
        "truncated-mid-frame", "".join(amc[: root_line + 40]), asf_text, "02_01.amc", "lacks bone"
    )
    r = root_line + 30 * 0  # the first frame's root line
    amc_case(
        "root-1e308",
        "".join([*amc[:r], _replace_field(amc[r], 1, "1e308"), *amc[r + 1 :]]),
        asf_text,
        "02_01.amc",
        f":{r + 1}:",
    )
    b = root_line + 3
    amc_case(
        "angle-1e30",
        "".join([*amc[:b], _replace_field(amc[b], 1, "1e30"), *amc[b + 1 :]]),
        asf_text,
        "02_01.amc",
        f":{b + 1}:",
    )
    amc_case(
        "nan",
        "".join([*amc[:b], _replace_field(amc[b], 2, "nan"), *amc[b + 1 :]]),
        asf_text,
        "02_01.amc",
        f":{b + 1}:",
    )
    frame2 = next(i for i, ln in enumerate(amc) if ln.strip() == "2")
    amc_case("one-frame", "".join(amc[:frame2]), asf_text, "02_01.amc", "at least two")
    amc_case(
        "random-bytes",
        rng.integers(0, 256, 3000, dtype=np.uint8).tobytes(),
        asf_text,
        "02_01.amc",
    )
    amc_case("empty", "", asf_text, "02_01.amc", "zero frames")
    amc_case("asf-truncated", "".join(amc), "".join(asf[:30]), "02.asf")
    unit = next(i for i, ln in enumerate(asf) if ln.strip().startswith("length"))
    amc_case(
        "asf-length-unit-1e-300",
        "".join(amc),
        "".join([*asf[:unit], "  length 1e-300\n", *asf[unit + 1 :]]),
        "02.asf",
        f":{unit + 1}:",
    )
    bone_len = next(
        i for i, ln in enumerate(asf) if ln.strip().startswith("length") and i > unit + 5
    )
    amc_case(
        "asf-bone-length-1e308",
        "".join(amc),
        "".join([*asf[:bone_len], "     length 1e308\n", *asf[bone_len + 1 :]]),
        "02.asf",
        f":{bone_len + 1}:",
    )

    # Kinect text formats
    def kinect_case(
        name: str, fmt: str, fname: str, data: str | bytes, *expect: str, **extra: Any
    ) -> None:
        d = c.folder(f"{fmt}-{name}")
        (d / fname).write_bytes(data if isinstance(data, bytes) else data.encode("utf-8"))
        motion = {"kind": "kinect", "format": fmt, "file": fname, **extra}
        c.run(f"{fmt}-{name}", _json_config(d, {"motion": motion}), fname, *expect)

    utk = _lines(UTK)
    uname = UTK.name
    kinect_case("truncated-line", "utkinect", uname, "".join(utk[:30]) + utk[30][:40], ":31:")
    kinect_case(
        "coordinate-1e308",
        "utkinect",
        uname,
        "".join([*utk[:9], _replace_field(utk[9], 4, "1e308"), *utk[10:]]),
        ":10:",
    )
    kinect_case(
        "frame-number-1e300",
        "utkinect",
        uname,
        "".join([*utk[:9], _replace_field(utk[9], 0, "1e300"), *utk[10:]]),
        ":10:",
    )
    kinect_case(
        "all-frame-numbers-equal",
        "utkinect",
        uname,
        "".join(_replace_field(ln, 0, "7") for ln in utk if ln.strip()),
        "same time stamp",
    )
    kinect_case("one-line", "utkinect", uname, utk[0], "at least two")
    kinect_case(
        "random-bytes", "utkinect", uname, rng.integers(0, 256, 2000, dtype=np.uint8).tobytes()
    )
    kinect_case("utf16", "utkinect", uname, "".join(utk).encode("utf-16"))
    kinect_case("empty", "utkinect", uname, "", "empty")
    d = c.folder("utkinect-bad-labels")
    (d / uname).write_text("".join(utk), encoding="utf-8")
    (d / "actionLabel.txt").write_text("s01_e01\nwalk: 1e400 nope\n", encoding="utf-8")
    c.run(
        "utkinect-bad-labels",
        _json_config(
            d,
            {"motion": {"kind": "kinect", "format": "utkinect", "file": uname, "segment": "walk"}},
        ),
        "actionLabel.txt",
    )

    msr = _lines(MSR)
    mname = MSR.name
    kinect_case("truncated-frame", "msr-action3d", mname, "".join(msr[:47]), "whole number")
    kinect_case(
        "value-inf",
        "msr-action3d",
        mname,
        "".join([*msr[:12], _replace_field(msr[12], 1, "inf"), *msr[13:]]),
        ":13:",
    )
    kinect_case("one-frame", "msr-action3d", mname, "".join(msr[:20]), "at least two")
    kinect_case(
        "huge-value",
        "msr-action3d",
        mname,
        "".join([*msr[:40], _replace_field(msr[40], 2, "-3e200"), *msr[41:]]),
        ":41:",
    )

    pc = _lines(PRECOG)
    pname = PRECOG.name
    kinect_case("bad-header", "precog", pname, "x;y\n" + "".join(pc[1:]), ":1:")
    row = pc[5].split(";")
    row[3] = "0.1 1e308 2.0"
    kinect_case(
        "coordinate-1e308", "precog", pname, "".join([*pc[:5], ";".join(row), *pc[6:]]), ":6:"
    )
    row = pc[5].rstrip("\r\n").split(";")
    row[20] = "1000000000000000000000"
    kinect_case(
        "action-id-huge",
        "precog",
        pname,
        "".join([*pc[:5], ";".join(row) + "\n", *pc[6:]]),
        ":6:",
    )
    kinect_case("header-only", "precog", pname, pc[0], "no frame")

    # NTU (Kinect v2) and NiTE files, written from the real UTKinect recording
    ntu = _ntu_lines(UTK)
    nname = "S001C001P001R001A001.skeleton"
    kinect_case(
        "declared-frames-1e12", "ntu", nname, "1000000000000\n" + "".join(ntu[1:]), ":1:", "limit"
    )
    kinect_case("truncated", "ntu", nname, "".join(ntu[:100]), ":1:", "frame count")
    kinect_case(
        "body-count-huge",
        "ntu",
        nname,
        "".join([ntu[0], "99999999\n", *ntu[2:]]),
        ":2:",
        "body count",
    )
    kinect_case(
        "coordinate-1e308",
        "ntu",
        nname,
        "".join([*ntu[:10], _replace_field(ntu[10], 0, "1e308"), *ntu[11:]]),
        ":11:",
    )
    kinect_case("frame-count-inf", "ntu", nname, "inf\n" + "".join(ntu[1:]), ":1:")

    nite = _nite_lines(UTK)
    tname = "walk.nite.txt"
    data0 = next(i for i, ln in enumerate(nite) if ln[:1].isdigit())
    equal = nite[:data0] + [_replace_field(ln, 0, "0.5") for ln in nite[data0:]]
    kinect_case("all-times-equal", "nite", tname, "".join(equal), "same time stamp")
    kinect_case(
        "time-inf",
        "nite",
        tname,
        "".join([*nite[:data0], _replace_field(nite[data0], 0, "inf"), *nite[data0 + 1 :]]),
        "time stamp",
    )
    kinect_case(
        "time-1e300",
        "nite",
        tname,
        "".join(
            [*nite[: data0 + 3], _replace_field(nite[data0 + 3], 0, "1e300"), *nite[data0 + 4 :]]
        ),
        "time stamp",
    )
    kinect_case(
        "frame-index-nan",
        "nite",
        tname,
        "".join([*nite[:data0], _replace_field(nite[data0], 1, "nan"), *nite[data0 + 1 :]]),
        f":{data0 + 1}:",
    )
    kinect_case(
        "coordinate-1e308",
        "nite",
        tname,
        "".join([*nite[:data0], _replace_field(nite[data0], 5, "1e308"), *nite[data0 + 1 :]]),
        f":{data0 + 1}:",
    )
    kinect_case("truncated-line", "nite", tname, "".join(nite[: data0 + 5]) + nite[data0 + 5][:50])
    kinect_case("one-frame", "nite", tname, "".join(nite[: data0 + 1]), "at least two")

    # .oni recordings (mdf kinect info): truncated and random bytes
    d = c.folder("oni-truncated")
    (d / "test.oni").write_bytes(ONI.read_bytes()[:3000])
    c.command("oni-truncated", ["kinect", "info", str(d / "test.oni")], d / "out", "test.oni")
    d = c.folder("oni-random-bytes")
    (d / "test.oni").write_bytes(rng.integers(0, 256, 5000, dtype=np.uint8).tobytes())
    c.command("oni-random-bytes", ["kinect", "info", str(d / "test.oni")], d / "out", "test.oni")


def _ntu_lines(utk: Path) -> list[str]:
    """An NTU RGB+D .skeleton file (Kinect v2 layout) holding the real UTKinect recording."""
    from mdf_kinect import KINECT_V1_JOINTS, KINECT_V2_JOINTS, read_utkinect

    rec = read_utkinect(utk)
    v1 = {n: i for i, n in enumerate(KINECT_V1_JOINTS)}
    alias = {
        "SpineBase": "HipCenter",
        "SpineMid": "Spine",
        "Neck": "ShoulderCenter",
        "SpineShoulder": "ShoulderCenter",
        "HandTipLeft": "HandLeft",
        "ThumbLeft": "HandLeft",
        "HandTipRight": "HandRight",
        "ThumbRight": "HandRight",
    }
    lines = [f"{rec.time.shape[0]}\n"]
    for k in range(rec.time.shape[0]):
        lines += ["1\n", "72057594037931101 0 1 1 1 1 0 0.1 0.2 2\n", "25\n"]
        for name in KINECT_V2_JOINTS:
            x, y, z = rec.positions[k, v1[alias.get(name, name)]]
            lines.append(f"{x:.6f} {y:.6f} {z:.6f} 250.1 180.2 900.3 500.4 0.1 0.2 0.3 0.9 2\n")
    return lines


def _nite_lines(utk: Path) -> list[str]:
    """A NiTE recording (``mdf capture``'s format) holding the real UTKinect recording."""
    import io

    from mdf_kinect import KINECT_V1_JOINTS, read_utkinect
    from mdf_kinect.nitefile import NITE_JOINTS, write_nite

    rec = read_utkinect(utk)
    v1 = {n: i for i, n in enumerate(KINECT_V1_JOINTS)}
    names = {
        "HEAD": "Head",
        "NECK": "ShoulderCenter",
        "LEFT_SHOULDER": "ShoulderLeft",
        "RIGHT_SHOULDER": "ShoulderRight",
        "LEFT_ELBOW": "ElbowLeft",
        "RIGHT_ELBOW": "ElbowRight",
        "LEFT_HAND": "HandLeft",
        "RIGHT_HAND": "HandRight",
        "TORSO": "Spine",
        "LEFT_HIP": "HipLeft",
        "RIGHT_HIP": "HipRight",
        "LEFT_KNEE": "KneeLeft",
        "RIGHT_KNEE": "KneeRight",
        "LEFT_FOOT": "FootLeft",
        "RIGHT_FOOT": "FootRight",
    }
    pos = rec.positions[:, [v1[names[j]] for j in NITE_JOINTS]]
    buf = io.StringIO()
    write_nite(
        buf,
        rec.time - rec.time[0],
        rec.frame_numbers.tolist(),
        1,
        pos,
        np.ones(pos.shape[:2]),
        {"source": "UTKinect-Action3D joints_s01_e01 (corpus)"},
    )
    return buf.getvalue().splitlines(keepends=True)


# ----------------------------------------------------------- real radar recordings (RadHAR)


def _radhar_cases(c: _Corpus) -> None:
    """The RadHAR rostopic text and compact NPZ, read by a dataset's ``recording`` source."""
    import gzip
    import zipfile

    packed = RADHAR_TEXT.read_bytes()
    text = gzip.decompress(packed).decode("utf-8")
    lines = text.splitlines(keepends=True)
    rng = np.random.default_rng(12)

    def case(name: str, fname: str, data: bytes, *expect: str) -> None:
        d = c.folder(f"radhar-{name}")
        (d / fname).write_bytes(data)
        cfg = {"sources": [{"label": "jump", "recording": {"kind": "radhar", "file": fname}}]}
        f = _json_config(d, cfg, "dataset.json")
        out = d / "out"
        argv = ["dataset", "build", str(f), "--out", str(out), "--no-progress"]
        c.command(f"radhar-{name}", argv, out, fname, *expect)

    def line_of(prefix: str, nth: int = 0) -> int:
        """0-based index of the ``nth`` line starting with ``prefix``."""
        return [i for i, ln in enumerate(lines) if ln.startswith(prefix)][nth]

    def with_value(prefix: str, value: str, nth: int = 5) -> tuple[bytes, int]:
        i = line_of(prefix, nth)
        key = prefix.split(":")[0]
        new = [*lines[:i], f"{key}: {value}\n", *lines[i + 1 :]]
        return "".join(new).encode(), i + 1

    name = "20_jump_1.txt"
    for label, key, value, problem in (
        ("x-1e308", "x:", "1e308", "outside the sensor's range"),
        ("y-nan", "y:", "nan", "not finite"),
        ("z-minus-inf", "z:", "-inf", "not finite"),
        ("velocity-42", "velocity:", "42.0", "outside the sensor's range"),
        ("intensity-minus-1e9", "intensity:", "-1e9", "outside the sensor's range"),
        ("point-id-fraction", "point_id:", "2.5", "not a whole number"),
        ("x-decimal-comma", "x:", "1,5", "not a number"),
    ):
        data, line = with_value(key, value)
        case(f"text-{label}", name, data, f"{name}:{line}:", problem)
    # a message cut in the middle (the last one), the gzip stream cut or damaged
    last = max(i for i, ln in enumerate(lines[:40]) if ln.startswith("---")) + 2
    case("text-truncated", name, "".join(lines[:40]).encode(), f"{name}:{last}:", "has no")
    case("gz-truncated", name + ".gz", packed[: len(packed) // 3], "truncated or damaged")
    damaged = bytearray(packed)
    damaged[2000:2040] = bytes(40)
    case("gz-damaged", name + ".gz", bytes(damaged), "truncated or damaged")
    # order: a point number that falls within a frame, a time stamp that goes back
    first_ids = [i for i, ln in enumerate(lines) if ln.startswith("point_id:")]
    i = first_ids[3]
    swapped = [*lines[:i], "point_id: 1\n", *lines[i + 1 :]]
    case("text-point-id-falls", name, "".join(swapped).encode(), f"{name}:{i + 1}:", "rise")
    secs = [i for i, ln in enumerate(lines) if ln.strip().startswith("secs:")]
    j = secs[10]
    back = [*lines[:j], "    secs: 1000\n", *lines[j + 1 :]]
    case("text-stamp-goes-back", name, "".join(back).encode(), f"{name}:{j + 1}:", "earlier")
    same = "".join(
        "    secs: 1561683224\n" if ln.strip().startswith("secs:") else ln for ln in lines
    )
    same = "".join(
        "    nsecs: 0\n" if ln.strip().startswith("nsecs:") else ln
        for ln in same.splitlines(keepends=True)
    )
    case("text-same-stamps", name, same.encode(), "same time stamp")
    one_frame = "".join(lines[: first_ids[5] - 6])  # the first frame's first messages only
    case("text-one-frame", name, one_frame.encode(), "only 1 frame")
    case("text-utf16", name, text.encode("utf-16"), "not UTF-8")
    case("text-nul-bytes", name, text[:3000].encode() + bytes(64), "NUL")
    case("text-random-bytes", name, rng.integers(0, 256, 5000, dtype=np.uint8).tobytes())
    case("text-empty", name, b"", "no point messages")

    # the compact NPZ
    with np.load(RADHAR_NPZ) as data:
        arrays = {k: data[k] for k in data.files}
    raw = RADHAR_NPZ.read_bytes()
    npz = RADHAR_NPZ.name

    def npz_case(name: str, *expect: str, **change: Any) -> None:
        import io

        buf = io.BytesIO()
        new = {k: v for k, v in {**arrays, **change}.items() if v is not None}
        np.savez(buf, **new)
        case(f"npz-{name}", npz, buf.getvalue(), *expect)

    case("npz-truncated", npz, raw[: len(raw) // 2], "not a readable NPZ")
    x = arrays["x"].copy()
    x[100] = np.float32("inf")
    npz_case("x-inf", "x[100]", "not finite", x=x)
    v = arrays["velocity"].copy()
    v[5] = 1e30
    npz_case("velocity-1e30", "velocity[5]", "outside", velocity=v)
    frame = arrays["frame"].copy()
    frame[np.nonzero(arrays["file_index"] == 0)[0][-1]] = np.iinfo(frame.dtype).max
    npz_case("frame-huge", "frame 2147483647", "beyond", frame=frame)
    index = arrays["file_index"].copy()
    index[0] = 999
    npz_case("file-index-outside", "file_index[0] = 999", file_index=index)
    npz_case("x-as-text", "x holds", x=np.array(["a"] * arrays["x"].size))
    npz_case("missing-intensity", "missing arrays: intensity", intensity=None)
    # an array whose header declares 10^12 values (a crafted or damaged file)
    import io

    buf = io.BytesIO()
    n = arrays["x"].size
    with zipfile.ZipFile(io.BytesIO(raw)) as zin, zipfile.ZipFile(buf, "w") as zout:
        for info in zin.infolist():
            member = zin.read(info)
            if info.filename == "y.npy":
                declared = b"(1000000000000,)".ljust(len(f"({n},)"))
                member = member.replace(f"({n},)".encode(), declared)
            zout.writestr(info, member)
    case("npz-declared-1e12", npz, buf.getvalue(), "y declares 1,000,000,000,000 values")


# ------------------------------------------------------------------------------ config files


def _config_file_cases(c: _Corpus) -> None:
    good = {
        "motion": {"kind": "point_targets", "length": 1.0, "targets": [{"position": [50, 0, 0]}]},
        "scatterers": {"kind": "points"},
        "scene": {"radar_position": [0.0, 0.0, 0.0]},
    }
    text = json.dumps(good)

    def file_case(name: str, fname: str, data: bytes, *expect: str) -> None:
        d = c.folder(f"config-{name}")
        f = d / fname
        f.write_bytes(data)
        c.run(f"config-{name}", f, fname, *expect)

    file_case("utf16-json", "run.json", text.encode("utf-16"), "UTF-8")
    file_case("utf16-le-no-bom", "run.json", text.encode("utf-16-le"), "UTF-8")
    file_case(
        "latin1-toml", "run.toml", '# caf\xe9\n[motion]\nkind = "x"\n'.encode("latin-1"), "UTF-8"
    )
    rng = np.random.default_rng(3)
    for ext in ("toml", "yaml", "json"):
        file_case(
            f"random-bytes-{ext}",
            f"run.{ext}",
            rng.integers(0, 256, 3000, dtype=np.uint8).tobytes(),
        )
    depth = 50_000
    file_case("deep-json", "run.json", ("[" * depth + "]" * depth).encode(), "nested")
    file_case(
        "deep-json-object", "run.json", ('{"a":' * depth + "1" + "}" * depth).encode(), "nested"
    )
    file_case(
        "deep-toml", "run.toml", ("x = " + "[" * depth + "]" * depth + "\n").encode(), "nested"
    )
    file_case(
        "deep-toml-inline",
        "run.toml",
        ("x = " + "{a=" * depth + "1" + "}" * depth).encode(),
        "nested",
    )
    file_case(
        "deep-yaml", "run.yaml", ("x: " + "[" * depth + "]" * depth + "\n").encode(), "nested"
    )
    file_case(
        "moderately-deep-json",
        "run.json",
        ('{"motion":' + "[" * 100 + "]" * 100 + "}").encode(),
        "nested",
    )
    big = '{"motion": {"kind": "point_targets"}, "pad": "' + "x" * (5 * 1024 * 1024) + '"}'
    file_case("too-large", "run.json", big.encode(), "at most")
    file_case("not-a-table", "run.json", b"[1, 2, 3]", "top level")
    file_case("wrong-extension", "run.ini", text.encode(), "unknown config format")
    file_case("invalid-toml", "run.toml", b"[motion\nkind = 1\n", "invalid TOML")
    file_case("invalid-yaml", "run.yaml", b"motion: [1, 2\n", "invalid YAML")
    file_case("invalid-json", "run.json", b'{"motion": }', "invalid JSON")
    file_case("empty-json", "run.json", b"", "invalid JSON")
    d = c.folder("config-missing")
    c.run("config-missing", d / "nope.toml", "nope.toml", "cannot read")


# --------------------------------------------------------------- absurd values, every section


def _field_cases(c: _Corpus) -> None:
    point = {"kind": "point_targets", "length": 1.0, "targets": [{"position": [50, 0, 0]}]}
    base: dict[str, Any] = {
        "motion": point,
        "scatterers": {"kind": "points"},
        "scene": {"radar_position": [0.0, 0.0, 0.0]},
    }
    inf, nan = float("inf"), float("nan")

    def case(name: str, section: str, change: dict[str, Any], field: str) -> None:
        cfg = json.loads(json.dumps(base))
        if section == "effects":
            cfg["effects"] = [change]
        elif section == "":
            cfg.update(change)
        else:
            cfg[section] = {**cfg.get(section, {}), **change}
        d = c.folder(f"field-{name}")
        c.run(f"field-{name}", _json_config(d, cfg), "run.json", field)

    radar = {"kind": "lfm"}
    case("prf-inf", "radar", {**radar, "prf": inf}, "radar.prf")
    case("prf-1e300", "radar", {**radar, "prf": 1e300}, "radar.prf")
    case("prf-nan", "radar", {**radar, "prf": nan}, "radar.prf")
    case("carrier-inf", "radar", {**radar, "carrier_frequency": inf}, "radar.carrier_frequency")
    case("carrier-1hz", "radar", {**radar, "carrier_frequency": 1.0}, "radar.carrier_frequency")
    case("bandwidth-inf", "radar", {**radar, "bandwidth": inf}, "radar.bandwidth")
    case(
        "bandwidth-above-carrier",
        "radar",
        {**radar, "carrier_frequency": 1e8, "bandwidth": 5e8},
        "radar",
    )
    case("pulse-longer-than-interval", "radar", {**radar, "pulse_width": 0.01}, "pulse_width")
    case("power-1e300", "radar", {**radar, "transmit_power": 1e300}, "radar.transmit_power")
    case("gain-nan", "radar", {**radar, "gain_dbi": nan}, "radar.gain_dbi")
    case("loss-1e9", "radar", {**radar, "system_loss_db": 1e9}, "radar.system_loss_db")
    case("length-inf", "motion", {"length": inf}, "motion.length")
    case("length-1e9", "motion", {"length": 1e9}, "motion.length")
    case(
        "target-nan",
        "motion",
        {"targets": [{"position": [nan, 0, 0]}]},
        "motion.targets.0.position",
    )
    case(
        "target-1e300",
        "motion",
        {"targets": [{"position": [1e300, 0, 0]}]},
        "motion.targets.0.position",
    )
    case(
        "velocity-inf",
        "motion",
        {"targets": [{"position": [50, 0, 0], "velocity": [inf, 0, 0]}]},
        "motion.targets.0.velocity",
    )
    case(
        "rcs-inf",
        "motion",
        {"targets": [{"position": [50, 0, 0], "rcs": inf}]},
        "motion.targets.0.rcs",
    )
    case("frame-rate-zero", "motion", {"frame_rate": 0.0}, "motion.frame_rate")
    case("frame-rate-1e12", "motion", {"frame_rate": 1e12}, "motion.frame_rate")
    case("start-inf", "motion", {"start": inf}, "motion.start")
    case("duration-nan", "motion", {"duration": nan}, "motion.duration")
    case(
        "pulses-beyond-limit",
        "motion",
        {"length": 80_000.0},
        "pulses",
    )
    case("radar-position-inf", "scene", {"radar_position": [inf, 0, 0]}, "scene.radar_position")
    case(
        "gate-inf",
        "scene",
        {"gate": inf},
        "scene.gate: must be one of 'track' (got inf) or must be a finite number",
    )
    case("min-range-inf", "scene", {"min_range": inf}, "scene.min_range")
    case("person-nan", "scene", {"person": {"position": [nan, 0]}}, "scene.person.position")
    case("heading-1e9", "scene", {"person": {"heading_deg": 1e9}}, "scene.person.heading_deg")
    case(
        "speed-inf",
        "scene",
        {"person": {"motion": "straight", "speed": inf}},
        "scene.person.speed",
    )
    case("window-1e9", "processing", {"window_length": 10**9}, "processing.window_length")
    case("nfft-huge", "processing", {"nfft": 2**40}, "processing.nfft")
    case("floor-minus-inf", "processing", {"floor_db": -inf}, "processing.floor_db")
    case("hop-zero", "processing", {"hop": 0}, "processing.hop")
    case("gap-inf", "conditioning", {"max_gap_s": inf}, "conditioning.max_gap_s")
    case("joint-speed-nan", "conditioning", {"max_speed_mps": nan}, "conditioning.max_speed_mps")
    case("points-rcs-inf", "scatterers", {"rcs": inf}, "scatterers.rcs")
    case("seed-negative", "", {"seed": -1}, "seed")
    case("seed-2-to-the-70", "", {"seed": 2**70}, "seed")
    case("noise-snr-inf", "effects", {"kind": "noise", "snr_db": inf}, "effects.0.snr_db")
    case("clutter-csr-nan", "effects", {"kind": "clutter", "csr_db": nan}, "effects.0.csr_db")
    case(
        "multipath-ground-inf",
        "effects",
        {"kind": "multipath", "ground_height": inf},
        "effects.0.ground_height",
    )
    case(
        "antenna-azimuth-1e9",
        "effects",
        {"kind": "antenna", "pointing": "angles", "azimuth_deg": 1e9},
        "effects.0.azimuth_deg",
    )
    case(
        "attenuation-rain-inf",
        "effects",
        {"kind": "attenuation", "rain_rate_mm_per_h": inf},
        "effects.0.rain_rate_mm_per_h",
    )

    # the FMCW and CW radars: absurd single fields, and chirp sequences that cannot exist
    fmcw = {"kind": "fmcw", "preset": "iwr1443_short_range_3d"}
    case("fmcw-start-inf", "radar", {**fmcw, "start_frequency": inf}, "radar.start_frequency")
    case("fmcw-slope-1e300", "radar", {**fmcw, "slope": 1e300}, "radar.slope")
    case("fmcw-slope-negative", "radar", {**fmcw, "slope": -70e12}, "radar.slope")
    case("fmcw-idle-nan", "radar", {**fmcw, "idle_time": nan}, "radar.idle_time")
    case("fmcw-loops-1e9", "radar", {**fmcw, "n_loops": 10**9}, "radar.n_loops")
    case("fmcw-samples-zero", "radar", {**fmcw, "n_samples": 0}, "radar.n_samples")
    case("fmcw-adc-1e12", "radar", {**fmcw, "sample_rate": 1e12}, "radar.sample_rate")
    case("fmcw-tx-zero", "radar", {**fmcw, "tdm_order": [0, 1]}, "radar.tdm_order.0")
    case("fmcw-tx-missing", "radar", {**fmcw, "tdm_order": [1, 9]}, "radar.tdm_order: TX 9")
    case(
        "fmcw-antenna-1e9",
        "radar",
        {**fmcw, "rx_positions": [[1e9, 0.0]]},
        "radar.rx_positions.0.0",
    )
    case("fmcw-noise-figure-inf", "radar", {**fmcw, "noise_figure_db": inf}, "noise_figure_db")
    case(
        "fmcw-cfar-threshold-nan",
        "radar",
        {**fmcw, "cfar_range": {"threshold_db": nan}},
        "radar.cfar_range.threshold_db",
    )
    case("fmcw-gate-width-inf", "radar", {**fmcw, "gate_width": inf}, "radar.gate_width")
    case("fmcw-fft-1e9", "radar", {**fmcw, "range_fft_size": 10**9}, "radar.range_fft_size")
    case(
        "fmcw-adc-beyond-ramp",
        "radar",
        {**fmcw, "sample_rate": 1e6},
        "radar.ramp_end_time: the ADC samples until 247.000 us",
    )
    case(
        "fmcw-chirps-beyond-frame",
        "radar",
        {**fmcw, "n_loops": 2000},
        "radar.frame_period: 6000 chirps",
    )
    case(
        "fmcw-sweep-beyond-bandwidth",
        "radar",
        {**fmcw, "slope": 100e12},
        "radar.slope: slope x ramp_end_time sweeps 5.7140 GHz",
    )
    case(
        "fmcw-frame-cube-48gib",
        "radar",
        {**fmcw, "doppler_fft_size": 65536, "range_fft_size": 4096},
        "radar.doppler_fft_size: one frame's",
    )
    case(
        "fmcw-beat-above-adc",  # the target at 50 m beats above the 4.884 MHz ADC
        "radar",
        fmcw,
        "radar.sample_rate: the farthest scatterer at 50.00 m",
    )
    case(
        "fmcw-maps-beyond-limit",
        "",
        {
            "motion": {**point, "length": 2.0, "targets": [{"position": [3, 0, 0]}]},
            "radar": {
                "kind": "fmcw",
                "tdm_order": [1],
                "tx_positions": [[0.0, 0.0]],
                "rx_positions": [[0.0, 0.0]],
                "range_fft_size": 4096,
                "doppler_fft_size": 4096,
                "n_loops": 16,
                "frame_period": 0.05,
            },
        },
        "radar.save_range_doppler",
    )
    case(
        "fmcw-chirps-beyond-budget",
        "",
        {"motion": {**point, "length": 4000.0}, "radar": fmcw},
        "motion.duration",
    )
    cw = {"kind": "cw"}
    case("cw-carrier-inf", "radar", {**cw, "carrier_frequency": inf}, "radar.carrier_frequency")
    case("cw-carrier-1hz", "radar", {**cw, "carrier_frequency": 1.0}, "radar.carrier_frequency")
    case("cw-rate-nan", "radar", {**cw, "sample_rate": nan}, "radar.sample_rate")
    case("cw-rate-1e12", "radar", {**cw, "sample_rate": 1e12}, "radar.sample_rate")
    case("cw-power-inf", "radar", {**cw, "transmit_power": inf}, "radar.transmit_power")
    case(
        "cw-samples-beyond-budget",
        "",
        {"motion": {**point, "length": 1000.0}, "radar": {**cw, "sample_rate": 1e5}},
        "motion.duration",
    )

    # body models and the other motion sources
    body = {"kind": "cmu", "file": str(BVH)}

    def body_case(name: str, cfg: dict[str, Any], field: str) -> None:
        d = c.folder(f"field-{name}")
        c.run(f"field-{name}", _json_config(d, cfg), "run.json", field)

    body_case("cmu-frame-rate-inf", {"motion": {**body, "frame_rate": inf}}, "motion.frame_rate")
    body_case("cmu-start-1e9", {"motion": {**body, "start": 1e9}}, "motion.start")
    body_case(
        "kinect-frame-rate-inf",
        {
            "motion": {
                "kind": "kinect",
                "format": "msr-action3d",
                "file": str(MSR),
                "frame_rate": inf,
            }
        },
        "motion.frame_rate",
    )
    body_case(
        "ellipsoid-points-1e6",
        {"motion": body, "scatterers": {"kind": "ellipsoid", "surface_points": 10**6}},
        "scatterers.surface_points",
    )
    body_case(
        "ellipsoid-specular-surface-points",
        {
            "motion": body,
            "scatterers": {
                "kind": "ellipsoid",
                "scattering_phase": "specular",
                "surface_points": 8,
            },
        },
        "scatterers: scattering_phase = 'specular' needs surface_points = 0",
    )
    body_case(
        "ellipsoid-height-inf",
        {"motion": body, "scatterers": {"kind": "ellipsoid", "height": inf}},
        "scatterers.height",
    )
    body_case(
        "kinect-floor-inf",
        {"motion": {"kind": "kinect", "format": "utkinect", "file": str(UTK), "floor": inf}},
        "motion.floor: must be one of 'auto' (got inf) or must be a finite number",
    )
    body_case("boulic-speed-inf", {"motion": {"kind": "boulic", "speed": inf}}, "motion.speed")
    body_case(
        "boulic-cycles-1e12", {"motion": {"kind": "boulic", "n_cycles": 10**12}}, "motion.n_cycles"
    )
    body_case(
        "shadowing-decimation-0",
        {"motion": {"kind": "boulic"}, "effects": [{"kind": "shadowing", "decimation": 0}]},
        "effects.0.decimation",
    )
    body_case(
        "mujoco-radii-inf",
        {
            "motion": {"kind": "boulic"},
            "scatterers": {"kind": "mujoco_body", "radii": {"head": [inf, 0.1]}},
        },
        "scatterers.radii",
    )
    # a recording without a duration: the pulse count is checked once the motion is loaded
    body_case(
        "recording-pulses-beyond-limit",
        {"motion": body, "radar": {"kind": "lfm", "prf": 1e7, "pulse_width": 1e-7}},
        "pulses",
    )


# ------------------------------------------------------------- dataset and experiment configs


def _dataset_cases(c: _Corpus) -> None:
    source = {"label": "walk", "motion": {"kind": "cmu", "file": str(BVH)}}

    def ds_case(name: str, cfg: dict[str, Any], *expect: str, fmt: str = "json") -> None:
        d = c.folder(f"dataset-{name}")
        f = _json_config(d, cfg, f"dataset.{fmt}")
        out = d / "out"
        c.command(
            f"dataset-{name}", ["dataset", "build", str(f), "--out", str(out)], out, f.name, *expect
        )

    inf, nan = float("inf"), float("nan")
    ds_case("record-length-inf", {"sources": [{**source, "record_length": inf}]}, "record_length")
    ds_case("hop-tiny", {"sources": [{**source, "record_length": 1.0, "hop": 1e-9}]}, "records")
    ds_case("aspect-nan", {"sources": [source], "variations": {"aspect_deg": [nan]}}, "aspect_deg")
    ds_case("range-inf", {"sources": [source], "variations": {"radar_range": [inf]}}, "radar_range")
    ds_case(
        "scheduler-in-config",
        {"sources": [source], "scheduler": "tcp://203.0.113.1:8786"},
        "scheduler",
        "--scheduler",
    )
    ds_case("workers-1e6", {"sources": [source], "workers": 10**6}, "workers")
    ds_case(
        "percentile-1e9",
        {"sources": [source], "features": {"method": "percentile", "percentiles": [1e9, 2e9]}},
        "features.percentiles",
    )
    ds_case(
        "base-prf-inf",
        {
            "sources": [{**source, "record_length": 1.0}],
            "base": {"radar": {"kind": "lfm", "prf": inf}},
        },
        "radar.prf",
    )
    ds_case("seed-nan", {"sources": [source], "seed": nan}, "seed")
    ds_case(
        "record-lengths-nan",
        {"sources": [source], "record_lengths": {"walk": nan}},
        "record_lengths",
    )
    ds_case("max-records-1e12", {"sources": [{**source, "max_records": 10**12}]}, "max_records")
    ds_case("hop-nan", {"sources": [{**source, "hop": nan}]}, "hop")

    # [randomize]: distributions and the motion augmentations
    one = {**source, "record_length": 1.0, "max_records": 1}

    def rz_case(name: str, randomize: dict[str, Any], *expect: str) -> None:
        ds_case(f"randomize-{name}", {"sources": [one], "randomize": randomize}, *expect)

    rz_case("uniform-inf", {"aspect_deg": {"uniform": [0.0, inf]}}, "randomize.aspect_deg")
    rz_case("normal-std-nan", {"radar_range": {"normal": [5.0, nan]}}, "randomize.radar_range")
    rz_case("normal-std-negative", {"radar_range": {"normal": [5.0, -1.0]}}, "deviation")
    rz_case("loguniform-zero", {"speed": {"loguniform": [0.0, 1.0]}}, "randomize.speed")
    rz_case("low-above-high", {"aspect_deg": {"uniform": [10.0, 0.0]}}, "low must not exceed")
    rz_case("two-distributions", {"aspect_deg": {"uniform": [0, 1], "normal": [0, 1]}}, "one of")
    rz_case("aspect-list", {"aspect_deg": [0.0, 10.0]}, "randomize.aspect_deg: must be a table (")
    rz_case("choice-empty", {"aspect_deg": {"choice": []}}, "randomize.aspect_deg.choice")
    rz_case("draws-1e9", {"draws": 10**9}, "randomize.draws")
    rz_case("bound-1e300", {"radar_range": {"uniform": [1.0, 1e300]}}, "randomize.radar_range")
    rz_case("speed-1e-12", {"speed": {"loguniform": [1e-12, 1e-11]}}, "randomize.speed", "0.1")
    rz_case("speed-1e10", {"speed": {"uniform": [1e9, 1e10]}}, "randomize.speed", "10")
    rz_case("body-scale-negative", {"body_scale": {"uniform": [-2.0, -1.0]}}, "body_scale")
    rz_case("body-scale-1e6", {"body_scale": {"normal": [1.0, 1e6]}}, "randomize.body_scale")
    rz_case("speed-choice-text", {"speed": {"choice": ["fast"]}}, "randomize.speed")
    rz_case("mirror-probability-2", {"mirror": 2.0}, "randomize.mirror")
    rz_case("time-warp-1", {"time_warp": 1.0}, "randomize.time_warp")
    rz_case("time-warp-nan", {"time_warp": nan}, "randomize.time_warp")
    rz_case(
        "param-beyond-field",
        {"params": {"radar.prf": {"uniform": [1e9, 1e10]}}},
        'randomize.params."radar.prf" drew',
        "record 0",
    )
    rz_case("param-unknown-field", {"params": {"radar.nope": {"uniform": [1, 2]}}}, "nope")
    # not a field inside a section: the record's seed is the build's, "speed" is no field
    rz_case("param-seed", {"params": {"seed": {"choice": [1, 2]}}}, 'randomize.params: "seed"')
    rz_case(
        "param-no-section", {"params": {"speed": {"uniform": [20, 30]}}}, '"speed"', "radar.prf"
    )
    rz_case("param-no-list-item", {"params": {"effects.3.snr_db": {"uniform": [1, 2]}}}, "effects")
    rz_case(
        "radar-range-absurd",
        {"radar_range": {"normal": [0.0, 1e9]}},
        "randomize.radar_range drew",
        "radar_position",
    )
    # a field the source does not have (a CMU trial's body is the recorded one)
    rz_case(
        "height-on-cmu", {"height": {"uniform": [1.5, 1.9]}}, "randomize.height drew", "record 0"
    )
    ds_case(
        "variations-height-on-cmu",
        {"sources": [one], "variations": {"height": [1.7]}},
        "variations.height",
        "unknown field 'height'",
    )
    ds_case(
        "source-randomize-speed-inf",
        {"sources": [{**one, "randomize": {"speed": {"uniform": [1.0, inf]}}}]},
        "randomize.speed",
    )
    # what a build sets for every record itself: never silently dropped
    repair = {"sanity": {"glitches": "repair"}}
    ds_case("base-motion", {"sources": [one], "base": {"motion": repair}}, "base.motion")
    ds_case("run-motion", {"sources": [{**one, "run": {"motion": repair}}]}, "[0].run.motion")
    ds_case("base-seed", {"sources": [one], "base": {"seed": 5}}, "base.seed", "seed")
    ds_case(
        "record-lengths-no-such-label",
        {"sources": [source], "record_lengths": {"walks": 1.0}},
        "record_lengths.walks",
        "'walk'",
    )
    # the span a source's records are cut from
    motion = source["motion"]
    ds_case(
        "source-start-text",
        {"sources": [{**one, "motion": {**motion, "start": "late"}}]},
        "sources[0].motion.start",
    )
    ds_case(
        "source-duration-zero",
        {"sources": [{**source, "motion": {**motion, "duration": 0.0}}]},
        "sources[0].motion.duration",
    )
    ds_case(
        "source-start-past-end",
        {"sources": [{**source, "motion": {**motion, "start": 1000.0}}]},
        "sources[0].motion.start",
        "1000",
    )

    def exp_case(name: str, cfg: dict[str, Any], *expect: str, argv: tuple[str, ...] = ()) -> None:
        d = c.folder(f"experiment-{name}")
        f = _json_config(d, cfg, "experiment.json")
        out = d / "out"
        c.command(
            f"experiment-{name}",
            ["experiment", str(f), "--out", str(out), "--no-progress", *argv],
            out,
            f.name,
            *expect,
        )

    ds = {"path": str(c.root / "no-dataset-needed")}
    exp_case(
        "estimator-os-system",
        {"dataset": ds, "classifier": {"kind": "sklearn", "estimator": "os.system"}},
        "classifier.estimator",
        "--allow-import",
    )
    exp_case(
        "estimator-outside-sklearn",
        {"dataset": ds, "classifier": {"kind": "sklearn", "estimator": "numpy.linalg.norm"}},
        "classifier.estimator",
    )
    exp_case("repeats-1e9", {"dataset": ds, "evaluation": {"repeats": 10**9}}, "evaluation.repeats")
    exp_case(
        "test-fraction-nan", {"dataset": ds, "evaluation": {"test_fraction": nan}}, "test_fraction"
    )
    exp_case(
        "knn-k-1e9", {"dataset": ds, "classifier": {"kind": "knn", "k": 10**9}}, "classifier.k"
    )
    exp_case("folds-inf", {"dataset": ds, "selection": {"folds": inf}}, "selection.folds")
    exp_case("seed-2-to-the-70", {"dataset": ds, "seed": 2**70}, "seed")
    exp_case("sizes-zero", {"dataset": ds, "selection": {"sizes": [0]}}, "selection.sizes")
    exp_case("sizes-1e9", {"dataset": ds, "selection": {"sizes": [10**9]}}, "selection.sizes")
    exp_case("folds-one", {"dataset": ds, "selection": {"folds": 1}}, "selection.folds")
    exp_case(
        "test-fraction-one", {"dataset": ds, "evaluation": {"test_fraction": 1.0}}, "test_fraction"
    )
    exp_case("workers-1e6", {"dataset": ds, "workers": 10**6}, "workers")
    exp_case("no-dataset", {"classifier": {"kind": "knn"}}, "dataset")
    exp_case("dataset-both", {"dataset": {**ds, "config": "x.toml"}}, "dataset")
    exp_case("dataset-missing", {"dataset": ds}, "no-dataset-needed")
    exp_case(
        "sklearn-param-inf",
        {
            "dataset": ds,
            "classifier": {
                "kind": "sklearn",
                "estimator": "sklearn.svm.SVC",
                "params": {"C": inf},
            },
        },
        "classifier.params.C: must be a finite number",
    )
    svc = {"kind": "sklearn", "estimator": "sklearn.svm.SVC"}
    exp_case(
        "sklearn-param-negative",
        {"dataset": ds, "classifier": {**svc, "params": {"C": -1.0}}},
        "classifier.params: The 'C' parameter of SVC must be",
    )
    exp_case(
        "sklearn-param-unknown",
        {"dataset": ds, "classifier": {**svc, "params": {"nope": 1}}},
        "classifier.params:",
        "'nope'",
    )
    exp_case(
        "scatter-pair-unknown",
        {"dataset": ds, "report": {"scatter_pairs": [["nope", "upper_max"]]}},
        "report.scatter_pairs",
    )
    exp_case(
        "cross-source-not-a-table",
        {"dataset": ds, "cross_source": [{"train": "a", "test": "b"}]},
        "cross_source",
    )


def _reader_cases(c: _Corpus) -> None:
    """C3D and TRC marker files (the real treadmill captures, damaged) and joint-track tables
    (the real UTKinect table, damaged, and small written ones)."""
    raw = C3D.read_bytes()
    rng = np.random.default_rng(11)

    def c3d_case(name: str, data: bytes, *expect: str) -> None:
        d = c.folder(f"c3d-{name}")
        (d / "walk.c3d").write_bytes(data)
        motion = {"kind": "c3d", "file": "walk.c3d"}
        c.run(f"c3d-{name}", _json_config(d, {"motion": motion}), "walk.c3d", *expect)

    c3d_case("truncated", raw[:200_000], "truncated")
    c3d_case("wrong-key", raw[:1] + b"\x51" + raw[2:], "not a C3D file")
    huge = bytearray(raw)
    huge[8:10] = (65535).to_bytes(2, "little")
    c3d_case("last-frame-65535", bytes(huge), "65491 frames")
    c3d_case("random-bytes", rng.integers(0, 256, 5000, dtype=np.uint8).tobytes(), "not a C3D")
    c3d_case("too-short", raw[:100], "too short")
    c3d_case("no-arm-markers", raw, "lacks head", "marker_map")

    trc = _lines(TRC)

    def trc_header(key: str, value: str) -> str:
        keys = [k.strip() for k in trc[1].split("\t")]
        values = trc[2].rstrip("\n").split("\t")
        values[keys.index(key)] = value
        return "".join([*trc[:2], "\t".join(values) + "\n", *trc[3:]])

    def trc_case(name: str, text: str, *expect: str) -> None:
        d = c.folder(f"trc-{name}")
        (d / "walk.trc").write_text(text, encoding="utf-8")
        motion = {"kind": "trc", "file": "walk.trc"}
        c.run(f"trc-{name}", _json_config(d, {"motion": motion}), "walk.trc", *expect)

    trc_case("truncated", "".join(trc[:60]), "walk.trc:3:", "truncated")
    trc_case("row-cut-short", "".join([*trc[:59], trc[59][:300] + "\n", *trc[60:]]), ":60:")
    trc_case("num-frames-1e9", trc_header("NumFrames", "1000000000"), "walk.trc:3:", "NumFrames")
    trc_case("num-markers-1e12", trc_header("NumMarkers", "1e12"), "walk.trc:3:", "NumMarkers")
    trc_case("num-markers-wrong", trc_header("NumMarkers", "40"), "walk.trc:4:", "NumMarkers")
    trc_case("data-rate-nan", trc_header("DataRate", "nan"), "walk.trc:3:", "DataRate")
    trc_case("data-rate-wrong", trc_header("DataRate", "120"), "walk.trc:8:", "DataRate")
    trc_case("units-furlongs", trc_header("Units", "furlongs"), "walk.trc:3:", "unit_m")
    for bad in ("1e308", "inf", "nan-word"):
        row = trc[9].replace("621.540410", bad, 1)
        trc_case(f"value-{bad}", "".join([*trc[:9], row, *trc[10:]]), "walk.trc:10:")
    trc_case("not-a-trc", "".join(["Hello\n", *trc[1:]]), "walk.trc:1:", "not a TRC")

    utk = _lines(UTK)
    joints = [
        "HipCenter", "Spine", "ShoulderCenter", "Head", "ShoulderLeft", "ElbowLeft",
        "WristLeft", "HandLeft", "ShoulderRight", "ElbowRight", "WristRight", "HandRight",
        "HipLeft", "KneeLeft", "AnkleLeft", "FootLeft", "HipRight", "KneeRight", "AnkleRight",
        "FootRight",
    ]  # fmt: skip
    table = {
        "kind": "table", "file": UTK.name, "header": False, "time_column": "frame",
        "frame_rate": 60.0, "joints": joints, "joint_set": "kinect-v1",
    }  # fmt: skip

    def table_case(
        name: str, fname: str, data: str | bytes, motion: dict[str, Any], *e: str
    ) -> None:
        d = c.folder(f"table-{name}")
        (d / fname).write_bytes(data if isinstance(data, bytes) else data.encode("utf-8"))
        c.run(f"table-{name}", _json_config(d, {"motion": {**motion, "file": fname}}), fname, *e)

    table_case("truncated-line", UTK.name, "".join(utk[:30]) + utk[30][:40], table, ":31:")
    table_case(
        "coordinate-1e308",
        UTK.name,
        "".join([*utk[:9], _replace_field(utk[9], 4, "1e308"), *utk[10:]]),
        table,
        ":10:",
        "beyond",
    )
    table_case(
        "word",
        UTK.name,
        "".join([*utk[:4], _replace_field(utk[4], 2, "up"), *utk[5:]]),
        table,
        ":5:",
    )
    table_case("binary", UTK.name, "".join(utk[:5]).encode() + b"\x00\x01", table, "NUL")
    long = {"kind": "table"}
    rows = "time,joint,x,y,z\n0,head,0,0,1.7\n0,head,0,0,1.7\n"
    table_case("joint-twice", "t.csv", rows, long, "t.csv:3:", "twice")
    rows = "time,joint,x,y,z\n0,head,0,0,1.7\n0.1,head,0,0,1.7\n"
    table_case("missing-joints", "t.csv", rows, long, "lacks base", "joint_map")
    table_case("time-inf", "t.csv", "time,joint,x,y,z\ninf,head,0,0,1\n", long, "time")
    rows = "time,joint,x,y,z,x\n0,head,0,0,1.7,0\n0.1,head,0,0,1.7,0\n"
    table_case("column-twice", "t.csv", rows, long, "t.csv:1:", "appears twice")
    d = c.folder("table-npz-objects")
    np.savez(d / "t.npz", positions=np.array([object()]), joints=np.array(["head"]))
    c.run("table-npz-objects", _json_config(d, {"motion": {"kind": "table", "file": "t.npz"}}),
          "t.npz", "objects")  # fmt: skip


def _command_cases(c: _Corpus) -> None:
    """Every command on the inputs any of them can be given by mistake: a config that is not
    there, a folder, an empty file or a config of another kind; --out inside a file; malformed
    options; and the plugin commands' files."""
    run = {
        "motion": {"kind": "point_targets", "length": 1.0, "targets": [{"position": [50, 0, 0]}]}
    }
    dataset = {"sources": [{"label": "walk", "motion": {"kind": "cmu", "file": str(BVH)}}]}
    experiment = {"dataset": {"config": "dataset.json"}}
    commands = {
        "run": ("run", "--out"),
        "show": ("show", "--out"),
        "check": ("check",),
        "dataset": ("dataset", "build", "--out"),
        "dataset-check": ("dataset", "check"),
        "experiment": ("experiment", "--out"),
    }

    def case(name: str, words: tuple[str, ...], config: str, *expect: str, **extra: str) -> None:
        d = c.folder(f"command-{name}")
        (d / "run.json").write_text(json.dumps(run))
        (d / "dataset.json").write_text(json.dumps(dataset))
        (d / "experiment.json").write_text(json.dumps(experiment))
        (d / "folder.toml").mkdir()
        (d / "empty.yaml").write_bytes(b"")
        (d / "a-file").write_text("not a folder\n")
        out = d / extra.get("out", "out")
        argv = [w for w in words if w != "--out"] + [str(d / config)]
        if "--out" in words:
            argv += ["--out", str(out)]
        argv += extra.get("options", "").split()
        c.command(f"command-{name}", argv, d / "out", *expect)

    for name, words in commands.items():
        case(f"{name}-missing-config", words, "nope.toml", "nope.toml", "cannot read")
        case(f"{name}-config-is-a-folder", words, "folder.toml", "folder.toml", "cannot read")
        case(f"{name}-empty-yaml", words, "empty.yaml", "empty.yaml", "top level")
    for name, words in commands.items():
        kind = (
            "dataset"
            if name in ("dataset", "dataset-check")
            else "experiment"
            if name == "experiment"
            else "run"
        )
        for other in ("run", "dataset", "experiment"):
            if other != kind:
                reader = commands["dataset" if other == "dataset" else other]
                case(
                    f"{name}-given-{other}-config",
                    words,
                    f"{other}.json",
                    f"{other}.json: a",
                    f"{other} config",
                    f"use `mdf {' '.join(w for w in reader if w != '--out')}",
                )
    for name, words in commands.items():
        if "--out" in words:
            config = {"dataset": "dataset.json", "experiment": "experiment.json"}.get(
                name, "run.json"
            )
            case(f"{name}-out-inside-a-file", words, config, "--out", "a-file", out="a-file/out")
    build = commands["dataset"]
    case("dataset-workers-negative", build, "dataset.json", "--workers", options="--workers -3")
    case("dataset-workers-word", build, "dataset.json", "--workers", options="--workers two")
    case(
        "dataset-scheduler-malformed",
        build,
        "dataset.json",
        "Dask scheduler 'nonsense': not an address",
        options="--scheduler nonsense",
    )
    case("show-fps-zero", commands["show"], "run.json", "--fps", options="--fps 0")
    # a frame every microsecond of the record would render for hours
    case("show-fps-1e6", commands["show"], "run.json", "--fps", "100", options="--fps 1000000")
    case("run-unknown-option", commands["run"], "run.json", "--bogus", options="--bogus")
    # a second config (or any stray word) points to the command's own help
    case("run-extra-word", commands["run"], "run.json", "unrecognized", "`mdf run --help`",
         options="extra")  # fmt: skip
    case("dataset-extra-word", build, "dataset.json", "unrecognized",
         "`mdf dataset build --help`", options="extra")  # fmt: skip
    for name, words in commands.items():
        if "--out" in words:  # `--out "$DIR"` with DIR unset: never the working folder
            d = c.folder(f"command-{name}-out-empty")
            argv = [w for w in words if w != "--out"] + [str(d / "x.json"), "--out", ""]
            c.command(f"command-{name}-out-empty", argv, d / "out", "--out: must not be empty")
    d = c.folder("command-unknown")
    c.command("command-unknown", ["simulate", str(d)], d / "out", "invalid choice", "mdf --help")
    c.command("command-none", [], d / "out", "required: COMMAND")
    c.command("command-plugins-extra", ["plugins", "all"], d / "out", "unrecognized", "all")
    c.command("command-schema-extra", ["config", "schema", "x"], d / "out", "unrecognized")
    # the Kinect plugin's commands: a folder or an empty file for a recording; --out of a
    # capture checked before the device starts (no NiTE2 here: the check must come first)
    d = c.folder("command-kinect-info-folder")
    (d / "rec.oni").mkdir()
    c.command("command-kinect-info-folder", ["kinect", "info", str(d / "rec.oni")], d / "out",
              "rec.oni", "cannot read")  # fmt: skip
    d = c.folder("command-kinect-info-empty")
    (d / "rec.oni").write_bytes(b"")
    c.command("command-kinect-info-empty", ["kinect", "info", str(d / "rec.oni")], d / "out",
              "rec.oni", "too short")  # fmt: skip
    d = c.folder("command-capture-out-folder")
    c.command("command-capture-out-folder", ["capture", "--out", str(d)], d / "out",
              f"--out {d}", "is a folder")  # fmt: skip
    d = c.folder("command-capture-out-inside-a-file")
    (d / "a-file").write_text("x\n")
    c.command("command-capture-out-inside-a-file",
              ["capture", "--out", str(d / "a-file" / "walk.nite.txt")], d / "out",
              "a-file is a file")  # fmt: skip
    d = c.folder("command-capture-duration-nan")
    c.command("command-capture-duration-nan",
              ["capture", "--out", str(d / "w.nite.txt"), "--duration", "nan"], d / "out",
              "--duration")  # fmt: skip


def _clip_frame(line: str, index: int, value: str | None) -> str:
    """A DeepMimic clip's frame line (``[v0, v1, ...],``) with value ``index`` replaced, or
    dropped when ``value`` is None."""
    head, body = line.split("[", 1)
    body, tail = body.rsplit("]", 1)
    values = body.split(",")
    if value is None:
        del values[index]
    else:
        values[index] = f" {value}"
    return head + "[" + ",".join(values) + "]" + tail


def _deepmimic_cases(c: _Corpus) -> None:
    """DeepMimic clips: the real walk (frame i on line i + 5) damaged, and a clip that does not
    loop asked to repeat."""
    walk = _lines(DEEPMIMIC_WALK)

    def clip_case(name: str, data: str | bytes, *expect: str, **motion: Any) -> None:
        d = c.folder(f"deepmimic-{name}")
        (d / "walk.txt").write_bytes(data if isinstance(data, bytes) else data.encode("utf-8"))
        cfg = {"motion": {"kind": "deepmimic", "file": "walk.txt", **motion}}
        c.run(f"deepmimic-{name}", _json_config(d, cfg), "walk.txt", *expect)

    def frame(i: int, index: int, value: str | None) -> str:
        lines = list(walk)
        lines[i + 4] = _clip_frame(lines[i + 4], index, value)
        return "".join(lines)

    clip_case("truncated", "".join(walk)[:20_000], "not valid JSON", "truncated")
    clip_case("frame-width", frame(10, 7, None), "walk.txt:15:", "frame 10 has 43 values")
    clip_case("nan", frame(5, 12, "NaN"), "walk.txt:10:", "not finite")
    clip_case("zero-duration", frame(3, 0, "0.0"), "walk.txt:8:", "duration 0.0")
    clip_case("negative-duration", frame(3, 0, "-0.0333"), "walk.txt:8:", "duration")
    clip_case("position-1e300", frame(7, 1, "1e300"), "walk.txt:12:", "root position")
    clip_case("quaternion-zero", frame(2, 8, "0"), "walk.txt:7:", "chest quaternion")
    clip_case("word", frame(4, 3, '"up"'), "walk.txt:9:", "not a number")
    clip_case("loop", "".join(walk).replace('"wrap"', '"bounce"'), "walk.txt:2:", "Loop")
    clip_case("not-a-clip", "[1, 2, 3]", "Frames")
    clip_case("binary", "".join(walk[:6]).encode() + b"\x00", "NUL")
    clip_case("one-frame", "".join(walk[:4]) + walk[4].rstrip().rstrip(",") + "\n]\n}\n", "1 frame")
    d = c.folder("deepmimic-huge")
    with open(d / "walk.txt", "wb") as f:  # sparse: huge on paper, nothing read or allocated
        f.truncate(200 * 1024 * 1024)
    c.run("deepmimic-huge", _json_config(d, {"motion": {"kind": "deepmimic", "file": "walk.txt"}}),
          "walk.txt", "beyond the limit")  # fmt: skip
    d = c.folder("deepmimic-cycles-of-a-punch")
    (d / "punch.txt").write_bytes(DEEPMIMIC_PUNCH.read_bytes())
    motion = {"kind": "deepmimic", "file": "punch.txt", "cycles": 2}
    c.run("deepmimic-cycles-of-a-punch", _json_config(d, {"motion": motion}), "punch.txt", "Loop")
    d = c.folder("deepmimic-character-without-arms")
    (d / "walk.txt").write_bytes(DEEPMIMIC_WALK.read_bytes())
    joints = [{"ID": 0, "Name": "root", "Type": "none", "Parent": -1}]
    (d / "legs.txt").write_text(json.dumps({"Skeleton": {"Joints": joints}}), encoding="utf-8")
    motion = {"kind": "deepmimic", "file": "walk.txt", "character": "legs.txt"}
    c.run("deepmimic-character-without-arms", _json_config(d, {"motion": motion}), "legs.txt",
          "lacks neck, left_shoulder")  # fmt: skip
    d = c.folder("deepmimic-mirrored-axes")
    (d / "walk.txt").write_bytes(DEEPMIMIC_WALK.read_bytes())
    motion = {"kind": "deepmimic", "file": "walk.txt", "axes": ["x", "z", "y"]}
    c.run("deepmimic-mirrored-axes", _json_config(d, {"motion": motion}), "motion.axes", "mirror")


def make_corpus(root: Path) -> list[Case]:
    """Write every case under ``root`` (an empty folder) and return them."""
    root.mkdir(parents=True, exist_ok=True)
    c = _Corpus(root)
    _motion_cases(c)
    _radhar_cases(c)
    _reader_cases(c)
    _deepmimic_cases(c)
    _config_file_cases(c)
    _field_cases(c)
    _dataset_cases(c)
    _command_cases(c)
    names = [case.name for case in c.cases]
    assert len(names) == len(set(names)), "case names must be unique"
    return c.cases


def case_names() -> list[str]:
    """The names of the corpus's cases (writes them to a temporary folder)."""
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        return [case.name for case in make_corpus(Path(tmp) / "corpus")]


def main(argv: list[str] | None = None) -> int:
    """``python tests/corpus/make_corpus.py OUT_DIR``: write the corpus and list its cases."""
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        print(__doc__)
        return 2
    for case in make_corpus(Path(args[0])):
        print(f"{case.name:40s} mdf {' '.join(case.argv)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
