"""Effects run only when the scene names them, in order, and are recorded in the metadata."""

from __future__ import annotations

import dataclasses
from types import ModuleType
from typing import Any, ClassVar, Literal

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


class ApproachConfig(PluginConfig):
    kind: Literal["approach"] = "approach"
    speed: float = 2.0
    how: Literal["dataclasses", "method", "new"] = "dataclasses"


class Approach(Effect):
    """Moves every scatterer toward the radar along the x axis at ``speed`` [m/s], writing the
    copy in one of three ways an author may choose."""

    name = "approach"
    Config = ApproachConfig
    stage = "scatterers"

    def apply(self, data: Scatterers, context: SceneContext) -> Scatterers:
        c: Any = self.config
        moved = data.positions.copy()
        moved[..., 0] += c.speed * context.pulse_times[:, None]
        if c.how == "dataclasses":
            return dataclasses.replace(data, positions=moved)
        if c.how == "method":
            return data.replace(positions=moved)
        return Scatterers(moved, data.rcs, data.names, data.semi_axes, data.axes)


class ProbeConfig(PluginConfig):
    kind: Literal["probe"] = "probe"
    label: str = ""


class Probe(Effect):
    """Draws five normal numbers from its generator and records them under its label."""

    name = "probe"
    Config = ProbeConfig
    stage = "received"
    drawn: ClassVar[dict[str, np.ndarray]] = {}

    def apply(self, data: Received, context: SceneContext) -> Received:
        Probe.drawn[self.config.label] = context.rng.standard_normal(5)  # type: ignore[attr-defined]
        return data


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
    return [Explode, ScaleRcs, Approach, Probe, UnitNoise]


@pytest.fixture(scope="module")
def registry() -> Registry:
    module = ModuleType("test_effects")
    module.mdframework_register_effects = mdframework_register_effects  # type: ignore[attr-defined]
    return build_registry([synthetic, module], autoload=True)


def run(registry: Registry, effects: list[dict[str, Any]], seed: int = 0, **more: Any) -> Any:
    cfg = {"motion": {"kind": "synthetic_walker", "length": 1.0}, "effects": effects, "seed": seed}
    cfg.update(more)
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


def mean_velocity(result: Any) -> float:
    """Power-weighted mean radial velocity of a run's spectrogram [m/s]."""
    p = result.spectrogram.power.astype(np.float64)
    return float((p * result.velocity[:, None]).sum() / p.sum())


@pytest.mark.parametrize("how", ["dataclasses", "method"])
def test_an_effect_that_moves_scatterers_is_seen_however_it_copies_them(
    registry: Registry, how: str
) -> None:
    """The ellipsoid model hands on the ranges it computed; an effect that moves the scatterers
    must not get those old ranges back, whether it copies with ``dataclasses.replace`` or
    ``Scatterers.replace``: the radar sees exactly what a freshly built ``Scatterers`` (no
    ranges remembered) gives, and the body's mean Doppler velocity rises by the 2 m/s added
    along x, times the cosine of the radar's elevation (it is 10 m down the x axis, 2 m up). The
    range gate follows the body, not the moved points, so it passes every range (phase_only)."""
    radar = {"kind": "lfm", "gate_response": "phase_only"}
    plain = run(registry, [], radar=radar)
    fresh = run(registry, [{"kind": "approach", "how": "new"}], radar=radar)
    moved = run(registry, [{"kind": "approach", "how": how}], radar=radar)
    assert np.array_equal(moved.received.signal, fresh.received.signal)
    expected = 2.0 * 10.0 / np.hypot(10.0, 2.0)
    assert mean_velocity(moved) - mean_velocity(plain) == pytest.approx(expected, abs=0.03)


def test_remembered_ranges_belong_to_the_positions_they_were_computed_from() -> None:
    """Ranges a model hands on are returned for its own positions and radar position only."""
    rng = np.random.default_rng(3)
    pos = rng.normal(size=(5, 4, 3))
    radar = np.array([10.0, 0.0, 2.0])
    exact = np.linalg.norm(pos - radar, axis=-1)
    marked = exact + 1.0  # not the true ranges, so that a use of them shows
    scat = Scatterers(pos, np.ones((5, 4)), tuple("abcd")).with_ranges(radar, marked)
    assert scat.ranges(radar) is marked
    assert np.array_equal(dataclasses.replace(scat, rcs=2 * scat.rcs).ranges(radar), marked)
    assert np.array_equal(scat.ranges(radar + 1.0), np.linalg.norm(pos - radar - 1.0, axis=-1))
    for copy in (dataclasses.replace(scat, positions=pos.copy()), scat.replace(positions=pos + 0)):
        assert copy.range_cache is None
        assert np.allclose(copy.ranges(radar), exact, rtol=0, atol=1e-12)


def draws(registry: Registry, labels: list[str], seed: int = 5, **more: Any) -> dict[str, Any]:
    """What each probe effect drew in a run listing them (after ``more`` effects)."""
    Probe.drawn = {}
    effects = [*more.get("before", []), *({"kind": "probe", "label": x} for x in labels)]
    run(registry, effects, seed=seed)
    return dict(Probe.drawn)


def test_each_effect_draws_from_its_own_stream(registry: Registry) -> None:
    """Listing an effect before another leaves the other's draws as they were (it used to share
    one generator, so the second effect drew what the first left); two effects draw different
    numbers; a scatterer-stage effect before them changes nothing."""
    alone = draws(registry, ["b"])["b"]
    both = draws(registry, ["a", "b"])
    assert np.array_equal(both["b"], alone)
    assert not np.any(np.isin(both["a"], alone))
    three = draws(registry, ["c", "a", "b"])
    assert np.array_equal(three["b"], alone) and np.array_equal(three["a"], both["a"])
    after_scatterers = draws(registry, ["b"], before=[{"kind": "scale_rcs"}])
    assert np.array_equal(after_scatterers["b"], alone)


def test_a_lone_effect_draws_what_it_always_drew(registry: Registry) -> None:
    """A run with one effect keeps its stream: the first child of the run seed's SeedSequence,
    so every published number made with one random effect stays as it was."""
    for seed in (0, 5, 2**63 + 1):
        expected = np.random.default_rng(np.random.SeedSequence(seed).spawn(2)[0])
        assert np.array_equal(draws(registry, ["x"], seed)["x"], expected.standard_normal(5))


def test_refuse_listed_after_names_both_places_and_refuses_a_list_without_the_effect() -> None:
    """Effect.refuse_listed_after (for a plugin's check_effects): one line naming both places
    in the list when a named effect comes later; a list that does not hold the effect itself
    (a caller's bug) is a ValueError saying so, not a bare StopIteration."""
    from mdframework.errors import SceneError

    first, second = ScaleRcs(ScaleConfig()), ScaleRcs(ScaleConfig())
    second.name = "later"
    with pytest.raises(SceneError) as info:
        first.refuse_listed_after([first, second], {"later": "the later one would miss it"})
    assert str(info.value) == (
        "effects: scale_rcs (effects[0]) is listed before later (effects[1]), so the later one "
        "would miss it: list scale_rcs after later"
    )
    first.refuse_listed_after([second, first], {"later": "x"})  # listed after: fine
    # the place of this very effect counts, not that of another of its kind; nor is an
    # effect listed after itself
    again = ScaleRcs(ScaleConfig())
    again.refuse_listed_after([first, second, again], {"later": "x"})
    first.refuse_listed_after([first], {"scale_rcs": "x"})
    with pytest.raises(ValueError, match="effect 'scale_rcs' is not in the list"):
        first.refuse_listed_after([second], {"later": "x"})
