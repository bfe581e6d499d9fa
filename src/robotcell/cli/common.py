"""Helpers shared by the CLI commands: number lists; CSV files and tables (from ``robotcell.tables``).

Every file the CLI reads or writes is CSV with a header, lengths in millimetres and angles in
degrees.
"""

from __future__ import annotations

import math

from robotcell.errors import InputError
from robotcell.tables import format_table, read_csv, require_columns, write_csv

__all__ = ["format_table", "parse_numbers", "read_csv", "require_columns", "write_csv"]


def parse_numbers(text: str, what: str, count: int | None = None) -> list[float]:
    """Parse ``"1,2,3"`` into floats, with an error naming ``what`` on bad input."""
    parts = [p.strip() for p in text.split(",") if p.strip() != ""]
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise InputError(f"{what} must be comma-separated numbers, got {text!r}") from None
    if count is not None and len(values) != count:
        raise InputError(f"{what} needs {count} comma-separated values, got {len(values)}")
    if not all(math.isfinite(v) for v in values):
        raise InputError(f"{what} contains NaN or infinite values")
    return values
