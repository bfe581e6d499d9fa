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
- **linear motions**: the straight line from the previous point followed as the controller
  follows it (:mod:`robotcell.programs.lines`): a change of the arm's configuration, a whole
  turn of an axis against the configuration written, a singularity passed on the way, reach or
  limits left on the way. Joint motions may move the axes as far as they like.

A point is good when it has no problem; the program is good when every point is.

In a cell with an identified arm the controller still computes with its nominal model: a
Cartesian point's joints are the nominal arm's solution in the configuration written
(:meth:`~robotcell.cell.model.Cell.controller`), and its TCP is where the identified arm takes those
joints, so a filtered program is checked where it really goes (docs/accuracy.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell
from robotcell.cell.kinematics import robot_pose
from robotcell.cell.validation import table_columns
from robotcell.clearance.bodies import BodiesFile
from robotcell.controllers.axes import ExternalAxes
from robotcell.controllers.model import Config, Program, ProgramPoint, Ref
from robotcell.controllers.registry import get
from robotcell.errors import InputError
from robotcell.ik.result import IKSolutions
from robotcell.ik.select import nearest
from robotcell.io.poseformats import pose_to_vendor
from robotcell.kinematics.transforms import invert
from robotcell.programs.clearcheck import CLEARANCE, clearance_problems
from robotcell.programs.config import candidates, config_text, config_values, select
from robotcell.programs.formats import read_program
from robotcell.programs.frames import Placement, placement, tool_pose_of
from robotcell.programs.lines import LineData, line_problems
from robotcell.programs.singular import (
    SHOULDER_MARGIN,
    SINGULAR_MARGIN,
    outside_text,
    singular_distances,
)
from robotcell.robot.robot import Robot

__all__ = ["CLEARANCE", "SHOULDER_MARGIN", "SINGULAR_MARGIN", "CheckReport", "CheckedPoint", "check_program",
           "check_program_file", "singular_distances"]

#: Rounds of choosing the solutions of points without flags all at once (:func:`_sequential`)
#: before the rest are chosen one by one.
SEQUENTIAL_ROUNDS = 20
#: The frame of a linear motion to a joint point: the world.
_WORLD = Placement("fixed", np.eye(4), "world")


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



@dataclass
class _Resolved:
    """What the cell makes of the points before their joints are known, one row per point.

    Attributes
    ----------
    tools : ndarray, shape (N, 4, 4)
        ``T_F_TCP`` (m; NaN where the cell has no such tool).
    frames : list of Placement or None
        The frame of each Cartesian point (None: a joint point, or a frame the cell lacks).
    track : ndarray, shape (N,)
        Track values (m).
    table : ndarray, shape (N,) or (N, n)
        Table values (rad).
    problems : list of list of str
    """

    tools: NDArray[np.float64]
    frames: list[Placement | None]
    track: NDArray[np.float64]
    table: NDArray[np.float64]
    problems: list[list[str]]


def _key(ref: Ref) -> tuple:
    """A tool or frame reference as a dictionary key (its pose by identity)."""
    return (ref.number, ref.name, ref.on_table, ref.kind,
            None if ref.pose is None else id(ref.pose))


def _resolve(cell: Cell, pts: list[ProgramPoint], axes: ExternalAxes) -> _Resolved:
    """Tool, frame and external axes of every point (each reference looked up once), and the
    track and table limits."""
    track, table, problems = axes.from_files([p.external for p in pts])
    tools: dict[tuple, tuple[NDArray | None, str | None]] = {}
    places: dict[tuple, tuple[Placement | None, str | None]] = {}
    nan = np.full((4, 4), np.nan)
    poses, frames = [], []
    for p, said in zip(pts, problems):
        key = _key(p.tool)
        if key not in tools:
            try:
                tools[key] = (tool_pose_of(cell, axes.vendor, p.tool), None)
            except InputError as exc:
                tools[key] = (None, str(exc))
        T_tool, why = tools[key]
        poses.append(nan if T_tool is None else T_tool)
        if why:
            said.insert(0, why)
        where = None
        if p.pose is not None:
            key = _key(p.frame)
            if key not in places:
                try:
                    places[key] = (placement(cell, axes.vendor, p.frame), None)
                except InputError as exc:
                    places[key] = (None, str(exc))
            where, why = places[key]
            if why:
                said.insert(1 if T_tool is None else 0, why)
        frames.append(where)
    res = _Resolved(np.array(poses).reshape(-1, 4, 4), frames, track, table, problems)
    _limits(cell, res)
    return res


def _limits(cell: Cell, res: _Resolved) -> None:
    """Name the track and table values outside their limits."""
    if cell.track is not None:
        for i in np.flatnonzero(~cell.track.within_limits(res.track)):
            res.problems[i].append(f"track {res.track[i] * 1e3:g} mm is outside its limits "
                                   f"[{cell.track.lower * 1e3:g}, {cell.track.upper * 1e3:g}] mm")
    tt = cell.turntable
    if tt is not None and len(res.track):
        for i in np.flatnonzero(~tt.within_limits(res.table)):
            res.problems[i].append(f"table {np.round(np.degrees(res.table[i]), 4)} deg is outside "
                                   f"its limits [{np.degrees(tt.lower)}, {np.degrees(tt.upper)}] "
                                   "deg")


def check_program(program: Program, cell: Cell, pulses_per_degree: ArrayLike | None = None,
                  singular_margin: float = SINGULAR_MARGIN,
                  shoulder_margin: float = SHOULDER_MARGIN,
                  skipped: list[str] | None = None, bodies: BodiesFile | None = None,
                  clearance: float = CLEARANCE) -> CheckReport:
    """Check every point of a program against a cell, and every linear motion between two.

    Parameters
    ----------
    program : Program
    cell : Cell
        The cell the program runs in (a six-axis ortho-parallel arm).
    pulses_per_degree : float or array_like, optional
        YASKAWA: encoder pulses per degree of each station axis (only for a job that moves one).
    singular_margin : float
        Closest good approach to the wrist or elbow singularity, at a point or on a linear motion
        (rad).
    shoulder_margin : float
        Closest good distance of the wrist centre from axis 1 (m).
    skipped : list of str, optional
        Motions the reader skipped, carried into the report.
    bodies : BodiesFile, optional
        The cell's parts as shapes (:func:`robotcell.clearance.read_bodies`): with them every
        point and motion is checked for clearance (:mod:`robotcell.programs.clearcheck`).
    clearance : float
        Smallest good distance between the robot and a part (m).

    Returns
    -------
    CheckReport

    Raises
    ------
    InputError
        A YASKAWA job that moves a station axis, for a cell with station axes, and no
        ``pulses_per_degree``.
    """
    ctrl = cell.controller()
    robot = ctrl.robot
    axes = get(program.vendor, "program format").external_axes(cell, pulses_per_degree)
    pts = program.points
    n = len(pts)
    res = _resolve(cell, pts, axes)
    q = np.full((n, robot.n_joints), np.nan)
    T_world = np.full((n, 4, 4), np.nan)
    problems, track, table, tools = res.problems, res.track, res.table, res.tools
    cart = np.array([i for i, (p, w) in enumerate(zip(pts, res.frames)) if p.pose is not None
                     and w is not None], dtype=int)
    cart = cart[np.isfinite(tools[cart]).all(axis=(1, 2))]
    solutions = _solve_cartesian(ctrl, pts, res, cart, q, T_world)
    _joint_points(cell, robot, pts, q, T_world, problems, track, tools)
    _sequential(ctrl, pts, cart, solutions, q, problems)
    if cell.identified is not None and cart.size:  # where the real arm takes the joints
        ok = cart[np.isfinite(q[cart]).all(axis=-1)]
        T_world[ok] = (robot_pose(cell, track[ok]) @ cell.robot.fk(q[ok], tool=np.eye(4))
                       @ tools[ok])
    wrist, elbow, shoulder = singular_distances(robot, np.nan_to_num(q))
    _singular(q, wrist, elbow, shoulder, singular_margin, shoulder_margin, problems)
    _lines(ctrl, pts, res, q, cart, solutions, singular_margin, shoulder_margin)
    if bodies is not None:
        near = clearance_problems(cell, [p.motion for p in pts], q, track, table, tools, bodies,
                                  clearance)
        for mine, found in zip(problems, near):
            mine.extend(found)
    known = np.isfinite(q).all(axis=-1)
    wrist, elbow, shoulder = (np.where(known, x, math.nan).tolist()
                              for x in (wrist, elbow, shoulder))
    checked = [CheckedPoint(p.name, p.line, p.motion, q[i], float(track[i]), table[i],
                            T_world[i], problems[i], wrist[i], elbow[i], shoulder[i])
               for i, p in enumerate(pts)]
    return CheckReport(program, checked, list(skipped or []))


def _joint_points(cell: Cell, robot: Robot, pts: list[ProgramPoint], q: NDArray,
                  T_world: NDArray, problems: list[list[str]], track: NDArray,
                  tools: NDArray) -> None:
    """Joint points: their joints as written, within the limits of ``robot`` (the controller's
    model), and their TCP in ``cell`` (in one batch)."""
    idx = np.array([i for i, p in enumerate(pts) if p.joints is not None], dtype=int)
    if idx.size == 0:
        return
    q[idx] = np.stack([pts[i].joints for i in idx])
    for i in idx[~robot.within_limits(q[idx])]:
        problems[i].append(outside_text(robot, q[i]))
    ok = idx[np.isfinite(tools[idx]).all(axis=(1, 2))]
    T_world[ok] = robot_pose(cell, track[ok]) @ cell.robot.fk(q[ok], tool=np.eye(4)) @ tools[ok]


def _solve_cartesian(cell: Cell, pts: list[ProgramPoint], res: _Resolved,
                     idx: NDArray[np.int_], q: NDArray, T_world: NDArray) -> IKSolutions | None:
    """IK of the Cartesian points ``idx`` in one batch; those with flags get their solution
    here. Returns the solutions (None without Cartesian points)."""
    if idx.size == 0:
        return None
    robot = cell.robot
    track, tools, problems = res.track, res.tools, res.problems
    poses = np.stack([pts[i].pose for i in idx])
    _, first, group = np.unique([id(res.frames[i]) for i in idx], return_index=True,
                                return_inverse=True)
    for g, k0 in enumerate(first):
        ks = np.flatnonzero(group == g)
        rows = idx[ks]
        T_world[rows] = res.frames[idx[k0]].world(cell, track[rows], res.table[rows]) @ poses[ks]
    T_R_F = invert(robot_pose(cell, track[idx])) @ T_world[idx] @ invert(tools[idx])
    sol = robot.ik(T_R_F, tool=np.eye(4))
    unreached = ~sol.reachable.any(axis=-1)
    for k in np.flatnonzero(unreached):
        err = (np.nanmin(sol.reach_error[k]) * 1e3 if sol.reach_error is not None
               else math.nan)
        problems[idx[k]].append("out of reach" + (f" by {err:.1f} mm" if math.isfinite(err)
                                                  else ""))
    flagged = np.array([k for k, i in enumerate(idx) if pts[i].config is not None
                        and not unreached[k]], dtype=int)
    if flagged.size == 0:
        return sol
    wanted = np.array([pts[idx[k]].config.values for k in flagged])
    vendor = pts[idx[flagged[0]]].config.vendor
    got, found, exists = select(robot, sol.q[flagged], sol.reachable[flagged], wanted, vendor)
    q[idx[flagged[found]]] = got[found]
    for j in np.flatnonzero(~found):
        k, i = flagged[j], idx[flagged[j]]
        text = config_text(pts[i].config)
        if exists[j]:
            problems[i].append(f"with the configuration as written ({text}) "
                               + _outside_any(cell, sol.q[k], pts[i].config))
        else:
            reached = sorted({config_text(Config(vendor, tuple(int(x) for x in row)))
                              for row in config_values(robot, sol.q[k][sol.reachable[k]],
                                                       vendor)})
            problems[i].append(f"no solution has the configuration as written ({text}); it is "
                               f"reached as {', '.join(reached)}")
    return sol


def _outside_any(cell: Cell, branches: NDArray, config: Config) -> str:
    """Why the solutions with ``config`` leave the limits, for the first of them."""
    robot = cell.robot
    cand = candidates(robot, branches[None])[0]
    flags = config_values(robot, np.nan_to_num(cand), config.vendor)
    match = np.all(flags == np.array(config.values), axis=-1) & np.isfinite(cand).all(axis=-1)
    return outside_text(robot, cand[int(np.argmax(match))])


def _sequential(cell: Cell, pts: list[ProgramPoint], cart: NDArray[np.int_],
                sol: IKSolutions | None, q: NDArray, problems: list[list[str]]) -> None:
    """Cartesian points without flags: the solution nearest to the previous point's, as a
    controller keeps the configuration (the first: nearest to the robot's home), or to the
    joints the point names (:attr:`ProgramPoint.near`, URScript's ``qnear``).

    Each point's choice depends on the one before; all are chosen at once against the previous
    points' choices of the round before, until no choice changes (a few rounds: a choice
    changes only where the one before it did), or one by one after SEQUENTIAL_ROUNDS."""
    if sol is None:
        return
    robot = cell.robot
    free = np.array([k for k, i in enumerate(cart) if pts[i].config is None
                     and sol.reachable[k].any()], dtype=int)
    if free.size == 0:
        return
    rows = cart[free]
    part = replace(sol, q=sol.q[free], valid=sol.valid[free], reachable=sol.reachable[free],
                   reach_error=None if sol.reach_error is None else sol.reach_error[free])
    home = robot.home if robot.home is not None else np.zeros(robot.n_joints)
    near = [(k, pts[i].near) for k, i in enumerate(rows) if pts[i].near is not None]

    def reference(rows_k: NDArray[np.int_], at: int = 0) -> NDArray:
        """The joints each point's solution is nearest to: its own ``near``, or the previous
        point's."""
        ref = _previous(q, rows_k, home)
        for k, joints in near:
            if at <= k < at + len(rows_k):
                ref[k - at] = joints
        return ref

    for _ in range(SEQUENTIAL_ROUNDS):
        got, found, _ = nearest(robot, part, reference(rows))
        new = np.where(found[:, None], got, np.nan)
        changed = ~np.all((new == q[rows]) | (np.isnan(new) & np.isnan(q[rows])), axis=-1)
        q[rows] = new
        if not changed.any():
            break
    else:  # the choices still change: the rest one by one, each against the one before
        for k in range(int(np.argmax(changed)), len(rows)):
            one = replace(part, q=part.q[k], valid=part.valid[k],
                          reachable=part.reachable[k], reach_error=None)
            got, found, _ = nearest(robot, one, reference(rows[k:k + 1], k)[0])
            q[rows[k]] = got if found else np.nan
    for i in rows[~np.isfinite(q[rows]).all(axis=-1)]:
        problems[i].append("no solution within the axis limits")


def _previous(q: NDArray, rows: NDArray[np.int_], home: NDArray) -> NDArray:
    """For each point of ``rows``, the joints of the last point before it that has any
    (``home`` before the first)."""
    known = np.isfinite(q).all(axis=-1)
    last = np.where(known, np.arange(len(q)), -1)
    last = np.maximum.accumulate(last)
    before = np.concatenate([[-1], last[:-1]])[rows]
    return np.where(before[:, None] >= 0, q[np.maximum(before, 0)], home)


def _singular(q: NDArray, wrist: NDArray, elbow: NDArray, shoulder: NDArray,
              singular_margin: float, shoulder_margin: float,
              problems: list[list[str]]) -> None:
    """Name the points within a margin of a singularity."""
    known = np.isfinite(q).all(axis=-1)
    with np.errstate(invalid="ignore"):
        near = known & ((wrist < singular_margin) | (elbow < singular_margin)
                        | (shoulder < shoulder_margin))
    for i in np.flatnonzero(near):
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


def _lines(cell: Cell, pts: list[ProgramPoint], res: _Resolved, q: NDArray,
           cart: NDArray[np.int_], solutions: IKSolutions | None, singular_margin: float,
           shoulder_margin: float) -> None:
    """The linear motions between two points with joints (:func:`line_problems`); the IK
    ``solutions`` of the Cartesian points ``cart`` are the ends of their lines."""
    known = np.isfinite(q).all(axis=-1) & np.isfinite(res.tools).all(axis=(1, 2))
    ends = np.array([i for i in range(1, len(pts)) if pts[i].motion == "lin"
                     and known[i] and known[i - 1]], dtype=int)
    if ends.size == 0:
        return
    frames = [_WORLD if w is None else w for w in res.frames]
    branches = None
    if solutions is not None:
        branches = np.full((len(pts),) + solutions.q.shape[1:], np.nan)
        branches[cart] = solutions.q
    data = LineData([p.name for p in pts], np.column_stack([ends - 1, ends]), q, res.track,
                    res.table, res.tools, frames, branches)
    for i, words in line_problems(cell, data, singular_margin, shoulder_margin).items():
        res.problems[i].extend(words)


def check_program_file(path: str | Path, cell: Cell, pulses_per_degree: ArrayLike | None = None,
                       singular_margin: float = SINGULAR_MARGIN,
                       shoulder_margin: float = SHOULDER_MARGIN,
                       bodies: BodiesFile | None = None, clearance: float = CLEARANCE
                       ) -> CheckReport:
    """Read a program file (any format, by extension) and check it against a cell.

    Parameters
    ----------
    path : str or Path
        KUKA ``.src`` (with its ``.dat``), ABB ``.mod``, FANUC ``.ls``, YASKAWA ``.jbi``.
    cell, pulses_per_degree, singular_margin, shoulder_margin, bodies, clearance
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
    return check_program(program, cell, pulses_per_degree, singular_margin, shoulder_margin,
                         skipped, bodies, clearance)
