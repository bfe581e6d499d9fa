"""Inverse kinematics of a model without closed form, seeded by a model that has one.

An identified (calibrated) arm is in general no longer ortho-parallel: its axes are tilted by
hundredths of a degree and offset by tenths of a millimetre, so the closed-form solvers of
:mod:`robotcell.ik.analytic` do not apply to it. Its nominal model's analytic solutions are,
however, within about a millimetre and a tenth of a degree of its own, and damped least squares
(:func:`robotcell.ik.numeric.solve_numeric`) from each of them converges to 1e-9 in a few
iterations. :class:`SeededSolver` does that per branch and returns the same fixed-shape
:class:`~robotcell.ik.result.IKSolutions` (all branches, NaN where a branch did not converge) as
the analytic solver, so choosing a branch, configuration flags and the cell work unchanged.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.ik.numeric import solve_numeric
from robotcell.ik.result import IKSolutions, flat_reference
from robotcell.kinematics.arm import Arm
from robotcell.kinematics.transforms import validate_pose

__all__ = ["SEEDED_TOL", "SeededSolver"]

#: Position (m) and orientation (rad) tolerance of the refinement.
SEEDED_TOL = 1e-9
#: Largest miss of the seed model's reach (m) for which a pulled-in target still seeds a branch.
EDGE = 0.02


class SeededSolver:
    """Every IK branch of ``robot``: the seed model's analytic branches refined numerically.

    Parameters
    ----------
    robot : Arm
        The model to solve (e.g. an identified arm; its coupling, if any, is honoured).
    seed : AnalyticSolver
        Analytic solver of a nearby model with the same chain of joints (its nominal model); its
        solutions are mapped through both couplings (seed controller -> chain -> ``robot``
        controller values) before the refinement.
    tol : float
        Position (m) and orientation (rad) tolerance of the refinement.

    Attributes
    ----------
    method, branches, params
        Those of the seed solver: the branches are numbered as the seed's (docs/ik.md) and the
        configuration flags use the seed's geometry.
    description : str
        ``numeric, seeded by <seed> (<method>)``.
    """

    def __init__(self, robot: Arm, seed: Any, tol: float = SEEDED_TOL) -> None:
        self.robot, self.seed, self.tol = robot, seed, tol
        self.method, self.branches, self.params = seed.method, seed.branches, seed.params
        self.description = f"numeric, seeded by {seed.robot.name} ({seed.method})"
        # Refined without limits (so that `reachable` ignores them, as the analytic solvers do);
        # the limits decide `valid` afterwards.
        free = tuple(replace(j, lower=-math.inf, upper=math.inf) for j in robot.joints)
        self._free = replace(robot, joints=free, ik_seed=None)

    def solve(self, T: ArrayLike, tool: ArrayLike | None = None,
              q_ref: ArrayLike | None = None) -> IKSolutions:
        """All branches for poses of the TCP.

        Parameters
        ----------
        T : array_like, shape (..., 4, 4)
            ``T_R_TCP``: target poses of the TCP in the robot base frame (m).
        tool : array_like, shape (4, 4), optional
            ``T_F_TCP`` instead of the robot's default tool (m), for both models.
        q_ref : array_like, shape (n,) or (..., n), optional
            Reference configuration (rad) for axes the seed finds free (singular poses).

        Returns
        -------
        IKSolutions
            ``q`` (..., branches, n): each seed branch refined on ``robot`` (rad, m), NaN where
            the seed branch does not reach the pose or the refinement did not reach ``tol``;
            ``reachable`` where it did; ``valid`` where also within the joint limits (and the
            coupling's interaction limits); ``reach_error`` the remaining position error (m).
        """
        arr = validate_pose(T, "target pose")
        tool_T = self.robot.tool if tool is None else validate_pose(tool, "tool")
        seeds = self.seed.solve(arr, tool_T, q_ref)
        nb, n = self.branches, self.robot.n_joints
        q = seeds.q.reshape(-1, nb, seeds.q.shape[-1]).copy()
        reach = seeds.reachable.reshape(-1, nb).copy()
        ref = flat_reference(q_ref, q.shape[-1], arr.shape[:-2])
        self._edge_seeds(arr.reshape(-1, 4, 4), tool_T, ref, seeds, q, reach)
        if self.seed.robot.coupling is not None:  # seed values -> chain values -> ours
            q = self.seed.robot.coupling.to_model(q)
        q = self.robot.coupling.to_controller(q) if self.robot.coupling is not None else q
        err = np.full(reach.shape, math.inf)
        targets = np.broadcast_to(arr.reshape(-1, 1, 4, 4), q.shape[:2] + (4, 4))
        idx = np.nonzero(reach)
        if idx[0].size:
            num = solve_numeric(self._free, targets[idx], q[idx], tol_position=self.tol,
                                tol_orientation=self.tol, max_iterations=100, restarts=0, tool=tool_T)
            q[idx], reach[idx], err[idx] = num.q, num.success, num.position_error
        q[~reach] = np.nan
        valid = reach & self.robot._inside(q)
        batch = arr.shape[:-2]
        return IKSolutions(q.reshape(batch + (nb, n)), valid.reshape(batch + (nb,)),
                           reach.reshape(batch + (nb,)), self.method, err.reshape(batch + (nb,)))

    def _edge_seeds(self, flat: NDArray[np.float64], tool_T: NDArray[np.float64],
                    ref: NDArray[np.float64] | None, seeds: IKSolutions, q: NDArray[np.float64],
                    reach: NDArray[np.bool_]) -> None:
        """Seeds for branches just outside the seed model's reach (at the workspace edge).

        The identified arm may reach a pose the nominal one misses by up to ``EDGE``: those
        branches are seeded by the nominal solution of the target pulled toward the robot base
        by the miss plus 1 mm (filled into ``q`` and ``reach`` in place).
        """
        if seeds.reach_error is None:
            return
        miss = seeds.reach_error.reshape(reach.shape)
        near = ~reach & np.isfinite(miss) & (miss < EDGE)
        rows = np.flatnonzero(near.any(axis=1))
        if rows.size == 0:
            return
        pulled = flat[rows].copy()
        p = pulled[:, :3, 3]
        pull = np.where(near[rows], miss[rows], 0.0).max(axis=1) + 1e-3
        norm = np.maximum(np.linalg.norm(p, axis=1, keepdims=True), 1e-9)
        pulled[:, :3, 3] = p - p / norm * pull[:, None]
        again = self.seed.solve(pulled, tool_T, None if ref is None else ref[rows])
        fill = near[rows] & again.reachable
        sub_q, sub_r = q[rows], reach[rows]
        sub_q[fill], sub_r[fill] = again.q[fill], True
        q[rows], reach[rows] = sub_q, sub_r
