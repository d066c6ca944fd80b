"""The ``mdf`` console script keeps the Ctrl-C rule while it imports the command line."""

from __future__ import annotations

import subprocess
import sys

INTERRUPT_ON_IMPORT = r"""
import sys

class Interrupt:
    # raise Ctrl-C exactly while mdframework.cli is being imported
    def find_spec(self, name, path=None, target=None):
        if name == "mdframework.cli":
            raise KeyboardInterrupt
        return None

sys.meta_path.insert(0, Interrupt())
from mdframework.launch import run
run()
"""


def test_ctrl_c_while_importing_the_cli_is_one_line_and_exit_130() -> None:
    done = subprocess.run(
        [sys.executable, "-c", INTERRUPT_ON_IMPORT], capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 130
    assert done.stderr == "mdf: interrupted\n"


def test_console_script_runs_the_cli() -> None:
    done = subprocess.run(
        [sys.executable, "-c", "from mdframework.launch import run; run()", "--version"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0 and done.stdout.startswith("mdf (mdframework)")


GC_DURING_COMMAND = r"""
import gc
import sys

import mdframework.cli

def main():
    print(gc.isenabled(), gc.get_freeze_count() > 0)
    return 3

mdframework.cli.main = main
from mdframework.launch import run
run()
"""


def test_the_command_runs_with_the_garbage_collector_on() -> None:
    # the collector is off only while the command line is imported (what the imports made is
    # then frozen): a long dataset build still frees its cycles; the command's exit code holds
    done = subprocess.run(
        [sys.executable, "-c", GC_DURING_COMMAND], capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 3, done.stderr
    assert done.stdout == "True True\n"
