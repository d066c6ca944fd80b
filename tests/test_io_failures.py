"""What a long dataset build on a shared machine meets: a full disk, a damaged dataset folder,
another command on the same folder, a file system without locks. Each must end in one line that
names the file or folder and says what to do (exit 2), never in an experiment on wrong data.

The dataset: two CMU recordings (walk 02_01, boxing 13_18), two 1 s records each.
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
import shutil
from pathlib import Path

import pytest
from conftest import EXAMPLES

from mdframework.cli import main
from mdframework.dataset import build_dataset, load_dataset, load_dataset_config
from mdframework.errors import DataFileError

pytestmark = pytest.mark.filterwarnings("ignore::mdframework.sanity.MotionSanityWarning")

CMU = EXAMPLES / "data" / "cmu" / "asf-amc"


def _config(path: Path) -> Path:
    path.write_text(f"""
seed = 3
[[sources]]
label = "walk"
motion = {{ kind = "cmu", file = "{CMU / "02_01.amc"}" }}
hop = 0.5
max_records = 2
[[sources]]
label = "boxing"
motion = {{ kind = "cmu", file = "{CMU / "13_18.amc"}", sanity = {{ glitches = "repair" }} }}
hop = 1.0
max_records = 2
[record_lengths]
walk = 1.0
boxing = 1.0
[base.scene]
radar_position = [8.0, 0.0, 1.5]
[base.processing]
window_length = 128
nfft = 128
""")
    return path


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The dataset config and a folder built from it (copy it before changing it)."""
    where = tmp_path_factory.mktemp("io")
    config = _config(where / "d.toml")
    cfg, base = load_dataset_config(config)
    build_dataset(cfg, base, where / "ds", workers=1, progress=False)
    return config, where / "ds"


def _copy(built: tuple[Path, Path], tmp_path: Path) -> Path:
    data = tmp_path / "ds"
    shutil.copytree(built[1], data)
    return data


def _experiment(data: Path, tmp_path: Path) -> Path:
    e = tmp_path / "e.toml"
    e.write_text(
        f'seed = 0\n[dataset]\npath = "{data}"\n[classifier]\nkind = "knn"\nk = 1\n'
        '[selection]\nmethod = "none"\n[evaluation]\nrepeats = 2\ntest_fraction = 0.5\n'
    )
    return e


def _last_cell_doubled(row: str) -> str:
    """``row`` (a line of index.csv) with its last cell (a feature) twice as large."""
    head, last = row.rstrip("\n").rsplit(",", 1)
    return f"{head},{2 * float(last)!r}\n"


def _one_error(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run ``mdf argv``: exit 2 and one line on stderr, which is returned."""
    capsys.readouterr()
    assert main([*argv, "--no-progress"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    return lines[0]


@pytest.mark.parametrize(
    "damage",
    ["cut mid-line", "cut at a row's end", "label edited", "feature edited"],
)
def test_an_index_changed_since_the_build_is_refused_and_a_rebuild_restores_it(
    built: tuple[Path, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    damage: str,
) -> None:
    """An index.csv cut short (a copy that ran out of space, a quota) or with a row changed
    gave an experiment fewer records, or wrong labels or features, without a word. Now it is one
    line naming the file and the fix; that fix, the same build run again, restores the index
    byte for byte, and the experiment runs."""
    data = _copy(built, tmp_path)
    index = data / "index.csv"
    good = index.read_bytes()
    text = good.decode()
    lines = text.splitlines(keepends=True)
    changed = {
        "cut mid-line": text[: len(text) - len(lines[-1]) // 2],
        "cut at a row's end": "".join(lines[:-1]),
        "label edited": text.replace(",walk,", ",boxing,", 1),
        "feature edited": text.replace(lines[1], _last_cell_doubled(lines[1]), 1),
    }[damage]
    assert changed != text
    index.write_text(changed)
    with pytest.raises(DataFileError, match=r"index\.csv: not the file the build wrote"):
        load_dataset(data)
    line = _one_error(
        ["experiment", str(_experiment(data, tmp_path)), "--out", str(tmp_path / "o")], capsys
    )
    assert line == (
        f"mdf: error: {index}: not the file the build wrote (cut short or edited since: it "
        "does not match the digest in dataset.json); run the same `mdf dataset build` again to "
        "rewrite it from the records"
    )
    assert main(["dataset", "build", str(built[0]), "--out", str(data), "--no-progress"]) == 0
    assert index.read_bytes() == good
    assert load_dataset(data, spectrograms=False).features.shape == (4, 7)


def test_dataset_json_invalid_or_missing_is_one_line(
    built: tuple[Path, Path], tmp_path: Path
) -> None:
    """dataset.json holds the index's digest: invalid or deleted, the dataset is refused naming
    it (it was not read at all)."""
    data = _copy(built, tmp_path)
    manifest = data / "dataset.json"
    manifest.write_text("{bad")
    with pytest.raises(DataFileError, match=r"dataset\.json: not valid JSON \(.*\); run the same"):
        load_dataset(data, spectrograms=False)
    manifest.unlink()
    with pytest.raises(DataFileError, match=r"dataset\.json: missing, though index\.csv is there"):
        load_dataset(data, spectrograms=False)


def test_an_index_of_a_build_before_digests_is_still_checked_for_cut_rows(
    built: tuple[Path, Path], tmp_path: Path
) -> None:
    """A dataset.json without the digest (built before it was written) is read as before, but a
    last row cut short, or a row with fewer fields than the header, is refused with its line."""
    data = _copy(built, tmp_path)
    manifest = json.loads((data / "dataset.json").read_text())
    del manifest["index_sha256"]
    (data / "dataset.json").write_text(json.dumps(manifest))
    index = data / "index.csv"
    text = index.read_text()
    assert load_dataset(data, spectrograms=False).features.shape == (4, 7)
    index.write_text(text[:-5])
    with pytest.raises(DataFileError, match=r"index\.csv: cut short \(its last row is incomplete"):
        load_dataset(data, spectrograms=False)
    lines = text.splitlines(keepends=True)
    short = lines[2].rsplit(",", 3)[0] + "\n"
    index.write_text("".join([*lines[:2], short, *lines[3:]]))
    with pytest.raises(DataFileError, match=r"index\.csv:3: \d+ fields where the header has"):
        load_dataset(data, spectrograms=False)


def test_the_digest_is_of_the_index_as_written(built: tuple[Path, Path]) -> None:
    data = built[1]
    digest = hashlib.sha256((data / "index.csv").read_bytes()).hexdigest()
    assert json.loads((data / "dataset.json").read_text())["index_sha256"] == digest


def _disk_fills_after(monkeypatch: pytest.MonkeyPatch, name: str, files: int) -> None:
    """``numpy.<name>`` writes ``files`` files (in each process: forked workers inherit the
    count), then fails as a full disk does, after writing part of the next."""
    import numpy as np

    real = getattr(np, name)
    written = [0]

    def write(file: object, *args: object, **kwargs: object) -> None:
        if written[0] >= files:
            if hasattr(file, "write"):
                file.write(b"PK\x03\x04 part of a record")
            raise OSError(errno.ENOSPC, "No space left on device")
        written[0] += 1
        real(file, *args, **kwargs)

    monkeypatch.setattr(np, name, write)


def test_a_full_disk_names_the_record_and_the_build_resumes_from_what_it_wrote(
    built: tuple[Path, Path],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The disk fills while the third record is written: one line naming that record's file and
    saying what to do (it was `mdf: error: No space left on device`), no partial file left; once
    there is room, the same command keeps the two records and builds the same dataset."""
    config, reference = built
    out = tmp_path / "ds"
    _disk_fills_after(monkeypatch, "savez", 2)
    line = _one_error(
        ["dataset", "build", str(config), "--out", str(out), "--workers", "1"], capsys
    )
    records = sorted((out / "records").iterdir())
    assert [p.name for p in records] == sorted(p.name for p in (reference / "records").iterdir())[
        :2
    ]
    third = sorted((reference / "records").iterdir())[2].name
    assert line == (
        f"mdf: error: {out / 'records' / third}: No space left on device; free some space and "
        "run the same command again: it resumes from the records written so far"
    )
    kept = {p.name: p.stat().st_ino for p in records}
    monkeypatch.undo()
    assert main(["dataset", "build", str(config), "--out", str(out), "--no-progress"]) == 0
    assert {n: (out / "records" / n).stat().st_ino for n in kept} == kept  # not recomputed
    assert (out / "index.csv").read_bytes() == (reference / "index.csv").read_bytes()
    for record in (reference / "records").iterdir():
        assert (out / "records" / record.name).read_bytes() == record.read_bytes()


def test_a_full_disk_during_a_run_names_out_and_keeps_the_earlier_output(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """`mdf run` into the folder of an earlier run, the disk full while it writes result.npz:
    one line naming --out and what to do; the earlier output stays as it was, no staging folder
    is left."""
    out = tmp_path / "walk"
    config = str(EXAMPLES / "cmu_walk.toml")
    assert main(["run", config, "--out", str(out), "--no-progress"]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    _disk_fills_after(monkeypatch, "savez_compressed", 0)
    line = _one_error(["run", config, "--out", str(out)], capsys)
    assert line == (
        f"mdf: error: --out {out}: No space left on device; free some space (or choose another "
        "--out) and run the command again"
    )
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


def test_a_dataset_that_a_build_is_writing_is_not_loaded(
    built: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Another process holds the dataset folder's lock (a resumed or --force build writing it:
    records removed, index.csv and dataset.json replaced one after the other): an experiment on
    it is one line naming that process (it read whatever was there, or said `not a built
    dataset (no index.csv); run mdf dataset build` during a first build); once the holder has
    ended, it loads."""
    import subprocess
    import sys

    data = _copy(built, tmp_path)
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys; from pathlib import Path; from mdframework.outdir import acquire_lock; "
            f"acquire_lock(Path({str(data)!r}), 'mdf dataset'); print('locked', flush=True); "
            "sys.stdin.read()",
        ],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline() == "locked\n"
        line = _one_error(
            ["experiment", str(_experiment(data, tmp_path)), "--out", str(tmp_path / "o")], capsys
        )
        assert line.startswith(
            f"mdf: error: {tmp_path / 'e.toml'}: {data}: being written by process {holder.pid} "
            "(mdf dataset, started "
        )
        assert line.endswith("); wait for it to finish and try again")
    finally:
        holder.communicate("")
    assert load_dataset(data, spectrograms=False).features.shape == (4, 7)


def test_a_file_system_without_locks_warns_and_the_command_goes_on(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """An NFS mount whose lock service does not answer makes every ``flock`` fail with ENOLCK:
    `mdf run` was an internal error (exit 1) on any folder there. Now it warns once, naming
    --out, and writes its output; the lock file is gone afterwards."""
    import fcntl

    import mdframework.outdir as outdir

    def no_locks(fd: int, operation: int) -> None:
        raise OSError(errno.ENOLCK, "No locks available")

    monkeypatch.setattr(outdir.fcntl, "flock", no_locks)
    assert outdir.fcntl is fcntl
    out = tmp_path / "walk"
    config = str(EXAMPLES / "point_target.toml")
    assert main(["run", config, "--out", str(out), "--no-progress", "--no-figures"]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"mdf: warning: --out {out}: cannot lock the folder (No locks available: its file "
        "system does not support file locks); nothing keeps another command from writing into "
        "it at the same time, so run one command at a time on it"
    ]
    assert (out / "result.npz").is_file() and not (out / ".mdf.lock").exists()
    assert not any(p.name.startswith(".mdf-staging-") for p in out.iterdir())


def test_an_experiment_whose_dataset_build_stopped_resumes_it(
    built: tuple[Path, Path],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """An experiment that builds its dataset (`[dataset] config`) stopped by a full disk (or a
    batch system's time limit) after two records: the same command, run again, was refused
    (`--out ...: the folder is not empty ('dataset') and holds no earlier mdf experiment
    output`); now it keeps the two records, finishes the build and writes the report."""
    config, reference = built
    e = tmp_path / "e.toml"
    e.write_text(
        f'seed = 0\nworkers = 1\n[dataset]\nconfig = "{config}"\n'
        '[classifier]\nkind = "knn"\nk = 1\n[selection]\nmethod = "none"\n'
        "[evaluation]\nrepeats = 2\ntest_fraction = 0.5\n"
    )
    out = tmp_path / "o"
    _disk_fills_after(monkeypatch, "savez", 2)
    line = _one_error(["experiment", str(e), "--out", str(out)], capsys)
    # not "(or choose another --out)": that would build the dataset anew
    assert line.endswith(
        ": No space left on device; free some space and run the same command again: it resumes "
        "from the records written so far"
    ), line
    records = out / "dataset" / "records"
    kept = {p.name: p.stat().st_ino for p in records.iterdir()}
    assert len(kept) == 2
    monkeypatch.undo()
    assert main(["experiment", str(e), "--out", str(out), "--no-progress"]) == 0
    assert {n: (records / n).stat().st_ino for n in kept} == kept  # not recomputed
    assert (out / "report.md").is_file()
    index = (out / "dataset" / "index.csv").read_bytes()
    assert index == (reference / "index.csv").read_bytes()


def test_a_full_disk_while_relabelling_keeps_every_record(
    built: tuple[Path, Path],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A --force rebuild that only renames a label rewrites each kept record's metadata; the
    disk full during that rewrite deleted the record (it was taken for a corrupt file) and the
    build went on to simulate it again. Now the build stops there, naming the record, and every
    record stays as it was; with room again, the rename completes without simulating anything."""
    config, _ = built
    data = _copy(built, tmp_path)
    before = {p.name: p.read_bytes() for p in (data / "records").iterdir()}
    renamed = tmp_path / "renamed.toml"
    renamed.write_text(
        config.read_text()
        .replace('label = "walk"', 'label = "stroll"')
        .replace("walk = 1.0", "stroll = 1.0")
    )
    _disk_fills_after(monkeypatch, "savez", 0)
    argv = ["dataset", "build", str(renamed), "--out", str(data), "--force", "--workers", "1"]
    line = _one_error(argv, capsys)
    assert "No space left on device; free some space and run the same command again" in line
    assert {p.name: p.read_bytes() for p in (data / "records").iterdir()} == before
    monkeypatch.undo()
    assert main([*argv, "--no-progress"]) == 0
    assert sorted(p.name for p in (data / "records").iterdir()) == sorted(before)
    assert sorted(set(load_dataset(data, spectrograms=False).labels)) == ["boxing", "stroll"]


@pytest.mark.parametrize("code", [errno.EIO, errno.ESTALE])
def test_a_failing_disk_is_one_line_not_an_internal_error(
    built: tuple[Path, Path],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    code: int,
) -> None:
    """An I/O error of the disk, or a network file system's stale handle, while a record is
    written is the environment's failure, not a bug of mdf's: one line naming the record, exit
    2 (it was `mdf: internal error: OSError ...`, exit 1)."""
    import numpy as np

    def failing(file: object, *args: object, **kwargs: object) -> None:
        raise OSError(code, os.strerror(code))

    monkeypatch.setattr(np, "savez", failing)
    out = tmp_path / "ds"
    argv = ["dataset", "build", str(built[0]), "--out", str(out), "--workers", "1"]
    line = _one_error(argv, capsys)
    first = sorted((built[1] / "records").iterdir())[0].name
    assert line == f"mdf: error: {out / 'records' / first}: {os.strerror(code)}"


def test_a_folder_in_place_of_a_record_is_one_line_and_kept(
    built: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A folder with a record's name in records/ (made by hand, or by a tool unpacking the
    .npz): a resumed build was an internal error (IsADirectoryError); now one line naming it,
    and the folder is left alone."""
    data = _copy(built, tmp_path)
    record = sorted((data / "records").iterdir())[1]
    record.unlink()
    record.mkdir()
    (record / "mine.txt").write_text("x")
    line = _one_error(["dataset", "build", str(built[0]), "--out", str(data)], capsys)
    assert line == (
        f"mdf: error: {record}: a folder where the dataset has a record's file; move it away "
        "and run the build again"
    )
    assert (record / "mine.txt").read_text() == "x"


@pytest.mark.parametrize("code", [errno.EIO, errno.ESTALE])
def test_a_record_the_disk_fails_to_give_is_kept_when_a_build_resumes(
    built: tuple[Path, Path],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    code: int,
) -> None:
    """A resumed build reads every record it finds; one that the disk fails to give (an I/O
    error, a stale NFS handle) stops the build with one line naming it, and the record stays
    (it was deleted as if corrupt, and recomputed, or lost if the disk then failed again)."""
    import numpy as np

    data = _copy(built, tmp_path)
    before = {p.name: p.read_bytes() for p in (data / "records").iterdir()}
    failing_record = sorted((data / "records").iterdir())[1]
    real_load = np.load

    def load(file: object, *args: object, **kwargs: object) -> object:
        if Path(str(file)) == failing_record:
            raise OSError(code, os.strerror(code), str(file))
        return real_load(file, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(np, "load", load)
    argv = ["dataset", "build", str(built[0]), "--out", str(data), "--workers", "1"]
    line = _one_error(argv, capsys)
    assert line == f"mdf: error: {failing_record}: {os.strerror(code)}"
    assert {p.name: p.read_bytes() for p in (data / "records").iterdir()} == before
