"""Configuration flags of the four program formats, both ways: from joints, and back to joints.

A Cartesian point reaches the robot with flags that choose among the arm's solutions. Every
definition below is in terms of the arm geometry of :func:`robotcell.ik.config.arm_sides`
(*front*: the wrist centre in front of axis 1; *elbow front*: the wrist centre in front of the
line through axes 2 and 3, KUKA's "A3 >= phi", the elbow-up arm) and of the controller's axis
values. Sources and the points where they disagree: ``docs/programs.md``.

- **KUKA** ``S``, ``T``: :func:`robotcell.ik.config.kuka_status_turn` (bit 0 overhead, bit 1
  A3 >= phi, bit 2 A5 <= 0; turn bit i for A(i+1) < 0).
- **ABB** ``[cf1, cf4, cf6, cfx]``: :func:`robotcell.ik.config.abb_confdata`.
- **FANUC** ``CONFIG : 'F|N U|D T|B, t1, t4, t6'``: flip ``F`` for J5 >= 0, ``N`` for J5 < 0
  (RoboDK's FANUC post); ``U`` the elbow-up arm; ``T`` the wrist centre in front of axis 1; the
  turn numbers of J1, J4 and J6 are ``sign(q) floor((|q| + 180 deg) / 360 deg)``, 0 for
  -180 < q < 180 deg (RoboDK's FANUC post).
- **YASKAWA** ``RCONF l,m,n,o,p,q``: ``l`` 0 Flip when the R axis (axis 4) is at
  -90 < R <= 90 deg (modulo 360), 1 No-flip; ``m`` 0 upper arm (elbow up), 1 lower arm; ``n`` 0
  front, 1 rear; ``o``, ``p``, ``q`` 1 when the R, T, S axis (4, 6, 1) is at 180 deg or more
  from 0 (DX100 and NX100 manuals, job data format and "Manipulator Types").

:func:`config_values` computes the flags of configurations; :func:`select` finds, for each point,
the solution whose flags are the ones written, moving axes 1, 4 and 6 by whole turns where the
flags count turns; :func:`config_text` and :func:`config_fields` are the text of the flags as the
file writes them.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.ik.config import ZERO_TOL, abb_confdata, arm_sides, kuka_status_turn
from robotcell.ik.limits import TWO_PI
from robotcell.programs.model import VENDORS, Config
from robotcell.robot.robot import Robot

__all__ = ["CONFIG_FIELDS", "candidates", "config_text", "config_values", "configs", "select"]

#: Names of the values of :class:`~robotcell.programs.model.Config` per vendor.
CONFIG_FIELDS = {
    "kuka": ("S", "T"),
    "abb": ("cf1", "cf4", "cf6", "cfx"),
    "fanuc": ("flip", "down", "back", "turn1", "turn4", "turn6"),
    "yaskawa": ("l", "m", "n", "o", "p", "q"),
}

#: Axes (0-based) that may be moved by whole turns to meet flags that count turns or quadrants.
_TURNING = (0, 3, 5)
_HALF = math.pi


def _turns(q: NDArray[np.float64]) -> NDArray[np.int_]:
    """FANUC turn number of joint values (rad): 0 for |q| < 180 deg, +-1 up to 540 deg, ..."""
    return (np.sign(q) * np.floor((np.abs(q) + _HALF) / TWO_PI)).astype(int)


def config_values(robot: Robot, q: ArrayLike, vendor: str) -> NDArray[np.int_]:
    """Configuration flags of arm configurations, as the vendor writes them.

    Parameters
    ----------
    robot : Robot
        A six-axis ortho-parallel arm with a spherical wrist.
    q : array_like, shape (..., 6)
        Controller axis values (rad). Values within 1e-12 rad of 0 count as 0.
    vendor : {"kuka", "abb", "fanuc", "yaskawa"}

    Returns
    -------
    ndarray of int, shape (..., k)
        The values of :data:`CONFIG_FIELDS` ``[vendor]``.
    """
    arr = np.asarray(q, dtype=float)
    arr = np.where(np.abs(arr) < ZERO_TOL, 0.0, arr)
    if vendor == "kuka":
        status, turn = kuka_status_turn(robot, arr)
        return np.stack([status, turn], axis=-1)
    if vendor == "abb":
        return abb_confdata(robot, arr)
    front, elbow = arm_sides(robot, arr)
    if vendor == "fanuc":
        flags = [arr[..., 4] >= 0, ~elbow, ~front]
        return np.stack([f.astype(int) for f in flags] + [_turns(arr[..., j]) for j in _TURNING],
                        axis=-1)
    if vendor == "yaskawa":
        r = np.mod(arr[..., 3] + _HALF / 2, TWO_PI)  # Flip: R in (-90, 90] deg, modulo 360
        flip = (r > 0) & (r <= _HALF)
        big = [np.abs(arr[..., j]) >= _HALF for j in (3, 5, 0)]
        return np.stack([(~flip).astype(int), (~elbow).astype(int), (~front).astype(int)]
                        + [b.astype(int) for b in big], axis=-1)
    raise InputError(f"unknown program format {vendor!r}; choose one of: {', '.join(VENDORS)}")


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
    """The flags as the vendor's file writes them.

    ``S 6,T 50`` (KUKA), ``[0,-1,0,1]`` (ABB), ``'N U T, 0, 0, 0'`` (FANUC), ``0,0,0,0,0,0``
    (YASKAWA ``RCONF``, without the unused trailing values).
    """
    v = config.values
    if config.vendor == "kuka":
        return f"S {v[0]},T {v[1]}"
    if config.vendor == "abb":
        return "[" + ",".join(str(x) for x in v) + "]"
    if config.vendor == "fanuc":
        flags = ("NF"[v[0]], "UD"[v[1]], "TB"[v[2]])
        return f"'{' '.join(flags)}, {v[3]}, {v[4]}, {v[5]}'"
    return ",".join(str(x) for x in v)
