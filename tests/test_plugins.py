"""Plugin discovery through real entry points, and the registry's rules."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pytest
import synthetic
from conftest import third_party_entry_points, without_third_party_warnings

from mdframework import cli, errors
from mdframework.plugins import (
    DISABLE_ENV,
    DISABLE_PLUGINS_ENV,
    PluginWarning,
    build_registry,
    default_registry,
)


def _make_distribution(root: Path, dist: str, module: str, body: str, ep_name: str) -> None:
    """Write an installed distribution (package + .dist-info with an entry point) into root."""
    (root / module).mkdir()
    (root / module / "__init__.py").write_text(textwrap.dedent(body))
    info = root / f"{dist.replace('-', '_')}-0.0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 0.0.1\n")
    (info / "entry_points.txt").write_text(f"[mdframework]\n{ep_name} = {module}\n")


THIRD_PARTY = """
    from typing import Literal
    import numpy as np
    from mdframework import MotionConfig, MotionSource, Motion, Skeleton, hookimpl

    class StillConfig(MotionConfig):
        kind: Literal["still_point"] = "still_point"

    class StillPoint(MotionSource):
        '''One point that does not move.'''
        name = "still_point"
        Config = StillConfig
        def load(self):
            t = np.linspace(0, 1, 11)
            return Motion(Skeleton(t, np.zeros((11, 1, 3)) + 5.0, ("p",)), {"source": "still"})

    @hookimpl
    def mdframework_register_motion_sources():
        return [StillPoint]
"""


def test_builtin_plugins_come_from_their_distributions() -> None:
    reg = build_registry(autoload=True)
    assert reg.plugins["radar"]["lfm"].provider.startswith("mdf-lfm ")
    assert reg.plugins["scatterers"]["ellipsoid"].provider.startswith("mdf-ellipsoid ")
    assert reg.plugins["motion"]["point_targets"].provider.startswith("mdf-point-targets ")


def test_third_party_distribution_is_discovered(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_modules: object
) -> None:
    _make_distribution(tmp_path, "mdf-test-still", "mdf_test_still", THIRD_PARTY, "still")
    monkeypatch.syspath_prepend(str(tmp_path))
    reg = build_registry(autoload=True)
    info = reg.plugins["motion"]["still_point"]
    assert info.provider == "mdf-test-still 0.0.1"
    motion = info.cls(info.cls.Config()).load()  # type: ignore[call-arg]
    assert motion.skeleton.positions[0, 0, 0] == 5.0


def test_documented_example_distribution_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_modules: object
) -> None:
    """The plugin author's guide's example (examples/plugin-example) loads through a real entry
    point and runs end to end: a target circling 1 m around a point 10 m from the radar has
    radial speed up to 2 pi r / T. (If the example itself is installed, it is disabled by name
    for this test, so the copy is the only 'circle'.)"""
    from conftest import EXAMPLES

    from mdframework.config import validate_run_config
    from mdframework.pipeline import simulate

    source = EXAMPLES / "plugin-example" / "src" / "mdf_example_circle" / "__init__.py"
    _make_distribution(
        tmp_path, "mdf-test-circle", "mdf_test_circle", source.read_text(), "test_circle"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv(DISABLE_PLUGINS_ENV, "mdf-example-circle")
    reg = build_registry(autoload=True)
    assert reg.plugins["motion"]["circle"].provider == "mdf-test-circle 0.0.1"
    cfg = {
        "motion": {"kind": "circle", "centre": [10.0, 0.0, 0.0], "radius": 1.0, "period": 2.0},
        "scatterers": {"kind": "points"},
        "scene": {"radar_position": [0.0, 0.0, 0.0]},
    }
    res = simulate(validate_run_config(cfg, registry=reg), reg)
    v = res.velocity[np.argmax(res.spectrogram.power, axis=0)]
    dv = res.velocity[1] - res.velocity[0]
    assert v.max() == pytest.approx(np.pi, abs=0.1 + dv)
    assert v.min() == pytest.approx(-np.pi, abs=0.1 + dv)


BROKEN = {
    "import": "import no_such_module_xyz\n",
    "hook": (
        "from mdframework import hookimpl\n"
        "@hookimpl\n"
        "def mdframework_register_effects():\n"
        "    raise RuntimeError('hook exploded')\n"
    ),
    "type": (
        "from mdframework import hookimpl\n"
        "@hookimpl\n"
        "def mdframework_register_radar_waveforms():\n"
        "    return [int]\n"
    ),
    "hookname": (
        "from mdframework import hookimpl\n"
        "@hookimpl\n"
        "def mdframework_register_motion_source():\n"
        "    return []\n"
    ),
}
BROKEN_WHY = {
    "import": "No module named 'no_such_module_xyz'",
    "hook": "hook exploded",
    "type": "which is not a RadarWaveform",
    "hookname": "did you mean 'mdframework_register_motion_sources'",
}


@pytest.mark.parametrize("how", sorted(BROKEN))
def test_a_broken_plugin_disables_only_itself_with_one_warning(
    how: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    clean_modules: object,
    fresh_default_registry: object,
) -> None:
    _make_distribution(tmp_path, "mdf-test-broken", f"mdf_test_broken_{how}", BROKEN[how], "broken")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.warns(PluginWarning) as caught:
        reg = build_registry(autoload=True)
    caught_here = without_third_party_warnings([str(w.message) for w in caught], "broken")
    assert len(caught_here) == 1 and BROKEN_WHY[how] in caught_here[0]
    assert "lfm" in reg.names("radar") and "cmu" in reg.names("motion")  # the rest still loads
    assert BROKEN_WHY[how] in reg.disabled["broken"]
    # the command line says it once on stderr, then works, and lists it as disabled
    assert cli.main(["plugins"]) == 0
    out, err = capsys.readouterr()
    lines = without_third_party_warnings(err.strip().splitlines(), "broken")
    assert len(lines) == 1 and lines[0].startswith("mdf: warning: plugin 'broken' is disabled")
    disabled = out.split("disabled:")[1]
    assert "broken" in disabled and BROKEN_WHY[how] in disabled


def test_ctrl_c_while_a_plugin_loads_ends_the_command_instead_of_disabling_it(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    clean_modules: object,
    fresh_default_registry: object,
) -> None:
    """pydantic turns a KeyboardInterrupt raised while it builds a plugin's schema into a
    SchemaError that does not chain it; once Ctrl-C has reached the process, a plugin that
    fails to load is the interrupt, not a broken plugin."""
    _make_distribution(
        tmp_path, "mdf-test-broken", "mdf_test_broken_late", BROKEN["import"], "broken"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(errors, "_interrupt_seen", True)
    with pytest.raises(KeyboardInterrupt):
        build_registry(autoload=True)


def test_an_interrupt_is_found_behind_wrapping_exceptions() -> None:
    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as inner:
            raise RuntimeError("while creating a class") from inner
    except RuntimeError as exc:
        assert errors.caused_by_interrupt(exc)
    assert not errors.caused_by_interrupt(RuntimeError("a plain failure"))


def test_a_kind_two_plugins_claim_is_withheld_with_one_warning() -> None:
    """Neither plugin is chosen for the user (it used to stop every command); the warning
    names both, and the other kinds stay."""
    other = ModuleType("other")

    class OtherWalker(synthetic.SyntheticWalker):
        """Another walker under the same name."""

    def mdframework_register_motion_sources() -> list[type]:
        return [OtherWalker]

    other.mdframework_register_motion_sources = synthetic.hookimpl(  # type: ignore[attr-defined]
        mdframework_register_motion_sources
    )
    with pytest.warns(PluginWarning) as caught:
        reg = build_registry([synthetic, other], autoload=False)
    assert len(caught) == 1
    message = str(caught[0].message)
    assert message.startswith("the motion kind 'synthetic_walker' is disabled: claimed by ")
    assert "other" in message and "synthetic" in message
    assert reg.names("motion") == [] and "motion kind 'synthetic_walker'" in reg.disabled
    # the same class from two plugins is no choice to make: it is registered once
    other.mdframework_register_motion_sources = (  # type: ignore[attr-defined]
        synthetic.mdframework_register_motion_sources
    )
    assert build_registry([synthetic, other], autoload=False).names("motion") == [
        "synthetic_walker"
    ]


def test_wrong_class_disables_the_plugin() -> None:
    bad = ModuleType("bad")

    def mdframework_register_radar_waveforms() -> list[type]:
        return [synthetic.SyntheticWalker]

    bad.mdframework_register_radar_waveforms = synthetic.hookimpl(  # type: ignore[attr-defined]
        mdframework_register_radar_waveforms
    )
    with pytest.warns(PluginWarning, match="not a RadarWaveform"):
        reg = build_registry([bad, synthetic], autoload=False)
    assert reg.names("radar") == [] and reg.names("motion") == ["synthetic_walker"]


def test_misspelled_hook_fails_loudly() -> None:
    typo = ModuleType("typo")

    def mdframework_register_motion_source() -> list[type]:
        return []

    typo.mdframework_register_motion_source = synthetic.hookimpl(  # type: ignore[attr-defined]
        mdframework_register_motion_source
    )
    with pytest.raises(Exception, match="unknown hook"):
        build_registry([typo], autoload=False)


def test_environment_variable_disables_autoload(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(DISABLE_ENV, "1")
    reg = build_registry([synthetic])
    assert reg.names("motion") == ["synthetic_walker"]
    assert reg.names("radar") == []
    with pytest.raises(KeyError, match="no radar plugin named 'lfm'") as info:
        reg.get("radar", "lfm")
    assert "plugin autoloading is off" in str(info.value)
    assert "mdf_lfm" in reg.disabled


@pytest.mark.parametrize("name", ["mdf_cmu", "mdf-cmu"])
def test_one_plugin_is_disabled_by_entry_point_or_distribution_name(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(DISABLE_PLUGINS_ENV, f"mdf_kinect, {name}")
    reg = build_registry()
    assert "cmu" not in reg.names("motion") and "kinect" not in reg.names("motion")
    assert "boulic" in reg.names("motion") and "lfm" in reg.names("radar")
    assert f"disabled by --disable-plugin or {DISABLE_PLUGINS_ENV}" in reg.disabled["mdf_cmu"]
    assert set(reg.disabled) - third_party_entry_points() == {"mdf_cmu", "mdf_kinect"}


def test_disabled_plugin_is_the_stated_cause_of_a_config_error(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    fresh_default_registry: object,
) -> None:
    from conftest import EXAMPLES

    monkeypatch.delenv(DISABLE_PLUGINS_ENV, raising=False)
    args = ["run", str(EXAMPLES / "cmu_walk.toml"), "--out", str(tmp_path / "o")]
    code = cli.main([*args, "--disable-plugin", "mdf_cmu"])
    err = without_third_party_warnings(capsys.readouterr().err.strip().splitlines())
    assert code == 2 and len(err) == 1
    assert "motion.kind: no motion plugin named 'cmu'" in err[0]
    # the option the user gave is named (it said only the environment variable, which the
    # option sets)
    assert "mdf_cmu (mdf-cmu 0.1.0, disabled by --disable-plugin or " in err[0]
    assert not (tmp_path / "o").exists()
    assert DISABLE_PLUGINS_ENV not in os.environ  # restored for whatever runs next
    assert "cmu" in default_registry().names("motion")


def test_a_misspelt_disable_plugin_name_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--disable-plugin mdf_kinnect`` would leave mdf_kinect on without a word: refused, with the
    nearest installed name, before anything runs."""
    from conftest import EXAMPLES

    monkeypatch.delenv(DISABLE_PLUGINS_ENV, raising=False)
    args = ["run", str(EXAMPLES / "point_target.toml"), "--out", str(tmp_path / "o")]
    code = cli.main([*args, "--disable-plugin", "mdf_kinnect"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1
    assert err[0].startswith(
        "mdf: error: --disable-plugin mdf_kinnect: no installed plugin has this name"
    )
    assert "(did you mean 'mdf_kinect'?)" in err[0]
    assert not (tmp_path / "o").exists()
    # the distribution's name is a name too
    assert cli.main(["plugins", "--disable-plugin", "mdf-cmu"]) == 0


def test_plugins_off_is_the_stated_cause(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    fresh_default_registry: object,
) -> None:
    """Not 'motion.length: Extra inputs are not permitted' but what is wrong and why."""
    from conftest import EXAMPLES

    monkeypatch.setenv(DISABLE_ENV, "1")
    code = cli.main(["run", str(EXAMPLES / "point_target.toml"), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2
    assert "motion.kind: no motion plugin named 'point_targets'; installed: none" in err
    assert f"plugin autoloading is off: {DISABLE_ENV}=1" in err
    assert cli.main(["plugins"]) == 0
    out = capsys.readouterr().out
    assert "disabled:" in out and "mdf_lfm" in out.split("disabled:")[1]


def test_old_spellings_still_work_with_a_deprecation_warning() -> None:
    from mdframework.testing import check_waveform

    old = ModuleType("old")

    def mdframework_register_waveforms() -> list[type]:
        from mdf_lfm import LfmPulseDoppler

        return [LfmPulseDoppler]

    old.mdframework_register_waveforms = synthetic.hookimpl(  # type: ignore[attr-defined]
        mdframework_register_waveforms
    )
    with pytest.warns(DeprecationWarning, match="mdframework_register_radar_waveforms"):
        reg = build_registry([old], autoload=False)
    assert reg.names("radar") == ["lfm"]
    with pytest.warns(DeprecationWarning, match="'effect' is now called 'effects'"):
        assert reg.names("effect") == []
    with pytest.warns(DeprecationWarning, match="use check_radar_waveform"):
        check_waveform(reg.get("radar", "lfm")(reg.get("radar", "lfm").Config()))


def test_the_recording_interface_keeps_its_old_hook_and_class_name() -> None:
    """``recording`` follows the naming rule (``RecordingSource``,
    ``mdframework_register_recording_sources``, ``check_recording_source``); a plugin written
    against the old names registers and runs the same, with DeprecationWarnings."""
    from mdf_radhar.source import RadharSource

    import mdframework
    from mdframework import interfaces
    from mdframework.hookspecs import mdframework_register_recording_sources
    from mdframework.plugins import INTERFACES

    assert INTERFACES["recording"].hook == mdframework_register_recording_sources.__name__
    assert INTERFACES["recording"].base is mdframework.RecordingSource
    with pytest.warns(DeprecationWarning, match="use mdframework.RecordingSource"):
        old_base = mdframework.RadarRecordingSource
    with pytest.warns(DeprecationWarning, match="use mdframework.interfaces.RecordingSource"):
        assert interfaces.RadarRecordingSource is old_base is mdframework.RecordingSource
    assert issubclass(RadharSource, old_base)  # a subclass of either name is the same class

    old = ModuleType("old_recordings")

    def mdframework_register_recordings() -> list[type]:
        return [RadharSource]

    old.mdframework_register_recordings = synthetic.hookimpl(  # type: ignore[attr-defined]
        mdframework_register_recordings
    )
    with pytest.warns(DeprecationWarning, match="mdframework_register_recording_sources"):
        reg = build_registry([old], autoload=False)
    assert reg.names("recording") == ["radhar"]
    assert reg.get("recording", "radhar") is RadharSource


def test_broken_pipe_ends_quietly() -> None:
    """`mdf plugins | true`: the reader is gone before mdf writes (its end of the pipe is closed
    before the interpreter has even started): no traceback, no message, exit 0."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "mdframework.cli", "plugins"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.close()
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 0
    assert without_third_party_warnings(err.splitlines()) == []


def test_an_effect_returning_none_is_named_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Not an AttributeError deep in the pipeline: the run names the effect and the check."""
    from typing import Literal

    from mdframework import Effect, PluginConfig

    class ForgetfulConfig(PluginConfig):
        """Nothing to configure."""

        kind: Literal["forgetful"] = "forgetful"

    class Forgetful(Effect):
        """Forgets to return the data."""

        name = "forgetful"
        Config = ForgetfulConfig
        stage = "received"

        def apply(self, data: object, context: object) -> None:
            return None

    module = ModuleType("forgetful_plugin")
    module.mdframework_register_effects = synthetic.hookimpl(  # type: ignore[attr-defined]
        lambda: [Forgetful]
    )
    from mdframework.config import validate_run_config
    from mdframework.pipeline import simulate

    reg = build_registry([module])
    cfg = {
        "motion": {"kind": "point_targets", "length": 1.0, "targets": [{"position": [50, 0, 0]}]},
        "scatterers": {"kind": "points"},
        "effects": [{"kind": "forgetful"}],
    }
    with pytest.raises(
        TypeError, match=r"^apply\(\) returned NoneType instead of Received\n"
    ) as exc:
        simulate(validate_run_config(cfg, registry=reg), reg)
    assert exc.value.__notes__ == [
        "in the effects plugin 'forgetful' "
        "(test_plugins.test_an_effect_returning_none_is_named_in_one_line.<locals>.Forgetful) on "
        "the 'received' stage; check it with mdframework.testing.check_effect"
    ]


def test_a_receiver_input_that_breaks_the_contract_names_the_effect() -> None:
    """What an effect's ``receiver_input`` returns for a radar that takes it (the FMCW radar
    making maps or points) is checked before the radar gets it: another type, a noise power
    that is not finite, static ranges and RCS of other shapes or values are the effect's bug,
    named so (the radar's receive() failed on them, and the radar was named); a valid one
    reaches the radar."""
    from types import SimpleNamespace
    from typing import Literal

    from mdframework import Effect, PluginConfig, ReceiverInput, SceneContext
    from mdframework.pipeline import hand_to_radar

    class LeakyConfig(PluginConfig):
        """Nothing to configure."""

        kind: Literal["leaky"] = "leaky"

    class Leaky(Effect):
        """Returns ``given`` from receiver_input."""

        name = "leaky"
        Config = LeakyConfig
        stage = "received"
        given: Any = None

        def apply(self, data: Any, context: Any) -> Any:
            return data

        def receiver_input(self, context: SceneContext) -> Any:
            self.seen = context.rng
            return self.given

    got: list[Any] = []
    radar = SimpleNamespace(set_receiver_inputs=got.extend)
    effect = Leaky()
    stages: Any = SimpleNamespace(radar=radar, effects=(effect,))
    rngs = [np.random.default_rng(0)]
    times = np.arange(4) / 1e3
    own = np.random.default_rng(1)
    context = SceneContext(np.zeros(3), 1e3, 24e9, times, np.ones(4), None, radar, own)
    ones = np.ones(3)
    cases: list[tuple[Any, type[Exception], str]] = [
        ({"noise_power": 1.0}, TypeError, "returned dict instead of ReceiverInput or None"),
        (ReceiverInput("leaky", noise_power=np.nan), ValueError, "noise power of nan W"),
        (ReceiverInput("leaky", noise_power=np.inf), ValueError, "noise power of inf W"),
        (
            ReceiverInput("leaky", static_ranges=ones[None], static_rcs=ones[None]),
            ValueError,
            r"\(1, 3\) and RCS of shape \(1, 3\), not \(P,\)",
        ),
        (ReceiverInput("leaky", static_ranges=ones), ValueError, r"\(3,\) and RCS of shape"),
        (ReceiverInput("leaky", static_ranges=ones, static_rcs=-ones), ValueError, "finite"),
    ]
    for given, error, text in cases:
        effect.given = given
        with pytest.raises(error, match=text) as exc:
            hand_to_radar(stages, context, rngs)
        assert "in receiver_input() of the effects plugin 'leaky'" in exc.value.__notes__[0]
    assert got == []
    valid = effect.given = ReceiverInput("leaky", static_ranges=ones, static_rcs=ones)
    assert hand_to_radar(stages, context, rngs) == frozenset({0})
    assert got == [valid]
    assert effect.seen is rngs[0]  # the effect's own stream, not the record's
    effect.stage = "scatterers"  # only received-stage effects are asked
    effect.given = {"not": "asked"}
    assert hand_to_radar(stages, context, rngs) == frozenset()
    assert got == [valid]


def test_an_interrupt_python_could_not_raise_ends_the_command_as_interrupted(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Ctrl-C arriving in a finaliser or a C callback is reported by Python as 'Exception
    ignored in ...' and the command goes on: the hook records it quietly, and the command ends
    with the one interrupted line and exit 130."""
    monkeypatch.setattr(errors, "_interrupt_seen", False)
    passed_on: list[object] = []
    handle = cli._quiet_unraisable_interrupt(passed_on.append)

    class Unraisable:
        def __init__(self, exc: BaseException) -> None:
            self.exc_value = exc

    other = Unraisable(RuntimeError("in a finaliser"))
    handle(other)
    assert passed_on == [other] and not errors.interrupt_seen()
    handle(Unraisable(KeyboardInterrupt()))
    assert passed_on == [other] and errors.interrupt_seen()
    # in a command: the hook that main installs records it while the command runs
    registry = cli.default_registry

    def interrupted_in_a_finaliser() -> Any:
        sys.unraisablehook(Unraisable(KeyboardInterrupt()))  # type: ignore[arg-type]
        return registry()

    monkeypatch.setattr(cli, "default_registry", interrupted_in_a_finaliser)
    assert cli.main(["plugins"]) == 130
    assert capsys.readouterr().err.strip().splitlines()[-1] == "mdf: interrupted"
    # a Ctrl-C of an earlier command in the process is not the next one's
    monkeypatch.setattr(cli, "default_registry", registry)
    assert cli.main(["plugins"]) == 0


def _radar_module(declared: bool) -> ModuleType:
    """A third-party radar with a PRF of 1 kHz and four pulses per slow-time sample (say four
    transmitters in turn): its config declares that pulse rate (a ``RadarConfig``), or is a bare
    ``PluginConfig`` that declares nothing."""
    from typing import Literal

    from pydantic import Field

    from mdframework import PluginConfig, RadarConfig, RadarWaveform, Received

    base = RadarConfig if declared else PluginConfig

    class QuadConfig(base):  # type: ignore[valid-type,misc]
        """Four pulses per slow-time sample."""

        kind: Literal["quad"] = "quad"
        prf: float = Field(1000.0, gt=0, description="Slow-time rate [Hz].")

        def pulse_rate(self) -> float:
            return 4.0 * self.prf

    class Quad(RadarWaveform):
        """Sums the scatterers' phasors."""

        name = "quad"
        Config = QuadConfig

        @property
        def carrier_frequency(self) -> float:
            return 10e9

        @property
        def prf(self) -> float:
            return float(self.config.prf)  # type: ignore[attr-defined]

        def receive(self, block: object) -> Received:
            r = block.ranges  # type: ignore[attr-defined]
            return Received(np.exp(-4j * np.pi * r / 0.03).sum(axis=1).astype(np.complex128))

    module = ModuleType("quad_radar")
    module.mdframework_register_radar_waveforms = synthetic.hookimpl(  # type: ignore[attr-defined]
        lambda: [Quad]
    )
    return module


def test_a_radar_config_declares_the_pulse_rate_that_the_budget_counts() -> None:
    """The pulse budget counts the rate a radar's config declares (RadarConfig.pulse_rate), both
    when the config is read and in the run: the radar's pulse_rate is the config's, with no
    override of its own. A third party's radar config that derives from PluginConfig alone
    declares nothing (a method of the same name is not read): the budget then counts its prf,
    and the run, not the config check, refuses a record over it."""
    from mdframework import limits
    from mdframework.config import validate_run_config
    from mdframework.errors import ConfigError, SceneError
    from mdframework.pipeline import simulate

    seconds = limits.MAX_PULSES / 4000.0 * 1.01  # over the budget in pulses, not in samples
    cfg = {
        "motion": {
            "kind": "point_targets",
            "length": seconds,
            "targets": [{"position": [50, 0, 0]}],
        },
        "scatterers": {"kind": "points"},
        "radar": {"kind": "quad"},
    }
    declared = build_registry([_radar_module(declared=True)])
    wf = declared.get("radar", "quad")(declared.get("radar", "quad").Config())  # type: ignore[call-arg]
    assert wf.pulse_rate == 4000.0 and wf.prf == 1000.0
    with pytest.raises(
        ConfigError, match=r"motion\.duration: .* at 4000 pulses/s is 5\.05e\+06 pulses"
    ):
        validate_run_config(cfg, registry=declared)

    bare = build_registry([_radar_module(declared=False)])
    wf = bare.get("radar", "quad")(bare.get("radar", "quad").Config())  # type: ignore[call-arg]
    assert wf.pulse_rate == 1000.0
    cfg["motion"]["length"] = limits.MAX_PULSES / 1000.0 * 1.01  # type: ignore[index]
    config = validate_run_config(cfg, registry=bare)  # not known from the config
    with pytest.raises(
        SceneError, match=r"motion\.duration: .* at 1000 pulses/s is 5\.05e\+06 pulses"
    ):
        simulate(config, bare)


def test_a_radar_spectrogram_gets_the_pulse_times_its_radar_gave() -> None:
    """RadarWaveform.spectrogram receives the record's pulse instants as the radar's own
    pulse_times gave them (here jittered pulses), for a radar whose spectrogram follows them."""
    from mdframework.config import validate_run_config
    from mdframework.pipeline import simulate
    from mdframework.testing import ReferenceRadar

    given: list[np.ndarray] = []
    seen: list[np.ndarray] = []

    class Jittered(ReferenceRadar):
        """Pulses up to 50 us off the uniform grid."""

        def pulse_times(self, start: float, end: float) -> np.ndarray:
            t = super().pulse_times(start, end)
            t[1:-1] += 50e-6 * np.sin(np.arange(t.size - 2))  # the ends stay in the record
            given.append(t)
            return t

        def spectrogram(self, signal: Any, times: Any, processing: Any) -> None:
            seen.append(np.array(times))
            return None  # the pipeline's STFT

    module = ModuleType("jittered_radar")
    module.mdframework_register_radar_waveforms = synthetic.hookimpl(  # type: ignore[attr-defined]
        lambda: [Jittered]
    )
    reg = build_registry([module])
    cfg = {
        "motion": {
            "kind": "point_targets",
            "length": 1.0,
            "start": 0.25,  # the scene clock: the record starts at 0.25 s
            "targets": [{"position": [50, 0, 0]}],
        },
        "scatterers": {"kind": "points"},
        "radar": {"kind": "reference"},
    }
    res = simulate(validate_run_config(cfg, registry=reg), reg)
    assert len(seen) == 1 and np.array_equal(seen[0], given[-1]) and seen[0][0] == 0.25
    assert np.ptp(np.diff(seen[0])) > 50e-6  # not the uniform grid
    np.testing.assert_allclose(res.pulse_times, seen[0] - seen[0][0], atol=1e-12)


def test_every_effect_contract_breach_is_refused_and_a_valid_output_passes() -> None:
    """What the pipeline checks after an effect's ``apply`` (docs/plugins.md): another type,
    another number of pulses, positions or a signal that are not finite, an RCS that is
    negative or not finite, a signal of another shape are each refused with a message saying
    which; the input itself (a valid output) passes."""
    from mdframework.interfaces import Received, Scatterers
    from mdframework.pipeline import _check_effect_output

    pos = np.zeros((4, 2, 3))
    pos[..., 0] = 5.0
    scat = Scatterers(pos, np.ones((4, 2)), ("a", "b"))
    rec = Received(np.ones(4, dtype=np.complex128))
    _check_effect_output(scat, scat)
    _check_effect_output(rec, rec)
    nan_pos = pos.copy()
    nan_pos[2, 1, 0] = np.nan
    bad_rcs = np.ones((4, 2))
    bad_rcs[1, 0] = -1e-3
    inf_rcs = np.ones((4, 2))
    inf_rcs[3, 1] = np.inf
    nan_signal = np.ones(4, dtype=np.complex128)
    nan_signal[3] = np.nan
    cases: list[tuple[Any, Any, type[Exception], str]] = [
        ([], scat, TypeError, "returned list instead of Scatterers"),
        (scat, rec, TypeError, "returned Scatterers instead of Received"),
        (Scatterers(pos[:3], np.ones((3, 2)), ("a", "b")), scat, ValueError, "3 pulses"),
        (Scatterers(nan_pos, np.ones((4, 2)), ("a", "b")), scat, ValueError, "not finite"),
        (Scatterers(pos, bad_rcs, ("a", "b")), scat, ValueError, "RCS not finite and >= 0"),
        (Scatterers(pos, inf_rcs, ("a", "b")), scat, ValueError, "RCS not finite and >= 0"),
        (Received(np.ones(5, dtype=np.complex128)), rec, ValueError, r"shape \(5,\)"),
        (Received(nan_signal), rec, ValueError, "signal that is not finite"),
    ]
    for out, data, error, text in cases:
        with pytest.raises(error, match=text):
            _check_effect_output(out, data)


#: what mdframework 0.2 added that a plugin may use (a pattern in its source -> the addition)
NEW_IN_0_2 = {
    r"\.max_static_range\b": "RadarWaveform.max_static_range",
    r"\bdef smaller_spectrogram\b": "RadarWaveform.smaller_spectrogram",
    r"\.refuse_listed_after\(": "Effect.refuse_listed_after",
    r"\bcontext\.echo\b": "SceneContext.echo",
    r"\bMAX_MOTION_TEXT_BYTES\b": "limits.MAX_MOTION_TEXT_BYTES",
    r"\bMAX_MOTION_ARRAY_BYTES\b": "limits.MAX_MOTION_ARRAY_BYTES",
    r"\bcheck_file_size\b": "limits.check_file_size",
    r"\bwindow_centre\b": "physics.spectrogram.window_centre",
    r"\brecord_arrays\b": "dataset.record_arrays",
}


def test_a_plugin_using_what_mdframework_0_2_added_requires_0_2() -> None:
    """A plugin distribution (built-in or an example) whose code uses a name mdframework 0.2
    added declares ``mdframework>=0.2``: installed beside an mdframework 0.1 it would fail at
    that name, an internal AttributeError, instead of being refused by pip (the TRC, Kinect
    text, table and BVH readers used the size limits of 0.2 with ``mdframework>=0.1``)."""
    import re
    import tomllib

    from conftest import ROOT

    roots = [*sorted((ROOT / "plugins").iterdir()), *sorted((ROOT / "examples").glob("plugin-*"))]
    wrong = []
    for root in roots:
        if not (root / "pyproject.toml").exists():
            continue
        project = tomllib.loads((root / "pyproject.toml").read_text())["project"]
        [pin] = [d for d in project["dependencies"] if re.match(r"mdframework\b", d)]
        used = sorted(
            {
                name
                for path in sorted((root / "src").rglob("*.py"))
                for pattern, name in NEW_IN_0_2.items()
                if re.search(pattern, path.read_text())
            }
        )
        if used and pin != "mdframework>=0.2":
            wrong.append(f"{project['name']} ({pin}) uses {', '.join(used)}")
    assert wrong == []


@pytest.mark.parametrize(
    "package", ["mdf_c3d", "mdf_table", "mdf_deepmimic", "mdf_cmu", "mdf_kinect"]
)
def test_a_plugin_package_exports_its_readers_on_first_use(package: str) -> None:
    """The packages that import their readers only when used still export every public name:
    each resolves (to the object of the module that defines it), dir() lists it, and a name
    the package does not have is an AttributeError (hasattr() is False, as before)."""
    import importlib

    fresh = f"import {package} as m; print(sorted(set(m.__all__) - set(dir(m))))"
    listed = subprocess.run([sys.executable, "-c", fresh], capture_output=True, text=True)
    assert listed.stdout == "[]\n", listed.stderr  # before any is imported
    module = importlib.import_module(package)
    for name in module.__all__:
        value = getattr(module, name)
        defined = getattr(value, "__module__", None)
        if defined is not None and defined.startswith(f"{package}."):
            assert getattr(importlib.import_module(defined), name) is value, name
    assert not hasattr(module, "no_such_name")
    with pytest.raises(AttributeError, match=rf"^module '{package}' has no attribute 'read_x'$"):
        module.read_x  # noqa: B018


def test_the_built_in_kinds_are_those_the_project_plugins_register() -> None:
    """``BUILT_IN_KINDS`` (what a config naming a kind of a distribution that is not installed is
    told to install) names each kind of the project's plugins with its distribution."""
    from mdframework.docgen import project_registry
    from mdframework.plugins import BUILT_IN_KINDS

    registry = project_registry()
    registered = {
        interface: {name: info.provider.split()[0] for name, info in plugins.items()}
        for interface, plugins in registry.plugins.items()
    }
    assert registered == BUILT_IN_KINDS


def test_a_kind_whose_distribution_is_not_installed_says_what_to_install(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """With the core and some plugins installed (pip install mdframework mdf-cmu ...), a config
    naming the kind of another built-in distribution is told which one and how to install it
    (it was told the kind is unknown, and the kinds installed); a kind no built-in distribution
    has, or one whose distribution is installed (so disabled or broken), gets no such hint."""
    import importlib.metadata

    from mdframework.docgen import project_registry

    real = importlib.metadata.distribution

    def distribution(name: str) -> importlib.metadata.Distribution:
        if name == "mdf-fmcw":
            raise importlib.metadata.PackageNotFoundError(name)
        return real(name)

    monkeypatch.setattr(importlib.metadata, "distribution", distribution)
    registry = project_registry().provided_by(["mdf-lfm", "mdf-cw"])
    assert registry.unknown_kind_message("radar", "fmcw") == (
        "no radar plugin named 'fmcw'; installed: cw, lfm; it comes with mdf-fmcw, which is not "
        "installed: pip install mdf-fmcw"
    )
    assert "pip install" not in registry.unknown_kind_message("radar", "sonar")
    assert "pip install" not in registry.unknown_kind_message("motion", "cmu")  # installed here


def test_a_third_party_radar_with_a_prf_claims_no_unambiguous_range() -> None:
    """A radar's ``prf`` does not give its unambiguous range: the quad radar sends four pulses
    per slow-time sample (its pulse interval is a quarter of 1 / prf), and the CW radar of the
    plugin guide calls its I/Q rate ``prf``. ``mdf check`` reported c / (2 prf) = 1499 m for
    the quad radar at prf 100 kHz (four times its pulse interval's 375 m) and warned about a
    fixed gate at 2 km as beyond it; a radar that does not say has none, and the LFM radar
    keeps its c / (2 prf)."""
    import warnings
    from dataclasses import replace

    from mdframework.check import _metres, format_plan, plan_run
    from mdframework.config import validate_run_config

    registry = build_registry([_radar_module(declared=True)])
    cfg = {
        "motion": {"kind": "point_targets", "length": 0.5, "targets": [{"position": [50, 0, 0]}]},
        "scatterers": {"kind": "points"},
        "radar": {"kind": "quad", "prf": 1e5},
        "scene": {"gate": 2000.0},
    }
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        plan = plan_run(validate_run_config(cfg, registry=registry), registry)
    assert plan.max_range_m is None
    assert "unambiguous to" not in format_plan(plan, "quad.toml")  # no range to state
    # a radar that gives a range resolution but no unambiguous range: the resolution alone
    text = format_plan(replace(plan, range_resolution_m=0.15), "q.toml")
    assert "\n  range       resolution 0.15 m\n" in text and "unambiguous to" not in text
    assert _metres(1499.0, 4) == "1.499 km" and _metres(12.49, 4) == "12.49 m"
    lfm = registry.get("radar", "lfm")
    assert lfm(lfm.Config(prf=1e4)).unambiguous_range() == pytest.approx(14989.6, abs=0.1)
