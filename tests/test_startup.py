"""Lazy start: commands import only what they use (checked with ``python -X importtime``).

``mdf --help``, ``mdf plugins``, ``mdf config schema`` and ``mdf check`` load every plugin of
this project (to list them, build the schema, add their commands) yet import none of the heavy
libraries; a point-target run imports matplotlib for its figure and nothing else heavy. A third
party's plugin installed beside ours is disabled in these commands (what it imports is its own
affair), and a failure names the module that imported each heavy library. Timing is measured
by ``benchmarks/bench_startup.py``, never here.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import EXAMPLES, third_party_entry_points

from mdframework.plugins import DISABLE_PLUGINS_ENV

HEAVY = {"sklearn", "mujoco", "matplotlib", "dask", "distributed", "openni"}


def imported_modules(args: list[str]) -> dict[str, str | None]:
    """Modules imported by ``mdf ARGS`` with this project's plugins only (a third party's plugin
    installed beside ours is disabled), each with the module that imported it
    (:func:`importers`)."""
    env = dict(os.environ)
    disabled = [env.get(DISABLE_PLUGINS_ENV, ""), *sorted(third_party_entry_points())]
    env[DISABLE_PLUGINS_ENV] = ",".join(name for name in disabled if name)
    proc = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "mdframework.cli", *args],
        capture_output=True,
        text=True,
        check=False,
        env=env,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    modules = importers(proc.stderr)
    assert len(modules) > 100, "python -X importtime reported nothing"
    return modules


def importers(report: str) -> dict[str, str | None]:
    """Each module in ``python -X importtime``'s ``report`` with the module whose import
    imported it (None: imported by a function as the program ran, not by a module's import).
    The report lists a module's own imports before it, indented one step further."""
    rows = []
    for line in report.splitlines():
        if line.startswith("import time:") and line.count("|") == 2:
            field = line.rsplit("|", 1)[-1]
            rows.append((len(field) - len(field.lstrip()), field.strip()))
    found: dict[str, str | None] = {}
    for i, (depth, name) in enumerate(rows):
        parent = next((n for d, n in rows[i + 1 :] if d < depth), None)
        found.setdefault(name, parent)
    return found


def top_level(modules: dict[str, str | None]) -> set[str]:
    """The top-level packages of ``modules``."""
    return {name.split(".")[0] for name in modules}


def heavy(modules: dict[str, str | None], libraries: set[str] = HEAVY) -> dict[str, str]:
    """Each heavy library of ``modules`` with the module that imported it (the nearest importer
    outside the heavy libraries), so that a failure names the culprit."""
    found: dict[str, str] = {}
    for name in modules:
        top = name.split(".")[0]
        if top not in libraries or top in found:
            continue
        who: str | None = name
        while who is not None and who.split(".")[0] in libraries:
            who = modules.get(who)
        found[top] = who or "a function, as the program ran"
    return found


def test_a_heavy_import_is_traced_to_the_module_that_made_it(tmp_path: Path) -> None:
    """A module ``outer`` imports ``inner``, which imports ``wave`` (standing for a heavy
    library): the report's nesting names ``inner`` as the importer of ``wave`` and ``outer``
    as that of ``inner``; a heavy importer is passed over for the module that imported it."""
    (tmp_path / "outer.py").write_text("import inner\n")
    (tmp_path / "inner.py").write_text("import wave\n")
    proc = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", "import outer"],
        capture_output=True,
        text=True,
        check=True,
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(tmp_path)},
    )
    modules = importers(proc.stderr)
    assert modules["outer"] is None and modules["inner"] == "outer"
    assert modules["wave"] == "inner"
    assert heavy(modules, {"wave"}) == {"wave": "inner"}
    assert heavy(modules, {"wave", "inner"}) == {"wave": "outer", "inner": "outer"}
    assert heavy(modules, {"outer"}) == {"outer": "a function, as the program ran"}


@pytest.mark.parametrize(
    "args",
    [["--help"], ["plugins"], ["config", "schema"], ["check", str(EXAMPLES / "cmu_walk.toml")]],
    ids=["help", "plugins", "schema", "check"],
)
def test_listing_commands_import_no_heavy_library(args: list[str]) -> None:
    modules = imported_modules(args)
    imported = top_level(modules)
    assert "mdf_mujoco" in imported and "mdf_knn" in imported  # the plugins were loaded ...
    assert heavy(modules) == {}  # ... without their heavy dependencies


def test_a_point_target_run_imports_only_matplotlib_of_the_heavy_libraries(
    tmp_path: Path,
) -> None:
    modules = imported_modules(
        ["run", str(EXAMPLES / "point_target.toml"), "--out", str(tmp_path / "o")]
    )
    assert (tmp_path / "o" / "spectrogram.png").exists()
    assert set(heavy(modules)) == {"matplotlib"}, heavy(modules)
    assert "scipy.fft" in modules  # but not scipy.signal (windows) or scipy.stats
    assert not {"scipy.signal", "scipy.stats"} & modules.keys()
    # constant-velocity targets are resampled linearly (exact): no spline library; and the
    # run's figure is a bare Figure: no pyplot
    assert not {"scipy.interpolate", "matplotlib.pyplot"} & modules.keys()


def test_an_fmcw_run_imports_neither_scipy_signal_nor_scipy_stats(tmp_path: Path) -> None:
    """The FMCW preset's frames have gaps, so its spectrogram is one Doppler spectrum per frame,
    windowed like the STFT (its cosine windows from numpy, not scipy.signal)."""
    modules = imported_modules(
        ["run", str(EXAMPLES / "fmcw_walk.toml"), "--out", str(tmp_path / "o"), "--no-figures"]
    )
    assert "mdf_fmcw.waveform" in modules  # the FMCW radar ran
    assert heavy(modules) == {}
    assert not {"scipy.signal", "scipy.stats"} & modules.keys()


def test_a_run_without_figures_imports_no_heavy_library(tmp_path: Path) -> None:
    modules = imported_modules(
        ["run", str(EXAMPLES / "point_target.toml"), "--out", str(tmp_path / "o"), "--no-figures"]
    )
    written = {p.name for p in (tmp_path / "o").iterdir() if not p.name.startswith(".")}
    assert written == {"result.npz", "features.json", "config.resolved.json", "metadata.json"}
    assert heavy(modules) == {}
    assert "yaml" not in modules  # PyYAML only for a YAML config
    # the file readers of the motion formats the run does not read stay unimported (their
    # packages export them on first use; loading a plugin imports its source classes only)
    readers = {"mdf_c3d.reader", "mdf_c3d.trc", "mdf_table.reader", "mdf_deepmimic.reader"}
    readers |= {"mdf_cmu.bvh", "mdf_cmu.asfamc", "mdf_cmu.rigs"}
    readers |= {"mdf_kinect.formats", "mdf_kinect.nitefile", "mdf_kinect.device"}
    assert "mdf_c3d.source" in modules and not readers & modules.keys()
    resolved = json.loads((tmp_path / "o" / "config.resolved.json").read_text())
    assert resolved["figures"]["enabled"] is False  # recorded with the run
