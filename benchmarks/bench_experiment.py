"""Benchmark: the paper's experiment at the paper's size, end to end.

Runs ``mdf experiment examples/experiment_paper.toml --out DIR`` as a user would, in a fresh
process: 480 records of 6 s simulated (the dataset is built from scratch with the default worker
count, one per core), the seven features, kNN (k = 5) with wrapper selection of 4 of 7 features
over 5 folds, the optimistic variant, 10 repeated splits, confusion matrices, feature statistics,
figures and the report. Reported: the wall time of the whole command (median over ``--repeats``
runs) and its CPU time (all processes), then the same experiment on the built dataset alone
(analysis only: selection, evaluation, outputs), with the share of the figures.

    .venv/bin/python benchmarks/bench_experiment.py [--repeats 1] [--config PATH] [--json OUT]

The goal is at most 30 s of wall time on the 2-core development machine. The machine is shared:
the load average is printed before and after.
"""

from __future__ import annotations

import argparse
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
DEFAULT_CONFIG = ROOT / "examples" / "experiment_paper.toml"
OUTPUTS = ("report.md", "summary.json", "feature_stats.csv", "scatter_torso_mean_upper_max.png")


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def end_to_end(config: Path, out: Path) -> tuple[float, float]:
    """Wall and CPU seconds of ``mdf experiment CONFIG --out OUT`` (all its processes)."""
    mdf = Path(sys.executable).with_name("mdf")
    cpu0 = _children_cpu()
    t0 = time.perf_counter()
    subprocess.run(
        [str(mdf), "experiment", str(config), "--out", str(out), "--no-progress"],
        check=True,
        stdout=subprocess.DEVNULL,
    )
    wall = time.perf_counter() - t0
    for name in OUTPUTS:
        if not (out / name).stat().st_size:
            raise SystemExit(f"{out / name} is empty")
    return wall, _children_cpu() - cpu0


def analysis_only(config: Path, dataset: Path, out: Path) -> dict[str, float]:
    """The same experiment on an already built dataset, timed in this process."""
    from mdframework import figures
    from mdframework.experiment import DatasetRef, load_experiment_config, run_experiment

    cfg = load_experiment_config(config)
    cfg = cfg.model_copy(update={"dataset": DatasetRef(path=dataset)})
    spent = {"figures": 0.0}

    def timed(fn: Any) -> Any:
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            t = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                spent["figures"] += time.perf_counter() - t

        return wrapper

    for name in ("plot_confusion", "plot_feature_scatter"):
        setattr(figures, name, timed(getattr(figures, name)))
    cpu0 = time.process_time()
    t0 = time.perf_counter()
    run_experiment(cfg, out, progress=False)
    return {
        "wall_s": time.perf_counter() - t0,
        "cpu_s": time.process_time() - cpu0,
        "figures_s": spent["figures"],
    }


def main() -> None:
    """Run the benchmark and print the figures."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--config", type=Path, default=DEFAULT_CONFIG)
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--json", type=Path, default=None, help="Also write the results here.")
    a = ap.parse_args()
    print(f"load average before: {os.getloadavg()}, cores: {os.cpu_count()}")
    walls, cpus = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(a.repeats):
            out = Path(tmp) / f"run{i}"
            wall, cpu = end_to_end(a.config, out)
            walls.append(wall)
            cpus.append(cpu)
            print(f"end to end, run {i + 1}: wall {wall:.1f} s, CPU {cpu:.1f} s", flush=True)
        summary = json.loads((Path(tmp) / "run0" / "summary.json").read_text())
        analysis = analysis_only(a.config, Path(tmp) / "run0" / "dataset", Path(tmp) / "analysis")
    result = {
        "n_records": summary["n_records"],
        "end_to_end_wall_s_median": statistics.median(walls),
        "end_to_end_cpu_s_median": statistics.median(cpus),
        "analysis": analysis,
        "balanced_accuracy": {
            g: r.get("balanced_accuracy_mean") for g, r in summary["within"].items()
        },
        "load_after": os.getloadavg(),
    }
    print(
        f"{result['n_records']} records: end to end median wall "
        f"{result['end_to_end_wall_s_median']:.1f} s (CPU "
        f"{result['end_to_end_cpu_s_median']:.1f} s over all processes); analysis alone "
        f"{analysis['wall_s']:.1f} s wall, {analysis['cpu_s']:.1f} s CPU, of which figures "
        f"{analysis['figures_s']:.1f} s; balanced accuracy {result['balanced_accuracy']}"
    )
    print(f"load average after: {os.getloadavg()}")
    if a.json is not None:
        a.json.write_text(json.dumps(result, indent=2) + "\n")


if __name__ == "__main__":
    main()
