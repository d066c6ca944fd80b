"""A third party's plugin installed beside ours never breaks our commands: a real distribution
(a package and its .dist-info with an entry point, on sys.path) that registers something
unusable is switched off with one warning, and the rest of mdf works."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import EXAMPLES
from test_plugins import _make_distribution

from mdframework import cli
from mdframework.plugins import DISABLE_PLUGINS_ENV, reset_default_registry

HEADER = """
from typing import Literal
import numpy as np
from mdframework import Effect, PluginConfig, Scatterers, SceneContext, hookimpl
"""

EFFECT = '''
class AcmeConfig(PluginConfig):
    kind: Literal["acme_fx"] = "acme_fx"

class AcmeFx(Effect):
    """Leaves the scatterers as they are."""
    name = "acme_fx"
    Config = AcmeConfig
    stage = "scatterers"
    def apply(self, data: Scatterers, context: SceneContext) -> Scatterers:
        return data
'''

#: how a plugin can be unusable, and what the warning says
BROKEN = {
    "one class, not a list": (
        EFFECT + "@hookimpl\ndef mdframework_register_effects():\n    return AcmeFx\n",
        "returned <class 'mdf_test_acme.AcmeFx'>, not a list of classes",
    ),
    "a number": (
        "@hookimpl\ndef mdframework_register_effects():\n    return 42\n",
        "returned 42, not a list of classes",
    ),
    "no Config": (
        EFFECT.replace("    Config = AcmeConfig\n", "")
        + "@hookimpl\ndef mdframework_register_effects():\n    return [AcmeFx]\n",
        "AcmeFx.Config is not a subclass of mdframework.PluginConfig",
    ),
    "kind as text": (
        EFFECT.replace('Literal["acme_fx"] = "acme_fx"', 'str = "acme_fx"')
        + "@hookimpl\ndef mdframework_register_effects():\n    return [AcmeFx]\n",
        "AcmeFx.Config needs kind: Literal['acme_fx'] = 'acme_fx'",
    ),
    "kind of another plugin": (
        EFFECT.replace('Literal["acme_fx"] = "acme_fx"', 'Literal["noise"] = "noise"')
        + "@hookimpl\ndef mdframework_register_effects():\n    return [AcmeFx]\n",
        "AcmeFx.Config needs kind: Literal['acme_fx']",
    ),
}


@pytest.fixture
def installed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A folder on sys.path to install distributions into; the registry is rebuilt before and
    after, and the test's modules are forgotten."""
    before = set(sys.modules)
    root = tmp_path / "site"
    root.mkdir()
    monkeypatch.syspath_prepend(str(root))
    monkeypatch.delenv(DISABLE_PLUGINS_ENV, raising=False)
    reset_default_registry()
    yield root
    reset_default_registry()
    for name in set(sys.modules) - before:
        if name.startswith("mdf_test"):
            del sys.modules[name]


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
    _make_distribution(installed, "acme-fx", "mdf_test_acme", HEADER + body, "acme_fx")
    out, err = listed(capsys)
    warnings = [line for line in err.splitlines() if "acme" in line]
    assert len(warnings) == 1 and warnings[0].startswith("mdf: warning: plugin 'acme_fx' is ")
    assert why in warnings[0]
    assert "acme_fx" in out.split("disabled:")[1]
    assert cli.main(["config", "schema"]) == 0
    assert run_point_target(tmp_path) == 0


CLASH = (
    HEADER
    + """
from mdf_lfm.waveform import LfmPulseDoppler

class AcmeLfm(LfmPulseDoppler):
    '''Another pulse-Doppler radar that claims the name of ours.'''

@hookimpl
def mdframework_register_radar_waveforms():
    return [AcmeLfm]
"""
)


def test_a_kind_claimed_twice_is_withheld_and_the_rest_works(
    installed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A third party's radar named `lfm`: every command stopped with exit code 2, `--help`
    too. Now neither `lfm` is chosen for the user; the commands that do not need it work, a run
    that does says why in one line, and switching one plugin off resolves it."""
    _make_distribution(installed, "acme-radar", "mdf_test_acme_radar", CLASH, "acme_radar")
    out, err = listed(capsys)
    assert "mdf: warning: the radar kind 'lfm' is disabled: claimed by acme-radar 0.0.1 and " in err
    assert "mdf --disable-plugin NAME" in err
    assert "radar kind 'lfm'" in out.split("disabled:")[1]
    assert run_point_target(tmp_path) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    assert "radar.kind: no radar plugin named 'lfm'" in lines[0]
    assert "claimed by acme-radar 0.0.1 and mdf-lfm" in lines[0]
    assert run_point_target(tmp_path, "--disable-plugin", "acme_radar") == 0


CLI_FAILS = (
    HEADER
    + EFFECT
    + """
@hookimpl
def mdframework_register_effects():
    return [AcmeFx]

@hookimpl
def mdframework_add_cli_commands(subparsers):
    raise RuntimeError("no command today")
"""
)


def test_a_plugin_whose_command_fails_is_switched_off_whole(
    installed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Its failing CLI hook listed it as disabled while its effect stayed installed and ran."""
    _make_distribution(installed, "acme-cmd", "mdf_test_acme_cmd", CLI_FAILS, "acme_cmd")
    out, err = listed(capsys)
    assert "no command today" in err and "acme_cmd" in out.split("disabled:")[1]
    assert "acme_fx" not in out.split("disabled:")[0]
    config = tmp_path / "fx.toml"
    text = (EXAMPLES / "point_target.toml").read_text()
    config.write_text('effects = [{ kind = "acme_fx" }]\n' + text)
    code = cli.main(["run", str(config), "--out", str(tmp_path / "o")])
    assert code == 2 and "no effects plugin named 'acme_fx'" in capsys.readouterr().err


@pytest.mark.parametrize("returned", ["{AcmeFx}", "(c for c in [AcmeFx])"], ids=["set", "gen"])
def test_any_collection_of_classes_registers(
    returned: str, installed: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A set or a generator of classes worked before the check for a returned single class,
    and still does."""
    body = (
        HEADER + EFFECT + f"@hookimpl\ndef mdframework_register_effects():\n    return {returned}\n"
    )
    _make_distribution(installed, "acme-fx", "mdf_test_acme", body, "acme_fx")
    out, err = listed(capsys)
    assert "acme" not in err and "acme_fx" in out and "disabled:" not in out


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

class AcmeConfig(LfmConfig):
    kind: Literal["acme_lfm"] = "acme_lfm"

class AcmeLfm(LfmPulseDoppler):
    """Our radar, for old and new mdframework."""
    name = "acme_lfm"
    Config = AcmeConfig

@hookimpl
def mdframework_register_radar_waveforms():
    return [AcmeLfm]

@hookimpl
def mdframework_register_waveforms():
    return [AcmeLfm]
'''
    )
    _make_distribution(installed, "acme-lfm", "mdf_test_acme_lfm", body, "acme_lfm")
    out, err = listed(capsys)
    assert "acme" not in err and "acme_lfm" in out and "disabled:" not in out


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
    sub = subparsers.add_parser("acme", help="an acme command")
    sub.set_defaults(func=lambda args: 0)
    raise RuntimeError("half a command")
"""
    )
    _make_distribution(installed, "acme-half", "mdf_test_acme_half", body, "acme_half")
    assert cli.main(["acme"]) == 2
    err = capsys.readouterr().err
    assert "half a command" in err and "invalid choice: 'acme'" in err
    with pytest.raises(SystemExit) as done:
        cli.main(["--help"])
    assert done.value.code == 0
    help_text = capsys.readouterr().out
    assert "plugins" in help_text and "acme" not in help_text
