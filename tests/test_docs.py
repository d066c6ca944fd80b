"""The docs match the code: generated reference current, every hook documented."""

from __future__ import annotations

import inspect

from conftest import ROOT

from mdframework import hookspecs
from mdframework.docgen import render


def test_config_reference_is_current() -> None:
    current = (ROOT / "docs" / "config-reference.md").read_text()
    assert current == render(), (
        "regenerate: python -m mdframework.docgen > docs/config-reference.md"
    )


def test_every_hook_is_documented_in_the_plugin_guide() -> None:
    guide = (ROOT / "docs" / "plugins.md").read_text()
    hooks = [
        n
        for n, f in inspect.getmembers(hookspecs, inspect.isfunction)
        if n.startswith("mdframework_")
    ]
    assert len(hooks) == 7
    for name in hooks:
        assert name in guide, f"{name} missing from docs/plugins.md"


def test_readme_quick_start() -> None:
    readme = (ROOT / "README.md").read_text()
    assert "make demo" in readme and "make test" in readme
