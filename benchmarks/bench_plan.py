"""Benchmark: what the content fingerprints cost a dataset's planning.

A record's id covers a fingerprint (SHA-1) of the motion or recording it is cut from
(``motion_fingerprint`` and ``recording_fingerprint`` of :mod:`mdframework.dataset`), computed
once per loaded motion or recording while the records are planned. For each dataset config
this plans the records (reading every file afresh, in this process) with the
fingerprints, and with them replaced by a constant, alternating the two ``--repeats`` times,
and prints the median planning times and their ratio, then the time of the fingerprints alone
(every loaded motion and recording hashed once, median of the repeats) and the bytes hashed.

    .venv/bin/python benchmarks/bench_plan.py [--repeats 5] [CONFIG ...]

Default configs: examples/datasets/sim2real.toml and examples/datasets/paper_480.toml (the
paper's 480 records). The machine is shared: the load average is printed before and after.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULTS = [
    ROOT / "examples" / "datasets" / "sim2real.toml",
    ROOT / "examples" / "datasets" / "paper_480.toml",
]


def plan_seconds(config: Path, fingerprints: bool) -> tuple[float, int]:
    """Seconds to plan ``config`` from cold caches, and its number of records."""
    from mdframework import dataset

    real = dataset.motion_fingerprint, dataset.recording_fingerprint
    if not fingerprints:
        dataset.motion_fingerprint = dataset.recording_fingerprint = lambda _: "0"  # type: ignore[assignment]
    try:
        cfg, base = dataset.load_dataset_config(config)
        dataset._forget_loaded()
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            specs = dataset.plan_records(cfg, base, workers=1)
        return time.perf_counter() - t0, len(specs)
    finally:
        dataset.motion_fingerprint, dataset.recording_fingerprint = real


def fingerprint_seconds(config: Path) -> tuple[float, int, int]:
    """Seconds to fingerprint every motion and recording ``config`` loads, their count and
    the bytes hashed (after a plan, from the loaded objects)."""
    import json

    from mdframework import dataset

    cfg, base = dataset.load_dataset_config(config)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        dataset._forget_loaded()
        dataset.plan_records(cfg, base, workers=1)
    motions = list(dataset._MOTIONS.values())
    recordings = [
        r
        for e in cfg.sources
        if e.recording is not None
        for r in dataset._load_recordings(json.dumps(e.recording, sort_keys=True), str(base))
    ]
    size = sum(m.skeleton.positions.nbytes + m.skeleton.time.nbytes for m in motions)
    size += sum(r.cloud.positions.nbytes * 2 for r in recordings)  # positions + 3 columns
    t0 = time.perf_counter()
    for m in motions:
        dataset.motion_fingerprint(m)
    for r in recordings:
        dataset.recording_fingerprint(r)
    return time.perf_counter() - t0, len(motions) + len(recordings), size


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("configs", nargs="*", type=Path, default=DEFAULTS)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()}")
    for config in args.configs:
        plan_seconds(config, True)  # imports and plugins loaded once
        with_fp: list[float] = []
        without: list[float] = []
        n = 0
        for _ in range(args.repeats):
            t, n = plan_seconds(config, True)
            with_fp.append(t)
            without.append(plan_seconds(config, False)[0])
        hashes = [fingerprint_seconds(config) for _ in range(args.repeats)]
        a, b = statistics.median(with_fp), statistics.median(without)
        fp = statistics.median(h[0] for h in hashes)
        print(
            f"{config.name}: {n} records; planning {a * 1e3:.1f} ms with fingerprints, "
            f"{b * 1e3:.1f} ms without (ratio {a / b:.3f}); fingerprints alone "
            f"{fp * 1e3:.2f} ms for {hashes[0][1]} motions/recordings, "
            f"{hashes[0][2] / 1e6:.1f} MB"
        )
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
