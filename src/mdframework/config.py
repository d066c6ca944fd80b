"""Run configs read from TOML, YAML or JSON files, validated against the installed plugins.

Every section that chooses a plugin has a ``kind`` field; the plugin's own ``Config`` model
validates the rest. The full run model is assembled from the registered plugins
(:func:`run_config_model`) on top of :class:`~mdframework.settings.RunConfigBase`, so
``mdf config schema`` shows exactly what is installed. This module sits above the pipeline: the
pipeline and the physics see only the shared models of :mod:`mdframework.settings`.

Relative paths inside a config are relative to the config file's folder.
"""

from __future__ import annotations

import json
import tomllib
from functools import lru_cache
from pathlib import Path
from typing import Annotated, Any, Union

import yaml
from pydantic import Field, ValidationError, create_model, model_validator

from .errors import ConfigError
from .interfaces import PluginConfig
from .plugins import Registry, default_registry
from .settings import RunConfigBase

#: (interface, ((plugin name, its Config model), ...)) for every interface, sorted by name
_ConfigModels = tuple[tuple[str, tuple[tuple[str, type[PluginConfig]], ...]], ...]


def _union(models: list[type[PluginConfig]]) -> Any:
    if not models:
        return PluginConfig
    if len(models) == 1:
        return models[0]
    return Annotated[Union[tuple(models)], Field(discriminator="kind")]  # noqa: UP007


def run_config_model(registry: Registry | None = None) -> type[RunConfigBase]:
    """The run-config model for the plugins in ``registry`` (default: the installed ones). It
    is built once per set of plugin config models (datasets validate one config per record)."""
    reg = registry or default_registry()
    key = tuple(
        (interface, tuple((n, reg.plugins[interface][n].cls.Config) for n in reg.names(interface)))
        for interface in sorted(reg.plugins)
    )
    return _run_config_model(key)


@lru_cache(maxsize=16)
def _run_config_model(key: _ConfigModels) -> type[RunConfigBase]:
    configs = {interface: dict(models) for interface, models in key}

    def union(interface: str) -> Any:
        return _union(list(configs.get(interface, {}).values()))

    def default(interface: str, name: str) -> Any:
        if name in configs.get(interface, {}):
            return Field(default={"kind": name}, validate_default=True)
        return ...

    # a section without ``kind`` means its default plugin, whatever else is installed
    kinds = {
        section: name
        for section, interface, name in (
            ("scatterers", "scatterers", "ellipsoid"),
            ("radar", "radar", "lfm"),
        )
        if name in configs.get(interface, {})
    }

    class Base(RunConfigBase):
        @model_validator(mode="before")
        @classmethod
        def _default_kinds(cls, data: Any) -> Any:
            if isinstance(data, dict):
                for section, name in kinds.items():
                    value = data.get(section)
                    if isinstance(value, dict) and "kind" not in value:
                        data = {**data, section: {"kind": name, **value}}
            return data

    effect_list: Any = list[union("effect")]  # type: ignore[misc]
    model = create_model(
        "RunConfig",
        __base__=Base,
        effects=(
            effect_list,
            Field(
                default_factory=list,
                description="Scene effects to simulate, in order; nothing else is computed.",
            ),
        ),
        motion=(union("motion"), ...),
        scatterers=(union("scatterers"), default("scatterers", "ellipsoid")),
        radar=(union("radar"), default("radar", "lfm")),
    )
    return model


def read_config_file(path: str | Path) -> dict[str, Any]:
    """Parse a TOML, YAML or JSON file into a dict; errors name the file and line."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise ConfigError(f"{p}: cannot read: {exc.strerror or exc}") from None
    suffix = p.suffix.lower()
    try:
        if suffix == ".toml":
            data: Any = tomllib.loads(text)
        elif suffix in (".yaml", ".yml"):
            data = yaml.safe_load(text)
        elif suffix == ".json":
            data = json.loads(text)
        else:
            raise ConfigError(f"{p}: unknown config format {suffix!r} (use .toml, .yaml or .json)")
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{p}: invalid TOML: {exc}") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}: " if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ConfigError(f"{p}: invalid YAML: {where}{problem}") from None
    except json.JSONDecodeError as exc:
        raise ConfigError(f"{p}: invalid JSON: line {exc.lineno}: {exc.msg}") from None
    if not isinstance(data, dict):
        raise ConfigError(f"{p}: the top level must be a table of sections")
    return data


def format_validation_error(exc: ValidationError, source: str, data: Any = None) -> str:
    """One line naming the file and the first invalid field (``section.field``)."""
    errors = exc.errors(include_url=False)
    first = errors[0]
    parts: list[str] = []
    node = data
    for part in first["loc"]:
        if isinstance(node, dict) and part not in node and node.get("kind") == part:
            continue  # the discriminator tag pydantic inserts for plugin sections
        parts.append(str(part))
        node = node.get(part) if isinstance(node, dict) else None
    more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
    msg = first["msg"]
    if first["type"] == "union_tag_invalid":
        msg = f"unknown kind {first['input'].get('kind')!r}; " + msg.split(";")[-1].strip()
    return f"{source}: {'.'.join(parts) or '(top level)'}: {msg}{more}"


def load_run_config(path: str | Path, registry: Registry | None = None) -> RunConfigBase:
    """Read and validate a run config file."""
    p = Path(path)
    data = read_config_file(p)
    return validate_run_config(data, source=str(p), base_dir=p.parent, registry=registry)


def validate_run_config(
    data: dict[str, Any],
    *,
    source: str = "<config>",
    base_dir: Path | None = None,
    registry: Registry | None = None,
) -> RunConfigBase:
    """Validate a config dict; errors are :class:`ConfigError` naming ``source`` and the field."""
    model = run_config_model(registry)
    try:
        return model.model_validate(data, context={"base_dir": base_dir})
    except ValidationError as exc:
        raise ConfigError(format_validation_error(exc, source, data)) from None
