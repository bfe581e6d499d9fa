"""Kinematics of a chain of joint axes given as a DH :class:`~robotcell.robot.robot.Robot`.

Two things the exports and the positioner need beyond the chain's FK:

- :func:`axis_frames` splits the chain into constant frames and elementary motions along or about
  Z, ``T_base_flange(q) = pre_1 M_1(q_1) pre_2 M_2(q_2) ... pre_n M_n(q_n) post`` (after the
  chain's ``base``), which is how URDF joints and KUKA's external-kinematics frames (``$ETx_TA1KR``,
  ``$ETx_TA2A1``, ...; "Z is the axis of motion") describe a chain;
- :func:`normal_up` chooses the two axis values of a 2-axis positioner that turn a direction
  carried by its last axis straight up (the weld normal of a part on a tilt-rotate positioner).

SI units: metres, radians.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.kinematics.bounds import LIMIT_TOL, within
from robotcell.kinematics.dh import link_transform
from robotcell.robot.robot import Robot

__all__ = ["axis_frames", "normal_up"]


def axis_frames(robot: Robot) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Constant frames between the joint motions of a DH chain.

    Parameters
    ----------
    robot : Robot
        The chain (standard or modified DH); its ``base`` is not included.

    Returns
    -------
    pre : ndarray, shape (n, 4, 4)
        ``pre_i``: pose of joint ``i``'s frame (Z on the axis, positive turn or slide = the
        controller's positive value times the joint's sign) in the frame of the previous joint
        after its motion (``pre_1``: in frame 0 of the chain).
    post : ndarray, shape (4, 4)
        From the last joint's frame after its motion to the flange (``T_n_F`` included).

    Notes
    -----
    Standard DH ``T_{i-1,i}(q) = M_i(q) S_i`` with ``S_i = Rot(z, theta_i) Trans(z, d_i) Trans(x,
    a_i) Rot(x, alpha_i) Rot(y, beta_i)`` at the constant offsets, so ``pre_1 = I``, ``pre_i = S_{i-1}``,
    ``post = S_n T_n_F``. Modified DH ``T_{i-1,i}(q) = S_i M_i(q)``, so ``pre_i = S_i`` and
    ``post = T_n_F``. ``M_i`` is ``Rot(z, sign_i q_i)`` or ``Trans(z, sign_i q_i)``.
    """
    S = np.array([link_transform(j.theta, j.d, j.a, j.alpha, robot.convention, j.beta)
                  for j in robot.joints])
    if robot.convention == "standard":
        pre = np.concatenate([np.eye(4)[None], S[:-1]])
        return pre, S[-1] @ robot.flange
    return S, np.array(robot.flange, dtype=float)


def _angle_about(k: NDArray[np.float64], u: NDArray[np.float64], v: NDArray[np.float64]
                 ) -> NDArray[np.float64]:
    """Angle turning ``u`` onto ``v`` about the unit axis ``k`` (Paden-Kahan subproblem 1)."""
    up = u - np.sum(u * k, axis=-1, keepdims=True) * k
    vp = v - np.sum(v * k, axis=-1, keepdims=True) * k
    return np.arctan2(np.sum(k * np.cross(up, vp), axis=-1), np.sum(up * vp, axis=-1))


def normal_up(chain: Robot, R_world_0: ArrayLike, normal: ArrayLike,
              up: ArrayLike = (0.0, 0.0, 1.0)) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Axis values of a 2-axis positioner that turn ``normal`` onto ``up``.

    The positioner's plate orientation is ``R_world_P(v) = R_world_0 P_0 Rz(phi_1) P_1 Rz(phi_2)
    P_2`` with ``phi_i = sign_i v_i`` (:func:`axis_frames`). Turning the plate direction
    ``normal`` onto ``up`` is Paden and Kahan's subproblem 2 (two rotations about intersecting
    axes taking one vector onto another; Murray, Li, Sastry, "A Mathematical Introduction to
    Robotic Manipulation", 1994, section 3.2.2): up to two solutions.

    Parameters
    ----------
    chain : Robot
        The positioner chain: 2 revolute joints (tilt, then rotate).
    R_world_0 : array_like, shape (..., 3, 3) or (..., 4, 4)
        Orientation of the chain's frame 0 in the world (base included).
    normal : array_like, shape (..., 3)
        Direction in the plate frame P (the chain's flange) to turn up, e.g. a weld's surface
        normal.
    up : array_like, shape (3,)
        The direction in the world to turn it onto; default +Z.

    Returns
    -------
    values : ndarray, shape (..., 2, 2)
        The two solutions ``[k, :]`` = (v_1, v_2) in radians, each wrapped into the axis limits
        when a whole turn does so (NaN when the direction cannot be turned up).
    valid : ndarray of bool, shape (..., 2)
        Solution exists and lies within the axis limits.
    """
    if chain.n_joints != 2 or np.any(chain.prismatic):
        raise InputError("turning a direction up needs a positioner of 2 revolute axes, got "
                         f"{chain.n_joints} axes")
    R0 = np.asarray(R_world_0, dtype=float)[..., :3, :3]
    n = np.asarray(normal, dtype=float)
    length = np.linalg.norm(n, axis=-1, keepdims=True)
    if np.any(length < 1e-12) or not np.all(np.isfinite(n)):
        raise InputError("the direction to turn up must be a finite non-zero vector")
    n = n / length
    pre, post = axis_frames(chain)
    # R0 P0 Rz(phi1) P1 Rz(phi2) P2 n = up  <=>  Rz(phi1) Rot(w, phi2) m = g
    P1 = pre[1, :3, :3]
    g = np.einsum("...ji,...j->...i", R0 @ pre[0, :3, :3], np.asarray(up, dtype=float))
    m = np.einsum("ij,...j->...i", P1 @ post[:3, :3], n)
    z = np.array([0.0, 0.0, 1.0])
    w = P1[:, 2]
    zw = float(z @ w)
    cross = np.cross(z, w)
    denom = zw * zw - 1.0
    if abs(denom) < 1e-12:
        raise InputError("the two positioner axes are parallel: they cannot turn a direction "
                         "up independently")
    wm, zg = m @ w, g @ z
    alpha = (zw * wm - zg) / denom
    beta = (zw * zg - wm) / denom
    gamma2 = (np.sum(m * m, axis=-1) - alpha**2 - beta**2 - 2 * alpha * beta * zw) / (cross @ cross)
    exists = gamma2 >= -1e-12
    gamma = np.sqrt(np.clip(gamma2, 0.0, None))
    out = np.full(np.shape(gamma) + (2, 2), np.nan)
    for k, sgn in enumerate((1.0, -1.0)):
        c = (alpha[..., None] * z + beta[..., None] * w + (sgn * gamma)[..., None] * cross)
        phi2 = _angle_about(w, m, c)
        phi1 = _angle_about(z, c, g)
        out[..., k, 0] = phi1
        out[..., k, 1] = phi2
    signs = np.array([j.sign for j in chain.joints])
    values = out * signs
    values[~exists] = np.nan
    # a whole turn more or less where that brings a value inside its limits
    # (2 pi written out: importing robotcell.ik.limits would load the whole IK package into
    # every command that reads a cell file)
    lo, hi, turn = chain.lower, chain.upper, 2.0 * np.pi
    low, high = values < lo - LIMIT_TOL, values > hi + LIMIT_TOL
    shift = np.where(low, np.ceil((lo - values) / turn),
                     np.where(high, -np.ceil((values - hi) / turn), 0.0))
    values = values + np.nan_to_num(shift) * turn
    with np.errstate(invalid="ignore"):
        valid = np.all(within(values, lo, hi), axis=-1)
    return values, valid
