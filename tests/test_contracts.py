"""Every installed plugin passes its interface's contract (the public suite in
mdframework.testing), and the suite catches broken plugins."""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pytest
from conftest import EXAMPLES, project_distributions
from helpers import walking_c3d

from mdframework.config import load_run_config
from mdframework.interfaces import Effect, PluginConfig, Received, Scatterers, SceneContext
from mdframework.physics import interpolation
from mdframework.pipeline import build_stages, place_body
from mdframework.plugins import INTERFACES, default_registry
from mdframework.skeleton import Skeleton
from mdframework.testing import (
    check_block_invariance,
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
    "deepmimic": "deepmimic_walk.toml",
    "kinect": "kinect_utkinect_walk.toml",
    "point_targets": "point_target.toml",
    "table": "table_utkinect_walk.toml",
    "trc": "trc_walk.toml",
}
#: motion sources checked on a file the test writes, because no real recording recorded by
#: others that they can map onto the whole body is shipped: the one public C3D file in
#: examples/data/c3d has no arm or head markers (tests/test_c3d.py checks physics on it)
WRITTEN_SOURCE_FILES = {"c3d": lambda folder: walking_c3d(folder / "walk.c3d")}
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
    if interface == "motion" and name in WRITTEN_SOURCE_FILES:
        path = WRITTEN_SOURCE_FILES[name](Path(tempfile.mkdtemp(prefix=f"contract-{name}-")))
        cls0: Any = info.cls
        return cls0(cls0.Config(file=path))
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

        def receive(self, block: Any) -> Received:
            return Received(np.conj(super().receive(block).signal))

    with pytest.raises(AssertionError, match="approaching target must show"):
        check_radar_waveform(Flipped(Flipped.Config()))

    class Squared(LfmPulseDoppler):
        """Squares the magnitude of the sum: not a superposition."""

        def receive(self, block: Any) -> Received:
            y = super().receive(block).signal
            return Received(y * np.abs(y))

    with pytest.raises(AssertionError, match="sum of their returns"):
        check_radar_waveform(Squared(Squared.Config()))

    class Misnamed(LfmPulseDoppler):
        """Registered as 'lfm2' but its config says kind = 'lfm'."""

        name = "lfm2"

    with pytest.raises(AssertionError, match=r"Config\.kind must be Literal\['lfm2'\]"):
        check_plugin_class(Misnamed, "radar")


@pytest.fixture(scope="module")
def placed_body() -> tuple[Any, Skeleton]:
    config = load_run_config(EXAMPLES / "cmu_walk.toml")
    motion = build_stages(config).source.load()
    body = place_body(motion.canonical(), config.scene.person, np.array([10.0, 0.0, 1.0]))
    t = interpolation.pulse_times(body.time[0], body.time[0] + 1.0, 2400.0)
    joints = interpolation.resample_tracks(body.time, body.positions, body.valid, t)
    return motion, Skeleton(t, joints, body.joint_names)


def _model(name: str) -> Any:
    cls: Any = REGISTRY.get("scatterers", name)
    return cls(cls.Config(body=True) if name == "points" else cls.Config())


@pytest.mark.parametrize("name", REGISTRY.names("scatterers"))
def test_scatterer_model_is_block_invariant(name: str, placed_body: tuple[Any, Skeleton]) -> None:
    """One block or blocks of 37 pulses give the same RCS and signal (streaming contract)."""
    motion, skeleton = placed_body
    lfm: Any = REGISTRY.get("radar", "lfm")
    check_block_invariance(_model(name), lfm(lfm.Config()), skeleton, motion)


@pytest.mark.parametrize("path", ["analytic", "raw"])
def test_waveform_paths_are_block_invariant(path: str, placed_body: tuple[Any, Skeleton]) -> None:
    motion, skeleton = placed_body
    short = skeleton.select_frames(slice(0, 300))
    lfm: Any = REGISTRY.get("radar", "lfm")
    check_block_invariance(_model("ellipsoid"), lfm(lfm.Config(path=path)), short, motion)


@pytest.mark.parametrize(
    ("kind", "fields"),
    [
        ("fmcw", {"beyond_max_range": "alias", "receiver_noise": True}),
        ("fmcw", {"beyond_max_range": "alias", "path": "raw"}),
        ("cw", {}),
    ],
)
def test_other_radars_are_block_invariant(
    kind: str, fields: dict[str, Any], placed_body: tuple[Any, Skeleton]
) -> None:
    """The FMCW radar (blocks of whole frames, receiver noise seeded per frame) and the CW
    radar pass the streaming contract."""
    motion, skeleton = placed_body
    short = skeleton.select_frames(slice(0, 480))
    cls: Any = REGISTRY.get("radar", kind)
    check_block_invariance(_model("ellipsoid"), cls(cls.Config(**fields)), short, motion)


SCATTERER_EFFECTS = [
    n for n in REGISTRY.names("effects") if REGISTRY.get("effects", n).stage == "scatterers"
]


@pytest.mark.parametrize("name", SCATTERER_EFFECTS)
def test_scatterer_effects_are_block_invariant(
    name: str, placed_body: tuple[Any, Skeleton]
) -> None:
    motion, skeleton = placed_body
    cls: Any = REGISTRY.get("effects", name)
    effect = cls(cls.Config())
    effect.start_record(skeleton, np.array([10.0, 0.0, 1.0]))
    lfm: Any = REGISTRY.get("radar", "lfm")
    check_block_invariance(_model("ellipsoid"), lfm(lfm.Config()), skeleton, motion, (effect,))


def test_block_invariance_check_catches_a_per_block_model(
    placed_body: tuple[Any, Skeleton],
) -> None:
    """A model that estimates the body height from each block (not the record) is caught."""
    from mdf_ellipsoid.model import EllipsoidBody

    from mdframework.physics import body as bodymodel

    class PerBlock(EllipsoidBody):
        """Re-estimates the height from every block."""

        def scatterers(self, motion: Any, skeleton: Skeleton, *args: Any) -> Any:
            self._a, self._semi_c = bodymodel.part_semi_axes(
                self._parts, bodymodel.estimate_height(skeleton.positions)
            )
            return super().scatterers(motion, skeleton, *args)

    motion, skeleton = placed_body
    lfm: Any = REGISTRY.get("radar", "lfm")
    with pytest.raises(AssertionError, match="not block-invariant"):
        check_block_invariance(PerBlock(PerBlock.Config()), lfm(lfm.Config()), skeleton, motion)
