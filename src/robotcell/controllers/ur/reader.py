"""Reading URScript programs (``.script``): PolyScope's saved scripts and robotcell's own.

The reader follows URScript as Universal Robots' manual describes it (sources in
``docs/programs.md``):

- a program is ``def NAME():`` (or ``sec NAME():``) .. ``end``, then in a saved file the call
  ``NAME()``; or statements and functions ``def NAME(a, b=1):`` at the top of the file, as
  PolyScope X saves a program and as Universal Robots' example scripts and URCap snippets are
  written (a client wraps such a snippet in a ``def`` before it sends it), the program then
  named after the file; ``def``, ``sec``, ``thread``, ``if``, ``while`` and ``for`` open a block
  (``elif``/``else`` continue one) that ``end`` closes, their body on the next lines or after
  the ``:`` (``if (n == 1): x = True``, as PolyScope saves URCap code; ``if (n == 9):
  movej(q) end`` on one line); ``#`` starts a comment; PolyScope's ``$ 1 "MoveJ"`` lines mark
  the program tree and are not statements; ``run``, ``join`` and ``kill`` handle threads;
- ``movej(q, a, v, t, r)`` and ``movel(pose, a, v, t, r)``, their arguments by position or by
  name: ``q`` joint positions ``[..]`` in rad, or a pose (the controller then computes the
  joints by inverse kinematics), ``pose`` a pose ``p[x, y, z, rx, ry, rz]`` (m, rotation vector
  in rad; a joint list is moved to by forward kinematics), ``v`` the TCP speed of ``movel`` in
  m/s, ``t`` a time that overrides the speed, ``r`` the blend radius in m;
- ``pose_trans(Feature, p[..])``: the pose ``p`` in the feature, ``Feature`` a pose the file
  declares (``global Plane_1=p[..]``, as PolyScope declares its waypoints); a variable
  assigned once ``pose_trans(A, B)`` or ``pose_add(A, B)`` of known poses is known
  (``pose_add``: "p_3.P = p_1.P + p_2.P, p_3.R = p_1.R * p_2.R", manual);
  ``get_inverse_kin(X, qnear=Q)``: the joints of the pose ``X`` nearest to ``Q`` ("the
  solution closest to qnear", manual); without a ``qnear`` the file gives, the solution nearest
  to the previous point's, as for every point without flags;
- ``set_tcp(p[..])``: the TCP in the tool flange frame for the motions after it (before any, the
  flange); PolyScope X adds the TCP's name, ``set_tcp(p[..], "Tool_flange")``;
- a pose of variables or expressions (``p[x, y, z, rx, ry, rz]``, ``p[v[0], .., 0]``) and a
  function's parameters (inside the function, where they hide a global of the same name) are
  values set at run time.

A value is known when the file assigns it once, as a literal (``global Waypoint_1_p=p[..]``,
``speed_ms = 0.25``); a variable assigned more than once changes at run time. Points are read in
the order of the file's lines (a subprogram's motions where it is written, not where it is
called). Motions whose target is computed at run time or is not known, circular (``movec``),
process (``movep``), servo and speed motions are named as not checked, never refused; a line
that cannot be read (a ``p[..]`` of numbers that are not six, a number that is none, a block
without its ``end``, text that is no URScript statement, an assignment without a value, a
number anywhere that is not finite) is refused with the file and line, and so is a file that
holds no statement. A file of statements at the top cut between two statements reads as a
shorter program: no ``end`` is missing.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
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

_DEF_RE = re.compile(r"^(?:def|sec)\s+([A-Za-z_]\w*)\s*\((.*)\)\s*:$", re.DOTALL)
_ASSIGN_RE = re.compile(r"^(?:global\s+|local\s+)?([A-Za-z_]\w*)\s*=(?!=)\s*(.+)$")
_CALL_RE = re.compile(r"^([A-Za-z_]\w*)\s*\((.*)\)$", re.DOTALL)
_NAMED_RE = re.compile(r"^([A-Za-z_]\w*)\s*=(?!=)\s*(.*)$", re.DOTALL)
_NUMERIC = re.compile(r"^[-+]?(?:[0-9.]|nan\b|inf)", re.IGNORECASE)
#: What makes an item of a list an expression, not a number: a name (a letter not after a
#: digit, as ``0.3x`` is a mistyped number), an index, a call or an operator.
_EXPRESSION = re.compile(r"[()\[\]*/%]|(?<![0-9.])[A-Za-z_]")
#: A number of a statement (not a digit of a name), and the words ``nan`` and ``inf``.
_NUMBER_RE = re.compile(r"(?<![\w.])(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?(?![\w.])"
                        r"|\b(?:nan|inf)\b", re.IGNORECASE)
#: Words that open a block, which ``end`` closes.
_BLOCKS = ("def", "thread", "sec", "if", "while", "for")
#: Words a statement may begin with that are followed by a space and more.
_STATEMENT_WORDS = frozenset({*_BLOCKS, "elif", "else", "return", "global", "local", "run",
                              "kill", "join", "halt", "end", "break", "continue", "pass", "not"})
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


def _body(text: str) -> list[str]:
    """A statement that opens or continues a block (``if``, ``elif``, ``else``, ``while``,
    ``for``, ``def``, ``thread``), split after its ``:`` outside brackets and quotes: the head,
    the statement written on the same line, and the ``end`` that closes the block there
    (``if (n == 9): movej(q, t=2) end``); other statements as they are."""
    if not re.match(r"^(?:" + "|".join((*_BLOCKS, "elif", "else")) + r")\b", text):
        return [text]
    head, *rest = split(text, ":")
    if not rest:
        return [text]
    body = ":".join(rest).strip()
    closed = re.fullmatch(r"(.*\S)\s+end", body, re.DOTALL)
    return [head + ":", *([closed.group(1), "end"] if closed else [body] * bool(body))]


def statements(lines: Lines) -> list[tuple[int, str]]:
    """The statements of the file with their first line: comments and PolyScope's ``$`` lines
    dropped, a statement whose brackets are open joined with the lines after it, and the
    statement after a block's ``:`` on the same line a statement of its own.

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
            out.extend((start, part) for part in _body(" ".join(cur)))
            cur = []
    if cur:
        raise lines.error(start, f"the brackets of {' '.join(cur)[:40]!r} are not closed "
                                 "(truncated file?)")
    return out


def _check_statement(lines: Lines, lineno: int, text: str) -> None:
    """Refuse text that is no URScript statement: one that does not begin with a name or a
    word of URScript (a template's ``{{ .. }}``), words not joined by an operator or brackets
    (``power on``, a dashboard server command), an assignment without its value."""
    first = re.match(r"^([A-Za-z_]\w*)(\s+[A-Za-z0-9_\"])?", text)
    if not first or (first.group(2) and first.group(1) not in _STATEMENT_WORDS):
        raise lines.error(lineno, f"{text[:50]!r} is not a URScript statement (a call, an "
                                  "assignment, or a statement of a word of URScript such as "
                                  "'if' or 'global'): not a URScript program")
    if re.fullmatch(r"(?:global\s+|local\s+)?[A-Za-z_]\w*\s*=", text):
        raise lines.error(lineno, f"{text!r} assigns no value (a template whose values are "
                                  "filled in before it is sent?): not a URScript program")
    for number in _NUMBER_RE.finditer(re.sub(r'"[^"]*"', '""', text)):
        lines.number(number.group(), lineno)  # every number finite, wherever it is


def _check_blocks(lines: Lines, stmts: list[tuple[int, str]]) -> str:
    """The program's name, once every statement is one and every block is closed by ``end``:
    that of a first ``def NAME():`` without parameters that holds the file (nothing after its
    ``end`` but the call ``NAME()``), else the file's name (statements at the top of the file,
    a library of functions)."""
    if not stmts:
        raise InputError(f"{lines.path}: no URScript statement, only comments or blank lines: "
                         "not a URScript program")
    m = _DEF_RE.match(stmts[0][1])
    name = m.group(1) if m and not m.group(2).strip() else None
    depth = 0
    for k, (lineno, text) in enumerate(stmts):
        _check_statement(lines, lineno, text)
        if name and not depth and k and not re.fullmatch(rf"{name}\s*\(\s*\)", text):
            name = None  # a statement at the top of the file, outside the first def
        if text == "end":
            depth -= 1
            if depth < 0:
                raise lines.error(lineno, "'end' closes no block")
        elif re.match(r"^(?:" + "|".join(_BLOCKS) + r")\b", text):
            depth += 1
    name = name or Path(lines.path).name.split(".")[0]
    if depth:
        raise lines.error(len(lines.lines), f"{depth} block(s) not closed by 'end' (truncated "
                                            "file?)")
    return name


def _scoped(stmts: list[tuple[int, str]]) -> Iterator[tuple[int, str, frozenset[str]]]:
    """The statements with the parameters of the functions they are in (``def NAME(a, b=1):``
    .. ``end``): names that each call sets, which hide a global of the same name there."""
    stack: list[frozenset[str]] = []
    for lineno, text in stmts:
        yield lineno, text, frozenset().union(*stack)
        if text == "end" and stack:
            stack.pop()
        elif re.match(r"^(?:" + "|".join(_BLOCKS) + r")\b", text):
            m = _DEF_RE.match(text)
            params = split(m.group(2)) if m and m.group(2).strip() else []
            stack.append(frozenset(re.sub(r"\s*=.*", "", a, flags=re.DOTALL) for a in params))


def _expression(item: str) -> bool:
    """Whether an item of a list is a name or an expression (set at run time), not a number
    (``nan``, ``1e400`` and ``0.3x`` are numbers, refused when they are read)."""
    return (not _NUMERIC.match(item) or bool(_EXPRESSION.search(item))
            and not re.fullmatch(r"[-+]?(?:nan|inf)", item, re.IGNORECASE))


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
        #: The parameters of the function of the statement read: hidden globals.
        self.hidden: frozenset[str] = frozenset()
        once: dict[str, tuple[str, int]] = {}  # assigned once, composed of other values
        for lineno, text, params in _scoped(stmts):
            if (m := _ASSIGN_RE.match(text)) and not text.endswith(":"):
                name, value = m.group(1), self.literal(m.group(2), lineno)
                # assigned twice: a value set at run time
                if name not in self.values and not (
                        params and re.search(rf"\b(?:{'|'.join(params)})\b", m.group(2))):
                    once[name] = (m.group(2), lineno)
                else:  # or of the function's parameters: set by each call
                    once.pop(name, None)
                self.values[name] = None if name in self.values or name not in once else value
        self.compose({k: v for k, v in once.items() if self.values[k] is None})
        self.tool: Ref | None = FLANGE
        self.tool_line = 0
        self.points: list[ProgramPoint] = []
        self.skipped: list[str] = []

    # -- values ------------------------------------------------------------------------------
    def numbers(self, text: str, lineno: int) -> NDArray[np.float64] | None:
        """The numbers of a list ``[..]`` (None when an item is not a number: a name, an
        expression); a number that is not finite or mistyped is refused."""
        items = split(text.strip()[1:-1]) if text.strip() != "[]" else []
        if not items or any(_expression(i) for i in items):
            return None
        return np.array([self.lines.number(i, lineno) for i in items])

    def pose(self, text: str, lineno: int) -> NDArray[np.float64] | None:
        """The pose of a literal ``[x, y, z, rx, ry, rz]`` after its ``p`` (m, rad); None when
        an item is a name or an expression (a pose computed at run time)."""
        items = split(text.strip()[1:-1])
        if all(items) and any(_expression(i) for i in items):
            return None
        values = self.numbers(text, lineno)
        if values is None or values.shape != (6,):
            raise self.lines.error(lineno, f"a pose is p[x, y, z, rx, ry, rz], six numbers; "
                                           f"got {text.strip()[:60]!r}")
        return pose_from_vendor(values, "ur")

    def literal(self, text: str, lineno: int) -> _Value | None:
        t = text.strip()
        if re.match(r"^p\s*\[", t) and t.endswith("]") and _depth(t[t.index("["):]) == 0:
            pose = self.pose(t[t.index("["):], lineno)
            return None if pose is None else _Value(pose, None, None, lineno)
        if t.startswith("[") and t.endswith("]") and _depth(t) == 0:
            items = self.numbers(t, lineno)
            return None if items is None else _Value(None, items, None, lineno)
        if _NUMERIC.match(t) and re.fullmatch(r"[-+0-9.eE]+|[-+]?(nan|inf)", t, re.IGNORECASE):
            return _Value(None, None, self.lines.number(t, lineno), lineno)
        return None

    def composed(self, text: str, lineno: int) -> _Value | None:
        """``pose_trans(p_from, p_from_to)`` or ``pose_add(p_1, p_2)`` of two known poses, as
        the manual defines them: ``T_from @ T_from_to``; the positions added and the rotations
        multiplied (``p_3.P = p_1.P + p_2.P``, ``p_3.R = p_1.R * p_2.R``). None otherwise."""
        m = _CALL_RE.match(text.strip())
        if not m or m.group(1) not in ("pose_trans", "pose_add"):
            return None
        args = split(m.group(2))
        known = [self.known(a, lineno) for a in args] if len(args) == 2 else [None]
        if any(v is None or v.pose is None for v in known):
            return None
        A, B = (v.pose for v in known)  # type: ignore[union-attr]
        if m.group(1) == "pose_trans":
            return _Value(A @ B, None, None, lineno)
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = A[:3, :3] @ B[:3, :3], A[:3, 3] + B[:3, 3]
        return _Value(T, None, None, lineno)

    def compose(self, assigned: dict[str, tuple[str, int]]) -> None:
        """Give the variables assigned once a pose composed of known poses (:meth:`composed`)
        their value, each once the poses it is composed of are known."""
        while resolved := {name: v for name, (text, lineno) in assigned.items()
                           if (v := self.composed(text, lineno)) is not None}:
            self.values.update(resolved)
            assigned = {k: v for k, v in assigned.items() if k not in resolved}

    def known(self, text: str, lineno: int) -> _Value | None:
        """A literal written here, or a variable the file assigns once."""
        t = text.strip()
        if re.fullmatch(r"[A-Za-z_]\w*", t):
            return None if t in self.hidden else self.values.get(t)
        return self.literal(t, lineno) or self.composed(t, lineno)

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
        if t in self.hidden:
            return f"{t} is a parameter of the function, set by each call"
        if re.fullmatch(r"[A-Za-z_]\w*", t):
            return f"{t} is a variable set at run time or not given a value in this file"
        if re.match(r"^p\s*\[", t):
            return "a pose of values computed at run time"
        return "a target computed at run time"

    # -- statements --------------------------------------------------------------------------
    def statement(self, text: str, lineno: int) -> None:
        m = _CALL_RE.match(text)
        if not m:
            return
        func = m.group(1)
        if func == "set_tcp":
            # set_tcp(pose), PolyScope X: set_tcp(pose, "name"); the pose by position or name
            args = split(m.group(2))
            name = next((n.group(2) for a in args if (n := _NAMED_RE.match(a))
                         and n.group(1) == "pose"), args[0]).strip()
            value = self.known(name, lineno)
            if value is None or value.pose is None:
                self.tool, self.tool_line = None, lineno
            else:
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
        No statement, text that is no URScript statement, a block without ``end``, open
        brackets, a pose or joint list of numbers that are not six, a number that is not one;
        the message names the file and line.
    """
    lines = Lines(path, "URScript program")
    stmts = statements(lines)
    name = _check_blocks(lines, stmts)
    reader = _Reader(lines, stmts)
    for lineno, text, params in _scoped(stmts):
        reader.hidden = params
        reader.statement(text, lineno)
    return Program(name, "ur", reader.points, (str(path),)), reader.skipped
