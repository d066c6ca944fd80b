"""The template's own tests: the contract suite, then what each plugin computes."""

from __future__ import annotations

import numpy as np
import pytest
from mdf_template import Gain, Pendulum
from mdf_template.source import GRAVITY

from mdframework import Received
from mdframework.testing import parametrize_with_checks, scene_context


@parametrize_with_checks([Pendulum, Gain, Gain(Gain.Config(gain_db=-30.0))])
def test_contract(plugin: object, check: object) -> None:
    check(plugin)  # type: ignore[operator]


def test_pendulum_swings_at_sqrt_g_over_l() -> None:
    """The bob returns to its start after one period 2 pi sqrt(L / g) and is lowest (z = pivot
    - L) when it crosses the vertical, a quarter period after the start."""
    length = 0.5
    motion = Pendulum(Pendulum.Config(length=length, frame_rate=1000.0)).load()
    period = 2 * np.pi * np.sqrt(length / GRAVITY)
    t = motion.skeleton.time
    bob = motion.skeleton.positions[:, 0, :]
    k = int(np.argmin(np.abs(t - period)))
    assert np.allclose(bob[k], bob[0], atol=2e-3)
    q = int(np.argmin(np.abs(t - period / 4)))
    assert bob[q, 2] == pytest.approx(2.0 - length, abs=1e-4)
    assert bob[q, 0] == pytest.approx(10.0, abs=5e-3)


def test_gain_scales_power_by_gain_db() -> None:
    context = scene_context()
    signal = np.exp(1j * np.linspace(0, 6, context.pulse_times.size))
    out = Gain(Gain.Config(gain_db=20.0)).apply(Received(signal), context)
    ratio_db = 10 * np.log10(np.mean(np.abs(out.signal) ** 2) / np.mean(np.abs(signal) ** 2))
    assert ratio_db == pytest.approx(20.0, abs=1e-12)
