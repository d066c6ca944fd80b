"""``--set KEY=VALUE``: a config field changed from the command line, as if the file said so."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import EXAMPLES

from mdframework import cli
from mdframework.config import apply_overrides, load_run_config, read_config_file
from mdframework.errors import ConfigError

POINT = EXAMPLES / "point_target.toml"


def mdf(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = cli.main(args)
    out = capsys.readouterr()
    return code, out.out, out.err


def test_values_are_read_as_toml_and_other_text_as_a_string() -> None:
    data = {"radar": {"kind": "lfm", "prf": 2400.0}, "effects": [{"kind": "noise"}]}
    got = apply_overrides(
        data,
        [
            "radar.prf=4000",
            "radar.fc = 7.7e10",
            "processing.window=hann",
            'scene.person.motion="recorded"',
            "scene.radar_position=[10.0, 0.0, 2.0]",
            "effects.0.snr_db=10",
            "figures.enabled=false",
            'motion."a.b"=1',
        ],
    )
    assert got["radar"] == {"kind": "lfm", "prf": 4000, "fc": 7.7e10}
    assert isinstance(got["radar"]["prf"], int) and isinstance(got["radar"]["fc"], float)
    assert got["processing"] == {"window": "hann"}  # a table made on the way
    assert got["scene"] == {"person": {"motion": "recorded"}, "radar_position": [10.0, 0.0, 2.0]}
    assert got["effects"] == [{"kind": "noise", "snr_db": 10}]
    assert got["figures"] == {"enabled": False}
    assert got["motion"] == {"a.b": 1}  # a quoted part keeps its dot
    # a value that TOML would read as more than one line of the file is text, not its first line
    two = apply_overrides({}, ["radar.prf=4000\nradar.fc = 1", "scene.gate=[1.0,\n2.0]"])
    assert two == {"radar": {"prf": "4000\nradar.fc = 1"}, "scene": {"gate": [1.0, 2.0]}}
    # no config field is a date or a time: a label that TOML reads as one stays the text given
    dates = apply_overrides({}, ["a=2024-01-01", "b=07:32:00", "c=1979-05-27T07:32:00Z"])
    assert dates == {"a": "2024-01-01", "b": "07:32:00", "c": "1979-05-27T07:32:00Z"}
    assert data == {"radar": {"kind": "lfm", "prf": 2400.0}, "effects": [{"kind": "noise"}]}


def test_overrides_apply_in_order_and_a_whole_table_replaces_the_old() -> None:
    data = {"radar": {"kind": "lfm", "prf": 2400.0, "fc": 15e9}}
    assert apply_overrides(data, ["radar.prf=1", "radar.prf=2"])["radar"]["prf"] == 2
    assert apply_overrides(data, ['radar={kind = "cw"}'])["radar"] == {"kind": "cw"}
    assert apply_overrides(data, ['radar={kind = "cw"}', "radar.fc=1e9"])["radar"] == {
        "kind": "cw",
        "fc": 1e9,
    }


@pytest.mark.parametrize(
    ("item", "message"),
    [
        ("radar", "--set radar: expected KEY=VALUE (e.g. --set radar.prf=4000)"),
        ("=4", "--set =4: expected KEY=VALUE (e.g. --set radar.prf=4000)"),
        ("radar..prf=4", "--set radar..prf=4: 'radar..prf' is not a dotted key like radar.prf"),
        ("seed.x=1", "--set seed.x=1: seed is 7, not a table"),
        (
            "effects.1.snr_db=1",
            "--set effects.1.snr_db=1: effects is a list of 1: index it "
            "with 0..0, or set the whole list",
        ),
        (
            "effects.x=1",
            "--set effects.x=1: effects is a list of 1: index it with 0..0, or set the whole list",
        ),
        (  # a digit that is not a decimal one indexes nothing (int() refused it: a traceback)
            'effects."²"=1',
            '--set effects."²"=1: effects is a list of 1: index it with 0..0, or set the '
            "whole list",
        ),
        (
            "scene.effects.0.x=1",
            "--set scene.effects.0.x=1: scene.effects is not in the config: set the whole list",
        ),
    ],
)
def test_malformed_overrides_are_one_line_naming_the_override(item: str, message: str) -> None:
    data = {"seed": 7, "effects": [{"kind": "noise"}]}
    with pytest.raises(ConfigError) as info:
        apply_overrides(data, [item])
    assert str(info.value) == message


def test_an_override_runs_as_the_same_edit_in_the_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The same record, to the bit, as a file that says what the overrides say."""
    edited = read_config_file(POINT)
    edited["radar"]["prf"] = 1200.0
    edited["scene"]["radar_position"] = [8.0, 1.0, 1.5]
    edited_file = tmp_path / "edited.json"
    edited_file.write_text(json.dumps(edited))
    assert (
        mdf(["run", str(edited_file), "--out", str(tmp_path / "file"), "--no-figures"], capsys)[0]
        == 0
    )
    code, _, err = mdf(
        ["run", str(POINT), "--out", str(tmp_path / "set"), "--no-figures",
         "--set", "radar.prf=1200", "--set", "scene.radar_position=[8.0, 1.0, 1.5]"],
        capsys,
    )  # fmt: skip
    assert code == 0, err
    resolved = json.loads((tmp_path / "set" / "config.resolved.json").read_text())
    assert resolved["radar"]["prf"] == 1200.0
    assert resolved["scene"]["radar_position"] == [8.0, 1.0, 1.5]
    with (
        np.load(tmp_path / "file" / "result.npz") as a,
        np.load(tmp_path / "set" / "result.npz") as b,
    ):
        assert np.array_equal(a["signal"], b["signal"])
        assert np.array_equal(a["spectrogram_db"], b["spectrogram_db"])
        # and not the example's own record: half the pulses of its PRF 2400 Hz
        assert len(b["signal"]) == 2401


def test_an_invalid_value_names_the_override_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    code, stdout, err = mdf(
        ["run", str(POINT), "--out", str(out), "--set", "radar.prf=4000", "--set", "radar.prf=-1"],
        capsys,
    )
    assert code == 2 and stdout == ""
    assert err == "mdf: error: --set radar.prf=-1: radar.prf: must be at least 1 (got -1)\n"
    assert not out.exists()
    code, _, err = mdf(["check", str(POINT), "--set", "radar.prff=1"], capsys)
    assert code == 2
    assert err == (
        "mdf: error: --set radar.prff=1: radar.prff: unknown field 'prff' (did you mean 'prf'?)\n"
    )
    # a field the override did not touch is still blamed on the file
    code, _, err = mdf(
        ["check", str(POINT), "--set", "radar.prf=1000", "--set", "radar.bogus=1"], capsys
    )
    assert code == 2 and err.startswith("mdf: error: --set radar.bogus=1: radar.bogus: unknown")


def test_check_reports_the_overridden_run(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = mdf(["check", str(POINT), "--set", "radar.prf=1200"], capsys)
    assert code == 0
    assert out.splitlines()[0] == f"{POINT} --set radar.prf=1200: valid"
    assert "PRF 1.2 kHz" in out and "2401 pulses" in out
    assert "+-6 m/s" in out  # lambda PRF / 4 = 0.02 m * 1200 / 4 (the example's 2400: +-12)


def test_a_relative_path_is_relative_to_the_config_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    config = load_run_config(
        EXAMPLES / "cmu_walk.toml", overrides=["motion.file=data/cmu/asf-amc/09_06.amc"]
    )
    assert config.motion.file == EXAMPLES / "data" / "cmu" / "asf-amc" / "09_06.amc"  # type: ignore[attr-defined]


DATASET = EXAMPLES / "datasets" / "cmu.toml"


def test_a_dataset_plan_takes_the_override(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = mdf(["dataset", "check", str(DATASET), "--json"], capsys)
    assert code == 0, err
    assert json.loads(out)["first"]["walk"]["n_pulses"] == 2401  # the config's PRF, 2400 Hz
    code, out, err = mdf(
        ["dataset", "check", str(DATASET), "--json", "--set", "base.radar.prf=1000",
         "--set", "variations.aspect_deg=[0.0]"],
        capsys,
    )  # fmt: skip
    assert code == 0, err
    plan = json.loads(out)
    assert plan["first"]["walk"]["n_pulses"] == 1001
    assert plan["n_records"] == 280 // 4  # one aspect of the config's four


def test_an_invalid_dataset_or_experiment_override_names_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = mdf(["dataset", "check", str(DATASET), "--set", "base.radar.prf=-1"], capsys)
    assert code == 2
    assert err.splitlines()[-1] == (
        "mdf: error: --set base.radar.prf=-1: sources[0] record 0: base.radar.prf: must be at "
        "least 1 (got -1)"
    )
    out = tmp_path / "ds"
    code, _, err = mdf(
        ["dataset", "build", str(DATASET), "--out", str(out), "--set", "seed=-1"], capsys
    )
    assert (code, err) == (2, "mdf: error: --set seed=-1: seed: must be at least 0 (got -1)\n")
    assert not out.exists()
    experiment = EXAMPLES / "experiment_cmu.toml"
    out = tmp_path / "exp"
    code, _, err = mdf(
        ["experiment", str(experiment), "--out", str(out), "--set", "classifier.k=0"], capsys
    )
    assert (code, err) == (
        2,
        "mdf: error: --set classifier.k=0: classifier.k: must be at least 1 (got 0)\n",
    )
    assert not out.exists()


def test_a_dataset_built_with_an_override_keeps_it_and_resumes_only_with_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    config = tmp_path / "ds.toml"
    walk = EXAMPLES / "data" / "cmu" / "asf-amc" / "02_01.amc"
    config.write_text(
        f'seed = 7\n[[sources]]\nlabel = "walk"\nmotion = {{ kind = "cmu", file = "{walk}" }}\n'
        "max_records = 2\n[record_lengths]\nwalk = 1.0\n[base.processing]\nnfft = 256\n"
    )
    out = tmp_path / "ds"
    build = ["dataset", "build", str(config), "--out", str(out), "--workers", "1", "--no-progress"]
    code, _, err = mdf([*build, "--set", "base.radar.prf=1200"], capsys)
    assert code == 0, err
    manifest = json.loads((out / "dataset.json").read_text())
    assert manifest["config"]["base"]["radar"]["prf"] == 1200
    with np.load(next((out / "records").glob("*.npz"))) as record:
        # lambda PRF / 4 = 6 m/s at PRF 1200 Hz (12 m/s at the default 2400 Hz)
        assert 5.9 < record["velocity_mps"].max() <= 6.0
    assert mdf([*build, "--set", "base.radar.prf=1200"], capsys)[0] == 0  # resumes: done
    code, _, err = mdf(build, capsys)  # the file's own PRF is another config
    assert code == 2 and "different config" in err


@pytest.mark.parametrize(
    ("item", "rest"),
    [
        ("sources.0.motion.file=nope.amc", "sources[0].motion.file: file not found: "),
        ('sources.0.motion.kind="bvh"', "sources[0].motion: file must be a .bvh file, got "),
    ],
)
def test_a_dataset_planning_error_names_the_override_that_caused_it(
    item: str, rest: str, capsys: pytest.CaptureFixture[str]
) -> None:
    # planning names a source as sources[0], validation as sources.0: both are the override's
    code, _, err = mdf(["dataset", "check", str(DATASET), "--set", item], capsys)
    assert code == 2
    assert err.splitlines()[-1].startswith(f"mdf: error: --set {item}: {rest}")


def test_a_key_may_index_a_list_as_dataset_errors_name_it() -> None:
    """Dataset errors name a source sources[0]; the docs tell users to write the key as errors
    name it, and sources[0].hop was refused as not a dotted key."""
    data = {"sources": [{"hop": 0.5}, {"hop": 0.5}]}
    got = apply_overrides(data, ["sources[1].hop=0.25", "sources.0.hop=1.0"])
    assert got == {"sources": [{"hop": 1.0}, {"hop": 0.25}]}


def test_an_error_between_two_fields_names_the_override_of_the_other(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A window longer than the file's nfft is reported at processing.nfft, naming
    window_length: the override of window_length caused it, not the file (it was blamed)."""
    item = "processing.window_length=60000"
    code, _, err = mdf(["check", str(POINT), "--set", item], capsys)
    assert code == 2
    assert err.startswith(f"mdf: error: --set {item}: processing.nfft: "), err
    # not a sibling that the message merely mentions as a word ("the window's length")
    code, _, err = mdf(
        ["check", str(POINT), "--set", item, "--set", "processing.window=hann"], capsys
    )
    assert err.startswith(f"mdf: error: --set {item}: processing.nfft: "), err
    # nor one in the list of a table's names: the unknown field is the file's
    config = tmp_path / "typo.toml"
    config.write_text(POINT.read_text().replace("prf = 2400.0", "prf = 2400.0\nfoo = 1"))
    code, _, err = mdf(["check", str(config), "--set", "radar.prf=3000"], capsys)
    assert err.startswith(f"mdf: error: {config}: radar.foo: unknown field 'foo' (allowed: "), err
    assert "prf" in err


def test_a_files_field_wrong_for_the_kind_an_override_chose_names_that_override(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The point target's LFM radar fields are unknown to the FMCW radar that --set chose:
    the file's field is at fault, and the message says which override made it wrong."""
    item = "radar.kind=fmcw"
    code, _, err = mdf(["check", str(POINT), "--set", item], capsys)
    assert code == 2
    assert err.startswith(f"mdf: error: {POINT}: radar.carrier_frequency: unknown field"), err
    assert err.endswith(f" (for the kind of --set {item})\n"), err


@pytest.mark.parametrize("command", ["check", "run"])
def test_a_scene_error_about_an_overridden_field_names_the_override(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A noise effect that --set added beside the FMCW radar's own receiver noise is refused
    when the run is built: the message names the override, as a config error about it does,
    not the file (which has no effects); from the file, it names the file."""
    fmcw = EXAMPLES / "fmcw_walk.toml"
    item = 'effects=[{kind="noise",mode="thermal"}]'
    out = tmp_path / "out"
    argv = [command, str(fmcw), "--set", item] + (["--out", str(out)] if command == "run" else [])
    code, _, err = mdf(argv, capsys)
    assert code == 2
    (line,) = err.splitlines()
    assert line.startswith(f"mdf: error: --set {item}: effects.noise: the 'fmcw' radar adds "), err
    assert not out.exists()
    config = tmp_path / "noisy.toml"
    config.write_text(
        fmcw.read_text().replace('file = "data/', f'file = "{EXAMPLES}/data/')
        + '\n[[effects]]\nkind = "noise"\nmode = "thermal"\n'
    )
    code, _, err = mdf(["check", str(config), "--set", "radar.gain_dbi=3"], capsys)
    assert err.startswith(f"mdf: error: {config}: effects.noise: the 'fmcw' radar adds "), err
