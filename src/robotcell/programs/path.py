"""A path to program: TCP targets in a frame of the cell, with how to move to each.

The path file is CSV with a header (millimetres, degrees; ``docs/programs.md``):

| column | | meaning |
|---|---|---|
| ``x, y, z`` | required | TCP position in the frame (mm) |
| ``a, b, c`` | required | TCP orientation, ``R = Rz(a) Ry(b) Rx(c)`` (deg), the cell's convention |
| ``motion`` | optional | ``ptp`` or ``lin`` (default: ``ptp`` to the first point, ``lin`` after) |
| ``speed`` | optional | TCP speed of a linear motion (mm/s; default 100) |
| ``zone`` | optional | corner distance (mm; default 0, an exact stop) |
| ``track`` | optional | track position (mm); otherwise chosen along the path |
| ``table`` | optional | turntable angle (deg); a positioner's axes are ``e1..en`` (see below) |

Without ``table`` (or ``e1..en``) the writer chooses the table's values along a path in a frame
the table carries (:func:`robotcell.cell.tablechoice.choose_table`); a path in another frame
keeps the table at 0.

A line may leave ``motion``, ``speed`` or ``zone`` empty: it takes the default above. The pose
columns, and ``track`` and the table's columns when the file has them, need a value on every
line (a track or table value has no default for one line alone).

:func:`read_path` reads it into SI units and checks every value against the cell.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from robotcell.cell import Cell, Positioner
from robotcell.controllers.model import MOTIONS
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor
from robotcell.io.tables import (
    optional_column,
    read_csv,
    refuse_empty,
    require_columns,
    unknown_columns,
)

__all__ = ["DEFAULT_SPEED", "PathTargets", "read_path", "table_columns"]

#: TCP speed of linear motions when the path gives none (m/s).
DEFAULT_SPEED = 0.1

_POSE = ("x", "y", "z", "a", "b", "c")
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

    def __len__(self) -> int:
        return self.T.shape[0]


def table_columns(cell: Cell) -> list[str]:
    """The path's table columns for ``cell``: ``table``, a positioner's ``e1..en``, or none."""
    tt = cell.turntable
    if tt is None:
        return []
    if isinstance(tt, Positioner):
        return [f"e{i + 1}" for i in range(tt.n_axes)]
    return ["table"]


def _numeric(cols: dict, name: str, path: str) -> NDArray[np.float64]:
    return require_columns(cols, [name], path)[:, 0]


def _limits(values: NDArray[np.float64], lo: float, hi: float, what: str, unit: float,
            path: str, column: str) -> None:
    bad = np.flatnonzero((values < lo) | (values > hi))
    if bad.size:
        i = int(bad[0])
        raise InputError(f"{path}: line {i + 2}: column '{column}' has {values[i] * unit:g}, "
                         f"outside the {what} limits [{lo * unit:g}, {hi * unit:g}]")


def read_path(path: str | Path, cell: Cell, extra: tuple[str, ...] = ()) -> PathTargets:
    """Read a path file for ``cell``.

    Parameters
    ----------
    path : str or Path
        CSV with the columns of the module's table.
    cell : Cell
        Says which external axis columns exist and their limits.
    extra : tuple of str
        Further columns the caller reads itself (not named as unused).

    Returns
    -------
    PathTargets

    Raises
    ------
    InputError
        A missing pose column, an empty pose, track or table value, a non-numeric value, an
        unknown motion, a speed that is not positive, a negative zone, a track or table column
        for a cell without one, or a value outside the track's or table's limits; the message
        names the file, line and column.
    """
    p = str(path)
    cols = read_csv(path)
    tcols = table_columns(cell)
    known = [*_POSE, "motion", "speed", "zone", "track", *tcols, "name", *extra]
    warnings = [f"{p}: column(s) {', '.join(unknown)} not used and ignored; check the spelling"
                for unknown in [unknown_columns(cols, known)] if unknown]
    T = pose_from_vendor(require_columns(cols, _POSE, p), "kuka")
    n = T.shape[0]
    motion = _motion(cols, n, p)
    speed = optional_column(cols, "speed", DEFAULT_SPEED * 1e3, p)
    speed = np.full(n, DEFAULT_SPEED) if speed is None else speed * 1e-3
    bad = np.flatnonzero(~(speed > 0))
    if bad.size:
        raise InputError(f"{p}: line {bad[0] + 2}: column 'speed' must be positive (mm/s)")
    zone = optional_column(cols, "zone", 0.0, p)
    zone = np.zeros(n) if zone is None else zone * 1e-3
    bad = np.flatnonzero(zone < 0)
    if bad.size:
        raise InputError(f"{p}: line {bad[0] + 2}: column 'zone' must not be negative (mm)")
    track = None
    if "track" in cols:
        if cell.track is None:
            raise InputError(f"{p}: column 'track', but the cell has no track; leave it out")
        refuse_empty(cols, ["track"], p, optional=True)
        track = _numeric(cols, "track", p) * 1e-3
        _limits(track, cell.track.lower, cell.track.upper, "track", 1e3, p, "track")
    table = _table(cols, cell, n, p)
    given = cell.turntable is None or any(c in cols for c in tcols)
    return PathTargets(T, motion, speed, zone, track, table, given, p, warnings)


def _motion(cols: dict, n: int, path: str) -> list[str]:
    """Column ``motion`` as ``ptp``/``lin`` per target; a line that leaves it empty, or a file
    without it, moves ``ptp`` to the first target and ``lin`` after it."""
    default = ["ptp"] + ["lin"] * (n - 1)
    if "motion" not in cols:
        return default
    motion = []
    for i, word in enumerate(cols["motion"]):
        key = "" if isinstance(word, float) and np.isnan(word) else str(word).strip().lower()
        if key and key not in _MOTION_WORDS:
            raise InputError(f"{path}: line {i + 2}: column 'motion' has {word!r}; use one of "
                             f"{', '.join(MOTIONS)}")
        motion.append(_MOTION_WORDS[key] if key else default[i])
    return motion


def _table(cols: dict, cell: Cell, n: int, path: str) -> NDArray[np.float64]:
    tt = cell.turntable
    names = table_columns(cell)
    foreign = [c for c in ("table", "e1", "e2", "e3") if c in cols and c not in names]
    if foreign:
        what = ("the cell has no turntable" if tt is None else
                f"the cell's table axes are column(s) {', '.join(names)}")
        raise InputError(f"{path}: column '{foreign[0]}', but {what}")
    if tt is None:
        return np.zeros(n)
    given = [c for c in names if c in cols]
    if not given:
        return np.zeros((n, len(names))) if isinstance(tt, Positioner) else np.zeros(n)
    if len(given) != len(names):
        missing = ", ".join(c for c in names if c not in cols)
        raise InputError(f"{path}: positioner {tt.name!r} has {len(names)} axes: missing "
                         f"column(s) {missing} (deg)")
    refuse_empty(cols, names, path, optional=True)
    values = np.column_stack([np.radians(_numeric(cols, c, path)) for c in names])
    lo, hi = np.atleast_1d(tt.lower), np.atleast_1d(tt.upper)
    for j, c in enumerate(names):
        _limits(values[:, j], lo[j], hi[j], f"{c} axis" if len(names) > 1 else "table",
                180 / np.pi, path, c)
    return values if isinstance(tt, Positioner) else values[:, 0]
