"""Configuration flags of a controller's program points, both ways: from joints, and back to
joints.

A Cartesian point reaches the robot with flags that choose among the arm's solutions. Each
controller defines its flags (:meth:`~robotcell.controllers.base.Controller.config_values`, with
their sources in ``docs/programs.md``) in terms of the arm geometry of
:func:`robotcell.ik.config.arm_sides` (*front*: the wrist centre in front of axis 1; *elbow
front*: the wrist centre in front of the line through axes 2 and 3, KUKA's "A3 >= phi", the
elbow-up arm) and of the controller's axis values: KUKA Status and Turn, ABB ``confdata``, FANUC
``CONFIG``, YASKAWA ``RCONF``.

:func:`config_values` computes the flags of configurations; :func:`select` finds, for each point,
the solution whose flags are the ones written, moving axes 1, 4 and 6 by whole turns where the
flags count turns; :func:`config_text` is the text of the flags as the file writes them.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.controllers.model import Config
from robotcell.controllers.registry import get
from robotcell.ik.config import ZERO_TOL
from robotcell.ik.limits import TWO_PI
from robotcell.robot.robot import Robot

__all__ = ["candidates", "config_text", "config_values", "configs", "select", "side_changes"]

#: Axes (0-based) that may be moved by whole turns to meet flags that count turns or quadrants.
_TURNING = (0, 3, 5)


def config_values(robot: Robot, q: ArrayLike, vendor: str) -> NDArray[np.int_]:
    """Configuration flags of arm configurations, as the vendor writes them.

    Parameters
    ----------
    robot : Robot
        A six-axis ortho-parallel arm with a spherical wrist.
    q : array_like, shape (..., 6)
        Controller axis values (rad). Values within 1e-12 rad of 0 count as 0.
    vendor : str
        A registered controller (:func:`robotcell.controllers.registry.names`).

    Returns
    -------
    ndarray of int, shape (..., k)
        The controller's flags (its ``config_fields``).
    """
    arr = np.asarray(q, dtype=float)
    arr = np.where(np.abs(arr) < ZERO_TOL, 0.0, arr)
    return get(vendor, "program format").config_values(robot, arr)


def configs(robot: Robot, q: ArrayLike, vendor: str) -> list[Config]:
    """:func:`config_values` of ``q`` of shape ``(N, 6)`` as one :class:`Config` per row."""
    values = config_values(robot, np.atleast_2d(q), vendor)
    return [Config(vendor, tuple(int(v) for v in row)) for row in values]


def candidates(robot: Robot, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Every branch with axes 1, 4 and 6 moved by -1, 0, +1 turns.

    Parameters
    ----------
    robot : Robot
    q : ndarray, shape (..., 8, 6)
        Analytic branches (rad).

    Returns
    -------
    ndarray, shape (..., 8 * 27, 6)
    """
    shifts = np.array(np.meshgrid(*([[-1.0, 0.0, 1.0]] * 3), indexing="ij")).reshape(3, -1).T
    steps = np.zeros((shifts.shape[0], robot.n_joints))
    for col, j in enumerate(_TURNING):
        if not robot.prismatic[j]:
            steps[:, j] = shifts[:, col] * TWO_PI
    out = q[..., :, None, :] + steps  # (..., 8, 27, 6)
    return out.reshape(*q.shape[:-2], -1, robot.n_joints)


def select(robot: Robot, q: ArrayLike, reachable: ArrayLike, wanted: ArrayLike,
           vendor: str, q_ref: ArrayLike | None = None
           ) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.bool_]]:
    """For each point, the solution whose flags are the ones written.

    Parameters
    ----------
    robot : Robot
    q : array_like, shape (N, 8, 6)
        The analytic branches of each point (:meth:`Robot.ik`), NaN where a branch does not
        reach.
    reachable : array_like of bool, shape (N, 8)
    wanted : array_like of int, shape (N, k)
        The flags written (:func:`config_values` layout).
    vendor : str
    q_ref : array_like, shape (N, 6), optional
        Preferred configurations: among the solutions with the flags, the nearest (e.g. the
        previous point's, for flags that do not count turns).

    Returns
    -------
    q : ndarray, shape (N, 6)
        The chosen solution (rad), inside the joint limits; NaN where none.
    found : ndarray of bool, shape (N,)
        A solution with the flags exists within the limits.
    exists : ndarray of bool, shape (N,)
        A solution with the flags exists, limits not considered (``exists & ~found``: the
        configuration as written puts an axis outside its limits).
    """
    cand = candidates(robot, np.asarray(q, dtype=float))                     # (N, M, 6)
    reach = np.repeat(np.asarray(reachable, dtype=bool), cand.shape[1] // 8, axis=-1)
    with np.errstate(invalid="ignore"):
        flags = config_values(robot, np.nan_to_num(cand), vendor)            # (N, M, k)
    match = np.all(flags == np.asarray(wanted, dtype=int)[:, None, :], axis=-1) & reach
    inside = robot._inside(cand)
    ok = match & inside
    if q_ref is None:
        cost = np.where(ok, np.sum(cand**2, axis=-1), np.inf)
    else:
        cost = np.where(ok, np.sum((cand - np.asarray(q_ref)[:, None, :]) ** 2, axis=-1), np.inf)
    k = np.argmin(cost, axis=-1)
    out = np.take_along_axis(cand, k[:, None, None], axis=1)[:, 0]
    found = np.any(ok, axis=-1)
    return np.where(found[:, None], out, np.nan), found, np.any(match, axis=-1)


def config_text(config: Config) -> str:
    """The flags as the controller's file writes them.

    ``S 6,T 50`` (KUKA), ``[0,-1,0,1]`` (ABB), ``'N U T, 0, 0, 0'`` (FANUC), ``0,0,0,0,0,0``
    (YASKAWA ``RCONF``, without the unused trailing values).
    """
    return get(config.vendor, "program format").config_text(config.values)


#: What changes when a bit of ABB's cfx changes (RAPID reference, confdata; docs/ik.md).
_SIDES = ((4, "the wrist centre passes axis 1: the shoulder"),
          (2, "the elbow passes stretched"),
          (1, "the wrist flips: axis 5 changes sign"))


def side_changes(robot: Robot, q0: ArrayLike, q1: ArrayLike) -> str:
    """Words for the sides of the arm (shoulder, elbow, wrist) that differ between two
    configurations (shape ``(6,)``, rad); empty when none does."""
    sides = config_values(robot, np.stack([np.asarray(q0, float), np.asarray(q1, float)]),
                          "abb")[:, 3]
    return "; ".join(w for bit, w in _SIDES if (sides[0] ^ sides[1]) & bit)
