"""A third party's plugin installed beside ours never breaks our commands: a real distribution
(a package and its .dist-info with an entry point, on sys.path) that registers something
unusable is switched off with one warning, and the rest of mdf works."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import EXAMPLES, without_third_party_warnings
from helpers import point_dataset
from test_plugins import _make_distribution

from mdframework import cli
from mdframework.plugins import DISABLE_PLUGINS_ENV

HEADER = """
from typing import Literal
import numpy as np
from mdframework import Effect, PluginConfig, Scatterers, SceneContext, hookimpl
"""

EFFECT = '''
class XyzzyConfig(PluginConfig):
    kind: Literal["xyzzy_fx"] = "xyzzy_fx"

class XyzzyFx(Effect):
    """Leaves the scatterers as they are."""
    name = "xyzzy_fx"
    Config = XyzzyConfig
    stage = "scatterers"
    def apply(self, data: Scatterers, context: SceneContext) -> Scatterers:
        return data
'''


def registering(returned: str) -> str:
    """Source of a hook that registers effects by returning the expression ``returned``."""
    return f"@hookimpl\ndef mdframework_register_effects():\n    return {returned}\n"


#: how a plugin can be unusable, and what the warning says
BROKEN = {
    "one class, not a list": (
        EFFECT + registering("XyzzyFx"),
        "returned <class 'mdf_test_xyzzy.XyzzyFx'>, not a list of classes",
    ),
    "a number": (
        registering("42"),
        "returned 42, not a list of classes",
    ),
    "no Config": (
        EFFECT.replace("    Config = XyzzyConfig\n", "") + registering("[XyzzyFx]"),
        "XyzzyFx.Config is not a subclass of mdframework.PluginConfig",
    ),
    "kind as text": (
        EFFECT.replace('Literal["xyzzy_fx"] = "xyzzy_fx"', 'str = "xyzzy_fx"')
        + registering("[XyzzyFx]"),
        "XyzzyFx.Config needs kind: Literal['xyzzy_fx'] = 'xyzzy_fx'",
    ),
    "exits when imported": (
        'import sys\nsys.exit("no GPU here")\n',
        "failed to load: SystemExit: no GPU here",
    ),
    "exits in its hook": (
        EFFECT + "import sys\n" + registering('sys.exit("no GPU here")'),
        "mdframework_register_effects raised SystemExit: no GPU here",
    ),
    "kind of another plugin": (
        EFFECT.replace('Literal["xyzzy_fx"] = "xyzzy_fx"', 'Literal["noise"] = "noise"')
        + registering("[XyzzyFx]"),
        "XyzzyFx.Config needs kind: Literal['xyzzy_fx']",
    ),
}


@pytest.fixture
def installed(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    clean_modules: object,
    fresh_default_registry: object,
) -> Path:
    """A folder on sys.path to install distributions into; the registry is rebuilt before and
    after (``fresh_default_registry``), and the test's modules are forgotten
    (``clean_modules``)."""
    root = tmp_path / "site"
    root.mkdir()
    monkeypatch.syspath_prepend(str(root))
    monkeypatch.delenv(DISABLE_PLUGINS_ENV, raising=False)
    return root


def listed(capsys: pytest.CaptureFixture[str]) -> tuple[str, str]:
    """What `mdf plugins` prints (stdout, stderr); it must succeed."""
    assert cli.main(["plugins"]) == 0
    out, err = capsys.readouterr()
    return out, err


def run_point_target(tmp_path: Path, *extra: str) -> int:
    out = tmp_path / "out"
    return cli.main(["run", str(EXAMPLES / "point_target.toml"), "--out", str(out), *extra])


@pytest.mark.parametrize("how", sorted(BROKEN))
def test_an_unusable_plugin_is_switched_off_and_mdf_works(
    how: str, installed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Each of these crashed every command (`mdf --help` included) with a traceback that did
    not name the plugin."""
    body, why = BROKEN[how]
    _make_distribution(installed, "xyzzy-fx", "mdf_test_xyzzy", HEADER + body, "xyzzy_fx")
    out, err = listed(capsys)
    warnings = [line for line in err.splitlines() if "xyzzy" in line]
    assert len(warnings) == 1 and warnings[0].startswith("mdf: warning: plugin 'xyzzy_fx' is ")
    assert why in warnings[0]
    assert "xyzzy_fx" in out.split("disabled:")[1]
    assert cli.main(["config", "schema"]) == 0
    assert run_point_target(tmp_path) == 0


@pytest.mark.parametrize("start_method", ["fork", "spawn"], indirect=True)
def test_a_build_warns_of_an_unusable_plugin_once_however_its_workers_start(
    start_method: str, installed: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """The build's process says that a plugin is switched off; its workers do not say it again
    (each spawned worker, which loads the plugins afresh, did)."""
    body, why = BROKEN["a number"]
    _make_distribution(installed, "xyzzy-fx", "mdf_test_xyzzy", HEADER + body, "xyzzy_fx")
    config = point_dataset(tmp_path / "d.toml")
    capfd.readouterr()
    args = ["dataset", "build", str(config), "--out", str(tmp_path / "ds"), "--workers", "2"]
    assert cli.main(args) == 0
    warned = [line for line in capfd.readouterr().err.splitlines() if "xyzzy" in line]
    assert len(warned) == 1 and why in warned[0], warned


CLASH = (
    HEADER
    + """
from mdf_lfm.waveform import LfmPulseDoppler

class XyzzyLfm(LfmPulseDoppler):
    '''Another pulse-Doppler radar that claims the name of ours.'''

@hookimpl
def mdframework_register_radar_waveforms():
    return [XyzzyLfm]
"""
)


def test_a_built_in_kind_stays_ours_when_a_third_party_claims_it(
    installed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A third party's radar named `lfm` stopped every command with exit code 2, `--help`
    too. Our `lfm` stays ours: that plugin is switched off with one warning, and our runs
    work."""
    _make_distribution(installed, "xyzzy-radar", "mdf_test_xyzzy_radar", CLASH, "xyzzy_radar")
    out, err = listed(capsys)
    warned = [line for line in err.splitlines() if "xyzzy" in line]
    assert len(warned) == 1
    assert warned[0].startswith(
        "mdf: warning: plugin 'xyzzy_radar' is disabled: xyzzy-radar 0.0.1: "
    )
    assert "its radar kind 'lfm' is built in (mdf-lfm " in warned[0]
    assert "xyzzy_radar" in out.split("disabled:")[1]
    assert run_point_target(tmp_path) == 0


def test_a_kind_two_third_parties_claim_is_withheld_and_the_rest_works(
    installed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Neither of two third parties' `xyzzy_fx` is chosen for the user: our commands work, a
    run that asks for it says why in one line, and switching one off settles it."""
    body = HEADER + EFFECT + registering("[XyzzyFx]")
    _make_distribution(installed, "xyzzy-one", "mdf_test_xyzzy_one", body, "xyzzy_one")
    _make_distribution(installed, "xyzzy-two", "mdf_test_xyzzy_two", body, "xyzzy_two")
    out, err = listed(capsys)
    claimed = "claimed by xyzzy-one 0.0.1 and xyzzy-two 0.0.1"
    assert f"mdf: warning: the effects kind 'xyzzy_fx' is disabled: {claimed}" in err
    assert "effects kind 'xyzzy_fx'" in out.split("disabled:")[1]
    assert run_point_target(tmp_path) == 0
    config = tmp_path / "fx.toml"
    config.write_text(
        'effects = [{ kind = "xyzzy_fx" }]\n' + (EXAMPLES / "point_target.toml").read_text()
    )
    capsys.readouterr()
    assert cli.main(["run", str(config), "--out", str(tmp_path / "fx")]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "no effects plugin named 'xyzzy_fx'" in lines[0], lines
    assert claimed in lines[0]
    assert (
        cli.main(
            ["run", str(config), "--out", str(tmp_path / "fx1"), "--disable-plugin", "xyzzy_two"]
        )
        == 0
    )


def test_the_built_in_distributions_are_the_plugins_folder() -> None:
    """The list that keeps our kinds ours names exactly the distributions under plugins/."""
    from conftest import project_distributions

    from mdframework.plugins import BUILT_IN_DISTRIBUTIONS

    assert project_distributions() == BUILT_IN_DISTRIBUTIONS


CLI_FAILS = (
    HEADER
    + EFFECT
    + registering("[XyzzyFx]")
    + """
@hookimpl
def mdframework_add_cli_commands(subparsers):
    raise RuntimeError("no command today")
"""
)


def test_a_plugin_whose_command_fails_is_switched_off_whole(
    installed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Its failing CLI hook listed it as disabled while its effect stayed installed and ran."""
    _make_distribution(installed, "xyzzy-cmd", "mdf_test_xyzzy_cmd", CLI_FAILS, "xyzzy_cmd")
    out, err = listed(capsys)
    assert "no command today" in err and "xyzzy_cmd" in out.split("disabled:")[1]
    assert "xyzzy_fx" not in out.split("disabled:")[0]
    config = tmp_path / "fx.toml"
    text = (EXAMPLES / "point_target.toml").read_text()
    config.write_text('effects = [{ kind = "xyzzy_fx" }]\n' + text)
    code = cli.main(["run", str(config), "--out", str(tmp_path / "o")])
    assert code == 2 and "no effects plugin named 'xyzzy_fx'" in capsys.readouterr().err


@pytest.mark.parametrize("returned", ["{XyzzyFx}", "(c for c in [XyzzyFx])"], ids=["set", "gen"])
def test_any_collection_of_classes_registers(
    returned: str, installed: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A set or a generator of classes worked before the check for a returned single class,
    and still does."""
    body = HEADER + EFFECT + registering(returned)
    _make_distribution(installed, "xyzzy-fx", "mdf_test_xyzzy", body, "xyzzy_fx")
    out, err = listed(capsys)
    assert "xyzzy" not in err and "xyzzy_fx" in out.split("disabled:")[0]


def test_one_class_under_the_old_and_the_new_hook_name_is_one_plugin(
    installed: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A plugin that supports two versions of mdframework by returning its class from both
    `mdframework_register_radar_waveforms` and the old `mdframework_register_waveforms` is not
    a kind claimed twice."""
    body = (
        HEADER
        + '''
from mdf_lfm.waveform import LfmConfig, LfmPulseDoppler

class XyzzyConfig(LfmConfig):
    kind: Literal["xyzzy_lfm"] = "xyzzy_lfm"

class XyzzyLfm(LfmPulseDoppler):
    """Our radar, for old and new mdframework."""
    name = "xyzzy_lfm"
    Config = XyzzyConfig

@hookimpl
def mdframework_register_radar_waveforms():
    return [XyzzyLfm]

@hookimpl
def mdframework_register_waveforms():
    return [XyzzyLfm]
'''
    )
    _make_distribution(installed, "xyzzy-lfm", "mdf_test_xyzzy_lfm", body, "xyzzy_lfm")
    out, err = listed(capsys)
    assert "xyzzy" not in err and "xyzzy_lfm" in out.split("disabled:")[0]


def test_the_commands_of_a_failing_command_hook_are_taken_off(
    installed: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A hook that adds its command and then raises: the command ran in the same invocation
    although the plugin was reported disabled."""
    body = (
        HEADER
        + """
@hookimpl
def mdframework_add_cli_commands(subparsers):
    sub = subparsers.add_parser("xyzzy", help="an xyzzy command")
    sub.set_defaults(func=lambda args: 0)
    raise RuntimeError("half a command")
"""
    )
    _make_distribution(installed, "xyzzy-half", "mdf_test_xyzzy_half", body, "xyzzy_half")
    assert cli.main(["xyzzy"]) == 2
    err = capsys.readouterr().err
    assert "half a command" in err and "invalid choice: 'xyzzy'" in err
    with pytest.raises(SystemExit) as done:
        cli.main(["--help"])
    assert done.value.code == 0
    help_text = capsys.readouterr().out
    assert "plugins" in help_text and "xyzzy" not in help_text


def test_the_project_registry_loads_only_this_trees_plugins(
    installed: Path, recwarn: pytest.WarningsRecorder
) -> None:
    """The reference pages and the contract tests document and check our plugins whatever
    else is installed: a third party's plugin, usable or not, is not even imported."""
    import sys

    from conftest import project_distributions

    from mdframework.docgen import project_registry

    body, _ = BROKEN["one class, not a list"]
    _make_distribution(installed, "xyzzy-fx", "mdf_test_xyzzy", HEADER + body, "xyzzy_fx")
    good = HEADER + EFFECT.replace("xyzzy_fx", "xyzzy_ok") + registering("[XyzzyFx]")
    _make_distribution(installed, "xyzzy-ok", "mdf_test_xyzzy_ok", good, "xyzzy_ok")
    project_registry.cache_clear()
    try:
        reg = project_registry()
    finally:
        project_registry.cache_clear()
    providers = {i.provider.split()[0] for infos in reg.plugins.values() for i in infos.values()}
    assert providers == project_distributions()
    assert "noise" in reg.names("effects") and "xyzzy_ok" not in reg.names("effects")
    assert not {"mdf_test_xyzzy", "mdf_test_xyzzy_ok"} & set(sys.modules)
    assert not [w for w in recwarn if "xyzzy" in str(w.message)]


@pytest.mark.parametrize(
    ("returned", "why"),
    [
        ("[data]", "TypeError: apply() returned list instead of Scatterers"),
        (
            "data.replace(positions=data.positions[1:], rcs=data.rcs[1:])",
            "ValueError: apply() returned 4095 pulses' scatterers, not 4096",  # the first block,
        ),
    ],
    ids=["type", "pulses"],
)
def test_an_effect_that_returns_the_wrong_thing_is_an_internal_error_naming_it(
    returned: str, why: str, installed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An effect whose apply() breaks its contract is the plugin's bug, not the user's: exit 1
    with one internal-error line naming the plugin (a wrong type was exit 2 as a user error; a
    wrong number of pulses failed later, naming nobody)."""
    body = EFFECT.replace("return data", f"return {returned}") + registering("[XyzzyFx]")
    _make_distribution(installed, "xyzzy-fx", "mdf_test_xyzzy", HEADER + body, "xyzzy_fx")
    config = tmp_path / "fx.toml"
    config.write_text(
        'effects = [{ kind = "xyzzy_fx" }]\n' + (EXAMPLES / "point_target.toml").read_text()
    )
    capsys.readouterr()
    assert cli.main(["run", str(config), "--out", str(tmp_path / "fx")]) == 1
    lines = without_third_party_warnings(capsys.readouterr().err.strip().splitlines())
    assert lines == [
        f"mdf: internal error: {why} (in the effects plugin 'xyzzy_fx' "
        "(mdf_test_xyzzy.XyzzyFx) on the 'scatterers' stage; check it with "
        "mdframework.testing.check_effect; run with --debug for the traceback)"
    ]


#: a built-in plugin subclassed by a third party whose method breaks, the run config's edit
#: that chooses it, and the method the internal error names
FAILING_METHOD = {
    "radar receive": (
        "from mdf_lfm.waveform import LfmPulseDoppler as Base\n",
        "radar_waveforms",
        "    def receive(self, block):\n        return 1 / 0\n",
        ('kind = "lfm"', 'kind = "xyzzy_bug"'),
        "ZeroDivisionError: division by zero (in receive() of the radar plugin 'xyzzy_bug' "
        "(mdf_test_xyzzy.XyzzyBug); check it with mdframework.testing.check_radar_waveform",
    ),
    "scatterer model": (
        "from mdf_point_targets.source import IsotropicPoints as Base\n",
        "scatterer_models",
        "    def scatterers(self, *args):\n        return [1, 2]\n",
        ('kind = "points"', 'kind = "xyzzy_bug"'),
        "AttributeError: 'list' object has no attribute 'rcs' (in scatterers() of the "
        "scatterers plugin 'xyzzy_bug' (mdf_test_xyzzy.XyzzyBug); check it with "
        "mdframework.testing.check_scatterer_model",
    ),
    "radar config validator": (
        "from mdf_lfm.waveform import LfmPulseDoppler as Base\n"
        "from pydantic import model_validator\n",
        "radar_waveforms",
        "    class Config(XyzzyConfig):\n"
        "        @model_validator(mode='after')\n"
        "        def _bug(self):\n"
        "            raise TypeError('not a ValueError')\n",
        ('kind = "lfm"', 'kind = "xyzzy_bug"'),
        "TypeError: not a ValueError (in Config.model_validate() of the radar plugin "
        "'xyzzy_bug' (mdf_test_xyzzy.XyzzyBug); check it with "
        "mdframework.testing.check_radar_waveform",
    ),
    "motion source": (
        "from mdf_point_targets.source import PointTargets as Base\n",
        "motion_sources",
        "    def load(self):\n        return None + 1\n",
        ('kind = "point_targets"', 'kind = "xyzzy_bug"'),
        "TypeError: unsupported operand type(s) for +: 'NoneType' and 'int' (in load() of the "
        "motion plugin 'xyzzy_bug' (mdf_test_xyzzy.XyzzyBug); check it with "
        "mdframework.testing.check_motion_source",
    ),
}


def install_broken(installed: Path, base: str, hook: str, method: str) -> None:
    """Install a third party's plugin ``mdf_test_xyzzy.XyzzyBug`` (kind ``xyzzy_bug``): the
    class ``Base`` that the import lines ``base`` give, registered by the hook
    ``mdframework_register_<hook>``, with ``method`` (source lines) overridden."""
    body = (
        f"{base}from typing import Literal\nfrom mdframework import hookimpl\n\n"
        f"class XyzzyConfig(Base.Config):\n    kind: Literal['xyzzy_bug'] = 'xyzzy_bug'\n\n"
        f"class XyzzyBug(Base):\n    '''Broken.'''\n    name = 'xyzzy_bug'\n"
        f"    Config = XyzzyConfig\n{method}\n"
        f"@hookimpl\ndef mdframework_register_{hook}():\n    return [XyzzyBug]\n"
    )
    _make_distribution(installed, "xyzzy-bug", "mdf_test_xyzzy", body, "xyzzy_bug")


@pytest.mark.parametrize("case", sorted(FAILING_METHOD))
def test_a_plugin_method_that_fails_is_an_internal_error_naming_the_plugin(
    case: str, installed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A third party's motion source, scatterer model or radar whose method raises is that
    plugin's bug: the internal error names it and its contract check (it named nobody, as if
    mdframework had failed; only effects were named); so is a radar config validator raising
    an exception other than pydantic's (the run config is validated whole: it named nobody)."""
    base, hook, method, (old, new), why = FAILING_METHOD[case]
    install_broken(installed, base, hook, method)
    config = tmp_path / "bug.toml"
    text = (EXAMPLES / "point_target.toml").read_text()
    assert old in text
    config.write_text(text.replace(old, new))
    capsys.readouterr()
    assert cli.main(["run", str(config), "--out", str(tmp_path / "o")]) == 1
    lines = without_third_party_warnings(capsys.readouterr().err.strip().splitlines())
    assert len(lines) == 1 and lines[0].startswith("mdf: internal error: "), lines
    assert why in lines[0]


#: the effect with an array in its config: neither JSON nor a JSON schema
ARRAY_CONFIG = "from pydantic import ConfigDict, Field\n" + EFFECT.replace(
    '    kind: Literal["xyzzy_fx"] = "xyzzy_fx"\n',
    "    model_config = ConfigDict(arbitrary_types_allowed=True)\n"
    '    kind: Literal["xyzzy_fx"] = "xyzzy_fx"\n'
    '    data: np.ndarray = Field(default_factory=lambda: np.zeros(3), description="Data.")\n',
)


def test_a_config_model_that_cannot_be_saved_is_named_before_the_run(
    installed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A third party's config model with a field that has no JSON form: `mdf config schema`
    says it leaves the plugin out (it did so silently), and a run that uses it stops before any
    pulse with an internal error naming the plugin (after the whole simulation, naming no one)."""
    body = HEADER + ARRAY_CONFIG + registering("[XyzzyFx]")
    _make_distribution(installed, "xyzzy-fx", "mdf_test_xyzzy", body, "xyzzy_fx")
    capsys.readouterr()
    assert cli.main(["config", "schema"]) == 0
    out, err = capsys.readouterr()
    assert "xyzzy_fx" not in out
    lines = [line for line in err.strip().splitlines() if "xyzzy" in line]
    assert lines == [
        "mdf: warning: the effects kind 'xyzzy_fx' (xyzzy-fx 0.0.1) is left out of the schema: "
        "its Config has no JSON schema (Cannot generate a JsonSchema for "
        "core_schema.IsInstanceSchema (<class 'numpy.ndarray'>)); check it with "
        "mdframework.testing.check_plugin_class"
    ], lines
    config = tmp_path / "fx.toml"
    config.write_text(
        'effects = [{ kind = "xyzzy_fx" }]\n' + (EXAMPLES / "point_target.toml").read_text()
    )
    assert cli.main(["run", str(config), "--out", str(tmp_path / "fx")]) == 1
    lines = without_third_party_warnings(capsys.readouterr().err.strip().splitlines())
    assert len(lines) == 1 and lines[0].startswith("mdf: internal error: "), lines
    assert (
        "(in the config of the effects plugin 'xyzzy_fx' (mdf_test_xyzzy.XyzzyConfig), which "
        "runs save as JSON; check it with mdframework.testing.check_config_round_trip;"
    ) in lines[0], lines
    assert not (tmp_path / "fx").exists()


def test_mdf_plugins_names_a_plugin_that_is_slow_to_import(
    installed: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every command imports every plugin: one that sleeps (or imports a heavy library) at
    import slowed every command, `mdf --help` included, and nothing said which."""
    from mdframework import plugins

    monkeypatch.setattr(plugins, "SLOW_IMPORT_SECONDS", 0.05)
    body = "import time\ntime.sleep(0.2)\n" + HEADER + EFFECT + registering("[XyzzyFx]")
    _make_distribution(installed, "xyzzy-fx", "mdf_test_xyzzy", body, "xyzzy_fx")
    out, _ = listed(capsys)
    slow = out.split("slow to import")[1].splitlines()
    assert "--disable-plugin" in slow[0]
    mine = [line.split() for line in slow[1:] if "xyzzy" in line]
    assert len(mine) == 1 and mine[0][:3] == ["xyzzy_fx", "xyzzy-fx", "0.0.1:"], mine
    assert 0.2 <= float(mine[0][3]) < 5 and mine[0][4] == "s"


@pytest.mark.parametrize("where", ["import", "hook"])
def test_what_a_plugin_prints_when_imported_stays_out_of_a_commands_output(
    where: str, installed: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A third party's plugin that prints a banner when imported, or when its registration
    hook runs: `mdf config schema > schema.json` wrote the banner into the JSON, which no JSON
    reader then took; it goes to stderr."""
    import json

    if where == "import":
        body = 'print("xyzzy: hello")\n' + HEADER + EFFECT + registering("[XyzzyFx]")
    else:
        body = HEADER + EFFECT + registering('print("xyzzy: hello") or [XyzzyFx]')
    _make_distribution(installed, "xyzzy-fx", "mdf_test_xyzzy", body, "xyzzy_fx")
    capsys.readouterr()
    assert cli.main(["config", "schema"]) == 0
    out, err = capsys.readouterr()
    assert "xyzzy_fx" in json.dumps(json.loads(out))  # the plugin works, its banner is not in
    assert "xyzzy: hello" in err


#: a radar that drops the last pulse of every block: a ValueError of the plugin's own
SHORT_RECEIVE = (
    "    def receive(self, block):\n        out = super().receive(block)\n"
    "        return replace(out, signal=out.signal[:-1])\n"
)


#: a radar whose constructor fails with a ValueError of its own
FAILING_INIT = (
    "    def __init__(self, config=None):\n        super().__init__(config)\n"
    "        raise ValueError('math domain error')\n"
)
#: the radar's broken method, and how the internal error names the plugin
DATASET_BUGS = {
    "receive": (
        SHORT_RECEIVE,
        "(in receive() of the radar plugin 'xyzzy_bug' (mdf_test_xyzzy.XyzzyBug); check it "
        "with mdframework.testing.check_radar_waveform; while building record 00000-",
    ),
    "constructor": (
        FAILING_INIT,
        "(in the radar plugin 'xyzzy_bug' (mdf_test_xyzzy.XyzzyBug) while it was built from its "
        "config; while building record 00000-",
    ),
}


@pytest.mark.parametrize("method", sorted(DATASET_BUGS))
@pytest.mark.parametrize("on_error", ["stop", "skip"])
def test_a_plugin_bug_in_a_dataset_record_is_an_internal_error_not_the_configs(
    on_error: str,
    method: str,
    installed: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A third party's radar whose receive() breaks its contract with a ValueError, or whose
    constructor raises one, in a dataset build: an internal error naming the plugin, as in
    `mdf run` (it was the user's error, exit 2 naming the config file, and with on_error =
    'skip' every record was skipped as if its config were bad)."""
    body, why = DATASET_BUGS[method]
    base = "from dataclasses import replace\nfrom mdf_lfm.waveform import LfmPulseDoppler as Base\n"
    install_broken(installed, base, "radar_waveforms", body)
    config = tmp_path / "d.toml"
    config.write_text(f"""
seed = 1
on_error = "{on_error}"
[[sources]]
label = "recede"
motion = {{ kind = "point_targets", length = 2.0, targets = [
    {{ position = [100.0, 0.0, 0.0], velocity = [1.0, 0.0, 0.0], rcs = 1.0 }}] }}
[base.scatterers]
kind = "points"
[base.radar]
kind = "xyzzy_bug"
""")
    capsys.readouterr()
    assert cli.main(["dataset", "build", str(config), "--out", str(tmp_path / "ds")]) == 1
    lines = without_third_party_warnings(capsys.readouterr().err.strip().splitlines())
    assert len(lines) == 1 and lines[0].startswith("mdf: internal error: ValueError: "), lines
    assert why in lines[0], lines


@pytest.mark.parametrize(
    ("method", "body"),
    [
        ("load", "    def load(self):\n        return 1 / 0\n"),
        ("__init__", "    def __init__(self, config=None):\n        1 / 0\n"),
    ],
)
def test_a_recording_source_that_fails_is_an_internal_error_naming_it(
    method: str, body: str, installed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A third party's recording source whose load() or constructor raises is its bug: the
    internal error names it and its contract check, as docs/plugins.md says of any plugin's
    method (it named nobody)."""
    base = "from mdf_radhar.source import RadharSource as Base\n"
    install_broken(installed, base, "recording_sources", body)
    data = EXAMPLES / "data" / "radhar" / "radhar_walk_subset.npz"
    config = tmp_path / "d.toml"
    config.write_text(f"""
[[sources]]
label = "walk"
recording = {{ kind = "xyzzy_bug", file = "{data}" }}
""")
    capsys.readouterr()
    assert cli.main(["dataset", "build", str(config), "--out", str(tmp_path / "ds")]) == 1
    lines = without_third_party_warnings(capsys.readouterr().err.strip().splitlines())
    assert len(lines) == 1, lines
    assert lines[0].startswith(
        f"mdf: internal error: ZeroDivisionError: division by zero (in {method}() of the "
        "recording plugin 'xyzzy_bug' (mdf_test_xyzzy.XyzzyBug); check it with "
        "mdframework.testing.check_recording_source;"
    ), lines


#: a radar whose receive() overflows (a numerical warning in a plugin's own code) and that
#: otherwise works
OVERFLOWING_RECEIVE = (
    "    def receive(self, block):\n"
    "        np.float64(1e308) * 10.0\n"
    "        return super().receive(block)\n"
)


@pytest.mark.parametrize(
    ("how", "start_method"),
    [
        (["--workers", "1"], "fork"),
        (["--workers", "2"], "fork"),
        (["--workers", "2"], "spawn"),
        (["--scheduler", "local"], "fork"),
    ],
    indirect=["start_method"],
)
def test_a_numerical_warning_in_a_record_stops_the_build_however_it_runs(
    how: list[str],
    start_method: str,
    installed: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """mdf stops at a numerical warning in its own or a plugin's code rather than write a
    result it cannot trust: in the build's process and its forked workers, in workers spawned
    afresh (as on macOS: they wrote every record with Python's own warning filters), and also on
    a local Dask cluster, whose workers start afresh (they wrote every record and the build
    succeeded, so the same config gave a dataset or an error depending on --scheduler)."""
    if how[0] == "--scheduler":
        pytest.importorskip("distributed")
    base = "import numpy as np\nfrom mdf_lfm.waveform import LfmPulseDoppler as Base\n"
    install_broken(installed, base, "radar_waveforms", OVERFLOWING_RECEIVE)
    config = point_dataset(tmp_path / "d.toml", radar="xyzzy_bug")
    out = tmp_path / "ds"
    capsys.readouterr()
    assert cli.main(["dataset", "build", str(config), "--out", str(out), *how]) == 1
    lines = without_third_party_warnings(capsys.readouterr().err.strip().splitlines())
    assert len(lines) == 1 and lines[0].startswith("mdf: internal error: RuntimeWarning: "), lines
    assert "overflow" in lines[0] and "xyzzy_bug" in lines[0], lines
    assert not (out / "index.csv").exists()


@pytest.fixture(scope="module")
def two_class_dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Built once: point targets approaching and receding, 7 records of 0.5 s each."""
    from mdframework.dataset import build_dataset, load_dataset_config

    root = tmp_path_factory.mktemp("two_class")
    sources = "".join(
        f'[[sources]]\nlabel = "{label}"\nhop = 0.25\nmotion = {{ kind = "point_targets", '
        f"length = 2.0, targets = [{{ position = [20.0, 0.0, 1.0], velocity = [{v}, 0.0, 0.0], "
        "rcs = 1.0 }] }\n"
        for label, v in (("approach", -1.0), ("recede", 1.0))
    )
    config = root / "d.toml"
    config.write_text(
        "seed = 1\n" + sources + "[record_lengths]\napproach = 0.5\nrecede = 0.5\n"
        '[base.scatterers]\nkind = "points"\n[base.radar]\nkind = "lfm"\n'
    )
    build_dataset(*load_dataset_config(config), root / "ds", progress=False)
    return root / "ds"


#: a third party's classifier (mdf-knn's, subclassed) with a method broken, its [classifier]
#: option (default k = 1), the exit code and the one line that says why
FAILING_CLASSIFIER = {
    "integer class codes": (
        "    def predict(self, features):\n        return np.zeros(len(features), dtype=int)\n",
        "",
        1,
        "mdf: internal error: ValueError: predict() returned labels it was not trained on: 0 "
        "(trained on: 'approach', 'recede') (in predict() of the classifier plugin 'xyzzy_bug' "
        "(mdf_test_xyzzy.XyzzyBug); check it with mdframework.testing.check_classifier; run "
        "with --debug for the traceback)",
    ),
    "its constructor raises": (
        "    def __init__(self, config=None):\n        raise KeyError('oops')\n",
        "",
        1,
        "mdf: internal error: KeyError: 'oops' (in __init__() of the classifier plugin "
        "'xyzzy_bug' (mdf_test_xyzzy.XyzzyBug); check it with "
        "mdframework.testing.check_classifier; run with --debug for the traceback)",
    ),
    "its config's validator raises": (
        "    class Config(XyzzyConfig):\n"
        "        @model_validator(mode='after')\n"
        "        def _bug(self):\n"
        "            raise TypeError('not a ValueError')\n",
        "",
        1,
        "mdf: internal error: TypeError: not a ValueError (in Config.model_validate() of the "
        "classifier plugin 'xyzzy_bug' (mdf_test_xyzzy.XyzzyBug); check it with "
        "mdframework.testing.check_classifier; run with --debug for the traceback)",
    ),
    "the user's bad option": (
        "",
        "k = 0",
        2,
        "mdf: error: {config}: classifier.k: must be at least 1 (got 0)",
    ),
}


@pytest.mark.parametrize("case", sorted(FAILING_CLASSIFIER))
def test_a_classifier_plugin_bug_is_an_internal_error_naming_it(
    case: str,
    installed: Path,
    two_class_dataset: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A third party's classifier that predicts labels it never saw (integer class codes) is
    its bug: the experiment stops naming it (it wrote a report of balanced accuracy 0), and so
    does one whose constructor or config validator raises (they named nobody); a bad option of
    its own is the user's error, exit 2 naming the field."""
    method, option, code, why = FAILING_CLASSIFIER[case]
    base = (
        "import numpy as np\nfrom pydantic import model_validator\n"
        "from mdf_knn import Knn as Base\n"
    )
    install_broken(installed, base, "classifiers", method or "    pass\n")
    config = tmp_path / "e.toml"
    config.write_text(
        f'seed = 0\n[dataset]\npath = "{two_class_dataset}"\n[classifier]\nkind = "xyzzy_bug"\n'
        f'{option or "k = 1"}\n[selection]\nmethod = "none"\n[evaluation]\nrepeats = 1\n'
    )
    capsys.readouterr()
    out = tmp_path / "o"
    assert cli.main(["experiment", str(config), "--out", str(out)]) == code
    lines = without_third_party_warnings(capsys.readouterr().err.strip().splitlines())
    assert lines == [why.format(config=config)]
    assert not (out / "report.md").exists()
