"""Checking a program against a cell: every point through the cell's kinematics.

For each point :func:`check_program` finds the arm's joint values the controller would use and
says what is wrong with it:

- **reach**: a Cartesian point the arm cannot reach (by how many mm), a tool or frame the cell
  lacks, an external axis the program does not write;
- **limits**: an axis, the track or the table outside its limits;
- **configuration**: the flags as written (KUKA S/T, ABB confdata, FANUC CONFIG, YASKAWA RCONF)
  select no solution, or one outside the limits. A point without flags takes the solution
  nearest to the previous point's (the first point: nearest to the robot's home), as a
  controller keeps the configuration on a linear motion;
- **singularity**: axis 5 within ``singular_margin`` of the wrist singularity, the arm within it
  of stretched or folded, or the wrist centre within ``shoulder_margin`` of axis 1;
- **jumps**: on a linear motion from the previous point, a change of the arm's configuration or
  an axis turning by more than ``max_step`` (a straight line cannot pass a flip). Joint motions
  may move the axes as far as they like.

A point is good when it has no problem; the program is good when every point is.

In a cell with an identified arm the controller still computes with its nominal model: a
Cartesian point's joints are the nominal arm's solution in the configuration written
(:meth:`~robotcell.cell.model.Cell.controller`), and its TCP is where the identified arm takes those
joints, so a filtered program is checked where it really goes (docs/accuracy.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell
from robotcell.cell.ik import MAX_STEP
from robotcell.cell.kinematics import robot_pose
from robotcell.controllers.axes import ExternalAxes
from robotcell.controllers.model import Config, Program, ProgramPoint
from robotcell.controllers.registry import get
from robotcell.errors import InputError
from robotcell.ik.analytic import analytic_solver
from robotcell.ik.select import nearest
from robotcell.io.poseformats import pose_to_vendor
from robotcell.kinematics.transforms import invert
from robotcell.programs.config import candidates, config_text, config_values, select
from robotcell.programs.formats import read_program
from robotcell.programs.frames import Placement, placement, tool_pose_of
from robotcell.programs.path import table_columns
from robotcell.robot.robot import Robot

__all__ = ["CheckReport", "CheckedPoint", "check_program", "check_program_file"]

#: Closest approach to the wrist or elbow singularity that still counts as good (rad).
SINGULAR_MARGIN = math.radians(2.0)
#: Closest approach of the wrist centre to axis 1 that still counts as good (m).
SHOULDER_MARGIN = 0.02


@dataclass
class CheckedPoint:
    """One point of a program as the cell sees it.

    Attributes
    ----------
    name : str
        As the program names it.
    line : int
        Line of its motion instruction.
    motion : str
    q : ndarray, shape (6,)
        Arm joints the controller uses (rad; NaN when none).
    track : float
        Track value (m).
    table : float or ndarray, shape (n,)
        Table values (rad).
    T_world_TCP : ndarray, shape (4, 4)
        TCP pose in the cell's world (m; NaN when the point cannot be placed).
    problems : list of str
        What is wrong, in words (empty: the point is good).
    wrist, elbow : float
        Angular distance to the wrist and the elbow singularities (rad; NaN when unknown).
    shoulder : float
        Distance of the wrist centre from axis 1 (m; NaN when unknown).
    """

    name: str
    line: int
    motion: str
    q: NDArray[np.float64]
    track: float
    table: float | NDArray[np.float64]
    T_world_TCP: NDArray[np.float64]
    problems: list[str] = field(default_factory=list)
    wrist: float = math.nan
    elbow: float = math.nan
    shoulder: float = math.nan


@dataclass
class CheckReport:
    """The result of :func:`check_program`.

    Attributes
    ----------
    program : Program
    points : list of CheckedPoint
    skipped : list of str
        Motions the reader did not turn into points (not checked).
    """

    program: Program
    points: list[CheckedPoint]
    skipped: list[str] = field(default_factory=list)

    @property
    def bad(self) -> list[CheckedPoint]:
        """The points with a problem."""
        return [p for p in self.points if p.problems]

    @property
    def good(self) -> bool:
        """Every point is good."""
        return not self.bad

    def rows(self) -> list[list[str]]:
        """``[point, line, problem]`` for each problem of each bad point."""
        return [[p.name, str(p.line), why] for p in self.bad for why in p.problems]

    def to_json(self, cell: Cell) -> dict:
        """The report as JSON-ready data (mm, deg)."""
        pts = []
        tcols = table_columns(cell)
        for p in self.points:
            d = {"name": p.name, "line": p.line, "motion": p.motion}
            d.update({f"a{i + 1}": _num(math.degrees(v)) for i, v in enumerate(p.q)})
            if cell.track is not None:
                d["track"] = _num(p.track * 1e3)
            d.update({k: _num(math.degrees(v)) for k, v in zip(tcols, np.atleast_1d(p.table))})
            xyzabc = pose_to_vendor(np.nan_to_num(p.T_world_TCP), "kuka")
            ok = bool(np.all(np.isfinite(p.T_world_TCP)))
            d["world"] = {k: _num(v) if ok else None for k, v in zip("xyzabc", xyzabc)}
            d["wrist_deg"] = _num(math.degrees(p.wrist))
            d["elbow_deg"] = _num(math.degrees(p.elbow))
            d["shoulder_mm"] = _num(p.shoulder * 1e3)
            d["problems"] = p.problems
            pts.append(d)
        return {"program": self.program.name, "format": self.program.vendor,
                "files": list(self.program.files), "points": pts, "bad": len(self.bad),
                "skipped": self.skipped}


def _num(v: float) -> float | None:
    return None if not math.isfinite(v) else round(float(v), 9)


def singular_distances(robot: Robot, q: ArrayLike
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Distances of configurations to the singularities of an ortho-parallel arm.

    Parameters
    ----------
    robot : Robot
    q : array_like, shape (..., 6)
        Controller axis values (rad).

    Returns
    -------
    wrist : ndarray, shape (...)
        Angle of axis 5 from its singular values (rad): the wrist singularity.
    elbow : ndarray, shape (...)
        Angle of the forearm from the line through axes 2 and 3 (rad): the arm stretched or
        folded.
    shoulder : ndarray, shape (...)
        Distance of the wrist centre from the line of axis 1 (m).
        All NaN for an arm that is not ortho-parallel.
    """
    arr = np.asarray(q, dtype=float)
    solver = analytic_solver(robot)
    if solver.method != "opw":
        nan = np.full(arr.shape[:-1], np.nan)
        return nan, nan, nan
    p = solver.params
    model = robot.coupling.to_model(arr) if robot.coupling is not None else arr
    th = model * p.signs + p.offsets
    t2, t3 = th[..., 1], th[..., 2]
    t23 = t2 + t3

    def off_pi(t: NDArray) -> NDArray:
        return np.abs(np.mod(t + math.pi / 2, math.pi) - math.pi / 2)

    wx = p.a1 + p.c2 * np.sin(t2) + p.a2 * np.cos(t23) + p.c3 * np.sin(t23)
    return off_pi(th[..., 4]), off_pi(t3 + math.atan2(p.a2, p.c3)), np.hypot(wx, p.b)


@dataclass
class _Resolved:
    """What the cell makes of a point before its joints are known."""

    T_F_TCP: NDArray[np.float64] | None
    where: Placement | None
    track: float
    table: float | NDArray[np.float64]
    problems: list[str]


def _resolve(cell: Cell, point: ProgramPoint, axes: ExternalAxes) -> _Resolved:
    problems: list[str] = []
    T_tool = where = None
    try:
        T_tool = tool_pose_of(cell, axes.vendor, point.tool)
    except InputError as exc:
        problems.append(str(exc))
    if point.pose is not None:
        try:
            where = placement(cell, axes.vendor, point.frame)
        except InputError as exc:
            problems.append(str(exc))
    track, table, missing = axes.from_file(point.external)
    problems += missing
    if cell.track is not None and not cell.track.within_limits(track):
        problems.append(f"track {track * 1e3:g} mm is outside its limits "
                        f"[{cell.track.lower * 1e3:g}, {cell.track.upper * 1e3:g}] mm")
    tt = cell.turntable
    if tt is not None and not np.all(tt.within_limits(table)):
        problems.append(f"table {np.round(np.degrees(table), 4)} deg is outside its limits "
                        f"[{np.degrees(tt.lower)}, {np.degrees(tt.upper)}] deg")
    return _Resolved(T_tool, where, track, table, problems)


def _outside(robot: Robot, q: NDArray[np.float64]) -> str:
    """Words for the first axis of ``q`` outside its limits."""
    bad = (q < robot.lower) | (q > robot.upper)
    if not np.any(bad):
        return "the axes' interaction limits are exceeded"
    j = int(np.argmax(bad))
    return (f"axis {j + 1} is at {math.degrees(q[j]):.1f} deg, outside its limits "
            f"[{math.degrees(robot.lower[j]):g}, {math.degrees(robot.upper[j]):g}] deg")


def check_program(program: Program, cell: Cell, pulses_per_degree: ArrayLike | None = None,
                  max_step: float = MAX_STEP, singular_margin: float = SINGULAR_MARGIN,
                  shoulder_margin: float = SHOULDER_MARGIN,
                  skipped: list[str] | None = None) -> CheckReport:
    """Check every point of a program against a cell.

    Parameters
    ----------
    program : Program
    cell : Cell
        The cell the program runs in (a six-axis ortho-parallel arm).
    pulses_per_degree : float or array_like, optional
        YASKAWA: encoder pulses per degree of each station axis.
    max_step : float
        Largest axis change on a linear motion between two points (rad).
    singular_margin : float
        Closest good approach to the wrist or elbow singularity (rad).
    shoulder_margin : float
        Closest good distance of the wrist centre from axis 1 (m).
    skipped : list of str, optional
        Motions the reader skipped, carried into the report.

    Returns
    -------
    CheckReport

    Raises
    ------
    InputError
        A YASKAWA program for a cell with station axes and no ``pulses_per_degree``.
    """
    ctrl = cell.controller()
    robot = ctrl.robot
    axes = get(program.vendor, "program format").external_axes(cell, pulses_per_degree)
    pts = program.points
    n = len(pts)
    res = [_resolve(cell, p, axes) for p in pts]
    q = np.full((n, robot.n_joints), np.nan)
    T_world = np.full((n, 4, 4), np.nan)
    problems = [list(r.problems) for r in res]
    cart = [i for i, (p, r) in enumerate(zip(pts, res))
            if p.pose is not None and r.where is not None and r.T_F_TCP is not None]
    if cart:
        _solve_cartesian(ctrl, pts, res, cart, q, T_world, problems)
    for i, (p, r) in enumerate(zip(pts, res)):
        if p.joints is not None:
            q[i] = p.joints
            if not robot.within_limits(p.joints):
                problems[i].append(_outside(robot, p.joints))
            if r.T_F_TCP is not None:
                T_world[i] = cell.fk(p.joints, r.track, r.table, tool=r.T_F_TCP)
    _sequential(ctrl, pts, res, q, T_world, problems)
    if cell.identified is not None:  # where the real arm takes the controller's joints
        for i in cart:
            if np.isfinite(q[i]).all():
                T_world[i] = cell.fk(q[i], res[i].track, res[i].table, tool=res[i].T_F_TCP)
    wrist, elbow, shoulder = singular_distances(robot, np.nan_to_num(q))
    for i in range(n):
        if np.isnan(q[i]).any():
            continue
        if wrist[i] < singular_margin:
            problems[i].append(f"axis 5 is {math.degrees(wrist[i]):.2f} deg from the wrist "
                               f"singularity (margin {math.degrees(singular_margin):g} deg)")
        if elbow[i] < singular_margin:
            problems[i].append(f"the arm is {math.degrees(elbow[i]):.2f} deg from stretched or "
                               f"folded (elbow singularity, margin "
                               f"{math.degrees(singular_margin):g} deg)")
        if shoulder[i] < shoulder_margin:
            problems[i].append(f"the wrist centre is {shoulder[i] * 1e3:.1f} mm from axis 1 "
                               f"(shoulder singularity, margin {shoulder_margin * 1e3:g} mm)")
    _jumps(robot, pts, q, max_step, problems)
    checked = [CheckedPoint(p.name, p.line, p.motion, q[i], r.track, r.table, T_world[i],
                            problems[i],
                            float(wrist[i]) if np.isfinite(q[i]).all() else math.nan,
                            float(elbow[i]) if np.isfinite(q[i]).all() else math.nan,
                            float(shoulder[i]) if np.isfinite(q[i]).all() else math.nan)
               for i, (p, r) in enumerate(zip(pts, res))]
    return CheckReport(program, checked, list(skipped or []))


def _solve_cartesian(cell: Cell, pts: list[ProgramPoint], res: list[_Resolved], idx: list[int],
                     q: NDArray, T_world: NDArray, problems: list[list[str]]) -> None:
    """IK of the Cartesian points ``idx``; those with flags get their solution here."""
    robot = cell.robot
    for i in idx:
        r = res[i]
        T_world[i] = r.where.world(cell, r.track, r.table) @ pts[i].pose
    e = np.array([res[i].track for i in idx])
    T_R_F = (invert(robot_pose(cell, e)) @ T_world[idx]
             @ invert(np.stack([res[i].T_F_TCP for i in idx])))
    sol = robot.ik(T_R_F, tool=np.eye(4))
    store = {i: k for k, i in enumerate(idx)}
    flagged = [i for i in idx if pts[i].config is not None]
    for i in idx:
        k = store[i]
        if not sol.reachable[k].any():
            err = (np.nanmin(sol.reach_error[k]) * 1e3 if sol.reach_error is not None
                   else math.nan)
            problems[i].append("out of reach" + (f" by {err:.1f} mm" if math.isfinite(err)
                                                 else ""))
    if not flagged:
        return
    ks = [store[i] for i in flagged]
    wanted = np.array([pts[i].config.values for i in flagged])
    vendor = pts[flagged[0]].config.vendor
    got, found, exists = select(robot, sol.q[ks], sol.reachable[ks], wanted, vendor)
    for j, i in enumerate(flagged):
        if not sol.reachable[store[i]].any():
            continue
        if found[j]:
            q[i] = got[j]
            continue
        text = config_text(pts[i].config)
        if exists[j]:
            problems[i].append(f"with the configuration as written ({text}) "
                               + _outside_any(cell, sol.q[store[i]], pts[i].config))
        else:
            reached = sorted({config_text(Config(vendor, tuple(int(x) for x in row)))
                              for row in config_values(robot, sol.q[store[i]][
                                  sol.reachable[store[i]]], vendor)})
            problems[i].append(f"no solution has the configuration as written ({text}); it is "
                               f"reached as {', '.join(reached)}")


def _outside_any(cell: Cell, branches: NDArray, config: Config) -> str:
    """Why the solutions with ``config`` leave the limits, for the first of them."""
    robot = cell.robot
    cand = candidates(robot, branches[None])[0]
    flags = config_values(robot, np.nan_to_num(cand), config.vendor)
    match = np.all(flags == np.array(config.values), axis=-1) & np.isfinite(cand).all(axis=-1)
    return _outside(robot, cand[int(np.argmax(match))])


def _sequential(cell: Cell, pts: list[ProgramPoint], res: list[_Resolved], q: NDArray,
                T_world: NDArray, problems: list[list[str]]) -> None:
    """Cartesian points without flags: the solution nearest to the previous point's."""
    robot = cell.robot
    ref = robot.home if robot.home is not None else np.zeros(robot.n_joints)
    for i, p in enumerate(pts):
        if p.pose is not None and p.config is None and np.isfinite(T_world[i]).all() \
                and not any(w.startswith("out of reach") for w in problems[i]):
            r = res[i]
            T_R_F = invert(robot_pose(cell, r.track)) @ T_world[i] @ invert(r.T_F_TCP)
            sol = robot.ik(T_R_F, tool=np.eye(4))
            got, found, _ = nearest(robot, sol, ref)
            if found:
                q[i] = got
            else:
                problems[i].append("no solution within the axis limits")
        if np.isfinite(q[i]).all():
            ref = q[i]


def _jumps(robot: Robot, pts: list[ProgramPoint], q: NDArray, max_step: float,
           problems: list[list[str]]) -> None:
    """Linear motions that change the configuration or turn an axis by more than max_step."""
    sides = np.full(len(pts), -1)
    ok = np.isfinite(q).all(axis=-1)
    if ok.any():
        sides[ok] = config_values(robot, q[ok], "abb")[:, 3]  # cfx: shoulder, elbow, wrist
    for i in range(1, len(pts)):
        if pts[i].motion != "lin" or not (ok[i] and ok[i - 1]):
            continue
        prev = pts[i - 1].name
        if sides[i] != sides[i - 1]:
            problems[i].append(f"the linear motion from {prev} changes the arm's configuration "
                               "(shoulder, elbow or wrist side): a straight line cannot")
        step = np.abs(q[i] - q[i - 1])
        j = int(np.argmax(step))
        if step[j] > max_step:
            problems[i].append(f"on the linear motion from {prev} axis {j + 1} turns by "
                               f"{math.degrees(step[j]):.1f} deg (more than "
                               f"{math.degrees(max_step):g})")


def check_program_file(path: str | Path, cell: Cell, pulses_per_degree: ArrayLike | None = None,
                       max_step: float = MAX_STEP, singular_margin: float = SINGULAR_MARGIN,
                       shoulder_margin: float = SHOULDER_MARGIN) -> CheckReport:
    """Read a program file (any format, by extension) and check it against a cell.

    Parameters
    ----------
    path : str or Path
        KUKA ``.src`` (with its ``.dat``), ABB ``.mod``, FANUC ``.ls``, YASKAWA ``.jbi``.
    cell, pulses_per_degree, max_step, singular_margin, shoulder_margin
        As for :func:`check_program`.

    Returns
    -------
    CheckReport
        A program none of whose motions can be checked (each depends on data the files do not
        hold, or it has no motion) gives a report with no point and the reasons in
        ``skipped``.

    Raises
    ------
    InputError
        A file that cannot be read (the message names the file and line).
    """
    program, skipped = read_program(path)
    if not program.points:  # a valid program whose motions all depend on data it lacks
        return CheckReport(program, [], list(skipped) or ["the program moves to no point"])
    return check_program(program, cell, pulses_per_degree, max_step, singular_margin,
                         shoulder_margin, skipped)
