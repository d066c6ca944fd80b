"""Fuzzing: random valid scenes through the whole pipeline (the property of
``tests/test_random_scenes.py`` on many more scenes).

Draws scenes with Hypothesis from ``tests/scenes.py`` (point targets and the shipped CMU and
Kinect recordings, every scatterer model that fits, the LFM, FMCW and CW radars, any subset of
effects, the geometry and the STFT, all within the documented ranges) and checks that each
either runs to finite outputs (``ok``) or is refused with a one-line user error (``refused``).
Any other outcome (an internal error, a numerical warning, a non-finite output) is a failure;
the first few are printed with their configs, and the exit code is 1.

    .venv/bin/python benchmarks/fuzz_scenes.py [--examples 10000] [--seed 0] [--json PATH]

Reports the counts of each outcome (in all and per radar kind), the refusal reasons (the error's
first words) and the time per scene (median over all scenes, one run); ``--json`` also writes
them, with the command, the date, the wall time and the load average, to a file
(``docs/data/fuzz_results.json`` holds the runs that ``docs/input-rules.md`` quotes).
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import collections  # noqa: E402
import json  # noqa: E402
import re  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import traceback  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from hypothesis import HealthCheck, given, seed, settings  # noqa: E402
from scenes import body_scenes, load_project_modules, point_scenes, run_scene  # noqa: E402

#: a number in an error message (grouping refusals by their words)
NUMBER = re.compile(r"[-+]?\d[\d.,]*(?:e[-+]?\d+)?")


def main(argv: list[str] | None = None) -> int:
    """Run the fuzzer; returns 1 if any scene failed."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--examples", type=int, default=10_000, help="scenes in all")
    parser.add_argument("--seed", type=int, default=0, help="Hypothesis seed")
    parser.add_argument("--json", type=Path, default=None, help="write the figures to this file")
    args = parser.parse_args(argv)
    started = time.time()
    load_before = os.getloadavg()

    outcomes: collections.Counter[str] = collections.Counter()
    by_radar: collections.Counter[tuple[str, str]] = collections.Counter()
    reasons: collections.Counter[str] = collections.Counter()
    failures: list[tuple[dict[str, Any], str]] = []
    times: list[float] = []

    def one(cfg: dict[str, Any]) -> None:
        t0 = time.perf_counter()
        try:
            outcome = run_scene(cfg)
        except Exception:
            outcome = "FAILED"
            failures.append((cfg, traceback.format_exc(limit=6)))
        times.append(time.perf_counter() - t0)
        kind, _, message = outcome.partition(": ")
        outcomes[kind] += 1
        by_radar[(cfg["radar"]["kind"], kind)] += 1
        if kind == "refused":
            # the field or problem: the message without the config's name, numbers as N
            text = NUMBER.sub("N", message.split(": ", 1)[-1])
            reasons[" ".join(text.split()[:6])] += 1

    half = args.examples // 2
    load_project_modules()  # the same scenes for a seed (see its docstring)
    for strategy in (point_scenes(), body_scenes()):
        run = settings(
            max_examples=half,
            deadline=None,
            database=None,
            suppress_health_check=list(HealthCheck),
        )(given(strategy)(one))
        seed(args.seed)(run)()

    total = sum(outcomes.values())
    print(f"scenes: {total}  " + "  ".join(f"{k}: {v}" for k, v in sorted(outcomes.items())))
    for radar in sorted({r for r, _ in by_radar}):
        counts = "  ".join(f"{k}: {v}" for (r, k), v in sorted(by_radar.items()) if r == radar)
        print(f"  radar {radar}: {counts}")
    print(f"median time per scene: {statistics.median(times) * 1e3:.1f} ms")
    print("refusals (first words of the error):")
    for text, count in reasons.most_common(12):
        print(f"  {count:6d}  {text}")
    for cfg, trace in failures[:5]:
        print("FAILED:", json.dumps(cfg))
        print(trace)
    wall = time.time() - started
    print(
        f"wall time: {wall:.0f} s; load average {load_before[0]:.2f} at the start, "
        f"{os.getloadavg()[0]:.2f} at the end"
    )
    if args.json is not None:
        figures = {
            "command": f"benchmarks/fuzz_scenes.py --examples {args.examples} --seed {args.seed}",
            "date": time.strftime("%Y-%m-%d", time.gmtime(started)),
            "scenes": total,
            "outcomes": dict(sorted(outcomes.items())),
            "failures": len(failures),
            "by_radar": {
                radar: {k: v for (r, k), v in sorted(by_radar.items()) if r == radar}
                for radar in sorted({r for r, _ in by_radar})
            },
            "refusals": dict(reasons.most_common()),
            "median_ms_per_scene": round(statistics.median(times) * 1e3, 1),
            "wall_s": round(wall),
            "load_average": [round(load_before[0], 2), round(os.getloadavg()[0], 2)],
        }
        args.json.write_text(json.dumps(figures, indent=1) + "\n")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
