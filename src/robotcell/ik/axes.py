"""Joint axes of a chain as lines in space, for recognising analytically solvable structures."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from robotcell.kinematics.arm import Arm

__all__ = ["AXIS_TOL", "angle_deg", "closest_point", "joint_axes", "line_distance"]

#: Tolerance of the structure tests: |cos| or |sin| of an angle between axes, and distances (m).
AXIS_TOL = 1e-9


def joint_axes(robot: Arm) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Axis lines of every joint at ``q = 0``, in the robot base frame R.

    Parameters
    ----------
    robot : Arm

    Returns
    -------
    points : ndarray, shape (n, 3)
        A point on each axis (m): the origin of the DH frame the joint moves about.
    directions : ndarray, shape (n, 3)
        Unit vectors such that a positive joint value turns right-handedly about (or slides
        along) them: the DH z axis times the joint's sign.
    """
    F = robot.frames(np.zeros(robot.n_joints))
    sel = F[:-1] if robot.convention == "standard" else F[1:]
    sign = np.array([j.sign for j in robot.joints])
    return sel[:, :3, 3].copy(), sel[:, :3, 2] * sign[:, None]


def closest_point(p1: NDArray[np.float64], u1: NDArray[np.float64], p2: NDArray[np.float64],
                  u2: NDArray[np.float64]) -> NDArray[np.float64]:
    """The point of line 1 (through ``p1``, direction ``u1``) closest to line 2, shape (3,) (m)."""
    w = p1 - p2
    b = float(u1 @ u2)
    den = 1.0 - b * b
    if den < AXIS_TOL**2:  # parallel: every point is as close; take p1
        return p1.copy()
    t = (b * float(u2 @ w) - float(u1 @ w)) / den
    return p1 + t * u1


def line_distance(p1: NDArray[np.float64], u1: NDArray[np.float64], p2: NDArray[np.float64],
                  u2: NDArray[np.float64]) -> float:
    """Shortest distance between two lines given by a point and a unit direction (m)."""
    w = p1 - p2
    n = np.cross(u1, u2)
    sin = float(np.linalg.norm(n))
    if sin < AXIS_TOL:  # parallel
        return float(np.linalg.norm(np.cross(w, u1)))
    return abs(float(w @ n)) / sin


def angle_deg(u1: NDArray[np.float64], u2: NDArray[np.float64]) -> float:
    """Angle between two unit vectors in degrees, for error messages."""
    return math.degrees(math.acos(max(-1.0, min(1.0, float(u1 @ u2)))))


def six_revolute_problems(robot: Arm) -> list[str]:
    """Why ``robot`` is not a chain of six revolute joints (empty if it is).

    The first check of every analytic solver: both need exactly six revolute axes.
    """
    if robot.n_joints != 6:
        return [f"it has {robot.n_joints} joints, not 6"]
    prismatic = [i + 1 for i, j in enumerate(robot.joints) if j.prismatic]
    if prismatic:
        return [f"joint(s) {', '.join(map(str, prismatic))} are prismatic"]
    return []
