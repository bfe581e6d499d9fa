"""The interface of a robot controller: everything robotcell knows of one, in one object.

A controller is a subclass of :class:`Controller` with one instance, registered by name in
:mod:`robotcell.controllers.registry`. The object holds its pose format, its export (the cell's
tools and frames as the controller takes them) and the reader and writer of its programs, its
configuration flags, the names and slot numbers it can hold, how its programs write the
external axes, and the sources of all of these. The rest of robotcell asks the object; nothing
outside :mod:`robotcell.controllers` branches on a controller's name (``docs/conventions.md``,
"How to add a controller").
"""

from __future__ import annotations

import re
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell
from robotcell.controllers.axes import ExternalAxes
from robotcell.controllers.data import ControllerData, Slot, collect, flatten_table
from robotcell.controllers.model import Config, Program, Ref
from robotcell.errors import InputError
from robotcell.io.poseformats import PoseFormat
from robotcell.robot.robot import Robot

__all__ = ["Controller", "IkFlags", "SlotRange", "ZeroOffsets"]

_IDENT = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")


@dataclass(frozen=True)
class SlotRange:
    """The numbers under which a controller holds tools, or frames.

    Attributes
    ----------
    key : str
        How the controller names a slot (``TOOL_DATA``, ``UFRAME``).
    first, last : int
        The lowest and the highest number it has.
    """

    key: str
    first: int
    last: int

    def check(self, slot: Slot, what: str, label: str) -> None:
        """Refuse ``slot`` when its number is not one of the range.

        Parameters
        ----------
        slot : Slot
            A tool or frame with its number (None: the controller numbers none, nothing to
            check).
        what : {"tool", "frame"}
        label : str
            The controller, for the message (``KUKA``).

        Raises
        ------
        InputError
            The number is outside ``first..last``; the message names the range.
        """
        if slot.number is None or self.first <= slot.number <= self.last:
            return
        raise InputError(f"{what} {slot.name!r} is number {slot.number}, which {label} does not "
                         f"have: its {what}s are {self.key}[{self.first}..{self.last}]; give the "
                         f"{what} a number from {self.first} to {self.last} in the cell file")


@dataclass(frozen=True)
class IkFlags:
    """The configuration flags ``robotcell ik`` prints beside the solutions in a controller's
    pose format.

    Attributes
    ----------
    label : str
        Header of the printed column (``S/T``).
    columns : tuple of str
        CSV columns of the flags (``status``, ``turn``).
    values : callable
        ``values(robot, q)`` with ``q`` of shape ``(..., 6)`` (rad): the flags, shape
        ``(..., len(columns))`` of int.
    text : callable
        ``text(row)``: one row of ``values`` as printed (``S 6 T 2``).
    """

    label: str
    columns: tuple[str, ...]
    values: Callable[[Robot, NDArray[np.float64]], NDArray[np.int_]]
    text: Callable[[NDArray[np.int_]], str]


@dataclass(frozen=True)
class ZeroOffsets:
    """How a controller takes identified joint zero offsets.

    Attributes
    ----------
    angle_scale, length_scale : float
        Controller units per radian and per metre.
    angle_unit, length_unit : str
        Their names (``deg``, ``mm``).
    heading : str
        What to do with the values, printed above them.
    column : str
        Header of the column of values.
    """

    angle_scale: float
    length_scale: float
    angle_unit: str
    length_unit: str
    heading: str
    column: str


class Controller(ABC):
    """One robot controller: a subclass sets the attributes and writes the methods below.

    Attributes
    ----------
    name : str
        Lower-case name, as the API and the command line's ``--format`` take it (``kuka``).
    label : str
        The name in messages (``KUKA``).
    pose_format : PoseFormat
        How the controller writes a pose (:mod:`robotcell.io.poseformats`).
    reference : {"world", "robot"}
        The frame its frames are measured in: the cell's world (KUKA ``$WORLD``), or the robot
        base at track position 0 (FANUC WORLD).
    table_frames : bool
        It holds frames carried by the turntable or positioner (KUKA ``EK``, ABB ``ufmec``);
        else a frame on the table is written where it is at table axis 0, and the table's root
        as one more frame.
    world_ref : Ref
        How a program names the controller's own reference (KUKA ``BASE_DATA`` 0, ABB
        ``wobj0``).
    world_name : str
        Its name in messages (``$WORLD``).
    program_suffixes : tuple of str
        File name endings of its programs, lower case (``.src``, ``.dat``).
    program_files : str
        Its program files in words, for messages (``KUKA .src with its .dat``).
    comment : str
        What starts a comment line of its programs (``;``).
    export_name : str
        The file its export is saved as (``config.dat``); its ending is the one an export
        output may have besides ``.txt``.
    name_limit : int
        Longest program name.
    upper_names : bool
        Program names are written in capitals.
    tool_slots, frame_slots : SlotRange or None
        The numbers of its tools and frames (None: it names them instead of numbering them).
    config_fields : tuple of str
        Names of its configuration flags (:class:`~robotcell.controllers.model.Config` values).
    shared_config : bool
        A point's flags are shared with the points after it in the file (YASKAWA ``RCONF``):
        filtering a point never rewrites them.
    edits_joints : bool
        :meth:`set_joints` can rewrite the joint points of its programs.
    csv_config : tuple of str
        Configuration columns of a poses file in this controller's flags (empty: none).
    ik_flags : IkFlags or None
        The flags ``robotcell ik`` prints in this pose format.
    zero_offsets : ZeroOffsets or None
        How it takes identified joint zero offsets (``robotcell identify --offsets-for``).
    sources : tuple of str
        Where these facts come from (``docs/export.md``, ``docs/programs.md``).
    """

    name: ClassVar[str]
    label: ClassVar[str]
    pose_format: ClassVar[PoseFormat]
    reference: ClassVar[str]
    table_frames: ClassVar[bool]
    world_ref: ClassVar[Ref]
    world_name: ClassVar[str]
    program_suffixes: ClassVar[tuple[str, ...]]
    program_files: ClassVar[str]
    comment: ClassVar[str]
    export_name: ClassVar[str]
    name_limit: ClassVar[int]
    upper_names: ClassVar[bool] = False
    tool_slots: ClassVar[SlotRange | None] = None
    frame_slots: ClassVar[SlotRange | None] = None
    config_fields: ClassVar[tuple[str, ...]] = ()
    shared_config: ClassVar[bool] = False
    edits_joints: ClassVar[bool] = False
    csv_config: ClassVar[tuple[str, ...]] = ()
    ik_flags: ClassVar[IkFlags | None] = None
    zero_offsets: ClassVar[ZeroOffsets | None] = None
    sources: ClassVar[tuple[str, ...]] = ()
    #: What is missing for coordinated programs of several robots (the public sources their
    #: form would follow); None where :meth:`write_coordinated` writes them.
    coordinated_missing: ClassVar[str | None] = (
        "no public manual or real program in the sources robotcell cites shows its form")
    #: A coordinated program is one file for all robots (YASKAWA: one job of several groups),
    #: not one file per robot (ABB: one module per task).
    coordinated_one_file: ClassVar[bool] = False

    def __repr__(self) -> str:
        return f"<controller {self.name}>"

    # -- the cell as the controller holds it ---------------------------------------------------
    @property
    def frame_kind(self) -> str:
        """:attr:`Ref.kind` of its frames: ``world``, or ``base`` (the robot base at track 0)."""
        return "world" if self.reference == "world" else "base"

    def data(self, cell: Cell) -> ControllerData:
        """The cell's tools and frames, numbered, in the controller's reference frame."""
        return collect(cell, self.reference)

    def frames(self, data: ControllerData) -> list[Slot]:
        """The frames as the controller numbers them: as collected, or flattened to fixed frames
        with the table's root added (:func:`~robotcell.controllers.data.flatten_table`)."""
        return data.frames if self.table_frames else flatten_table(data)

    def check_tool(self, slot: Slot) -> None:
        """Refuse a tool whose number the controller does not have."""
        if self.tool_slots is not None:
            self.tool_slots.check(slot, "tool", self.label)

    def check_frame(self, slot: Slot) -> None:
        """Refuse a frame whose number the controller does not have."""
        if self.frame_slots is not None:
            self.frame_slots.check(slot, "frame", self.label)

    def check_table_ref(self, ref: Ref, slot: Slot) -> None:
        """Refuse a program's reference to ``slot`` that says otherwise than the cell whether
        the frame is carried by the table (only a controller that writes it can disagree)."""

    def refusal(self, cell: Cell) -> str | None:
        """Why the controller holds no program or export of ``cell`` (its arm's flags are not
        defined, or its external axes are more than the programs hold); None when it holds it.
        A command that writes for every controller by default skips the ones that refuse."""
        try:
            self.data(cell)
            self.external_axes(cell)
            self.config_values(cell.robot, np.zeros((1, cell.robot.n_joints)))
        except InputError as exc:
            return str(exc)
        return None

    def export(self, cell: Cell) -> str:
        """The text to paste into the controller: tools, frames, placements of ``cell``.

        Raises
        ------
        InputError
            A tool or frame number the controller does not have, or a cell it cannot hold.
        """
        data = self.data(cell)
        for s in data.tools:
            self.check_tool(s)
        for s in self.frames(data):
            self.check_frame(s)
        return self.format_export(data, cell.name)

    def pair_lines(self, cell: Cell) -> list[str]:
        """Comment lines that place the robots of a cell of several robots in each other as the
        controller holds them when it moves them all (FANUC's coordinated pair, YASKAWA's robot
        calibration; :mod:`robotcell.controllers.robotpairs`); none here."""
        return []

    @abstractmethod
    def format_export(self, data: ControllerData, cell_name: str) -> str:
        """The export text of ``data`` (collected in :attr:`reference`)."""

    @abstractmethod
    def parse_export(self, text: str) -> ControllerData:
        """Read an export written by :meth:`export` back (poses in metres)."""

    # -- programs ------------------------------------------------------------------------------
    @abstractmethod
    def write_program(self, program: Program, header: list[str]) -> dict[str, str]:
        """The files of a program of Cartesian points: file name -> text.

        ``header`` holds comment lines (without the comment marker) that say where the program
        comes from; every file written holds them.
        """

    @abstractmethod
    def read_program(self, path: str | Path) -> tuple[Program, list[str]]:
        """Read a program file: the program, and the motions not turned into points (with
        their lines)."""

    def coordinated_refusal(self) -> InputError:
        """The error that refuses coordinated programs of this controller, naming what is
        missing."""
        return InputError(f"{self.label} coordinated programs of several robots are not "
                          f"written or checked: {self.coordinated_missing}; write each "
                          "robot's program alone (program write --robot-name NAME)")

    def write_coordinated(self, programs: list[Program], header: list[str]) -> dict[str, str]:
        """The files of a coordinated program: one program per robot (in the order of the
        tasks or groups), all of one name and as many points, every point reached together
        with the same point of the others. File name -> text.

        Raises
        ------
        InputError
            The controller's coordinated form is not written (:attr:`coordinated_missing`).
        """
        raise self.coordinated_refusal()

    def coordinated_robots(self, cell: Cell, robots: list[str]) -> None:
        """Refuse robots of the cell whose coordinated program this controller does not write
        (before their paths are solved); by default none.

        Raises
        ------
        InputError
            Robots the controller's coordinated form does not hold, naming why.
        """

    def read_coordinated(self, paths: list[str | Path], n: int
                         ) -> list[tuple[Program, list[str]]]:
        """Each robot's program of a coordinated program, in order: here each file's
        (:attr:`coordinated_one_file` False), the program and the motions not turned into
        points.

        Parameters
        ----------
        paths : list of str or Path
            The program's files (one per robot, or the one file).
        n : int
            The number of robots.
        """
        return [self.read_program(p) for p in paths]

    def coordinated_problems(self, paths: list[str | Path]) -> list[str]:
        """What breaks the controller's rules for the synchronisation of the coordinated
        program in ``paths`` (one file per robot in order, or the one file), each with its
        file and line.

        Raises
        ------
        InputError
            The controller's coordinated form is not read (:attr:`coordinated_missing`), or a
            file cannot be read.
        """
        raise self.coordinated_refusal()

    def comments(self, text: str) -> list[str]:
        """The comment lines of a program file's ``text``, without the comment marker: where a
        written program says what it was written from."""
        lines = (line.strip() for line in text.splitlines())
        return [line[len(self.comment):] for line in lines if line.startswith(self.comment)]

    @abstractmethod
    def point_names(self, n: int) -> list[str]:
        """Names of ``n`` points as the program numbers them (``XP1``, ``p1``, ``P[1]``)."""

    def program_name(self, name: str) -> str:
        """``name`` as a program name (in capitals where :attr:`upper_names`).

        Raises
        ------
        InputError
            Not a letter followed by letters, digits or ``_``, or longer than
            :attr:`name_limit`.
        """
        if not _IDENT.match(name) or len(name) > self.name_limit:
            raise InputError(f"program name {name!r} is not valid for {self.label}: a "
                             f"letter, then letters, digits or '_', at most {self.name_limit} "
                             "characters; give another name")
        return name.upper() if self.upper_names else name

    def default_name(self, stem: str) -> str:
        """A program name made of a file name's stem: other characters become ``_``, a leading
        ``P`` where it does not start with a letter, cut to :attr:`name_limit`."""
        clean = "".join(ch if ch.isalnum() and ch.isascii() else "_" for ch in stem)
        if not clean[:1].isalpha():
            clean = "P" + clean
        return clean[:self.name_limit]

    def piece_name(self, name: str, k: int) -> str:
        """The name of piece ``k`` of a program ``name`` (``NAME_2``), cut to fit."""
        suffix = f"_{k}"
        return self.program_name(name[:self.name_limit - len(suffix)] + suffix)

    # -- configuration flags -------------------------------------------------------------------
    @abstractmethod
    def config_values(self, robot: Robot, q: NDArray[np.float64]) -> NDArray[np.int_]:
        """The flags of arm configurations ``q`` (``(..., 6)``, rad, values within 1e-12 of 0
        already 0): shape ``(..., len(config_fields))``."""

    @abstractmethod
    def config_text(self, values: tuple[int, ...]) -> str:
        """The flags as the program file writes them."""

    def configs_from_columns(self, path: str, cols: dict[str, Any]) -> list[Config]:
        """The configuration of each row of a poses file from its :attr:`csv_config` columns
        (whole numbers; a controller that writes its flags as text reads them here).

        Raises
        ------
        InputError
            A value that is not a whole number; the message names the line and column.
        """
        values = []
        for c in self.csv_config:
            v = cols[c]
            bad = [i for i, x in enumerate(v) if not isinstance(x, (float, np.floating))
                   or not float(x).is_integer()]
            if bad:
                raise InputError(f"{path}: line {bad[0] + 2}: column '{c}' must be an integer, "
                                 f"got {v[bad[0]]!r}")
            values.append(np.asarray(v, dtype=int))
        return [Config(self.name, tuple(int(x) for x in row)) for row in np.column_stack(values)]

    # -- external axes -------------------------------------------------------------------------
    @abstractmethod
    def external_axes(self, cell: Cell, pulses_per_degree: ArrayLike | None = None
                      ) -> ExternalAxes:
        """The names and units of ``cell``'s track and table axes in this controller's programs.

        Raises
        ------
        InputError
            More external axes than the programs hold, or a unit the call must give
            (``pulses_per_degree``).
        """

    # -- editing a program's text in place -----------------------------------------------------
    def set_joints(self, lines: list[str], idx: int, q: NDArray[np.float64]) -> bool:
        """Write the six axis values ``q`` (rad) of the joint point on line ``idx`` (0-based) of
        ``lines`` (changed in place); False when they are not found there (or, without
        :attr:`edits_joints`, never written)."""
        return False

    @abstractmethod
    def set_pose(self, lines: list[str], idx: int, T: NDArray[np.float64],
                 config: Config | None = None) -> bool:
        """Write the Cartesian values ``T`` (m, in the point's frame) of the point on line
        ``idx`` (0-based), and its flags unless None; False when they are not found there."""
