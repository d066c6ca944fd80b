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

Where the CPU goes, per build: the planning workers (with more than one worker the planner
loads the motions in other processes: planning, though it runs in parallel), the main process
during the build (for Dask: the client, the scheduler and the nannies of the local cluster,
importing Dask, sending the motions), and the worker processes (for Dask: starting a fresh
interpreter each, their event loops, the records). "Records only" is the per-record cost
without the planning workers.

``--contention N`` measures what running side by side costs on this machine: N records of the
dataset (spread over its sources) built in a 2-worker pool, one worker busy at a time and then
both at once, alternating three times, with their files written to the disk and to a file
system in memory (``/dev/shm``); and, for comparison, a plain numpy job (the same work
repeated) on a cache-sized array (256 KiB) and on a large one (16 MiB), alone and two at once.
Their CPU and wall time per record (per job) side by side over alone is the part of the
2-worker cost that the machine adds (shared caches, memory bandwidth, the kernel's work of
writing the files to the disk, the other jobs on it), not the build.

``--repeat N`` runs every build N times, alternating (1 and 2 workers, local and Dask, then
again), and reports medians: the load of a shared machine drifts, so figures taken minutes
apart are not comparable, and alternation pairs them. ``--idle S`` also measures what an idle
local Dask cluster costs per second of wall time (its periodic monitors), with the build's
settings (``LOCAL_DASK_CONFIG``) and with Dask's defaults (the profiler off in both).

    .venv/bin/python benchmarks/bench_dataset.py [--config PATH] [--workers 1 2]
        [--schedulers local dask] [--repeat N] [--idle SECONDS] [--contention N]
        [--json OUT.json]
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import resource
import statistics
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
    plan_workers_cpu = _cpu(resource.RUSAGE_CHILDREN)  # the planning workers, ended by now
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
                "plan_workers_cpu_s": plan_workers_cpu,
                # the build planned again (cheap: the motions are loaded) and ran the records
                "main_build_cpu_s": time.process_time() - serial_cpu,
                "workers_cpu_s": _cpu(resource.RUSAGE_CHILDREN) - plan_workers_cpu,
                "n_records": len(rows),
            }
        )
    )


def _idle_child(settings: str, workers: int, seconds: float) -> None:
    """Run in a fresh process: the CPU an idle local Dask cluster costs per second of wall
    time, in this process (scheduler, nannies, client) and in its workers."""
    import dask
    from distributed import Client, LocalCluster

    from mdframework.cluster import LOCAL_DASK_CONFIG

    config = dict(LOCAL_DASK_CONFIG)
    if settings == "dask":  # Dask's defaults, but for the profiler and the malloc setting
        config = {k: v for k, v in config.items() if "profile" in k or "MALLOC" in k}
    with dask.config.set(config):
        cluster = LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
        )
    client = Client(cluster)
    time.sleep(2.0)  # past the start
    worker0 = client.run(_self_cpu)
    main0, t0 = time.process_time(), time.perf_counter()
    time.sleep(seconds)
    worker1 = client.run(_self_cpu)
    main1, wall = time.process_time(), time.perf_counter() - t0
    client.close()
    cluster.close()
    workers_cpu = sum(worker1[w] - worker0[w] for w in worker1)
    print(
        json.dumps(
            {
                "main_ms_per_s": 1e3 * (main1 - main0) / wall,
                "workers_ms_per_s": 1e3 * workers_cpu / wall,
            }
        )
    )


def _timed_records(specs: list[Any], out: str) -> list[tuple[float, float]]:
    """Wall time and CPU time of this whole worker process (the thread that computes and the
    one that writes each file to the disk) of each record built here [s]; each record's file is
    in place before the next starts."""
    from mdframework.dataset import build_record

    times = []
    for spec in specs:
        t0, c0 = time.perf_counter(), _self_cpu()
        build_record(spec, out)
        times.append((time.perf_counter() - t0, _self_cpu() - c0))
    return times


def _numpy_job(n_values: int, reps: int) -> list[float]:
    """Thread CPU time [s] of each of ``reps`` rounds of the same numpy work on an array of
    ``n_values`` float64 (sine, product, cumulative sum, over the whole array)."""
    import numpy as np

    a = np.linspace(0.0, 1.0, n_values)
    work = max(1, (1 << 22) // n_values)  # the same number of values touched per round
    times = []
    for _ in range(reps):
        t0 = _thread_cpu()
        for _ in range(work):
            b = np.sin(a) * a
            a = np.cumsum(b) * 1e-9 + a
        times.append(_thread_cpu() - t0)
    return times


def _contention_child(config: str, n_records: int) -> None:
    """Run in a fresh process: wall and CPU time per record (and CPU per numpy round) with one
    worker of a 2-worker pool busy, and with both busy, alternating three times. The records
    are written to the disk (a temporary folder) and, for comparison, to a file system in
    memory (``/dev/shm``, where there is one): the difference is what writing to the disk adds
    when both workers are busy."""
    import numpy as np

    from mdframework.dataset import load_dataset_config, plan_records
    from mdframework.workers import worker_pool

    cfg, base = load_dataset_config(config)
    specs = plan_records(cfg, base, workers=1)
    chosen = specs[:: max(1, len(specs) // n_records)][:n_records]
    halves = [chosen[0::2], chosen[1::2]]
    out: dict[str, Any] = {}
    with contextlib.ExitStack() as stack:
        disk = stack.enter_context(tempfile.TemporaryDirectory())
        folders = {"records, disk": disk}
        if Path("/dev/shm").is_dir():
            folders["records, memory"] = stack.enter_context(
                tempfile.TemporaryDirectory(dir="/dev/shm")
            )
        pool = stack.enter_context(worker_pool(2))
        jobs: dict[str, tuple[Any, list[Any]]] = {}
        for name, folder in folders.items():
            (Path(folder) / "records").mkdir()
            jobs[name] = (_timed_records, [[h, folder] for h in halves])
        jobs["numpy 256 KiB"] = (_numpy_job, [[1 << 15, 20]] * 2)
        jobs["numpy 16 MiB"] = (_numpy_job, [[1 << 21, 20]] * 2)
        for name, (fn, args) in jobs.items():
            warm = [pool.submit(fn, *args[0]), pool.submit(fn, *args[1])]
            [w.result() for w in warm]
            alone: list[Any] = []
            both: list[Any] = []
            for _ in range(3):
                for a in args:
                    alone += pool.submit(fn, *a).result()
                futures = [pool.submit(fn, *a) for a in args]
                both += [t for f in futures for t in f.result()]
            if name.startswith("records"):
                out[name] = {
                    "alone_ms": 1e3 * float(np.mean([c for _, c in alone])),
                    "both_ms": 1e3 * float(np.mean([c for _, c in both])),
                    "alone_wall_ms": 1e3 * float(np.mean([w for w, _ in alone])),
                    "both_wall_ms": 1e3 * float(np.mean([w for w, _ in both])),
                }
            else:
                out[name] = {
                    "alone_ms": 1e3 * float(np.mean(alone)),
                    "both_ms": 1e3 * float(np.mean(both)),
                }
    print(json.dumps(out))


def _thread_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_THREAD)
    return usage.ru_utime + usage.ru_stime


def _self_cpu() -> float:
    return _cpu(resource.RUSAGE_SELF)


def _cpu(who: int) -> float:
    usage = resource.getrusage(who)
    return usage.ru_utime + usage.ru_stime


def _run_child(args: list[str]) -> tuple[dict[str, Any], float, float]:
    """The child's JSON line, its wall time and the CPU time of its whole process tree."""
    cpu0 = _cpu(resource.RUSAGE_CHILDREN)
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
    return (
        json.loads(proc.stdout.strip().splitlines()[-1]),
        wall,
        _cpu(resource.RUSAGE_CHILDREN) - cpu0,
    )


def _build(config: str, sched: str, n: int) -> dict[str, float]:
    """One build (and, for Dask, one start of the cluster alone) in fresh processes."""
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        info, wall, cpu = _run_child([config, sched, str(n), str(Path(tmp) / "ds")])
    start_wall = start_cpu = 0.0
    if sched == "dask":
        s_info, _, s_cpu = _run_child([config, sched, str(n), "-", "--start-only"])
        start_wall, start_cpu = s_info["start_s"], s_cpu - s_info["serial_cpu_s"]
    serial, parallel = info["serial_cpu_s"], cpu - info["serial_cpu_s"]
    records = info["n_records"]
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
        "per_record_cpu_ms": 1e3 * parallel / records,
        "per_record_cpu_ms_after_start": 1e3 * (parallel - start_cpu) / records,
        "plan_workers_cpu_s": info["plan_workers_cpu_s"],
        "main_build_cpu_s": info["main_build_cpu_s"],
        "workers_cpu_s": info["workers_cpu_s"],
        # after the build: the process's exit, and processes reaped only then
        "other_cpu_s": parallel
        - info["plan_workers_cpu_s"]
        - info["main_build_cpu_s"]
        - info["workers_cpu_s"],
        "records_only_cpu_ms": 1e3 * (parallel - info["plan_workers_cpu_s"]) / records,
        "n_records": records,
        "load_before": load,
    }
    print(
        f"{sched:5s} workers={n}: wall {wall:6.1f} s, CPU {cpu:6.1f} s, of which serial "
        f"{serial:4.1f} s (imports and planning); per record {r['per_record_cpu_ms']:.0f} "
        f"ms CPU ({r['per_record_cpu_ms_after_start']:.0f} ms after the workers' start); "
        f"predicted wall on {n} idle core(s) {r['predicted_wall_s']:.1f} s",
        flush=True,
    )
    print(
        f"      planning workers {r['plan_workers_cpu_s']:.2f} s; during the build: main "
        f"process {r['main_build_cpu_s']:.2f} s, workers {r['workers_cpu_s']:.2f} s, other "
        f"{r['other_cpu_s']:.2f} s; records only {r['records_only_cpu_ms']:.1f} ms a record; "
        f"load average before {load:.2f}",
        flush=True,
    )
    return r


def _idle(seconds: float, workers: list[int]) -> dict[str, dict[int, dict[str, float]]]:
    """What an idle local Dask cluster costs per second, with Dask's monitors and with the
    build's."""
    out: dict[str, dict[int, dict[str, float]]] = {}
    for settings in ("dask", "build"):
        out[settings] = {}
        for n in workers:
            proc = subprocess.run(
                [sys.executable, __file__, "--idle-child", settings, str(n), str(seconds)],
                capture_output=True,
                text=True,
                env={**os.environ, "PYTHONWARNINGS": "ignore"},
            )
            if proc.returncode:
                raise SystemExit(f"idle child failed:\n{proc.stderr}")
            res = json.loads(proc.stdout.strip().splitlines()[-1])
            out[settings][n] = res
            print(
                f"idle local Dask cluster, {settings + ' settings':14s} workers={n}: "
                f"{res['main_ms_per_s']:.1f} ms CPU a second in the main process, "
                f"{res['workers_ms_per_s']:.1f} ms in the workers",
                flush=True,
            )
    return out


def _contention(config: str, n_records: int) -> dict[str, dict[str, float]]:
    """CPU per record (and per numpy round) alone and side by side, in a fresh process."""
    proc = subprocess.run(
        [sys.executable, __file__, "--config", config, "--contention-child", str(n_records)],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONWARNINGS": "ignore"},
    )
    if proc.returncode:
        raise SystemExit(f"contention child failed:\n{proc.stderr}")
    res: dict[str, dict[str, float]] = json.loads(proc.stdout.strip().splitlines()[-1])
    for name, r in res.items():
        r["ratio"] = r["both_ms"] / r["alone_ms"]
        wall = ""
        if "alone_wall_ms" in r:
            r["wall_ratio"] = r["both_wall_ms"] / r["alone_wall_ms"]
            wall = (
                f"; wall {r['alone_wall_ms']:.1f} ms alone, {r['both_wall_ms']:.1f} ms side by "
                f"side: {r['wall_ratio']:.3f}"
            )
        print(
            f"side by side, {name:15s}: {r['alone_ms']:.1f} ms CPU alone, {r['both_ms']:.1f} ms "
            f"with both workers busy: {r['ratio']:.3f}{wall}; load average "
            f"{os.getloadavg()[0]:.2f}",
            flush=True,
        )
    return res


def _spread(values: list[float], scale: float = 1.0, fmt: str = ".2f") -> str:
    """The median of ``values`` (times ``scale``), with their range when there are several."""
    med = format(scale * statistics.median(values), fmt)
    if len(values) == 1:
        return med
    return f"{med} (range {scale * min(values):{fmt}} to {scale * max(values):{fmt}})"


def main() -> None:
    """Parse arguments, run the builds, print the table."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--config", default=str(DEFAULT_CONFIG))
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--schedulers", nargs="*", default=["local", "dask"])
    ap.add_argument("--repeat", type=int, default=1, help="Rounds of alternating builds.")
    ap.add_argument("--idle", type=float, default=0.0, help="Seconds of idle Dask cluster.")
    ap.add_argument("--contention", type=int, default=0, help="Records side by side.")
    ap.add_argument("--json", type=Path, default=None, help="Also write the results here.")
    ap.add_argument("--child", nargs=4, metavar=("CONFIG", "SCHED", "N", "OUT"), default=None)
    ap.add_argument("--start-only", action="store_true")
    ap.add_argument("--idle-child", nargs=3, metavar=("SETTINGS", "N", "SECONDS"), default=None)
    ap.add_argument("--contention-child", type=int, default=None)
    a = ap.parse_args()
    if a.contention_child is not None:
        _contention_child(a.config, a.contention_child)
        return
    if a.child is not None:
        config, sched, n, out = a.child
        _child(config, sched, int(n), out, a.start_only)
        return
    if a.idle_child is not None:
        settings, n, seconds = a.idle_child
        _idle_child(settings, int(n), float(seconds))
        return

    print(f"load average before: {os.getloadavg()}, cores: {os.cpu_count()}", flush=True)
    rounds: list[dict[str, dict[int, dict[str, float]]]] = []
    for k in range(a.repeat):
        if a.repeat > 1:
            print(f"round {k + 1} of {a.repeat}", flush=True)
        rounds.append(
            {sched: {n: _build(a.config, sched, n) for n in a.workers} for sched in a.schedulers}
        )
    print(f"load average after: {os.getloadavg()}")
    results = (
        rounds[0]
        if a.repeat == 1
        else {
            sched: {
                n: {
                    key: statistics.median(r[sched][n][key] for r in rounds)
                    for key in rounds[0][sched][n]
                }
                for n in a.workers
            }
            for sched in a.schedulers
        }
    )
    if a.repeat > 1:
        print(f"medians of {a.repeat} rounds (ranges over the rounds; ratios paired by round):")
        for sched, res in results.items():
            for n, r in res.items():
                print(
                    f"{sched:5s} workers={n}: serial {r['serial_cpu_s']:.2f} s, per record "
                    f"{r['per_record_cpu_ms']:.1f} ms ({r['per_record_cpu_ms_after_start']:.1f} "
                    f"after the workers' start; records only {r['records_only_cpu_ms']:.1f}), "
                    f"predicted wall {r['predicted_wall_s']:.2f} s"
                )
    summary: dict[str, Any] = {
        "results": results,
        "rounds": rounds,
        "load_after": os.getloadavg(),
    }
    for sched, res in results.items():
        if 1 in res and 2 in res:
            eff = [r[sched][1]["wall_s"] / (2 * r[sched][2]["wall_s"]) for r in rounds]
            eff_pred = [
                r[sched][1]["predicted_wall_s"] / (2 * r[sched][2]["predicted_wall_s"])
                for r in rounds
            ]
            serial_fraction = res[1]["serial_cpu_s"] / res[1]["predicted_wall_s"]
            summary[sched] = {
                "efficiency_wall": statistics.median(eff),
                "efficiency_predicted": statistics.median(eff_pred),
                "efficiency_predicted_rounds": eff_pred,
                "serial_fraction": serial_fraction,
            }
            print(
                f"{sched}: efficiency 1 -> 2 workers: {_spread(eff_pred, 100, '.0f')} % predicted "
                f"from CPU times, {_spread(eff, 100, '.0f')} % in wall time on this machine now; "
                f"serial part {res[1]['serial_cpu_s']:.1f} s CPU = {100 * serial_fraction:.1f} % "
                f"of one worker's build (with 2 workers: {res[2]['serial_cpu_s']:.1f} s, and "
                f"{res[2]['plan_workers_cpu_s']:.1f} s of planning in 2 processes)"
            )
    if "local" in results and "dask" in results:
        for n in sorted(set(results["local"]) & set(results["dask"])):
            ratios = {
                key: [r["dask"][n][key] / r["local"][n]["per_record_cpu_ms"] for r in rounds]
                for key in ("per_record_cpu_ms", "per_record_cpu_ms_after_start")
            }
            records_only = [
                r["dask"][n]["records_only_cpu_ms"] / r["local"][n]["records_only_cpu_ms"]
                for r in rounds
            ]
            summary[f"dask_over_local_{n}"] = {
                "with_start": statistics.median(ratios["per_record_cpu_ms"]),
                "after_start": statistics.median(ratios["per_record_cpu_ms_after_start"]),
                "records_only": statistics.median(records_only),
            }
            print(
                f"Dask / local per-record CPU, {n} worker(s): "
                f"{_spread(ratios['per_record_cpu_ms'])} with the cluster's start, "
                f"{_spread(ratios['per_record_cpu_ms_after_start'])} after it; records only "
                f"{_spread(records_only)}"
            )
    if a.idle > 0:
        summary["idle_cluster"] = _idle(a.idle, a.workers)
    if a.contention > 0:
        summary["side_by_side"] = _contention(a.config, a.contention)
    if a.json is not None:
        a.json.write_text(json.dumps(summary, indent=2) + "\n")


if __name__ == "__main__":
    main()
