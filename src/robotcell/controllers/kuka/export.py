"""KUKA KR C4 / KR C5 export: ``$config.dat`` and ``$machine.dat`` lines.

Written (see ``docs/export.md`` for sources and the paste locations):

- ``TOOL_DATA[n]={X ..,Y ..,Z ..,A ..,B ..,C ..}`` and ``TOOL_NAME[n,]="name"``: TCP in
  ``$FLANGE``.
- ``BASE_DATA[n]=...`` and ``BASE_NAME[n,]=...``: a base fixed in the cell, in ``$WORLD``; a
  base on the turntable, in the flange of the turntable's kinematic at axis value 0, used with
  ``$BASE=EK(MACHINE_DEF[m].ROOT,MACHINE_DEF[m].MECH_TYPE,BASE_DATA[n])`` (the line says so in
  its comment, which is how :func:`parse` tells the two apart).
- ``MACHINE_DEF[m]={NAME[] ..,ROOT {..},MECH_TYPE #EASYS,..}``: the turntable root in
  ``$WORLD``, +Z on the table axis.
- ``$ROBROOT`` (robot base in ``$WORLD``) for a cell without track; for a robot on a linear unit
  (ROBROOT kinematic ``#ERSYS``), ``$ERSYSROOT`` (the unit's root in ``$WORLD``, +Z along the
  motion, as for every frame of KUKA external kinematics), ``$ET1_TA1KR`` (null frame) and
  ``$ET1_TFLA3`` (robot base on the carriage at E1 = 0).
- For a positioner chain (``#EASYS`` with 1-3 axes, ``ET2`` next to a linear unit, else ``ET1``):
  ``$ETk_TA1KR``, ``$ETk_TA2A1``, ``$ETk_TA3A2`` (each axis frame, +Z on the axis, in the
  previous one at axis value 0; null frames for missing axes) and ``$ETk_TFLA3`` (the plate, the
  kinematic's flange, in the last axis frame), after ``MACHINE_DEF[m].ROOT``.

Poses: X, Y, Z in mm (6 decimals), A, B, C in degrees (9 decimals), ``R = Rz(A) Ry(B) Rx(C)``.
"""

from __future__ import annotations

import re

import numpy as np

from robotcell.controllers.data import (
    DEG_DECIMALS,
    MM_DECIMALS,
    ControllerData,
    Slot,
    fmt_num,
    parse_float,
)
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor

__all__ = ["MACHINE_INDEX", "format_data", "parse"]

#: ``MACHINE_DEF`` index of the turntable (``MACHINE_DEF[1]`` is the robot).
MACHINE_INDEX = 2
_KEYS = ("X", "Y", "Z", "A", "B", "C")
#: Frames of a KUKA external kinematic, root to flange.
_ET_FRAMES = ("TA1KR", "TA2A1", "TA3A2", "TFLA3")


def frame_text(T: np.ndarray) -> str:
    """A pose as a KRL ``FRAME`` aggregate ``{X ..,Y ..,Z ..,A ..,B ..,C ..}`` (mm, deg)."""
    v = pose_to_vendor(T, "kuka")
    parts = [f"{k} {fmt_num(x, MM_DECIMALS if i < 3 else DEG_DECIMALS)}"
             for i, (k, x) in enumerate(zip(_KEYS, v))]
    return "{" + ",".join(parts) + "}"


def format_data(data: ControllerData, cell_name: str) -> str:
    """KRL text for :class:`ControllerData` collected with ``reference="world"``."""
    L = [f"; robotcell export for KUKA KR C4/KR C5: cell {cell_name!r}",
         "; X, Y, Z in mm; A, B, C in deg with R = Rz(A) Ry(B) Rx(C)",
         ";",
         "; ---- R1\\System\\$config.dat ----"]
    if data.tools:
        L.append("; tools: TCP in $FLANGE")
    for s in data.tools:
        L += [f"TOOL_DATA[{s.number}]={frame_text(s.pose)}", f'TOOL_NAME[{s.number},]="{s.name}"']
    fixed = [s for s in data.frames if not s.on_table]
    table = [s for s in data.frames if s.on_table]
    if fixed:
        L.append("; bases fixed in the cell: pose in $WORLD")
    for s in fixed:
        L += [f"BASE_DATA[{s.number}]={frame_text(s.pose)}", f'BASE_NAME[{s.number},]="{s.name}"']
    if data.turntable is not None:
        m = MACHINE_INDEX
        if table:
            L.append(f"; bases on turntable {data.turntable.name}: pose in its flange at axis 0;")
            L.append(f"; use $BASE=EK(MACHINE_DEF[{m}].ROOT,MACHINE_DEF[{m}].MECH_TYPE,BASE_DATA[n])")
        for s in table:
            L += [f"BASE_DATA[{s.number}]={frame_text(s.pose)} ; on MACHINE_DEF[{m}]",
                  f'BASE_NAME[{s.number},]="{s.name}"']
        L.append("; turntable root point in $WORLD, +Z on the table axis")
        L.append(f'MACHINE_DEF[{m}]={{NAME[] "{data.turntable.name}",COOP_KRC_INDEX 1,'
                 f'PARENT[] "WORLD",ROOT {frame_text(data.turntable.pose)},MECH_TYPE #EASYS,'
                 'GEOMETRY[] " "}')
    L.append(";")
    L.append("; ---- R1\\Mada\\$machine.dat ----")
    if data.robot is not None:
        L.append("; robot base in $WORLD")
        L.append(f"$ROBROOT={frame_text(data.robot.pose)}")
    if data.track_root is not None and data.track_robot is not None:
        L.append(f"; linear unit {data.track_root.name}: ROBROOT kinematic, "
                 "$EX_KIN={ET1 #ERSYS,...}, $ET1_AX={TR_A1 #E1,...}")
        L.append("; root of the unit in $WORLD, +Z along the motion")
        L.append(f"$ERSYSROOT={frame_text(data.track_root.pose)}")
        L.append("; chain: $ERSYSROOT : $ET1_TA1KR : Trans(Z, E1) : $ET1_TFLA3 = $ROBROOT_C;")
        L.append("; $ET1_TA2A1 and $ET1_TA3A2 must be null frames")
        L.append(f"$ET1_TA1KR={frame_text(np.eye(4))}")
        L.append("; robot base on the carriage at E1 = 0")
        L.append(f"$ET1_TFLA3={frame_text(data.track_robot.pose)}")
        if abs(data.track_scale - 1.0) > 1e-12:
            L.append(f"; track scale {data.track_scale:.9f}: E1 moves the robot by scale * E1; "
                     "correct the gear ratio of E1 in the machine data by this factor")
    if data.positioner_frames and data.turntable is not None:
        k = 2 if data.track_root is not None else 1
        frames = data.positioner_frames
        n = len(frames) - 1
        null = np.eye(4)
        chain = [*frames[:n], *[null] * (3 - n)]
        L.append(f"; positioner {data.turntable.name}: external base kinematic "
                 f"$EX_KIN={{ET{k} #EASYS,...}} with {n} axes; +Z on each axis")
        L.append(f"; chain: MACHINE_DEF[{MACHINE_INDEX}].ROOT : $ET{k}_TA1KR : Rot(Z, axis 1) : "
                 f"$ET{k}_TA2A1 : Rot(Z, axis 2) : $ET{k}_TA3A2 : Rot(Z, axis 3) : $ET{k}_TFLA3")
        for key, T in zip(_ET_FRAMES, [*chain, frames[n]]):
            L.append(f"$ET{k}_{key}={frame_text(T)}")
    for name in data.skipped:
        L.append(f"; frame {name!r} moves with the robot on the track: no KUKA base holds it")
    return "\n".join(L) + "\n"



_FRAME_RE = r"\{([^{}]*)\}"
_LINE_RE = {
    "data": re.compile(r"^\s*(TOOL_DATA|BASE_DATA)\[(\d+)\]\s*=\s*" + _FRAME_RE + r"(.*)$",
                       re.IGNORECASE),
    "name": re.compile(r'^\s*(TOOL_NAME|BASE_NAME)\[(\d+),\]\s*=\s*"([^"]*)"', re.IGNORECASE),
    "machine": re.compile(r'^\s*MACHINE_DEF\[(\d+)\]\s*=\s*\{\s*NAME\[\]\s*"([^"]*)".*?ROOT\s*'
                          + _FRAME_RE + r".*?MECH_TYPE\s*#(\w+)", re.IGNORECASE),
    "var": re.compile(r"^\s*\$(ROBROOT|ERSYSROOT|ET\d_TA1KR|ET\d_TA2A1|ET\d_TA3A2|ET\d_TFLA3)"
                      r"\s*=\s*" + _FRAME_RE, re.IGNORECASE),
}


def parse_frame(body: str, where: str) -> np.ndarray:
    """Parse the inside of a KRL ``FRAME`` aggregate (``X 1.0,Y 2.0,...``) into a pose (metres)."""
    vals: dict[str, float] = {}
    for part in body.split(","):
        tok = part.split()
        if len(tok) != 2 or tok[0].upper() not in _KEYS:
            raise InputError(f"{where}: cannot read {part.strip()!r} (expected e.g. 'X 12.5')")
        vals[tok[0].upper()] = parse_float(tok[1], where)
    missing = [k for k in _KEYS if k not in vals]
    if missing:
        raise InputError(f"{where}: frame lacks {', '.join(missing)}")
    return pose_from_vendor([vals[k] for k in _KEYS], "kuka")


def parse(text: str) -> ControllerData:
    """Read KUKA lines (as written by :func:`export`) back into :class:`ControllerData`.

    Parameters
    ----------
    text : str
        ``$config.dat`` / ``$machine.dat`` lines; other lines and comments are ignored.

    Returns
    -------
    ControllerData
        Poses in metres. Tool and base names come from ``TOOL_NAME`` / ``BASE_NAME`` (else
        ``tool<n>``, ``base<n>``).
    """
    data = ControllerData()
    tools: dict[int, np.ndarray] = {}
    bases: dict[int, tuple[np.ndarray, bool]] = {}
    names: dict[tuple[str, int], str] = {}
    ersys: dict[str, np.ndarray] = {}
    for lineno, line in enumerate(text.splitlines(), start=1):
        where = f"line {lineno}"
        if m := _LINE_RE["data"].match(line):
            kind, n, T = m.group(1).upper(), int(m.group(2)), parse_frame(m.group(3), where)
            if kind == "TOOL_DATA":
                tools[n] = T
            else:
                bases[n] = (T, "MACHINE_DEF[" in m.group(4).upper())
        elif m := _LINE_RE["name"].match(line):
            names[(m.group(1).upper()[:4], int(m.group(2)))] = m.group(3)
        elif m := _LINE_RE["machine"].match(line):
            if m.group(4).upper() != "EASYS":
                raise InputError(f"{where}: MECH_TYPE #{m.group(4)} is not a turntable (#EASYS)")
            data.turntable = Slot(m.group(2), None, parse_frame(m.group(3), where))
        elif m := _LINE_RE["var"].match(line):
            ersys[m.group(1).upper()] = parse_frame(m.group(2), where)
    for n in sorted(tools):
        data.tools.append(Slot(names.get(("TOOL", n), f"tool{n}"), n, tools[n]))
    for n in sorted(bases):
        T, on_table = bases[n]
        data.frames.append(Slot(names.get(("BASE", n), f"base{n}"), n, T, on_table=on_table))
    if "ROBROOT" in ersys:
        data.robot = Slot("robot", None, ersys["ROBROOT"])
    if "ERSYSROOT" in ersys:
        data.track_root = Slot("track", None, ersys["ERSYSROOT"] @ ersys.get("ET1_TA1KR", np.eye(4)))
        data.track_robot = Slot("track", None, ersys.get("ET1_TFLA3", np.eye(4)))
    k = 2 if "ERSYSROOT" in ersys else 1
    if f"ET{k}_TFLA3" in ersys:
        data.positioner_frames = [ersys.get(f"ET{k}_{key}", np.eye(4)) for key in _ET_FRAMES]
    return data
