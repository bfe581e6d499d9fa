"""Analytic inverse kinematics of ortho-parallel arms with a spherical wrist.

The method is Brandstoetter, Angerer and Hofbaur, "An analytical solution of the inverse
kinematics problem of industrial serial manipulators with an ortho-parallel basis and a spherical
wrist", Austrian Robotics Workshop 2014 (the method of ROS-Industrial's opw_kinematics). In the
paper's frame O (z along axis 1; axes 2 and 3 along y at zero) the arm is described by seven
lengths: ``a1`` (axis 1 to axis 2 along x), ``c1`` (height of axis 2), ``c2`` (axis 2 to axis 3),
``a2`` and ``c3`` (axis 3 to the wrist centre, across and along the forearm), ``b`` (lateral
offset) and ``c4`` (wrist centre to flange). With ``theta = sign * q + offset``::

    R_O_e = Rz(t1) Ry(t2 + t3) Rz(t4) Ry(t5) Rz(t6)
    wrist = Rz(t1) [a1 + c2 sin t2 + a2 cos t23 + c3 sin t23, b, c1 + c2 cos t2 - a2 sin t23 + c3 cos t23]
    p_O_e = wrist + c4 * R_O_e[:, 2]

:func:`opw_parameters` derives all of this from any robot model whose axes have that structure,
numerically from the axis lines at ``q = 0``. The solver follows the paper's geometry but
computes every angle from sines and cosines that are kept consistent with each other (each
joint's angle is solved from the already computed previous ones), so that every returned branch
reproduces the pose to rounding error, also next to singular configurations.
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
from robotcell.kinematics.transforms import invert, rot_y, rot_z

__all__ = ["OPWParameters", "opw_fk", "opw_parameters", "opw_problems"]

#: Below this distance (m) of the wrist centre from axis 1, and this sine of the paper's angle
#: t5, the configuration is treated as exactly singular: axis 1, respectively axis 4, is free and
#: chosen (see :func:`robotcell.ik.kernels._opw`; the pose error this admits is at most this size).
SINGULAR_TOL = 1e-12
#: Relative rounding of the wrist centre and the arm's lengths (times their size in m): a pose
#: outside reach by less is inside up to rounding (reported with ``reach_error`` 0).
ROUND = 64 * np.finfo(float).eps


@dataclass(frozen=True)
class OPWParameters:
    """The ortho-parallel description of a robot (lengths in metres, angles in radians).

    Attributes
    ----------
    a1, a2, b, c1, c2, c3, c4 : float
        Lengths of Brandstoetter et al. (2014), in the frame O.
    signs, offsets : ndarray, shape (6,)
        ``theta_i = signs_i * q_i + offsets_i`` maps controller axis values to the paper's angles.
        (opw_kinematics writes ``theta = q * sign_corrections - offsets``.)
    T_R_O : ndarray, shape (4, 4)
        Pose of the frame O in the robot base frame R.
    T_e_n : ndarray, shape (4, 4)
        Pose of the robot's last DH frame n in the paper's end frame e.
    """

    a1: float
    a2: float
    b: float
    c1: float
    c2: float
    c3: float
    c4: float
    signs: NDArray[np.float64]
    offsets: NDArray[np.float64]
    T_R_O: NDArray[np.float64]
    T_e_n: NDArray[np.float64]


def opw_problems(robot: Arm) -> list[str]:
    """Reasons why ``robot`` is not an ortho-parallel arm with a spherical wrist (empty if it is).

    Parameters
    ----------
    robot : Arm

    Returns
    -------
    list of str
        One sentence per failed condition, naming the axes.
    """
    basic = six_revolute_problems(robot)
    if basic:
        return basic
    p, u = joint_axes(robot)
    out = []
    for i, j in ((0, 1), (2, 3), (3, 4), (4, 5)):
        if abs(float(u[i] @ u[j])) > AXIS_TOL:
            out.append(f"axes {i + 1} and {j + 1} are not perpendicular "
                       f"({angle_deg(u[i], u[j]):.9g} deg)")
    if np.linalg.norm(np.cross(u[1], u[2])) > AXIS_TOL:
        out.append(f"axes 2 and 3 are not parallel ({angle_deg(u[1], u[2]):.9g} deg)")
    elif line_distance(p[1], u[1], p[2], u[2]) < AXIS_TOL:
        out.append("axes 2 and 3 coincide")
    for i, j in ((3, 4), (4, 5), (3, 5)):
        d = line_distance(p[i], u[i], p[j], u[j])
        if d > AXIS_TOL:
            out.append(f"axes {i + 1} and {j + 1} do not intersect (they are {d * 1e3:.6g} mm "
                       "apart): the wrist is not spherical")
    return out


def _frame(x: NDArray[np.float64], y: NDArray[np.float64], z: NDArray[np.float64],
           o: NDArray[np.float64]) -> NDArray[np.float64]:
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, y, z, o
    return T


def _pick(sign_source: float) -> float:
    """+1 unless ``sign_source`` is clearly negative."""
    return -1.0 if sign_source < -AXIS_TOL else 1.0


def opw_parameters(robot: Arm) -> OPWParameters:
    """Derive the ortho-parallel parameters of a robot model.

    The frame O has its z axis along axis 1 (pointing to the same side as ``Z_R``), its y axis
    along axis 2 (pointing to the same side as ``Y_R``) and its origin on axis 1 at the foot of the
    perpendicular from R's origin. The offsets put the paper's zero (arm upright, ``c2 > 0``, axis
    4 pointing from axis 3 away to the wrist centre, wrist straight) where the model has it.

    Parameters
    ----------
    robot : Arm
        Six revolute joints: axis 1 perpendicular to axis 2, axes 2 and 3 parallel, axis 4
        perpendicular to axis 3, axes 4, 5, 6 mutually perpendicular and meeting in one point.

    Returns
    -------
    OPWParameters

    Raises
    ------
    InputError
        When the model lacks that structure; the message names every failed condition.
    """
    problems = opw_problems(robot)
    if problems:
        raise InputError(
            f"{robot.name} is not an ortho-parallel arm with a spherical wrist: "
            + "; ".join(problems)
            + ". Use robotcell.ik.solve_numeric for this model."
        )
    p, u = joint_axes(robot)
    s1 = _pick(float(u[0, 2]))
    z = s1 * u[0]
    s2 = _pick(float(u[1, 1]))
    y = s2 * u[1]
    x = np.cross(y, z)
    origin = p[0] - z * float(z @ p[0])
    T_R_O = _frame(x, y, z, origin)
    T_O_R = invert(T_R_O)
    R, t = T_O_R[:3, :3], T_O_R[:3, 3]
    P = p @ R.T + t  # axis points in O
    U = u @ R.T  # axis directions in O
    f2 = P[1]  # axis 2 lies along y: its x and z are constant
    a1, c1 = float(f2[0]), float(f2[2])
    f3 = P[2]
    v23 = np.array([f3[0] - a1, f3[2] - c1])
    c2 = float(np.hypot(*v23))
    off2 = math.atan2(v23[0], v23[1])
    s3 = _pick(float(U[2] @ y))
    wc = closest_point(P[3], U[3], P[4], U[4])
    b = float(wc[1])
    w = np.array([wc[0] - f3[0], wc[2] - f3[2]])
    e4 = U[3] if float(U[3][[0, 2]] @ w) >= -AXIS_TOL else -U[3]
    t23 = math.atan2(e4[0], e4[2])
    s4 = _pick(float(U[3] @ e4))
    off3 = t23 - off2
    ct, st = math.cos(t23), math.sin(t23)
    a2 = float(w[0] * ct - w[1] * st)
    c3 = float(w[0] * st + w[1] * ct)
    R_c = rot_y(t23)
    u5 = R_c.T @ U[4]
    s5 = _pick(float(u5[1]))
    off4 = math.atan2(-s5 * u5[0], s5 * u5[1])
    u6 = rot_z(off4).T @ R_c.T @ U[5]
    s6 = _pick(float(u6[2]))
    off5 = math.atan2(s6 * u6[0], s6 * u6[2])
    flange = (T_O_R @ robot.frames(np.zeros(6))[-1] @ robot.flange)[:3, 3]
    c4 = float((flange - wc) @ (s6 * U[5]))
    signs = np.array([s1, s2, s3, s4, s5, s6])
    offsets = np.array([0.0, off2, off3, off4, off5, 0.0])
    partial = OPWParameters(a1, a2, b, c1, c2, c3, c4, signs, offsets, T_R_O, np.eye(4))
    T_O_n = T_O_R @ robot.frames(np.zeros(6))[-1]
    T_e_n = invert(opw_fk(partial, offsets)) @ T_O_n
    return OPWParameters(a1, a2, b, c1, c2, c3, c4, signs, offsets, T_R_O, T_e_n)


def opw_fk(params: OPWParameters, theta: NDArray[np.float64]) -> NDArray[np.float64]:
    """Forward kinematics in the paper's form.

    Parameters
    ----------
    params : OPWParameters
    theta : ndarray, shape (..., 6)
        The paper's joint angles (rad), ``signs * q + offsets``.

    Returns
    -------
    ndarray, shape (..., 4, 4)
        ``T_O_e``, pose of the paper's end frame in O (m).
    """
    th = np.asarray(theta, dtype=float)
    t1, t2, t3, t4, t5, t6 = np.moveaxis(th, -1, 0)
    t23 = t2 + t3
    R = rot_z(t1) @ rot_y(t23) @ rot_z(t4) @ rot_y(t5) @ rot_z(t6)
    pa = params
    arm = np.stack([
        pa.a1 + pa.c2 * np.sin(t2) + pa.a2 * np.cos(t23) + pa.c3 * np.sin(t23),
        np.full_like(t1, pa.b),
        pa.c1 + pa.c2 * np.cos(t2) - pa.a2 * np.sin(t23) + pa.c3 * np.cos(t23),
    ], axis=-1)
    wrist = (rot_z(t1) @ arm[..., None])[..., 0]
    T = np.zeros(th.shape[:-1] + (4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = wrist + pa.c4 * R[..., :, 2]
    T[..., 3, 3] = 1.0
    return T
