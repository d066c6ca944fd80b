"""The distributions as a packager builds them (sdist and wheel, not the editable install of the
development set-up): each carries its licence, the core's wheel its ``py.typed``, and the core's
sdist no half of the test suite. ``.ci/check_dists.sh`` builds every distribution, installs the
wheels into a fresh environment and runs ``mdf`` from outside the repository."""

from __future__ import annotations

import shutil
import subprocess
import sys
import tarfile
import tomllib
import zipfile
from pathlib import Path

import pytest
from conftest import ROOT

DISTRIBUTIONS = [ROOT, *sorted(p.parent for p in (ROOT / "plugins").glob("*/pyproject.toml"))]


@pytest.mark.parametrize("folder", DISTRIBUTIONS, ids=[p.name for p in DISTRIBUTIONS])
def test_every_distribution_declares_and_ships_the_licence(folder: Path) -> None:
    """Every distribution says MIT and ships the licence text beside its pyproject (a plugin's
    sdist and wheel hold only its own folder); setuptools reads the SPDX form from 77 on."""
    project = tomllib.loads((folder / "pyproject.toml").read_text(encoding="utf-8"))
    assert project["project"]["license"] == "MIT"
    assert project["project"]["license-files"] == ["LICENSE"]
    assert (folder / "LICENSE").read_bytes() == (ROOT / "LICENSE").read_bytes()
    assert project["build-system"]["requires"] == ["setuptools>=77"]


def _build(src: Path, out: Path) -> tuple[list[str], list[str]]:
    """The names in the sdist and in the wheel that setuptools builds from a copy of ``src``
    (the build writes into its source folder), with the setuptools of this environment."""
    copy = out / "src"
    shutil.copytree(src, copy, ignore=shutil.ignore_patterns("*.egg-info", "__pycache__", "build"))
    names = []
    for hook in ("build_sdist", "build_wheel"):  # one process each (both in one misplace one)
        done = subprocess.run(
            [
                sys.executable,
                "-c",
                f"from setuptools import build_meta as b; import sys; print(b.{hook}(sys.argv[1]))",
                str(out),
            ],
            cwd=copy,
            capture_output=True,
            text=True,
        )
        assert done.returncode == 0, done.stderr[-2000:]
        names.append(done.stdout.splitlines()[-1])  # after setuptools' log
    sdist, wheel = names
    with tarfile.open(out / sdist) as tar:
        sdist_names = [m.name.partition("/")[2] for m in tar.getmembers()]
    with zipfile.ZipFile(out / wheel) as zf:
        wheel_names = zf.namelist()
        metadata = next(n for n in wheel_names if n.endswith(".dist-info/METADATA"))
        assert "License-Expression: MIT" in zf.read(metadata).decode()
    return sdist_names, wheel_names


def test_the_core_sdist_and_wheel(tmp_path: Path) -> None:
    """The core's sdist holds what building it needs (pyproject, README, LICENSE, the sources)
    and not the test files setuptools picks up by default (without conftest.py, helpers and the
    examples, none of them ran); its wheel holds the licence and ``py.typed``."""
    src = tmp_path / "core"
    src.mkdir()
    for name in ("pyproject.toml", "README.md", "LICENSE", "MANIFEST.in"):
        shutil.copy(ROOT / name, src / name)
    shutil.copytree(ROOT / "src", src / "src", ignore=shutil.ignore_patterns("*.egg-info"))
    shutil.copytree(ROOT / "tests", src / "tests", ignore=shutil.ignore_patterns("__pycache__"))
    sdist, wheel = _build(src, tmp_path)
    assert {"pyproject.toml", "README.md", "LICENSE", "src/mdframework/py.typed"} <= set(sdist)
    assert not [n for n in sdist if n.startswith("tests")]
    assert "mdframework/py.typed" in wheel
    assert any(n.endswith(".dist-info/licenses/LICENSE") for n in wheel)


def test_a_plugin_sdist_and_wheel(tmp_path: Path) -> None:
    """A plugin's sdist and wheel carry the licence (they held none: no licence text, and no
    licence in the metadata), and its README as the long description of its package page, in
    Markdown (they had none: an empty page)."""
    sdist, wheel = _build(ROOT / "plugins" / "mdf-cw", tmp_path)
    assert {"LICENSE", "README.md"} <= set(sdist)
    assert any(n.endswith(".dist-info/licenses/LICENSE") for n in wheel)
    [name] = [n for n in wheel if n.endswith(".dist-info/METADATA")]
    [whl] = tmp_path.glob("*.whl")
    with zipfile.ZipFile(whl) as zf:
        headers, _, body = zf.read(name).decode().partition("\n\n")
    assert "Description-Content-Type: text/markdown" in headers.splitlines()
    assert body == (ROOT / "plugins" / "mdf-cw" / "README.md").read_text(encoding="utf-8")


PLUGINS = DISTRIBUTIONS[1:]


@pytest.mark.parametrize("folder", PLUGINS, ids=[p.name for p in PLUGINS])
def test_a_plugin_declares_the_installed_packages_its_modules_import(folder: Path) -> None:
    """A plugin installed alone gets what it imports (mdf-clutter imported scipy, which came
    only through mdframework's own dependencies): every installed distribution that a module
    of the plugin imports is one of its dependencies (optional ones included); the standard
    library, the plugin's own package and packages that are not installed here are left out."""
    import ast
    import importlib.metadata
    import re

    project = tomllib.loads((folder / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    requirements = [*project.get("dependencies", [])]
    for extra in project.get("optional-dependencies", {}).values():
        requirements += extra
    declared = {re.split(r"[\s<>=!~\[;]", r, maxsplit=1)[0].lower() for r in requirements}
    declared = {name.replace("_", "-") for name in declared}
    # pydantic is mdframework's plugin interface (a plugin's config is a PluginConfig, one of
    # mdframework's pydantic models): the plugin has it, of the version mdframework needs
    declared.add("pydantic")
    owners = importlib.metadata.packages_distributions()
    imported: dict[str, str] = {}  # undeclared distributions -> the module importing them
    for source in sorted((folder / "src").rglob("*.py")):
        for node in ast.walk(ast.parse(source.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                tops = [alias.name.partition(".")[0] for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                tops = [node.module.partition(".")[0]]
            else:
                continue
            for top in tops:
                if (
                    top in sys.stdlib_module_names
                    or top == source.relative_to(folder / "src").parts[0]
                ):
                    continue
                # a package can come in several distributions (mujoco 4's ``mujoco`` module
                # in mujoco, mujoco-core and mujoco-studio): declaring one of them suffices
                dists = {d.lower().replace("_", "-") for d in owners.get(top, [])}
                if dists and not dists & declared:
                    imported.setdefault(" or ".join(sorted(dists)), str(source.relative_to(folder)))
    assert imported == {}, f"imported but not declared in {folder.name}'s pyproject"


#: what a distribution's code calls that a dependency added only in a later release than the
#: oldest its pyproject once allowed: (pattern in its sources, dependency, lowest release that has
#: it, what). Installed beside an older release the call fails, an internal TypeError, instead of
#: pip refusing the install.
NEWER_APIS = [
    (r'method="makima"', "scipy", "1.13", "Akima1DInterpolator(method='makima')"),
    (r"\bmj_multiRay\(", "mujoco", "3.5", "mj_multiRay's normal argument"),
]


@pytest.mark.parametrize("folder", DISTRIBUTIONS, ids=[p.name for p in DISTRIBUTIONS])
def test_a_distribution_requires_the_releases_whose_api_it_calls(folder: Path) -> None:
    """The lower bound of a dependency is a release that has what the code calls: with scipy
    1.11 or 1.12 (``scipy>=1.11``) ``interpolation = "akima"`` was an internal TypeError
    (``method`` came in 1.13), and with mujoco 3.0 to 3.4 (``mujoco>=3``) the shadowing effect
    was one (``mj_multiRay`` took no ``normal`` before 3.5)."""
    import re

    from packaging.requirements import Requirement
    from packaging.version import Version

    project = tomllib.loads((folder / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    requirements = {r.name: r for r in map(Requirement, project.get("dependencies", []))}
    code = "\n".join(p.read_text(encoding="utf-8") for p in sorted(folder.glob("src/**/*.py")))
    wrong = []
    for pattern, dist, release, what in NEWER_APIS:
        if not re.search(pattern, code):
            continue
        lowest = [Version(s.version) for s in requirements[dist].specifier if s.operator == ">="]
        if not lowest or max(lowest) < Version(release):
            wrong.append(f"{what} needs {dist}>={release}, not {requirements[dist]}")
    assert wrong == []


def test_every_newer_api_is_still_called() -> None:
    """Each pattern of :data:`NEWER_APIS` is found in some distribution's code (a pattern that
    no longer matches checks nothing)."""
    import re

    code = "\n".join(
        p.read_text(encoding="utf-8") for d in DISTRIBUTIONS for p in d.glob("src/**/*.py")
    )
    assert [what for pattern, _, _, what in NEWER_APIS if not re.search(pattern, code)] == []


@pytest.mark.parametrize("folder", PLUGINS, ids=[p.name for p in PLUGINS])
def test_a_plugin_has_a_package_page(folder: Path) -> None:
    """Each plugin distribution declares its README (a package index shows it; they had none,
    so a plugin's page was empty), and the README says what a researcher needs before
    installing: its name, every kind it registers and every field of each kind's config (a
    field added to the code and not to the page fails here), its dependencies as the
    pyproject declares them, and the licence; no relative link (a package page cannot follow
    one)."""
    import re

    from mdframework.docgen import project_registry

    project = tomllib.loads((folder / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert project["readme"] == "README.md"
    readme = (folder / "README.md").read_text(encoding="utf-8")
    assert readme.startswith(f"# {project['name']}\n\n")
    flat = " ".join(readme.split())  # the page's text, as Markdown joins wrapped lines
    registry = project_registry()
    kinds = [
        (name, info.cls.Config)
        for plugins in registry.plugins.values()
        for name, info in plugins.items()
        if info.provider.split()[0] == project["name"]
    ]
    assert kinds, f"{project['name']} registers nothing here"
    for name, config in kinds:
        assert f'`kind = "{name}"`' in flat, name
        missing = [f for f in config.model_fields if f != "kind" and f"`{f}`" not in flat]
        assert missing == [], f"{name}: fields not on the page"
    for requirement in project["dependencies"]:
        assert f"`{requirement}`" in flat, requirement
    assert f"Python {project['requires-python']}" in flat
    assert "## Licence\n\nMIT" in readme
    assert re.findall(r"\]\((?!https?://)[^)]*\)", readme) == []


@pytest.mark.parametrize("folder", PLUGINS, ids=[p.name for p in PLUGINS])
def test_a_plugin_page_names_its_entry_point_and_documentation_as_they_are(folder: Path) -> None:
    """A plugin's README names its entry point and module as its pyproject declares them (the
    name --disable-plugin takes), and the documentation's pages and Config reference sections
    it sends the reader to by their titles (it cannot link them): each is a page's title (its
    heading or its name in the site's menu) or a section of that page."""
    import re

    project = tomllib.loads((folder / "pyproject.toml").read_text(encoding="utf-8"))
    points = project["project"]["entry-points"]["mdframework"]
    flat = " ".join((folder / "README.md").read_text(encoding="utf-8").split())
    for name, module in points.items():
        assert f"Entry point `{name}` (module `{module}`)" in flat
    docs = ROOT / "docs"
    titles = {
        p.read_text(encoding="utf-8").splitlines()[0].removeprefix("# ") for p in docs.glob("*.md")
    }
    menu = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    titles |= set(re.findall(r"^  - (.+?): \S+\.md$", menu, re.M))
    cited = re.findall(r'page "([^"]+)"', flat)
    assert "Config reference" in cited and set(cited) <= titles, set(cited) - titles
    reference = (docs / "config-reference.md").read_text(encoding="utf-8")
    headings = set(re.findall(r"^#+ (kind = `\w+`)", reference, re.M))
    sections = re.findall(r'"(kind = `\w+`)"', flat)
    assert sections and set(sections) <= headings, set(sections) - headings


def test_the_core_package_page_has_no_relative_link() -> None:
    """The core's README is its package page too, where a link to docs/... or examples/...
    leads nowhere (it linked to docs/getting-started.md, docs/kinect.md and docs/index.md): it
    names the documentation's pages instead, and says which distributions a run needs."""
    import re

    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert re.findall(r"\]\((?!https?://)[^)]*\)", readme) == []
    assert "pip install mdframework mdf-cmu mdf-ellipsoid mdf-lfm" in readme
    # "the table above names them all": the plugins its layout table names
    layout = readme[readme.index("## Layout") : readme.index("## Documentation")]
    assert all(f"`{folder.name}`" in layout for folder in PLUGINS)


@pytest.mark.parametrize("folder", DISTRIBUTIONS, ids=[p.name for p in DISTRIBUTIONS])
def test_every_distribution_fills_its_package_page(folder: Path) -> None:
    """What a package index and ``pip show`` show before installing: a README that exists and
    is not empty, the authors the licence names, keywords, and classifiers of the Python
    versions the project is tested with and of the one system it supports."""
    project = tomllib.loads((folder / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert (folder / project["readme"]).read_text(encoding="utf-8").strip()
    holder = (ROOT / "LICENSE").read_text(encoding="utf-8").splitlines()[2]
    assert holder == "Copyright (c) 2026 the mdframework authors"
    assert project["authors"] == [{"name": "the mdframework authors"}]
    assert "radar" in project["keywords"]
    versions = [f"Programming Language :: Python :: 3.{minor}" for minor in (11, 12, 13)]
    assert set(versions) | {"Operating System :: POSIX :: Linux"} <= set(project["classifiers"])
