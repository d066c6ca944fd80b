"""Render the config reference (docs/config-reference.md) from the pydantic models.

The reference is generated, never written by hand, so it always matches the code:
``python -m mdframework.docgen > docs/config-reference.md`` (a test checks it is current).
"""

from __future__ import annotations

import sys
import types
from typing import Annotated, Any, Literal, Union, get_args, get_origin

from pydantic import BaseModel
from pydantic.fields import FieldInfo
from pydantic_core import PydanticUndefined

from .plugins import INTERFACES, Registry, default_registry
from .settings import PersonConfig, ProcessingConfig, SanityConfig, SceneConfig

SECTIONS = {
    "motion": "`[motion]`: the motion source",
    "scatterers": "`[scatterers]`: the scatterer (RCS) model",
    "radar": "`[radar]`: the radar waveform",
    "effects": "`[[effects]]`: scene effects (only those listed are simulated)",
    "classifier": "`[classifier]`: classifiers",
    "recording": "`recording` of a dataset source: readers of real radar recordings",
}


def _type_name(annotation: Any) -> str:
    origin, args = get_origin(annotation), get_args(annotation)
    if origin is Annotated:
        return _type_name(args[0])
    if origin in (Union, types.UnionType):
        return " | ".join(_type_name(a) for a in args)
    if origin is Literal:
        return " | ".join(repr(a) for a in args)
    if origin is not None:
        return f"{getattr(origin, '__name__', origin)}[{', '.join(_type_name(a) for a in args)}]"
    if annotation is type(None):
        return "None"
    return annotation.__name__ if isinstance(annotation, type) else str(annotation)


def _default(field: FieldInfo) -> str:
    if field.default is PydanticUndefined:
        if field.default_factory is not None:
            return "(see below)" if isinstance(field.default_factory, type) else "[]"
        return "**required**"
    if isinstance(field.default, str):
        return f'`"{field.default}"`'
    return f"`{field.default!r}`".replace("(", "[").replace(")", "]")


def model_table(model: type[BaseModel], skip: tuple[str, ...] = ()) -> str:
    """A Markdown table of a model's fields: name, type, default, description."""
    rows = ["| field | type | default | description |", "|---|---|---|---|"]
    for name, field in model.model_fields.items():
        if name in skip:
            continue
        desc = (field.description or "").replace("|", "\\|").replace("\n", " ")
        typ = _type_name(field.annotation).replace("|", "\\|")
        rows.append(f"| `{name}` | `{typ}` | {_default(field)} | {desc} |")
    return "\n".join(rows)


def render(registry: Registry | None = None) -> str:
    """The whole config reference as Markdown."""
    reg = registry or default_registry()
    out = [
        "# Config reference",
        "",
        "Generated from the code by `python -m mdframework.docgen`; do not edit by hand.",
        "Run configs are TOML, YAML or JSON. Unknown fields are errors. Relative paths are",
        "relative to the config file. Units are SI unless a field name says otherwise",
        "(`_deg`, `_db`, `_dbi`). `mdf config schema` prints the same as a JSON schema.",
        "",
        "## Top level",
        "",
        "| field | description |",
        "|---|---|",
        "| `motion` | the motion source (required), see below |",
        "| `scatterers` | the scatterer model, default `ellipsoid` |",
        "| `radar` | the radar, default `lfm` |",
        "| `effects` | list of scene effects, default none |",
        "| `scene` | radar position, the person's placement, range gate |",
        "| `processing` | resampling and spectrogram |",
        "| `seed` | seed of every random draw, default 0 |",
        "",
        "## `[scene]`",
        "",
        model_table(SceneConfig),
        "",
        "### `[scene.person]`",
        "",
        model_table(PersonConfig),
        "",
        "## `[processing]`",
        "",
        model_table(ProcessingConfig),
        "",
        "## `[motion.sanity]` (every motion source)",
        "",
        "Motion sanity checks, run on every human motion after loading; see "
        "[motion formats and sanity checks](motion-formats.md).",
        "",
        model_table(SanityConfig),
        "",
    ]
    for interface in INTERFACES:
        names = reg.names(interface)
        if not names:
            continue
        out += [f"## {SECTIONS[interface]}", ""]
        for name in names:
            info = reg.plugins[interface][name]
            doc = (info.cls.__doc__ or "").strip().splitlines()[0]
            out += [f"### kind = `{name}` ({info.provider.split()[0]})", "", doc, ""]
            out += [model_table(info.cls.Config, skip=("kind",)), ""]
    return "\n".join(out)


def project_registry() -> Registry:
    """The installed plugins whose code lives in this source tree's ``plugins/`` folder (the
    reference documents those, whatever else is installed)."""
    import inspect
    from pathlib import Path

    root = Path(__file__).resolve().parents[2] / "plugins"
    reg = default_registry()
    own = {
        info.provider.split()[0]
        for infos in reg.plugins.values()
        for info in infos.values()
        if root in Path(inspect.getfile(info.cls)).resolve().parents
    }
    return reg.provided_by(own)


if __name__ == "__main__":
    sys.stdout.write(render(project_registry()))
