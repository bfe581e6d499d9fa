"""Pendant listings (FANUC, YASKAWA): one line per tool and user frame, as typed on the pendant.

A listing is ``KEY[n]  F1 v1 .. F6 v6  <comment> name`` for each tool, then each user frame (mm,
deg), with comment lines around them. FANUC and YASKAWA write the same layout and differ only in
the wording held by :class:`PendantListing`: line keys, comment marker, field names (from
:data:`robotcell.io.poseformats.FORMATS`) and the names of the reference frame, the track and the
turntable axis. Both refer the frames to the robot base at track position 0
(:func:`robotcell.controllers.data.collect` with ``reference="robot"``) and have no frames on a
turntable (:func:`robotcell.controllers.data.flatten_table`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from robotcell.controllers.data import (
    DEG_DECIMALS,
    MM_DECIMALS,
    ControllerData,
    Slot,
    flatten_table,
    fmt_num,
    parse_float,
)
from robotcell.controllers.robotpairs import RobotPair
from robotcell.errors import InputError
from robotcell.io.poseformats import FORMATS, pose_from_vendor, pose_to_vendor

__all__ = ["PairWording", "PendantListing", "format_listing", "listing_line", "pair_listing",
           "parse_listing", "parse_pendant_listing", "pose_text"]


@dataclass(frozen=True)
class PendantListing:
    """The vendor wording of a pendant listing.

    Attributes
    ----------
    vendor : str
        Pose format name in :data:`robotcell.io.poseformats.FORMATS` (``fanuc``, ``yaskawa``).
    product : str
        Name in the title line (``FANUC``, ``YASKAWA Motoman``).
    tool_key : str
        Line key of a tool (``UTOOL``, ``TOOL``); user frames are ``UFRAME``.
    comment : str
        Comment marker (``!``, ``'``).
    notes : tuple of str
        Comment lines after the title, without the marker: where to enter the values, units and
        angle convention, the tool reference.
    reference : str
        Name of the frame the user frames are in (``WORLD``, ``base coordinates``).
    at_track_zero : str
        Said of the reference frame for a robot on a track (``rail at 0``).
    track : str
        Name of the track (``rail``, ``traveling axis``).
    table_axis : str
        Name of the turntable axis (``table axis``, ``station axis``).
    """

    vendor: str
    product: str
    tool_key: str
    comment: str
    notes: tuple[str, ...]
    reference: str
    at_track_zero: str
    track: str
    table_axis: str


@dataclass(frozen=True)
class PairWording:
    """How a listing names the placement of a cell's robots in each other.

    Each text is formatted with the pair's fields: ``reference`` and ``other`` (robot names),
    ``group`` (the other robot's motion group) and ``pair`` (``group - 1``).

    Attributes
    ----------
    title : str
        The first comment line: where the values go on the controller.
    head : str
        The line that names one pair (``Coord Pair {pair}: Leader Group {group} = {other}``).
    meaning : str
        What the six values are (``{other}'s WORLD in {reference}'s WORLD``).
    """

    title: str
    head: str
    meaning: str


def pair_listing(pairs: list[RobotPair], style: PendantListing, wording: PairWording
                 ) -> list[str]:
    """Comment lines placing a cell's robots in each other, for the end of a listing.

    Parameters
    ----------
    pairs : list of RobotPair
        From :func:`robotcell.controllers.robotpairs.robot_pairs`.
    style : PendantListing
        The vendor's comment marker and pose fields.
    wording : PairWording

    Returns
    -------
    list of str
        The title, then per pair its line and the values (mm, deg), or why none is written;
        empty for a cell of one robot.
    """
    if not pairs:
        return []
    c, fields = style.comment, FORMATS[style.vendor].fields
    lines = [f"{c} {wording.title.format(reference=pairs[0].reference)}"]
    for p in pairs:
        names = {"reference": p.reference, "other": p.other, "group": p.group,
                 "pair": p.group - 1}
        head = f"{c} {wording.head.format(**names)}"
        if p.pose is None:
            lines.append(f"{head}: not written ({p.why})")
            continue
        meaning = wording.meaning.format(**names)
        lines += [f"{head}: {meaning} ({p.other}'s base: {p.provenance})",
                  f"{c}   {pose_text(pose_to_vendor(p.pose, style.vendor), fields)}"]
    return lines


def listing_line(key: str, number: int, values: NDArray[np.float64], fields: tuple[str, ...],
                 comment: str, name: str) -> str:
    """``KEY[n]  F1 v1  F2 v2 ...  <comment> name``: a pose as typed on a pendant screen.

    Parameters
    ----------
    key : str
        ``UTOOL``, ``UFRAME``, ``TOOL``, ...
    number : int
        Slot number.
    values : ndarray, shape (6,)
        Three lengths (mm) and three angles (deg).
    fields : tuple of str
        The six field names.
    comment : str
        The vendor's comment marker.
    name : str
        Name written after the comment marker.
    """
    return f"{key}[{number}]  {pose_text(values, fields)}  {comment} {name}"


def pose_text(values: NDArray[np.float64], fields: tuple[str, ...]) -> str:
    """``F1 v1  F2 v2 ...``: three lengths (mm, 6 decimals) and three angles (deg, 9 decimals)."""
    return "  ".join(f"{f} {fmt_num(v, MM_DECIMALS if i < 3 else DEG_DECIMALS)}"
                     for i, (f, v) in enumerate(zip(fields, values)))


def parse_listing(text: str, keys: tuple[str, ...], fields: tuple[str, ...], comment: str
                  ) -> list[tuple[str, int, list[float], str]]:
    """Read lines written by :func:`listing_line`.

    Parameters
    ----------
    text : str
        The listing; lines starting with ``comment`` and blank lines are ignored.
    keys : tuple of str
        Accepted line keys.
    fields : tuple of str
        The six field names, in order.
    comment : str
        The vendor's comment marker.

    Returns
    -------
    list of (key, number, values, name)
        ``values`` are the six numbers as written (mm, deg).
    """
    head = re.compile(r"^\s*(" + "|".join(keys) + r")\[(\d+)\]\s+(.*)$", re.IGNORECASE)
    out = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        where = f"line {lineno}"
        stripped = line.strip()
        if not stripped or stripped.startswith(comment):
            continue
        m = head.match(line)
        if not m:
            raise InputError(f"{where}: expected '<{'|'.join(keys)}>[n]  {fields[0]} ...', "
                             f"got {stripped[:40]!r}")
        body, _, name = m.group(3).partition(comment)
        tok = body.split()
        if len(tok) != 12 or [t.upper() for t in tok[0::2]] != [f.upper() for f in fields]:
            raise InputError(f"{where}: expected the fields {' '.join(fields)} each followed by "
                             "a number")
        values = [parse_float(t, where) for t in tok[1::2]]
        out.append((m.group(1).upper(), int(m.group(2)), values, name.strip()))
    return out


def format_listing(data: ControllerData, cell_name: str, style: PendantListing) -> str:
    """The listing of ``data`` (collected with ``reference="robot"``) in the wording ``style``.

    Parameters
    ----------
    data : ControllerData
        Poses in metres, in the robot base at track position 0.
    cell_name : str
        Written in the title line.
    style : PendantListing

    Returns
    -------
    str
        Tool lines, then user frame lines (frames on the turntable at axis 0 and the turntable
        root as one more frame), lengths in mm and angles in deg, one per line.
    """
    c, fields = style.comment, FORMATS[style.vendor].fields

    def line(key: str, s: Slot) -> str:
        return listing_line(key, s.number, pose_to_vendor(s.pose, style.vendor), fields, c, s.name)

    L = [f"{c} robotcell export for {style.product}: cell {cell_name!r}",
         *(f"{c} {note}" for note in style.notes)]
    L += [line(style.tool_key, s) for s in data.tools]
    L.append(f"{c} UFRAME: in {style.reference} (at the robot base" +
             (f", {style.at_track_zero})" if data.track_root is not None else ")"))
    if data.turntable is not None:
        t = data.turntable.name
        L.append(f"{c} frames on {t} at {style.table_axis} 0; {t}: table root, Z on the axis")
    L += [line("UFRAME", s) for s in flatten_table(data)]
    if data.track_root is not None:
        d = data.track_root.pose[:3, 2]
        L.append(f"{c} {style.track} {data.track_root.name}: moves the robot along ({d[0]:.9f}, "
                 f"{d[1]:.9f}, {d[2]:.9f}) in {style.reference}, scale {data.track_scale:.9f}")
    for name in data.skipped:
        L.append(f"{c} frame {name} moves with the robot on the {style.track}: not exported")
    return "\n".join(L) + "\n"


def parse_pendant_listing(text: str, style: PendantListing) -> ControllerData:
    """Read a listing written by :func:`format_listing` back into :class:`ControllerData`.

    Parameters
    ----------
    text : str
        Listing lines; comment lines are ignored.
    style : PendantListing

    Returns
    -------
    ControllerData
        ``tools`` from the tool lines, ``frames`` (all fixed, in the reference frame) from
        ``UFRAME`` lines; poses in metres.

    Raises
    ------
    InputError
        A line that is not a listing line, or a slot written twice.
    """
    data = ControllerData()
    seen: set[tuple[str, int]] = set()
    keys = (style.tool_key, "UFRAME")
    fields = FORMATS[style.vendor].fields
    for key, n, values, name in parse_listing(text, keys, fields, style.comment):
        if (key, n) in seen:
            raise InputError(f"{key}[{n}] appears twice")
        seen.add((key, n))
        slot = Slot(name or f"{key.lower()}{n}", n, pose_from_vendor(values, style.vendor))
        (data.tools if key == style.tool_key else data.frames).append(slot)
    return data
