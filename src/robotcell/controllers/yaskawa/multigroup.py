"""YASKAWA jobs of two robots and a station: one job ``NAME.jbi``, the robots in two groups.

Written (sources in ``docs/programs.md``, "Coordinated programs"), in the form of the jobs a
DX200 pendant saved for two robots and a 2-axis station (rpiRobotics/dx200_motion_progam_exec,
``example_inform/R1-R2-S1.JBI``):

- ``//POS``: ``///NPOS 2n,0,n,0,0,0``; the robots' ``C`` positions in one section, point ``k``
  of the first robot ``C{2k}``, of the second ``C{2k+1}``, each preceded by its robot's own
  ``///USER``, ``///TOOL`` and ``///RCONF`` lines (the pendant precedes each robot's position
  by its ``///TOOL``); Cartesian (``///POSTYPE USER|BASE``, ``///RECTAN``) as one robot's job
  (:mod:`.program`); the station's ``ECxxxxx`` in pulses after ``///POSTYPE PULSE``;
- ``//INST``: ``///GROUP1 RB1,ST1`` (the first robot with the station), ``///GROUP2 RB2``,
  and per point one line ``MOVJ C00000 EC00000 VJ=20.00  +MOVJ C00001 VJ=20.00``: group 1's
  robot and the station, then ``+`` group 2's robot.

:func:`group_problems` checks a job against these rules: the groups declared so, and every
motion line moving both robots (a ``+MOVx`` with group 2's position) and the station in
group 1.
"""

from __future__ import annotations

import re
import textwrap
from pathlib import Path

from robotcell.controllers.model import Program
from robotcell.controllers.text import Lines
from robotcell.controllers.yaskawa.program import (
    COMMENT_CHARS,
    ROBOT_POSITION,
    motion_parts,
    move_text,
    position_text,
    rconf_text,
    zone_text,
)
from robotcell.errors import InputError

__all__ = ["GROUPS", "ROBOTS", "check_robots", "group_problems", "write_job"]

#: The groups of a job of two robots, the first with the station (``///GROUP1``,
#: ``///GROUP2``), as a DX200 saves them; without a station ``RB1``.
GROUPS = ("RB1,ST1", "RB2")
#: Robots a job of several groups holds: the sources show two.
ROBOTS = 2
#: The partner motion's separator on a line: two spaces, as the pendant saves it.
_PLUS = "  +"


def check_robots(n: int, tracked: list[str]) -> None:
    """Refuse what no source shows in a job of several groups.

    Parameters
    ----------
    n : int
        Number of robots.
    tracked : list of str
        The robots on a track (a base axis).

    Raises
    ------
    InputError
        Not two robots, or a robot on a track.
    """
    if n != ROBOTS:
        raise InputError(f"a YASKAWA coordinated job holds two robots (///GROUP1 RB1,ST1 and "
                         f"///GROUP2 RB2, as a DX200 saves them); got {n}: no public job or "
                         "manual page robotcell cites shows the groups of three or more")
    if tracked:
        raise InputError(f"robot(s) {', '.join(tracked)} on a track: no public job or manual "
                         "page robotcell cites shows a base axis (BS1, BC positions) in a job "
                         "of two robots; write each robot's job alone")


def _positions(programs: list[Program]) -> list[str]:
    """The robots' ``C`` lines in turn, each after its robot's ``USER``/``TOOL``/``RCONF``."""
    out: list[str] = []
    postype = None
    for k in range(len(programs[0].points)):
        for r, program in enumerate(programs):
            p = program.points[k]
            user = p.frame.number
            kind = "USER" if user else "BASE"
            out += [f"///USER {user}"] if user else []
            out.append(f"///TOOL {p.tool.number or 0}")
            if kind != postype:
                out += [f"///POSTYPE {kind}", "///RECTAN"]
                postype = kind
            out += [f"///RCONF {rconf_text(p)}", f"C{2 * k + r:05d}={position_text(p)}"]
    return out


def _station(programs: list[Program]) -> list[str]:
    """The station's ``EC`` positions, one per point; the robots' values must agree."""
    first = programs[0].points[0]
    axes = sorted(k for k in first.external if k.startswith("EC"))
    if not axes:
        return []
    out = ["///POSTYPE PULSE", "///PULSE"]
    for k, points in enumerate(zip(*(p.points for p in programs))):
        values = [[round(p.external[a]) for a in axes] for p in points]
        if any(v != values[0] for v in values):
            raise InputError(f"point {k + 1}: the robots' programs hold the station at "
                             f"different values ({values}); a job has one station position "
                             "per line")
        out.append(f"EC{k:05d}=" + ",".join(str(v) for v in values[0]))
    return out


def write_job(programs: list[Program], header: list[str]) -> dict[str, str]:
    """The job of two robots' programs: point ``k`` of both on one line, with the station.

    Parameters
    ----------
    programs : list of Program
        The first robot's (group 1, with the station) and the second's (group 2), each of
        Cartesian points (``pose``, ``config``, ``external``: ``EC1``.. in pulses), one tool and
        one user frame; as many points, the same station values.
    header : list of str
        Comment lines (``'``, 32 characters each at most).

    Returns
    -------
    dict of str to str
        ``NAME.jbi`` -> text.

    Raises
    ------
    InputError
        Not two programs, a robot with a base axis, programs of different lengths, in
        different user frames, or with different station values.
    """
    check_robots(len(programs), [p.name for p in programs if "BC1" in p.points[0].external])
    if len({len(p.points) for p in programs}) > 1:
        raise InputError("the robots of a YASKAWA coordinated job move to as many points each")
    users = sorted({p.points[0].frame.number or 0 for p in programs})
    if len(users) > 1:
        raise InputError(f"the robots' paths are in user frames {users[0]} and {users[1]}: a "
                         "relative job has one ////FRAME USER; give the frame one number")
    n, name, user = len(programs[0].points), programs[0].name, users[0]
    station = _station(programs)
    pos = ["/JOB", f"//NAME {name}", "//POS",
           f"///NPOS {2 * n},0,{n if station else 0},0,0,0", *_positions(programs), *station]
    group1 = GROUPS[0] if station else GROUPS[0].split(",")[0]
    inst = ["//INST", "///DATE 2000/01/01 00:00", "///COMM robotcell", "///ATTR SC,RW,RJ",
            *([f"////FRAME USER {user}"] if user else []),
            f"///GROUP1 {group1}", f"///GROUP2 {GROUPS[1]}", "NOP"]
    inst += [f"'{part}" for h in header for part in textwrap.wrap(h, COMMENT_CHARS)]
    for k, (a, b) in enumerate(zip(*(p.points for p in programs))):
        axes = f"C{2 * k:05d}" + (f" EC{k:05d}" if station else "")
        inst.append(move_text(a, axes) + zone_text(a.zone or 0.0) + _PLUS
                    + move_text(b, f"C{2 * k + 1:05d}"))
    inst.append("END")
    return {f"{name}.jbi": "\n".join(pos + inst) + "\n"}


def _line_problems(parts: list[tuple[str, str]], lineno: int, station: bool) -> list[str]:
    """What breaks the rules of a job of two robots on one motion line."""
    (instr, rest), partners = parts[0], parts[1:]
    where = f"line {lineno}: {instr} {rest}"
    out = []
    robots = [(i, r) for i, r in partners if ROBOT_POSITION.search(r)]
    if not partners:
        out.append(f"{where}: no +MOVJ/+MOVL of group 2 (RB2) on the line; every motion of a "
                   "job of two robots moves both")
    elif not robots:
        out.append(f"{where}: its +{partners[0][0]} names no position of group 2's robot (a C "
                   "position or a position variable)")
    elif len(partners) > 1:
        out.append(f"{where}: {len(partners)} motions after '+'; a job of two robots has one, "
                   "group 2's")
    for i, r in partners:
        if re.search(r"\b(EC|EX)\d+", r, re.IGNORECASE):
            out.append(f"{where}: +{i} {r} moves the station in group 2; it is in group 1 "
                       f"(///GROUP1 {GROUPS[0]})")
    if station and not re.search(r"\b(EC|EX)\d+", rest, re.IGNORECASE):
        out.append(f"{where}: group 1 ({GROUPS[0]}) names no station position (EC): the "
                   "station's values at this point are not in the line")
    return out


def group_problems(path: str | Path) -> list[str]:
    """Where a job breaks the rules of a job of two robots and a station.

    The rules of the jobs a DX200 saved (``R1-R2-S1.JBI``): ``///GROUP1 RB1,ST1`` (or ``RB1``,
    without a station) and ``///GROUP2 RB2``; every motion line moves group 1's robot (with
    the station's ``EC`` position where group 1 holds ``ST1``) and, after ``+``, group 2's
    robot to a position of its own.

    Parameters
    ----------
    path : str or Path
        A ``.jbi`` job.

    Returns
    -------
    list of str
        Each problem with the job's line.

    Raises
    ------
    InputError
        A file that cannot be read.
    """
    lines = Lines(path, "YASKAWA job")
    groups: dict[int, str] = {}
    motions: list[tuple[int, list[tuple[str, str]]]] = []
    inst = False
    for lineno, raw in enumerate(lines.lines, start=1):
        text = raw.strip()
        if text.upper().startswith("//INST"):
            inst = True
        elif inst and (m := re.match(r"^///GROUP(\d+)\s+(\S+)", text, re.IGNORECASE)):
            groups[int(m.group(1))] = m.group(2).upper()
        elif inst and (parts := motion_parts(text)):
            motions.append((lineno, parts))
    out = []
    declared = [groups.get(1), groups.get(2)]
    if declared[0] not in (GROUPS[0], GROUPS[0].split(",")[0]) or declared[1] != GROUPS[1] \
            or set(groups) - {1, 2}:
        said = ", ".join(f"///GROUP{k} {v}" for k, v in sorted(groups.items())) or "no group"
        out.append(f"{path}: the job declares {said}; a job of two robots declares ///GROUP1 "
                   f"{GROUPS[0]} (the first robot with the station, RB1 without one) and "
                   f"///GROUP2 {GROUPS[1]}")
    station = declared[0] == GROUPS[0]
    for lineno, parts in motions:
        out += [f"{path}: {p}" for p in _line_problems(parts, lineno, station)]
    return out
