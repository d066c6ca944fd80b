"""Benchmark: start-up cost of a whole ``mdf`` process against the imports it cannot avoid.

Measures, paired and alternating (A, B, A, B, ...) so that the machine's load drifts equally over
both, the wall time of

- A: ``mdf run examples/point_target.toml --out <tmp>`` (a 2 s point-target record, every file
  written: result.npz, spectrogram.png, config and metadata), a fresh output folder each time;
  and the same with ``--no-figures`` (no spectrogram.png, so no matplotlib);
- B: ``python -c "import numpy, scipy.fft, pydantic"`` (the floor: the libraries every run needs);

with the project's bytecode caches written first (as an installed package has them), and prints
the medians, the median of the per-pair ratios A/B (the goal is <= 2), and the same
for ``mdf --help`` and ``mdf plugins``. It also lists which of the heavy libraries (scikit-learn,
MuJoCo, matplotlib, Dask, OpenNI) each command imports.

    .venv/bin/python benchmarks/bench_startup.py [--pairs 15]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
FLOOR = [sys.executable, "-c", "import numpy, scipy.fft, pydantic"]
HEAVY = ("sklearn", "mujoco", "matplotlib", "dask", "distributed", "openni")


def _wall(cmd: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def heavy_imports(args: list[str]) -> list[str]:
    """The heavy top-level packages ``mdf ARGS`` imports (from ``python -X importtime``)."""
    proc = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "mdframework.cli", *args],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    )
    names = {line.rsplit("|", 1)[-1].strip() for line in proc.stderr.splitlines() if "|" in line}
    return sorted({n.split(".")[0] for n in names} & set(HEAVY))


def paired(command: list[str], pairs: int, fresh_out: bool) -> dict[str, float]:
    """Median wall times [s] of ``command`` and of the floor, alternating, and the median of the
    per-pair ratios."""
    a, b = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(pairs):
            cmd = [*command, "--out", f"{tmp}/run{i}"] if fresh_out else command
            a.append(_wall(cmd))
            b.append(_wall(FLOOR))
    ratios = [x / y for x, y in zip(a, b, strict=True)]
    return {
        "median_s": statistics.median(a),
        "floor_median_s": statistics.median(b),
        "median_ratio": statistics.median(ratios),
    }


def main() -> None:
    """Run the benchmark and print a JSON summary."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=15, help="A/B pairs (default 15)")
    args = parser.parse_args()
    mdf = str(BIN / "mdf")
    # bytecode caches of the core and the plugins, as an installed package has them (`make
    # bytecode`); without them, under PYTHONDONTWRITEBYTECODE, every process compiles them again
    subprocess.run(
        [sys.executable, "-m", "compileall", "-q", str(ROOT / "src"), str(ROOT / "plugins")],
        check=True,
        stdout=subprocess.DEVNULL,
    )
    for _ in range(2):  # warm the file cache
        _wall(FLOOR)
        _wall([mdf, "--help"])
    run = [mdf, "run", str(ROOT / "examples" / "point_target.toml")]
    results = {
        "run point_target": paired(run, args.pairs, fresh_out=True),
        "run --no-figures": paired([*run, "--no-figures"], args.pairs, fresh_out=True),
        "--help": paired([mdf, "--help"], args.pairs, fresh_out=False),
        "plugins": paired([mdf, "plugins"], args.pairs, fresh_out=False),
    }
    with tempfile.TemporaryDirectory() as tmp:
        imports = {
            "--help": heavy_imports(["--help"]),
            "plugins": heavy_imports(["plugins"]),
            "config schema": heavy_imports(["config", "schema"]),
            "run point_target": heavy_imports(
                ["run", str(ROOT / "examples" / "point_target.toml"), "--out", f"{tmp}/o"]
            ),
            "run --no-figures": heavy_imports(
                [
                    "run",
                    str(ROOT / "examples" / "point_target.toml"),
                    "--no-figures",
                    "--out",
                    f"{tmp}/n",
                ]
            ),
        }
    for name, r in results.items():
        print(
            f"mdf {name:<18} {1e3 * r['median_s']:7.0f} ms   "
            f"floor {1e3 * r['floor_median_s']:5.0f} ms   ratio {r['median_ratio']:.2f}   "
            "heavy imports: "
            f"{', '.join(imports.get(name, [])) or 'none'}"
        )
    print(json.dumps({"pairs": args.pairs, "results": results, "heavy_imports": imports}))


if __name__ == "__main__":
    main()
