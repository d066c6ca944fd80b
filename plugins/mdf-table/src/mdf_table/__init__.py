"""mdf-table: plain joint-track tables (CSV, TSV, whitespace text or NPZ; long or wide form)
mapped onto the canonical body. See ``docs/motion-formats.md``."""

from __future__ import annotations

from .reader import JOINT_SETS, Table, TableLayout, read_table
from .source import TableConfig, TableSource

__all__ = ["JOINT_SETS", "Table", "TableConfig", "TableLayout", "TableSource", "read_table"]
