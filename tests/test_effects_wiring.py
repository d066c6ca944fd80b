"""Effects run only when the scene names them, in order, and are recorded in the metadata."""

from __future__ import annotations

from types import ModuleType
from typing import Any, Literal

import numpy as np
import pytest
import synthetic

from mdframework import Effect, PluginConfig, Received, Scatterers, SceneContext, hookimpl
from mdframework.config import validate_run_config
from mdframework.pipeline import simulate
from mdframework.plugins import Registry, build_registry


class ExplodeConfig(PluginConfig):
    kind: Literal["explode"] = "explode"


class Explode(Effect):
    """Fails if it is ever constructed or called."""

    name = "explode"
    Config = ExplodeConfig
    stage = "received"

    def __init__(self, config: PluginConfig) -> None:
        raise AssertionError("an effect the scene does not name was constructed")

    def apply(self, data: Any, context: SceneContext) -> Any:
        raise AssertionError("an effect the scene does not name was applied")


class ScaleConfig(PluginConfig):
    kind: Literal["scale_rcs"] = "scale_rcs"
    factor: float = 4.0


class ScaleRcs(Effect):
    """Multiplies every RCS by a factor."""

    name = "scale_rcs"
    Config = ScaleConfig
    stage = "scatterers"

    def apply(self, data: Scatterers, context: SceneContext) -> Scatterers:
        return data.replace(rcs=data.rcs * self.config.factor)  # type: ignore[attr-defined]


class NoiseConfig(PluginConfig):
    kind: Literal["unit_noise"] = "unit_noise"


class UnitNoise(Effect):
    """Adds complex noise from the context's generator."""

    name = "unit_noise"
    Config = NoiseConfig
    stage = "received"

    def apply(self, data: Received, context: SceneContext) -> Received:
        n = data.signal.shape
        noise = context.rng.normal(size=n) + 1j * context.rng.normal(size=n)
        return Received(data.signal + 1e-9 * noise, data.range_time, data.range_axis)


@hookimpl
def mdframework_register_effects() -> list[type[Effect]]:
    return [Explode, ScaleRcs, UnitNoise]


@pytest.fixture(scope="module")
def registry() -> Registry:
    module = ModuleType("test_effects")
    module.mdframework_register_effects = mdframework_register_effects  # type: ignore[attr-defined]
    return build_registry([synthetic, module], autoload=True)


def run(registry: Registry, effects: list[dict[str, Any]], seed: int = 0) -> Any:
    cfg = {"motion": {"kind": "synthetic_walker", "length": 1.0}, "effects": effects, "seed": seed}
    return simulate(validate_run_config(cfg, registry=registry), registry)


def test_effects_not_named_do_no_work(registry: Registry) -> None:
    res = run(registry, [])
    assert res.metadata["effects"] == []


def test_scatterer_effect_scales_amplitude_and_is_recorded(registry: Registry) -> None:
    plain = run(registry, [])
    scaled = run(registry, [{"kind": "scale_rcs", "factor": 4.0}])
    assert np.allclose(scaled.received.signal, 2.0 * plain.received.signal, rtol=1e-12)
    assert scaled.metadata["effects"] == [
        {"kind": "scale_rcs", "stage": "scatterers", "factor": 4.0}
    ]


def test_received_effect_is_seeded(registry: Registry) -> None:
    a = run(registry, [{"kind": "unit_noise"}], seed=1)
    b = run(registry, [{"kind": "unit_noise"}], seed=1)
    c = run(registry, [{"kind": "unit_noise"}], seed=2)
    assert np.array_equal(a.received.signal, b.received.signal)
    assert not np.array_equal(a.received.signal, c.received.signal)
    assert [e["kind"] for e in a.metadata["effects"]] == ["unit_noise"]
