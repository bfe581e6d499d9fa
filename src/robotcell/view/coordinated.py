"""A coordinated program of several robots in the 3D view of their cell, all moving together.

The program (one file per robot, ABB: one MultiMove module per task) is read and checked by
:func:`robotcell.programs.coordcheck.check_coordinated`, as ``robotcell program
check-coordinated`` does: point ``k`` of every robot is reached at the same time, with the
shared positioner at the same values. The view steps through the points on one slider, with
every robot's arm, tool and TCP and the positioner with the frames it carries at each point,
draws each robot's TCP path, and marks each robot's bad points with their problems. With the
cell's parts as shapes (``bodies``), it also draws at each point the closest pair of shapes
(each robot against the others and against the parts, :func:`closest_pairs`): a line between
their two nearest points, labelled with the pair and its distance, in red under the clearance
limit.

The page stays under :data:`robotcell.view.plot.MAX_PAGE_BYTES` as a one-robot program's does
(:func:`robotcell.view.program.fitting_page`): with the arm at every k-th point when a long
program needs it, the whole paths and every mark at all points.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from robotcell.cell import Cell
from robotcell.clearance import Clearance, clearance_between
from robotcell.clearance.bodies import BodiesFile
from robotcell.errors import InputError
from robotcell.io.fileio import atomic_write
from robotcell.kinematics.transforms import invert
from robotcell.programs.check import CLEARANCE, CheckReport
from robotcell.programs.coordcheck import CoordinatedReport, check_coordinated
from robotcell.view.cellscene import fixed_items, frame_size, robot_items, work_items
from robotcell.view.path import DECIMALS, one_per_frame, ordinal, path_steps, triad_line
from robotcell.view.plot import page
from robotcell.view.program import fitting_page
from robotcell.view.scene import Item, Lines, Points, Scene, Step, Triads
from robotcell.view.shapes import OUTLIER_COLOR

__all__ = ["CLOSEST", "CoordinatedView", "closest_pairs", "coordinated_scene",
           "write_coordinated_view"]

#: Name of the line between the two nearest points of the closest pair, at each point.
CLOSEST = "closest pair"
#: Colours of the robots' TCP paths, in the order of the robots.
PATH_COLORS = ("teal", "royalblue", "darkmagenta", "olive")
#: Colour of the closest pair at a point where it keeps the clearance limit.
CLEAR_COLOR = "darkgoldenrod"
#: A sample spacing no motion reaches (rad, m): :func:`clearance_between` at the points alone.
_POINTS_ONLY = 1e9


@dataclass(frozen=True)
class CoordinatedView:
    """What :func:`write_coordinated_view` wrote.

    Attributes
    ----------
    path : Path
        The page.
    report : CoordinatedReport
        The program's check.
    every : int
        The arms are drawn at every ``every``-th point.
    size : int
        Size of the page (bytes).
    closest : Clearance or None
        The closest pair at each point (:func:`closest_pairs`), with ``bodies``.
    """

    path: Path
    report: CoordinatedReport
    every: int
    size: int
    closest: Clearance | None


@dataclass(frozen=True)
class _Robot:
    """One robot's program as the view draws it: its points (N) and where they put the arm."""

    name: str
    view: Cell
    report: CheckReport
    q: NDArray[np.float64]          # (N, n), rad, m; NaN: no joint values
    track: NDArray[np.float64]      # (N,), m
    table: NDArray[np.float64]      # (N,) or (N, k), rad
    T_tcp: NDArray[np.float64]      # (N, 4, 4), the TCP in the world (m; NaN: not placed)
    T_flange: NDArray[np.float64]   # (N, 4, 4), the flange in the world (m; NaN: no joints)
    shown: NDArray[np.intp]         # (N,), the point whose arm is drawn at each point

    @property
    def has_q(self) -> NDArray[np.bool_]:
        return np.all(np.isfinite(self.q), axis=1)


def _shown(has_q: NDArray[np.bool_]) -> NDArray[np.intp]:
    """At each point, the point whose arm is drawn: the nearest one before it (itself included)
    with joint values, else the first with them."""
    at = np.maximum.accumulate(np.where(has_q, np.arange(len(has_q)), -1))
    return np.where(at < 0, int(np.argmax(has_q)), at)


def _robots(cell: Cell, report: CoordinatedReport) -> list[_Robot]:
    """Each robot's points, refused unless every program moves to as many points."""
    counts = {r: len(rep.points) for r, rep in report.reports.items()}
    if len(set(counts.values())) > 1:
        raise InputError("the programs move to different numbers of points ("
                         + ", ".join(f"{r} {n}" for r, n in counts.items())
                         + "): a coordinated program moves every robot to its point k at once, "
                         "so they cannot be drawn together; draw each robot's program alone")
    out = []
    for name, rep in report.reports.items():
        view = cell.for_robot(name)
        pts = rep.points
        q = np.array([p.q for p in pts], dtype=float)
        track = np.array([p.track for p in pts], dtype=float)
        table = np.array([p.table for p in pts], dtype=float)
        flange = np.full((len(pts), 4, 4), np.nan)
        has = np.all(np.isfinite(q), axis=1)
        if np.any(has):
            flange[has] = view.fk(q[has], track[has], table[has], tool=np.eye(4))
        T_tcp = np.array([p.T_world_TCP for p in pts], dtype=float)
        out.append(_Robot(name, view, rep, q, track, table, T_tcp, flange, _shown(has)))
    if not any(np.any(r.has_q) for r in out):
        raise InputError("no point of the coordinated program can be placed in the cell, so "
                         "there is no arm to draw: " + "; ".join(
                             f"{r.name} point {r.report.points[0].name}: "
                             f"{'; '.join(r.report.points[0].problems) or 'no joint values'}"
                             for r in out))
    return out


def closest_pairs(cell: Cell, report: CoordinatedReport, bodies: BodiesFile) -> Clearance:
    """The closest pair of shapes at each point of a coordinated program: over each robot
    against the others and each robot against the parts, as
    :func:`robotcell.clearance.clearance_between` finds it at the points.

    Parameters
    ----------
    cell : Cell
        The cell of several robots the program was checked in.
    report : CoordinatedReport
        :func:`robotcell.programs.coordcheck.check_coordinated` of the program.
    bodies : BodiesFile
        The cell's parts, the capsules' radii and the pairs never reported.

    Returns
    -------
    Clearance
        One sample per point (``position`` 0 .. N - 1): the smallest distance (m), its pair
        (``rob1.tool``, ``plate``) and the nearest point of each shape in the world (m).
        ``inf``, ``("", "")`` and NaN at a point where a robot has no joint values, and where
        no pair is checked.

    Raises
    ------
    InputError
        Programs of different numbers of points, a part the cell cannot place (a parent it
        lacks, ``robot`` or ``flange`` without the robot's name), or the collision library
        missing.
    """
    robots = _robots(cell, report)
    n = len(robots[0].q)
    known = np.all([r.has_q for r in robots], axis=0)
    dist, near = np.full(n, np.inf), np.full((n, 2, 3), np.nan)
    pair: list[tuple[str, str]] = [("", "")] * n
    if np.any(known):
        tools = {}
        for r in robots:  # T_F_TCP of the first point placed (one tool per program)
            k = int(np.argmax(known & np.all(np.isfinite(r.T_tcp), axis=(1, 2))))
            if np.all(np.isfinite(r.T_tcp[k])):
                tools[r.name] = invert(r.T_flange[k]) @ r.T_tcp[k]
        got = clearance_between(cell, {r.name: r.q[known] for r in robots},
                                track={r.name: r.track[known] for r in robots},
                                table=robots[0].table[known], tools=tools, bodies=bodies,
                                step=_POINTS_ONLY)
        idx = np.flatnonzero(known)
        dist[idx], near[idx] = got.distance, got.nearest
        for i, p in zip(idx, got.pair):
            pair[i] = p
    return Clearance(dist, tuple(pair), near, np.arange(n, dtype=float))


def _labels(robots: list[_Robot]) -> list[str]:
    """The name of each point on the slider: the programs' name of it, or each robot's."""
    names = [[p.name for p in r.report.points] for r in robots]
    return [k[0] if len(set(k)) == 1 else " / ".join(k) for k in zip(*names)]


def _paths(robots: list[_Robot], size: float) -> tuple[list[Item], list[str]]:
    """The world axes, each robot's track, TCP path and bad points, and the notes on them."""
    items: list[Item] = [Triads("world", np.eye(4), ["world"], length=2 * size)]
    notes: list[str] = []
    for r, color in zip(robots, PATH_COLORS * len(robots)):
        items += [replace(it, name=f"{r.name}: {it.name}") for it in fixed_items(r.view, size)[1:]]
        pts = r.report.points
        where = r.T_tcp[:, :3, 3]
        items.append(Lines(f"{r.name}: TCP path", where, color=color, width=5.0, hover_xyz=True,
                           hover=[f"<b>{r.name} {p.name}</b> (line {p.line}, {p.motion})"
                                  for p in pts]))
        placed = np.all(np.isfinite(where), axis=1)
        bad = [i for i, p in enumerate(pts) if p.problems and placed[i]]
        if bad:
            items.append(Points(f"{r.name}: bad points", where[bad], color=OUTLIER_COLOR,
                                symbol="x", size=8.0, labels=[pts[i].name for i in bad],
                                hover=[f"<b>{r.name} point {pts[i].name}</b>: "
                                       f"{'; '.join(pts[i].problems)}" for i in bad]))
            notes.append(f"{r.name}: {len(bad)} point(s) marked bad: hover over a cross for "
                         "the reason")
        lost = [p for i, p in enumerate(pts) if p.problems and not placed[i]]
        if lost:
            notes.append(f"{r.name}: not drawn, no position: " + "; ".join(
                f"point {p.name}: {'; '.join(p.problems)}" for p in lost))
    return items, notes


def _at_point(robots: list[_Robot], j: int, size: float) -> list[Item]:
    """The moving parts of the cell at point ``j``: each robot's links, its tool from the
    flange to the TCP, its TCP as a triad and the frames on its base, then the shared
    positioner and the frames it carries, one item per frame."""
    items: list[Item] = []
    for r in robots:
        k = int(r.shown[j])
        label = f"{r.name}: "
        (links,) = robot_items(r.view, r.q[k], float(r.track[k]), size, detail=False,
                               with_tools=False, triads=False, label=label)
        T_tcp = r.T_tcp[k]
        items += [links, Lines(f"{label}tool", np.vstack([r.T_flange[k, :3, 3], T_tcp[:3, 3]]),
                               color=links.color), triad_line(f"{label}TCP", T_tcp, size)]
        mine = {f: fr for f, fr in r.view.frames.items() if fr.parent == "robot"}
        items += [replace(it, name=f"{label}{it.name}") for it in one_per_frame(work_items(
            replace(r.view, turntable=None, frames=mine), float(r.track[k]), 0.0, size,
            detail=False, triads=False))]
    first = robots[0]
    shared = [f for f, fr in first.view.frames.items() if fr.parent in ("world", "turntable")]
    return items + one_per_frame(work_items(first.view, 0.0, first.table[int(first.shown[j])],
                                            size, detail=False, triads=False, frames=shared))


def _pair_items(closest: Clearance, j: int, limit: float) -> tuple[Lines, Points]:
    """The closest pair at point ``j``: the line between its nearest points, and its label at
    the line's middle (the pair and its distance; its hover text to 0.001 mm with the limit),
    in red under ``limit`` (m)."""
    d, (a, b) = float(closest.distance[j]), closest.pair[j]
    if not np.isfinite(d):
        return (Lines(CLOSEST, np.full((2, 3), np.nan), color=CLEAR_COLOR),
                Points(f"{CLOSEST}: distance", np.zeros((0, 3)), color=CLEAR_COLOR))
    color = OUTLIER_COLOR if d < limit else CLEAR_COLOR
    label = (f"{a} and {b} overlap by {-d * 1e3:.1f} mm" if d < 0
             else f"{a} - {b} {d * 1e3:.1f} mm")
    hover = (f"<b>closest pair</b>: {a} and {b}, {d * 1e3:.3f} mm (limit {limit * 1e3:g} mm"
             f"{', under it' if d < limit else ''})")
    ends = closest.nearest[j]
    return (Lines(CLOSEST, ends, color=color, width=6.0),
            Points(f"{CLOSEST}: distance", ends.mean(axis=0)[None], color=color, size=3.0,
                   labels=[label], hover=[hover]))


def coordinated_scene(cell: Cell, report: CoordinatedReport, bodies: BodiesFile | None = None,
                      every: int = 1, clearance: float = CLEARANCE) -> Scene:
    """The scene of a checked coordinated program: every robot and the positioner moving
    together on one slider, each robot's path and bad points, the closest pair at each point.

    Parameters
    ----------
    cell : Cell
        The cell of several robots the program was checked in.
    report : CoordinatedReport
        :func:`robotcell.programs.coordcheck.check_coordinated` of the program.
    bodies : BodiesFile, optional
        The cell's parts as shapes: with them the closest pair at each point is drawn
        (:func:`closest_pairs`).
    every : int
        Draw the arms at every ``every``-th point.
    clearance : float
        The clearance limit (m): a closest pair nearer than it is drawn in red.

    Returns
    -------
    Scene
        In the cell's world, 0.01 mm: the world axes and each robot's track, each robot's TCP
        path (``ROBOT: TCP path``, hover: the point's name, line, motion and position) and bad
        points (``ROBOT: bad points``), what does not move; one step per point drawn with the
        moving parts as one polyline (:data:`robotcell.view.path.MOVING`: ``ROBOT: robot
        MODEL: links``, ``ROBOT: tool``, ``ROBOT: TCP``, the positioner's links), its plate
        and, with ``bodies``, the closest pair (:data:`CLOSEST`) and its label.

    Raises
    ------
    InputError
        Programs of different numbers of points, no point any robot reaches, ``every`` < 1,
        and what :func:`closest_pairs` refuses.
    """
    closest = None if bodies is None else closest_pairs(cell, report, bodies)
    return _scene(cell, report, closest, every, clearance)


def _scene(cell: Cell, report: CoordinatedReport, closest: Clearance | None, every: int,
           limit: float) -> Scene:
    if int(every) != every or every < 1:
        raise InputError(f"every must be a whole number >= 1, got {every}")
    robots = _robots(cell, report)
    size = max(frame_size(r.view.robot) for r in robots)
    n = len(robots[0].q)
    items, notes = _paths(robots, size)
    notes.insert(0, "lengths in mm; move the slider (or press play) to put every robot at its "
                    "point; hover over a path for a point's name and position")
    labels = _labels(robots)
    steps = np.arange(0, n, int(every))
    still, frames = path_steps([_at_point(robots, int(j), size) for j in steps],
                               [labels[j] for j in steps])
    items += still
    if closest is not None:
        frames = [Step(f.label, (*f.items, *_pair_items(closest, int(j), limit)))
                  for f, j in zip(frames, steps)]
        under = int(np.count_nonzero(closest.distance < limit))
        notes.append(f"at each point the closest pair of shapes joined by a line, with its "
                     f"distance; {under} point(s) under the clearance limit of "
                     f"{limit * 1e3:g} mm (red)")
    notes += [f"synchronisation: {s}" for s in report.sync]
    if every > 1:
        notes.append(f"the arms are drawn at every {ordinal(every)} of the {n} points (the "
                     "paths and every mark at all of them)")
    bad = sum(len(r.report.bad) for r in robots)
    title = (" + ".join(r.report.program.name for r in robots) + f" in {cell.name}: "
             f"{len(robots)} robots, {n} points each, {bad} bad")
    return Scene(title, items, notes, frames, decimals=DECIMALS)


def write_coordinated_view(cell: Cell, programs: Sequence[str | Path], path: str | Path,
                           robots: Sequence[str] | None = None, bodies: BodiesFile | None = None,
                           clearance: float = CLEARANCE) -> CoordinatedView:
    """Check a coordinated program against a cell and write its 3D view as one page.

    Parameters
    ----------
    cell : Cell
        A cell of several robots.
    programs : sequence of str or Path
        One program file per robot (ABB: ``NAME_T_ROB1.mod``, ``NAME_T_ROB2.mod``, ..).
    path : str or Path
        The HTML file to write (atomically; nothing is written when the program is refused).
    robots : sequence of str, optional
        The robot of each file, in order; default the cell's robots in the cell's order.
    bodies : BodiesFile, optional
        The cell's parts: the clearance is checked and the closest pair drawn at each point.
    clearance : float
        Smallest good distance (m).

    Returns
    -------
    CoordinatedView

    Raises
    ------
    InputError
        What :func:`~robotcell.programs.coordcheck.check_coordinated` refuses (a file that
        cannot be read, as many files as robots not given), programs of different numbers of
        points, none of whose points can be placed, a page too large even with the arms at
        one point, or ``path`` naming a file the program is read from.
    """
    report = check_coordinated(programs, cell, robots, bodies, clearance)
    read = next((f for rep in report.reports.values() for f in rep.program.files
                 if Path(f).resolve() == Path(path).resolve()), None)
    if read is not None:
        raise InputError(f"{path} is {read}, which the program is read from: writing the view "
                         "there would replace it; write to another file")
    closest = None if bodies is None else closest_pairs(cell, report, bodies)
    title = " + ".join(rep.program.name for rep in report.reports.values())
    every, text = fitting_page(
        lambda k: page(_scene(cell, report, closest, k, clearance),
                       title=f"{title} in {cell.name}: robotcell view"),
        len(next(iter(report.reports.values())).points), ", ".join(map(str, programs)))
    atomic_write(path, text)
    return CoordinatedView(Path(path), report, every, len(text.encode()), closest)
