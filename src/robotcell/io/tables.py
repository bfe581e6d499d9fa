"""Tables of measurements and results: CSV files with a header, and plain-text tables.

Every file robotcell reads or writes as a table is CSV with a header, lengths in millimetres and
angles in degrees (the vendor boundary, see ``docs/conventions.md``). The library and the CLI
share these readers and writers.
"""

from __future__ import annotations

import csv
import difflib
import io
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any, TextIO

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.io.fileio import atomic_write, read_text

__all__ = [
    "CELL_EXTENT_MM",
    "LIMIT_TOLERANCE",
    "MAX_ABS_VALUE",
    "NOTE_COLUMNS",
    "empty_rows",
    "format_table",
    "optional_column",
    "outside_limits",
    "read_csv",
    "read_csv_lines",
    "refuse_empty",
    "require_columns",
    "spreadsheet_number",
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

    Numeric columns become float arrays; a column with any non-numeric entry, or with no value
    at all, stays a list of strings; a note column (:data:`NOTE_COLUMNS`) is always text.
    Column names are lower-cased and stripped. Files as spreadsheets save them are read:

    - the encoding follows :func:`robotcell.io.fileio.read_text` (UTF-8 with or without a
      byte-order mark; otherwise Windows-1252 / Latin-1);
    - the separator is ``,``, or ``;`` when the header line holds semicolons and no comma (the
      "CSV" of a spreadsheet in a European locale). In a semicolon-separated file a number may
      use a decimal comma (``1234,5``); a number with both ``.`` and ``,`` (a thousands
      separator) is refused with a message that names the dialect;
    - blank lines, and lines of separators only, are skipped; a column without a name whose
      cells are all empty (the trailing separator a spreadsheet writes) is left out, and so are
      empty cells after the last column;
    - an empty cell is kept as "not given": NaN in a numeric column, ``""`` in a text column.
      Whether it may be empty is for the reader of the column to say (:func:`require_columns`,
      :func:`refuse_empty`, :func:`optional_column`);
    - numbers are read as a spreadsheet writes them (:func:`spreadsheet_number`): ``1_673.4``
      or digits other than ``0-9``, which Python's ``float`` would take, are refused.

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
        Column name -> values, one per data line.

    Raises
    ------
    InputError
        Missing or binary file, empty file, a comment or title line above the header, a header
        of one column whose names are separated by a tab or ``|``, ragged rows, a value in a
        column without a name, a comment line among the data, NaN or infinity, a number
        beyond :data:`MAX_ABS_VALUE` in size, a number written with a thousands separator or
        with ``_``; each naming its line (as the file counts them, the header being line 1
        when nothing is above it).
    """
    return read_csv_lines(path, allow_nan)[0]


def read_csv_lines(path: str | Path, allow_nan: bool = False
                   ) -> tuple[dict[str, np.ndarray | list[str]], NDArray[np.intp]]:
    """:func:`read_csv`, and the line of the file each data row stands on.

    Parameters
    ----------
    path : str or Path
    allow_nan : bool
        As for :func:`read_csv`.

    Returns
    -------
    cols : dict of str to ndarray or list of str
        As :func:`read_csv` returns them.
    lines : ndarray of int, shape (N,)
        The line of each row, as the file counts them (blank lines skipped by the reader
        counted too): for messages naming a row's line.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such file" + (" (it is a folder)" if p.is_dir() else ""))
    text = read_text(p)
    first = next((ln for ln in text.splitlines() if ln.strip()), "")
    semicolon = ";" in first and "," not in first
    reader = csv.reader(io.StringIO(text, newline=""), delimiter=";" if semicolon else ",")
    try:
        rows = [(reader.line_num, r) for r in reader if any(c.strip() for c in r)]
    except csv.Error as exc:
        raise InputError(f"{path}: not a valid CSV file ({exc})") from None
    if len(rows) < 2:
        raise InputError(f"{path}: needs a header line and at least one data line")
    header = _header(rows, path, semicolon)
    cells = _cells(rows, header, path, semicolon)
    lines = [line for line, _ in rows[1:]]
    return ({h: _column(v, h, lines, path, semicolon, allow_nan) for h, v in cells.items()},
            np.array(lines, dtype=np.intp))


#: A number as a spreadsheet writes it: a sign, digits 0-9 with a decimal point, an exponent;
#: or NaN and infinity, read so that they are refused by name.
_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:e[+-]?[0-9]+)?"
                     r"|[+-]?(?:nan|inf|infinity)", re.IGNORECASE)


def spreadsheet_number(text: str) -> float | None:
    """``text`` as a number, if a spreadsheet writes it so, else None.

    A sign, the digits ``0-9`` with an optional decimal point, an optional exponent
    (``-1.5E+03``); ``nan`` and ``inf``/``infinity`` are numbers too (for the caller to refuse
    or allow). Python's ``float`` reads more: ``1_673.4`` (digit grouping) and digits of other
    scripts (``١٢``), which are typing errors in a table; they give None here.

    Parameters
    ----------
    text : str
        A cell or an option's value; surrounding white space is ignored.

    Returns
    -------
    float or None
    """
    t = text.strip()
    return float(t) if _NUMBER.fullmatch(t) else None


def _number(cell: str, decimal_comma: bool) -> float | None:
    """``cell`` as a float (a decimal comma allowed when ``decimal_comma``), or None."""
    if decimal_comma and "," in cell and "." not in cell and cell.count(",") == 1:
        cell = cell.replace(",", ".")
    return spreadsheet_number(cell)


def _python_only(cell: str, decimal_comma: bool) -> bool:
    """Whether Python's ``float`` reads ``cell`` although a spreadsheet writes no such number."""
    if _number(cell, decimal_comma) is not None:
        return False
    try:
        float(cell.replace(",", ".") if decimal_comma and cell.count(",") == 1 else cell)
    except ValueError:
        return False
    return True


def _shown(cells: list[str], sep: str) -> str:
    """A line of the file as it was written, cut to 60 characters, for a message."""
    line = sep.join(cells).strip()
    return repr(line if len(line) <= 60 else line[:57] + "...")


def _header(rows: list[tuple[int, list[str]]], path: str | Path, semicolon: bool) -> list[str]:
    """The column names of the first line, ``""`` for a column without a name; refused when
    the first line is a comment or a title above the header, or its names are separated by
    tabs or ``|``, or a name repeats."""
    (line, cells), (_, data) = rows[0], rows[1]
    header = [h.strip().lower() for h in cells]
    sep = ";" if semicolon else ","
    if not any(_number(c.strip(), semicolon) is not None for c in data):  # a second header?
        if header[0].startswith("#"):
            raise InputError(f"{path}: line {line} {_shown(cells, sep)} is a comment above the "
                             "header: robotcell reads the first line as the header (the column "
                             "names) and skips no comment lines; delete the comment line(s), or "
                             "keep remarks in a column 'note'")
        if len(_trimmed(data)) > len(_trimmed(cells)):
            raise InputError(f"{path}: line {line} {_shown(cells, sep)} has "
                             f"{len(_trimmed(cells))} value(s), and the line after it "
                             f"{len(_trimmed(data))} names and no number: a title above the "
                             "header? robotcell reads the first line as the header (the column "
                             "names); delete the line(s) above it")
    other = next((name for s, name in (("\t", "tabs"), ("|", "'|'"))
                  if len(_trimmed(header)) == 1 and s in header[0]), None)
    if other is not None:
        raise InputError(f"{path}: the header is one column {cells[0].strip()!r}, its names "
                         f"separated by {other}: robotcell reads values separated by ',' (or "
                         "';' with decimal commas); save the file as CSV")
    named = [h for h in header if h]
    if len(set(named)) != len(named):
        raise InputError(f"{path}: repeated column name in header {named}")
    return header


def _trimmed(cells: list[str]) -> list[str]:
    """The cells of a line without the empty ones at its end (trailing separators)."""
    n = len(cells)
    while n and not cells[n - 1].strip():
        n -= 1
    return cells[:n]


def _cells(rows: list[tuple[int, list[str]]], header: list[str], path: str | Path,
           semicolon: bool) -> dict[str, list[str]]:
    """The stripped cells of every named column; refused: a line with more values than the
    header or fewer than its named columns, a value in a column without a name, a comment
    line."""
    width = len(_trimmed(header))
    notes = header[0] in NOTE_COLUMNS
    cols: dict[str, list[str]] = {h: [] for h in header if h}
    for line, row in rows[1:]:
        cells = [c.strip() for c in row]
        if cells[0].startswith("#") and not notes:
            raise InputError(f"{path}: line {line} starts with '#': robotcell skips no comment "
                             "lines; delete it, or keep the remark in a column 'note'")
        given = len(_trimmed(cells))
        if given > len(header) or len(cells) < width:
            hint = ""
            if not semicolon and given > width:
                hint = (" (decimal commas in a comma-separated file? Save it with ';' as the "
                        "separator, or write numbers with a decimal point)")
            raise InputError(f"{path}: line {line} has {min(given, len(cells))} values, header "
                             f"has {width}{hint}")
        for j, c in enumerate(cells[:len(header)]):
            if c and not header[j]:
                raise InputError(f"{path}: line {line}: value {c!r} in column {j + 1}, which has "
                                 "no name in the header; name the column, or delete the value")
        for h, c in zip(header, cells):
            if h:
                cols[h].append(c)
    return cols


def _column(cells: list[str], name: str, lines: list[int], path: str | Path, semicolon: bool,
            allow_nan: bool) -> np.ndarray | list[str]:
    """One column: text (a note column, a column with text or without any value), or numbers
    with NaN where a cell is empty; refused: Python-only numbers, NaN (unless ``allow_nan``),
    infinity, a size beyond :data:`MAX_ABS_VALUE`, a thousands separator."""
    if name in NOTE_COLUMNS:
        return cells
    odd = next((i for i, c in enumerate(cells) if _python_only(c, semicolon)), None)
    if odd is not None:
        c = cells[odd]
        fix = (f"write {c.replace('_', '')}" if "_" in c else "write it with the digits 0-9")
        raise InputError(f"{path}: line {lines[odd]}: column '{name}' has {c!r}, which is not a "
                         f"number as a spreadsheet writes it; {fix}")
    values = [_number(c, semicolon) if c else math.nan for c in cells]
    if any(v is None for v in values) or not any(cells):
        if semicolon:
            _refuse_thousands(cells, name, path)
        return cells
    arr = np.array(values, dtype=float)
    given = np.array([c != "" for c in cells])
    bad = np.flatnonzero(given & (np.isinf(arr) if allow_nan else ~np.isfinite(arr)))
    if bad.size:
        raise InputError(f"{path}: line {lines[bad[0]]}: column '{name}' has "
                         f"{cells[bad[0]]!r}: NaN or infinite values are not measurements; "
                         "correct the value, or delete the line")
    huge = np.flatnonzero(np.abs(arr) > MAX_ABS_VALUE)
    if huge.size:
        raise InputError(f"{path}: line {lines[huge[0]]}: column '{name}' has {cells[huge[0]]}, "
                         f"beyond {MAX_ABS_VALUE:.0e} in size: no "
                         "measurement in mm or deg is that large; correct the typing error")
    return arr


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


def empty_rows(values: np.ndarray | Sequence[str]) -> NDArray[np.intp]:
    """The rows of a column of :func:`read_csv` whose cell is empty ("not given").

    Parameters
    ----------
    values : ndarray or sequence of str, shape (N,)
        A numeric column (an empty cell is NaN) or a text column (an empty cell is ``""``).

    Returns
    -------
    ndarray of int
        Row indices (row ``i`` is line ``i + 2`` of the file), increasing.
    """
    if isinstance(values, np.ndarray):
        return np.flatnonzero(np.isnan(values))
    return np.array([i for i, v in enumerate(values) if not str(v).strip()], dtype=np.intp)


def refuse_empty(cols: Mapping[str, Any], names: Iterable[str], path: str | Path,
                 optional: bool = False) -> None:
    """Refuse an empty cell in the columns ``names`` that ``cols`` has, naming line and column.

    A reader calls it for the columns it needs a value of on every line: a required column, or
    an optional one with no default per line (a track position, a table angle).

    Parameters
    ----------
    cols : mapping
        Columns from :func:`read_csv`.
    names : iterable of str
        The columns to check; those ``cols`` lacks are skipped.
    path : str or Path
        The file, for the message.
    optional : bool
        The column may be left out as a whole (the message says so).

    Raises
    ------
    InputError
        E.g. ``"t.csv: line 4: empty value in column 'z' (and 2 more lines), which needs a
        value on every line; fill it in, or delete the line"``.
    """
    for name in names:
        if name not in cols:
            continue
        rows = empty_rows(cols[name])
        if rows.size:
            more = f" (and {rows.size - 1} more line(s))" if rows.size > 1 else ""
            fix = ("fill it in on every line, or leave the column out" if optional
                   else "fill it in, or delete the line")
            raise InputError(f"{path}: line {rows[0] + 2}: empty value in column '{name}'{more}, "
                             f"which needs a value on every line; {fix}")


def require_columns(cols: Mapping[str, Any], names: Sequence[str], path: str | Path,
                    empty_as_nan: bool = False) -> np.ndarray:
    """Stack numeric columns ``names`` into an ``(N, len(names))`` array, or raise naming the gap.

    Parameters
    ----------
    cols : mapping
        Columns from :func:`read_csv`.
    names : sequence of str
        Columns the reader needs, each with a number on every line.
    path : str or Path
        The file, for the message.
    empty_as_nan : bool
        Take an empty cell as NaN (a file whose writer writes ``nan`` for a value it did not
        have) instead of refusing it.

    Returns
    -------
    ndarray, shape (N, len(names))

    Raises
    ------
    InputError
        A missing column, an empty cell (naming line and column), or a value that is not a
        number (naming line, column and value).
    """
    missing = [n for n in names if n not in cols]
    if missing:
        raise InputError(f"{path}: missing column(s) {', '.join(missing)} (have: {', '.join(cols)})")
    if not empty_as_nan:
        refuse_empty(cols, names, path)
    out = []
    for n in names:
        v = cols[n]
        if not isinstance(v, np.ndarray):
            bad = next((i for i, c in enumerate(v) if str(c).strip()), None)
            if bad is not None:
                raise InputError(f"{path}: line {bad + 2}: column '{n}' must be numeric, found "
                                 f"{v[bad]!r}")
            v = np.full(len(v), np.nan)
        out.append(v)
    return np.stack(out, axis=1)


def optional_column(cols: Mapping[str, Any], name: str, default: float, path: str | Path
                    ) -> NDArray[np.float64] | None:
    """A numeric column with a default per line: ``default`` where a cell is empty.

    Parameters
    ----------
    cols : mapping
        Columns from :func:`read_csv`.
    name : str
        The column.
    default : float
        The value of a line that leaves the cell empty, in the column's unit.
    path : str or Path
        The file, for the message.

    Returns
    -------
    ndarray, shape (N,), or None
        The values; None when the file has no such column.

    Raises
    ------
    InputError
        A value that is not a number, naming line and column.
    """
    if name not in cols:
        return None
    v = require_columns(cols, [name], path, empty_as_nan=True)[:, 0]
    return np.where(np.isnan(v), default, v)


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
