"""Programs after a recalibration: joint points moved so that the TCP stays where it was.

A Cartesian point follows a recalibrated tool or frame by itself: the controller computes its
joints from the new tool and frame data (``robotcell export``). A point stored as joint values
(KUKA ``E6AXIS``/``AXIS``, ABB ``jointtarget``, FANUC joint positions) does not: after the tool
or the base is recalibrated, or the arm identified, the same joints put the TCP elsewhere.
:func:`retarget_program` recomputes them: the TCP of each joint point in the old cell (with the
old cell's tool, track and table; for an arm identified since, where the old nominal model put
it) is solved in the new cell at the same track and table values, in the configuration nearest
to the old joints. Only the joint values in the files change; every other line is kept.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell
from robotcell.cell.kinematics import robot_pose
from robotcell.controllers.model import Program, ProgramPoint
from robotcell.controllers.registry import get
from robotcell.errors import InputError, RobotcellError
from robotcell.ik.select import nearest
from robotcell.io.fileio import read_text
from robotcell.kinematics.transforms import invert
from robotcell.programs.files import write_all
from robotcell.programs.formats import read_program
from robotcell.programs.frames import tool_pose_of

__all__ = ["RetargetFailed", "RetargetResult", "RetargetedPoint", "retarget_program"]


class RetargetFailed(RobotcellError):
    """Joint points the new cell cannot put where the old one had the TCP (nothing written)."""


@dataclass
class RetargetedPoint:
    """A joint point before and after.

    Attributes
    ----------
    name : str
    line : int
    q_old, q_new : ndarray, shape (6,)
        Joint values (rad).
    change : float
        Largest change of an axis (rad).
    tcp_error : float
        Distance between the TCP of the new joints in the new cell and the TCP of the old joints
        in the old cell (m): 0 up to rounding.
    """

    name: str
    line: int
    q_old: NDArray[np.float64]
    q_new: NDArray[np.float64]
    change: float
    tcp_error: float


@dataclass
class RetargetResult:
    """What :func:`retarget_program` did.

    Attributes
    ----------
    program : Program
        The program as read.
    points : list of RetargetedPoint
        The joint points, recomputed.
    cartesian : int
        Cartesian points, left as they are (they follow the exported tool and frame data).
    files : list of str
        The files written.
    """

    program: Program
    points: list[RetargetedPoint] = field(default_factory=list)
    cartesian: int = 0
    files: list[str] = field(default_factory=list)


def _solve(old: Cell, new: Cell, points: list[ProgramPoint], vendor: str,
           pulses_per_degree: ArrayLike | None) -> tuple[list[RetargetedPoint], list[str]]:
    ctl = get(vendor, "program format")
    axes_old = ctl.external_axes(old, pulses_per_degree)
    axes_new = ctl.external_axes(new, pulses_per_degree)
    out, problems = [], []
    for p in points:
        track, table, missing = axes_old.from_file(p.external)
        track_n, table_n, _ = axes_new.from_file(p.external)
        if missing:
            problems.append(f"{p.name} (line {p.line}): {'; '.join(missing)}")
            continue
        try:
            T_old = old.fk(p.joints, track, table, tool=tool_pose_of(old, vendor, p.tool))
            T_tool = tool_pose_of(new, vendor, p.tool)
        except InputError as exc:
            problems.append(f"{p.name} (line {p.line}): {exc}")
            continue
        T_R_F = invert(robot_pose(new, track_n)) @ T_old @ invert(T_tool)
        sol = new.robot.ik(T_R_F, tool=np.eye(4))
        q, found, _ = nearest(new.robot, sol, p.joints)
        if not found:
            why = "out of reach" if not sol.reachable.any() else "outside the axis limits"
            problems.append(f"{p.name} (line {p.line}): the new cell cannot put the TCP where "
                            f"the old one had it ({why})")
            continue
        T_new = new.fk(q, track_n, table_n, tool=T_tool)
        err = float(np.linalg.norm(T_new[:3, 3] - T_old[:3, 3]))
        out.append(RetargetedPoint(p.name, p.line, p.joints.copy(), q,
                                   float(np.max(np.abs(q - p.joints))), err))
    return out, problems


def _same_layout(old: Cell, new: Cell) -> None:
    """Refuse two cells that are not one cell before and after a recalibration."""
    def parts(cell: Cell) -> list[str]:
        tt = cell.turntable
        return [f"a {cell.robot.n_joints}-axis arm", "a track" if cell.track else "no track",
                "no turntable" if tt is None else
                ("a turntable" if np.ndim(tt.lower) == 0 else f"a {tt.n_axes}-axis positioner")]

    differ = [(a, b) for a, b in zip(parts(old), parts(new)) if a != b]
    if differ:
        what = "; ".join(f"the old cell has {a}, the new cell {b}" for a, b in differ)
        raise InputError(f"the old and the new cell are not one cell before and after a "
                         f"recalibration: {what}")


def retarget_program(path: str | Path, old: Cell, new: Cell, folder: str | Path,
                     pulses_per_degree: ArrayLike | None = None,
                     inputs: tuple[str | Path, ...] = ()) -> RetargetResult:
    """Recompute the joint points of a program for a recalibrated cell and write it to a folder.

    Parameters
    ----------
    path : str or Path
        The program (KUKA ``.src`` with its ``.dat``, ABB ``.mod``, FANUC ``.ls``).
    old, new : Cell
        The cell the program was taught in, and the cell after the recalibration (the same
        tools and frames by name and number; a new tool pose, base, track, table or an
        identified arm).
    folder : str or Path
        Where the program's files are written, under their names (all or none).
    pulses_per_degree : float or array_like, optional
        YASKAWA station axes (pulses per degree).
    inputs : tuple of str or Path
        Further files the run read (the cell files), which no output may replace.

    Returns
    -------
    RetargetResult

    Raises
    ------
    InputError
        An unreadable program, a program with no point, a folder that cannot be written, or
        cells that differ in their axes (arm, track, turntable or positioner).
    RetargetFailed
        A joint point the new cell cannot reach or that names a tool the cells lack; nothing is
        written.
    """
    _same_layout(old, new)
    program, _ = read_program(path)
    if not program.points:
        raise InputError(f"{path}: the program moves to no point robotcell reads: nothing to "
                         "retarget")
    vendor = program.vendor
    ctl = get(vendor, "program format")
    joint = [p for p in program.points if p.joints is not None]
    result = RetargetResult(program, cartesian=len(program.points) - len(joint))
    if joint and not ctl.edits_joints:
        raise InputError(f"{path}: {vendor} joint points are not retargeted")
    moved, problems = _solve(old, new, joint, vendor, pulses_per_degree)
    if problems:
        raise RetargetFailed("nothing written: " + "; ".join(problems))
    result.points = moved
    texts: dict[str, list[str]] = {f: read_text(f, "program file").splitlines()
                                   for f in program.files}
    for p, r in zip(joint, moved):
        file, _, line = p.where.rpartition(":")
        if not ctl.set_joints(texts[file], int(line) - 1, r.q_new):
            raise RetargetFailed(f"nothing written: {p.name}: cannot find its six axis values "
                                 f"on {file} line {line}")
    out = {Path(f).name: "\n".join(lines) + "\n" for f, lines in texts.items()}
    result.files = write_all(folder, out, (*program.files, *inputs))
    return result
