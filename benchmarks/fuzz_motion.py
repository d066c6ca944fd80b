"""Fuzzing: damaged copies of the shipped motion files through ``mdf run``.

Each case copies one shipped recording (CMU ASF/AMC and BVH, a Mixamo BVH, DeepMimic, UTKinect,
MSR Action3D, a TRC, and the UTKinect file read as a generic table) with one random defect (the
file cut at a byte, a byte changed, a number replaced by ``nan``, ``inf``, ``1e308``, text or
nothing, a line dropped, repeated, swapped or inserted) and runs the shipped example config on
it, in this process, as ``mdf run CONFIG --set motion.file=COPY --no-figures``. A case passes
when the run ends with exit code 0 (``ok``: the defect left a readable motion) or 2 with one
line on stderr naming the damaged file (``refused``), and leaves no output folder behind when
refused. Anything else (an internal error, a traceback, another exit code) is a failure; the
first few are printed, and the exit code is 1.

The C3D reader (a C library underneath) gets its own damaged copies of the shipped treadmill
walk: each is read in a child process, so that a crash in the library is a failure too. So does
the Kinect plugin's OpenNI2 playback: each damaged copy of the shipped ``.oni`` recording goes
through ``mdf kinect info``, in this process (the command plays the file in a child process of
its own, and reports a crash of OpenNI2 as one line).

    .venv/bin/python benchmarks/fuzz_motion.py [--cases 600] [--c3d 150] [--oni 100] [--seed 0]
        [--json PATH]

Reports the outcomes per format and in all; ``--json`` also writes them, with the command, the
date and the wall time (``docs/data/fuzz_motion_results.json`` holds the run that
``docs/input-rules.md`` quotes).
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import io
import json
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mdframework import cli

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
ASF_AMC, MSR = "data/cmu/asf-amc", "data/kinect/msr-action3d"
#: format -> (example config, the file damaged, files copied beside it, the file the config reads)
FORMATS: dict[str, tuple[str, str, tuple[str, ...], str | None]] = {
    "amc": ("cmu_walk.toml", f"{ASF_AMC}/02_01.amc", (f"{ASF_AMC}/02.asf",), None),
    "asf": ("cmu_walk.toml", f"{ASF_AMC}/02.asf", (f"{ASF_AMC}/02_01.amc",), "02_01.amc"),
    "cmu-bvh": ("cmu_walk.toml", "data/cmu/bvh/16_21.bvh", (), None),
    "bvh": ("bvh_mixamo.toml", "data/bvh/test_freebvh.bvh", (), None),
    "deepmimic": ("deepmimic_walk.toml", "data/deepmimic/humanoid3d_walk.txt", (), None),
    "utkinect": ("kinect_utkinect_walk.toml", "data/kinect/utkinect/joints_s01_e01.txt",
                 ("data/kinect/utkinect/actionLabel.txt",), None),
    "msr": ("kinect_msr_boxing.toml", f"{MSR}/a16_s01_e01_skeleton3D.txt", (), None),
    "trc": ("trc_walk.toml", "data/trc/opensim_subject01_walk.trc", (), None),
    "table": ("table_utkinect_walk.toml", "data/kinect/utkinect/joints_s01_e01.txt", (), None),
}  # fmt: skip
C3D = EXAMPLES / "data" / "c3d" / "treadmill_events.c3d"
ONI = EXAMPLES / "data" / "kinect" / "oni" / "test.oni"
NUMBER = re.compile(rb"-?\d+(?:\.\d+)?(?:e-?\d+)?")
REPLACEMENTS = (b"nan", b"inf", b"-inf", b"1e308", b"-1e308", b"0", b"", b"x", b"1e-320",
                b"99999999999999999999", b"-0", b"1.5", b"-1")  # fmt: skip
INSERTS = (b"", b"   ", b"\t", b"#", b"garbage line", b"1 2 3", b"\x00\xff")


def damage_text(raw: bytes, rng: random.Random) -> tuple[bytes, str]:
    """One random defect of a text file, and its description."""
    op = rng.choice(["cut", "byte", "number", "number", "drop", "repeat", "swap", "insert"])
    if op == "cut":
        k = rng.randrange(len(raw))
        return raw[:k], f"cut at byte {k}"
    if op == "byte":
        k = rng.randrange(len(raw))
        return raw[:k] + bytes([rng.randrange(256)]) + raw[k + 1 :], f"byte {k} changed"
    if op == "number":
        m = rng.choice(list(NUMBER.finditer(raw)))
        new = rng.choice(REPLACEMENTS)
        return raw[: m.start()] + new + raw[
            m.end() :
        ], f"{m.group()!r} -> {new!r} at byte {m.start()}"
    lines = raw.split(b"\n")
    k = rng.randrange(len(lines))
    if op == "drop":
        del lines[k]
    elif op == "repeat":
        lines.insert(k, lines[k])
    elif op == "swap":
        j = rng.randrange(len(lines))
        lines[k], lines[j] = lines[j], lines[k]
        op += f" with line {j + 1}"
    else:
        lines.insert(k, rng.choice(INSERTS))
    return b"\n".join(lines), f"line {k + 1}: {op}"


def damage_binary(raw: bytes, rng: random.Random) -> tuple[bytes, str]:
    """One random defect of a binary file (a C3D: its header and parameters are the first blocks
    of 512 bytes), and its description."""
    b = bytearray(raw)
    op = rng.choice(["cut", "byte", "byte", "word", "zeros"])
    if op == "cut":
        k = rng.randrange(len(b))
        return bytes(b[:k]), f"cut at byte {k}"
    if op == "byte":
        k = rng.choice([rng.randrange(512), rng.randrange(512, 512 * 20), rng.randrange(len(b))])
        b[k] = rng.randrange(256)
        return bytes(b), f"byte {k} changed"
    if op == "word":
        k = rng.randrange(512 * 20 - 4)
        b[k : k + 4] = rng.randbytes(4)
        return bytes(b), f"bytes {k}..{k + 3} changed"
    k, n = rng.randrange(len(b)), rng.randrange(1, 2000)
    b[k : k + n] = bytes(len(b[k : k + n]))
    return bytes(b), f"{n} bytes zeroed at {k}"


def run_case(fmt: str, case: Path, rng: random.Random) -> tuple[str, str]:
    """Damage one file of ``fmt`` in the folder ``case`` and run its config; (outcome, note)."""
    config, data, beside, reads = FORMATS[fmt]
    for name in beside:
        shutil.copy(EXAMPLES / name, case / Path(name).name)
    damaged, what = damage_text((EXAMPLES / data).read_bytes(), rng)
    (case / Path(data).name).write_bytes(damaged)
    motion = case / (reads or Path(data).name)
    out = case / "out"
    err = io.StringIO()
    args = ["run", str(EXAMPLES / config), "--out", str(out), "--no-figures", "--no-progress",
            "--set", f"motion.file={json.dumps(str(motion))}"]  # fmt: skip
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = cli.main(args)
    errors = [line for line in err.getvalue().splitlines() if not line.startswith("mdf: warning")]
    if code == 0:
        return "ok", what
    if code == 2 and len(errors) == 1 and str(case) in errors[0] and not out.exists():
        return "refused", what
    return "failed", f"{what}: exit {code}: {' | '.join(errors)[:300]}"


C3D_READ = """
import sys
from pathlib import Path
from mdframework.errors import MdfError
from mdf_c3d import read_c3d
try:
    read_c3d(Path(sys.argv[1]))
except MdfError as exc:
    print(exc, file=sys.stderr)
    sys.exit(2)
"""


def run_c3d_case(case: Path, rng: random.Random) -> tuple[str, str]:
    """Damage the shipped C3D file and read it in a child process; (outcome, note)."""
    damaged, what = damage_binary(C3D.read_bytes(), rng)
    path = case / C3D.name
    path.write_bytes(damaged)
    done = subprocess.run(
        [sys.executable, "-c", C3D_READ, str(path)], capture_output=True, text=True, timeout=120
    )
    lines = done.stderr.strip().splitlines()
    if done.returncode == 0:
        return "ok", what
    if done.returncode == 2 and len(lines) == 1 and str(path) in lines[0]:
        return "refused", what
    return "failed", f"{what}: exit {done.returncode}: {' | '.join(lines[-3:])[:300]}"


def run_oni_case(case: Path, rng: random.Random) -> tuple[str, str]:
    """Damage the shipped .oni recording and run ``mdf kinect info`` on it; (outcome, note)."""
    damaged, what = damage_binary(ONI.read_bytes(), rng)
    path = case / ONI.name
    path.write_bytes(damaged)
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = cli.main(["kinect", "info", str(path)])
    errors = [line for line in err.getvalue().splitlines() if not line.startswith("mdf: warning")]
    if code == 0:
        return "ok", what
    if code == 2 and len(errors) == 1 and str(path) in errors[0]:
        return "refused", what
    return "failed", f"{what}: exit {code}: {' | '.join(errors)[:300]}"


def main(argv: list[str] | None = None) -> int:
    """Run the fuzzer; returns 1 if any case failed."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=600, help="damaged text files, in all")
    parser.add_argument("--c3d", type=int, default=150, help="damaged C3D files")
    parser.add_argument("--oni", type=int, default=100, help="damaged .oni recordings")
    parser.add_argument("--seed", type=int, default=0, help="seed of the damage")
    parser.add_argument("--json", type=Path, default=None, help="write the figures to this file")
    args = parser.parse_args(argv)
    started = time.time()
    rng = random.Random(args.seed)
    counts: collections.Counter[tuple[str, str]] = collections.Counter()
    failures: list[str] = []
    formats = list(FORMATS)
    with tempfile.TemporaryDirectory(prefix="mdf-fuzz-motion-") as tmp:
        kinds = [formats[i % len(formats)] for i in range(args.cases)]
        kinds += ["c3d"] * args.c3d + ["oni"] * args.oni
        for i, fmt in enumerate(kinds):
            case = Path(tmp) / f"case{i}"
            case.mkdir()
            if fmt == "c3d":
                outcome, note = run_c3d_case(case, rng)
            elif fmt == "oni":
                outcome, note = run_oni_case(case, rng)
            else:
                outcome, note = run_case(fmt, case, rng)
            counts[fmt, outcome] += 1
            if outcome == "failed":
                failures.append(f"case {i} ({fmt}) {note}")
            shutil.rmtree(case)
    outcomes: collections.Counter[str] = collections.Counter()
    for (_, outcome), n in counts.items():
        outcomes[outcome] += n
    for fmt in [*formats, "c3d", "oni"]:
        row = {o: counts[fmt, o] for o in ("ok", "refused", "failed")}
        print(f"{fmt:<10} {row}")
    total = sum(outcomes.values())
    print(f"{total} cases: {outcomes['ok']} ok, {outcomes['refused']} refused, "
          f"{outcomes['failed']} failed ({time.time() - started:.0f} s)")  # fmt: skip
    for line in failures[:10]:
        print("FAILED", line)
    if args.json:
        report = {
            "command": f"benchmarks/fuzz_motion.py --cases {args.cases} --c3d {args.c3d} "
            f"--oni {args.oni} --seed {args.seed}",
            "commit": subprocess.run(
                ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True
            ).stdout.strip(),
            "date": time.strftime("%Y-%m-%d", time.gmtime(started)),
            "cases": total,
            "outcomes": {o: outcomes[o] for o in ("ok", "refused", "failed")},
            "by_format": {
                fmt: {o: counts[fmt, o] for o in ("ok", "refused", "failed")}
                for fmt in [*formats, "c3d", "oni"]
            },
            "wall_s": round(time.time() - started, 1),
        }
        args.json.write_text(json.dumps(report, indent=2) + "\n")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
