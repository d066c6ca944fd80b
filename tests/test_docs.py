"""The docs match the code: generated reference current, every hook documented."""

from __future__ import annotations

import argparse
import inspect
import os
import re
import subprocess
import sys
import types
from pathlib import Path

import pytest
from conftest import ROOT, project_distributions

from mdframework import hookspecs
from mdframework.docgen import render
from mdframework.plugins import INTERFACES, OLD_HOOKS, build_registry, default_registry
from mdframework.testing import check_plugin


def test_config_reference_is_current() -> None:
    """The reference documents the project's own plugins (whatever else is installed)."""
    current = (ROOT / "docs" / "config-reference.md").read_text()
    assert current == render(default_registry().provided_by(project_distributions())), (
        "regenerate: python -m mdframework.docgen > docs/config-reference.md"
    )


def test_every_hook_is_documented_in_the_plugin_guide() -> None:
    guide = (ROOT / "docs" / "plugins.md").read_text()
    hooks = [
        n
        for n, f in inspect.getmembers(hookspecs, inspect.isfunction)
        if n.startswith("mdframework_") and n not in OLD_HOOKS
    ]
    assert len(hooks) == 7
    for name in hooks:
        assert name in guide, f"{name} missing from docs/plugins.md"


def test_readme_quick_start() -> None:
    readme = (ROOT / "README.md").read_text()
    assert "make demo" in readme and "make test" in readme


def _python_blocks(path: Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", path.read_text(), flags=re.S)


def test_every_example_in_the_plugin_guide_runs_and_passes_the_contract_suite(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Each ```python block of docs/plugins.md runs as shown (imports included); every plugin
    it registers passes the whole contract suite; every interface has an example."""
    monkeypatch.syspath_prepend(str(ROOT / "examples" / "plugin-template" / "src"))
    blocks = _python_blocks(ROOT / "docs" / "plugins.md")
    registered: dict[str, list[str]] = {}
    for i, code in enumerate(blocks):
        module = types.ModuleType(f"mdf_docs_example_{i}")
        monkeypatch.setitem(sys.modules, module.__name__, module)
        exec(compile(code, f"docs/plugins.md block {i}", "exec"), module.__dict__)
        registry = build_registry([module], autoload=False)
        for interface in INTERFACES:
            for name in registry.names(interface):
                check_plugin(registry.get(interface, name))
                registered.setdefault(interface, []).append(name)
        for name, value in module.__dict__.items():
            if name.startswith("test_") and callable(value) and not hasattr(value, "pytestmark"):
                value()  # the guide's own example tests
    assert set(registered) == set(INTERFACES), registered


def test_the_plugin_guide_cli_example_adds_a_documented_command(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code = next(b for b in _python_blocks(ROOT / "docs" / "plugins.md") if "add_command" in b)
    namespace: dict[str, object] = {}
    exec(code, namespace)
    parser = argparse.ArgumentParser(prog="mdf")
    sub = parser.add_subparsers()
    namespace["mdframework_add_cli_commands"](subparsers=sub)  # type: ignore[operator]
    args = parser.parse_args(["hello", "--who", "plugin author"])
    assert args.func(args) == 0 and capsys.readouterr().out == "hello, plugin author\n"
    assert "mdf hello --who world" in sub.choices["hello"].format_help()


def test_the_plugin_template_passes_its_own_tests() -> None:
    """examples/plugin-template is a distribution with its own tests (run as its author would,
    with the package on the path)."""
    template = ROOT / "examples" / "plugin-template"
    env = {**os.environ, "PYTHONPATH": str(template / "src")}
    proc = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-n", "0", "-p", "no:cacheprovider", "tests"],
        cwd=template,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout[-3000:]
    assert " passed" in proc.stdout and "failed" not in proc.stdout
