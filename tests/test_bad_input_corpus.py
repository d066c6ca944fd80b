"""The bad-input corpus (``tests/corpus/make_corpus.py``): every case, made from the shipped real
files at test time, ends as the project promises: exit code 2, one line on stderr that names the
file (and line) or the config field, no traceback, and nothing written to ``--out``."""

from __future__ import annotations

from pathlib import Path

import pytest
from corpus.make_corpus import Case, case_names, make_corpus

from mdframework import cli

NAMES = case_names()


@pytest.fixture(scope="module")
def corpus(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Case]:
    root = tmp_path_factory.mktemp("corpus") / "cases"
    return {case.name: case for case in make_corpus(root)}


def _files(folder: Path) -> set[Path]:
    return {p for p in folder.rglob("*") if p.is_file()}


def test_the_corpus_covers_every_format_and_config_section() -> None:
    prefixes = {name.split("-")[0] for name in NAMES}
    assert {"bvh", "amc", "utkinect", "msr", "precog", "ntu", "nite", "oni", "radhar"} <= prefixes
    assert {"c3d", "trc", "table"} <= prefixes
    assert {"config", "field", "dataset", "experiment"} <= prefixes
    fields = " ".join(NAMES)
    for section in ("prf", "carrier", "target", "gate", "window", "gap", "seed", "noise"):
        assert section in fields
    for part in ("fmcw", "cw-", "randomize-", "sklearn"):
        assert part in fields, part
    for command in ("run", "show", "check", "dataset", "experiment", "kinect-info", "capture"):
        assert any(name.startswith(f"command-{command}-") for name in NAMES), command
    assert 330 <= len(NAMES) <= 370  # "about 350" in docs/input-rules.md


@pytest.mark.parametrize("name", NAMES)
def test_bad_input_case(
    name: str, corpus: dict[str, Case], capsys: pytest.CaptureFixture[str]
) -> None:
    case = corpus[name]
    folder = case.out.parent
    before = _files(folder)
    code = cli.main(list(case.argv))
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert code == 2, captured.err
    assert len(lines) == 1, captured.err
    assert lines[0].startswith("mdf: error: "), lines[0]
    for text in case.expect:
        assert text in lines[0], (text, lines[0])
    assert "Traceback" not in captured.err + captured.out
    # nothing half-written: no output folder contents, no stray files beside the inputs
    assert not case.out.exists() or not _files(case.out)
    assert _files(folder) == before


def test_the_examples_in_the_docs_are_real_messages(
    corpus: dict[str, Case], capsys: pytest.CaptureFixture[str]
) -> None:
    from conftest import ROOT

    page = (ROOT / "docs" / "input-rules.md").read_text()
    examples = [ln for ln in page.splitlines() if ln.startswith("mdf: error: ")]
    assert len(examples) == 3
    produced = []
    for name in ("bvh-coordinate-1e308", "field-prf-inf", "field-pulses-beyond-limit"):
        cli.main(list(corpus[name].argv))
        produced.append(capsys.readouterr().err.strip())
    for line in examples:
        where, rest = line.removeprefix("mdf: error: ").split(": ", 1)
        assert any(p.endswith(f"{Path(where).name}: {rest}") for p in produced), line
