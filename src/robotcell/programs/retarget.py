"""Programs after a recalibration: joint points moved so that the TCP stays where it was.

A Cartesian point follows a recalibrated tool or frame by itself: the controller computes its
joints from the new tool and frame data (``robotcell export``). A point stored as joint values
(KUKA ``E6AXIS``/``AXIS``, ABB ``jointtarget``, FANUC joint positions) does not: after the tool
or the base is recalibrated, or the arm identified, the same joints put the TCP elsewhere.
:func:`retarget_program` recomputes them: the TCP of each joint point in the old cell (with the
old cell's tool, track and table; for an arm identified since, where the old nominal model put
it) is solved in the new cell at the same track and table values, in the point's configuration:
the same shoulder, elbow and wrist sides, each revolute axis on the turn nearest to its old value.
A point the new cell reaches only in another configuration, or whose configuration puts an axis
outside its limits, is refused and named (a retarget never changes a configuration silently);
joint values outside the model's limits in the program itself are named. All points are solved
in one batch. Only the joint values in the files change; every other line is kept.
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
from robotcell.ik.limits import TWO_PI
from robotcell.ik.result import IKSolutions
from robotcell.io.fileio import read_text
from robotcell.kinematics.transforms import invert
from robotcell.programs.config import config_values, side_changes
from robotcell.programs.files import write_all
from robotcell.programs.formats import read_program
from robotcell.programs.frames import tool_pose_of
from robotcell.programs.singular import outside_text
from robotcell.robot.robot import Robot

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
    notes : list of str
        Joint values outside the model's limits in the program itself, by point.
    """

    program: Program
    points: list[RetargetedPoint] = field(default_factory=list)
    cartesian: int = 0
    files: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def _resolve(old: Cell, new: Cell, points: list[ProgramPoint], vendor: str,
             pulses_per_degree: ArrayLike | None) -> tuple[list[int], dict[str, NDArray],
                                                           list[str]]:
    """The points that can be solved (indices into ``points``), their track values and tool
    poses in the old and the new cell (``track``, ``track_n``, ``tool``, ``tool_n``; the TCP in
    the world does not depend on the table), and the problems of the others."""
    ctl = get(vendor, "program format")
    axes_old = ctl.external_axes(old, pulses_per_degree)
    axes_new = ctl.external_axes(new, pulses_per_degree)
    tools: dict[tuple, tuple] = {}
    rows, problems = [], []
    cols: dict[str, list] = {k: [] for k in ("track", "track_n", "tool", "tool_n")}
    for k, p in enumerate(points):
        track, _, missing = axes_old.from_file(p.external)
        track_n, _, _ = axes_new.from_file(p.external)
        if missing:
            problems.append(f"{p.name} (line {p.line}): {'; '.join(missing)}")
            continue
        key = (p.tool.number, p.tool.name, None if p.tool.pose is None else id(p.tool.pose))
        if key not in tools:
            try:
                tools[key] = (tool_pose_of(old, vendor, p.tool), tool_pose_of(new, vendor, p.tool))
            except InputError as exc:
                tools[key] = (exc, exc)
        if isinstance(tools[key][0], InputError):
            problems.append(f"{p.name} (line {p.line}): {tools[key][0]}")
            continue
        rows.append(k)
        for name, v in zip(cols, (track, track_n, *tools[key])):
            cols[name].append(v)
    return rows, {k: np.asarray(v, dtype=float) for k, v in cols.items()}, problems


def _keep(robot: Robot, sol: IKSolutions, q_old: NDArray[np.float64]
          ) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64]]:
    """Of each point's branches, the one on the old joints' sides, each revolute axis on the
    turn nearest to its old value.

    Returns
    -------
    kept : ndarray, shape (N, 6)
        NaN where no reachable branch is on the old sides.
    has : ndarray of bool, shape (N,)
    near : ndarray, shape (N, 6)
        The reachable branch nearest to the old joints, whatever its sides (NaN where none).
    """
    rev = ~robot.prismatic
    cand = sol.q.copy()
    cand[..., rev] += TWO_PI * np.round((q_old[:, None, rev] - cand[..., rev]) / TWO_PI)
    dist = np.where(sol.reachable, np.sum((cand - q_old[:, None]) ** 2, axis=-1), np.inf)
    try:
        with np.errstate(invalid="ignore"):
            sides = config_values(robot, np.nan_to_num(cand), "abb")[..., 3]
        old_sides = config_values(robot, q_old, "abb")[:, 3]
        same = np.where(sides == old_sides[:, None], dist, np.inf)
    except InputError:  # no spherical wrist (a UR arm): no flags name its sides; the branch
        same = dist     # nearest to the old joints is theirs (a recalibration moves them little)
    rows = np.arange(len(q_old))
    kept = cand[rows, np.argmin(same, axis=-1)]
    has = np.isfinite(same).any(axis=-1)
    near = cand[rows, np.argmin(dist, axis=-1)]
    return (np.where(has[:, None], kept, np.nan), has,
            np.where(np.isfinite(dist).any(axis=-1)[:, None], near, np.nan))


def _solve(old: Cell, new: Cell, points: list[ProgramPoint], vendor: str,
           pulses_per_degree: ArrayLike | None
           ) -> tuple[list[RetargetedPoint], list[str], list[str]]:
    """The joint points solved in the new cell in their configurations, in one batch: the
    points, the problems (nothing may be written) and the notes."""
    rows, c, problems = _resolve(old, new, points, vendor, pulses_per_degree)
    notes = []
    q_old = np.array([points[k].joints for k in rows]).reshape(-1, new.robot.n_joints)
    for k, q in zip(rows, q_old):
        if not old.robot.within_limits(q):
            notes.append(f"{points[k].name} (line {points[k].line}): in the program "
                         f"{outside_text(old.robot, q)}")
    if not rows:
        return [], problems, notes
    T_old = robot_pose(old, c["track"]) @ old.robot.fk(q_old, tool=np.eye(4)) @ c["tool"]
    T_R_F = invert(robot_pose(new, c["track_n"])) @ T_old @ invert(c["tool_n"])
    sol = new.robot.ik(T_R_F, tool=np.eye(4))
    kept, has, near = _keep(new.robot, sol, q_old)
    inside = new.robot._inside(kept)
    T_new = (robot_pose(new, c["track_n"]) @ new.robot.fk(np.nan_to_num(kept), tool=np.eye(4))
             @ c["tool_n"])
    err = np.linalg.norm(T_new[:, :3, 3] - T_old[:, :3, 3], axis=-1)
    out = []
    for j, k in enumerate(rows):
        p = points[k]
        where = f"{p.name} (line {p.line}): "
        if not sol.reachable[j].any():
            problems.append(where + "the new cell cannot put the TCP where the old one had it "
                                    "(out of reach)")
        elif not has[j]:
            problems.append(where + "the new cell reaches the TCP only in another configuration "
                                    f"({side_changes(new.robot, q_old[j], near[j])}): "
                                    "retargeting would change it")
        elif not inside[j]:
            was = " (outside them in the program already)" if not old.robot.within_limits(
                q_old[j]) else ""
            problems.append(where + "the new cell keeps the point's configuration only with "
                            + outside_text(new.robot, kept[j]).replace(" is at ", " at ") + was)
        else:
            out.append(RetargetedPoint(p.name, p.line, q_old[j].copy(), kept[j],
                                       float(np.max(np.abs(kept[j] - q_old[j]))), float(err[j])))
    return out, problems, notes


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
        A joint point the new cell cannot reach in its configuration (out of reach, only on
        other sides of the shoulder, elbow or wrist, or with an axis outside its limits), or
        that names a tool the cells lack; nothing is written. The message names each, and the
        joint values outside the model's limits in the program.
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
    moved, problems, notes = _solve(old, new, joint, vendor, pulses_per_degree)
    if problems:
        raise RetargetFailed("nothing written: " + "; ".join(problems + notes))
    result.points, result.notes = moved, notes
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
