"""YASKAWA Motoman INFORM jobs: ``NAME.jbi`` (``/JOB``, ``//POS``, ``//INST``).

Written (sources in ``docs/programs.md``, chiefly the DX100 and NX100 manuals' job data format):

- ``//POS``: ``///NPOS c,bc,ec,0,0,0``; ``///USER n`` and ``///POSTYPE USER`` for a user frame
  (``///POSTYPE BASE`` for the world, which YASKAWA measures in the base coordinates at base
  axis 0), ``///TOOL n`` (the numbers of ``robotcell export``); ``///RECTAN``, then per point
  ``///RCONF l,m,n,o,p,q,0,...`` (24 values, where it changes) and ``Cxxxxx=X,Y,Z,Rx,Ry,Rz`` (mm, deg with
  ``R = Rz(Rz) Ry(Ry) Rx(Rx)``); the track as base axis ``BCxxxxx=mm``; then ``///POSTYPE
  PULSE``, ``///PULSE`` and the turntable or positioner as station axes ``ECxxxxx=pulses``;
- ``//INST``: ``///ATTR SC,RW,RJ`` (Cartesian positions: a relative job) with ``////FRAME USER
  n`` for a user frame, ``///GROUP1 RB1[,BS1]`` (the robot and its base axis) and ``///GROUP2
  ST1`` (the station, a group of its own), ``NOP``, ``MOVJ Cxxxxx [BCxxxxx] VJ=20.00`` or ``MOVL
  ... V=100.0``, ``PL=k`` for a zone, the station moved with it as ``+MOVJ ECxxxxx VJ=20.00``,
  ``END``.

Angles are written with 4 decimals (9e-7 rad), millimetres with 3, pulses as integers.

Read: the same, and what pendants and offline tools write: several ``USER``/``TOOL``/``RCONF``
blocks, ``RCONF`` with 6, 8 or 24 values, ``///FRAME`` with three or four slashes, sections
such as ``//ARGINFO`` between ``//POS`` and ``//INST``, ``+MOVJ`` station motions, tools set by
``SETTOOL`` from ``SETE`` values, in program order. Named as not checked, with the reason: pulse
positions of the robot (their pulses per degree are not in the job), position variables, tools
and user frames set at run time, station-only motions, ``MOVC``/``MOVS``/``SMOVC``, motions
whose station position is in degrees (``///POSTYPE ANGLE``), ``IMOV`` (incremental) and a
motion after another word (``COMM MOVJ P000``) (``docs/programs.md``).
"""

from __future__ import annotations

import re
import textwrap
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from robotcell.controllers.model import PTP_SPEED, Config, Program, ProgramPoint, Ref
from robotcell.controllers.text import Lines, fmt_num
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor

__all__ = ["config_text", "motion_parts", "move_text", "position_text", "rconf_text", "read",
           "read_groups", "set_pose", "write", "zone_text"]

#: Decimals written: mm, deg.
MM_PLACES, DEG_PLACES = 3, 4
#: Values of a ``///RCONF`` line: DX100 and later write 24, the first 6 used.
RCONF_VALUES = 24
#: Longest comment line (characters after ``'``; "up to 32 characters", NX100 job data format).
COMMENT_CHARS = 32


# -- writing -------------------------------------------------------------------------------------
def config_text(values: tuple[int, ...]) -> str:
    """``RCONF`` values as written, without the unused trailing ones: ``0,0,0,0,0,0``."""
    return ",".join(str(x) for x in values)


def zone_text(zone: float) -> str:
    """`` PL=k`` of a corner distance (m; PL 1..8 by its mm), empty for an exact stop."""
    mm = zone * 1e3
    return "" if mm <= 0 else f" PL={min(8, max(1, round(mm)))}"


def rconf_text(point: ProgramPoint) -> str:
    """The ``///RCONF`` values of a Cartesian point: its flags and the unused zeros (24 in
    all)."""
    assert point.config is not None
    values = point.config.values
    return config_text(values) + ",0" * (RCONF_VALUES - len(values))


def position_text(point: ProgramPoint) -> str:
    """``X,Y,Z,Rx,Ry,Rz`` of a Cartesian point (mm with 3 decimals, deg with 4), the values of
    its ``Cxxxxx=`` line."""
    assert point.pose is not None
    v = pose_to_vendor(point.pose, "yaskawa")
    return ",".join(fmt_num(x, MM_PLACES if k < 3 else DEG_PLACES) for k, x in enumerate(v))


def move_text(point: ProgramPoint, axes: str) -> str:
    """``MOVJ axes VJ=20.00`` or ``MOVL axes V=100.0`` of a point (``axes``: its positions,
    ``C00000 BC00000``), without a zone."""
    if point.motion == "ptp":
        return f"MOVJ {axes} VJ={PTP_SPEED * 100:.2f}"
    return f"MOVL {axes} V={(point.speed or 0.1) * 1e3:.1f}"


def write(program: Program, header: list[str]) -> dict[str, str]:
    """``NAME.jbi`` of a program of Cartesian points.

    Parameters
    ----------
    program : Program
        Points with ``pose``, ``config`` (RCONF) and ``external`` (``BC1``, ``EC1``..), one
        tool and one user frame (by number; None: the base coordinates).
    header : list of str
        Comment lines (``'`` comments, 32 characters each at most).

    Returns
    -------
    dict of str to str
    """
    pts = program.points
    first = pts[0]
    n = len(pts)
    base = [p.external["BC1"] for p in pts] if "BC1" in first.external else []
    station = sorted(k for k in first.external if k.startswith("EC"))
    user = first.frame.number
    pos = ["/JOB", f"//NAME {program.name}", "//POS",
           f"///NPOS {n},{n if base else 0},{n if station else 0},0,0,0"]
    if user:
        pos.append(f"///USER {user}")
    pos += [f"///TOOL {first.tool.number or 0}",
            f"///POSTYPE {'USER' if user else 'BASE'}", "///RECTAN"]
    rconf = None
    for i, p in enumerate(pts):
        text = rconf_text(p)
        if text != rconf:
            pos.append(f"///RCONF {text}")
            rconf = text
        pos.append(f"C{i:05d}={position_text(p)}")
    pos += [f"BC{i:05d}={fmt_num(b, MM_PLACES)}" for i, b in enumerate(base)]
    if station:
        pos += ["///POSTYPE PULSE", "///PULSE"]
        pos += [f"EC{i:05d}=" + ",".join(str(round(p.external[k])) for k in station)
                for i, p in enumerate(pts)]
    inst = ["//INST", "///DATE 2000/01/01 00:00", "///COMM robotcell", "///ATTR SC,RW,RJ",
            *([f"////FRAME USER {user}"] if user else []),
            "///GROUP1 RB1" + (",BS1" if base else ""), *(["///GROUP2 ST1"] if station else []),
            "NOP"]
    inst += [f"'{part}" for h in header for part in textwrap.wrap(h, COMMENT_CHARS)]
    for i, p in enumerate(pts):
        axes = f"C{i:05d}" + (f" BC{i:05d}" if base else "")
        move = move_text(p, axes) + zone_text(p.zone or 0.0)
        inst.append(move + (f" +MOVJ EC{i:05d} VJ={PTP_SPEED * 100:.2f}" if station else ""))
    inst.append("END")
    return {f"{program.name}.jbi": "\n".join(pos + inst) + "\n"}


# -- reading -------------------------------------------------------------------------------------
_DATA_RE = re.compile(r"^(C|BC|EC|P|BP|EX)(\d+)\s*=\s*(.*)$")
_MOVE_RE = re.compile(r"^\s*(MOVJ|MOVL|MOVC|MOVS|SMOVJ|SMOVL|SMOVC)\s+(.*)$", re.IGNORECASE)
#: ``IMOV P000 V=138 PL=1 RF``: a motion by the increment a variable holds, from where the
#: axes are (INFORM ``IMOV``): its target is not in the job.
_IMOV_RE = re.compile(r"^\s*IMOV\s+(\S+)", re.IGNORECASE)
#: A motion after another word (``COMM MOVJ P000``, saved by DX200 and YRC1000 controllers):
#: no job format robotcell cites describes it, so it is named, never read as a motion.
_PREFIXED_MOVE_RE = re.compile(r"^\s*([A-Z]\w*)\s+((?:S?MOV[JLCS]|IMOV)\b.*)$", re.IGNORECASE)
#: A coordinated job's second group moving with the line before (``+MOVJ EC00000 VJ=10.00``).
_COORD_MOVE_RE = re.compile(r"^\s*\+(MOVJ|MOVL|MOVC|MOVS)\s+(.*)$", re.IGNORECASE)
#: ``SETTOOL TL#(n) P001``: tool n set from a position variable (INFORM, "SETTOOL").
_SETTOOL_RE = re.compile(r"^\s*SETTOOL\s+TL#\(\s*(\d+)\s*\)\s*(\S+)?", re.IGNORECASE)
#: ``SETE P00095 (1) -30000``: element k (1..6: X, Y, Z, Rx, Ry, Rz) of a position variable.
_SETE_RE = re.compile(r"^\s*SETE\s+(L?P\d+)\s*\(\s*(\d+)\s*\)\s*(\S+)", re.IGNORECASE)
#: ``MFRAME UF#(n) PX000 PX001 PX002``: user frame n made from position variables.
_MFRAME_RE = re.compile(r"^\s*MFRAME\s+UF#\(\s*(\d+)\s*\)", re.IGNORECASE)
#: Characters that end a line without being part of it (whitespace, the Ctrl-Z end of file).
_BLANK = " \t\r\n\x1a\x00"
#: Where a motion of another group starts on a motion line (``MOVJ C00000 EC00000 VJ=10.00
#: +MOVJ C00001 VJ=10.00``: a job of two robots and a station saved by a DX200).
_PARTNER_SPLIT = re.compile(r"\s+\+(?=(?:MOVJ|MOVL|MOVC|MOVS)\b)", re.IGNORECASE)
#: A robot's position in a motion: a ``C`` position or a position variable.
ROBOT_POSITION = re.compile(r"\b(C\d+|L?P\d+)\b", re.IGNORECASE)


def motion_parts(text: str) -> list[tuple[str, str]] | None:
    """The motions of one line of a job: group 1's, then each ``+MOVx`` of another group on
    the same line.

    Parameters
    ----------
    text : str
        A line of the ``//INST`` section.

    Returns
    -------
    list of (str, str) or None
        ``(instruction, rest)`` per motion, the instruction in capitals
        (``[("MOVL", "C00004 EC00002 V=11.0"), ("MOVL", "C00005 V=11.0")]``); None for a
        line that is no motion.
    """
    m = _MOVE_RE.match(text)
    if not m:
        return None
    first, *others = _PARTNER_SPLIT.split(m.group(2))
    parts = [(m.group(1).upper(), first.strip())]
    for other in others:
        instr, _, rest = other.partition(" ")
        parts.append((instr.upper(), rest.strip()))
    return parts


class _Position:
    def __init__(self, kind: str, values: list[float], postype: str, user: int, tool: int,
                 rconf: tuple[int, ...] | None, where: str) -> None:
        self.kind, self.values, self.postype = kind, values, postype
        self.user, self.tool, self.rconf, self.where = user, tool, rconf, where


#: What the positions after ``///RECTAN``, ``///PULSE`` and ``///ANGLE`` hold: ``C`` positions
#: are Cartesian, in pulses or (no job shows one) axis angles; station positions after
#: ``///ANGLE`` are in degrees (jobs DX200 cells saved: ``///POSTYPE ANGLE``, ``///ANGLE``,
#: ``EC00000=-45.0000``, as job writers write a station's angles in degrees).
_DATA_KINDS = {"RECTAN": "", "PULSE": "-pulse", "ANGLE": "-angle"}


def _pos_section(lines: Lines, start: int, end: int) -> dict[str, _Position]:
    out: dict[str, _Position] = {}
    postype, user, tool, rconf, data = "PULSE", 0, 0, None, "PULSE"
    for lineno in range(start, end):
        text = lines.lines[lineno - 1].strip()
        if not text:
            continue
        if text.startswith("///"):
            key, _, value = text[3:].partition(" ")
            key = key.upper()
            if key == "USER":
                user = int(lines.number(value, lineno))
            elif key == "TOOL":
                tool = int(lines.number(value, lineno))
            elif key == "POSTYPE":
                postype = value.strip().upper()
            elif key in _DATA_KINDS:
                data = key
            elif key == "RCONF":
                parts = [p for p in value.split(",") if p.strip()]
                if len(parts) < 6:
                    raise lines.error(lineno, "RCONF needs at least 6 values l,m,n,o,p,q")
                rconf = tuple(int(lines.number(p, lineno)) for p in parts[:6])
            continue
        m = _DATA_RE.match(text)
        if not m:
            raise lines.error(lineno, f"expected a position line, got {text[:40]!r}")
        values = [lines.number(v, lineno) for v in m.group(3).split(",")]
        kind = m.group(1) + (_DATA_KINDS[data] if m.group(1) == "C" or data == "ANGLE" else "")
        if kind == "C" and len(values) < 6:
            raise lines.error(lineno, f"C{m.group(2)} needs X, Y, Z, Rx, Ry, Rz")
        out[m.group(1) + m.group(2)] = _Position(kind, values,
                                                 postype if data == "RECTAN" else data, user,
                                                 tool, rconf, lines.where(lineno))
    return out


def read(path: str | Path) -> tuple[Program, list[str]]:
    """Read a YASKAWA ``.jbi`` job: the points of the robot of group 1 (the motion that starts
    each line), with the station's values of the line (``EC``); a job of two robots' second
    robot (group 2, the ``+MOVJ``/``+MOVL`` with a robot position on the same line) is named
    as not checked (:func:`read_groups` reads both).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    program : Program
        Points in the order the job moves to them; ``line`` is the file's line of the motion;
        external axes as ``BC1`` (mm) and ``EC1``.. (pulses).
    skipped : list of str
        Motions to robot positions in pulses, to station positions in degrees, circular and
        spline motions, incremental motions, a motion after another word; reading group 1,
        the second robot's motions of a job of two robots. Each starts with ``line N:``.

    Raises
    ------
    InputError
        No ``/JOB``, ``//POS``, ``//INST`` or final ``END``, an unreadable position, a motion to a
        position the job does not hold; the message names the file and line.
    """
    return _read(path, (1,))[0]


def _read(path: str | Path, groups: tuple[int, ...]) -> list[tuple[Program, list[str]]]:
    """The points of each robot group of ``groups`` (1, 2) and what was not checked."""
    lines = Lines(path, "YASKAWA job")
    marks: dict[str, int] = {}
    sections: list[int] = []  # the lines of every '//' section header: //POS, //ARGINFO, //INST
    for lineno, text in enumerate(lines.lines, start=1):
        key = text.strip().split(" ")[0].upper() if text.strip() else ""
        if re.match(r"^//?[A-Z]", key):
            sections.append(lineno)
        if key in ("/JOB", "//POS", "//INST") and key not in marks:
            marks[key] = lineno
    for key in ("/JOB", "//POS", "//INST"):
        if key not in marks:
            found = ", ".join(f"{k} at line {n}" for k, n in marks.items())
            raise InputError(f"{path}: no {key} line" + (f" ({found} only)" if found else "")
                             + ": not a YASKAWA job, or only a part of one")
    last = next((i for i in range(len(lines.lines), 0, -1)
                 if lines.lines[i - 1].strip(_BLANK)), 0)
    if lines.lines[last - 1].strip(_BLANK).upper() != "END":
        raise InputError(f"{path}: line {last}: the job does not end with END (truncated file?)")
    name = next((t.split(None, 1)[1].strip() for t in lines.lines
                 if t.strip().upper().startswith("//NAME") and len(t.split()) > 1),
                Path(path).stem)
    pos_end = min((n for n in sections if n > marks["//POS"]), default=marks["//INST"])
    positions = _pos_section(lines, marks["//POS"] + 1, pos_end)
    out = []
    for g in groups:
        job = _Job(lines, positions, g)
        for lineno in range(marks["//INST"] + 1, last):
            job.instruction(lines.lines[lineno - 1].strip(), lineno)
        job.convert()
        notes = job.skipped + (job.partners if len(groups) == 1 else [])
        out.append((Program(name, "yaskawa", job.points, (str(path),)), notes))
    return out


def read_groups(path: str | Path) -> list[tuple[Program, list[str]]]:
    """Read a YASKAWA job of two robots: the points of group 1's robot and of group 2's.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    list of (Program, list of str)
        Per group, its robot's points and the motions not turned into points (as :func:`read`;
        neither names the other robot's points).

    Raises
    ------
    InputError
        As :func:`read`.
    """
    return _read(path, (1, 2))


class _Job:
    """The instructions of a job in order: the motions and what changes tools and frames."""

    def __init__(self, lines: Lines, positions: dict[str, _Position], group: int) -> None:
        self.lines, self.positions, self.group = lines, positions, group
        self.changed: dict[tuple[str, int], str] = {}  # (TOOL|USER, n) -> why, set by the job
        self.tools: dict[int, NDArray[np.float64]] = {}  # tools set by SETTOOL from SETE values
        self.elements: dict[str, dict[int, float] | None] = {}  # SETE constants per variable
        self.points: list[ProgramPoint] = []
        self.values: list[list[float]] = []  # each point's position, converted at the end
        self.skipped: list[str] = []
        self.partners: list[str] = []  # reading group 1: the second robot's motions

    def convert(self) -> None:
        """Every point's pose from its position, converted in one batch."""
        poses = pose_from_vendor(np.reshape(self.values, (-1, 6)), "yaskawa")
        for point, pose in zip(self.points, poses):
            point.pose = pose

    def instruction(self, text: str, lineno: int) -> None:
        if m := _SETE_RE.match(text):
            var, k, value = m.group(1).upper(), int(m.group(2)), m.group(3)
            known = self.elements.setdefault(var, {})
            if known is not None and re.fullmatch(r"[-+]?\d+", value):
                known[k] = float(value)
            else:
                self.elements[var] = None  # an element set from a variable at run time
        elif m := _SETTOOL_RE.match(text):
            self.settool(int(m.group(1)), (m.group(2) or "").upper(), lineno)
        elif m := _MFRAME_RE.match(text):
            self.changed[("USER", int(m.group(1)))] = (
                f"user frame {m.group(1)} is set by MFRAME at line {lineno} from position "
                "variables")
        elif m := _COORD_MOVE_RE.match(text):
            self.coordinated(m.group(2), lineno)
        elif parts := motion_parts(text):
            self.motion_line(parts, lineno)
        elif m := _IMOV_RE.match(text):
            self.skipped.append(f"line {lineno}: IMOV {m.group(1)} (an incremental motion: "
                                f"by the values of {m.group(1)} from where the axes are, a "
                                "target the job does not hold)")
        elif m := _PREFIXED_MOVE_RE.match(text):
            self.skipped.append(f"line {lineno}: {m.group(1).upper()} {m.group(2).strip()} (a "
                                f"motion after {m.group(1).upper()}, which the job format does "
                                "not describe: not read as a motion)")

    def settool(self, n: int, var: str, lineno: int) -> None:
        """``SETTOOL TL#(n) Pxxx``: tool n from the position variable, when the job sets its six
        elements X, Y, Z (um) and Rx, Ry, Rz (0.01 deg) by ``SETE`` with numbers (the units
        RoboDK's Motoman post writes); else the tool is not known."""
        known = self.elements.get(var)
        if known is not None and all(k in known for k in range(1, 7)):
            values = [known[k] / (1000 if k <= 3 else 100) for k in range(1, 7)]
            self.tools[n] = pose_from_vendor(values, "yaskawa")
            self.changed.pop(("TOOL", n), None)
            return
        self.tools.pop(n, None)
        self.changed[("TOOL", n)] = (f"tool {n} is set by SETTOOL at line {lineno} from "
                                     f"{var or 'a variable'}, whose values the job sets at run "
                                     "time")

    def external(self, refs: list[tuple[str, str]]) -> dict[str, float]:
        out: dict[str, float] = {}
        for k, n in refs:
            if k == "BC":
                out["BC1"] = self.positions[k + n].values[0]
            elif k == "EC":
                out.update({f"EC{i + 1}": v for i, v in enumerate(self.positions[k + n].values)})
        return out

    def refs(self, rest: str, lineno: int) -> list[tuple[str, str]]:
        """The ``C``, ``BC`` and ``EC`` positions a motion names, each in ``//POS``, or an error
        naming the line and the positions of the kind ``//POS`` holds (a job that names
        ``C000`` where ``//POS`` holds ``C00000`` is refused, not matched by number)."""
        refs = re.findall(r"\b(C|BC|EC)(\d+)\b", rest)
        missing = [(k, k + n) for k, n in refs if k + n not in self.positions]
        if missing:
            held = [n for n in self.positions if n.rstrip("0123456789") == missing[0][0]]
            raise self.lines.error(lineno, f"{', '.join(m for _, m in missing)} not in the //POS "
                                   "section" + (f" (it holds {held[0]} to {held[-1]})" if held
                                                else ""))
        return refs

    def coordinated(self, rest: str, lineno: int) -> None:
        """``+MOVJ EC00001 ...``: a station's motion with the robot's on the line before; a
        station position in degrees takes the robot's point out of the check."""
        refs = self.refs(rest, lineno)
        if self.points and self.points[-1].line == lineno - 1:
            if why := self.in_degrees(refs):
                point = self.points.pop()
                self.values.pop()
                self.skipped.append(f"line {point.line}: {point.name} ({why})")
                return
            self.points[-1].external.update(self.external(refs))

    def in_degrees(self, refs: list[tuple[str, str]]) -> str | None:
        """Why a motion is not checked when one of its station positions is in degrees
        (``///POSTYPE ANGLE``): robotcell converts station positions from pulses."""
        deg = [k + n for k, n in refs if k == "EC" and self.positions[k + n].kind == "EC-angle"]
        return (f"the station position {', '.join(deg)} is in degrees (///POSTYPE ANGLE), not "
                "in the encoder pulses robotcell converts with --pulses-per-degree") if deg \
            else None

    def motion_line(self, parts: list[tuple[str, str]], lineno: int) -> None:
        """A motion line (:func:`motion_parts`): group 1's motion, and each ``+MOVx`` of the
        line: one with a robot position is the second robot's (group 2), one without a
        station's, whose ``EC`` values join the point of either robot."""
        (instr, rest), partners = parts[0], parts[1:]
        robots = [(i, m.group(1), r) for i, r in partners if (m := ROBOT_POSITION.search(r))]
        station = [ref for i, r in partners if not ROBOT_POSITION.search(r)
                   for ref in self.refs(r, lineno) if ref[0] == "EC"]
        if self.group == 1:
            self.motion(instr, rest, lineno, station)
            self.partners += [f"line {lineno}: +{i} {name} (the second robot's point, group "
                              "2: checked with the job as a coordinated program)"
                              for i, name, _ in robots]
        elif robots:
            i, _, r = robots[0]
            shared = [ref for ref in self.refs(rest, lineno) if ref[0] == "EC"]
            self.motion(i, r, lineno, shared + station)

    def motion(self, instr: str, rest: str, lineno: int,
               station: tuple[tuple[str, str], ...] | list[tuple[str, str]] = ()) -> None:
        """One robot's motion; ``station``: the line's station positions moved with it."""
        lines = self.lines
        if instr in ("MOVC", "MOVS", "SMOVC"):
            self.skipped.append(f"line {lineno}: {' '.join([instr, *rest.split()[:1]])} "
                                "(circular and spline motions are not checked)")
            return
        refs = self.refs(rest, lineno)
        if why := self.in_degrees(refs + [ref for ref in station if ref not in refs]):
            self.skipped.append(f"line {lineno}: {instr} {rest.split()[0]} ({why})")
            return
        cname = next((k + n for k, n in refs if k == "C"), None)
        if cname is None:
            var = re.search(r"\b(L?(?:P|BP|EX)\d+|L?(?:P|BP|EX)\[[^\]]*\])", rest)
            axes = " ".join(k + n for k, n in refs)
            self.skipped.append(f"line {lineno}: {instr} " + (
                f"{var.group(1)} (a position variable, set at run time)" if var else
                f"{axes} (a motion of the base axis or the station alone)" if axes else
                "without a C position"))
            return
        c = self.positions[cname]
        if c.kind != "C":
            self.skipped.append(f"line {lineno}: {instr} {cname} (" + (
                "robot pulses: their pulses per degree are not in the job" if c.kind == "C-pulse"
                else "a robot position as axis angles (///ANGLE), which no job robotcell cites "
                "holds") + ")")
            return
        why = self.changed.get(("TOOL", c.tool)) or (
            self.changed.get(("USER", c.user)) if c.postype == "USER" else None)
        if why:
            self.skipped.append(f"line {lineno}: {instr} {cname} ({why})")
            return
        frame = (Ref(number=c.user, kind="base") if c.postype == "USER" else
                 Ref(kind="robot" if c.postype == "ROBOT" else "base", number=None))
        if c.postype not in ("USER", "BASE", "ROBOT"):
            raise lines.error(lineno, f"{cname}: POSTYPE {c.postype} is not read (USER, BASE, "
                                      "ROBOT or PULSE)")
        self.values.append(c.values[:6])
        config = Config("yaskawa", c.rconf) if c.rconf is not None else None
        speed = re.search(r"\bV\s*=\s*([0-9.]+)", rest)
        zone = re.search(r"\bPL\s*=\s*(\d+)", rest)
        motion = "ptp" if instr.endswith("J") else "lin"
        self.points.append(ProgramPoint(
            cname, lineno, motion, Ref(number=c.tool, pose=self.tools.get(c.tool)), frame,
            None, None, config,
            self.external(refs + [ref for ref in station if ref not in refs]),
            lines.number(speed.group(1), lineno) * 1e-3 if speed and motion == "lin" else None,
            lines.number(zone.group(1), lineno) * 1e-3 if zone else 0.0, c.where))


# -- editing in place ----------------------------------------------------------------------------
def set_pose(lines: list[str], idx: int, T: NDArray[np.float64], config: Config | None) -> bool:
    """Write X..Rz (``T``, m) of the ``Cnnnnn`` on line ``idx``; its ``///RCONF`` is shared by
    the points after it and never written (``config`` is not used)."""
    m = re.match(r"^(\s*C\d+\s*=\s*)([^,]*(?:,[^,]*){5})(.*)$", lines[idx])
    if not m:
        return False
    v = pose_to_vendor(T, "yaskawa")
    text = ",".join(fmt_num(x, MM_PLACES if i < 3 else DEG_PLACES) for i, x in enumerate(v))
    lines[idx] = m.group(1) + text + m.group(3)
    return True
