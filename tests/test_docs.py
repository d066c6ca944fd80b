"""The docs match the code: every `mdf` command shown in README.md and docs/ runs, every config
shown parses (and matches the example file it quotes), the generated reference is current and
covers every section, every hook is documented, and nothing points outside the repository."""

from __future__ import annotations

import argparse
import inspect
import os
import re
import shlex
import subprocess
import sys
import tomllib
import types
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from conftest import EXAMPLES, ROOT, project_distributions

from mdframework import hookspecs
from mdframework.config import validate_run_config
from mdframework.docgen import _submodel, render
from mdframework.plugins import INTERFACES, OLD_HOOKS, build_registry, default_registry
from mdframework.settings import RunConfigBase
from mdframework.testing import check_plugin

DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]

#: Commands shown in the docs that cannot run here, each with the reason; every entry must still
#: appear in the docs (so the list cannot go stale).
NOT_RUNNABLE = {
    "mdf capture --out walk01.nite.txt --duration 6": "needs a Kinect and NiTE2",
    "mdf capture --out walk01.nite.txt --device file.oni": "needs NiTE2 (not redistributable)",
    "mdf run ... --debug": "a pattern, not a command",
    "mdf dataset build examples/datasets/cmu.toml --out out/dataset_cmu --scheduler "
    "tcp://host:8786": "needs a running Dask cluster at that address",
}
#: Commands that need a plugin the repository does not ship yet: skipped (saying so) until it is
#: installed, then run like the others.
NEEDS_PLUGIN = {
    "mdf experiment examples/experiment_sim2real.toml --out out/experiment_sim2real": (
        "radar",
        "fmcw",
    ),
}
#: Motion kinds of configs shown for plugins that are not installed in the test environment,
#: and the test that runs them through a real entry point instead.
FOREIGN_KINDS = {"circle": "tests/test_plugins.py::test_documented_example_distribution_runs"}


@dataclass(frozen=True)
class Block:
    """A fenced code block of a Markdown file."""

    file: Path
    line: int
    lang: str
    text: str

    @property
    def where(self) -> str:
        return f"{self.file.relative_to(ROOT)}:{self.line}"


def blocks() -> list[Block]:
    """Every fenced block of README.md and docs/*.md."""
    found = []
    fence = re.compile(r"^```(\w*)\n(.*?)^```", re.S | re.M)
    for path in DOCS:
        text = path.read_text()
        for m in fence.finditer(text):
            line = text.count("\n", 0, m.start()) + 1
            found.append(Block(path, line, m.group(1), m.group(2)))
    return found


def commands() -> list[tuple[str, str]]:
    """(where, command) for every distinct `mdf` command line of the shell blocks (comments
    removed), where it first appears."""
    found: dict[str, str] = {}
    for block in blocks():
        if block.lang not in ("sh", "console", "bash", ""):
            continue
        for k, raw in enumerate(block.text.splitlines()):
            line = raw.removeprefix("$ ").split("  #")[0].split(" # ")[0].strip()
            line = line.removeprefix(".venv/bin/")
            if line.startswith("mdf "):
                found.setdefault(" ".join(line.split()), f"{block.where}+{k + 1}")
    return [(where, command) for command, where in found.items()]


COMMANDS = commands()


def out_folder(command: str) -> str | None:
    """The ``--out`` folder of a command line, if it has one."""
    argv = command.split()
    return argv[argv.index("--out") + 1] if "--out" in argv[:-1] else None


def command_units() -> list[list[tuple[str, str]]]:
    """The commands in scheduling units: the commands that share an output folder (the dataset
    commands that resume one build) form one unit, in order; every other command is a unit of
    its own."""
    units: dict[str, list[tuple[str, str]]] = {}
    for where, command in COMMANDS:
        units.setdefault(out_folder(command) or command, []).append((where, command))
    return list(units.values())


@pytest.fixture(scope="module")
def workdir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One output root for the module's commands (on each worker), as for a reader who runs
    them in order (the dataset commands that share an output folder resume one build)."""
    return tmp_path_factory.mktemp("docs_commands")


def run_documented_command(where: str, command: str, workdir: Path) -> None:
    """Run one documented command in its own process, from the repository root, as a reader
    runs it (outputs under ``workdir``); skip the ones that cannot run here, saying why."""
    if command in NOT_RUNNABLE:
        pytest.skip(f"{where}: {NOT_RUNNABLE[command]}")
    if command in NEEDS_PLUGIN:
        interface, kind = NEEDS_PLUGIN[command]
        if kind not in default_registry().names(interface):
            pytest.skip(f"{where}: needs the {interface} plugin {kind!r}, not installed")
    argv = shlex.split(command)[1:]
    for i, arg in enumerate(argv[:-1]):
        if arg == "--out":  # outputs go to the temporary root, inputs stay as documented
            argv[i + 1] = str(workdir / argv[i + 1])
    mdf = [sys.executable, "-m", "mdframework.cli"]
    done = subprocess.run([*mdf, *argv], cwd=ROOT, capture_output=True, text=True, check=False)
    assert done.returncode == 0, f"{where}: `{command}` exited {done.returncode}: {done.stderr}"


def _command_class(index: int, unit: list[tuple[str, str]]) -> type:
    """A test class running ``unit``'s commands: under ``--dist loadscope`` each class is a unit
    that pytest-xdist sends to whichever worker is free, so the long commands run side by side
    while the rest of this file (and every other file) stays on one worker."""

    @pytest.mark.parametrize(("where", "command"), [pytest.param(*wc, id=wc[1]) for wc in unit])
    def test_every_documented_command_runs(
        self: object, where: str, command: str, workdir: Path
    ) -> None:
        """Each command in its own process, from the repository root, as a reader runs it."""
        run_documented_command(where, command, workdir)

    return type(
        f"TestDocumentedCommands{index:02d}",
        (),
        {"test_every_documented_command_runs": test_every_documented_command_runs},
    )


for _index, _unit in enumerate(command_units()):
    _cls = _command_class(_index, _unit)
    globals()[_cls.__name__] = _cls


def test_commands_that_cannot_run_here_are_still_documented() -> None:
    shown = {c for _, c in COMMANDS}
    assert set(NOT_RUNNABLE) <= shown, set(NOT_RUNNABLE) - shown
    assert len(COMMANDS) >= 10  # the extraction finds the commands at all


def _subset(part: Any, whole: Any) -> bool:
    """Every key of ``part`` is in ``whole`` with an equal value, and every item of a list of
    tables in an item of ``whole``'s list (recursively: an abridged copy)."""
    if isinstance(part, dict):
        return isinstance(whole, dict) and all(
            k in whole and _subset(v, whole[k]) for k, v in part.items()
        )
    if isinstance(part, list) and part and all(isinstance(p, dict) for p in part):
        return isinstance(whole, list) and all(any(_subset(p, w) for w in whole) for p in part)
    return bool(part == whole)


def _merge(defaults: dict[str, Any], given: dict[str, Any]) -> dict[str, Any]:
    """``given`` over ``defaults``, table by table."""
    out = dict(defaults)
    for key, value in given.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = value
    return out


TOML_BLOCKS = [b for b in blocks() if b.lang == "toml"]


@pytest.mark.parametrize("block", TOML_BLOCKS, ids=[b.where for b in TOML_BLOCKS])
def test_every_documented_config_parses(block: Block) -> None:
    """A block that names an example file (``# examples/x.toml``) must agree with it; run
    configs validate against the installed plugins, dataset and experiment configs against
    their models; fragments (``effects = [...]``) validate inside a minimal run config."""
    from mdframework.dataset import DatasetConfig
    from mdframework.experiment import ExperimentConfig

    data = tomllib.loads(block.text)
    first = block.text.lstrip().splitlines()[0]
    named = re.match(r"#\s*(examples/\S+\.toml)", first)
    base_dir = EXAMPLES
    if named:
        path = ROOT / named.group(1)
        whole = tomllib.loads(path.read_text())
        if "sources" in whole:  # a block may show a section's defaults that the file leaves out
            whole = _merge(DatasetConfig.model_validate(whole).model_dump(mode="json"), whole)
        assert _subset(data, whole), f"{block.where} differs from {path}"
        base_dir = path.parent
    run_fields = {*RunConfigBase.model_fields, "motion", "scatterers", "radar", "effects"}
    fragment_of = None if set(data) <= run_fields else set(data)
    if "project" in data:  # a distribution's pyproject.toml
        assert "mdframework" in data["project"]["entry-points"], block.where
    elif "sources" in data or (fragment_of and fragment_of <= set(DatasetConfig.model_fields)):
        if named:  # an abridged copy of a whole file: validate the file
            data = tomllib.loads((ROOT / named.group(1)).read_text())
        source = {"label": "walk", "motion": {"kind": "point_targets"}}
        DatasetConfig.model_validate({"sources": [source], **data})
    elif "dataset" in data or (fragment_of and fragment_of <= set(ExperimentConfig.model_fields)):
        ExperimentConfig.model_validate({**data, "dataset": {"path": "out"}})
    else:
        kind = data.get("motion", {}).get("kind")
        if kind in FOREIGN_KINDS:
            pytest.skip(f"{block.where}: kind {kind!r} runs in {FOREIGN_KINDS[kind]}")
        target = {"position": [9.0, 0.0, 0.0]}
        minimal = {
            "motion": {"kind": "point_targets", "length": 1.0, "targets": [target]},
            "scatterers": {"kind": "points"},
        }
        if "motion" not in data:
            data = {**minimal, **data}
        validate_run_config(data, source=block.where, base_dir=base_dir)


def test_config_reference_is_current() -> None:
    """The reference documents the project's own plugins (whatever else is installed)."""
    current = (ROOT / "docs" / "config-reference.md").read_text()
    assert current == render(default_registry().provided_by(project_distributions())), (
        "regenerate: python -m mdframework.docgen > docs/config-reference.md"
    )


def test_config_reference_covers_every_section() -> None:
    reference = render()
    for name, field in RunConfigBase.model_fields.items():
        sub = _submodel(field.annotation)
        if sub is None:
            continue
        assert f"### `[{name}]`" in reference, name
        for inner in sub.model_fields:
            assert f"| `{inner}` |" in reference, f"{name}.{inner}"
    assert "(see below)" not in reference
    run_part = reference.split("## Dataset configs")[0]
    assert "[classifier]" not in run_part  # classifiers belong to experiment configs


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


OUTSIDE = ("physics.md", "../shared", "/work/", "reference material")


def test_docs_stand_alone() -> None:
    """No reference to material outside the repository, and every relative link resolves."""
    link = re.compile(r"\]\(([^)#\s]+)(?:#[^)]*)?\)")
    for path in DOCS:
        text = path.read_text()
        for banned in OUTSIDE:
            assert banned not in text, f"{path.relative_to(ROOT)} mentions {banned!r}"
        for target in link.findall(text):
            if "://" in target:
                continue
            assert (path.parent / target).exists(), f"{path.relative_to(ROOT)}: {target}"


def test_code_and_examples_cite_nothing_outside_the_repository() -> None:
    """The API reference is made from the docstrings, and examples are read as documentation."""
    files = [
        *(ROOT / "src").rglob("*.py"),
        *(ROOT / "plugins").rglob("*.py"),
        *(ROOT / "examples").rglob("*.toml"),
        *(ROOT / "examples").rglob("*.md"),
    ]
    assert len(files) > 50
    for path in files:
        text = path.read_text()
        for banned in OUTSIDE:
            assert banned not in text, f"{path.relative_to(ROOT)} mentions {banned!r}"


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
