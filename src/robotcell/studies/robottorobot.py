"""Simulated robot-to-robot touches: several robots of a virtual layout touch common points.

The layout is the truth: each :class:`SimulatedRobot` stands at a known pose in the world (on a
track or not) and carries a true tool. :func:`touch_design` chooses, per common point, how each
robot reaches it (tool pointing down, tilted as little as its joints allow; a robot on a track
drives abreast of the point), :func:`flange_poses` places the flange so that the true TCP lies at
the point plus the touch error, and :func:`simulate_robot_to_robot` writes the measurement
tables of every robot (joint values ``a1..a6`` in degrees and column ``point``), which
``robotcell calibrate robot-to-robot`` reads (see ``docs/simulate.md``).
"""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell.calibrate.simulation import DOWN
from robotcell.errors import InputError
from robotcell.kinematics.transforms import invert, make_pose, transform_points
from robotcell.robot.robot import Robot

__all__ = ["SPREAD", "Design", "SimulatedRobot", "default_points", "flange_poses",
           "simulate_robot_to_robot", "table_text", "touch_design", "touch_table"]

#: Where the common points lie by default (m): about the point on the floor midway between the
#: two bases, in the reference base's axes; a triangle of 300 mm or more in every view.
SPREAD = np.array([[0.0, 0.3, 0.35], [-0.05, -0.35, 0.3], [0.15, 0.0, 0.6], [0.05, 0.3, 0.65],
                   [-0.1, -0.05, 0.45]])


@dataclass(frozen=True)
class SimulatedRobot:
    """One robot of a virtual layout.

    Attributes
    ----------
    model : Robot
        Its arm.
    base : ndarray, shape (4, 4)
        ``T_world_L``: where its touches' frame stands in the world (m): the robot base, or for
        a robot on a track the track frame, in which the base is at ``track * axis`` at each
        track position.
    tool : ndarray, shape (4, 4)
        The true tool ``T_F_TCP`` it touches with (m).
    name : str
    axis : ndarray, shape (3,), optional
        Direction of its track in L (unit); None: the robot does not move.
    """

    model: Robot
    base: NDArray[np.float64]
    tool: NDArray[np.float64]
    name: str
    axis: NDArray[np.float64] | None = None

    def at(self, track: ArrayLike) -> NDArray[np.float64]:
        """``T_L_R`` at track positions (N,) (m): the identity for a robot without a track."""
        e = np.atleast_1d(np.asarray(track, dtype=float))
        T = np.broadcast_to(np.eye(4), e.shape + (4, 4)).copy()
        if self.axis is not None:
            T[:, :3, 3] = e[:, None] * self.axis
        return T


@dataclass(frozen=True)
class Design:
    """How one robot reaches each common point.

    Attributes
    ----------
    rotations : ndarray, shape (K, 3, 3)
        Flange rotation ``R_R_F`` at each point.
    track : ndarray, shape (K,)
        Track position at each point (m; zeros without a track).
    joints : ndarray, shape (K, n)
        Joint values (rad) that reach each point without error.
    """

    rotations: NDArray[np.float64]
    track: NDArray[np.float64]
    joints: NDArray[np.float64]


def touch_design(robot: SimulatedRobot, points: ArrayLike) -> Design:
    """Choose how ``robot`` reaches each point (world, m): the least tilted reachable orientation.

    Raises
    ------
    InputError
        A point the robot reaches in no candidate orientation within its joint limits.
    """
    p_w = np.asarray(points, dtype=float).reshape(-1, 3)
    p_L = transform_points(invert(robot.base), p_w)
    track = (p_L @ robot.axis if robot.axis is not None else np.zeros(len(p_L)))
    p_R = transform_points(invert(robot.at(track)), p_L)                       # (K, 3)
    R_L = robot.base[:3, :3].T @ DOWN                                         # (M, 3, 3) in L
    T = make_pose(R_L[None], p_R[:, None])                                    # (K, M, 4, 4)
    sol = robot.model.ik(T, robot.tool)
    ok = sol.valid.any(axis=-1)                                               # (K, M)
    if not ok.any(axis=1).all():
        bad = np.flatnonzero(~ok.any(axis=1))
        raise InputError(f"{robot.name} reaches point(s) {', '.join(str(i + 1) for i in bad)} in "
                         "no orientation within its joint limits; move the points into its reach")
    m = ok.argmax(axis=1)                                                     # first = least tilt
    k = np.arange(len(p_R))
    branch = sol.valid[k, m].argmax(axis=-1)
    q = sol.q[k, m, branch]
    R_F = R_L[m] @ robot.tool[:3, :3].T
    return Design(R_F, track, q)


def flange_poses(robot: SimulatedRobot, design: Design, points: ArrayLike,
                 errors: ArrayLike | None = None) -> NDArray[np.float64]:
    """Flange poses ``T_R_F`` (N, 4, 4) that put the true TCP at each point plus its error.

    Parameters
    ----------
    robot : SimulatedRobot
    design : Design
        Its orientations and track positions, one per touch (N).
    points : array_like, shape (N, 3)
        The touched points in the world (m).
    errors : array_like, shape (N, 3), optional
        Touch errors in the world (m).
    """
    p_w = np.asarray(points, dtype=float).reshape(-1, 3)
    if errors is not None:
        p_w = p_w + np.asarray(errors, dtype=float)
    p_R = transform_points(invert(robot.base @ robot.at(design.track)), p_w)
    t = robot.tool[:3, 3]
    return make_pose(design.rotations, p_R - design.rotations @ t)


def touch_table(robot: SimulatedRobot, design: Design, flange: NDArray[np.float64],
                names: Sequence[str]) -> dict[str, object]:
    """The measurement table (mm, deg) of a robot's touches: ``a1..an`` and ``point``.

    The joint values are the IK branch of ``flange`` nearest the design's (one per touch).
    """
    sol = robot.model.ik(flange, np.eye(4))
    d = np.where(sol.valid, np.linalg.norm(np.nan_to_num(sol.q - design.joints[:, None], nan=1e9),
                                           axis=-1), np.inf)
    q = sol.q[np.arange(len(flange)), d.argmin(axis=-1)]
    table: dict[str, object] = {f"a{i + 1}": np.degrees(q[:, i]) for i in range(q.shape[1])}
    table["point"] = list(names)
    return table


def simulate_robot_to_robot(robots: Sequence[SimulatedRobot], points: ArrayLike, *,
                            noise: float, rng: np.random.Generator, repeats: int = 1
                            ) -> list[dict[str, object]]:
    """The measurement tables of every robot touching every common point ``repeats`` times.

    Parameters
    ----------
    robots : sequence of SimulatedRobot
        Robots without a track (a table has no track column without a cell).
    points : array_like, shape (K, 3)
        Common points in the world (m); named ``P1..PK``.
    noise : float
        Touch error (m, 1-sigma per coordinate).
    rng : numpy.random.Generator
    repeats : int
        Touches per point and robot.

    Returns
    -------
    list of dict
        Per robot, column name to values (mm, deg; ``point`` as names).
    """
    if repeats < 1:
        raise InputError(f"repeats must be 1 or more, got {repeats}")
    p = np.repeat(np.asarray(points, dtype=float).reshape(-1, 3), repeats, axis=0)
    names = [f"P{i // repeats + 1}" for i in range(len(p))]
    out = []
    for robot in robots:
        if robot.axis is not None:
            raise InputError(f"{robot.name} is on a track: its touch table needs a cell")
        design = touch_design(robot, p)
        flange = flange_poses(robot, design, p, rng.normal(0.0, noise, p.shape))
        out.append(touch_table(robot, design, flange, names))
    return out


def default_points(T_ref_other: ArrayLike) -> NDArray[np.float64]:
    """The default common points (K, 3) in the reference base (m): :data:`SPREAD` about the
    point on the floor midway between the two bases."""
    mid = 0.5 * np.asarray(T_ref_other, dtype=float)[:3, 3] * np.array([1.0, 1.0, 0.0])
    return mid + SPREAD


def table_text(table: dict[str, object]) -> str:
    """A touch table as CSV text: joint values with 6 decimals (deg), the point's name."""
    buf = io.StringIO(newline="")
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(list(table))
    columns = [list(v) if isinstance(v, list) else [f"{x:.6f}" for x in np.asarray(v)]
               for v in table.values()]
    w.writerows(zip(*columns, strict=True))
    return buf.getvalue()
