"""Universal Robots programs: one URScript file ``NAME.script`` (sources in ``docs/programs.md``).

Written:

- ``def NAME():`` .. ``end``, then the call ``NAME()`` (the form of RoboDK's Universal Robots
  post and of the scripts PolyScope saves), the header as ``#`` comments;
- ``set_tcp(p[x, y, z, rx, ry, rz])``: the program's tool, the TCP in the tool flange frame, as
  ``robotcell export --format ur`` writes it;
- for a frame of the cell, ``global NAME=p[..]``: the feature's pose in the robot base, and each
  point as ``pose_trans(NAME, p[..])``, the pose in the feature (the manual's ``pose_trans``:
  ``T_base_to = T_base_feature T_feature_to``); in the base frame the pose alone;
- a joint motion as ``movej(pose, r=..)`` (the controller finds the joints by inverse
  kinematics, nearest to where the arm is; joint speed and acceleration left at the manual's
  defaults), a joint point as ``movej([q1, .., q6], r=..)`` in rad; a linear motion as
  ``movel(pose, v=.., r=..)``: the TCP speed in m/s, the blend radius ``r`` in m (0: stop).

Poses in m (9 decimals) and a rotation vector in rad (11 decimals), joints in rad (12).
A UR arm has no configuration flags and no external axes: a cell with a track or a turntable
is refused before a program is written (:meth:`robotcell.controllers.ur.UniversalRobots.data`).

Read: by :mod:`robotcell.controllers.ur.reader` (:func:`read`).
"""

from __future__ import annotations

import re

import numpy as np
from numpy.typing import NDArray

from robotcell.controllers.data import fmt_num
from robotcell.controllers.model import Config, Program, ProgramPoint, Ref
from robotcell.controllers.text import NUMBER
from robotcell.controllers.ur.export import identifier, pose_text
from robotcell.controllers.ur.reader import read
from robotcell.errors import InputError

__all__ = ["read", "set_joints", "set_pose", "write"]

#: Decimals of joint values written (rad): 5e-13 rad.
Q_DECIMALS = 12
#: Decimals of speeds (m/s) and blend radii (m) written: 1e-6 mm.
SPEED_DECIMALS = 9


def _frame_line(program: Program, frame: Ref) -> str:
    """``global NAME=p[..]`` of the program's frame: its pose as the reference holds it, else
    the cell's frame of that name (in the robot base)."""
    name = frame.name or ""
    pose = frame.pose
    if pose is None and program.data is not None:
        pose = next((s.pose for s in program.data.frames if s.name == name), None)
    if pose is None or not name:
        raise InputError(f"frame {frame.label()}: the program holds no pose and name of it "
                         "(write the program from a cell that has it)")
    return f"  global {identifier(name, 'frame')}={pose_text(pose)}"


def _tool_line(program: Program, p: ProgramPoint) -> str:
    """``set_tcp(p[..])`` of the program's tool: its pose as the reference holds it, else the
    cell's tool of that name."""
    pose = p.tool.pose
    if pose is None and program.data is not None:
        pose = next((s.pose for s in program.data.tools if s.name == p.tool.name), None)
    if pose is None:
        raise InputError(f"tool {p.tool.label()}: the program holds no pose of it (write the "
                         "program from a cell that has it)")
    return f"  set_tcp({pose_text(pose)})"


def _target(p: ProgramPoint, feature: str | None) -> str:
    if p.joints is not None:
        return "[" + ", ".join(fmt_num(q, Q_DECIMALS) for q in p.joints) + "]"
    assert p.pose is not None
    pose = pose_text(p.pose)
    return pose if feature is None else f"pose_trans({feature}, {pose})"


def motion_text(p: ProgramPoint, feature: str | None) -> str:
    """The motion to one point: ``movej(..., r=..)`` or ``movel(..., v=.., r=..)``."""
    r = f"r={fmt_num(p.zone or 0.0, SPEED_DECIMALS)}"
    if p.motion == "ptp":
        return f"  movej({_target(p, feature)}, {r})"
    return f"  movel({_target(p, feature)}, v={fmt_num(p.speed or 0.1, SPEED_DECIMALS)}, {r})"


def write(program: Program, header: list[str]) -> dict[str, str]:
    """``NAME.script`` of a program: ``def NAME():`` with the tool, the feature and the
    motions, then ``NAME()``.

    Parameters
    ----------
    program : Program
        Points with ``pose`` (m, in the frame) or ``joints`` (rad), one tool and one frame,
        and the cell's data (``program.data``) for their poses.
    header : list of str
        Comment lines (without ``#``).

    Returns
    -------
    dict of str to str
        File name -> text.

    Raises
    ------
    InputError
        A frame or tool whose pose the program does not hold, or a frame name that is not a
        URScript name.
    """
    name = program.name
    first = program.points[0]
    frame = first.frame
    feature = frame.name if frame.name or frame.pose is not None else None
    L = [f"def {name}():", *(f"  # {h}" for h in header),
         ("  # poses p[x, y, z, rx, ry, rz]: m and a rotation vector (rad); joints in rad; "
          "v in m/s, r (blend radius) in m"),
         f"  # tool {first.tool.label()}", _tool_line(program, first)]
    if feature is not None:
        L += [f"  # feature {feature}: its pose in the robot base", _frame_line(program, frame)]
    L += [motion_text(p, feature) for p in program.points]
    L += ["end", f"{name}()"]
    return {f"{name}.script": "\n".join(L) + "\n"}


# -- editing in place ----------------------------------------------------------------------------
_POSE_RE = re.compile(r"p\[[^\[\]]*\]")
_LIST_RE = re.compile(r"(?<![\w\]])\[\s*" + r"\s*,\s*".join([f"({NUMBER})"] * 6) + r"\s*\]")


def set_pose(lines: list[str], idx: int, T: NDArray[np.float64], config: Config | None) -> bool:
    """Write the pose ``T`` (m, in the point's frame) into the last ``p[..]`` of line ``idx``
    (the target of ``movel(pose_trans(F, p[..]))``, of ``movel(p[..])`` or of
    ``global X=p[..]``); a UR arm has no flags, ``config`` is not written."""
    line = lines[idx]
    found = list(_POSE_RE.finditer(line))
    if not found:
        return False
    m = found[-1]
    lines[idx] = line[:m.start()] + pose_text(T) + line[m.end():]
    return True


def set_joints(lines: list[str], idx: int, q: NDArray[np.float64]) -> bool:
    """Write the six joint values ``q`` (rad) into the first list of six numbers on line
    ``idx``."""
    line = lines[idx]
    m = _LIST_RE.search(line)
    if not m:
        return False
    text = "[" + ", ".join(fmt_num(v, Q_DECIMALS) for v in q) + "]"
    lines[idx] = line[:m.start()] + text + line[m.end():]
    return True
