"""Clearance along a program: its points and the motion between them, as the controller moves.

Between two points a joint move (``PTP``, ``MoveJ``, ``J``, ``MOVJ``) runs every axis linearly
in its own values; a linear move (``LIN``, ``MoveL``, ``L``, ``MOVL``) runs the TCP along the
straight line with its orientation turned about one axis (the shortest rotation), the arm's
joints on the IK branch of the neighbouring points. Each segment is cut into samples no further
apart than ``step`` (a joint's turn in rad, a track's travel or the TCP's travel in m), and
every sample is checked (:func:`robotcell.clearance.distance.smallest_distances`).
"""

from __future__ import annotations

import fnmatch
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robotcell.cell.kinematics import frame_pose, robot_pose, table_batch, table_values, tool_pose
from robotcell.cell.model import Cell
from robotcell.clearance.bodies import BodiesFile, Body
from robotcell.clearance.distance import Clearance, Shapes, smallest_distances
from robotcell.clearance.skeleton import frame_segments
from robotcell.errors import InputError
from robotcell.kinematics.transforms import finite_array

__all__ = ["ArmMotion", "arm_input", "arm_shapes", "clearance", "interpolate", "joined", "pairs",
           "samples", "shared_table"]

#: Default sample spacing: 0.01 rad of a joint (0.57 deg), 10 mm of the track or the TCP.
STEP = 0.01


def _motions(motion: str | Sequence[str], n: int) -> list[str]:
    kinds = [motion] * max(n - 1, 0) if isinstance(motion, str) else list(motion)
    if len(kinds) != max(n - 1, 0):
        raise InputError(f"motion gives {len(kinds)} moves for {n} points; give one per "
                         f"segment ({max(n - 1, 0)}) or one for all")
    bad = sorted(set(kinds) - {"joint", "linear"})
    if bad:
        raise InputError(f"unknown motion {bad[0]!r}; use 'joint' or 'linear'")
    return kinds


def samples(q: NDArray[np.float64], extra: NDArray[np.float64], tcp: NDArray[np.float64],
            step: float) -> NDArray[np.float64]:
    """Where to sample each segment: the positions ``i + f`` along the program, shape (P,).

    Parameters
    ----------
    q : ndarray, shape (N, n)
        Joint values (rad, m).
    extra : ndarray, shape (N, k)
        Track (m) and table or positioner values (rad).
    tcp : ndarray, shape (N, 3)
        TCP positions in the world (m).
    step : float
        Largest change between samples: of a joint or table value (rad), of the track or the
        TCP (m).
    """
    if len(q) < 2:
        return np.zeros(len(q))
    travel = np.concatenate([np.abs(np.diff(q, axis=0)), np.abs(np.diff(extra, axis=0)),
                             np.linalg.norm(np.diff(tcp, axis=0), axis=1)[:, None]], axis=1)
    cuts = np.maximum(1, np.ceil(travel.max(axis=1) / step)).astype(int)
    starts = np.repeat(np.arange(len(cuts)), cuts)
    within = np.arange(cuts.sum()) - np.repeat(np.cumsum(cuts) - cuts, cuts)
    return np.append(starts + within / np.repeat(cuts, cuts), len(q) - 1.0)


def interpolate(values: NDArray[np.float64], pos: NDArray[np.float64]) -> NDArray[np.float64]:
    """``values`` ``(N, k)`` at the places ``pos`` ``(P,)`` along the program, linearly."""
    i = np.minimum(np.floor(pos).astype(int), len(values) - 2) if len(values) > 1 else \
        np.zeros(len(pos), int)
    f = (pos - i)[:, None] if len(values) > 1 else np.zeros((len(pos), 1))
    nxt = values[np.minimum(i + 1, len(values) - 1)]
    return values[i] * (1 - f) + nxt * f


def _linear_joints(cell: Cell, q: NDArray[np.float64], Q: NDArray[np.float64],
                   pos: NDArray[np.float64], linear: NDArray[np.bool_],
                   tool: NDArray[np.float64]) -> NDArray[np.float64]:
    """Joint values of the samples inside linear moves: the IK of the straight line, on the
    branch nearest the joints' own interpolation."""
    if not linear.any():
        return Q
    i = np.minimum(np.floor(pos).astype(int), len(q) - 2)
    inside = linear[i] & (pos != np.round(pos))
    k, f = i[inside], (pos - i)[inside]
    T = cell.robot.fk(q, tool)
    rot = Rotation.from_matrix(T[:, :3, :3])
    turn = (rot[k].inv() * rot[k + 1]).as_rotvec()
    Ts = np.tile(np.eye(4), (len(k), 1, 1))
    Ts[:, :3, :3] = (rot[k] * Rotation.from_rotvec(turn * f[:, None])).as_matrix()
    Ts[:, :3, 3] = T[k, :3, 3] * (1 - f[:, None]) + T[k + 1, :3, 3] * f[:, None]
    sol = cell.robot.ik(Ts, tool)
    gap = np.where(sol.valid, np.linalg.norm(sol.q - Q[inside][:, None, :], axis=-1), np.inf)
    best = np.argmin(gap, axis=1)
    lost = ~np.isfinite(gap[np.arange(len(k)), best])
    if lost.any():
        raise InputError(f"the linear move from point {k[lost][0] + 1} to {k[lost][0] + 2} "
                         "leaves the robot's reach or joint limits between them")
    out = Q.copy()
    out[inside] = sol.q[np.arange(len(k)), best]
    return out


def _parent_poses(cell: Cell, body: Body, E: NDArray[np.float64], TH: NDArray[np.float64],
                  T_world_F: NDArray[np.float64]) -> NDArray[np.float64]:
    if body.parent == "flange":
        return T_world_F
    if body.parent == "plate":
        if cell.turntable is None:
            raise InputError(f"body {body.name!r} is on the plate, but the cell has no "
                             "turntable or positioner")
        return frame_pose(cell, "turntable", E, TH) @ cell.turntable.T_root_P(TH)
    return frame_pose(cell, body.parent, E, TH)


def pairs(a: tuple[str, ...], b: tuple[str, ...], ignore: Sequence[tuple[str, str]]
          ) -> NDArray[np.intp]:
    """The pairs ``(i, j)`` of shapes of ``a`` and ``b`` that ``ignore`` does not list; a
    pattern matches a name as written (``kuka.tool``) or without its robot's prefix (``tool``).
    """
    def match(name: str, pattern: str) -> bool:
        return (fnmatch.fnmatchcase(name, pattern)
                or ("." in name and fnmatch.fnmatchcase(name.partition(".")[2], pattern)))

    def ignored(x: str, y: str) -> bool:
        return any((match(x, p) and match(y, r)) or (match(y, p) and match(x, r))
                   for p, r in ignore)
    return np.array([(i, j) for i, x in enumerate(a) for j, y in enumerate(b)
                     if not ignored(x, y)], dtype=np.intp).reshape(-1, 2)


def clearance(cell: Cell, q: ArrayLike, *, track: ArrayLike = 0.0, table: ArrayLike = 0.0,
              tool: str | ArrayLike | None = None, bodies: BodiesFile | None = None,
              motion: str | Sequence[str] = "joint", step: float = STEP) -> Clearance:
    """The smallest distance between the robot (links, tool, what the flange holds) and the
    cell's parts along a program.

    Parameters
    ----------
    cell : Cell
        The cell (its robot, track, turntable or positioner, frames).
    q : array_like, shape (N, n)
        The program's joint values, point by point (rad, m).
    track : array_like, shape (N,) or scalar
        Track values (m).
    table : array_like, shape (N,), (N, k) or scalar
        Table angle or positioner axis values (rad).
    tool : str or array_like (4, 4), optional
        The tool's name in the cell, or ``T_F_TCP`` (m); its capsule runs from the flange to
        the TCP. None: no tool.
    bodies : BodiesFile, optional
        The cell's parts, the arm's capsule radii and the pairs never reported
        (:func:`robotcell.clearance.read_bodies`).
    motion : str or sequence of str
        ``joint`` or ``linear``: for every segment, or one per segment (N - 1).
    step : float
        Largest change between samples of a segment: a joint's or the table's turn (rad), the
        track's or the TCP's travel (m).

    Returns
    -------
    Clearance
        The smallest distance and its pair at every sample, with the samples' places along the
        program; ``per_point()`` and ``per_segment()`` gather them.

    Raises
    ------
    InputError
        Joint values of the wrong shape or not finite, a linear move through an unreachable
        pose, a body on a frame the cell lacks, or the collision library missing.
    """
    bodies = bodies or BodiesFile()
    arm = arm_input(cell, q, track, tool, motion)
    if not (np.isfinite(step) and step > 0):
        raise InputError(f"step must be > 0, got {step!r}")
    TH = shared_table(cell, table, arm.n)
    pos = samples(arm.q, np.column_stack([arm.E, TH.reshape(arm.n, -1)]), arm.tcp, step)
    robot, Es, T_world_F = arm_shapes(cell, arm, pos, bodies, "")
    THs = interpolate(TH.reshape(arm.n, -1), pos).reshape((len(pos),) + TH.shape[1:])
    held = [b for b in bodies.bodies if b.parent == "flange"]
    parts = [b for b in bodies.bodies if b.parent != "flange"]
    if held:
        robot = joined(robot, _body_shapes(cell, held, Es, THs, T_world_F))
    others = _body_shapes(cell, parts, Es, THs, T_world_F)
    return smallest_distances(robot, others, pairs(robot.names, others.names, bodies.ignore), pos)


@dataclass(frozen=True)
class ArmMotion:
    """One robot's program as the clearance check takes it.

    Attributes
    ----------
    q : ndarray, shape (N, n)
        Joint values (rad, m).
    E : ndarray, shape (N,)
        Track values (m).
    T_tool : ndarray, shape (4, 4), or None
        ``T_F_TCP`` (m); None: no tool.
    linear : ndarray of bool, shape (N - 1,)
        Each segment is a linear move.
    tcp : ndarray, shape (N, 3)
        The TCP (the flange without a tool) in the world (m).
    """

    q: NDArray[np.float64]
    E: NDArray[np.float64]
    T_tool: NDArray[np.float64] | None
    linear: NDArray[np.bool_]
    tcp: NDArray[np.float64]

    @property
    def n(self) -> int:
        """The number of program points."""
        return len(self.q)


def arm_input(cell: Cell, q: ArrayLike, track: ArrayLike, tool: str | ArrayLike | None,
               motion: str | Sequence[str]) -> ArmMotion:
    """The checked joint values, track values, tool and motions of one robot (``cell`` is the
    cell as that robot sees it)."""
    q = np.atleast_2d(finite_array(q, "q"))
    if q.ndim != 2 or q.shape[1] != cell.robot.n_joints:
        raise InputError(f"q must have shape (N, {cell.robot.n_joints}), got {q.shape}")
    n = len(q)
    E = np.broadcast_to(finite_array(track, "track"), (n,)).astype(float)
    T_tool = tool_pose(cell, tool) if tool is not None else None
    flange_tool = np.eye(4) if T_tool is None else T_tool
    linear = np.array([k == "linear" for k in _motions(motion, n)], dtype=bool)
    tcp = (robot_pose(cell, E) @ cell.robot.fk(q, flange_tool))[:, :3, 3]
    return ArmMotion(q, E, T_tool, linear, tcp)


def shared_table(cell: Cell, table: ArrayLike, n: int) -> NDArray[np.float64]:
    """The table's values at each of ``n`` points, shape (N,) or (N, k) (rad)."""
    th = table_values(cell, table)
    return np.broadcast_to(th, (n,) + th.shape[len(table_batch(cell, th)):])


def arm_shapes(cell: Cell, arm: ArmMotion, pos: NDArray[np.float64], bodies: BodiesFile,
               prefix: str) -> tuple[Shapes, NDArray[np.float64], NDArray[np.float64]]:
    """One robot's capsules at the samples ``pos``, named ``prefix + link``.

    Parameters
    ----------
    cell : Cell
        The cell as the robot sees it (:meth:`~robotcell.cell.model.Cell.for_robot`).
    arm : ArmMotion
    pos : ndarray, shape (P,)
        The samples' places along the program.
    bodies : BodiesFile
        For the capsules' radii.
    prefix : str
        Put before each name (``kuka.``), empty for a cell of one robot.

    Returns
    -------
    shapes : Shapes
    track : ndarray, shape (P,)
        Track values at the samples (m).
    T_world_F : ndarray, shape (P, 4, 4)
        The flange in the world at the samples (m).
    """
    flange_tool = np.eye(4) if arm.T_tool is None else arm.T_tool
    Q = interpolate(arm.q, pos)
    Q = _linear_joints(cell, arm.q, Q, pos, arm.linear, flange_tool)
    Es = interpolate(arm.E[:, None], pos)[:, 0]
    T_world_R = robot_pose(cell, Es)
    F = cell.robot.frames(Q)
    segs, names = frame_segments(cell.robot, F, arm.T_tool)
    kept = np.flatnonzero(np.linalg.norm(segs[..., 1, :] - segs[..., 0, :], axis=-1).max(axis=0)
                          > 1e-9)
    segs, names = segs[:, kept], tuple(prefix + names[k] for k in kept)
    segs = np.einsum("pij,pkej->pkei", T_world_R[:, :3, :3], segs) + T_world_R[:, None, None, :3, 3]
    r = bodies.links.radius_of(cell.robot)
    radius = np.array([bodies.links.tool_radius if nm[len(prefix):] == "tool" else r
                       for nm in names])
    return Shapes.capsules(names, segs, radius), Es, T_world_R @ F[:, -1] @ cell.robot.flange


def _body_shapes(cell: Cell, bodies: Sequence[Body], E: NDArray[np.float64],
                 TH: NDArray[np.float64], T_world_F: NDArray[np.float64]) -> Shapes:
    P = len(E)
    poses = np.empty((P, len(bodies), 4, 4))
    for k, b in enumerate(bodies):
        poses[:, k] = _parent_poses(cell, b, E, TH, T_world_F) @ b.pose
    radii = np.broadcast_to(np.array([b.bounding_radius for b in bodies]), (P, len(bodies)))
    return Shapes(tuple(b.name for b in bodies), tuple(b.shape for b in bodies),
                  tuple(b.size for b in bodies), poses, radii)


def joined(a: Shapes, b: Shapes) -> Shapes:
    """The shapes of ``a`` and of ``b`` (parts of fixed size) as one group."""
    P = a.poses.shape[0]
    lengths = np.concatenate([a.lengths if a.lengths is not None else np.zeros(a.radii.shape),
                              np.full((P, len(b.names)), np.nan)], axis=1)
    return Shapes(a.names + b.names, a.kinds + b.kinds, a.sizes + b.sizes,
                  np.concatenate([a.poses, b.poses], axis=1),
                  np.concatenate([a.radii, b.radii], axis=1), lengths)
