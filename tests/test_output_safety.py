"""What an output folder keeps of the user's, and what a swap of files killed at any instant
leaves (the rules of docs/getting-started.md#output-folders). Each case is a reviewer's
reproduction: the files named there used to be deleted, or left half swapped."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from conftest import EXAMPLES
from test_outputs import mdf

from mdframework import outdir
from mdframework.errors import OutputError
from mdframework.experiment import EXPERIMENT_FILES
from mdframework.output import OUTPUTS

POINT = EXAMPLES / "point_target.toml"


def one_record_dataset(tmp_path: Path, out: Path) -> list[str]:
    """The arguments of ``mdf dataset build`` for a one-record dataset into ``out``."""
    amc = EXAMPLES / "data" / "cmu" / "asf-amc" / "02_01.amc"
    cfg = tmp_path / "d.toml"
    cfg.write_text(
        f'[[sources]]\nlabel = "walk"\nmotion = {{ kind = "cmu", file = "{amc}" }}\n'
        "max_records = 1\n[record_lengths]\nwalk = 1.0\n[base.processing]\nnfft = 256\n"
    )
    return ["dataset", "build", str(cfg), "--out", str(out), "--no-progress", "--workers", "1"]


def tree(folder: Path) -> dict[str, bytes | None]:
    """Every entry under ``folder`` (a folder as None), hidden ones included."""
    return {
        str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else None)
        for p in sorted(folder.rglob("*"))
        if p.name != outdir.LOCK
    }


def test_a_folder_of_files_with_the_runs_names_but_no_marker_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``points.csv`` and ``motion.mp4`` are names a run writes; without the run's marker they
    are the user's: refused (exit 2, one line naming the folder and --force), nothing touched."""
    out = tmp_path / "mine"
    out.mkdir()
    (out / "points.csv").write_text("data\n")
    (out / "motion.mp4").write_text("x\n")
    before = tree(out)
    code, err = mdf(["run", str(POINT), "--out", str(out)], capsys)
    assert code == 2
    (line,) = err.strip().splitlines()
    assert line.startswith(f"mdf: error: --out {out}: ") and "--force" in line
    assert tree(out) == before


def test_a_folder_of_own_named_folders_is_refused_for_an_experiment(tmp_path: Path) -> None:
    """``within_subject_analysis/`` and ``within_notes.txt`` match the experiment's
    ``within_*``: the folder is still the user's."""
    out = tmp_path / "mine5"
    (out / "within_subject_analysis").mkdir(parents=True)
    (out / "within_subject_analysis" / "f.txt").write_text("w")
    (out / "within_notes.txt").write_text("n")
    (out / "feature_stats.xlsx").write_text("s")
    before = tree(out)
    with pytest.raises(OutputError, match=r"is not empty .*--force"):
        with outdir.output_folder(out, "experiment", EXPERIMENT_FILES):
            pass
    assert tree(out) == before


def test_a_folder_holding_only_an_index_and_a_manifest_is_refused_for_a_dataset(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "mine4"
    out.mkdir()
    (out / "index.csv").write_text("id,label\nmine,walk\n")
    (out / "dataset.json").write_text('{"mine": true}\n')
    before = tree(out)
    code, err = mdf(one_record_dataset(tmp_path, out), capsys)
    assert code == 2 and "--force" in err and str(out) in err, err
    assert tree(out) == before


def commit(folder: outdir.OutputFolder, files: dict[str, str], **kw: object) -> None:
    stage = folder.stage()
    for name, text in files.items():
        (stage / name).write_text(text)
    folder.commit(stage, **kw)  # type: ignore[arg-type]


def test_only_files_the_command_wrote_are_removed(tmp_path: Path) -> None:
    """An earlier output's own files are removed when not made again, but never a file of the
    user's with one of the command's names, nor one of ours the user has since replaced."""
    out = tmp_path / "o"
    with outdir.output_folder(out, "experiment", EXPERIMENT_FILES) as folder:
        commit(folder, {"report.md": "1", "within_a_confusion.csv": "1", "summary.json": "1"})
    (out / "within_notes.txt").write_text("user's")  # matches within_*
    (out / "summary.json").unlink()  # the user replaces one of ours with a file of their own
    (out / "summary.json").write_text("user's summary")
    (out / "within_dir").mkdir()
    (out / "within_dir" / "f.txt").write_text("user's")
    with outdir.output_folder(out, "experiment", EXPERIMENT_FILES) as folder:
        commit(folder, {"report.md": "2"})
    assert (out / "report.md").read_text() == "2"
    assert not (out / "within_a_confusion.csv").exists()  # ours, not made again
    assert (out / "within_notes.txt").read_text() == "user's"
    assert (out / "summary.json").read_text() == "user's summary"
    assert (out / "within_dir" / "f.txt").read_text() == "user's"
    # a user's file the new output would replace is refused without --force, nothing moved
    before = tree(out)
    with outdir.output_folder(out, "experiment", EXPERIMENT_FILES) as folder:
        with pytest.raises(OutputError, match=r"'within_notes\.txt'.*--force"):
            commit(folder, {"report.md": "3", "within_notes.txt": "ours"})
    assert tree(out) == before
    with outdir.output_folder(out, "experiment", EXPERIMENT_FILES, force=True) as folder:
        commit(folder, {"report.md": "3", "within_notes.txt": "ours"})
    assert (out / "within_notes.txt").read_text() == "ours"
    assert (out / "within_dir" / "f.txt").read_text() == "user's"


def previous_run(tmp_path: Path) -> tuple[Path, dict[str, bytes | None]]:
    """A folder holding an earlier run's output and a file of the user's."""
    out = tmp_path / "o"
    with outdir.output_folder(out, "run", OUTPUTS) as folder:
        commit(folder, {"result.npz": "old", "metadata.json": "old", "range_time.png": "old"})
    (out / "notes.txt").write_text("user's")
    return out, tree(out)


NEW = {"features.json": "new", "metadata.json": "new", "result.npz": "new"}


@pytest.mark.parametrize("k", range(8))
def test_an_interrupt_during_the_swap_leaves_the_earlier_output(tmp_path: Path, k: int) -> None:
    """A Ctrl-C (KeyboardInterrupt) raised at the instant of the k-th rename of a swap (the
    marker that records the swap; three new files in, two replaced and one removed aside: six;
    the marker that ends the swap) moves everything back: the earlier output as it was, marker
    included."""
    out, before = previous_run(tmp_path)
    real = outdir.os.replace
    calls = []

    def replace(src: object, dst: object) -> None:
        calls.append(dst)
        if len(calls) == k + 1:
            raise KeyboardInterrupt
        real(src, dst)  # type: ignore[arg-type]

    with outdir.output_folder(out, "run", OUTPUTS) as folder:
        stage = folder.stage()
        for name, text in NEW.items():
            (stage / name).write_text(text)
        outdir.os.replace = replace  # type: ignore[assignment]
        try:
            with pytest.raises(KeyboardInterrupt):
                folder.commit(stage)
        finally:
            outdir.os.replace = real
    assert tree(out) == before


SWAP_KILLED = textwrap.dedent(
    """
    import os, sys
    from pathlib import Path
    from mdframework import outdir
    from mdframework.output import OUTPUTS
    out, k = Path(sys.argv[1]), int(sys.argv[2])
    real, calls = os.replace, []
    def replace(src, dst):
        calls.append(dst)
        if len(calls) == k + 1:
            os._exit(9)  # killed outright: no clean-up of any kind
        real(src, dst)
    with outdir.output_folder(out, "run", OUTPUTS) as folder:
        stage = folder.stage()
        for name in ("features.json", "metadata.json", "result.npz"):
            (stage / name).write_text("new")
        outdir.os.replace = replace
        folder.commit(stage)
    """
)


@pytest.mark.parametrize("k", range(8))
def test_a_process_killed_during_the_swap_is_undone_by_the_next_command(
    tmp_path: Path, k: int
) -> None:
    """The process dies at the instant of the k-th rename of the swap (as in the test above;
    k = 7: the marker that ends the swap): the folder may hold a mix, recorded in the marker;
    the next command on the folder moves everything back before it starts."""
    out, before = previous_run(tmp_path)
    proc = subprocess.run(
        [sys.executable, "-c", SWAP_KILLED, str(out), str(k)], capture_output=True, text=True
    )
    assert proc.returncode == 9, proc.stderr
    with outdir.output_folder(out, "run", OUTPUTS):
        after = tree(out)
    assert after == before
    marker = json.loads((out / ".mdf-run.json").read_text())
    assert sorted(marker["files"]) == ["metadata.json", "range_time.png", "result.npz"]


def test_stale_staging_folders_in_the_staging_dir_are_swept(tmp_path: Path) -> None:
    """A killed command's staging folder in ``--staging-dir`` goes with the next command that
    uses that staging dir; a live command's (its lock held) stays, as does anything else."""
    sdir = tmp_path / "sdir"
    sdir.mkdir()
    killed = textwrap.dedent(
        """
        import os, sys
        from mdframework import outdir
        from mdframework.output import OUTPUTS
        with outdir.output_folder(sys.argv[1], "run", OUTPUTS, staging_dir=sys.argv[2]) as f:
            (f.stage() / "result.npz").write_text("partial")
            os._exit(9)
        """
    )
    proc = subprocess.run([sys.executable, "-c", killed, str(tmp_path / "a"), str(sdir)])
    assert proc.returncode == 9
    (left,) = sdir.glob(".mdf-staging-run-*")
    assert (left / "result.npz").exists()
    (sdir / "mine.txt").write_text("user's")
    (sdir / ".mdf-staging-notadir").write_text("not ours to judge")
    with outdir.output_folder(tmp_path / "b", "run", OUTPUTS, staging_dir=sdir) as live:
        live_stage = live.stage()
        assert not left.exists()
        # another command meanwhile: the live staging folder is not swept
        with outdir.output_folder(tmp_path / "c", "run", OUTPUTS, staging_dir=sdir):
            assert live_stage.is_dir()
    assert sorted(p.name for p in sdir.iterdir()) == [".mdf-staging-notadir", "mine.txt"]


def test_a_build_stopped_between_its_index_files_is_refused_until_finished(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``index.csv``, ``skipped.csv`` and ``dataset.json`` are three files: a stop after the
    first (a signal at that instant) leaves them not matching, and the dataset is refused with
    one line saying to run the build again, which finishes it."""
    from mdframework import dataset

    out = tmp_path / "ds"
    args = one_record_dataset(tmp_path, out)
    real = dataset.atomic_write_text

    def stop_after_the_index(path: Path, text: str, **kw: str) -> None:
        real(path, text, **kw)
        if path.name == dataset.INDEX:
            raise KeyboardInterrupt

    monkeypatch.setattr(dataset, "atomic_write_text", stop_after_the_index)
    assert mdf(args, capsys)[0] == 130
    assert (out / dataset.INDEX).exists() and not (out / dataset.MANIFEST).exists()
    with pytest.raises(dataset.MdfError, match=r"stopped while it wrote index\.csv.* again"):
        dataset.load_dataset(out)
    monkeypatch.setattr(dataset, "atomic_write_text", real)
    assert mdf(args, capsys)[0] == 0
    assert len(dataset.load_dataset(out).labels) == 1


@pytest.mark.parametrize("kind", ["link", "fifo"])
def test_a_lock_file_that_is_a_link_or_a_pipe_is_refused_untouched(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], kind: str
) -> None:
    """A received folder whose ``.mdf.lock`` is a link to a file elsewhere (or a pipe): the
    command refuses it with one line, and the linked file is not truncated or written (the
    lock's holder details were written through the link, even when the folder was then
    refused)."""
    precious = tmp_path / "precious.txt"
    precious.write_text("the user's data\n")
    out = tmp_path / "received"
    out.mkdir()
    if kind == "link":
        (out / outdir.LOCK).symlink_to(Path("..") / "precious.txt")
    else:
        os.mkfifo(out / outdir.LOCK)
    code, err = mdf(["run", str(POINT), "--out", str(out)], capsys)
    assert code == 2
    (line,) = err.strip().splitlines()
    assert line.startswith(f"mdf: error: --out {out}: holds {outdir.LOCK} as a link"), line
    assert precious.read_text() == "the user's data\n"
    assert sorted(p.name for p in out.iterdir()) == [outdir.LOCK]


def test_a_dataset_whose_records_folder_is_a_link_is_refused_untouched(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A received dataset folder whose ``records`` links to a folder elsewhere: a build (with
    --force too) refuses it with one line, before writing a record there or removing one of
    the record-named files it holds (an earlier config's records are removed on a rebuild)."""
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "00099-aaaaaaaaaa.npz").write_bytes(b"a record of another dataset")
    before = tree(elsewhere)
    out = tmp_path / "received"
    out.mkdir()
    (out / "records").symlink_to(Path("..") / "elsewhere")
    for force in ([], ["--force"]):
        code, err = mdf([*one_record_dataset(tmp_path, out), *force], capsys)
        assert code == 2
        (line,) = err.strip().splitlines()
        assert line.startswith(f"mdf: error: --out {out}: "), line
        assert "its 'records' is a link" in line or not force, line
        assert tree(elsewhere) == before


@pytest.mark.parametrize("target", ["a-file", "nothing"])
def test_a_records_link_to_a_file_or_nothing_is_named_as_a_file_in_the_way(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], target: str
) -> None:
    """A dataset folder whose ``records`` is a link to a file, or to nothing: the build with
    --force is refused naming the file in the way (the message said a link to another
    folder)."""
    out = tmp_path / "received"
    out.mkdir()
    if target == "a-file":
        (tmp_path / target).write_text("a file of the user's\n")
    (out / "records").symlink_to(tmp_path / target)
    code, err = mdf([*one_record_dataset(tmp_path, out), "--force"], capsys)
    assert code == 2
    (line,) = err.strip().splitlines()
    assert line.startswith(f"mdf: error: --out {out}: holds the file 'records', "), line
    assert target == "nothing" or (tmp_path / target).read_text() == "a file of the user's\n"


def test_a_received_dataset_json_that_is_a_pipe_is_not_read(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A received dataset folder whose marker names no config and whose ``dataset.json`` (where
    a build before markers kept its config) is a named pipe: the build waited forever on the
    pipe. The pipe counts as a damaged manifest (no earlier config), and the build replaces it."""
    out = tmp_path / "received"
    out.mkdir()
    (out / ".mdf-dataset.json").write_text("{}")
    os.mkfifo(out / "dataset.json")
    code, err = mdf(one_record_dataset(tmp_path, out), capsys)
    assert code == 0, err
    assert json.loads((out / "dataset.json").read_text())["n_records"] == 1


@pytest.mark.parametrize("linked", ["aside", "stage", "foreign"])
def test_a_received_marker_cannot_move_files_from_elsewhere_into_out(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], linked: str
) -> None:
    """A received folder whose marker records a swap killed half done, with the staging folder
    (or the folder of replaced files in it) a link to a folder of the user's: undoing the swap
    moved the user's files out of that folder into --out. Nothing outside --out moves now, nor
    from a real folder of the user's that the marker names as the staging folder."""
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "id_rsa").write_text("secret\n")
    before = tree(mine)
    out = tmp_path / "received"
    stage = out / ".mdf-staging-run-x"
    if linked == "aside":
        stage.mkdir(parents=True)
        (stage / ".mdf-aside").symlink_to(Path("..") / ".." / "mine")
    elif linked == "foreign":
        out.mkdir()
        (mine / ".mdf-aside").mkdir()
        (mine / ".mdf-aside" / "notes.txt").write_text("mine too\n")
        before = tree(mine)
        stage = mine
    else:
        out.mkdir()
        (mine / ".mdf-aside").mkdir()
        (mine / ".mdf-aside" / "notes.txt").write_text("mine too\n")
        before = tree(mine)
        stage.symlink_to(mine)
    swap = {"stage": str(stage), "new": [], "previous_marker": None}
    (out / ".mdf-run.json").write_text(json.dumps({"command": "run", "swap": swap}))
    mdf(["run", str(POINT), "--out", str(out)], capsys)
    assert tree(mine) == before


@pytest.mark.parametrize("new", [None, 5, {"a": 1}])
def test_a_received_marker_whose_swap_lists_no_names_is_left(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], new: object
) -> None:
    """A received marker recording a swap whose new files are not a list of names: the run
    goes ahead (nothing to undo), with a marker of its own."""
    out = tmp_path / "received"
    stage = out / ".mdf-staging-run-x"
    stage.mkdir(parents=True)
    swap = {"stage": str(stage), "new": new, "previous_marker": None}
    (out / ".mdf-run.json").write_text(json.dumps({"command": "run", "swap": swap}))
    code, err = mdf(["run", str(POINT), "--out", str(out)], capsys)
    assert code == 0, err
    assert json.loads((out / ".mdf-run.json").read_text())["command"] == "run"


def test_read_marker_text_reads_at_most_max_marker_bytes(tmp_path: Path) -> None:
    """A marker of MAX_MARKER_BYTES is read whole; one byte more is refused."""
    path = tmp_path / "marker.json"
    path.write_text("x" * outdir.MAX_MARKER_BYTES)
    assert len(outdir.read_marker_text(path)) == outdir.MAX_MARKER_BYTES
    path.write_text("x" * (outdir.MAX_MARKER_BYTES + 1))
    with pytest.raises(ValueError, match="more than"):
        outdir.read_marker_text(path)


@pytest.mark.parametrize("special", ["fifo", "devzero"])
def test_a_marker_that_is_a_pipe_or_a_device_is_not_read(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], special: str
) -> None:
    """A received folder whose run marker is a named pipe or a link to ``/dev/zero``: reading
    it waited forever, or filled the memory (an internal MemoryError). It is an unreadable
    marker now: the run writes its files and a marker of its own in its place."""
    out = tmp_path / "received"
    out.mkdir()
    marker = out / ".mdf-run.json"
    if special == "fifo":
        os.mkfifo(marker)
    else:
        marker.symlink_to("/dev/zero")
    code, err = mdf(["run", str(POINT), "--out", str(out)], capsys)
    assert code == 0, err
    assert marker.is_file() and not marker.is_symlink()
    assert json.loads(marker.read_text())["command"] == "run"


def test_a_received_marker_whose_swap_names_a_folder_leaves_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A received marker recording a half-done swap whose new files include the name of a
    folder in --out: undoing the swap was an internal IsADirectoryError. A command writes
    files only, so the folder is not one it moved in: it is left, and the run goes on to its
    usual judgement of the folder (which holds files the run did not write: refused)."""
    out = tmp_path / "received"
    stage = out / ".mdf-staging-run-x"
    stage.mkdir(parents=True)
    (out / "data").mkdir()
    (out / "data" / "keep.txt").write_text("mine\n")
    swap = {"stage": str(stage), "new": ["data"], "previous_marker": None}
    (out / ".mdf-run.json").write_text(json.dumps({"command": "run", "swap": swap}))
    code, err = mdf(["run", str(POINT), "--out", str(out)], capsys)
    assert code == 2, err
    assert "internal error" not in err
    assert (out / "data" / "keep.txt").read_text() == "mine\n"
