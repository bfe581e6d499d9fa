"""Inverse kinematics of an identified model: the nominal analytic IK seeds the numeric IK.

An identified arm is in general no longer ortho-parallel, so the closed-form solvers of
:mod:`robotcell.ik` do not apply to it; :class:`robotcell.ik.seeded.SeededSolver` refines its
nominal model's analytic branches on it. The identified model names its nominal as ``ik_seed``,
so ``identified.ik(T)`` does the same without this function.
"""

from __future__ import annotations

from numpy.typing import ArrayLike

from robotcell.ik import analytic_solver
from robotcell.ik.result import IKSolutions
from robotcell.ik.seeded import SeededSolver
from robotcell.robot.robot import Robot

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
        ``q`` (..., 8, n): each nominal branch refined on the identified model (rad, m), NaN
        where it did not reach ``tol``; ``valid`` where it did within the limits.

    Raises
    ------
    InputError
        The nominal model has no analytic solver, or invalid poses.
    """
    return SeededSolver(identified, analytic_solver(nominal), tol).solve(T, tool)
