"""Coordinated programs: several robots of a cell moving through their paths together.

Each robot has a path file (:mod:`robotcell.programs.path`) in one frame, the world or a frame
of the cell (on the shared positioner: the robots work on the part as the positioner turns
it). Point ``k`` of every path is reached at the same time, with the positioner at the same
values: the paths have as many points, or every file has a ``time`` column and the points are
matched by time (:func:`robotcell.programs.pathtime.match_by_time`). The positioner's values
(columns ``table`` or ``e1..en``) are those of the files that give them (where several give
them, they agree), or, where none does and the frame is on the positioner, chosen once for all
robots (:func:`robotcell.cell.tablechoice.choose_shared_table`). Each robot's track is its own
file's ``track`` column, or follows its path. Each robot's path
is solved through the cell as that robot sees it (:meth:`robotcell.cell.Cell.for_robot`,
:func:`robotcell.programs.write.build_programs`), and the controller writes the programs as
one coordinated program (:meth:`robotcell.controllers.base.Controller.write_coordinated`: ABB
MultiMove, a YASKAWA job of two robots and a station); a controller whose coordinated form robotcell does not write refuses, naming what
is missing. :func:`check_coordinated` reads such a program back (docs/programs.md,
"Coordinated programs").
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from robotcell.cell import Cell
from robotcell.cell.tablechoice import carried_by_table, choose_shared_table
from robotcell.controllers.base import Controller
from robotcell.controllers.registry import get
from robotcell.errors import InputError
from robotcell.programs.files import check_folder, write_all
from robotcell.programs.path import PathTargets, read_path
from robotcell.programs.pathtime import match_by_time
from robotcell.programs.write import WriteResult, build_programs

__all__ = ["CoordinatedResult", "shared_table", "write_coordinated"]


@dataclass
class CoordinatedResult:
    """What :func:`write_coordinated` wrote.

    Attributes
    ----------
    files : list of str
        The files written: one per robot (ABB: one module per task), or one for all
        (YASKAWA: one job).
    robots : list of str
        The robots in the order of the tasks (``T_ROB1``, ``T_ROB2``, ..) or groups.
    results : dict of str to WriteResult
        Each robot's solved path: joints ``q`` (rad), ``track`` (m), ``table`` (rad) per point.
    warnings : list of str
    """

    files: list[str]
    robots: list[str]
    results: dict[str, WriteResult] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)


def _robots(cell: Cell, names: Sequence[str], tools: Mapping[str, str]) -> list[str]:
    """The robots of ``names`` in the order of the cell's robots, each with a tool."""
    for name in names:
        cell.robot_key(name)
    if len(names) < 2:
        raise InputError(f"a coordinated program moves at least two robots; got "
                         f"{', '.join(names) or 'none'}")
    missing = [r for r in names if r not in tools]
    if missing:
        raise InputError(f"no tool for robot(s) {', '.join(missing)}: give one per robot "
                         "(ROBOT=TOOL)")
    return [r for r in cell.robot_names if r in names]


def shared_table(cell: Cell, targets: Mapping[str, PathTargets], frame: str,
                 tools: Mapping[str, str] | None = None) -> dict[str, PathTargets]:
    """The paths with the positioner's values of the files that give them, for every robot, or
    chosen once for all robots where no file gives them.

    Parameters
    ----------
    cell : Cell
        A cell of several robots.
    targets : mapping of str to PathTargets
        Each robot's path, as many points each (:func:`robotcell.programs.pathtime.match_by_time`
        makes paths with times so).
    frame : str
        The paths' frame.
    tools : mapping of str to str, optional
        Each robot's tool, for the choice (absent: the robot model's tool).

    Returns
    -------
    dict of str to PathTargets
        Every path with the same ``table`` (rad), given or chosen
        (:func:`robotcell.cell.tablechoice.choose_shared_table`), ``table_given`` True.

    Raises
    ------
    InputError
        Paths of different lengths; files that give different values for one point; a point
        at which no positioner values serve every robot (naming the point and the robot).
    """
    lengths = {r: len(t) for r, t in targets.items()}
    if len(set(lengths.values())) > 1:
        raise InputError("the robots' paths must have as many points each (point k of every "
                         "path is reached together): "
                         + ", ".join(f"{r} {n}" for r, n in lengths.items())
                         + "; give a time column in every file to match the points by time")
    if cell.turntable is None:
        return dict(targets)
    given = {r: t for r, t in targets.items() if t.table_given}
    if not given:
        if not carried_by_table(cell.for_robot(next(iter(targets))), frame):
            return dict(targets)
        choice = choose_shared_table(cell, {r: t.T for r, t in targets.items()}, frame,
                                     {r: t.track for r, t in targets.items()}, dict(tools or {}))
        return {r: replace(t, table=choice.table, table_given=True) for r, t in targets.items()}
    first, values = next(iter(given.items()))
    want = values.table.reshape(len(values), -1)
    for t in given.values():
        bad = np.flatnonzero(np.abs(t.table.reshape(len(t), -1) - want).max(axis=1) > 1e-9)
        if bad.size:
            raise InputError(f"{t.line(int(bad[0]))}: the positioner's values differ from those "
                             f"of {values.source} ({first}); every robot's point k is reached "
                             "at the same values")
    return {r: replace(t, table=values.table, table_given=True) for r, t in targets.items()}


#: The start of the header of a coordinated program robotcell writes.
_HEADER = "robotcell coordinated program of cell"


def _refuse_others(folder: Path, texts: dict[str, str], ctl: Controller) -> None:
    """Refuse to replace a file of the folder that is not a coordinated program robotcell
    wrote (an earlier one is replaced; its comments may wrap the header over lines)."""
    header = "".join(_HEADER.split())
    for name in texts:
        path = folder / name
        said = "".join(ctl.comments(path.read_text(errors="replace"))) if path.is_file() else ""
        if path.is_file() and header not in "".join(said.split()):
            raise InputError(f"cannot write {path}: it is a file robotcell did not write as a "
                             "coordinated program; give this program another name or folder, "
                             "or remove that file first")


def write_coordinated(paths: Mapping[str, str | Path], cell: Cell, tools: Mapping[str, str],
                      frame: str, vendor: str, folder: str | Path, name: str | None = None,
                      inputs: tuple[str | Path, ...] = (),
                      pulses_per_degree: ArrayLike | None = None) -> CoordinatedResult:
    """Write the coordinated program of several robots' paths, all of its files or none.

    Parameters
    ----------
    paths : mapping of str to str or Path
        Each robot's path file (CSV, :func:`robotcell.programs.path.read_path`) by its name in
        the cell; at least two robots.
    cell : Cell
        A cell of several robots.
    tools : mapping of str to str
        Each robot's tool (a tool of that robot in the cell).
    frame : str
        ``world`` or a frame of the cell: the frame of every path's poses.
    vendor : str
        A registered controller whose coordinated form robotcell writes (``abb``: MultiMove;
        ``yaskawa``: one job of two robots and a station).
    folder : str or Path
        Output folder (created when missing; its parent must exist).
    name : str, optional
        Program name; default: the first robot's path file's name.
    inputs : tuple of str or Path
        Further files the run read (the cell file), which no output may replace.
    pulses_per_degree : float or array_like, optional
        YASKAWA: encoder pulses per degree of each station axis.

    Returns
    -------
    CoordinatedResult

    Raises
    ------
    InputError
        A controller whose coordinated form is not written (the message names what is
        missing) or does not hold these robots (YASKAWA: two, none on a track), a robot the
        cell lacks, a missing tool, paths of different lengths without times, times in some
        files only, first or last times that differ, a time on a joint motion, a value outside
        the positioner's or a track's limits, positioner values that disagree, a point no
        positioner values serve for every robot, a bad path file, name or folder: nothing is
        written.
    robotcell.programs.write.PathBreaks
        A robot's path cannot be one program (reach, limits, singularity): nothing is written.
    """
    check_folder(folder)
    ctl = get(vendor, "program format")
    if ctl.coordinated_missing is not None:
        raise ctl.coordinated_refusal()
    robots = _robots(cell, list(paths), tools)
    ctl.coordinated_robots(cell, robots)
    read = {r: read_path(paths[r], cell.for_robot(r)) for r in robots}
    targets = shared_table(cell, match_by_time(read), frame, tools)
    if name is None:
        name = ctl.default_name(Path(paths[robots[0]]).stem)
    results = {r: build_programs(cell.for_robot(r), targets[r], ctl.name, name, tools[r], frame,
                                 pulses_per_degree=pulses_per_degree) for r in robots}
    header = [f"{_HEADER} {cell.name!r}, frame {frame!r}: "
              + ", ".join(f"{r}: path {Path(paths[r]).name}, tool {tools[r]!r}" for r in robots)]
    texts = ctl.write_coordinated([results[r].programs[0] for r in robots], header)
    _refuse_others(Path(folder), texts, ctl)
    files = write_all(folder, texts, (*paths.values(), *inputs))
    warnings = [w for r in robots for w in targets[r].warnings]
    return CoordinatedResult(files, robots, results, warnings)
