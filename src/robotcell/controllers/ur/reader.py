"""Reading URScript programs (``.script``): PolyScope's saved scripts and robotcell's own.

The reader follows URScript as Universal Robots' manual describes it (sources in
``docs/programs.md``):

- a program is ``def NAME():`` .. ``end`` (then, in a saved file, the call ``NAME()``); a line
  ending with ``:`` opens a block (``def``, ``if``, ``while``, ``thread``; ``elif``/``else``
  continue one) that ``end`` closes; ``#`` starts a comment; PolyScope's ``$ 1 "MoveJ"`` lines
  mark the program tree and are not statements;
- ``movej(q, a, v, t, r)`` and ``movel(pose, a, v, t, r)``, their arguments by position or by
  name: ``q`` joint positions ``[..]`` in rad, or a pose (the controller then computes the
  joints by inverse kinematics), ``pose`` a pose ``p[x, y, z, rx, ry, rz]`` (m, rotation vector
  in rad; a joint list is moved to by forward kinematics), ``v`` the TCP speed of ``movel`` in
  m/s, ``t`` a time that overrides the speed, ``r`` the blend radius in m;
- ``pose_trans(Feature, p[..])``: the pose ``p`` in the feature, ``Feature`` a pose the file
  declares (``global Plane_1=p[..]``, as PolyScope declares its waypoints);
  ``get_inverse_kin(X, qnear=Q)``: the joints of the pose ``X`` nearest to ``Q`` ("the
  solution closest to qnear", manual); without a ``qnear`` the file gives, the solution nearest
  to the previous point's, as for every point without flags;
- ``set_tcp(p[..])``: the TCP in the tool flange frame for the motions after it (before any, the
  flange).

A value is known when the file assigns it once, as a literal (``global Waypoint_1_p=p[..]``,
``speed_ms = 0.25``); a variable assigned more than once changes at run time. Points are read in
the order of the file's lines (a subprogram's motions where it is written, not where it is
called). Motions whose target is computed at run time or is not known, circular (``movec``),
process (``movep``), servo and speed motions are named as not checked, never refused; a line
that cannot be read (a ``p[..]`` without six numbers, a number that is none, a block without
its ``end``) is refused with the file and line.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from robotcell.controllers.model import Program, ProgramPoint, Ref
from robotcell.controllers.text import Lines, split, strip_comment
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor

__all__ = ["BASE", "FLANGE", "read"]

#: The frame of a point written in the robot base (no feature).
BASE = Ref(kind="base")
#: The tool of motions before any ``set_tcp``: the tool flange.
FLANGE = Ref(name="flange", pose=np.eye(4))

_DEF_RE = re.compile(r"^def\s+([A-Za-z_]\w*)\s*\(\s*\)\s*:$")
_ASSIGN_RE = re.compile(r"^(?:global\s+|local\s+)?([A-Za-z_]\w*)\s*=(?!=)\s*(.+)$")
_CALL_RE = re.compile(r"^([A-Za-z_]\w*)\s*\((.*)\)$", re.DOTALL)
_NAMED_RE = re.compile(r"^([A-Za-z_]\w*)\s*=(?!=)\s*(.*)$", re.DOTALL)
_NUMERIC = re.compile(r"^[-+]?(?:[0-9.]|nan\b|inf)", re.IGNORECASE)
_NOT_CHECKED = {"movec": "circular motions are not checked",
                "movep": "process motions are not checked",
                "servoj": "a servo motion is not checked",
                "servoc": "a servo motion is not checked",
                "speedj": "a speed motion is not checked",
                "speedl": "a speed motion is not checked"}
#: Arguments of movej and movel by position.
_ARGS = ("target", "a", "v", "t", "r")


def _depth(text: str) -> int:
    text = re.sub(r'"[^"]*"', "", text)
    return text.count("(") + text.count("[") - text.count(")") - text.count("]")


def statements(lines: Lines) -> list[tuple[int, str]]:
    """The statements of the file with their first line: comments and PolyScope's ``$`` lines
    dropped, a statement whose brackets are open joined with the lines after it.

    Raises
    ------
    InputError
        Brackets still open at the end of the file, or closed more often than opened.
    """
    out: list[tuple[int, str]] = []
    cur: list[str] = []
    start = depth = 0
    for lineno, raw in enumerate(lines.lines, start=1):
        line = strip_comment(raw, "#").strip()
        if not line or (not cur and line.startswith("$")):
            continue
        if not cur:
            start = lineno
        cur.append(line)
        depth += _depth(line)
        if depth < 0:
            raise lines.error(lineno, f"a bracket is closed that was not opened: {line[:40]!r}")
        if depth == 0:
            out.append((start, " ".join(cur)))
            cur = []
    if cur:
        raise lines.error(start, f"the brackets of {' '.join(cur)[:40]!r} are not closed "
                                 "(truncated file?)")
    return out


def _check_blocks(lines: Lines, stmts: list[tuple[int, str]]) -> str:
    """The program's name (its first ``def``), once every block is closed by ``end``."""
    if not stmts or not (m := _DEF_RE.match(stmts[0][1])):
        raise InputError(f"{lines.path}: no 'def NAME():' line first: not a URScript program")
    depth = 0
    for lineno, text in stmts:
        if text == "end":
            depth -= 1
            if depth < 0:
                raise lines.error(lineno, "'end' closes no block")
        elif text.endswith(":") and not re.match(r"^(elif|else)\b", text):
            depth += 1
    if depth:
        raise lines.error(len(lines.lines), f"{depth} block(s) not closed by 'end', 'def "
                                            f"{m.group(1)}():' among them (truncated file?)")
    return m.group(1)


@dataclass(frozen=True)
class _Value:
    """A literal the file assigns: a pose (4x4), joints or a list, or a number; and its line."""

    pose: NDArray[np.float64] | None
    items: NDArray[np.float64] | None
    number: float | None
    line: int


class _Reader:
    """The statements of one file, its known values, and the motions read so far."""

    def __init__(self, lines: Lines, stmts: list[tuple[int, str]]) -> None:
        self.lines = lines
        self.values: dict[str, _Value | None] = {}
        for lineno, text in stmts:
            if (m := _ASSIGN_RE.match(text)) and not text.endswith(":"):
                name, value = m.group(1), self.literal(m.group(2), lineno)
                # assigned twice: a value set at run time
                self.values[name] = None if name in self.values else value
        self.tool: Ref | None = FLANGE
        self.tool_line = 0
        self.points: list[ProgramPoint] = []
        self.skipped: list[str] = []

    # -- values ------------------------------------------------------------------------------
    def numbers(self, text: str, lineno: int) -> NDArray[np.float64] | None:
        """The numbers of a list ``[..]`` (None when an item is not a number, as a list of
        names); a number that is not finite is refused."""
        items = split(text.strip()[1:-1]) if text.strip() != "[]" else []
        if not items or not all(_NUMERIC.match(i) for i in items):
            return None
        return np.array([self.lines.number(i, lineno) for i in items])

    def pose(self, text: str, lineno: int) -> NDArray[np.float64]:
        """The pose of a literal ``[x, y, z, rx, ry, rz]`` after its ``p`` (m, rad)."""
        values = self.numbers(text, lineno)
        if values is None or values.shape != (6,):
            raise self.lines.error(lineno, f"a pose is p[x, y, z, rx, ry, rz], six numbers; "
                                           f"got {text.strip()[:60]!r}")
        return pose_from_vendor(values, "ur")

    def literal(self, text: str, lineno: int) -> _Value | None:
        t = text.strip()
        if re.match(r"^p\s*\[", t) and t.endswith("]"):
            return _Value(self.pose(t[t.index("["):], lineno), None, None, lineno)
        if t.startswith("[") and t.endswith("]") and _depth(t) == 0:
            items = self.numbers(t, lineno)
            return None if items is None else _Value(None, items, None, lineno)
        if _NUMERIC.match(t) and re.fullmatch(r"[-+0-9.eE]+|[-+]?(nan|inf)", t, re.IGNORECASE):
            return _Value(None, None, self.lines.number(t, lineno), lineno)
        return None

    def known(self, text: str, lineno: int) -> _Value | None:
        """A literal written here, or a variable the file assigns once."""
        t = text.strip()
        if re.fullmatch(r"[A-Za-z_]\w*", t):
            return self.values.get(t)
        return self.literal(t, lineno)

    def number(self, text: str | None, lineno: int) -> float | None:
        v = None if text is None else self.known(text, lineno)
        return None if v is None else v.number

    # -- targets -----------------------------------------------------------------------------
    def target(self, text: str, lineno: int) -> tuple[_Value, Ref, str] | str:
        """The target of a motion: its value, its frame and its name; or why it is not read."""
        t = text.strip()
        if (m := _CALL_RE.match(t)) and m.group(1) == "get_inverse_kin":
            args = split(m.group(2))
            return self.target(args[0], lineno) if args and args[0] else "no pose given"
        if m and m.group(1) == "pose_trans":
            args = split(m.group(2))
            if len(args) != 2:
                raise self.lines.error(lineno, "pose_trans takes two poses (p_from, p_from_to)")
            feature, pose = self.known(args[0], lineno), self.known(args[1], lineno)
            if feature is None or feature.pose is None or pose is None or pose.pose is None:
                return "a pose computed at run time"
            named = re.fullmatch(r"[A-Za-z_]\w*", args[0].strip())
            frame = Ref(name=args[0].strip() if named else None, pose=feature.pose,
                        on_table=False, kind="base")
            return pose, frame, args[1].strip() if re.fullmatch(r"\w+", args[1].strip()) \
                else f"line {lineno}"
        value = self.known(t, lineno)
        if value is not None and (value.pose is not None or value.items is not None):
            if value.items is not None and value.items.shape != (6,):
                raise self.lines.error(lineno, f"joint positions are six numbers (rad); got "
                                               f"{t[:60]!r}")
            name = t if re.fullmatch(r"[A-Za-z_]\w*", t) else f"line {lineno}"
            return value, BASE, name
        if re.fullmatch(r"[A-Za-z_]\w*", t):
            return f"{t} is a variable set at run time or not given a value in this file"
        return "a target computed at run time"

    # -- statements --------------------------------------------------------------------------
    def statement(self, text: str, lineno: int) -> None:
        m = _CALL_RE.match(text)
        if not m:
            return
        func = m.group(1)
        if func == "set_tcp":
            value = self.known(m.group(2), lineno)
            if value is None or value.pose is None:
                self.tool, self.tool_line = None, lineno
            else:
                name = m.group(2).strip()
                self.tool = Ref(name=name if re.fullmatch(r"[A-Za-z_]\w*", name) else None,
                                pose=value.pose)
        elif func in _NOT_CHECKED:
            self.skipped.append(f"line {lineno}: {func} ({_NOT_CHECKED[func]})")
        elif func in ("movej", "movel"):
            self.motion(func, m.group(2), lineno)

    def near(self, target: str, lineno: int) -> NDArray[np.float64] | None:
        """The ``qnear`` of a target ``get_inverse_kin(X, qnear)`` (second argument, or named)
        when the file gives it as six joint values (rad); None otherwise."""
        m = _CALL_RE.match(target.strip())
        if not m or m.group(1) != "get_inverse_kin":
            return None
        args = split(m.group(2))
        given = next((n.group(2) for a in args[1:] if (n := _NAMED_RE.match(a))
                      and n.group(1) == "qnear"), None)
        if given is None and len(args) > 1 and not _NAMED_RE.match(args[1]):
            given = args[1]
        value = None if given is None else self.known(given, lineno)
        if value is None or value.items is None or value.items.shape != (6,):
            return None
        return value.items

    def motion(self, func: str, text: str, lineno: int) -> None:
        args: dict[str, str] = {}
        for k, part in enumerate(split(text)):
            if named := _NAMED_RE.match(part):
                args[named.group(1)] = named.group(2)
            elif k < len(_ARGS):
                args[_ARGS[k]] = part
        target = args.get("target") or args.get("q") or args.get("pose")
        if not target:
            raise self.lines.error(lineno, f"{func} without a target")
        got = self.target(target, lineno)
        if isinstance(got, str):
            t = target.strip()
            t = t if len(t) <= 50 else t[:47] + "..."
            self.skipped.append(f"line {lineno}: {func}({t}) ({got})")
            return
        if self.tool is None:
            self.skipped.append(f"line {lineno}: {func} (the TCP set on line {self.tool_line} "
                                "is computed at run time)")
            return
        value, frame, name = got
        timed = self.number(args.get("t"), lineno)
        speed = self.number(args.get("v"), lineno) if func == "movel" and not timed else None
        zone = self.number(args.get("r"), lineno) if "r" in args else 0.0
        joints = value.items
        self.points.append(ProgramPoint(
            name, lineno, "ptp" if func == "movej" else "lin", self.tool,
            BASE if joints is not None else frame, value.pose, joints, None, {}, speed, zone,
            self.lines.where(value.line if name != f"line {lineno}" else lineno),
            None if joints is not None else self.near(target, lineno)))


def read(path: str | Path) -> tuple[Program, list[str]]:
    """Read a URScript program.

    Parameters
    ----------
    path : str or Path
        A ``.script`` file.

    Returns
    -------
    program : Program
        Points in the order of the file's lines; ``line`` is the line of the motion.
    skipped : list of str
        Motions not turned into points, each with its line and why it is not checked.

    Raises
    ------
    InputError
        No ``def NAME():`` first, a block without ``end``, open brackets, a pose or joint list
        that is not six numbers, a number that is not one; the message names the file and line.
    """
    lines = Lines(path, "URScript program")
    stmts = statements(lines)
    name = _check_blocks(lines, stmts)
    reader = _Reader(lines, stmts)
    for lineno, text in stmts:
        reader.statement(text, lineno)
    return Program(name, "ur", reader.points, (str(path),)), reader.skipped
