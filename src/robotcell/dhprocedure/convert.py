"""Exact conversion between standard and modified (Craig) DH tables of the same robot.

Standard frame ``i`` and modified frame ``i`` share the common normal of joint axes ``i`` and
``i+1``: the standard frame sits where that normal meets axis ``i+1`` (Z along it), the modified
frame where it leaves axis ``i`` (Z along axis ``i``). So ``M_i = S_i Rx(-alpha_i) Tx(-a_i)`` and

* standard -> modified: row ``i`` keeps ``theta_i, d_i`` (offset, sign, limits) and takes
  ``a, alpha`` from standard row ``i-1`` (``a_0 = alpha_0 = 0``); the last standard ``a_n,
  alpha_n`` move into the flange: ``T_n_F' = Tx(a_n) Rx(alpha_n) T_n_F``. The base is unchanged.
* modified -> standard: row ``i`` takes ``a, alpha`` from modified row ``i+1`` (``a_n = alpha_n =
  0``, so frame n stays put and the flange is unchanged); the first modified ``a_0, alpha_0``
  move into the base: ``T_R_0' = T_R_0 Rx(alpha_0) Tx(a_0)``.

Both are exact: the two models have the same forward kinematics for every joint value.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from robotcell.errors import InputError
from robotcell.kinematics.dh import Convention
from robotcell.kinematics.transforms import make_pose, rot_x
from robotcell.robot.robot import Robot

__all__ = ["convert_convention"]


def convert_convention(robot: Robot, to: Convention) -> Robot:
    """The same robot in the other DH convention, with identical forward kinematics.

    Parameters
    ----------
    robot : Robot
    to : {"standard", "modified"}
        Target convention; a robot already in it is returned unchanged.

    Returns
    -------
    Robot
        Same joints (types, signs, limits, names, theta and d columns), ``a`` and ``alpha``
        moved by one row, base or flange adjusted, tool and home kept.
    """
    if to not in ("standard", "modified"):
        raise InputError(f"target convention must be 'standard' or 'modified', got {to!r}")
    if robot.convention == to:
        return robot
    tilted = [j.name or str(i) for i, j in enumerate(robot.joints, start=1) if j.beta != 0.0]
    if tilted:
        raise InputError(f"{robot.name}: joint(s) {', '.join(tilted)} have a Hayati beta, which "
                         "has no equivalent row in the other convention; keep the model in its "
                         "own convention, or derive the other one from the robot's axes by the DH "
                         "procedure")
    js = robot.joints
    if to == "modified":
        shifted = [(0.0, 0.0)] + [(j.a, j.alpha) for j in js[:-1]]
        base, flange = robot.base, _x_screw(js[-1].a, js[-1].alpha) @ robot.flange
    else:
        shifted = [(j.a, j.alpha) for j in js[1:]] + [(0.0, 0.0)]
        base, flange = robot.base @ _x_screw(js[0].a, js[0].alpha), robot.flange
    joints = tuple(replace(j, a=a, alpha=alpha) for j, (a, alpha) in zip(js, shifted))
    return replace(robot, joints=joints, convention=to, base=base, flange=flange)


def _x_screw(a: float, alpha: float) -> NDArray[np.float64]:
    """``Tx(a) Rx(alpha)`` (they commute), shape (4, 4)."""
    return make_pose(rot_x(alpha), np.array([a, 0.0, 0.0]))
