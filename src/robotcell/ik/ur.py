"""Analytic inverse kinematics of Universal-Robots-type arms (three parallel middle axes).

The structure: axis 1 meets axis 2 at a right angle, axes 2, 3 and 4 are parallel, axis 5 is
perpendicular to axis 4 and meets it, axis 6 is perpendicular to axis 5 and meets it. Any such
model is brought to the canonical standard DH table of Universal Robots (support article "DH
parameters for calculations of kinematics and dynamics")::

    i   a    alpha   d
    1   0    pi/2    d1
    2   a2   0       0
    3   a3   0       0
    4   0    pi/2    d4
    5   0    -pi/2   d5
    6   0    0       d6

with ``theta_i = sign_i * q_i + offset_i``. The solution follows the geometric derivation of
K. P. Hawkins, "Analytic inverse kinematics for the Universal Robots UR-5/UR-10 arms" (Georgia
Tech, 2013): axis 1 from the wrist-1 point's offset ``d4`` out of the arm plane, axis 5 from the
angle between axis 6 and the common direction of axes 2-4, axis 6 from the same direction seen in
the flange frame, then a planar two-link problem for axes 2 and 3. Unlike Hawkins, the angle of
axis 5 is taken from the orientation alone (``atan2``, accurate at the wrist singularity) and axes
2-4 are solved from the already computed axes 1, 5 and 6, so every branch reproduces the pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from robotcell.errors import InputError
from robotcell.ik.axes import (
    AXIS_TOL,
    angle_deg,
    closest_point,
    joint_axes,
    line_distance,
    six_revolute_problems,
)
from robotcell.kinematics.arm import Arm
from robotcell.kinematics.dh import link_transform
from robotcell.kinematics.transforms import invert

__all__ = ["URParameters", "ur_fk", "ur_parameters", "ur_problems"]

#: Below this sine of the canonical t5 the wrist is treated as exactly singular: axis 6 is free and
#: chosen by :func:`robotcell.ik.kernels._free_t6` (axes 2-4 then take the rest of the rotation).
SINGULAR_TOL = 1e-12
_ALPHA = np.array([math.pi / 2, 0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0])


@dataclass(frozen=True)
class URParameters:
    """The canonical UR description of a robot (metres, radians).

    Attributes
    ----------
    d1, a2, a3, d4, d5, d6 : float
        Canonical DH lengths (see the module docstring).
    signs, offsets : ndarray, shape (6,)
        ``theta_i = signs_i * q_i + offsets_i``.
    T_R_O : ndarray, shape (4, 4)
        Pose of the canonical DH frame 0 in the robot base frame R.
    T_e_n : ndarray, shape (4, 4)
        Pose of the robot's last DH frame n in the canonical frame 6.
    """

    d1: float
    a2: float
    a3: float
    d4: float
    d5: float
    d6: float
    signs: NDArray[np.float64]
    offsets: NDArray[np.float64]
    T_R_O: NDArray[np.float64]
    T_e_n: NDArray[np.float64]


def ur_problems(robot: Arm) -> list[str]:
    """Reasons why ``robot`` is not a Universal-Robots-type arm (empty if it is)."""
    basic = six_revolute_problems(robot)
    if basic:
        return basic
    p, u = joint_axes(robot)
    out = []
    for i, j in ((0, 1), (3, 4), (4, 5)):
        if abs(float(u[i] @ u[j])) > AXIS_TOL:
            out.append(f"axes {i + 1} and {j + 1} are not perpendicular "
                       f"({angle_deg(u[i], u[j]):.9g} deg)")
    for i, j in ((1, 2), (1, 3)):
        if np.linalg.norm(np.cross(u[i], u[j])) > AXIS_TOL:
            out.append(f"axes {i + 1} and {j + 1} are not parallel "
                       f"({angle_deg(u[i], u[j]):.9g} deg)")
    for i, j in ((0, 1), (3, 4), (4, 5)):
        d = line_distance(p[i], u[i], p[j], u[j])
        if d > AXIS_TOL:
            out.append(f"axes {i + 1} and {j + 1} do not intersect ({d * 1e3:.6g} mm apart)")
    if not out:
        for i, j in ((1, 2), (2, 3)):
            if line_distance(p[i], u[i], p[j], u[j]) < AXIS_TOL:
                out.append(f"axes {i + 1} and {j + 1} coincide")
    return out


def _signed_length(v: NDArray[np.float64]) -> tuple[float, float]:
    """Write a planar vector as ``a * (cos t, sin t)`` with ``|t| <= pi/2``: returns ``(a, t)``."""
    length = float(np.hypot(v[0], v[1]))
    a = -length if v[0] < -AXIS_TOL else length
    return a, math.atan2(v[1] / a, v[0] / a)


def ur_fk(params: URParameters, theta: NDArray[np.float64]) -> NDArray[np.float64]:
    """Canonical forward kinematics ``T_O_6`` (m) for canonical angles ``theta`` (..., 6) (rad)."""
    th = np.asarray(theta, dtype=float)
    pa = params
    a = [0.0, pa.a2, pa.a3, 0.0, 0.0, 0.0]
    d = [pa.d1, 0.0, 0.0, pa.d4, pa.d5, pa.d6]
    T = np.broadcast_to(np.eye(4), th.shape[:-1] + (4, 4))
    for i in range(6):
        T = T @ link_transform(th[..., i], d[i], a[i], _ALPHA[i])
    return T


def ur_parameters(robot: Arm) -> URParameters:
    """Derive the canonical UR parameters of a robot model.

    Frame O: z along axis 1 (its positive direction), y opposite to axis 2 (so that the canonical
    ``alpha_1 = +pi/2`` holds with ``sign_2 = +1``), origin on axis 1 at the foot of the
    perpendicular from R's origin. ``a2`` and ``a3`` carry the sign that keeps their offsets within
    +-90 degrees (Universal Robots' own tables have negative ``a2``, ``a3``).

    Raises
    ------
    InputError
        When the model lacks the structure; the message names every failed condition.
    """
    problems = ur_problems(robot)
    if problems:
        raise InputError(f"{robot.name} is not a Universal-Robots-type arm: "
                         + "; ".join(problems) + ".")
    p, u = joint_axes(robot)
    z = u[0]
    y = -u[1]
    x = np.cross(y, z)
    origin = p[0] - z * float(z @ p[0])
    T_R_O = np.eye(4)
    T_R_O[:3, 0], T_R_O[:3, 1], T_R_O[:3, 2], T_R_O[:3, 3] = x, y, z, origin
    T_O_R = invert(T_R_O)
    P = p @ T_O_R[:3, :3].T + T_O_R[:3, 3]
    U = u @ T_O_R[:3, :3].T
    d1 = float(closest_point(P[0], U[0], P[1], U[1])[2])
    # Planar coordinates in the canonical frame 1 at theta1 = 0: (x_O, z_O - d1).

    def plane(v: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.array([v[0], v[2] - d1])

    a2, off2 = _signed_length(plane(P[2]) - plane(P[1]))
    a3, t23 = _signed_length(plane(P[3]) - plane(P[2]))
    off3 = t23 - off2
    s3 = -1.0 if float(U[2] @ U[1]) < 0 else 1.0
    s4 = -1.0 if float(U[3] @ U[1]) < 0 else 1.0
    # Canonical z4 = Rz(t234) (0, -1, 0) in frame-1 coordinates (x1, y1, z1) = (x_O, z_O, -y_O).
    u5 = np.array([U[4][0], U[4][2], -U[4][1]])
    t234 = math.atan2(u5[0], -u5[1])
    off4 = t234 - t23
    p45 = closest_point(P[3], U[3], P[4], U[4])
    p56 = closest_point(P[4], U[4], P[5], U[5])
    d4 = -float(p45[1])  # offset along the canonical z1 = -y_O
    d5 = float((p56 - p45) @ U[4])
    F = robot.frames(np.zeros(6))
    d6 = float(((T_O_R @ F[-1])[:3, 3] - p56) @ U[5])
    ones = np.ones(6)
    partial = URParameters(d1, a2, a3, d4, d5, d6, ones, np.zeros(6), T_R_O, np.eye(4))
    # Axis 5 angle: canonical z5 = -sin(t5) x4 + cos(t5) y4, with frame 4 from the canonical FK.
    R4 = ur_fk_frames(partial, np.array([0.0, off2, off3, off4, 0.0, 0.0]))[:3, :3]
    u6 = R4.T @ U[5]
    off5 = math.atan2(-u6[0], u6[1])
    signs = np.array([1.0, 1.0, s3, s4, 1.0, 1.0])
    offsets = np.array([0.0, off2, off3, off4, off5, 0.0])
    T_e_n = invert(ur_fk(partial, offsets)) @ T_O_R @ F[-1]
    return URParameters(d1, a2, a3, d4, d5, d6, signs, offsets, T_R_O, T_e_n)


def ur_fk_frames(params: URParameters, theta: NDArray[np.float64]) -> NDArray[np.float64]:
    """Canonical ``T_O_4`` (pose of frame 4) for one set of canonical angles, shape (4, 4)."""
    pa = params
    a = [0.0, pa.a2, pa.a3, 0.0]
    d = [pa.d1, 0.0, 0.0, pa.d4]
    T = np.eye(4)
    for i in range(4):
        T = T @ link_transform(theta[i], d[i], a[i], _ALPHA[i])
    return T
