"""Benchmark: the Boulic walker's MuJoCo kinematics and the shadowing test, per pulse, for a 6 s
walk at PRF 2400 Hz (14 400 pulses), one core.

Reports the median over repeats (one run) of:

- ``source``: the motion source (MuJoCo kinematics at the walker's own rate, nt = 512 per cycle),
  per pulse of the record;
- ``kinematics``: ``mj_kinematics`` at every pulse time (what the ``mujoco_body`` model does);
- ``mujoco_body``: the whole scatterer model (kinematics, placement, local-frame RCS);
- ``shadowing``: the line-of-sight test (16 rays per pulse via ``mj_multiRay``), decimation 1
  and 4.

    .venv/bin/python benchmarks/bench_boulic.py [--repeats 7]
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402

import numpy as np  # noqa: E402
from mdf_mujoco.body_model import WalkerBody  # noqa: E402
from mdf_mujoco.scatterers import MujocoBody, MujocoBodyConfig  # noqa: E402
from mdf_mujoco.shadowing import Shadowing, ShadowingConfig  # noqa: E402
from mdf_mujoco.source import BoulicConfig, BoulicWalker  # noqa: E402

from mdframework import SceneContext, Skeleton  # noqa: E402
from mdframework.physics.interpolation import pulse_times, resample_tracks  # noqa: E402

PRF = 2400.0
DURATION = 6.0
RADAR = np.array([10.0, 0.0, 2.0])


def median_time(fn: Callable[[], object], repeats: int) -> float:
    """Median wall time [s] of ``repeats`` calls after one warm-up call."""
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()

    source = BoulicWalker(BoulicConfig(rv=1.0, duration=DURATION))
    motion = source.load()
    t = pulse_times(0.0, DURATION, PRF)
    n = t.size
    skel = motion.skeleton
    joints = resample_tracks(skel.time, skel.positions, skel.valid, t)
    at_pulses = Skeleton(t, joints, skel.joint_names)
    walker = WalkerBody(source.gait())
    q = walker.qpos(t)
    model = MujocoBody(MujocoBodyConfig())
    scat = model.scatterers(motion, at_pulses, RADAR, 0.02)
    ctx = SceneContext(RADAR, PRF, 15e9, t, np.zeros(n), at_pulses, None, np.random.default_rng())  # type: ignore[arg-type]
    shadow1 = Shadowing(ShadowingConfig())
    shadow4 = Shadowing(ShadowingConfig(decimation=4))

    results = {
        "source": median_time(source.load, args.repeats),
        "kinematics": median_time(lambda: walker.kinematics(q), args.repeats),
        "mujoco_body": median_time(
            lambda: model.scatterers(motion, at_pulses, RADAR, 0.02), args.repeats
        ),
        "shadowing": median_time(lambda: shadow1.visibility(scat, ctx), args.repeats),
        "shadowing_decimation_4": median_time(lambda: shadow4.visibility(scat, ctx), args.repeats),
    }
    report = {
        "pulses": n,
        "repeats": args.repeats,
        "total_s": results,
        "per_pulse_us": {k: v / n * 1e6 for k, v in results.items()},
    }
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
