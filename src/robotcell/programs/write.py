"""From a path through the cell to the controller's program files.

:func:`write_program` reads a path (:mod:`robotcell.programs.path`), solves it as one joint
trajectory through the cell (:func:`robotcell.cell.ik.ik_path`: one arm configuration, the track
moving along the path where it is not given, the table's values chosen along a path on the table
where they are not given: :func:`robotcell.cell.tablechoice.choose_table`), builds the
:class:`~robotcell.controllers.model.Program` of one format and writes its files, all or none. A
path that cannot be one program (out of reach, a joint limit, a configuration change, a jump of
the table) raises :class:`PathBreaks` naming the points and why; with ``split`` every
continuous piece becomes its own program (a path with no piece, no point reached, raises all
the same).

The Cartesian values a program holds come from one function, :func:`written_poses`: the pose of
the TCP, computed from the joints by the FK of the cell's controller model (the nominal arm of a
cell with an identified one: :meth:`~robotcell.cell.model.Cell.controller`; or of a given
``controller`` cell), in the frame the program measures its points in. Joints solved on the
identified arm and written through the nominal one are filtered points (docs/accuracy.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell
from robotcell.cell.ik import MAX_STEP, CellPath, PathBreak, ik_path, split_path
from robotcell.cell.kinematics import tool_pose
from robotcell.cell.tablechoice import TableChoice, carried_by_table, choose_table
from robotcell.controllers.axes import ExternalAxes
from robotcell.controllers.base import Controller
from robotcell.controllers.model import Program, ProgramPoint, Ref
from robotcell.controllers.registry import get
from robotcell.errors import InputError, RobotcellError
from robotcell.io.fileio import read_text
from robotcell.kinematics.transforms import invert
from robotcell.programs.config import configs
from robotcell.programs.files import check_folder, write_all
from robotcell.programs.frames import Placement, program_refs
from robotcell.programs.path import PathTargets, read_path

__all__ = ["PathBreaks", "ProgramOptions", "WriteResult", "build_programs", "write_program",
           "written_poses"]


@dataclass(frozen=True)
class ProgramOptions:
    """How a path is solved into programs and whose model writes their Cartesian values.

    Attributes
    ----------
    split : bool
        Write one program per continuous piece instead of refusing a path that breaks.
    controller : Cell, optional
        The cell whose FK gives the Cartesian values written (default ``cell.controller()``: the
        cell itself, or with an identified arm the cell with its nominal arm, so that the
        controller's own model takes the written points to the joints solved on the real arm).
    max_step : float
        Largest joint change between consecutive targets that counts as continuous (rad).
    """

    split: bool = False
    controller: Cell | None = None
    max_step: float = MAX_STEP


@dataclass(frozen=True)
class _Format:
    """What every program of a path shares: its controller, the references of its tool and
    frame, where its frame is (:func:`robotcell.programs.frames.program_refs`) and how its
    external axes are written."""

    ctl: Controller
    tool_ref: Ref
    frame_ref: Ref
    where: Placement
    axes: ExternalAxes


class PathBreaks(RobotcellError):
    """A path that cannot be one program; ``breaks`` say where and why.

    Attributes
    ----------
    breaks : list of PathBreak
        ``index`` 0-based target, ``kind`` (reach, limit, singularity) and the cause.
    """

    def __init__(self, message: str, breaks: list[PathBreak]) -> None:
        super().__init__(message)
        self.breaks = breaks


@dataclass
class WriteResult:
    """What :func:`write_program` wrote.

    Attributes
    ----------
    files : list of str
        Paths written (empty when nothing was written).
    programs : list of Program
        One program, or one per piece with ``split``.
    q : ndarray, shape (N, 6)
        Arm joints per path target (rad; NaN for targets in no program).
    track : ndarray, shape (N,)
        Track values (m).
    table : ndarray, shape (N,) or (N, n)
        Table values (rad).
    breaks : list of PathBreak
        Where the path breaks (empty for one program).
    program_of : ndarray of int, shape (N,)
        Index into ``programs`` of each target (-1: in none).
    warnings : list of str
    replaced : list of str
        Files written over: earlier programs of the same path file, under the same names.
    """

    files: list[str]
    programs: list[Program]
    q: NDArray[np.float64]
    track: NDArray[np.float64]
    table: NDArray[np.float64]
    breaks: list[PathBreak] = field(default_factory=list)
    program_of: NDArray[np.int_] = field(default_factory=lambda: np.zeros(0, dtype=int))
    warnings: list[str] = field(default_factory=list)
    replaced: list[str] = field(default_factory=list)


def written_poses(cell: Cell, where: Placement, q: ArrayLike, track: ArrayLike,
                  table: ArrayLike, tool: ArrayLike) -> NDArray[np.float64]:
    """The Cartesian poses a program writes for joint values: the TCP in the program's frame.

    ``T_X_TCP = inv(T_world_X(e, v)) T_world_R(e) T_R_TCP(q)`` with the FK of ``cell``. This is
    the one place where joints become the numbers of a Cartesian point; pass the controller's
    own model as ``cell`` to write what the controller computes from the same joints.

    Parameters
    ----------
    cell : Cell
    where : Placement
        The program's frame (:func:`robotcell.programs.frames.program_refs`).
    q : array_like, shape (N, 6)
        Arm joints (rad).
    track : array_like, shape (N,)
        Track values (m).
    table : array_like, shape (N,) or (N, n)
        Table values (rad).
    tool : array_like, shape (4, 4)
        ``T_F_TCP`` (m).

    Returns
    -------
    ndarray, shape (N, 4, 4)
        Metres.
    """
    T_world_TCP = cell.fk(q, track, table, tool=np.asarray(tool, dtype=float))
    return invert(where.world(cell, track, table)) @ T_world_TCP


def _with_table(cell: Cell, targets: PathTargets, frame: str, tool: str, max_step: float
                ) -> tuple[PathTargets, TableChoice | None]:
    """The targets with the table's values chosen where the file gives none and the path's
    frame is on the table; and the choice (None when nothing was chosen)."""
    if targets.table_given or not carried_by_table(cell, frame):
        return targets, None
    choice = choose_table(cell, targets.T, frame, targets.track, tool, max_step)
    return replace(targets, table=choice.table, table_given=True), choice


def _noted(breaks: list[PathBreak], choice: TableChoice | None) -> list[PathBreak]:
    """Breaks at a point no table value the choice tried reaches say so (whatever the values
    the path is then solved at make of it: out of reach, or reached outside the limits)."""
    if choice is None:
        return breaks
    return [replace(b, message=f"{b.message}; {note}")
            if (note := choice.unreached(b.index)) else b for b in breaks]


def _solve(cell: Cell, targets: PathTargets, frame: str, tool: str, max_step: float
           ) -> tuple[list[tuple[int, int]], list[PathBreak], list[CellPath]]:
    """Continuous pieces of the path, where it breaks, and each piece's joint trajectory."""
    motion = "moving" if targets.track is None and cell.track is not None else "fixed"
    kw = {"frame": frame, "tool": tool, "max_step": max_step, "track_motion": motion}
    # A path or a piece of one target is solved as two identical targets, then cut back to one.
    n = len(targets)
    rows = np.arange(n) if n > 1 else np.zeros(2, dtype=int)
    split = split_path(cell, targets.T[rows], table=targets.table[rows],
                       track=None if targets.track is None else targets.track[rows], **kw)
    segments = split.segments if n > 1 else [(0, 1)] * len(split.segments)
    breaks = split.breaks if n > 1 else split.breaks[:1]
    paths = []
    for a, b in segments:
        idx = np.arange(a, b) if b - a > 1 else np.array([a, a])
        # the piece at the track values split_path followed it with (a moving track chosen
        # for the piece alone would differ at its ends)
        track = None if cell.track is None else split.track[idx]
        path = ik_path(cell, targets.T[idx], track=track, table=targets.table[idx], **kw)
        paths.append(path if b - a > 1 else replace(path, q=path.q[:1], track=path.track[:1],
                                                    table=path.table[:1]))
    return segments, breaks, paths


def build_programs(cell: Cell, targets: PathTargets, vendor: str, name: str, tool: str,
                   frame: str, options: ProgramOptions = ProgramOptions(),
                   pulses_per_degree: ArrayLike | None = None) -> WriteResult:
    """Solve a path through the cell and build its program(s), without writing files.

    Parameters
    ----------
    cell : Cell
        The cell the joints are solved in.
    targets : PathTargets
    vendor : str
        A registered controller (:func:`robotcell.controllers.registry.names`).
    name : str
        Program name (``NAME_1``, ``NAME_2``, ... with ``options.split``).
    tool : str
        A tool of the cell.
    frame : str
        The path's frame: ``world`` or a frame of the cell.
    options : ProgramOptions
        Pieces or one program, the controller's model, the largest joint step (rad).
    pulses_per_degree : float or array_like, optional
        YASKAWA: encoder pulses per degree of each station axis.

    Returns
    -------
    WriteResult
        With ``files`` empty.

    Raises
    ------
    InputError
        A tool or frame the cell lacks, a tool or frame number or a name the controller cannot
        hold, a YASKAWA cell with a turntable and no ``pulses_per_degree``.
    PathBreaks
        The path breaks (reach, limit, singularity, a jump of the table) and ``options.split``
        is False, or no point of it can be reached.
    """
    ctl = get(vendor, "program format")
    base_name = ctl.program_name(name)
    fmt = _Format(ctl, *program_refs(cell, ctl.name, tool, frame),
                  ctl.external_axes(cell, pulses_per_degree))
    targets, choice = _with_table(cell, targets, frame, tool, options.max_step)
    targets = replace(targets, table=fmt.axes.held(targets.table))  # the point goes with the axis
    pieces, breaks, paths = _solve(cell, targets, frame, tool, options.max_step)
    breaks = _noted(breaks, choice)
    n = len(targets)
    nt = targets.table.shape[1:] if targets.table.ndim > 1 else ()
    q = np.full((n, cell.robot.n_joints), np.nan)
    track, table = np.full(n, np.nan), np.full((n, *nt), np.nan)
    owner = np.full(n, -1)
    if breaks and (not options.split or not pieces):
        raise PathBreaks(_break_message(breaks, pieces), breaks)
    programs = []
    for k, ((a, b), path) in enumerate(zip(pieces, paths)):
        q[a:b], track[a:b], table[a:b] = path.q, path.track, path.table
        owner[a:b] = k
        pname = base_name if len(pieces) == 1 else ctl.piece_name(base_name, k + 1)
        programs.append(_program(options.controller or cell.controller(), targets, (a, b), path,
                                 pname, fmt))
    return WriteResult([], programs, q, track, table, breaks, owner, list(targets.warnings))


#: Breaks a :class:`PathBreaks` message names (``breaks`` holds them all).
NAMED_BREAKS = 5


def _break_message(breaks: list[PathBreak], pieces: list[tuple[int, int]]) -> str:
    where = "; ".join(f"point {b.index + 1} ({b.kind}): {b.message}"
                      for b in breaks[:NAMED_BREAKS])
    if len(breaks) > NAMED_BREAKS:
        where += f"; and {len(breaks) - NAMED_BREAKS} more"
    if not pieces:
        return (f"no point of the path can be reached: {where}. There is nothing to write, in "
                "one program or in pieces: check the frame and the tool of the path, its units "
                "(mm, deg) and where it lies in the cell")
    if len(pieces) == 1:
        (a, b), = pieces
        todo = f"write its one good piece (points {a + 1} to {b}) with split"
    else:
        todo = f"write {len(pieces)} programs, one per piece, with split"
    return (f"the path cannot be one program: it breaks at {len(breaks)} "
            f"point{'' if len(breaks) == 1 else 's'}: {where}. "
            f"Change the path there, or {todo}")


def _program(cell: Cell, targets: PathTargets, piece: tuple[int, int], path: CellPath,
             name: str, fmt: _Format) -> Program:
    """The program of the targets ``piece`` (first, end) of the path, solved as ``path``, with
    the Cartesian values of ``cell``'s FK."""
    a, b = piece
    T_tool = tool_pose(cell, fmt.tool_ref.name)
    poses = written_poses(cell, fmt.where, path.q, path.track, path.table, T_tool)
    flags = configs(cell.robot, path.q, fmt.ctl.name)
    names = fmt.ctl.point_names(b - a)
    points = []
    for i in range(b - a):
        j = a + i
        motion = targets.motion[j]
        points.append(ProgramPoint(
            names[i], 0, motion, fmt.tool_ref, fmt.frame_ref, pose=poses[i], config=flags[i],
            external=fmt.axes.to_file(path.track[i], path.table[i]),
            speed=float(targets.speed[j]),
            zone=float(targets.zone[j])))
    return Program(name, fmt.ctl.name, points, data=fmt.ctl.data(cell))

def write_program(path: str | Path, cell: Cell, tool: str, frame: str, vendor: str,
                  folder: str | Path, name: str | None = None,
                  options: ProgramOptions = ProgramOptions(),
                  pulses_per_degree: ArrayLike | None = None,
                  inputs: tuple[str | Path, ...] = ()) -> WriteResult:
    """Write the program of a path file, all of its files or none.

    Parameters
    ----------
    path : str or Path
        The path CSV (:func:`robotcell.programs.path.read_path`).
    cell : Cell
    tool : str
        A tool of the cell.
    frame : str
        ``world`` or a frame of the cell: the frame of the path's poses.
    vendor : str
        A registered controller (:func:`robotcell.controllers.registry.names`).
    folder : str or Path
        Output folder (created when missing; its parent must exist). A program of the same
        path file written there before under the same name is replaced (and listed in
        ``replaced``); any other file of that name, or of that name in other capitals (a
        controller does not tell them apart), is refused.
    name : str, optional
        Program name; default: the path file's name, shortened to what the format allows.
    options : ProgramOptions
        One program or one per continuous piece (``split``), the cell whose FK writes the
        Cartesian values (``controller``), the largest joint step (``max_step``, rad); e.g.
        ``ProgramOptions(split=True)``.
    pulses_per_degree : float or array_like, optional
        YASKAWA: encoder pulses per degree of each station axis.
    inputs : tuple of str or Path
        Further files the run read (the cell file), which no output may replace.

    Returns
    -------
    WriteResult

    Raises
    ------
    InputError
        Bad path file, tool, frame, name or folder, or a file of the program's name in the
        folder that is not an earlier program of this path file: nothing is written.
    PathBreaks
        The path breaks and ``options.split`` is False, or no point of it can be reached:
        nothing is written.
    """
    check_folder(folder)
    ctl = get(vendor, "program format")
    targets = read_path(path, cell)
    default = name is None
    if name is None:
        name = ctl.default_name(Path(path).stem)
    result = build_programs(cell, targets, ctl.name, name, tool, frame, options,
                            pulses_per_degree)
    header = [(f"robotcell program of path {Path(path).name}: cell {cell.name!r}, "
               f"tool {tool!r}, frame {frame!r}")]
    texts: dict[str, str] = {}
    for prog in result.programs:
        texts.update(ctl.write_program(prog, header))
    cut = (f" ({ctl.label} program names hold {ctl.name_limit} characters, so "
           f"{Path(path).name} is written as {result.programs[0].name})"
           if default and len(Path(path).stem) > ctl.name_limit else "")
    result.replaced = _replaced(Path(folder), texts, ctl, Path(path).name, cut, (path, *inputs))
    result.files = write_all(folder, texts, (path, *inputs))
    return result


#: The start of the header line of a program written from a path file, then its name and ':'.
_SOURCE = "robotcell program of path "


def _squeezed(text: str) -> str:
    return "".join(text.split())


def _replaced(folder: Path, texts: dict[str, str], ctl: Controller, source: str, cut: str,
              inputs: tuple[str | Path, ...]) -> list[str]:
    """The files of ``texts`` that are in ``folder`` already: earlier programs of the path file
    ``source``. Any other file of one of the names, or of one in other capitals, is refused
    (the ``inputs`` of the run are left to :func:`~robotcell.programs.files.write_all`, which
    refuses them).

    Raises
    ------
    InputError
        A file the program would replace that is not a program of ``source``; the message
        names it, and the source it was written from where it says so.
    """
    if not folder.is_dir():
        return []
    read = {Path(i).resolve() for i in inputs}
    present = {p.name: p for p in folder.iterdir() if p.resolve() not in read}
    replaced = []
    for name in texts:
        other = next((p for n, p in present.items() if n.lower() == name.lower() and n != name),
                     None)
        if other is not None:
            raise InputError(f"cannot write {folder / name}: {other} is there, and a controller "
                             "takes the two names for one program; remove or rename it, or give "
                             "this program another name or folder")
        if name not in present or present[name].is_dir():
            continue
        try:
            said = _squeezed("".join(ctl.comments(read_text(present[name], "program file"))))
        except InputError:  # not text: not a program robotcell wrote
            said = ""
        if _squeezed(f"{_SOURCE}{source}:") in said:
            replaced.append(str(present[name]))
            continue
        start = said.find(_squeezed(_SOURCE))
        origin = (f"a program written from {said[start:].split(':')[0][len(_squeezed(_SOURCE)):]}"
                  if start >= 0 else f"a file robotcell did not write from {source}")
        raise InputError(f"cannot write {folder / name}: it is {origin}, and this program of "
                         f"{source} would replace it{cut}; give this program another name or "
                         "folder, or remove that file first")
    return replaced
