"""The ``mdf`` command line: examples run, outputs are complete, errors are one line."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import EXAMPLES

from mdframework import cli
from mdframework.config import load_run_config, read_config_file

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
        "radar.prf: Input should be greater than 0",
    ),
    "extra.toml": (
        '[motion]\nkind = "point_targets"\nlength = 1.0\nspeed = 3\n'
        "targets = [{ position = [10, 0, 0] }]\n",
        "motion.speed: Extra inputs are not permitted",
    ),
    "kind.toml": ('[motion]\nkind = "nope"\n', "motion: unknown kind 'nope'"),
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
    ("extra", "expected"),
    [
        ("gate = -5.0\n", "scene.gate"),
        (
            '[processing]\nwindow = "nosuchwindow"\n',
            "processing.window: Value error, unknown window",
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
