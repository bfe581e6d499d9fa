"""Coupled forward kinematics of a cell: arm, linear track and turntable.

With the lecture's notation (``docs/conventions.md`` for the frame names):

- Track: the robot base R moves along an axis of the track frame L,
  ``T_L_R(e) = [[L_Q_R, o + e * scale * u], [0, 1]]`` with ``T_L_R0 = [[L_Q_R, o], [0, 1]]`` the
  pose at track position 0 and ``u`` the unit axis. A TCP at ``f`` in R is at
  ``p = x + L_Q_R f`` in L (``x = o + e * scale * u``, the lecture has ``o = 0`` and
  ``u = X_L``) and ``L_Q_TCP = L_Q_R R_Q_TCP``.
- Turntable: a frame W carried by the table is at ``T_parent_W(theta) = T_parent_B Rz(theta)
  T_B_W``; with the table's parent the robot base this is the lecture's
  ``R_T_W(theta) = R_T_B Rz(theta) B_T_W``. A positioner chain generalises it:
  ``T_parent_W(v) = T_parent_0 T_0_P(v) T_P_W`` with ``v`` the axis values ``(..., n)`` and
  ``T_0_P`` the chain's DH product up to its plate P (``Positioner.T_root_P``); the ``table``
  argument of every function below is then ``v``.
- TCP: ``T_world_TCP = T_world_R(e) T_R_TCP(q)`` and, in any frame X of the cell,
  ``T_X_TCP = inv(T_world_X(e, theta)) T_world_TCP``.

The cell model (:mod:`robotcell.cell`) imports this module, never the other way: the functions
take any object with the attributes of :class:`CellModel`, which :class:`robotcell.cell.Cell` has.

Every function broadcasts the batch shapes of the joints ``(..., n)``, the track positions
``(...)`` and the table angles ``(...)``. SI units: metres, radians.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.kinematics.transforms import finite_array, invert, make_pose, rot_z, validate_pose
from robotcell.robot.robot import Robot

__all__ = ["RESERVED_FRAMES", "CellModel", "broadcast_table", "fk", "frame_pose", "robot_pose", "table_batch",
           "table_pose", "table_values", "tool_pose", "track_pose"]

#: Frame names :func:`frame_pose` understands besides the cell's own frames, and what they mean.
RESERVED_FRAMES = {
    "world": "world",
    "track": "L", "L": "L",
    "robot": "R", "R": "R",
    "turntable": "B", "B": "B",
}


class CellModel(Protocol):
    """What coupled kinematics read of a cell; :class:`robotcell.cell.Cell` is one.

    Attributes
    ----------
    robot : Robot
    T_world_R : ndarray, shape (4, 4)
        Robot base in the world for a cell without track (metres).
    track : robotcell.cell.Track or None
    turntable : robotcell.cell.Turntable or None
    tools : mapping of str to robotcell.cell.Tool
    frames : mapping of str to robotcell.cell.Frame
    """

    @property
    def robot(self) -> Robot: ...

    @property
    def T_world_R(self) -> NDArray[np.float64]: ...

    @property
    def track(self) -> Any: ...

    @property
    def turntable(self) -> Any: ...

    @property
    def tools(self) -> Mapping[str, Any]: ...

    @property
    def frames(self) -> Mapping[str, Any]: ...


def track_pose(T_L_R0: ArrayLike, step: ArrayLike, e: ArrayLike) -> NDArray[np.float64]:
    """Pose of the robot base on a track: ``T_L_R0`` translated by ``e * step``.

    Parameters
    ----------
    T_L_R0 : array_like, shape (4, 4)
        Pose of R in L at track position 0 (metres).
    step : array_like, shape (3,)
        Displacement of R in L per unit of track position (``scale * axis``, dimensionless).
    e : array_like, shape (...)
        Track positions (metres).

    Returns
    -------
    ndarray, shape (..., 4, 4)
        ``T_L_R(e)``.
    """
    e_arr = finite_array(e, "track position")
    T = np.broadcast_to(np.asarray(T_L_R0, dtype=float), e_arr.shape + (4, 4)).copy()
    T[..., :3, 3] += e_arr[..., None] * np.asarray(step, dtype=float)
    return T


def table_pose(theta: ArrayLike) -> NDArray[np.float64]:
    """The table's turn ``Rz(theta)`` as poses, shape ``(..., 4, 4)`` (``theta`` in radians)."""
    return make_pose(rot_z(finite_array(theta, "table angle")))


def table_values(cell: CellModel, table: ArrayLike) -> NDArray[np.float64]:
    """Values of the axes carrying the work: table angles ``(...)`` or positioner axes ``(..., n)``.

    Parameters
    ----------
    cell : CellModel
    table : array_like
        Table angle (rad), shape ``(...)``, for a turntable (and 0 for a cell without one); axis
        values (rad), shape ``(..., n)`` or a scalar for every axis, for a positioner chain.

    Returns
    -------
    ndarray
    """
    if cell.turntable is None:
        th = finite_array(table, "table angle")
        if np.any(th != 0):
            raise InputError("the cell has no turntable; the table angle must be 0")
        return th
    return cell.turntable.axis_values(table)


def table_batch(cell: CellModel, th: NDArray[np.float64]) -> tuple[int, ...]:
    """Batch shape of the values from :func:`table_values`: ``(...)``."""
    return th.shape if cell.turntable is None else cell.turntable.batch_shape(th)


def broadcast_table(cell: CellModel, th: NDArray[np.float64], batch: tuple[int, ...]
                    ) -> NDArray[np.float64]:
    """Values from :func:`table_values` broadcast to the batch shape ``batch``."""
    shape = batch + th.shape[len(table_batch(cell, th)):]
    return th if th.shape == shape else np.broadcast_to(th, shape)


def robot_pose(cell: CellModel, e: ArrayLike) -> NDArray[np.float64]:
    """Pose of the robot base in the world at track positions ``e``.

    Parameters
    ----------
    cell : CellModel
    e : array_like, shape (...)
        Track positions (m); must be 0 in a cell without track.

    Returns
    -------
    ndarray, shape (..., 4, 4)
        ``T_world_R(e)`` (m).
    """
    e = finite_array(e, "track position")
    if cell.track is None:
        if np.any(e != 0):
            raise InputError("the cell has no track; the track position must be 0")
        return np.broadcast_to(cell.T_world_R, e.shape + (4, 4))
    return cell.track.T_world_L @ cell.track.T_L_R(e)


def _table_root(cell: CellModel, e: NDArray[np.float64]) -> NDArray[np.float64]:
    """``T_world_B(e)``: the table root, moved by the track when the table rides on the robot."""
    if cell.turntable is None:
        raise InputError("the cell has no turntable")
    tt = cell.turntable
    if tt.parent == "world":
        return np.broadcast_to(tt.T_parent_root, e.shape + (4, 4))
    return robot_pose(cell, e) @ tt.T_parent_root


def frame_pose(cell: CellModel, name: str, track: ArrayLike = 0.0, table: ArrayLike = 0.0
               ) -> NDArray[np.float64]:
    """Pose of a frame of the cell in the world.

    Parameters
    ----------
    cell : CellModel
    name : str
        ``world``; ``track`` or ``L``; ``robot`` or ``R``; ``turntable`` or ``B`` (the table's
        fixed root frame); or the name of one of the cell's frames.
    track : array_like, shape (...)
        Track position (metres); must be 0 in a cell without track.
    table : array_like, shape (...) or (..., n)
        Table angle (radians), or a positioner's axis values (:func:`table_values`); must be 0
        in a cell without turntable.

    Returns
    -------
    ndarray, shape (..., 4, 4)
        ``T_world_X`` with the broadcast batch shape of ``track`` and ``table`` (metres).
    """
    e = finite_array(track, "track position")
    th = table_values(cell, table)
    batch = np.broadcast_shapes(e.shape, table_batch(cell, th))
    e = np.broadcast_to(e, batch)
    kind = RESERVED_FRAMES.get(name)
    if kind == "world":
        return np.broadcast_to(np.eye(4), batch + (4, 4)).copy()
    if kind == "L":
        if cell.track is None:
            raise InputError("the cell has no track, so no frame 'track' (L)")
        return np.broadcast_to(cell.track.T_world_L, batch + (4, 4)).copy()
    if kind == "R":
        return np.array(robot_pose(cell, e))
    if kind == "B":
        return np.array(_table_root(cell, e))
    if name not in cell.frames:
        known = ", ".join(sorted({"world", "track", "robot", "turntable", *cell.frames}))
        raise InputError(f"unknown frame {name!r}; the cell has: {known}")
    fr = cell.frames[name]
    if fr.parent == "world":
        return np.broadcast_to(fr.pose, batch + (4, 4)).copy()
    if fr.parent == "robot":
        return robot_pose(cell, e) @ fr.pose
    return _table_root(cell, e) @ cell.turntable.T_root_P(th) @ fr.pose


def tool_pose(cell: CellModel, tool: str | ArrayLike | None) -> NDArray[np.float64] | None:
    """``T_F_TCP`` of a tool given by name (a tool of the cell) or as a pose; None stays None.

    Parameters
    ----------
    cell : CellModel
    tool : str or array_like of shape (4, 4) or None
        Tool name, or ``T_F_TCP`` (m), or None for the robot model's own tool.

    Returns
    -------
    ndarray, shape (4, 4), or None
    """
    if isinstance(tool, str):
        if tool not in cell.tools:
            known = ", ".join(sorted(cell.tools)) or "none"
            raise InputError(f"unknown tool {tool!r}; the cell has: {known}")
        return cell.tools[tool].T_F_TCP
    return None if tool is None else validate_pose(tool, "tool")


def fk(cell: CellModel, q: ArrayLike, track: ArrayLike = 0.0, table: ArrayLike = 0.0,
       tool: str | ArrayLike | None = None, frame: str = "world") -> NDArray[np.float64]:
    """TCP pose in a frame of the cell, given arm joints, track position and table angle.

    Parameters
    ----------
    cell : CellModel
    q : array_like, shape (..., n)
        Arm joint values (controller values; radians, metres for prismatic joints).
    track : array_like, shape (...)
        Track position (metres); must be 0 in a cell without track.
    table : array_like, shape (...) or (..., n)
        Table angle (radians), or a positioner's axis values; must be 0 without turntable.
    tool : str or array_like of shape (4, 4), optional
        A tool of the cell by name, or ``T_F_TCP`` (metres); default: the robot model's tool.
    frame : str
        Frame to express the pose in (see :func:`frame_pose`); default ``world``.

    Returns
    -------
    ndarray, shape (..., 4, 4)
        ``T_X_TCP`` with the broadcast batch shape of ``q[..., 0]``, ``track`` and ``table``.

    Examples
    --------
    The lecture's track relation, for a cell ``c`` with a track along X_L at the world origin:
    ``c.fk(q, track=e, frame="track")[:3, 3] == e * X_L + L_Q_R @ robot.fk(q)[:3, 3]``.
    """
    q_arr = np.asarray(q, dtype=float)
    T_tool = tool_pose(cell, tool)
    e = finite_array(track, "track position")
    if frame == "world" and e.ndim == 0:
        th = table_values(cell, table)
        if table_batch(cell, th) == ():
            # One track position: the chain starts at the robot's frame 0 in the world.
            if cell.track is None and e != 0:
                raise InputError("the cell has no track; the track position must be 0")
            T_world_0, d = _placement(cell)
            return cell.robot.fk_from(T_world_0, q_arr, tool=T_tool,
                                      shift=None if d is None else d * float(e))
    T_world_TCP = robot_pose(cell, e) @ cell.robot.fk(q_arr, tool=T_tool)
    return invert(frame_pose(cell, frame, e, table)) @ T_world_TCP


#: ``(key, placement)`` of the last cell: what the robot's placement was computed from, and the
#: placement (a loop of single poses computes it once; another cell, robot or track anew).
_LAST_PLACEMENT: list = [(None, None)]


def _placement(cell: CellModel) -> tuple[NDArray[np.float64], NDArray[np.float64] | None]:
    """``T_world_0``, the robot's DH frame 0 in the world at track position 0, and its
    displacement per unit of track position (m, in the world; None without a track)."""
    robot, t = cell.robot, cell.track
    if t is None:
        key = (robot, cell.T_world_R.tobytes())
    else:
        key = (robot, t.T_world_L.tobytes(), t.T_L_R0.tobytes(), t.axis, t.scale)
    last = _LAST_PLACEMENT[0]  # one read: another thread may replace it
    if last[0] != key:
        if t is None:
            value = (np.ascontiguousarray(cell.T_world_R @ robot.base), None)
        else:
            value = (np.ascontiguousarray(t.T_world_L @ t.T_L_R0 @ robot.base),
                     t.T_world_L[:3, :3] @ (t.direction * t.scale))
        last = _LAST_PLACEMENT[0] = (key, value)
    return last[1]
