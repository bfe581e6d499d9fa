"""ABB RAPID export: a module of ``tooldata``, ``wobjdata`` and base-frame ``pose`` data.

Written (see ``docs/export.md`` for sources):

- ``PERS tooldata name:=[TRUE,[[x,y,z],[q1,q2,q3,q4]],[mass,[cx,cy,cz],[1,0,0,0],0,0,0]];``:
  TCP in the flange (``tool0``) frame. A tool without mass in the cell gets ABB's ``load0``
  values ``[0.001,[0,0,0.001],[1,0,0,0],0,0,0]`` and a comment asking for the real load.
- ``PERS wobjdata name:=[FALSE,TRUE,"",[[uframe]],[[0,0,0],[1,0,0,0]]];`` for a frame fixed in
  the cell (user frame in world), and ``[FALSE,FALSE,"UNIT",[[0,0,0],[1,0,0,0]],[[oframe]]]``
  for a frame on the turntable: ``ufprog`` FALSE and ``ufmec`` the turntable's mechanical unit,
  the object frame in the unit's frame at axis 0.
- ``CONST pose`` values for the system parameters: the turntable's base frame in world
  (``<unit>_base``), the robot's base frame in world (``robot_base``), or for a robot on a track
  the track root in world, +Z along the motion (``<unit>_root``) and the robot base on the
  carriage at axis 0 (``<unit>_robot``).

Positions in mm with 6 decimals; quaternions scalar first, normalised, ``q1 >= 0``, 10 decimals.
"""

from __future__ import annotations

import re

import numpy as np

from robotcell.controllers.data import (
    MM_DECIMALS,
    QUAT_DECIMALS,
    ControllerData,
    Slot,
    fmt_num,
    parse_float,
)
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor

__all__ = ["format_data", "parse", "tooldata_text", "wobjdata_text"]

#: ABB's ``load0``: the load written for a tool whose mass the cell does not know.
LOAD0 = "[0.001,[0,0,0.001],[1,0,0,0],0,0,0]"
_IDENTITY = "[[0,0,0],[1,0,0,0]]"


def pose_text(T: np.ndarray) -> str:
    """A pose as RAPID ``pose`` data ``[[x,y,z],[q1,q2,q3,q4]]`` (mm, normalised quaternion)."""
    v = pose_to_vendor(T, "abb")
    trans = ",".join(fmt_num(x, MM_DECIMALS) for x in v[:3])
    quat = ",".join(fmt_num(x, QUAT_DECIMALS) for x in v[3:])
    return f"[[{trans}],[{quat}]]"


def _load_text(s: Slot) -> str:
    if s.mass is None:
        return LOAD0
    cog = np.zeros(3) if s.cog is None else s.cog * 1e3
    return (f"[{fmt_num(s.mass, MM_DECIMALS)},[{','.join(fmt_num(c, MM_DECIMALS) for c in cog)}],"
            "[1,0,0,0],0,0,0]")


def tooldata_text(s: Slot) -> str:
    """A tool's ``tooldata`` value: ``[TRUE,[[x,y,z],[q1,q2,q3,q4]],load]`` (the TCP in the flange
    frame; ABB's ``load0`` where the cell has no mass for it)."""
    return f"[TRUE,{pose_text(s.pose)},{_load_text(s)}]"


def wobjdata_text(s: Slot, unit: str | None) -> str:
    """A frame's ``wobjdata`` value: a user frame in world for a frame fixed in the cell, or on
    the mechanical unit ``unit`` (``ufprog`` FALSE) with the object frame in the unit's frame at
    axis 0 for a frame on the turntable."""
    if s.on_table:
        return f'[FALSE,FALSE,"{unit}",{_IDENTITY},{pose_text(s.pose)}]'
    return f'[FALSE,TRUE,"",{pose_text(s.pose)},{_IDENTITY}]'


def format_data(data: ControllerData, cell_name: str) -> str:
    """RAPID module text for :class:`ControllerData` collected with ``reference="world"``."""
    idents: dict[str, str] = {}
    for s in [*data.tools, *data.frames]:
        key = s.name.lower()  # RAPID identifiers are case-insensitive
        if key in idents:
            raise InputError(f"tool/frame names {idents[key]!r} and {s.name!r} are the same RAPID "
                             "identifier; rename one in the cell")
        idents[key] = s.name
    L = ["MODULE robotcell_cell",
         f"    ! robotcell export for ABB RAPID: cell {cell_name!r}",
         "    ! x, y, z in mm; quaternions [q1,q2,q3,q4] scalar first, normalised"]
    if data.tools:
        L.append("    ! tools: TCP in the flange (tool0) frame")
    for s in data.tools:
        if s.mass is None:
            L.append(f"    ! {s.name}: mass unknown in the cell, load0 written; set the real load")
        L.append(f"    PERS tooldata {s.name}:={tooldata_text(s)};")
    fixed = [s for s in data.frames if not s.on_table]
    table = [s for s in data.frames if s.on_table]
    if fixed:
        L.append("    ! work objects fixed in the cell: user frame in world")
    for s in fixed:
        L.append(f"    PERS wobjdata {s.name}:={wobjdata_text(s, None)};")
    if data.turntable is not None:
        unit = data.turntable.name
        if table:
            L.append(f"    ! work objects on {unit}: object frame in the unit's frame at axis 0")
        for s in table:
            L.append(f"    PERS wobjdata {s.name}:={wobjdata_text(s, unit)};")
        L.append(f"    ! system parameters, Motion > Single {unit} > base frame (in world, "
                 "z on the table axis):")
        L.append(f"    CONST pose {unit}_base:={pose_text(data.turntable.pose)};")
        if data.positioner_frames:
            L.append(f"    ! {unit} axes, not read by RAPID (the unit's kinematic model in the system "
                     "parameters holds them): each axis frame, z on the axis, in the previous at "
                     "axis 0, then the plate")
            *axes, plate = data.positioner_frames
            for i, T in enumerate(axes, start=1):
                L.append(f"    CONST pose {unit}_axis{i}:={pose_text(T)};")
            L.append(f"    CONST pose {unit}_plate:={pose_text(plate)};")
    if data.robot is not None:
        L.append("    ! system parameters, Motion > Robot > base frame (in world):")
        L.append(f"    CONST pose robot_base:={pose_text(data.robot.pose)};")
    if data.track_root is not None and data.track_robot is not None:
        unit = data.track_root.name
        L.append(f"    ! track {unit}: root in world, z along the motion; robot base on the "
                 "carriage at axis 0")
        L.append(f"    CONST pose {unit}_root:={pose_text(data.track_root.pose)};")
        L.append(f"    CONST pose {unit}_robot:={pose_text(data.track_robot.pose)};")
        if abs(data.track_scale - 1.0) > 1e-12:
            L.append(f"    ! track scale {data.track_scale:.9f}: the carriage moves scale * "
                     "axis value")
    for name in data.skipped:
        L.append(f"    ! frame {name} moves with the robot on the track: not exported")
    L.append("ENDMODULE")
    return "\n".join(L) + "\n"



_NUM = r"\s*([-+0-9.eE]+)\s*"
_POSE = r"\[\s*\[" + ",".join([_NUM] * 3) + r"\]\s*,\s*\[" + ",".join([_NUM] * 4) + r"\]\s*\]"
_TOOL_RE = re.compile(r"^\s*(?:PERS|CONST|VAR)\s+tooldata\s+(\w+)\s*:=\s*\[\s*(TRUE|FALSE)\s*,\s*"
                      + _POSE + r"\s*,\s*\[" + _NUM + r",\s*\[" + ",".join([_NUM] * 3) + r"\]",
                      re.IGNORECASE)
_WOBJ_RE = re.compile(r"^\s*(?:PERS|CONST|VAR)\s+wobjdata\s+(\w+)\s*:=\s*\[\s*(TRUE|FALSE)\s*,\s*"
                      r"(TRUE|FALSE)\s*,\s*\"([^\"]*)\"\s*,\s*" + _POSE + r"\s*,\s*" + _POSE,
                      re.IGNORECASE)
_POSE_RE = re.compile(r"^\s*(?:PERS|CONST|VAR)\s+pose\s+(\w+)\s*:=\s*" + _POSE, re.IGNORECASE)


def _pose(values: tuple[str, ...], where: str) -> np.ndarray:
    return pose_from_vendor([parse_float(v, where) for v in values], "abb")


def parse(text: str) -> ControllerData:
    """Read RAPID data (as written by :func:`export`) back into :class:`ControllerData`.

    Parameters
    ----------
    text : str
        RAPID module or declarations; other lines are ignored.

    Returns
    -------
    ControllerData
        Poses in metres. A work object with ``ufprog`` TRUE is fixed (pose ``uframe oframe``);
        one with ``ufprog`` FALSE is on the mechanical unit ``ufmec`` (pose ``oframe``). Base
        frames are the ``CONST pose`` named ``robot_base``, ``<unit>_base`` (turntable, the unit
        of the coordinated work objects), ``<unit>_root`` and ``<unit>_robot`` (track).
    """
    data = ControllerData()
    poses: dict[str, np.ndarray] = {}
    unit = None
    for lineno, line in enumerate(text.splitlines(), start=1):
        where = f"line {lineno}"
        if m := _TOOL_RE.match(line):
            g = m.groups()
            mass = parse_float(g[9], where)
            cog = np.array([parse_float(v, where) for v in g[10:13]]) * 1e-3
            data.tools.append(Slot(g[0], len(data.tools) + 1, _pose(g[2:9], where),
                                   mass=mass, cog=cog))
        elif m := _WOBJ_RE.match(line):
            g = m.groups()
            uframe, oframe = _pose(g[4:11], where), _pose(g[11:18], where)
            if g[2].upper() == "TRUE":
                data.frames.append(Slot(g[0], len(data.frames) + 1, uframe @ oframe))
            else:
                if unit is not None and g[3] != unit:
                    raise InputError(f"{where}: work objects on two units ({unit}, {g[3]})")
                unit = g[3]
                data.frames.append(Slot(g[0], len(data.frames) + 1, oframe, on_table=True))
        elif m := _POSE_RE.match(line):
            poses[m.group(1)] = _pose(m.groups()[1:], where)
    if "robot_base" in poses:
        data.robot = Slot("robot", None, poses["robot_base"])
    for name, T in poses.items():
        if name.endswith("_base") and name != "robot_base":
            data.turntable = Slot(name[: -len("_base")], None, T)
            axes = [poses[f"{name[:-5]}_axis{i}"] for i in (1, 2, 3)
                    if f"{name[:-5]}_axis{i}" in poses]
            if axes and f"{name[:-5]}_plate" in poses:
                data.positioner_frames = [*axes, poses[f"{name[:-5]}_plate"]]
        elif name.endswith("_root") and name[:-5] + "_robot" in poses:
            data.track_root = Slot(name[:-5], None, T)
            data.track_robot = Slot(name[:-5], None, poses[name[:-5] + "_robot"])
    return data
