"""ABB RAPID programs: one module ``NAME.mod`` with the points and a procedure that moves to them.

Written (sources in ``docs/programs.md``):

- ``CONST robtarget pi:=[[x,y,z],[q1,q2,q3,q4],[cf1,cf4,cf6,cfx],[eax_a,...,eax_f]];`` per point:
  the TCP in the work object (mm, quaternion scalar first), the configuration
  (:mod:`robotcell.programs.config`), the external axes (track mm, table deg; ``9E9`` for axes
  the cell lacks);
- ``MODULE MOD_NAME`` (RoboDK's ABB post names the module apart from the routine), the program's
  ``tooldata`` and ``wobjdata`` declared in it as ``LOCAL PERS`` with the values of ``robotcell
  export`` (local to the module, as RoboDK declares its own);
- ``PROC NAME()`` with ``ConfJ \\On; ConfL \\On;`` and ``MoveJ``/``MoveL pi, speed, zone,
  tool\\WObj:=wobj;`` where the tool and the work object are the ``tooldata`` and ``wobjdata``
  that ``robotcell export`` writes (``wobj0`` for the world); speeds and zones are ABB's
  predefined data where one matches (``v100``, ``z10``, ``fine``), else written out.

Read: by :mod:`robotcell.controllers.abb.reader` (:func:`read`), which follows RAPID's grammar
and names what the module does not hold as not checked.
"""

from __future__ import annotations

import math
import re

import numpy as np
from numpy.typing import NDArray

from robotcell.controllers.abb import export as export_abb
from robotcell.controllers.abb.reader import EAX, read
from robotcell.controllers.data import MM_DECIMALS, QUAT_DECIMALS
from robotcell.controllers.model import Config, Program, ProgramPoint
from robotcell.controllers.text import JOINT_DECIMALS, fmt_num
from robotcell.io.poseformats import pose_to_vendor

__all__ = ["EAX", "config_text", "declarations", "read", "robtarget_text", "set_joints", "set_pose",
           "speed_text", "write", "zone_text"]

#: ABB's value of an external axis that is not connected.
NO_AXIS = "9E9"
#: Predefined speeddata (mm/s) and zonedata (mm) of the RAPID reference.
SPEEDS = (5, 10, 20, 30, 40, 50, 60, 80, 100, 150, 200, 300, 400, 500, 600, 800, 1000, 1500,
          2000, 2500, 3000, 4000, 5000, 6000, 7000)
ZONES = (0, 1, 5, 10, 15, 20, 30, 40, 50, 60, 80, 100, 150, 200)


# -- writing -------------------------------------------------------------------------------------
def config_text(values: tuple[int, ...]) -> str:
    """``confdata`` as a ``robtarget`` writes it: ``[0,-1,0,1]``."""
    return "[" + ",".join(str(x) for x in values) + "]"


def speed_text(v: float) -> str:
    """``speeddata`` of a TCP speed ``v`` (m/s): predefined (``v100``) or written out."""
    mm = v * 1e3
    for s in SPEEDS:
        if abs(mm - s) < 1e-9:
            return f"v{s}"
    return f"[{mm:.6g},500,5000,1000]"


def zone_text(z: float) -> str:
    """``zonedata`` of a corner distance ``z`` (m): ``fine``, predefined (``z10``) or written
    out."""
    mm = z * 1e3
    if mm == 0:
        return "fine"
    for s in ZONES:
        if abs(mm - s) < 1e-9:
            return f"z{s}"
    # the pattern of the predefined zones (z10: 10, 15, 15, 1.5, 15, 1.5)
    values = (mm, 1.5 * mm, 1.5 * mm, 0.15 * mm, 1.5 * mm, 0.15 * mm)
    return "[FALSE," + ",".join(f"{v:.6g}" for v in values) + "]"


def robtarget_text(p: ProgramPoint) -> str:
    """The ``robtarget`` value of a Cartesian point (mm, quaternion, confdata, extax)."""
    assert p.pose is not None and p.config is not None
    v = pose_to_vendor(p.pose, "abb")
    trans = ",".join(fmt_num(x, MM_DECIMALS) for x in v[:3])
    quat = ",".join(fmt_num(x, QUAT_DECIMALS) for x in v[3:])
    eax = ",".join(fmt_num(p.external[k], MM_DECIMALS) if k in p.external else NO_AXIS
                   for k in EAX)
    return f"[[{trans}],[{quat}],{config_text(p.config.values)},[{eax}]]"


#: What the module name adds to the program's name: RoboDK's ABB post writes ``MODULE MOD_NAME``
#: with ``PROC NAME()`` in it, a module and a routine of two names.
MODULE_PREFIX = "MOD_"


def declarations(program: Program, tool: str, wobj: str) -> list[str]:
    """``LOCAL PERS`` declarations of the program's tool and work object, with the values of
    ``robotcell export``, so that the module holds what it moves with (empty where the program
    carries no cell data, and for ``wobj0``)."""
    data = program.data
    if data is None:
        return []
    out = []
    t = next((s for s in data.tools if s.name == tool), None)
    if t is not None:
        if t.mass is None:
            out.append(f"    ! {t.name}: mass unknown in the cell, load0 written; set the real load")
        out.append(f"    LOCAL PERS tooldata {t.name}:={export_abb.tooldata_text(t)};")
    w = next((s for s in data.frames if s.name == wobj), None)
    if w is not None:
        unit = data.turntable.name if data.turntable is not None else None
        out.append(f"    LOCAL PERS wobjdata {w.name}:={export_abb.wobjdata_text(w, unit)};")
    if out:
        out.insert(0, ("    ! tool and work object as robotcell export writes them, local to this "
                       "module"))
    return out


def write(program: Program, header: list[str]) -> dict[str, str]:
    """``NAME.mod`` of a program of Cartesian points: ``MODULE MOD_NAME`` holding the tool and
    the work object (``LOCAL PERS``), the targets and ``PROC NAME()``.

    Parameters
    ----------
    program : Program
        Points with ``pose``, ``config`` (ABB confdata) and ``external`` (``eax_a``..), one tool
        and one work object (by name), and the cell's data (``program.data``) to declare them.
    header : list of str
        Comment lines (without ``!``).

    Returns
    -------
    dict of str to str
        File name -> text.
    """
    name = program.name
    first = program.points[0]
    tool, wobj = first.tool.name, first.frame.name or "wobj0"
    L = [f"MODULE {MODULE_PREFIX}{name}", *(f"    ! {h}" for h in header),
         *declarations(program, tool, wobj),
         ("    ! robtarget: x, y, z (mm) and quaternion [q1,q2,q3,q4] of the TCP in the work "
          "object, confdata [cf1,cf4,cf6,cfx], extax (track mm, table deg; 9E9: no axis)")]
    L += [f"    CONST robtarget {p.name}:={robtarget_text(p)};" for p in program.points]
    L += ["", f"    PROC {name}()", "        ConfJ \\On;", "        ConfL \\On;"]
    for p in program.points:
        move = "MoveJ" if p.motion == "ptp" else "MoveL"
        L.append(f"        {move} {p.name},{speed_text(p.speed or 0.1)},"
                 f"{zone_text(p.zone or 0.0)},{tool}\\WObj:={wobj};")
    L += ["    ENDPROC", "ENDMODULE"]
    return {f"{name}.mod": "\n".join(L) + "\n"}


# -- editing in place ----------------------------------------------------------------------------
def set_joints(lines: list[str], idx: int, q: NDArray[np.float64]) -> bool:
    """Write the robot axes (``q``, rad) of the ``jointtarget`` on line ``idx``."""
    line = lines[idx]
    m = re.search(r"\[\s*\[([^\[\]]*)\]", line)
    if not m or len(m.group(1).split(",")) != 6:
        return False
    values = ",".join(fmt_num(math.degrees(v), JOINT_DECIMALS) for v in q)
    lines[idx] = line[:m.start(1)] + values + line[m.end(1):]
    return True


def set_pose(lines: list[str], idx: int, T: NDArray[np.float64], config: Config | None) -> bool:
    """Write the position and quaternion (``T``, m) and, unless None, the ``confdata`` of the
    ``robtarget`` on line ``idx``."""
    line = lines[idx]
    m = re.search(r"\[\s*\[([^\[\]]*)\]\s*,\s*\[([^\[\]]*)\]\s*,\s*\[([^\[\]]*)\]", line)
    if not m or len(m.group(1).split(",")) != 3 or len(m.group(2).split(",")) != 4:
        return False
    v = pose_to_vendor(T, "abb")
    parts = [(m.start(1), m.end(1), ",".join(fmt_num(x, MM_DECIMALS) for x in v[:3])),
             (m.start(2), m.end(2), ",".join(fmt_num(x, QUAT_DECIMALS) for x in v[3:]))]
    if config is not None:
        parts.append((m.start(3), m.end(3), ",".join(str(x) for x in config.values)))
    for start, end, text in reversed(parts):
        line = line[:start] + text + line[end:]
    lines[idx] = line
    return True
