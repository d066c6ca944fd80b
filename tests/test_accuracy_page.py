"""docs/accuracy.md against the numbers that benchmarks/bench_accuracy.py wrote.

The benchmark (``--docs``) writes its ``results.json`` to ``docs/data/accuracy_results.json`` and
its tables into the page between the generated markers; the page must show exactly the tables the
script renders from that file, quote the command that made it, and every decimal number and
every time factor in the prose about the ladders must be one the script printed.
"""

from __future__ import annotations

import importlib.util
import json
import re
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "accuracy.md"
RESULTS = ROOT / "docs" / "data" / "accuracy_results.json"
#: the prose checked: from the top of the page to the FMCW section (bench_fmcw's numbers)
FMCW_SECTION = "## FMCW per frame"
#: decimal numbers of the method itself, not measured: the velocity resolution a feature change
#: is compared with
METHOD_CONSTANTS = {"0.1"}


def _bench() -> ModuleType:
    name = "bench_accuracy"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, ROOT / "benchmarks" / "bench_accuracy.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def _results() -> dict[str, Any]:
    data: dict[str, Any] = json.loads(RESULTS.read_text())
    return data


def _block(page: str, bench: ModuleType) -> tuple[str, str]:
    """The generated block and the rest of the page."""
    start, end = page.index(bench.BEGIN), page.index(bench.END)
    return page[start + len(bench.BEGIN) : end].strip("\n") + "\n", page[:start] + page[end:]


#: a whole number as written: ``21``, ``0.36``, ``5.7e-06``
NUMBER = r"(?<![\w.])\d+(?:\.\d+)?(?:e[+-]\d+)?(?![\d.])"


def prose_numbers(prose: str) -> set[str]:
    """The measured numbers of a text: decimals (``0.36``, ``5.7e-06``) and factors (``18x``,
    ``0.21x``), each as written."""
    numbers = {n for n in re.findall(NUMBER, prose) if "." in n}
    numbers |= set(re.findall(NUMBER + r"(?=x(?!\w))", prose))
    return numbers - METHOD_CONSTANTS


def test_prose_numbers_finds_decimals_and_factors() -> None:
    text = "costs 1.49-1.56x (about 18x), 0.36 dB, 2.1e-06 of the peak, hop 8, x32, 0.1 m/s"
    assert prose_numbers(text) == {"1.49", "1.56", "18", "0.36", "2.1e-06"}
    assert "1.2" not in set(re.findall(NUMBER, "1.22 and 11.2 and 1.23"))


def test_the_page_shows_the_tables_the_script_renders() -> None:
    pytest.importorskip("mdf_fmcw")  # the FMCW ladder's scene
    bench = _bench()
    results = _results()
    generated, _ = _block(PAGE.read_text(), bench)
    assert generated == bench.markdown(results)
    rows = results["rows"]
    assert {r["scene"] for r in rows} == {"boulic", "cmu_run_09_06", "kinect_walk", "fmcw_walk"}
    # the full run: every rung of every ladder, each timed repeatedly, one default and one
    # reference per ladder and scene
    for scene in ("boulic", "cmu_run_09_06", "kinect_walk"):
        want = {(s.ladder, s.name) for s in bench.ladders(scene, quick=False)}
        assert {(r["ladder"], r["setting"]) for r in rows if r["scene"] == scene} == want
    assert results["repeats"] >= 11 and results["slow_repeats"] >= 3
    for r in rows:
        assert r["runs"] >= results["slow_repeats"], r
        if r["default"]:
            assert r["x_default"] == 1.0
        if r["reference"]:
            assert r["spec_err_db"] == 0.0 and r["feat_err_mps"] == 0.0
    for scene, ladder in {(r["scene"], r["ladder"]) for r in rows}:
        rungs = [r for r in rows if (r["scene"], r["ladder"]) == (scene, ladder)]
        assert sum(r["default"] for r in rungs) == sum(r["reference"] for r in rungs) == 1


def test_the_page_quotes_the_command_and_only_the_scripts_numbers() -> None:
    pytest.importorskip("mdf_fmcw")
    bench = _bench()
    results = _results()
    page = PAGE.read_text()
    generated, prose = _block(page, bench)
    assert ".venv/bin/python " + results["command"] in prose
    assert results["commit"].split()[0] in prose and results["date"] in prose
    ladder_prose = prose[: prose.index(FMCW_SECTION)]
    rendered = bench.markdown(results)
    printed = set(re.findall(NUMBER, rendered))  # whole numbers: "1.2" is not in "1.22"
    missing = sorted(prose_numbers(ladder_prose) - printed)
    assert not missing, f"numbers on the page that the script did not print: {missing}"
    assert generated == rendered


def test_paired_ratio_is_the_median_of_the_rounds_both_ran() -> None:
    bench = _bench()
    setting = [1.0, None, 3.0, 8.0, 2.0]
    default = [2.0, 1.0, 1.0, None, 1.0]
    # rounds 0, 2, 4: ratios 0.5, 3, 2
    assert bench.paired_ratio(setting, default) == 2.0


def test_time_ladder_alternates_and_counts_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    bench = _bench()
    calls: list[str] = []

    def fake_run(cfg: str, motion: None) -> tuple[str, float]:
        calls.append(cfg)
        return cfg, 1.0

    monkeypatch.setattr(bench, "run_once", fake_run)
    prepared = {"a": ("a", None), "b": ("b", None), "c": ("c", None)}
    results, times = bench.time_ladder(prepared, {"a": 3, "b": 3, "c": 1})
    # the order rotates each round; c sits out after its one run
    assert calls == ["a", "b", "c", "b", "a", "a", "b"]
    assert times["c"] == [1.0, None, None] and times["a"] == [1.0, 1.0, 1.0]
    assert results == {"a": "a", "b": "b", "c": "c"}
