"""Run configs read from TOML, YAML or JSON files, validated against the installed plugins.

Every section that chooses a plugin has a ``kind`` field; the plugin's own ``Config`` model
validates the rest. The full run model is assembled from the registered plugins
(:func:`run_config_model`) on top of :class:`~mdframework.settings.RunConfigBase`, so
``mdf config schema`` shows exactly what is installed. This module sits above the pipeline: the
pipeline and the physics see only the shared models of :mod:`mdframework.settings`.

Relative paths inside a config are relative to the config file's folder.
"""

from __future__ import annotations

import copy
import datetime
import difflib
import json
import re
import stat
import sys
import tomllib
from collections.abc import Hashable, Iterator, Sequence
from contextlib import contextmanager
from functools import lru_cache
from pathlib import Path
from typing import Annotated, Any, Union, get_args

from pydantic import BaseModel, Field, ValidationError, create_model, model_validator

from . import limits
from .errors import ConfigError, MdfError, SceneError, unnameable
from .interfaces import PluginConfig, RadarConfig
from .plugins import Registry, blame, default_registry, suggest
from .settings import MotionConfig, RunConfigBase
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

    # a section without ``kind`` means its default plugin, whatever else is installed
    kinds = {
        section: name
        for section, name in DEFAULT_KINDS.items()
        if name in configs.get(PLUGIN_SECTIONS[section], {})
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

    effect_list: Any = list[union("effects")]  # type: ignore[misc]
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
        scatterers=(union("scatterers"), default("scatterers", DEFAULT_KINDS["scatterers"])),
        radar=(union("radar"), default("radar", DEFAULT_KINDS["radar"])),
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


#: numbers PyYAML's YAML 1.1 rules leave as text: an exponent without a dot or sign (15e9),
#: and TOML's inf (lower case, without YAML's leading dot)
_YAML_FLOAT = re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?[eE][-+]?[0-9]+|inf)$")


def _load_yaml(p: Path, text: str) -> Any:
    """The data of a YAML config (PyYAML imported here: only YAML configs need it). A key given
    twice in one mapping is an error naming its line (PyYAML would keep the last silently);
    keys merged in with ``<<`` may still be overridden."""
    import yaml

    class Loader(yaml.SafeLoader):  # type: ignore[misc]  # PyYAML is untyped here
        def construct_object(self, node: Any, deep: bool = False) -> Any:
            try:
                return super().construct_object(node, deep=deep)
            except ValueError as exc:  # a date 2024-13-45, a number of 5000 digits
                raise yaml.constructor.ConstructorError(
                    problem=_value_problem(exc), problem_mark=node.start_mark
                ) from None

        def construct_mapping(self, node: Any, deep: bool = False) -> Any:
            seen: set[Any] = set()
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    continue
                key = self.construct_object(key_node, deep=True)
                if not isinstance(key, Hashable):  # PyYAML's own error follows
                    continue
                if key in seen:
                    raise yaml.constructor.ConstructorError(
                        problem=f"key {key!r} given twice in one mapping",
                        problem_mark=key_node.start_mark,
                    )
                seen.add(key)
            return super().construct_mapping(node, deep=deep)

    # YAML 1.1 reads 15e9, 1e-3 and inf as text (it wants 1.5e+10 and .inf): read them as the
    # numbers TOML, JSON and Python read, but only where unquoted
    Loader.add_implicit_resolver("tag:yaml.org,2002:float", _YAML_FLOAT, list("-+0123456789i"))
    try:
        return yaml.load(text, Loader=Loader)  # a SafeLoader
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}: " if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ConfigError(f"{p}: invalid YAML: {where}{problem}") from None


def _value_problem(exc: ValueError) -> str:
    """A value a parser cannot make (``ValueError``) in plain words."""
    if "integer string conversion" in str(exc):  # Python's limit, not the config's
        return f"a whole number of more than {sys.get_int_max_str_digits()} digits"
    return str(exc)  # "month must be in 1..12"


def _long_number_line(text: str) -> int | None:
    """The line of ``text`` of its first run of more digits than Python converts to an integer
    (TOML's ``_`` between them counted out), or None."""
    limit = sys.get_int_max_str_digits()  # 0: no limit
    for number in re.finditer(r"[0-9][0-9_]*", text):
        if limit and len(number.group().replace("_", "")) > limit:
            return text.count("\n", 0, number.start()) + 1
    return None


class _RepeatedKey(ValueError):
    """A key given twice in one JSON object (``line``: where that object starts)."""

    line: int | None = None


def _repeated_key_line(text: str) -> int | None:
    """The line where the JSON object holding a repeated key starts: ``text`` parsed again (only
    when a key repeats) with the pure-Python scanner, which tells where each object starts."""
    import json.decoder
    import json.scanner

    # the json module's own pure-Python parser (JSONObject, py_make_scanner: not in typeshed)
    objects: Any = getattr(json.decoder, "JSONObject")  # noqa: B009
    decoder: Any = json.JSONDecoder(object_pairs_hook=_json_object)

    def parse_object(s_and_end: tuple[str, int], *args: Any) -> Any:
        try:
            return objects(s_and_end, *args)
        except _RepeatedKey as exc:
            if exc.line is None:  # the innermost object: the one holding the key
                exc.line = text.count("\n", 0, s_and_end[1]) + 1
            raise

    decoder.parse_object = parse_object
    decoder.scan_once = getattr(json.scanner, "py_make_scanner")(decoder)  # noqa: B009
    try:
        decoder.decode(text)
    except _RepeatedKey as exc:
        return exc.line
    return None


def _json_object(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """A JSON object, refusing a key given twice (``json`` would keep the last silently)."""
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise _RepeatedKey(f"key {key!r} given twice in one object")
        out[key] = value
    return out


def _check_depth(p: Path, data: Any) -> None:
    """Refuse tables and lists nested deeper than ``limits.MAX_CONFIG_DEPTH`` (iteratively, so
    that the check itself cannot overflow the stack), and data of more values than a config
    file has bytes (YAML aliases of aliases, which would otherwise expand exponentially)."""
    stack: list[tuple[Any, int]] = [(data, 1)]
    count = 0
    while stack:
        node, depth = stack.pop()
        count += 1
        if count > limits.MAX_CONFIG_BYTES:  # more values than bytes: YAML aliases repeated
            raise ConfigError(
                f"{p}: more than {limits.MAX_CONFIG_BYTES:,} values once its YAML aliases "
                "(*name) are expanded; write the values out instead of nesting aliases"
            )
        if depth > limits.MAX_CONFIG_DEPTH:
            raise ConfigError(
                f"{p}: tables and lists are nested more than {limits.MAX_CONFIG_DEPTH} deep"
            )
        if isinstance(node, dict):
            stack.extend((v, depth + 1) for v in node.values())
        elif isinstance(node, list):
            stack.extend((v, depth + 1) for v in node)


#: the kinds of config file: the top-level field that marks each, and the command that reads it
CONFIG_KINDS = {
    "run": ("motion", "mdf run {path} --out DIR"),
    "dataset": ("sources", "mdf dataset build {path} --out DIR"),
    "experiment": ("dataset", "mdf experiment {path} --out DIR"),
}


def _check_kind(path: Path, data: dict[str, Any], kind: str) -> None:
    """Refuse a config of another kind than the command reads (a dataset config given to
    ``mdf run``), naming the field that tells and the command that reads it."""
    if CONFIG_KINDS[kind][0] in data:
        return
    for other, (key, command) in CONFIG_KINDS.items():
        if other != kind and key in data:
            raise ConfigError(
                f"{path}: {_a(other)} config (it has `{key}`), not {_a(kind)} config: use "
                f"`{command.format(path=path)}`"
            )


def _a(word: str) -> str:
    return f"an {word}" if word[0] in "aeiou" else f"a {word}"


def read_config_file(
    path: str | Path, kind: str | None = None, overrides: Sequence[str] = ()
) -> dict[str, Any]:
    """Parse a TOML, YAML or JSON file into a dict; errors name the file and line.

    The file must be UTF-8 (a byte-order mark is allowed), at most ``limits.MAX_CONFIG_BYTES``
    long, with tables and lists nested at most ``limits.MAX_CONFIG_DEPTH`` deep. ``kind``
    (``"run"``, ``"dataset"``, ``"experiment"``): a config of another kind is refused, naming
    the command that reads it. ``overrides`` (``KEY=VALUE``, the command line's ``--set``) are
    applied last (:func:`apply_overrides`); validate the result within
    :func:`blaming_overrides`.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in (".toml", ".yaml", ".yml", ".json"):
        raise ConfigError(f"{p}: unknown config format {suffix!r} (use .toml, .yaml or .json)")
    try:
        st = p.stat()
        if not stat.S_ISREG(st.st_mode):  # a folder, a pipe (which would block), a device
            what = "it is a folder" if p.is_dir() else "not a regular file (a pipe or a device?)"
            raise ConfigError(f"{p}: cannot read: {what}")
        size = st.st_size
        if size > limits.MAX_CONFIG_BYTES:
            raise ConfigError(
                f"{p}: {size:,} bytes; a config file may hold at most "
                f"{limits.MAX_CONFIG_BYTES:,} bytes"
            )
        with p.open("rb") as fh:
            raw = fh.read(limits.MAX_CONFIG_BYTES + 1)
    except OSError as exc:
        raise ConfigError(f"{p}: cannot read: {exc.strerror or exc}") from None
    except UnicodeEncodeError:
        raise ConfigError(f"{p}: cannot read: {unnameable(p)}") from None
    if len(raw) > limits.MAX_CONFIG_BYTES:  # grew while reading, or not a regular file
        raise ConfigError(f"{p}: a config file may hold at most {limits.MAX_CONFIG_BYTES:,} bytes")
    text = _decode(p, raw)
    try:
        if suffix == ".toml":
            data: Any = tomllib.loads(text)
        elif suffix == ".json":
            data = json.loads(text, object_pairs_hook=_json_object)
        else:
            data = _load_yaml(p, text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{p}: invalid TOML: {exc}") from None
    except json.JSONDecodeError as exc:
        raise ConfigError(f"{p}: invalid JSON: line {exc.lineno}: {exc.msg}") from None
    except _RepeatedKey as exc:
        try:
            line = _repeated_key_line(text)
        except RecursionError:  # deeper than the pure-Python parser goes: no line then
            line = None
        where = f"line {line}: " if line is not None else ""
        opened = " (the object opened there)" if line is not None else ""
        raise ConfigError(f"{p}: invalid JSON: {where}{exc}{opened}") from None
    except RecursionError:
        raise ConfigError(
            f"{p}: tables and lists are nested more than {limits.MAX_CONFIG_DEPTH} deep"
        ) from None
    except ValueError as exc:  # a number of 5000 digits
        what = {".toml": "TOML", ".json": "JSON"}.get(suffix, "YAML")
        line = _long_number_line(text)
        where = f"line {line}: " if line is not None else ""
        raise ConfigError(f"{p}: invalid {what}: {where}{_value_problem(exc)}") from None
    if not isinstance(data, dict):
        raise ConfigError(f"{p}: the top level must be a table of sections")
    _check_depth(p, data)
    if kind is not None:
        _check_kind(p, data, kind)
    return apply_overrides(data, overrides) if overrides else data


#: top-level fields of run configs (a TOML key written after a [table] header lands in it)
TOP_LEVEL = ("seed", "motion", "scatterers", "radar", "effects", "scene", "processing",
             "conditioning")  # fmt: skip
#: sections that choose a plugin by ``kind``, and their interface
PLUGIN_SECTIONS = {"motion": "motion", "scatterers": "scatterers", "radar": "radar"}
#: the plugin a section without ``kind`` (or no section at all) means
DEFAULT_KINDS = {"scatterers": "ellipsoid", "radar": "lfm"}


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _model_candidates(annotation: Any) -> list[type[BaseModel]]:
    """The pydantic models an annotation may hold (through Optional, unions, lists, dicts)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    found: list[type[BaseModel]] = []
    for arg in get_args(annotation):
        found += _model_candidates(arg)
    return found


def _model_at(
    model: type[BaseModel] | None, loc: tuple[Any, ...], data: Any
) -> type[BaseModel] | None:
    """The model that validates the object at ``loc`` (choosing plugin models by ``kind``)."""
    node = data
    for part in loc:
        if model is None:
            return None
        if isinstance(part, int):
            node = node[part] if isinstance(node, list) and part < len(node) else None
            continue
        field = model.model_fields.get(str(part))
        node = node.get(part) if isinstance(node, dict) else None
        if field is None:
            return None
        candidates = _model_candidates(field.annotation)
        kind = None
        if isinstance(node, dict):
            kind = node.get("kind")
        elif isinstance(node, list) and node and isinstance(node[0], dict):
            kind = None  # resolved at the list index below
        model = _pick(candidates, kind)
        if isinstance(node, list):
            return _model_in_list(candidates, loc[loc.index(part) + 1 :], node)
    return model


def _model_in_list(
    candidates: list[type[BaseModel]], rest: tuple[Any, ...], node: list[Any]
) -> type[BaseModel] | None:
    if not rest or not isinstance(rest[0], int) or rest[0] >= len(node):
        return None
    item = node[rest[0]]
    kind = item.get("kind") if isinstance(item, dict) else None
    return _model_at(_pick(candidates, kind), tuple(rest[1:]), item)


def _pick(candidates: list[type[BaseModel]], kind: Any) -> type[BaseModel] | None:
    if len(candidates) == 1:
        return candidates[0]
    for cand in candidates:
        field = cand.model_fields.get("kind")
        if field is not None and kind in get_args(field.annotation):
            return cand
    return None


#: pydantic comparison errors -> (words, ctx key)
_BOUNDS = {
    "greater_than": ("greater than", "gt"),
    "greater_than_equal": ("at least", "ge"),
    "less_than": ("less than", "lt"),
    "less_than_equal": ("at most", "le"),
}


def _plain(error: Any, allowed: list[str] | None) -> str:
    """A pydantic error in plain words, with the nearest valid name for unknown fields."""
    kind, msg, ctx = error["type"], error["msg"], error.get("ctx") or {}
    got = f" (got {_short(error.get('input'))})"
    if kind == "extra_forbidden":
        name = str(error["loc"][-1])
        text = f"unknown field {name!r}"
        if allowed:
            hint = suggest(name, allowed)
            text += hint or f" (allowed: {', '.join(allowed)})"
        return text
    if kind == "missing":
        return "required field is missing"
    if kind in _BOUNDS:
        words, key = _BOUNDS[kind]
        bound = ctx.get(key)
        shown = f"{bound:g}" if isinstance(bound, float) else str(bound)
        return f"must be {words} {shown}{got}"
    if kind == "literal_error":
        expected = str(ctx.get("expected", "")).replace(" or ", ", ")
        options = [o.strip().strip("'\"") for o in expected.split(",")]
        return f"must be one of {expected}{got}{suggest(str(error.get('input')), options)}"
    if kind in ("model_type", "dict_type"):  # not pydantic's "instance of <class>"
        return f"must be a table{got}"
    if kind in ("too_short", "too_long"):  # pydantic: "List should have at least 1 item ..."
        least = "at least" if kind == "too_short" else "at most"
        n = ctx.get("min_length" if kind == "too_short" else "max_length")
        return f"must hold {least} {n} item{'' if n == 1 else 's'}{got}"
    if kind == "invalid_key":  # a YAML key 1, true or null
        return f"a key must be text{got}"
    if kind == "int_parsing_size":  # pydantic: "Unable to parse input string as an integer"
        return f"must be a whole number within the field's range{got}"
    if kind == "string_type" and isinstance(error.get("input"), (bool, int, float, datetime.date)):
        # YAML 1.1 reads unquoted yes/no/on/off as flags, 1:30 as 90, 2024-01-01 as a date
        value = error["input"]
        what = (
            "a flag"
            if isinstance(value, bool)
            else "a date"
            if isinstance(value, datetime.date)
            else "a number"
        )
        shown = value.isoformat() if isinstance(value, datetime.date) else _short(value).lower()
        return f"must be text, not {what} ({shown}): quote it"
    if kind == "path_type":  # pydantic: "Input is not a valid path for <class 'pathlib.Path'>"
        return f"must be a path (text){got}"
    if kind in ("value_error", "assertion_error"):
        return str(msg.split(", ", 1)[1] if ", " in msg else msg)
    plain = str(msg).replace("Input should be", "must be").replace("Value error, ", "")
    return plain + (got if kind.endswith(("_type", "_parsing")) else "")


def _toml_hint(parts: list[str], source: str) -> str:
    """The table-order trap: a top-level key written after a [table] header belongs to it."""
    if len(parts) < 2 or parts[-1] not in TOP_LEVEL or parts[0] not in TOP_LEVEL:
        return ""
    where = "[" + ".".join(parts[:-1]) + "]"
    if source.endswith(".toml"):
        return (
            f"; in TOML a key belongs to the last [table] header above it, so "
            f"'{parts[-1]} = ...' written after {where} landed inside it: move it above the "
            "first [table] header"
            + (" or write each effect as an [[effects]] table" if parts[-1] == "effects" else "")
        )
    return f"; {parts[-1]!r} is a top-level field: move it out of {where}"


def _with_default_kinds(data: Any) -> Any:
    """A run config's data with the default ``kind`` of each section that gives none (as
    validation fills it in), so that errors inside such a section name its fields."""
    if not isinstance(data, dict):
        return data
    filled = dict(data)
    for section, name in DEFAULT_KINDS.items():
        value = filled.get(section)
        if isinstance(value, dict) and "kind" not in value:
            filled[section] = {"kind": name, **value}
    return filled


def _field_loc(raw: tuple[Any, ...], data: Any) -> list[Any]:
    """An error location without the tags pydantic inserts for the members of a union (a
    plugin's ``kind``, or ``literal['track']`` under a number)."""
    loc: list[Any] = []
    node = data
    for part in raw:
        if isinstance(node, dict) and part not in node and node.get("kind") == part:
            continue  # the discriminator tag pydantic inserts for plugin sections
        if node is not None and not isinstance(node, dict | list) and isinstance(part, str):
            continue  # a union member's tag under a scalar value
        loc.append(part)
        if isinstance(node, dict):
            node = node.get(part)
        elif isinstance(node, list) and isinstance(part, int) and part < len(node):
            node = node[part]
        else:
            node = None
    return loc


def format_validation_error(
    exc: ValidationError,
    source: str,
    data: Any = None,
    model: type[BaseModel] | None = None,
) -> str:
    """One line naming the file and the first invalid field (``section.field``) in plain words,
    with the nearest valid name for an unknown field and the TOML table-order hint. ``model``
    (the model validated) lets it list the valid field names."""
    errors = exc.errors(include_url=False)
    first = errors[0]
    if isinstance(model, type) and issubclass(model, RunConfigBase):
        data = _with_default_kinds(data)
    loc = _field_loc(first["loc"], data)
    parts = [str(part) for part in loc]
    allowed = None
    if first["type"] == "extra_forbidden":
        parent = _model_at(model, tuple(loc[:-1]), data)
        if parent is not None:
            allowed = sorted(parent.model_fields)
    # the members of a union on one field (e.g. 'track' or a number) fail together: one message
    same = [e for e in errors if _field_loc(e["loc"], data) == loc]
    more = f" (and {len(errors) - len(same)} more)" if len(errors) > len(same) else ""
    if first["type"] == "union_tag_invalid":
        msg = f"unknown kind {first['input'].get('kind')!r}; " + first["msg"].split(";")[-1].strip()
    else:
        msg = " or ".join(dict.fromkeys(_plain(e, allowed) for e in same))
    if first["type"] == "value_error" and len(same) == 1:
        parts, msg = _field_in_message(parts, msg, _model_at(model, tuple(loc), data))
    hint = _toml_hint(parts, source) if first["type"] == "extra_forbidden" else ""
    return f"{source}: {'.'.join(parts) or '(top level)'}: {msg}{hint}{more}"


def _field_in_message(
    parts: list[str], msg: str, section: type[BaseModel] | None
) -> tuple[list[str], str]:
    """A check across a section's fields names the field it blames first (``"ramp_end_time:
    the ADC samples until ..."``): move that field into the location, so the line reads
    ``radar.ramp_end_time: the ADC samples until ...``."""
    name, sep, rest = msg.partition(": ")
    if sep and section is not None and name.split(".")[0] in section.model_fields:
        return [*parts, *name.split(".")], rest
    return parts, msg


def check_plugin_kinds(data: dict[str, Any], source: str, registry: Registry) -> None:
    """Every plugin section names an installed kind; else a :class:`ConfigError` that lists the
    installed kinds, suggests the nearest and says which plugins are disabled."""
    sections: list[tuple[str, str, Any]] = [
        (key, interface, data.get(key)) for key, interface in PLUGIN_SECTIONS.items()
    ]
    effects = data.get("effects")
    if isinstance(effects, list):
        sections += [(f"effects.{i}", "effects", e) for i, e in enumerate(effects)]
    for where, interface, section in sections:
        if section is None and where != "motion":
            continue  # a default applies
        if not isinstance(section, dict):
            if section is None:
                problem = "missing: add a [motion] section with a kind"
                near = difflib.get_close_matches("motion", [str(k) for k in data], n=1)
                if near:  # a misspelt [motion] table
                    problem += f" (the config has [{near[0]}]: rename it)"
            else:
                problem = f"must be a table with a kind (got {_short(section)})"
            raise ConfigError(f"{source}: {where}: {problem}{_kinds(registry, interface)}")
        kind = section.get("kind")
        if kind is None and "kind" in section:  # YAML's null, JSON's null: not the default
            raise ConfigError(
                f"{source}: {where}.kind: null: say which {interface} plugin"
                f"{_kinds(registry, interface)}"
            )
        if kind is None:
            if len(registry.names(interface)) == 1:
                continue  # the only plugin's config has its kind as default
            if DEFAULT_KINDS.get(where) in registry.plugins[interface]:
                continue  # the section's default plugin (filled in by the run model)
            raise ConfigError(
                f"{source}: {where}.kind: missing: say which {interface} plugin"
                f"{_kinds(registry, interface)}"
            )
        if str(kind) not in registry.plugins[interface]:
            message = registry.unknown_kind_message(interface, str(kind))
            raise ConfigError(f"{source}: {where}.kind: {message}")


def _kinds(registry: Registry, interface: str) -> str:
    names = ", ".join(registry.names(interface)) or "none"
    return f" (installed kinds: {names}{registry.disabled_note()})"


def _dotted(place: str) -> str:
    """A place as some errors write it (``sources[0].hop``) as a key writes it
    (``sources.0.hop``)."""
    return re.sub(r"\[(\d+)\]", r".\1", place)


def _override_key(item: str) -> tuple[list[str], str]:
    """``KEY=VALUE`` -> (the key's parts, the value's text); a malformed item is a
    :class:`ConfigError` naming it."""
    key, sep, value = item.partition("=")
    key = key.strip()
    if not sep or not key:
        raise ConfigError(f"--set {item}: expected KEY=VALUE (e.g. --set radar.prf=4000)")
    try:  # a TOML dotted key: bare or quoted parts
        parsed: Any = tomllib.loads(f"{key} = 0")
    except tomllib.TOMLDecodeError:
        try:  # a list indexed as errors write it: sources[0].hop
            parsed = tomllib.loads(f"{_dotted(key)} = 0")
        except tomllib.TOMLDecodeError:
            raise ConfigError(f"--set {item}: {key!r} is not a dotted key like radar.prf") from None
    parts: list[str] = []
    while isinstance(parsed, dict):
        (name, parsed), *_ = parsed.items()
        parts.append(name)
    return parts, value.strip()


def _override_value(text: str) -> Any:
    """A ``--set`` value as TOML reads it (``4000``, ``7.7e10``, ``true``, ``"a b"``,
    ``[1, 2]``, ``{kind = "noise"}``); text that is not one TOML value, or is a date or a time
    (no config field is), is a string."""
    try:
        doc = tomllib.loads(f"v = {text}")
    except tomllib.TOMLDecodeError:
        return text
    if len(doc) != 1 or isinstance(doc["v"], datetime.date | datetime.time):
        return text  # "4000\nradar.fc = 1" is no one value; no field is a date: 2024-01-01
    return doc["v"]


def apply_overrides(data: dict[str, Any], overrides: Sequence[str]) -> dict[str, Any]:
    """A config's data with ``KEY=VALUE`` overrides (``mdf run --set``) applied in order.

    ``KEY`` is a dotted path (``radar.prf``, ``effects.0.snr_db``: an integer part indexes a
    list); tables on the way are made when missing. ``VALUE`` is read as a TOML value, else as a
    string, and means what it would written in the config file (a relative path is relative to
    the config file's folder). ``data`` is not changed. A key that runs through a value that is
    not a table, or an index beyond a list, is a :class:`ConfigError` naming the override.
    """
    result: dict[str, Any] = copy.deepcopy(data)
    for item in overrides:
        parts, text = _override_key(item)
        try:
            value = _override_value(text)
        except ValueError as exc:  # a number of 5000 digits
            raise ConfigError(f"--set {item}: {_value_problem(exc)}") from None
        node: Any = result
        for depth, part in enumerate(parts):
            last = depth == len(parts) - 1
            where = ".".join(parts[:depth])  # (depth > 0: the top level is a table)
            if isinstance(node, list):
                if not part.isdecimal() or int(part) >= len(node):
                    has = f"a list of {len(node)}: index it with 0..{len(node) - 1}, or"
                    raise ConfigError(
                        f"--set {item}: {where} is {has if node else 'an empty list:'} set the "
                        "whole list"
                    )
                index = int(part)
                if last:
                    node[index] = value
                else:
                    node = node[index]
            elif isinstance(node, dict):
                if last:
                    node[part] = value
                elif part not in node and parts[depth + 1].isdecimal():
                    here = ".".join(parts[: depth + 1])
                    raise ConfigError(
                        f"--set {item}: {here} is not in the config: set the whole list"
                    )
                else:
                    node = node.setdefault(part, {})
            else:
                raise ConfigError(f"--set {item}: {where} is {_short(node)}, not a table")
    return result


@contextmanager
def blaming_overrides(source: str, overrides: Sequence[str]) -> Iterator[None]:
    """A :class:`ConfigError` or :class:`SceneError` about a field that an override set
    (``source: field: ...`` or ``source: sources[0] record 3: field: ...``, a field above or
    below it, or a field of the same table whose message names the override's field) names the
    override instead of the file ``source``. One about a file's field of a table whose ``kind``
    an override chose (``--set radar.kind=fmcw`` with the LFM radar's fields in the file) names
    that override after the message."""
    try:
        yield
    except (ConfigError, SceneError) as exc:
        rest = str(exc).removeprefix(f"{source}: ")
        if rest == str(exc):
            raise
        # the message's places, outermost first
        fields = [_dotted(place) for place in rest.split(": ")[:-1]]
        said = re.sub(r"\([^)]*\)", "", rest)  # the message without its lists of names
        for item in reversed(overrides):  # the last override of a key is the one that counts
            key = ".".join(_override_key(item)[0])
            table, _, name = key.rpartition(".")
            # an error between two fields of a table names the other: processing.nfft: 1024 is
            # shorter than window_length 60000 (not in a list of names: "(allowed: ...)")
            named = bool(table) and re.search(rf"(?<![\w.]){re.escape(name)}(?![\w'])", said)
            for field in fields:
                if (
                    key == field
                    or key.startswith(f"{field}.")
                    or field.startswith(f"{key}.")
                    or (named and field.rpartition(".")[0] == table)
                ):
                    raise type(exc)(f"--set {item.strip()}: {rest}") from None
        for item in reversed(overrides):  # the file's field, wrong for a kind an override chose
            key = ".".join(_override_key(item)[0])
            table, _, name = key.rpartition(".")
            if name == "kind" and table and any(f.startswith(f"{table}.") for f in fields):
                raise type(exc)(f"{exc} (for the kind of --set {item.strip()})") from None
        raise


def load_run_config(
    path: str | Path, registry: Registry | None = None, overrides: Sequence[str] = ()
) -> RunConfigBase:
    """Read and validate a run config file, with ``overrides`` (``KEY=VALUE``, see
    :func:`apply_overrides`) applied first; an invalid field that an override set is blamed on
    the override."""
    p = Path(path)
    data = read_config_file(p, "run", overrides)
    with blaming_overrides(str(p), overrides):
        return validate_run_config(data, source=str(p), base_dir=p.parent, registry=registry)


def validate_run_config(
    data: dict[str, Any],
    *,
    source: str = "<config>",
    base_dir: Path | None = None,
    registry: Registry | None = None,
) -> RunConfigBase:
    """Validate a config dict; errors are :class:`ConfigError` naming ``source`` and the field."""
    reg = registry or default_registry()
    check_plugin_kinds(data, source, reg)
    model = run_config_model(reg)
    try:
        config = model.model_validate(data, context={"base_dir": base_dir})
    except ValidationError as exc:
        raise ConfigError(format_validation_error(exc, source, data, model)) from None
    except MdfError:
        raise
    except Exception:  # a plugin's validator failed otherwise than pydantic expects: its bug
        _name_failing_validator(data, reg, base_dir)
        raise
    _check_saveable(config)
    _check_pulse_budget(config, source)
    return config


def _name_failing_validator(data: dict[str, Any], reg: Registry, base_dir: Path | None) -> None:
    """Validate each plugin section of ``data`` alone, in its plugin's own config model: the
    one whose validator raises an exception other than pydantic's raises it again with a note
    naming the plugin (:func:`~mdframework.plugins.blame`); the whole run config names nobody."""
    sections = [(name, data.get(name)) for name in ("motion", "scatterers", "radar")]
    effects = data.get("effects")
    sections += [("effects", e) for e in effects] if isinstance(effects, list) else []
    for interface, section in sections:
        if not isinstance(section, dict) or not isinstance(section.get("kind"), str):
            continue
        try:
            cls = reg.get(interface, section["kind"])
        except KeyError:
            continue
        with blame(cls, "Config.model_validate"):
            try:
                cls.Config.model_validate(section, context={"base_dir": base_dir})
            except ValidationError:
                pass  # the user's error, which the whole config reports


def _check_saveable(config: RunConfigBase) -> None:
    """Runs save their config as JSON (``config.resolved.json``): a plugin's config that
    cannot be saved is that plugin's bug, found here, before any work, and named in the
    exception's note (which the CLI's internal error shows)."""
    from pydantic_core import PydanticSerializationError

    cfg: Any = config
    sections = [("motion", cfg.motion), ("scatterers", cfg.scatterers), ("radar", cfg.radar)]
    sections += [("effects", effect) for effect in cfg.effects]
    for interface, section in sections:
        try:
            section.model_dump_json()
        except PydanticSerializationError as exc:
            cls = type(section)
            exc.add_note(
                f"in the config of the {interface} plugin {section.kind!r} "
                f"({cls.__module__}.{cls.__qualname__}), which runs save as JSON; check it "
                "with mdframework.testing.check_config_round_trip"
            )
            raise


def _check_pulse_budget(config: RunConfigBase, source: str) -> None:
    """When the config alone fixes the record length, refuse a record of more than
    ``limits.MAX_PULSES`` pulses now (the pipeline checks the others once the motion is
    loaded)."""
    cfg: Any = config
    length = cfg.motion.known_length() if isinstance(cfg.motion, MotionConfig) else None
    prf = cfg.radar.pulse_rate() if isinstance(cfg.radar, RadarConfig) else None
    if length is None or prf is None:
        return
    n_points = len(getattr(cfg.motion, "targets", ())) or len(CANONICAL_JOINTS)
    try:
        limits.check_pulses(
            length, prf, n_points, "motion.duration", cfg.processing.keep_scatterers
        )
    except SceneError as exc:
        raise ConfigError(f"{source}: {exc}") from None
