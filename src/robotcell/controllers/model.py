"""What a robot program holds, whatever the vendor: points, their motions, tools and frames.

Every controller's program reader returns a :class:`Program` and every writer takes one
(:mod:`robotcell.controllers`).
A program knows nothing of a cell: a point keeps the values as the file writes them (a Cartesian
pose in the point's reference frame, joint values, the vendor's configuration flags, the external
axes by the name the file gives them) and how the file names its tool and frame (a number, a
name, or a pose written in the file itself). :mod:`robotcell.programs.frames` and
:mod:`robotcell.controllers.axes` tie those names to a cell.

Units are SI (metres, radians) except the external axes, which stay in the units the file writes
(mm, deg, encoder pulses) until a cell says which axis each one is.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from robotcell.controllers.data import ControllerData

__all__ = ["FLAG_LIMIT", "MOTIONS", "PTP_SPEED", "Config", "Program", "ProgramPoint", "Ref"]

#: Largest size of a configuration value (a flag, a quadrant or turn count) a file may write: a
#: larger one is a typing error, not a configuration of an arm.
FLAG_LIMIT = 2**31

#: Motions a point is reached with: joint interpolation, or a straight line of the TCP.
MOTIONS = ("ptp", "lin")

#: Speed of joint motions where a format writes it as a fraction of the axes' maximum speed
#: (KUKA ``BAS(#VEL_PTP,20)``, FANUC ``20%``, YASKAWA ``VJ=20.00``).
PTP_SPEED = 0.2


@dataclass(frozen=True)
class Ref:
    """How a program names its tool or the frame its Cartesian points are in.

    Attributes
    ----------
    number : int or None
        Controller slot (KUKA ``TOOL_DATA[n]``/``BASE_DATA[n]``, FANUC ``UT``/``UF``, YASKAWA
        tool and user frame numbers); 0 is the controller's own reference (KUKA ``$WORLD``,
        FANUC WORLD, the flange).
    name : str or None
        Name (ABB ``tooldata``/``wobjdata``, KUKA ``TOOL_NAME``), as the file spells it.
    pose : ndarray, shape (4, 4), or None
        A pose the file itself writes (KUKA ``$TOOL={X ..}``, ABB data declared in the module),
        metres: ``T_F_TCP`` for a tool; for a frame its pose in the world of the controller, or
        in the frame of the unit carrying it when ``on_table``.
    on_table : bool or None
        The frame is carried by the turntable or positioner (KUKA ``EK(...)``, ABB ``ufprog``
        FALSE): its points move with the table. None: the program does not say (a KUKA base
        chosen by number, whose kinematic the controller's setup gives).
    kind : str
        For frames, what the controller measures the point in when no number or name is given:
        ``world`` (KUKA ``$WORLD``, ABB ``wobj0``), ``base`` (the robot base at track position
        0: FANUC WORLD, YASKAWA base coordinates) or ``robot`` (the robot base where it stands:
        YASKAWA robot coordinates).
    """

    number: int | None = None
    name: str | None = None
    pose: NDArray[np.float64] | None = None
    on_table: bool | None = False
    kind: str = "world"

    def label(self) -> str:
        """The reference as a reader recognises it: name, number, or ``(in the file)``."""
        if self.name:
            return self.name + (f" ({self.number})" if self.number is not None else "")
        if self.number is not None:
            return str(self.number)
        return "written in the program" if self.pose is not None else self.kind


@dataclass(frozen=True)
class Config:
    """A vendor's configuration flags of one Cartesian point.

    Attributes
    ----------
    vendor : str
        The controller's name (:func:`robotcell.controllers.registry.names`).
    values : tuple of int
        KUKA ``(status, turn)``; ABB ``(cf1, cf4, cf6, cfx)``; FANUC ``(flip, down, back,
        turn1, turn4, turn6)`` (flags 1 for F, D, B); YASKAWA ``RCONF`` ``(l, m, n, o, p, q)``
        (see :mod:`robotcell.programs.config` for each definition and its source).
    """

    vendor: str
    values: tuple[int, ...]


@dataclass
class ProgramPoint:
    """One point of a program, as the file writes it.

    Attributes
    ----------
    name : str
        The point's name in the file (``XP3``, ``p10``, ``P[3]``, ``C00002``), or ``line N`` for a
        point written inline in a motion instruction.
    line : int
        Line (1-based) of the motion instruction that moves to the point.
    motion : {"ptp", "lin"}
        Joint motion or linear motion.
    tool, frame : Ref
        The tool and the reference frame the point is taught with.
    pose : ndarray, shape (4, 4), or None
        TCP pose in the reference frame (metres), for a Cartesian point.
    joints : ndarray, shape (n,), or None
        Arm joint values (radians; controller values), for a joint point.
    config : Config or None
        Configuration flags written with a Cartesian point, where the controller uses them (None
        when the file writes none, or when the controller ignores them for this motion: KUKA's
        Status and Turn on a linear motion, ABB's confdata under ``ConfJ``/``ConfL \\Off``).
    external : dict of str to float
        External axis values by the name the file gives them (``E1``, ``eax_b``, ``GP2:J1``,
        ``BC1``, ``EC1``), in the file's units (mm, deg, pulses).
    speed : float or None
        TCP speed (m/s) where the file writes one: linear motions, and ABB's joint motions
        (``speeddata``). The other formats move joint motions at a fraction of the axes' speed
        (:data:`PTP_SPEED`).
    zone : float or None
        Corner distance (m; 0 for an exact stop) where the file writes one.
    where : str
        The file (and line) that holds the point's values, for messages.
    near : ndarray, shape (n,), or None
        Joints (radians) whose nearest inverse-kinematics solution the controller takes for a
        Cartesian point without flags (URScript ``get_inverse_kin(pose, qnear=q)``); None:
        the solution nearest to the previous point's.
    """

    name: str
    line: int
    motion: str
    tool: Ref
    frame: Ref
    pose: NDArray[np.float64] | None = None
    joints: NDArray[np.float64] | None = None
    config: Config | None = None
    external: dict[str, float] = field(default_factory=dict)
    speed: float | None = None
    zone: float | None = None
    where: str = ""
    near: NDArray[np.float64] | None = None


@dataclass
class Program:
    """A robot program: its name, format and points in the order they are moved to.

    Attributes
    ----------
    name : str
        Program name (KUKA ``DEF``, ABB module, FANUC ``/PROG``, YASKAWA ``//NAME``).
    vendor : str
        The controller's name (:func:`robotcell.controllers.registry.names`).
    points : list of ProgramPoint
    files : tuple of str
        The files it was read from (empty for a program built in memory).
    data : ControllerData or None
        The cell's tools and frames as the controller holds them, for a writer that declares
        the program's tool and frame in the program itself (ABB); None for a program read from
        a file.
    """

    name: str
    vendor: str
    points: list[ProgramPoint] = field(default_factory=list)
    files: tuple[str, ...] = ()
    data: ControllerData | None = None
