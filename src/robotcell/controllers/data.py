"""What every controller export needs: the cell's frames in the controller's reference frame.

:func:`collect` turns a :class:`~robotcell.cell.Cell` into :class:`ControllerData`: numbered
tools, frames (fixed, or carried by the turntable) and the placement of the robot, the track and
the turntable, all as poses in metres. Each vendor module formats that data as text and parses
the text back into the same structure, so ``parse(format(collect(cell)))`` is checked against
``collect(cell)``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from robotcell.cell import Cell, Positioner
from robotcell.cell.axischain import axis_frames
from robotcell.errors import InputError
from robotcell.kinematics.transforms import invert, make_pose, rot_y

__all__ = ["ControllerData", "Slot", "collect", "fmt_num", "track_root_rotation"]

#: Decimals written for millimetres: rounding error 5e-7 mm.
MM_DECIMALS = 6
#: Decimals written for degrees: rounding error 5e-10 deg, 1e-8 mm at a lever of 1 m.
DEG_DECIMALS = 9
#: Decimals written for quaternion components: rounding error 5e-11, 1e-7 mm at 1 m.
QUAT_DECIMALS = 10


@dataclass
class Slot:
    """One pose as a controller stores it.

    Attributes
    ----------
    name : str
        Name in the cell (tool, frame, mechanical unit).
    number : int or None
        Controller slot number (None for placements that have no number).
    pose : ndarray, shape (4, 4)
        The pose (metres): ``T_F_TCP`` for a tool, the frame in the controller's reference (or in
        the turntable root B at axis 0 for ``on_table``) for a frame.
    on_table : bool
        Frame carried by the turntable.
    mass : float or None
        Tool mass (kg).
    cog : ndarray, shape (3,), or None
        Tool centre of gravity in the flange frame (metres).
    """

    name: str
    number: int | None
    pose: NDArray[np.float64]
    on_table: bool = False
    mass: float | None = None
    cog: NDArray[np.float64] | None = None


@dataclass
class ControllerData:
    """A cell as a controller sees it.

    Attributes
    ----------
    tools : list of Slot
    frames : list of Slot
        Frames fixed in the reference frame, and frames on the turntable (``on_table``).
    robot : Slot or None
        Robot base in the reference frame (cells without track, when the reference is the world).
    track_root : Slot or None
        Track root in the reference frame, its +Z along the motion (KUKA's convention for the
        frames of external kinematics).
    track_robot : Slot or None
        Robot base in the track root frame at track position 0.
    track_scale : float
        Track displacement per unit of the controller's track value.
    turntable : Slot or None
        Turntable root B in the reference frame (Z on the axis); for a positioner chain its root
        (frame 0 of the chain).
    positioner_frames : list of ndarray, shape (4, 4) each
        For a positioner chain of n axes, the n + 1 frames of KUKA's external kinematics
        (``TA1KR``, ``TA2A1``, ``TA3A2``, ``TFLA3``): the pose of each axis frame (Z on the axis)
        in the previous one at axis value 0, then the plate in the last axis frame
        (:func:`robotcell.cell.axischain.axis_frames`); empty for a one-axis turntable, whose frames
        are null.
    skipped : list of str
        Frames the controller cannot hold (fixed to a robot that moves on a track).
    """

    tools: list[Slot] = field(default_factory=list)
    frames: list[Slot] = field(default_factory=list)
    robot: Slot | None = None
    track_root: Slot | None = None
    track_robot: Slot | None = None
    track_scale: float = 1.0
    turntable: Slot | None = None
    positioner_frames: list[NDArray[np.float64]] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)


def track_root_rotation(axis: str) -> NDArray[np.float64]:
    """Pose ``T_L_K`` turning the track frame L so that +Z of K is the motion axis of L.

    ``x``: ``Ry(+90 deg)`` (Z_K = X_L); ``y``: ``Rx(-90 deg)`` (Z_K = Y_L); ``z``: identity.
    """
    if axis == "x":
        return make_pose(rot_y(math.pi / 2))
    if axis == "y":
        return make_pose(np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]]))
    return np.eye(4)


#: Half a turn about X: turns Z of an axis frame round, ``Rx(pi) Rz(q) Rx(pi) = Rz(-q)``.
_FLIP = np.diag([1.0, -1.0, -1.0, 1.0])


def positive_z_frames(frames: list[NDArray[np.float64]], signs: list[float]
                      ) -> list[NDArray[np.float64]]:
    """Axis frames whose +Z turns the way the controller's axis value counts.

    ``frames`` are ``pre_1 .. pre_n, post`` of :func:`robotcell.cell.axischain.axis_frames`, where
    joint ``i`` turns by ``sign_i q_i`` about Z. For ``sign_i = -1`` the frame of axis ``i`` is
    turned half round X (``pre_i Rx(pi)``) and the next frame compensates (``Rx(pi) pre_{i+1}``),
    so that every axis turns by ``+q_i`` about its Z, as KUKA's external kinematics count.
    """
    out = [np.array(F, dtype=float) for F in frames]
    for i, s in enumerate(signs):
        if s < 0:
            out[i] = out[i] @ _FLIP
            out[i + 1] = _FLIP @ out[i + 1]
    return out


def _numbers(given: list[int | None]) -> list[int]:
    """Explicit numbers, then the lowest free numbers for the others, in order."""
    used = {n for n in given if n is not None}
    out, nxt = [], 1
    for n in given:
        if n is None:
            while nxt in used:
                nxt += 1
            n = nxt
            used.add(n)
        out.append(n)
    return out


def collect(cell: Cell, reference: Literal["world", "robot"]) -> ControllerData:
    """The cell's poses in a controller's reference frame.

    Parameters
    ----------
    cell : Cell
    reference : {"world", "robot"}
        ``world`` (KUKA ``$WORLD``, ABB world) or ``robot``: the robot base at track position 0
        (Fanuc WORLD, Yaskawa base coordinates, which sit at the robot).

    Returns
    -------
    ControllerData

    Raises
    ------
    InputError
        A turntable carried by the track: no controller export holds it.
    """
    data = ControllerData()
    T_world_ref = np.eye(4) if reference == "world" else cell.frame_pose("robot", 0.0)
    T_ref_world = invert(T_world_ref)
    nums = _numbers([t.number for t in cell.tools.values()])
    for (name, tool), n in zip(cell.tools.items(), nums):
        data.tools.append(Slot(name, n, tool.T_F_TCP.copy(), mass=tool.mass,
                               cog=None if tool.cog is None else tool.cog.copy()))
    if cell.turntable is not None:
        if cell.turntable.parent == "robot" and cell.track is not None:
            raise InputError(f"turntable {cell.turntable.name!r} rides on the track with the "
                             "robot; controller exports need it fixed in the world")
        data.turntable = Slot(cell.turntable.name, None,
                              T_ref_world @ cell.frame_pose("turntable", 0.0))
        if isinstance(cell.turntable, Positioner):
            pre, post = axis_frames(cell.turntable.chain)
            data.positioner_frames = positive_z_frames(
                [*pre, post], [j.sign for j in cell.turntable.chain.joints])
    nums = _numbers([f.number for f in cell.frames.values()])
    for (name, fr), n in zip(cell.frames.items(), nums):
        if fr.parent == "turntable":
            data.frames.append(Slot(name, n, fr.pose.copy(), on_table=True))
        elif fr.parent == "robot" and cell.track is not None:
            data.skipped.append(name)
        else:
            data.frames.append(Slot(name, n, T_ref_world @ cell.frame_pose(name, 0.0)))
    if cell.track is not None:
        t = cell.track
        K = track_root_rotation(t.axis)
        data.track_root = Slot(t.name, None, T_ref_world @ t.T_world_L @ K)
        data.track_robot = Slot(t.name, None, invert(K) @ t.T_L_R0)
        data.track_scale = t.scale
    elif reference == "world":
        data.robot = Slot("robot", None, cell.T_world_R.copy())
    return data


def fmt_num(v: float, decimals: int) -> str:
    """Fixed decimals, without a negative zero (``-0.000000`` is written ``0.000000``)."""
    s = f"{v:.{decimals}f}"
    return s[1:] if re.fullmatch(r"-0\.?0*", s) else s


def parse_float(text: str, where: str) -> float:
    """A number from an export, or an :class:`InputError` naming where it was."""
    try:
        v = float(text)
    except ValueError:
        raise InputError(f"{where}: {text!r} is not a number") from None
    if not math.isfinite(v):
        raise InputError(f"{where}: {text!r} is not finite")
    return v


def flatten_table(data: ControllerData) -> list[Slot]:
    """Frames for controllers without frames on a turntable: everything as fixed user frames.

    Frames on the turntable become their pose at table axis 0 in the reference frame (on a
    positioner chain: at every axis 0, through its axis frames), and the turntable root B itself
    becomes one more frame (the next free number) named after the unit.

    Parameters
    ----------
    data : ControllerData

    Returns
    -------
    list of Slot
        Fixed frames, sorted by number.
    """
    out = []
    plate = np.linalg.multi_dot([np.eye(4), np.eye(4), *data.positioner_frames])
    for s in data.frames:
        if s.on_table:
            assert data.turntable is not None
            out.append(Slot(s.name, s.number, data.turntable.pose @ plate @ s.pose))
        else:
            out.append(s)
    if data.turntable is not None:
        used = {s.number for s in out}
        n = 1
        while n in used:
            n += 1
        out.append(Slot(data.turntable.name, n, data.turntable.pose.copy()))
    return sorted(out, key=lambda s: s.number or 0)

