"""The docs match the code: every `mdf` command shown in README.md and docs/ runs, every Python
block of every page runs (after the documented commands that make the files it reads), every
config shown parses (and matches the example file it quotes), the generated reference is current
and covers every section, every hook is documented, and nothing points outside the repository."""

from __future__ import annotations

import argparse
import ast
import builtins
import importlib.util
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
from mdframework.pipeline import build_stages
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


#: ``mdf ...``, optionally after environment assignments (``MDF_PROGRESS=1 mdf run ...``)
MDF_LINE = re.compile(r"^(?:[A-Z_][A-Z0-9_]*=\S*\s+)*mdf\s")


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
            if MDF_LINE.match(line):
                found.setdefault(" ".join(line.split()), f"{block.where}+{k + 1}")
    return [(where, command) for command, where in found.items()]


COMMANDS = commands()


class Reader:
    """Runs documented commands as a reader would, each once, with their outputs under one
    root (``--out out/x`` writes ``ROOT/out/x``; the dataset commands that share an output
    folder resume one build). Python blocks run with the root as working directory, where
    ``examples`` is the repository's."""

    def __init__(self, root: Path) -> None:
        self.root = root
        (root / "examples").symlink_to(EXAMPLES, target_is_directory=True)
        self.done: dict[str, subprocess.CompletedProcess[str]] = {}

    def run(self, command: str) -> subprocess.CompletedProcess[str]:
        """Run ``[VAR=value ...] mdf ARGS`` from the repository root (inputs as documented,
        outputs under the root); the result of an earlier run of the same command otherwise."""
        if command not in self.done:
            words = shlex.split(command)
            k = next(i for i, w in enumerate(words) if w == "mdf")
            env = {**os.environ, **dict(w.split("=", 1) for w in words[:k])}
            argv = words[k + 1 :]
            for i, arg in enumerate(argv[:-1]):
                if arg == "--out":
                    argv[i + 1] = str(self.root / argv[i + 1])
            mdf = [sys.executable, "-m", "mdframework.cli"]
            self.done[command] = subprocess.run(
                [*mdf, *argv], cwd=ROOT, env=env, capture_output=True, text=True, check=False
            )
        return self.done[command]


@pytest.fixture(scope="module")
def reader(tmp_path_factory: pytest.TempPathFactory) -> Reader:
    """One output root for the module's commands and Python blocks."""
    return Reader(tmp_path_factory.mktemp("docs_commands"))


def skip_reason(where: str, command: str) -> str | None:
    """Why a documented command cannot run here, or None."""
    if command in NOT_RUNNABLE:
        return f"{where}: {NOT_RUNNABLE[command]}"
    if command in NEEDS_PLUGIN:
        interface, kind = NEEDS_PLUGIN[command]
        if kind not in default_registry().names(interface):
            return f"{where}: needs the {interface} plugin {kind!r}, not installed"
    return None


def out_folder(command: str) -> str | None:
    """The ``--out`` folder of a command line, if it has one."""
    words = shlex.split(command)
    return words[words.index("--out") + 1] if "--out" in words[:-1] else None


def split_commands() -> tuple[list[tuple[str, str]], list[tuple[str, str]]]:
    """The commands that run with the rest of this file (those that share an output folder with
    another command, as the dataset commands that resume one build, and those that make a file
    a page's Python blocks read, whose result the blocks' test reuses), and the others, each of
    which becomes a test class of its own (``TestDocumentedCommandNN``): under
    ``--dist loadscope`` pytest-xdist sends each class to whichever worker is free, so the long
    commands run side by side while every file keeps its own worker."""
    code = "\n".join(b.text for b in blocks() if b.lang == "python")
    read = set(re.findall(r"[\"'](out/[\w.-]+)", code))
    outs = [out_folder(c) for _, c in COMMANDS]
    together, alone = [], []
    for (where, command), out in zip(COMMANDS, outs, strict=True):
        keep = out is not None and (outs.count(out) > 1 or out in read)
        (together if keep else alone).append((where, command))
    return together, alone


TOGETHER, ALONE = split_commands()


def run_documented_command(where: str, command: str, reader: Reader) -> None:
    """Run one documented command as a reader does (or skip it, saying why it cannot run)."""
    why = skip_reason(where, command)
    if why:
        pytest.skip(why)
    done = reader.run(command)
    assert done.returncode == 0, f"{where}: `{command}` exited {done.returncode}: {done.stderr}"


@pytest.mark.parametrize(("where", "command"), TOGETHER, ids=[c for _, c in TOGETHER])
def test_every_documented_command_runs(where: str, command: str, reader: Reader) -> None:
    """Each command in its own process, from the repository root, as a reader runs it (the
    commands of :func:`split_commands` that stay together; the others below)."""
    run_documented_command(where, command, reader)


def _command_class(index: int, where: str, command: str) -> type:
    """A test class that runs one documented command (see :func:`split_commands`)."""

    @pytest.mark.parametrize(("where", "command"), [(where, command)], ids=[command])
    def test_every_documented_command_runs(
        self: object, where: str, command: str, reader: Reader
    ) -> None:
        """The command in its own process, from the repository root, as a reader runs it."""
        run_documented_command(where, command, reader)

    name = f"TestDocumentedCommand{index:02d}"
    return type(
        name, (), {"test_every_documented_command_runs": test_every_documented_command_runs}
    )


for _index, (_where, _command) in enumerate(ALONE):
    _cls = _command_class(_index, _where, _command)
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
    configs validate against the installed plugins and build their plugins (refused as a run
    refuses them before its first pulse: an effect order, a radar an effect cannot work with),
    dataset and experiment configs against their models; fragments (``effects = [...]``)
    validate inside a minimal run config."""
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
    if "project" in data:  # a distribution's pyproject.toml, whole: it installs as shown
        assert "mdframework" in data["project"]["entry-points"], block.where
        # (without a version, `pip install -e` of a copy failed: "project must contain
        # ['version']")
        assert {"name", "version"} <= set(data["project"]) and "build-system" in data, block.where
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
        config = validate_run_config(data, source=block.where, base_dir=base_dir)
        build_stages(config)  # what a run refuses before its first pulse (effects' order, radar)


def test_config_reference_is_current() -> None:
    """The reference documents the project's own plugins (whatever else is installed)."""
    current = (ROOT / "docs" / "config-reference.md").read_text()
    assert current == render(default_registry().provided_by(project_distributions())), (
        "regenerate: python -m mdframework.docgen > docs/config-reference.md"
    )


def test_the_reference_of_an_installed_mdframework_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`python -m mdframework.docgen` run on an installed (not editable) mdframework has no
    plugins/ folder to document: it says so, where it wrote the reference without a single
    plugin section."""
    from mdframework import docgen

    installed = tmp_path / "lib" / "python3.11" / "site-packages" / "mdframework" / "docgen.py"
    monkeypatch.setattr(docgen, "__file__", str(installed))
    docgen.project_registry.cache_clear()
    try:
        with pytest.raises(RuntimeError, match=r"^no plugins/ folder beside this mdframework"):
            docgen.project_registry()
    finally:
        docgen.project_registry.cache_clear()

    # the command itself, on a copy of the package where pip puts it: one line, exit 1
    import shutil

    site = tmp_path / "site-packages"
    shutil.copytree(
        ROOT / "src" / "mdframework",
        site / "mdframework",
        ignore=shutil.ignore_patterns("__pycache__"),
    )
    done = subprocess.run(
        [sys.executable, "-m", "mdframework.docgen"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(site)},
        timeout=60,
    )
    assert (done.returncode, done.stdout) == (1, "")
    assert done.stderr == (
        f"mdframework.docgen: no plugins/ folder beside this mdframework ({tmp_path}): the "
        "reference documents the plugins of a source tree; run python -m mdframework.docgen "
        "in a clone of the repository\n"
    )


def test_config_reference_covers_every_section() -> None:
    from mdframework.docgen import project_registry

    reference = render(project_registry())  # ours, whatever else is installed
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


def _config_models() -> dict[str, type[Any]]:
    """Every config model the reference documents, by a name for messages: the run, dataset
    and experiment configs, the motion sanity checks, each plugin kind's config of the
    project's plugins, and every model their fields hold."""
    from mdframework.dataset import DatasetConfig
    from mdframework.docgen import project_registry
    from mdframework.experiment import ExperimentConfig
    from mdframework.settings import SanityConfig

    roots: dict[str, type[Any]] = {
        "run": RunConfigBase,
        "motion.sanity": SanityConfig,
        "dataset": DatasetConfig,
        "experiment": ExperimentConfig,
    }
    registry = project_registry()
    for interface, plugins in registry.plugins.items():
        for name, info in plugins.items():
            roots[f"{interface} {name}"] = info.cls.Config
    found: dict[str, type[Any]] = {}
    stack = list(roots.items())
    while stack:
        label, model = stack.pop()
        if model in found.values():
            continue
        found[label] = model
        for field, info in model.model_fields.items():
            sub = _submodel(info.annotation)
            if sub is not None:
                stack.append((f"{label}.{field}", sub))
    return found


def test_the_reference_documents_every_field_of_every_config_model() -> None:
    """Every field of every config model, nested ones included, has its row in the reference
    (name, type, default, range, description): the fields of the models that plugin configs
    hold (the point targets' ``targets``, the FMCW radar's ``cfar_range`` and the static
    scene's ``reflectors``) were named nowhere, only the field that holds them, and the run's
    ``seed`` had neither default nor range."""
    from mdframework.docgen import model_table, project_registry

    reference = render(project_registry())
    missing = []
    for label, model in _config_models().items():
        rows = model_table(model).splitlines()[2:]
        for name, row in zip(model.model_fields, rows, strict=True):
            leaf = name != "kind" and _submodel(model.model_fields[name].annotation) is None
            if leaf and model is RunConfigBase:  # the run's own fields: one table of their own
                row = f"\n| `{name}` | {model.model_fields[name].description} Default `"
            if leaf and row not in reference:
                missing.append(f"{label}.{name}")
    assert missing == []


#: the float fields without a unit of their own: ratios, fractions, probabilities, positions in
#: units of another field, a table's time range in its column's unit, a distribution's values
#: (the drawn field's unit); any other float field names its unit in its description ([m],
#: [dB] ...) or in its name (_deg)
NO_UNIT = {
    "max_lost_fraction", "glitch_ratio", "glitch_local_ratio", "glitch_return_ratio",
    "speed_scale", "bone_tolerance", "mirror", "time_warp", "test_fraction", "min_confidence",
    "rain_k", "rain_alpha", "path_fraction", "wind_fraction", "reflection_magnitude",
    "multi_object_threshold", "tx_positions", "rx_positions", "time_range",
    "uniform", "loguniform", "normal", "choice",
}  # fmt: skip
UNIT_NAME = re.compile(r"_(deg|db|dbi|m|m2|s|hz|mps|per_km|per_h)$")


def test_every_config_field_has_a_description_and_every_float_field_a_unit() -> None:
    """The reference's description column is never empty (a field holding a model takes the
    model's docstring), and a float field says its unit (the features' ``percentiles`` said
    "Percentile method.", the motion sources' ``start`` "s from the first frame" with no
    unit in brackets)."""
    from mdframework.docgen import _type_name

    models = _config_models()
    assert len(models) > 40
    bare, unitless = [], []
    for label, model in models.items():
        for name, info in model.model_fields.items():
            sub = _submodel(info.annotation)
            text = info.description or (sub.__doc__ if sub is not None else "") or ""
            if name != "kind" and not text.strip():
                bare.append(f"{label}.{name}")
            floats = re.search(r"\bfloat\b", _type_name(info.annotation))
            has_unit = re.search(r"\[[^\],]*[A-Za-z%][^\],]*\]", info.description or "")
            if floats and not (has_unit or UNIT_NAME.search(name) or name in NO_UNIT):
                unitless.append(f"{label}.{name}")
    assert bare == []
    assert unitless == [], unitless


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
    it registers passes the whole contract suite and has a kind of its own (a reader who copies
    one that claims a built-in kind into a distribution gets it switched off); every interface
    has an example."""
    from mdframework.docgen import project_registry

    ours = project_registry()
    monkeypatch.syspath_prepend(str(ROOT / "examples" / "plugin-template" / "src"))
    blocks = _python_blocks(ROOT / "docs" / "plugins.md")
    registered: dict[str, list[str]] = {}
    for i, code in enumerate(blocks):
        module = types.ModuleType(f"mdf_docs_example_{i}")
        monkeypatch.setitem(sys.modules, module.__name__, module)
        # dont_inherit: as in the reader's own module, not under this file's __future__ import
        where = f"docs/plugins.md block {i}"
        exec(compile(code, where, "exec", dont_inherit=True), module.__dict__)
        registry = build_registry([module], autoload=False)
        for interface in INTERFACES:
            for name in registry.names(interface):
                assert name not in ours.names(interface), f"block {i}: {interface} {name!r}"
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
    exec(compile(code, "docs/plugins.md", "exec", dont_inherit=True), namespace)
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


#: Modules that Python blocks may use although the project does not depend on them: a block
#: importing one that is not installed is compiled and its names checked, not run.
OPTIONAL_MODULES = {"torch": "PyTorch, for the deep-learning example of the datasets page"}
#: Pages whose Python blocks have their own test.
OWN_TEST = {
    "plugins.md": "test_every_example_in_the_plugin_guide_runs_and_passes_the_contract_suite"
}
PYTHON_PAGES = sorted(
    {b.file for b in blocks() if b.lang == "python" and b.file.name not in OWN_TEST}
)


def _imports(tree: ast.AST) -> set[str]:
    """Top-level modules a block imports."""
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            found.add(node.module.split(".")[0])
    return found


def _free_names(tree: ast.AST) -> set[str]:
    """Names a block reads without defining them itself (nor importing, nor builtins)."""
    stored, loaded = set(), set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name):
            (loaded if isinstance(node.ctx, ast.Load) else stored).add(node.id)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            stored |= {(a.asname or a.name).split(".")[0] for a in node.names}
        elif isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            stored.add(node.name)
        elif isinstance(node, ast.arg):
            stored.add(node.arg)
    return loaded - stored - set(dir(builtins))


def producer(out: str) -> str | None:
    """The first documented command that can run here and writes ``--out out``."""
    for where, command in COMMANDS:
        words = shlex.split(command)
        writes = [words[i + 1] for i, w in enumerate(words[:-1]) if w == "--out"]
        if writes == [out] and not skip_reason(where, command):
            return command
    return None


@pytest.mark.parametrize("page", PYTHON_PAGES, ids=[p.name for p in PYTHON_PAGES])
def test_every_python_block_of_a_page_runs(
    page: Path, reader: Reader, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A page's ```python blocks run in order in one namespace (as a reader pastes them into
    one session), from a folder where ``examples/`` is the repository's and ``out/`` holds what
    the page's documented commands write (each file a block reads from ``out/`` is made first
    by the command the docs show for it)."""
    code = [b for b in blocks() if b.file == page and b.lang == "python"]
    for out in sorted(set(re.findall(r"[\"'](out/[\w.-]+)", "\n".join(b.text for b in code)))):
        command = producer(out)
        assert command, f"{page.name}: no documented command writes {out}"
        done = reader.run(command)
        assert done.returncode == 0, f"`{command}` exited {done.returncode}: {done.stderr}"
    monkeypatch.chdir(reader.root)
    namespace: dict[str, object] = {"__name__": f"docs_{page.stem}"}
    for block in code:
        tree = ast.parse(block.text, block.where)
        missing = {m for m in _imports(tree) if importlib.util.find_spec(m) is None}
        assert missing <= set(OPTIONAL_MODULES), f"{block.where}: cannot import {missing}"
        if missing:  # compiled above; what it takes from earlier blocks must exist
            undefined = _free_names(tree) - set(namespace)
            assert not undefined, f"{block.where}: {sorted(undefined)} defined by no block above"
            continue
        exec(compile(tree, block.where, "exec", dont_inherit=True), namespace)


def test_every_page_with_python_blocks_is_checked() -> None:
    pages = {b.file.name for b in blocks() if b.lang == "python"}
    assert pages == {p.name for p in PYTHON_PAGES} | set(OWN_TEST)
    assert {"getting-started.md", "datasets.md", "figures.md", "fmcw.md"} <= pages


def test_the_site_lists_every_page_and_the_examples_table_every_example() -> None:
    """Every docs page is in the site's navigation (mkdocs only logs pages left out), every
    public module of the core is in the API reference, and the examples table of the getting
    started page names every example config."""
    nav = (ROOT / "mkdocs.yml").read_text()
    for page in (ROOT / "docs").glob("*.md"):
        assert f": {page.name}" in nav, f"{page.name} is not in the nav of mkdocs.yml"
    api = (ROOT / "docs" / "api.md").read_text()
    listed = re.findall(r"^::: (mdframework\S*)$", api, flags=re.M)
    assert len(listed) == len(set(listed)), "a module is listed twice in docs/api.md"
    named = set()  # the modules the pages send readers to (a function's module counts)
    for page in (ROOT / "docs").glob("*.md"):
        for dotted in re.findall(r"mdframework(?:\.[a-z_]+)+", page.read_text()):
            parts = dotted.split(".")
            while (
                len(parts) > 1 and not (ROOT / "src" / "/".join(parts)).with_suffix(".py").exists()
            ):
                parts.pop()
            named.add(".".join(parts))
    internal = {"mdframework", "mdframework.cli", "mdframework.docgen"}
    assert named - internal - {"mdframework.physics"} <= set(listed), named - set(listed)
    for module in ("interfaces", "hookspecs", "plugins", "testing", "pipeline", "figures"):
        assert f"mdframework.{module}" in listed, module
    table = (ROOT / "docs" / "getting-started.md").read_text().split("## Examples")[1]
    for config in (ROOT / "examples").glob("*.toml"):
        assert f"`{config.name}`" in table, f"{config.name} missing from the examples table"


def test_the_effects_page_table_lists_every_effect_plugin() -> None:
    """The page's table of effect kinds names every effect this project ships (it once left
    out `static_scene`, documented further down the same page)."""
    from mdframework.docgen import project_registry

    page = (ROOT / "docs" / "effects.md").read_text()
    names = project_registry().names("effects")
    assert len(names) >= 7
    for name in names:
        assert f"\n| `{name}` | `plugins/" in page, name


#: ``[.venv/bin/]python benchmarks/x.py ARGS`` or ``python docs/make_x.py ARGS`` in a shell block
SCRIPT_LINE = re.compile(r"^(?:\.venv/bin/)?python\s+((?:benchmarks|docs)/[\w-]+\.py)(.*)$")


def script_commands() -> list[tuple[str, str, list[str]]]:
    """(where, script, arguments) of every script command of the shell blocks."""
    found = []
    for block in blocks():
        if block.lang not in ("sh", "console", "bash", ""):
            continue
        for k, raw in enumerate(block.text.splitlines()):
            line = raw.removeprefix("$ ").split("  #")[0].split(" # ")[0].strip()
            m = SCRIPT_LINE.match(line)
            if m:
                found.append((f"{block.where}+{k + 1}", m.group(1), shlex.split(m.group(2))))
    return found


class _Parsed(Exception):
    """Raised in place of running a script once its arguments parsed."""


def test_every_documented_script_command_parses(monkeypatch: pytest.MonkeyPatch) -> None:
    """Each benchmark or docs script command the pages show is one the script accepts: its
    options parse with the script's own parser (nothing is run); a script without options is
    shown without any. The measured figures these commands make are checked against their
    pages by tests of their own (test_accuracy_page.py, test_sim2real_page.py, ...)."""
    shown = script_commands()
    assert len({s for _, s, _ in shown}) >= 10  # the extraction finds them at all
    real_parse = argparse.ArgumentParser.parse_args

    def parse_then_stop(self: argparse.ArgumentParser, args: Any = None, ns: Any = None) -> Any:
        real_parse(self, args, ns)
        raise _Parsed

    monkeypatch.setattr(argparse.ArgumentParser, "parse_args", parse_then_stop)
    for folder in ("benchmarks", "docs"):  # scripts import their neighbours
        monkeypatch.syspath_prepend(str(ROOT / folder))
    environ = dict(os.environ)  # some scripts pin BLAS threads when imported
    try:
        _parse_each(shown, monkeypatch)
    finally:
        os.environ.clear()
        os.environ.update(environ)


def _parse_each(shown: list[tuple[str, str, list[str]]], monkeypatch: pytest.MonkeyPatch) -> None:
    """Import each script and run its ``main`` up to its parsed arguments."""
    for where, script, args in shown:
        path = ROOT / script
        assert path.exists(), f"{where}: no {script}"
        if "argparse" not in path.read_text():
            assert not args, f"{where}: {script} takes no options, the page gives {args}"
            continue
        name = f"mdf_docs_script_{path.stem}"
        spec = importlib.util.spec_from_file_location(name, path)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        monkeypatch.setitem(sys.modules, name, module)  # dataclasses look their module up
        spec.loader.exec_module(module)
        monkeypatch.setattr(sys, "argv", [str(path), *args])
        with pytest.raises(_Parsed):
            try:
                module.main()
            except SystemExit as exc:
                pytest.fail(f"{where}: `{script} {shlex.join(args)}` does not parse ({exc})")


def test_a_field_whose_default_differs_from_its_tables_defaults_says_so() -> None:
    """The FMCW radar's cfar_range defaults to mode 'so' with 4 guard cells, while a
    ``[radar.cfar_range]`` table that sets only threshold_db gets the table's own defaults,
    mode 'ca' with 2 guard cells: the reference's table of it gave those alone, so a user
    changing the threshold changed the detector without knowing it. The subsection says
    both."""
    from mdf_fmcw.waveform import FmcwConfig

    default, partial = (
        FmcwConfig().cfar_range,
        FmcwConfig(cfar_range={"threshold_db": 12}).cfar_range,
    )
    assert default is not None and partial is not None
    assert (default.mode, default.guard, partial.mode, partial.guard) == ("so", 4, "ca", 2)
    line = (
        'Without a `[radar.cfar_range]` table the field\'s default applies (mode = "so", '
        "guard = 4, the rest as below); a table gives each field it leaves out the default below."
    )
    assert line in render().splitlines()
