"""Touches of a point on a turntable or a positioner, taken into the frame its calibration uses.

The turntable, workpiece and positioner procedures share them: the table's or the axes' values of
each touch checked against the limits, the touched point in the parent frame of the table (the
world, through the robot's track, or the robot base), and the items the touches rest on.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.measurements import TouchTable
from robotcell.cell import Cell, Turntable
from robotcell.cell.calibrate.chain import Chained
from robotcell.cell.calibrate.common import (
    Notes,
    chained_inputs,
    no_cell_track,
    refuse_track_column,
)
from robotcell.cell.calibrate.context import CalibrationContext
from robotcell.cell.calibrate.touches import robot_in_world, tool_transform, track_positions
from robotcell.cell.validation import check_axis_limits
from robotcell.errors import InputError
from robotcell.kinematics.transforms import transform_points


def cell_turntable(cell: Cell, label: str) -> Turntable:
    """The cell's turntable, refusing a cell without one."""
    if cell.turntable is None:
        raise InputError(f"{label} has no turntable; add a 'turntable' section to the cell "
                         "file first")
    if not isinstance(cell.turntable, Turntable):
        raise InputError(f"the positioner {cell.turntable.name!r} of {label} is a chain of "
                         f"{cell.turntable.n_axes} axes: the turntable procedure is for a "
                         "one-axis turntable; a positioner chain is calibrated by "
                         "robotcell.cell.calibrate.positioner (robotcell.identification."
                         "calibrate_positioner)")
    return cell.turntable


def _table_touches(cell: Cell | None, m: TouchTable, f: NDArray[np.float64],
                   label: str) -> NDArray[np.float64]:
    """Touches in the turntable's parent frame: mapped to the world for a table in the world."""
    if cell is None:
        refuse_track_column(m, no_cell_track())
        return f
    if cell_turntable(cell, label).parent == "world":
        return transform_points(robot_in_world(cell, m, label), f)
    track_positions(cell, m, label)
    return f


def on_table(cell: Cell | None, m: TouchTable, context: CalibrationContext, notes: Notes,
             check: Callable[[], None]
             ) -> tuple[NDArray[np.float64], NDArray[np.float64], Chained]:
    """Touches of a point on a turntable: its angles (rad), the touches in its parent frame
    (m) and the inputs they rest on; ``check`` refuses what the procedure cannot use once the
    angles are within the table's limits."""
    tool, label, nominal = context.tool, context.label(cell), context.nominal
    f_R = m.tcp(tool_transform(cell, tool, m))
    theta = m.axes[:, 0]
    if cell is not None:
        check_axis_limits(cell.turntable, theta, ["e1"], m.source, label)
    check()
    f = _table_touches(cell, m, f_R, label)
    return theta, f, chained_inputs(cell, m, f_R, tool, world_track(cell, m), nominal, notes)


def world_track(cell: Cell | None, m: TouchTable) -> NDArray[np.float64] | None:
    """Track positions of touches mapped to the world (zeros for a robot without a track) in a
    cell whose turntable is in the world; None where the touches stay in the robot base."""
    if not _in_world(cell):
        return None
    e = track_positions(cell, m)
    return np.zeros(m.n) if e is None else e


def _in_world(cell: Cell | None) -> bool:
    """A cell with a turntable or positioner in the world: its robot's touches of the table are
    mapped to the world, through the track or the robot's base."""
    return cell is not None and cell.turntable is not None and cell.turntable.parent == "world"


def positioner_points(cell: Cell, m: TouchTable, tool: str | ArrayLike | None, label: str
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The axis values (rad) of touches of a point on a positioner and the point in its parent
    frame (m), checked against the axes' limits (as
    :func:`robotcell.cell.calibrate.positioner_touches` gives them)."""
    f = m.tcp(tool_transform(cell, tool, m))
    names = [f"e{i + 1}" for i in range(m.axes.shape[1])]
    check_axis_limits(cell.turntable, m.axes, names, m.source, label)
    if cell.turntable.parent == "world":
        return m.axes, transform_points(robot_in_world(cell, m, label), f)
    track_positions(cell, m, label)
    return m.axes, f
