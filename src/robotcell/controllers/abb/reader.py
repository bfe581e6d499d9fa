"""Reading ABB RAPID modules (``.mod``, ``.prg``).

The reader follows RAPID as ABB's manuals describe it (sources in ``docs/programs.md``):

- a module is ``MODULE name [(attributes)]`` .. ``ENDMODULE``; statements end with ``;`` and may
  run over several lines; ``!`` starts a comment; old files start with a ``%%%`` header;
- data declarations ``[LOCAL|TASK] CONST|PERS|VAR type name [{dims}] [:= value]``, arrays written
  ``[v1, v2, ...]`` and used as ``name{i}`` (Technical reference manual - RAPID kernel, "Data
  declarations", "Array declarations");
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
named as not checked, never refused.
"""

from __future__ import annotations

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

_DECL_RE = re.compile(r"^(?:LOCAL\s+|TASK\s+)*(CONST|PERS|VAR)\s+(\w+)\s+(\w+)\s*(\{[^}]*\})?"
                      r"\s*(?::=\s*(.*))?$", re.IGNORECASE | re.DOTALL)
_KEYWORD_RE = re.compile(r"^(MODULE|ENDMODULE|PROC|ENDPROC|FUNC|ENDFUNC|TRAP|ENDTRAP|IF|ELSEIF|"
                         r"ELSE|ENDIF|FOR|ENDFOR|WHILE|ENDWHILE|TEST|CASE|DEFAULT|ENDTEST|ERROR|"
                         r"BACKWARD|UNDO|RECORD|ENDRECORD)\b", re.IGNORECASE)
_CALL_RE = re.compile(r"^(\w+)\b\s*(.*)$", re.DOTALL)
_CONF_RE = re.compile(r"^(ConfJ|ConfL)\s*\\\s*(On|Off)\b", re.IGNORECASE)
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


def _numbers(text: str, count: int, lines: Lines, lineno: int) -> list[float]:
    parts = _inner(text, lines, lineno)
    if len(parts) != count:
        raise lines.error(lineno, f"expected {count} values in {text.strip()[:40]!r}")
    return [lines.number(p, lineno) for p in parts]


class _Target:
    """A ``robtarget`` (pose, confdata) or a ``jointtarget`` (joints), with its external axes."""

    def __init__(self, kind: str, value: str, lines: Lines, lineno: int) -> None:
        self.where = lines.where(lineno)
        parts = _inner(value, lines, lineno)
        self.pose = self.joints = self.config = None
        if kind == "jointtarget":
            if len(parts) != 2:
                raise lines.error(lineno, "a jointtarget is [[axes 1-6],[external axes]]")
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
        values = _numbers(parts[-1], 6, lines, lineno)
        self.external = {k: v for k, v in zip(EAX, values) if abs(v) < 9e8}


class _Data:
    """The data a module declares: targets (arrays as ``name{i}``), tools, work objects,
    speeds and zones by lower-case name, and targets declared without a value."""

    def __init__(self) -> None:
        self.targets: dict[str, _Target] = {}
        self.unset: set[str] = set()
        self.tools: dict[str, np.ndarray] = {}
        self.wobjs: dict[str, Ref] = {}
        self.values: dict[str, tuple[str, str]] = {}

    def declare(self, m: re.Match, lines: Lines, lineno: int) -> None:
        kind, var, dims, value = m.group(2).lower(), m.group(3).lower(), m.group(4), m.group(5)
        if kind in ("robtarget", "jointtarget"):
            if value is None:
                self.unset.add(var)
            elif dims:
                for i, item in enumerate(_inner(value, lines, lineno), start=1):
                    self.targets[f"{var}{{{i}}}"] = _Target(kind, item, lines, lineno)
            else:
                self.targets[var] = _Target(kind, value, lines, lineno)
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


def read(path: str | Path) -> tuple[Program, list[str]]:
    """Read a RAPID module.

    Parameters
    ----------
    path : str or Path
        A ``.mod`` (or ``.prg``) file.

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
        No ``MODULE``/``ENDMODULE``, a statement without ``;``, an unreadable target or number;
        the message names the file and line.
    """
    lines = Lines(path, "RAPID module")
    stmts = statements(lines)
    if not stmts or not re.match(r"^MODULE\b", stmts[0][1], re.IGNORECASE):
        raise InputError(f"{path}: no MODULE line: not a RAPID module")
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
        elif key in data.targets:
            value, pname = data.targets[key], target
        else:
            self.skipped.append(f"line {lineno}: {instr} {target} "
                                f"({_why_not_held(target, key, data)})")
            return
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
    if "{" in key:
        return f"{target} is an element chosen at run time or not declared in the module"
    return (f"{target} is declared in no data of this module (a target of another module of the "
            "task is not read)")


def _speed(text: str, values: dict, lines: Lines, lineno: int) -> float | None:
    """TCP speed (m/s) of a ``speeddata`` (``v100``, declared, or written out); a number alone
    (a ``\\V:=`` value) is mm/s."""
    t = text.strip()
    if m := re.match(r"^v(\d+)$", t, re.IGNORECASE):
        return int(m.group(1)) * 1e-3
    if re.match(r"^[-+0-9.eE]+$", t):
        return lines.number(t, lineno) * 1e-3
    if t.lower() in values:
        t = values[t.lower()][1]
    if t.startswith("["):
        return lines.number(split(t[1:-1])[0], lineno) * 1e-3
    return None


def _zone(text: str, values: dict, lines: Lines, lineno: int) -> float | None:
    """Zone radius (m) of a ``zonedata`` (``fine``, ``z10``, declared, or written out)."""
    t = text.strip()
    if t.lower() == "fine":
        return 0.0
    if m := re.match(r"^z(\d+)$", t, re.IGNORECASE):
        return int(m.group(1)) * 1e-3
    if t.lower() in values:
        t = values[t.lower()][1]
    if t.startswith("["):
        parts = split(t[1:-1])
        return 0.0 if parts[0].upper() == "TRUE" else lines.number(parts[1], lineno) * 1e-3
    return None
