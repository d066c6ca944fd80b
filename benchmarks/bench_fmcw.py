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

``--against OTHER`` times this checkout against another one (its root or its ``src``, e.g. an
earlier commit exported with ``git archive``: its core and built-in plugins go first on the
path), the analytic path with points, in fresh processes alternating this, other, this, ...
(``--rounds`` of each), on ``--scene walk`` (the scene above) or ``room`` (the sim-to-real
dataset's simulated room: the same walk, away from the sensor 1 m in front of the subject, with its
12 static reflectors, antenna pattern and 1 W; many more points a frame). It prints both
medians of the CPU ms per frame, the median ratio of the rounds, and whether the two gave the
same slow-time signal and point clouds (their largest difference); and the same for drawing one
frame's receiver noise alone (the radar's ``_noise``, 300 frames a round, CPU ms a frame).

    .venv/bin/python benchmarks/bench_fmcw.py [--repeats 3] [--duration 2.0]
    .venv/bin/python benchmarks/bench_fmcw.py --against OTHER [--scene walk|room] [--rounds 5]
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

from mdframework.config import read_config_file, validate_run_config  # noqa: E402
from mdframework.pipeline import RunResult, build_stages, load_motion, simulate_motion  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "fmcw_walk.toml"
#: Chirps a frame of the IWR1443 preset (both scenes)
CHIRPS_PER_FRAME = 48
#: ``--scene room``: the simulated room of examples/datasets/sim2real.toml (its base radar,
#: static reflectors and antenna pattern) around the walk of SCENE, walking away from a sensor
#: 1 m in front of the subject
ROOM: dict[str, Any] = {
    "radar": {
        "kind": "fmcw",
        "preset": "iwr1443_short_range_3d",
        "transmit_power": 1.0,
        "save_range_doppler": False,
        "boresight_azimuth_deg": 180.0,
    },
    "scene": {
        "radar_position": [1.0, 0.0, 1.0],
        "min_range": 0.25,
        "person": {"motion": "recorded", "position": [0.0, 0.0], "aspect_deg": 180.0},
    },
    "effects": [
        {
            "kind": "static_scene",
            "count": 12,
            "distance_m": [0.5, 3.5],
            "spread_deg": 60.0,
            "height_m": [0.0, 2.0],
            "rcs_m2": [0.01, 1.0],
        },
        {
            "kind": "antenna",
            "pointing": "angles",
            "azimuth_deg": 180.0,
            "beamwidth_az_deg": 90.0,
            "beamwidth_el_deg": 40.0,
        },
    ],
}


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


def scene(name: str, duration: float) -> dict[str, Any]:
    """The config of ``--scene`` ``name`` with a record of ``duration`` [s]."""
    base = read_config_file(SCENE)
    base["motion"]["duration"] = duration
    return {**base, **ROOM} if name == "room" else base


#: frames of receiver noise drawn a round (``--against``)
NOISE_FRAMES = 300


def child(name: str, duration: float, repeats: int, out: str) -> None:
    """In a fresh process: the median CPU ms per frame of the analytic path with points, and of
    drawing one frame's receiver noise; the signal and points saved to ``out``."""
    data = scene(name, duration)
    seconds, res = run(data, repeats)
    radar = build_stages(validate_run_config(data, base_dir=SCENE.parent)).radar
    n_rx = radar.antennas.rx.shape[0]
    t0 = time.process_time()
    for frame in range(NOISE_FRAMES):
        radar._noise(frame, n_rx)
    noise_ms = (time.process_time() - t0) / NOISE_FRAMES * 1e3
    import mdf_fmcw

    import mdframework

    n_frames = res.received.signal.shape[0] // CHIRPS_PER_FRAME
    points = res.received.products["points"]
    np.savez(out, signal=res.received.signal, points=points)
    modules = [str(mdframework.__file__), str(mdf_fmcw.__file__)]
    print(
        json.dumps(
            {"ms": seconds / n_frames * 1e3, "frames": n_frames, "points": len(points)}
            | {"noise_ms": noise_ms, "modules": modules}
        )
    )


def against(other: str, name: str, duration: float, repeats: int, rounds: int) -> None:
    """Alternate this checkout and ``other``; print the medians, the ratio and the agreement."""
    from bench_records import other_paths

    paths = os.pathsep.join(str(p) for p in other_paths(other))
    env_other = {**os.environ, "PYTHONPATH": paths, "PYTHONWARNINGS": "ignore"}
    env_this = {**os.environ, "PYTHONWARNINGS": "ignore"}
    times: dict[str, list[float]] = {"this": [], "other": []}
    noise: dict[str, list[float]] = {"this": [], "other": []}
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(rounds):
            for who, env in (("this", env_this), ("other", env_other)):
                argv = ["--child", name, str(duration), str(repeats), f"{tmp}/{who}.npz"]
                proc = subprocess.run(
                    [sys.executable, __file__, *argv], capture_output=True, text=True, env=env
                )
                if proc.returncode:
                    sys.exit(f"{who} failed:\n{proc.stderr[-2000:]}")
                got = json.loads(proc.stdout.strip().splitlines()[-1])
                root = str(Path(paths.split(os.pathsep)[0]).parent) + os.sep
                if (who == "other") != all(m.startswith(root) for m in got["modules"]):
                    sys.exit(f"{who} imported {got['modules']}")
                times[who].append(got["ms"])
                noise[who].append(got["noise_ms"])
            print(
                f"round {k + 1}: this {times['this'][-1]:.2f}, other {times['other'][-1]:.2f} "
                f"ms a frame ({got['frames']} frames, {got['points']} points); noise alone "
                f"this {noise['this'][-1]:.3f}, other {noise['other'][-1]:.3f}",
                flush=True,
            )
        a, b = np.load(f"{tmp}/this.npz"), np.load(f"{tmp}/other.npz")
        same_signal = bool(np.array_equal(a["signal"], b["signal"]))
        same_rows = a["points"].shape == b["points"].shape
        diff = float(np.max(np.abs(a["points"] - b["points"]), initial=0.0)) if same_rows else None
    ratios = [t / o for t, o in zip(times["this"], times["other"], strict=True)]
    print(
        f"scene {name}, {duration} s, CPU ms a frame, median of {rounds} rounds (each the median "
        f"of {repeats}): this {statistics.median(times['this']):.2f}, other "
        f"{statistics.median(times['other']):.2f}, median ratio {statistics.median(ratios):.3f} "
        f"({min(ratios):.3f} to {max(ratios):.3f})"
    )
    ratios = [t / o for t, o in zip(noise["this"], noise["other"], strict=True)]
    print(
        f"drawing one frame's receiver noise, CPU ms, median of {rounds} rounds: this "
        f"{statistics.median(noise['this']):.3f}, other {statistics.median(noise['other']):.3f}, "
        f"median ratio {statistics.median(ratios):.3f} ({min(ratios):.3f} to {max(ratios):.3f})"
    )
    print(
        f"slow-time signal bitwise equal: {same_signal}; points: "
        + (f"the same rows, largest difference {diff:.1e}" if same_rows else "DIFFERENT rows")
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--duration", type=float, default=2.0, help="record length [s]")
    parser.add_argument("--against", default=None, help="another checkout (root or src)")
    parser.add_argument("--scene", choices=["walk", "room"], default="walk")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--child", nargs=4, default=None, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child is not None:
        child(args.child[0], float(args.child[1]), int(args.child[2]), args.child[3])
        return
    if args.against is not None:
        against(args.against, args.scene, args.duration, args.repeats, args.rounds)
        return
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
