"""Reading a coordinated program back: every robot's program checked, all robots together.

:func:`check_coordinated` reads one file per robot (ABB: one module per MultiMove task), or
the one file of a controller whose coordinated program is one file for all robots (YASKAWA: a
job of two robot groups), the robots in the order of the files or groups: the cell's robots in
its order, or as named. It checks the synchronisation by the controller's rules
(:meth:`robotcell.controllers.base.Controller.coordinated_problems`: ABB's ``\\ID``, YASKAWA's
groups), that the programs move to as many points each with the positioner at the same values
at every point, each program against the cell as its robot sees it
(:func:`robotcell.programs.check.check_program`: reach, limits, configuration, singularities),
and with ``bodies`` the clearance of the robots against each other and the parts along the
program they run together (:func:`robotcell.clearance.clearance_between`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from robotcell.cell import Cell
from robotcell.clearance.bodies import BodiesFile
from robotcell.clearance.distance import Clearance
from robotcell.controllers.base import Controller
from robotcell.controllers.registry import get
from robotcell.errors import InputError
from robotcell.programs.check import CLEARANCE, CheckReport, check_program
from robotcell.programs.formats import vendor_of

__all__ = ["CoordinatedReport", "check_coordinated"]


@dataclass
class CoordinatedReport:
    """The result of :func:`check_coordinated`.

    Attributes
    ----------
    reports : dict of str to CheckReport
        Each robot's program checked, by the robot's name, in the order of the files.
    sync : list of str
        What breaks the synchronisation: the controller's rules, different numbers of points,
        different positioner values at one point.
    """

    reports: dict[str, CheckReport]
    sync: list[str] = field(default_factory=list)

    @property
    def good(self) -> bool:
        """The synchronisation holds and every point of every robot is good."""
        return not self.sync and all(r.good for r in self.reports.values())

    def rows(self) -> list[list[str]]:
        """``[robot, point, line, problem]`` for each problem of each bad point."""
        return [[robot, *row] for robot, r in self.reports.items() for row in r.rows()]


def _robots(cell: Cell, paths: Sequence[str | Path], robots: Sequence[str] | None,
            ctl: Controller) -> list[str]:
    names = list(cell.robot_names if robots is None else robots)
    for name in names:
        cell.robot_key(name)
    if ctl.coordinated_one_file and len(paths) != 1:
        raise InputError(f"{len(paths)} program files: a {ctl.label} coordinated program is one "
                         "file for all robots; give that one file")
    if not ctl.coordinated_one_file and len(names) != len(paths):
        files = "1 program file" if len(paths) == 1 else f"{len(paths)} program files"
        raise InputError(f"{files} for {len(names)} robots ({', '.join(names)}): give one "
                         "file per robot, in the order of the robots (or name them)")
    return names


def check_coordinated(paths: Sequence[str | Path], cell: Cell,
                      robots: Sequence[str] | None = None, bodies: BodiesFile | None = None,
                      clearance: float = CLEARANCE,
                      pulses_per_degree: ArrayLike | None = None) -> CoordinatedReport:
    """Read a coordinated program and check it against a cell.

    Parameters
    ----------
    paths : sequence of str or Path
        One program file per robot (ABB: ``NAME_T_ROB1.mod``, ``NAME_T_ROB2.mod``, ..), or the
        one file of a controller whose coordinated program is one file (YASKAWA: ``NAME.jbi``,
        the robots of group 1 and group 2).
    cell : Cell
        A cell of several robots.
    robots : sequence of str, optional
        The robot of each file (or of each group), in order; default: the cell's robots in the
        cell's order (the order of the tasks ``T_ROB1``, ``T_ROB2``, .. or of the groups that
        :func:`write_coordinated` writes).
    bodies : BodiesFile, optional
        The cell's parts: with them the clearance of every robot against the others and the
        parts at every point and along every motion.
    clearance : float
        Smallest good distance (m).
    pulses_per_degree : float or array_like, optional
        YASKAWA: encoder pulses per degree of each station axis.

    Returns
    -------
    CoordinatedReport

    Raises
    ------
    InputError
        A file that cannot be read, files of different formats or of a controller whose
        coordinated form is not read, a number of files the controller's form does not have
        (one per robot, or one), a robot the cell lacks, a YASKAWA job of a cell with a station
        and no ``pulses_per_degree``.
    """
    vendors = sorted({vendor_of(p) for p in paths})
    if len(vendors) > 1:
        raise InputError(f"the files of one coordinated program are of one format; got "
                         f"{', '.join(vendors)}")
    ctl = get(vendors[0], "program format")
    names = _robots(cell, paths, robots, ctl)
    read = ctl.read_coordinated(list(paths), len(names))
    sync = ctl.coordinated_problems(list(paths))
    reports = {r: check_program(program, cell.for_robot(r), pulses_per_degree, skipped=skipped)
               for r, (program, skipped) in zip(names, read)}
    counts = {r: len(rep.points) for r, rep in reports.items()}
    if len(set(counts.values())) > 1:
        sync.append("the programs move to different numbers of points: "
                    + ", ".join(f"{r} {n}" for r, n in counts.items()))
    elif cell.turntable is not None and any(counts.values()):
        sync += _table_problems(reports)
    if bodies is not None and not sync:
        _clearance(cell, reports, bodies, clearance)
    return CoordinatedReport(reports, sync)


def _table_problems(reports: dict[str, CheckReport]) -> list[str]:
    """Points at which the programs hold different positioner values."""
    tables = {r: np.array([np.atleast_1d(p.table) for p in rep.points], dtype=float)
              for r, rep in reports.items()}
    first, want = next(iter(tables.items()))
    out = []
    for r, got in tables.items():
        for k in np.flatnonzero(np.abs(got - want).max(axis=1) > 1e-6):
            out.append(f"{r}: point {reports[r].points[k].name} (line "
                       f"{reports[r].points[k].line}): the positioner is at "
                       f"{np.round(np.degrees(got[k]), 4)} deg, {first}'s at "
                       f"{np.round(np.degrees(want[k]), 4)} deg")
    return out


def _clearance(cell: Cell, reports: dict[str, CheckReport], bodies: BodiesFile,
               limit: float) -> None:
    """Add the clearance problems of the robots together to their points (where every robot's
    joints are known at every point and each program keeps one tool): each robot against the
    parts, each pair of robots against each other, so that every pair under the limit is
    named, not only the closest."""
    from robotcell.clearance import clearance_between

    q = {r: np.array([p.q for p in rep.points]) for r, rep in reports.items()}
    if not all(np.isfinite(v).all() for v in q.values()):
        return
    tools = {}
    for r, rep in reports.items():  # T_F_TCP from the first point (one tool per program)
        view = cell.for_robot(r)
        T_world_F = view.frame_pose("robot", rep.points[0].track) @ view.robot.fk(
            q[r][0], np.eye(4))
        tools[r] = np.linalg.inv(T_world_F) @ rep.points[0].T_world_TCP
    names = list(reports)
    arms = BodiesFile(links=bodies.links, ignore=bodies.ignore)
    groups = [((r,), bodies) for r in names] + [
        ((a, b), arms) for i, a in enumerate(names) for b in names[i + 1:]]
    table = np.array([p.table for p in reports[names[0]].points], dtype=float)
    for robots, shapes in groups:
        got = clearance_between(
            cell, {r: q[r] for r in robots},
            track={r: [p.track for p in reports[r].points] for r in robots}, table=table,
            tools={r: tools[r] for r in robots}, bodies=shapes,
            motion={r: ["linear" if p.motion in ("lin", "circ") else "joint"
                        for p in reports[r].points[1:]] for r in robots})
        _report(reports, robots, got, limit)


def _report(reports: dict[str, CheckReport], robots: tuple[str, ...], got: Clearance,
            limit: float) -> None:
    """The points and motions of ``got`` under ``limit``, given to each robot of ``robots``."""
    from robotcell.programs.clearcheck import problem_text

    at_points = got.per_point()
    along = got.per_segment() if len(at_points) > 1 else np.zeros(0)
    clear = at_points >= limit
    found = [(k, problem_text("clearance", got, k, d, limit))
             for k, d in enumerate(at_points) if d < limit]
    found += [(k + 1, problem_text("on the way here, clearance", got, k + 0.5, along[k], limit))
              for k in np.flatnonzero((along < limit) & clear[1:] & clear[:-1])]
    for k, text in found:
        for r in robots:
            reports[r].points[k].problems.append(text)
