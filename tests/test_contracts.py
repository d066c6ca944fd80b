"""Every plugin of this project passes its interface's contract (the public suite in
mdframework.testing), and the suite catches broken plugins.

The checks run on the plugins whose code lives in this tree's ``plugins/`` (a third party's plugin
installed beside ours is checked by its own tests, with the same suite): one that needs a file,
or whose name clashes with ours, must not break the collection of this file."""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pytest
from conftest import EXAMPLES
from helpers import walking_c3d

from mdframework.config import load_run_config
from mdframework.docgen import project_registry
from mdframework.interfaces import Effect, PluginConfig, Received, Scatterers, SceneContext
from mdframework.physics import interpolation
from mdframework.pipeline import build_stages, place_body
from mdframework.plugins import INTERFACES
from mdframework.skeleton import Skeleton
from mdframework.testing import (
    JointPoints,
    ReferenceRadar,
    check_block_invariance,
    check_effect,
    check_plugin,
    check_plugin_class,
    check_radar_waveform,
    parametrize_with_checks,
    plugin_checks,
    walking_motion,
)

REGISTRY = project_registry()

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
#: where those files are written (at collection, before any fixture); removed when the process
#: ends (a folder per collection was left in the temporary folder, hundreds of them by now)
WRITTEN_FILES_FOLDER = tempfile.TemporaryDirectory(prefix="contract-")
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
        folder = Path(WRITTEN_FILES_FOLDER.name) / name
        folder.mkdir(exist_ok=True)
        path = WRITTEN_SOURCE_FILES[name](folder)
        cls0: Any = info.cls
        return cls0(cls0.Config(file=path))
    if interface == "motion":
        assert name in SOURCE_EXAMPLES, f"add an example using the {name!r} source"
        return build_stages(
            load_run_config(EXAMPLES / SOURCE_EXAMPLES[name], REGISTRY), REGISTRY
        ).source
    cls: Any = info.cls
    if interface == "recording":
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


class _Stage(_Returns):
    """A scatterer-stage effect whose apply returns what ``result`` says."""

    stage = "scatterers"  # type: ignore[assignment]


class Counted(_Stage):
    """Scales each pulse's RCS by 1 + 1e-3 k, k counting the pulses since start_record: a
    correct stateful effect (state carried across blocks, reset in start_record)."""

    def start_record(self, body: Skeleton, radar_position: Any) -> None:
        self.seen = 0

    def apply(self, data: Any, context: SceneContext) -> Any:
        k = self.seen + np.arange(data.rcs.shape[0])
        self.seen += data.rcs.shape[0]
        return data.replace(rcs=data.rcs * (1 + 1e-3 * k)[:, None])


class Smoothed(_Stage):
    """Smooths each scatterer's RCS over pulses (first-order IIR, time constant 10 pulses),
    carrying the filter's state across blocks and resetting it in start_record."""

    state: Any = None

    def start_record(self, body: Skeleton, radar_position: Any) -> None:
        self.state = None

    def apply(self, data: Any, context: SceneContext) -> Any:
        out = np.empty_like(data.rcs)
        s = data.rcs[0] if self.state is None else self.state
        for i, row in enumerate(data.rcs):
            s = out[i] = 0.9 * s + 0.1 * row
        self.state = s
        return data.replace(rcs=out)


def test_a_stateful_effect_that_resets_in_start_record_passes() -> None:
    """The checks start each pass of the block-invariance check as a run starts a record (with
    start_record), so state carried across blocks is allowed; the smoothing one would pass a
    constant RCS whatever its state, so the checks feed an RCS that swings over time."""
    check_plugin(Counted(Counted.Config()))
    check_plugin(Smoothed(Smoothed.Config()))
    effect = Counted(Counted.Config())  # check_block_invariance resets it, not its caller
    effect.seen = 12345
    motion = walking_motion(0.2)
    body = motion.canonical()
    check_block_invariance(
        JointPoints(JointPoints.Config()),
        ReferenceRadar(ReferenceRadar.Config()),
        body,
        motion,
        (effect,),
    )


def test_the_suite_catches_state_that_is_never_reset() -> None:
    """The same smoothing, its state reset only when the effect is made: the record's second
    pass starts from the first's last RCS (caught only because the checks' RCS changes)."""

    class Stale(Smoothed):
        """Never resets its filter."""

        def start_record(self, body: Skeleton, radar_position: Any) -> None:
            pass

    with pytest.raises(AssertionError, match="reset in start_record what apply accumulates"):
        check_effect(Stale(Stale.Config()))
    motion = walking_motion(0.2)
    body = motion.canonical()
    points = JointPoints(JointPoints.Config(rcs_swing=0.5))
    radar = ReferenceRadar(ReferenceRadar.Config())
    with pytest.raises(AssertionError, match=r"effect 'returns' gives different scatterer rcs"):
        check_block_invariance(points, radar, body, motion, (Stale(Stale.Config()),))


def test_the_suite_checks_the_dtypes_the_interfaces_give() -> None:
    class Real(_Returns):
        """Drops the imaginary part (a run would show a mirrored spectrogram)."""

        result = staticmethod(lambda r: Received(r.signal.real.copy()))

    class Single(_Returns):
        """Returns a complex64 signal."""

        result = staticmethod(lambda r: Received(r.signal.astype(np.complex64)))

    class Float32(_Stage):
        """Returns float32 positions and RCS."""

        result = staticmethod(
            lambda d: Scatterers(d.positions.astype(np.float32), d.rcs.astype(np.float32), d.names)
        )

    expected = [
        (Real, r"Real \('returns'\): apply\(\) must give Received.signal as complex128 .*float64"),
        (Single, r"Received.signal as complex128 .*got complex64"),
        (Float32, r"Float32 \('returns'\): apply\(\) must give Scatterers.positions as float64"),
    ]
    for cls, message in expected:
        with pytest.raises(AssertionError, match=message):
            check_effect(cls(cls.Config()))


def test_the_suite_catches_an_effect_that_changes_its_input_in_place() -> None:
    class Halves(_Stage):
        """Halves the input's RCS in place and returns it."""

        def apply(self, data: Any, context: SceneContext) -> Any:
            data.rcs[...] *= 0.5
            return data

    with pytest.raises(
        AssertionError, match=r"Halves \('returns'\): apply\(\) changed its input's rcs"
    ):
        check_effect(Halves(Halves.Config()))


def test_the_suite_names_the_effect_that_is_not_block_invariant() -> None:
    """An effect that adds a scatterer to the first block only, and one that moves the
    scatterers by an amount set by the block's length: each is named (not the checks' own
    radar), in an AssertionError (not numpy's ValueError)."""

    class Extra(_Stage):
        """Adds a scatterer in the block that starts at pulse 0 only."""

        def apply(self, data: Any, context: SceneContext) -> Any:
            if context.block_start:
                return data
            n = data.positions.shape[0]
            return Scatterers(
                np.concatenate([data.positions, data.positions[:, :1] + 1.0], axis=1),
                np.concatenate([data.rcs, np.ones((n, 1))], axis=1),
                (*data.names, "extra"),
            )

    class Shifts(_Stage):
        """Moves every scatterer by 0.1 mm per pulse of the block."""

        def apply(self, data: Any, context: SceneContext) -> Any:
            return data.replace(positions=data.positions + 1e-4 * data.positions.shape[0])

    every_block = "effect 'returns': every block must have the same scatterers, but it gives 18"
    with pytest.raises(AssertionError, match=every_block):
        check_plugin(Extra(Extra.Config()))
    with pytest.raises(AssertionError) as info:
        check_plugin(Shifts(Shifts.Config()))
    message = str(info.value)
    assert "effect 'returns' gives different scatterer positions" in message, message
    assert "radar" not in message and "waveform" not in message, message


def test_the_suite_says_a_class_has_no_config() -> None:
    class Bare(Effect):
        """An effect without a Config."""

        name = "bare"
        stage = "scatterers"

        def apply(self, data: Any, context: SceneContext) -> Any:
            return data

    with pytest.raises(AssertionError, match=r"Bare \('bare'\) has no Config"):
        check_plugin(Bare)

    class NeedsGain(_Returns):
        """Its Config needs a gain."""

        class Config(PluginConfig):
            """A gain."""

            kind: Literal["returns"] = "returns"
            gain: float

    with pytest.raises(AssertionError, match=r"its Config has required fields \(gain\)"):
        check_plugin(NeedsGain)


def test_the_suite_names_a_config_that_breaks_its_own_rules() -> None:
    """A default that its own field refuses (pydantic does not validate defaults, so the run
    used it), and a field with no JSON schema (`mdf config schema` left the plugin out, and the
    run could not save config.resolved.json): each an AssertionError naming the plugin and the
    check, not a bare pydantic error."""
    from pydantic import ConfigDict, Field

    class BadDefault(_Returns):
        """Its default gain is below the gain's own minimum."""

        class Config(PluginConfig):
            """A gain."""

            kind: Literal["returns"] = "returns"
            gain: float = Field(-1.0, gt=0, description="Gain.")

    with pytest.raises(AssertionError) as info:
        check_plugin(BadDefault)
    assert str(info.value).startswith(
        "BadDefault ('returns') fails check_config_round_trip: BadDefault ('returns'): its "
        "config is not valid: gain: Input should be greater than 0"
    ), info.value

    class ArrayField(_Returns):
        """Its config holds a numpy array."""

        class Config(PluginConfig):
            """An array."""

            model_config = ConfigDict(arbitrary_types_allowed=True)
            kind: Literal["returns"] = "returns"
            data: np.ndarray = Field(default_factory=lambda: np.zeros(3), description="Data.")

    with pytest.raises(AssertionError) as info:
        check_plugin(ArrayField)
    assert str(info.value).startswith(
        "ArrayField ('returns') fails check_plugin_class: ArrayField.Config has no JSON schema "
        "(mdf config schema shows it): Cannot generate a JsonSchema"
    ), info.value


def test_the_suite_names_the_plugin_and_the_failing_check() -> None:
    class NoneEffect(_Returns):
        """Forgets to return the data."""

    with pytest.raises(AssertionError, match=r"NoneEffect \('returns'\) fails check_effect"):
        check_plugin(NoneEffect(NoneEffect.Config()))


def test_the_contracts_catch_broken_waveforms() -> None:
    """A waveform with the wrong Doppler sign, one that is not linear in the scatterers, one
    whose separate responses are not separate, and a config whose kind is not its name."""
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

    class Summed(LfmPulseDoppler):
        """Gives every scatterer the sum of all as its own response (the clutter patches would
        each carry the others)."""

        def receive_each(self, block: Any) -> Any:
            total = self.receive_signal(block)
            return np.tile(total, (block.ranges.shape[1], 1))

    with pytest.raises(AssertionError, match=r"receive_each\(\) must give each scatterer's own"):
        check_radar_waveform(Summed(Summed.Config()))

    class Decimated(LfmPulseDoppler):
        """Takes its spectrogram of every other pulse but keeps the default geometry, so that
        `mdf check` would report twice the frames the run makes."""

        def spectrogram(self, signal: Any, times: Any, processing: Any) -> Any:
            from mdframework.physics.spectrogram import spectrogram

            p = processing
            y = np.asarray(signal)[::2]
            return spectrogram(y, self.prf / 2, window_length=p.window_length, hop=p.hop)

    with pytest.raises(AssertionError, match=r"spectrogram_geometry\(\) says \(128, "):
        check_radar_waveform(Decimated(Decimated.Config()))

    class Misnamed(LfmPulseDoppler):
        """Registered as 'lfm2' but its config says kind = 'lfm'."""

        name = "lfm2"

    with pytest.raises(AssertionError, match=r"Config\.kind must be Literal\['lfm2'\]"):
        check_plugin_class(Misnamed, "radar")


@pytest.fixture(scope="module")
def placed_body() -> tuple[Any, Skeleton]:
    config = load_run_config(EXAMPLES / "cmu_walk.toml", REGISTRY)
    motion = build_stages(config, REGISTRY).source.load()
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
    effect = cls(cls.Config())  # check_block_invariance calls its start_record
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
