"""Analytic inverse kinematics of 4-axis palletizers (passive parallelogram, level flange).

A palletizer (ABB IRB 460 / 660, FANUC M-410, KUKA KR ... PA, Motoman MPL) carries its wrist on a
passive parallelogram that keeps the flange level: axis 1 turns the arm about the vertical, axes 2
and 3 move the upper arm and the forearm in the arm's plane, and axis 4 (ABB: axis 6) turns the
flange about an axis parallel to axis 1. In the frame O (z along axis 1, y normal to the arm's
plane) a point ``W`` on the flange axis is::

    W = Rz(phi1) [A_r + L2 cos(phi2) + L3 cos(phi3), b, A_h + L2 sin(phi2) + L3 sin(phi3)]

with the upper arm's and the forearm's angles ``phi2 = g22 q2 + o2``,
``phi3 = g32 q2 + g33 q3 + o3`` (linear in the controller values, whatever the coupling),
``phi1 = s1 q1`` and the flange turned about z by ``psi = s1 q1 + s4 q4``. The parameters are read
off the model numerically (forward kinematics of the coupled robot), so any model file that has
this structure works. The solution: ``psi`` from the orientation, ``W`` from the position, axis 1
from ``W`` (two solutions, front and back), then the planar two-link problem for the two arm
angles (two solutions, elbow up and down): 4 branches ``k = 2 * shoulder + elbow``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from robotcell.errors import InputError
from robotcell.ik.axes import AXIS_TOL
from robotcell.ik.limits import wrap_to_pi
from robotcell.kinematics.arm import Arm

__all__ = ["PalletizerParameters", "palletizer_parameters", "palletizer_problems"]

#: Largest deviation of a target orientation from level (sine of the tilt) that still counts as
#: reachable; a palletizer's flange cannot tilt.
LEVEL_TOL = 1e-9
#: Allowed excess of the cosine of the elbow angle beyond +-1 (stretched or folded arm).
COS_TOL = 1e-10
_STEP = 0.5  # rad, probe step of the parameter identification


@dataclass(frozen=True)
class PalletizerParameters:
    """The planar description of a palletizer (metres, radians), see the module docstring.

    Attributes
    ----------
    A_r, A_h, b, L2, L3 : float
        Shoulder point in the arm plane, lateral offset of that plane, upper arm and forearm.
    s1, s4 : float
        Turn of the arm / of the flange about z per unit of axis 1 / axis 4.
    g22, o2, g32, g33, o3 : float
        ``phi2 = g22 q2 + o2``, ``phi3 = g32 q2 + g33 q3 + o3``.
    v_n : ndarray, shape (3,)
        The point ``W`` seen from the last DH frame n (fixed in that frame, m).
    R_n0 : ndarray, shape (3, 3)
        Orientation of frame n in O at all axes 0.
    T_R_O : ndarray, shape (4, 4)
        Pose of O in the robot base frame R.
    T_e_n : ndarray, shape (4, 4)
        Identity: the solver's end frame is the last DH frame n.
    """

    A_r: float
    A_h: float
    b: float
    L2: float
    L3: float
    s1: float
    s4: float
    g22: float
    o2: float
    g32: float
    g33: float
    o3: float
    v_n: NDArray[np.float64]
    R_n0: NDArray[np.float64]
    T_R_O: NDArray[np.float64]
    T_e_n: NDArray[np.float64]


def _end(robot: Arm, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Pose of the last DH frame n in R at controller values ``q`` (..., 4)."""
    return robot.frames(q)[..., -1, :, :]


def _turn(Ra: NDArray[np.float64], Rb: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rotation vector of ``Rb Ra^T`` (rad)."""
    return Rotation.from_matrix(Rb @ Ra.T).as_rotvec()


def _circle(p: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
    """Centre and radius of the circle through three 2-D points ``p`` (3, 2)."""
    a, b, c = p
    M = 2.0 * np.array([b - a, c - a])
    rhs = np.array([b @ b - a @ a, c @ c - a @ a])
    centre = np.linalg.solve(M, rhs)
    return centre, float(np.linalg.norm(a - centre))


def palletizer_problems(robot: Arm) -> list[str]:
    """Why ``robot`` is not a 4-axis palletizer with a level flange (empty if it is)."""
    if robot.n_joints != 4:
        return [f"it has {robot.n_joints} controller axes, not 4"]
    if np.any(robot.prismatic):
        return ["it has prismatic axes"]
    rng = np.random.default_rng(0)
    q = rng.uniform(-0.5, 0.5, (3, 4))
    moved = q + np.array([0.0, 0.4, -0.3, 0.0])
    R0, R1 = _end(robot, q)[:, :3, :3], _end(robot, moved)[:, :3, :3]
    out = []
    if np.abs(R0 - R1).max() > AXIS_TOL:
        out.append("the flange orientation changes with axes 2 and 3 (no parallelogram keeps it level)")
    T0 = _end(robot, np.zeros(4))
    w1 = _turn(T0[:3, :3], _end(robot, np.array([_STEP, 0, 0, 0]))[:3, :3])
    w4 = _turn(T0[:3, :3], _end(robot, np.array([0, 0, 0, _STEP]))[:3, :3])
    if min(np.linalg.norm(w1), np.linalg.norm(w4)) < AXIS_TOL:
        out.append("axis 1 or axis 4 does not turn the flange")
    elif np.linalg.norm(np.cross(w1, w4)) > AXIS_TOL * max(1.0, float(np.linalg.norm(w1))):
        out.append("axis 4 is not parallel to axis 1")
    return out


def palletizer_parameters(robot: Arm) -> PalletizerParameters:
    """Identify the planar parameters of a palletizer from its forward kinematics.

    Raises
    ------
    InputError
        When the model lacks the structure; the message names every failed condition.
    """
    problems = palletizer_problems(robot)
    if problems:
        raise InputError(f"{robot.name} is not a 4-axis palletizer: " + "; ".join(problems) + ".")
    z4 = np.zeros(4)
    T0 = _end(robot, z4)

    def probe(axis: int, value: float) -> NDArray[np.float64]:
        q = z4.copy()
        q[axis] = value
        return _end(robot, q)

    w1 = _turn(T0[:3, :3], probe(0, _STEP)[:3, :3])
    s1 = float(np.linalg.norm(w1)) / _STEP
    z = w1 / np.linalg.norm(w1)
    if z[2] < 0:  # z of O points to the same side as Z_R when possible
        z, s1 = -z, -s1
    s4 = float(_turn(T0[:3, :3], probe(3, _STEP)[:3, :3]) @ z) / _STEP
    # A point on the flange axis (axis 4): midpoint of the frame origin turned half a revolution.
    half = math.pi / abs(s4)
    c4 = 0.5 * (T0[:3, 3] + probe(3, half)[:3, 3])
    v_n = T0[:3, :3].T @ (c4 - T0[:3, 3])

    def wrist(q: NDArray[np.float64]) -> NDArray[np.float64]:
        T = _end(robot, q)
        return T[..., :3, 3] + T[..., :3, :3] @ v_n

    # Axis 1 line: midpoint of W turned half a revolution about axis 1.
    W0 = wrist(z4)
    c1 = 0.5 * (W0 + wrist(np.array([math.pi / abs(s1), 0, 0, 0])))
    c1 = c1 - z * float(z @ c1)  # foot of the perpendicular from R's origin
    dW2 = wrist(np.array([0, _STEP, 0, 0])) - W0
    dW3 = wrist(np.array([0, 0, _STEP, 0])) - W0
    y = np.cross(dW2, dW3)
    if np.linalg.norm(y) < AXIS_TOL:
        y = np.cross(z, W0 - c1)
    y = y / np.linalg.norm(y)
    if float(np.cross(y, z) @ (W0 - c1)) < 0:  # x towards the wrist at all axes 0
        y = -y
    if abs(float(y @ z)) > AXIS_TOL:
        raise InputError(f"{robot.name} is not a 4-axis palletizer: the arm's plane is not vertical "
                         "(axis 2 not perpendicular to axis 1).")
    x = np.cross(y, z)
    T_R_O = np.eye(4)
    T_R_O[:3, 0], T_R_O[:3, 1], T_R_O[:3, 2], T_R_O[:3, 3] = x, y, z, c1

    def plane(q: NDArray[np.float64]) -> NDArray[np.float64]:
        w = wrist(q) - c1
        return np.stack([w @ x, w @ z], axis=-1)

    b = float((W0 - c1) @ y)
    steps = np.array([0.0, _STEP, 2 * _STEP])
    # Axis 3 alone turns the forearm about the elbow: a circle about the elbow point.
    qs = np.zeros((3, 4))
    qs[:, 2] = steps
    elbow0, L3 = _circle(plane(qs))
    # The same at two more values of axis 2 gives the elbow's circle about the shoulder.
    elbows = [elbow0]
    for v in steps[1:]:
        qs[:, 1] = v
        elbows.append(_circle(plane(qs))[0])
    A, L2 = _circle(np.array(elbows))

    def angle(v: NDArray[np.float64]) -> float:
        return math.atan2(float(v[1]), float(v[0]))

    o2 = angle(elbows[0] - A)
    g22 = float(wrap_to_pi(angle(elbows[1] - A) - o2)) / _STEP
    p0 = plane(z4)
    o3 = angle(p0 - elbows[0])
    q2 = np.array([0, _STEP, 0, 0])
    g32 = float(wrap_to_pi(angle(plane(q2) - elbows[1]) - o3)) / _STEP
    g33 = float(wrap_to_pi(angle(plane(np.array([0, 0, _STEP, 0])) - elbows[0]) - o3)) / _STEP
    R_n0 = T_R_O[:3, :3].T @ T0[:3, :3]
    return PalletizerParameters(float(A[0]), float(A[1]), b, L2, L3, s1, s4, g22, o2, g32, g33,
                                o3, v_n, R_n0, T_R_O, np.eye(4))
