"""Benchmark: set-up time of a fresh clone: the first ``make demo``, then ``make test``.

Clones the repository's committed HEAD into a new folder under /tmp, then times the first
``make demo`` (creating .venv and installing the core and every plugin, running every example and
the CMU experiment) and then ``make test`` (ruff, mypy, the whole pytest suite in parallel).
Prints the wall time of each, the CPU time of each (all processes), pytest's own summary line,
and the load average before and after, since the machine may be shared.

    .venv/bin/python benchmarks/bench_setup.py [--keep] [--json OUT.json]

Goals: the first ``make demo`` within 3 minutes, ``make test`` within 4 minutes.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def timed(cmd: list[str], cwd: Path, log: Path) -> dict[str, Any]:
    """Run ``cmd`` in ``cwd`` with its output in ``log``; wall and CPU seconds, exit code."""
    load = os.getloadavg()
    cpu0 = _children_cpu()
    t0 = time.perf_counter()
    with log.open("w") as fh:
        code = subprocess.run(cmd, cwd=cwd, stdout=fh, stderr=subprocess.STDOUT).returncode
    return {
        "command": " ".join(cmd),
        "wall_s": time.perf_counter() - t0,
        "cpu_s": _children_cpu() - cpu0,
        "exit_code": code,
        "load_before": load,
        "load_after": os.getloadavg(),
        "log": str(log),
    }


def main() -> None:
    """Clone, time ``make demo`` and ``make test``, print the figures."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--keep", action="store_true", help="Keep the clone (its path is printed).")
    ap.add_argument("--json", type=Path, default=None, help="Also write the results here.")
    a = ap.parse_args()
    work = Path(tempfile.mkdtemp(prefix="mdf-setup-", dir="/tmp"))
    clone = work / "mdframework"
    subprocess.run(["git", "clone", "--quiet", str(ROOT), str(clone)], check=True)
    head = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], cwd=clone, capture_output=True, text=True
    ).stdout.strip()
    print(f"fresh clone of {head} in {clone}; cores: {os.cpu_count()}", flush=True)
    results = {}
    for target in ("demo", "test"):
        r = timed(["make", target], clone, work / f"make-{target}.log")
        results[target] = r
        tail = (work / f"make-{target}.log").read_text().strip().splitlines()[-3:]
        print(
            f"make {target}: exit {r['exit_code']}, wall {r['wall_s']:.0f} s, CPU "
            f"{r['cpu_s']:.0f} s, load average {r['load_before'][0]:.1f} before, "
            f"{r['load_after'][0]:.1f} after; last lines: {tail}",
            flush=True,
        )
    if a.json is not None:
        a.json.write_text(json.dumps(results, indent=2) + "\n")
    if not a.keep:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
