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
from robotcell.ik.limits import wrap_to_pi
from robotcell.ik.opw import ROUND, _controller_angle, reach_distance
from robotcell.ik.result import REACH_TOL
from robotcell.kinematics.arm import Arm
from robotcell.kinematics.dh import link_transform
from robotcell.kinematics.transforms import invert

__all__ = ["URParameters", "ur_fk", "ur_kernel", "ur_parameters", "ur_problems"]

#: Below this sine of the canonical t5 the wrist is treated as exactly singular: axis 6 is free and
#: chosen by :func:`_free_t6` (axes 2-4 then take the rest of the rotation).
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


def _free_t6(c: tuple[NDArray[np.float64], NDArray[np.float64]],
             u: tuple[NDArray[np.float64], NDArray[np.float64]],
             w: tuple[NDArray[np.float64], NDArray[np.float64]],
             target: NDArray[np.float64], d5: float, rmin: float, rmax: float
             ) -> NDArray[np.float64]:
    """Canonical t6 (rad) at the wrist singularity: nearest to ``target`` with axes 2/3 in reach.

    At ``sin t5 = 0`` axis 6 is parallel to axes 2-4 and only the sum of the angles is fixed. Axis
    6 then moves the wrist-1 point on a circle of radius ``d5`` around the planar position ``c``
    of the wrist-2 point: ``p(t6) = c + d5 (sin t6 u + cos t6 w)`` (``u``, ``w`` the planar
    directions of the flange's x and y axes). The planar problem of axes 2 and 3 is solvable where
    ``rmin <= |p| <= rmax``, an arc of angles ``|theta| in [ta, tb]`` around the direction of ``c``;
    the target angle is moved onto it (onto its nearest point to the reach when it is empty).
    """
    cx, cy = c
    cn = np.hypot(cx, cy)
    safe = np.where(cn > 0, cn, 1.0)
    ex, ey = cx / safe, cy / safe
    lo = (rmin * rmin - cn * cn - d5 * d5) / (2 * d5 * safe)
    hi = (rmax * rmax - cn * cn - d5 * d5) / (2 * d5 * safe)
    ta = np.arccos(np.clip(hi, -1.0, 1.0))
    tb = np.arccos(np.clip(lo, -1.0, 1.0))
    st, ct = np.sin(target), np.cos(target)
    vx, vy = st * u[0] + ct * w[0], st * u[1] + ct * w[1]
    th = np.arctan2(ex * vy - ey * vx, ex * vx + ey * vy)
    th = np.where(th < 0, -1.0, 1.0) * np.clip(np.abs(th), ta, tb)
    vx, vy = np.cos(th) * ex - np.sin(th) * ey, np.sin(th) * ex + np.cos(th) * ey
    t6 = np.arctan2(vx * u[0] + vy * u[1], vx * w[0] + vy * w[1])
    return np.where(cn > 0, t6, target)


def ur_kernel(params: URParameters, R: NDArray[np.float64], P: NDArray[np.float64],
              out: NDArray[np.float64], err: NDArray[np.float64],
              ref: NDArray[np.float64] | None = None,
              lower: NDArray[np.float64] | None = None,
              upper: NDArray[np.float64] | None = None) -> NDArray[np.bool_]:
    """All 8 solutions, as controller axis values, for poses of frame 6 expressed in O.

    Parameters
    ----------
    params : URParameters
    R : ndarray, shape (N, 3, 3)
        Rotations ``R_O_6``.
    P : ndarray, shape (N, 3)
        Positions ``p_O_6`` (m).
    out : ndarray, shape (N, 8, 6)
        Receives the controller values ``q = sign * (theta - offset)`` in ``(-pi, pi]`` (rad);
        branch ``k = 4 * shoulder + 2 * elbow + wrist``:
        shoulder 1 = second solution of axis 1, wrist 1 = negative canonical ``t5``, elbow 1 =
        negative canonical ``t3``. Unreachable branches are NaN.
    err : ndarray, shape (N, 8)
        Receives the distance (m) of the wrist points outside the branch's reach (0 inside).
    ref : ndarray, shape (N, 6), optional
        Reference controller values (rad): at the wrist singularity axis 6 is chosen nearest to
        the reference's axis 6 (default: canonical 0) among the values that keep axes 2 and 3 in
        reach.
    lower, upper : ndarray, shape (6,), optional
        Not needed by this structure (same signature as the other kernels).

    Returns
    -------
    ndarray of bool, shape (N, 8)
        Which branches reach the pose (``err <= REACH_TOL``).
    """
    pa = params
    X0, X1, X2 = R[:, 0, 0], R[:, 1, 0], R[:, 2, 0]
    Y0, Y1, Y2 = R[:, 0, 1], R[:, 1, 1], R[:, 2, 1]
    Z0, Z1, Z2 = R[:, 0, 2], R[:, 1, 2], R[:, 2, 2]
    p5x = P[:, 0] - pa.d6 * Z0
    p5y = P[:, 1] - pa.d6 * Z1
    p5z = P[:, 2] - pa.d6 * Z2
    r2 = p5x * p5x + p5y * p5y
    a2, a3 = pa.a2, pa.a3
    rmax, rmin = abs(a2) + abs(a3), abs(abs(a2) - abs(a3))
    rnd = ROUND * 2 * (abs(pa.d1) + rmax + abs(pa.d4) + abs(pa.d5) + abs(pa.d6))
    r = np.sqrt(r2)
    # The wrist-2 point must not be nearer to axis 1 than d4.
    err_sh = reach_distance(0.0, abs(pa.d4) - r, rnd)
    inv_r = 1.0 / np.where(r2 > 0, r, 1.0)
    t = np.clip(pa.d4 * inv_r, -1.0, 1.0)
    k = np.sqrt(1.0 - t * t)
    den3 = 1.0 / (2.0 * a2 * a3)
    reach = np.empty((P.shape[0], 8), dtype=bool)
    ang = _controller_angle(pa.signs, pa.offsets)
    t6_ref = 0.0 if ref is None else pa.signs[5] * ref[:, 5] + pa.offsets[5]
    for sh in (0, 1):
        kk = k if sh == 0 else -k
        c1 = (p5x * kk - p5y * t) * inv_r
        s1 = (p5y * kk + p5x * t) * inv_r
        t1q = ang(0, s1, c1)
        vx = X0 * s1 - X1 * c1
        vy = Y0 * s1 - Y1 * c1
        vz = Z0 * s1 - Z1 * c1
        h = np.sqrt(vx * vx + vy * vy)
        t6p = np.arctan2(-vy, vx)
        free6 = np.flatnonzero(h < SINGULAR_TOL)
        for wr in (0, 1):
            t6 = t6p if wr == 0 else t6p + math.pi
            if free6.size:
                t6 = t6.copy()
                f, cf, sf = free6, c1[free6], s1[free6]
                target = np.broadcast_to(t6_ref, t6.shape)[f] + wr * math.pi
                t6[f] = (target if pa.d5 == 0 else
                         _free_t6((cf * p5x[f] + sf * p5y[f], p5z[f] - pa.d1),
                                  (cf * X0[f] + sf * X1[f], X2[f]), (cf * Y0[f] + sf * Y1[f], Y2[f]),
                                  target, pa.d5, rmin, rmax))
            s5 = h if wr == 0 else -h
            c5 = vz
            s6, c6 = np.sin(t6), np.cos(t6)
            q5 = ang(4, s5, c5)
            q6 = ang(5, s6, c6)
            z4x, z4y, z4z = -s6 * X0 - c6 * Y0, -s6 * X1 - c6 * Y1, -s6 * X2 - c6 * Y2
            # x4 = c5 c6 X6 - c5 s6 Y6 - s5 Z6 (c5, s5 scaled alike by the unit length of v)
            x4x = c5 * (c6 * X0 - s6 * Y0) - s5 * Z0
            x4y = c5 * (c6 * X1 - s6 * Y1) - s5 * Z1
            x4z = c5 * (c6 * X2 - s6 * Y2) - s5 * Z2
            p4x = p5x - pa.d5 * z4x
            p4y = p5y - pa.d5 * z4y
            p4z = p5z - pa.d5 * z4z
            px = c1 * p4x + s1 * p4y
            py = p4z - pa.d1
            t234 = np.arctan2(x4z, c1 * x4x + s1 * x4y)
            pr = np.sqrt(px * px + py * py)
            # The wrist-1 point must lie between the folded and the stretched elbow.
            e = np.sqrt(reach_distance(err_sh, np.maximum(pr - rmax, rmin - pr), rnd))
            ok = e <= REACH_TOL
            D = np.clip((pr * pr - a2 * a2 - a3 * a3) * den3, -1.0, 1.0)
            S = np.sqrt(1.0 - D * D)
            for el in (0, 1):
                s3 = S if el == 0 else -S
                wx = a2 + a3 * D
                wy = a3 * s3
                t2 = np.arctan2(py * wx - px * wy, px * wx + py * wy)
                t3 = np.arctan2(s3, D)
                kidx = 4 * sh + 2 * el + wr
                out[:, kidx, 0] = t1q
                out[:, kidx, 1] = wrap_to_pi((t2 - pa.offsets[1]) * pa.signs[1])
                out[:, kidx, 2] = wrap_to_pi((t3 - pa.offsets[2]) * pa.signs[2])
                out[:, kidx, 3] = wrap_to_pi((t234 - t2 - t3 - pa.offsets[3]) * pa.signs[3])
                out[:, kidx, 4] = q5
                out[:, kidx, 5] = q6
                reach[:, kidx] = ok
                err[:, kidx] = e
    out[~reach] = np.nan
    return reach
