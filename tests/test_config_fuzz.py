"""Defects found by fuzzing every command's config one field at a time: each is one line on
stderr naming the config field, exit code 2, and nothing written (or, for a config that
``mdf check`` calls valid, a run that does not fail)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import EXAMPLES

from mdframework import cli, limits

POINT = (
    '[motion]\nkind = "point_targets"\nlength = 1.0\n'
    "targets = [{ position = [100.0, 0.0, 0.0], velocity = [1.0, 0.0, 0.0], rcs = 1.0 }]\n"
    '[scatterers]\nkind = "points"\n'
)


def one_error_line(args: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run the CLI; it must fail with exit code 2 and one error line, which is returned."""
    code = cli.main(args)
    err = capsys.readouterr().err
    lines = [line for line in err.strip().splitlines() if "warning" not in line]
    assert code == 2, err
    assert len(lines) == 1 and lines[0].startswith("mdf: error: "), err
    return lines[0]


def test_a_file_name_too_long_is_the_users_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cfg = tmp_path / "c.toml"
    cfg.write_text(f'[motion]\nkind = "cmu"\nfile = "{tmp_path}/{"a" * 300}.amc"\n')
    line = one_error_line(["check", str(cfg)], capsys)
    assert f"{cfg}: motion.file: " in line and "cannot read: File name too long" in line
    assert "plugin" not in line  # not blamed on the motion plugin
    assert len(line) < 400  # the 300 characters are cut short


@pytest.mark.parametrize("width", ["5e-324", "1e-9"])
def test_a_tiny_outlier_bin_is_refused_before_it_allocates(
    width: str, capsys: pytest.CaptureFixture[str]
) -> None:
    # 1e-9 m bins took 37 s and 2.5 GB of memory for the shipped MSR recording (1e-10: 25 GB);
    # a denormal width was an internal error (OverflowError)
    config = str(EXAMPLES / "kinect_msr_boxing.toml")
    line = one_error_line(["check", config, "--set", f"conditioning.outlier_bin_m={width}"], capsys)
    assert f"--set conditioning.outlier_bin_m={width}: conditioning: outlier_bin_m: " in line
    assert "histogram bins, more than 1,000,000: raise outlier_bin_m" in line


DATASET = (
    '[[sources]]\nlabel = "walk"\nmotion = { kind = "boulic", n_cycles = 2 }\n'
    "record_length = 1.0\nmax_records = 1\n"
    "[variations]\naspect_deg = [0.0]\nradar_range = [6.0]\n"
)


def dataset_check_error(
    extra: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> tuple[Path, str]:
    """``mdf dataset check`` of :data:`DATASET` with ``extra`` after it: the config and the
    one error line."""
    cfg = tmp_path / "d.toml"
    cfg.write_text(DATASET + extra)
    return cfg, one_error_line(["dataset", "check", str(cfg)], capsys)


@pytest.mark.parametrize(
    ("scene", "expected"),
    [
        ("5", "scene: must be a table (got 5)"),
        ('"x"', "scene: must be a table (got 'x')"),
        ("{ person = 3 }", "scene.person: must be a table (got 3)"),
        ("{ radar_position = 3 }", "scene.radar_position: must be a valid tuple (got 3)"),
        ('{ person = { position = "ab" } }', "scene.person.position: must be a valid tuple"),
    ],
)
def test_a_varied_scene_of_the_wrong_shape_is_named(
    scene: str, expected: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the variations (aspect, radar range) were applied to the scene before it was validated
    cfg, line = dataset_check_error(f"[base]\nscene = {scene}\n", tmp_path, capsys)
    assert line.startswith(f"mdf: error: {cfg}: sources[0] record 0: {expected}"), line


def test_the_varied_default_scene_still_moves_the_radar(tmp_path: Path) -> None:
    from mdframework.dataset import load_dataset_config, plan_records

    cfg_path = tmp_path / "d.toml"
    cfg_path.write_text(DATASET + "radar_height = [1.5]\n")
    cfg, base = load_dataset_config(cfg_path)
    (spec,) = plan_records(cfg, base)
    scene = spec.run_config["scene"]
    assert scene["radar_position"] == [6.0, 0.0, 1.5]  # from the default start (0, 0)
    assert scene["person"] == {"aspect_deg": 0.0}


def test_dataset_check_plans_every_sources_first_record(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the second source of a label was never planned: check said valid, the build failed
    cfg = tmp_path / "d.toml"
    second = '[[sources]]\nlabel = "walk"\nmotion = { kind = "boulic", n_cycles = 2 }\n'
    cfg.write_text(DATASET + second + "record_length = 0.01\nmax_records = 2\n")
    line = one_error_line(["dataset", "check", str(cfg)], capsys)
    assert line.startswith(f"mdf: error: {cfg}: record 00001-"), line
    cause = "processing.window_length: the record has 25 samples (0.0104 s) but the STFT window"
    assert cause in line
    out = tmp_path / "out"
    assert cause in one_error_line(["dataset", "build", str(cfg), "--out", str(out)], capsys)


def test_an_fmcw_slope_too_shallow_for_a_finite_range_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # mdf check called slope = 1e-300 valid; the run's range axis was infinite times zero
    cfg = tmp_path / "c.toml"
    cfg.write_text(POINT + '[radar]\nkind = "fmcw"\nslope = 1e-300\n')
    line = one_error_line(["check", str(cfg)], capsys)
    assert f"{cfg}: radar.slope: must be at least 1e+06 (got 1e-300)" in line


@pytest.mark.parametrize("kind", ["lfm", "cw", "fmcw"])
def test_an_echo_too_strong_for_the_arithmetic_is_refused_by_check_and_run(
    kind: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # gain_dbi = 300 (within the generic decibel range): mdf check said valid, the run was an
    # internal error (an overflow in the radar's float32 amplitudes or in the spectrogram)
    cfg = tmp_path / "c.toml"
    near = "[scene]\nradar_position = [95.0, 0.0, 0.0]\n"  # within the FMCW radar's range
    cfg.write_text(POINT + near + f'[radar]\nkind = "{kind}"\ngain_dbi = 300\n')
    expected = f"{cfg}: radar.gain_dbi: the echo of 1 m^2 at 1 m would carry "
    assert expected in one_error_line(["check", str(cfg)], capsys)
    out = tmp_path / "out"
    assert expected in one_error_line(["run", str(cfg), "--out", str(out)], capsys)
    assert not out.exists()
    cfg.write_text(POINT + near + f'[radar]\nkind = "{kind}"\ngain_dbi = 60\n')  # a real one
    assert cli.main(["check", str(cfg)]) == 0


@pytest.mark.parametrize("field", ["path", "config"])
def test_a_dataset_path_with_a_nul_character_is_named(
    field: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # dataset.path = "a\u0000b" was an internal error (ValueError: embedded null byte)
    cfg = tmp_path / "e.toml"
    cfg.write_text(f'[dataset]\n{field} = "a\\u0000b"\n')
    out = tmp_path / "out"
    line = one_error_line(["experiment", str(cfg), "--out", str(out)], capsys)
    assert line == f"mdf: error: {cfg}: dataset.{field}: a file name cannot hold a NUL character"
    assert not out.exists()


@pytest.mark.parametrize(
    ("setting", "expected"),
    [
        # pydantic said "Unable to parse input string as an integer, exceeded maximum size"
        (
            "processing.window_length=1e308",
            "processing.window_length: must be a whole number within the field's range "
            "(got 1e+308)",
        ),
        # pydantic said "Input is not a valid path for <class 'pathlib.Path'>"
        ("motion.file=5", "motion.file: must be a path (text) (got 5)"),
        # a kind in another case had no hint ('Lfm' had one, 'LFM' none)
        ("radar.kind='LFM'", "radar.kind: no radar plugin named 'LFM' (did you mean 'lfm'?)"),
        ("motion.kind='CMU'", "motion.kind: no motion plugin named 'CMU' (did you mean 'cmu'?)"),
    ],
)
def test_field_errors_in_plain_words(
    setting: str, expected: str, capsys: pytest.CaptureFixture[str]
) -> None:
    config = str(EXAMPLES / "cmu_walk.toml")
    line = one_error_line(["check", config, "--set", setting], capsys)
    assert line.startswith(f"mdf: error: --set {setting}: {expected}"), line


BIG = "1" + "0" * 5000  # more digits than Python converts to an integer


@pytest.mark.parametrize(
    ("name", "text", "expected"),
    [
        (  # the line: a config of many numbers has one that is too long
            "c.json",
            '{"motion": {},\n "seed": ' + BIG + "}",
            "invalid JSON: line 2: a whole number of more than 4300 digits",
        ),
        (
            "c.toml",
            f"[motion]\nkind = 'cmu'\n[processing]\nnfft = 1_{BIG}\n",
            "invalid TOML: line 4: a whole number of more than 4300 digits",
        ),
        ("c.yaml", f"motion: {{}}\nseed: {BIG}\n", "invalid YAML: line 2: a whole number of more"),
        (
            "d.yaml",
            "motion: {}\nseed: 2024-13-45\n",
            "invalid YAML: line 2: month must be in 1..12",
        ),
    ],
)
def test_a_value_the_parser_cannot_make_is_named(
    name: str, text: str, expected: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # each was an internal error (ValueError from int() or datetime.date())
    cfg = tmp_path / name
    cfg.write_text(text)
    assert one_error_line(["check", str(cfg)], capsys).startswith(f"mdf: error: {cfg}: {expected}")


def test_an_override_the_parser_cannot_make_is_named(capsys: pytest.CaptureFixture[str]) -> None:
    config = str(EXAMPLES / "point_target.toml")
    line = one_error_line(["check", config, "--set", f"seed={BIG}"], capsys)
    assert line.endswith(": a whole number of more than 4300 digits")
    assert line.startswith(f"mdf: error: --set seed={BIG[:20]}")


def test_a_null_kind_is_named(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # radar.kind = null said "radar: unknown kind None; Input tag 'None' found using 'kind'
    # does not match any of the expected tags: ..."
    cfg = tmp_path / "c.json"
    cfg.write_text(
        '{"motion": {"kind": "point_targets", "length": 1.0, "targets": [{"position": '
        '[100.0, 0, 0]}]}, "scatterers": {"kind": "points"}, "radar": {"kind": null}}'
    )
    line = one_error_line(["check", str(cfg)], capsys)
    assert line.startswith(f"mdf: error: {cfg}: radar.kind: null: say which radar plugin ("), line


def _limit_memory() -> None:  # (in the child process)
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (3 * 1024**3, 3 * 1024**3))


def test_a_wide_analytic_margin_needs_no_table_of_margin_times_scatterers(tmp_path: Path) -> None:
    # analytic_margin = 65536 (its bound) made a table of every chirp's scatterers x 131074
    # bins: about 4.5 GB for the shipped FMCW walk (the run grew past 8 GB before it was
    # stopped); every bin is near then, whatever the scatterers
    import subprocess
    import sys

    out = tmp_path / "out"
    args = ["run", str(EXAMPLES / "walk_side_by_side_fmcw.toml"), "--out", str(out)]
    args += ["--no-figures", "--set", "motion.duration=0.5"]
    args += ["--set", "radar.analytic_margin=65536"]
    done = subprocess.run(
        [sys.executable, "-m", "mdframework.cli", *args],
        capture_output=True,
        text=True,
        preexec_fn=_limit_memory,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert (out / "result.npz").is_file()


def test_a_hop_too_small_to_count_windows_is_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # hop = 1e-308 gave an infinite count of windows: OverflowError, with max_records too
    cfg = tmp_path / "d.toml"
    cfg.write_text(DATASET.replace("max_records = 1\n", "hop = 1e-308\n"))
    line = one_error_line(["dataset", "check", str(cfg)], capsys)
    assert line.startswith(f"mdf: error: {cfg}: sources[0]: 1.69e+308 windows x 1 variation(s)")
    assert line.endswith("beyond the limit of 1,000,000 records; raise hop or set max_records")
    cfg.write_text(DATASET.replace("max_records = 1\n", "hop = 1e-308\nmax_records = 2\n"))
    assert cli.main(["dataset", "check", str(cfg)]) == 0


KERNEL = """
import resource, sys
import numpy as np
from mdframework.physics import fmcw
resource.setrlimit(resource.RLIMIT_AS, (600 * 1024**2, 600 * 1024**2))
seq = fmcw.ChirpSequence(77e9, 70e12, 7e-6, 7e-6, 57.14e-6, 4.884e6, 240, 16, (0, 2, 1), 33.3e-3)
delays = 2 * np.random.default_rng(1).uniform(0.5, 5.0, (64, 17)) / 299792458.0
out = fmcw.analytic_range_profile(delays, np.ones((64, 17)), seq, "hann", 16384, np.arange(16384))
print(out.shape)
"""


def test_the_analytic_range_profile_of_every_bin_fits_in_memory() -> None:
    # a zero-padded range FFT (range_fft_size 16384) with a margin wide enough to keep every
    # bin made a (chirps, scatterers, bins) kernel at once: 64 x 17 x 16384 here, 4.25 GiB for
    # the shipped FMCW walk at range_fft_size = 65536 (a MemoryError, an internal error)
    import os
    import subprocess
    import sys

    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    done = subprocess.run(
        [sys.executable, "-c", KERNEL], capture_output=True, text=True, env=env, timeout=300
    )
    assert done.returncode == 0, done.stderr[-500:]
    assert done.stdout.strip() == "(64, 16384)"


def test_the_analytic_range_profile_in_blocks_of_bins_is_the_whole(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import numpy as np

    from mdframework.physics import fmcw

    seq = fmcw.ChirpSequence(77e9, 70e12, 7e-6, 7e-6, 57.14e-6, 4.884e6, 240, 16, (0, 2, 1), 0.03)
    rng = np.random.default_rng(2)
    delays = 2 * rng.uniform(0.5, 5.0, (4, 3)) / 299792458.0
    amplitudes = rng.uniform(0.5, 1.5, (4, 3))
    phasors = np.exp(1j * rng.uniform(0, 6.3, (4, 2, 3)))
    bins = np.arange(0, 512, 3)
    whole = [fmcw.analytic_range_profile(delays, amplitudes, seq, "hann", 512, bins, p)
             for p in (None, phasors)]  # fmt: skip
    monkeypatch.setattr(fmcw, "_KERNEL_CELLS", 25)  # blocks of 2 bins (12 chirps x scatterers)
    for p, expected in zip((None, phasors), whole, strict=True):
        got = fmcw.analytic_range_profile(delays, amplitudes, seq, "hann", 512, bins, p)
        np.testing.assert_array_equal(got, expected)


@pytest.mark.parametrize(
    ("setting", "expected"),
    [
        # pydantic: "List should have at least 1 item after validation, not 0"
        ("motion.targets=[]", "motion.targets: must hold at least 1 item (got [])"),
        # pydantic: "Tuple should have at most 3 items after validation, not 4"
        (
            "scene.radar_position=[1, 2, 3, 4]",
            "scene.radar_position: must hold at most 3 items (got [1, 2, 3, 4])",
        ),
        # the whole name was shown, however long
        (
            f"radar.kind='{'x' * 300}'",
            f"radar.kind: no radar plugin named '{'x' * 57}...'; installed: ",
        ),
    ],
)
def test_more_field_errors_in_plain_words(
    setting: str, expected: str, capsys: pytest.CaptureFixture[str]
) -> None:
    config = str(EXAMPLES / "point_target.toml")
    line = one_error_line(["check", config, "--set", setting], capsys)
    assert f": {expected}" in line, line
    assert len(line) < 2 * len(setting) + 200


def test_a_yaml_key_that_is_not_text_is_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cfg = tmp_path / "c.yaml"  # pydantic: "1: Keys should be strings"
    cfg.write_text("motion: {kind: point_targets, length: 1.0, targets: [{position: [9, 0, 0]}]}\n"
                   "scatterers: {kind: points}\n1: 2\n")  # fmt: skip
    line = one_error_line(["check", str(cfg)], capsys)
    assert line == f"mdf: error: {cfg}: 1: a key must be text (got 1)"


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        ("on", "must be text, not a flag (true): quote it"),
        ("1:30", "must be text, not a number (90): quote it"),
        ("2024-01-01", "must be text, not a date (2024-01-01): quote it"),
    ],
)
def test_yaml_text_read_as_a_flag_number_or_date_says_to_quote_it(
    value: str, expected: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """docs/input-rules.md: YAML 1.1 reads unquoted yes/no/on/off as flags, 1:30 as 90 and
    2024-01-01 as a date, so quote them where text is meant; a text field given one said
    "must be a valid string (got True)" or "(got datetime.date(2024, 1, 1))"."""
    cfg = tmp_path / "c.yaml"
    cfg.write_text(f"motion: {{kind: point_targets, length: 1.0, label: {value}, "
                   "targets: [{position: [9, 0, 0]}]}\nscatterers: {kind: points}\n")  # fmt: skip
    line = one_error_line(["check", str(cfg)], capsys)
    assert line == f"mdf: error: {cfg}: motion.label: {expected}"


@pytest.mark.parametrize(
    ("setting", "field"),
    [
        ("atmospheric_loss_db = 400", "radar.atmospheric_loss_db"),
        ("system_loss_db = 400", "radar.system_loss_db"),
        ("gain_dbi = -400", "radar.gain_dbi"),
        ("transmit_power = 1e-300", "radar.transmit_power"),
    ],
)
def test_an_echo_too_weak_for_the_arithmetic_is_refused_by_dataset_check(
    setting: str, field: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # mdf dataset check called these valid; the build stopped at the first record: "the
    # spectrogram is silent: no frame rises above the floor"
    _, line = dataset_check_error(f'[base.radar]\nkind = "lfm"\n{setting}\n', tmp_path, capsys)
    assert f": {field}: the echo of 1 m^2 at 1 m would carry " in line, line
    assert "less than 1e-30 W, too weak for the arithmetic" in line


@pytest.mark.parametrize(
    ("carrier", "power", "gain"),
    [
        (2.38e9, 1e6, 73.0),  # an S-band 305 m dish planetary radar (Arecibo: 1 MW)
        (8.56e9, 5e5, 74.0),  # an X-band 70 m dish planetary radar (Goldstone DSS-14)
        (10e9, 2.5e5, 67.0),  # an X-band 37 m dish imaging radar (HUSIR)
        (1.25e9, 1.54e7, 51.0),  # an L-band 29 m phased array (Cobra Dane: 15.4 MW peak)
    ],
)
def test_a_real_high_power_radar_is_not_refused_as_too_strong(
    carrier: float, power: float, gain: float, tmp_path: Path
) -> None:
    # these were refused (echo of 1 m^2 at 1 m above 1e12 W), though the float32 arithmetic
    # holds echoes 1e8 times stronger (a 1e6 m^2 point at 0.5 m in a 65536-point STFT)
    echo = power * 10 ** (gain / 5) * (299_792_458.0 / carrier) ** 2 / (4 * np.pi) ** 3
    assert 1e12 < echo <= limits.MAX_ECHO_POWER_W
    cfg = tmp_path / "c.toml"
    radar = f'kind = "cw"\ncarrier_frequency = {carrier}\ntransmit_power = {power}\n'
    cfg.write_text(POINT + f"[radar]\n{radar}gain_dbi = {gain}\n")
    assert cli.main(["check", str(cfg)]) == 0
    assert cli.main(["run", str(cfg), "--out", str(tmp_path / "out")]) == 0
