"""Robot-to-robot calibration into a cell of several robots.

Each robot touches the common points with one of its tools in the cell, at one track position
(``track``, m; 0 without a track); :func:`robotcell.calibration.robottorobot_tables.robot_to_robot_tables`
estimates ``T_Rref_Rother`` between the two bases at those positions, and :func:`place_robot`
writes the other robot's base into the cell through :meth:`robotcell.cell.Cell.set_robot_base`
(for a robot on a track: its base at track position 0, ``track.robot_at_zero``), with the pose's
1-sigma as its recorded error source. Docs: docs/calibration.md, "Robot to robot".
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from robotcell.calibration.result import CalibrationResult
from robotcell.calibration.robottorobot_tables import RobotTable, robot_to_robot_tables
from robotcell.calibration.uncertainty import factor_of
from robotcell.cell.model import Cell
from robotcell.cell.parts import Provenance
from robotcell.errors import InputError
from robotcell.io.tables import read_csv
from robotcell.kinematics.transforms import invert

__all__ = ["RobotTouchFile", "calibrate_robot_to_robot", "place_robot", "robot_table"]


@dataclass(frozen=True)
class RobotTouchFile:
    """One robot's touches of the common points, in a cell.

    Parameters
    ----------
    robot : str
        The robot's name in the cell.
    path : str
        Its touch file (CSV: ``point`` and x,y,z mm in its base, or joint values a1..an deg).
    tool : str
        The tool of that robot in the cell that touched.
    track : float
        Its track position during the touches (m); 0 for a robot without a track.
    """

    robot: str
    path: str
    tool: str
    track: float = 0.0


def robot_table(cell: Cell, touches: RobotTouchFile) -> RobotTable:
    """One robot's touch file with its model and the named tool of the cell."""
    view = cell.for_robot(touches.robot)
    if touches.tool not in view.tools:
        known = ", ".join(sorted(view.tools)) or "none"
        raise InputError(f"robot {touches.robot!r} has no tool {touches.tool!r}; its tools: "
                         f"{known}")
    if view.track is None and touches.track != 0:
        raise InputError(f"robot {touches.robot!r} has no track; its track position must be 0")
    return RobotTable(read_csv(touches.path), touches.path, touches.robot, view.robot,
                      view.tools[touches.tool].T_F_TCP)


def calibrate_robot_to_robot(cell: Cell, reference: RobotTouchFile, other: RobotTouchFile, *,
                             sigma: float | None = None, tool_sigma: float | None = None,
                             method: str = "common points",
                             on_note: Callable[[str], None] | None = None) -> CalibrationResult:
    """The pose of ``other.robot``'s base in ``reference.robot``'s base from their touches.

    Parameters
    ----------
    cell : Cell
        A cell of several robots (their models and tools).
    reference, other : RobotTouchFile
        The two robots' touches; the result is in the reference robot's base.
    sigma : float, optional
        Touch accuracy (m, 1-sigma per coordinate).
    tool_sigma : float, optional
        Accuracy of both tools' TCP (m); default an assumed figure the result marks assumed.
    method : {"common points", "pointer"}
    on_note : callable, optional
        Receives notes on the measurements.

    Returns
    -------
    CalibrationResult
        ``values["T_ref_other"]``: ``T_Rref_Rother`` at the two track positions (m).

    Raises
    ------
    InputError
        A robot or tool the cell lacks, the same robot twice, a track position for a robot
        without a track, or touches the estimator refuses.
    """
    if cell.robot_key(reference.robot) == cell.robot_key(other.robot):
        raise InputError(f"the reference and the other robot are both {reference.robot!r}; "
                         "name two robots of the cell")
    return robot_to_robot_tables(robot_table(cell, reference), robot_table(cell, other),
                                 sigma=sigma, tool_sigma=tool_sigma, method=method,
                                 on_note=on_note)


def place_robot(cell: Cell, result: CalibrationResult, reference: RobotTouchFile,
                other: RobotTouchFile, time: str | None = None) -> Cell:
    """``cell`` with ``other.robot``'s base placed from a robot-to-robot result.

    The pose at the other robot's track position is taken back to its track position 0 (the
    carriage's travel along the track, which does not depend on the base being placed); its
    1-sigma (``result.estimates["T_ref_other"]``, in the reference base) is recorded as the
    base's error source, named by the calibration and its file.
    """
    T_world_R = (cell.for_robot(reference.robot).frame_pose("robot", track=reference.track)
                 @ np.asarray(result.values["T_ref_other"], dtype=float))
    view = cell.for_robot(other.robot)
    if view.track is not None:  # the carriage's travel, in the world, taken back to track 0
        travel = view.frame_pose("robot", track=other.track) @ invert(
            view.frame_pose("robot", track=0.0))
        T_world_R = invert(travel) @ T_world_R
    stamp = time or Provenance.now("robot-to-robot").time
    ident = f"robots.{other.robot} base {stamp}"
    est = result.estimates.get("T_ref_other")
    sources = {} if est is None else {ident: factor_of(est.covariance)}
    provenance = Provenance(
        "robot-to-robot", time=stamp, rms_mm=result.rms * 1e3, id=ident,
        note=(f"{len(result.residuals)} touches from {Path(reference.path).name} and "
              f"{Path(other.path).name}; base in robot {reference.robot!r}"),
        measurements=str(Path(other.path).resolve()), inputs=(f"robots.{reference.robot}",),
        sources=sources)
    out = replace(cell)
    out.set_robot_base(other.robot, T_world_R, provenance)
    return out
