"""Targets files: TCP poses in a frame, with the external axes of each target (mm, deg).

Every command and function that takes targets reads them here: ``ik --input``, ``reach``,
``sweep``, the path file of ``program write`` and the poses file of ``compensate``, and
:func:`robotcell.studies.reach.reach_map`'s callers. The format is described once, in
``docs/targets.md``: the pose columns of a vendor format (``kuka``: ``x,y,z,a,b,c`` in mm and
deg), optionally ``track`` (mm), ``table`` (deg) or a positioner's ``e1..en`` (deg), ``name``,
and the columns a caller reads itself (motion, configuration flags, ...).

:func:`read_targets` returns them in SI units (:class:`Targets`); what the values must satisfy
in a cell (the axis limits) is for the caller to check, since a command may warn where a
program writer refuses.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotcell.errors import InputError
from robotcell.io.poseformats import FORMATS, pose_from_vendor
from robotcell.io.tables import (
    CELL_EXTENT_MM,
    outside_limits,
    read_csv_lines,
    refuse_empty,
    require_columns,
    unknown_columns,
)

__all__ = ["ANY_TABLE", "Targets", "axis_columns", "read_targets", "target_poses"]

#: ``table`` of :func:`read_targets` for a reader without a cell: ``table`` or ``e1..en``,
#: as the file has them.
ANY_TABLE = "any"

_AXIS = re.compile(r"e([1-9][0-9]*)")


@dataclass(frozen=True)
class Targets:
    """The targets of a file, in SI units.

    Attributes
    ----------
    poses : ndarray, shape (N, 4, 4)
        TCP targets ``T_X_TCP`` in the file's frame (m).
    track : ndarray, shape (N,), or None
        Track positions (m) from column ``track``; None: the file has none.
    table : ndarray, shape (N,) or (N, n), or None
        Turntable angles (column ``table``) or a positioner's axis values (columns
        ``e1..en``), rad; None: the file has none.
    table_columns : tuple of str
        The columns ``table`` came from: ``()``, ``("table",)`` or ``("e1", ..., "en")``.
    names : list of str or None
        Column ``name``: a name per target (``""`` where a line leaves it empty).
    extra : dict of str to ndarray or list of str
        The caller's further columns (``extra`` of :func:`read_targets`) that the file has, as
        :func:`robotcell.io.tables.read_csv` reads them (mm, deg, text).
    lines : ndarray of int, shape (N,)
        The file's line of each target, for messages.
    source : str
        The file, for messages.
    warnings : list of str
        Columns the reader does not use (misspelt?), one message.
    """

    poses: NDArray[np.float64]
    track: NDArray[np.float64] | None = None
    table: NDArray[np.float64] | None = None
    table_columns: tuple[str, ...] = ()
    names: list[str] | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    lines: NDArray[np.intp] = field(default_factory=lambda: np.empty(0, dtype=np.intp))
    source: str = ""
    warnings: list[str] = field(default_factory=list)

    def __len__(self) -> int:
        return self.poses.shape[0]


def target_poses(values: NDArray[np.float64], fmt: str, source: str) -> NDArray[np.float64]:
    """Poses (m) from values of vendor format ``fmt`` (mm, deg), refusing a position beyond
    the size of any real cell.

    Parameters
    ----------
    values : ndarray, shape (N, k) or (k,)
        The format's fields per target (a file's rows, or one option's values).
    fmt : str
        A format of :data:`robotcell.io.poseformats.FORMATS`.
    source : str
        The file (rows: named by line and column) or the option (one pose: named by field).

    Returns
    -------
    ndarray, shape (N, 4, 4) or (4, 4)

    Raises
    ------
    InputError
        A position beyond :data:`robotcell.io.tables.CELL_EXTENT_MM` (no target is that far).
    """
    f = FORMATS[fmt]
    limit = CELL_EXTENT_MM * 1e-3 / f.length_scale
    unit = "m" if f.length_scale == 1.0 else "mm"
    v = np.asarray(values, dtype=float)
    names = [n.lower() for n in f.fields[:3]]
    bad = outside_limits(np.atleast_2d(v)[:, :3], names, [-limit] * 3, [limit] * 3, [unit] * 3,
                         lines=v.ndim == 2)
    if bad is not None:
        raise InputError(f"{source}: a target beyond {CELL_EXTENT_MM * 1e-3:g} m, the size of any "
                         f"real cell: {bad}; correct the value (a typing or unit error?)")
    return pose_from_vendor(v, fmt)


def _table_names(cols: Mapping[str, Any], table: Sequence[str] | str | None, source: str,
                 positioner: str) -> tuple[str, ...]:
    """The table columns to read: those of ``table`` (all of them, or none), refusing a table
    column of another kind of table."""
    axes = sorted((c for c in cols if _AXIS.fullmatch(c)), key=lambda c: int(c[1:]))
    if table is None:
        return ()
    if table == ANY_TABLE:
        if "table" in cols and axes:
            raise InputError(f"{source}: columns table and {', '.join(axes)}: give one or the "
                             "other (a turntable's angle, or a positioner's axes)")
        return ("table",) if "table" in cols else tuple(f"e{i + 1}" for i in range(len(axes)))
    names = tuple(table)
    foreign = [c for c in (*(["table"] if "table" in cols else []), *axes) if c not in names
               and (c == "table" or not names or names == ("table",))]
    if foreign and names and names != ("table",):
        raise InputError(f"{source}: column 'table' holds a turntable angle; {positioner} has "
                         f"{len(names)} axes: give columns {', '.join(names)} (deg)")
    if foreign:
        what = ("the cell has no turntable" if not names
                else "the cell's table axes are column(s) table")
        raise InputError(f"{source}: column '{foreign[0]}', but {what}; leave it out")
    given = [c for c in names if c in cols]
    if given and len(given) != len(names):
        missing = ", ".join(c for c in names if c not in cols)
        raise InputError(f"{source}: {positioner} has {len(names)} axes: missing column(s) "
                         f"{missing} (deg)")
    return names if given else ()


def axis_columns(cols: Mapping[str, Any], source: str, track: bool = True,
                 table: Sequence[str] | str | None = ANY_TABLE,
                 positioner: str = "the positioner"
                 ) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None,
                            tuple[str, ...]]:
    """The external axis columns of a table: ``track`` (mm) and ``table`` or ``e1..en`` (deg).

    Parameters
    ----------
    cols : mapping
        Columns from :func:`robotcell.io.tables.read_csv`.
    source : str
        The file, for messages.
    track : bool
        Read column ``track``; False: the reader has no use for it.
    table : sequence of str, ``"any"`` or None
        The table columns of the cell the values are for: ``()`` (no table: a table column is
        refused), ``("table",)`` (a turntable), ``("e1", ..., "en")`` (a positioner: every
        axis or none); ``"any"`` (:data:`ANY_TABLE`): ``table`` or ``e1..en``, as the file has
        them; None: the reader has no use for them.
    positioner : str
        The positioner, for messages (``"positioner 'DKP_2'"``).

    Returns
    -------
    track : ndarray, shape (N,), or None
        Track positions (m); None without the column.
    table : ndarray, shape (N,) or (N, n), or None
        Table angles or positioner axis values (rad); None without the columns.
    table_columns : tuple of str
        The columns ``table`` came from.

    Raises
    ------
    InputError
        An empty or non-numeric value (naming line and column), a table column of another kind
        of table than the cell's, a positioner's axis missing.
    """
    track_m = None
    if track and "track" in cols:
        refuse_empty(cols, ["track"], source, optional=True)
        track_m = require_columns(cols, ["track"], source)[:, 0] * 1e-3
    names = _table_names(cols, table, source, positioner)
    if not names:
        return track_m, None, ()
    refuse_empty(cols, names, source, optional=True)
    values = np.radians(require_columns(cols, names, source))
    return track_m, (values[:, 0] if names == ("table",) else values), names


def read_targets(path: str | Path, fmt: str = "kuka", *, track: bool = True,
                 table: Sequence[str] | str | None = ANY_TABLE,
                 positioner: str = "the positioner", extra: Sequence[str] = (),
                 reader: str = "this command") -> Targets:
    """Read a targets file (``docs/targets.md``).

    Parameters
    ----------
    path : str or Path
        CSV with a header.
    fmt : str
        The pose columns: a format of :data:`robotcell.io.poseformats.FORMATS` (``kuka``:
        ``x,y,z,a,b,c`` in mm and deg, ``R = Rz(a) Ry(b) Rx(c)``).
    track, table, positioner
        Which external axis columns are read, as for :func:`axis_columns`.
    extra : sequence of str
        Further columns the caller reads itself (motion, configuration flags, ...): returned
        in :attr:`Targets.extra` when the file has them, and not named as unused.
    reader : str
        What reads the file, for the warning about columns not used.

    Returns
    -------
    Targets

    Raises
    ------
    InputError
        As :func:`robotcell.io.tables.read_csv` and :func:`axis_columns`; a missing pose column,
        an empty or non-numeric pose value, a position beyond 100 m; each message names the
        file, and the line and column where there is one.
    """
    p = str(path)
    cols, lines = read_csv_lines(path)
    poses_names = [f.lower() for f in FORMATS[fmt].fields]
    e, th, tcols = axis_columns(cols, p, track, table, positioner)
    tables = (() if table is None else ("table", *(c for c in cols if _AXIS.fullmatch(c)))
              if table == ANY_TABLE else tuple(table))
    known = [*poses_names, *(["track"] if track else []), *tables, "name", *extra]
    unknown = unknown_columns(cols, known)
    said = f"{p}: column(s) {', '.join(unknown)} not used by {reader} and ignored"
    warnings = [f"{said}; check the spelling"] if unknown else []
    T = target_poses(require_columns(cols, poses_names, p), fmt, p)
    names = [str(v).strip() for v in cols["name"]] if "name" in cols else None
    given = {k: cols[k] for k in extra if k in cols}
    return Targets(T, e, th, tcols, names, given, lines, p, warnings)
