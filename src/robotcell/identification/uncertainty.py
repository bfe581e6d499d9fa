"""How well an identified model knows where its TCP goes: the covariance of its constants through FK.

An identified model carries the covariance ``C`` of the constants the identification moved
(:class:`~robotcell.kinematics.covariance.ParameterCovariance`: the block of the identification's
``cov = s0^2 (J^T J)^-1`` that belongs to the arm, the robot base in the device frame and the
targets marginalised out). A TCP position ``p(x, q)`` then has the covariance ``J_p C J_p^T``
with ``J_p = dp/dx``, the analytic derivative of the identification's chain
(:meth:`robotcell.identification.chain.Chain.point_jacobian`): first-order propagation, exact to
well below the sigma itself at the sub-millimetre changes an identification makes.

The 1-sigma of a position is ``sqrt(trace(J_p C J_p^T))``: the RMS length of its 3-D error.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.identification.chain import Chain
from robotcell.kinematics.transforms import validate_pose
from robotcell.robot.robot import Robot

__all__ = ["position_covariance", "position_jacobian", "position_sigma"]


def _chain_values(robot: Robot, chain: Chain) -> NDArray[np.float64]:
    """The chain's parameter vector for ``robot``: its constants, scale and J2/J3 factor."""
    x = chain.values.copy()
    c = robot.coupling
    if c is None:
        return x
    C = c.matrix
    n = robot.n_joints
    off = C - np.diag(np.diag(C))
    if off.shape != (n, n) or np.any(c.offset) or (
            np.any(off) and not (n >= 3 and np.count_nonzero(off) == 1 and off[2, 1] != 0)):
        raise InputError(f"{robot.name}: a coupling other than a scale per axis and a J2/J3 factor "
                         "has no identification parameters")
    x[chain.scale_params] = np.diag(C) - 1.0
    if chain.coupling_param >= 0:
        x[chain.coupling_param] = C[2, 1] / C[2, 2]
    return x


def position_jacobian(robot: Robot, q: ArrayLike, tool: ArrayLike | None = None
                      ) -> NDArray[np.float64]:
    """Derivative of the TCP position with respect to the covariance's parameters.

    Parameters
    ----------
    robot : Robot
        An identified model with a ``covariance`` (``robotcell identify``).
    q : array_like, shape (..., n)
        Controller joint values (rad, m).
    tool : array_like, shape (4, 4), optional
        ``T_F_TCP`` (m); default the robot's tool.

    Returns
    -------
    ndarray, shape (..., 3, p)
        In the robot base frame R, one column per name of ``robot.covariance`` (m per m or rad).

    Raises
    ------
    InputError
        A model without a covariance, or one naming a parameter its chain does not have.
    """
    cov = robot.covariance
    if cov is None:
        raise InputError(f"{robot.name} carries no covariance of its constants: identify it "
                         "(robotcell identify -o) to know how well its TCP is known")
    arr = robot._joints(q)
    T_tool = robot.tool if tool is None else validate_pose(tool, "tool")
    chain = Chain(robot, 1, False, np.eye(4), T_tool)
    missing = [n for n in cov.names if n not in chain.names]
    if missing:
        raise InputError(f"{robot.name}: its covariance names parameter(s) {', '.join(missing)}, "
                         "which its chain does not have")
    x = _chain_values(robot, chain)
    flat = arr.reshape(-1, robot.n_joints)
    ev = chain.evaluate(x, flat, gravity=False)
    pts, _ = chain.predict(x, flat)
    cols = [chain.index(n) for n in cov.names]
    J = chain.point_jacobian(x, flat, ev, pts)[:, 0][..., cols]  # (N, 3, p)
    return J.reshape(arr.shape[:-1] + (3, len(cols)))


def position_covariance(robot: Robot, q: ArrayLike, tool: ArrayLike | None = None
                        ) -> NDArray[np.float64]:
    """Covariance of the TCP position from the identified constants' covariance.

    Parameters
    ----------
    robot, q, tool
        As for :func:`position_jacobian`.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        In the robot base frame R (m^2).
    """
    J = position_jacobian(robot, q, tool)
    return J @ robot.covariance.matrix @ np.swapaxes(J, -1, -2)


def position_sigma(robot: Robot, q: ArrayLike, tool: ArrayLike | None = None
                   ) -> NDArray[np.float64]:
    """1-sigma of the TCP position: the RMS length of its error, ``sqrt(trace(cov))``.

    Parameters
    ----------
    robot, q, tool
        As for :func:`position_covariance`.

    Returns
    -------
    ndarray, shape (...)
        Metres.
    """
    C = position_covariance(robot, q, tool)
    return np.sqrt(np.trace(C, axis1=-2, axis2=-1))
