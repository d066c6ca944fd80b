"""The command line in the environments a cluster job gives it: stderr closed or on a full disk,
a C locale with non-ASCII labels; and the help and docs naming exactly what a command writes."""

from __future__ import annotations

import ast
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import EXAMPLES, without_third_party_warnings

from mdframework import cli
from mdframework.experiment import load_experiment_config
from mdframework.output import OUTPUTS

ROOT = Path(__file__).resolve().parents[1]
WARNS = """
[motion]
kind = "point_targets"
length = 1.0
targets = [{ position = [100.0, 0.0, 0.0], velocity = [1.0, 0.0, 0.0], rcs = 1.0 }]
[scatterers]
kind = "points"
[scene]
radar_position = [0.0, 0.0, 0.0]
gate = 30.0
[processing]
empty = "warn"
"""


def shell(command: str, **env: str) -> subprocess.CompletedProcess[str]:
    """``command`` in bash, with ``$MDF`` the command line of this interpreter's mdf."""
    return subprocess.run(
        ["bash", "-c", command],
        env={**os.environ, "MDF": f"{sys.executable} -m mdframework.cli", **env},
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.mark.parametrize("redirect", ["2>&-", "2>/dev/full"])
def test_a_closed_or_full_stderr_never_fails_a_command(tmp_path: Path, redirect: str) -> None:
    """A run that warns (its target outside a fixed range gate), with every progress line
    shown (``MDF_PROGRESS=1``), writes its output and exits 0 whatever stderr is: closed
    (``2>&-``: ``sys.stderr`` is None) or a full disk (``2>/dev/full``: every write fails)."""
    cfg = tmp_path / "warns.toml"
    cfg.write_text(WARNS, encoding="utf-8")
    out = tmp_path / "o"
    done = shell(f'$MDF run "{cfg}" --out "{out}" {redirect}', MDF_PROGRESS="1")
    assert done.returncode == 0, done.stdout
    assert (out / "result.npz").exists()
    assert done.stdout.strip().splitlines() == [str(out / n) for n in sorted(visible(out))]
    # an error still exits 2 (its line is lost with stderr)
    bad = shell(f'$MDF run "{tmp_path / "missing.toml"}" --out "{tmp_path / "x"}" {redirect}')
    assert bad.returncode == 2, bad.stdout


def visible(out: Path) -> list[str]:
    return [p.name for p in out.iterdir() if not p.name.startswith(".")]


def test_a_c_locale_builds_and_loads_a_non_ascii_label(tmp_path: Path) -> None:
    """Under ``LC_ALL=C`` (ASCII) without Python's UTF-8 mode, a dataset labelled ``gehen-ü``
    builds and loads with its label intact: every file is written and read as UTF-8."""
    amc = EXAMPLES / "data" / "cmu" / "asf-amc" / "02_01.amc"
    cfg = tmp_path / "d.toml"
    cfg.write_text(
        f'[[sources]]\nlabel = "gehen-ü"\nmotion = {{ kind = "cmu", file = "{amc}" }}\n'
        'max_records = 1\n[record_lengths]\n"gehen-ü" = 1.0\n[base.processing]\nnfft = 256\n',
        encoding="utf-8",
    )
    out = tmp_path / "ds"
    c_locale = {"LC_ALL": "C", "PYTHONUTF8": "0", "PYTHONCOERCECLOCALE": "0"}
    built = shell(f'$MDF dataset build "{cfg}" --out "{out}" --no-progress --workers 1', **c_locale)
    assert built.returncode == 0, built.stderr
    loaded = shell(
        f"{sys.executable} -c 'from mdframework.dataset import load_dataset; "
        f'd = load_dataset("{out}"); print(ascii([str(x) for x in d.labels]))\'',
        **c_locale,
    )
    assert loaded.returncode == 0, loaded.stderr
    assert loaded.stdout.strip() == ascii(["gehen-ü"])


def test_a_c_locale_refuses_a_config_file_name_it_cannot_hold_in_one_line(tmp_path: Path) -> None:
    """Under the same ASCII locale, an experiment whose dataset config has a non-ASCII name (the
    experiment config is UTF-8; the system's file names are ASCII) is one line naming it and
    the remedy, exit 2 (it was an internal error, UnicodeEncodeError)."""
    (tmp_path / "e.toml").write_text(
        '[dataset]\nconfig = "dü.toml"\n[classifier]\nkind = "knn"\nk = 1\n', encoding="utf-8"
    )
    c_locale = {"LC_ALL": "C", "PYTHONUTF8": "0", "PYTHONCOERCECLOCALE": "0"}
    done = shell(f'$MDF experiment "{tmp_path / "e.toml"}" --out "{tmp_path / "o"}"', **c_locale)
    lines = without_third_party_warnings(done.stderr.strip().splitlines())
    assert done.returncode == 2, done.stderr
    assert len(lines) == 1 and lines[0].startswith("mdf: error: "), lines
    assert "file names cannot hold (ascii); set a UTF-8 locale" in lines[0], lines
    # a motion file so named: it said "file not found"
    (tmp_path / "r.toml").write_text(
        (EXAMPLES / "cmu_walk.toml").read_text().replace("data/cmu/asf-amc", "dätä"),
        encoding="utf-8",
    )
    done = shell(f'$MDF run "{tmp_path / "r.toml"}" --out "{tmp_path / "o"}"', **c_locale)
    lines = without_third_party_warnings(done.stderr.strip().splitlines())
    assert done.returncode == 2, done.stderr
    assert len(lines) == 1 and lines[0].startswith("mdf: error: "), lines
    assert "motion.file: " in lines[0] and "cannot hold (ascii)" in lines[0], lines


#: receivers whose ``open`` opens no text file (zip and gzip members, file descriptors)
BINARY_OPENERS = {"os", "archive", "z", "gzip"}


def unspecified_encodings(root: Path) -> list[str]:
    """Calls that open, read or write a text file without ``encoding=`` (which would take the
    locale's), as ``path:line``: ``open(...)`` and ``X.open(...)`` not in a binary mode,
    ``X.read_text(...)`` and ``X.write_text(...)``."""
    found = []
    for path in sorted(root.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.Call) or any(k.arg == "encoding" for k in node.keywords):
                continue
            func = node.func
            if isinstance(func, ast.Attribute) and func.attr in ("read_text", "write_text"):
                found.append(f"{path.relative_to(ROOT)}:{node.lineno}")
                continue
            opens = (isinstance(func, ast.Name) and func.id == "open") or (
                isinstance(func, ast.Attribute)
                and func.attr == "open"
                and not (isinstance(func.value, ast.Name) and func.value.id in BINARY_OPENERS)
            )
            modes = [*node.args, *(k.value for k in node.keywords if k.arg == "mode")]
            binary = any(
                isinstance(a, ast.Constant) and isinstance(a.value, str) and "b" in a.value
                for a in modes
            )
            if opens and not binary:
                found.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    return found


def test_every_text_file_is_opened_as_utf8() -> None:
    """What one locale writes another reads: no text file of the package or its plugins is
    opened with the locale's encoding. (The checker finds the calls it should: a file with one
    of each.)"""
    assert unspecified_encodings(ROOT / "src") == []
    assert unspecified_encodings(ROOT / "plugins") == []


def test_the_encoding_checker_finds_each_kind_of_call(tmp_path: Path) -> None:
    global ROOT
    sample = tmp_path / "pkg" / "m.py"
    sample.parent.mkdir()
    sample.write_text(
        "open('a')\nopen('a', 'rb')\np.read_text()\np.write_text('x', encoding='utf-8')\n"
        "p.open('w')\nz.open(info)\nos.open('a', 0)\nq.write_text('x')\n",
        encoding="utf-8",
    )
    saved, ROOT = ROOT, tmp_path
    try:
        assert unspecified_encodings(tmp_path / "pkg") == [
            "pkg/m.py:1",
            "pkg/m.py:3",
            "pkg/m.py:5",
            "pkg/m.py:8",
        ]
    finally:
        ROOT = saved


def help_text(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    with pytest.raises(SystemExit):
        cli.main([*args, "--help"])
    return " ".join(capsys.readouterr().out.split())


def test_run_help_names_every_file_a_run_writes(capsys: pytest.CaptureFixture[str]) -> None:
    text = help_text(capsys, "run")
    written = [n for n in OUTPUTS if n not in ("motion.gif", "motion.mp4", "skeleton.png")]
    assert [n for n in written if n not in text] == []
    assert "dataset" not in text.split("--force", 1)[1].split("--staging-dir", 1)[0]


def test_the_documented_built_dataset_path_resolves_where_the_readme_builds_it(
    tmp_path: Path,
) -> None:
    """docs/experiments.md's alternative to building: `path = ...` for the dataset the README
    builds with `--out out/dataset_cmu` from the repository root, in a config in `examples/`
    (paths are relative to the config file's folder)."""
    doc = (ROOT / "docs" / "experiments.md").read_text(encoding="utf-8")
    (line,) = [ln for ln in doc.splitlines() if "# or: path = " in ln]
    path_line = line.split("# or: ", 1)[1].split("  ", 1)[0]
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert "mdf dataset build examples/datasets/cmu.toml --out out/dataset_cmu" in readme
    config = (EXAMPLES / "experiment_cmu.toml").read_text(encoding="utf-8")
    config = config.replace('config = "datasets/cmu.toml"', path_line)
    (tmp_path / "examples").mkdir()
    moved = tmp_path / "examples" / "experiment_cmu.toml"
    moved.write_text(config, encoding="utf-8")
    loaded = load_experiment_config(moved)
    assert loaded.dataset.path is not None
    assert Path(loaded.dataset.path).resolve() == (tmp_path / "out" / "dataset_cmu").resolve()


def test_sigterm_cleans_up_like_ctrl_c(tmp_path: Path) -> None:
    """SIGTERM (what SLURM sends at a job's time limit) during a run: one line, exit 143, no
    lock and no staging folder left."""
    cfg = tmp_path / "long.toml"
    cfg.write_text(
        (EXAMPLES / "point_target.toml")
        .read_text(encoding="utf-8")
        .replace("length = 2.0", "length = 120.0")  # 10 s of CPU: not ended before the signal
        .replace('kind = "lfm"', 'kind = "lfm"\npath = "raw"'),
        encoding="utf-8",
    )
    out = tmp_path / "o"
    proc = subprocess.Popen(
        [sys.executable, "-m", "mdframework.cli", "run", str(cfg), "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not (out / ".mdf.lock").exists():
        time.sleep(0.02)
    time.sleep(0.5)
    os.killpg(proc.pid, signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 143, err
    assert without_third_party_warnings(err.strip().splitlines()) == ["mdf: terminated"]
    assert not out.exists() or sorted(p.name for p in out.iterdir()) == []


@pytest.mark.parametrize(
    ("signum", "code", "line"),
    [(signal.SIGINT, 130, "mdf: interrupted"), (signal.SIGTERM, 143, "mdf: terminated")],
)
def test_interrupt_inside_exec_keeps_the_exit_code(
    tmp_path: Path, signum: int, code: int, line: str
) -> None:
    """Hard case (CI saw it once as exit -2 instead of 143): the signal lands while Python runs
    source text through ``exec`` (as dataclasses do while a module is imported lazily). CPython
    then marks the KeyboardInterrupt as unhandled, and under ``python -m`` the process would die
    by SIGINT at exit although ``mdf`` handled it. The command must still end with its own code."""
    (tmp_path / "signal_in_exec.py").write_text(
        "import os, signal, sys\n"
        "from mdframework import cli\n"
        "def run(argv):\n"
        f"    exec('import os, signal; os.kill(os.getpid(), {int(signum)})')\n"
        "    return 0\n"
        "cli._main_with_options = run\n"
        "sys.exit(cli.main([]))\n",
        encoding="utf-8",
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), *sys.path])}
    done = subprocess.run(
        [sys.executable, "-m", "signal_in_exec"],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        timeout=120,
    )
    assert (done.returncode, done.stderr.strip()) == (code, line)
