"""What FMCW fidelity costs per frame: raw against analytic range profiles, with and without
point-cloud extraction.

Scene: ``examples/fmcw_walk.toml`` (CMU 02_01 walk toward the IWR1443 short-range 3-D preset: 48
chirps of 240 samples on 4 RX per 33.3 ms frame, 17 ellipsoid scatterers). Four settings:
``path`` analytic or raw x ``points`` on or off (range-Doppler maps are kept in all four).

Time: the median over ``--repeats`` runs of the whole pipeline after loading the motion, divided
by the number of frames, one core (BLAS threads pinned to 1), in CPU time of this process (the
development machine is shared: wall time there measures the other jobs too). Agreement of the
raw and analytic paths on this scene: the largest difference of their range-Doppler maps
relative to each frame's peak, and the mean number of points per frame of each.

    .venv/bin/python benchmarks/bench_fmcw.py [--repeats 3] [--duration 2.0]
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

from mdframework.config import read_config_file, validate_run_config  # noqa: E402
from mdframework.pipeline import RunResult, build_stages, load_motion, simulate_motion  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "fmcw_walk.toml"


def run(data: dict[str, Any], repeats: int) -> tuple[float, RunResult]:
    """Median CPU time of the pipeline after loading, and the last result."""
    config = validate_run_config(data, base_dir=SCENE.parent)
    stages = build_stages(config)
    motion = load_motion(stages.source)
    times = []
    result = None
    for _ in range(repeats):
        stages = build_stages(config)
        t0 = time.process_time()
        result = simulate_motion(config, stages, motion)
        times.append(time.process_time() - t0)
    assert result is not None
    return statistics.median(times), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--duration", type=float, default=2.0, help="record length [s]")
    args = parser.parse_args()
    base = read_config_file(SCENE)
    base["motion"]["duration"] = args.duration
    rows = []
    results: dict[str, RunResult] = {}
    for path in ("analytic", "raw"):
        for points in (False, True):
            data = {**base, "radar": {**base["radar"], "path": path, "points": points}}
            seconds, res = run(data, args.repeats)
            n_frames = res.received.products["range_doppler"].shape[0]
            n_points = res.received.products["points"].shape[0] if points else 0
            results[f"{path}-{points}"] = res
            rows.append((path, points, seconds / n_frames * 1e3, n_frames, n_points / n_frames))
    ref = rows[1][2]
    print(f"scene {SCENE.name}, {args.duration} s, median of {args.repeats}, one core, CPU time")
    print("| path | points | ms per frame | x analytic with points | frames | points per frame |")
    print("|---|---|---|---|---|---|")
    for path, points, ms, n_frames, ppf in rows:
        print(
            f"| {path} | {'yes' if points else 'no'} | {ms:.1f} | {ms / ref:.2f} | {n_frames} | "
            f"{ppf:.1f} |"
        )
    a = results["analytic-True"].received.products["range_doppler"].astype(np.float64)
    r = results["raw-True"].received.products["range_doppler"].astype(np.float64)
    peak = r.max(axis=(1, 2), keepdims=True)
    print(
        f"raw vs analytic range-Doppler maps: max |difference| / frame peak = "
        f"{float(np.max(np.abs(a - r) / peak)):.2e}"
    )


if __name__ == "__main__":
    main()
