"""Shared fixtures."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

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
