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

Read: the same, and what pendants and offline tools write: ``MoveAbsJ`` to ``jointtarget``s,
points inline in the instruction, ``tooldata``/``wobjdata`` declared in the module (they win
over the cell's of the same name), statements over several lines, optional arguments
(``\\Conc``, ``\\V``, ``\\Z``). Targets computed at run time (``Offs``, ``RelTool``,
``CalcRobT``) and circular motions are skipped and named.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from robotcell.controllers.abb import export as export_abb
from robotcell.controllers.data import MM_DECIMALS, QUAT_DECIMALS
from robotcell.controllers.model import Config, Program, ProgramPoint, Ref
from robotcell.controllers.text import JOINT_DECIMALS, Lines, fmt_num, strip_comment
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor

__all__ = ["EAX", "config_text", "read", "set_joints", "set_pose", "write"]

#: The logical external axes of a robtarget, in order.
EAX = ("eax_a", "eax_b", "eax_c", "eax_d", "eax_e", "eax_f")
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


def _speed_text(v: float) -> str:
    mm = v * 1e3
    for s in SPEEDS:
        if abs(mm - s) < 1e-9:
            return f"v{s}"
    return f"[{mm:.6g},500,5000,1000]"


def _zone_text(z: float) -> str:
    mm = z * 1e3
    if mm == 0:
        return "fine"
    for s in ZONES:
        if abs(mm - s) < 1e-9:
            return f"z{s}"
    # the pattern of the predefined zones (z10: 10, 15, 15, 1.5, 15, 1.5)
    values = (mm, 1.5 * mm, 1.5 * mm, 0.15 * mm, 1.5 * mm, 0.15 * mm)
    return "[FALSE," + ",".join(f"{v:.6g}" for v in values) + "]"


def _robtarget(p: ProgramPoint) -> str:
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


def _declarations(program: Program, tool: str, wobj: str) -> list[str]:
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
         *_declarations(program, tool, wobj),
         ("    ! robtarget: x, y, z (mm) and quaternion [q1,q2,q3,q4] of the TCP in the work "
          "object, confdata [cf1,cf4,cf6,cfx], extax (track mm, table deg; 9E9: no axis)")]
    L += [f"    CONST robtarget {p.name}:={_robtarget(p)};" for p in program.points]
    L += ["", f"    PROC {name}()", "        ConfJ \\On;", "        ConfL \\On;"]
    for p in program.points:
        move = "MoveJ" if p.motion == "ptp" else "MoveL"
        L.append(f"        {move} {p.name},{_speed_text(p.speed or 0.1)},"
                 f"{_zone_text(p.zone or 0.0)},{tool}\\WObj:={wobj};")
    L += ["    ENDPROC", "ENDMODULE"]
    return {f"{name}.mod": "\n".join(L) + "\n"}


# -- reading -------------------------------------------------------------------------------------
_DECL_RE = re.compile(r"^(?:LOCAL\s+|TASK\s+)?(CONST|PERS|VAR)\s+(\w+)\s+(\w+)\s*:=\s*(.*)$",
                      re.IGNORECASE | re.DOTALL)
_MOVE_RE = re.compile(r"^(MoveJ|MoveL|MoveAbsJ|MoveC|MoveJDO|MoveLDO|MoveJSync|MoveLSync)\b\s*"
                      r"(.*)$", re.IGNORECASE | re.DOTALL)


def _statements(lines: Lines) -> list[tuple[int, str]]:
    """RAPID statements (ending with ``;``, keywords without) with their first line."""
    out: list[tuple[int, str]] = []
    cur: list[str] = []
    start = 0
    header = False  # the %%% ... %%% block of old .prg/.mod files
    for lineno, raw in enumerate(lines.lines, start=1):
        line = strip_comment(raw, "!").strip()
        if line.startswith("%%%"):
            header = not header
            continue
        if not line or header:
            continue
        if not cur:
            start = lineno
        cur.append(line)
        text = " ".join(cur)
        keyword = re.match(r"^(MODULE|ENDMODULE|PROC|ENDPROC|FUNC|ENDFUNC|TRAP|ENDTRAP|IF|ELSE|"
                           r"ENDIF|FOR|ENDFOR|WHILE|ENDWHILE|TEST|CASE|DEFAULT|ENDTEST|ERROR|"
                           r"BACKWARD|UNDO)\b", text, re.IGNORECASE)
        if text.endswith(";") or (keyword and len(cur) == 1):
            out.append((start, text.rstrip(";").strip()))
            cur = []
    if cur:
        raise lines.error(start, f"the statement {' '.join(cur)[:40]!r} has no ';' (truncated "
                                 "file?)")
    return out


def _split(text: str) -> list[str]:
    """Top-level comma-separated parts of ``text`` (brackets and parentheses kept)."""
    parts, depth, cur, quoted = [], 0, [], False
    for ch in text:
        if ch == '"':
            quoted = not quoted
        elif not quoted and ch in "[(":
            depth += 1
        elif not quoted and ch in "])":
            depth -= 1
        if ch == "," and depth == 0 and not quoted:
            parts.append("".join(cur).strip())
            cur = []
        else:
            cur.append(ch)
    parts.append("".join(cur).strip())
    return parts


def _inner(text: str, lines: Lines, lineno: int) -> list[str]:
    t = text.strip()
    if not (t.startswith("[") and t.endswith("]")):
        raise lines.error(lineno, f"expected [...], got {t[:40]!r}")
    return _split(t[1:-1])


def _numbers(text: str, count: int, lines: Lines, lineno: int) -> list[float]:
    parts = _inner(text, lines, lineno)
    if len(parts) != count:
        raise lines.error(lineno, f"expected {count} values in {text.strip()[:40]!r}")
    return [lines.number(p, lineno) for p in parts]


def _external(text: str, lines: Lines, lineno: int) -> dict[str, float]:
    values = _numbers(text, 6, lines, lineno)
    return {k: v for k, v in zip(EAX, values) if abs(v) < 9e8}


class _Target:
    def __init__(self, kind: str, value: str, lines: Lines, lineno: int) -> None:
        self.where = lines.where(lineno)
        parts = _inner(value, lines, lineno)
        if kind == "jointtarget":
            if len(parts) != 2:
                raise lines.error(lineno, "a jointtarget is [[axes 1-6],[external axes]]")
            self.pose, self.config = None, None
            self.joints = np.radians(_numbers(parts[0], 6, lines, lineno))
        else:
            if len(parts) != 4:
                raise lines.error(lineno, "a robtarget is [[x,y,z],[q1,q2,q3,q4],"
                                          "[cf1,cf4,cf6,cfx],[external axes]]")
            xyz = _numbers(parts[0], 3, lines, lineno)
            quat = _numbers(parts[1], 4, lines, lineno)
            try:
                self.pose = pose_from_vendor(xyz + quat, "abb")
            except InputError as exc:
                raise lines.error(lineno, str(exc)) from None
            cf = _numbers(parts[2], 4, lines, lineno)
            self.config = Config("abb", tuple(round(c) for c in cf))
            self.joints = None
        self.external = _external(parts[-1], lines, lineno)


def read(path: str | Path) -> tuple[Program, list[str]]:
    """Read a RAPID module.

    Parameters
    ----------
    path : str or Path
        A ``.mod`` (or ``.prg``) file.

    Returns
    -------
    program : Program
        Points in the order the module's procedures move to them; ``line`` is the line of the
        move instruction.
    skipped : list of str
        Motions not turned into points (computed targets, circular motions).

    Raises
    ------
    InputError
        No ``MODULE``/``ENDMODULE``, a statement without ``;``, an unreadable target, a move to a
        target declared nowhere; the message names the file and line.
    """
    lines = Lines(path, "RAPID module")
    statements = _statements(lines)
    if not statements or not re.match(r"^MODULE\b", statements[0][1], re.IGNORECASE):
        raise InputError(f"{path}: no MODULE line: not a RAPID module")
    if not re.match(r"^ENDMODULE\b", statements[-1][1], re.IGNORECASE):
        raise InputError(f"{path}: line {len(lines.lines)}: no ENDMODULE (truncated file?)")
    name = statements[0][1].split()[1] if len(statements[0][1].split()) > 1 else Path(path).stem
    targets: dict[str, _Target] = {}
    data: dict[str, tuple[str, str]] = {}
    tools: dict[str, np.ndarray] = {}
    wobjs: dict[str, Ref] = {}
    for lineno, text in statements:
        m = _DECL_RE.match(text)
        if not m:
            continue
        kind, var, value = m.group(2).lower(), m.group(3), m.group(4)
        if kind in ("robtarget", "jointtarget"):
            targets[var.lower()] = _Target(kind, value, lines, lineno)
        elif kind in ("tooldata", "wobjdata"):
            compact = re.sub(r"\s+", "", value)
            slots = export_abb.parse(f"PERS {kind} {var}:={compact};")
            if kind == "tooldata" and slots.tools:
                tools[var.lower()] = slots.tools[0].pose
            elif kind == "wobjdata" and slots.frames:
                s = slots.frames[0]
                wobjs[var.lower()] = Ref(name=var, pose=s.pose, on_table=s.on_table)
        elif kind in ("speeddata", "zonedata"):
            data[var.lower()] = (kind, value)
    points: list[ProgramPoint] = []
    skipped: list[str] = []
    for lineno, text in statements:
        m = _MOVE_RE.match(text)
        if not m:
            continue
        instr = m.group(1)
        if instr.lower() == "movec":
            skipped.append(f"line {lineno}: MoveC (circular motions are not checked)")
            continue
        args = [a for a in _split(m.group(2)) if a and not a.startswith("\\")]
        if len(args) < 4:
            raise lines.error(lineno, f"{instr} needs target, speed, zone and tool")
        target, speed, zone, tool = args[0], args[1], args[2], args[3]
        tool_name = tool.partition("\\")[0]
        wobj = re.search(r"\\WObj\s*:=\s*(\w+)", m.group(2), re.IGNORECASE)
        if target.startswith("["):
            kind = "jointtarget" if instr.lower() == "moveabsj" else "robtarget"
            value, pname = _Target(kind, target, lines, lineno), f"line {lineno}"
        elif re.match(r"^\w+$", target) and target.lower() in targets:
            value, pname = targets[target.lower()], target
        elif re.match(r"^\w+$", target):
            raise lines.error(lineno, f"{target} is not declared in the module")
        else:
            skipped.append(f"line {lineno}: {instr} {target} (a target computed at run time)")
            continue
        tname = tool_name.strip()
        tref = Ref(name=tname, pose=tools.get(tname.lower()))
        wname = wobj.group(1) if wobj else "wobj0"
        fref = wobjs.get(wname.lower(), Ref(name=wname, on_table=None))
        points.append(ProgramPoint(
            pname, lineno, "ptp" if instr.lower().startswith(("movej", "moveabsj")) else "lin",
            tref, fref, value.pose, value.joints, value.config, dict(value.external),
            _speed(speed, data, lines, lineno), _zone(zone, data, lines, lineno), value.where))
    return Program(name, "abb", points, (str(path),)), skipped


def _speed(text: str, data: dict, lines: Lines, lineno: int) -> float | None:
    t = text.strip()
    if m := re.match(r"^v(\d+)$", t, re.IGNORECASE):
        return int(m.group(1)) * 1e-3
    if t.lower() in data:
        t = data[t.lower()][1]
    if t.startswith("["):
        return lines.number(_split(t[1:-1])[0], lineno) * 1e-3
    return None


def _zone(text: str, data: dict, lines: Lines, lineno: int) -> float | None:
    t = text.strip()
    if t.lower() == "fine":
        return 0.0
    if m := re.match(r"^z(\d+)$", t, re.IGNORECASE):
        return int(m.group(1)) * 1e-3
    if t.lower() in data:
        t = data[t.lower()][1]
    if t.startswith("["):
        parts = _split(t[1:-1])
        return 0.0 if parts[0].upper() == "TRUE" else lines.number(parts[1], lineno) * 1e-3
    return None


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
