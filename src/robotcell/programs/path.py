"""A path to program: TCP targets in a frame of the cell, with how to move to each.

The path file is a targets file (``docs/targets.md``, read by
:func:`robotcell.io.targets.read_targets`: ``x, y, z`` mm, ``a, b, c`` deg, optional ``track``
mm and ``table`` or ``e1..en`` deg, ``name``) with the columns of a motion
(``docs/programs.md``):

| column | | meaning |
|---|---|---|
| ``motion`` | optional | ``ptp`` or ``lin`` (default: ``ptp`` to the first point, ``lin`` after) |
| ``speed`` | optional | TCP speed of a linear motion (mm/s; default 100) |
| ``zone`` | optional | corner distance (mm; default 0, an exact stop) |
| ``time`` | optional | when the point is reached (s, increasing; ``pathtime``) |

Without ``track`` the track is chosen along the path. Without ``table`` (or ``e1..en``) the
writer chooses the table's values along a path in a frame the table carries
(:func:`robotcell.cell.tablechoice.choose_table`); a path in another frame keeps the table at 0.

A line may leave ``motion``, ``speed`` or ``zone`` empty: it takes the default above.

:func:`read_path` reads it into SI units and checks every value against the cell.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from robotcell.cell import Cell, Positioner
from robotcell.cell.validation import table_columns, table_label
from robotcell.controllers.model import MOTIONS
from robotcell.errors import InputError
from robotcell.io.tables import optional_column, require_columns
from robotcell.io.targets import read_targets

__all__ = ["DEFAULT_SPEED", "TIME_TOL", "PathTargets", "read_path"]

#: TCP speed of linear motions when the path gives none (m/s).
DEFAULT_SPEED = 0.1

_MOTION = ("motion", "speed", "zone", "time")
_MOTION_WORDS = {"ptp": "ptp", "lin": "lin", "j": "ptp", "l": "lin", "joint": "ptp",
                 "linear": "lin", "movej": "ptp", "movel": "lin"}


@dataclass
class PathTargets:
    """A path in SI units.

    Attributes
    ----------
    T : ndarray, shape (N, 4, 4)
        TCP targets in the path's frame (m).
    motion : list of str
        ``ptp`` or ``lin`` per target.
    speed : ndarray, shape (N,)
        TCP speed of linear motions (m/s).
    zone : ndarray, shape (N,)
        Corner distance (m).
    track : ndarray, shape (N,), or None
        Track positions (m), or None to choose them.
    table : ndarray, shape (N,) or (N, n)
        Turntable angles or positioner axis values (rad).
    table_given : bool
        The file gives the table's values; False: ``table`` is 0, for the writer to choose
        where the path's frame is on the table (:func:`robotcell.cell.tablechoice.choose_table`).
    source : str
        The file, for messages.
    warnings : list of str
        Columns the reader does not use (misspelt?).
    extra : dict of str to ndarray or list of str
        The caller's further columns (``extra`` of :func:`read_path`) the file has, as read.
    time : ndarray, shape (N,), or None
        When each point is reached (s, increasing), from column ``time``; None: no times.
    lines : ndarray of int, shape (N,), or None
        The file's line of each point, for messages (0: a point the file does not hold, put
        between two of its points; None: unknown).
    """

    T: NDArray[np.float64]
    motion: list[str]
    speed: NDArray[np.float64]
    zone: NDArray[np.float64]
    track: NDArray[np.float64] | None
    table: NDArray[np.float64]
    table_given: bool = True
    source: str = ""
    warnings: list[str] = field(default_factory=list)
    extra: dict = field(default_factory=dict)
    time: NDArray[np.float64] | None = None
    lines: NDArray[np.intp] | None = None

    def line(self, i: int) -> str:
        """Where point ``i`` is, for messages: ``file: line L``, or ``file: at T s`` for a
        point the file does not hold."""
        if self.lines is not None and self.lines[i] > 0:
            return f"{self.source}: line {self.lines[i]}"
        if self.time is not None:
            return f"{self.source}: at {self.time[i]:g} s (between two of its points)"
        return f"{self.source}: line {i + 2}"

    def __len__(self) -> int:
        return self.T.shape[0]


def _limits(values: NDArray[np.float64], lo: float, hi: float, what: str, unit: float,
            lines: NDArray[np.intp], path: str, column: str) -> None:
    bad = np.flatnonzero((values < lo) | (values > hi))
    if bad.size:
        i = int(bad[0])
        raise InputError(f"{path}: line {lines[i]}: column '{column}' has {values[i] * unit:g}, "
                         f"outside the {what} limits [{lo * unit:g}, {hi * unit:g}]")


def read_path(path: str | Path, cell: Cell, extra: tuple[str, ...] = ()) -> PathTargets:
    """Read a path file for ``cell``.

    Parameters
    ----------
    path : str or Path
        A targets file (:func:`robotcell.io.targets.read_targets`) with the columns of the
        module's table.
    cell : Cell
        Says which external axis columns exist and their limits.
    extra : tuple of str
        Further columns the caller reads itself (not named as unused; in
        :attr:`PathTargets.extra`).

    Returns
    -------
    PathTargets

    Raises
    ------
    InputError
        A missing pose column, an empty pose, track, table or time value, a non-numeric value,
        an unknown motion, a speed that is not positive, a negative zone, times that do not
        increase, a track or table column
        for a cell without one, or a value outside the track's or table's limits; the message
        names the file, line and column.
    """
    t = read_targets(path, "kuka", table=table_columns(cell), positioner=table_label(cell),
                     extra=(*_MOTION, *extra))
    p, cols, n = t.source, t.extra, len(t)
    motion = _motion(cols, t.lines, p)
    speed = optional_column(cols, "speed", DEFAULT_SPEED * 1e3, p)
    speed = np.full(n, DEFAULT_SPEED) if speed is None else speed * 1e-3
    bad = np.flatnonzero(~(speed > 0))
    if bad.size:
        raise InputError(f"{p}: line {t.lines[bad[0]]}: column 'speed' must be positive (mm/s)")
    zone = optional_column(cols, "zone", 0.0, p)
    zone = np.zeros(n) if zone is None else zone * 1e-3
    bad = np.flatnonzero(zone < 0)
    if bad.size:
        raise InputError(f"{p}: line {t.lines[bad[0]]}: column 'zone' must not be negative (mm)")
    if t.track is not None:
        if cell.track is None:
            raise InputError(f"{p}: column 'track', but the cell has no track; leave it out")
        _limits(t.track, cell.track.lower, cell.track.upper, "track", 1e3, t.lines, p, "track")
    table = _table(t.table, cell, n, t.lines, p)
    given = cell.turntable is None or t.table is not None
    return PathTargets(t.poses, motion, speed, zone, t.track, table, given, p, t.warnings,
                       {k: v for k, v in cols.items() if k in extra}, _time(cols, t.lines, p),
                       t.lines)


#: Smallest step between two times of a path (s): closer times are one time.
TIME_TOL = 1e-6


def _time(cols: dict, lines: NDArray[np.intp], path: str) -> NDArray[np.float64] | None:
    """Column ``time`` (s), each value given, finite and later than the one before by more
    than :data:`TIME_TOL`; None without the column."""
    if "time" not in cols:
        return None
    t = require_columns(cols, ["time"], path)[:, 0]
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise InputError(f"{path}: line {lines[bad[0]]}: column 'time' must be a finite number "
                         "(s)")
    bad = np.flatnonzero(np.diff(t) <= TIME_TOL)
    if bad.size:
        i = int(bad[0]) + 1
        raise InputError(f"{path}: line {lines[i]}: column 'time' has {t[i]:g} s, not later than "
                         f"{t[i - 1]:g} s of the line before; the times of a path increase")
    return t


def _motion(cols: dict, lines: NDArray[np.intp], path: str) -> list[str]:
    """Column ``motion`` as ``ptp``/``lin`` per target; a line that leaves it empty, or a file
    without it, moves ``ptp`` to the first target and ``lin`` after it."""
    default = ["ptp"] + ["lin"] * (len(lines) - 1)
    if "motion" not in cols:
        return default
    motion = []
    for i, word in enumerate(cols["motion"]):
        key = "" if isinstance(word, float) and np.isnan(word) else str(word).strip().lower()
        if key and key not in _MOTION_WORDS:
            raise InputError(f"{path}: line {lines[i]}: column 'motion' has {word!r}; use one of "
                             f"{', '.join(MOTIONS)}")
        motion.append(_MOTION_WORDS[key] if key else default[i])
    return motion


def _table(values: NDArray[np.float64] | None, cell: Cell, n: int, lines: NDArray[np.intp],
           path: str) -> NDArray[np.float64]:
    """The table's values of the path (rad), each within the limits of its axis; 0 where the
    file gives none."""
    tt = cell.turntable
    names = table_columns(cell)
    if values is None:
        return np.zeros((n, len(names))) if isinstance(tt, Positioner) else np.zeros(n)
    v = values.reshape(n, -1)
    lo, hi = np.atleast_1d(tt.lower), np.atleast_1d(tt.upper)
    for j, c in enumerate(names):
        _limits(v[:, j], lo[j], hi[j], f"{c} axis" if len(names) > 1 else "table",
                180 / np.pi, lines, path, c)
    return values
