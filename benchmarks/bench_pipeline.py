"""Benchmark: skeleton -> spectrogram for a 6 s record with 17 scatterers at PRF 2400 Hz.

Reports the median wall time of the analytic path (eq. 4, exact LFM gate response) and the raw
path (sampled chirps + matched filter), measured in the same run, and scatterer-pulses per second.
Loading the motion is excluded; everything after it (window, placement, resampling, RCS, ranges,
receive, STFT, dB) is included.

    .venv/bin/python benchmarks/bench_pipeline.py [--repeats 15] [--raw-repeats 3]
"""

from __future__ import annotations

import os

# one core: keep BLAS from spreading over threads (set before numpy is imported)
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from mdframework import CANONICAL_JOINTS, Motion, Skeleton  # noqa: E402
from mdframework.config import validate_run_config  # noqa: E402
from mdframework.physics import body  # noqa: E402
from mdframework.pipeline import build_stages, simulate_motion  # noqa: E402


def walking_motion(duration: float = 6.0, frame_rate: float = 120.0) -> Motion:
    """A 1.8 m body walking at 1.3 m/s with limbs swinging at 0.9 Hz (benchmark input)."""
    f, h = body.SEGMENT_FRACTIONS, 1.8
    t = np.arange(0, duration + 1e-9, 1 / frame_rate)
    z_hip = (f["upper_leg"] + f["lower_leg"]) * h
    top = z_hip + f["torso"] * h
    pos = np.zeros((t.size, len(CANONICAL_JOINTS), 3))
    j = {n: i for i, n in enumerate(CANONICAL_JOINTS)}
    swing = np.deg2rad(25) * np.sin(2 * np.pi * 0.9 * t)
    pos[:, j["base"]] = [0, 0, z_hip]
    pos[:, j["neck"]] = [0, 0, top]
    pos[:, j["head"]] = [0, 0, top + f["head"] * h]
    for s, y in (("l", 1.0), ("r", -1.0)):
        a = y * swing
        pos[:, j[f"{s}_shoulder"]] = [0, y * f["shoulder"] * h, top]
        pos[:, j[f"{s}_hip"]] = [0, y * f["hip"] * h, z_hip]
        for root, chain, sign in (
            ("shoulder", ("elbow", "hand"), -1),
            ("hip", ("knee", "ankle"), 1),
        ):
            length = 0.0
            for name, seg in zip(
                chain,
                ("upper_arm", "lower_arm") if root == "shoulder" else ("upper_leg", "lower_leg"),
                strict=True,
            ):
                length += f[seg] * h
                p0 = pos[:, j[f"{s}_{root}"]]
                pos[:, j[f"{s}_{name}"], 0] = p0[:, 0] + length * np.sin(sign * a)
                pos[:, j[f"{s}_{name}"], 1] = p0[:, 1]
                pos[:, j[f"{s}_{name}"], 2] = p0[:, 2] - length * np.cos(sign * a)
        ankle = pos[:, j[f"{s}_ankle"]]
        pos[:, j[f"{s}_toe"]] = ankle + np.array([f["foot"] * h, 0.0, 0.0])
    pos[:, :, 0] += 1.3 * t[:, None]
    skel = Skeleton(t, pos, CANONICAL_JOINTS)
    return Motion(skel, {"source": "benchmark"}, {n: n for n in CANONICAL_JOINTS})


def time_path(path: str, motion: Motion, repeats: int) -> tuple[list[float], int, int]:
    """Wall times [s] of ``repeats`` runs of one receive path."""
    cfg = validate_run_config(
        {
            "motion": {
                "kind": "point_targets",
                "length": 1.0,  # unused: the benchmark passes its own motion
                "targets": [{"position": [1, 0, 0]}],
            },
            "scatterers": {"kind": "ellipsoid", "placement": "joints17", "height": 1.8},
            "radar": {"kind": "lfm", "path": path},
            "scene": {"radar_position": [12.0, 0.0, 1.5]},
        }
    )
    stages = build_stages(cfg)
    times = []
    for _ in range(repeats + 1):
        t0 = time.perf_counter()
        res = simulate_motion(cfg, stages, motion)
        times.append(time.perf_counter() - t0)
    n_pulses, n_scat = res.pulse_times.shape[0], len(res.metadata["scatterers"])
    return times[1:], n_pulses, n_scat  # the first run warms caches and is dropped


def main() -> None:
    """Run the benchmark and print a JSON summary."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--raw-repeats", type=int, default=3)
    args = parser.parse_args()
    motion = walking_motion()
    report: dict[str, object] = {"cpu_count": os.cpu_count()}
    for path, repeats in (("analytic", args.repeats), ("raw", args.raw_repeats)):
        times, n_pulses, n_scat = time_path(path, motion, repeats)
        med = statistics.median(times)
        report[path] = {
            "median_s": round(med, 5),
            "min_s": round(min(times), 5),
            "repeats": repeats,
            "n_pulses": n_pulses,
            "n_scatterers": n_scat,
            "scatterer_pulses_per_s": round(n_pulses * n_scat / med),
        }
    a, r = report["analytic"], report["raw"]
    assert isinstance(a, dict) and isinstance(r, dict)
    report["raw_over_analytic"] = round(r["median_s"] / a["median_s"], 1)
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
