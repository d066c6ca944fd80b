"""docs/input-rules.md quotes the 10,000-scene fuzz that benchmarks/fuzz_scenes.py wrote
(``--json``, both runs kept in ``docs/data/fuzz_results.json``): its totals must be those runs'
sums, and the commands those runs'."""

from __future__ import annotations

import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_input_rules_quotes_the_recorded_fuzz_runs() -> None:
    runs = json.loads((ROOT / "docs" / "data" / "fuzz_results.json").read_text())
    page = " ".join((ROOT / "docs" / "input-rules.md").read_text().split())
    scenes = sum(r["scenes"] for r in runs)
    ok = sum(r["outcomes"].get("ok", 0) for r in runs)
    refused = sum(r["outcomes"].get("refused", 0) for r in runs)
    assert sum(r["failures"] for r in runs) == 0 and ok + refused == scenes
    assert f"ran {scenes:,} scenes" in page
    assert f"{ok:,} ran to finite outputs, {refused:,} were refused with one line" in page
    assert "and none failed" in page
    for r in runs:
        options = r["command"].split("fuzz_scenes.py ", 1)[1]  # e.g. --examples 5000 --seed 1
        examples, seed = options.split(" --seed ")
        assert f"`{examples}`" in page and f"`--seed {seed}`" in page


def test_input_rules_quotes_the_recorded_motion_fuzz_run() -> None:
    """The damaged-motion-file fuzz (benchmarks/fuzz_motion.py --json) as the page quotes it."""
    run = json.loads((ROOT / "docs" / "data" / "fuzz_motion_results.json").read_text())
    page = " ".join((ROOT / "docs" / "input-rules.md").read_text().split())
    outcomes = run["outcomes"]
    assert outcomes["failed"] == 0 and outcomes["ok"] + outcomes["refused"] == run["cases"]
    assert sum(sum(f.values()) for f in run["by_format"].values()) == run["cases"]
    options = run["command"].split("fuzz_motion.py ", 1)[1]
    assert (
        f"it ran {run['cases']:,} damaged files (`{options}`, commit {run['commit']}): "
        f"{outcomes['ok']:,} were read and ran, {outcomes['refused']:,} were refused with one "
        "line naming the file, and none failed" in page
    )
