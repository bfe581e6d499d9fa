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
from robotcell.errors import InputError
from robotcell.ik.config import ZERO_TOL
from robotcell.ik.limits import TWO_PI
from robotcell.kinematics.bounds import within
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
    qa = np.asarray(q, dtype=float)
    reach8 = np.asarray(reachable, dtype=bool)
    want = np.asarray(wanted, dtype=int)
    n_pts = qa.shape[0]
    out = np.full((n_pts, robot.n_joints), np.nan)
    found = np.zeros(n_pts, dtype=bool)
    todo = np.arange(n_pts)
    if q_ref is None:
        todo = _select_nearest_zero(robot, qa, reach8, want, vendor, out, found)
    ref = None if q_ref is None else np.asarray(q_ref, dtype=float)[todo]
    pt, cand = _inside_candidates(robot, qa[todo], reach8[todo])
    flags = config_values(robot, cand, vendor)
    hit = np.all(flags == want[todo][pt], axis=-1)
    pt, cand = pt[hit], cand[hit]
    cost = np.sum((cand - (0.0 if ref is None else ref[pt])) ** 2, axis=-1)
    order = np.lexsort((cost, pt))
    first = order[np.r_[True, pt[order][1:] != pt[order][:-1]]] if order.size else order
    out[todo[pt[first]]] = cand[first]
    found[todo[pt[first]]] = True
    exists = found.copy()
    rest = np.flatnonzero(~found & reach8.any(axis=-1))
    if rest.size:  # limits not considered
        every = candidates(robot, qa[rest])                                   # (m, 216, 6)
        reach = np.repeat(reach8[rest], every.shape[1] // 8, axis=-1)
        with np.errstate(invalid="ignore"):
            f = config_values(robot, np.nan_to_num(every), vendor)
        exists[rest] = np.any(np.all(f == want[rest][:, None], axis=-1) & reach, axis=-1)
    return out, found, exists


def _select_nearest_zero(robot: Robot, q: NDArray[np.float64], reachable: NDArray[np.bool_],
                         wanted: NDArray[np.int_], vendor: str, out: NDArray[np.float64],
                         found: NDArray[np.bool_]) -> NDArray[np.int_]:
    """The first step of :func:`select` without a reference: of each branch only the candidate
    with axes 1, 4 and 6 nearest to 0 inside the limits (the cheapest of the branch). A point
    whose flags exactly one of these has takes it (``out``, ``found``): the flags of every
    controller tell the branches apart, and among a branch's candidates with the same flags
    this is the cheapest. Returns the points left for the full search."""
    turning = [j for j in _TURNING if not robot.prismatic[j]]
    cand = q.copy()
    for j in turning:
        lo, hi = robot.lower[j], robot.upper[j]
        v = cand[..., j] - TWO_PI * np.round(cand[..., j] / TWO_PI)          # in [-pi, pi]
        near = v - np.sign(v) * TWO_PI                                       # next nearest
        far = v + np.sign(v) * TWO_PI
        best = np.where(within(v, lo, hi), v, np.nan)
        for other in (near, far):  # where v is outside the limits
            best = np.where(np.isnan(best) & within(other, lo, hi), other, best)
        cand[..., j] = np.where(np.isnan(q[..., j]), np.nan, best)
    ok = reachable & robot._inside(cand)
    hit = np.zeros(ok.shape, dtype=bool)
    if ok.any():
        rows = np.nonzero(ok)[0]
        flags = config_values(robot, cand[ok], vendor)
        hit[ok] = np.all(flags == wanted[rows], axis=-1)
    one = np.count_nonzero(hit, axis=-1) == 1
    k = np.argmax(hit, axis=-1)
    out[one] = cand[one, k[one]]
    found[one] = True
    return np.flatnonzero(~one)


def _inside_candidates(robot: Robot, q: NDArray[np.float64], reachable: NDArray[np.bool_]
                       ) -> tuple[NDArray[np.int_], NDArray[np.float64]]:
    """The candidates of :func:`candidates` that reach and are inside the limits, without
    forming the others: the point of each ``(K,)`` and its joints ``(K, 6)``."""
    lo, hi = robot.lower, robot.upper
    turning = [j for j in _TURNING if not robot.prismatic[j]]
    others = [j for j in range(robot.n_joints) if j not in turning]
    ok = reachable & np.all(within(q[..., others], lo[others], hi[others]), axis=-1)  # (N, 8)
    shifts = np.array(np.meshgrid(*([[-1, 0, 1]] * len(turning)), indexing="ij")).reshape(
        len(turning), -1).T                                                  # (S, t)
    combo = np.broadcast_to(ok[..., None], ok.shape + (len(shifts),)).copy()
    for t, j in enumerate(turning):
        vals = q[..., j, None] + TWO_PI * np.array([-1.0, 0.0, 1.0])          # (N, 8, 3)
        combo &= within(vals, lo[j], hi[j])[..., shifts[:, t] + 1]
    pt, br, sh = np.nonzero(combo)
    cand = q[pt, br].copy()
    cand[:, turning] += TWO_PI * shifts[sh]
    keep = robot._inside(cand)  # the interaction limits of coupled axes too
    return pt[keep], cand[keep]


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
    configurations (shape ``(6,)``, rad); empty when none does, or when the arm has no
    spherical wrist (a UR arm), whose sides these words do not name."""
    try:
        sides = config_values(robot, np.stack([np.asarray(q0, float), np.asarray(q1, float)]),
                              "abb")[:, 3]
    except InputError:
        return ""
    return "; ".join(w for bit, w in _SIDES if (sides[0] ^ sides[1]) & bit)
