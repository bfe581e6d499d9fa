"""Tables of measurements and results: CSV files with a header, and plain-text tables.

Every file robotcell reads or writes as a table is CSV with a header, lengths in millimetres and
angles in degrees (the vendor boundary, see ``docs/conventions.md``). The library and the CLI
share these readers and writers.
"""

from __future__ import annotations

import csv
import difflib
import io
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TextIO

import numpy as np
from numpy.typing import ArrayLike

from robotcell.errors import InputError
from robotcell.io.fileio import atomic_write, read_text

__all__ = [
    "CELL_EXTENT_MM",
    "LIMIT_TOLERANCE",
    "MAX_ABS_VALUE",
    "NOTE_COLUMNS",
    "format_table",
    "outside_limits",
    "read_csv",
    "require_columns",
    "unknown_columns",
    "unknown_columns_warning",
    "write_columns",
    "write_csv",
]


#: Largest magnitude of a number in a table or an option (mm, deg): a float64 of 1e15 resolves
#: only 0.125 mm, so a larger value cannot be a measurement; it is a typing error.
MAX_ABS_VALUE = 1e15

#: Largest length in any real robot cell (mm): 100 m. A length beyond it, in a file or an option,
#: is a unit or typing error; a calibration result beyond it is graded poor.
CELL_EXTENT_MM = 1e5

#: A value beyond a limit by up to this much (mm or deg: the resolution a pendant shows) is a
#: value at the limit, rounded in the file, and counts as within it.
LIMIT_TOLERANCE = 1e-3

#: Columns every reader accepts and ignores: free text beside the measurements.
NOTE_COLUMNS = ("note", "notes", "comment", "comments", "remark", "remarks", "description")


def read_csv(path: str | Path, allow_nan: bool = False) -> dict[str, np.ndarray | list[str]]:
    """Read a CSV file with a header into columns.

    Numeric columns become float arrays; a column with any non-numeric entry stays a list of
    strings. Column names are lower-cased and stripped. Files as spreadsheets save them are
    read:

    - the encoding follows :func:`robotcell.io.fileio.read_text` (UTF-8 with or without a
      byte-order mark; otherwise Windows-1252 / Latin-1);
    - the separator is ``,``, or ``;`` when the header line holds semicolons and no comma (the
      "CSV" of a spreadsheet in a European locale). In a semicolon-separated file a number may
      use a decimal comma (``1234,5``); a number with both ``.`` and ``,`` (a thousands
      separator) is refused with a message that names the dialect.

    Parameters
    ----------
    path : str or Path
        The CSV file.
    allow_nan : bool
        Accept ``nan``: a value the file's writer did not have (``robotcell reach`` writes it
        for the axes of an unreachable target). Infinity is refused all the same.

    Returns
    -------
    dict of str to ndarray or list of str
        Column name -> values, one per data line (blank lines skipped).

    Raises
    ------
    InputError
        Missing or binary file, empty file, a header of one column whose names are separated by
        a tab or ``|``, ragged rows, an empty cell, NaN or infinity, a number beyond
        :data:`MAX_ABS_VALUE` in size, or a number written with a thousands separator.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such file" + (" (it is a folder)" if p.is_dir() else ""))
    text = read_text(p)
    first = next((ln for ln in text.splitlines() if ln.strip()), "")
    semicolon = ";" in first and "," not in first
    reader = csv.reader(io.StringIO(text, newline=""), delimiter=";" if semicolon else ",")
    try:
        rows = [r for r in reader if any(c.strip() for c in r)]
    except csv.Error as exc:
        raise InputError(f"{path}: not a valid CSV file ({exc})") from None
    if len(rows) < 2:
        raise InputError(f"{path}: needs a header line and at least one data line")
    header = [h.strip().lower() for h in rows[0]]
    other = next((name for s, name in (("\t", "tabs"), ("|", "'|'"))
                  if len(header) == 1 and s in header[0]), None)
    if other is not None:
        raise InputError(f"{path}: the header is one column {rows[0][0].strip()!r}, its names "
                         f"separated by {other}: robotcell reads values separated by ',' (or "
                         "';' with decimal commas); save the file as CSV")
    if len(set(header)) != len(header):
        raise InputError(f"{path}: repeated column name in header {header}")
    cols: dict[str, list[str]] = {h: [] for h in header}
    for lineno, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            hint = ""
            if not semicolon and len(row) > len(header):
                hint = (" (decimal commas in a comma-separated file? Save it with ';' as the "
                        "separator, or write numbers with a decimal point)")
            raise InputError(f"{path}: line {lineno} has {len(row)} values, header has "
                             f"{len(header)}{hint}")
        for h, cell in zip(header, row):
            cell = cell.strip()
            if cell == "":
                raise InputError(f"{path}: line {lineno}: empty value in column '{h}'")
            cols[h].append(cell)
    out: dict[str, np.ndarray | list[str]] = {}
    for h, cells in cols.items():
        values = [_number(c, semicolon) for c in cells]
        if any(v is None for v in values):
            if semicolon and h not in NOTE_COLUMNS:
                _refuse_thousands(cells, h, path)
            out[h] = cells
            continue
        arr = np.array(values, dtype=float)
        if np.any(np.isinf(arr) if allow_nan else ~np.isfinite(arr)):
            raise InputError(f"{path}: column '{h}' contains NaN or infinite values")
        huge = np.flatnonzero(np.abs(arr) > MAX_ABS_VALUE)
        if huge.size:
            raise InputError(f"{path}: line {huge[0] + 2}: column '{h}' has {cells[huge[0]]}, "
                             f"beyond {MAX_ABS_VALUE:.0e} in size: no "
                             "measurement in mm or deg is that large; correct the typing error")
        out[h] = arr
    return out


def _number(cell: str, decimal_comma: bool) -> float | None:
    """``cell`` as a float (a decimal comma allowed when ``decimal_comma``), or None."""
    if decimal_comma and "," in cell and "." not in cell and cell.count(",") == 1:
        cell = cell.replace(",", ".")
    try:
        return float(cell)
    except ValueError:
        return None


def _refuse_thousands(cells: list[str], column: str, path: str | Path) -> None:
    """Refuse a number with both ``.`` and ``,`` in a semicolon-separated file."""
    for c in cells:
        if "," in c and "." in c and _number(c.replace(".", "").replace(",", ""), False) is not None:
            raise InputError(f"{path}: column '{column}' has {c!r}: this file is semicolon-"
                             "separated with decimal commas (European locale), and a number may "
                             "not carry a thousands separator; write it as "
                             f"{c.replace('.', '')!r} or save the file with ',' as the separator "
                             "and '.' as the decimal mark")


def unknown_columns(cols: dict, known: Iterable[str]) -> list[str]:
    """The column names of ``cols`` that are neither in ``known`` nor a note column.

    A reader states the columns it uses; a column it does not know (a misspelt ``piont``) would
    otherwise be ignored silently. The note columns (:data:`NOTE_COLUMNS`) are always accepted.

    Parameters
    ----------
    cols : dict
        Columns from :func:`read_csv`.
    known : iterable of str
        Lower-case names the reader uses.

    Returns
    -------
    list of str
        Unknown names, each followed by `` (did you mean 'point'?)`` when a known name is close.
    """
    known = list(known)
    out = []
    for name in cols:
        if name in known or name in NOTE_COLUMNS:
            continue
        close = difflib.get_close_matches(name, known, n=1, cutoff=0.6)
        out.append(f"{name!r}" + (f" (did you mean {close[0]!r}?)" if close else ""))
    return out


def unknown_columns_warning(source: str | Path, cols: dict, known: Iterable[str],
                            reader: str = "this command") -> str | None:
    """A ``warning:`` naming the columns of ``cols`` that ``reader`` does not use, or None.

    Parameters
    ----------
    source : str or Path
        The table's name (its file), for the message.
    cols : dict
        Columns from :func:`read_csv`.
    known : iterable of str
        Lower-case names the reader uses.
    reader : str
        What reads the table, for the message.

    Returns
    -------
    str or None
        E.g. ``"warning: t.csv: column(s) 'piont' (did you mean 'point'?) not used by this
        command and ignored; check the spelling"``; None when every column is known.
    """
    unknown = unknown_columns(cols, known)
    if not unknown:
        return None
    return (f"warning: {source}: column(s) {', '.join(unknown)} not used by {reader} and "
            "ignored; check the spelling")


def outside_limits(values: np.ndarray, columns: Sequence[str], lower: Sequence[float],
                   upper: Sequence[float], units: Sequence[str], shown: int = 3,
                   lines: bool = True) -> str | None:
    """The values of a table outside the limits of their columns, named by line and column.

    Parameters
    ----------
    values : ndarray, shape (N, k)
        The values as the file holds them (mm, deg); row ``i`` is line ``i + 2`` of the file.
    columns : sequence of str, length k
        Column names.
    lower, upper : sequence of float, length k
        Limits of each column, in the units of the file; infinite for none. A value beyond a
        limit by up to :data:`LIMIT_TOLERANCE` counts as within it.
    units : sequence of str, length k
        Unit of each column, for the message.
    shown : int
        How many values to name; the others are counted.
    lines : bool
        Name the line of each value; False for a single row given otherwise (an option).

    Returns
    -------
    str or None
        None when every value is within its limits, else the first ones, e.g. ``"line 4,
        column 'a6': 150000 deg (limits -350 .. 350 deg); line 9, ...; and 5 more"``.
    """
    v = np.asarray(values, dtype=float).reshape(len(values), len(columns))
    lo = np.asarray(lower, dtype=float) - LIMIT_TOLERANCE
    hi = np.asarray(upper, dtype=float) + LIMIT_TOLERANCE
    rows, cols = np.nonzero((v < lo) | (v > hi))
    if not rows.size:
        return None
    named = [(f"line {i + 2}, column '{columns[j]}'" if lines else columns[j])
             + f": {v[i, j]:g} {units[j]} (limits {lower[j]:g} .. {upper[j]:g} {units[j]})"
             for i, j in zip(rows[:shown], cols[:shown])]
    more = f"; and {rows.size - shown} more" if rows.size > shown else ""
    return "; ".join(named) + more


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
    """Write an ``(N, len(header))`` array as CSV with fixed decimals to a path or open stream.

    A path is written atomically (:func:`robotcell.io.fileio.atomic_write`): a failed run leaves
    the file as it was. Columns of other types: :func:`write_columns`.
    """
    table = np.atleast_2d(np.asarray(rows, dtype=float))
    _write(path, list(header), [_formatted(c, decimals) for c in table.T], len(table))


def write_columns(path: str | Path | TextIO, columns: Mapping[str, ArrayLike],
                  decimals: int = 6) -> None:
    """Write named columns as CSV, each in its type, to a path (atomically) or open stream.

    Parameters
    ----------
    path : str, Path or text stream
    columns : mapping of str to array_like, each of shape (N,)
        Column name -> values. Booleans are written ``true``/``false``, integers as integers,
        other numbers with ``decimals`` fixed decimals.
    decimals : int
    """
    cells = [_formatted(np.asarray(v), decimals) for v in columns.values()]
    _write(path, list(columns), cells, max((len(c) for c in cells), default=0))


def _formatted(values: np.ndarray, decimals: int) -> list[str]:
    """The CSV text of a column: ``true``/``false``, integers, or fixed decimals."""
    if values.dtype == np.bool_:
        return ["true" if v else "false" for v in values]
    if np.issubdtype(values.dtype, np.integer):
        return [str(int(v)) for v in values]
    return [f"{v:.{decimals}f}" for v in values.astype(float)]


def _write(path: str | Path | TextIO, header: list[str], cells: list[list[str]], n: int) -> None:
    """Rows ``i < n`` of the formatted columns, to a stream or atomically to a path."""
    buf = io.StringIO(newline="")
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for i in range(n):
        w.writerow([c[i] for c in cells])
    if isinstance(path, (str, Path)):
        atomic_write(path, buf.getvalue())
    else:
        path.write(buf.getvalue())


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
