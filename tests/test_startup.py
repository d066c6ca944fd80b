"""Lazy start: commands import only what they use (checked with ``python -X importtime``).

``mdf --help``, ``mdf plugins``, ``mdf config schema`` and ``mdf check`` load every installed
plugin (to list them, build the schema, add their commands) yet import none of the heavy
libraries; a point-target run imports matplotlib for its figure and nothing else heavy. Timing
is measured by ``benchmarks/bench_startup.py``, never here.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import EXAMPLES

HEAVY = {"sklearn", "mujoco", "matplotlib", "dask", "distributed", "openni"}


def imported_modules(args: list[str]) -> set[str]:
    """Modules imported by ``mdf ARGS``, from ``python -X importtime``'s report."""
    proc = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "mdframework.cli", *args],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    rows = [line.rsplit("|", 1)[-1].strip() for line in proc.stderr.splitlines() if "|" in line]
    assert len(rows) > 100, "python -X importtime reported nothing"
    return set(rows)


def top_level(modules: set[str]) -> set[str]:
    """The top-level packages of ``modules``."""
    return {name.split(".")[0] for name in modules}


@pytest.mark.parametrize(
    "args",
    [["--help"], ["plugins"], ["config", "schema"], ["check", str(EXAMPLES / "cmu_walk.toml")]],
    ids=["help", "plugins", "schema", "check"],
)
def test_listing_commands_import_no_heavy_library(args: list[str]) -> None:
    imported = top_level(imported_modules(args))
    assert "mdf_mujoco" in imported and "mdf_knn" in imported  # the plugins were loaded ...
    assert imported & HEAVY == set()  # ... without their heavy dependencies


def test_a_point_target_run_imports_only_matplotlib_of_the_heavy_libraries(
    tmp_path: Path,
) -> None:
    modules = imported_modules(
        ["run", str(EXAMPLES / "point_target.toml"), "--out", str(tmp_path / "o")]
    )
    assert (tmp_path / "o" / "spectrogram.png").exists()
    assert top_level(modules) & HEAVY == {"matplotlib"}
    assert "scipy.fft" in modules  # but not scipy.signal (windows) or scipy.stats
    assert not {"scipy.signal", "scipy.stats"} & modules
    # constant-velocity targets are resampled linearly (exact): no spline library; and the
    # run's figure is a bare Figure: no pyplot
    assert not {"scipy.interpolate", "matplotlib.pyplot"} & modules


def test_an_fmcw_run_imports_neither_scipy_signal_nor_scipy_stats(tmp_path: Path) -> None:
    """The FMCW preset's frames have gaps, so its spectrogram is one Doppler spectrum per frame,
    windowed like the STFT (its cosine windows from numpy, not scipy.signal)."""
    modules = imported_modules(
        ["run", str(EXAMPLES / "fmcw_walk.toml"), "--out", str(tmp_path / "o"), "--no-figures"]
    )
    assert "mdf_fmcw.waveform" in modules  # the FMCW radar ran
    assert top_level(modules) & HEAVY == set()
    assert not {"scipy.signal", "scipy.stats"} & modules


def test_a_run_without_figures_imports_no_heavy_library(tmp_path: Path) -> None:
    modules = imported_modules(
        ["run", str(EXAMPLES / "point_target.toml"), "--out", str(tmp_path / "o"), "--no-figures"]
    )
    written = {p.name for p in (tmp_path / "o").iterdir() if not p.name.startswith(".")}
    assert written == {"result.npz", "features.json", "config.resolved.json", "metadata.json"}
    assert top_level(modules) & HEAVY == set()
    assert "yaml" not in modules  # PyYAML only for a YAML config
    resolved = json.loads((tmp_path / "o" / "config.resolved.json").read_text())
    assert resolved["figures"]["enabled"] is False  # recorded with the run
