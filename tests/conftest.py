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


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The documented commands first (tests/test_docs.py): under ``--dist loadscope`` each is a
    unit of its own that pytest-xdist sends to whichever worker is free, and the long ones
    (experiments, dataset builds) finish last on one worker unless they start early. Every
    other test keeps its order, and each file its worker."""
    items.sort(key=lambda item: 0 if "::TestDocumentedCommand" in item.nodeid else 1)
