"""Numbers the docs quote, against the scripts and experiments that make them (each runs a
simulation or an experiment: a unit of its own for the parallel test run)."""

from __future__ import annotations

import importlib.util
import re
import types
from pathlib import Path
from typing import Any

import pytest
from conftest import EXAMPLES, ROOT


def _script(name: str) -> types.ModuleType:
    """One of the docs' scripts (docs/NAME.py), imported."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "docs" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _mdf(*args: str) -> Any:
    """``mdf ARGS`` run from the repository's root as a reader runs it (a separate process),
    which must succeed: its CompletedProcess (text)."""
    import subprocess
    import sys

    return subprocess.run(
        [sys.executable, "-m", "mdframework.cli", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )


def test_the_reproduction_page_quotes_the_held_out_recordings_experiment(tmp_path: Path) -> None:
    """The page's accuracy with whole CMU recordings held out is what the script that the page
    names measures (the page once quoted a number no config reproduced)."""
    report = _script("make_reproduction_figures").held_out_recordings(tmp_path)
    measured = re.search(r"Balanced accuracy ([\d.]+) \(std ([\d.]+) over (\d+) splits;", report)
    page = " ".join((ROOT / "docs" / "reproducing-erol-gurbuz-2015.md").read_text().split())
    quoted = re.search(
        r"subjects\) then still reach ([\d.]+) ± ([\d.]+) over the (\d+) splits that exist", page
    )
    assert measured is not None and quoted is not None
    assert quoted.groups() == measured.groups()
    # two recordings of each of three classes: the 2 * 2 * 2 splits, each once
    assert "These allow 8 distinct splits only, and each is made once" in report
    after = page.split("splits that exist")[1][:120]
    recalls = re.findall(r"(walk|run|boxing) (0\.\d\d)[,;]", after)
    assert len(recalls) == 3
    for cls, recall in recalls:
        row = re.search(rf"^\| {cls} \|(.*)$", report, flags=re.M)
        assert row is not None
        cells = [c.strip() for c in row.group(1).split("|") if c.strip()]
        order = ["boxing", "run", "walk"]
        assert cells[order.index(cls)].startswith(recall), (cls, cells)


def test_the_validation_page_table_is_what_its_script_computes() -> None:
    """docs/validation.md's feature table, row by row, against make_validation_figures.py's
    runs (a hand-copied cell had drifted by 0.001)."""
    from mdframework.features import FEATURE_NAMES

    script = _script("make_validation_figures")
    page = (ROOT / "docs" / "validation.md").read_text()
    runs = {
        "Boulic (corrected)": lambda: script.boulic(False),
        "Boulic (chen_compatible)": lambda: script.boulic(True),
        "CMU 02_01 walk": script.cmu,
        "Kinect UTKinect walk": script.kinect,
    }
    for name, run in runs.items():
        row = re.search(rf"^\| {re.escape(name)} \|(.*)\|$", page, flags=re.M)
        assert row is not None, name
        quoted = [float(c) for c in row.group(1).split("|")]
        f = script.features(run())
        computed = [f[k] for k in FEATURE_NAMES]
        assert max(abs(q - c) for q, c in zip(quoted, computed, strict=True)) <= 5.0001e-4, name


def _check_the_figures_the_page_copies(out: Path, experiment: str) -> None:
    """The figures of ``mdf experiment examples/<experiment>.toml`` that
    docs/make_reproduction_figures.py copies into docs/figures exist, each of the shipped copy's
    size in pixels (the script does not run here: it would repeat these tests' experiments)."""
    from PIL import Image

    copies = _script("make_reproduction_figures").COPIES[experiment]
    assert copies
    for made, shipped in copies.items():
        with Image.open(out / made) as a, Image.open(ROOT / "docs" / "figures" / shipped) as b:
            assert a.size == b.size, (made, a.size, b.size)


def _half_unit(number: str) -> float:
    """Half a unit of the last digit a number is written with (``-0.762`` -> 0.0005)."""
    decimals = len(number.split(".")[1]) if "." in number else 0
    return 0.5 * 10.0**-decimals


def test_the_reproduction_page_feature_table_is_the_cross_source_experiments(
    tmp_path: Path,
) -> None:
    """The page's Table 2 of our data, cell by cell (mean and variance), against the
    feature_stats.csv that `mdf experiment examples/experiment_cross_source.toml` writes, each
    within the page's rounding (hand-copied cells had drifted by up to 0.0008)."""
    import csv

    from mdframework import cli

    out = tmp_path / "x"
    args = ["experiment", str(EXAMPLES / "experiment_cross_source.toml"), "--out", str(out)]
    assert cli.main([*args, "--no-progress"]) == 0
    _check_the_figures_the_page_copies(out, "experiment_cross_source")
    with (out / "feature_stats.csv").open() as fh:
        stats = {(r["label"], r["group"]): r for r in csv.DictReader(fh)}
    page = (ROOT / "docs" / "reproducing-erol-gurbuz-2015.md").read_text().splitlines()
    first = page.index(next(line for line in page if line.startswith("| feature [m/s] | walk K")))
    header = [c.strip() for c in page[first].split("|")[2:-1]]
    columns = [re.fullmatch(r"(\w+) (\w+) \(n=(\d+)\)", c) for c in header]
    checked = 0
    for line in page[first + 2 : first + 9]:
        feature, *cells = [c.strip() for c in line.split("|")[1:-1]]
        for column, text in zip(columns, cells, strict=True):
            assert column is not None
            row = stats[(column.group(1), column.group(2).lower())]
            assert row["n"] == column.group(3)
            m = re.fullmatch(r"(-?[\d.]+) \(([\d.]+)\)", text)
            assert m is not None, text
            for shown, key in zip(m.groups(), ("mean", "var"), strict=True):
                exact = float(row[f"{feature}_{key}"])
                assert abs(float(shown) - exact) <= _half_unit(shown) + 1e-12, (
                    feature,
                    column.group(0),
                    shown,
                    exact,
                )
                checked += 1
    assert checked == 84
    _check_the_cross_source_accuracies(out)
    _check_the_peak_torso_bandwidth(out / "dataset")


def _check_the_peak_torso_bandwidth(dataset: Path) -> None:
    """The page: with ``torso = "peak"`` the CMU walk's mean torso bandwidth grows to about
    1.6 m/s (from the records' own spectrograms, whose median-track feature is the build's)."""
    import numpy as np

    from mdframework.dataset import load_dataset
    from mdframework.features import FEATURE_NAMES, spectrogram_features

    page = " ".join((ROOT / "docs" / "reproducing-erol-gurbuz-2015.md").read_text().split())
    quoted = re.search(r"the walk's torso bandwidth grows to about ([\d.]+) m/s", page)
    assert quoted is not None
    data = load_dataset(dataset)
    k = FEATURE_NAMES.index("torso_bandwidth")
    walks = np.nonzero((np.asarray(data.table["group"]) == "cmu") & (data.labels == "walk"))[0]
    assert walks.size >= 10
    tracks: dict[str, list[float]] = {"median": [], "peak": []}
    for i in walks:
        power = 10.0 ** (data.spectrograms[i].astype(np.float64) / 10.0)
        for method, found in tracks.items():
            found.append(spectrogram_features(power, data.velocity, torso_method=method)[k])
    assert np.allclose(tracks["median"], data.features[walks, k], atol=1e-9)
    assert _close(quoted.group(1), float(np.mean(tracks["peak"])))


def _close(shown: str, exact: float) -> bool:
    """``shown`` is ``exact`` to the page's rounding."""
    return abs(float(shown) - exact) <= _half_unit(shown) + 1e-12


def _check_the_cross_source_accuracies(out: Path) -> None:
    """The page's Table 4 of our data (balanced accuracy and confusion matrix of training on
    Kinect, testing on CMU) and the within-source accuracies beside it, against the same
    experiment's summary.json and cross_confusion.csv."""
    import csv
    import json

    summary = json.loads((out / "summary.json").read_text())
    page = (ROOT / "docs" / "reproducing-erol-gurbuz-2015.md").read_text()
    section = page.split("## Table 4")[1].split("\n## ")[0]
    prose = " ".join(section.split())
    cross = re.search(r"balanced accuracy \*\*([\d.]+)\*\*", prose)
    assert cross is not None
    assert _close(cross.group(1), summary["cross"]["balanced_accuracy"])
    within = re.search(
        r"Kinect group alone the same classifier reaches ([\d.]+) ± ([\d.]+) \(([\d.]+) "
        r"optimistic\); within the CMU group ([\d.]+) ± ([\d.]+)\.",
        prose,
    )
    assert within is not None
    kinect, cmu = summary["within"]["kinect"], summary["within"]["cmu"]
    exact = [
        kinect["balanced_accuracy_mean"],
        kinect["balanced_accuracy_std"],
        kinect["optimistic_accuracy_mean"],
        cmu["balanced_accuracy_mean"],
        cmu["balanced_accuracy_std"],
    ]
    for shown, value in zip(within.groups(), exact, strict=True):
        assert _close(shown, value), (shown, value)
    with (out / "cross_confusion.csv").open() as fh:
        rows = {r["true"]: r for r in csv.DictReader(fh)}
    table = re.findall(r"^\| (boxing|run|walk) \|(.*)\|$", section, flags=re.M)
    header = re.search(r"^\| true \\ predicted \|(.*)\|$", section, flags=re.M)
    assert header is not None and len(table) == len(rows) == 3
    predicted = [c.strip() for c in header.group(1).split("|")]
    for true, cells in table:
        for column, shown in zip(predicted, cells.split("|"), strict=True):
            assert _close(shown.strip(), float(rows[true][column])), (true, column, shown)


def _span(text: str) -> tuple[str, str]:
    """``"0.16-2.51"`` -> ``("0.16", "2.51")``."""
    low, high = text.split("-")
    return low, high


def test_the_datasets_page_quotes_the_torso_tracks_of_the_cmu_walk() -> None:
    """docs/datasets.md: on CMU 02_01 (examples/cmu_walk.toml) the peak torso track spans
    0.16-2.51 m/s, the median one 0.30-1.52 m/s, and the hip centre's true radial speed (the
    tracking gate's, at the pulse times) 0.79-1.58 m/s, each within the page's rounding."""
    import numpy as np

    from mdframework.config import load_run_config
    from mdframework.features import envelopes
    from mdframework.pipeline import build_stages, simulate_motion

    page = " ".join((ROOT / "docs" / "datasets.md").read_text().split())
    quoted = re.search(
        r"on CMU 02_01 the peak track spans ([\d.]+-[\d.]+) m/s, the median ([\d.]+-[\d.]+) "
        r"m/s, the hip centre's true radial speed ([\d.]+-[\d.]+) m/s",
        page,
    )
    assert quoted is not None
    config = load_run_config(EXAMPLES / "cmu_walk.toml")
    stages = build_stages(config)
    res = simulate_motion(config, stages, stages.source.load())
    power = 10.0 ** (np.asarray(res.spectrogram_db, dtype=np.float64) / 10.0)
    computed = []
    for method in ("peak", "median"):
        torso = envelopes(power, res.velocity, torso_method=method).torso
        computed.append((np.nanmin(torso), np.nanmax(torso)))
    radial = -np.gradient(np.asarray(res.gate_range), res.pulse_times)  # + approaching
    computed.append((radial.min(), radial.max()))
    for text, values in zip(quoted.groups(), computed, strict=True):
        for shown, exact in zip(_span(text), values, strict=True):
            assert abs(float(shown) - exact) <= _half_unit(shown) + 1e-12, (text, values)


def test_the_kinect_page_quotes_its_figure_scripts_foot_speeds() -> None:
    """docs/kinect.md: the peak foot speeds that docs/make_kinect_figure.py measures on the
    UTKinect walk (left foot 9.4 m/s raw, 3.7 m/s conditioned, the fastest foot), and the raw
    spectrogram's spikes past +-6 m/s (within the figure's 40 dB) near t = 1.1 s and 2.0 s only,
    none once conditioned."""
    import numpy as np

    script = _script("make_kinect_figure")
    page = " ".join((ROOT / "docs" / "kinect.md").read_text().split())
    quoted = re.search(
        r"left foot's tracking \(peak ([\d.]+) m/s between frames\) throw spikes past \+-6 m/s "
        r"near t = ([\d.]+) s and t = ([\d.]+) s; conditioned, the peak foot speed is ([\d.]+) m/s",
        page,
    )
    assert quoted is not None
    raw_peak, t1, t2, conditioned_peak = quoted.groups()
    for enabled, shown in ((False, raw_peak), (True, conditioned_peak)):
        res, peak = script.run(enabled)
        fastest = max(peak, key=peak.__getitem__)
        assert fastest == "l_toe" or enabled, peak
        assert abs(float(shown) - peak[fastest]) <= _half_unit(shown), (shown, peak)
        db = np.asarray(res.spectrogram_db)
        spikes = res.spectrogram.time[(db[np.abs(res.velocity) > 6.0] > -40.0).any(axis=0)]
        if enabled:
            assert spikes.size == 0, spikes
        else:
            near = [np.abs(spikes - float(t)) <= 0.1 for t in (t1, t2)]
            assert all(n.any() for n in near) and np.logical_or(*near).all(), spikes


def test_the_reproduction_page_quotes_the_cmu_experiment(tmp_path: Path) -> None:
    """The page's within-CMU result (Table 3 of our data): the record count, balanced accuracy
    ± its standard deviation over the splits, the optimistic variant and the confusion matrix
    (mean ± std), against what `mdf experiment examples/experiment_cmu.toml` writes."""
    import csv
    import json

    from mdframework import cli

    out = tmp_path / "c"
    args = ["experiment", str(EXAMPLES / "experiment_cmu.toml"), "--out", str(out)]
    assert cli.main([*args, "--no-progress"]) == 0
    _check_the_figures_the_page_copies(out, "experiment_cmu")
    summary = json.loads((out / "summary.json").read_text())
    cmu = summary["within"]["cmu"]
    page = (ROOT / "docs" / "reproducing-erol-gurbuz-2015.md").read_text()
    section = page.split("Here (`experiment_cmu.toml`")[1].split("\n## ")[0]
    prose = " ".join(section.split())
    quoted = re.search(
        r"(\d+) records; (\d+) stratified .*?balanced accuracy \*\*([\d.]+) ± ([\d.]+)\*\*; the "
        r"paper's optimistic test-set selection gives ([\d.]+)",
        prose,
    )
    assert quoted is not None
    n_records, n_splits, mean, std, optimistic = quoted.groups()
    assert (int(n_records), int(n_splits)) == (summary["n_records"], cmu["n_splits"])
    exact = [
        cmu["balanced_accuracy_mean"],
        cmu["balanced_accuracy_std"],
        cmu["optimistic_accuracy_mean"],
    ]
    for shown, value in zip((mean, std, optimistic), exact, strict=True):
        assert _close(shown, value), (shown, value)
    tables = {}
    for name in ("within_cmu_confusion.csv", "within_cmu_confusion_std.csv"):
        with (out / name).open() as fh:
            tables[name] = {r["true"]: r for r in csv.DictReader(fh)}
    header = re.search(r"^\| true \\ predicted \|(.*)\|$", section, flags=re.M)
    rows = re.findall(r"^\| (boxing|jump|run|walk) \|(.*)\|$", section, flags=re.M)
    assert header is not None and len(rows) == 4
    predicted = [c.strip() for c in header.group(1).split("|")]
    for true, cells in rows:
        for column, cell in zip(predicted, cells.split("|"), strict=True):
            m = re.fullmatch(r"([\d.]+) ± ([\d.]+)", cell.strip())
            assert m is not None, cell
            means, stds = tables["within_cmu_confusion.csv"], tables["within_cmu_confusion_std.csv"]
            assert _close(m.group(1), float(means[true][column])), (true, column, cell)
            assert _close(m.group(2), float(stds[true][column])), (true, column, cell)


def test_the_validation_page_quotes_the_walks_step_times() -> None:
    """docs/validation.md: a step of the CMU walk (02_01, from the cadence the sanity checks
    measure) and of the Boulic walker (half its gait cycle at rv = 1, H = 1.8 m)."""
    import warnings

    from mdf_mujoco.gait import Gait

    from mdframework.config import load_run_config
    from mdframework.pipeline import build_stages, load_motion

    page = " ".join((ROOT / "docs" / "validation.md").read_text().split())
    quoted = re.search(r"about ([\d.]+) s per step against Boulic's ([\d.]+) s\)", page)
    assert quoted is not None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        motion = load_motion(build_stages(load_run_config(EXAMPLES / "cmu_walk.toml")).source)
    cmu_step = 60.0 / motion.metadata["sanity"]["cadence"]["steps_per_min"]
    boulic_step = Gait(1.8, 1.0).cycle_duration / 2
    for shown, exact in zip(quoted.groups(), (cmu_step, boulic_step), strict=True):
        assert abs(float(shown) - exact) <= _half_unit(shown), (shown, exact)


def test_the_datasets_page_shows_what_mdf_dataset_check_prints() -> None:
    """docs/datasets.md shows `mdf dataset check examples/datasets/cmu.toml`, abridged (`...`):
    each line it shows is a line the command prints."""
    page = (ROOT / "docs" / "datasets.md").read_text()
    shown = re.search(r"```text\n(examples/datasets/cmu\.toml: valid.*?)```", page, re.S)
    assert shown is not None
    done = _mdf("dataset", "check", "examples/datasets/cmu.toml")
    printed = done.stdout.splitlines()
    lines = [line for line in shown.group(1).splitlines() if line.strip() != "..."]
    assert len(lines) >= 3
    assert all(line in printed for line in lines), (lines, printed)
    # the records are stored uncompressed (the page's format section): the size is no
    # "before compression" estimate of a smaller file
    size = [line for line in printed if line.startswith("  spectrograms about")]
    assert size and "uncompressed" in size[0] and "before compression" not in size[0], size


def test_the_getting_started_page_lists_the_exit_codes_mdf_help_lists() -> None:
    """docs/getting-started.md and `mdf --help` give a script the same exit codes, with the
    same meanings."""
    from mdframework import cli

    page = " ".join((ROOT / "docs" / "getting-started.md").read_text().split())
    quoted = re.search(r"Exit codes, for scripts \(`mdf --help` lists them too\): (.*?)\.", page)
    assert quoted is not None
    codes = re.findall(r"(\d+) ([a-z ]+?)(?: \(|;|$)", quoted.group(1))
    assert codes == [
        ("0", "done"),
        ("1", "internal error"),
        ("2", "bad input"),
        (str(cli.EXIT_INTERRUPTED), "interrupted"),
        (str(cli.EXIT_TERMINATED), "terminated"),
    ]


def test_the_getting_started_page_quotes_mdf_checks_bytes_per_scatterer() -> None:
    """docs/getting-started.md: `mdf check` counts about N bytes per scatterer and pulse."""
    from mdframework.check import SCATTERER_PULSE_BYTES

    page = " ".join((ROOT / "docs" / "getting-started.md").read_text().split())
    quoted = re.search(r"at about (\d+) bytes per scatterer and pulse", page)
    assert quoted is not None and int(quoted.group(1)) == SCATTERER_PULSE_BYTES


def test_the_effects_page_quotes_the_thermal_noise_of_sqrt_rcs_amplitudes() -> None:
    """docs/effects.md: with `amplitude = "sqrt_rcs"` a 1 m^2 target's signal is 1, and the
    noise effect's thermal noise (the lfm radar's and the effect's defaults) would be some N dB
    below it, which is why that mode is refused there."""
    import math

    from mdf_lfm.waveform import LfmConfig
    from mdf_noise.noise import NoiseConfig, noise_power

    page = " ".join((ROOT / "docs" / "effects.md").read_text().split())
    quoted = re.search(r"the noise would be some (\d+) dB below a 1 m\^2 target", page)
    assert quoted is not None
    radar, noise = LfmConfig(), NoiseConfig()
    power = noise_power(
        "thermal",
        noise_figure_db=noise.noise_figure_db,
        temperature=noise.temperature,
        pulse_width=radar.pulse_width,
        bandwidth=radar.bandwidth,
    )
    assert abs(-10 * math.log10(power) - int(quoted.group(1))) < 1.5


def test_the_benchmarks_page_speed_up_of_the_fmcw_clutter_is_its_tables() -> None:
    """docs/benchmarks.md: the FMCW clutter's speed-ups are the ratios of the table's mean CPU
    times before and after, to the page's rounding (it said 3.8 for 8.78 s -> 2.28 s)."""
    page = (ROOT / "docs" / "benchmarks.md").read_text()
    rows = re.findall(r"^\| (6|60) s \| ([\d.]+), ([\d.]+) \| ([\d.]+), ([\d.]+) \| ", page, re.M)
    assert [r[0] for r in rows] == ["6", "60"]
    quoted = re.search(
        r"^([\d.]+) and ([\d.]+) times faster \(the means of the CPU times\)", page, re.M
    )
    assert quoted is not None
    for (_, *times), shown in zip(rows, quoted.groups(), strict=True):
        b1, b2, a1, a2 = (float(t) for t in times)
        assert f"{(b1 + b2) / (a1 + a2):.1f}" == shown


def _commands_with_option(option: str) -> set[str]:
    """The `mdf` commands (``run``, ``dataset build``, ...) whose parser takes ``option``."""
    import argparse

    from mdframework import cli

    found: set[str] = set()

    def walk(parser: argparse.ArgumentParser, name: str) -> None:
        for action in parser._actions:
            if option in action.option_strings and name:
                found.add(name)
            if isinstance(action, argparse._SubParsersAction):
                for sub, subparser in action.choices.items():
                    walk(subparser, f"{name} {sub}".strip())

    walk(cli.build_parser(), "")
    return found


def test_the_getting_started_page_names_the_commands_that_stage_their_files() -> None:
    """docs/getting-started.md: the commands whose files go through a staging folder are those
    that take --staging-dir (the page once said it of every command, but `mdf dataset build`
    has no such option), and the folder must exist (it is not created as --out is)."""
    import subprocess
    import sys
    import tempfile

    page = " ".join((ROOT / "docs" / "getting-started.md").read_text().split())
    quoted = re.search(
        r"The new files of `mdf (\w+)`, `(\w+)` and `(\w+)` are written into a hidden staging "
        r"folder inside `--out` \(or into `--staging-dir DIR`, an existing folder on the same "
        r"file system",
        page,
    )
    assert quoted is not None
    assert set(quoted.groups()) == _commands_with_option("--staging-dir")
    with tempfile.TemporaryDirectory() as tmp:
        options = ["--out", f"{tmp}/out", "--staging-dir", f"{tmp}/missing", "--no-figures"]
        done = subprocess.run(
            [
                sys.executable,
                "-m",
                "mdframework.cli",
                "run",
                "examples/point_target.toml",
                *options,
            ],
            cwd=ROOT,
            capture_output=True,
            text=True,
            check=False,
        )
    assert done.returncode == 2, done.stderr
    assert done.stderr == f"mdf: error: --staging-dir {tmp}/missing: No such file or directory\n"


def test_the_getting_started_page_shows_what_mdf_check_prints() -> None:
    """docs/getting-started.md shows `mdf check examples/point_target.toml` and what it
    prints: the very lines, in order (the docs' other tests only run the command)."""
    page = (ROOT / "docs" / "getting-started.md").read_text()
    shown = re.search(
        r"```sh\nmdf check examples/point_target\.toml\n```\n\n```text\n(.*?)```", page, re.S
    )
    assert shown is not None
    done = _mdf("check", "examples/point_target.toml")
    assert done.stdout == shown.group(1)


def test_the_effects_page_quotes_how_much_shadowing_hides_on_the_side_view_walk(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """docs/effects.md's numbers for shadowing and multipath on
    ``examples/boulic_walk_shadowing.toml``: how often the torso's direct path is hidden and
    how often its image path is (the ray from the radar's mirror image below the ground), and
    how much more the direct scatterers were hidden with multipath listed first (the refused
    order, let through here). The page once said 'all the time', 13 % and 13 %."""
    import mdf_multipath.multipath

    from mdframework.config import read_config_file, validate_run_config
    from mdframework.pipeline import simulate

    base = read_config_file(EXAMPLES / "boulic_walk_shadowing.toml")
    shadow = base["effects"][0]

    def hidden(effects: list[dict[str, Any]], **scene: Any) -> dict[str, float]:
        cfg = {**base, "effects": effects, "scene": {**base["scene"], **scene}}
        res = simulate(validate_run_config(cfg))
        [got] = [e for e in res.metadata["effects"] if e["kind"] == "shadowing"]
        return dict(got["blocked_fraction"])

    x, y, z = base["scene"]["radar_position"]
    direct = hidden([shadow, {"kind": "multipath"}])
    image = hidden([shadow], radar_position=[x, y, -z])  # the ground at z = 0
    monkeypatch.setattr(mdf_multipath.multipath.GroundMultipath, "check_effects", lambda *a: None)
    copies = hidden([{"kind": "multipath"}, shadow])
    more = max(copies[name] - direct[name] for name in direct)
    page = " ".join((ROOT / "docs" / "effects.md").read_text().split())
    quoted = re.search(
        r"the torso is hidden (\d+) % of the time, its image path \(the ray from the radar's "
        r"mirror image below the ground\) (\d+) % of it\).*?it hid the direct scatterers up to "
        r"(\d+) % of the time more",
        page,
    )
    assert quoted is not None
    measured = [round(100 * v) for v in (direct["torso"], image["torso"], more)]
    assert [int(q) for q in quoted.groups()] == measured


def test_the_input_rules_page_quotes_the_echo_powers_of_its_example_radars() -> None:
    """docs/input-rules.md's MAX_ECHO_POWER_W and MIN_ECHO_POWER_W rows give the range
    equation's echo of 1 m^2 at 1 m for three radars: each is that formula's value."""
    import numpy as np

    from mdframework import limits

    page = (ROOT / "docs" / "input-rules.md").read_text()
    rows = {
        name: next(line for line in page.splitlines() if line.startswith(f"| `{name}` |"))
        for name in ("MAX_ECHO_POWER_W", "MIN_ECHO_POWER_W")
    }

    def echo(power_w: float, gain_dbi: float, carrier_hz: float, losses_db: float) -> float:
        wavelength = 299_792_458.0 / carrier_hz
        return (
            power_w
            * 10 ** (gain_dbi / 5)
            * wavelength**2
            / ((4 * np.pi) ** 3 * 10 ** (losses_db / 10))
        )

    quoted = [
        (rows["MAX_ECHO_POWER_W"], "a 1 MW planetary radar with a 73 dBi dish at 2.38 GHz, "
         "Arecibo's: {:.2g}", echo(1e6, 73.0, 2.38e9, 0.0)),
        (rows["MAX_ECHO_POWER_W"], "a 1 MW radar with a 60 dBi antenna at 10 GHz: {:.2g}",
         echo(1e6, 60.0, 10e9, 0.0)),
        (rows["MIN_ECHO_POWER_W"], "a 1 mW radar at 60 GHz with 0 dBi and 100 dB of losses: "
         "{:.2g}", echo(1e-3, 0.0, 60e9, 100.0)),
    ]  # fmt: skip
    for row, text, value in quoted:
        shown = text.format(value).replace("e+", "e")  # 3.2e15, as the page writes it
        assert shown in row, (shown, row)
    assert limits.MAX_ECHO_POWER_W > echo(1e6, 73.0, 2.38e9, 0.0)
    assert limits.MIN_ECHO_POWER_W < echo(1e-3, 0.0, 60e9, 100.0)
    dbm = 10 * np.log10(limits.MIN_ECHO_POWER_W / 1e-3)
    assert f"({dbm:.0f} dBm;" in rows["MIN_ECHO_POWER_W"]


def test_the_fmcw_page_shows_what_mdf_check_prints_and_its_formulas_give() -> None:
    """docs/fmcw.md names the lines of `mdf check` that report its table's quantities and shows
    them for examples/fmcw_walk.toml: each shown line is printed, and its numbers are the
    table's formulas for the preset's chirp (the loop rate 1 / (n_tx T_c), the maximum range
    c sample_rate / (2 S), ...)."""
    page = (ROOT / "docs" / "fmcw.md").read_text()
    shown = re.search(r"```text\n(  carrier .*?)```", page, re.S)
    assert shown is not None
    done = _mdf("check", "examples/fmcw_walk.toml")
    lines = shown.group(1).splitlines()
    assert lines and all(line in done.stdout.splitlines() for line in lines), done.stdout
    text = " ".join(lines)
    c = 299_792_458.0
    from mdf_fmcw.presets import PRESETS

    chirp = PRESETS["iwr1443_short_range_3d"]  # the example's preset, no field overridden
    f0, slope, idle, adc = (
        chirp[k] for k in ("start_frequency", "slope", "idle_time", "adc_start_time")
    )
    ramp, fs, n, loops = (
        chirp[k] for k in ("ramp_end_time", "sample_rate", "n_samples", "n_loops")
    )
    n_tx = len(chirp["tdm_order"])
    t_c = idle + ramp
    wavelength = c / (f0 + slope * (adc + (n - 1) / (2 * fs)))
    quoted = {
        "wavelength {:.3g} cm": 100 * wavelength,
        "slow time {:.4g} kHz": 1e-3 / (n_tx * t_c),
        "window 325 Hz = {:.3g} m/s": wavelength / (2 * loops * n_tx * t_c),
        "unambiguous +-{:.3g} m/s": wavelength / (4 * n_tx * t_c),
        "range resolution {:.3g} m": c / (2 * slope * n / fs),
        "unambiguous to {:.4g} m": c * fs / (2 * slope),
    }  # fmt: skip
    for words, value in quoted.items():
        assert words.format(value) in text.replace("range       ", "range "), words.format(value)
