"""Inverse kinematics of an identified model: the nominal analytic IK seeds the numeric IK.

An identified arm is in general no longer ortho-parallel (its axes are tilted by hundredths of a
degree and offset by tenths of a millimetre), so the closed-form solvers of :mod:`robotcell.ik`
do not apply to it. Its nominal model's 8 analytic solutions are, however, within about a
millimetre and a tenth of a degree of the identified model's, and damped least squares from there
converges to 1e-9 in a few iterations per branch.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from robotcell.ik import solve, solve_numeric
from robotcell.ik.result import IKSolutions
from robotcell.kinematics.robot import Robot
from robotcell.kinematics.transforms import validate_pose

__all__ = ["solve_identified"]


def solve_identified(identified: Robot, nominal: Robot, T: ArrayLike, tool: ArrayLike | None = None,
                     tol: float = 1e-9) -> IKSolutions:
    """Every IK branch of an identified model, seeded by the nominal model's analytic IK.

    Parameters
    ----------
    identified : Robot
        The identified model (e.g. ``IdentificationResult.robot``).
    nominal : Robot
        Its nominal model, with an analytic solver (ortho-parallel or UR-type arm).
    T : array_like, shape (..., 4, 4)
        ``T_R_TCP``: target poses of the TCP in the robot base frame (m).
    tool : array_like, shape (4, 4), optional
        ``T_F_TCP`` (m); default the identified model's tool, for both models.
    tol : float
        Position (m) and orientation (rad) tolerance of the numeric refinement.

    Returns
    -------
    IKSolutions
        ``q`` (..., 8, n): each nominal branch refined on the identified model (rad, m); ``valid``
        where the nominal branch was valid and the refinement reached ``tol`` within the limits.

    Raises
    ------
    InputError
        The nominal model has no analytic solver, or invalid poses.
    """
    arr = validate_pose(T, "target pose")
    tool_T = identified.tool if tool is None else validate_pose(tool, "tool")
    seeds = solve(nominal, arr, tool_T)
    batch = arr.shape[:-2]
    targets = np.broadcast_to(arr[..., None, :, :], batch + (8, 4, 4))
    q0 = np.nan_to_num(seeds.q)
    num = solve_numeric(identified, targets, q0, tol_position=tol, tol_orientation=tol,
                        max_iterations=30, restarts=0, tool=tool_T)
    valid = seeds.valid & num.success
    return IKSolutions(np.where(valid[..., None], num.q, np.nan), valid, seeds.reachable & num.success,
                       "nominal-seeded numeric")
