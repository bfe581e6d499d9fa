"""Measurement tables of a cell: read once, where the robot base was at each touch, which tool.

A calibration reads its measurements once (:func:`read_touches`): a CSV file through
:func:`robotcell.io.tables.read_csv`, or a table given in Python (column name to values in the
units of the measurement CSV, mm and deg), by the procedure's specification into
:class:`~robotcell.calibration.measurements.TouchTable` (SI). The mapping that turns touches
taken in a cell into the robot base and world frames: the robot's track position at each touch
(column ``track``) gives ``T_world_R`` per touch through the cell's track (:func:`robot_in_world`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.measurements import TouchTable, columns_of, read_touch_table
from robotcell.calibration.spec import SPECS, TableSpec
from robotcell.cell import Cell
from robotcell.cell.kinematics import tool_pose
from robotcell.cell.validation import check_axis_limits
from robotcell.errors import InputError, term
from robotcell.io.tables import read_csv
from robotcell.kinematics.transforms import validate_pose
from robotcell.robot.robot import Robot

__all__ = ["MeasurementInput", "Table", "load_table", "read_touches", "robot_in_world",
           "tool_transform", "track_positions"]

#: A measurement table: column name (lower case) to numbers (mm, deg) or strings, one per touch.
Table = Mapping[str, Any]

#: What a calibration takes as its measurements: read touches, a table, or a CSV file.
MeasurementInput = TouchTable | Table | str | Path


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
    return columns_of(measurements, source), source


def read_touches(procedure: TableSpec | str, measurements: MeasurementInput,
                 source: str | None = None, robot: Robot | None = None,
                 on_note: Callable[[str], None] | None = None) -> TouchTable:
    """The measurements of a calibration, read once by the procedure's specification.

    Parameters
    ----------
    procedure : TableSpec or str
        The procedure (:data:`~robotcell.calibration.spec.SPECS`).
    measurements : TouchTable, mapping, str or Path
        Touches read before (returned as they are; their notes go to ``on_note`` again), a
        table, or a CSV file.
    source : str, optional
        As for :func:`load_table`.
    robot : Robot, optional
        The arm, for joint values.
    on_note : callable, optional
        Receives each note on the table as it arises
        (:func:`~robotcell.calibration.measurements.read_touch_table`).

    Returns
    -------
    TouchTable
    """
    spec = SPECS[procedure] if isinstance(procedure, str) else procedure
    if isinstance(measurements, TouchTable):
        if measurements.procedure.name != spec.name:
            raise InputError(f"{measurements.source}: touches of the "
                             f"{measurements.procedure.name} procedure, not of {spec.name}")
        for note in measurements.notes:
            if on_note is not None:
                on_note(note)
        return measurements
    cols, source = load_table(measurements, source)
    return read_touch_table(spec, cols, source, robot, on_note)


def tool_transform(cell: Cell | None, tool: str | ArrayLike | None,
                   touches: TouchTable | None = None) -> NDArray[np.float64] | None:
    """``T_F_TCP`` (m) of the tool that touched: a tool of the cell by name, a pose, or None.

    With ``touches``: touches given as joint values in a cell that has tools need the tool said,
    since the wrong tool (or none) moves every touch by its length, which no fit can tell from a
    bad cell.
    """
    if (tool is None and cell is not None and cell.tools and touches is not None
            and touches.joints is not None):
        known = ", ".join(sorted(cell.tools))
        raise InputError(f"touches given as joint values: say which tool touched, "
                         f"{term('tool=NAME', 'tool=NAME')} (the cell has: {known}), or "
                         f"{term('tool=flange', 'tool=numpy.eye(4)')} for the bare flange")
    if isinstance(tool, str):
        if cell is None:
            raise InputError(f"tool {tool!r} names a tool of a cell, but no cell was given; give "
                             "T_F_TCP as a 4x4 pose (m)")
        return tool_pose(cell, tool)
    return None if tool is None else validate_pose(tool, "tool")


def track_positions(cell: Cell, touches: TouchTable, label: str = "the cell"
                    ) -> NDArray[np.float64] | None:
    """Column ``track`` (m), or None; refused with non-zero values in a cell without track.

    Parameters
    ----------
    cell : Cell
    touches : TouchTable
        The touches; ``track`` the robot's track position at each (m).
    label : str
        Name of the cell in messages (its file name).

    Returns
    -------
    ndarray, shape (N,), or None
        Track position of the robot at each touch (m), within the track's limits.
    """
    e = touches.track
    if cell.track is None and e is not None and np.any(e != 0):
        raise InputError(f"{touches.source}: column 'track' has non-zero values, but the cell "
                         f"{label} has no track; remove the column or add the track to "
                         "the cell file")
    if e is not None:
        check_axis_limits(cell.track, e, ["track"], touches.source, label)
    return e


def robot_in_world(cell: Cell, touches: TouchTable, label: str = "the cell"
                   ) -> NDArray[np.float64]:
    """``T_world_R`` at each touch, shape (N, 4, 4) (m), from column ``track``.

    Parameters
    ----------
    cell : Cell
    touches : TouchTable
        The touches; their track positions are required when the robot is on a track.
    label : str
        Name of the cell in messages (its file name).
    """
    e = track_positions(cell, touches, label)
    if e is None:
        if cell.track is not None:
            raise InputError(
                f"{touches.source}: missing column 'track' (track position of the robot at each "
                f"touch, mm): the robot of {label} is on a track, and the touches are "
                "mapped to the world through it; add the column (0 where the track did not "
                "move)")
        e = np.zeros(touches.n)
    return cell.frame_pose("robot", track=e)
