"""Tables of measurements and results: CSV files with a header, and plain-text tables.

Every file robotcell reads or writes as a table is CSV with a header, lengths in millimetres and
angles in degrees (the vendor boundary, see ``docs/conventions.md``). The library and the CLI
share these readers and writers.
"""

from __future__ import annotations

import csv
from collections.abc import Sequence
from pathlib import Path
from typing import TextIO

import numpy as np

from robotcell.errors import InputError

__all__ = ["format_table", "read_csv", "require_columns", "write_csv"]


def read_csv(path: str | Path) -> dict[str, np.ndarray | list[str]]:
    """Read a CSV file with a header into columns.

    Numeric columns become float arrays; a column with any non-numeric entry stays a list of
    strings. Column names are lower-cased and stripped.

    Raises
    ------
    InputError
        Missing file, empty file, ragged rows, or an empty cell.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such file")
    with p.open(newline="", encoding="utf-8") as fh:
        rows = [r for r in csv.reader(fh) if any(c.strip() for c in r)]
    if len(rows) < 2:
        raise InputError(f"{path}: needs a header line and at least one data line")
    header = [h.strip().lower() for h in rows[0]]
    if len(set(header)) != len(header):
        raise InputError(f"{path}: repeated column name in header {header}")
    cols: dict[str, list[str]] = {h: [] for h in header}
    for lineno, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise InputError(f"{path}: line {lineno} has {len(row)} values, header has {len(header)}")
        for h, cell in zip(header, row):
            cell = cell.strip()
            if cell == "":
                raise InputError(f"{path}: line {lineno}: empty value in column '{h}'")
            cols[h].append(cell)
    out: dict[str, np.ndarray | list[str]] = {}
    for h, cells in cols.items():
        try:
            arr = np.array([float(c) for c in cells])
        except ValueError:
            out[h] = cells
            continue
        if not np.all(np.isfinite(arr)):
            raise InputError(f"{path}: column '{h}' contains NaN or infinite values")
        out[h] = arr
    return out


def require_columns(cols: dict, names: Sequence[str], path: str | Path) -> np.ndarray:
    """Stack numeric columns ``names`` into an ``(N, len(names))`` array, or raise naming the gap."""
    missing = [n for n in names if n not in cols]
    if missing:
        raise InputError(f"{path}: missing column(s) {', '.join(missing)} (have: {', '.join(cols)})")
    for n in names:
        if not isinstance(cols[n], np.ndarray):
            raise InputError(f"{path}: column '{n}' must be numeric")
    return np.stack([cols[n] for n in names], axis=1)


def write_csv(path: str | Path | TextIO, header: Sequence[str], rows: np.ndarray,
              decimals: int = 6) -> None:
    """Write an ``(N, len(header))`` array as CSV with fixed decimals to a path or open stream."""
    if hasattr(path, "write"):
        _write_rows(path, header, rows, decimals)
        return
    with Path(path).open("w", newline="", encoding="utf-8") as fh:
        _write_rows(fh, header, rows, decimals)


def _write_rows(fh: TextIO, header: Sequence[str], rows: np.ndarray, decimals: int) -> None:
    w = csv.writer(fh, lineterminator="\n")
    w.writerow(header)
    for r in np.atleast_2d(rows):
        w.writerow([f"{v:.{decimals}f}" for v in r])


def format_table(headers: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """A plain-text table with right-aligned columns; floats with 3 decimals."""
    def cell(v: object) -> str:
        if isinstance(v, float):
            return f"{v:.3f}"
        return str(v)

    body = [[cell(v) for v in r] for r in rows]
    widths = [max(len(str(h)), *(len(r[i]) for r in body)) if body else len(str(h))
              for i, h in enumerate(headers)]
    lines = ["  ".join(str(h).rjust(w) for h, w in zip(headers, widths))]
    lines.append("  ".join("-" * w for w in widths))
    lines += ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in body]
    return "\n".join(lines)
