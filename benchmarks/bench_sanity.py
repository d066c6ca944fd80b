"""What the motion sanity checks cost next to reading the motion.

For shipped recordings of each kind (a long CMU ASF/AMC boxing trial, a cgspeed BVH, a Mixamo
BVH, a Kinect walk), the median over repeats of: reading the motion (``source.load()``) and
running :func:`mdframework.sanity.check_motion` on it with the default options (warnings
silenced). Prints a Markdown table with the frame count, both medians and their ratio.

    .venv/bin/python benchmarks/bench_sanity.py [--repeats 7]
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings
from pathlib import Path

from mdframework.config import validate_run_config
from mdframework.pipeline import build_stages
from mdframework.sanity import check_motion

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CASES = {
    "CMU 13_18 boxing (ASF/AMC)": {"kind": "cmu", "file": "data/cmu/asf-amc/13_18.amc"},
    "CMU 80_10 boxing (cgspeed BVH)": {"kind": "cmu", "file": "data/cmu/bvh/80_10.bvh"},
    "Mixamo walk (BVH)": {"kind": "bvh", "file": "data/bvh/test_freebvh.bvh"},
    "UTKinect s01_e01 walk": {
        "kind": "kinect",
        "format": "utkinect",
        "file": "data/kinect/utkinect/joints_s01_e01.txt",
        "segment": "walk",
        "activity": "walk",
    },
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    print("| recording | frames | load [ms] | checks [ms] | checks / load |")
    print("|---|---|---|---|---|")
    for name, section in CASES.items():
        cfg = validate_run_config({"motion": section}, source=name, base_dir=EXAMPLES)
        source = build_stages(cfg).source
        sanity_cfg = source.config.sanity  # type: ignore[attr-defined]
        loads, checks = [], []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for _ in range(args.repeats):
                t0 = time.perf_counter()
                motion = source.load()
                t1 = time.perf_counter()
                check_motion(motion, sanity_cfg)
                t2 = time.perf_counter()
                loads.append(t1 - t0)
                checks.append(t2 - t1)
        lo, ch = statistics.median(loads), statistics.median(checks)
        print(
            f"| {name} | {motion.skeleton.n_frames} | {1e3 * lo:.1f} | {1e3 * ch:.1f} | "
            f"{ch / lo:.2f} |"
        )


if __name__ == "__main__":
    main()
