"""Reading KUKA KRL programs: ``NAME.src`` and the ``NAME.dat`` beside it.

The reader follows KRL as KUKA's manuals describe it (sources in ``docs/programs.md``):

- a ``.src`` holds ``DEF NAME( )`` .. ``END`` (the main routine), then local routines; a ``.dat``
  holds ``DEFDAT NAME [PUBLIC]`` .. ``ENDDAT`` with declarations ``DECL [GLOBAL] TYPE NAME=value``
  and, for arrays, ``NAME[i]=value`` (KSS 8 Operating and Programming Instructions for System
  Integrators, "Structure and creation of robot programs");
- motions ``PTP``/``LIN``/``CIRC`` and the spline ones ``SPTP``/``SLIN``/``SCIRC``/``SPL``, to a
  point named in the ``.dat``, an aggregate written in the line, or an expression; ``C_DIS``,
  ``C_PTP``, ``C_ORI``, ``C_VEL``, ``C_SPL`` approximate (written last, after a ``WITH`` clause
  too); ``WITH`` gives values for that motion (``$TOOL``, ``$BASE``, ``$IPO_MODE``, ``$VEL.CP``,
  ``$APO.CDIS`` given there hold for it, and the spline inline forms' ``STOOL2(FPn)``,
  ``SBASE(FPn.BASE_NO)``, ``SIPO_MODE(FPn.IPO_FRAME)``, ``SVEL_CP``, ``SAPO``, ``SAPO_PTP`` as
  KSS's ``bas.src`` defines them); ``PTP_REL``/``LIN_REL``/``CIRC_REL`` (and the spline ones)
  move relative to where the robot is; ``frame1 : frame2`` is the geometric operator;
- the tool and the base: ``$TOOL=``/``$BASE=`` a frame, ``TOOL_DATA[n]``, ``BASE_DATA[n]``,
  ``EK(...)`` or ``$NULLFRAME``; ``BAS(#TOOL,n)``/``BAS(#BASE,n)``; the inline forms'
  ``FDAT_ACT=FPn`` with ``DECL FDAT FPn={TOOL_NO n,BASE_NO m,...}``; ``TOOL_DATA[n]={...}`` and
  ``BASE_DATA[n]={...}`` assigned in the program. All of these take effect in program order,
  as the controller runs them; so do the speed and approximation distance
  (:mod:`robotcell.controllers.kuka.movedata`);
- ``$IPO_MODE = #TCP`` (or an FDAT's ``IPO_FRAME #TCP``) moves with an external TCP: the tool
  fixed in the cell, the workpiece on the flange ("$IPO_MODE tells the robot that it is holding
  the workpiece and the tool is fixed in the workspace", robot-forum.com); its Cartesian points
  are named as not checked until ``#BASE``;
- Status and Turn are used by the controller for PTP motions only ("The robot controller only
  takes the programmed Status and Turn values into consideration for PTP motions. They are
  ignored for CP motions", KSS 8 System Integrators manual): a ``LIN``/``SLIN`` point's S and T
  are not taken as its configuration, except for the program's first point, where they are the
  only statement of the configuration the robot starts in.

What the file does not hold is read and named, never refused: points of ``$config.dat``
(``XHOME``, the tool and base of ``FDAT FHOME``), points declared in another module (or in no
``.dat``: a program may have none), variables set at run time, ``$AXIS_ACT``/``$POS_ACT``,
aggregates that give some components only (``LIN {Z 500}``), relative motions, the geometric
operator, circular and spline-segment motions, and motions in local routines are returned as
"not checked" with the reason.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robotcell.controllers.kuka.movedata import MoveData, Settings, zone
from robotcell.controllers.model import FLAG_LIMIT, Config, Program, ProgramPoint, Ref
from robotcell.controllers.text import Lines, strip_comment
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor
from robotcell.io.tables import MAX_ABS_VALUE

__all__ = ["read"]

_POSE_KEYS = ("X", "Y", "Z", "A", "B", "C")
_AXIS_KEYS = tuple(f"A{i}" for i in range(1, 7))
_EXT_KEYS = tuple(f"E{i}" for i in range(1, 7))
_CARTESIAN = {"E6POS", "POS", "FRAME"}
_JOINT = {"E6AXIS", "AXIS"}
_TYPES = "E6POS|POS|FRAME|E6AXIS|AXIS|FDAT|PDAT|LDAT"

_DECL_RE = re.compile(rf"^\s*(?:GLOBAL\s+)?(?:DECL\s+)?(?:GLOBAL\s+)?({_TYPES})\s+(\w+)"
                      r"\s*(\[[^\]]*\])?\s*(?:=\s*(.*))?$", re.IGNORECASE)
_ELEMENT_RE = re.compile(r"^\s*(\w+)\s*\[\s*(\d+)\s*\]\s*=\s*(\{.*)$")
_LOCAL_RE = re.compile(r"^\s*(?:DECL\s+)?(?:GLOBAL\s+)?(?:E6POS|POS|FRAME|E6AXIS|AXIS)\s+(.+)$",
                       re.IGNORECASE)
_MOVE_RE = re.compile(r"^\s*(S?PTP_REL|S?LIN_REL|S?CIRC_REL|SPTP|SLIN|SCIRC|PTP|LIN|CIRC|SPL)"
                      r"\b\s*(.*)$", re.IGNORECASE)
_ROUTINE_RE = re.compile(r"^\s*(?:GLOBAL\s+)?DEF(?:FCT\s+\w+)?\s+(\w+)", re.IGNORECASE)
_END_RE = re.compile(r"^\s*END(?:FCT)?\s*$", re.IGNORECASE)
_TOOL_RE = re.compile(r"^\s*\$TOOL\s*=\s*(.*)$", re.IGNORECASE)
_BASE_RE = re.compile(r"^\s*\$BASE\s*=\s*(.*)$", re.IGNORECASE)
_SLOT_SET_RE = re.compile(r"^\s*(TOOL_DATA|BASE_DATA)\s*\[\s*(\w+)\s*\]\s*(\.\s*\w+)?\s*=\s*(.*)$",
                          re.IGNORECASE)
_BAS_RE = re.compile(r"^\s*BAS\s*\(\s*#(\w+)\s*(?:,\s*([^)]*?))?\s*\)", re.IGNORECASE)
_EK_RE = re.compile(r"^EK\s*\(.*?,\s*BASE_DATA\s*\[\s*(\d+)\s*\]\s*\)$", re.IGNORECASE)
_DATA_RE = re.compile(r"^(TOOL_DATA|BASE_DATA)\s*\[\s*(\d+)\s*\]$", re.IGNORECASE)
_FDAT_ACT_RE = re.compile(r"^\s*FDAT_ACT\s*=\s*(.*)$", re.IGNORECASE)
_LDAT_ACT_RE = re.compile(r"^\s*(LDAT_ACT|PDAT_ACT)\s*=\s*(\w+)", re.IGNORECASE)
_VEL_RE = re.compile(r"^\s*\$VEL\.CP\s*=\s*([-+0-9.eE]+)\s*$", re.IGNORECASE)
_APO_RE = re.compile(r"^\s*\$APO\.CDIS\s*=\s*([-+0-9.eE]+)\s*$", re.IGNORECASE)
_IPO_RE = re.compile(r"^\s*\$IPO_MODE\s*=\s*#(\w+)\s*$", re.IGNORECASE)
#: The functions of the spline inline forms' ``WITH`` clause (KSS 8 ``bas.src``): their name and
#: argument, ``STOOL2(FP1)``, ``SBASE(FP1.BASE_NO)``, ``SVEL_CP(0.5, , LCPDAT1)``.
_CALL_RE = re.compile(r"^(\w+)\s*\(\s*(.*?)\s*\)$")
_ASSIGN_RE = re.compile(r"^\s*(\w+(?:\s*\[[^\]]*\])?)\s*(?:\.\s*\w+\s*)?=[^=]")
_APPROX_RE = re.compile(r"\b(C_DIS|C_PTP|C_ORI|C_VEL|C_SPL)\b", re.IGNORECASE)
_TARGET_RE = re.compile(r"^[\w$]+(?:\s*\[[^\]]*\])?(?:\s*\.\s*\w+)*")
#: The numbers of a PDAT or LDAT the reader takes: speed (% or m/s) and corner distance (mm).
_MOTION_NUMBERS = {"VEL", "APO_DIST"}
#: A tool or base the program sets from data it does not hold: why, in words.
Unknown = str
#: The home points KSS declares in $config.dat (XHOME, XHOME1 .. XHOME5).
_HOME_RE = re.compile(r"^X?HOME\d*$", re.IGNORECASE)


def _split_items(body: str) -> list[str]:
    """Top-level comma-separated items of an aggregate's inside (quotes and braces kept)."""
    items, depth, quoted, cur = [], 0, False, []
    for ch in body:
        if ch == '"':
            quoted = not quoted
        elif not quoted and ch == "{":
            depth += 1
        elif not quoted and ch == "}":
            depth -= 1
        if ch == "," and depth == 0 and not quoted:
            items.append("".join(cur))
            cur = []
        else:
            cur.append(ch)
    items.append("".join(cur))
    return [i for i in items if i.strip()]


def aggregate_fields(text: str, lines: Lines, lineno: int) -> tuple[str | None, dict[str, str]]:
    """``{[TYPE:] K v, ...}`` -> (TYPE or None, {K (upper): v}); an unclosed brace is an error."""
    t = text.strip()
    if not t.startswith("{"):
        raise lines.error(lineno, f"expected an aggregate {{...}}, got {t[:40]!r}")
    if not t.endswith("}"):
        raise lines.error(lineno, "the aggregate is not closed with '}' (truncated file?)")
    body = t[1:-1]
    typ = None
    m = re.match(r"^\s*(\w+)\s*:(.*)$", body, re.DOTALL)
    if m and m.group(1).upper() not in ("S", "T"):
        typ, body = m.group(1).upper(), m.group(2)
    fields = {}
    for item in _split_items(body):
        im = re.match(r"^\s*([A-Za-z_$][\w\[\]$]*)\s*(.*?)\s*$", item, re.DOTALL)
        if not im:
            raise lines.error(lineno, f"cannot read {item.strip()!r} in the aggregate")
        fields[im.group(1).upper()] = im.group(2)
    return typ, fields


def int_value(text: str, lines: Lines, lineno: int) -> int:
    """``6``, ``'B110'`` (binary) or ``'H6'`` (hexadecimal) as an integer."""
    t = text.strip().strip("'")
    try:
        if t[:1] in "Bb" and len(t) > 1:
            v = lines.integer(t[1:], lineno, 2)
        elif t[:1] in "Hh" and len(t) > 1:
            v = lines.integer(t[1:], lineno, 16)
        else:
            f = float(t)
            if not abs(f) <= MAX_ABS_VALUE:  # NaN, infinite, 1e300
                raise ValueError(t)
            v = int(f)
    except ValueError:
        v = FLAG_LIMIT
    if abs(v) >= FLAG_LIMIT:
        raise lines.error(lineno, f"{text.strip()!r} is not a status or turn value")
    return v


class _Point:
    """A point value: Cartesian (pose, config) or joints, with its external axes."""

    def __init__(self, kind: str, fields: dict[str, str], lines: Lines, lineno: int,
                 name: str) -> None:
        def num(key: str) -> float:
            return lines.number(fields[key], lineno)

        self.where = lines.where(lineno)
        self.external = {k: num(k) for k in _EXT_KEYS if k in fields}
        self.pose = self.joints = self.config = None
        if kind in _JOINT:
            missing = [k for k in _AXIS_KEYS if k not in fields]
            if missing:
                raise lines.error(lineno, f"{name}: the axis values lack {', '.join(missing)}")
            self.joints = np.radians([num(k) for k in _AXIS_KEYS])
            return
        missing = [k for k in _POSE_KEYS if k not in fields]
        if missing:
            raise lines.error(lineno, f"{name}: the pose lacks {', '.join(missing)}")
        self.pose = pose_from_vendor([num(k) for k in _POSE_KEYS], "kuka")
        if "S" in fields and "T" in fields:
            self.config = Config("kuka", (int_value(fields["S"], lines, lineno),
                                          int_value(fields["T"], lines, lineno)))


def _kind_of(typ: str | None, fields: dict[str, str]) -> str:
    if typ in _CARTESIAN | _JOINT:
        return typ
    return "E6AXIS" if any(k in fields for k in _AXIS_KEYS) else "E6POS"


def _partial(typ: str | None, fields: dict[str, str]) -> str | None:
    """What an aggregate that is not a whole pose or axis position gives (``Z``), or None."""
    keys = _AXIS_KEYS if _kind_of(typ, fields) in _JOINT else _POSE_KEYS
    if all(k in fields for k in keys):
        return None
    return ", ".join(fields) or "nothing"


def _external(mode: str, lineno: int) -> Unknown | None:
    """Why Cartesian points are not checked under the interpolation mode ``mode`` from line
    ``lineno``: ``#TCP`` is an external TCP (the tool fixed in the cell, the workpiece moved by
    the robot); None for ``#BASE``, the tool on the flange."""
    if mode.strip().lstrip("#").upper() != "TCP":
        return None
    return (f"an external TCP, $IPO_MODE #TCP from line {lineno}: the tool is fixed in the cell "
            "and the robot moves the workpiece, which robotcell does not check")


def _frame_value(text: str, lines: Lines, lineno: int) -> np.ndarray:
    _, fields = aggregate_fields(text, lines, lineno)
    missing = [k for k in _POSE_KEYS if k not in fields]
    if missing:
        raise lines.error(lineno, f"the frame lacks {', '.join(missing)}")
    return pose_from_vendor([lines.number(fields[k], lineno) for k in _POSE_KEYS], "kuka")


@dataclass
class _Dat:
    """What a ``.dat`` declares: points by name (upper case, ``XP[3]`` for array elements),
    motion data (FDAT, PDAT, LDAT) by name, and points declared without a value."""

    points: dict[str, _Point] = field(default_factory=dict)
    data: dict[str, dict[str, str]] = field(default_factory=dict)
    unset: set[str] = field(default_factory=set)


def _read_dat(path: Path) -> _Dat:
    lines = Lines(path, "KUKA .dat file")
    dat, arrays = _Dat(), {}
    started = ended = False
    for lineno, raw in enumerate(lines.lines, start=1):
        line = strip_comment(raw, ";")
        if not line.strip() or line.lstrip().startswith("&"):
            continue
        if re.match(r"^\s*DEFDAT\b", line, re.IGNORECASE):
            started = True
            continue
        if re.match(r"^\s*ENDDAT\b", line, re.IGNORECASE):
            ended = True
            break
        if m := _ELEMENT_RE.match(line):
            name = m.group(1).upper()
            if name in arrays:
                typ, fields = aggregate_fields(m.group(3), lines, lineno)
                key = f"{name}[{int(m.group(2))}]"
                dat.points[key] = _Point(_kind_of(typ or arrays[name], fields), fields, lines,
                                         lineno, key)
            continue
        m = _DECL_RE.match(line)
        if not m:
            continue
        kind, name, dims, value = m.group(1).upper(), m.group(2).upper(), m.group(3), m.group(4)
        if dims:
            arrays[name] = kind
        elif value is None:
            dat.unset.add(name)
        elif kind in ("FDAT", "PDAT", "LDAT"):
            dat.data[name] = fields = aggregate_fields(value, lines, lineno)[1]
            for key in _MOTION_NUMBERS & fields.keys():  # a corrupt value: refused here
                lines.number(fields[key], lineno)
        else:
            typ, fields = aggregate_fields(value, lines, lineno)
            dat.points[name] = _Point(_kind_of(typ or kind, fields), fields, lines, lineno, name)
    if not started:
        what = "the file is empty" if not any(map(str.strip, lines.lines)) else "no DEFDAT line"
        raise InputError(f"{path}: {what}: not a KUKA .dat file")
    if not ended:
        raise InputError(f"{path}: line {len(lines.lines)}: no ENDDAT (truncated file?)")
    return dat


def _dat_of(src: Path) -> Path | None:
    for p in src.parent.glob("*"):
        if p.stem.lower() == src.stem.lower() and p.suffix.lower() == ".dat":
            return p
    return None


def _src_of(path: Path) -> Path:
    if path.suffix.lower() != ".dat":
        return path
    return next((p for p in path.parent.glob("*") if p.stem.lower() == path.stem.lower()
                 and p.suffix.lower() == ".src"), path.with_suffix(".src"))


def read(path: str | Path) -> tuple[Program, list[str]]:
    """Read a KUKA program: the ``.src`` and the ``.dat`` of the same name beside it.

    Parameters
    ----------
    path : str or Path
        The ``.src`` file (or the ``.dat``: the ``.src`` of the same name is read).

    Returns
    -------
    program : Program
        Points in the order the main routine moves to them; ``line`` is the ``.src`` line.
    skipped : list of str
        Motions not turned into points, each with its line and why it is not checked.

    Raises
    ------
    InputError
        A missing or empty file, a missing ``DEF``/``END``/``ENDDAT``, an unreadable aggregate
        or number; the message names the file and line.
    """
    src = _src_of(Path(path))
    lines = Lines(src, "KUKA .src file")
    dat_path = _dat_of(src)
    reader = _SrcReader(lines, dat_path, _read_dat(dat_path) if dat_path else _Dat())
    name = reader.run()
    files = (str(src),) + ((str(dat_path),) if dat_path is not None else ())
    return Program(name, "kuka", reader.out, files), reader.skipped


class _SrcReader:
    """The statements of a ``.src`` in program order, with the tool, base, speed and zone they
    set, turned into points and notes."""

    def __init__(self, lines: Lines, dat_path: Path | None, dat: _Dat) -> None:
        self.lines, self.dat_path, self.dat = lines, dat_path, dat
        # until the program sets them, the controller keeps the tool and base of what ran before
        self.tool: Ref | Unknown = ("the program sets no tool before this motion (calls to "
                                     "other routines are not followed)")
        self.base: Ref | Unknown = ("the program sets no base before this motion (calls to "
                                     "other routines are not followed)")
        self.slots: dict[tuple[str, int], np.ndarray | Unknown] = {}
        self.moves = MoveData(lines, dat.data)  # $VEL.CP, $APO.CDIS, LDAT_ACT, PDAT_ACT
        self.external: Unknown | None = None  # under $IPO_MODE #TCP: why, else None
        self.local: set[str] = set()
        self.assigned: dict[str, _Point | str] = {}  # points given a value in the .src
        self.out: list[ProgramPoint] = []
        self.skipped: list[str] = []

    def run(self) -> str:
        """Read every line; the program's name."""
        lines = self.lines
        name, routine = Path(lines.path).stem, None
        started = ended = False
        for lineno, raw in enumerate(lines.lines, start=1):
            line = strip_comment(raw, ";")
            if not line.strip() or line.lstrip().startswith("&"):
                continue
            if m := _ROUTINE_RE.match(line):
                if not started:
                    name, started = m.group(1), True
                elif ended:
                    routine = m.group(1)
                continue
            if _END_RE.match(line):
                ended = ended or started
                continue
            if ended:
                if m := _MOVE_RE.match(line):
                    self.skipped.append(f"line {lineno}: {m.group(1).upper()} in the local "
                                        f"routine {routine} (local routines are not followed)")
                continue
            self.statement(line, lineno)
        if not started:
            what = "the file is empty" if not any(map(str.strip, lines.lines)) else "no DEF line"
            raise InputError(f"{lines.path}: {what}: not a KUKA .src file")
        if not ended:
            raise InputError(f"{lines.path}: line {len(lines.lines)}: no END (truncated file?)")
        return name

    def statement(self, line: str, lineno: int) -> None:
        """One statement of the main routine."""
        lines = self.lines
        if m := _MOVE_RE.match(line):
            self.motion(m.group(1).upper(), m.group(2), lineno)
        elif m := _TOOL_RE.match(line):
            self.tool = self.tool_ref(m.group(1).strip(), lineno)
        elif m := _BASE_RE.match(line):
            self.base = self.base_ref(m.group(1).strip(), lineno)
        elif m := _SLOT_SET_RE.match(line):
            self.set_slot(m, lineno)
        elif m := _BAS_RE.match(line):
            self.bas(m.group(1).upper(), (m.group(2) or "").strip(), lineno)
        elif m := _FDAT_ACT_RE.match(line):
            self.tool, self.base, mode = self.fdat(m.group(1).strip(), lineno)
            if mode is not None:  # BAS(#FRAMES) sets $IPO_MODE to the FDAT's IPO_FRAME
                self.external = _external(mode, lineno)
        elif m := _LDAT_ACT_RE.match(line):
            self.moves.act(m.group(1), m.group(2))
        elif m := _VEL_RE.match(line):
            self.moves.speed = lines.number(m.group(1), lineno)
        elif m := _APO_RE.match(line):
            self.moves.cdis = lines.number(m.group(1), lineno) * 1e-3
        elif m := _IPO_RE.match(line):
            self.external = _external(m.group(1), lineno)
        elif m := _LOCAL_RE.match(line):
            for part in re.split(r",(?![^\[]*\])", m.group(1)):
                self.local.add(re.split(r"[\[=\s]", part.strip(), maxsplit=1)[0].upper())
        elif m := _ASSIGN_RE.match(line):
            self.assign(m, line, lineno)

    def assign(self, m: re.Match, line: str, lineno: int) -> None:
        """``NAME = {aggregate}`` gives a point of the program (or of its .dat) a value from
        here on; any other assignment to one makes it a value of run time."""
        key = re.sub(r"\s+", "", m.group(1)).upper()
        if key not in self.dat.points and key.split("[")[0] not in self.local | self.dat.unset:
            return
        value = line[line.index("=") + 1:].strip()
        if "." not in line[:line.index("=")] and value.startswith("{") and ":" not in (
                _target(value)[1]):
            typ, fields = aggregate_fields(value, self.lines, lineno)
            if given := _partial(typ, fields):
                self.assigned[key] = (f"{m.group(1).strip()} is given {given} only (line "
                                      f"{lineno}), not a whole point")
            else:
                self.assigned[key] = _Point(_kind_of(typ, fields), fields, self.lines, lineno,
                                            key)
        else:
            self.assigned[key] = f"{m.group(1).strip()} is set at run time (line {lineno})"

    # -- tool and base -------------------------------------------------------------------------
    def slot(self, kind: str, n: int) -> tuple[np.ndarray | None, Unknown | None]:
        """The pose the program gave ``TOOL_DATA[n]``/``BASE_DATA[n]`` (None: the cell's), or
        why it is not known."""
        value = self.slots.get((kind, n))
        if isinstance(value, str):
            return None, value
        return value, None

    def tool_ref(self, value: str, lineno: int) -> Ref | Unknown:
        if value.startswith("{"):
            return Ref(pose=_frame_value(value, self.lines, lineno))
        if value.upper() in ("$NULLFRAME", "TOOL_DATA[0]"):
            return Ref(number=0)
        if m := _DATA_RE.match(value):
            n = int(m.group(2))
            pose, why = self.slot("TOOL_DATA", n)
            return why or Ref(number=n, pose=pose)
        return f"the tool is $TOOL={value}, computed at run time (line {lineno})"

    def base_ref(self, value: str, lineno: int) -> Ref | Unknown:
        if value.startswith("{"):
            return Ref(pose=_frame_value(value, self.lines, lineno), on_table=False)
        if value.upper() in ("$NULLFRAME", "$WORLD", "BASE_DATA[0]"):
            return Ref(number=0, on_table=False)
        m = _EK_RE.match(value) or _DATA_RE.match(value)
        if m:
            n = int(m.group(m.lastindex))
            pose, why = self.slot("BASE_DATA", n)
            return why or Ref(number=n, pose=pose, on_table=m.re is _EK_RE)
        return f"the base is $BASE={value}, computed at run time (line {lineno})"

    def set_slot(self, m: re.Match, lineno: int) -> None:
        """``TOOL_DATA[n]={...}``, ``BASE_DATA[n]={...}`` (or a part or a value computed at run
        time) set in the program."""
        kind, index, part, value = m.group(1).upper(), m.group(2), m.group(3), m.group(4).strip()
        if not index.isdigit():
            return  # a slot chosen at run time: each later use of a slot is by number
        key = (kind, int(index))
        if part is None and value.startswith("{"):
            self.slots[key] = _frame_value(value, self.lines, lineno)
        else:
            self.slots[key] = f"{kind}[{index}] is set at run time (line {lineno})"

    def bas(self, command: str, arg: str, lineno: int) -> None:
        """``BAS(#TOOL,n)``, ``BAS(#BASE,n)``; the speed and approximation distance the
        other commands set (:class:`~robotcell.controllers.kuka.movedata.MoveData`)."""
        if command in ("TOOL", "BASE"):
            self.bas_frame(command, arg, lineno)
        else:
            self.moves.bas(command, arg, lineno)

    def bas_frame(self, kind: str, number: str, lineno: int) -> None:
        if not number.isdigit():
            why = f"BAS(#{kind},{number}) chooses the {kind.lower()} at run time (line {lineno})"
            if kind == "TOOL":
                self.tool = why
            else:
                self.base = why
            return
        n = int(number)
        if kind == "TOOL":
            pose, why = self.slot("TOOL_DATA", n)
            self.tool = why or Ref(number=n, pose=pose)
        else:
            pose, why = self.slot("BASE_DATA", n)
            self.base = why or Ref(number=n, pose=pose, on_table=None)

    def fdat(self, value: str, lineno: int) -> tuple[Ref | Unknown, Ref | Unknown, str | None]:
        """Tool, base and ``IPO_FRAME`` (None: not known) of ``FDAT_ACT=FPn`` (or an FDAT
        aggregate)."""
        if value.startswith("{"):
            fields = aggregate_fields(value, self.lines, lineno)[1]
        else:
            name = re.match(r"^\w*", value).group(0)
            if name.upper() not in self.dat.data:
                why = (f"the tool and base are those of FDAT {name} (line {lineno}), which "
                       + ("KSS declares in $config.dat" if name.upper() == "FHOME" else
                          "is not declared in the program's .dat")
                       + ", not beside the program")
                return why, why, None
            fields = self.dat.data[name.upper()]
        tool_no = int_value(fields.get("TOOL_NO", "0"), self.lines, lineno)
        base_no = int_value(fields.get("BASE_NO", "0"), self.lines, lineno)
        tool_pose, tool_why = self.slot("TOOL_DATA", tool_no)
        base_pose, base_why = self.slot("BASE_DATA", base_no)
        return (tool_why or Ref(number=tool_no, pose=tool_pose),
                base_why or Ref(number=base_no, pose=base_pose, on_table=None),
                fields.get("IPO_FRAME"))

    def settings(self, clause: str, lineno: int) -> Settings:
        """The tool, base, interpolation mode, speed and approximation distance of one motion:
        those its ``WITH`` clause gives, else the current ones.

        The spline inline forms give them through functions KSS's ``bas.src`` defines:
        ``$TOOL = STOOL2(FP1)`` is ``TOOL_DATA[FP1.TOOL_NO]`` (``STOOL``), ``$BASE =
        SBASE(FP1.BASE_NO)`` is ``BASE_DATA[FP1.BASE_NO]`` (``$WORLD`` for 0), ``$IPO_MODE =
        SIPO_MODE(FP1.IPO_FRAME)`` the FDAT's ``IPO_FRAME`` (the tool and base corrections of
        technology packages, off in ``$config.dat``, are not applied); the speed and distance
        as :meth:`MoveData.with_item <robotcell.controllers.kuka.movedata.MoveData.with_item>`
        reads them. Any other function is a value of run time.
        """
        s = Settings(self.tool, self.base, self.external, self.moves.speed, self.moves.cdis)
        for item in _top_level(clause):
            key, _, value = item.partition("=")
            key, value = re.sub(r"\s+", "", key).upper(), value.strip()
            call = _CALL_RE.match(value)
            fn, arg = (call.group(1).upper(), call.group(2)) if call else ("", "")
            fdat = arg.split(".")[0]
            if key == "$TOOL":
                s.tool = (self.fdat(arg, lineno)[0] if fn == "STOOL2"
                          else self.tool_ref(value, lineno))
            elif key == "$BASE" and fn == "SBASE" and arg.upper().endswith(".BASE_NO"):
                s.base = self.fdat(fdat, lineno)[1]
            elif key == "$BASE":
                s.base = self.base_ref(f"BASE_DATA[{arg}]" if fn == "SBASE" and arg.isdigit()
                                      else value, lineno)
            elif key == "$IPO_MODE":
                mode = self.fdat(fdat, lineno)[2] if fn == "SIPO_MODE" else value
                s.external = s.external if mode is None else _external(mode, lineno)
            else:
                self.moves.with_item(key, value, s, lineno)
        return s

    # -- motions -------------------------------------------------------------------------------
    def motion(self, kind: str, rest: str, lineno: int) -> None:
        """A motion instruction: a point, or a note saying why it is not checked."""
        parts = re.split(r"\s+WITH\s+", rest, maxsplit=1, flags=re.IGNORECASE)
        target, after = _target(parts[0].strip())
        # the approximation keyword ends the instruction, after a WITH clause if there is one
        clause, approx = _approx(parts[1] if len(parts) > 1 else "")
        approx = approx or next((m.group(1).upper() for m in _APPROX_RE.finditer(after)), None)
        label = f"line {lineno}: {kind} {target}"
        if kind.endswith("_REL"):
            self.skipped.append(f"{label} (a motion relative to where the robot is at run time)")
            return
        if kind in ("CIRC", "SCIRC", "SPL"):
            what = "circular motions" if kind.endswith("CIRC") else "spline segments"
            self.skipped.append(f"line {lineno}: {kind} ({what} are not checked)")
            return
        if after.startswith(":"):
            self.skipped.append(f"{label} {after} (a pose computed at run time with the "
                                "geometric operator ':')")
            return
        value, why = self.point(target, lineno)
        if value is None:
            self.skipped.append(f"{label} ({why})")
            return
        s = self.settings(clause, lineno)
        if value.pose is not None and (why := next(
                (w for w in (s.external, s.tool, s.base) if isinstance(w, str)), None)):
            self.skipped.append(f"{label} ({why})")
            return
        if isinstance(s.tool, str):  # joints: checked whatever the tool; the TCP: the flange's
            s.tool = Ref(number=0)
        if isinstance(s.base, str):
            s.base = Ref(number=0, on_table=None)
        self.out.append(self.program_point(kind, target, value, s, approx, lineno))

    def point(self, target: str, lineno: int) -> tuple[_Point | None, str]:
        """The point a motion goes to, or None and why it is not held by the program."""
        if target.startswith("{"):
            typ, fields = aggregate_fields(target, self.lines, lineno)
            if given := _partial(typ, fields):  # the other components are not in the file
                return None, (f"the aggregate gives {given} only, not a whole "
                              + ("axis position" if _kind_of(typ, fields) in _JOINT else "pose"))
            return _Point(_kind_of(typ, fields), fields, self.lines, lineno, "the aggregate"), ""
        key = re.sub(r"\s+", "", target).upper()
        if key.startswith("$"):
            return None, "not held by the program"
        if key in self.assigned:
            value = self.assigned[key]
            return (None, value) if isinstance(value, str) else (value, "")
        if key in self.dat.points:
            return self.dat.points[key], ""
        base = key.split("[")[0].split(".")[0]
        if base in self.local or base in self.dat.unset:
            return None, f"{target} is a variable set at run time"
        if _HOME_RE.match(key):
            return None, f"{target} is a point of $config.dat, not beside the program"
        if self.dat_path is None:
            return None, (f"{target} is declared neither in the .src nor in a .dat beside it: "
                          f"there is no {Path(self.lines.path).stem}.dat, copy the program's "
                          ".dat beside the .src if it has one (a global point of another "
                          "module or of $config.dat is not read)")
        return None, (f"{target} is declared in neither the program's .dat nor its .src (a "
                      "global point of another module is not read)")

    def program_point(self, kind: str, target: str, value: _Point, s: Settings,
                      approx: str | None, lineno: int) -> ProgramPoint:
        motion = "lin" if kind in ("LIN", "SLIN") else "ptp"
        name = f"line {lineno}" if target.startswith("{") else target
        # S and T: PTP only. A linear first motion keeps the configuration the robot is in,
        # which the files do not hold: the point's S and T are the best statement of it.
        config = value.config if motion == "ptp" or not self.out else None
        return ProgramPoint(name, lineno, motion, s.tool, s.base, value.pose, value.joints,
                            config, dict(value.external), s.speed if motion == "lin" else None,
                            zone(approx, s.cdis), value.where)


def _target(text: str) -> tuple[str, str]:
    """A motion's target (an aggregate, a name, an array element or a field) and what follows
    it."""
    if text.startswith("{"):
        depth = 0
        for i, ch in enumerate(text):
            depth += (ch == "{") - (ch == "}")
            if depth == 0:
                return text[:i + 1], text[i + 1:].strip()
        return text, ""
    m = _TARGET_RE.match(text)
    if not m:
        return text, ""
    return m.group(0), text[m.end():].strip()


def _approx(text: str) -> tuple[str, str | None]:
    """``text`` without the approximation keyword that ends it (``C_DIS``, ``C_SPL``, ..), and
    the keyword (upper case; None without one)."""
    m = re.search(rf"(?:^|\s){_APPROX_RE.pattern}\s*$", text, re.IGNORECASE)
    if not m:
        return text, None
    return text[:m.start()].rstrip(), m.group(1).upper()


def _top_level(text: str) -> list[str]:
    """The comma-separated items of ``text`` outside brackets, braces and parentheses."""
    items, depth, cur = [], 0, []
    for ch in text:
        depth += (ch in "([{") - (ch in ")]}")
        if ch == "," and depth == 0:
            items.append("".join(cur).strip())
            cur = []
        else:
            cur.append(ch)
    items.append("".join(cur).strip())
    return [i for i in items if i]
