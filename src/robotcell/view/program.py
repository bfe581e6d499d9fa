"""A robot program in the 3D view of its cell: its path, the arm at each point, its bad points.

The program is read and checked by :func:`robotcell.programs.check.check_program_file`, as
``robotcell program check`` does: each point gets the arm's joint values the controller would
use, its track and table values, its TCP in the world and its problems. The view
(:func:`robotcell.view.path.path_scene`) draws the path of the TCPs, the arm at each point on a
slider, and marks every point with a problem with a red cross, its problems in the hover text.
A point the arm cannot reach has no joint values: it is marked where the program puts its TCP,
and its step shows the arm at the point before it.

:func:`write_program_view` keeps the page under :data:`robotcell.view.plot.MAX_PAGE_BYTES`: a
program of a few hundred points has the arm at every point; a longer one has it at every k-th
point (the smallest k that fits), with the whole path and every mark, and the page says so.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.io.fileio import atomic_write
from robotcell.kinematics.transforms import invert
from robotcell.programs.check import CheckReport, check_program_file
from robotcell.view.path import PathMarks, path_scene
from robotcell.view.plot import MAX_PAGE_BYTES, page
from robotcell.view.scene import Scene

__all__ = ["ProgramView", "fitting_page", "program_scene", "write_program_view"]


@dataclass(frozen=True)
class ProgramView:
    """What :func:`write_program_view` wrote.

    Attributes
    ----------
    path : Path
        The page.
    report : CheckReport
        The program's check.
    every : int
        The arm is drawn at every ``every``-th point.
    size : int
        Size of the page (bytes).
    """

    path: Path
    report: CheckReport
    every: int
    size: int


def program_scene(cell: Cell, report: CheckReport, every: int = 1) -> Scene:
    """The scene of a checked program: its path, the arm at each point, its bad points.

    Parameters
    ----------
    cell : Cell
        The cell the program was checked in.
    report : CheckReport
        :func:`robotcell.programs.check.check_program` (or ``check_program_file``) of it.
    every : int
        Draw the arm at every ``every``-th point.

    Returns
    -------
    Scene
        In the cell's world (:func:`robotcell.view.path.path_scene`): the points by their
        names in the program, on the slider; hover over the path: name, line, motion and
        position; over a cross: the problems of the point.

    Raises
    ------
    InputError
        No point of the program has joint values (none can be placed in the cell).
    """
    pts = report.points
    q = np.array([p.q for p in pts], dtype=float)
    track = np.array([p.track for p in pts], dtype=float)
    table = np.array([p.table for p in pts], dtype=float)
    T_world = np.array([p.T_world_TCP for p in pts], dtype=float)
    name = report.program.name
    if not np.any(np.all(np.isfinite(q), axis=1)):
        first = next((p for p in pts if p.problems), pts[0])
        raise InputError(f"{name}: no point of the program can be placed in the cell, so there "
                         f"is no arm to draw; point {first.name} (line {first.line}): "
                         f"{'; '.join(first.problems) or 'no joint values'}")
    # each point's tool, as the check found it: the TCP it puts in the world, from the flange
    placed = np.all(np.isfinite(q), axis=1) & np.all(np.isfinite(T_world), axis=(1, 2))
    tools = np.full((len(pts), 4, 4), np.nan)
    if np.any(placed):
        T_world_F = cell.fk(q[placed], track[placed], table[placed], tool=np.eye(4))
        tools[placed] = invert(T_world_F) @ T_world[placed]
    bad = [bool(p.problems) for p in pts]
    marks = PathMarks(labels=[p.name for p in pts], bad=bad,
                      reasons=["; ".join(p.problems) for p in pts], points=T_world[:, :3, 3],
                      hover=[f"<b>{p.name}</b> (line {p.line}, {p.motion})" for p in pts])
    scene = path_scene(cell, q, track, table, tool=tools, marks=marks,
                       title=(f"{name} ({report.program.vendor}) in {cell.name}: {len(pts)} "
                              f"points, {sum(bad)} bad"), every=every)
    if report.skipped:
        scene.notes.append(f"not drawn, not checked: {len(report.skipped)} motion(s) "
                           f"({report.skipped[0]}{', ...' if len(report.skipped) > 1 else ''})")
    return scene


def _page(cell: Cell, report: CheckReport, every: int) -> str:
    return page(program_scene(cell, report, every),
                title=f"{report.program.name} in {cell.name}: robotcell view")


def write_program_view(cell: Cell, program: str | Path, path: str | Path,
                       pulses_per_degree: ArrayLike | None = None) -> ProgramView:
    """Check a program file against a cell and write its 3D view as one page.

    Parameters
    ----------
    cell : Cell
    program : str or Path
        KUKA ``.src`` (with its ``.dat``), ABB ``.mod``, FANUC ``.ls``, YASKAWA ``.jbi``.
    path : str or Path
        The HTML file to write (atomically; nothing is written when the program is refused).
    pulses_per_degree : float or array_like, optional
        YASKAWA: encoder pulses per degree of each station axis.

    Returns
    -------
    ProgramView
        The arm is drawn at every point if the page stays under
        :data:`~robotcell.view.plot.MAX_PAGE_BYTES`, else at every k-th, the smallest k that
        keeps it so.

    Raises
    ------
    InputError
        A program that cannot be read (the file and line named), one whose points cannot be
        placed in the cell, one whose path alone would make the page too large, or ``path``
        naming a file the program is read from (a KUKA ``.dat``).
    """
    report = check_program_file(program, cell, pulses_per_degree)
    read = next((f for f in report.program.files if Path(f).resolve() == Path(path).resolve()),
                None)
    if read is not None:  # a KUKA program's .dat beside its .src
        raise InputError(f"{path} is {read}, which the program is read from: writing the view "
                         "there would replace it; write to another file")
    every, text = fitting_page(lambda k: _page(cell, report, k), len(report.points),
                               str(program))
    atomic_write(path, text)
    return ProgramView(Path(path), report, every, len(text.encode()))


def fitting_page(render: Callable[[int], str], n: int, what: str) -> tuple[int, str]:
    """The page of a path of ``n`` points with the arm at every point, or at every k-th point
    for the smallest k that keeps it under :data:`~robotcell.view.plot.MAX_PAGE_BYTES`.

    Parameters
    ----------
    render : callable
        ``render(k)``: the page with the arm at every k-th point.
    n : int
        The number of points.
    what : str
        What the page shows, for the message (the program's file).

    Returns
    -------
    every : int
        k.
    page : str
        ``render(k)``.

    Raises
    ------
    InputError
        The page is too large even with the arm at one point.
    """
    pages: dict[int, str] = {}

    def fits(every: int) -> bool:
        pages.setdefault(every, render(every))
        return len(pages[every].encode()) <= MAX_PAGE_BYTES

    every = 1
    if not fits(1):
        if not fits(n):
            raise InputError(f"{what}: its {n} points make a page of "
                             f"{len(pages[n].encode()) / 1e6:.1f} MB even with the arm at one "
                             f"point, more than {MAX_PAGE_BYTES / 1e6:g} MB; view it in parts")
        # the page grows by about the same number of bytes per step of the slider
        one, full = len(pages[n].encode()), len(pages[1].encode())
        steps = 1 + int((MAX_PAGE_BYTES - one) * (n - 1) // (full - one))
        every = max(2, math.ceil(n / steps))
        while every > 2 and fits(every - 1):
            every -= 1
        while not fits(every):
            every += 1
    return every, pages[every]
