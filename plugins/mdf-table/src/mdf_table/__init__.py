"""mdf-table: plain joint-track tables (CSV, TSV, whitespace text or NPZ; long or wide form)
mapped onto the canonical body. See ``docs/motion-formats.md``."""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .source import TableConfig, TableSource

if TYPE_CHECKING:
    from .reader import JOINT_SETS, Table, TableLayout, read_table

#: public names imported on first use: loading the plugin (every mdf command loads every
#: plugin) imports its source classes only, not the reader
_EXPORTS = {
    "JOINT_SETS": "reader",
    "Table": "reader",
    "TableLayout": "reader",
    "read_table": "reader",
}

__all__ = ["JOINT_SETS", "Table", "TableConfig", "TableLayout", "TableSource", "read_table"]


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})
