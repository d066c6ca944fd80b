"""The ``mdf`` command line: examples run, outputs are complete, errors are one line."""

from __future__ import annotations

import argparse
import csv
import json
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import EXAMPLES

from mdframework import cli
from mdframework.config import load_run_config, read_config_file
from mdframework.errors import ConfigError

EXAMPLE_CONFIGS = sorted(p for p in EXAMPLES.glob("*.toml") if not p.stem.startswith("experiment_"))


def run_cli(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = cli.main(args)
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.mark.parametrize("config", EXAMPLE_CONFIGS, ids=[p.stem for p in EXAMPLE_CONFIGS])
def test_every_example_parses(config: Path) -> None:
    load_run_config(config)


@pytest.mark.parametrize("config", EXAMPLE_CONFIGS, ids=[p.stem for p in EXAMPLE_CONFIGS])
def test_every_example_runs(
    config: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    code, _, err = run_cli(["run", str(config), "--out", str(out)], capsys)
    assert code == 0, err
    with np.load(out / "result.npz") as d:
        n_doppler, n_frames = d["spectrogram_db"].shape
        assert d["signal"].dtype == np.complex128 and d["signal"].ndim == 1
        assert d["doppler_hz"].shape == d["velocity_mps"].shape == (n_doppler,)
        assert d["time_s"].shape == (n_frames,)
        assert np.all(np.isfinite(d["spectrogram_db"]))
        # velocity axis = Doppler * lambda / 2 with exact c
        lam = json.loads((out / "metadata.json").read_text())["wavelength_m"]
        assert np.allclose(d["velocity_mps"], d["doppler_hz"] * lam / 2, rtol=1e-14)
    assert (out / "spectrogram.png").stat().st_size > 10_000
    resolved = json.loads((out / "config.resolved.json").read_text())
    assert resolved["radar"]["kind"] == read_config_file(config).get("radar", {}).get("kind", "lfm")
    # the resolved config is itself a valid config that reproduces the run
    again = tmp_path / "again.json"
    again.write_text(json.dumps(resolved))
    load_run_config(again)


def test_resolved_config_of_a_relative_config_path_runs_from_anywhere(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """`mdf run cfg/walk.toml` (a path relative to the working folder): the resolved config
    names the motion file absolutely, so it checks from another folder and reproduces the run."""
    cfg = tmp_path / "cfg"
    cfg.mkdir()
    for name in ("02_01.amc", "02.asf"):
        (cfg / name).write_bytes((EXAMPLES / "data" / "cmu" / "asf-amc" / name).read_bytes())
    (cfg / "walk.toml").write_text(
        '[motion]\nkind = "cmu"\nfile = "02_01.amc"\nduration = 1.0\n\n'
        '[scatterers]\nkind = "ellipsoid"\n\n[radar]\nkind = "lfm"\n\n'
        "[scene]\nradar_position = [10.0, 0.0, 2.0]\n"
    )
    monkeypatch.chdir(tmp_path)
    assert run_cli(["run", "cfg/walk.toml", "--out", "out", "--no-figures"], capsys)[0] == 0
    resolved = json.loads((tmp_path / "out" / "config.resolved.json").read_text())
    assert resolved["motion"]["file"] == str(cfg / "02_01.amc")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    code, _, err = run_cli(["check", str(tmp_path / "out" / "config.resolved.json")], capsys)
    assert code == 0, err


def test_a_full_disk_is_one_line_naming_the_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A full disk cannot be made here, so numpy's writer raises what a full disk makes it
    raise: the command says so in one line naming the file, exit code 2, and leaves no
    output folder behind (it was not there before)."""
    import errno

    def full(file: Any, *args: Any, **kwargs: Any) -> None:
        raise OSError(errno.ENOSPC, "No space left on device", str(file))

    monkeypatch.setattr(np, "savez_compressed", full)
    out = tmp_path / "o"
    code, _, err = run_cli(
        ["run", str(EXAMPLES / "point_target.toml"), "--out", str(out), "--no-figures"], capsys
    )
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    # the file by the name it was to have in --out (not its staging folder's), and what to do
    assert err.strip() == (
        f"mdf: error: {out / 'result.npz'}: No space left on device; free some space (or choose "
        "another --out) and run the command again"
    )
    assert list(tmp_path.iterdir()) == []  # no output folder, no staging debris


def test_point_target_example_doppler(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "pt"
    assert run_cli(["run", str(EXAMPLES / "point_target.toml"), "--out", str(out)], capsys)[0] == 0
    with np.load(out / "result.npz") as d:
        k = np.argmax(d["spectrogram_db"], axis=0)
        assert np.all(np.abs(d["doppler_hz"][k] + 100.069) <= 2400 / 1024 / 2)


def test_plugins_lists_interfaces_and_distributions(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run_cli(["plugins"], capsys)
    assert code == 0
    assert "radar:" in out and "motion:" in out
    line = next(x for x in out.splitlines() if x.strip().startswith("lfm "))
    assert "mdf-lfm" in line


def test_config_schema_is_json_schema(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run_cli(["config", "schema"], capsys)
    assert code == 0
    schema = json.loads(out)
    assert {"motion", "radar", "scene", "processing"} <= set(schema["properties"])
    assert "motion" in schema["required"]
    assert "lfm" in json.dumps(schema)


BAD_CONFIGS = {
    "syntax.toml": ("[motion\nkind = 1\n", "invalid TOML"),
    "field.toml": (
        '[motion]\nkind = "point_targets"\nlength = 1.0\n'
        "targets = [{ position = [10, 0, 0] }]\n[radar]\nkind = 'lfm'\nprf = -5\n",
        "radar.prf: must be at least 1 (got -5)",
    ),
    "extra.toml": (
        '[motion]\nkind = "point_targets"\nlength = 1.0\nspeed = 3\n'
        "targets = [{ position = [10, 0, 0] }]\n",
        "motion.speed: unknown field 'speed'",
    ),
    "kind.toml": ('[motion]\nkind = "nope"\n', "motion.kind: no motion plugin named 'nope'"),
    "nofile.toml": ('[motion]\nkind = "cmu"\nfile = "missing.bvh"\n', "motion.file:"),
    "yaml.yaml": ("motion: [1, 2\n", "invalid YAML: line"),
    "short.toml": (
        '[motion]\nkind = "point_targets"\nlength = 0.05\n'
        "targets = [{ position = [10, 0, 0] }]\n[scatterers]\nkind = 'points'\n",
        "processing.window_length",
    ),
    "atradar.toml": (
        '[motion]\nkind = "point_targets"\nlength = 1.0\n'
        "targets = [{ position = [10, 0, 0] }]\n[scatterers]\nkind = 'points'\n"
        "[scene]\nradar_position = [10, 0, 0]\n",
        "comes within 0 m of the radar",
    ),
    "nobody.toml": (
        '[motion]\nkind = "point_targets"\nlength = 1.0\ntargets = [{ position = [10, 0, 0] }]\n',
        "scatterers.kind: the 'ellipsoid' model needs a human body",
    ),
}


@pytest.mark.parametrize("name", sorted(BAD_CONFIGS))
def test_bad_input_is_one_line_exit_2_and_writes_nothing(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text, expected = BAD_CONFIGS[name]
    cfg = tmp_path / name
    cfg.write_text(text)
    out = tmp_path / "out"
    code, _stdout, err = run_cli(["run", str(cfg), "--out", str(out)], capsys)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("mdf: error: ")
    assert expected in lines[0]
    assert str(cfg) in lines[0]  # names the file
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]  # no staging debris


def test_missing_config_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_cli(
        ["run", str(tmp_path / "nope.toml"), "--out", str(tmp_path / "o")], capsys
    )
    assert code == 2 and "nope.toml: cannot read" in err


def test_debug_shows_the_traceback(tmp_path: Path) -> None:
    cfg = tmp_path / "kind.toml"
    cfg.write_text('[motion]\nkind = "nope"\n')
    args = [
        sys.executable,
        "-m",
        "mdframework.cli",
        "--debug",
        "run",
        str(cfg),
        "--out",
        str(tmp_path / "o"),
    ]
    proc = subprocess.run(args, capture_output=True, text=True, check=False)
    assert proc.returncode == 2
    assert "Traceback" in proc.stderr and "mdf: error:" in proc.stderr
    proc = subprocess.run(
        [a for a in args if a != "--debug"], capture_output=True, text=True, check=False
    )
    assert proc.returncode == 2 and "Traceback" not in proc.stderr


def test_yaml_and_json_configs_run(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import tomllib

    import yaml

    data = tomllib.loads((EXAMPLES / "point_target.toml").read_text())
    (tmp_path / "pt.yaml").write_text(yaml.safe_dump(data))
    (tmp_path / "pt.json").write_text(json.dumps(data))
    results = []
    for name in ("pt.yaml", "pt.json"):
        out = tmp_path / name.replace(".", "_")
        assert run_cli(["run", str(tmp_path / name), "--out", str(out)], capsys)[0] == 0
        with np.load(out / "result.npz") as d:
            results.append(d["signal"])
    assert np.array_equal(results[0], results[1])


@pytest.mark.parametrize(
    ("name", "text", "expected"),
    [
        (
            "twice.yaml",
            "motion:\n  kind: point_targets\nmotion: {}\n",
            "line 3: key 'motion' given",
        ),
        (
            "nested.yml",
            "radar:\n  kind: lfm\n  prf: 2400\n  prf: 1000\n",
            "line 4: key 'prf' given twice",
        ),
        (
            "twice.json",
            '{"motion": {"kind": "point_targets"},\n "radar": {"kind": "lfm",\n "prf": 2400,'
            ' "prf": 1000}}',
            "line 2: key 'prf' given twice in one object (the object opened there)",
        ),
        ("list-key.yaml", "radar:\n  ? [a, b]\n  : 1\n", "line 2: found unhashable key"),
    ],
)
def test_a_key_given_twice_in_yaml_or_json_is_refused(
    name: str, text: str, expected: str, tmp_path: Path
) -> None:
    """TOML refuses a repeated key; YAML and JSON parsers keep the last one silently, which
    would run another radar than the one the user reads first."""
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(ConfigError, match=re.escape(expected)) as err:
        read_config_file(path)
    assert str(path) in str(err.value)
    # a merge key may still be overridden: that is what it is for
    path = tmp_path / "merge.yaml"
    path.write_text("base: &b {prf: 2400, kind: lfm}\nradar:\n  <<: *b\n  prf: 1000\n")
    assert read_config_file(path)["radar"] == {"prf": 1000, "kind": "lfm"}


@pytest.mark.parametrize(
    ("section", "field", "value", "expected"),
    [
        ("radar", "prf", True, "radar.prf: a number, not a flag (true)"),
        ("radar", "gain_dbi", True, "radar.gain_dbi: a number, not a flag (true)"),
        ("processing", "floor_db", "-50", 'processing.floor_db: a number, not text ("-50")'),
        ("processing", "hop", True, "processing.hop: a number, not a flag (true)"),
        ("processing", "keep_scatterers", 1, "processing.keep_scatterers: true or false, not int"),
        ("scene", "radar_position", [True, 0, 0], "scene.radar_position: a number, not a flag"),
        ("scene", "gate", True, "scene.gate: a number or 'track', not a flag (true)"),
        ("scene", "gate", "2.5", "scene.gate: a number or 'track', not text (\"2.5\")"),
        (
            "figures",
            "velocity_span",
            True,
            "figures.velocity_span: a number or 'auto' or 'full', not a flag",
        ),
        ("processing", "hop", "x" * 100, 'processing.hop: a number, not text ("xxxxxxxxx'),
        ("scene", "gate", "trak", "scene.gate: a number or 'track', not text (\"trak\")"),
        ("scene", "radar_position", [0, "1", 0], 'scene.radar_position: a number, not text ("1")'),
    ],
)
def test_numbers_and_flags_are_not_converted(
    section: str, field: str, value: Any, expected: str, tmp_path: Path
) -> None:
    """pydantic's lax mode would read `prf = true` as 1 Hz and `floor_db = "-50"` as -50 dB:
    a flag or text where a number belongs (or a number where a flag belongs) is refused, naming
    the field, in the core's sections and the plugins' alike, and inside a point target."""
    import tomllib

    data = tomllib.loads((EXAMPLES / "point_target.toml").read_text())
    data.setdefault(section, {})[field] = value
    path = tmp_path / "c.json"
    path.write_text(json.dumps(data))
    with pytest.raises(ConfigError) as err:
        load_run_config(path)
    assert expected in str(err.value) and len(str(err.value)) < 200
    data = tomllib.loads((EXAMPLES / "point_target.toml").read_text())
    data["motion"]["targets"][0]["rcs"] = "1"
    path.write_text(json.dumps(data))
    with pytest.raises(ConfigError, match=re.escape('rcs: a number, not text ("1")')):
        load_run_config(path)
    data["motion"]["targets"][0]["rcs"] = 1  # an integer is a number
    path.write_text(json.dumps(data))
    assert load_run_config(path).motion.targets[0].rcs == 1.0  # type: ignore[attr-defined]


def test_a_data_file_that_is_a_folder_is_named_as_one(tmp_path: Path) -> None:
    """`file = "data/cmu"` names a folder: the error says so (not "must be a .bvh or .amc
    file, got 'cmu'", which reads like the source's kind)."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(f'[motion]\nkind = "cmu"\nfile = "{EXAMPLES / "data" / "cmu"}"\n')
    with pytest.raises(ConfigError, match=r"motion\.file: .*data/cmu is a folder; name a file"):
        load_run_config(cfg)


def test_named_choices_and_yaml_numbers_still_read(tmp_path: Path) -> None:
    """What the check must not refuse: a field's named choices (`gate = "track"`,
    `velocity_span = "full"`), and numbers YAML 1.1 would leave as text when unquoted (`15e9`,
    `1e-3`, `inf`), read as TOML and JSON read them; quoted, they stay text and are refused. A
    flag field given a date (TOML has dates) is one line too."""
    path = tmp_path / "pt.yaml"
    path.write_text(
        "motion: {kind: point_targets, length: 1.0, targets: [{position: [50, 0, 0]}]}\n"
        "radar: {kind: lfm, carrier_frequency: 15e9, bandwidth: 150e6, prf: 2.4e3}\n"
        "scene: {radar_position: [0, 0, 1e-3], gate: track}\n"
        "figures: {velocity_span: full}\n"
    )
    cfg: Any = load_run_config(path)
    assert (cfg.radar.carrier_frequency, cfg.radar.bandwidth, cfg.radar.prf) == (15e9, 150e6, 2400)
    assert cfg.scene.radar_position[2] == 1e-3 and cfg.scene.gate == "track"
    # TOML's lower-case inf only: `Nan` (a given name) and `Infinity` stay text
    assert read_config_file_text(
        tmp_path, "a: inf\nb: -inf\nc: 1_000e3\nd: Nan\ne: Infinity\n"
    ) == {
        "a": float("inf"),
        "b": float("-inf"),
        "c": 1e6,
        "d": "Nan",
        "e": "Infinity",
    }
    path.write_text(path.read_text().replace("15e9", '"15e9"'))
    with pytest.raises(ConfigError, match=re.escape("radar.carrier_frequency: a number, not text")):
        load_run_config(path)
    toml = tmp_path / "date.toml"
    toml.write_text(
        (EXAMPLES / "point_target.toml").read_text()
        + "[processing]\nkeep_scatterers = 1979-05-27\n"
    )
    with pytest.raises(ConfigError, match=r"processing\.keep_scatterers: true or false, not date"):
        load_run_config(toml)


def read_config_file_text(folder: Path, text: str) -> Any:
    """read_config_file of a YAML file holding ``text``."""
    path = folder / "t.yaml"
    path.write_text(text)
    return read_config_file(path)


def test_a_repeated_key_deeper_than_the_line_finder_goes_is_still_one_line(
    tmp_path: Path,
) -> None:
    """The line of a repeated JSON key comes from a second, pure-Python parse, which recurses
    deeper than the first: at 400 levels it would overflow, so the error names no line there."""
    path = tmp_path / "deep.json"
    path.write_text('{"a":' * 400 + '{"x": 1, "x": 2}' + "}" * 400)
    with pytest.raises(ConfigError, match=r"invalid JSON: key 'x' given twice in one object$"):
        read_config_file(path)


def test_a_config_that_is_not_a_regular_file_is_refused(tmp_path: Path) -> None:
    """A named pipe would block the reader forever; a folder is named as one."""
    pipe = tmp_path / "fifo.toml"
    os.mkfifo(pipe)
    with pytest.raises(ConfigError, match=r"fifo\.toml: cannot read: not a regular file"):
        read_config_file(pipe)
    (tmp_path / "dir.toml").mkdir()
    with pytest.raises(ConfigError, match=r"dir\.toml: cannot read: it is a folder"):
        read_config_file(tmp_path / "dir.toml")


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        ("gate = -5.0\n", "scene.gate"),
        (
            '[processing]\nwindow = "nosuchwindow"\n',
            "processing.window: unknown window",
        ),
    ],
)
def test_more_config_field_errors(
    extra: str, expected: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cfg = tmp_path / "c.toml"
    cfg.write_text((EXAMPLES / "point_target.toml").read_text() + extra)  # ends in [scene]
    code, _, err = run_cli(["run", str(cfg), "--out", str(tmp_path / "o")], capsys)
    assert code == 2 and expected in err and len(err.strip().splitlines()) == 1


FIX_HINTS = {
    "misspelt motion table": (
        '[motions]\nkind = "point_targets"\nlength = 1.0\ntargets = [{ position = [10, 0, 0] }]\n',
        "motion: missing: add a [motion] section with a kind (the config has [motions]: rename it)",
    ),
    "nearest field": (
        '[motion]\nkind = "point_targets"\nlength = 1.0\n'
        "targets = [{ position = [10, 0, 0] }]\n[scatterers]\nkind = 'points'\n"
        "[radar]\nkind = 'lfm'\nfrequency = 24e9\n",
        "radar.frequency: unknown field 'frequency' (did you mean 'carrier_frequency'?)",
    ),
    "nearest field of a default kind": (  # [radar] without kind is lfm
        '[motion]\nkind = "point_targets"\nlength = 1.0\n'
        "targets = [{ position = [10, 0, 0] }]\n[scatterers]\nkind = 'points'\n"
        "[radar]\nfrequency = 24e9\n",
        "radar.frequency: unknown field 'frequency' (did you mean 'carrier_frequency'?)",
    ),
    "nearest field of the default scatterer model": (
        '[motion]\nkind = "point_targets"\nlength = 1.0\n'
        "targets = [{ position = [10, 0, 0] }]\n[scatterers]\nplacment = 'joints17'\n",
        "scatterers.placment: unknown field 'placment' (did you mean 'placement'?)",
    ),
    "nearest kind": (
        '[motion]\nkind = "point_target"\n',
        "motion.kind: no motion plugin named 'point_target' (did you mean 'point_targets'?); "
        "installed: ",
    ),
    "nearest effect": (
        '[motion]\nkind = "point_targets"\nlength = 1.0\n'
        "targets = [{ position = [10, 0, 0] }]\n[scatterers]\nkind = 'points'\n"
        '[[effects]]\nkind = "nose"\n',
        "effects.0.kind: no effects plugin named 'nose' (did you mean 'noise'?); installed: "
        "antenna, attenuation, clutter, ",  # then those of other distributions installed
    ),
    "toml table order": (
        '[motion]\nkind = "point_targets"\nlength = 1.0\n'
        "targets = [{ position = [10, 0, 0] }]\n[scatterers]\nkind = 'points'\n"
        '[scene]\nradar_position = [0, 0, 0]\neffects = [{ kind = "noise" }]\n',
        "scene.effects: unknown field 'effects' (allowed: gate, min_range, person, "
        "radar_position); in TOML a key belongs to the last [table] header above it, so "
        "'effects = ...' written after [scene] landed inside it: move it above the first "
        "[table] header or write each effect as an [[effects]] table",
    ),
    "literal": (
        '[motion]\nkind = "point_targets"\nlength = 1.0\n'
        "targets = [{ position = [10, 0, 0] }]\n[scatterers]\nkind = 'points'\n"
        '[processing]\naliasing = "warning"\n',
        "processing.aliasing: must be one of 'warn', 'error' (got 'warning') "
        "(did you mean 'warn'?)",
    ),
    "missing kind": (
        "[motion]\nlength = 1.0\n",
        "motion.kind: missing: say which motion plugin (installed kinds: boulic, ",
    ),
}


@pytest.mark.parametrize("case", sorted(FIX_HINTS))
def test_errors_say_how_to_fix(
    case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str], only_our_plugins: None
) -> None:
    text, expected = FIX_HINTS[case]
    cfg = tmp_path / "c.toml"
    cfg.write_text(text)
    code, _, err = run_cli(["run", str(cfg), "--out", str(tmp_path / "o")], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert f"mdf: error: {cfg}: {expected}" in err
    assert "Extra inputs" not in err and "Input should" not in err and "Value error" not in err


def _subparsers(parser: argparse.ArgumentParser, path: str = "mdf") -> list[tuple[str, Any]]:
    found = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                found.append((f"{path} {name}", sub))
                found += _subparsers(sub, f"{path} {name}")
    return found


def test_every_command_has_a_description_and_examples() -> None:
    """Including the commands plugins add (mdf kinect info, mdf capture)."""
    commands = _subparsers(cli.build_parser())
    names = [n for n, _ in commands]
    assert {"mdf run", "mdf check", "mdf dataset build", "mdf kinect info", "mdf capture"} <= set(
        names
    )
    for name, sub in commands:
        assert sub.description and len(sub.description) > 20, f"{name} has no description"
        assert sub.epilog and sub.epilog.startswith("examples:"), f"{name} has no examples"
        for line in sub.epilog.splitlines()[1:]:
            assert line.strip().startswith("mdf "), f"{name}: example {line!r}"


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        cli.main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out.startswith("mdf (mdframework) 0.2.2, Python 3.")


@pytest.mark.parametrize("where", ["first", "after the command", "last"])
def test_debug_is_accepted_anywhere(where: str, tmp_path: Path) -> None:
    cfg = tmp_path / "kind.toml"
    cfg.write_text('[motion]\nkind = "nope"\n')
    args = ["run", str(cfg), "--out", str(tmp_path / "o")]
    position = {"first": 0, "after the command": 1, "last": len(args)}[where]
    args.insert(position, "--debug")
    proc = subprocess.run(
        [sys.executable, "-m", "mdframework.cli", *args], capture_output=True, text=True
    )
    assert proc.returncode == 2
    assert "Traceback" in proc.stderr and "mdf: error:" in proc.stderr


def test_split_global_options_stops_at_double_dash() -> None:
    rest, debug, off = cli.split_global_options(
        ["run", "--disable-plugin", "mdf_cmu", "x.toml", "--disable-plugin=mdf_kinect", "--debug"]
    )
    assert rest == ["run", "x.toml"] and debug and off == ["mdf_cmu", "mdf_kinect"]
    rest, debug, off = cli.split_global_options(["run", "--", "--debug"])
    assert rest == ["run", "--", "--debug"] and not debug and off == []


def test_check_output_in_the_docs_is_current(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    guide = (EXAMPLES.parent / "docs" / "getting-started.md").read_text()
    monkeypatch.chdir(EXAMPLES.parent)  # the guide's path, from the repository root
    code, out, _ = run_cli(["check", "examples/point_target.toml"], capsys)
    assert code == 0
    assert f"```text\n{out}```" in guide


def check_then_run(
    config: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> tuple[dict[str, Any], dict[str, Any], Path]:
    """`mdf check --json` then `mdf run` of ``config``: the plan, the run's metadata and its
    result.npz. The spectrogram shape and Doppler bin spacing of the plan are the run's."""
    code, out, err = run_cli(["check", str(config), "--json"], capsys)
    assert code == 0, err
    plan = json.loads(out)
    code, _, err = run_cli(
        ["run", str(config), "--out", str(tmp_path / "o"), "--no-figures"], capsys
    )
    assert code == 0, err
    meta = json.loads((tmp_path / "o" / "metadata.json").read_text())
    with np.load(tmp_path / "o" / "result.npz") as d:
        assert d["signal"].shape == (plan["n_pulses"],)
        assert d["spectrogram_db"].shape == (plan["nfft"], plan["n_frames"])
        dv = float(np.diff(d["velocity_mps"][:2])[0])
    assert plan["velocity_bin_mps"] == pytest.approx(dv, rel=1e-12)
    return plan, meta, tmp_path / "o" / "result.npz"


@pytest.mark.parametrize(
    "name",
    ["cmu_walk.toml", "point_target.toml", "boulic_walk.toml", "cw_walk.toml", "fmcw_walk.toml"],
)
def test_check_predicts_what_the_run_does(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The pulses, spectrogram geometry, axes and aliasing verdict of `mdf check` are those of
    the run, for pulsed (LFM), CW and FMCW radars (whose spectrogram is one spectrum per frame:
    75 frames of 1024 bins in 2.5 s of 30 Hz frames); the fastest joint's radial speed bounds
    the run's fastest scatterer within the frame-rate differencing (10 %)."""
    plan, meta, _ = check_then_run(EXAMPLES / name, tmp_path, capsys)
    assert plan["max_unambiguous_velocity_mps"] == meta["max_unambiguous_velocity_mps"]
    assert plan["max_joint_radial_speed_mps"] >= 0.9 * meta["max_radial_speed_mps"]
    assert plan["aliasing"] is False
    if name == "fmcw_walk.toml":
        assert (plan["nfft"], plan["n_frames"], plan["window_pulses"]) == (1024, 75, 16)


@pytest.mark.parametrize(
    ("name", "rate", "record", "window"),
    [
        ("point_target.toml", "PRF 2.4 kHz", "4801 pulses", "window 256 pulses"),
        ("cw_walk.toml", "slow time 2 kHz", "5701 samples", "window 256 samples"),
        (
            "fmcw_walk.toml",
            "slow time 5.197 kHz (1440 pulses per second of record)",
            "3600 pulses",
            "window 16 samples",
        ),
    ],
)
def test_check_names_the_slow_time_as_the_radar_has_it(
    name: str, rate: str, record: str, window: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """`mdf check` calls a pulse-Doppler radar's slow-time rate its PRF and the samples pulses;
    a CW radar's is its I/Q rate and its samples are no pulses; an FMCW radar's is its loop
    rate, its pulses the chirps, 3 per loop and none between frames (48 per 33.3 ms frame)."""
    assert cli.main(["check", str(EXAMPLES / name)]) == 0
    out = capsys.readouterr().out
    assert f"), {rate}\n" in out and f": {record}; " in out
    assert f"spectrogram {window} (" in out


def test_check_accepts_an_fmcw_record_shorter_than_the_stft_window(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """FMCW frames with gaps give one spectrum per frame, so 0.15 s (5 frames of 48 chirps, 80
    samples of the first slot, fewer than the 256 of processing.window_length) runs, and `mdf
    check` says so (it used to refuse it for the STFT window the run does not use); an LFM
    record as short is refused by both, naming the field."""
    text = (EXAMPLES / "fmcw_walk.toml").read_text()
    text = text.replace("duration = 2.5", "duration = 0.15")
    text = text.replace('"data/', f'"{EXAMPLES}/data/')
    (tmp_path / "short.toml").write_text(text)
    plan, _, _ = check_then_run(tmp_path / "short.toml", tmp_path, capsys)
    assert (plan["n_pulses"], plan["n_frames"]) == (240, 5)
    lfm = text.replace('kind = "fmcw"\npreset = "iwr1443_short_range_3d"', 'kind = "lfm"')
    (tmp_path / "lfm.toml").write_text(lfm.replace("duration = 0.15", "duration = 0.05"))
    for command in (["check"], ["run", "--out", str(tmp_path / "lfm")]):
        code, _, err = run_cli([*command, str(tmp_path / "lfm.toml")], capsys)
        assert code == 2 and "processing.window_length: the record has 121 samples" in err, err


def test_check_warns_of_aliasing_and_names_the_prf(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """3 m/s at 24 GHz needs PRF >= 4 * 3 / 0.012491 = 960.7 Hz; 500 Hz aliases."""
    cfg = tmp_path / "fast.toml"
    cfg.write_text(
        '[motion]\nkind = "point_targets"\nlength = 2.0\n'
        "targets = [{ position = [100.0, 0.0, 0.0], velocity = [3.0, 0.0, 0.0] }]\n"
        '[scatterers]\nkind = "points"\n[radar]\ncarrier_frequency = 24e9\nprf = 500.0\n'
        "[scene]\nradar_position = [0.0, 0.0, 0.0]\n"
        "[processing]\nwindow_length = 128\nhop = 16\nnfft = 256\n"
    )
    code, out, _ = run_cli(["check", str(cfg)], capsys)
    assert code == 0
    assert (
        "aliasing    LIKELY: fastest joint 3 m/s radially; raise radar.prf to at least 961 Hz"
        in out
    )
    assert not (tmp_path / "o").exists()


def test_check_refuses_a_body_nearer_the_radar_than_min_range(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A radar inside the walker's path: the run refuses the scatterer at the pelvis (the
    range equation does not hold at centimetres); `mdf check` refuses the joint there too,
    instead of calling the config valid."""
    cfg = tmp_path / "close.toml"
    amc = EXAMPLES / "data" / "cmu" / "asf-amc" / "02_01.amc"
    cfg.write_text(
        f'[motion]\nkind = "cmu"\nfile = "{amc}"\nduration = 1.0\n'
        '[scatterers]\nkind = "ellipsoid"\n[radar]\nkind = "lfm"\n'
        "[scene]\nradar_position = [0.1, 0.0, 1.0]\n"
    )
    code, _, err = run_cli(["check", str(cfg)], capsys)
    assert code == 2 and "joint 'base' comes within 0.0659 m of the radar" in err, err
    code, _, err = run_cli(["run", str(cfg), "--out", str(tmp_path / "o")], capsys)
    assert code == 2 and "scatterer 'base' comes within 0.0657 m of the radar" in err, err


def test_a_target_too_near_is_refused_at_its_time_in_the_recording(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A point reaching the radar 3.374 s into its recording, in a record cut at
    ``motion.start = 2``: the refusal names both times, 1.374 s into the record and 3.374 s
    into the recording (the time ``motion.start`` counts), in the run and in ``mdf check``
    (its joint frames 10 ms apart: 3.370 s). It named the record's time alone, where the
    recording shows nothing."""
    cfg = tmp_path / "near.toml"
    cfg.write_text(
        '[motion]\nkind = "point_targets"\nlength = 5.0\nstart = 2.0\n'
        "targets = [{ position = [10.123, 0.0, 0.0], velocity = [-3.0, 0.0, 0.0] }]\n"
        '[scatterers]\nkind = "points"\n[scene]\nradar_position = [0.0, 0.0, 0.0]\n'
    )
    code, _, err = run_cli(["run", str(cfg), "--out", str(tmp_path / "o")], capsys)
    assert code == 2 and "t = 1.374 s into the record, 3.374 s into the recording" in err, err
    code, _, err = run_cli(["check", str(cfg)], capsys)
    assert code == 2 and "t = 1.370 s into the record, 3.370 s into the recording" in err, err


def test_progress_notes_only_on_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    """Notes of slow steps reach an interactive user; a pipe keeps one line per error."""
    import io

    from mdframework import progress

    class Tty(io.StringIO):
        def isatty(self) -> bool:
            return True

    for stream, expected in ((Tty(), "mdf: planning ...\n"), (io.StringIO(), "")):
        monkeypatch.setattr(sys, "stderr", stream)
        progress.note("planning")
        progress.note("hidden", enabled=False)
        assert stream.getvalue() == expected


def _screen(text: str) -> list[str]:
    """The lines a terminal shows after ``text`` (newline, carriage return, cursor up, clear
    line): a small model of a terminal for the status-line tests."""
    lines, row, col = [""], 0, 0
    i = 0
    while i < len(text):
        if text.startswith("\x1b[1A", i):
            row, i = max(row - 1, 0), i + 4
            continue
        if text.startswith("\x1b[2K", i):
            lines[row], i = "", i + 4
            continue
        ch = text[i]
        i += 1
        if ch == "\n":
            row, col = row + 1, 0
            if row == len(lines):
                lines.append("")
        elif ch == "\r":
            col = 0
        else:
            line = lines[row].ljust(col)
            lines[row] = line[:col] + ch + line[col + 1 :]
            col += 1
    while lines and not lines[-1]:
        lines.pop()
    return lines


def test_a_bad_experiment_config_leaves_one_line_on_a_terminal(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """On a terminal `mdf experiment` notes what it is doing while it reads the config and the
    plugins; when the config turns out bad, that note is erased, so the error is the only line
    left (it used to leave two). A note followed by other output stays."""
    import io

    from mdframework import progress

    class Tty(io.StringIO):
        def isatty(self) -> bool:
            return True

    bad = tmp_path / "experiment.json"
    bad.write_text(json.dumps({"dataset": {"path": str(tmp_path)}, "classifier": {"k": 10**9}}))
    term = Tty()
    monkeypatch.setattr(sys, "stderr", term)
    assert cli.main(["experiment", str(bad), "--out", str(tmp_path / "out")]) == 2
    shown = _screen(term.getvalue())
    assert term.getvalue().startswith("mdf: reading the experiment config")  # it was shown
    assert len(shown) == 1 and shown[0].startswith("mdf: error: ") and "classifier.k" in shown[0]
    # the same for a dataset whose recording is refused while the records are planned
    (tmp_path / "bad.txt").write_text("point_id: 0\nx: 1e308\n")
    ds = tmp_path / "dataset.json"
    source = {"label": "a", "recording": {"kind": "radhar", "file": "bad.txt"}}
    ds.write_text(json.dumps({"sources": [source]}))
    term = Tty()
    monkeypatch.setattr(sys, "stderr", term)
    assert cli.main(["dataset", "build", str(ds), "--out", str(tmp_path / "ds")]) == 2
    shown = _screen(term.getvalue())
    assert "mdf: planning the records" in term.getvalue()
    assert len(shown) == 1 and shown[0].startswith("mdf: error: ") and "bad.txt:2: x" in shown[0]
    # a note followed by other output (a warning) stays; so does one when nothing fails
    term = Tty()
    monkeypatch.setattr(sys, "stderr", term)
    progress.note("step one")
    progress.printed()
    print("mdf: warning: something", file=sys.stderr)
    progress.retract()
    progress.note("step two")
    assert _screen(term.getvalue()) == [
        "mdf: step one ...",
        "mdf: warning: something",
        "mdf: step two ...",
    ]
    progress.retract()
    assert _screen(term.getvalue())[-1] == "mdf: warning: something"


def test_ctrl_c_wrapped_by_python_is_still_an_interrupt(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Ctrl-C while a class is created (an import) reaches us as a RuntimeError whose cause is
    the KeyboardInterrupt (Python 3.11): one line, exit 130, not an internal error."""
    from mdframework import cli

    def interrupted(args: Any) -> int:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as exc:
            raise RuntimeError("Error calling __set_name__ on 'Field' instance") from exc

    monkeypatch.setattr(cli, "_cmd_plugins", interrupted)
    assert cli.main(["plugins"]) == cli.EXIT_INTERRUPTED
    assert capsys.readouterr().err == "mdf: interrupted\n"


@pytest.mark.parametrize("command", ["run", "check"])
def test_a_bug_in_a_plugins_constructor_is_an_internal_error_naming_the_plugin(
    command: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A KeyError inside a radar's __init__ is the plugin's bug, not the user's input: exit 1,
    one line naming the exception and the plugin (it used to be `mdf: error: presets`, exit 2,
    as if the config had named an unknown kind); --debug shows the traceback."""
    from mdf_lfm import LfmPulseDoppler

    def broken_init(self: Any, config: Any) -> None:
        self.preset = {}["presets"]  # type: ignore[misc]

    monkeypatch.setattr(LfmPulseDoppler, "__init__", broken_init)
    args = [command, str(EXAMPLES / "point_target.toml")]
    if command == "run":
        args += ["--out", str(tmp_path / "o")]
    code, _, err = run_cli(args, capsys)
    assert code == 1, err
    assert err.strip() == (
        "mdf: internal error: KeyError: 'presets' (in the radar plugin 'lfm' "
        "(mdf_lfm.waveform.LfmPulseDoppler) while it was built from its config; run with --debug "
        "for the traceback)"
    )
    assert not (tmp_path / "o").exists()
    with pytest.raises(KeyError, match="presets"):
        cli.main([*args, "--debug"])


def test_check_counts_the_scatterers_effects_add(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A room of 40 static reflectors with its ground bounce: the run's pulses carry
    3 x (17 + 40) = 171 scatterers (direct, single bounce, image), and `mdf check` counts them
    all in its memory estimate (it used to count the 17 joints alone, 10 times too few)."""
    from mdframework.check import MIB, SCATTERER_PULSE_BYTES

    amc = EXAMPLES / "data" / "cmu" / "asf-amc" / "02_01.amc"
    cfg = tmp_path / "room.toml"
    cfg.write_text(
        'effects = [{ kind = "static_scene", count = 40, seed = 0 }, { kind = "multipath" }]\n'
        f'[motion]\nkind = "cmu"\nfile = "{amc}"\nduration = 0.5\n'
        '[scatterers]\nkind = "ellipsoid"\n[radar]\nkind = "lfm"\n'
        "[scene]\nradar_position = [10.0, 0.0, 2.0]\n"
    )
    plan, meta, _ = check_then_run(cfg, tmp_path, capsys)
    assert len(meta["scatterers"]) == 171
    assert plan["n_scatterers"] == 171
    rows = min(plan["n_pulses"], 4096)
    expected = rows * 171 * SCATTERER_PULSE_BYTES / MIB
    assert plan["memory_terms_mib"]["scatterers"] == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("bandwidth", [150e6, 300e6])
def test_check_counts_the_raw_paths_fast_time_arrays(bandwidth: float) -> None:
    """The raw path's fast-time arrays (sampled echoes, the chirp's terms, the matched filter's
    FFTs) are most of its memory and were left out of `mdf check`'s estimate (13 MiB for the
    raw walk, which peaks 40 MiB above the analytic path): the radar's own term is now within
    15 % of what tracemalloc measures the raw path to add, at two bandwidths (the fast-time
    samples and the filter grow with it). Each peak is the lower of two runs after a short one
    (the first run's imports, and a resize of the interned strings' table, which the run's
    paths feed: 3.7 MB in the analytic run's peak put the term 16 % above)."""
    from helpers import traced_peak

    from mdframework.check import MIB, plan_run
    from mdframework.pipeline import simulate

    def configs(duration: float) -> tuple[Any, Any]:
        sets = [f"motion.duration={duration}", f"radar.bandwidth={bandwidth}"]
        sets.append("figures.enabled=false")
        return (
            load_run_config(
                EXAMPLES / "cmu_walk_raw.toml", overrides=[*sets, 'radar.path="analytic"']
            ),
            load_run_config(EXAMPLES / "cmu_walk_raw.toml", overrides=sets),
        )

    def peak(config: Any, short: Any) -> int:
        return traced_peak(lambda: simulate(config), warm_up=lambda: simulate(short), runs=2)[1]

    analytic, raw = configs(1.0)
    peaks = [peak(*pair) for pair in zip((analytic, raw), configs(0.2), strict=True)]
    term = plan_run(raw).memory_terms_mib["fast time"] * MIB
    assert term == pytest.approx(peaks[1] - peaks[0], rel=0.15)
    assert "fast time" not in plan_run(analytic).memory_terms_mib


def test_check_counts_a_long_walks_motion_and_echo_and_a_float32_db_map() -> None:
    """A 60 s Boulic walk (380 frames a second): `mdf check`'s memory is within 15 % of what
    tracemalloc measures the run to hold at its peak. It left out the motion (the recording,
    the placed window and its two interpolants: as much as the spectrogram here) and the echo
    kept for the received-stage effects, and counted the dB map in float64 (it is float32):
    27 % too little, and for a 30-minute walk 1.75 GB where the run peaked at 2.8 GB."""
    import tracemalloc

    from mdframework import pipeline
    from mdframework.check import MIB, plan_run
    from mdframework.config import validate_run_config
    from mdframework.pipeline import simulate

    config = validate_run_config(
        {
            "motion": {"kind": "boulic", "duration": 60.0},
            "scatterers": {"kind": "ellipsoid"},
            "radar": {"kind": "lfm"},
            "scene": {"radar_position": [12.0, 0.0, 1.5], "person": {"motion": "treadmill"}},
        }
    )
    simulate(config)  # the first run's one-time allocations out of the way
    pipeline._LAST_WINDOW.clear()
    tracemalloc.start()
    try:
        simulate(config)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    plan = plan_run(config)
    assert plan.memory_mib * MIB == pytest.approx(peak, rel=0.15)
    assert plan.memory_terms_mib["motion"] > 0.4 * plan.memory_terms_mib["spectrogram"]


def test_check_memory_terms_of_the_echo_and_a_shared_canonical_body() -> None:
    """The signal term counts the echo the received-stage effects refer to (8 + 8 + 16 + 16
    bytes a pulse), and a canonical body that shares the recording's arrays is not counted
    twice; one of its own is."""
    from mdf_mujoco.source import BoulicConfig, BoulicWalker

    from mdframework.check import MIB, memory_estimate, motion_memory
    from mdframework.skeleton import Skeleton

    terms = memory_estimate(1000, 0, 1, 1, 100)
    assert terms["signal"] == pytest.approx(1000 * 48 / MIB)
    assert "motion" not in terms
    motion = BoulicWalker(BoulicConfig(n_cycles=2, nt=64)).load()
    body = motion.canonical()
    window = 3 * body.n_joints * 3 * 8 * 10
    source = motion.skeleton.positions.nbytes
    assert motion_memory(motion, body, 10) == source + window
    copy = Skeleton(body.time, body.positions.copy(), body.joint_names, body.valid)
    assert motion_memory(motion, copy, 10) == 2 * source + window


def test_getting_started_quotes_the_raw_walks_fast_time_memory() -> None:
    from mdframework.check import plan_run

    term = plan_run(load_run_config(EXAMPLES / "cmu_walk_raw.toml")).memory_terms_mib["fast time"]
    page = " ".join((EXAMPLES.parent / "docs" / "getting-started.md").read_text().split())
    assert f"{term:.0f} MiB for `examples/cmu_walk_raw.toml`" in page


def test_check_counts_an_fmcw_radars_range_doppler_maps(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The kept range-Doppler maps grow with the record (about 0.9 GB for ten minutes of the
    IWR1443 preset's walk): `mdf check` counts them twice, the blocks' maps and their join."""
    from mdframework.check import MIB

    plan, _, result_npz = check_then_run(EXAMPLES / "fmcw_walk.toml", tmp_path, capsys)
    with np.load(result_npz) as result:
        maps = result["range_doppler"].nbytes
    assert plan["memory_terms_mib"]["range-Doppler maps"] == pytest.approx(2 * maps / MIB)


def test_check_refuses_an_fmcw_scatterer_beyond_the_maximum_range(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The FMCW radar refuses a body beyond its maximum range before its first chirp; `mdf
    check` refuses it with the same line instead of calling the config valid."""
    text = (EXAMPLES / "fmcw_walk.toml").read_text().replace('"data/', f'"{EXAMPLES}/data/')
    cfg = tmp_path / "far.toml"
    cfg.write_text(
        text.replace("radar_position = [6.0, 0.0, 1.0]", "radar_position = [14.0, 0.0, 1.0]")
    )
    line = "radar.sample_rate: the farthest scatterer at 14.26 m beats at 6.658 MHz"
    for command in (["check"], ["run", "--out", str(tmp_path / "o")]):
        code, _, err = run_cli([*command, str(cfg)], capsys)
        assert code == 2 and line in err, err


def test_dataset_check_predicts_the_build(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`mdf dataset check` plans a dataset as the build does and reports, per label, the
    records and what `mdf check` says of the first: here 2 walk records of 1 s and 2 run
    records of 0.5 s at PRF 1500 Hz, each with 3 x (17 + 10) = 81 scatterers (a room of 10
    reflectors and its ground bounce); the build then makes exactly those records with those
    spectrograms (the run's own count of the scatterers is tested above). The run at 10 m/s
    aliases at 7.5 m/s and the plan says so. It writes
    nothing, and a run config is refused naming the command that reads it."""
    cmu = EXAMPLES / "data" / "cmu" / "asf-amc"
    cfg = tmp_path / "ds.toml"
    cfg.write_text(
        "seed = 1\n"
        f'[[sources]]\nlabel = "walk"\nmotion = {{ kind = "cmu", file = "{cmu}/02_01.amc" }}\n'
        "hop = 1.0\n"
        f'[[sources]]\nlabel = "run"\nmotion = {{ kind = "cmu", file = "{cmu}/09_06.amc" }}\n'
        "hop = 0.5\n"
        "[record_lengths]\nwalk = 1.0\nrun = 0.5\n"
        '[base.radar]\nkind = "lfm"\nprf = 1500.0\n[base.scatterers]\nkind = "ellipsoid"\n'
        '[base]\neffects = [{ kind = "static_scene", count = 10, seed = 0 }, '
        '{ kind = "multipath" }]\n'
        "[base.processing]\nnfft = 256\nwindow_length = 128\nhop = 16\n"
    )
    code, out, err = run_cli(["dataset", "check", str(cfg), "--json"], capsys)
    assert code == 0, err
    plan = json.loads(out)
    assert list(tmp_path.iterdir()) == [cfg]
    assert plan["records"] == {"walk": 2, "run": 2} and plan["n_records"] == 4
    assert plan["first"]["run"]["aliasing"] and not plan["first"]["walk"]["aliasing"]
    code, _, err = run_cli(
        ["dataset", "build", str(cfg), "--out", str(tmp_path / "ds"), "--workers", "1"], capsys
    )
    assert code == 0, err
    rows = list(csv.DictReader((tmp_path / "ds" / "index.csv").open()))
    assert [r["label"] for r in rows].count("walk") == 2 and len(rows) == 4
    for row in rows:
        first = plan["first"][row["label"]]
        with np.load(tmp_path / "ds" / "records" / f"{row['id']}.npz") as d:
            assert d["spectrogram_db"].shape == (first["nfft"], first["n_frames"])
        assert first["n_scatterers"] == 81
    code, out, err = run_cli(["dataset", "check", str(EXAMPLES / "cmu_walk.toml")], capsys)
    assert code == 2 and "a run config (it has `motion`), not a dataset config" in err


def test_dataset_check_warns_once_and_sizes_no_spectrograms_of_recordings(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A motion planned again (its label's first record) does not repeat its warnings: the
    sim-to-real dataset's 13_18 glitch is said once (it was said twice); a dataset of real
    radar recordings only has no spectrograms to size (null, it said 0.0)."""
    code, _, err = run_cli(
        ["dataset", "check", str(EXAMPLES / "datasets" / "sim2real.toml")], capsys
    )
    assert code == 0 and err.count("13_18.amc: 3 single-frame glitch(es)") == 1, err
    code, out, err = run_cli(
        ["dataset", "check", str(EXAMPLES / "datasets" / "radhar.toml"), "--json"], capsys
    )
    assert code == 0 and json.loads(out)["spectrogram_mib"] is None, err


def test_check_judges_aliasing_on_the_tracks_the_run_interpolates(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """CMU 09_06 (a run) at PRF 2040 Hz: the frames' differences give 10.16 m/s, under the
    unambiguous 10.19 m/s, but the cubic spline the run resamples at its pulses reaches
    10.61 m/s, so the run warns of aliasing and asks for 2124 Hz. `mdf check`
    judged the frames alone ("none expected", and at least 2033 Hz to a run that aliased);
    it now names the run's speed and PRF."""
    text = (EXAMPLES / "cmu_run.toml").read_text().replace('"data/', f'"{EXAMPLES}/data/')
    cfg = tmp_path / "run.toml"
    cfg.write_text(text.replace('kind = "lfm"', 'kind = "lfm"\nprf = 2040.0'))
    code, out, err = run_cli(["check", str(cfg)], capsys)
    assert code == 0, err
    assert "LIKELY: fastest joint 10.6 m/s radially; raise radar.prf to at least 2124 Hz" in out
    code, _, err = run_cli(["run", str(cfg), "--out", str(tmp_path / "o"), "--no-figures"], capsys)
    assert code == 0 and "raise radar.prf to at least 2124 Hz" in err, err


def test_mdf_help_lists_the_exit_codes_a_script_sees(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A script needs the exit codes: `mdf --help` lists them, and they are the ones the
    commands return (2 for a missing config)."""
    with pytest.raises(SystemExit) as ended:
        cli.main(["--help"])
    assert ended.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    for number, meaning in (
        (0, "done"),
        (1, "internal error"),
        (2, "bad input"),
        (cli.EXIT_INTERRUPTED, "interrupted (Ctrl-C)"),
        (cli.EXIT_TERMINATED, "terminated (SIGTERM)"),
    ):
        assert f"{number} {meaning}" in text
    code, _, _ = run_cli(["check", str(tmp_path / "nope.toml")], capsys)
    assert code == 2


def test_experiment_takes_the_build_options_of_dataset_build(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """`mdf experiment` builds its dataset as `mdf dataset build` does, so it takes the same
    --workers (over the config's `workers`) and --scheduler (it refused both as unknown, so a
    cluster job could not choose its processes or its scheduler)."""
    from mdframework import experiment
    from mdframework.errors import ConfigError

    seen: dict[str, Any] = {}

    def build(*args: Any, **kw: Any) -> None:
        seen.update(workers=kw["workers"], scheduler=kw["scheduler"])
        raise ConfigError("stopped here")

    monkeypatch.setattr(experiment, "build_dataset", build)
    cfg = EXAMPLES / "experiment_cmu.toml"
    argv = ["experiment", str(cfg), "--out", str(tmp_path / "e")]
    code, _, err = run_cli([*argv, "--workers", "3", "--scheduler", "local"], capsys)
    assert code == 2 and "stopped here" in err, err
    assert seen == {"workers": 3, "scheduler": "local"}
    monkeypatch.undo()
    code, _, err = run_cli([*argv, "--scheduler", "nonsense"], capsys)
    assert code == 2 and "Dask scheduler 'nonsense': not an address" in err, err


def test_an_fft_shorter_than_its_window_names_the_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """nfft below window_length is blamed on processing.nfft (it named the section alone)."""
    cfg = tmp_path / "fft.toml"
    cfg.write_text(
        (EXAMPLES / "point_target.toml").read_text()
        + "[processing]\nnfft = 100\nwindow_length = 256\n"
    )
    code, _, err = run_cli(["check", str(cfg)], capsys)
    assert code == 2
    assert err.strip() == (
        f"mdf: error: {cfg}: processing.nfft: 100 is shorter than window_length 256: give an "
        "nfft of at least the window's length"
    )


def stop_and_skip(folder: Path, text: str) -> tuple[Path, Path]:
    """The dataset config ``text`` written as is (``stop.toml``) and with ``on_error = "skip"``
    (``skip.toml``) into ``folder``."""
    stop, skip = folder / "stop.toml", folder / "skip.toml"
    stop.write_text(text)
    skip.write_text('on_error = "skip"\n' + text)
    return stop, skip


def test_dataset_check_all_finds_the_record_the_build_stops_at(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A walk toward a radar 3.2 m ahead in 0.5 s records: the fifth record brings the hip
    within 0.24 m, under scene.min_range. `mdf dataset check --all` plans every record and
    stops naming that record, window and cause as the build does; with on_error = "skip" it
    counts it as the build skips it."""
    amc = EXAMPLES / "data" / "cmu" / "asf-amc" / "02_01.amc"
    text = (
        f'seed = 1\n[[sources]]\nlabel = "walk"\nmotion = {{ kind = "cmu", file = "{amc}" }}\n'
        "hop = 0.5\n[record_lengths]\nwalk = 0.5\n"
        '[base.radar]\nkind = "lfm"\n[base.scatterers]\nkind = "ellipsoid"\n'
        "[base.scene]\nradar_position = [3.2, 0.0, 1.0]\n"
    )
    stop, skip = stop_and_skip(tmp_path, text)
    where = re.escape(f"(walk; source file {amc}, window 2.000-2.500 s): ")
    where = r"record 00004-[0-9a-f]{10} " + where
    code, _, err = run_cli(["dataset", "check", str(stop), "--all"], capsys)
    assert code == 2 and re.search(where + "joint 'l_hip' comes within 0.242 m", err), err
    code, _, err = run_cli(["dataset", "build", str(stop), "--out", str(tmp_path / "d")], capsys)
    assert code == 2 and re.search(where + "scatterer 'l_hip' comes within 0.242 m", err), err
    code, out, err = run_cli(["dataset", "check", str(skip), "--all", "--json"], capsys)
    assert code == 0, err
    plan = json.loads(out)
    assert plan["n_planned"] == {"walk": 4} and plan["n_skipped"] == {"walk": 1}
    assert re.match(where, plan["skipped"]["walk"])


def hand_lost_walk(folder: Path) -> str:
    """The real UTKinect walk (file frames 252-390 at 60 Hz) written into ``folder`` with its
    left hand lost after 0.8 s (file frame 300): a table motion section, inline TOML."""
    ut = EXAMPLES / "data" / "kinect" / "utkinect" / "joints_s01_e01.txt"
    rows = [line.split() for line in ut.read_text().splitlines() if line.strip()]
    for row in rows:  # HandLeft, the eighth joint
        if float(row[0]) > 300:
            row[1 + 7 * 3 : 1 + 8 * 3] = ["0", "0", "0"]
    table = folder / "walk.txt"
    table.write_text("\n".join(" ".join(row) for row in rows) + "\n")
    joints = ", ".join(
        f'"{j}"'
        for j in (
            "HipCenter Spine ShoulderCenter Head ShoulderLeft ElbowLeft WristLeft HandLeft "
            "ShoulderRight ElbowRight WristRight HandRight HipLeft KneeLeft AnkleLeft FootLeft "
            "HipRight KneeRight AnkleRight FootRight"
        ).split()
    )
    return (
        f'kind = "table", file = "{table}", header = false, delimiter = "whitespace", '
        f'time_column = "frame", frame_rate = 60.0, joints = [{joints}], joint_set = "kinect-v1", '
        'axes = ["z", "x", "y"], zero_is_missing = true, time_range = [252, 390]'
    )


def test_dataset_check_names_a_record_the_run_cannot_interpolate_as_the_build_does(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The real UTKinect walk with its left hand lost after its first 0.8 s: the second
    record's window has no track of it to interpolate (a ValueError of the core, not of a
    plugin). The build names that record and its cause (exit 2), or skips it; `mdf dataset
    check` said 'internal error' (exit 1), as it caught only mdframework's own errors."""
    motion = hand_lost_walk(tmp_path)
    text = (
        f'seed = 1\n[[sources]]\nlabel = "walk"\nmotion = {{ {motion} }}\n'
        '[record_lengths]\nwalk = 0.5\n[base.radar]\nkind = "lfm"\n[base.scatterers]\n'
        'kind = "ellipsoid"\n[base.scene]\n'
        'person = { motion = "recorded", position = [2.3, 0.0] }\n'
    )
    stop, skip = stop_and_skip(tmp_path, text)
    cause = r"s\): motion: joint 'l_hand' is tracked only until 0\.800 s of the recording, but "
    code, _, err = run_cli(["dataset", "build", str(stop), "--out", str(tmp_path / "d")], capsys)
    assert code == 2 and re.search(r"mdf: error: .*record 0000[123]-.*" + cause, err), err
    code, _, err = run_cli(["dataset", "check", str(stop), "--all"], capsys)
    window = r"mdf: error: .*record 00001-.*window 0\.500-1\.000 "
    assert code == 2 and re.search(window + cause + "the record runs from 0.500 to 1.000", err)
    code, out, err = run_cli(["dataset", "check", str(skip), "--all", "--json"], capsys)
    assert code == 0, err
    plan = json.loads(out)
    assert plan["n_skipped"] == {"walk": plan["records"]["walk"] - plan["n_planned"]["walk"]} != {}
    assert re.search(cause, plan["skipped"]["walk"])


def test_a_record_past_a_lost_joints_track_is_the_users_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The real UTKinect walk with its left hand lost after 0.8 s, a record from 1.0 s: the
    run cannot interpolate that joint there. `mdf run` and `mdf check` said 'internal error:
    ValueError ... joint 7 ...' (exit 1); it is the input's: one line naming the joint, when
    it is tracked and the record's window (exit 2), before any pulse."""
    config = tmp_path / "run.toml"
    config.write_text(
        f"motion = {{ {hand_lost_walk(tmp_path)}, start = 1.0, duration = 0.5 }}\n"
        'scatterers = { kind = "ellipsoid" }\nradar = { kind = "lfm" }\n'
        'scene = { person = { motion = "recorded", position = [2.3, 0.0] } }\n'
    )
    said = (
        r"^mdf: error: .*run\.toml: motion: joint 'l_hand' is tracked only until 0\.800 s of "
        r"the recording, but the record runs from 1\.000 to 1\.500 s"
    )
    for command in (["check"], ["run", "--out", str(tmp_path / "out"), "--no-figures"]):
        code, _, err = run_cli([command[0], str(config), *command[1:]], capsys)
        lines = [line for line in err.splitlines() if "warning" not in line]
        assert code == 2 and len(lines) == 1 and re.search(said, lines[0]), err


def test_a_missing_optional_package_is_one_line_naming_it_and_the_install(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """mdf-mujoco installed without mujoco (`pip install --no-deps`, or mujoco uninstalled
    since): the Boulic walker says which package is missing, which distribution needs it and
    how to install it, exit 2; it was `mdf: internal error: ModuleNotFoundError: No module
    named 'mujoco' (in load() of the motion plugin 'boulic' ...; check it with
    mdframework.testing.check_motion_source ...)`, blaming the plugin. The same for the core's
    figures without matplotlib; a module missing from a package that is there stays an
    internal error."""
    monkeypatch.setitem(sys.modules, "mujoco", None)  # import mujoco: ModuleNotFoundError
    out = tmp_path / "boulic"
    code, _, err = run_cli(["run", str(EXAMPLES / "boulic_walk.toml"), "--out", str(out)], capsys)
    assert (code, err) == (
        2,
        "mdf: error: mdf-mujoco needs the Python package 'mujoco', which is not installed: "
        "pip install mujoco\n",
    )
    assert not out.exists()

    monkeypatch.setitem(sys.modules, "matplotlib", None)
    out = tmp_path / "pt"
    code, _, err = run_cli(["run", str(EXAMPLES / "point_target.toml"), "--out", str(out)], capsys)
    assert (code, err) == (
        2,
        "mdf: error: mdframework needs the Python package 'matplotlib', which is not "
        "installed: pip install matplotlib\n",
    )
    assert not out.exists()
    monkeypatch.undo()

    from mdf_lfm import LfmPulseDoppler

    def broken_init(self: Any, config: Any) -> None:
        import numpy.no_such_part  # noqa: F401

    monkeypatch.setattr(LfmPulseDoppler, "__init__", broken_init)
    code, _, err = run_cli(["check", str(EXAMPLES / "point_target.toml")], capsys)
    assert code == 1, err
    assert err.startswith(
        "mdf: internal error: ModuleNotFoundError: No module named 'numpy.no_such_part' (in the "
        "radar plugin 'lfm'"
    ), err


@pytest.mark.parametrize(
    ("module", "install"),
    [
        ("sklearn.neighbors", "scikit-learn"),
        ("yaml", "pyyaml"),
        ("distributed.client", "mdframework[dask]"),
        ("ezc3d", "ezc3d"),
    ],
)
def test_a_missing_package_is_installed_by_its_name_on_pypi(
    module: str, install: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The pip install the line gives installs the package: scikit-learn, not `sklearn` (a
    deprecated stub on PyPI that fails to install), PyYAML, not `yaml`; Dask through
    mdframework's extra. Imported here, no distribution's module: 'this command needs'."""
    import importlib

    top = module.partition(".")[0]
    for name in {top, module}:  # import: ModuleNotFoundError, whatever was imported before
        monkeypatch.setitem(sys.modules, name, None)
    with pytest.raises(ModuleNotFoundError) as caught:
        importlib.import_module(module)
    assert cli._missing_package(caught.value) == (
        f"this command needs the Python package {top!r}, which is not installed: "
        f"pip install {install}"
    )


def _plan_of_a_fixed_point(radar_: dict[str, Any]) -> Any:
    """`mdf check`'s plan of a fixed 1 m^2 point 5 m from ``radar_`` at the origin."""
    from mdframework.check import plan_run
    from mdframework.config import validate_run_config

    motion = {"kind": "point_targets", "length": 0.5, "targets": [{"position": [5, 0, 0]}]}
    scene = {"radar_position": [0.0, 0.0, 0.0]}
    return plan_run(
        validate_run_config(
            {"motion": motion, "scatterers": {"kind": "points"}, "radar": radar_, "scene": scene}
        )
    )


@pytest.mark.parametrize("kind", ["fmcw", "lfm", "cw"])
def test_check_of_a_target_that_does_not_move_radially(kind: str) -> None:
    """A sensor pointed at a fixed corner reflector (no radial motion): `mdf check` of the
    FMCW radar ended in an internal error (the advice for the loop rate reaching 0 Hz divided
    by it); now every radar reports no aliasing and no advice (there is no rate to reach)."""
    from mdframework.check import format_plan

    plan = _plan_of_a_fixed_point({"kind": kind})
    assert plan.max_joint_radial_speed_mps == 0.0 and not plan.aliasing
    assert plan.prf_needed_hz == 0.0 and plan.faster_sampling == ""
    assert "aliasing    none expected: fastest joint 0 m/s radially" in format_plan(plan, "x")


@pytest.mark.parametrize(
    ("radar_", "resolution", "max_range"),
    [
        # c / (2 B) = 149.9 m for 1 MHz; c / (2 PRF) = 14.99 km at 10 kHz
        ({"kind": "lfm", "carrier_frequency": 10e9, "bandwidth": 1e6, "prf": 1e4}, 149.9, 14990),
        # AWR1843-like: B = S n / fs = 3.072 GHz, c / (2 B) = 0.0488 m; c fs / (2 S) = 12.49 m
        (
            {"kind": "fmcw", "slope": 60e12, "sample_rate": 5e6, "n_samples": 256},
            0.0488,
            12.49,
        ),
        ({"kind": "cw"}, None, None),
    ],
)
def test_check_reports_the_range_resolution_and_unambiguous_range(
    radar_: dict[str, Any], resolution: float | None, max_range: float | None
) -> None:
    """A sensor modelled from its data sheet: `mdf check` states the range resolution and the
    largest unambiguous range it implies (it stated neither: a pulse radar's c / (2 PRF) and an
    FMCW radar's maximum range c fs / (2 S) were nowhere to be seen before a run refused or
    folded a target), and no range line for a CW radar."""
    from mdframework.check import format_plan

    plan = _plan_of_a_fixed_point(radar_)
    text = format_plan(plan, "sensor.toml")
    if resolution is None:
        assert plan.range_resolution_m is None and plan.max_range_m is None
        assert "\n  range " not in text
        return
    assert plan.range_resolution_m == pytest.approx(resolution, rel=1e-3)
    assert plan.max_range_m == pytest.approx(max_range, rel=1e-3)
    assert re.search(r"\n  range +resolution [0-9.]+ m, unambiguous to [0-9.]+ k?m\n", text)


@pytest.mark.parametrize(
    ("radar_", "gate", "limit"),
    [
        ({"kind": "fmcw", "slope": 60e12, "sample_rate": 5e6}, 20.0, "12.49 m"),
        ({"kind": "lfm", "prf": 1e5}, 2000.0, "1499 m"),
    ],
)
def test_a_fixed_gate_beyond_the_unambiguous_range_is_warned_about_by_check_and_run(
    radar_: dict[str, Any], gate: float, limit: str
) -> None:
    """A fixed scene.gate beyond the sensor's unambiguous range (an FMCW radar's maximum range
    c fs / (2 S), a pulse radar's c / (2 PRF)) is no gate the sensor has: `mdf check` said the
    config was valid without a word, and the run found only an empty result. Both now warn
    before the first pulse, naming scene.gate and the range; a gate within it is not warned
    about."""
    import warnings

    from mdframework.check import plan_run
    from mdframework.config import validate_run_config
    from mdframework.pipeline import simulate

    def config(at: float) -> Any:
        motion = {"kind": "point_targets", "length": 0.5, "targets": [{"position": [5, 0, 0]}]}
        scene = {"radar_position": [0.0, 0.0, 0.0], "gate": at}
        return validate_run_config(
            {"motion": motion, "scatterers": {"kind": "points"}, "radar": radar_, "scene": scene}
        )

    match = rf"scene\.gate: the fixed range gate at {gate:g} m is beyond .* range {limit}"
    with pytest.warns(UserWarning, match=match):
        plan_run(config(gate))
    with pytest.warns(UserWarning, match=match):
        simulate(config(gate))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        plan_run(config(5.0))
        simulate(config(5.0))
