"""From a path through the cell to the controller's program files.

:func:`write_program` reads a path (:mod:`robotcell.programs.path`), solves it as one joint
trajectory through the cell (:func:`robotcell.cell.ik.ik_path`: one arm configuration, the track
moving along the path where it is not given, the table's values chosen along a path on the table
where they are not given: :func:`robotcell.cell.tablechoice.choose_table`), builds the
:class:`~robotcell.programs.model.Program` of one format and writes its files, all or none. A
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
from robotcell.errors import RobotcellError
from robotcell.kinematics.transforms import invert
from robotcell.programs.axes import ExternalAxes, external_axes
from robotcell.programs.config import configs
from robotcell.programs.files import check_folder, write_all
from robotcell.programs.formats import format_module
from robotcell.programs.frames import Placement, program_refs
from robotcell.programs.model import Program, ProgramPoint, Ref
from robotcell.programs.path import PathTargets, read_path
from robotcell.programs.text import NAME_LIMITS, program_name

__all__ = ["PathBreaks", "WriteResult", "build_programs", "point_names", "write_program",
           "written_poses"]

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
    """

    files: list[str]
    programs: list[Program]
    q: NDArray[np.float64]
    track: NDArray[np.float64]
    table: NDArray[np.float64]
    breaks: list[PathBreak] = field(default_factory=list)
    program_of: NDArray[np.int_] = field(default_factory=lambda: np.zeros(0, dtype=int))
    warnings: list[str] = field(default_factory=list)


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


def point_names(vendor: str, n: int) -> list[str]:
    """Names of ``n`` points as each format numbers them (``XP1``, ``p1``, ``P[1]``, ``C00000``)."""
    if vendor == "kuka":
        return [f"XP{i + 1}" for i in range(n)]
    if vendor == "abb":
        return [f"p{i + 1}" for i in range(n)]
    if vendor == "fanuc":
        return [f"P[{i + 1}]" for i in range(n)]
    return [f"C{i:05d}" for i in range(n)]


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
                   frame: str, split: bool = False, controller: Cell | None = None,
                   pulses_per_degree: ArrayLike | None = None, max_step: float = MAX_STEP
                   ) -> WriteResult:
    """Solve a path through the cell and build its program(s), without writing files.

    Parameters
    ----------
    cell : Cell
        The cell the joints are solved in.
    targets : PathTargets
    vendor : {"kuka", "abb", "fanuc", "yaskawa"}
    name : str
        Program name (``NAME_1``, ``NAME_2``, ... with ``split``).
    tool : str
        A tool of the cell.
    frame : str
        The path's frame: ``world`` or a frame of the cell.
    split : bool
        Write one program per continuous piece instead of refusing a path that breaks.
    controller : Cell, optional
        The cell whose FK gives the Cartesian values written (default ``cell.controller()``: the
        cell itself, or with an identified arm the cell with its nominal arm, so that the
        controller's own model takes the written points to the joints solved on the real arm).
    pulses_per_degree : float or array_like, optional
        YASKAWA: encoder pulses per degree of each station axis.
    max_step : float
        Largest joint change between consecutive targets that counts as continuous (rad).

    Returns
    -------
    WriteResult
        With ``files`` empty.

    Raises
    ------
    InputError
        A tool or frame the cell lacks, a bad name, a YASKAWA cell with a turntable and no
        ``pulses_per_degree``.
    PathBreaks
        The path breaks (reach, limit, singularity, a jump of the table) and ``split`` is False,
        or no point of it can be reached.
    """
    base_name = program_name(name, vendor)
    tool_ref, frame_ref, where = program_refs(cell, vendor, tool, frame)
    axes = external_axes(cell, vendor, pulses_per_degree)
    targets, choice = _with_table(cell, targets, frame, tool, max_step)
    targets = replace(targets, table=axes.held(targets.table))  # the point goes with the axis
    pieces, breaks, paths = _solve(cell, targets, frame, tool, max_step)
    breaks = _noted(breaks, choice)
    n = len(targets)
    nt = targets.table.shape[1:] if targets.table.ndim > 1 else ()
    q = np.full((n, cell.robot.n_joints), np.nan)
    track, table = np.full(n, np.nan), np.full((n, *nt), np.nan)
    owner = np.full(n, -1)
    if breaks and (not split or not pieces):
        raise PathBreaks(_break_message(breaks, pieces), breaks)
    programs = []
    for k, ((a, b), path) in enumerate(zip(pieces, paths)):
        q[a:b], track[a:b], table[a:b] = path.q, path.track, path.table
        owner[a:b] = k
        pname = base_name if len(pieces) == 1 else _piece_name(base_name, k + 1, vendor)
        programs.append(_program(controller or cell.controller(), targets, a, b, path, pname,
                                 vendor, tool_ref, frame_ref, where, axes))
    return WriteResult([], programs, q, track, table, breaks, owner, list(targets.warnings))


def _piece_name(name: str, k: int, vendor: str) -> str:
    suffix = f"_{k}"
    return program_name(name[:NAME_LIMITS[vendor] - len(suffix)] + suffix, vendor)


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


def _program(cell: Cell, targets: PathTargets, a: int, b: int, path: CellPath, name: str, vendor: str,
             tool_ref: Ref, frame_ref: Ref, where: Placement, axes: ExternalAxes) -> Program:
    T_tool = tool_pose(cell, tool_ref.name)
    poses = written_poses(cell, where, path.q, path.track, path.table, T_tool)
    flags = configs(cell.robot, path.q, vendor)
    names = point_names(vendor, b - a)
    points = []
    for i in range(b - a):
        j = a + i
        motion = targets.motion[j]
        points.append(ProgramPoint(
            names[i], 0, motion, tool_ref, frame_ref, pose=poses[i], config=flags[i],
            external=axes.to_file(path.track[i], path.table[i]),
            speed=float(targets.speed[j]),
            zone=float(targets.zone[j])))
    return Program(name, vendor, points)


def write_program(path: str | Path, cell: Cell, tool: str, frame: str, vendor: str,
                  folder: str | Path, name: str | None = None, split: bool = False,
                  controller: Cell | None = None, pulses_per_degree: ArrayLike | None = None,
                  max_step: float = MAX_STEP, inputs: tuple[str | Path, ...] = ()
                  ) -> WriteResult:
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
    vendor : {"kuka", "abb", "fanuc", "yaskawa"}
    folder : str or Path
        Output folder (created when missing; its parent must exist).
    name : str, optional
        Program name; default: the path file's name, shortened to what the format allows.
    split, controller, pulses_per_degree, max_step
        As for :func:`build_programs`.
    inputs : tuple of str or Path
        Further files the run read (the cell file), which no output may replace.

    Returns
    -------
    WriteResult

    Raises
    ------
    InputError
        Bad path file, tool, frame, name or folder: nothing is written.
    PathBreaks
        The path breaks and ``split`` is False, or no point of it can be reached: nothing is
        written.
    """
    check_folder(folder)
    targets = read_path(path, cell)
    if name is None:
        name = _default_name(Path(path).stem, vendor)
    result = build_programs(cell, targets, vendor, name, tool, frame, split, controller,
                            pulses_per_degree, max_step)
    header = [(f"robotcell program of path {Path(path).name}: cell {cell.name!r}, "
               f"tool {tool!r}, frame {frame!r}")]
    module = format_module(vendor)
    texts: dict[str, str] = {}
    for prog in result.programs:
        texts.update(module.write(prog, header))
    result.files = write_all(folder, texts, (path, *inputs))
    return result


def _default_name(stem: str, vendor: str) -> str:
    clean = "".join(ch if ch.isalnum() and ch.isascii() else "_" for ch in stem)
    if not clean[:1].isalpha():
        clean = "P" + clean
    return clean[:NAME_LIMITS[vendor]]
