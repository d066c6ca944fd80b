"""Dataset builds: deterministic across workers and schedulers, resumable, atomic."""

from __future__ import annotations

import importlib.metadata
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
import warnings
from contextlib import closing
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import EXAMPLES
from helpers import point_dataset

from mdframework import cli, dataset
from mdframework import workers as pool_workers
from mdframework.dataset import (
    RECORDS,
    Dataset,
    DatasetWarning,
    build_dataset,
    load_dataset,
    load_dataset_config,
    plan_records,
    read_record,
    record_arrays,
)
from mdframework.errors import ConfigError, DataFileError, MdfError
from mdframework.features import FEATURE_NAMES
from mdframework.sanity import MotionSanityWarning

CMU = EXAMPLES / "data" / "cmu"


def ignore_fork_with_threads() -> None:
    """Ignore Python's (3.12 and later) warning that a process with threads forks, as
    pyproject.toml's filters do, where a test's own filters would show it: in a test process the
    local Dask cluster of an earlier test leaves a thread (Dask's offload thread); a command's
    own process has none (the test of a build forking from one thread)."""
    warnings.filterwarnings("ignore", r"This process .* is multi-threaded", DeprecationWarning)


def write_config(path: Path, *, boxing_records: int = 2, aspects: str = "[0.0, 45.0]") -> Path:
    path.write_text(f"""
seed = 7
[[sources]]
label = "walk"
motion = {{ kind = "cmu", file = "{CMU / "asf-amc" / "02_01.amc"}" }}
[[sources]]
label = "run"
motion = {{ kind = "cmu", file = "{CMU / "asf-amc" / "09_06.amc"}" }}
[[sources]]
label = "boxing"
motion = {{ kind = "cmu", file = "{CMU / "bvh" / "80_10.bvh"}" }}
max_records = {boxing_records}
[record_lengths]
walk = 1.0
run = 1.0
boxing = 1.0
[variations]
aspect_deg = {aspects}
[base.processing]
nfft = 256
""")
    return path


def records(out: Path) -> dict[str, tuple[dict[str, np.ndarray], dict[str, object]]]:
    return {p.name: read_record(p) for p in sorted((out / RECORDS).glob("*.npz"))}


def assert_same(a: Path, b: Path) -> None:
    ra, rb = records(a), records(b)
    assert list(ra) == list(rb) and ra
    for name in ra:
        for key in ra[name][0]:
            assert np.array_equal(ra[name][0][key], rb[name][0][key]), (name, key)
        assert ra[name][1] == rb[name][1]
    assert (a / "index.csv").read_text() == (b / "index.csv").read_text()


def _seeds_by_window(specs: list[Any]) -> dict[tuple[Any, ...], tuple[Any, ...]]:
    """Each record's seed and random draws by its source file, window, aspect and draw number."""
    out: dict[tuple[Any, ...], tuple[Any, ...]] = {}
    for spec in specs:
        m = spec.run_config["motion"]
        where = (m["file"], m["start"], spec.run_config["scene"]["person"]["aspect_deg"])
        n = sum(k[:3] == where for k in out)
        out[(*where, n)] = (spec.run_config["seed"], json.dumps(spec.draws))
    return out


def test_adding_records_leaves_the_other_records_seeds_and_draws(tmp_path: Path) -> None:
    """A record's seed and random draws derive from what the record is (its source's motion,
    its window, its grid point, its draw number), not from its number in the dataset: another
    aspect, another source before the others or more boxing windows left every other record's
    noise and draws as they were (they shifted every later record's)."""
    extra = "[randomize]\ndraws = 2\nradar_height = { uniform = [1.0, 2.0] }\n"
    first = write_config(tmp_path / "a.toml")
    first.write_text(first.read_text() + extra)
    cfg, base = load_dataset_config(first)
    before = _seeds_by_window(plan_records(cfg, base))
    more = write_config(tmp_path / "b.toml", boxing_records=3, aspects="[0.0, 20.0, 45.0]")
    text = more.read_text().replace(
        "[[sources]]",
        f'[[sources]]\nlabel = "jump"\nmotion = {{ kind = "cmu", file = '
        f'"{CMU / "bvh" / "13_41.bvh"}" }}\nmax_records = 1\n[[sources]]',
        1,
    )
    more.write_text(text.replace("walk = 1.0", "walk = 1.0\njump = 1.0") + extra)
    cfg, base = load_dataset_config(more)
    after = _seeds_by_window(plan_records(cfg, base))
    # windows: walk 2, run 1, boxing 2 then 3, jump 1; x 2 then 3 aspects x 2 draws
    assert (len(before), len(after)) == (5 * 2 * 2, 7 * 3 * 2)
    assert {k: after[k] for k in before} == before
    # and every record its own seed and draws
    assert len({v[0] for v in after.values()}) == len({v[1] for v in after.values()}) == len(after)


def test_a_variation_value_given_twice_gives_records_of_their_own_seeds(tmp_path: Path) -> None:
    """Two records alike but for their place in the grid (an aspect given twice: two noise
    realisations of one view, as the seeds from the record's number gave) have seeds and
    draws of their own; derived from what the record is alone, they were the same record
    twice, a test record's copy in the training set. The others keep theirs."""
    extra = "[randomize]\ndraws = 2\nradar_height = { uniform = [1.0, 2.0] }\n"
    once = write_config(tmp_path / "a.toml", aspects="[0.0]")
    once.write_text(once.read_text() + extra)
    twice = write_config(tmp_path / "b.toml", aspects="[0.0, 0.0]")
    twice.write_text(twice.read_text() + extra)
    single = [
        (s.run_config["seed"], json.dumps(s.draws))
        for s in plan_records(*load_dataset_config(once))
    ]
    double = [
        (s.run_config["seed"], json.dumps(s.draws))
        for s in plan_records(*load_dataset_config(twice))
    ]
    assert len(double) == 2 * len(single) and len(set(double)) == len(double)
    assert set(single) <= set(double)


def test_a_grid_point_given_three_times_gives_three_records_of_their_own(
    tmp_path: Path,
) -> None:
    """Each record alike (an aspect given three times) is told from the ones before it by
    its count of them, not by a mark of being a copy: the third was the second again."""
    extra = "[randomize]\ndraws = 2\nradar_height = { uniform = [1.0, 2.0] }\n"
    thrice = write_config(tmp_path / "c.toml", aspects="[0.0, 0.0, 0.0]")
    thrice.write_text(thrice.read_text() + extra)
    seeds = [
        (s.run_config["seed"], json.dumps(s.draws))
        for s in plan_records(*load_dataset_config(thrice))
    ]
    assert len(seeds) == 5 * 3 * 2 and len(set(seeds)) == len(seeds)


def test_the_dataset_seed_reaches_every_records_seed_and_draws(tmp_path: Path) -> None:
    """Another top-level seed gives every record another run seed and other draws (the seed
    is in each record's key, besides what the record is)."""
    extra = "[randomize]\ndraws = 2\nradar_height = { uniform = [1.0, 2.0] }\n"
    by_seed = []
    for seed in (7, 8):
        path = write_config(tmp_path / f"s{seed}.toml")
        path.write_text(path.read_text().replace("seed = 7", f"seed = {seed}") + extra)
        by_seed.append(_seeds_by_window(plan_records(*load_dataset_config(path))))
    assert by_seed[0].keys() == by_seed[1].keys()
    for k in by_seed[0]:
        assert by_seed[0][k][0] != by_seed[1][k][0], k
        assert by_seed[0][k][1] != by_seed[1][k][1], k


def test_a_later_motion_start_keeps_the_seeds_of_the_windows_it_keeps(tmp_path: Path) -> None:
    """A window is known by its start in the motion: a source's motion.start moved on by one
    record length drops the first window and leaves the later windows' seeds and draws as
    they were (counted among the source's windows, every one would have shifted)."""
    extra = "[randomize]\ndraws = 2\nradar_height = { uniform = [1.0, 2.0] }\n"
    first = write_config(tmp_path / "a.toml", boxing_records=3)
    first.write_text(first.read_text() + extra)
    later = write_config(tmp_path / "b.toml", boxing_records=2)
    boxing = f'file = "{CMU / "bvh" / "80_10.bvh"}"'
    later.write_text(later.read_text().replace(boxing, f"{boxing}, start = 1.0") + extra)
    before = _seeds_by_window(plan_records(*load_dataset_config(first)))
    after = _seeds_by_window(plan_records(*load_dataset_config(later)))
    kept = {k: v for k, v in after.items() if "80_10" in str(k[0])}
    assert sorted({k[1] for k in kept}) == [1.0, 2.0]
    assert {k: before[k] for k in kept} == kept
    assert {k: v for k, v in before.items() if "80_10" not in str(k[0])} == {
        k: v for k, v in after.items() if "80_10" not in str(k[0])
    }


def test_a_copy_elsewhere_draws_the_same(tmp_path: Path) -> None:
    """A record's seed and draws derive from its motion's contents, not its file's path: the
    same config with its motion files copied to another folder, named by a relative path or
    an absolute one, draws the same (the path as written changed every record's draws)."""
    extra = "[randomize]\ndraws = 2\nradar_height = { uniform = [1.0, 2.0] }\n"
    first = write_config(tmp_path / "a.toml")
    first.write_text(first.read_text() + extra)
    copy = tmp_path / "elsewhere"
    copy.mkdir()
    text = first.read_text()
    for name in ("asf-amc/02_01.amc", "asf-amc/02.asf", "asf-amc/09_06.amc", "asf-amc/09.asf"):
        shutil.copy(CMU / name, copy / Path(name).name)
    shutil.copy(CMU / "bvh" / "80_10.bvh", copy / "80_10.bvh")
    text = text.replace(f"{CMU / 'asf-amc'}/", "").replace(f"{CMU / 'bvh'}/", "")
    (copy / "b.toml").write_text(text)

    def seeds(path: Path) -> list[tuple[Any, str]]:
        specs = plan_records(*load_dataset_config(path))
        return [(s.run_config["seed"], json.dumps(s.draws)) for s in specs]

    before = seeds(first)
    assert seeds(copy / "b.toml") == before and len(set(before)) == len(before)


def test_plan_and_load(tmp_path: Path) -> None:
    cfg, base = load_dataset_config(write_config(tmp_path / "d.toml"))
    specs = plan_records(cfg, base)
    # walk 2.85 s -> 2 windows, run 1.17 s -> 1, boxing -> 2; times 2 aspects
    assert [s.label for s in specs] == ["walk"] * 4 + ["run"] * 2 + ["boxing"] * 4
    assert len({s.run_config["seed"] for s in specs}) == len(specs)
    out = tmp_path / "ds"
    rows = build_dataset(cfg, base, out, workers=1, progress=False)
    data = load_dataset(out)
    assert data.features.shape == (10, 7)
    assert list(data.labels) == [r["label"] for r in rows]
    assert isinstance(data.spectrograms, np.ndarray) and data.spectrograms.shape[0] == 10
    assert data.velocity is not None and data.spectrograms.shape[1] == data.velocity.size
    # the records one at a time, from the folder given as load_dataset takes it (text too: a
    # str failed with "unsupported operand type(s) for /")
    one_by_one = [a["spectrogram_db"] for a in record_arrays(str(out), data.table["id"])]
    assert np.array_equal(np.stack(one_by_one), data.spectrograms)
    # walking toward the radar at aspect 0: positive torso velocity; boxing: about zero
    torso = data.features[:, FEATURE_NAMES.index("torso_mean")]
    assert np.all(torso[data.labels == "walk"][::2] > 0.8)
    assert np.all(np.abs(torso[data.labels == "boxing"]) < 0.3)
    assert np.allclose(
        data.table["total_bandwidth"], data.table["upper_max"] - data.table["lower_min"]
    )
    arrays, meta = read_record(out / RECORDS / f"{rows[0]['id']}.npz")
    assert meta["units"]["features"] == "m/s" and meta["label"] == "walk"
    # the arrays as docs/datasets.md lists them
    n_doppler, n_frames = arrays["spectrogram_db"].shape
    assert arrays["spectrogram_db"].dtype == np.float32
    assert arrays["velocity_mps"].dtype == np.float64 and arrays["velocity_mps"].shape == (
        n_doppler,
    )
    assert arrays["time_s"].dtype == np.float64 and arrays["time_s"].shape == (n_frames,)
    assert arrays["features"].dtype == np.float64 and arrays["features"].shape == (7,)
    assert 0.0 < arrays["time_s"][0] < arrays["time_s"][-1] < float(rows[0]["duration_s"])
    assert "histograms" not in meta["units"]  # a spectrogram record has none


def test_a_missing_or_corrupt_record_names_its_file_when_loaded(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A dataset folder whose record file was deleted or damaged after the build: loading
    it (and an experiment on its histograms) is one line naming the file and the cure, not a
    FileNotFoundError or numpy's "pickled (object) data" ValueError."""
    cfg, base = load_dataset_config(write_config(tmp_path / "d.toml", boxing_records=1))
    out = tmp_path / "ds"
    build_dataset(cfg, base, out, workers=1, progress=False)
    files = sorted((out / RECORDS).glob("*.npz"))
    files[1].unlink()
    with pytest.raises(DataFileError) as err:
        load_dataset(out)
    assert str(err.value).startswith(f"{files[1]}: ")
    assert "mdf dataset build" in str(err.value)
    files[0].write_text("damaged\n")
    with pytest.raises(DataFileError, match=rf"^{re.escape(str(files[0]))}: .*mdf dataset build"):
        load_dataset(out, spectrograms=False, histograms=True)
    # a compressed record (a received one could expand megabytes into gigabytes) is refused
    # before anything is read from it: a build never compresses one
    arrays, meta = read_record(files[2])
    for damaged in files[:2]:
        damaged.write_bytes(files[2].read_bytes())
    np.savez_compressed(files[2], **arrays, meta=np.array(json.dumps(meta)))
    with pytest.raises(DataFileError, match=rf"^{re.escape(str(files[2]))}: not a complete"):
        load_dataset(out)


@pytest.mark.parametrize("name", ["index.csv", "dataset.json", "record"])
def test_a_dataset_file_that_is_a_pipe_is_refused_unread(tmp_path: Path, name: str) -> None:
    """A received dataset whose index, manifest or record file is a named pipe: loading it
    (``mdf experiment``) waited forever on the pipe. It is one error naming the file, before
    the file is opened."""
    out = tmp_path / "ds"
    (out / RECORDS).mkdir(parents=True)
    header = ",".join(["id", "label", "group", *FEATURE_NAMES])
    (out / "index.csv").write_text(f"{header}\nr0,walk,g0,{','.join(['1.0'] * 7)}\n")
    (out / "dataset.json").write_text("{}")
    path = out / RECORDS / "r0.npz" if name == "record" else out / name
    path.unlink(missing_ok=True)
    os.mkfifo(path)
    with pytest.raises(DataFileError, match=rf"^{re.escape(str(path))}: "):
        load_dataset(out)


def test_same_result_with_one_and_two_workers_and_dask(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each build starts without the motions an earlier one loaded: with 2 workers the planner
    loads them in 2 processes."""
    cfg, base = load_dataset_config(write_config(tmp_path / "d.toml"))
    build_dataset(cfg, base, tmp_path / "one", workers=1, progress=False)
    monkeypatch.setattr(dataset, "_MOTIONS", {})
    build_dataset(cfg, base, tmp_path / "two", workers=2, progress=False)
    assert_same(tmp_path / "one", tmp_path / "two")
    pytest.importorskip("distributed")
    monkeypatch.setattr(dataset, "_MOTIONS", {})
    build_dataset(cfg, base, tmp_path / "dask", workers=2, scheduler="local", progress=False)
    assert_same(tmp_path / "one", tmp_path / "dask")


@pytest.mark.parametrize("start_method", ["spawn", "forkserver"], indirect=True)
def test_workers_that_are_not_forked_build_the_same_dataset_and_say_the_same(
    start_method: str,
    tmp_path: Path,
    capfd: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Workers started afresh (macOS spawns them; Python 3.14 defaults to a fork server on
    Linux) build the records a forked worker builds, to the bit, and the command says the same:
    they are given the motions planning loaded, so the motion warnings are shown once, by the
    build's process (spawned workers loaded the motions again and printed the warnings in
    Python's own format; a fork server's workers exited at once: "a process in the process
    pool was terminated abruptly")."""
    config = write_config(tmp_path / "d.toml")
    err = {}
    for method in ("fork", start_method):
        monkeypatch.setenv(pool_workers.START_METHOD_ENV, method)
        dataset._forget_loaded()
        capfd.readouterr()
        out = tmp_path / method
        args = ["dataset", "build", str(config), "--out", str(out), "--workers", "2"]
        assert cli.main(args) == 0
        err[method] = capfd.readouterr().err
    assert err["fork"] == err[start_method]
    assert err["fork"].count("mdf: warning: ") == 2, err  # the boxing motion's two warnings
    assert "Warning: " not in err["fork"]
    assert_same(tmp_path / "fork", tmp_path / start_method)


def test_workers_are_forked_on_linux_whatever_pythons_default(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """On Linux the pool forks its workers (fast, and they inherit what the build loaded) even
    where Python's default is another method (Python 3.14: forkserver); MDF_START_METHOD
    chooses, and a method this platform lacks is one line naming the variable."""
    import multiprocessing

    monkeypatch.delenv(pool_workers.START_METHOD_ENV, raising=False)
    before = multiprocessing.get_start_method(allow_none=True)
    try:
        multiprocessing.set_start_method("forkserver", force=True)
        expected = "fork" if sys.platform.startswith("linux") else "forkserver"
        assert pool_workers.start_method() == expected
        with pool_workers.worker_pool(1) as pool:
            pool.submit(int).result()
            (proc,) = pool._processes.values()  # type: ignore[attr-defined]
            assert type(proc).__name__ == f"{expected.capitalize()}Process"
    finally:
        multiprocessing.set_start_method(before, force=True)
    monkeypatch.setenv(pool_workers.START_METHOD_ENV, "spawn")
    assert pool_workers.start_method() == "spawn"
    monkeypatch.setenv(pool_workers.START_METHOD_ENV, "vfork")
    with pytest.raises(MdfError, match=r"^MDF_START_METHOD='vfork': not a start method"):
        pool_workers.start_method()


@pytest.mark.parametrize(
    ("variable", "value", "message"),
    [
        ("MDF_START_METHOD", "vfork", "MDF_START_METHOD='vfork': not a start method of this "
         "platform; use one of "),
        ("MDF_DASK_TIMEOUT", "-1", "MDF_DASK_TIMEOUT='-1': give a timeout in seconds, "
         "0 < t <= 3600"),
    ],
)  # fmt: skip
def test_a_bad_environment_variable_is_named_alone_not_as_the_configs(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    variable: str,
    value: str,
    message: str,
) -> None:
    """The line names the variable, not the config file, which says nothing of it."""
    monkeypatch.setenv(variable, value)
    config = write_config(tmp_path / "d.toml", boxing_records=1, aspects="[0.0]")
    out = tmp_path / "out"
    args = ["dataset", "build", str(config), "--out", str(out), "--workers", "2", "--no-progress"]
    if variable == "MDF_DASK_TIMEOUT":
        args += ["--scheduler", "tcp://127.0.0.1:1"]
    assert cli.main(args) == 2
    err = capsys.readouterr().err.splitlines()[-1]
    assert err.startswith(f"mdf: error: {message}"), err
    assert "d.toml" not in err


@pytest.mark.parametrize("command", ["dataset build", "experiment"])
def test_a_bad_start_method_is_blamed_on_the_variable_not_the_config(
    command: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """MDF_START_METHOD (and MDF_DASK_SCHEDULER) are not the config's fields: a bad one is
    named alone (it was prefixed with the config file's name), before any folder is made."""
    config = write_config(tmp_path / "d.toml")
    if command == "experiment":
        config = tmp_path / "e.toml"
        config.write_text('[dataset]\nconfig = "d.toml"\n[classifier]\nkind = "knn"\n')
    out = tmp_path / "out"
    args = [*command.split(), str(config), "--out", str(out), "--workers", "2", "--no-progress"]
    monkeypatch.setenv(pool_workers.START_METHOD_ENV, "vfork")
    assert cli.main(args) == 2
    assert capsys.readouterr().err.startswith("mdf: error: MDF_START_METHOD='vfork': not a ")
    assert not out.exists()
    monkeypatch.delenv(pool_workers.START_METHOD_ENV)
    monkeypatch.setenv(dataset.SCHEDULER_ENV, "bogus::")
    assert cli.main(args) == 2
    assert capsys.readouterr().err.startswith("mdf: error: Dask scheduler 'bogus::': not an ")
    assert not out.exists()


def test_a_build_forks_its_workers_from_a_process_of_one_thread(tmp_path: Path) -> None:
    """No thread of the command is alive when a build forks its workers (in the child, a lock
    such a thread held stays held): the progress bar's monitor thread was (tqdm starts one for
    every bar, a disabled one too), and Python 3.12 and later warned "This process is
    multi-threaded, use of fork() may lead to deadlocks in the child" once per worker."""
    script = (
        "import os, sys, threading\n"
        "cpus = os.cpu_count() or 1\n"  # motions load in one process per CPU: 2 on one CPU
        "os.cpu_count = lambda: max(2, cpus)\n"
        "seen = []\n"
        "os.register_at_fork(before=lambda: seen.append([t.name for t in threading.enumerate()]))\n"
        "from mdframework.cli import main\n"
        "code = main(sys.argv[1:])\n"
        "print(seen)\n"
        "sys.exit(code)\n"
    )
    config = write_config(tmp_path / "d.toml")
    args = ["dataset", "build", str(config), "--out", str(tmp_path / "ds"), "--workers", "2"]
    env = {**os.environ, pool_workers.START_METHOD_ENV: "fork"}
    done = subprocess.run(
        [sys.executable, "-c", script, *args], capture_output=True, text=True, env=env
    )
    assert done.returncode == 0, done.stderr
    seen = json.loads(done.stdout.strip().splitlines()[-1].replace("'", '"'))
    assert len(seen) == 4, seen  # 2 workers to load the motions, 2 to build the records
    assert all(threads == ["MainThread"] for threads in seen), seen


def test_a_local_dask_cluster_leaves_port_8787_free(tmp_path: Path) -> None:
    """A local Dask cluster has no dashboard, and the HTTP server its scheduler still starts
    (health and metrics routes) runs on a free loopback port, not on Dask's default 8787: a
    user's own Dask dashboard started during a build keeps its port (and a second build on the
    machine gives no "port in use" warning)."""
    pytest.importorskip("distributed")
    cfg, _ = load_dataset_config(write_config(tmp_path / "d.toml"))

    def port_free() -> bool:
        with socket.socket() as probe:
            try:
                probe.bind(("127.0.0.1", 8787))
            except OSError:
                return False
        return True

    if not port_free():
        pytest.skip("something else on this machine holds port 8787")
    executor = dataset._executor(cfg, 1, "local")
    with closing(executor):
        next(executor)  # the cluster runs
        assert port_free()


@pytest.mark.parametrize("n_records", [0, 1, 5, 64, 480, 1001])
@pytest.mark.parametrize("threads", [1, 2, 7])
def test_record_chunks_keep_order_and_shrink_to_single_records(
    n_records: int, threads: int
) -> None:
    """Worker tasks hold consecutive records, all of them once, in order; at most
    MAX_RECORDS_PER_TASK each; each takes at most its share of the records left, so the
    tasks shrink and the last ``threads`` tasks are single records."""
    specs: list[Any] = list(range(n_records))
    chunks = dataset.record_chunks(specs, threads)
    assert [i for chunk in chunks for i in chunk] == specs
    sizes = [len(chunk) for chunk in chunks]
    assert all(1 <= size <= dataset.MAX_RECORDS_PER_TASK for size in sizes)
    assert sizes == sorted(sizes, reverse=True)
    share = threads * dataset.TASKS_PER_THREAD
    left = n_records
    for size in sizes:
        assert size == 1 or size <= left / share
        left -= size
    assert sizes[-threads:] == [1] * min(threads, len(sizes))
    if n_records >= 480:  # a long build: tasks of several records
        assert max(sizes) == dataset.MAX_RECORDS_PER_TASK and len(chunks) < n_records / 3


def test_tasks_of_several_records_keep_errors_and_skips(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Records built several to a worker task (forced here: 3 a task) give the rows and
    skipped records of a build in one process; with on_error = "stop" the build stops on a
    failing record (with 2 workers the first to fail, not always the first in order)."""
    monkeypatch.setattr(dataset, "TASKS_PER_THREAD", 1)
    monkeypatch.setattr(dataset, "MAX_RECORDS_PER_TASK", 3)
    cfg, base = load_dataset_config(write_config(tmp_path / "d.toml", boxing_records=4))
    specs = plan_records(cfg, base)
    assert max(len(c) for c in dataset.record_chunks(specs, 2)) == 3
    build_dataset(cfg, base, tmp_path / "one", workers=1, progress=False)
    build_dataset(cfg, base, tmp_path / "two", workers=2, progress=False)
    assert_same(tmp_path / "one", tmp_path / "two")
    # a radar 2 m ahead: the walk and run records reach it (fail), the boxing ones do not
    near = write_config(tmp_path / "near.toml", boxing_records=4)
    near.write_text(near.read_text() + "[base.scene]\nradar_position = [2.0, 0.0, 1.2]\n")
    text = near.read_text()
    cfg, base = load_dataset_config(near)
    for workers in (1, 2):
        with pytest.raises(dataset.MdfError, match=r"^record \S+ \((walk|run); .* comes within "):
            build_dataset(cfg, base, tmp_path / f"stop{workers}", workers=workers, progress=False)
    near.write_text('on_error = "skip"\n' + text)
    cfg, base = load_dataset_config(near)
    for workers in (1, 2):
        with pytest.warns(DatasetWarning, match="skipped: "):
            build_dataset(cfg, base, tmp_path / f"skip{workers}", workers=workers, progress=False)
    assert_same(tmp_path / "skip1", tmp_path / "skip2")
    skipped = [(tmp_path / f"skip{w}" / dataset.SKIPPED).read_text() for w in (1, 2)]
    assert skipped[0] == skipped[1] and len(skipped[0].splitlines()) > 2
    assert len(records(tmp_path / "skip1")) >= 4  # the boxing records


def test_local_dask_workers_run_with_the_build_settings(tmp_path: Path) -> None:
    """The local Dask cluster a build starts: its workers run without Dask's
    MALLOC_TRIM_THRESHOLD_, without the statistical profiler and with the slower monitors
    (LOCAL_DASK_CONFIG), and they hold the motions the planner loaded."""
    pytest.importorskip("distributed")
    import dask
    from distributed import default_client

    cfg, base = load_dataset_config(write_config(tmp_path / "d.toml"))
    plan_records(cfg, base)
    executor = dataset._executor(cfg, 1, "local")
    next(executor)
    try:
        client = default_client()
        keys = list(dataset.LOCAL_DASK_CONFIG)

        def settings() -> tuple[dict[str, Any], bool, int]:
            return (
                {key: dask.config.get(key) for key in keys},
                "MALLOC_TRIM_THRESHOLD_" in os.environ,
                len(dataset._MOTIONS),
            )

        (seen,) = client.run(settings).values()
    finally:
        executor.close()
    assert seen == (dataset.LOCAL_DASK_CONFIG, False, len(dataset._MOTIONS))
    assert len(dataset._MOTIONS) >= 3


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's malloc")
def test_workers_reuse_freed_memory_for_large_arrays() -> None:
    """A fresh process maps a 10 MiB array afresh each time it is made (and faults its pages
    in); after ``keep_freed_memory`` (what every local worker runs first) it reuses the freed
    block: no page faults. Workers forked from a planner that had not freed large arrays took
    3,600 page faults and up to a third more CPU per record without it."""
    script = """
import resource, sys
import numpy as np
from mdframework.workers import keep_freed_memory
if sys.argv[1] == "1":
    keep_freed_memory()
a = np.ones(10 << 17)
del a
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(20):
    a = np.ones(10 << 17)
    del a
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""
    faults = [
        int(
            subprocess.run(
                [sys.executable, "-c", script, flag], capture_output=True, text=True, check=True
            ).stdout
        )
        for flag in ("0", "1")
    ]
    assert faults[0] >= 20 and faults[1] <= faults[0] / 10, faults


def _blas_threads() -> list[tuple[int, int]]:
    """(threads, the most threads the library runs) of each BLAS library of this process."""
    from threadpoolctl import threadpool_info, threadpool_limits

    def threads() -> list[int]:
        return [int(lib["num_threads"]) for lib in threadpool_info() if lib["user_api"] == "blas"]

    now = threads()
    with threadpool_limits(1 << 16):  # as many as each library allows (OpenBLAS: 64)
        most = threads()
    return list(zip(now, most, strict=True))


def test_pool_workers_share_the_cpus_blas_threads() -> None:
    """Each of n local workers runs its BLAS with cpu_count // n threads (at least one, at most
    what the library allows: OpenBLAS runs 64 on a machine of 128 CPUs), so that n workers side
    by side never start more BLAS threads than there are CPUs."""
    from mdframework.workers import worker_pool

    n_cpu = os.cpu_count() or 1
    for n in (1, 2, n_cpu + 1):
        with worker_pool(n) as pool:
            threads = pool.submit(_blas_threads).result()
        share = max(1, n_cpu // n)
        assert threads and all(t == min(share, most) for t, most in threads), (n, threads)


def _mixed_sources(tmp_path: Path, *extra: str) -> Path:
    """Sources of every loader: ASF/AMC and BVH (both warn about glitches), the Boulic walker,
    and ``extra`` sources."""
    path = tmp_path / "mixed.toml"
    path.write_text(
        "\n".join(
            [
                "[record_lengths]\nwalk = 1.0\nboxing = 1.0",
                *(
                    f'[[sources]]\nlabel = "{label}"\nmax_records = 2\nmotion = {motion}'
                    for label, motion in [
                        ("boxing", f'{{ kind = "cmu", file = "{CMU / "asf-amc" / "13_18.amc"}" }}'),
                        ("walk", '{ kind = "boulic", n_cycles = 2 }'),
                        ("boxing", f'{{ kind = "cmu", file = "{CMU / "bvh" / "80_10.bvh"}" }}'),
                        ("walk", f'{{ kind = "cmu", file = "{CMU / "asf-amc" / "02_01.amc"}" }}'),
                    ]
                ),
                *extra,
            ]
        )
        + "\n"
    )
    return path


def _plan_fresh(
    cfg: dataset.DatasetConfig, base: Path, workers: int, monkeypatch: pytest.MonkeyPatch
) -> tuple[list[dataset.RecordSpec], dict[tuple[str, str], Any], list[tuple[type, str]], int]:
    """Plan with an empty motion cache: specs, motions, warnings shown (category, text) and how
    many motions this process loaded itself."""
    monkeypatch.setattr(dataset, "_MOTIONS", {})
    cpus = os.cpu_count() or 1  # motions load in one process per CPU: 2 on a machine of one
    monkeypatch.setattr(os, "cpu_count", lambda: max(2, cpus))
    calls = []
    real = dataset.load_motion
    monkeypatch.setattr(dataset, "load_motion", lambda src: calls.append(src) or real(src))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ignore_fork_with_threads()
        specs = plan_records(cfg, base, workers=workers)
    shown = [(w.category, str(w.message)) for w in caught]
    return specs, dict(dataset._MOTIONS), shown, len(calls)


def test_motions_loaded_in_parallel_plan_the_same_records(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With 2 workers the planner's process loads none of the motions itself; the motions are
    the same to the bit, the specs equal, and every warning of their loading is shown once, in
    source order, as when one process loads them all."""
    cfg, base = load_dataset_config(_mixed_sources(tmp_path))
    specs1, motions1, shown1, loaded1 = _plan_fresh(cfg, base, 1, monkeypatch)
    specs2, motions2, shown2, loaded2 = _plan_fresh(cfg, base, 2, monkeypatch)
    assert (loaded1, loaded2) == (4, 0)
    assert specs1 == specs2 and len(specs1) == 8
    assert list(motions1) == list(motions2)
    for key, m1 in motions1.items():
        m2 = motions2[key]
        assert type(m1) is type(m2)
        for name in ("time", "positions", "valid"):
            a, b = getattr(m1.skeleton, name), getattr(m2.skeleton, name)
            assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), (key, name)
        assert m1.metadata == m2.metadata and m1.canonical_map == m2.canonical_map
    assert shown1 == shown2
    glitches = [text for category, text in shown2 if category is MotionSanityWarning]
    files = [str(CMU / "asf-amc" / "13_18.amc"), str(CMU / "bvh" / "80_10.bvh")]
    assert [t.split(": ")[0] for t in glitches] == files, shown2


@pytest.mark.parametrize("start_method", ["fork", "spawn"], indirect=True)
def test_parallel_loading_keeps_errors_and_warning_filters(
    start_method: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A motion that fails to load, or whose warning the filters turn into an error, stops
    planning with the same error whether it was loaded in another process or not (a spawned
    process is given the filters: with Python's own, it showed the warning and went on)."""
    (tmp_path / "02.asf").write_bytes((CMU / "asf-amc" / "02.asf").read_bytes())
    amc = (CMU / "asf-amc" / "02_01.amc").read_text().split("\n")
    (tmp_path / "02_01.amc").write_text("\n".join(amc[:60]) + "\n")  # ends inside frame 3
    motion = f'{{ kind = "cmu", file = "{tmp_path / "02_01.amc"}" }}'
    broken = f'[[sources]]\nlabel = "walk"\nmotion = {motion}'
    cfg, base = load_dataset_config(_mixed_sources(tmp_path, broken))
    errors = []
    for workers in (1, 2):
        monkeypatch.setattr(dataset, "_MOTIONS", {})
        with pytest.raises(DataFileError, match="lacks bone") as err, warnings.catch_warnings():
            warnings.simplefilter("ignore")
            plan_records(cfg, base, workers=workers)
        errors.append(str(err.value))
    assert errors[0] == errors[1]
    cfg, base = load_dataset_config(_mixed_sources(tmp_path))
    errors = []
    for workers in (1, 2):
        monkeypatch.setattr(dataset, "_MOTIONS", {})
        with pytest.raises(MotionSanityWarning) as warn, warnings.catch_warnings():
            warnings.simplefilter("error", MotionSanityWarning)
            plan_records(cfg, base, workers=workers)
        errors.append(str(warn.value))
    glitch = f"{CMU / 'asf-amc' / '13_18.amc'}: 3 single-frame glitch"
    assert errors[0] == errors[1] and errors[0].startswith(glitch)


def test_corrupt_and_partial_records_are_redone(tmp_path: Path) -> None:
    cfg, base = load_dataset_config(write_config(tmp_path / "d.toml"))
    out = tmp_path / "ds"
    build_dataset(cfg, base, out, workers=1, progress=False)
    reference = tmp_path / "ref"
    build_dataset(cfg, base, reference, workers=1, progress=False)
    files = sorted((out / RECORDS).glob("*.npz"))
    files[0].write_bytes(files[0].read_bytes()[:200])  # truncated by a crash
    files[1].unlink()  # never written
    with np.load(files[2]) as npz:  # readable, but its metadata lacks a field (it crashed)
        arrays = {k: npz[k] for k in npz.files}
    meta = json.loads(str(arrays["meta"]))
    del meta["start_s"]
    arrays["meta"] = np.array(json.dumps(meta))
    with files[2].open("wb") as fh:
        np.savez(fh, **arrays)
    (out / RECORDS / ".tmp-abc.npz").write_bytes(b"half")  # temp file of a killed writer
    files[3].write_bytes(files[4].read_bytes())  # whole, but another record's (copied over)
    stamp = {p.name: p.stat().st_mtime_ns for p in files[4:]}
    build_dataset(cfg, base, out, workers=1, progress=False)
    assert_same(out, reference)
    assert not list((out / RECORDS).glob(".tmp-*"))
    assert {p.name: p.stat().st_mtime_ns for p in files[4:]} == stamp  # not redone


def test_a_record_without_permission_stops_the_resume_and_is_kept(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A record the user may not read is not someone else's corrupt file to delete: the
    resume stops naming it. (The read is made to fail as the OS would for a file of another
    user: the suite runs as root in CI, where a chmod does not deny reading.)"""
    cfg, base = load_dataset_config(write_config(tmp_path / "d.toml"))
    out = tmp_path / "ds"
    build_dataset(cfg, base, out, workers=1, progress=False)
    first = sorted((out / RECORDS).glob("*.npz"))[0]

    def denied(path: Path) -> Any:
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(dataset, "read_record", denied)
    with pytest.raises(MdfError) as err:
        build_dataset(cfg, base, out, workers=1, progress=False)
    assert str(err.value).startswith(f"{first}: Permission denied: a record of this dataset")
    assert first.exists()


def finished_records(out: Path) -> list[Path]:
    """Record files of a dataset folder (not the hidden temporary files of writes under way)."""
    return [p for p in (out / RECORDS).glob("*.npz") if not p.name.startswith(".")]


def test_kill_and_resume(tmp_path: Path) -> None:
    cfg_path = write_config(
        tmp_path / "d.toml", boxing_records=12, aspects="[0.0, 30.0, 60.0, 90.0]"
    )
    out = tmp_path / "ds"
    cmd = [
        sys.executable,
        "-m",
        "mdframework.cli",
        "dataset",
        "build",
        str(cfg_path),
        "--out",
        str(out),
        "--workers",
        "1",
        "--no-progress",
    ]
    proc = subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True
    )
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        done = finished_records(out) if (out / RECORDS).exists() else []
        if len(done) >= 6:
            break
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    partial = finished_records(out)  # a killed write leaves only a hidden .tmp-* file
    assert 6 <= len(partial) < 60, "the build finished before it could be killed"
    for p in partial:  # every record file present is complete
        read_record(p)
    assert not (out / "index.csv").exists()
    again = subprocess.run(cmd, capture_output=True, text=True, check=False)
    assert again.returncode == 0, again.stderr
    cfg, base = load_dataset_config(cfg_path)
    build_dataset(cfg, base, tmp_path / "fresh", workers=2, progress=False)
    assert_same(out, tmp_path / "fresh")


def test_bad_dataset_configs(tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text('[[sources]]\nlabel = "walk"\nmotion = { kind = "cmu" }\nbogus = 1\n')
    with pytest.raises(
        ConfigError, match=r"bad\.toml: sources\.0\.bogus: unknown field 'bogus' \(allowed: "
    ):
        load_dataset_config(bad)
    long = tmp_path / "long.toml"
    long.write_text(
        f'[[sources]]\nlabel = "run"\nrecord_length = 3.0\n'
        f'motion = {{ kind = "cmu", file = "{CMU / "asf-amc" / "09_06.amc"}" }}\n'
    )
    cfg, base = load_dataset_config(long)
    with (
        pytest.warns(DatasetWarning, match=r"sources\[0\] \(.*09_06\.amc\): the 1\.167 s "),
        pytest.raises(ConfigError, match=r"no records: every source is shorter .*09_06\.amc"),
    ):
        plan_records(cfg, base)


def test_base_scene_is_kept_unless_varied(tmp_path: Path) -> None:
    p = tmp_path / "d.toml"
    p.write_text(f"""
[[sources]]
label = "walk"
record_length = 1.0
motion = {{ kind = "cmu", file = "{CMU / "asf-amc" / "02_01.amc"}", start = 0.5, duration = 1.5 }}
[variations]
radar_range = [7.0]
[base.scene]
radar_position = [5.0, 3.0, 2.5]
person = {{ aspect_deg = 90.0, position = [1.0, 2.0] }}
""")
    cfg, base = load_dataset_config(p)
    specs = plan_records(cfg, base)
    # the source's own start/duration bound the span: 0.5..2.0 s gives one 1 s window
    assert [s.run_config["motion"]["start"] for s in specs] == [0.5]
    scene = specs[0].run_config["scene"]
    assert scene["person"]["aspect_deg"] == 90.0  # not replaced: no aspect variation
    assert scene["radar_position"] == [8.0, 2.0, 2.5]  # range varied from the start, height kept


def test_point_target_dataset(tmp_path: Path) -> None:
    p = tmp_path / "d.toml"
    p.write_text("""
[[sources]]
label = "receding"
record_length = 0.5
[sources.motion]
kind = "point_targets"
length = 1.0
targets = [{ position = [50.0, 0, 0], velocity = [1.0, 0, 0] }]
[base.scatterers]
kind = "points"
[base.scene]
radar_position = [0.0, 0.0, 0.0]
[base.processing]
window_length = 128
""")
    cfg, base = load_dataset_config(p)
    rows = build_dataset(cfg, base, tmp_path / "ds", workers=1, progress=False)
    assert len(rows) == 2
    for row in rows:
        assert row["torso_mean"] == pytest.approx(-1.0, abs=0.1)
    data = load_dataset(tmp_path / "ds")
    assert data.labels.dtype.kind == "U" and list(data.labels) == ["receding"] * 2


def test_radar_position_and_walker_height_variations(tmp_path: Path) -> None:
    p = tmp_path / "d.toml"
    p.write_text("""
[[sources]]
label = "walk"
record_length = 1.0
motion = { kind = "boulic", n_cycles = 1 }
[variations]
radar_position = [[10.0, 0.0, 2.0], [0.0, 10.0, 1.0]]
height = [1.6, 1.9]
""")
    cfg, base = load_dataset_config(p)
    specs = plan_records(cfg, base)
    combos = {
        (tuple(s.run_config["scene"]["radar_position"]), s.run_config["motion"]["height"])
        for s in specs
    }
    assert combos == {
        ((10.0, 0.0, 2.0), 1.6),
        ((10.0, 0.0, 2.0), 1.9),
        ((0.0, 10.0, 1.0), 1.6),
        ((0.0, 10.0, 1.0), 1.9),
    }
    rows = build_dataset(cfg, base, tmp_path / "ds", workers=1, progress=False)
    torso = {(r["radar_x_m"], r["height_m"]): r["torso_mean"] for r in rows}
    # a taller walker at the same relative velocity walks faster (v = rv * 0.491 H)
    assert torso[(10.0, 1.9)] > torso[(10.0, 1.6)]
    p.write_text(p.read_text() + "radar_range = [5.0]\n")
    with pytest.raises(ConfigError, match="radar_position, or radar_range"):
        load_dataset_config(p)


def test_cli_dataset_error_names_the_config_and_leaves_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from mdframework import cli

    p = tmp_path / "d.toml"
    p.write_text(
        f'[[sources]]\nlabel = "run"\nrecord_length = 3.0\n'
        f'motion = {{ kind = "cmu", file = "{CMU / "asf-amc" / "09_06.amc"}" }}\n'
    )
    out = tmp_path / "ds"
    assert cli.main(["dataset", "build", str(p), "--out", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[0].startswith("mdf: warning: sources[0] (") and "shorter than" in err[0]
    assert len(err) == 2 and err[1].startswith(f"mdf: error: {p}: no records: every source")
    assert not out.exists()


@pytest.mark.parametrize(
    ("where", "named"),
    [
        ("base", "base.radar.prf"),
        ("run", "sources[1].run.radar.prf"),
        ("motion", "sources[1].motion.scale"),
    ],
)
def test_a_record_error_names_the_field_where_the_dataset_config_wrote_it(
    tmp_path: Path, where: str, named: str
) -> None:
    """A bad PRF written under [base.radar] (or a source's `run`) and a bad motion field of
    the second source: the error names `base.radar.prf`, `sources[1].run.radar.prf` and
    `sources[1].motion.scale`, not the record's own `radar.prf` or an anonymous motion."""
    bvh = CMU / "bvh" / "16_21.bvh"
    source = {"label": "walk", "record_length": 1.0, "max_records": 1}
    motion = {"kind": "cmu", "file": str(bvh)}
    second = {**source, "motion": dict(motion)}
    base: dict = {"radar": {"kind": "lfm", "prf": 2000.0}}
    if where == "base":
        base["radar"]["prf"] = -5.0
    elif where == "run":
        second["run"] = {"radar": {"prf": 0.0}}
    else:
        second["motion"]["scale"] = 2.0
    cfg = {"sources": [{**source, "motion": motion}, second], "base": base}
    path = tmp_path / "d.json"
    path.write_text(json.dumps(cfg))
    with pytest.raises(ConfigError) as err:
        plan_records(*load_dataset_config(path))
    assert named + ": " in str(err.value)
    assert where == "motion" or str(err.value).startswith(f"sources[{0 if where == 'base' else 1}]")


def test_a_stopped_build_removes_the_records_it_was_writing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Workers stopped by Ctrl-C or by another record's error can leave a record half-written
    (a `.tmp-*.part` file): the build removes it as it stops, and only it."""
    cfg, base = load_dataset_config(write_config(tmp_path / "d.toml"))
    out = tmp_path / "ds"

    def stopped(config: object, workers: object, scheduler: object) -> Any:
        def run(specs: list[Any], out_dir: str) -> Any:
            records = Path(out_dir) / RECORDS
            (records / ".tmp-k3j_9x2a.part").write_bytes(b"half a record")
            (records / ".tmp-notes.txt").write_text("not a record")
            raise KeyboardInterrupt
            yield

        yield run

    monkeypatch.setattr(dataset, "_executor", stopped)
    with pytest.raises(KeyboardInterrupt):
        build_dataset(cfg, base, out, workers=2, progress=False)
    assert sorted(p.name for p in (out / RECORDS).iterdir()) == [".tmp-notes.txt"]


def test_a_warped_records_id_covers_where_its_source_ends(tmp_path: Path) -> None:
    """A time warp can move a record back from the end of its source's span, so two sources
    that differ only in `duration` make records with different ids (they had the same id, and
    a resumed or --force build kept the stale record)."""
    amc = CMU / "asf-amc" / "02_01.amc"
    ids = []
    for duration in (2.0, 2.5):  # the recording lasts 2.85 s
        cfg = {
            "seed": 2,
            "sources": [
                {
                    "label": "walk",
                    "motion": {"kind": "cmu", "file": str(amc), "duration": duration},
                    "record_length": 1.0,
                    "max_records": 2,
                }
            ],
            "randomize": {"time_warp": 0.9},
        }
        path = tmp_path / f"w{duration}.json"
        path.write_text(json.dumps(cfg))
        ids.append([s.record_id for s in plan_records(*load_dataset_config(path))])
    assert len(ids[0]) == len(ids[1]) == 2
    assert not set(ids[0]) & set(ids[1])


def test_a_motion_files_own_error_keeps_its_file_name(tmp_path: Path) -> None:
    """Only an error in the source's motion section is renamed `sources[N].motion...`; a
    reader's error names its file (it was glued to the prefix: `sources[0]./.../02_01.amc`)."""
    import shutil

    lone = tmp_path / "lone"
    lone.mkdir()
    shutil.copy(CMU / "asf-amc" / "02_01.amc", lone / "02_01.amc")  # without its skeleton
    cfg = {
        "sources": [{"label": "walk", "motion": {"kind": "cmu", "file": str(lone / "02_01.amc")}}]
    }
    path = tmp_path / "d.json"
    path.write_text(json.dumps(cfg))
    with pytest.raises(MdfError) as err:
        plan_records(*load_dataset_config(path))
    assert str(err.value).startswith(str(lone / "02_01.amc"))


def _build_walk(
    tmp_path: Path, name: str, radar: str, features: str = ""
) -> tuple[list[str], Dataset]:
    """Build a dataset of 1 s records of the CMU walk seen by ``radar`` (TOML lines) from 6 m,
    max_records per source 2; its band-edge warnings and the loaded dataset."""
    cfg_path = tmp_path / f"{name}.toml"
    cfg_path.write_text(f"""
seed = 1
{features}
[[sources]]
label = "walk"
motion = {{ kind = "cmu", file = "{CMU / "asf-amc" / "02_01.amc"}" }}
max_records = 2
[record_lengths]
walk = 1.0
[base.radar]
{radar}
[base.scene]
radar_position = [6.0, 0.0, 1.0]
""")
    cfg, base_dir = load_dataset_config(cfg_path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        build_dataset(cfg, base_dir, tmp_path / name, workers=1, progress=False)
    edge = [str(w.message) for w in caught if "edge of the Doppler band" in str(w.message)]
    return edge, load_dataset(tmp_path / name)


FMCW_RADAR = "kind = 'fmcw'\npreset = 'iwr1443_short_range_3d'\npoints = false"


def test_records_whose_envelope_reaches_the_band_edge_are_counted(tmp_path: Path) -> None:
    """The paper's radar (PRF 2400 Hz at 15 GHz: +-12 m/s) keeps a walk's envelope inside the
    band; the FMCW preset's 0 dBi antennas leave the spectrogram too little above the noise, so
    the envelope spans the band: index.csv counts such frames per record, and the build warns
    once naming how many records have any."""
    base = {
        "lfm": "kind = 'lfm'\ncarrier_frequency = 15e9\nbandwidth = 150e6\nprf = 2400.0",
        "fmcw": FMCW_RADAR,
    }
    for name, radar in base.items():
        edge, data = _build_walk(tmp_path, name, radar)
        counts = data.table["band_edge_frames"]
        if name == "lfm":
            assert not edge and np.all(counts == 0)
        else:
            assert len(edge) == 1 and edge[0].startswith("2 of 2 records")
            assert np.all(counts > 10)
            upper = data.features[:, FEATURE_NAMES.index("upper_max")]
            assert np.allclose(upper, data.velocity[-1])  # the band's edge, not the body's


def test_band_edge_frames_are_counted_for_percentile_envelopes(tmp_path: Path) -> None:
    """The percentile envelopes of a spectrogram that stands little above the noise (the FMCW
    preset's 0 dBi antennas) lie a few bins inside the band (3 % and 97 % of white noise), not
    on its edge, yet describe the band, not the body: the frames are counted by the threshold
    envelope of the features' threshold_db, as for the threshold method, and the build warns."""
    counts = {}
    for method in ("threshold", "percentile"):
        edge, data = _build_walk(tmp_path, method, FMCW_RADAR, f"features.method = '{method}'")
        counts[method] = data.table["band_edge_frames"]
        assert len(edge) == 1 and edge[0].startswith("2 of 2 records")
        if method == "percentile":  # the band's percentiles, inside its edge
            upper = data.features[:, FEATURE_NAMES.index("upper_max")]
            assert np.all((upper > data.velocity[-1] - 1.0) & (upper < data.velocity[-1]))
    assert np.array_equal(counts["percentile"], counts["threshold"])
    assert np.all(counts["threshold"] > 10)


def test_a_drawn_motion_file_names_its_own_subject_and_recording(tmp_path: Path) -> None:
    """A record whose motion file is drawn (randomize.params."motion.file") is that file's
    subject and recording, not its source's: a CMU subject 9 run drawn in a subject 2 source
    was labelled subject 2, so leaving subjects out could train and test on subject 9."""
    amc = CMU / "asf-amc"
    cfg_path = tmp_path / "d.toml"
    cfg_path.write_text(f"""
seed = 1
[[sources]]
label = "walk"
motion = {{ kind = "cmu", file = "{amc / "02_01.amc"}" }}
record_length = 1.0
[randomize]
draws = 3
[randomize.params]
"motion.file" = {{ choice = ["{amc / "02_01.amc"}", "{amc / "09_06.amc"}"] }}
""")
    cfg, base = load_dataset_config(cfg_path)
    specs = plan_records(cfg, base)
    named = {(Path(s.run_config["motion"]["file"]).name, s.subject, s.recording) for s in specs}
    assert named == {("02_01.amc", "2", "02_01.amc"), ("09_06.amc", "9", "09_06.amc")}


def test_dataset_json_and_run_metadata_name_the_software_versions(tmp_path: Path) -> None:
    """dataset.json and a run's metadata.json name the versions of mdframework, its numerical
    libraries and every plugin distribution (none was written anywhere: a dataset could not
    say what made it)."""
    from mdframework import cli

    config = point_dataset(tmp_path / "d.toml")
    build_dataset(*load_dataset_config(config), tmp_path / "ds", workers=1, progress=False)
    assert cli.main(["run", str(EXAMPLES / "point_target.toml"), "--out", str(tmp_path / "r")]) == 0
    for written in (tmp_path / "ds" / "dataset.json", tmp_path / "r" / "metadata.json"):
        versions = json.loads(written.read_text())["versions"]
        assert versions["mdframework"] == importlib.metadata.version("mdframework"), written
        assert versions["numpy"] == np.__version__, written
        for dist in ("mdf-point-targets", "mdf-lfm"):
            assert f"{dist} {importlib.metadata.version(dist)}" in versions["plugins"], written


def five_records(tmp_path: Path) -> tuple[Any, Path, Path]:
    """A dataset of five records of 0.5 s from a 2.5 s motion, built into ``tmp_path / "ds"``:
    its config, base folder and folder."""
    config = point_dataset(tmp_path / "d.toml")
    text = config.read_text().replace("length = 0.5", "length = 2.5")
    config.write_text(text + "[record_lengths]\nrecede = 0.5\n")
    cfg, base = load_dataset_config(config)
    out = tmp_path / "ds"
    build_dataset(cfg, base, out, workers=1, progress=False)
    assert len(list((out / RECORDS).glob("*.npz"))) == 5
    return cfg, base, out


def test_a_folder_of_records_of_other_ids_is_said_to_be_computed_afresh(tmp_path: Path) -> None:
    """A folder built by an earlier version whose records had other ids (0.2.0: seeds from the
    records' numbers, and the seed is in the id) and resumed with the same config: every
    record is computed afresh and the old files removed at the end, which the build did
    without a word (a dataset of days of compute looked resumed). It warns once, saying how
    many of the build's records are there; a folder of the build's own records says nothing."""
    cfg, base, out = five_records(tmp_path)
    files = sorted((out / RECORDS).glob("*.npz"))
    old = [f.with_name(f"{f.name[:6]}0123456789.npz") for f in files[1:]]  # other digests
    for file, renamed in zip(files[1:], old, strict=True):
        file.rename(renamed)
    (out / RECORDS / "notes.npz").write_bytes(b"the user's, not a record")  # neither counted
    with pytest.warns(dataset.DatasetWarning) as caught:
        build_dataset(cfg, base, out, workers=1, progress=False)
    said = [str(w.message) for w in caught if "not records of this config" in str(w.message)]
    assert said == [
        f"4 records in {out / RECORDS} (e.g. {old[0].stem}) are not records of this config as "
        "this version computes it (an earlier version of mdframework gave records other ids "
        "and seeds, or their motion files changed since): 1 of the build's 5 records are "
        "there, the others are computed afresh, and those of other ids are removed when the "
        "build ends"
    ]
    notes = out / RECORDS / "notes.npz"
    assert sorted((out / RECORDS).glob("*.npz")) == sorted([*files, notes])  # notes stay
    with warnings.catch_warnings():
        warnings.simplefilter("error", dataset.DatasetWarning)
        build_dataset(cfg, base, out, workers=1, progress=False)
        # a folder of another config's records, rebuilt with --force: of course other ids
        other = cfg.model_copy(update={"seed": cfg.seed + 1})
        build_dataset(other, base, out, workers=1, progress=False, force=True)
    assert not set((out / RECORDS).glob("*.npz")) & set(files)


def test_a_stopped_rebuild_with_another_config_resumes_without_the_other_ids_warning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A --force rebuild with another config, stopped before any record, leaves the complete
    dataset of the first config in place (its index and records): resumed, the folder's other
    records are that dataset's, not an earlier version's, and nothing is said of them."""
    cfg, base, out = five_records(tmp_path)
    other = cfg.model_copy(update={"seed": cfg.seed + 1})

    def stopped(config: object, workers: object, scheduler: object) -> Any:
        def run(specs: list[Any], out_dir: str) -> Any:
            raise KeyboardInterrupt
            yield

        yield run

    with monkeypatch.context() as patched:
        patched.setattr(dataset, "_executor", stopped)
        with pytest.raises(KeyboardInterrupt):
            build_dataset(other, base, out, workers=1, progress=False, force=True)
    assert len(list((out / RECORDS).glob("*.npz"))) == 5  # the first config's, indexed
    with warnings.catch_warnings():
        warnings.simplefilter("error", dataset.DatasetWarning)
        build_dataset(other, base, out, workers=1, progress=False)
    assert len(list((out / RECORDS).glob("*.npz"))) == 5  # now the other config's


def test_a_record_kept_from_other_software_versions_is_said(tmp_path: Path) -> None:
    """Each record names the versions that computed it; a build that keeps records computed
    by other versions (their id covers the config, not the software), or by a version before
    records named theirs, warns, naming how many and what differs, so that a dataset mixing
    versions is never silent."""
    from mdframework.plugins import versions

    cfg, base, out = five_records(tmp_path)
    files = sorted((out / RECORDS).glob("*.npz"))
    arrays, meta = read_record(files[1])
    ran = ("mdf-lfm", "mdf-point-targets")  # only the plugins the record ran
    assert meta["versions"] == {
        **versions(),
        "plugins": [f"{d} {importlib.metadata.version(d)}" for d in ran],
    }
    meta["versions"] = {**meta["versions"], "mdframework": "0.0.1"}
    np.savez(files[1], **arrays, meta=np.array(json.dumps(meta)))
    kept = files[1].read_bytes()
    with pytest.warns(dataset.DatasetWarning) as caught:
        build_dataset(cfg, base, out, workers=1, progress=False)
    said = [str(w.message) for w in caught if "versions" in str(w.message)]
    assert len(said) == 1, said
    assert said[0].startswith(f"1 of 5 records (e.g. {files[1].stem}) were computed by ")
    assert f'mdframework: "0.0.1" -> "{versions()["mdframework"]}"' in said[0]
    assert files[1].read_bytes() == kept  # kept, not computed again
    # records as a version before records named theirs wrote them (no versions) are said too
    # (they were kept without a word: yesterday's records mixed with today's)
    for file in files[2:4]:
        arrays, meta = read_record(file)
        del meta["versions"]
        np.savez(file, **arrays, meta=np.array(json.dumps(meta)))
    with pytest.warns(dataset.DatasetWarning) as caught:
        build_dataset(cfg, base, out, workers=1, progress=False)
    said = [str(w.message) for w in caught if "versions" in str(w.message)]
    assert len(said) == 1, said
    assert said[0].startswith(f"3 of 5 records (e.g. {files[1].stem}) were computed by ")
    assert "(2 by a version from before records named their versions; mdframework: " in said[0]
    assert files[1].read_bytes() == kept
