"""Shared fixtures."""

from __future__ import annotations

import os

# One BLAS/OpenMP thread per process, set before numpy loads OpenBLAS (workers and the `mdf`
# processes that tests start inherit it): pytest-xdist already runs one worker per core, and a
# second BLAS thread per worker only contends for the same cores. On a loaded 2-core machine
# the FMCW angle scans (small complex matmuls) of one random scene took 100-120 s of CPU with
# OpenBLAS's threads against 23 s with one. The benchmarks set the same. An explicit setting
# in the environment wins.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from mdframework.cluster import SCHEDULER_ENV, SCHEDULER_TIMEOUT_ENV  # noqa: E402
from mdframework.progress import PROGRESS_ENV  # noqa: E402

# How commands print and where builds run, as the environment of whoever runs the tests may set
# it (MDF_PROGRESS=1 in a shell's profile failed 49 tests of five files on a command's stderr,
# MDF_DASK_TIMEOUT the test of its default, and MDF_DASK_SCHEDULER would send the tests' builds
# to that cluster): the tests' commands, here and in the processes they start, run without it;
# a test that needs one sets it itself.
for _var in (PROGRESS_ENV, SCHEDULER_ENV, SCHEDULER_TIMEOUT_ENV):
    os.environ.pop(_var, None)

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


@pytest.fixture
def rng() -> np.random.Generator:
    """One seeded source of randomness per test."""
    return np.random.default_rng(20150501)


def project_distributions() -> set[str]:
    """Names of the plugin distributions this repository ships (plugins/*/pyproject.toml)."""
    import tomllib

    return {
        tomllib.loads(p.read_text())["project"]["name"]
        for p in (ROOT / "plugins").glob("*/pyproject.toml")
    }


def third_party_entry_points() -> set[str]:
    """Names of the installed ``mdframework`` entry points that no distribution of this
    repository provides: a third party's plugins installed beside ours (our tests check our
    plugins and must pass whatever those are, broken ones included)."""
    import importlib.metadata
    import re

    def canonical(name: str) -> str:
        return re.sub(r"[-_.]+", "-", name).lower()

    own = {canonical(name) for name in project_distributions()}
    return {
        ep.name
        for ep in importlib.metadata.entry_points(group="mdframework")
        if ep.dist is None or canonical(ep.dist.name) not in own
    }


def without_third_party_warnings(lines: list[str], *keep: str) -> list[str]:
    """``lines`` (of stderr, or warning messages) less the warnings that a third party's plugin
    installed beside ours is disabled (a broken one warns in every command; tests are about
    ours and the ones they install, ``keep``)."""
    others = third_party_entry_points() - set(keep)
    return [line for line in lines if not any(f"plugin {n!r} is disabled" in line for n in others)]


@pytest.fixture
def only_our_plugins(monkeypatch: pytest.MonkeyPatch, fresh_default_registry: object) -> None:
    """Switch off the third parties' plugins installed beside ours (as ``--disable-plugin``
    does), for a test whose messages list the installed kinds."""
    from mdframework.plugins import DISABLE_PLUGINS_ENV

    disabled = [os.environ.get(DISABLE_PLUGINS_ENV, ""), *sorted(third_party_entry_points())]
    monkeypatch.setenv(DISABLE_PLUGINS_ENV, ",".join(name for name in disabled if name))


#: Units of ``--dist loadscope`` (a test class, else a file) that take longest, in the order they
#: start: the random-scene classes (20-60 s of CPU each), the documented commands (each a class of
#: its own; the experiments take 5-25 s) and the files that start many `mdf` processes. pytest-xdist
#: hands the next unit to whichever worker is free, so the long ones must come first or one of
#: them ends the run alone on one worker while the other waits (it did: the last 57 s of a
#: 215 s run). pyproject.toml turns off xdist's own reordering (by tests per unit), which put
#: these one-test units last.
LONG_UNITS = (
    "test_random_scenes.py::TestRandomBodyScenes",
    "test_random_scenes.py::TestRandomPointScenes",
    "::TestDocumentedCommand",
    "test_outputs.py",
    "test_cli.py",
    "test_docs.py",
    "test_docs_numbers.py",
)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The :data:`LONG_UNITS` first, in that order; every other test keeps its order, and each
    file its worker."""

    def rank(item: pytest.Item) -> int:
        return next((i for i, u in enumerate(LONG_UNITS) if u in item.nodeid), len(LONG_UNITS))

    items.sort(key=rank)


@pytest.fixture
def clean_modules() -> object:
    """Forget the modules a test imported from the distributions it made (``mdf_test*``)."""
    import sys

    before = set(sys.modules)
    yield None
    for name in set(sys.modules) - before:
        if name.startswith("mdf_test"):
            del sys.modules[name]


@pytest.fixture
def fresh_default_registry() -> object:
    """Rebuild the process's default registry around a test (which changes the environment)."""
    from mdframework.plugins import reset_default_registry

    reset_default_registry()
    yield None
    reset_default_registry()


@pytest.fixture
def start_method(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> object:
    """Worker processes start by ``request.param`` (``fork``, ``spawn``, ``forkserver``; use
    with indirect parametrization): ``MDF_START_METHOD`` says so, and so does Python's default
    (for any pool that would not ask mdf)."""
    import multiprocessing

    from mdframework.workers import START_METHOD_ENV

    method = request.param
    monkeypatch.setenv(START_METHOD_ENV, method)
    before = multiprocessing.get_start_method(allow_none=True)
    multiprocessing.set_start_method(method, force=True)
    yield method
    multiprocessing.set_start_method(before, force=True)
