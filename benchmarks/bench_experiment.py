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

``--scaling N [N ...]`` measures instead how the analysis grows with the record count, on
synthetic built datasets of N records written directly in the dataset format (six classes of
recordings of 10 records, features on a 0.05 m/s grid so that kNN distance ties occur, and one
``records/<id>.npz`` of 60 x 17 Doppler histograms per record). Every stage runs in a fresh
process, ``--repeats`` times: ``load`` (the index of a feature dataset), ``knn`` (one kNN, k = 5,
fit on 60 % and predicting 40 % of the records, seven features), ``wrapper`` (the wrapper
selection of 4 of 7 features over 5 folds on that 60 %, only up to ``--wrapper-max`` records),
``experiment`` (``mdf experiment``'s analysis with selection ``none``: 10 stratified splits,
every output and figure) and ``histograms`` (the ``input = "histogram"`` classifier input:
every record file read). It prints the median wall time, the process's peak resident memory
[MiB] and the part of it the stage added (over the imports and, for knn and wrapper, the loaded
features), and the exponent of the wall time between successive sizes
(``log(t2 / t1) / log(n2 / n1)``):

    .venv/bin/python benchmarks/bench_experiment.py --scaling 1000 5000 20000 [--repeats 1]
        [--wrapper-max 5000] [--stages load knn wrapper experiment histograms]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import textwrap
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


SCALING_STAGES = ("load", "knn", "wrapper", "experiment", "histograms")
#: the synthetic datasets' classes and recordings
LABELS = ("walk", "run", "jog", "box", "crawl", "jump")
PER_RECORDING = 10

#: one stage in a fresh process: argv stage, dataset folder, histogram dataset folder
STAGE_CHILD = textwrap.dedent(
    """
    import json, resource, sys, tempfile, time
    from pathlib import Path
    import sklearn.model_selection  # imported before the stage, as the experiment has it
    from mdframework.classify import fit_predict, wrapper_select
    from mdframework.dataset import load_dataset
    from mdframework.experiment import (
        ExperimentConfig, classifier_factory, classifier_inputs, run_experiment)

    stage, data, hdata = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
    knn = classifier_factory({"kind": "knn", "k": 5}, "bench")
    cfg = ExperimentConfig.model_validate(
        {"dataset": {"path": str(data)}, "selection": {"method": "none"},
         "report": {"scatter_pairs": [["torso_mean", "upper_max"]]}})
    if stage in ("knn", "wrapper"):
        ds = load_dataset(data, spectrograms=False)
        cut = int(0.6 * len(ds.labels))
        x, y = ds.features, ds.labels
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    t0 = time.perf_counter()
    if stage == "load":
        load_dataset(data, spectrograms=False)
    elif stage == "knn":
        fit_predict(knn(), x[:cut], y[:cut], x[cut:])
    elif stage == "wrapper":
        wrapper_select(x[:cut], y[:cut], knn, sizes=[4], folds=5)
    elif stage == "experiment":
        with tempfile.TemporaryDirectory() as tmp:
            run_experiment(cfg, Path(tmp) / "out", progress=False)
    else:
        hcfg = cfg.model_copy(update={"input": "histogram"})
        classifier_inputs(hcfg, hdata)
    wall = time.perf_counter() - t0
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(json.dumps({"wall_s": wall, "peak_rss_mib": rss, "stage_rss_mib": rss - before}))
    """
)


def write_dataset(out: Path, n: int, histograms: bool) -> None:
    """A built dataset of ``n`` synthetic records in the on-disk format (index.csv, dataset.json
    with the index digest; with ``histograms`` one record file per record), written directly."""
    import csv
    import hashlib
    import io

    import numpy as np

    from mdframework.dataset import INDEX, INDEX_DIGEST, MANIFEST, RECORDS
    from mdframework.features import FEATURE_NAMES

    rng = np.random.default_rng(0)
    centres = rng.normal(0.0, 1.0, (len(LABELS), len(FEATURE_NAMES)))
    recording = np.arange(n) // PER_RECORDING
    classes = recording % len(LABELS)  # a recording is of one class
    feats = centres[classes] + rng.normal(0.0, 0.8, (n, len(FEATURE_NAMES)))
    feats = np.round(feats / 0.05) * 0.05  # a velocity grid: distance ties
    header = ["id", "label", "group", "source", "file", "subject", "recording", "dataset"]
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow([*header, "start_s", "duration_s", *FEATURE_NAMES])
    out.mkdir(parents=True)
    if histograms:
        (out / RECORDS).mkdir()
    for i in range(n):
        rid, label = f"{i:06d}-synthetic", LABELS[classes[i]]
        name = f"{label}_{recording[i]:05d}"
        text = [rid, label, "synth", "synth", name, f"s{recording[i] % 40:02d}", name, "synth"]
        writer.writerow([*text, 2.0 * (i % PER_RECORDING), 2.0, *map(float, feats[i])])
        if histograms:
            h = rng.random((60, 17)).astype(np.float32)
            np.savez(
                out / RECORDS / f"{rid}.npz",
                spectrogram_db=(10.0 * np.log10(h.T)).astype(np.float32),
                velocity_mps=np.linspace(-2.0, 2.0, 17),
                time_s=np.arange(60) / 30.0,
                features=feats[i],
                histograms=h,
                meta=np.array(json.dumps({"id": rid, "label": label})),
            )
    index = buf.getvalue()
    (out / INDEX).write_text(index, encoding="utf-8")
    digest = hashlib.sha256(index.encode("utf-8")).hexdigest()
    (out / MANIFEST).write_text(json.dumps({"n_records": n, INDEX_DIGEST: digest}) + "\n")


def run_stage(stage: str, data: Path, hdata: Path) -> dict[str, float]:
    """Wall time of one stage and the peak RSS of its fresh process."""
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    out = subprocess.run(
        [sys.executable, "-c", STAGE_CHILD, stage, str(data), str(hdata)],
        check=False,
        capture_output=True,
        text=True,
        env=env,
    )
    if out.returncode != 0:
        sys.exit(f"{stage} on {data} failed:\n{out.stderr[-2000:]}")
    return dict(json.loads(out.stdout.strip().splitlines()[-1]))


def scaling(sizes: list[int], stages: list[str], repeats: int, wrapper_max: int) -> list[dict]:
    """Median wall time and peak RSS of every stage at every size, with the exponents."""
    rows: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in sizes:
            data, hdata = Path(tmp) / f"features_{n}", Path(tmp) / f"histograms_{n}"
            write_dataset(data, n, histograms=False)
            if "histograms" in stages:
                write_dataset(hdata, n, histograms=True)
            for stage in stages:
                if stage == "wrapper" and n > wrapper_max:
                    continue
                runs = [run_stage(stage, data, hdata) for _ in range(repeats)]
                earlier = [r for r in rows if r["stage"] == stage]
                row = {
                    "n": n,
                    "stage": stage,
                    "wall_s": statistics.median(r["wall_s"] for r in runs),
                    "peak_rss_mib": statistics.median(r["peak_rss_mib"] for r in runs),
                    "stage_rss_mib": statistics.median(r["stage_rss_mib"] for r in runs),
                }
                if earlier:  # the growth exponent since the previous size
                    t1, n1 = earlier[-1]["wall_s"], earlier[-1]["n"]
                    row["exponent"] = math.log(row["wall_s"] / t1) / math.log(n / n1)
                rows.append(row)
                power = f"{row['exponent']:.2f}" if "exponent" in row else "-"
                print(
                    f"| {n} | {stage} | {row['wall_s']:.3f} | {row['peak_rss_mib']:.0f} | "
                    f"{row['stage_rss_mib']:.0f} | {power} |",
                    flush=True,
                )
    return rows


def main() -> None:
    """Run the benchmark and print the figures."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--config", type=Path, default=DEFAULT_CONFIG)
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--json", type=Path, default=None, help="Also write the results here.")
    ap.add_argument("--scaling", type=int, nargs="+", default=None, metavar="N")
    ap.add_argument("--stages", nargs="+", choices=SCALING_STAGES, default=list(SCALING_STAGES))
    ap.add_argument("--wrapper-max", type=int, default=5000)
    a = ap.parse_args()
    print(f"load average before: {os.getloadavg()}, cores: {os.cpu_count()}")
    if a.scaling:
        print(
            "| n | stage | wall s (median) | peak RSS MiB | of which the stage | exponent |\n"
            "|---|---|---|---|---|---|"
        )
        rows = scaling(a.scaling, a.stages, a.repeats, a.wrapper_max)
        print(f"load average after: {os.getloadavg()}")
        if a.json is not None:
            a.json.write_text(json.dumps(rows, indent=2) + "\n")
        return
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
