"""Measurement tables of a cell: where the robot base was at each touch, and which tool touched.

The mapping that turns touches taken in a cell into the robot base and world frames: column
``track`` (the robot's track position at each touch, mm) gives ``T_world_R`` per touch through the
cell's track (:func:`robot_in_world`). Tables are mappings of column name to values in the units
of the measurement CSV (mm, deg), as :func:`robotcell.io.tables.read_csv` returns them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.measurements import repeated_rows, track_column
from robotcell.cell import Cell
from robotcell.cell.kinematics import tool_pose
from robotcell.cell.validation import check_axis_limits
from robotcell.errors import InputError
from robotcell.io.tables import read_csv
from robotcell.kinematics.transforms import validate_pose

__all__ = ["POSE_COLUMNS", "Table", "line_labels", "load_table", "raw_rows", "repeat_notes",
           "robot_in_world", "tool_transform", "track_positions"]

#: A measurement table: column name (lower case) to numbers (mm, deg) or strings, one per touch.
Table = Mapping[str, Any]

#: Columns that make a touch: a flange or TCP pose (mm, deg) or the arm's joint values.
POSE_COLUMNS = ["x", "y", "z", "a", "b", "c"] + [f"a{i}" for i in range(1, 10)]


def load_table(measurements: Table | str | Path, source: str | None = None
               ) -> tuple[dict[str, Any], str]:
    """The columns of a measurement table and the name used for it in messages.

    Parameters
    ----------
    measurements : mapping or str or Path
        Columns (name to a sequence of numbers in mm/deg, or of strings), or a CSV file.
    source : str, optional
        Name of the measurements in messages and in the provenance note; default the file name,
        or ``"measurements"`` for a table.

    Returns
    -------
    cols : dict
        Lower-case column names; numeric columns as float arrays of equal length N.
    source : str
    """
    if isinstance(measurements, (str, Path)):
        return read_csv(measurements), source or str(measurements)
    source = source or "measurements"
    if not isinstance(measurements, Mapping) or not measurements:
        raise InputError(f"{source}: measurements must be a non-empty mapping of column name to "
                         "values (mm, deg), or the path of a CSV file")
    cols: dict[str, Any] = {}
    for name, values in measurements.items():
        if isinstance(values, str) or np.ndim(values) != 1:
            raise InputError(f"{source}: column {name!r} must be a sequence, one value per touch")
        values = list(values)
        try:
            arr = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            cols[str(name).strip().lower()] = [str(v) for v in values]
            continue
        if arr.ndim != 1 or not np.all(np.isfinite(arr)):
            raise InputError(f"{source}: column {name!r} must be one finite number per touch")
        cols[str(name).strip().lower()] = arr
    lengths = {len(v) for v in cols.values()}
    if len(lengths) != 1:
        raise InputError(f"{source}: the columns have different lengths {sorted(lengths)}")
    return cols, source


def raw_rows(cols: Table, names: Sequence[str]) -> NDArray[np.float64]:
    """The numeric columns among ``names`` as an (N, k) array, for the repeated-row note; no
    rows when none of them is there (the procedure then names the missing columns)."""
    use = [n for n in names if n in cols and isinstance(cols[n], np.ndarray)]
    return np.stack([cols[n] for n in use], axis=1) if use else np.zeros((0, 0))


def repeat_notes(cols: Table, names: Sequence[str], source: str) -> list[str]:
    """``note: ...`` per group of identical rows: repeated touches are data, each one used."""
    return [f"note: {n}" for n in repeated_rows(raw_rows(cols, names), source)]


def line_labels(n: int, roles: Sequence[str] | None = None) -> list[str]:
    """Names of the touches as lines of the CSV (``line 2``, ``line 3 (x)``, ...)."""
    if roles is None:
        return [f"line {i + 2}" for i in range(n)]
    return [f"line {i + 2} ({r})" for i, r in enumerate(roles)]


def tool_transform(cell: Cell | None, tool: str | ArrayLike | None,
                   cols: Table | None = None) -> NDArray[np.float64] | None:
    """``T_F_TCP`` (m) of the tool that touched: a tool of the cell by name, a pose, or None.

    With ``cols``, the measurement columns: touches given as joint values in a cell that has
    tools need the tool said, since the wrong tool (or none) moves every touch by its length,
    which no fit can tell from a bad cell.
    """
    if (tool is None and cell is not None and cell.tools and cols is not None
            and "a1" in cols and "x" not in cols):
        known = ", ".join(sorted(cell.tools))
        raise InputError(f"touches given as joint values: say which tool touched, --tool NAME "
                         f"(the cell has: {known}), or --tool 0,0,0,0,0,0 for the bare flange")
    if isinstance(tool, str):
        if cell is None:
            raise InputError(f"tool {tool!r} names a tool of a cell, but no cell was given; give "
                             "T_F_TCP as a 4x4 pose (m)")
        return tool_pose(cell, tool)
    return None if tool is None else validate_pose(tool, "tool")


def track_positions(cell: Cell, cols: Table, source: str, label: str = "the cell"
                    ) -> NDArray[np.float64] | None:
    """Column ``track`` (m), or None; refused with non-zero values in a cell without track.

    Parameters
    ----------
    cell : Cell
    cols : mapping
        Measurement columns; ``track`` in mm.
    source : str
        Name of the measurements, for messages.
    label : str
        Name of the cell in messages (its file name).

    Returns
    -------
    ndarray, shape (N,), or None
        Track position of the robot at each touch (m).
    """
    e = track_column(cols, source)
    if cell.track is None and e is not None and np.any(e != 0):
        raise InputError(f"{source}: column 'track' has non-zero values, but the cell "
                         f"{label} has no track; remove the column or add the track to "
                         "the cell file")
    if e is not None:
        check_axis_limits(cell.track, e, ["track"], source, label)
    return e


def robot_in_world(cell: Cell, cols: Table, source: str, n: int, label: str = "the cell"
                   ) -> NDArray[np.float64]:
    """``T_world_R`` at each of ``n`` touches, shape (n, 4, 4) (m), from column ``track``.

    Parameters
    ----------
    cell : Cell
    cols : mapping
        Measurement columns; ``track`` in mm, required when the robot is on a track.
    source : str
        Name of the measurements, for messages.
    n : int
        Number of touches.
    label : str
        Name of the cell in messages (its file name).
    """
    e = track_positions(cell, cols, source, label)
    if e is None:
        if cell.track is not None:
            raise InputError(
                f"{source}: missing column 'track' (track position of the robot at each "
                f"touch, mm): the robot of {label} is on a track, and the touches are "
                "mapped to the world through it; add the column (0 where the track did not "
                "move)")
        e = np.zeros(n)
    return cell.frame_pose("robot", track=e)
