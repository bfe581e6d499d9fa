"""Robot to robot from two measurement tables, one per robot, as the command line reads them.

Each table has the touches of one robot: TCP positions ``x, y, z`` (mm, in its base) or joint
values ``a1..an`` (deg) with the robot's model and the tool that touched, and column ``point``
naming the common point of every touch. :func:`robot_to_robot_tables` reads both and calls
:func:`robotcell.calibration.robottorobot.robot_to_robot`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotcell.calibration.measurements import read_touch_table
from robotcell.calibration.result import CalibrationResult
from robotcell.calibration.robottorobot import RobotTouches, robot_to_robot
from robotcell.calibration.sigmaparts import ASSUMED_SUFFIX
from robotcell.calibration.spec import Column, TableSpec
from robotcell.calibration.uncertainty import Sources
from robotcell.errors import InputError
from robotcell.io.tables import empty_rows
from robotcell.robot.robot import Robot

__all__ = ["NOMINAL_TOOL_SIGMA", "SPEC", "RobotTable", "robot_to_robot_tables", "robot_touches",
           "tool_error"]

#: The measurement table of one robot's touches.
SPEC = TableSpec(
    "robot-to-robot", "tcp", (Column("point", "point", "", "name of the common point touched",
                                     decimals=0),),
    counted="touches", unused=MappingProxyType({"track": (
        "(track position of each touch) is not used by {procedure} without a cell: touch the "
        "points with the track at one position and remove the column")}))

#: Accuracy of a tool stated by nobody (m, 1-sigma per coordinate of its TCP): the nominal
#: accuracy of a cell item without recorded uncertainty (``docs/calibration.md``).
NOMINAL_TOOL_SIGMA = 1e-3


@dataclass(frozen=True)
class RobotTable:
    """One robot's measurement table.

    Attributes
    ----------
    columns : mapping
        Lower-case column names to values, as :func:`robotcell.io.tables.read_csv` reads them.
    source : str
        Its name in messages (the file).
    name : str
        The robot's name in labels (``"r1"``).
    robot : Robot, optional
        The arm, for joint values ``a1..an``.
    tool : ndarray, shape (4, 4), optional
        ``T_F_TCP`` of the tool that touched (m), for joint values; default the model's tool.
    """

    columns: Mapping[str, Any]
    source: str
    name: str
    robot: Robot | None = None
    tool: NDArray[np.float64] | None = None


def _names(table: RobotTable, n: int) -> tuple[str, ...]:
    """Column ``point``: required, a name on every line."""
    if "point" not in table.columns:
        raise InputError(f"{table.source}: missing column 'point' (the name of the common point "
                         "each touch touched, the same names in both robots' files)")
    values = table.columns["point"]
    empty = empty_rows(values)
    if len(empty):
        raise InputError(f"{table.source}: line {int(empty[0]) + 2}: empty value in column "
                         "'point', which needs the name of the point touched on every line")
    return tuple(str(v).strip() for v in values)[:n]


def tool_error(robot: str, tool_sigma: float | None) -> Sources:
    """The error of a robot's tool as one source named after the robot (``"r1 tool"``, marked
    assumed when nobody stated it), over its TCP position (3): the same error in every set of
    touches the robot made with it."""
    sigma = NOMINAL_TOOL_SIGMA if tool_sigma is None else tool_sigma
    suffix = ASSUMED_SUFFIX if tool_sigma is None else ""
    return Sources.of(f"{robot} tool{suffix}", np.eye(3) * sigma**2)


def robot_touches(table: RobotTable, tool_sigma: float | None,
                  on_note: Callable[[str], None] | None) -> RobotTouches:
    """One robot's touches of common points: TCP positions, or flange poses with the tool and
    its error (:func:`tool_error`)."""
    m = read_touch_table(SPEC, table.columns, table.source, table.robot, on_note)
    names = _names(table, m.n)
    if m.points is not None:
        if on_note is not None:
            on_note(f"note: {table.source}: touches given as x, y, z were computed by the "
                    "controller with its tool, whose error is left out; give joint values a1..a6 "
                    "with the robot and the tool to include it")
        return RobotTouches(m.points, names, robot=table.name)
    tool = table.robot.tool if table.tool is None else table.tool
    return RobotTouches.from_flange(m.flange(), tool, names,
                                    tool_sigma=tool_error(table.name, tool_sigma),
                                    robot=table.name)


def robot_to_robot_tables(reference: RobotTable, other: RobotTable, *, sigma: float | None = None,
                          tool_sigma: float | None = None, method: str = "common points",
                          on_note: Callable[[str], None] | None = None) -> CalibrationResult:
    """The pose of one robot's base relative to another's from their two touch tables.

    Parameters
    ----------
    reference, other : RobotTable
        The reference robot's table (the frame of the result) and the other robot's.
    sigma : float, optional
        Touch accuracy (m per coordinate); default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    tool_sigma : float, optional
        Accuracy of both tools' TCP (m, 1-sigma per coordinate), for joint values; default
        :data:`NOMINAL_TOOL_SIGMA`, an assumed figure the result says is assumed.
    method : {"common points", "pointer"}
    on_note : callable, optional
        Receives notes (columns not used, identical rows, a tool's error left out).

    Returns
    -------
    CalibrationResult
        See :func:`~robotcell.calibration.robottorobot.robot_to_robot`.
    """
    if tool_sigma is not None and not (np.isfinite(tool_sigma) and tool_sigma > 0):
        raise InputError(f"the tools' accuracy must be a positive number, got {tool_sigma}")
    ref = robot_touches(reference, tool_sigma, on_note)
    oth = robot_touches(other, tool_sigma, on_note)
    return robot_to_robot(ref, oth, sigma=sigma, method=method)
