"""Dataset builds on a Dask cluster of one's own (``--scheduler HOST:PORT``): Dask's
``LocalCluster`` with worker processes stands in for it, started before the test changes its
working folder, so that its workers work in another folder than the build, as on a real
cluster."""

from __future__ import annotations

import os
import re
import threading
import warnings
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
from conftest import EXAMPLES
from test_dataset import assert_same

from mdframework import cli, dataset
from mdframework.cluster import SCHEDULER_TIMEOUT_ENV, Workerless, check_paths, check_workers
from mdframework.dataset import RECORDS, build_dataset, load_dataset_config
from mdframework.errors import SettingError

pytest.importorskip("distributed")

CONFIG = """
seed = 7
[[sources]]
label = "walk"
motion = {{ kind = "cmu", file = "{walk}" }}
max_records = {walks}
[[sources]]
label = "boxing"
motion = {{ kind = "cmu", file = "{boxing}" }}
max_records = 2
[record_lengths]
walk = 1.0
boxing = 1.0
[variations]
aspect_deg = {aspects}
[base.processing]
nfft = 256
"""


def write_relative_config(folder: Path, *, walks: int = 2, aspects: str = "[0.0, 45.0]") -> Path:
    """A dataset config in ``folder`` naming its motion files relative to itself."""
    folder.mkdir(parents=True, exist_ok=True)
    cmu = Path(os.path.relpath(EXAMPLES / "data" / "cmu", folder))
    path = folder / "d.toml"
    path.write_text(
        CONFIG.format(
            walk=cmu / "asf-amc" / "02_01.amc",
            boxing=cmu / "bvh" / "80_10.bvh",
            walks=walks,
            aspects=aspects,
        )
    )
    return path


@pytest.fixture
def cluster(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[Any]:
    """A Dask cluster of worker processes whose working folder is ``tmp_path / "workers"``
    (``request.param``: LocalCluster's arguments, default one worker of one thread)."""
    from distributed import LocalCluster

    where = tmp_path / "workers"
    where.mkdir()
    kwargs = {"n_workers": 1, **getattr(request, "param", {})}
    before = Path.cwd()
    # Dask's nannies set MALLOC_TRIM_THRESHOLD_ in this process's environment for the workers
    # they spawn (a user's cluster does; a build's local cluster does not) and leave it there:
    # a later test's workers or subprocesses would run with it
    trim = "MALLOC_TRIM_THRESHOLD_"
    trim_before = os.environ.get(trim)
    os.chdir(where)
    try:
        cluster = LocalCluster(
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},  # not 8787: a user's
            **kwargs,
        )
    finally:
        os.chdir(before)
    try:
        with cluster:
            yield cluster
    finally:
        if trim_before is None:
            os.environ.pop(trim, None)
        else:
            os.environ[trim] = trim_before


def test_relative_paths_resolve_on_workers_of_another_folder(
    cluster: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A config given by a relative path, naming its motion files relative to itself, and a
    relative --out: the workers, working in another folder, read the motions and write the
    records where the build does (they looked for the files, and wrote the records, relative
    to their own folder: 'file not found', then 'No such file or directory'), and the
    dataset is the local build's to the bit."""
    write_relative_config(tmp_path / "cfg")
    monkeypatch.chdir(tmp_path / "cfg")
    config, base = load_dataset_config("d.toml")
    assert not base.is_absolute()
    build_dataset(config, base, Path("local"), workers=1, progress=False)
    checked: list[list[str]] = []
    check = dataset.check_paths

    def and_note_them(client: Any, paths: list[str]) -> None:
        checked.append(paths)
        check(client, paths)

    monkeypatch.setattr(dataset, "check_paths", and_note_them)
    args = ["dataset", "build", "d.toml", "--out", "out", "--no-progress"]
    assert cli.main([*args, "--scheduler", cluster.scheduler_address]) == 0
    assert_same(tmp_path / "cfg" / "local", tmp_path / "cfg" / "out")
    assert not (tmp_path / "workers" / "out").exists()
    # the workers were asked, before any record, whether they see the records folder and the
    # motion files, by the absolute paths they use
    cmu = EXAMPLES.resolve() / "data" / "cmu"
    records = str(tmp_path / "cfg" / "out" / RECORDS)
    motions = [cmu / "asf-amc" / "02_01.amc", cmu / "bvh" / "80_10.bvh"]
    assert [[p[0], *sorted(str(Path(f).resolve()) for f in p[1:])] for p in checked] == [
        [records, *map(str, motions)]
    ]


@pytest.mark.parametrize("cluster", [{"n_workers": 0}], indirect=True)
def test_a_scheduler_without_workers_is_one_line_after_the_timeout(
    cluster: Any,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A build on a scheduler that has no workers waited forever, printing nothing."""
    monkeypatch.setenv(SCHEDULER_TIMEOUT_ENV, "1")
    config = write_relative_config(tmp_path / "cfg")
    address = cluster.scheduler_address
    args = ["dataset", "build", str(config), "--out", str(tmp_path / "out"), "--no-progress"]
    done: list[int] = []
    build = threading.Thread(target=lambda: done.append(cli.main([*args, "--scheduler", address])))
    build.start()
    build.join(60)
    assert done == [2], "the build waited for workers"
    err = capsys.readouterr().err.splitlines()
    assert err[-1] == (
        f"mdf: error: the Dask scheduler {address!r} has no workers (waited 1 s for one); "
        f"start them (`dask worker {address}`), or set MDF_DASK_TIMEOUT"
    )
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "cluster", [{"env": {"MDFRAMEWORK_DISABLE_PLUGINS": "mdf-cmu"}}], indirect=True
)
def test_a_worker_without_a_plugin_is_named_not_the_config(
    cluster: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A worker lacking a plugin the build has (here disabled there) is refused before any
    record, naming the worker and the plugin; every record of the plugin failed, blamed on
    the config (`d.toml: record 00000-...: motion.kind: no motion plugin named 'cmu'`), which
    `mdf dataset check` calls valid."""
    config = write_relative_config(tmp_path / "cfg")
    out = tmp_path / "out"
    args = ["dataset", "build", str(config), "--out", str(out), "--no-progress"]
    assert cli.main([*args, "--scheduler", cluster.scheduler_address]) == 2
    err = capsys.readouterr().err.splitlines()[-1]
    (worker,) = cluster.scheduler.workers
    assert err.startswith(f"mdf: error: Dask worker {worker} has no mdf-cmu "), err
    assert err.endswith(
        "every worker needs the build's mdframework and plugins, of the same versions"
    )
    assert not out.exists()


def test_workers_gone_mid_build_end_it_with_one_line(
    cluster: Any,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Every worker gone mid-build (killed, or the cluster scaled down): Dask waits for new
    ones, and the build waited forever. After the timeout without a worker it stops with one
    line; the records finished stay, and no file being written is left."""
    monkeypatch.setenv(SCHEDULER_TIMEOUT_ENV, "1")
    config = write_relative_config(tmp_path / "cfg", walks=20, aspects="[0.0, 10.0, 20.0, 30.0]")
    out = tmp_path / "out"

    def scale_down_after_a_record() -> None:
        while not list((out / RECORDS).glob("*.npz")) and build.is_alive():
            threading.Event().wait(0.02)
        cluster.scale(0)

    args = ["dataset", "build", str(config), "--out", str(out), "--no-progress"]
    done: list[int] = []
    address = cluster.scheduler_address
    build = threading.Thread(target=lambda: done.append(cli.main([*args, "--scheduler", address])))
    build.start()
    scale_down_after_a_record()
    build.join(60)
    assert done == [2], "the build waited for workers"
    err = capsys.readouterr().err.splitlines()[-1]
    assert err.startswith(f"mdf: error: the Dask scheduler {address!r} has had no workers for 1 s")
    left = sorted(p.name for p in (out / RECORDS).iterdir())
    assert left and all(dataset._RECORD_NAME.fullmatch(name) for name in left), left
    assert not (out / "index.csv").exists()


def test_a_file_left_by_a_killed_worker_is_removed_when_the_build_ends(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A Dask worker killed while it writes a record leaves its temporary file; Dask runs the
    task again elsewhere and the build ends well: the file was left in records/ of the
    finished dataset. Here the build's own records land while such a file appears."""
    config, base = load_dataset_config(write_relative_config(tmp_path / "cfg"))
    out = tmp_path / "out"
    real = dataset.build_records

    def and_a_killed_workers_file(specs: list[Any], out_dir: str) -> list[dict[str, Any]]:
        (Path(out_dir) / RECORDS / ".tmp-k1ll3d_0.part").write_bytes(b"PK\x03\x04")
        return real(specs, out_dir)

    monkeypatch.setattr(dataset, "build_records", and_a_killed_workers_file)
    build_dataset(config, base, out, workers=1, progress=False)
    assert sorted(p.name for p in (out / RECORDS).iterdir() if not p.name.endswith(".npz")) == []
    assert len(list((out / RECORDS).iterdir())) == 8


def test_a_scheduler_lost_mid_build_is_one_line(
    cluster: Any,
    tmp_path: Path,
    capfd: pytest.CaptureFixture[str],
    caplog: pytest.LogCaptureFixture,
) -> None:
    """The scheduler gone mid-build (killed, its machine down): Dask cancels every task, and
    the build ended as an internal error (`FutureCancelledError: ... scheduler-connection-lost`)
    after Dask's client logged a traceback. Now one line naming the scheduler and saying how
    to resume; the records finished stay."""
    config = write_relative_config(tmp_path / "cfg", walks=20, aspects="[0.0, 10.0, 20.0, 30.0]")
    out = tmp_path / "out"
    address = cluster.scheduler_address

    def stop_the_scheduler_after_a_record() -> None:
        while not list((out / RECORDS).glob("*.npz")) and build.is_alive():
            threading.Event().wait(0.02)
        cluster.close()  # its workers, then its scheduler

    args = ["dataset", "build", str(config), "--out", str(out), "--no-progress"]
    done: list[int] = []
    build = threading.Thread(target=lambda: done.append(cli.main([*args, "--scheduler", address])))
    build.start()
    stop_the_scheduler_after_a_record()
    build.join(60)
    assert done == [2]
    err = capfd.readouterr().err
    assert "Traceback" not in err
    assert err.splitlines()[-1].startswith(f"mdf: error: lost the Dask scheduler {address!r} ")
    assert err.splitlines()[-1].endswith("the same command, run again, resumes from them")
    assert list((out / RECORDS).glob("*.npz"))
    # nor logged (Dask's client logs the lost connection with its traceback, at its own level)
    assert [r.getMessage() for r in caplog.records if r.name.startswith("distributed")] == []


def test_a_worker_that_does_not_see_the_data_or_out_is_named(cluster: Any, tmp_path: Path) -> None:
    """A worker on a machine without the build's file system (its data files, --out) is
    named before any record, with the first path it does not see (such a worker failed every
    record, as the config's error 'motion.file: file not found', or, writing, as an internal
    error). Here a path no worker sees stands for one; checked for real with a worker in a
    mount namespace where the config's folder was an empty tmpfs."""
    from distributed import Client

    config, base = load_dataset_config(write_relative_config(tmp_path / "cfg"))
    files = dataset._data_files(dataset.plan_records(config, base))
    assert sorted(Path(f).name for f in files) == ["02_01.amc", "80_10.bvh"]
    assert all(Path(f).is_absolute() and Path(f).is_file() for f in files)
    gone = str(tmp_path / "elsewhere" / "records")
    with Client(cluster) as client:
        check_paths(client, files)  # every worker sees them
        with pytest.raises(SettingError) as err:
            check_paths(client, [*files, gone, gone + "2"])
    (worker,) = cluster.scheduler.workers
    assert str(err.value) == (
        f"Dask worker {worker} does not see {gone} (and 1 more): the workers read the data "
        "files and write the records by the paths of this machine, so the data and --out must "
        "be on a file system they share, at the same paths"
    )


def test_a_worker_without_mdframework_is_named_one_that_left_is_not() -> None:
    """A worker without mdframework cannot unpickle the version check: Dask returns
    ``Exception('ModuleNotFoundError(...)')`` for it (seen with a worker whose Python had no
    mdframework; its build went on without the worker, which Dask removed). One that died
    meanwhile (a comm error) is left to Dask."""
    from distributed.comm.core import CommClosedError

    from mdframework.plugins import versions

    class Client:
        def __init__(self, answers: dict[str, Any]) -> None:
            self.answers = answers

        def wait_for_workers(self, n: int, timeout: float) -> None:
            pass

        def run(self, function: Any, on_error: str) -> dict[str, Any]:
            assert on_error == "return"
            return self.answers

    ours = versions()
    left = CommClosedError("in <TCP (closed)>: Stream is closed")
    check_workers(Client({"tcp://a:1": ours, "tcp://b:2": left}), "tcp://s:8786")
    lacking = Exception("ModuleNotFoundError(\"No module named 'mdframework'\")")
    with pytest.raises(SettingError) as err:
        check_workers(Client({"tcp://a:1": ours, "tcp://b:2": lacking}), "tcp://s:8786")
    assert str(err.value) == (
        'Dask worker tcp://b:2 cannot run mdframework (ModuleNotFoundError("No module named '
        "'mdframework'\")); every worker needs the build's mdframework and plugins installed"
    )
    older = {**ours, "mdframework": "0.2.0"}
    with pytest.raises(SettingError, match=r"^Dask worker tcp://a:1 has mdframework '0.2.0', "):
        check_workers(Client({"tcp://a:1": older}), "tcp://s:8786")


def test_workers_of_other_numeric_versions_are_a_dataset_warning() -> None:
    """Workers of another NumPy (or Python, SciPy, scikit-learn) than the build's compute
    records that may differ in the last bits: the build goes on, with one warning naming the
    versions, of the category the build gives (DatasetWarning); workers of the same versions
    say nothing."""
    from mdframework.plugins import versions

    ours = versions()

    class Client:
        def __init__(self, theirs: dict[str, Any]) -> None:
            self.theirs = theirs

        def wait_for_workers(self, n: int, timeout: float) -> None:
            pass

        def run(self, function: Any, on_error: str) -> dict[str, Any]:
            return {"tcp://a:1": ours, "tcp://b:2": self.theirs}

    with pytest.warns(dataset.DatasetWarning) as caught:
        check_workers(Client({**ours, "numpy": "1.0.0"}), "tcp://s:8786", dataset.DatasetWarning)
    assert [str(w.message) for w in caught] == [
        "Dask workers run numpy '1.0.0', not this process's versions: their records may "
        "differ in the last bits from a local build's"
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_workers(Client(ours), "tcp://s:8786", dataset.DatasetWarning)


def test_the_build_is_stopped_after_the_timeout_without_a_worker_not_before(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The watch of a build on a cluster of one's own cancels the build's tasks once the
    scheduler has had no worker for MDF_DASK_TIMEOUT: a worker seen meanwhile starts the wait
    afresh (workers restarting one by one are not a cluster without workers), and a scheduler
    lost is left to Dask. Driven poll by poll, each a second of a clock of its own."""
    from mdframework import cluster as dask_cluster

    monkeypatch.setenv(SCHEDULER_TIMEOUT_ENV, "1.5")
    clock = [0.0]
    monkeypatch.setattr(dask_cluster, "time", SimpleNamespace(monotonic=lambda: clock[0]))

    class Client:
        def __init__(self, answers: list[Any]) -> None:
            self.answers, self.polls = answers, 0
            self.cancelled: tuple[int, list[str]] | None = None

        def nthreads(self) -> dict[str, int]:
            self.polls += 1
            clock[0] += 1.0
            answer = self.answers.pop(0) if self.answers else {}
            if isinstance(answer, Exception):
                raise answer
            return dict(answer)

        def cancel(self, futures: list[str]) -> None:
            self.cancelled = (self.polls, futures)

    class AtOnce:  # the watch's wait of a second between polls, without waiting
        def wait(self, timeout: float) -> bool:
            return False

    one = {"tcp://w:1": 1}
    client = Client([{}, one, {}, one])  # alone from poll 5: 1 s at poll 6, 2 s at poll 7
    watch = Workerless(client, ["f1", "f2"], "tcp://s:8786")
    watch._done = AtOnce()  # type: ignore[assignment]
    watch.run()
    assert client.cancelled == (7, ["f1", "f2"])
    assert str(watch.error).startswith(
        "the Dask scheduler 'tcp://s:8786' has had no workers for 1.5 s (they were killed, or "
        "left); the records finished stay, and the same command, run again when it has "
        "workers, resumes from them"
    )
    client = Client([one, {}, OSError("scheduler lost")])
    watch = Workerless(client, ["f1"], "tcp://s:8786")
    watch._done = AtOnce()  # type: ignore[assignment]
    watch.run()
    assert (client.polls, client.cancelled, watch.error) == (3, None, None)


def test_a_task_whose_workers_all_died_is_one_line_naming_its_first_record(
    cluster: Any,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capfd: pytest.CaptureFixture[str],
) -> None:
    """Every worker that ran a task died (killed, out of memory; here the task ends its
    worker's process): Dask gives up on the task (KilledWorker), and the build ended as an
    internal error. Now one line naming the task's first record and how to resume."""
    cluster.scheduler.allowed_failures = 0  # Dask's three retries would take a restart each
    config_file = write_relative_config(tmp_path / "cfg")
    config, base = load_dataset_config(config_file)
    specs = dataset.plan_records(config, base)
    firsts = {chunk[0].record_id for chunk in dataset.record_chunks(specs, 1)}
    assert len(firsts) < len(specs)
    monkeypatch.setattr(dataset, "build_records", lambda specs, out_dir: os._exit(1))
    out = tmp_path / "out"
    args = ["dataset", "build", str(config_file), "--out", str(out), "--no-progress"]
    assert cli.main([*args, "--scheduler", cluster.scheduler_address]) == 2
    err = capfd.readouterr().err
    assert "Traceback" not in err
    said = re.fullmatch(
        r"mdf: error: Dask workers died while building record (\S+) and the records after it "
        r"in its task, on every worker Dask tried \(killed, or out of memory: see the workers' "
        r"logs\); the records finished stay in (.+), and the same command, run again, resumes "
        r"from them",
        err.splitlines()[-1],
    )
    assert said and said[1] in firsts and said[2] == str(out), err


def test_the_files_the_workers_must_see_are_recordings_and_motions_by_absolute_path(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The files a cluster's workers are checked for: a real radar's recordings too, and a
    motion file given from the home folder (`~/...`) by its path there, not under the config's
    folder (a worker would be named for not seeing a path that does not exist)."""
    radhar = EXAMPLES / "datasets" / "radhar.toml"
    config, base = load_dataset_config(radhar)
    files = dataset._data_files(dataset.plan_records(config, base))
    assert sorted(files) == [
        os.path.abspath(EXAMPLES / "data" / "radhar" / f"radhar_{a}_subset.npz")
        for a in ("boxing", "jump", "walk")
    ]
    home = tmp_path / "home"
    home.mkdir()
    for name in ("02.asf", "02_01.amc"):
        (home / name).write_bytes((EXAMPLES / "data" / "cmu" / "asf-amc" / name).read_bytes())
    monkeypatch.setenv("HOME", str(home))
    (tmp_path / "d.toml").write_text(
        '[[sources]]\nlabel = "walk"\nmotion = { kind = "cmu", file = "~/02_01.amc" }\n'
        "max_records = 1\n[record_lengths]\nwalk = 1.0\n"
    )
    config, base = load_dataset_config(tmp_path / "d.toml")
    assert dataset._data_files(dataset.plan_records(config, base)) == [str(home / "02_01.amc")]
