"""The robot cell: robot, linear track, turntable or positioner, tools and frames.

A cell file is written in millimetres and degrees (see ``docs/cell.md`` for the schema); a
:class:`Cell` holds the same content in SI units. Poses in the file are mappings
``{x, y, z, a, b, c}`` with ``R = Rz(a) Ry(b) Rx(c)`` (the KUKA convention, as in robot model
files). Every calibrated quantity carries its :class:`~robotcell.cell.parts.Provenance`; the
parts of a cell are :mod:`robotcell.cell.parts`.

The file (YAML schema, reader, writer, atomic save with numbered backups) is
:mod:`robotcell.cell.schema`, below this module: :func:`cell_from_dict` builds a cell from what
it reads, and :meth:`Cell.load` and :meth:`Cell.save` call them. :meth:`Cell.save` writes
atomically: a process that dies during a save leaves either the old or the new file, never a
partial one.

Coupled kinematics (TCP pose in any frame given the arm joints, the track position and the table
angle) are in :mod:`robotcell.cell.kinematics`; :meth:`Cell.fk` and :meth:`Cell.frame_pose` call
them, and :meth:`Cell.ik` and :meth:`Cell.ik_path` call :mod:`robotcell.cell.ik`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import kinematics
from robotcell.cell.kinematics import RESERVED_FRAMES
from robotcell.cell.parts import (
    Frame,
    IdentifiedArm,
    Positioner,
    Provenance,
    Tool,
    Track,
    Turntable,
    check_identified,
    check_name,
    single_pose,
)
from robotcell.cell.schema import cell_fields, read_cell_file, save_cell
from robotcell.cell.validation import check_lengths
from robotcell.errors import InputError
from robotcell.kinematics.transforms import validate_pose
from robotcell.robot.robot import Robot

if TYPE_CHECKING:
    from robotcell.cell.ik import CellIKSolutions, CellPath

__all__ = ["IK_CHUNK", "RESERVED_FRAMES", "Cell", "cell_from_dict"]

#: Targets per call of :meth:`Cell.ik` in :meth:`Cell.ik_batch`: bounds the memory of a long list.
IK_CHUNK = 500


# -- the cell -------------------------------------------------------------------------------------
@dataclass
class Cell:
    """A robot cell in SI units.

    Attributes
    ----------
    robot : Robot
        The arm. Its default tool applies when :meth:`fk` gets no tool.
    robot_model : str
        How the cell file names the robot: a library name, or the path of a model file (absolute,
        or relative to the working directory).
    T_world_R : ndarray, shape (4, 4)
        Pose of the robot base in the world for a cell without track (metres).
    track : Track or None
    turntable : Turntable or Positioner or None
        What carries the work: a one-axis turntable or a positioner chain of 1-3 axes (also
        :attr:`positioner`). Frames with parent ``turntable`` are carried by its last axis.
    tools : dict of str to Tool
    frames : dict of str to Frame
    name : str
    identified : IdentifiedArm or None
        Set when ``robot`` is an identified arm: then ``robot`` says where the TCP goes (FK, IK,
        reach, checks, touches given as joint values) and ``identified.nominal``, the controller's
        model, turns joint values into what the controller is told (:meth:`controller`).
        ``robot`` carries the nominal's tool, and the nominal as its ``ik_seed`` when its model
        file names none (a model written by another tool): its IK branches are the nominal's.
    """

    robot: Robot
    robot_model: str
    T_world_R: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    track: Track | None = None
    turntable: Turntable | Positioner | None = None
    tools: dict[str, Tool] = field(default_factory=dict)
    frames: dict[str, Frame] = field(default_factory=dict)
    name: str = "cell"
    identified: IdentifiedArm | None = None

    def __post_init__(self) -> None:
        self.T_world_R = single_pose(self.T_world_R, "robot T_world_R")
        if self.identified is not None:
            check_identified(self.identified.nominal, self.robot)
            if not np.array_equal(self.robot.tool, self.identified.nominal.tool):
                self.robot = self.robot.with_tool(self.identified.nominal.tool)
            if self.robot.ik_seed is None:  # a model from another tool: the nominal seeds its IK
                self.robot = replace(self.robot, ik_seed=self.identified.nominal)
        if self.track is not None and not np.allclose(self.T_world_R, np.eye(4), atol=0):
            raise InputError("a robot on a track is placed by the track (track frame and "
                             "robot_at_zero); do not give the robot a frame as well")
        for name in self.tools:
            check_name(name, "tool")
        for name, fr in self.frames.items():
            check_name(name, "frame")
            self._check_parent(name, fr)
        _unique_numbers({k: t.number for k, t in self.tools.items()}, "tool")
        _unique_numbers({k: f.number for k, f in self.frames.items()}, "frame")

    @property
    def nominal_robot(self) -> Robot:
        """The model the controller computes with: the nominal of an identified arm, else ``robot``."""
        return self.robot if self.identified is None else self.identified.nominal

    def controller(self) -> Cell:
        """The cell as the controller computes it: with the nominal arm (``self`` without an
        identified one). Its FK of joint values is what a program's Cartesian point says."""
        if self.identified is None:
            return self
        return replace(self, robot=self.identified.nominal, identified=None)

    def set_identified(self, robot: Robot, model: str, provenance: Provenance) -> None:
        """Make ``robot`` (an identification of the cell's arm) the arm the cell computes with.

        Parameters
        ----------
        robot : Robot
            The identified model (e.g. ``IdentificationResult.robot``).
        model : str
            The model file it is (or will be) saved as; the cell file names it.
        provenance : Provenance

        Raises
        ------
        InputError
            ``robot`` is not an identification of the cell's nominal arm (:func:`check_identified`).
        """
        nominal = self.nominal_robot
        check_identified(nominal, robot)
        self.identified = IdentifiedArm(nominal, model, provenance)
        self.robot = robot.with_tool(nominal.tool)

    @property
    def positioner(self) -> Turntable | Positioner | None:
        """The external axes carrying the work (the same object as :attr:`turntable`)."""
        return self.turntable

    def _check_parent(self, name: str, fr: Frame) -> None:
        if fr.parent == "turntable" and self.turntable is None:
            raise InputError(f"frame {name!r} is carried by the turntable, but the cell has none")

    # -- editing (used by calibration commands) -------------------------------------------------
    def set_tool(self, name: str, T_F_TCP: ArrayLike, provenance: Provenance,
                 number: int | None = None, mass: float | None = None,
                 cog: ArrayLike | None = None) -> Tool:
        """Add or replace a tool; an existing tool keeps its number and load unless given.

        Parameters
        ----------
        name : str
            Tool name (letter, then letters, digits, ``_``; at most 24 characters).
        T_F_TCP : array_like, shape (4, 4)
            Pose of the TCP in the flange frame (metres).
        provenance : Provenance
        number : int, optional
            Controller slot.
        mass : float, optional
            Tool mass (kg).
        cog : array_like, shape (3,), optional
            Centre of gravity in the flange frame (metres).

        Returns
        -------
        Tool
        """
        check_name(name, "tool")
        old = self.tools.get(name)
        tool = Tool(
            T_F_TCP=np.asarray(T_F_TCP, dtype=float),
            number=number if number is not None else (old.number if old else None),
            mass=mass if mass is not None else (old.mass if old else None),
            cog=np.asarray(cog, dtype=float) if cog is not None else (old.cog if old else None),
            provenance=provenance,
        )
        _unique_numbers({**{k: t.number for k, t in self.tools.items()}, name: tool.number}, "tool")
        self.tools[name] = tool
        return tool

    def update_frame(self, name: str, pose: ArrayLike, provenance: Provenance,
                     parent: Literal["world", "robot", "turntable"] | None = None,
                     number: int | None = None) -> Frame:
        """Add or replace a frame; an existing frame keeps its parent and number unless given.

        Parameters
        ----------
        name : str
            Frame name (not one of ``world``, ``track``, ``L``, ``robot``, ``R``,
            ``turntable``, ``B``).
        pose : array_like, shape (4, 4)
            Pose of the frame in its parent (metres); in B at table angle 0 for a frame on the
            turntable.
        provenance : Provenance
        parent : {"world", "robot", "turntable"}, optional
            Default: the existing frame's parent, else ``world``.
        number : int, optional
            Controller slot.

        Returns
        -------
        Frame
        """
        check_name(name, "frame")
        old = self.frames.get(name)
        fr = Frame(
            pose=np.asarray(pose, dtype=float),
            parent=parent or (old.parent if old else "world"),
            number=number if number is not None else (old.number if old else None),
            provenance=provenance,
        )
        self._check_parent(name, fr)
        _unique_numbers({**{k: f.number for k, f in self.frames.items()}, name: fr.number}, "frame")
        self.frames[name] = fr
        return fr

    def update_track(self, provenance: Provenance, **changes: Any) -> Track:
        """Replace fields of the track (``T_world_L``, ``T_L_R0``, ``axis``, ``scale``, ...).

        Parameters
        ----------
        provenance : Provenance
            Provenance of the new track calibration.
        **changes
            :class:`Track` attributes to change (SI units).

        Returns
        -------
        Track
        """
        if self.track is None:
            raise InputError("the cell has no track to update")
        self.track = replace(self.track, provenance=provenance, **changes)
        return self.track

    def update_turntable(self, provenance: Provenance, **changes: Any) -> Turntable:
        """Replace fields of the turntable (``T_parent_B``, ``parent``, limits, ``name``).

        Parameters
        ----------
        provenance : Provenance
            Provenance of the new turntable calibration.
        **changes
            :class:`Turntable` attributes to change (SI units).

        Returns
        -------
        Turntable
        """
        if not isinstance(self.turntable, Turntable):
            raise InputError("the cell has no turntable to update" if self.turntable is None else
                             "the cell's positioner is an axis chain: use update_positioner")
        self.turntable = replace(self.turntable, provenance=provenance, **changes)
        return self.turntable

    def update_positioner(self, provenance: Provenance, chain: Robot) -> Positioner:
        """Write a calibrated positioner chain into the cell, keeping its parent and name.

        The hook of the positioner calibration (:func:`robotcell.identification.calibrate_positioner`
        returns the identified chain as a :class:`~robotcell.robot.robot.Robot`): a turntable becomes a
        :class:`Positioner` with that chain.

        Parameters
        ----------
        provenance : Provenance
        chain : Robot
            1-3 revolute axes; base = root pose in the parent (metres), limits (radians).

        Returns
        -------
        Positioner
        """
        old = self.turntable
        if old is None:
            raise InputError("the cell has no positioner to update")
        self.turntable = Positioner(chain, parent=old.parent, name=old.name,
                                    provenance=provenance)
        return self.turntable

    # -- kinematics -----------------------------------------------------------------------------
    def frame_pose(self, name: str, track: ArrayLike = 0.0, table: ArrayLike = 0.0
                   ) -> NDArray[np.float64]:
        """Pose of a frame of the cell in the world; see :func:`robotcell.cell.kinematics.frame_pose`."""
        return kinematics.frame_pose(self, name, track, table)

    def fk(self, q: ArrayLike, track: ArrayLike = 0.0, table: ArrayLike = 0.0,
           tool: str | ArrayLike | None = None, frame: str = "world") -> NDArray[np.float64]:
        """TCP pose in a frame of the cell; see :func:`robotcell.cell.kinematics.fk`.

        ``table`` is the table angle ``(...)`` of a turntable, or the axis values ``(..., n)`` of
        a positioner chain (radians).
        """
        return kinematics.fk(self, q, track, table, tool, frame)

    def ik(self, T: ArrayLike, frame: str = "world", track: ArrayLike | None = None,
           table: ArrayLike | Literal["normal_up"] = 0.0, tool: str | ArrayLike | None = None,
           samples: int | None = None) -> CellIKSolutions:
        """Every arm solution for targets in a frame of the cell; see :func:`robotcell.cell.ik.ik`.

        ``table``: the table angle ``(...)``, the positioner's axis values ``(..., n)``, or, for a
        2-axis positioner and targets in a frame it carries, ``"normal_up"``: the axis values
        that turn each target's surface normal (its ``-Z``: the tool's Z points into the surface)
        straight up, the welding position (:meth:`Positioner.normal_up`; of its two solutions,
        per target, the one within the axis limits where the arm has more valid branches).
        """
        from robotcell.cell import ik as cell_ik  # the IK package only for commands that solve IK

        if not isinstance(table, str):
            return cell_ik.ik(self, T, frame, track, table, tool, samples)
        values, ok = self._normal_up(T, frame, track)
        sols = [cell_ik.ik(self, T, frame, track, np.where(ok[..., k, None], values[..., k, :], 0.0),
                          tool, samples) for k in range(2)]
        counts = np.stack([np.where(ok[..., k], s.count, -1) for k, s in enumerate(sols)])
        second = counts[1] > counts[0]

        def pick(a: NDArray, b: NDArray) -> NDArray:
            return np.where(second.reshape(second.shape + (1,) * (a.ndim - second.ndim)), b, a)

        first, other = sols
        err = (None if first.reach_error is None or other.reach_error is None
               else pick(first.reach_error, other.reach_error))
        return cell_ik.CellIKSolutions(
            pick(first.q, other.q), pick(first.valid, other.valid),
            pick(first.reachable, other.reachable), pick(first.track, other.track),
            pick(first.table, other.table), first.method, err)

    def ik_batch(self, T: ArrayLike, frame: str = "world", track: ArrayLike | None = None,
                 table: ArrayLike | Literal["normal_up"] = 0.0,
                 tool: str | ArrayLike | None = None, chunk: int = IK_CHUNK,
                 progress: Callable[[int], None] | None = None) -> CellIKSolutions:
        """:meth:`ik` of a long list of targets, ``chunk`` targets per call (bounded memory).

        Parameters
        ----------
        T : array_like, shape (N, 4, 4)
            Targets in ``frame`` (m).
        frame : str
        track : array_like, shape (N,) or (), optional
            Track values (m), per target or one for all; None: chosen per target.
        table : array_like, shape (N,), (N, n), () or (n,), or "normal_up"
            Table angle or positioner axis values (rad), per target or one for all.
        tool : str or array_like, optional
        chunk : int
            Targets per call of :meth:`ik` (at least 1).
        progress : callable, optional
            Called with the number of targets solved after each chunk.

        Returns
        -------
        CellIKSolutions
            Shapes ``(N, 8, n)``, ``(N, 8)``, track ``(N,)``, table ``(N,)`` or ``(N, n)``.
        """
        T = validate_pose(T, "T")
        if T.ndim != 3:
            raise InputError(f"T must be a list of poses, shape (N, 4, 4), got {T.shape}")
        if not (isinstance(chunk, int) and chunk >= 1):
            raise InputError(f"chunk must be an integer >= 1, got {chunk!r}")
        n = len(T)
        pos = self.turntable
        table_shape = (pos.n_axes,) if isinstance(pos, Positioner) else ()
        try:
            e = None if track is None else np.broadcast_to(np.asarray(track, float), (n,))
            th = (table if isinstance(table, str)
                  else np.broadcast_to(np.asarray(table, float), (n, *table_shape)))
        except ValueError:
            raise InputError(f"track must have shape (N,) or (), and table shape "
                             f"{(n, *table_shape)} or {table_shape}, for N = {n} targets") from None
        parts = []
        for start in range(0, max(n, 1), chunk):
            sl = slice(start, min(start + chunk, n))
            parts.append(self.ik(T[sl], frame, None if e is None else e[sl],
                                 th if isinstance(th, str) else th[sl], tool))
            if progress is not None:
                progress(sl.stop - sl.start)
        return parts[0].concatenate(parts, table_shape)

    def _normal_up(self, T: ArrayLike, frame: str, track: ArrayLike | None
                   ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """Positioner axis values turning the targets' -Z up, for :meth:`ik`."""
        pos = self.turntable
        if not isinstance(pos, Positioner) or pos.n_axes != 2:
            raise InputError("table='normal_up' needs a positioner of 2 axes")
        if frame not in self.frames or self.frames[frame].parent != "turntable":
            raise InputError(f"table='normal_up' needs targets in a frame carried by the "
                             f"positioner, got frame {frame!r}")
        T_P = self.frames[frame].pose @ validate_pose(T, "target pose")
        parent = (np.eye(4) if pos.parent == "world"
                  else kinematics.robot_pose(self, 0.0 if track is None else track))
        values, valid = pos.normal_up(-T_P[..., :3, 2], parent)
        if not np.all(np.any(valid, axis=-1)):
            raise InputError("the positioner cannot turn every target's normal up within its "
                             "axis limits")
        return values, valid

    def ik_path(self, T: ArrayLike, frame: str = "world", track: ArrayLike | None = None,
                table: ArrayLike = 0.0, tool: str | ArrayLike | None = None,
                q_start: ArrayLike | None = None, max_step: float | None = None,
                samples: int = 33, track_motion: str = "fixed") -> CellPath:
        """A continuous trajectory through targets; see :func:`robotcell.cell.ik.ik_path`
        (``max_step`` None: its default, :data:`robotcell.cell.ik.MAX_STEP`, rad)."""
        from robotcell.cell import ik as cell_ik

        return cell_ik.ik_path(self, T, frame, track, table, tool, q_start,
                               cell_ik.MAX_STEP if max_step is None else max_step, samples,
                               track_motion)

    # -- files ------------------------------------------------------------------------------------
    @classmethod
    def load(cls, path: str | Path) -> Cell:
        """Read a cell file.

        Parameters
        ----------
        path : str or Path
            YAML cell file (millimetres, degrees). A robot model path inside it is resolved
            against the file's directory. The file is read as UTF-8, else as Windows-1252
            (:mod:`robotcell.io.fileio`).

        Returns
        -------
        Cell

        Raises
        ------
        InputError
            Missing or unreadable file, invalid YAML, or invalid content; the message names the
            file and the key.
        """
        return cell_from_dict(*read_cell_file(path))

    def save(self, path: str | Path) -> Path | None:
        """Write the cell file atomically, keeping what the user wrote and every old version.

        An existing cell file is updated in place: only the values this cell changes are
        rewritten, and its comments, key order and layout stay. The previous file is first
        copied to the next numbered backup ``<path>.<N>.bak`` (none is ever overwritten;
        ``robotcell cell history`` lists them). The text is written to a temporary file in the
        same directory, flushed and fsynced, then moved over ``path`` with ``os.replace``: if
        the process dies at any point, ``path`` holds either the old or the new content in
        full. The file and its backups keep the permissions of the file replaced (a new file
        gets ``0o666`` less the umask). The new text is read back as a cell before it replaces
        the file. See :func:`robotcell.cell.schema.save_cell`.

        ``save`` writes this cell over whatever the file says now. To change a cell file that
        another process may update at the same time, use
        :func:`robotcell.cell.update.update_cell_file`, which reads, changes and writes under
        the file's lock.

        Parameters
        ----------
        path : str or Path
            Destination. A robot model file is written relative to its directory. Through a
            symbolic link the file it points to is written (the link stays); a file with
            several hard links is refused.

        Returns
        -------
        Path or None
            The backup of the previous file, or None when there was no file.

        Raises
        ------
        InputError
            The file cannot be written, or the cell as written would not load; the file is
            unchanged.
        """
        return save_cell(self, path, cell_from_dict)


def cell_from_dict(data: Any, origin: str = "cell", base_dir: str | Path = ".") -> Cell:
    """Build a cell from the parsed content of a cell file.

    Parameters
    ----------
    data : dict
        Parsed YAML (millimetres, degrees).
    origin : str
        What to call the source in error messages (a file name).
    base_dir : str or Path
        Directory against which a relative robot model path is resolved.

    Returns
    -------
    Cell

    Raises
    ------
    InputError
        Invalid content, or a length beyond the size of any real cell
        (:func:`robotcell.cell.validation.check_lengths`); the message names ``origin`` and the
        key.
    """
    fields = cell_fields(data, origin, base_dir)
    try:
        cell = Cell(**fields)
    except InputError as exc:
        raise InputError(f"{origin}: {exc}") from None
    check_lengths(cell, origin)
    return cell


def _unique_numbers(numbers: dict[str, int | None], what: str) -> None:
    seen: dict[int, str] = {}
    for name, n in numbers.items():
        if n is None:
            continue
        if n in seen:
            raise InputError(f"{what}s {seen[n]!r} and {name!r} have the same number {n}")
        seen[n] = name
