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

import copy
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import kinematics
from robotcell.cell.kinematics import RESERVED_FRAMES
from robotcell.cell.parts import (
    DEFAULT_ROBOT,
    CellRobot,
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
    unique_numbers,
)
from robotcell.cell.schema import cell_fields, read_cell_file, save_cell
from robotcell.cell.validation import check_lengths
from robotcell.errors import InputError
from robotcell.kinematics.transforms import invert, validate_pose
from robotcell.robot.robot import Robot

if TYPE_CHECKING:
    from robotcell.cell.ik import CellIKSolutions, CellPath

__all__ = ["IK_CHUNK", "RESERVED_FRAMES", "Cell", "cell_from_dict"]

#: Targets per call of :meth:`Cell.ik` in :meth:`Cell.ik_batch`: bounds the memory of a long list.
IK_CHUNK = 500


def _calibrated_by(provenance: Provenance, robot: str) -> Provenance:
    """A shared item's provenance, calibrated through robot ``robot``'s view, naming that robot
    in its options (``robot``) when it records a touch file: ``calibrate cell`` repeats it in
    that robot's view."""
    if provenance.measurements is None or "robot" in provenance.options:
        return provenance
    return replace(provenance, options={**provenance.options, "robot": robot})


# -- the cell -------------------------------------------------------------------------------------
#: A keyword of :class:`Cell` not given (``None`` is a value: ``track=None`` removes the track).
_KEEP: Any = object()

#: The keywords of :class:`Cell` that describe its one robot, and the :class:`CellRobot` field each sets.
_ROBOT_KEYWORDS = {"robot": "robot", "robot_model": "model", "T_world_R": "T_world_R",
                   "track": "track", "tools": "tools", "identified": "identified"}


def _robot_attribute(key: str) -> property:
    """An attribute of the cell's only robot (``cell.robot``, ``cell.track``, ...)."""
    attr = _ROBOT_KEYWORDS[key]

    def get(self: Cell) -> Any:
        return getattr(self.robots[self.robot_name], attr)

    def set_(self: Cell, value: Any) -> None:
        name = self.robot_name
        unit = copy.copy(self.robots[name])  # a copy of the cell keeps its robot as it was
        setattr(unit, attr, value)
        self.robots = {**self.robots, name: unit}

    return property(get, set_, doc=f"``{attr}`` of the cell's only robot (:class:`CellRobot`); "
                    "InputError in a cell of several robots: use ``cell.robots[name]``.")


@dataclass(init=False)
class Cell:
    """A robot cell in SI units: one or several robots, what carries the work, and the frames.

    ``Cell(robot=..., robot_model=..., track=..., tools=...)`` is a cell of one robot (named
    :data:`~robotcell.cell.parts.DEFAULT_ROBOT`, ``"robot"``); ``Cell(robots={name:
    CellRobot(...)}, ...)`` a cell of several, sharing the world, the turntable or positioner
    and the frames. The one-robot attributes (``robot``, ``robot_model``, ``T_world_R``,
    ``track``, ``tools``, ``identified``, ``nominal_robot``) are those of the only robot; in a
    cell of several robots they raise InputError naming the robots, and :meth:`for_robot` (or
    the ``robot=`` keyword of :meth:`fk`, :meth:`ik`, ...) says which robot is meant.

    Attributes
    ----------
    robots : dict of str to CellRobot
        The robots by name: arm, model name, base pose or track, tools, identified arm.
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
        Shared by the robots. The parent of a frame fixed to a robot base is ``robot`` in a
        one-robot cell and the robot's name in a cell of several.
    name : str
    identified : IdentifiedArm or None
        Set when ``robot`` is an identified arm: then ``robot`` says where the TCP goes (FK, IK,
        reach, checks, touches given as joint values) and ``identified.nominal``, the controller's
        model, turns joint values into what the controller is told (:meth:`controller`).
        ``robot`` carries the nominal's tool, and the nominal as its ``ik_seed`` when its model
        file names none (a model written by another tool): its IK branches are the nominal's.
    """

    robots: dict[str, CellRobot]
    turntable: Turntable | Positioner | None
    frames: dict[str, Frame]
    name: str

    def __init__(self, robot: Robot = _KEEP, robot_model: str = _KEEP,
                 T_world_R: ArrayLike = _KEEP, track: Track | None = _KEEP,
                 turntable: Turntable | Positioner | None = None,
                 tools: dict[str, Tool] = _KEEP, frames: dict[str, Frame] | None = None,
                 name: str = "cell", identified: IdentifiedArm | None = _KEEP, *,
                 robots: dict[str, CellRobot] | None = None) -> None:
        given = {_ROBOT_KEYWORDS[k]: v for k, v in (
            ("robot", robot), ("robot_model", robot_model), ("T_world_R", T_world_R),
            ("track", track), ("tools", tools), ("identified", identified)) if v is not _KEEP}
        self.robots = _robots(robots, given)
        self.turntable = turntable
        self.frames = dict(frames or {})
        self.name = name
        self._check()

    def _check(self) -> None:
        several = len(self.robots) > 1
        for rname in self.robots:
            if several or rname != DEFAULT_ROBOT:
                check_name(rname, "robot")
        if several and self.turntable is not None and self.turntable.parent != "world":
            raise InputError(f"the turntable or positioner of a cell of several robots "
                             f"({', '.join(self.robots)}) is shared: its parent must be world, "
                             f"got {self.turntable.parent!r}")
        for name, fr in self.frames.items():
            check_name(name, "frame")
            self.frames[name] = self._check_parent(name, fr)
        unique_numbers({k: f.number for k, f in self.frames.items()}, "frame")

    robot = _robot_attribute("robot")
    robot_model = _robot_attribute("robot_model")
    T_world_R = _robot_attribute("T_world_R")
    track = _robot_attribute("track")
    tools = _robot_attribute("tools")
    identified = _robot_attribute("identified")

    # -- the robots -------------------------------------------------------------------------------
    @property
    def robot_names(self) -> tuple[str, ...]:
        """The names of the cell's robots, in the file's order (``("robot",)`` for one robot
        given as ``robot:``)."""
        return tuple(self.robots)

    @property
    def robot_name(self) -> str:
        """The name of the cell's only robot.

        Raises
        ------
        InputError
            The cell has several robots: the message names them.
        """
        if len(self.robots) == 1:
            return next(iter(self.robots))
        raise InputError(f"the cell has {len(self.robots)} robots ({', '.join(self.robots)}); "
                         "say which one is meant (robot=NAME)")

    def robot_key(self, robot: str | None) -> str:
        """The name of robot ``robot`` of the cell (None: the only robot).

        Raises
        ------
        InputError
            No robot of that name (the message lists the cell's robots), or None in a cell of
            several robots.
        """
        if robot is None:
            return self.robot_name
        if robot not in self.robots:
            raise InputError(f"the cell has no robot {robot!r}; its robots: "
                             f"{', '.join(self.robots)}")
        return robot

    def for_robot(self, robot: str | None = None) -> Cell:
        """The cell as one robot sees it: a one-robot cell with that robot, the shared
        turntable or positioner and the frames.

        In a one-robot cell this is the cell itself. In a cell of several robots, frames fixed
        to this robot's base get parent ``robot``; frames fixed to the base of another robot
        without a track are placed in the world; frames fixed to another robot on a track are
        left out (where they are depends on that robot's track). The tools are the robot's.

        Parameters
        ----------
        robot : str, optional
            A name of :attr:`robot_names`; None: the only robot.

        Returns
        -------
        Cell

        Raises
        ------
        InputError
            An unknown name (the cell's robots are listed), or None in a cell of several robots.
        """
        key = self.robot_key(robot)
        if len(self.robots) == 1:
            return self
        frames: dict[str, Frame] = {}
        for fname, fr in self.frames.items():
            if fr.parent == key:
                frames[fname] = replace(fr, parent="robot")
            elif fr.parent in self.robots:
                other = self.robots[fr.parent]
                if other.track is None:
                    frames[fname] = replace(fr, pose=other.T_world_R @ fr.pose, parent="world")
            else:
                frames[fname] = fr
        view = object.__new__(Cell)  # the parts were checked when this cell was made
        view.robots, view.turntable, view.frames, view.name = (
            {key: self.robots[key]}, self.turntable, frames, self.name)
        return view

    def with_view(self, view: Cell, robot: str | None = None) -> Cell:
        """This cell with the changes made to the view :meth:`for_robot` gave of robot ``robot``.

        The robot (arm, base or track, tools) is the view's; frames the view fixes to its robot
        are written back fixed to this robot; a frame the view changed or added is written as
        the view has it; frames the view placed in the world for another robot, unchanged, and
        frames it left out stay as they are. The turntable or positioner is the view's.

        Parameters
        ----------
        view : Cell
            A one-robot cell from :meth:`for_robot`, changed (e.g. by a calibration).
        robot : str, optional
            The robot it is the view of (None: the only robot).

        Returns
        -------
        Cell
            A new cell (this one is unchanged); ``view`` itself for a one-robot cell.
        """
        key = self.robot_key(robot)
        if len(self.robots) == 1:
            return view
        frames = dict(self.frames)
        for fname, fr in view.frames.items():
            old = self.frames.get(fname)
            if fr.parent == "robot":
                frames[fname] = replace(fr, parent=key)
            elif not (old is not None and old.parent in self.robots
                      and fr.provenance is old.provenance and fr.number == old.number):
                # a frame the view changed (a placed one keeps its provenance)
                frames[fname] = fr if old is not None and fr.provenance is old.provenance else (
                    replace(fr, provenance=_calibrated_by(fr.provenance, key)))
        table = view.turntable
        if table is not None and table is not self.turntable:
            table = replace(table, provenance=_calibrated_by(table.provenance, key))
        return Cell(robots={**self.robots, key: view.robots[view.robot_name]},
                    turntable=table, frames=frames, name=self.name)

    def _view(self, robot: str | None, frame: str) -> Cell:
        """:meth:`for_robot`, refusing a frame on another robot's track by name."""
        view = self.for_robot(robot)
        if frame in self.frames and frame not in view.frames:
            raise InputError(f"frame {frame!r} is fixed to robot {self.frames[frame].parent!r}, "
                             f"which moves on its track: robot {view.robot_name!r} does not know "
                             "where it is; give that robot, or a frame in the world or on the "
                             "positioner")
        return view

    def set_robot_base(self, robot: str | None, pose: ArrayLike, provenance: Provenance,
                       reference: str | None = None, reference_track: float = 0.0) -> CellRobot:
        """Place a robot's base, e.g. from a robot-to-robot calibration.

        Parameters
        ----------
        robot : str or None
            The robot placed (None: the only robot).
        pose : array_like, shape (4, 4)
            ``T_world_R`` (metres), or ``T_Rref_R``, the base in the base of robot
            ``reference``. For a robot on a track, the base at track position 0: written into
            ``track.robot_at_zero`` (the track frame stays).
        provenance : Provenance
            Where the pose comes from.
        reference : str, optional
            Another robot of the cell whose base ``pose`` is given in.
        reference_track : float
            The reference robot's track position (m) at which ``pose`` holds, if it has a track.

        Returns
        -------
        CellRobot
            The robot as placed.

        Raises
        ------
        InputError
            An unknown robot, a reference that is the robot itself, or a pose that is not a
            rigid transform.
        """
        key = self.robot_key(robot)
        T = single_pose(pose, "robot base pose")
        if reference is not None:
            ref = self.robot_key(reference)
            if ref == key:
                raise InputError(f"robot {key!r} cannot be placed relative to itself")
            T = self.for_robot(ref).frame_pose("robot", track=reference_track) @ T
        unit = self.robots[key]
        if unit.track is None:
            unit = replace(unit, T_world_R=T, base_provenance=provenance)
        else:
            unit = replace(unit, track=replace(unit.track, T_L_R0=invert(unit.track.T_world_L) @ T,
                                               provenance=provenance))
        self.robots = {**self.robots, key: unit}
        return unit

    @property
    def nominal_robot(self) -> Robot:
        """The model the controller computes with: the nominal of an identified arm, else ``robot``."""
        return self.robots[self.robot_name].nominal_robot

    def controller(self) -> Cell:
        """The cell as the controller computes it: with the nominal arm (``self`` without an
        identified one). Its FK of joint values is what a program's Cartesian point says."""
        if all(u.identified is None for u in self.robots.values()):
            return self
        return replace(self, robots={k: u.controller() for k, u in self.robots.items()})

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
        self.robots = {**self.robots, self.robot_name: replace(
            self.robots[self.robot_name], robot=robot.with_tool(nominal.tool),
            identified=IdentifiedArm(nominal, model, provenance))}

    @property
    def positioner(self) -> Turntable | Positioner | None:
        """The external axes carrying the work (the same object as :attr:`turntable`)."""
        return self.turntable

    def _check_parent(self, name: str, fr: Frame) -> Frame:
        """``fr`` checked against the cell; a one-robot cell spells a robot parent ``robot``."""
        if fr.parent == "turntable" and self.turntable is None:
            raise InputError(f"frame {name!r} is carried by the turntable, but the cell has none")
        if fr.parent in ("world", "turntable"):
            return fr
        if len(self.robots) == 1:
            if fr.parent == "robot" or fr.parent in self.robots:
                return fr if fr.parent == "robot" else replace(fr, parent="robot")
        elif fr.parent in self.robots:
            return fr
        raise InputError(f"frame {name!r} has parent {fr.parent!r}; the parent must be world, "
                         f"turntable or a robot of the cell: {', '.join(self._robot_parents())}")

    def _robot_parents(self) -> list[str]:
        return ["robot"] if len(self.robots) == 1 else list(self.robots)

    # -- editing (used by calibration commands) -------------------------------------------------
    def set_tool(self, name: str, T_F_TCP: ArrayLike, provenance: Provenance,
                 number: int | None = None, mass: float | None = None,
                 cog: ArrayLike | None = None, robot: str | None = None) -> Tool:
        """Add or replace a tool of a robot; an existing tool keeps its number and load unless given.

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
        robot : str, optional
            The robot whose tool it is (None: the only robot).

        Returns
        -------
        Tool
        """
        check_name(name, "tool")
        tools = self.robots[self.robot_key(robot)].tools
        old = tools.get(name)
        tool = Tool(
            T_F_TCP=np.asarray(T_F_TCP, dtype=float),
            number=number if number is not None else (old.number if old else None),
            mass=mass if mass is not None else (old.mass if old else None),
            cog=np.asarray(cog, dtype=float) if cog is not None else (old.cog if old else None),
            provenance=provenance,
        )
        unique_numbers({**{k: t.number for k, t in tools.items()}, name: tool.number}, "tool")
        tools[name] = tool
        return tool

    def update_frame(self, name: str, pose: ArrayLike, provenance: Provenance,
                     parent: str | None = None,
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
        parent : str, optional
            ``world``, ``turntable``, ``robot`` (one-robot cell) or a robot's name. Default:
            the existing frame's parent, else ``world``.
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
        fr = self._check_parent(name, fr)
        unique_numbers({**{k: f.number for k, f in self.frames.items()}, name: fr.number}, "frame")
        self.frames[name] = fr
        return fr

    def update_track(self, provenance: Provenance, robot: str | None = None, **changes: Any
                     ) -> Track:
        """Replace fields of a robot's track (``T_world_L``, ``T_L_R0``, ``axis``, ``scale``, ...).

        Parameters
        ----------
        provenance : Provenance
            Provenance of the new track calibration.
        robot : str, optional
            The robot on the track (None: the only robot).
        **changes
            :class:`Track` attributes to change (SI units).

        Returns
        -------
        Track
        """
        key = self.robot_key(robot)
        unit = self.robots[key]
        if unit.track is None:
            raise InputError("the cell has no track to update" if len(self.robots) == 1
                             else f"robot {key!r} has no track to update")
        track = replace(unit.track, provenance=provenance, **changes)
        self.robots = {**self.robots, key: replace(unit, track=track)}
        return track

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
    def frame_pose(self, name: str, track: ArrayLike = 0.0, table: ArrayLike = 0.0,
                   robot: str | None = None) -> NDArray[np.float64]:
        """Pose of a frame of the cell in the world; see :func:`robotcell.cell.kinematics.frame_pose`.

        ``robot``: the robot whose track position ``track`` is, and whose base ``robot`` and
        ``track`` name (None: the only robot; see :meth:`for_robot`).
        """
        return kinematics.frame_pose(self._view(robot, name), name, track, table)

    def fk(self, q: ArrayLike, track: ArrayLike = 0.0, table: ArrayLike = 0.0,
           tool: str | ArrayLike | None = None, frame: str = "world", robot: str | None = None
           ) -> NDArray[np.float64]:
        """TCP pose in a frame of the cell; see :func:`robotcell.cell.kinematics.fk`.

        ``table`` is the table angle ``(...)`` of a turntable, or the axis values ``(..., n)`` of
        a positioner chain (radians). ``robot``: the robot whose joints ``q`` and track position
        ``track`` are (None: the only robot; an unknown name raises InputError naming the cell's
        robots).
        """
        return kinematics.fk(self._view(robot, frame), q, track, table, tool, frame)

    def ik(self, T: ArrayLike, frame: str = "world", track: ArrayLike | None = None,
           table: ArrayLike | Literal["normal_up"] = 0.0, tool: str | ArrayLike | None = None,
           samples: int | None = None, robot: str | None = None) -> CellIKSolutions:
        """Every arm solution for targets in a frame of the cell; see :func:`robotcell.cell.ik.ik`.

        ``robot``: the robot solved for (None: the only robot; see :meth:`for_robot`).

        ``table``: the table angle ``(...)``, the positioner's axis values ``(..., n)``, or, for a
        2-axis positioner and targets in a frame it carries, ``"normal_up"``: the axis values
        that turn each target's surface normal (its ``-Z``: the tool's Z points into the surface)
        straight up, the welding position (:meth:`Positioner.normal_up`; of its two solutions,
        per target, the one within the axis limits where the arm has more valid branches).
        """
        from robotcell.cell import ik as cell_ik  # the IK package only for commands that solve IK

        if robot is not None and len(self.robots) > 1:
            return self._view(robot, frame).ik(T, frame, track, table, tool, samples)
        self.robot_key(robot)
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
                 progress: Callable[[int], None] | None = None, robot: str | None = None
                 ) -> CellIKSolutions:
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
        robot : str, optional
            The robot solved for (None: the only robot; see :meth:`for_robot`).

        Returns
        -------
        CellIKSolutions
            Shapes ``(N, 8, n)``, ``(N, 8)``, track ``(N,)``, table ``(N,)`` or ``(N, n)``.
        """
        if robot is not None and len(self.robots) > 1:
            return self._view(robot, frame).ik_batch(T, frame, track, table, tool, chunk,
                                                         progress)
        self.robot_key(robot)
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
                samples: int = 33, track_motion: str = "fixed", robot: str | None = None
                ) -> CellPath:
        """A continuous trajectory through targets; see :func:`robotcell.cell.ik.ik_path`
        (``max_step`` None: its default, :data:`robotcell.cell.ik.MAX_STEP`, rad; ``robot``:
        the robot that follows it, None: the only robot)."""
        from robotcell.cell import ik as cell_ik

        return cell_ik.ik_path(self._view(robot, frame), T, frame, track, table, tool, q_start,
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
    for name in cell.robot_names:
        check_lengths(cell.for_robot(name),
                      origin if len(cell.robots) == 1 else f"{origin}: robot {name!r}")
    return cell


def _robots(robots: dict[str, CellRobot] | None, given: dict[str, Any]) -> dict[str, CellRobot]:
    """The robots of a new cell: ``robots``, with the one-robot keywords ``given`` applied."""
    if robots is None:
        if "robot" not in given or "model" not in given:
            raise InputError("a cell needs its robot and the robot's model name (robot=..., "
                             "robot_model=...), or its robots (robots={name: CellRobot(...)})")
        return {DEFAULT_ROBOT: CellRobot(**given)}
    if not robots:
        raise InputError("a cell needs at least one robot")
    if not given:
        return dict(robots)
    if len(robots) != 1:
        raise InputError(f"the cell has {len(robots)} robots ({', '.join(robots)}); give each "
                         f"its {', '.join(given)} in its CellRobot")
    (name, unit), = robots.items()
    return {name: replace(unit, **given)}
