"""Arm configuration flags: the solver's own (shoulder, elbow, wrist) and as robot controllers
write them (KUKA Status/Turn, ABB confdata).

**The solver's flags.** Every analytic solver (:mod:`robotcell.ik.analytic`) numbers its branches
``k = 4 * shoulder + 2 * elbow + wrist`` (a 4-axis palletizer ``k = 2 * shoulder + elbow``), each
flag 0 or 1 (docs/ik.md, "Branches"): :func:`branch_of_flags` and :func:`flags_of_branch` go
between the two. These are the configuration of every arm type robotcell solves, also of a
Universal-Robots-type arm, whose controller has no configuration flags (URScript's
``get_inverse_kin(x, qnear)`` returns the solution nearest ``qnear``). On a UR arm (canonical angles
``t_i``, the controller's values for Universal Robots' own models): shoulder 1 = the wrist-2 point
(where axes 5 and 6 meet) at negative x of the canonical frame 1 (the base frame turned with axis
1), elbow 1 = ``sin t3 < 0``, wrist 1 = ``sin t5 < 0``.

Defined for ortho-parallel arms with a spherical wrist (:mod:`robotcell.ik.opw`), from the
geometry of the configuration:

* **front / overhead**: the x coordinate of the wrist centre in the "A1 coordinate system" (the
  robot base frame R turned with axis 1; identical to R when axis 1 is at 0). Positive: basic
  area, the wrist centre in front of axis 1.
* **elbow**: on which side of the line through axes 2 and 3 the wrist centre lies, measured in the
  arm's plane towards the front (for KUKA arms this is "A3 >= phi", phi being the A3 angle at
  which the wrist centre is on that line).
* the sign of axis 5, and quadrants or signs of the axis values themselves.

KUKA (KUKA System Software 8 operating and programming instructions, "Status" and "Turn", as
quoted in robot-forum.com thread 7173 and summarised by industrialmonitordirect.com "Converting
KUKA robot axis positions to configuration (RST)"):

* Status bit 0 = 1: overhead area (wrist centre x < 0 in the A1 coordinate system);
* Status bit 1 = 1: A3 >= phi (wrist centre in front of the line A2-A3);
* Status bit 2 = 1: A5 <= 0 (0 for A5 > 0);
* Turn bit i (i = 0..5) = 1 when axis A(i+1) < 0 (values within 1e-12 rad of 0 count as 0).

(Some third-party controllers emulating KUKA count status bit 2 the other way; KUKA's own
tables, as above, set it for A5 <= 0.)

ABB (RAPID reference manual, data type ``confdata``): ``cf1``, ``cf4``, ``cf6`` are the quadrants
``floor(q / 90 deg)`` of axes 1, 4 and 6 (0 for 0..90 deg, -1 for -90..0 deg, ...); ``cfx`` is
``4 * (wrist centre behind axis 1) + 2 * (wrist centre behind the lower arm) + (axis 5 < 0)``,
i.e. 0 = front, in front of the lower arm, axis 5 positive ... 7 = behind, behind, negative.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.ik.analytic import analytic_solver
from robotcell.ik.opw import OPWParameters
from robotcell.kinematics.arm import Arm

__all__ = ["ARM_FLAGS", "abb_confdata", "arm_sides", "branch_of_flags", "flags_of_branch",
           "kuka_status_turn"]

#: The solver's configuration flags, the bits of its branch index (most significant first).
ARM_FLAGS = ("shoulder", "elbow", "wrist")

_QUARTER = math.pi / 2
#: Joint values closer to 0 than this (rad) count as 0 for signs and quadrants: solvers return
#: rounding noise such as -1e-17 for an exact 0.
ZERO_TOL = 1e-12


def _joint_values(q: ArrayLike) -> NDArray[np.float64]:
    arr = np.asarray(q, dtype=float)
    return np.where(np.abs(arr) < ZERO_TOL, 0.0, arr)


def _opw(robot: Arm) -> OPWParameters:
    solver = analytic_solver(robot)
    if solver.method != "opw":
        raise InputError(f"configuration flags are defined for arms with a spherical wrist; "
                         f"{robot.name} is a {solver.method.upper()}-type arm")
    assert isinstance(solver.params, OPWParameters)
    return solver.params


def arm_sides(robot: Arm, q: ArrayLike) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """Which side of axis 1 and of the lower arm the wrist centre is on.

    Parameters
    ----------
    robot : Arm
        An ortho-parallel arm with a spherical wrist.
    q : array_like, shape (..., 6)
        Controller axis values (rad); NaN gives False. A coupled robot's values are mapped to the
        model's joint values first (the geometry is the model's).

    Returns
    -------
    front : ndarray of bool, shape (...)
        Wrist centre x >= 0 in the A1 coordinate system (not overhead).
    elbow_front : ndarray of bool, shape (...)
        Wrist centre in front of the line through axes 2 and 3 (KUKA: A3 >= phi).
    """
    p = _opw(robot)
    arr = np.asarray(q, dtype=float)
    if arr.ndim == 0 or arr.shape[-1] != 6:
        raise InputError(f"q must have shape (..., 6), got {arr.shape}")
    if robot.coupling is not None:
        arr = robot.coupling.to_model(arr)
    th = arr * p.signs + p.offsets
    t2, t3 = th[..., 1], th[..., 2]
    t23 = t2 + t3
    wx = p.a1 + p.c2 * np.sin(t2) + p.a2 * np.cos(t23) + p.c3 * np.sin(t23)
    # X of R, seen in the arm frame (O turned with axis 1): constant.
    e = p.T_R_O[:3, :3].T @ np.array([1.0, 0.0, 0.0])
    g = math.atan2(e[1], e[0])
    front = wx * math.cos(g) + p.b * math.sin(g) >= 0
    psi = math.atan2(p.a2, p.c3)
    elbow_front = np.sin(t3 + psi) * math.copysign(1.0, math.cos(g)) >= 0
    return front, elbow_front


def kuka_status_turn(robot: Arm, q: ArrayLike) -> tuple[NDArray[np.int_], NDArray[np.int_]]:
    """KUKA Status and Turn of configurations.

    Parameters
    ----------
    robot : Arm
    q : array_like, shape (..., 6)
        Joint values A1..A6 (rad).

    Returns
    -------
    status, turn : ndarray of int, shape (...)
    """
    arr = _joint_values(q)
    front, elbow = arm_sides(robot, arr)
    status = (~front).astype(int) + 2 * elbow.astype(int) + 4 * (arr[..., 4] <= 0).astype(int)
    turn = np.sum((arr < 0).astype(int) << np.arange(6), axis=-1)
    return status, turn


def abb_confdata(robot: Arm, q: ArrayLike) -> NDArray[np.int_]:
    """ABB ``confdata`` ``[cf1, cf4, cf6, cfx]`` of configurations.

    Parameters
    ----------
    robot : Arm
    q : array_like, shape (..., 6)
        Joint values of axes 1..6 (rad).

    Returns
    -------
    ndarray of int, shape (..., 4)
    """
    arr = _joint_values(q)
    front, elbow = arm_sides(robot, arr)
    quad = np.floor(arr[..., [0, 3, 5]] / _QUARTER).astype(int)
    cfx = 4 * (~front).astype(int) + 2 * (~elbow).astype(int) + (arr[..., 4] < 0).astype(int)
    return np.concatenate([quad, cfx[..., None]], axis=-1)


def branch_of_flags(method: str, flags: ArrayLike) -> NDArray[np.int_]:
    """The branch index of the solver's configuration flags.

    Parameters
    ----------
    method : str
        The solver's method (:attr:`robotcell.ik.result.IKSolutions.method`): ``opw``, ``ur`` or
        ``palletizer``.
    flags : array_like of int, shape (..., 3)
        ``shoulder, elbow, wrist`` (:data:`ARM_FLAGS`), each 0 or 1.

    Returns
    -------
    ndarray of int, shape (...)
        ``4 * shoulder + 2 * elbow + wrist``; a palletizer's ``2 * shoulder + elbow``.

    Raises
    ------
    InputError
        A flag that is not 0 or 1, or a wrist flag of 1 for a palletizer (it has no wrist flip).
    """
    f = np.asarray(flags)
    if f.ndim == 0 or f.shape[-1] != 3:
        raise InputError(f"flags must have shape (..., 3) (shoulder, elbow, wrist), got {f.shape}")
    if not np.isin(f, (0, 1)).all():
        raise InputError(f"the flags {', '.join(ARM_FLAGS)} are 0 or 1, got "
                         f"{np.unique(f[~np.isin(f, (0, 1))]).tolist()}")
    f = f.astype(int)
    if method == "palletizer":
        if f[..., 2].any():
            raise InputError("a 4-axis palletizer has no wrist flip: its branches are "
                             "2 * shoulder + elbow; give wrist 0")
        return 2 * f[..., 0] + f[..., 1]
    return 4 * f[..., 0] + 2 * f[..., 1] + f[..., 2]


def flags_of_branch(method: str, branch: ArrayLike) -> NDArray[np.int_]:
    """The solver's configuration flags of branch indices (the inverse of
    :func:`branch_of_flags`).

    Parameters
    ----------
    method : str
        ``opw``, ``ur`` or ``palletizer``.
    branch : array_like of int, shape (...)
        Branch indices; -1 for none.

    Returns
    -------
    ndarray of int, shape (..., 3)
        ``shoulder, elbow, wrist``; -1 where ``branch`` is negative; a palletizer's wrist is 0.
    """
    b = np.asarray(branch, dtype=int)
    bits = (np.stack([b >> 1, b & 1, np.zeros_like(b)], axis=-1) if method == "palletizer"
            else np.stack([b >> 2, (b >> 1) & 1, b & 1], axis=-1))
    return np.where(b[..., None] < 0, -1, bits)
