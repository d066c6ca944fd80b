"""docs/sim-to-real.md against the numbers that benchmarks/bench_sim2real.py wrote.

The benchmark (``--docs``) copies its ``results.json`` to ``docs/data/sim2real_results.json``;
the page must show exactly the tables the script renders from it, quote the command that made
it, and every other decimal number in its prose must be one of the script's figures.
"""

from __future__ import annotations

import importlib.util
import json
import re
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "sim-to-real.md"
RESULTS = ROOT / "docs" / "data" / "sim2real_results.json"
BEGIN = "<!-- bench_sim2real tables: generated, do not edit -->"
END = "<!-- end of bench_sim2real tables -->"


def _bench() -> ModuleType:
    spec = importlib.util.spec_from_file_location(
        "bench_sim2real", ROOT / "benchmarks" / "bench_sim2real.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _results() -> dict[str, Any]:
    data: dict[str, Any] = json.loads(RESULTS.read_text())
    return data


def _block(page: str) -> tuple[str, str]:
    """The generated block and the rest of the page."""
    start, end = page.index(BEGIN), page.index(END)
    return page[start + len(BEGIN) : end].strip("\n") + "\n", page[:start] + page[end:]


def test_the_page_shows_the_tables_the_script_renders() -> None:
    pytest.importorskip("mdf_fmcw")  # the benchmark's config needs the FMCW radar
    bench = _bench()
    results = _results()
    generated, _ = _block(PAGE.read_text())
    assert generated == bench.markdown(results)
    assert set(results["sim_to_real"]) <= set(bench.VARIANTS)
    # three or more seeds for every variant: the spread is over seeds
    assert len(results["seeds"]) >= 3
    for variant, res in results["sim_to_real"].items():
        for key, cell in res.items():
            if key != "what":
                assert len(cell["scores"]) == len(results["seeds"]), (variant, key)


def test_the_page_quotes_the_command_and_only_the_scripts_numbers() -> None:
    pytest.importorskip("mdf_fmcw")
    bench = _bench()
    results = _results()
    page = PAGE.read_text()
    generated, prose = _block(page)
    assert ".venv/bin/python " + results["command"] in prose
    # every accuracy-like number (0.xxx) and every signed difference in points in the prose is
    # one the script printed
    numbers = set(re.findall(r"(?<![\d.])0\.\d{3}(?!\d)", prose))
    numbers |= set(re.findall(r"(?<![\w.])[+-]\d+\.\d(?!\d)", prose))
    rendered = bench.markdown(results)
    missing = sorted(n for n in numbers if n not in rendered)
    assert not missing, f"numbers on the page that the script did not print: {missing}"
    assert generated == rendered


def test_the_goal_sentence_follows_the_numbers() -> None:
    """The goal verdict is computed, not written: met exactly where the mean is >= 0.80 and
    within 10 points of the real-to-real mean of the same input and classifier."""
    bench = _bench()
    results = {
        "real_to_real": {"a": {"mean": 0.92}, "b": {"mean": 0.92}, "c": {"mean": 0.85}},
        "sim_to_real": {"full": {"a": {"mean": 0.83}, "b": {"mean": 0.81}, "c": {"mean": 0.79}}},
    }
    assert bench.goal(results) == {"a": True, "b": False, "c": False}
    assert bench.goal_line(results).endswith("met for `a`; not met for `b`, `c`.")


def test_the_goal_margins_and_the_ablation_differences_carry_their_standard_errors() -> None:
    """How narrowly the goal is met, and each ablation difference, are computed with their
    standard error over the seeds; the differences are taken seed by seed (the variants of one
    seed share most of their draws), so a shift that every seed shows is told from the spread
    of the seeds."""
    import numpy as np

    bench = _bench()
    full = [0.80, 0.90, 0.70, 0.84]
    results = {
        "real_to_real": {"a": {"mean": 0.95}, "b": {"mean": 0.85}},
        "sim_to_real": {
            "full": {
                "a": {"mean": float(np.mean(full)), "scores": full},
                "b": {"mean": 0.81, "scores": [0.81]},
            }
        },
    }
    margin, se = bench.goal_margins(results)["a"]
    # the bound is the stricter of 0.80 and 10 points below real-to-real: 0.85
    assert margin == pytest.approx(100 * (np.mean(full) - 0.85))
    assert se == pytest.approx(100 * np.std(full, ddof=1) / 2)
    assert bench.goal_margins(results)["b"] == (pytest.approx(1.0), None)  # one seed: no error
    assert "`a` -4.0 ± 4.2" in bench.margins_line(results)
    # every seed 2 points lower: -2.0 with no error, though the seeds spread by 8 points
    variant = {"mean": float(np.mean(full)) - 0.02, "scores": [v - 0.02 for v in full]}
    diff, diff_se = bench.paired_difference(variant, results["sim_to_real"]["full"]["a"])
    assert diff == pytest.approx(-2.0)
    assert diff_se == pytest.approx(0.0, abs=1e-9)


def test_a_variant_that_drops_the_room_says_so() -> None:
    """An ablation row's words name what its change does to the room (the static reflectors):
    a variant that removes them says 'room'."""
    import copy

    from mdframework.config import read_config_file

    bench = _bench()
    base = read_config_file(bench.CONFIG)
    for name, (what, change) in bench.VARIANTS.items():
        cfg = copy.deepcopy(base)
        change(cfg)
        kinds = [e.get("kind") for e in cfg["base"]["effects"]]
        if "static_scene" not in kinds:
            assert "room" in what, (name, what)


def test_the_prose_figures_derived_from_the_results() -> None:
    """Figures of the prose that the script does not print as such: the walks' per-class rates
    on the histogram input (two decimals, which the test above does not look at), how many
    points the histogram inputs fall below real-to-real, and how many times as many points a
    simulated frame holds as a real one."""
    results = _results()
    _, prose = _block(PAGE.read_text())
    prose = " ".join(prose.split())
    sim, real = results["sim_to_real"]["full"], results["real_to_real"]
    weak = re.search(
        r"weak class \((0\.\d\d) for k-NN, (0\.\d\d) for the forest, against (0\.\d\d) and "
        r"(0\.\d\d) real-to-real\)",
        prose,
    )
    assert weak is not None
    inputs = ("knn/histogram", "forest/histogram")
    walks = [sim[k]["per_class"]["walk"] for k in inputs]
    walks += [real[k]["per_class"]["walk"] for k in inputs]
    assert list(weak.groups()) == [f"{w:.2f}" for w in walks]
    below = re.search(r"at least 0\.80, and (\d+) and (\d+) points below the reference", prose)
    assert below is not None
    gaps = [100 * (real[k]["mean"] - sim[k]["mean"]) for k in inputs]
    assert list(below.groups()) == [f"{g:.0f}" for g in gaps]
    # the range of one seed's score over the seeds, in whole per cent
    spread = re.search(
        r"k-NN on the histograms scores between (\d+) and (\d+) % over the (\w+) seeds, the "
        r"forest between (\d+) and (\d+) %",
        prose,
    )
    assert spread is not None
    words = {3: "three", 5: "five", 10: "ten"}
    assert spread.group(3) == words.get(len(results["seeds"]))
    ranges = [f(sim[k]["scores"]) for k in inputs for f in (min, max)]
    assert [spread.group(i) for i in (1, 2, 4, 5)] == [f"{100 * v:.0f}" for v in ranges]
    times = re.search(
        r"simulated frames also hold ([\d.]+) to ([\d.]+) times as many points", prose
    )
    assert times is not None
    points = results["points"]
    ratios = [points["full"][a]["points"] / points["real"][a]["points"] for a in points["real"]]
    low, high = (float(t) for t in times.groups())
    assert low - 0.05 <= min(ratios) and max(ratios) <= high + 0.05, ratios
    # the moving points per frame of the lively, the real and the shipped jumps
    jumps = re.search(
        r"have (\d\.\d\d) moving points per frame against the real jumps' (\d\.\d\d) \(the "
        r"points table; the shipped slow jumps still have (\d\.\d\d)\)",
        prose,
    )
    assert jumps is not None
    moving = [points[v]["jump"]["moving"] for v in ("lively_jumps", "real", "full")]
    assert list(jumps.groups()) == [f"{m:.2f}" for m in moving]


def test_the_real_to_real_split_words_count_the_shipped_recordings() -> None:
    """The page says a real-to-real split holds out 5 of each activity's 12 recordings (the
    test fraction 0.4 rounded to whole recordings, as the splits do); the script's constant
    must be the number of recordings the repository ships for each activity."""
    import numpy as np

    from mdframework.experiment import recordings_held_out

    bench = _bench()
    for npz in sorted((ROOT / "examples" / "data" / "radhar").glob("radhar_*_subset.npz")):
        with np.load(npz) as data:
            assert len(set(data["files"].tolist())) == bench.REAL_RECORDINGS, npz.name
    held = recordings_held_out(bench.REAL_RECORDINGS, bench.TEST_FRACTION)
    assert (held, bench.REAL_RECORDINGS) == (5, 12)
    assert "holding out 5 of the 12 recordings of every class" in PAGE.read_text()


def test_the_reproduce_section_says_the_experiment_is_one_seed() -> None:
    """`mdf experiment examples/experiment_sim2real.toml` builds one dataset seed: the page says
    which, and that its score is the benchmark's first seed's, not the table's mean."""
    import tomllib

    results = _results()
    config = tomllib.loads((ROOT / "examples" / "datasets" / "sim2real.toml").read_text())
    reproduce = " ".join(PAGE.read_text().split("## Reproduce", 1)[1].split())
    assert f"one dataset seed (the config's `seed = {config['seed']}`)" in reproduce
    assert results["seeds"][0] == config["seed"]
    assert "the first of the benchmark's k-NN histogram scores, not their mean" in reproduce
