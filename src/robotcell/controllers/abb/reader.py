"""Reading ABB RAPID modules (``.mod``, ``.prg``, ``.modx``).

The reader follows RAPID as ABB's manuals describe it (sources in ``docs/programs.md``):

- a module is ``MODULE name [(attributes)]`` .. ``ENDMODULE``; statements end with ``;`` and may
  run over several lines; ``!`` starts a comment; old files start with a ``%%%`` header;
- data declarations ``[LOCAL|TASK] CONST|PERS|VAR type name [{dims}] [:= value]``, arrays written
  ``[v1, v2, ...]`` (``[[a, b], [c, d]]`` for two dimensions) and used as ``name{i}``,
  ``name{i,j}``, a value written out or the name of other data (Technical reference manual -
  RAPID kernel, "Data declarations", "Array declarations");
- placeholders (``<SMT>``: a statement not yet written) stand without ``;`` and move nothing;
- a procedure call's arguments: required ones after commas, optional ones written
  ``\\Name[:=value]`` with or without a comma before them, so ``MoveJ p10\\ID:=10, v100, ...``
  and ``MoveAbsJ [...]\\NoEOffs, ...`` (RAPID kernel manual, "Procedure call");
- the motions ``MoveJ``/``MoveL``/``MoveAbsJ`` and their ``DO``, ``AO``, ``GO`` and ``Sync``
  forms (target, speed, zone, tool), ``TriggJ``/``TriggL`` and the arc welding ``ArcL``/
  ``ArcLStart``/``ArcLEnd`` (zone and tool the last two required arguments), ``SpotJ``/``SpotL``
  (no zone); ``\\V:=`` and ``\\Z:=`` override the speed and the zone, ``\\WObj:=`` names the work
  object (RAPID Instructions, Functions and Data types);
- ``ConfJ``/``ConfL`` ``\\On`` (the default) or ``\\Off``: with monitoring off the controller
  moves to the closest configuration and does not use the target's ``confdata``; the reader
  keeps ``confdata`` only for motions that use it, in program order.

Targets computed at run time (``Offs``, ``RelTool``, ``CRobT``, a variable declared without a
value, or one of another module of the task) and circular, search and external-axis motions are
named as not checked, never refused; so are a placeholder and a call of an instruction or
routine the reader does not know whose first argument is a target. A target declared with a quaternion
that is no rotation (``[0,0,0,0]``, a position not yet defined) is read; a motion to it is
refused.
"""

from __future__ import annotations

import codecs
import re
from pathlib import Path

import numpy as np

from robotcell.controllers.abb import export as export_abb
from robotcell.controllers.model import Config, Program, ProgramPoint, Ref
from robotcell.controllers.text import Lines, split, strip_comment
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor

__all__ = ["EAX", "MOVE_INSTRUCTIONS", "read"]

#: The logical external axes of a robtarget, in order.
EAX = ("eax_a", "eax_b", "eax_c", "eax_d", "eax_e", "eax_f")
#: The robot axes of a jointtarget, for messages.
_AXES = "rax_1, rax_2, rax_3, rax_4, rax_5, rax_6"

_DECL_RE = re.compile(r"^(?:LOCAL\s+|TASK\s+)*(CONST|PERS|VAR)\s+(\w+)\s+(\w+)\s*(\{[^}]*\})?"
                      r"\s*(?::=\s*(.*))?$", re.IGNORECASE | re.DOTALL)
_KEYWORD_RE = re.compile(r"^(MODULE|ENDMODULE|PROC|ENDPROC|FUNC|ENDFUNC|TRAP|ENDTRAP|IF|ELSEIF|"
                         r"ELSE|ENDIF|FOR|ENDFOR|WHILE|ENDWHILE|TEST|CASE|DEFAULT|ENDTEST|ERROR|"
                         r"BACKWARD|UNDO|RECORD|ENDRECORD)\b", re.IGNORECASE)
_CALL_RE = re.compile(r"^(\w+)\b\s*(.*)$", re.DOTALL)
#: Reserved words that start a statement ending with ``;`` (RAPID kernel manual, "Statements").
_STATEMENT_WORDS = frozenset(("return", "raise", "goto", "connect", "exit", "retry", "trynext"))
_CONF_RE = re.compile(r"^(ConfJ|ConfL)\s*\\\s*(On|Off)\b", re.IGNORECASE)
#: RAPID's placeholders for parts of a program not yet written (``<SMT>`` a statement, ``<DDN>``
#: a data declaration, ..): a placeholder written for a whole statement or declaration has no
#: ``;``.
_PLACEHOLDER_RE = re.compile(r"^<(TDN|DDN|RDN|PAR|ALT|DIM|SMT|VAR|EIT|CSE|EXP|ARG|ID)>$")
#: Motions to one target: indices of target, speed, zone (None: a stop point) and tool among
#: the required arguments.
_LINEAR, _JOINT = "lin", "ptp"
_MOTIONS: dict[str, tuple[str, int, int, int | None, int]] = {
    **{name.lower(): (kind, 0, 1, 2, 3) for kind, names in (
        (_JOINT, ("MoveJ", "MoveAbsJ", "MoveJDO", "MoveJAO", "MoveJGO", "MoveJSync")),
        (_LINEAR, ("MoveL", "MoveLDO", "MoveLAO", "MoveLGO", "MoveLSync"))) for name in names},
    "triggj": (_JOINT, 0, 1, -2, -1), "triggl": (_LINEAR, 0, 1, -2, -1),
    **{name.lower(): (_LINEAR, 0, 1, -2, -1) for name in ("ArcL", "ArcLStart", "ArcLEnd",
                                                           "ArcL1", "ArcL2")},
    "spotj": (_JOINT, 0, 1, None, -1), "spotl": (_LINEAR, 0, 1, None, -1),
}
_CIRCULAR = {n.lower() for n in ("MoveC", "MoveCDO", "MoveCAO", "MoveCGO", "MoveCSync", "TriggC",
                                 "ArcC", "ArcCStart", "ArcCEnd", "ArcC1", "ArcC2", "SearchC")}
_OTHER_MOTIONS = {"searchl": "a search motion stops where its signal comes",
                  "moveextj": "a motion of external axes only"}
#: Every move instruction the reader knows, in lower case (MultiMove's ``\\ID`` rules apply to
#: them all).
MOVE_INSTRUCTIONS = frozenset(_MOTIONS) | frozenset(_CIRCULAR) | frozenset(_OTHER_MOTIONS)


def statements(lines: Lines) -> list[tuple[int, str]]:
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
        if not cur and _PLACEHOLDER_RE.match(line):
            out.append((lineno, line))
            continue
        if not cur:
            start = lineno
        cur.append(line)
        text = " ".join(cur)
        if text.endswith(";") or (_KEYWORD_RE.match(text) and len(cur) == 1):
            out.append((start, text.rstrip(";").strip()))
            cur = []
    if cur:
        raise lines.error(start, f"the statement {' '.join(cur)[:40]!r} has no ';' (truncated "
                                 "file?)")
    return out


def arguments(text: str) -> tuple[list[str], dict[str, str]]:
    """The required arguments of a procedure call in order, and its optional ones by lower-case
    name (``\\WObj:=wobj1`` -> ``{"wobj": "wobj1"}``, ``\\Conc`` -> ``{"conc": ""}``)."""
    required: list[str] = []
    optional: dict[str, str] = {}
    for part in split(text):
        pieces = split(part, "\\")  # the argument, then each optional one
        head = pieces.pop(0).strip()
        if head:
            required.append(head)
        for opt in pieces:
            name, _, value = opt.partition(":=")
            optional[name.strip().rstrip("?").lower()] = value.strip()
    return required, optional


def _inner(text: str, lines: Lines, lineno: int) -> list[str]:
    t = text.strip()
    if not (t.startswith("[") and t.endswith("]")):
        raise lines.error(lineno, f"expected [...], got {t[:40]!r}")
    return split(t[1:-1])


def _numbers(text: str, names: str, lines: Lines, lineno: int) -> list[float]:
    """The numbers of ``[a, b, ...]``, as many as ``names`` (``"x, y, z"``) names."""
    parts = _inner(text, lines, lineno)
    count = len(names.split(","))
    if len(parts) != count:
        raise lines.error(lineno, f"expected {count} values ({names}) in {text.strip()[:40]!r}, "
                                  f"got {len(parts)}")
    return [lines.number(p, lineno) for p in parts]


class _Target:
    """A ``robtarget`` (pose, confdata) or a ``jointtarget`` (joints), with its external axes.

    A ``robtarget`` whose quaternion is no rotation (not normalised, such as ``[0,0,0,0]``, which
    modules declare for a position not yet defined) keeps the reason in ``problem``: a module
    may declare it, a motion cannot move to it.
    """

    def __init__(self, kind: str, value: str, lines: Lines, lineno: int) -> None:
        self.where = lines.where(lineno)
        self.line = lineno
        parts = _inner(value, lines, lineno)
        self.pose = self.joints = self.config = self.problem = None
        if kind == "jointtarget":
            if len(parts) != 2:
                raise lines.error(lineno, "a jointtarget is [[axes 1-6],[external axes]], got "
                                          f"{len(parts)} part(s)")
            self.joints = np.radians(_numbers(parts[0], _AXES, lines, lineno))
        else:
            if len(parts) != 4:
                raise lines.error(lineno, "a robtarget is [[x,y,z],[q1,q2,q3,q4],"
                                          f"[cf1,cf4,cf6,cfx],[external axes]], got {len(parts)} "
                                          "part(s)")
            xyz = _numbers(parts[0], "x, y, z", lines, lineno)
            quat = _numbers(parts[1], "q1, q2, q3, q4", lines, lineno)
            try:
                self.pose = pose_from_vendor(xyz + quat, "abb")
            except InputError as exc:
                self.problem = str(exc)
            cf = _numbers(parts[2], "cf1, cf4, cf6, cfx", lines, lineno)
            self.config = Config("abb", tuple(round(c) for c in cf))
        values = _numbers(parts[-1], ", ".join(EAX), lines, lineno)
        self.external = {k: v for k, v in zip(EAX, values) if abs(v) < 9e8}


def _elements(value: str, ndims: int, lines: Lines, lineno: int) -> list[tuple[tuple[int, ...],
                                                                              str]]:
    """The elements of an array of ``ndims`` dimensions written ``[[a, b], [c, d]]``, with
    their indices from 1 (``(2, 1)`` for ``c``, used as ``name{2,1}``; RAPID kernel manual,
    "Array declarations")."""
    out = []
    for i, item in enumerate(_inner(value, lines, lineno), start=1):
        if ndims == 1:
            out.append(((i,), item))
        else:
            out += [((i, *index), t) for index, t in _elements(item, ndims - 1, lines, lineno)]
    return out


class _Data:
    """The data a module declares: targets (arrays as ``name{i}``), tools, work objects,
    speeds and zones by lower-case name, targets declared without a value, and targets declared
    as another data's name or an expression (``named``: name -> the text, without spaces)."""

    def __init__(self) -> None:
        self.targets: dict[str, _Target] = {}
        self.unset: set[str] = set()
        self.named: dict[str, str] = {}
        self.tools: dict[str, np.ndarray] = {}
        self.wobjs: dict[str, Ref] = {}
        self.values: dict[str, tuple[str, str]] = {}

    def declare(self, m: re.Match, lines: Lines, lineno: int) -> None:
        kind, var, dims, value = m.group(2).lower(), m.group(3).lower(), m.group(4), m.group(5)
        if kind in ("robtarget", "jointtarget"):
            if value is None:
                self.unset.add(var)
            elif dims:
                for index, item in _elements(value, dims.count(",") + 1, lines, lineno):
                    self.target(f"{var}{{{','.join(map(str, index))}}}", kind, item, lines,
                                lineno)
            else:
                self.target(var, kind, value, lines, lineno)
        elif kind in ("tooldata", "wobjdata") and value is not None and not dims:
            compact = re.sub(r"\s+", "", value)
            slots = export_abb.parse(f"PERS {kind} {m.group(3)}:={compact};")
            if kind == "tooldata" and slots.tools:
                self.tools[var] = slots.tools[0].pose
            elif kind == "wobjdata" and slots.frames:
                s = slots.frames[0]
                self.wobjs[var] = Ref(name=m.group(3), pose=s.pose, on_table=s.on_table)
        elif kind in ("speeddata", "zonedata") and value is not None:
            self.values[var] = (kind, value)

    def target(self, key: str, kind: str, value: str, lines: Lines, lineno: int) -> None:
        """Declare the target ``key``: a value written out (``[[x,y,z],...]``), or the name of
        other data or an expression (``CONST robtarget p{2} := [p10, p20];`` holds the values of
        ``p10`` and ``p20``, RAPID kernel manual, "Data declarations": the value of a constant
        is an expression)."""
        if value.strip().startswith("["):
            self.targets[key] = _Target(kind, value, lines, lineno)
        else:
            self.named[key] = re.sub(r"\s+", "", value)

    def find(self, key: str) -> tuple[_Target | None, str]:
        """The target ``key`` (lower case, no spaces) holds, following the names it is declared
        as; or None and the name or expression, as written, the names end on."""
        seen, name = {key}, key
        while key in self.named and key not in self.targets:
            name = self.named[key]
            key = name.lower()
            if key in seen:
                break
            seen.add(key)
        return self.targets.get(key), name


def read(path: str | Path) -> tuple[Program, list[str]]:
    """Read a RAPID module.

    Parameters
    ----------
    path : str or Path
        A ``.mod`` (or ``.prg``, ``.modx``) file.

    Returns
    -------
    program : Program
        Points in the order the module's statements move to them; ``line`` is the line of the
        move instruction.
    skipped : list of str
        Motions not turned into points, each with its line and why it is not checked.

    Raises
    ------
    InputError
        A binary file, no ``MODULE``/``ENDMODULE``, a statement without ``;``, an unreadable
        target or number, a motion to a target whose quaternion is no rotation; the message
        names the file and line.
    """
    if _binary(path):
        raise InputError(f"{path}: not a RAPID module in text (it holds NUL characters, as a "
                         "binary file does); give the module as RobotStudio or the controller "
                         "saves it, as text")
    lines = Lines(path, "RAPID module")
    first = _first_code(lines)
    if not re.match(r"^MODULE\b", first[1], re.IGNORECASE):
        raise InputError(f"{path}: line {first[0]}: no MODULE line"
                         + (f" ({first[1][:40]!r} comes first)" if first[1] else "")
                         + ": not a RAPID module")
    stmts = statements(lines)
    if not re.match(r"^ENDMODULE\b", stmts[-1][1], re.IGNORECASE):
        raise InputError(f"{path}: line {len(lines.lines)}: no ENDMODULE (truncated file?)")
    m = re.match(r"^MODULE\s+(\w+)", stmts[0][1], re.IGNORECASE)
    name = m.group(1) if m else Path(path).stem
    data = _Data()
    for lineno, text in stmts:
        if m := _DECL_RE.match(text):
            data.declare(m, lines, lineno)
    motions = _Motions(lines, data)
    for lineno, text in stmts:
        motions.statement(text, lineno)
    return Program(name, "abb", motions.points, (str(path),)), motions.skipped


def _binary(path: str | Path) -> bool:
    """The file holds NUL characters and is no UTF-16 text (which the text reader names)."""
    p = Path(path)
    if not p.is_file():
        return False
    data = p.read_bytes()
    return b"\x00" in data and not data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE))


def _first_code(lines: Lines) -> tuple[int, str]:
    """The first line of code (after comments, blank lines and a ``%%%`` header) and its
    number; ``(1, "")`` for a file of none."""
    header = False
    for lineno, raw in enumerate(lines.lines, start=1):
        line = strip_comment(raw, "!").strip()
        if line.startswith("%%%"):
            header = not header
        elif line and not header:
            return lineno, line
    return 1, ""


class _Motions:
    """The statements of a module in order: ``ConfJ``/``ConfL`` and the motions."""

    def __init__(self, lines: Lines, data: _Data) -> None:
        self.lines, self.data = lines, data
        self.conf = {"ptp": True, "lin": True}  # ConfJ, ConfL \On: RAPID's default
        self.points: list[ProgramPoint] = []
        self.skipped: list[str] = []

    def statement(self, text: str, lineno: int) -> None:
        if m := _CONF_RE.match(text):
            self.conf["ptp" if m.group(1).lower() == "confj" else "lin"] = (
                m.group(2).lower() == "on")
            return
        if _PLACEHOLDER_RE.match(text):
            self.skipped.append(f"line {lineno}: {text} (a placeholder of a part not yet "
                                "written: it moves nothing)")
            return
        m = _CALL_RE.match(text)
        if not m or _DECL_RE.match(text):
            return
        instr = m.group(1)
        key = instr.lower()
        if key in _CIRCULAR:
            self.skipped.append(f"line {lineno}: {instr} (circular motions are not checked)")
        elif key in _OTHER_MOTIONS:
            self.skipped.append(f"line {lineno}: {instr} ({_OTHER_MOTIONS[key]})")
        elif key in _MOTIONS:
            self.motion(instr, m.group(2), lineno)
        elif not _KEYWORD_RE.match(text) and key not in _STATEMENT_WORDS:
            self.unread(instr, m.group(2), lineno)

    def unread(self, instr: str, text: str, lineno: int) -> None:
        """Name a call of an instruction or routine the reader does not know whose first argument
        is a target (``ArcRepL p10, ...``, ``PickPart pPick;``): a motion it makes to the target is
        not checked."""
        required, _ = arguments(text)
        first = required[0] if required else ""
        key = re.sub(r"\s+", "", first).lower()
        if first.startswith("[[") or (key and self.data.find(key)[0] is not None):
            shown = first if len(first) <= 40 else first[:37] + "..."
            self.skipped.append(f"line {lineno}: {instr} {shown} ({instr} is an instruction or "
                                "routine robotcell does not read: a motion it makes to this "
                                "target is not checked)")

    def motion(self, instr: str, text: str, lineno: int) -> None:
        lines, data = self.lines, self.data
        motion, i_target, i_speed, i_zone, i_tool = _MOTIONS[instr.lower()]
        required, optional = arguments(text)
        if len(required) < 3 + (i_zone is not None):
            raise lines.error(lineno, f"{instr} needs target, speed, zone and tool")
        target = required[i_target]
        key = re.sub(r"\s+", "", target).lower()
        if target.startswith("["):
            kind = "jointtarget" if instr.lower() == "moveabsj" else "robtarget"
            value, pname = _Target(kind, target, lines, lineno), f"line {lineno}"
        elif (found := data.find(key))[0] is not None:
            value, pname = found[0], target
        else:
            self.skipped.append(f"line {lineno}: {instr} {target} "
                                f"({_why_not_held(target, key, data)})")
            return
        if value.problem is not None:  # an inline target's text is on the motion's line
            what = instr if target.startswith("[") else (
                f"{instr} {target} (its value on line {value.line})")
            raise lines.error(lineno, f"{what}: {value.problem}")
        tname = required[i_tool].strip()
        tref = Ref(name=tname, pose=data.tools.get(tname.lower()))
        wname = optional.get("wobj") or "wobj0"
        fref = data.wobjs.get(wname.lower(), Ref(name=wname, on_table=None))
        speed = _speed(optional["v"], {}, lines, lineno) if optional.get("v") else _speed(
            required[i_speed], data.values, lines, lineno)
        zone = 0.0 if i_zone is None else (
            lines.number(optional["z"], lineno) * 1e-3 if optional.get("z") else
            _zone(required[i_zone], data.values, lines, lineno))
        config = value.config if self.conf[motion] else None
        self.points.append(ProgramPoint(pname, lineno, motion, tref, fref, value.pose,
                                        value.joints, config, dict(value.external), speed, zone,
                                        value.where))


def _why_not_held(target: str, key: str, data: _Data) -> str:
    """Why a motion's target (``key``: lower case, no spaces) is not a point of the module."""
    if re.match(r"^\w+$", key) is None and re.match(r"^\w+\{", key) is None:
        return "a target computed at run time"
    if key.split("{")[0] in data.unset:
        return f"{target} is a variable set at run time"
    if key in data.named:
        end = data.find(key)[1]
        if re.match(r"^\w+$", end) is None:
            return f"{target} is declared as {end}, a target computed at run time"
        if end.lower() in data.unset:
            return f"{target} is declared as {end}, a variable set at run time"
        return (f"{target} is declared as {end}, which is declared in no data of this module (a "
                "target of another module of the task is not read)")
    if "{" in key:
        return f"{target} is an element chosen at run time or not declared in the module"
    return (f"{target} is declared in no data of this module (a target of another module of the "
            "task is not read)")


def _declared(text: str, values: dict) -> str:
    """The value of a ``speeddata`` or ``zonedata`` as written, following the names of the
    module's declarations (``CONST zonedata corner := z10;``)."""
    t, seen = text.strip(), set()
    while t.lower() in values and t.lower() not in seen:
        seen.add(t.lower())
        t = values[t.lower()][1].strip()
    return t


def _speed(text: str, values: dict, lines: Lines, lineno: int) -> float | None:
    """TCP speed (m/s) of a ``speeddata`` (``v100``, declared, or written out); a number alone
    (a ``\\V:=`` value) is mm/s."""
    t = _declared(text, values)
    if m := re.match(r"^v(\d+)$", t, re.IGNORECASE):
        return int(m.group(1)) * 1e-3
    if re.match(r"^[-+0-9.eE]+$", t):
        return lines.number(t, lineno) * 1e-3
    if t.startswith("["):
        return lines.number(split(t[1:-1])[0], lineno) * 1e-3
    return None


def _zone(text: str, values: dict, lines: Lines, lineno: int) -> float | None:
    """Zone radius (m) of a ``zonedata`` (``fine``, ``z10``, declared, or written out)."""
    t = _declared(text, values)
    if t.lower() == "fine":
        return 0.0
    if m := re.match(r"^z(\d+)$", t, re.IGNORECASE):
        return int(m.group(1)) * 1e-3
    if t.startswith("["):
        parts = split(t[1:-1])
        return 0.0 if parts[0].upper() == "TRUE" else lines.number(parts[1], lineno) * 1e-3
    return None
