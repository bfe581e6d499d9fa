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

from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.io.export.common import (
    ControllerData,
    Slot,
    collect,
    flatten_table,
    listing_line,
    parse_listing,
)
from robotcell.io.poseformats import FORMATS, pose_from_vendor, pose_to_vendor

__all__ = ["export", "format_data", "parse"]

_FIELDS = FORMATS["yaskawa"].fields


def format_data(data: ControllerData, cell_name: str) -> str:
    """Pendant listing for :class:`ControllerData` collected with ``reference="robot"``."""
    L = [f"' robotcell export for YASKAWA Motoman: cell {cell_name!r}",
         "' TOOL: ROBOT > TOOL; UFRAME: ROBOT > USER COORDINATE (BUSER values)",
         "' X, Y, Z in mm; Rx, Ry, Rz in deg with R = Rz(Rz) Ry(Ry) Rx(Rx)",
         "' TOOL: TCP in the flange frame"]
    L += [listing_line("TOOL", s.number, pose_to_vendor(s.pose, "yaskawa"), _FIELDS, "'", s.name)
          for s in data.tools]
    L.append("' UFRAME: in base coordinates (at the robot base" +
             (", BASEP 0: base axis at 0)" if data.track_root is not None else ")"))
    if data.turntable is not None:
        L.append(f"' frames on {data.turntable.name} at station axis 0; {data.turntable.name}: "
                 "table root, Z on the axis")
    L += [listing_line("UFRAME", s.number, pose_to_vendor(s.pose, "yaskawa"), _FIELDS, "'",
                       s.name) for s in flatten_table(data)]
    if data.track_root is not None:
        d = data.track_root.pose[:3, 2]
        L.append(f"' traveling axis {data.track_root.name}: moves the robot along ({d[0]:.9f}, "
                 f"{d[1]:.9f}, {d[2]:.9f}) in base coordinates, scale {data.track_scale:.9f}")
    for name in data.skipped:
        L.append(f"' frame {name} moves with the robot on the traveling axis: not exported")
    return "\n".join(L) + "\n"


def export(cell: Cell) -> str:
    """YASKAWA listing of the tools and user frames of ``cell``."""
    return format_data(collect(cell, "robot"), cell.name)


def parse(text: str) -> ControllerData:
    """Read a listing written by :func:`export` back into :class:`ControllerData`.

    Parameters
    ----------
    text : str
        Listing lines; ``'`` comment lines are ignored.

    Returns
    -------
    ControllerData
        ``tools`` from ``TOOL`` lines, ``frames`` (all fixed, in base coordinates) from
        ``UFRAME`` lines; poses in metres.
    """
    data = ControllerData()
    seen: set[tuple[str, int]] = set()
    for key, n, values, name in parse_listing(text, ("TOOL", "UFRAME"), _FIELDS, "'"):
        if (key, n) in seen:
            raise InputError(f"{key}[{n}] appears twice")
        seen.add((key, n))
        slot = Slot(name or f"{key.lower()}{n}", n, pose_from_vendor(values, "yaskawa"))
        (data.tools if key == "TOOL" else data.frames).append(slot)
    return data
