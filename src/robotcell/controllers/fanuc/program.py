"""FANUC TP programs as ASCII listings: ``NAME.ls`` (``/PROG``, ``/ATTR``, ``/MN``, ``/POS``).

Written (sources in ``docs/programs.md``):

- ``/MN``: ``UFRAME_NUM=n``, ``UTOOL_NUM=n`` (the numbers of ``robotcell export``), then
  ``J P[i] 20% FINE`` / ``L P[i] 100mm/sec CNTk`` per point;
- ``/POS``: ``P[i]{ GP1: UF : n, UT : n, CONFIG : 'N U T, t1, t4, t6', X =   -63.679  mm, ...,
  R =    50.373 deg`` and a rail as ``E1=  4010.288  mm`` in group 1 (an integrated extended
  axis), and the turntable or positioner as group 2, ``GP2: UF, UT, J1=   191.000 deg, ...``;
  ``};``. Values as controllers save them: 10 characters, 3 decimals, ``.153`` for 0.153.

Positions are the TCP in the user frame, which ``robotcell export`` writes in FANUC WORLD (the
robot base at rail position 0); a frame on the turntable is the user frame of its pose at table
axis 0, with the table at the point's angle in group 2 (no coordinated motion is written).

Read: the same, and what pendants, controller backups and offline tools write: numbered and
unnumbered ``/MN`` lines (``   5:J P[1] ...``, ``    :J P[1] ...``), joint positions
(``J1 = .. deg``), comments on positions (``P[3:"approach"]``), other numbers of decimals,
``cm/min``, ``sec`` and ``%`` speeds, the words of a listing saved in German (``KONFIG``,
``mm/sek``, ``WKZ_Offset``), ``/END`` followed by an end-of-file mark, a tool or user frame set
in the program from a position register (``PR[9,1]=-30.0 ;`` or ``PR[9,1]=(-30.0) ;`` ..
``UTOOL[9]=PR[9] ;`` or ``UTOOL[9:comment]=PR[9] ;``: its values win over the cell's), in
program order; the groups ``DEFAULT_GROUP`` moves. Named as not checked, with the reason:
motions to position registers (``PR[R[n]]`` too), ``Offset``/``Tool_Offset``/``VOFFSET``/
``INC`` and ``COORD`` motions, positions in frames set from registers set or chosen at run time
(``UFRAME[21]=PR[R[99]]``), circular motions, positions not recorded (``********``), with no
group 1 data or written as ``RX..RR``, ``P[...]`` with no number, and the data of groups the
program does not move or that hold another arm's Cartesian position (``docs/programs.md``).
"""

from __future__ import annotations

import math
import re
import textwrap
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from robotcell.controllers.data import DEG_DECIMALS, MM_DECIMALS
from robotcell.controllers.model import FLAG_LIMIT, PTP_SPEED, Config, Program, ProgramPoint, Ref
from robotcell.controllers.text import JOINT_DECIMALS, NUMBER, Lines, fmt_num
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor

__all__ = ["config_text", "parse_config", "read", "set_joints", "set_pose", "write"]

_POSE_KEYS = ("X", "Y", "Z", "W", "P", "R")
#: Longest comment line of the TP editor (characters after ``!``).
COMMENT_CHARS = 29


# -- writing -------------------------------------------------------------------------------------
def config_text(values: tuple[int, ...]) -> str:
    """``CONFIG`` as a position writes it: ``'N U T, 0, 0, 0'``."""
    flags = ("NF"[values[0]], "UD"[values[1]], "TB"[values[2]])
    return f"'{' '.join(flags)}, {values[3]}, {values[4]}, {values[5]}'"


def _cnt(zone: float) -> str:
    mm = zone * 1e3
    return "FINE" if mm <= 0 else f"CNT{min(100, max(1, round(mm)))}"


#: Decimals of the values of a position, as controllers save them (mm and deg).
TP_DECIMALS = 3


def tp_number(x: float) -> str:
    """A value of a position as a controller saves it: 10 characters, 3 decimals, no ``0``
    before the point of a value below 1 in size (``   -63.679``, ``      .153``,
    ``     0.000``)."""
    text = f"{x:10.3f}"
    if float(text) == 0.0:
        return f"{0.0:10.3f}"
    if abs(float(text)) < 1.0:
        text = text.replace("0.", ".").rjust(10)
    return text


def _position(p: ProgramPoint) -> list[str]:
    assert p.pose is not None and p.config is not None
    v = pose_to_vendor(p.pose, "fanuc")
    uf, ut = p.frame.number or 0, p.tool.number or 0
    L = [f"{p.name}{{", "   GP1:",
         f"\tUF : {uf}, UT : {ut},\t\tCONFIG : {config_text(p.config.values)},",
         "\t" + ",\t".join(f"{k} ={tp_number(x)}  mm" for k, x in zip(_POSE_KEYS[:3], v[:3]))
         + ","]
    rot = ",\t".join(f"{k} ={tp_number(x)} deg" for k, x in zip(_POSE_KEYS[3:], v[3:]))
    rail = p.external.get("E1")
    L.append(f"\t{rot}" + ("," if rail is not None else ""))
    if rail is not None:
        L.append(f"\tE1={tp_number(rail)}  mm")
    table = [(k.split(":")[1], v) for k, v in p.external.items() if k.startswith("GP2:")]
    if table:
        L += ["   GP2:", f"\tUF : {uf}, UT : {ut},\t",
              "\t" + ",\t".join(f"{k}={tp_number(x)} deg" for k, x in table)]
    L.append("};")
    return L


def write(program: Program, header: list[str]) -> dict[str, str]:
    """``NAME.ls`` of a program of Cartesian points.

    Parameters
    ----------
    program : Program
        Points with ``pose``, ``config`` (FANUC CONFIG) and ``external`` (``E1``, ``GP2:J1``..),
        one tool and one user frame (by number).
    header : list of str
        Comment lines, shortened to the TP editor's comment width.

    Returns
    -------
    dict of str to str
    """
    pts = program.points
    first = pts[0]
    gp2 = any(k.startswith("GP2:") for k in first.external)
    mn = [f"! {part} ;" for h in header for part in textwrap.wrap(h, COMMENT_CHARS)]
    mn += [f"UFRAME_NUM={first.frame.number or 0} ;", f"UTOOL_NUM={first.tool.number or 0} ;"]
    for p in pts:
        if p.motion == "ptp":
            mn.append(f"J {p.name} {PTP_SPEED * 100:.0f}% {_cnt(p.zone or 0.0)} ;")
        else:
            mn.append(f"L {p.name} {(p.speed or 0.1) * 1e3:.0f}mm/sec {_cnt(p.zone or 0.0)} ;")
    attr = ["/ATTR", "OWNER\t\t= MNEDITOR;", 'COMMENT\t\t= "robotcell";', "PROG_SIZE\t= 0;",
            "CREATE\t\t= DATE 00-01-01  TIME 00:00:00;",
            "MODIFIED\t= DATE 00-01-01  TIME 00:00:00;", "FILE_NAME\t= ;", "VERSION\t\t= 0;",
            f"LINE_COUNT\t= {len(mn)};", "MEMORY_SIZE\t= 0;", "PROTECT\t\t= READ_WRITE;",
            "TCD:  STACK_SIZE\t= 0,", "      TASK_PRIORITY\t= 50,", "      TIME_SLICE\t= 0,",
            "      BUSY_LAMP_OFF\t= 0,", "      ABORT_REQUEST\t= 0,", "      PAUSE_REQUEST\t= 0;",
            f"DEFAULT_GROUP\t= 1,{'1' if gp2 else '*'},*,*,*;",
            "CONTROL_CODE\t= 00000000 00000000;"]
    text = [f"/PROG  {program.name}", *attr, "/MN"]
    for i, ln in enumerate(mn, start=1):
        text.append(f"{i:4d}:{'' if ln[:2] in ('J ', 'L ') else '  '}{ln}")
    text.append("/POS")
    for p in pts:
        text += _position(p)
    text.append("/END")
    return {f"{program.name}.ls": "\n".join(text) + "\n"}


# -- reading -------------------------------------------------------------------------------------
#: The start of a ``/MN`` line: its number and ``:``, or ``:`` alone (listings of controller
#: backups and offline tools number some lines or none: ``   5:J P[1] ...``, ``    :J P[1] ...``).
_STEP = r"^\s*\d*\s*:\s*"
#: A motion: type, ``P[n]`` (``P[...]`` while its number is not set) or ``PR[n]`` (``PR[AR[n]]``
#: by an argument), an optional comment, the rest (speed, termination, options).
_MOVE_RE = re.compile(_STEP + r"([JLCA])\s+(?:(P)\[\s*(\d+|\.\.\.)|(PR)\[\s*(\d+|[A-Z]+\[\s*\d+\s*\]))"
                      r"\s*(?::[^\]]*)?\]\s*(.*?)\s*;?\s*$")
_POS_HEAD_RE = re.compile(r"^\s*P\[\s*(\d+)\s*(?::[^\]]*)?\]\s*\{")
#: A value of a position, ``X =   -63.679  mm``: the text up to the unit, read by
#: ``Lines.number`` (which names a value that is not a number, such as ``nan``).
_VALUE_RE = re.compile(r"\b([A-Z]+\d*)\s*=\s*([^\s,;*]*)\s*(mm|deg)?")
#: A value the controller holds no number for (``X = ********  mm``, with ``UF : F``): a
#: position not recorded, as controllers save it.
_UNSET_RE = re.compile(r"\b[A-Z]+\d*\s*=\s*\*+")
_UF_RE = re.compile(r"\bUF\s*:\s*(\d+)\s*,\s*UT\s*:\s*(\d+)")
#: ``KONFIG`` in listings saved by a controller set to German (the English and German listings
#: of the same programs in one backup differ in these words only).
_CONFIG_RE = re.compile(r"\b(?:CONFIG|KONFIG)\s*:\s*'([^']*)'")
#: An element of a position register set to a number, bare or in parentheses as the pendant
#: writes a negative one (``PR[16,1]=(-.4) ;``, a controller backup's tool data program).
_PR_SET_RE = re.compile(_STEP + r"PR\[\s*(\d+)\s*,\s*(\d)\s*(?::[^\]]*)?\]\s*=\s*(\(\s*)?"
                        r"([-+0-9.eE]+)(?(3)\s*\))\s*;")
_PR_ANY_RE = re.compile(_STEP + r"PR\[\s*(\d+)\s*(?:,\s*\d+\s*)?(?::[^\]]*)?\]\s*=")
#: A tool or user frame set in the program: from ``PR[m]`` (group 3), or from anything else
#: (``PR[R[99]]``, a register chosen at run time; group 4).
_FRAME_SET_RE = re.compile(_STEP + r"(UTOOL|UFRAME)\[\s*(\d+)\s*(?::[^\]]*)?\]\s*=\s*"
                           r"(?:PR\[\s*(\d+)\s*(?::[^\]]*)?\]|(.*?))\s*;", re.IGNORECASE)
_SECTION_RE = re.compile(r"^\s*(/[A-Za-z]+)")
_GROUP_RE = re.compile(r"^\s*DEFAULT_GR\w*\s*=\s*([^;]*);")
#: Motion options that move the position by data outside the program (FANUC R-30iB
#: Operator's Manual, "Motion instruction options": Offset, Tool_Offset, VOFFSET, INC;
#: ``WKZ_Offset`` is Tool_Offset in a German listing).
_OFFSET_RE = re.compile(r"\b(Tool_Offset|WKZ_Offset|Offset|VOFFSET|VTOOL_OFFSET|INC)\b"
                        r"\s*(?:,\s*(PR\[[^\]]*\]))?", re.IGNORECASE)
_SPEED_RE = re.compile(r"^([0-9.]+)\s*(mm/sec|mm/sek|cm/min|inch/min|deg/sec|sec|sek|msec|%)",
                       re.IGNORECASE)
#: Linear speeds in m/s per unit (``mm/sek``: mm/sec in a German listing).
_LINEAR_SPEED = {"mm/sec": 1e-3, "mm/sek": 1e-3, "cm/min": 1e-2 / 60, "inch/min": 0.0254 / 60}


def parse_config(text: str) -> Config:
    """``N U T, 0, 0, 0`` (a FANUC ``CONFIG`` string) as flags (flip, down, back) and turns.

    Raises
    ------
    InputError
        Text that is not ``F|N U|D T|B, t1, t4, t6`` with integer turn numbers.
    """
    head, *turns = [t.strip() for t in text.split(",")]
    letters = head.split()
    if len(letters) != 3 or letters[0] not in "NF" or letters[1] not in "UD" \
            or letters[2] not in "TB" or len(turns) != 3:
        raise InputError(f"CONFIG '{text}' is not 'F|N U|D T|B, t1, t4, t6'")
    try:
        t = tuple(int(x) for x in turns)
    except ValueError:
        raise InputError(f"CONFIG '{text}': the turn numbers must be integers") from None
    if max(abs(x) for x in t) >= FLAG_LIMIT:
        raise InputError(f"CONFIG '{text}': a turn number that large is a typing error")
    return Config("fanuc", (int(letters[0] == "F"), int(letters[1] == "D"),
                            int(letters[2] == "B"), *t))


def _config(text: str, lineno: int, lines: Lines) -> Config:
    """:func:`parse_config`, the error naming the file and line."""
    try:
        return parse_config(text)
    except InputError as exc:
        raise lines.error(lineno, str(exc)) from None


class _Position:
    """One ``P[n]{...};`` block: group 1 pose or joints, its config, UF/UT, external axes.

    ``missing`` says why a motion to it cannot be checked (None when it can): a position not
    recorded (``********``), one with no group 1 data (a program moving other groups), or group
    1 written as ``RX, RY, RZ, RW, RP, RR``, a form no public description gives the frame of.
    ``arms`` are the other groups that hold a Cartesian position (another arm), not axes.
    """

    def __init__(self, block: list[tuple[int, str]], lines: Lines) -> None:
        start = block[0][0]
        self.where = lines.where(start)
        self.uf = self.ut = 0
        self.config: Config | None = None
        self.missing: str | None = None
        values: dict[str, dict[str, float]] = {}
        config: tuple[str, int] | None = None
        unset = False
        group = "GP1"
        for lineno, text in block:
            if m := re.match(r"^\s*(GP\d+)\s*:", text):
                group = m.group(1)
                values.setdefault(group, {})
                continue
            values.setdefault(group, {})
            if _UNSET_RE.search(text):
                unset = True
                continue
            if group == "GP1" and (m := _UF_RE.search(text)):
                self.uf, self.ut = int(m.group(1)), int(m.group(2))
            if group == "GP1" and (m := _CONFIG_RE.search(text)):
                config = (m.group(1), lineno)
            for m in _VALUE_RE.finditer(text):
                values[group][m.group(1)] = lines.number(m.group(2), lineno)
        if config is not None and not unset:
            self.config = _config(*config, lines)
        gp1 = values.pop("GP1", None)
        self.arms = sorted(g for g, v in values.items() if all(k in v for k in _POSE_KEYS))
        self.external = {k: v for k, v in (gp1 or {}).items() if re.fullmatch(r"E\d", k)}
        self.external.update({f"{g}:{k}": v for g, vals in values.items() if g not in self.arms
                              for k, v in vals.items()})
        self.pose = self.joints = None
        self._group1(gp1 or {}, unset, sorted(values), lines, start)

    def _group1(self, values: dict[str, float], unset: bool, others: list[str], lines: Lines,
                start: int) -> None:
        """The pose or joints of group 1, or why there are none (``missing``).

        Parameters
        ----------
        values : dict of str to float
            Group 1's values by key (``X`` mm, ``W`` deg, ``J1`` deg, ...).
        unset : bool
            Whether a value of the position is ``********`` (not recorded).
        others : list of str
            The other groups the position holds (``GP2``, ...).
        lines : Lines
            The file, for the error.
        start : int
            The line of ``P[n]{``, 1-based.
        """
        if not values and not unset and others:
            self.missing = (f"holds no group 1 data, only {', '.join(others)}: the motion does "
                            "not move the arm of group 1")
        elif unset:
            self.missing = "is not recorded: its values are ******** in the listing"
        elif all(k in values for k in _POSE_KEYS):
            self.pose = pose_from_vendor([values[k] for k in _POSE_KEYS], "fanuc")
        elif all(f"J{i}" in values for i in range(1, 7)):
            self.joints = np.radians([values[f"J{i}"] for i in range(1, 7)])
            self.config = None
        elif all(f"R{k}" in values for k in _POSE_KEYS):
            self.missing = ("is written as RX, RY, RZ, RW, RP, RR, a form whose frame no public "
                            "description gives")
        else:
            raise lines.error(start, "the position has neither X, Y, Z, W, P, R nor J1..J6 in "
                                     "group 1")


def _positions(lines: Lines, start: int, end: int) -> dict[int, _Position]:
    out: dict[int, _Position] = {}
    block: list[tuple[int, str]] = []
    number = None
    for lineno in range(start, end):
        text = lines.lines[lineno - 1]
        if number is None:
            if m := _POS_HEAD_RE.match(text):
                number, block = int(m.group(1)), [(lineno, text[m.end():])]
            elif text.strip():
                raise lines.error(lineno, f"expected P[n]{{, got {text.strip()[:40]!r}")
            continue
        if "};" in text:
            block.append((lineno, text.split("};")[0]))
            out[number] = _Position(block, lines)
            number = None
        else:
            block.append((lineno, text))
    if number is not None:
        raise lines.error(end - 1, f"P[{number}] is not closed with '}};' (truncated file?)")
    return out


def _speed(text: str, motion: str, lines: Lines, lineno: int) -> float | None:
    m = _SPEED_RE.match(text)
    if not m:
        return None
    v, unit = lines.number(m.group(1), lineno), m.group(2).lower()
    scale = _LINEAR_SPEED.get(unit)
    return None if motion == "ptp" or scale is None else v * scale


def _zone(text: str, lines: Lines, lineno: int) -> float | None:
    if re.search(r"\bFINE\b", text):
        return 0.0
    if m := re.search(r"\bCNT\s*(\d+)", text):
        return int(m.group(1)) * 1e-3
    return None


def _default_group(lines: Lines, start: int, end: int) -> set[str]:
    """The motion groups the program moves (``GP1``, ...) from ``DEFAULT_GROUP = 1,1,*,*,*;``
    in ``/ATTR`` (every group when the line is missing)."""
    for lineno in range(start, end):
        if m := _GROUP_RE.match(lines.lines[lineno - 1]):
            flags = [f.strip() for f in m.group(1).split(",")]
            return {f"GP{i + 1}" for i, f in enumerate(flags) if f == "1"}
    return {f"GP{i}" for i in range(1, 9)}


def _run_time_option(rest: str) -> str | None:
    """Why a motion's position is not the one in ``/POS``: an option that offsets it by data
    the program does not hold, or a coordinated motion."""
    if m := _OFFSET_RE.search(rest):
        opt = m.group(1)
        reg = f", {m.group(2)}" if m.group(2) else ""
        return (f"{opt}{reg}: the position is offset at run time by data not in the program"
                if opt.upper() != "INC" else "INC: a motion relative to where the robot is")
    if re.search(r"\bCOORD\b", rest, re.IGNORECASE):
        return ("COORD: a coordinated motion, run relative to the leader group's moving frame, "
                "which the program does not hold")
    return None


def _sections(lines: Lines) -> dict[str, int]:
    """The line of each section mark (``/PROG``, ``/MN``, ...); the file refused when it has no
    ``/PROG`` (naming its first line: a controller's report saved as ``.LS``, such as
    ``ERRALL.LS``, is no program), or no ``/MN`` or ``/END`` (naming its last line)."""
    marks: dict[str, int] = {}
    for lineno, text in enumerate(lines.lines, start=1):
        m = _SECTION_RE.match(text)  # '/END' and whatever follows it on the line (an EOF mark)
        key = m.group(1).upper() if m else ""
        if key in ("/PROG", "/ATTR", "/MN", "/POS", "/END", "/APPL") and key not in marks:
            marks[key] = lineno
    if "/PROG" not in marks:
        first = next(((i, t.strip()) for i, t in enumerate(lines.lines, 1) if t.strip()), None)
        if first is None:
            raise InputError(f"{lines.path}: the file is empty: not a FANUC .ls listing")
        raise lines.error(first[0], "no /PROG line: not a FANUC TP listing (it starts "
                                    f"{first[1][:48]!r})")
    for key in ("/MN", "/END"):
        if key not in marks:
            raise lines.error(len(lines.lines), f"no {key} line (truncated file?)")
    return marks


def read(path: str | Path) -> tuple[Program, list[str]]:
    """Read a FANUC ``.ls`` listing.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    program : Program
        Points in the order the ``/MN`` section moves to them; ``line`` is the file's line of the
        motion; the frame and tool are the ``UF``/``UT`` of each position.
    skipped : list of str
        The motions not checked and the position data not used, each with its reason
        (``line N: ...``, ``P[n]: ...``).

    Raises
    ------
    InputError
        No ``/PROG``, ``/MN``, ``/POS`` or ``/END``, an unreadable position, a motion to a
        position the file does not hold; the message names the file and line.
    """
    lines = Lines(path, "FANUC .ls file")
    marks = _sections(lines)
    name = lines.lines[marks["/PROG"] - 1].split()[1] if len(
        lines.lines[marks["/PROG"] - 1].split()) > 1 else Path(path).stem
    pos_start = marks.get("/POS", marks["/END"])
    positions = _positions(lines, pos_start + 1, marks["/END"]) if "/POS" in marks else {}
    skipped: list[str] = []
    groups = _default_group(lines, marks["/PROG"], marks["/MN"])
    for n, p in positions.items():
        off = sorted({k.split(":")[0] for k in p.external if k.startswith("GP")} - groups)
        for g in off:
            p.external = {k: v for k, v in p.external.items() if not k.startswith(g + ":")}
            skipped.append(f"P[{n}]: its {g} data are not used: the program's DEFAULT_GROUP "
                           f"does not move group {g[2:]}")
        skipped += [f"P[{n}]: its {g} data are not used: a Cartesian position (X, Y, Z, W, P, R) "
                    "of another arm, not the axes of a table" for g in p.arms
                    if g in groups and not p.missing]
    main = _Main(lines, positions, skipped)
    for lineno in range(marks["/MN"] + 1, pos_start):
        main.line(lines.lines[lineno - 1], lineno)
    return Program(name, "fanuc", main.points, (str(path),)), skipped


class _Main:
    """The ``/MN`` lines in order: position registers and the tool and user frames set from
    them, and the motions."""

    def __init__(self, lines: Lines, positions: dict[int, _Position], skipped: list[str]) -> None:
        self.lines, self.positions, self.skipped = lines, positions, skipped
        # PR elements set to numbers since the register was last set otherwise
        self.registers: dict[int, dict[int, float]] = {}
        # UTOOL/UFRAME set from a PR in the program: the pose, or why it is not known
        self.defined: dict[tuple[str, int], np.ndarray | str] = {}
        self.points: list[ProgramPoint] = []

    def line(self, text: str, lineno: int) -> None:
        if m := _PR_SET_RE.match(text):
            self.registers.setdefault(int(m.group(1)), {})[int(m.group(2))] = (
                self.lines.number(m.group(4), lineno))
        elif m := _FRAME_SET_RE.match(text):
            self.frame_set(m.group(1).upper(), int(m.group(2)), m.group(3) or m.group(4), lineno)
        elif m := _PR_ANY_RE.match(text):  # a register set at run time (LPOS, another PR)
            self.registers.pop(int(m.group(1)), None)
        elif m := _MOVE_RE.match(text):
            self.motion(m, lineno)

    def frame_set(self, kind: str, number: int, source: str, lineno: int) -> None:
        """``UTOOL[n]=PR[m]``: the register's values if the program sets all six as numbers.

        Parameters
        ----------
        kind : str
            ``UTOOL`` or ``UFRAME``.
        number : int
            The frame's number.
        source : str
            The register's number (``"9"`` of ``PR[9]``), or what else the frame is set from.
        lineno : int
            The line, 1-based.
        """
        pr = self.registers.get(int(source), {}) if source.isdigit() else {}
        if sorted(pr) == [1, 2, 3, 4, 5, 6]:
            self.defined[(kind, number)] = pose_from_vendor([pr[i] for i in range(1, 7)],
                                                            "fanuc")
        else:
            what = f"PR[{source}]" if source.isdigit() else source
            self.defined[(kind, number)] = (f"{kind}[{number}] is set at line {lineno} from "
                                            f"{what}, whose values are set at run time")

    def motion(self, m: re.Match, lineno: int) -> None:
        lines, skipped = self.lines, self.skipped
        kind, rest = m.group(1), m.group(6)
        label = f"P[{m.group(3)}]" if m.group(2) else f"PR[{m.group(5)}]"
        if kind in ("C", "A"):
            skipped.append(f"line {lineno}: {kind} {label} (circular motions are not checked)")
            return
        if m.group(4):
            skipped.append(f"line {lineno}: {kind} {label} (a position register, not held by "
                           "the program)")
            return
        if m.group(3) == "...":
            skipped.append(f"line {lineno}: {kind} {label} (the position number is not set)")
            return
        if why := _run_time_option(rest):
            skipped.append(f"line {lineno}: {kind} {label} ({why})")
            return
        n = int(m.group(3))
        if n not in self.positions:
            raise lines.error(lineno, f"{label} is not in the /POS section")
        p = self.positions[n]
        if p.missing:
            skipped.append(f"line {lineno}: {kind} {label} ({label} {p.missing})")
            return
        tool, frame = self.defined.get(("UTOOL", p.ut)), self.defined.get(("UFRAME", p.uf))
        why = next((w for w in (tool, frame) if isinstance(w, str)), None)
        if why and (p.pose is not None or isinstance(tool, str)):
            skipped.append(f"line {lineno}: {kind} {label} ({why})")
            return
        motion = "ptp" if kind == "J" else "lin"
        self.points.append(ProgramPoint(
            label, lineno, motion, Ref(number=p.ut, pose=tool),
            Ref(number=p.uf, kind="base", pose=None if isinstance(frame, str) else frame),
            p.pose, p.joints, p.config, dict(p.external), _speed(rest, motion, lines, lineno),
            _zone(rest, lines, lineno), p.where))


# -- editing in place ----------------------------------------------------------------------------
def _gp1(lines: list[str], idx: int) -> range:
    """The lines of a position block's group 1, from its header line ``idx``."""
    end = idx
    for k in range(idx, len(lines)):
        if k > idx and re.match(r"^\s*GP[2-9]\s*:", lines[k]):
            break
        end = k
        if "};" in lines[k]:
            break
    return range(idx, end + 1)


def set_joints(lines: list[str], idx: int, q: NDArray[np.float64]) -> bool:
    """Write ``J1..J6`` (``q``, rad) of the joint position whose ``P[n]{`` is line ``idx``."""
    done = 0
    for k in _gp1(lines, idx):
        for i in range(6):
            lines[k], n = re.subn(rf"(\bJ{i + 1}\s*=\s*){NUMBER}",
                                  lambda m, v=q[i]: m.group(1)
                                  + fmt_num(math.degrees(v), JOINT_DECIMALS), lines[k], count=1)
            done += n
    return done == 6


def set_pose(lines: list[str], idx: int, T: NDArray[np.float64], config: Config | None) -> bool:
    """Write X..R (``T``, m) and, unless None, ``CONFIG`` of the position whose ``P[n]{`` is
    line ``idx``."""
    v = pose_to_vendor(T, "fanuc")
    values = {k: fmt_num(x, MM_DECIMALS if i < 3 else DEG_DECIMALS)
              for i, (k, x) in enumerate(zip(_POSE_KEYS, v))}
    done = 0
    for k in _gp1(lines, idx):
        line = lines[k]
        for key, text in values.items():
            line, n = re.subn(rf"(\b{key}\s*=\s*){NUMBER}", lambda m, t=text: m.group(1) + t,
                              line, count=1)
            done += n
        if config is not None:
            line, n = re.subn(r"(\b(?:CONFIG|KONFIG)\s*:\s*)'[^']*'",
                              lambda m: m.group(1) + config_text(config.values), line, count=1)
            done += 10 * n
        lines[k] = line
    return done == (16 if config is not None else 6)
