"""Choosing one solution the way a controller does: nearest to a configuration, or by flags.

Every function takes the :class:`~robotcell.ik.result.IKSolutions` of a batch and returns one
configuration per pose plus a ``found`` mask; revolute joints may move to a 2*pi-equivalent
inside the limits (that is how a taught configuration with A6 = -300 deg is matched).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.ik.config import abb_confdata, kuka_status_turn
from robotcell.ik.limits import TWO_PI, shift_into_interval
from robotcell.ik.result import IKSolutions
from robotcell.kinematics.arm import Arm
from robotcell.kinematics.bounds import within

__all__ = ["nearest", "select_abb", "select_kuka"]


def _pick(q: NDArray[np.float64], ok: NDArray[np.bool_], cost: NDArray[np.float64] | None = None
          ) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.int_]]:
    """First (or cheapest) branch with ``ok``: q (..., n), found (...), branch (..., -1 if none)."""
    key = np.where(ok, 0.0 if cost is None else cost, np.inf)
    k = np.argmin(key, axis=-1)
    found = np.any(ok, axis=-1)
    out = np.take_along_axis(q, k[..., None, None], axis=-2)[..., 0, :]
    out = np.where(found[..., None], out, np.nan)
    return out, found, np.where(found, k, -1)


def nearest(robot: Arm, solutions: IKSolutions, q_ref: ArrayLike,
            weights: ArrayLike | None = None
            ) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.int_]]:
    """The valid solution nearest to a reference configuration.

    Each revolute joint value is first moved to its 2*pi-equivalent inside the limits nearest to
    the reference; then the branch with the smallest ``sum(weights * (q - q_ref)**2)`` wins.

    Parameters
    ----------
    robot : Arm
        The robot that produced ``solutions`` (limits, joint types); for a track robot its
        :meth:`~robotcell.ik.track.TrackRobot.as_robot`.
    solutions : IKSolutions
        ``q`` of shape ``(..., 8, n)``.
    q_ref : array_like, shape (n,) or (..., n)
        Reference configuration(s) (rad, m), e.g. the current one.
    weights : array_like, shape (n,), optional
        Per-joint weights (default 1).

    Returns
    -------
    q : ndarray, shape (..., n)
        Chosen configuration (NaN where none is valid).
    found : ndarray of bool, shape (...)
    branch : ndarray of int, shape (...)
        Index of the chosen branch, -1 where none.
    """
    n = robot.n_joints
    ref = np.asarray(q_ref, dtype=float)
    if ref.ndim == 0 or ref.shape[-1] != n:
        raise InputError(f"q_ref must have shape (..., {n}), got {ref.shape}")
    w = np.ones(n) if weights is None else np.asarray(weights, dtype=float)
    if w.shape != (n,) or np.any(w < 0):
        raise InputError(f"weights must be {n} non-negative numbers, got {weights!r}")
    q = solutions.q
    r = ref[..., None, :]
    rev = ~robot.prismatic
    k = np.where(rev, np.round((r - q) / TWO_PI), 0.0)
    cands = q[..., None] + TWO_PI * (k[..., None] + np.array([0.0, -1.0, 1.0]))  # (..., 8, n, 3)
    inside = within(cands, robot.lower[:, None], robot.upper[:, None])
    dist = np.where(inside, np.abs(cands - r[..., None]), np.inf)
    dist[..., ~rev, 1:] = np.inf
    j = np.argmin(dist, axis=-1)
    qq = np.take_along_axis(cands, j[..., None], axis=-1)[..., 0]
    ok = solutions.valid & np.all(np.take_along_axis(inside, j[..., None], axis=-1)[..., 0], axis=-1)
    cost = np.sum(w * (qq - r) ** 2, axis=-1)
    return _pick(qq, ok, cost)


def _signed(q: NDArray[np.float64], negative: NDArray[np.bool_], lo: NDArray[np.float64],
            hi: NDArray[np.float64]) -> NDArray[np.float64]:
    """The 2*pi-equivalent of ``q`` with the requested sign inside ``[lo, hi]``, else NaN."""
    nonneg = q - TWO_PI * np.floor(q / TWO_PI)  # smallest equivalent >= 0
    neg = nonneg - TWO_PI  # largest equivalent < 0
    out = np.where(negative, neg, nonneg)
    # Joints with less than one revolution of range: keep the value if it already has the sign.
    out = np.where((q < 0) == negative, np.where(within(q, lo, hi), q, out), out)
    return np.where(within(out, lo, hi), out, np.nan)


def select_kuka(robot: Arm, solutions: IKSolutions, status: ArrayLike, turn: ArrayLike
                ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """The solution with the given KUKA Status and Turn (see :mod:`robotcell.ik.config`).

    Parameters
    ----------
    robot : Arm
    solutions : IKSolutions
        From ``robot.ik``, ``q`` of shape ``(..., 8, 6)``.
    status, turn : array_like of int, shape broadcastable to (...)

    Returns
    -------
    q : ndarray, shape (..., 6)
        Joint values (rad) whose Status and Turn are the requested ones, NaN where none.
    found : ndarray of bool, shape (...)
    """
    st = np.asarray(status, dtype=int)[..., None]
    tu = np.asarray(turn, dtype=int)[..., None, None]
    negative = ((tu >> np.arange(6)) & 1).astype(bool)
    q = _signed(solutions.q, negative, robot.lower, robot.upper)
    got_status, _ = kuka_status_turn(robot, q)
    ok = solutions.reachable & ~np.any(np.isnan(q), axis=-1) & (got_status == st)
    out, found, _ = _pick(q, ok)
    return out, found


def select_abb(robot: Arm, solutions: IKSolutions, confdata: ArrayLike
               ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """The solution with the given ABB ``confdata`` ``[cf1, cf4, cf6, cfx]``.

    Parameters
    ----------
    robot : Arm
    solutions : IKSolutions
        From ``robot.ik``, ``q`` of shape ``(..., 8, 6)``.
    confdata : array_like of int, shape (..., 4)

    Returns
    -------
    q : ndarray, shape (..., 6)
        Joint values (rad) in the requested quadrants and configuration, NaN where none.
    found : ndarray of bool, shape (...)
    """
    cf = np.asarray(confdata, dtype=int)
    if cf.ndim == 0 or cf.shape[-1] != 4:
        raise InputError(f"confdata must have 4 values [cf1, cf4, cf6, cfx], got shape {cf.shape}")
    q = solutions.q.copy()
    quarter = math.pi / 2
    for col, c in ((0, cf[..., 0]), (3, cf[..., 1]), (5, cf[..., 2])):
        lo = c[..., None] * quarter
        v = shift_into_interval(q[..., col], lo, lo + quarter * (1 - 1e-15))
        q[..., col] = np.where(within(v, robot.lower[col], robot.upper[col]), v, np.nan)
    inside = np.all(within(q, robot.lower, robot.upper), axis=-1)
    got = abb_confdata(robot, np.nan_to_num(q))
    ok = solutions.reachable & inside & (got[..., 3] == cf[..., None, 3])
    out, found, _ = _pick(q, ok)
    return out, found
