"""Benchmark: set-up time of a fresh clone: the first ``make demo``, then ``make test``.

Clones the repository's committed HEAD into a new folder under /tmp, then times the first
``make demo`` in two parts, ``make venv`` (creating .venv and installing the core and every
plugin) and ``make demo`` (every example, then the CMU experiment), and then ``make test``
(ruff, mypy, the whole pytest suite in parallel, the docs site). Prints the wall time of each,
the CPU time of each (all processes), the last lines of its output, and the load average before
and after, since the machine may be shared.

``--pairs N`` compares the installers instead: N pairs of fresh clones, one installing with pip
(``make venv INSTALLER=pip``) and one with uv (the default), alternating so that the machine's
load drifts over both alike, each then running ``make demo``; it prints every run, the medians
and the median of the per-pair ratios (uv over pip) of the first ``make demo``'s wall time.
Both installers' caches are as this machine has them (warm after the first run).

    .venv/bin/python benchmarks/bench_setup.py [--keep] [--json OUT.json]
    .venv/bin/python benchmarks/bench_setup.py --pairs 2 [--no-test]

Goals: the first ``make demo`` within 3 minutes, ``make test`` within 4 minutes.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
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


def fresh_clone(work: Path, name: str) -> Path:
    """A clone of the committed HEAD under ``work``."""
    clone = work / name
    subprocess.run(["git", "clone", "--quiet", str(ROOT), str(clone)], check=True)
    return clone


def report(name: str, r: dict[str, Any], log: Path) -> None:
    """One line per timed command."""
    tail = log.read_text().strip().splitlines()[-2:]
    print(
        f"{name}: exit {r['exit_code']}, wall {r['wall_s']:.0f} s, CPU {r['cpu_s']:.0f} s, "
        f"load average {r['load_before'][0]:.1f} before, {r['load_after'][0]:.1f} after; "
        f"last lines: {tail}",
        flush=True,
    )


def first_demo(clone: Path, work: Path, tag: str, installer: str) -> dict[str, Any]:
    """``make venv`` then ``make demo`` in ``clone``; both timings and their sum."""
    out: dict[str, Any] = {}
    for target in ("venv", "demo"):
        log = work / f"{tag}-make-{target}.log"
        r = timed(["make", target, f"INSTALLER={installer}"], clone, log)
        report(f"{tag} make {target} (INSTALLER={installer})", r, log)
        out[target] = r
    out["first_demo_wall_s"] = out["venv"]["wall_s"] + out["demo"]["wall_s"]
    out["first_demo_cpu_s"] = out["venv"]["cpu_s"] + out["demo"]["cpu_s"]
    print(
        f"{tag}: first make demo {out['first_demo_wall_s']:.0f} s wall "
        f"({out['first_demo_cpu_s']:.0f} s CPU)",
        flush=True,
    )
    return out


def main() -> None:
    """Clone, time ``make venv``, ``make demo`` and ``make test``, print the figures."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--keep", action="store_true", help="Keep the clones (their path is printed).")
    ap.add_argument("--json", type=Path, default=None, help="Also write the results here.")
    ap.add_argument("--pairs", type=int, default=0, help="Compare pip and uv over N pairs.")
    ap.add_argument("--no-test", action="store_true", help="Skip make test.")
    a = ap.parse_args()
    work = Path(tempfile.mkdtemp(prefix="mdf-setup-", dir="/tmp"))
    print(f"work folder {work}; cores: {os.cpu_count()}", flush=True)
    results: dict[str, Any] = {}
    clone = None
    if a.pairs > 0:
        runs: dict[str, list[float]] = {"pip": [], "uv": []}
        for i in range(a.pairs):
            for installer in ("pip", "uv"):
                tag = f"pair{i}-{installer}"
                clone = fresh_clone(work, tag)
                results[tag] = first_demo(clone, work, tag, installer)
                runs[installer].append(results[tag]["first_demo_wall_s"])
                if not a.keep and i < a.pairs - 1:
                    shutil.rmtree(clone, ignore_errors=True)
        ratios = [u / p for p, u in zip(runs["pip"], runs["uv"], strict=True)]
        print(
            f"first make demo, median wall: pip {statistics.median(runs['pip']):.0f} s, "
            f"uv {statistics.median(runs['uv']):.0f} s; median ratio uv / pip "
            f"{statistics.median(ratios):.2f} over {a.pairs} pairs",
            flush=True,
        )
    else:
        clone = fresh_clone(work, "mdframework")
        results["demo"] = first_demo(clone, work, "clone", "uv")
    if not a.no_test and clone is not None:
        log = work / "make-test.log"
        r = timed(["make", "test"], clone, log)
        report("make test", r, log)
        results["test"] = r
    if a.json is not None:
        a.json.write_text(json.dumps(results, indent=2) + "\n")
    if not a.keep:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
