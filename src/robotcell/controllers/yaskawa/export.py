"""YASKAWA Motoman export: tool files and user frames as shown on the pendant.

One line per frame, ``TOOL[n]  X ..  Y ..  Z ..  Rx ..  Ry ..  Rz ..  ' name`` (ROBOT > TOOL)
and ``UFRAME[n]  ...`` (ROBOT > USER COORDINATE: the frame in the base coordinates, the
``BUSER`` values of ``UFRAME.CND``). Lengths in mm (6 decimals), Rx, Ry, Rz in degrees
(9 decimals) with ``R = Rz(Rz) Ry(Ry) Rx(Rx)``. Tools are in the flange frame. User frames are in
the base coordinates, which sit at the robot base (at base-axis position 0 for a robot on a
traveling axis: ``UFRAME.CND`` records that position as ``BASEP``, and these values assume 0). A
frame on the turntable is written at station axis 0, and the turntable root (Z on the axis) as
one more user frame, the next free number. ``UFRAME.CND`` itself also stores the three taught
points in pulses, which only the controller can compute, so it is not written.

In a cell of several robots, :func:`pair_lines` adds the robot calibration of every robot to
R1 (the cell's first robot): X, Y, Z, Rx, Ry, Rz of R2's robot coordinates in R1's, as the
pendant shows a calibration (DISPLAY > COORDINATE DATA) and ``RBCALIB.DAT`` stores it (its
``//SRANG`` line). They are written to compare with the controller's own calibration, which the
pendant measures (ROBOT > ROBOT CALIB) and which ``RBCALIB.DAT`` holds with the calibration
positions in pulses, so the file is not written. Source: Yaskawa-Global/motoros2 (Apache-2.0),
``src/Ros_mpGetRobotCalibrationData.c`` (the file's lines), ``src/ControllerStatusIO.c`` and
``src/PositionMonitor.c`` (the slave robot's frame placed in the master's by these values, ZYX
Euler angles). See ``docs/export.md``.
"""

from __future__ import annotations

from robotcell.controllers.data import ControllerData
from robotcell.controllers.pendant import (
    PairWording,
    PendantListing,
    format_listing,
    pair_listing,
    parse_pendant_listing,
)
from robotcell.controllers.robotpairs import RobotPair

__all__ = ["LISTING", "PAIRS", "format_data", "pair_lines", "parse"]

#: YASKAWA wording of the pendant listing
LISTING = PendantListing(
    vendor="yaskawa", product="YASKAWA Motoman", tool_key="TOOL", comment="'",
    notes=("TOOL: ROBOT > TOOL; UFRAME: ROBOT > USER COORDINATE (BUSER values)",
           "X, Y, Z in mm; Rx, Ry, Rz in deg with R = Rz(Rz) Ry(Ry) Rx(Rx)",
           "TOOL: TCP in the flange frame"),
    reference="base coordinates", at_track_zero="BASEP 0: base axis at 0",
    track="traveling axis", table_axis="station axis")


def format_data(data: ControllerData, cell_name: str) -> str:
    """Pendant listing for :class:`ControllerData` collected with ``reference="robot"``."""
    return format_listing(data, cell_name, LISTING)


def parse(text: str) -> ControllerData:
    """Read a listing written by :func:`export` back (tools, frames in base coordinates; m)."""
    return parse_pendant_listing(text, LISTING)


#: How the listing names the placement of the robots in each other.
PAIRS = PairWording(
    title=("robot calibration to R1 = {reference} (robots numbered in the order of the cell "
           "file's robots): compare with DISPLAY > COORDINATE DATA after ROBOT > ROBOT CALIB"),
    head="R1+R{group} (R{group} = {other})",
    meaning="R{group}'s robot coordinates in R1's")


def pair_lines(pairs: list[RobotPair]) -> list[str]:
    """The comment lines placing the cell's robots in each other (:data:`PAIRS`)."""
    return pair_listing(pairs, LISTING, PAIRS)
