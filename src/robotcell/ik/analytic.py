"""Batched analytic inverse kinematics of an :class:`~robotcell.kinematics.arm.Arm`.

:func:`solve` recognises the structure of the model once (cached per robot object) and returns
all 8 solutions of every pose: ortho-parallel arms with a spherical wrist through
:mod:`robotcell.ik.opw`, Universal-Robots-type arms through :mod:`robotcell.ik.ur`, and all 4
solutions of 4-axis palletizers through :mod:`robotcell.ik.palletizer`.

A robot with a joint coupling (:mod:`robotcell.kinematics.coupling`) is solved on its uncoupled model; the
model solutions are mapped to controller values right after the kernel, and the 2*pi rule, the
joint limits and the interaction limits are then applied to the controller values, as the pendant
shows them. Robots without a coupling skip the mapping.

A robot with neither structure but with an ``ik_seed`` (an identified arm names its nominal
model) gets a :class:`~robotcell.ik.seeded.SeededSolver`: the seed's analytic branches refined
numerically on the robot, with the same result shape.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.ik.limits import JointFolder, wrap_to_pi
from robotcell.ik.opw import OPWParameters, opw_kernel, opw_parameters, opw_problems
from robotcell.ik.palletizer import (
    PalletizerParameters,
    palletizer_kernel,
    palletizer_parameters,
    palletizer_problems,
)
from robotcell.ik.result import IKSolutions, exact_branches, flat_reference
from robotcell.ik.seeded import SeededSolver
from robotcell.ik.ur import URParameters, ur_kernel, ur_parameters, ur_problems
from robotcell.kinematics.arm import Arm
from robotcell.kinematics.bounds import within
from robotcell.kinematics.transforms import invert, validate_pose

__all__ = ["AnalyticSolver", "analytic_solver", "solve"]

#: Poses per block: keeps the kernel's temporaries in cache.
_BLOCK = 512

Kernel = Callable[..., NDArray[np.bool_]]


class AnalyticSolver:
    """Analytic IK of one robot: structure parameters plus the batched kernel.

    Parameters
    ----------
    robot : Arm
        A model with one of the supported structures.

    Raises
    ------
    InputError
        When the model has neither structure; the message says which conditions fail.
    """

    def __init__(self, robot: Arm) -> None:
        coupling = robot.coupling
        # The kernels see the model's joint values; a palletizer's kernel works on the controller
        # values directly (its parameters are read off the coupled forward kinematics).
        model = robot.uncoupled()
        self.params: OPWParameters | URParameters | PalletizerParameters
        opw = opw_problems(model)
        self.branches, self._mapped = 8, coupling is not None
        if not opw:
            self.method = "opw"
            self.params = opw_parameters(model)
            self._kernel: Kernel = opw_kernel
        elif not (ur := ur_problems(model)):
            self.method = "ur"
            self.params = ur_parameters(model)
            self._kernel = ur_kernel
        elif not (pal := palletizer_problems(robot)):
            self.method = "palletizer"
            self.params = palletizer_parameters(robot)
            self._kernel = palletizer_kernel
            self.branches, self._mapped = 4, False
        else:
            raise InputError(
                f"no analytic inverse kinematics for {robot.name}: not an ortho-parallel arm "
                f"with a spherical wrist ({'; '.join(opw)}), nor a Universal-Robots-type arm "
                f"({'; '.join(ur)}), nor a 4-axis palletizer ({'; '.join(pal)}). Name a nearby "
                "model with a closed form (its nominal model) with the model file key 'ik_seed', "
                "or use robotcell.ik.solve_numeric for this model."
            )
        self.robot = robot
        self.description = f"{self.method} solver"
        self._T_O_R = invert(self.params.T_R_O)
        self._fold = JointFolder(robot.lower, robot.upper)
        self._limits = None
        if coupling is not None:
            rev_model = np.array([not j.prismatic for j in robot.joints])
            periodic = coupling.periodic(rev_model, ~robot.prismatic)
            # Controller axes the mapping changes and that turn a full revolution: wrapped back to
            # (-pi, pi] before the 2*pi rule; axes that do not are checked against plain limits.
            self._wrap = [j for j in coupling.changed_axes() if periodic[j]] if self._mapped else []
            fixed = np.flatnonzero(~periodic & ~robot.prismatic)
            per = np.flatnonzero(periodic | robot.prismatic)
            if fixed.size:
                self._fold = JointFolder(robot.lower[per], robot.upper[per])
            self._limits = (per, fixed, robot.lower[fixed], robot.upper[fixed],
                            coupling if coupling.interaction.shape[0] else None)

    def _controller(self, q: NDArray[np.float64], reach: NDArray[np.bool_]) -> NDArray[np.bool_]:
        """Map a block of kernel solutions to controller values in place; return ``valid``."""
        coupling = self.robot.coupling
        if self._mapped:
            coupling.to_controller(q, out=q)
            for j in self._wrap:
                q[..., j] = wrap_to_pi(q[..., j])
        per, fixed, lo, hi, inter = self._limits
        if fixed.size:
            sub = q[..., per]
            ok = self._fold(sub)
            q[..., per] = sub
            f = q[..., fixed]
            ok &= np.all(within(f, lo, hi), axis=-1)
        else:
            ok = self._fold(q)
        if inter is not None:
            ok &= inter.within_interaction(q)
        return reach & ok

    def solve(self, T: ArrayLike, tool: ArrayLike | None = None,
              q_ref: ArrayLike | None = None) -> IKSolutions:
        """All 8 solutions for poses of the TCP.

        Parameters
        ----------
        T : array_like, shape (..., 4, 4)
            ``T_R_TCP``: target poses of the TCP in the robot base frame (m).
        tool : array_like, shape (4, 4), optional
            ``T_F_TCP`` instead of the robot's default tool (m).
        q_ref : array_like, shape (6,) or (..., 6), optional
            Reference configuration(s) (rad), e.g. the current or the taught one. Used only where
            an axis is free (singular configurations, see docs/ik.md): that axis takes the value
            nearest to the reference. Without it, a free axis takes a fixed choice.

        Returns
        -------
        IKSolutions
            ``q`` of shape ``(..., 8, 6)`` (``(..., 4, 4)`` for a palletizer): controller values
            (rad); ``reach_error`` of shape ``(..., 8)`` (``(..., 4)``) (m).
        """
        arr = validate_pose(T, "target pose")
        tool_T = self.robot.tool if tool is None else validate_pose(tool, "tool")
        ref = flat_reference(q_ref, self.robot.n_joints, arr.shape[:-2])
        # T_O_end = T_O_R @ T_R_TCP @ T_TCP_end, with T_TCP_end = inv(T_end_n @ flange @ tool).
        T_tcp_end = invert(self.params.T_e_n @ self.robot.flange @ tool_T)
        batch = arr.shape[:-2]
        flat = arr.reshape(-1, 4, 4)
        N = flat.shape[0]
        nb, n = self.branches, self.robot.n_joints
        q = np.empty((N, nb, n))
        reach = np.empty((N, nb), dtype=bool)
        valid = np.empty((N, nb), dtype=bool)
        err = np.zeros((N, nb))
        lo, hi = self.robot.lower, self.robot.upper
        if ref is not None and self._mapped:
            ref = self.robot.coupling.to_model(ref)  # the kernels see model values
        A = self._T_O_R[:3, :3]
        a = self._T_O_R[:3, 3]
        B = T_tcp_end[:3, :3]
        bvec = T_tcp_end[:3, 3]
        for s in range(0, N, _BLOCK):
            blk = flat[s:s + _BLOCK]
            Rt = blk[:, :3, :3]
            R = A @ (Rt @ B)
            P = (Rt @ bvec + blk[:, :3, 3]) @ A.T + a
            qb = q[s:s + _BLOCK]
            if self.method == "palletizer":  # no reach distance: inf where a branch misses
                rb = self._kernel(self.params, R, P, qb)
                err[s:s + _BLOCK][~rb] = np.inf
            else:
                rb = self._kernel(self.params, R, P, qb, err[s:s + _BLOCK],
                                  None if ref is None else ref[s:s + _BLOCK], lo, hi)
            if self._limits is None:
                vb = rb & self._fold(qb)  # 2*pi rule and limits, in cache
            else:
                vb = self._controller(qb, rb)
            valid[s:s + _BLOCK] = exact_branches(vb, err[s:s + _BLOCK])
            reach[s:s + _BLOCK] = rb
        return IKSolutions(q.reshape(batch + (nb, n)), valid.reshape(batch + (nb,)),
                           reach.reshape(batch + (nb,)), self.method, err.reshape(batch + (nb,)))


_CACHE: weakref.WeakKeyDictionary[Arm, AnalyticSolver | SeededSolver] = weakref.WeakKeyDictionary()


def analytic_solver(robot: Arm) -> AnalyticSolver | SeededSolver:
    """The (cached) IK solver of ``robot``; raises :class:`InputError` if it has none.

    The analytic solver of its structure; for a robot without one but with an ``ik_seed``, the
    seed's analytic branches refined numerically (:class:`~robotcell.ik.seeded.SeededSolver`).
    """
    solver = _CACHE.get(robot)
    if solver is None:
        try:
            solver = AnalyticSolver(robot)
        except InputError:
            if robot.ik_seed is None:
                raise
            solver = SeededSolver(robot, analytic_solver(robot.ik_seed))
        _CACHE[robot] = solver
    return solver


def solve(robot: Arm, T: ArrayLike, tool: ArrayLike | None = None,
          q_ref: ArrayLike | None = None) -> IKSolutions:
    """All analytic IK solutions of ``robot`` for TCP poses ``T`` (see :meth:`AnalyticSolver.solve`).

    Parameters
    ----------
    robot : Arm
    T : array_like, shape (..., 4, 4)
        ``T_R_TCP`` (m), including the robot's base, flange and tool transforms.
    tool : array_like, shape (4, 4), optional
        ``T_F_TCP`` instead of the robot's default tool (m).
    q_ref : array_like, shape (6,) or (..., 6), optional
        Reference configuration (rad) for axes that are free at singular configurations.

    Returns
    -------
    IKSolutions
    """
    return analytic_solver(robot).solve(T, tool, q_ref)
