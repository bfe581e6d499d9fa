"""Universal Robots export: the cell's tools and frames as URScript (``docs/export.md``).

Written (sources in ``docs/export.md``):

- per tool, a comment ``# tool NAME (n)``, then ``set_tcp(p[x, y, z, rx, ry, rz])``: the TCP in
  the tool flange frame, and ``set_payload(m, [cx, cy, cz])`` where the cell knows the tool's
  mass (kg; centre of gravity in m from the tool flange);
- per frame, ``global NAME=p[x, y, z, rx, ry, rz]``: the frame as a feature, its pose in the
  robot base frame (the name is a URScript identifier).

Poses ``p[...]``: metres (9 decimals, 5e-7 mm) and a rotation vector in radians (11 decimals),
as URScript writes a pose. A UR arm has no external axes: a cell with a track or a turntable is
refused before this is written (:meth:`robotcell.controllers.ur.UniversalRobots.data`).
"""

from __future__ import annotations

import re

import numpy as np
from numpy.typing import NDArray

from robotcell.controllers.data import ControllerData, Slot, fmt_num, parse_float
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor

__all__ = ["M_DECIMALS", "RAD_DECIMALS", "format_data", "identifier", "parse", "pose_text"]

#: Decimals of metres written: rounding error 5e-10 m (5e-7 mm), as the other exports' mm.
M_DECIMALS = 9
#: Decimals of a rotation vector's radians: rounding error 5e-12 rad.
RAD_DECIMALS = 11

_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
#: Words of URScript a name may not be (the manual's keywords and the motions robotcell writes).
KEYWORDS = frozenset({"def", "end", "if", "elif", "else", "while", "for", "return", "global",
                      "local", "thread", "run", "kill", "halt", "break", "continue", "sec",
                      "True", "False", "and", "or", "not", "xor", "p", "movej", "movel",
                      "movec", "movep", "set_tcp", "set_payload", "pose_trans",
                      "get_inverse_kin"})


def identifier(name: str, what: str) -> str:
    """``name`` when it is a URScript identifier (a letter or ``_``, then letters, digits or
    ``_``; not a keyword).

    Raises
    ------
    InputError
        It is not; the message names it and what it names.
    """
    if not _IDENT.match(name) or name in KEYWORDS:
        raise InputError(f"{what} {name!r} is not a URScript name (a letter or '_', then "
                         "letters, digits or '_', not a word of URScript); rename it in the cell")
    return name


def pose_text(T: NDArray[np.float64]) -> str:
    """A pose as URScript writes it: ``p[x, y, z, rx, ry, rz]`` (m, rotation vector in rad)."""
    v = pose_to_vendor(T, "ur")
    return ("p[" + ", ".join([*(fmt_num(x, M_DECIMALS) for x in v[:3]),
                              *(fmt_num(r, RAD_DECIMALS) for r in v[3:])]) + "]")


def format_data(data: ControllerData, cell_name: str) -> str:
    """URScript lines for :class:`ControllerData` collected with ``reference="robot"``.

    Raises
    ------
    InputError
        A frame whose name is not a URScript name.
    """
    for s in data.frames:
        identifier(s.name, "frame")
    L = [f"# robotcell export for Universal Robots (URScript): cell {cell_name!r}",
         "# poses p[x, y, z, rx, ry, rz]: metres and a rotation vector (rad)"]
    if data.tools:
        L.append("# tools: TCP in the tool flange frame (set_tcp), payload in kg and m "
                 "(set_payload)")
    for s in data.tools:
        L.append(f"# tool {s.name} ({s.number})")
        L.append(f"set_tcp({pose_text(s.pose)})")
        if s.mass is not None:
            cog = np.zeros(3) if s.cog is None else s.cog
            L.append(f"set_payload({fmt_num(s.mass, M_DECIMALS)}, ["
                     + ", ".join(fmt_num(c, M_DECIMALS) for c in cog) + "])")
    if data.frames:
        L.append("# frames as features: pose in the robot base frame")
    for s in data.frames:
        L.append(f"global {s.name}={pose_text(s.pose)}")
    return "\n".join(L) + "\n"


_NUM = r"\s*([^,\[\]\s]+)\s*"
_P = r"p\[" + ",".join([_NUM] * 6) + r"\]"
_TOOL_RE = re.compile(r"^#\s*tool\s+(\S+)\s+\((\d+)\)\s*$")
_TCP_RE = re.compile(r"^set_tcp\(\s*" + _P + r"\s*\)\s*$")
_PAYLOAD_RE = re.compile(r"^set_payload\(" + _NUM + r",\s*\[" + ",".join([_NUM] * 3)
                         + r"\]\s*\)\s*$")
_FRAME_RE = re.compile(r"^global\s+([A-Za-z_]\w*)\s*=\s*" + _P + r"\s*$")


def _pose(values: tuple[str, ...], where: str) -> NDArray[np.float64]:
    return pose_from_vendor([parse_float(v, where) for v in values], "ur")


def parse(text: str) -> ControllerData:
    """Read an export written by :func:`format_data` back into :class:`ControllerData`.

    Parameters
    ----------
    text : str
        The export; a ``set_tcp`` line belongs to the ``# tool NAME (n)`` line before it, a
        ``set_payload`` line to the tool before it; other lines are ignored.

    Returns
    -------
    ControllerData
        Poses in metres, tools numbered as written, frames in the order written.

    Raises
    ------
    InputError
        A number that is not one (the message names the line), or a ``set_tcp`` without its
        tool line.
    """
    data = ControllerData()
    pending: tuple[str, int] | None = None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line, where = raw.strip(), f"line {lineno}"
        if m := _TOOL_RE.match(line):
            pending = (m.group(1), int(m.group(2)))
        elif m := _TCP_RE.match(line):
            if pending is None:
                raise InputError(f"{where}: set_tcp without a '# tool NAME (n)' line before it")
            data.tools.append(Slot(pending[0], pending[1], _pose(m.groups(), where)))
            pending = None
        elif (m := _PAYLOAD_RE.match(line)) and data.tools:
            tool = data.tools[-1]
            tool.mass = parse_float(m.group(1), where)
            tool.cog = np.array([parse_float(v, where) for v in m.groups()[1:]])
        elif m := _FRAME_RE.match(line):
            data.frames.append(Slot(m.group(1), len(data.frames) + 1,
                                    _pose(m.groups()[1:], where)))
    return data
