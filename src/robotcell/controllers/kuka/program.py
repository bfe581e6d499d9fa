"""KUKA KRL programs: ``NAME.src`` (the motions) and ``NAME.dat`` (the points), both ways.

Written (sources in ``docs/programs.md``):

- ``NAME.src``: ``DEF NAME( )``, the initialisation that pendant-made programs start with
  (``BAS (#INITMOV,0 )`` after the stop interrupt), ``$TOOL=TOOL_DATA[n]``, ``$BASE=BASE_DATA[n]``
  for a base fixed in the cell or ``$BASE=EK(MACHINE_DEF[2].ROOT,MACHINE_DEF[2].MECH_TYPE,
  BASE_DATA[n])`` for a base on the turntable (the numbers of ``robotcell export``),
  ``$ACT_EX_AX=n``, the number of external axes the program moves (track and table axes, as
  RoboDK's KUKA posts write it), ``$VEL.CP`` (m/s), ``$APO.CDIS`` (mm), then ``PTP XPi`` / ``LIN XPi`` (``C_DIS`` where the zone
  is not 0) and ``END``.
- ``NAME.dat``: ``DEFDAT NAME`` with one ``DECL E6POS XPi={X ..,Y ..,Z ..,A ..,B ..,C ..,S ..,
  T ..,E1 ..,...,E6 ..}`` per point (mm, deg; ``R = Rz(A) Ry(B) Rx(C)``) and ``ENDDAT``.

Read: by :mod:`robotcell.controllers.kuka.reader` (:func:`read`), which follows KRL's grammar
and names what the files do not hold as not checked.
"""

from __future__ import annotations

import math
import re

import numpy as np
from numpy.typing import NDArray

from robotcell.controllers.data import DEG_DECIMALS, MM_DECIMALS
from robotcell.controllers.kuka.export import MACHINE_INDEX
from robotcell.controllers.kuka.reader import read
from robotcell.controllers.model import PTP_SPEED, Config, Program, ProgramPoint, Ref
from robotcell.controllers.text import JOINT_DECIMALS, NUMBER, fmt_num
from robotcell.io.poseformats import pose_to_vendor

__all__ = ["config_text", "read", "set_joints", "set_pose", "write"]

_POSE_KEYS = ("X", "Y", "Z", "A", "B", "C")
_EXT_KEYS = tuple(f"E{i}" for i in range(1, 7))


# -- writing -------------------------------------------------------------------------------------
def config_text(values: tuple[int, ...]) -> str:
    """Status and Turn as an ``E6POS`` writes them: ``S 6,T 50``."""
    return f"S {values[0]},T {values[1]}"


def _aggregate(p: ProgramPoint) -> str:
    assert p.pose is not None and p.config is not None
    v = pose_to_vendor(p.pose, "kuka")
    parts = [f"{k} {fmt_num(x, MM_DECIMALS if i < 3 else DEG_DECIMALS)}"
             for i, (k, x) in enumerate(zip(_POSE_KEYS, v))]
    parts.append(config_text(p.config.values))
    parts += [f"{k} {fmt_num(p.external.get(k, 0.0), DEG_DECIMALS)}" for k in _EXT_KEYS]
    return "{" + ",".join(parts) + "}"


def _base_line(ref: Ref) -> str:
    if ref.number in (None, 0):
        return "$BASE=$NULLFRAME"
    if ref.on_table:
        m = MACHINE_INDEX
        return (f"$BASE=EK(MACHINE_DEF[{m}].ROOT,MACHINE_DEF[{m}].MECH_TYPE,"
                f"BASE_DATA[{ref.number}])")
    return f"$BASE=BASE_DATA[{ref.number}]"


def _external_axes(program: Program) -> int:
    """The number of external axes the program moves: the track and the table's axes it
    writes (``E1``..), the unused ones (written as 0) left out."""
    return len({k for p in program.points for k in p.external})


def write(program: Program, header: list[str]) -> dict[str, str]:
    """``NAME.src`` and ``NAME.dat`` of a program of Cartesian points.

    Parameters
    ----------
    program : Program
        Points with ``pose``, ``config`` (KUKA S/T) and ``external`` (``E1``..), one tool and
        one base.
    header : list of str
        Comment lines (without ``;``) that say where the program comes from.

    Returns
    -------
    dict of str to str
        File name -> text.
    """
    name = program.name
    first = program.points[0]
    src = ["&ACCESS RVP", "&REL 1", f"DEF {name}( )", *(f"; {h}" for h in header),
           (f"; points: {name}.dat (X, Y, Z mm, A, B, C deg with R = Rz(A) Ry(B) Rx(C) in "
            "the base; S, T; E1..E6)"),
           ";FOLD INI", "  ;FOLD BASISTECH INI",
           "    GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )",
           "    INTERRUPT ON 3", "    BAS (#INITMOV,0 )", "  ;ENDFOLD (BASISTECH INI)",
           ";ENDFOLD (INI)",
           f"$TOOL=TOOL_DATA[{first.tool.number}]  ; {first.tool.name}",
           _base_line(first.frame) + (f"  ; {first.frame.name}" if first.frame.name else "")]
    axes = _external_axes(program)
    if axes:
        src.append(f"$ACT_EX_AX={axes}")
    speed = zone = None
    for i, p in enumerate(program.points):
        if p.motion == "lin" and p.speed is not None and p.speed != speed:
            src.append(f"$VEL.CP={p.speed:.6g}")
            speed = p.speed
        if p.motion == "ptp" and i == 0:
            src.append(f"BAS(#VEL_PTP,{PTP_SPEED * 100:.0f})")
        z = p.zone or 0.0
        if z > 0 and z != zone:
            src.append(f"$APO.CDIS={z * 1e3:.6g}")
            zone = z
        src.append(f"{p.motion.upper()} {p.name}" + (" C_DIS" if z > 0 else ""))
    src.append("END")
    dat = ["&ACCESS RVP", "&REL 1", f"DEFDAT {name}", *(f"; {h}" for h in header)]
    dat += [f"DECL E6POS {p.name}={_aggregate(p)}" for p in program.points]
    dat.append("ENDDAT")
    return {f"{name}.src": "\n".join(src) + "\n", f"{name}.dat": "\n".join(dat) + "\n"}


# -- editing in place ----------------------------------------------------------------------------
def set_joints(lines: list[str], idx: int, q: NDArray[np.float64]) -> bool:
    """Write the axis values ``A1..A6`` (``q``, rad) of the ``E6AXIS``/``AXIS`` on line ``idx``."""
    line = lines[idx]
    for i in range(6):
        line, n = re.subn(rf"(\bA{i + 1}\s+){NUMBER}", lambda m, v=q[i]: m.group(1)
                          + fmt_num(math.degrees(v), JOINT_DECIMALS), line, count=1,
                          flags=re.IGNORECASE)
        if n != 1:
            return False
    lines[idx] = line
    return True


def _replace_fields(line: str, values: dict[str, str], pattern: str) -> tuple[str, int]:
    """Replace the number after each key of ``values`` (``pattern`` has {key} and {num})."""
    done = 0
    for key, text in values.items():
        line, n = re.subn(pattern.format(key=key, num=NUMBER), lambda m, t=text: m.group(1) + t,
                          line, count=1, flags=re.IGNORECASE)
        done += n
    return line, done


def set_pose(lines: list[str], idx: int, T: NDArray[np.float64], config: Config | None) -> bool:
    """Write X..C (``T``, m) and, unless None, S and T of the ``E6POS``/``POS`` on line ``idx``."""
    v = pose_to_vendor(T, "kuka")
    values = {k: fmt_num(x, MM_DECIMALS if i < 3 else DEG_DECIMALS)
              for i, (k, x) in enumerate(zip(_POSE_KEYS, v))}
    line, done = _replace_fields(lines[idx], values, r"([{{,]\s*{key}\s+){num}")
    if done != 6:
        return False
    if config is not None:
        flags = {"S": str(config.values[0]), "T": str(config.values[1])}
        line, n = _replace_fields(line, flags, r"([{{,]\s*{key}\s+)(?:'B[01]+'|{num})")
        if n != 2:
            return False
    lines[idx] = line
    return True
