"""FANUC export: tool and user frames as entered with the pendant's Direct Entry method.

One line per frame, ``UTOOL[n]  X ..  Y ..  Z ..  W ..  P ..  R ..  ! name`` and
``UFRAME[n]  ...``: the values to type at MENU > SETUP > Frames > (Tool | User) Frame > DETAIL >
METHOD > Direct Entry, or to load into a position register and assign in a TP program
(``UTOOL[n]=PR[m]``, ``UFRAME[n]=PR[m]``). Lengths in mm (6 decimals), W, P, R in degrees
(9 decimals) with ``R = Rz(R) Ry(P) Rx(W)``. Tools are in the faceplate frame; user frames in
FANUC WORLD, which sits at the robot base (at track position 0 for a robot on a rail). A frame
on the turntable is written at table axis 0, and the turntable root (Z on the axis) is written as
one more user frame, the next free number. See ``docs/export.md``.
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

_FIELDS = FORMATS["fanuc"].fields


def format_data(data: ControllerData, cell_name: str) -> str:
    """Direct Entry listing for :class:`ControllerData` collected with ``reference="robot"``."""
    L = [f"! robotcell export for FANUC: cell {cell_name!r}",
         "! Direct Entry values: MENU > SETUP > Frames > Tool/User Frame > DETAIL > METHOD",
         "! X, Y, Z in mm; W, P, R in deg with R = Rz(R) Ry(P) Rx(W)",
         "! UTOOL: TCP in the faceplate frame"]
    L += [listing_line("UTOOL", s.number, pose_to_vendor(s.pose, "fanuc"), _FIELDS, "!", s.name)
          for s in data.tools]
    L.append("! UFRAME: in WORLD (at the robot base" +
             (", rail at 0)" if data.track_root is not None else ")"))
    if data.turntable is not None:
        L.append(f"! frames on {data.turntable.name} at table axis 0; {data.turntable.name}: "
                 "table root, Z on the axis")
    L += [listing_line("UFRAME", s.number, pose_to_vendor(s.pose, "fanuc"), _FIELDS, "!", s.name)
          for s in flatten_table(data)]
    if data.track_root is not None:
        d = data.track_root.pose[:3, 2]
        L.append(f"! rail {data.track_root.name}: moves the robot along ({d[0]:.9f}, {d[1]:.9f}, "
                 f"{d[2]:.9f}) in WORLD, scale {data.track_scale:.9f}")
    for name in data.skipped:
        L.append(f"! frame {name} moves with the robot on the rail: not exported")
    return "\n".join(L) + "\n"


def export(cell: Cell) -> str:
    """FANUC Direct Entry listing of the tools and user frames of ``cell``."""
    return format_data(collect(cell, "robot"), cell.name)


def parse(text: str) -> ControllerData:
    """Read a listing written by :func:`export` back into :class:`ControllerData`.

    Parameters
    ----------
    text : str
        Listing lines; ``!`` comment lines are ignored.

    Returns
    -------
    ControllerData
        ``tools`` from ``UTOOL`` lines, ``frames`` (all fixed, in WORLD) from ``UFRAME`` lines;
        poses in metres.
    """
    data = ControllerData()
    seen: set[tuple[str, int]] = set()
    for key, n, values, name in parse_listing(text, ("UTOOL", "UFRAME"), _FIELDS, "!"):
        if (key, n) in seen:
            raise InputError(f"{key}[{n}] appears twice")
        seen.add((key, n))
        slot = Slot(name or f"{key.lower()}{n}", n, pose_from_vendor(values, "fanuc"))
        (data.tools if key == "UTOOL" else data.frames).append(slot)
    return data
