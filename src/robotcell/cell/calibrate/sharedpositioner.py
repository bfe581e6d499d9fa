"""A 2-axis positioner shared by two robots of a cell: both calibrations compared, all touches
in one fit.

Each robot touches common points (as for the robot-to-robot calibration,
:mod:`robotcell.cell.calibrate.robottorobot`) and its own point on the positioner's plate at
several (tilt, rotate) values, each at one track position, with one of its tools in the cell.
:func:`shared_positioner` calibrates the robot-to-robot pose, the positioner from each robot's
touches in its own base, compares the two
(:func:`robotcell.identification.sharedpositioner.compare_positioner`) and fits every touch
at once (:func:`robotcell.identification.sharedpositioner.shared_positioner`). Nothing is
written into the cell. Docs: docs/calibration.md, "One positioner, two robots".
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from robotcell.calibration.result import CalibrationResult
from robotcell.calibration.robottorobot import RobotTouches
from robotcell.calibration.robottorobot_tables import (
    robot_to_robot_tables,
    robot_touches,
    tool_error,
)
from robotcell.calibration.sharedtable import Agreement
from robotcell.calibration.spec import SPECS
from robotcell.cell.calibrate.robottorobot import RobotTouchFile, robot_table
from robotcell.cell.calibrate.touches import read_touches
from robotcell.cell.model import Cell
from robotcell.errors import InputError
from robotcell.identification.positioner import PositionerCalibration, calibrate_positioner
from robotcell.identification.sharedpositioner import compare_positioner
from robotcell.identification.sharedpositioner import shared_positioner as joint_fit
from robotcell.kinematics.transforms import invert

__all__ = ["SharedPositioner", "shared_positioner"]


@dataclass(frozen=True)
class SharedPositioner:
    """The positioner two robots calibrated, compared and fitted together.

    Attributes
    ----------
    link : CalibrationResult
        The robot-to-robot pose from the common points alone (``T_ref_other``).
    reference, other : CalibrationResult
        Each robot's calibration of the positioner in its own base (``positioner-2axis``, at
        its track position).
    agreement : Agreement
        The two calibrations compared through ``link``.
    joint : CalibrationResult
        All touches in one fit (``T_ref_other``, ``T_ref_B``, ``axis_offset``, ``axis_angle``);
        its JSON holds the comparison as ``agreement``.
    """

    link: CalibrationResult
    reference: CalibrationResult
    other: CalibrationResult
    agreement: Agreement
    joint: CalibrationResult


def _plate_touches(cell: Cell, touches: RobotTouchFile, tool_sigma: float | None,
                   on_note: Callable[[str], None] | None
                   ) -> tuple[np.ndarray, RobotTouches, list[str]]:
    """One robot's touches of its point on the plate: axis values (rad), the touches in its
    base with its tool's error, and their labels."""
    table = robot_table(cell, touches)
    m = read_touches(SPECS["positioner"], table.columns, touches.path, table.robot, on_note)
    if m.track is not None and not np.allclose(m.track, touches.track, atol=1e-6):
        raise InputError(f"{touches.path}: column 'track' differs from the track position "
                         f"{touches.track * 1e3:g} mm of robot {touches.robot!r}; touch the "
                         "plate at the track position of the common points")
    names = ["plate"] * m.n
    if m.joints is None:
        if on_note is not None:
            on_note(f"note: {touches.path}: touches given as x, y, z were computed by the "
                    "controller with its tool, whose error is left out; give joint values "
                    "a1..a6 to include it")
        return m.axes, RobotTouches(m.tcp(), names, robot=touches.robot), m.labels()
    return m.axes, RobotTouches.from_flange(m.flange(), table.tool, names,
                                            tool_sigma=tool_error(touches.robot, tool_sigma),
                                            robot=touches.robot), m.labels()


def _calibrated(cell: Cell, touches: RobotTouchFile, plate: tuple, sigma: float | None
                ) -> PositionerCalibration:
    """The positioner from one robot's touches, in its base at its track position, started
    from the cell's chain."""
    pos = cell.turntable
    assert pos is not None
    T_w_R = cell.for_robot(touches.robot).frame_pose("robot", track=touches.track)
    nominal = pos.chain.with_base(invert(T_w_R) @ pos.chain.base)
    values, t, labels = plate
    return calibrate_positioner(values, t.points, nominal=nominal, sigma=sigma, labels=labels,
                                inputs=t.inputs)


def shared_positioner(cell: Cell, common: tuple[RobotTouchFile, RobotTouchFile],
                      plate: tuple[str, str], *, sigma: float | None = None,
                      tool_sigma: float | None = None,
                      on_note: Callable[[str], None] | None = None) -> SharedPositioner:
    """Two robots' calibrations of the cell's 2-axis positioner, compared and fitted together.

    Parameters
    ----------
    cell : Cell
        A cell of several robots with a positioner of 2 axes.
    common : (RobotTouchFile, RobotTouchFile)
        The reference robot's and the other robot's touches of the common points (their tools
        and track positions hold for the plate touches too).
    plate : (str, str)
        Each robot's touch file of its point on the plate: joint values ``a1..an`` (deg, or
        ``x, y, z`` mm in its base) and the axis values ``e1``, ``e2`` (deg); a column
        ``track``, if any, equal to the robot's track position.
    sigma : float, optional
        Touch accuracy (m, 1-sigma per coordinate).
    tool_sigma : float, optional
        Accuracy of both tools' TCP (m); default an assumed figure the results mark assumed.
    on_note : callable, optional
        Receives notes on the measurements.

    Returns
    -------
    SharedPositioner

    Raises
    ------
    InputError
        A cell without a 2-axis positioner, the same robot twice, a robot or tool the cell
        lacks, or touches the estimators refuse.
    """
    pos = cell.turntable
    if pos is None or pos.n_axes != 2 or pos.parent != "world":
        raise InputError("the cell has no 2-axis positioner in the world that both robots "
                         "share; add a 'positioner' section with parent world")
    ref, oth = common
    if cell.robot_key(ref.robot) == cell.robot_key(oth.robot):
        raise InputError(f"the reference and the other robot are both {ref.robot!r}; name two "
                         "robots of the cell")
    tables = [robot_table(cell, t) for t in common]
    sets = [robot_touches(t, tool_sigma, on_note) for t in tables]
    link = robot_to_robot_tables(tables[0], tables[1], sigma=sigma, tool_sigma=tool_sigma,
                                 on_note=on_note)
    plates = [_plate_touches(cell, replace(t, path=p), tool_sigma, on_note)
              for t, p in zip(common, plate, strict=True)]
    cals = [_calibrated(cell, t, p, sigma) for t, p in zip(common, plates, strict=True)]
    agreement = compare_positioner(cals[0].result, cals[1].result, link,
                                   names=(ref.robot, oth.robot))
    joint = joint_fit(plates[0][1], plates[0][0], plates[1][1], plates[1][0],
                      common=(sets[0], sets[1]), sigma=sigma, start=(cals[0], cals[1]))
    joint = replace(joint, json_fields={**joint.json_fields, "agreement": agreement.to_json()})
    return SharedPositioner(link, cals[0].result, cals[1].result, agreement, joint)
