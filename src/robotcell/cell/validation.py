"""Checks of values given for a cell: axis values against the axis limits, lengths against the
size of any real cell.

- :func:`check_axis_limits`: track positions and table or positioner axis values of a table of
  touches or targets against the limits of the cell's track, turntable or positioner, named by
  line and column (mm, deg).
- :func:`table_columns`, :func:`table_label`: the columns of a file that hold the table's values
  for the cell, and how messages name its positioner
  (:func:`robotcell.io.targets.read_targets`).
- :func:`check_lengths`: every position of a cell (frames, tools, track, turntable, positioner)
  within :data:`~robotcell.io.tables.CELL_EXTENT_MM` (100 m) of its parent, named by its key in
  the cell file: a frame 1e308 mm away is a typing or unit error, and no computation with it
  means anything.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence

import numpy as np
from numpy.typing import ArrayLike

from robotcell.cell.kinematics import CellModel
from robotcell.cell.parts import Positioner, Track, Turntable
from robotcell.errors import InputError
from robotcell.io.tables import CELL_EXTENT_MM, MAX_ABS_VALUE, outside_limits

__all__ = ["SCALE_RANGE", "axis_limit_violation", "axis_range", "check_axis_limits",
           "check_lengths", "table_columns", "table_label"]

#: Track scales (displacement per unit of the controller's track value) a real track has: a
#: factor 10 from 1 is a unit error.
SCALE_RANGE = (0.1, 10.0)


def table_columns(cell: CellModel) -> tuple[str, ...]:
    """The columns of a targets or joints file that hold the table's values for ``cell``.

    Returns
    -------
    tuple of str
        ``()`` for a cell without a table, ``("table",)`` for a turntable (deg),
        ``("e1", ..., "en")`` for a positioner of n axes (deg).
    """
    tt = cell.turntable
    if tt is None:
        return ()
    if isinstance(tt, Positioner):
        return tuple(f"e{i + 1}" for i in range(tt.n_axes))
    return ("table",)


def table_label(cell: CellModel) -> str:
    """The cell's positioner as messages name it (``"positioner 'DKP_2'"``)."""
    tt = cell.turntable
    return f"positioner {tt.name!r}" if isinstance(tt, Positioner) else "the positioner"


def axis_range(axis: Track | Turntable | Positioner) -> tuple[np.ndarray, np.ndarray]:
    """The values an axis can take (SI): its limits; a track's also within 100 m
    (:data:`~robotcell.io.tables.CELL_EXTENT_MM`), whether or not the cell file gives limits."""
    lower, upper = np.asarray(axis.lower, dtype=float), np.asarray(axis.upper, dtype=float)
    if isinstance(axis, Track):
        extent = CELL_EXTENT_MM * 1e-3
        return np.maximum(lower, -extent), np.minimum(upper, extent)
    return lower, upper


def axis_limit_violation(axis: Track | Turntable | Positioner | None, values: ArrayLike,
                         columns: Sequence[str], source: str, label: str = "the cell",
                         limits: bool = True) -> str | None:
    """What :func:`check_axis_limits` refuses, as a message, or None.

    Parameters
    ----------
    axis, values, columns, source, label
        As for :func:`check_axis_limits`.
    limits : bool
        True: the axis limits (:func:`axis_range`); False: only the 100 m within which any track
        ends (:data:`~robotcell.io.tables.CELL_EXTENT_MM`), beyond which a value is a typing
        error (a table or positioner has no such bound: None).

    Returns
    -------
    str or None
        ``"<source>: values outside the limits of the track 'KL1500' of <label>: line 3,
        column 'track': 7000 mm (limits 0 .. 6000 mm)"``, or None when every value is within.
    """
    if axis is None or not (limits or isinstance(axis, Track)):
        return None
    track = isinstance(axis, Track)
    scale, unit = (1e3, "mm") if track else (180.0 / math.pi, "deg")
    k = len(columns)
    lo, hi = axis_range(axis)
    if not limits:
        lo, hi = -CELL_EXTENT_MM * 1e-3, CELL_EXTENT_MM * 1e-3
    lower = np.broadcast_to(lo * scale, (k,))
    upper = np.broadcast_to(hi * scale, (k,))
    v = np.asarray(values, dtype=float).reshape(-1, k) * scale
    bad = outside_limits(v, columns, lower, upper, [unit] * k)
    if bad is None:
        return None
    what = "track" if track else ("turntable" if isinstance(axis, Turntable) else "positioner")
    return f"{source}: values outside the limits of the {what} {axis.name!r} of {label}: {bad}"


def check_axis_limits(axis: Track | Turntable | Positioner | None, values: ArrayLike,
                      columns: Sequence[str], source: str, label: str = "the cell") -> None:
    """Refuse axis values of a table outside the limits of the cell's axis.

    Parameters
    ----------
    axis : Track or Turntable or Positioner or None
        The axis the values belong to; None: nothing to check.
    values : array_like, shape (N,) or (N, n_axes)
        Track positions (m) or table / positioner axis values (rad), one row per line of the
        table (row ``i`` is line ``i + 2``).
    columns : sequence of str
        The columns they come from (``track``, ``e1``, ``e1, e2``), for the message.
    source : str
        Name of the table (its file), for the message.
    label : str
        Name of the cell (its file), for the message.

    Raises
    ------
    InputError
        Naming the line and column of the first values outside the limits (mm or deg), a
        track's within 100 m (:func:`axis_range`).
    """
    bad = axis_limit_violation(axis, values, columns, source, label)
    if bad is not None:
        raise InputError(f"{bad}. The axis cannot move there: correct the value (a typing or "
                         "unit error?), or the limits in the cell file")


def _pose(key: str, T: np.ndarray) -> Iterator[tuple[str, float]]:
    for i, c in enumerate("xyz"):
        yield f"{key}.{c}", float(T[i, 3])


def _lengths(cell: CellModel) -> Iterator[tuple[str, float]]:
    """Every length of ``cell`` (m) with the key of the cell file that holds it."""
    if cell.track is None:
        yield from _pose("robot.frame", cell.T_world_R)
    else:
        t = cell.track
        yield from _pose("track.frame", t.T_world_L)
        yield from _pose("track.robot_at_zero", t.T_L_R0)
        for key, v in (("track.min", t.lower), ("track.max", t.upper)):
            if math.isfinite(v):
                yield key, v
    tt = cell.turntable
    if isinstance(tt, Turntable):
        yield from _pose("turntable.frame", tt.T_parent_B)
    elif isinstance(tt, Positioner):
        yield from _pose("positioner.frame", tt.T_parent_root)
        yield from _pose("positioner.plate", tt.chain.flange)
    for name, tool in cell.tools.items():
        yield from _pose(f"tools.{name}.frame", tool.T_F_TCP)
        if tool.cog is not None:
            for i, c in enumerate("xyz"):
                yield f"tools.{name}.cog[{i}]", float(tool.cog[i])
    for name, fr in cell.frames.items():
        yield from _pose(f"frames.{name}.frame", fr.pose)


def check_lengths(cell: CellModel, origin: str = "cell") -> None:
    """Refuse a cell with a length beyond the size of any real cell, or an implausible scale.

    Parameters
    ----------
    cell : CellModel
        A cell as read from a file (SI units): a :class:`~robotcell.cell.model.Cell`.
    origin : str
        The file, for the message.

    Raises
    ------
    InputError
        Naming the key of the cell file (``turntable.frame.y``), its value in mm and the bound:
        a track scale within :data:`SCALE_RANGE`, every length of a pose within
        :data:`~robotcell.io.tables.CELL_EXTENT_MM` of its parent (a track's limits and a
        tool's centre of mass included), and a positioner's DH ``a`` and ``d`` within
        :data:`~robotcell.io.tables.MAX_ABS_VALUE` (the ``d`` of nearly parallel axes is far
        longer than the positioner).
    """
    if cell.track is not None and not SCALE_RANGE[0] <= cell.track.scale <= SCALE_RANGE[1]:
        raise InputError(f"{origin}: key 'track.scale' is {cell.track.scale:g}, outside "
                         f"{SCALE_RANGE[0]:g} .. {SCALE_RANGE[1]:g}: a real track moves about 1 "
                         "mm per mm of its axis value; a factor this far from 1 is a unit error")
    for key, v in _lengths(cell):
        if not abs(v) * 1e3 <= CELL_EXTENT_MM:
            raise InputError(f"{origin}: key '{key}' is {v * 1e3:g} mm, beyond "
                             f"{CELL_EXTENT_MM / 1e3:g} m, the size of any real robot cell: a "
                             "typing or unit error (the cell file is in mm)")
    if isinstance(cell.turntable, Positioner):
        for i, j in enumerate(cell.turntable.chain.joints, start=1):
            for k, v in (("a", j.a), ("d", j.d)):
                if not abs(v) * 1e3 <= MAX_ABS_VALUE:
                    raise InputError(f"{origin}: key 'positioner.axes[{i}].{k}' is {v * 1e3:g} "
                                     f"mm, beyond {MAX_ABS_VALUE:.0e} mm: a typing error")
