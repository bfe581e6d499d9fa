"""YASKAWA Motoman export: tool files and user frames as shown on the pendant.

One line per frame, ``TOOL[n]  X ..  Y ..  Z ..  Rx ..  Ry ..  Rz ..  ' name`` (ROBOT > TOOL)
and ``UFRAME[n]  ...`` (ROBOT > USER COORDINATE: the frame in the base coordinates, the
``BUSER`` values of ``UFRAME.CND``). Lengths in mm (6 decimals), Rx, Ry, Rz in degrees
(9 decimals) with ``R = Rz(Rz) Ry(Ry) Rx(Rx)``. Tools are in the flange frame. User frames are in
the base coordinates, which sit at the robot base (at base-axis position 0 for a robot on a
traveling axis: ``UFRAME.CND`` records that position as ``BASEP``, and these values assume 0). A
frame on the turntable is written at station axis 0, and the turntable root (Z on the axis) as
one more user frame, the next free number. ``UFRAME.CND`` itself also stores the three taught
points in pulses, which only the controller can compute, so it is not written. See
``docs/export.md``.
"""

from __future__ import annotations

from robotcell.controllers.data import ControllerData
from robotcell.controllers.pendant import PendantListing, format_listing, parse_pendant_listing

__all__ = ["LISTING", "format_data", "parse"]

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
