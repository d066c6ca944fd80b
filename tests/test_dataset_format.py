"""A built dataset read as its documented format, by a program without mdframework (a training
script on another machine): the docs' numpy/json/csv reader, every ``index.csv`` column and
``dataset.json`` key documented, the folder's format version."""

from __future__ import annotations

import csv
import json
import re
import shutil
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import numpy as np
import pytest
from conftest import EXAMPLES

from mdframework.dataset import (
    DATASET_FORMAT,
    build_dataset,
    load_dataset,
    load_dataset_config,
    read_record,
)
from mdframework.errors import DataFileError, OutputError

DOCS = Path(__file__).resolve().parent.parent / "docs" / "datasets.md"
CMU = EXAMPLES / "data" / "cmu"
RADHAR = EXAMPLES / "data" / "radhar"
#: the run's records reach the band's edge (a warning the test does not need)
pytestmark = pytest.mark.filterwarnings("ignore::mdframework.dataset.DatasetWarning")
FORMAT_HEADING = "## The dataset folder's format"


def format_section() -> str:
    """The datasets page's section on the folder's format, up to the next ``## `` heading."""
    text = DOCS.read_text()
    start = text.index(FORMAT_HEADING)
    end = text.find("\n## ", start + 1)
    return text[start : end if end > 0 else None]


def documented_names(table_title: str) -> set[str]:
    """The first-column names (in backquotes) of the section's table that follows the line
    ``table_title``."""
    section = format_section()
    rows = section[section.index(table_title) :].split("\n\n")[1].splitlines()[2:]
    return {name for row in rows for name in re.findall(r"`([^`]+)`", row.split("|")[1])}


@pytest.fixture(scope="module")
def spectrogram_set(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A small simulated dataset: two labels, two aspects, a drawn SNR."""
    root = tmp_path_factory.mktemp("fmt")
    config = root / "ds.toml"
    config.write_text(f"""
seed = 3
[[sources]]
label = "walk"
motion = {{ kind = "cmu", file = "{CMU / "asf-amc" / "02_01.amc"}" }}
hop = 1.0
max_records = 2
[[sources]]
label = "run"
motion = {{ kind = "cmu", file = "{CMU / "asf-amc" / "09_06.amc"}" }}
max_records = 1
[record_lengths]
walk = 0.5
run = 0.5
[variations]
aspect_deg = [0.0, 40.0]
[[base.effects]]
kind = "noise"
snr_db = 20.0
[base.processing]
window_length = 128
hop = 32
nfft = 128
[randomize.params]
"effects.0.snr_db" = {{ uniform = [5.0, 25.0] }}
""")
    build_dataset(*load_dataset_config(config), root / "out", workers=1, progress=False)
    return root / "out"


@pytest.fixture(scope="module")
def histogram_set(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A small dataset of real radar recordings (histogram records)."""
    root = tmp_path_factory.mktemp("fmt_hist")
    config = root / "ds.toml"
    config.write_text(f"""
[record_lengths]
walk = 1.0
[[sources]]
label = "walk"
recording = {{ kind = "radhar", file = "{RADHAR / "radhar_walk_subset.npz"}", \
recordings = ["__20_walk_1.txt"] }}
hop = 5.0
max_records = 2
""")
    build_dataset(*load_dataset_config(config), root / "out", workers=1, progress=False)
    return root / "out"


def test_every_index_column_and_manifest_key_is_documented(
    spectrogram_set: Path, histogram_set: Path
) -> None:
    """A consumer reads index.csv by its column names: each must be named on the page."""
    columns = documented_names("`index.csv` columns")
    for folder in (spectrogram_set, histogram_set):
        with open(folder / "index.csv", newline="", encoding="utf-8") as fh:
            header = next(csv.reader(fh))
        if folder == spectrogram_set:  # the drawn SNR's column
            assert "draw.effects.0.snr_db" in header
        plain = {c if not c.startswith("draw.") else "draw.<name>" for c in header}
        assert plain <= columns, sorted(plain - columns)
        manifest = json.loads((folder / "dataset.json").read_text())
        assert set(manifest) <= documented_names("`dataset.json` keys")
        _, meta = read_record(folder / "records" / f"{_first_id(folder)}.npz")
        assert set(meta) <= documented_names("`meta` keys"), sorted(
            set(meta) - documented_names("`meta` keys")
        )


def _first_id(folder: Path) -> str:
    with open(folder / "index.csv", newline="", encoding="utf-8") as fh:
        return str(next(csv.DictReader(fh))["id"])


def test_dataset_json_names_the_format_version(spectrogram_set: Path) -> None:
    manifest = json.loads((spectrogram_set / "dataset.json").read_text())
    assert manifest["format_version"] == DATASET_FORMAT == 1
    assert f"`format_version` | {DATASET_FORMAT}" in format_section().replace("`,", "`")


def test_a_dataset_of_a_newer_format_is_refused_and_one_of_before_formats_read(
    spectrogram_set: Path, tmp_path: Path
) -> None:
    """A reader that does not know a format's meaning says so rather than misread it; a
    folder built before format versions (no ``format_version``) is read as before."""
    for name, version in (("newer", DATASET_FORMAT + 1), ("older", None)):
        folder = tmp_path / name
        shutil.copytree(spectrogram_set, folder)
        manifest = json.loads((folder / "dataset.json").read_text())
        if version is None:
            del manifest["format_version"]
        else:
            manifest["format_version"] = version
        (folder / "dataset.json").write_text(json.dumps(manifest))
    with pytest.raises(DataFileError, match=r"format_version 2: a dataset of a newer format"):
        load_dataset(tmp_path / "newer")
    older = load_dataset(tmp_path / "older")
    assert list(older.labels) == list(load_dataset(spectrogram_set).labels)


@pytest.mark.parametrize("version", ["1", True, 0, 1.5, None])
def test_a_format_version_that_is_no_formats_number_is_not_called_newer(
    spectrogram_set: Path, tmp_path: Path, version: object
) -> None:
    # "1" (text) was refused as "a dataset of a newer format ... (1)"; true was read as 1
    folder = tmp_path / "edited"
    shutil.copytree(spectrogram_set, folder)
    manifest = json.loads((folder / "dataset.json").read_text())
    (folder / "dataset.json").write_text(json.dumps({**manifest, "format_version": version}))
    with pytest.raises(DataFileError) as info:
        load_dataset(folder)
    assert f"format_version {version!r} is not a format's number (1, 2, ...); " in str(info.value)
    assert "newer" not in str(info.value)


def documented_reader() -> str:
    """The section's Python block: the reader that uses numpy, json, csv and hashlib only."""
    blocks = re.findall(r"```python\n(.*?)```", format_section(), flags=re.S)
    assert len(blocks) == 1
    return str(blocks[0])


def run_reader(folder: Path, then: str = "") -> subprocess.CompletedProcess[str]:
    """The page's reader, as the page shows it, on ``folder`` (as its ``out/dataset_cmu``) in a
    Python where mdframework cannot be imported (as on a machine without it), then ``then``."""
    script = "import sys\nsys.modules['mdframework'] = None\n" + documented_reader()
    with tempfile.TemporaryDirectory() as cwd:
        (Path(cwd) / "out").mkdir()
        (Path(cwd) / "out" / "dataset_cmu").symlink_to(folder)
        return subprocess.run(
            [sys.executable, "-c", script + textwrap.dedent(then)],
            capture_output=True,
            text=True,
            check=False,
            cwd=cwd,
        )


@pytest.mark.parametrize("which", ["spectrogram_set", "histogram_set"])
def test_the_documented_reader_needs_no_mdframework(
    which: str, request: pytest.FixtureRequest
) -> None:
    """The page's reader gives what load_dataset gives: ids, labels, subjects, recordings and
    the first record's arrays, bit for bit, with their dtypes."""
    folder: Path = request.getfixturevalue(which)
    done = run_reader(
        folder,
        f"""
        import json
        import numpy as np
        arrays, meta = read_record_file({str(folder)!r}, rows[0]["id"])
        np.savez({str(folder / "reader.npz")!r}, **arrays)
        got = {{k: [r[k] for r in rows] for k in ("id", "label", "subject", "recording")}}
        print(json.dumps({{**got, "meta_label": meta["label"]}}))
        """,
    )
    assert done.returncode == 0, done.stderr
    got = json.loads(done.stdout.splitlines()[-1])
    data = load_dataset(folder)
    for key in ("id", "label", "subject", "recording"):
        assert got[key] == list(data.table[key])
    assert got["meta_label"] == data.labels[0]
    first, _ = read_record(folder / "records" / f"{data.table['id'][0]}.npz")
    with np.load(folder / "reader.npz") as mine:
        assert set(mine.files) == set(first)
        for name in first:
            np.testing.assert_array_equal(mine[name], first[name])
            assert mine[name].dtype == first[name].dtype


def test_the_documented_reader_detects_an_incomplete_or_edited_folder(
    spectrogram_set: Path, tmp_path: Path
) -> None:
    """What a consumer must detect from the files alone, as the page's reader does."""
    cases = {}
    for case in ("edited", "missing", "no_index", "unlisted"):
        copy = tmp_path / case
        shutil.copytree(spectrogram_set, copy)
        cases[case] = copy
    index = cases["edited"] / "index.csv"
    index.write_text(index.read_text().replace(",walk,", ",run,", 1))
    first = _first_id(cases["missing"])
    (cases["missing"] / "records" / f"{first}.npz").unlink()
    (cases["no_index"] / "index.csv").unlink()
    # a record of another config left by a stopped rebuild is not part of the dataset
    shutil.copy(
        cases["unlisted"] / "records" / f"{first}.npz",
        cases["unlisted"] / "records" / "00099-0000000000.npz",
    )
    assert run_reader(cases["unlisted"]).returncode == 0
    for case in ("edited", "missing", "no_index"):
        done = run_reader(cases[case])
        assert done.returncode != 0, case


def walk_config(path: Path, extra: str = "", place: str = "recording", records: int = 1) -> Path:
    """Write ``path``: a dataset config of ``records`` half-second CMU walk records with a small
    spectrogram, whose scene names no aspect, then ``extra``."""
    path.write_text(f"""
seed = 5
place = "{place}"
[[sources]]
label = "walk"
motion = {{ kind = "cmu", file = "{CMU / "asf-amc" / "02_01.amc"}" }}
max_records = {records}
[record_lengths]
walk = 0.5
[base.processing]
window_length = 128
hop = 32
nfft = 128
{extra}
""")
    return path


@pytest.mark.parametrize("place", ["recording", "record"])
def test_a_record_of_the_default_aspect_says_so(tmp_path: Path, place: str) -> None:
    """A scene that names no aspect faces the person toward the radar (aspect 0): its records
    are those of ``aspect_deg = [0.0]`` and index.csv says 0, not nothing; a scene placed by
    ``heading_deg`` has no aspect, and its column stays empty."""
    scenes = {
        "default": "",
        "zero": "[variations]\naspect_deg = [0.0]",
        "heading": "[base.scene.person]\nheading_deg = 90.0",
    }
    tables = {}
    for name, extra in scenes.items():
        config = walk_config(tmp_path / f"{name}.toml", extra, place)
        build_dataset(*load_dataset_config(config), tmp_path / name, workers=1, progress=False)
        tables[name] = load_dataset(tmp_path / name)
    assert tables["default"].table["aspect_deg"][0] == 0.0 == tables["zero"].table["aspect_deg"][0]
    np.testing.assert_array_equal(tables["default"].spectrograms, tables["zero"].spectrograms)
    assert np.isnan(tables["heading"].table["aspect_deg"][0])


def test_a_resumed_build_of_before_format_versions_says_the_default_aspect_too(
    tmp_path: Path,
) -> None:
    """Records written before the default aspect was written as 0 (their ``aspect_deg`` null)
    that a build resumes and keeps say 0 in index.csv and their ``meta`` like the records it
    computes: the index of a format 1 folder does not mix 0 and empty for the same scene."""
    config = walk_config(tmp_path / "ds.toml", records=2)
    out = tmp_path / "out"
    build_dataset(*load_dataset_config(config), out, workers=1, progress=False)
    first = load_dataset(out).table
    records = sorted((out / "records").glob("*.npz"))
    assert len(records) == 2
    arrays, meta = read_record(records[0])  # as the previous version wrote it
    np.savez(records[0], **arrays, meta=np.array(json.dumps({**meta, "aspect_deg": None})))
    records[1].unlink()  # a build stopped before its last record
    build_dataset(*load_dataset_config(config), out, workers=1, progress=False)
    table = load_dataset(out).table
    assert list(table["id"]) == list(first["id"])  # the same records, none recomputed afresh
    assert list(table["seed"]) == list(first["seed"])
    assert list(table["aspect_deg"]) == [0.0, 0.0]
    assert read_record(records[0])[1]["aspect_deg"] == 0.0


def test_a_build_does_not_rewrite_a_folder_of_a_newer_format_as_its_own(tmp_path: Path) -> None:
    """A build by this version into a folder that a newer mdframework built (a format it cannot
    read) stops before it writes: it kept the newer records and relabelled the folder as its
    own format, which readers of that format then misread."""
    config = walk_config(tmp_path / "ds.toml")
    out = tmp_path / "out"
    build_dataset(*load_dataset_config(config), out, workers=1, progress=False)
    manifest = json.loads((out / "dataset.json").read_text())
    newer = json.dumps({**manifest, "format_version": DATASET_FORMAT + 1})
    (out / "dataset.json").write_text(newer)
    for force in (False, True):
        with pytest.raises(OutputError, match=r"format_version 2, newer than this mdframework"):
            build_dataset(*load_dataset_config(config), out, workers=1, progress=False, force=force)
        assert (out / "dataset.json").read_text() == newer


def test_the_page_quotes_the_size_of_a_record_of_the_cmu_dataset(tmp_path: Path) -> None:
    """docs/datasets.md: a record of examples/datasets/cmu.toml takes 153 KiB (its 512 x 68
    float32 map 136 KiB, meta 11 KiB), the 280 records 43 MB (the first source's first record,
    built; the count is what `mdf dataset check` prints, tested with the page's output)."""
    page = " ".join(DOCS.read_text().split())
    config, base = load_dataset_config(EXAMPLES / "datasets" / "cmu.toml")
    first = config.sources[0].model_copy(update={"max_records": 1})
    lengths = {"walk": config.record_lengths["walk"]}
    config = config.model_copy(update={"sources": [first], "record_lengths": lengths})
    build_dataset(config, base, tmp_path / "out", workers=1, progress=False)
    path = tmp_path / "out" / "records" / f"{_first_id(tmp_path / 'out')}.npz"
    with np.load(path, allow_pickle=False) as data:
        shape, map_bytes = data["spectrogram_db"].shape, data["spectrogram_db"].nbytes
        meta_bytes = data["meta"].nbytes
    size = path.stat().st_size
    quoted = (
        f"takes {size / 1024:.0f} KiB (its {shape[0]} x {shape[1]} float32 map "
        f"{map_bytes / 1024:.0f} KiB, `meta` {meta_bytes / 1024:.0f} KiB), the 280 records "
        f"{280 * size / 1e6:.0f} MB"
    )
    assert quoted in page, quoted
    assert "examples/datasets/cmu.toml: valid, 280 records" in DOCS.read_text()
