"""Benchmark: CPU time per dataset record, records built one after another in one process.

Plans a dataset config (default ``examples/datasets/paper_480.toml``), builds a few records to
warm up, then times ``--records`` consecutive records (in the config's order, so the records of
one window at its several aspects follow one another, as a worker builds them) with
``build_records`` in the same process, and reports the CPU time per record of the whole
process (the thread that computes and the one that writes the files). Each round runs in a
fresh process.

``--against OTHER`` pairs this checkout with another one (e.g. a worktree of an earlier commit:
``git worktree add /tmp/old <commit>``), given by its root or its ``src`` folder: its core and
its built-in plugins (``plugins/*/src``) go first on the path of the other rounds. The rounds
alternate between the two (this, other, this, other, ...), and the script prints both medians
and the median of the per-round ratios, so that the machine's load drifts over both alike.

    .venv/bin/python benchmarks/bench_records.py [--config PATH] [--records 160]
        [--rounds 3] [--against OTHER] [--json OUT.json]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_CONFIG = ROOT / "examples" / "datasets" / "paper_480.toml"
#: records built before the timed ones (imports, first interpolants, caches)
WARM_UP = 16


def _child(config: str, first: int, n_records: int) -> None:
    """Run in a fresh process: CPU per record of ``n_records`` records from ``first`` on."""
    import tempfile
    import time
    import warnings

    warnings.simplefilter("ignore")
    import mdframework
    from mdframework.dataset import build_records, load_dataset_config, plan_records

    cfg, base = load_dataset_config(config)
    specs = plan_records(cfg, base)
    timed = specs[first : first + n_records]
    with tempfile.TemporaryDirectory() as out:
        (Path(out) / "records").mkdir()
        build_records(specs[:WARM_UP], out)
        cpu = time.process_time()
        build_records(timed, out)
        per_record = (time.process_time() - cpu) / len(timed)
    plugins = [
        str(getattr(m, "__file__", None) or getattr(m, "__path__", [""])[0])
        for n, m in sys.modules.items()
        if n.startswith("mdf_") and "." not in n
    ]
    print(
        json.dumps(
            {"per_record_ms": 1e3 * per_record, "package": mdframework.__file__, "plugins": plugins}
        )
    )


def other_paths(other: str) -> list[Path]:
    """The import paths of another checkout (its root or its ``src`` folder): its ``src`` and
    the ``src`` of each of its plugins."""
    root = Path(other).resolve()
    if root.name == "src" and (root / "mdframework").is_dir():
        root = root.parent
    if not (root / "src" / "mdframework").is_dir():
        raise SystemExit(f"--against {other}: no src/mdframework there")
    return [root / "src", *sorted(root.glob("plugins/*/src"))]


def _round(config: str, first: int, n_records: int, other: str | None) -> dict[str, Any]:
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "PYTHONWARNINGS": "ignore"}
    if other is not None:
        paths = [str(p) for p in other_paths(other)]
        env["PYTHONPATH"] = os.pathsep.join([*paths, env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    proc = subprocess.run(
        [sys.executable, __file__, "--child", config, str(first), str(n_records)],
        capture_output=True,
        text=True,
        env=env,
    )
    if proc.returncode:
        raise SystemExit(f"child failed:\n{proc.stderr}")
    result: dict[str, Any] = json.loads(proc.stdout.strip().splitlines()[-1])
    return result


def main() -> None:
    """Parse arguments, run the rounds, print the medians."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--config", default=str(DEFAULT_CONFIG))
    ap.add_argument("--records", type=int, default=160)
    ap.add_argument("--first", type=int, default=40, help="Index of the first timed record.")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--against", default=None, help="Another checkout (root or src).")
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--child", nargs=3, default=None, metavar=("CONFIG", "FIRST", "N"))
    a = ap.parse_args()
    if a.child is not None:
        _child(a.child[0], int(a.child[1]), int(a.child[2]))
        return
    print(f"load average before: {os.getloadavg()}", flush=True)
    this: list[float] = []
    other: list[float] = []
    for k in range(a.rounds):
        this.append(_round(a.config, a.first, a.records, None)["per_record_ms"])
        line = f"round {k + 1}: this checkout {this[-1]:.2f} ms a record"
        if a.against is not None:
            res = _round(a.config, a.first, a.records, a.against)
            root = other_paths(a.against)[0].parent
            for module in [res["package"], *res["plugins"]]:
                if not module.startswith(str(root) + os.sep):
                    raise SystemExit(f"--against {a.against}: imported {module} instead")
            other.append(res["per_record_ms"])
            line += f", other {other[-1]:.2f} ms, ratio {this[-1] / other[-1]:.3f}"
        print(line, flush=True)
    summary: dict[str, object] = {"this_ms": statistics.median(this), "rounds_this": this}
    text = f"median: this checkout {statistics.median(this):.2f} ms of CPU a record"
    if other:
        ratio = statistics.median(t / o for t, o in zip(this, other, strict=True))
        summary.update(other_ms=statistics.median(other), rounds_other=other, ratio=ratio)
        text += f", other {statistics.median(other):.2f} ms, median ratio {ratio:.3f}"
    print(text)
    print(f"load average after: {os.getloadavg()}")
    if a.json is not None:
        a.json.write_text(json.dumps(summary, indent=2) + "\n")


if __name__ == "__main__":
    main()
