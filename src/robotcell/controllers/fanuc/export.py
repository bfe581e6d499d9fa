"""FANUC export: tool and user frames as entered with the pendant's Direct Entry method.

One line per frame, ``UTOOL[n]  X ..  Y ..  Z ..  W ..  P ..  R ..  ! name`` and
``UFRAME[n]  ...``: the values to type at MENU > SETUP > Frames > (Tool | User) Frame > DETAIL >
METHOD > Direct Entry, or to load into a position register and assign in a TP program
(``UTOOL[n]=PR[m]``, ``UFRAME[n]=PR[m]``). Lengths in mm (6 decimals), W, P, R in degrees
(9 decimals) with ``R = Rz(R) Ry(P) Rx(W)``. Tools are in the faceplate frame; user frames in
FANUC WORLD, which sits at the robot base (at track position 0 for a robot on a rail). A frame
on the turntable is written at table axis 0, and the turntable root (Z on the axis) is written as
one more user frame, the next free number.

In a cell of several robots, :func:`pair_lines` adds the coordinated pair of the first two
robots (motion groups 1 and 2), as MENU > SETUP > Coord shows it with Leader Group 2 and
Follower Group 1: X, Y, Z, W, P, R of the leader's WORLD in the follower's WORLD, the values the
``C_TYP`` Known Direct method takes. Source: rpiRobotics/fanuc_motion_program_exec (Apache-2.0),
``doc/multi_robot_coord_setup.md``, ``doc/roboguide_base.md`` with its pendant screenshot
``doc/figures_base/teach_pendant.png`` and ``tools/roboguide_base_adjust.py`` (R2's WORLD is
R1's WORLD times these values). See ``docs/export.md``.
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

#: FANUC wording of the pendant listing
LISTING = PendantListing(
    vendor="fanuc", product="FANUC", tool_key="UTOOL", comment="!",
    notes=("Direct Entry values: MENU > SETUP > Frames > Tool/User Frame > DETAIL > METHOD",
           "X, Y, Z in mm; W, P, R in deg with R = Rz(R) Ry(P) Rx(W)",
           "UTOOL: TCP in the faceplate frame"),
    reference="WORLD", at_track_zero="rail at 0", track="rail", table_axis="table axis")


def format_data(data: ControllerData, cell_name: str) -> str:
    """Direct Entry listing for :class:`ControllerData` collected with ``reference="robot"``."""
    return format_listing(data, cell_name, LISTING)


def parse(text: str) -> ControllerData:
    """Read a listing written by :func:`export` back: tools, and frames fixed in WORLD (metres)."""
    return parse_pendant_listing(text, LISTING)


#: How the listing names the placement of the robots in each other.
PAIRS = PairWording(
    title=("coordinated pair: MENU > SETUP > Coord, C_TYP Known Direct, SHIFT+EXEC, then "
           "restart the controller; motion groups in the order of the cell file's robots"),
    head="Coord Pair {pair}: Leader Group {group} = {other}, Follower Group 1 = {reference}",
    meaning="{other}'s WORLD in {reference}'s WORLD")


def pair_lines(pairs: list[RobotPair]) -> list[str]:
    """The comment lines placing the cell's robots in each other (:data:`PAIRS`)."""
    return pair_listing(pairs, LISTING, PAIRS)
