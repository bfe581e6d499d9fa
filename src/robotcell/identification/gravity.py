"""Gravity torques on the joints of a serial chain from its links' masses (for joint compliance).

A link's mass ``m_k`` (kg) sits at its centre of mass ``c_k``, given in the link's DH frame ``k``
(the frame that moves with joint ``k``). With gravity ``g = (0, 0, -9.80665)`` m/s^2 along -Z of
the robot base frame R (a floor-mounted robot), the static torque about joint ``i``'s axis (unit
direction ``z_i`` through ``o_i``, the DH axis whose rotation is the DH variable) is::

    tau_i = sum_{k >= i} ((c_k - o_i) x m_k g) . z_i        (N m)

A joint whose drive is compliant turns by ``compliance_i * tau_i`` under it (Mooring, Roth and
Driels, *Fundamentals of Manipulator Calibration*, Wiley 1991, on joint compliance as a
non-geometric error).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.robot.robot import Robot

__all__ = ["GRAVITY", "gravity_torques", "require_masses"]

#: Standard gravity along -Z of the robot base frame (m/s^2).
GRAVITY = np.array([0.0, 0.0, -9.80665])


def require_masses(robot: Robot, joints: tuple[int, ...]) -> None:
    """Refuse a model without the link masses that the gravity torque on ``joints`` needs.

    Raises
    ------
    InputError
        No link from the first of ``joints`` (0-based) on has a mass; the message names the
        model file keys.
    """
    if not any(j.mass > 0 for j in robot.joints[min(joints):]):
        axes = ", ".join(robot.joints[j].name or f"A{j + 1}" for j in joints)
        raise InputError(
            f"gravity compliance of {axes} needs the link masses of {robot.name}: add the model "
            f"file keys 'mass' (kg) and 'com' (centre of mass in the link's DH frame, in the file's "
            f"length unit) to the joints from {robot.joints[min(joints)].name or 'A2'} on; see "
            "docs/models.md")


def gravity_torques(robot: Robot, q: ArrayLike, joints: tuple[int, ...]) -> NDArray[np.float64]:
    """Static gravity torque about the DH axis of each of ``joints`` (0-based).

    Parameters
    ----------
    robot : Robot
        Model with link masses (``Joint.mass`` kg, ``Joint.com`` m in the link frame).
    q : array_like, shape (N, n)
        Controller values (rad, m).
    joints : tuple of int
        Joints whose torque is wanted.

    Returns
    -------
    ndarray, shape (N, len(joints))
        Torque about the DH axis ``z_i`` (N m): positive when gravity turns the DH variable up.
    """
    F = robot.frames(np.atleast_2d(np.asarray(q, dtype=float)))  # (N, m+1, 4, 4)
    mass = np.array([j.mass for j in robot.joints])
    com = np.array([[*j.com, 1.0] for j in robot.joints])
    c = np.einsum("nkij,kj->nki", F[:, 1:, :3, :], com)  # centres of mass in R, (N, m, 3)
    axis = F[:, :-1] if robot.convention == "standard" else F[:, 1:]
    out = np.zeros((F.shape[0], len(joints)))
    for col, i in enumerate(joints):
        o, z = axis[:, i, :3, 3], axis[:, i, :3, 2]
        arm = c[:, i:] - o[:, None, :]
        moment = np.cross(arm, mass[i:, None] * GRAVITY).sum(axis=1)
        out[:, col] = np.einsum("ni,ni->n", moment, z)
    return out
