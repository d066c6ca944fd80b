"""Every installed plugin passes its interface's contract (the public suite in
mdframework.testing), and the suite catches broken plugins."""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
import pytest
from conftest import EXAMPLES, project_distributions

from mdframework.config import load_run_config
from mdframework.interfaces import Effect, PluginConfig, Received, Scatterers, SceneContext
from mdframework.pipeline import build_stages
from mdframework.plugins import INTERFACES, default_registry
from mdframework.testing import (
    check_effect,
    check_plugin,
    check_plugin_class,
    check_radar_waveform,
    parametrize_with_checks,
    plugin_checks,
)

REGISTRY = default_registry()
OWN = project_distributions()

#: an example config that uses each of the project's motion sources (every one must have one)
SOURCE_EXAMPLES = {
    "boulic": "boulic_walk.toml",
    "bvh": "bvh_mixamo.toml",
    "cmu": "cmu_walk.toml",
    "kinect": "kinect_utkinect_walk.toml",
    "point_targets": "point_target.toml",
}
#: a recording each of the project's recording sources reads in its contract check
RECORDING_EXAMPLES = {"radhar": {"file": "data/radhar/radhar_walk_subset.npz"}}
#: configs for plugins whose default Config is not the one to check
CONFIGS: dict[tuple[str, str], dict[str, Any]] = {
    ("scatterers", "points"): {"body": True},
    ("classifier", "sklearn"): {"estimator": "sklearn.svm.SVC"},
}


def _instance(interface: str, name: str) -> Any:
    """The plugin to check: motion sources as their example configs say (they need files),
    the others with their default config."""
    info = REGISTRY.plugins[interface][name]
    if interface == "motion" and info.provider.split()[0] in OWN:
        assert name in SOURCE_EXAMPLES, f"add an example using the {name!r} source"
        return build_stages(load_run_config(EXAMPLES / SOURCE_EXAMPLES[name])).source
    cls: Any = info.cls
    if interface == "recording" and info.provider.split()[0] in OWN:
        assert name in RECORDING_EXAMPLES, f"add an example recording for the {name!r} source"
        section = {"kind": name, **RECORDING_EXAMPLES[name]}
        return cls(cls.Config.model_validate(section, context={"base_dir": EXAMPLES}))
    return cls(cls.Config(**CONFIGS.get((interface, name), {})))


PLUGINS = [_instance(i, n) for i in INTERFACES for n in REGISTRY.names(i)]


@parametrize_with_checks(PLUGINS)
def test_installed_plugin_contract(plugin: Any, check: Any) -> None:
    check(plugin)


def test_every_interface_has_checks_beyond_the_class() -> None:
    for interface in INTERFACES:
        name = REGISTRY.names(interface)[0]
        assert len(plugin_checks(REGISTRY.get(interface, name))) >= 3, interface


class ReturnsConfig(PluginConfig):
    """Nothing to configure."""

    kind: Literal["returns"] = "returns"


class _Returns(Effect):
    """An effect whose apply returns what ``result`` says (for the checks' own test)."""

    name = "returns"
    stage = "received"
    Config = ReturnsConfig

    result: Any = None

    def apply(self, data: Any, context: SceneContext) -> Any:
        return self.result(data) if callable(self.result) else self.result


def test_the_suite_catches_an_effect_that_returns_none() -> None:
    class NoneEffect(_Returns):
        """Forgets to return the data."""

    with pytest.raises(AssertionError, match=r"must return Received, got None"):
        check_effect(NoneEffect(NoneEffect.Config()))


def test_the_suite_catches_an_effect_that_drops_pulses_or_is_not_seeded() -> None:
    class Drops(_Returns):
        """Returns half the pulses."""

        result = staticmethod(lambda r: Received(r.signal[::2]))

    with pytest.raises(AssertionError, match="one sample per pulse"):
        check_effect(Drops(Drops.Config()))

    class Unseeded(_Returns):
        """Draws noise from a global generator instead of the context's."""

        rng = np.random.default_rng()
        result = staticmethod(lambda r: Received(r.signal + Unseeded.rng.normal()))

    with pytest.raises(AssertionError, match="same seed must give the same output"):
        check_effect(Unseeded(Unseeded.Config()))

    class WrongStage(_Returns):
        """Declares the scatterers stage but returns a Received."""

        stage = "scatterers"  # type: ignore[assignment]
        result = staticmethod(lambda s: Received(np.zeros(s.positions.shape[0], complex)))

    with pytest.raises(AssertionError, match="must return Scatterers"):
        check_effect(WrongStage(WrongStage.Config()))
    assert Scatterers  # the type the scatterers stage must return


def test_the_suite_names_the_plugin_and_the_failing_check() -> None:
    class NoneEffect(_Returns):
        """Forgets to return the data."""

    with pytest.raises(AssertionError, match=r"NoneEffect \('returns'\) fails check_effect"):
        check_plugin(NoneEffect(NoneEffect.Config()))


def test_the_contracts_catch_broken_waveforms() -> None:
    """A waveform with the wrong Doppler sign, one that is not linear in the scatterers, and a
    config whose kind is not its name."""
    from mdf_lfm import LfmPulseDoppler

    class Flipped(LfmPulseDoppler):
        """Conjugates its output: approaching targets come out negative."""

        def receive(self, ranges: Any, rcs: Any, gate_range: Any) -> Received:
            return Received(np.conj(super().receive(ranges, rcs, gate_range).signal))

    with pytest.raises(AssertionError, match="approaching target must show"):
        check_radar_waveform(Flipped(Flipped.Config()))

    class Squared(LfmPulseDoppler):
        """Squares the magnitude of the sum: not a superposition."""

        def receive(self, ranges: Any, rcs: Any, gate_range: Any) -> Received:
            y = super().receive(ranges, rcs, gate_range).signal
            return Received(y * np.abs(y))

    with pytest.raises(AssertionError, match="sum of their returns"):
        check_radar_waveform(Squared(Squared.Config()))

    class Misnamed(LfmPulseDoppler):
        """Registered as 'lfm2' but its config says kind = 'lfm'."""

        name = "lfm2"

    with pytest.raises(AssertionError, match=r"Config\.kind must be Literal\['lfm2'\]"):
        check_plugin_class(Misnamed, "radar")
