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
from pydantic import Field, ValidationError, create_model

from . import limits
from .errors import ConfigError, SceneError
from .interfaces import PluginConfig
from .plugins import Registry, default_registry
from .settings import RunConfigBase
from .skeleton import CANONICAL_JOINTS

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

    effect_list: Any = list[union("effect")]  # type: ignore[misc]
    model = create_model(
        "RunConfig",
        __base__=RunConfigBase,
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


def _decode(p: Path, raw: bytes) -> str:
    """UTF-8 text, with or without a byte-order mark; anything else is a ConfigError."""
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise ConfigError(f"{p}: the file is UTF-16; save it as UTF-8")
    if b"\0" in raw:
        line = raw[: raw.index(b"\0")].count(b"\n") + 1
        raise ConfigError(
            f"{p}: line {line}: a NUL byte: not UTF-8 text (UTF-16 or binary?); save the config "
            "as UTF-8"
        )
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise ConfigError(
            f"{p}: line {line}: not UTF-8 text (byte 0x{raw[exc.start]:02x}); save the config "
            "as UTF-8"
        ) from None


def _check_depth(p: Path, data: Any) -> None:
    """Refuse tables and lists nested deeper than ``limits.MAX_CONFIG_DEPTH`` (iteratively, so
    that the check itself cannot overflow the stack)."""
    stack: list[tuple[Any, int]] = [(data, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > limits.MAX_CONFIG_DEPTH:
            raise ConfigError(
                f"{p}: tables and lists are nested more than {limits.MAX_CONFIG_DEPTH} deep"
            )
        if isinstance(node, dict):
            stack.extend((v, depth + 1) for v in node.values())
        elif isinstance(node, list):
            stack.extend((v, depth + 1) for v in node)


def read_config_file(path: str | Path) -> dict[str, Any]:
    """Parse a TOML, YAML or JSON file into a dict; errors name the file and line.

    The file must be UTF-8 (a byte-order mark is allowed), at most ``limits.MAX_CONFIG_BYTES``
    long, with tables and lists nested at most ``limits.MAX_CONFIG_DEPTH`` deep.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in (".toml", ".yaml", ".yml", ".json"):
        raise ConfigError(f"{p}: unknown config format {suffix!r} (use .toml, .yaml or .json)")
    try:
        size = p.stat().st_size
        if size > limits.MAX_CONFIG_BYTES:
            raise ConfigError(
                f"{p}: {size:,} bytes; a config file may hold at most "
                f"{limits.MAX_CONFIG_BYTES:,} bytes"
            )
        with p.open("rb") as fh:
            raw = fh.read(limits.MAX_CONFIG_BYTES + 1)
    except OSError as exc:
        raise ConfigError(f"{p}: cannot read: {exc.strerror or exc}") from None
    if len(raw) > limits.MAX_CONFIG_BYTES:  # grew while reading, or not a regular file
        raise ConfigError(f"{p}: a config file may hold at most {limits.MAX_CONFIG_BYTES:,} bytes")
    text = _decode(p, raw)
    try:
        if suffix == ".toml":
            data: Any = tomllib.loads(text)
        elif suffix == ".json":
            data = json.loads(text)
        else:
            data = yaml.safe_load(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{p}: invalid TOML: {exc}") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}: " if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ConfigError(f"{p}: invalid YAML: {where}{problem}") from None
    except json.JSONDecodeError as exc:
        raise ConfigError(f"{p}: invalid JSON: line {exc.lineno}: {exc.msg}") from None
    except RecursionError:
        raise ConfigError(
            f"{p}: tables and lists are nested more than {limits.MAX_CONFIG_DEPTH} deep"
        ) from None
    if not isinstance(data, dict):
        raise ConfigError(f"{p}: the top level must be a table of sections")
    _check_depth(p, data)
    return data


def _field_path(loc: tuple[Any, ...], data: Any) -> str:
    """``section.field`` of an error location, without the tags pydantic inserts for the
    members of a union (a plugin's ``kind``, or ``literal['track']`` under a number)."""
    parts: list[str] = []
    node = data
    for part in loc:
        if isinstance(node, dict) and part not in node and node.get("kind") == part:
            continue  # the discriminator tag pydantic inserts for plugin sections
        if node is not None and not isinstance(node, dict | list) and isinstance(part, str):
            continue  # a union member's tag under a scalar value
        parts.append(str(part))
        if isinstance(node, dict):
            node = node.get(part)
        elif isinstance(node, list) and isinstance(part, int) and 0 <= part < len(node):
            node = node[part]
        else:
            node = None
    return ".".join(parts)


def format_validation_error(exc: ValidationError, source: str, data: Any = None) -> str:
    """One line naming the file and the first invalid field (``section.field``); the errors of
    the members of a union on that field are joined with "or"."""
    errors = exc.errors(include_url=False)
    first = errors[0]
    field = _field_path(first["loc"], data)
    same = [e for e in errors if _field_path(e["loc"], data) == field]
    more = len(errors) - len(same)
    more_text = f" (and {more} more)" if more else ""
    msg = first["msg"]
    if first["type"] == "union_tag_invalid":
        msg = f"unknown kind {first['input'].get('kind')!r}; " + msg.split(";")[-1].strip()
    elif len(same) > 1:
        msg = " or ".join(dict.fromkeys(e["msg"] for e in same))
    return f"{source}: {field or '(top level)'}: {msg}{more_text}"


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
        config = model.model_validate(data, context={"base_dir": base_dir})
    except ValidationError as exc:
        raise ConfigError(format_validation_error(exc, source, data)) from None
    _check_pulse_budget(config, source)
    return config


def _check_pulse_budget(config: RunConfigBase, source: str) -> None:
    """When the config alone fixes the record length, refuse a record of more than
    ``limits.MAX_PULSES`` pulses now (the pipeline checks the others once the motion is
    loaded)."""
    cfg: Any = config
    length = cfg.motion.known_length() if hasattr(cfg.motion, "known_length") else None
    prf = getattr(cfg.radar, "prf", None)
    if length is None or prf is None:
        return
    n_points = len(getattr(cfg.motion, "targets", ())) or len(CANONICAL_JOINTS)
    try:
        limits.check_pulses(
            length, prf, n_points, "motion.duration", cfg.processing.keep_scatterers
        )
    except SceneError as exc:
        raise ConfigError(f"{source}: {exc}") from None
