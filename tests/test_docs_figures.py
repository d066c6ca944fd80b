"""The figures of docs/figures: each shown by a page and made by a script, and the scripts that
make them still run and draw figures of the shipped ones' size."""

from __future__ import annotations

import importlib.util
import os
import re
import sys
import types
from pathlib import Path

import pytest
from conftest import ROOT

FIGURES = ROOT / "docs" / "figures"
#: the scripts that write into docs/figures
MAKERS = sorted((ROOT / "docs").glob("make_*.py")) + sorted((ROOT / "benchmarks").glob("*.py"))


def _script(path: Path) -> types.ModuleType:
    """A docs or benchmark script, imported (not run)."""
    name = f"mdf_docs_figures_{path.stem}"
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up
    environ = dict(os.environ)  # the benchmarks pin BLAS threads when imported
    try:
        spec.loader.exec_module(module)
    finally:
        os.environ.clear()
        os.environ.update(environ)
    return module


def _shown() -> dict[str, list[str]]:
    """Figure file name -> the docs pages that embed it."""
    shown: dict[str, list[str]] = {}
    for page in [*sorted((ROOT / "docs").glob("*.md")), ROOT / "README.md"]:
        for name in re.findall(r"\]\((?:docs/)?figures/([\w.-]+)\)", page.read_text()):
            shown.setdefault(name, []).append(page.name)
    return shown


def _png_shape(path: Path) -> tuple[int, int]:
    """(width, height) of a PNG [pixels]."""
    from PIL import Image

    with Image.open(path) as image:
        return image.size


def test_every_figure_is_shown_by_a_page_and_made_by_a_script() -> None:
    """Each file of docs/figures is embedded by a docs page and named by a script that makes it
    (three were shown nowhere, a stale figure no script made would be checked by nothing); each
    figure a page embeds exists."""
    shipped = {p.name for p in FIGURES.iterdir()}
    assert len(shipped) >= 15
    shown = _shown()
    assert sorted(shipped - set(shown)) == [], "in docs/figures, shown by no page"
    assert sorted(set(shown) - shipped) == [], "shown by a page, not in docs/figures"
    sources = {path.relative_to(ROOT).as_posix(): path.read_text() for path in MAKERS}
    for name in sorted(shipped):
        makers = [where for where, text in sources.items() if f'"{name}"' in text]
        assert makers, f"{name}: no script in docs/ or benchmarks/ makes it"


def _named(path: Path) -> list[str]:
    """The files of docs/figures that a script names."""
    text = path.read_text()
    return sorted(p.name for p in FIGURES.iterdir() if f'"{p.name}"' in text)


@pytest.mark.parametrize(
    "name",
    [
        "make_figures",
        "make_preview_figures",
        "make_effects_figures",
        "make_fmcw_figures",
        "make_kinect_figure",
        "make_validation_figures",
    ],
)
def test_each_docs_script_draws_the_figures_it_ships(name: str, tmp_path: Path) -> None:
    """``docs/<name>.py`` run into a scratch folder (``main(folder)``) writes exactly the files of
    docs/figures it names, each of the shipped one's size in pixels (its panels and layout).
    make_reproduction_figures.py's copies are checked where test_docs_numbers.py runs its
    experiments."""
    path = ROOT / "docs" / f"{name}.py"
    module = _script(path)
    target = getattr(module, "TARGET", None)
    module.main(tmp_path / target.name if target is not None else tmp_path)
    made = sorted(p.name for p in tmp_path.iterdir())
    assert made == _named(path)
    for figure in made:
        assert _png_shape(tmp_path / figure) == _png_shape(FIGURES / figure), figure


def test_the_accuracy_figure_is_the_one_drawn_from_the_pages_results(tmp_path: Path) -> None:
    """docs/figures/accuracy_time_vs_error.png has the size of the figure bench_accuracy.py draws
    from docs/data/accuracy_results.json (the numbers of docs/accuracy.md): one panel per scene
    with a spectrogram error (the FMCW walk's ladder, the maps' error, is not drawn)."""
    import json

    from mdframework.figures import DPI

    module = _script(ROOT / "benchmarks" / "bench_accuracy.py")
    results = json.loads((ROOT / "docs" / "data" / "accuracy_results.json").read_text())
    module.write_outputs(results, tmp_path)
    shipped = _png_shape(module.DOCS_FIGURE)
    assert shipped == _png_shape(tmp_path / "time_vs_error.png")
    scenes = {r["scene"] for r in results["rows"] if r["map_err"] is None}
    assert scenes == {"boulic", "cmu_run_09_06", "kinect_walk"}
    assert shipped[0] == round(5.2 * len(scenes) * DPI)  # 5.2 in a panel


def test_the_sim_to_real_figure_is_drawn_by_its_benchmark(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """bench_sim2real.py's histogram figure (the benchmark takes minutes: its dataset is replaced
    by three classes' mean histograms) draws, at the shipped figure's size, one panel per class
    with the real and the simulated bars, each class's shares where they were put."""
    import numpy as np

    module = _script(ROOT / "benchmarks" / "bench_sim2real.py")
    velocity = (np.arange(17) - 8) * 0.61466867
    shares = {
        group: {c: np.eye(17)[k + (group == module.SIM)] for k, c in enumerate(("a", "b", "c"))}
        for group in (module.REAL, module.SIM)
    }
    monkeypatch.setattr(module, "mean_histograms", lambda path, group: shares[group])
    monkeypatch.setattr(
        module, "load_dataset", lambda *a, **k: types.SimpleNamespace(velocity=velocity)
    )
    drawn: list[object] = []
    import mdframework.figures as figures

    original = figures.save

    def keep(fig: object, path: Path, caption: str = "", **kw: object) -> None:
        drawn.append(fig)
        original(fig, path, caption, **kw)

    monkeypatch.setattr(figures, "save", keep)
    module.plot_histograms(tmp_path / "ds", tmp_path / "h.png")
    assert _png_shape(tmp_path / "h.png") == _png_shape(module.DOCS_FIGURE)
    [fig] = drawn
    axes = fig.axes  # type: ignore[attr-defined]
    assert [ax.get_title() for ax in axes] == ["a", "b", "c"]
    for k, ax in enumerate(axes):
        real, sim = ax.containers
        assert np.argmax([b.get_height() for b in real]) == k
        assert np.argmax([b.get_height() for b in sim]) == k + 1
