"""Benchmark: dataset build scaling from 1 to 2 workers, local process pool and Dask.

Builds the paper-sized dataset (``examples/datasets/paper_480.toml``: 480 records of 6 s) from
scratch with 1 and with 2 workers, on the local process pool and on a local Dask cluster. Every
build runs in a fresh Python process, as ``mdf dataset build`` would, so each pays its own
imports, planning (reading the recordings and generating the Boulic walkers) and worker start.

Measured per build: the wall time of the whole child process, the CPU time of the whole process
tree, and the CPU time of its serial part (interpreter start, imports and planning, in the main
process before any worker exists). Dask's fixed cost (starting and stopping the cluster with no
records) is measured in a separate child.

On a quiet machine the wall times give the efficiency ``wall(1) / (2 wall(2))`` directly. On a
shared machine (several engineers' jobs on 2 cores) wall times say little, so the script also
reports the efficiency predicted from CPU times: ``T(n) = serial + (total - serial) / n`` (the
parallel part spread evenly over n cores), which captures every cost that more workers add
(motions loaded once per worker, worker start, scheduling) but not the waiting for a busy core.
The per-record cost is ``(total - serial) / n_records`` CPU seconds, and Dask's is compared with
the local pool's at the same worker count.

    .venv/bin/python benchmarks/bench_dataset.py [--config PATH] [--workers 1 2]
        [--schedulers local dask] [--json OUT.json]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_CONFIG = ROOT / "examples" / "datasets" / "paper_480.toml"


def _child(config: str, scheduler: str, workers: int, out: str, start_only: bool) -> None:
    """Run in a fresh process: time planning and the build (or the executor's start alone)."""
    t0 = time.perf_counter()
    from mdframework.dataset import _executor, build_dataset, load_dataset_config, plan_records

    t_import = time.perf_counter() - t0
    cfg, base = load_dataset_config(config)
    address = None if scheduler == "local" else "local"
    t1 = time.perf_counter()
    if start_only:
        serial_cpu = time.process_time()
        for _ in _executor(cfg, workers, address):
            pass
        print(
            json.dumps(
                {
                    "start_s": time.perf_counter() - t1,
                    "import_s": t_import,
                    "serial_cpu_s": serial_cpu,
                }
            )
        )
        return
    specs = plan_records(cfg, base, workers=workers)
    t_plan = time.perf_counter() - t1
    serial_cpu = time.process_time()  # since the interpreter started: imports and planning
    t2 = time.perf_counter()
    rows = build_dataset(cfg, base, Path(out), workers=workers, scheduler=address, progress=False)
    t_build = time.perf_counter() - t2
    assert len(rows) == len(specs)
    print(
        json.dumps(
            {
                "import_s": t_import,
                "plan_s": t_plan,
                "build_s": t_build,
                "serial_cpu_s": serial_cpu,
                "n_records": len(rows),
            }
        )
    )


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _run_child(args: list[str]) -> tuple[dict[str, Any], float, float]:
    """The child's JSON line, its wall time and the CPU time of its whole process tree."""
    cpu0 = _children_cpu()
    t0 = time.perf_counter()
    proc = subprocess.run(
        [sys.executable, __file__, "--child", *args],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONWARNINGS": "ignore"},
    )
    if proc.returncode:
        raise SystemExit(f"child {args} failed:\n{proc.stderr}")
    wall = time.perf_counter() - t0
    return json.loads(proc.stdout.strip().splitlines()[-1]), wall, _children_cpu() - cpu0


def main() -> None:
    """Parse arguments, run the builds, print the table."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--config", default=str(DEFAULT_CONFIG))
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--schedulers", nargs="+", default=["local", "dask"])
    ap.add_argument("--json", type=Path, default=None, help="Also write the results here.")
    ap.add_argument("--child", nargs=4, metavar=("CONFIG", "SCHED", "N", "OUT"), default=None)
    ap.add_argument("--start-only", action="store_true")
    a = ap.parse_args()
    if a.child is not None:
        config, sched, n, out = a.child
        _child(config, sched, int(n), out, a.start_only)
        return

    print(f"load average before: {os.getloadavg()}, cores: {os.cpu_count()}", flush=True)
    results: dict[str, dict[int, dict[str, float]]] = {}
    for sched in a.schedulers:
        results[sched] = {}
        for n in a.workers:
            with tempfile.TemporaryDirectory() as tmp:
                info, wall, cpu = _run_child([a.config, sched, str(n), str(Path(tmp) / "ds")])
            start_wall = start_cpu = 0.0
            if sched == "dask":
                s_info, _, s_cpu = _run_child([a.config, sched, str(n), "-", "--start-only"])
                start_wall, start_cpu = s_info["start_s"], s_cpu - s_info["serial_cpu_s"]
            serial, parallel = info["serial_cpu_s"], cpu - info["serial_cpu_s"]
            r = {
                "wall_s": wall,
                "cpu_s": cpu,
                "serial_cpu_s": serial,
                "parallel_cpu_s": parallel,
                "predicted_wall_s": serial + parallel / n,
                "plan_wall_s": info["plan_s"],
                "import_wall_s": info["import_s"],
                "dask_start_wall_s": start_wall,
                "dask_start_cpu_s": start_cpu,
                "per_record_cpu_ms": 1e3 * parallel / info["n_records"],
                "per_record_cpu_ms_after_start": 1e3 * (parallel - start_cpu) / info["n_records"],
                "n_records": info["n_records"],
            }
            results[sched][n] = r
            print(
                f"{sched:5s} workers={n}: wall {wall:6.1f} s, CPU {cpu:6.1f} s, of which serial "
                f"{serial:4.1f} s (imports and planning); per record {r['per_record_cpu_ms']:.0f} "
                f"ms CPU ({r['per_record_cpu_ms_after_start']:.0f} ms after the workers' start); "
                f"predicted wall on {n} idle core(s) {r['predicted_wall_s']:.1f} s",
                flush=True,
            )
    print(f"load average after: {os.getloadavg()}")
    summary: dict[str, Any] = {"results": results, "load_after": os.getloadavg()}
    for sched, res in results.items():
        if 1 in res and 2 in res:
            eff = res[1]["wall_s"] / (2 * res[2]["wall_s"])
            eff_pred = res[1]["predicted_wall_s"] / (2 * res[2]["predicted_wall_s"])
            serial_fraction = res[1]["serial_cpu_s"] / res[1]["predicted_wall_s"]
            summary[sched] = {
                "efficiency_wall": eff,
                "efficiency_predicted": eff_pred,
                "serial_fraction": serial_fraction,
            }
            print(
                f"{sched}: efficiency 1 -> 2 workers: {100 * eff_pred:.0f} % predicted from CPU "
                f"times, {100 * eff:.0f} % in wall time on this machine now; serial part "
                f"{res[1]['serial_cpu_s']:.1f} s CPU = {100 * serial_fraction:.1f} % of one "
                f"worker's build"
            )
    if "local" in results and "dask" in results:
        for n in sorted(set(results["local"]) & set(results["dask"])):
            loc, dsk = results["local"][n], results["dask"][n]
            ratio = dsk["per_record_cpu_ms"] / loc["per_record_cpu_ms"]
            ratio_run = dsk["per_record_cpu_ms_after_start"] / loc["per_record_cpu_ms"]
            summary[f"dask_over_local_{n}"] = {"with_start": ratio, "after_start": ratio_run}
            print(
                f"Dask / local per-record CPU, {n} worker(s): {ratio:.2f} with the cluster's "
                f"start, {ratio_run:.2f} after it"
            )
    if a.json is not None:
        a.json.write_text(json.dumps(summary, indent=2) + "\n")


if __name__ == "__main__":
    main()
