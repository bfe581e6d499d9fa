"""Numeric inverse kinematics for any chain: damped least squares with Levenberg-Marquardt damping.

Works for every :class:`~robotcell.kinematics.arm.Arm` (prismatic joints, 7 or more axes, calibrated
models whose axes are no longer exactly parallel). For a batch of targets it iterates all
unconverged targets together:

1. error ``e = (p_target - p, rotvec(R_target R^T))`` in the robot base frame (m, rad);
2. step ``dq = J^T (J J^T + lambda I)^-1 e`` with the geometric Jacobian ``J`` (6 x n);
3. ``q <- clip(q + dq, lower, upper)`` if that lowers ``|e|`` (then ``lambda /= 3``), otherwise
   the step is rejected and ``lambda *= 4`` (Levenberg 1944, Marquardt 1963; for IK e.g. Sugihara,
   "Solvability-unconcerned inverse kinematics by the Levenberg-Marquardt method", IEEE T-RO 2011).

A target that has not converged after ``max_iterations`` (or whose damping grows past 1e6, a
local minimum or a joint limit) restarts from a random configuration within the limits, drawn
from a seeded generator, at most ``restarts`` times. Success is decided from the final forward
kinematics against the tolerances given: it is never reported above them.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robotcell.errors import InputError
from robotcell.ik.result import NumericIKResult
from robotcell.kinematics.arm import Arm
from robotcell.kinematics.transforms import validate_pose

__all__ = ["solve_numeric"]

_LAMBDA0 = 1e-3
_LAMBDA_MIN = 1e-12
_LAMBDA_MAX = 1e6


def _error(robot: Arm, q: NDArray[np.float64], target: NDArray[np.float64],
           tool: NDArray[np.float64] | None) -> NDArray[np.float64]:
    """6-vector error (m, rad) from the TCP at ``q`` (N, n) to ``target`` (N, 4, 4); (N, 6)."""
    T = robot.fk(q, tool=tool).reshape(-1, 4, 4)
    dp = target[:, :3, 3] - T[:, :3, 3]
    dR = target[:, :3, :3] @ np.swapaxes(T[:, :3, :3], -1, -2)
    return np.concatenate([dp, Rotation.from_matrix(dR).as_rotvec()], axis=1)


def _random_in_limits(robot: Arm, rng: np.random.Generator, m: int) -> NDArray[np.float64]:
    lo = np.where(np.isfinite(robot.lower), robot.lower, np.where(robot.prismatic, -1.0, -math.pi))
    hi = np.where(np.isfinite(robot.upper), robot.upper, np.where(robot.prismatic, 1.0, math.pi))
    return rng.uniform(lo, hi, (m, robot.n_joints))


def solve_numeric(
    robot: Arm,
    T: ArrayLike,
    q0: ArrayLike | None = None,
    *,
    tol_position: float = 1e-9,
    tol_orientation: float = 1e-9,
    max_iterations: int = 30,
    restarts: int = 150,
    seed: int = 0,
    tool: ArrayLike | None = None,
) -> NumericIKResult:
    """Find one configuration per target pose by damped least squares with restarts.

    Parameters
    ----------
    robot : Arm
        Any chain.
    T : array_like, shape (..., 4, 4)
        ``T_R_TCP``: target poses of the TCP in the robot base frame (m).
    q0 : array_like, shape (n,) or (..., n), optional
        Start configuration(s) (rad, m), e.g. an analytic solution of the nominal model. Default:
        the robot's home, else the middle of the limits (0 for unlimited joints).
    tol_position : float
        Success threshold on the position error (m).
    tol_orientation : float
        Success threshold on the orientation error (rad).
    max_iterations : int
        Iterations per attempt.
    restarts : int
        Attempts from random in-limit configurations after the first one fails.
    seed : int
        Seed of the restart generator (``np.random.default_rng``).
    tool : array_like, shape (4, 4), optional
        ``T_F_TCP`` instead of the robot's default tool (m).

    Returns
    -------
    NumericIKResult
        Fields of batch shape ``(...)``; ``q`` of shape ``(..., n)``: controller values (the
        robot's coupling, if any, is applied by its forward kinematics and Jacobian); ``success``
        is False where an interaction limit of the coupling is broken.
    """
    if tol_position <= 0 or tol_orientation <= 0:
        raise InputError("tol_position and tol_orientation must be positive")
    if max_iterations < 1 or restarts < 0:
        raise InputError("max_iterations must be >= 1 and restarts >= 0")
    arr = validate_pose(T, "target pose")
    tool_T = None if tool is None else validate_pose(tool, "tool")
    batch = arr.shape[:-2]
    target = arr.reshape(-1, 4, 4)
    N, n = target.shape[0], robot.n_joints
    q = _start(robot, q0, batch, N)
    tol = (tol_position, tol_orientation)
    rng = np.random.default_rng(seed)
    iterations = np.zeros(N, dtype=int)
    used_restarts = np.zeros(N, dtype=int)
    best_q = q.copy()
    best_cost = np.full(N, np.inf)
    done = np.zeros(N, dtype=bool)
    for attempt in range(restarts + 1):
        idx = np.flatnonzero(~done)
        if idx.size == 0:
            break
        if attempt > 0:
            q[idx] = _random_in_limits(robot, rng, idx.size)
            used_restarts[idx] += 1
        qa, e, cost = _attempt(robot, q[idx], target[idx], tool_T, tol, max_iterations,
                               iterations, idx)
        q[idx] = qa
        improved = cost < best_cost[idx]
        best_q[idx[improved]] = qa[improved]
        best_cost[idx[improved]] = cost[improved]
        done[idx] = _converged(e, tol)
    e = _error(robot, best_q, target, tool_T)
    pos = np.linalg.norm(e[:, :3], axis=1)
    ang = np.linalg.norm(e[:, 3:], axis=1)
    success = (pos <= tol_position) & (ang <= tol_orientation)
    if robot.coupling is not None:  # an interaction limit (e.g. FANUC J2/J3) is a limit too
        success &= robot.coupling.within_interaction(best_q)
    return NumericIKResult(best_q.reshape(batch + (n,)), success.reshape(batch),
                           pos.reshape(batch), ang.reshape(batch), iterations.reshape(batch),
                           used_restarts.reshape(batch))


def _start(robot: Arm, q0: ArrayLike | None, batch: tuple[int, ...], N: int
           ) -> NDArray[np.float64]:
    """The first configuration of each of the ``N`` targets of batch shape ``batch``: ``q0``, or
    the robot's home, or the middle of its limits (0 for unlimited joints); clipped to the
    limits, (N, n) (rad, m)."""
    n, lower, upper = robot.n_joints, robot.lower, robot.upper
    if q0 is None:
        mid = np.where(np.isfinite(lower) & np.isfinite(upper), (lower + upper) / 2, 0.0)
        start = robot.home if robot.home is not None else mid
        q = np.broadcast_to(start, (N, n)).copy()
    else:
        q = np.broadcast_to(robot._joints(q0, "q0"), batch + (n,)).reshape(N, n).copy()
    return np.clip(q, lower, upper)


def _converged(e: NDArray[np.float64], tol: tuple[float, float]) -> NDArray[np.bool_]:
    """Whether each error ``e`` (N, 6) is within ``tol`` (position in m, orientation in rad)."""
    return ((np.linalg.norm(e[:, :3], axis=1) <= tol[0])
            & (np.linalg.norm(e[:, 3:], axis=1) <= tol[1]))


def _attempt(robot: Arm, qa: NDArray[np.float64], ta: NDArray[np.float64],
             tool: NDArray[np.float64] | None, tol: tuple[float, float], max_iterations: int,
             iterations: NDArray[np.int_], idx: NDArray[np.int_]
             ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """One attempt of damped least squares from ``qa`` (M, n) towards the targets ``ta``
    (M, 4, 4), at most ``max_iterations`` steps per target.

    A target stops when it is within ``tol`` (m, rad) or its damping passes ``_LAMBDA_MAX``.
    ``iterations`` (N,) counts the steps, in place, at the targets' indices ``idx`` (M,).
    Returns the final configurations (M, n) (``qa``, changed in place), their errors (M, 6) and
    costs ``|e|^2`` (M,).
    """
    n = robot.n_joints
    lower, upper = robot.lower, robot.upper
    eye = np.eye(6)
    e = _error(robot, qa, ta, tool)
    cost = np.einsum("ij,ij->i", e, e)
    lam = np.full(len(qa), _LAMBDA0)
    live = ~_converged(e, tol)
    for _ in range(max_iterations):
        act = np.flatnonzero(live)
        if act.size == 0:
            break
        iterations[idx[act]] += 1
        J = robot.jacobian(qa[act], tool=tool).reshape(-1, 6, n)
        A = J @ np.swapaxes(J, -1, -2) + lam[act, None, None] * eye
        dq = (np.swapaxes(J, -1, -2) @ np.linalg.solve(A, e[act][..., None]))[..., 0]
        cand = np.clip(qa[act] + dq, lower, upper)
        ec = _error(robot, cand, ta[act], tool)
        cc = np.einsum("ij,ij->i", ec, ec)
        better = cc < cost[act]
        acc = act[better]
        qa[acc], e[acc], cost[acc] = cand[better], ec[better], cc[better]
        lam[acc] = np.maximum(lam[acc] / 3.0, _LAMBDA_MIN)
        rej = act[~better]
        lam[rej] *= 4.0
        live[acc] = ~_converged(e[acc], tol)
        live[rej] &= lam[rej] < _LAMBDA_MAX
    return qa, e, cost
