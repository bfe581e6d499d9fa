"""Touches for Monte Carlo tests: a design simulated once without error, then new errors per trial.

``robotcell simulate`` solves the inverse kinematics of every touch; for many trials of one design
that is the slow part. :func:`jitter` instead moves the recorded joint values so that the TCP lands
off the exact touch by a Gaussian error (per coordinate, in the robot base, orientation kept): the
error model of ``simulate``, to second order in the error (two Newton steps on the arm's
Jacobian, exact to far below a nanometre for errors of a tenth of a millimetre).
"""

from dataclasses import replace

import numpy as np
from scipy.spatial.transform import Rotation


def jitter(robot, q, tool, rng, noise, offsets=None):
    """Joint values (N, n) whose TCP is that of ``q`` plus ``N(0, noise^2)`` (+ ``offsets``)."""
    T0 = robot.fk(q, tool)
    p = T0[:, :3, 3] + rng.normal(0.0, noise, (len(q), 3))
    if offsets is not None:
        p = p + offsets
    q1 = np.array(q, dtype=float)
    for _ in range(2):
        T = robot.fk(q1, tool)
        turn = Rotation.from_matrix(T0[:, :3, :3] @ np.swapaxes(T[:, :3, :3], 1, 2)).as_rotvec()
        err = np.concatenate([p - T[:, :3, 3], turn], axis=1)
        q1 = q1 + np.linalg.solve(robot.jacobian(q1, tool), err[..., None])[..., 0]
    return q1


def retouched(touches, cell, tool, rng, noise, offsets=None):
    """The measurement table of ``touches`` (simulated without error) with new touch errors."""
    return replace(touches, q=jitter(cell.robot, touches.q, tool, rng, noise, offsets)).to_table()


def pose_error(T_est, T_true):
    """Origin error (m) and rotation error vector ``d`` with ``R_true = exp(d) R_est`` (rad)."""
    d = Rotation.from_matrix(T_true[:3, :3] @ T_est[:3, :3].T).as_rotvec()
    return np.r_[T_true[:3, 3] - T_est[:3, 3], d]


def gross_offset(rng, n, size):
    """An offset of length ``size`` in a random direction on one random touch of ``n``."""
    out = np.zeros((n, 3))
    k = int(rng.integers(n))
    v = rng.normal(size=3)
    out[k] = size * v / np.linalg.norm(v)
    return out, k
