"""Progress of the slow steps of `mdf run`, `mdf show` and `mdf check`: shown on a terminal (after
a second), forced on or off with MDF_PROGRESS, hidden with --no-progress, never in a pipe."""

from __future__ import annotations

import io
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import ROOT

from mdframework import progress
from mdframework.config import load_run_config
from mdframework.pipeline import simulate
from mdframework.preview import animation_times

#: A short point target with a received-stage effect: every step of a run, in under a second.
CONFIG = """
[motion]
kind = "point_targets"
length = 0.5
targets = [{ position = [100.0, 0.0, 0.0], velocity = [1.0, 0.0, 0.0] }]
[scatterers]
kind = "points"
[radar]
prf = 2400.0
[scene]
radar_position = [0.0, 0.0, 0.0]
[[effects]]
kind = "noise"
snr_db = 20.0
[processing]
window_length = 128
hop = 32
nfft = 256
block_pulses = 256
"""

#: The steps of a run, in order, as `MDF_PROGRESS=1 mdf run` reports them.
RUN_STEPS = [
    "mdf: reading the config and the installed plugins ...",
    "mdf: loading the motion (point_targets) ...",
    "mdf: conditioning and placing the body ...",
    "mdf: simulating the pulses:",
    "mdf: effects on the received signal (noise) ...",
    "mdf: spectrogram ...",
    "mdf: writing result.npz ...",
    "mdf: drawing spectrogram.png ...",
    "mdf: writing features.json ...",
]


def mdf(args: list[str], env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    """``mdf ARGS`` in its own process, stdout and stderr captured (pipes, not a terminal)."""
    clean = {k: v for k, v in os.environ.items() if k != progress.PROGRESS_ENV}
    return subprocess.run(
        [sys.executable, "-m", "mdframework.cli", *args],
        cwd=ROOT,
        env={**clean, **env},
        capture_output=True,
        text=True,
        check=False,
    )


def lines(stderr: str) -> list[str]:
    """stderr split on newlines and on tqdm's carriage returns, blank lines dropped."""
    return [x.strip() for x in stderr.replace("\r", "\n").splitlines() if x.strip()]


def in_order(expected: list[str], got: list[str]) -> bool:
    """Each expected line starts some line of ``got``, in this order."""
    i = 0
    for line in got:
        if i < len(expected) and line.startswith(expected[i]):
            i += 1
    return i == len(expected)


@pytest.fixture
def config(tmp_path: Path) -> Path:
    path = tmp_path / "short.toml"
    path.write_text(CONFIG)
    return path


def test_forced_progress_reports_every_step_of_a_run_in_order(config: Path, tmp_path: Path) -> None:
    done = mdf(["run", str(config), "--out", str(tmp_path / "o")], {progress.PROGRESS_ENV: "1"})
    assert done.returncode == 0, done.stderr
    got = lines(done.stderr)
    assert in_order(RUN_STEPS, got), got
    n_pulses = simulate(load_run_config(config)).pulse_times.size  # the bar counts them all
    assert any(f"/{n_pulses} " in line for line in got if "simulating" in line), got
    assert all(line.startswith("mdf: ") for line in got), got  # nothing else on stderr
    # stdout keeps listing the written files, one per line
    assert done.stdout.splitlines()[0].endswith("config.resolved.json")


def test_a_run_in_a_pipe_or_with_no_progress_prints_nothing_on_stderr(
    config: Path, tmp_path: Path
) -> None:
    piped = mdf(["run", str(config), "--out", str(tmp_path / "a")], {})
    assert piped.returncode == 0 and piped.stderr == ""
    hidden = mdf(
        ["run", str(config), "--out", str(tmp_path / "b"), "--no-progress"],
        {progress.PROGRESS_ENV: "1"},
    )
    assert hidden.returncode == 0 and hidden.stderr == ""
    off = mdf(["check", str(config)], {progress.PROGRESS_ENV: "0"})
    assert off.returncode == 0 and off.stderr == ""


def test_forced_progress_of_show_counts_the_animation_frames(config: Path, tmp_path: Path) -> None:
    out = tmp_path / "show"
    done = mdf(["show", str(config), "--out", str(out), "--fps", "4"], {progress.PROGRESS_ENV: "1"})
    assert done.returncode == 0, done.stderr
    got = lines(done.stderr)
    body = simulate(load_run_config(config)).body
    frames = animation_times(body, 4).size
    assert in_order(
        [
            *RUN_STEPS,
            "mdf: laying out motion.gif ...",
            "mdf: drawing motion.gif:   0%|",
            "mdf: drawing skeleton.png ...",
        ],
        got,
    ), got
    assert any(line.endswith("frame/s]") and f"/{frames} " in line for line in got), got
    assert (out / "motion.gif").exists() and (out / "skeleton.png").exists()


def test_library_calls_stay_silent_even_when_progress_is_forced(
    config: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """simulate() without a reporter (datasets' workers, scripts) prints nothing."""
    monkeypatch.setenv(progress.PROGRESS_ENV, "1")
    simulate(load_run_config(config))
    assert capsys.readouterr().err == ""


class Terminal(io.StringIO):
    """A stderr that says it is a terminal."""

    def isatty(self) -> bool:
        return True


def on_terminal(monkeypatch: pytest.MonkeyPatch) -> Terminal:
    """stderr replaced by a :class:`Terminal` (in the test body: pytest's own capture resets
    sys.stderr after fixtures run)."""
    monkeypatch.delenv(progress.PROGRESS_ENV, raising=False)
    stream = Terminal()
    monkeypatch.setattr(sys, "stderr", stream)
    return stream


def test_on_a_terminal_a_step_appears_once_it_outlasts_the_delay(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    terminal = on_terminal(monkeypatch)
    reporter = progress.Progress(delay=0.05)
    with reporter.step("slow step"):
        deadline = time.monotonic() + 30.0  # however loaded the machine, the timer fires
        while "slow step" not in terminal.getvalue() and time.monotonic() < deadline:
            time.sleep(0.01)
    assert terminal.getvalue() == "mdf: slow step ...\n"


def test_on_a_terminal_a_step_shorter_than_the_delay_prints_nothing(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    terminal = on_terminal(monkeypatch)
    # 1 s: a loaded machine (or a garbage collection) can stall this thread for a good part of
    # 0.2 s between the step's start and its end, and the message then appeared
    reporter = progress.Progress(delay=1.0)
    with reporter.step("quick step"):
        pass
    reporter.stage("next")
    reporter.end()  # ended before its delay: never printed, not even later
    time.sleep(1.3)
    assert terminal.getvalue() == ""
    assert progress.Progress().delay == progress.DELAY_S  # the default on a terminal


def test_a_bar_on_a_terminal_counts_the_work(monkeypatch: pytest.MonkeyPatch) -> None:
    terminal = on_terminal(monkeypatch)
    reporter = progress.Progress(delay=0.0)
    with reporter.bar(3, "frames of x.gif", "frame") as advance:
        for _ in range(3):
            advance(1)
    assert "mdf: frames of x.gif:   0%|" in terminal.getvalue()
    assert "0/3" in terminal.getvalue()


def test_no_progress_and_mdf_progress_decide_over_the_terminal(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    on_terminal(monkeypatch)
    assert progress.progress_enabled() and not progress.progress_enabled(False)
    monkeypatch.setenv(progress.PROGRESS_ENV, "0")
    assert not progress.progress_enabled()
    monkeypatch.setattr(sys, "stderr", io.StringIO())
    monkeypatch.setenv(progress.PROGRESS_ENV, "1")
    assert progress.progress_enabled() and progress.Progress().delay == 0.0
    assert not progress.progress_enabled(False)  # --no-progress wins


@pytest.mark.parametrize(
    ("value", "shown"),
    [
        *[("1", True), ("Yes", True), ("on", True), ("TRUE", True)],
        *[("0", False), ("no", False), ("Off", False), ("false", False)],
        *[("", None), ("maybe", None), ("2", None)],
    ],
)
def test_progress_variable_reads_the_usual_words_for_on_and_off(
    value: str, shown: bool | None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`MDF_PROGRESS=yes` used to be ignored silently; words other than these still leave the
    choice to the terminal."""
    monkeypatch.setenv(progress.PROGRESS_ENV, value)
    assert progress._forced() is shown


def test_an_unknown_progress_value_is_refused_naming_the_variable(
    config: Path, tmp_path: Path
) -> None:
    """`MDF_PROGRESS=maybe` was ignored without a word: a command that reports progress refuses
    it, as it refuses a bad MDF_START_METHOD, with one line naming the variable and the values
    it takes, before it does anything; an empty value is unset."""
    out = tmp_path / "o"
    done = mdf(["run", str(config), "--out", str(out)], {progress.PROGRESS_ENV: "maybe"})
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.splitlines() == [
        "mdf: error: MDF_PROGRESS='maybe': not a progress setting; use 1, true, yes or on to "
        "show progress, 0, false, no or off to hide it (any case), or leave it unset"
    ]
    assert not out.exists()
    assert mdf(["check", str(config)], {progress.PROGRESS_ENV: " "}).returncode == 0
