"""Robot-to-robot calibration into a cell of several robots.

Each robot touches the common points with one of its tools in the cell, at one track position
(``track``, m; 0 without a track); :func:`robotcell.calibration.robottorobot_tables.robot_to_robot_tables`
estimates ``T_Rref_Rother`` between the two bases at those positions, and :func:`place_robot`
writes the other robot's base into the cell through :meth:`robotcell.cell.Cell.set_robot_base`
(for a robot on a track: its base at track position 0, ``track.robot_at_zero``), with the pose's
1-sigma as its recorded error source. Docs: docs/calibration.md, "Robot to robot".
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from robotcell.calibration.result import CalibrationResult
from robotcell.calibration.robottorobot_tables import RobotTable, robot_to_robot_tables
from robotcell.calibration.uncertainty import factor_of
from robotcell.cell.calibrate.common import sha256_of, touch_file_problem
from robotcell.cell.calibrate.whole import fitted_note
from robotcell.cell.model import Cell
from robotcell.cell.parts import Provenance
from robotcell.errors import InputError
from robotcell.io.tables import read_csv
from robotcell.kinematics.transforms import invert

__all__ = ["RobotTouchFile", "calibrate_robot_to_robot", "link_options", "place_robot",
           "placed_base", "repeat_link", "robot_table"]


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


def placed_base(cell: Cell, T_ref_other: np.ndarray, reference: RobotTouchFile,
                other: RobotTouchFile) -> np.ndarray:
    """The other robot's base in the world as the cell writes it, from ``T_ref_other`` (4x4, m)
    at the two robots' track positions: ``T_world_R``, for a robot on a track at its track
    position 0 (the carriage's travel along the track taken back)."""
    T_world_R = (cell.for_robot(reference.robot).frame_pose("robot", track=reference.track)
                 @ np.asarray(T_ref_other, dtype=float))
    view = cell.for_robot(other.robot)
    if view.track is not None:  # the carriage's travel, in the world, taken back to track 0
        travel = view.frame_pose("robot", track=other.track) @ invert(
            view.frame_pose("robot", track=0.0))
        T_world_R = invert(travel) @ T_world_R
    return T_world_R


def place_robot(cell: Cell, result: CalibrationResult, reference: RobotTouchFile,
                other: RobotTouchFile, time: str | None = None, *,
                tool_sigma: float | None = None, note: str = "") -> Cell:
    """``cell`` with ``other.robot``'s base placed from a robot-to-robot result.

    The pose at the other robot's track position is taken back to its track position 0 (the
    carriage's travel along the track, which does not depend on the base being placed); its
    1-sigma (``result.estimates["T_ref_other"]``, in the reference base) is recorded as the
    base's error source, named by the calibration and its file. The provenance records what
    ``calibrate cell`` needs to repeat it (:func:`link_options`): both touch files with their
    checksums, the robots, tools and track positions, the touch accuracy, ``tool_sigma`` (m;
    None: the assumed figure) and the method. ``note`` replaces the note written.
    """
    T_world_R = placed_base(cell, result.values["T_ref_other"], reference, other)
    stamp = time or Provenance.now("robot-to-robot").time
    ident = f"robots.{other.robot} base {stamp}"
    est = result.estimates.get("T_ref_other")
    sources = {} if est is None else {ident: factor_of(est.covariance)}
    provenance = Provenance(
        "robot-to-robot", time=stamp, rms_mm=result.rms * 1e3, id=ident,
        note=note or (f"{len(result.residuals)} touches from {Path(reference.path).name} and "
                      f"{Path(other.path).name}; base in robot {reference.robot!r}"),
        measurements=str(Path(other.path).resolve()), sha256=sha256_of(other.path),
        options=link_options(result, reference, other, tool_sigma),
        inputs=(f"robots.{reference.robot}",), sources=sources)
    out = replace(cell)
    out.set_robot_base(other.robot, T_world_R, provenance)
    return out


def link_options(result: CalibrationResult, reference: RobotTouchFile, other: RobotTouchFile,
                 tool_sigma: float | None) -> dict[str, Any]:
    """The options a robot-to-robot placement records, in the units of the command line.

    ``reference`` (the reference robot), ``reference_file`` (its touch file, relative to the
    folder of the other robot's file, the provenance's ``measurements``), ``reference_sha256``,
    ``tool_ref`` and ``tool_other``, ``track_ref_mm`` and ``track_other_mm``, ``sigma_mm``,
    ``tool_sigma_mm`` (when given) and ``method``.
    """
    ref_file = os.path.relpath(Path(reference.path).resolve(), Path(other.path).resolve().parent)
    out: dict[str, Any] = {
        "reference": reference.robot, "reference_file": ref_file,
        "reference_sha256": sha256_of(reference.path), "tool_ref": reference.tool,
        "tool_other": other.tool, "track_ref_mm": float(reference.track * 1e3),
        "track_other_mm": float(other.track * 1e3), "sigma_mm": float(result.touch_sigma * 1e3),
        "method": str(result.json_fields.get("method", "common points"))}
    if tool_sigma is not None:
        out["tool_sigma_mm"] = float(tool_sigma * 1e3)
    return out


@dataclass(frozen=True)
class RecordedLink:
    """A robot-to-robot placement as a cell records it, ready to be repeated.

    Attributes
    ----------
    reference, other : RobotTouchFile
        The two robots' touches (``other.robot`` is the robot placed).
    provenance : Provenance
        The provenance of the placed base.
    """

    reference: RobotTouchFile
    other: RobotTouchFile
    provenance: Provenance

    @classmethod
    def of(cls, robot: str, prov: Provenance) -> RecordedLink | None:
        """The link that placed ``robot`` (its base's provenance ``prov``); None when the
        provenance does not record what repeating needs (a placement written before it did)."""
        o = prov.options
        if prov.measurements is None or "reference_file" not in o:
            return None
        ref_path = Path(prov.measurements).parent / str(o["reference_file"])
        return cls(RobotTouchFile(str(o["reference"]), str(ref_path), str(o["tool_ref"]),
                                  float(o.get("track_ref_mm", 0.0)) * 1e-3),
                   RobotTouchFile(robot, prov.measurements, str(o["tool_other"]),
                                  float(o.get("track_other_mm", 0.0)) * 1e-3), prov)

    def problems(self) -> list[str]:
        """Its touch files that are missing or changed since the placement (none: repeatable)."""
        o = self.provenance.options
        found = (touch_file_problem(f"robots.{self.other.robot}.base", path, digest)
                 for path, digest in ((self.reference.path, o.get("reference_sha256")),
                                      (self.other.path, self.provenance.sha256)))
        return [p for p in found if p is not None]


def repeat_link(cell: Cell, link: RecordedLink, time: str | None = None
                ) -> tuple[Cell, CalibrationResult]:
    """Repeat a recorded robot-to-robot calibration on ``cell`` as it stands (its tools and
    the reference robot's base as they are now) and place the robot again.

    Returns
    -------
    cell : Cell
        A new cell with the robot placed again; its base's provenance keeps the files and
        options, with the new time, RMS and error source.
    result : CalibrationResult
    """
    o = link.provenance.options
    tool_sigma = o["tool_sigma_mm"] * 1e-3 if "tool_sigma_mm" in o else None
    result = calibrate_robot_to_robot(
        cell, link.reference, link.other, sigma=float(o["sigma_mm"]) * 1e-3,
        tool_sigma=tool_sigma, method=str(o.get("method", "common points")))
    placed = place_robot(cell, result, link.reference, link.other, time, tool_sigma=tool_sigma,
                         note=fitted_note(link.provenance.note))
    return placed, result
