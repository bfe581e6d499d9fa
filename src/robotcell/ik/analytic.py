"""Batched analytic inverse kinematics of a :class:`~robotcell.robot.Robot`.

:func:`solve` recognises the structure of the model once (cached per robot object) and returns
all 8 solutions of every pose: ortho-parallel arms with a spherical wrist through
:mod:`robotcell.ik.opw`, Universal-Robots-type arms through :mod:`robotcell.ik.ur`.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.ik.limits import JointFolder
from robotcell.ik.opw import OPWParameters, opw_kernel, opw_parameters, opw_problems
from robotcell.ik.result import IKSolutions
from robotcell.ik.ur import URParameters, ur_kernel, ur_parameters, ur_problems
from robotcell.robot import Robot
from robotcell.transforms import finite_array, invert, validate_pose

__all__ = ["AnalyticSolver", "analytic_solver", "solve"]

#: Poses per block: keeps the kernel's temporaries in cache.
_BLOCK = 512

Kernel = Callable[..., NDArray[np.bool_]]


class AnalyticSolver:
    """Analytic IK of one robot: structure parameters plus the batched kernel.

    Parameters
    ----------
    robot : Robot
        A model with one of the supported structures.

    Raises
    ------
    InputError
        When the model has neither structure; the message says which conditions fail.
    """

    def __init__(self, robot: Robot) -> None:
        opw = opw_problems(robot)
        if not opw:
            self.method = "opw"
            self.params: OPWParameters | URParameters = opw_parameters(robot)
            self._kernel: Kernel = opw_kernel
        else:
            ur = ur_problems(robot)
            if ur:
                raise InputError(
                    f"no analytic inverse kinematics for {robot.name}: not an ortho-parallel arm "
                    f"with a spherical wrist ({'; '.join(opw)}), nor a Universal-Robots-type arm "
                    f"({'; '.join(ur)}). Use robotcell.ik.solve_numeric for this model."
                )
            self.method = "ur"
            self.params = ur_parameters(robot)
            self._kernel = ur_kernel
        self.robot = robot
        self._T_O_R = invert(self.params.T_R_O)
        self._fold = JointFolder(robot.lower, robot.upper)

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
            ``q`` of shape ``(..., 8, 6)`` (rad), ``reach_error`` of shape ``(..., 8)`` (m).
        """
        arr = validate_pose(T, "target pose")
        tool_T = self.robot.tool if tool is None else validate_pose(tool, "tool")
        ref = None
        if q_ref is not None:
            ref = finite_array(q_ref, "q_ref")
            if ref.ndim == 0 or ref.shape[-1] != 6:
                raise InputError(f"q_ref must have shape (..., 6), got {ref.shape}")
            try:
                ref = np.broadcast_to(ref, arr.shape[:-2] + (6,)).reshape(-1, 6)
            except ValueError:
                raise InputError(f"q_ref of shape {ref.shape} does not match the "
                                 f"{arr.shape[:-2]} poses") from None
        # T_O_end = T_O_R @ T_R_TCP @ T_TCP_end, with T_TCP_end = inv(T_end_n @ flange @ tool).
        T_tcp_end = invert(self.params.T_e_n @ self.robot.flange @ tool_T)
        batch = arr.shape[:-2]
        flat = arr.reshape(-1, 4, 4)
        N = flat.shape[0]
        q = np.empty((N, 8, 6))
        reach = np.empty((N, 8), dtype=bool)
        valid = np.empty((N, 8), dtype=bool)
        err = np.empty((N, 8))
        lo, hi = self.robot.lower, self.robot.upper
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
            rb = self._kernel(self.params, R, P, qb, err[s:s + _BLOCK],
                              None if ref is None else ref[s:s + _BLOCK], lo, hi)
            valid[s:s + _BLOCK] = rb & self._fold(qb)  # 2*pi rule and limits, in cache
            reach[s:s + _BLOCK] = rb
        return IKSolutions(q.reshape(batch + (8, 6)), valid.reshape(batch + (8,)),
                           reach.reshape(batch + (8,)), self.method, err.reshape(batch + (8,)))


_CACHE: weakref.WeakKeyDictionary[Robot, AnalyticSolver] = weakref.WeakKeyDictionary()


def analytic_solver(robot: Robot) -> AnalyticSolver:
    """The (cached) analytic solver of ``robot``; raises :class:`InputError` if it has none."""
    solver = _CACHE.get(robot)
    if solver is None:
        solver = AnalyticSolver(robot)
        _CACHE[robot] = solver
    return solver


def solve(robot: Robot, T: ArrayLike, tool: ArrayLike | None = None,
          q_ref: ArrayLike | None = None) -> IKSolutions:
    """All analytic IK solutions of ``robot`` for TCP poses ``T`` (see :meth:`AnalyticSolver.solve`).

    Parameters
    ----------
    robot : Robot
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
