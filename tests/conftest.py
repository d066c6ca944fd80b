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
