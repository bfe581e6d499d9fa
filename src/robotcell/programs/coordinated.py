"""Coordinated programs: several robots of a cell moving through their paths together.

Each robot has a path file (:mod:`robotcell.programs.path`) in one frame, the world or a frame
of the cell (on the shared positioner: the robots work on the part as the positioner turns
it). Point ``k`` of every path is reached at the same time, with the positioner at the same
values: the paths have as many points, and the positioner's values (columns ``table`` or
``e1..en``) are given in at least one of the files (where several give them, they agree).
Each robot's track is its own file's ``track`` column, or follows its path. Each robot's path
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
from robotcell.cell.tablechoice import carried_by_table
from robotcell.controllers.base import Controller
from robotcell.controllers.registry import get
from robotcell.errors import InputError
from robotcell.programs.files import check_folder, write_all
from robotcell.programs.path import PathTargets, read_path
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


def shared_table(cell: Cell, targets: Mapping[str, PathTargets], frame: str
                 ) -> dict[str, PathTargets]:
    """The paths with the positioner's values of the files that give them, for every robot.

    Raises
    ------
    InputError
        Paths of different lengths; files that give different values for one point; no file
        giving the values of a positioner that carries the paths' frame.
    """
    lengths = {r: len(t) for r, t in targets.items()}
    if len(set(lengths.values())) > 1:
        raise InputError("the robots' paths must have as many points each (point k of every "
                         "path is reached together): "
                         + ", ".join(f"{r} {n}" for r, n in lengths.items()))
    if cell.turntable is None:
        return dict(targets)
    given = {r: t for r, t in targets.items() if t.table_given}
    if not given:
        if carried_by_table(cell.for_robot(next(iter(targets))), frame):
            raise InputError(f"frame {frame!r} is on positioner {cell.turntable.name!r}: give "
                             "its values (columns table or e1..en, deg) in at least one path "
                             "file; a coordinated program does not choose them")
        return dict(targets)
    first, values = next(iter(given.items()))
    want = values.table.reshape(len(values), -1)
    for t in given.values():
        bad = np.flatnonzero(np.abs(t.table.reshape(len(t), -1) - want).max(axis=1) > 1e-9)
        if bad.size:
            raise InputError(f"{t.source}: line {bad[0] + 2}: the positioner's values differ "
                             f"from those of {values.source} ({first}); every robot's point k "
                             "is reached at the same values")
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
        cell lacks, a missing tool, paths of different lengths, a value
        outside the positioner's or a track's limits, positioner values not given or
        disagreeing, a bad path file, name or folder: nothing is written.
    robotcell.programs.write.PathBreaks
        A robot's path cannot be one program (reach, limits, singularity): nothing is written.
    """
    check_folder(folder)
    ctl = get(vendor, "program format")
    if ctl.coordinated_missing is not None:
        raise ctl.coordinated_refusal()
    robots = _robots(cell, list(paths), tools)
    ctl.coordinated_robots(cell, robots)
    targets = shared_table(cell, {r: read_path(paths[r], cell.for_robot(r)) for r in robots},
                           frame)
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
