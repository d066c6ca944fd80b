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
