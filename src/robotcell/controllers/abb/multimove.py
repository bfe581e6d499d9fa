"""ABB MultiMove: coordinated programs of several robots, one RAPID module per motion task.

Written (sources in ``docs/programs.md``, "Coordinated programs"):

- one module per task, ``NAME_T_ROB1.mod`` .. (``MODULE NAME_T_ROB1``), the tasks named
  ``T_ROB1``, ``T_ROB2``, .. in the order of the robots, as in the MultiMove application manual
  (3HAC021272-001) and the modules COMPAS RRC's offline tool saved on a controller
  (ebruun/ECL_robotic_cell, ``HOME/1/1_T_ROB1.mod``);
- in each: ``VAR syncident sync1;``, ``VAR syncident sync2;``, ``TASK PERS tasks
  all_tasks{n} := [["T_ROB1"],["T_ROB2"]];``, the task's tool and work object (``LOCAL PERS``,
  a work object on the positioner coordinated with its mechanical unit: ``robhold`` FALSE,
  ``ufprog`` FALSE, ``ufmec`` the unit's name), the targets, and ``PROC NAME()`` with
  ``SyncMoveOn sync1, all_tasks;``, every move with ``\\ID:=10``, ``20``, .. (the same number
  in every task for the moves that run together), ``SyncMoveOff sync2;``.

The manual's rules (3HAC021272-001, "Synchronized movements"): every move between
``SyncMoveOn`` and ``SyncMoveOff`` has ``\\ID``, the same for the moves that execute together
in every task; the tasks execute as many moves between the two; a move outside has no
``\\ID``. :func:`sync_moves` reads them from a module and :func:`id_problems` checks them.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from robotcell.controllers.abb.program import declarations, robtarget_text, speed_text, zone_text
from robotcell.controllers.abb.reader import MOVE_INSTRUCTIONS, arguments, statements
from robotcell.controllers.model import Program
from robotcell.controllers.text import Lines
from robotcell.errors import InputError

__all__ = ["ID_STEP", "SyncMove", "id_problems", "sync_moves", "task_names", "write_tasks"]

#: The ``\\ID`` of the k-th synchronised move is ``ID_STEP * k`` (10, 20, ..).
ID_STEP = 10
#: A RAPID name holds 32 characters.
RAPID_NAME = 32


def task_names(n: int) -> list[str]:
    """The motion tasks of ``n`` robots: ``T_ROB1`` .. ``T_ROBn``."""
    return [f"T_ROB{k + 1}" for k in range(n)]


def write_tasks(programs: list[Program], header: list[str]) -> dict[str, str]:
    """The modules of a MultiMove program, one per task, every move synchronised.

    Parameters
    ----------
    programs : list of Program
        One per robot in task order, each of Cartesian points (``pose``, ``config``,
        ``external``), one tool and one work object, with the cell's data (``data``) to
        declare them; all of one name and as many points.
    header : list of str
        Comment lines (without ``!``).

    Returns
    -------
    dict of str to str
        File name (``NAME_T_ROB1.mod``) -> text.

    Raises
    ------
    InputError
        Programs of different lengths, or a name too long for a RAPID module name.
    """
    tasks = task_names(len(programs))
    if len({len(p.points) for p in programs}) > 1:
        raise InputError("the tasks of a MultiMove program must move to as many points each")
    name = programs[0].name
    if len(f"{name}_{tasks[-1]}") > RAPID_NAME:
        raise InputError(f"program name {name!r} is too long for a MultiMove module "
                         f"({name}_{tasks[-1]} has more than {RAPID_NAME} characters)")
    listed = ",".join(f'["{t}"]' for t in tasks)
    out = {}
    for task, program in zip(tasks, programs):
        first = program.points[0]
        tool, wobj = first.tool.name, first.frame.name or "wobj0"
        L = [f"MODULE {name}_{task}", *(f"    ! {h}" for h in header),
             (f"    ! task {task} of {len(tasks)}: every move synchronised with the other tasks "
             "by its \\ID"),
             "    VAR syncident sync1;", "    VAR syncident sync2;",
             f"    TASK PERS tasks all_tasks{{{len(tasks)}}} := [{listed}];",
             *declarations(program, tool, wobj),
             ("    ! robtarget: x, y, z (mm) and quaternion [q1,q2,q3,q4] of the TCP in the work "
              "object, confdata [cf1,cf4,cf6,cfx], extax (track mm, positioner deg; 9E9: no "
              "axis)")]
        L += [f"    CONST robtarget {p.name}:={robtarget_text(p)};" for p in program.points]
        L += ["", f"    PROC {name}()", "        ConfJ \\On;", "        ConfL \\On;",
              "        SyncMoveOn sync1, all_tasks;"]
        for k, p in enumerate(program.points, start=1):
            move = "MoveJ" if p.motion == "ptp" else "MoveL"
            L.append(f"        {move} {p.name}\\ID:={ID_STEP * k},{speed_text(p.speed or 0.1)},"
                     f"{zone_text(p.zone or 0.0)},{tool}\\WObj:={wobj};")
        L += ["        SyncMoveOff sync2;", "    ENDPROC", "ENDMODULE"]
        out[f"{name}_{task}.mod"] = "\n".join(L) + "\n"
    return out


@dataclass(frozen=True)
class SyncMove:
    """A move instruction of a task as MultiMove sees it.

    Attributes
    ----------
    line : int
        Its line in the module.
    instr : str
        The instruction (``MoveL``).
    ident : str or None
        Its ``\\ID`` argument as written (None: none).
    synced : bool
        It lies between ``SyncMoveOn`` and ``SyncMoveOff``.
    """

    line: int
    instr: str
    ident: str | None
    synced: bool


def sync_moves(path: str | Path) -> list[SyncMove]:
    """The move instructions of a RAPID module in order, with their ``\\ID`` and whether they
    run synchronised (between ``SyncMoveOn`` and ``SyncMoveOff``).

    Raises
    ------
    InputError
        A module that cannot be read (the message names the file and line).
    """
    lines = Lines(path, "RAPID module")
    moves, synced = [], False
    for lineno, text in statements(lines):
        m = re.match(r"^(\w+)\b\s*(.*)$", text, re.DOTALL)
        if not m:
            continue
        key = m.group(1).lower()
        if key == "syncmoveon":
            synced = True
        elif key == "syncmoveoff":
            synced = False
        elif key in MOVE_INSTRUCTIONS:
            _, optional = arguments(m.group(2))
            moves.append(SyncMove(lineno, m.group(1), optional.get("id"), synced))
    return moves


def id_problems(tasks: dict[str, list[SyncMove]]) -> list[str]:
    """Where the moves of several tasks break MultiMove's rules for ``\\ID``.

    Parameters
    ----------
    tasks : dict of str to list of SyncMove
        Each task's (file's) moves, :func:`sync_moves`.

    Returns
    -------
    list of str
        Each problem with its file and line: a synchronised move without ``\\ID``, a move with
        ``\\ID`` outside ``SyncMoveOn`` .. ``SyncMoveOff``, an ``\\ID`` used twice in a task,
        an ``\\ID`` without a partner in another task, tasks of different numbers of
        synchronised moves or with their ``\\ID`` in another order.
    """
    out: list[str] = []
    ids: dict[str, list[str]] = {}
    for task, moves in tasks.items():
        ids[task] = []
        for m in moves:
            if m.synced and m.ident is None:
                out.append(f"{task}: line {m.line}: {m.instr} between SyncMoveOn and "
                           "SyncMoveOff has no \\ID")
            elif not m.synced and m.ident is not None:
                out.append(f"{task}: line {m.line}: {m.instr} outside SyncMoveOn .. SyncMoveOff "
                           f"has \\ID:={m.ident}")
            elif m.synced:
                if m.ident in ids[task]:
                    out.append(f"{task}: line {m.line}: \\ID:={m.ident} is used twice")
                ids[task].append(m.ident)
    counts = {task: len(v) for task, v in ids.items()}
    if len(set(counts.values())) > 1:
        out.append("the tasks execute different numbers of synchronised moves: "
                   + ", ".join(f"{t} {n}" for t, n in counts.items()))
    for task, mine in ids.items():
        for other, theirs in ids.items():
            if other == task:
                continue
            for k, ident in enumerate(mine):
                if ident not in theirs:
                    out.append(f"{task}: \\ID:={ident} has no partner in {other}")
                elif k < len(theirs) and theirs[k] != ident:
                    out.append(f"{task}: \\ID:={ident} is move {k + 1} here and move "
                               f"{theirs.index(ident) + 1} in {other}")
    return out
