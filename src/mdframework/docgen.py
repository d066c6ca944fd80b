"""Render the config reference (docs/config-reference.md) from the pydantic models.

The reference is generated, never written by hand, so it always matches the code:
``python -m mdframework.docgen > docs/config-reference.md`` (a test checks it is current). Every
section of every model is rendered: a field whose type is itself a model gets its own
subsection, so no field is left undocumented.
"""

from __future__ import annotations

import re
import sys
import types
from functools import cache
from typing import Annotated, Any, Literal, Union, get_args, get_origin

from pydantic import BaseModel
from pydantic.fields import FieldInfo
from pydantic_core import PydanticUndefined

from .plugins import Registry, default_registry
from .settings import RunConfigBase, SanityConfig

RUN_PLUGIN_SECTIONS = {
    "motion": ("motion", "`[motion]`: the motion source"),
    "scatterers": ("scatterers", "`[scatterers]`: the scatterer (RCS) model"),
    "radar": ("radar", "`[radar]`: the radar waveform"),
    "effects": (
        "effects",
        "`[[effects]]`: scene effects (only those listed are simulated; the FMCW radar's "
        "`receiver_noise` is the radar's own)",
    ),
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


def _submodel(annotation: Any) -> type[BaseModel] | None:
    """The model a field holds (directly, optionally, or as list items), if any."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for arg in get_args(annotation):
        found = _submodel(arg)
        if found is not None:
            return found
    return None


def _default(field: FieldInfo, target: str) -> str:
    """The default as Markdown; a section made by its model's defaults points to ``target``."""
    if field.default is PydanticUndefined:
        factory = field.default_factory
        if factory is None:
            return "**required**"
        if isinstance(factory, type) and issubclass(factory, BaseModel):
            return f"see `[{target}]`"
        value = factory()  # type: ignore[call-arg]
        return f"`{value!r}`".replace("(", "[").replace(")", "]")
    if isinstance(field.default, str):
        return f'`"{field.default}"`'
    return f"`{field.default!r}`".replace("(", "[").replace(")", "]")


def _number(value: float) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def numeric_ranges(schema: dict[str, Any]) -> list[str]:
    """The intervals of every number in a field's JSON schema (members of unions, items of lists
    and tuples, values of tables), as ``[lo, hi]`` with round brackets for open ends; a number
    without a bound on one side gives an infinite end (which ``tests`` refuse)."""
    found: list[str] = []
    stack = [schema]
    while stack:
        node = stack.pop()
        if node.get("type") in ("number", "integer"):
            lo, hi = node.get("minimum"), node.get("maximum")
            lo_open, hi_open = "exclusiveMinimum" in node, "exclusiveMaximum" in node
            lo = node.get("exclusiveMinimum", lo)
            hi = node.get("exclusiveMaximum", hi)
            left = "(-inf" if lo is None else ("(" if lo_open else "[") + _number(lo)
            right = "inf)" if hi is None else _number(hi) + (")" if hi_open else "]")
            found.append(f"{left}, {right}")
        for key in ("anyOf", "oneOf", "allOf", "prefixItems"):
            stack.extend(reversed(node.get(key, [])))
        for key in ("items", "additionalProperties"):
            if isinstance(node.get(key), dict):
                stack.append(node[key])
    return list(dict.fromkeys(found))


def model_table(
    model: type[BaseModel],
    skip: tuple[str, ...] = (),
    prefix: str = "",
    seen: dict[type[BaseModel], str] | None = None,
) -> str:
    """A Markdown table of a model's fields: name, type, default, allowed range, description
    (intervals from the JSON schema, :func:`numeric_ranges`). ``prefix`` is
    the model's own section (``scene``), used to name nested sections; ``seen`` maps a model
    already documented to its section."""
    seen = seen or {}
    rows = ["| field | type | default | range | description |", "|---|---|---|---|---|"]
    props = model.model_json_schema().get("properties", {})
    for name, field in model.model_fields.items():
        if name in skip:
            continue
        sub = _submodel(field.annotation)
        desc = field.description or (_summary(sub) if sub is not None else "")
        desc = desc.replace("|", "\\|").replace("\n", " ")
        typ = _type_name(field.annotation).replace("|", "\\|")
        own = f"{prefix}.{name}" if prefix else name
        target = seen.get(sub, own) if sub is not None else own
        if target != own:
            desc += f" Fields: see `[{target}]`."
        ranges = " or ".join(numeric_ranges(props.get(field.alias or name, {})))
        rows.append(f"| `{name}` | `{typ}` | {_default(field, target)} | {ranges} | {desc} |")
    return "\n".join(rows)


def model_sections(
    model: type[BaseModel],
    section: str,
    level: int,
    skip: tuple[str, ...] = (),
    seen: dict[type[BaseModel], str] | None = None,
) -> list[str]:
    """The model's table, then one subsection per model a field holds (recursively); a model
    is documented once, where it first appears, and later fields point there."""
    seen = {} if seen is None else seen
    subs = []
    for name, field in model.model_fields.items():
        sub = _submodel(field.annotation)
        if name in skip or sub is None or sub in seen:
            continue
        path = f"{section}.{name}" if section else name
        seen[sub] = path
        subs.append((path, get_origin(field.annotation) is list, sub, field.default))
    out = [model_table(model, skip, section, seen), ""]
    for path, is_list, sub, default in subs:
        out += [f"{'#' * level} `{f'[[{path}]]' if is_list else f'[{path}]'}`", ""]
        out += [_summary(sub), ""]
        out += _own_default(path, sub, default)
        out += model_sections(sub, path, level + 1, seen=seen)
    return out


def _own_default(path: str, sub: type[BaseModel], default: Any) -> list[str]:
    """For a field whose default is a ``sub`` other than the one ``sub``'s own defaults make
    (the FMCW radar's ``cfar_range``): a line saying that a table it gives leaves the fields it
    omits at the table's defaults below, not at the field's."""
    if not isinstance(default, sub):
        return []
    differ = [
        f"{name} = {_default(FieldInfo(default=getattr(default, name)), '').strip('`')}"
        for name, f in sub.model_fields.items()
        if not f.is_required()
        and getattr(default, name) != f.get_default(call_default_factory=True)
    ]
    if not differ:
        return []
    return [
        f"Without a `[{path}]` table the field's default applies ({', '.join(differ)}, the "
        "rest as below); a table gives each field it leaves out the default below.",
        "",
    ]


def _summary(model: type[BaseModel]) -> str:
    """The model's docstring on one line, Sphinx roles (:mod:`x`) reduced to code (`x`)."""
    return re.sub(r":\w+:`~?([^`]+)`", r"`\1`", " ".join((model.__doc__ or "").split()))


def _plugin_sections(reg: Registry, interface: str, title: str, section: str = "") -> list[str]:
    names = reg.names(interface)
    if not names:
        return []
    out = [f"## {title}", ""]
    for name in names:
        info = reg.plugins[interface][name]
        doc = (info.cls.__doc__ or "").strip().splitlines()[0]
        out += [f"### kind = `{name}` ({info.provider.split()[0]})", "", doc, ""]
        # the models its fields hold get subsections (the sanity checks' is documented once)
        seen: dict[type[BaseModel], str] = {SanityConfig: "motion.sanity"}
        out += model_sections(info.cls.Config, section, 4, skip=("kind",), seen=seen)
    if interface == "motion":
        out += [
            "### `[motion.sanity]` (every motion source)",
            "",
            "Motion sanity checks, run on every human motion after loading; see "
            "[motion formats and sanity checks](motion-formats.md).",
            "",
            model_table(SanityConfig, prefix="motion.sanity"),
            "",
        ]
    return out


def render(registry: Registry | None = None) -> str:
    """The whole config reference as Markdown: run, dataset and experiment configs."""
    from .dataset import DatasetConfig
    from .experiment import ExperimentConfig

    reg = registry or default_registry()
    plugin_fields = ("motion", "scatterers", "radar", "effects")
    out = [
        "# Config reference",
        "",
        "Generated from the code by `python -m mdframework.docgen`; do not edit by hand.",
        "Configs are TOML, YAML or JSON. Unknown fields are errors. Relative paths are",
        "relative to the config file. Units are SI unless a field name says otherwise",
        "(`_deg`, `_db`, `_dbi`). `mdf config schema` prints the run config as a JSON schema.",
        "",
        "- [Run configs](#run-configs) (`mdf run`, `mdf show`): motion, scatterers, radar,",
        "  effects, scene, processing, conditioning, figures.",
        "- [Dataset configs](#dataset-configs) (`mdf dataset build`).",
        "- [Experiment configs](#experiment-configs) (`mdf experiment`), with the classifiers.",
        "",
        "## Run configs",
        "",
        "| field | description |",
        "|---|---|",
        "| `motion` | the motion source (required), see `[motion]` below |",
        "| `scatterers` | the scatterer model, default `ellipsoid` |",
        "| `radar` | the radar, default `lfm` |",
        "| `effects` | list of scene effects, default none |",
    ]
    props = RunConfigBase.model_json_schema().get("properties", {})
    for name, field in RunConfigBase.model_fields.items():
        desc = field.description or ""
        if _submodel(field.annotation) is None:  # a value, not a section: its default and range
            ranges = " or ".join(numeric_ranges(props.get(field.alias or name, {})))
            desc += f" Default {_default(field, name)}" + (f", range {ranges}." if ranges else ".")
        out.append(f"| `{name}` | {desc} |")
    out.append("")
    for name, field in RunConfigBase.model_fields.items():
        sub = _submodel(field.annotation)
        if sub is not None:
            out += [f"### `[{name}]`", "", _summary(sub), ""]
            out += model_sections(sub, name, 4)
    for interface, (section, title) in RUN_PLUGIN_SECTIONS.items():
        out += _plugin_sections(reg, interface, title, section)
    out += ["## Dataset configs", "", _summary(DatasetConfig), ""]
    out += model_sections(DatasetConfig, "", 3)
    out += _plugin_sections(
        reg, "recording", "`recording` of a dataset source: readers of real radar recordings"
    )
    out += ["## Experiment configs", "", _summary(ExperimentConfig), ""]
    out += model_sections(ExperimentConfig, "", 3)
    out += _plugin_sections(reg, "classifier", "`[classifier]` of experiment configs: classifiers")
    assert all(f not in RunConfigBase.model_fields for f in plugin_fields)
    return "\n".join(out).rstrip("\n") + "\n"


@cache
def project_registry() -> Registry:
    """The plugins whose code lives in this source tree's ``plugins/`` folder, loaded without
    any other installed plugin: the reference documents those, and the project's tests check
    them, whatever else is installed (a third party's plugin that fails to load, or claims one
    of our kinds, changes nothing here)."""
    import importlib.metadata
    import importlib.util
    from pathlib import Path

    from .plugins import build_registry

    root = Path(__file__).resolve().parents[2] / "plugins"
    if not root.is_dir():  # an installed mdframework: the reference would lack every plugin
        raise RuntimeError(
            f"no plugins/ folder beside this mdframework ({root.parent}): the reference "
            "documents the plugins of a source tree; run python -m mdframework.docgen in a "
            "clone of the repository"
        )

    def ours(ep: importlib.metadata.EntryPoint) -> bool:
        spec = importlib.util.find_spec(ep.module.split(".")[0])  # imports nothing
        where = spec.origin if spec is not None else None
        return where is not None and root in Path(where).resolve().parents

    return build_registry(autoload=True, select=ours)


if __name__ == "__main__":
    try:
        registry = project_registry()
    except RuntimeError as exc:
        sys.exit(f"mdframework.docgen: {exc}")
    sys.stdout.write(render(registry))
