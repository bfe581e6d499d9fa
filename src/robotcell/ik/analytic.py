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

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.ik import opw, palletizer, ur
from robotcell.ik.axes import AXIS_TOL
from robotcell.ik.limits import wrap_to_pi
from robotcell.ik.result import EXACT_TOL, REACH_TOL, IKSolutions, flat_reference
from robotcell.ik.seeded import SeededSolver
from robotcell.kinematics.arm import Arm
from robotcell.kinematics.bounds import LIMIT_TOL
from robotcell.kinematics.transforms import invert, validate_pose, validate_single_pose

__all__ = ["AnalyticSolver", "analytic_solver", "solve"]


class AnalyticSolver:
    """Analytic IK of one robot: structure parameters plus the compiled kernel.

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
        self.params: opw.OPWParameters | ur.URParameters | palletizer.PalletizerParameters
        problems = opw.opw_problems(model)
        self.branches, self._mapped = 8, coupling is not None
        if not problems:
            self.method = "opw"
            self.params = opw.opw_parameters(model)
        elif not (ur_problems := ur.ur_problems(model)):
            self.method = "ur"
            self.params = ur.ur_parameters(model)
        elif not (pal_problems := palletizer.palletizer_problems(robot)):
            self.method = "palletizer"
            self.params = palletizer.palletizer_parameters(robot)
            self.branches, self._mapped = 4, False
        else:
            raise InputError(
                f"no analytic inverse kinematics for {robot.name}: not an ortho-parallel arm "
                f"with a spherical wrist ({'; '.join(problems)}), nor a Universal-Robots-type arm "
                f"({'; '.join(ur_problems)}), nor a 4-axis palletizer ({'; '.join(pal_problems)}). "
                "Name a nearby model with a closed form (its nominal model) with the model file "
                "key 'ik_seed', or use robotcell.ik.solve_numeric for this model."
            )
        from robotcell.ik import kernels  # compiled code: numba loads when a solver is built

        self._kernels = kernels
        self.robot = robot
        self.description = f"{self.method} solver"
        lower, upper = robot.lower, robot.upper
        modes = kernels.fold_modes(lower, upper)
        self._wrap: list[int] = []
        self._inter = None
        if coupling is not None:
            rev_model = np.array([not j.prismatic for j in robot.joints])
            periodic = coupling.periodic(rev_model, ~robot.prismatic)
            # Controller axes the mapping changes and that turn a full revolution: wrapped back to
            # (-pi, pi] before the 2*pi rule; axes that do not are checked against plain limits.
            self._wrap = [j for j in coupling.changed_axes() if periodic[j]] if self._mapped else []
            fixed = ~periodic & ~robot.prismatic
            per = ~fixed
            modes[per] = kernels.fold_modes(lower[per], upper[per])
            modes[fixed] = kernels.FOLD_CHECK
            self._inter = coupling if coupling.interaction.shape[0] else None
        self._modes = modes
        tolerances = {"LIMIT_TOL": LIMIT_TOL, "REACH_TOL": REACH_TOL, "EXACT_TOL": EXACT_TOL,
                      "SINGULAR_TOL": ur.SINGULAR_TOL if self.method == "ur" else opw.SINGULAR_TOL,
                      "ROUND": opw.ROUND, "LEVEL_TOL": palletizer.LEVEL_TOL,
                      "COS_TOL": palletizer.COS_TOL, "AXIS_TOL": AXIS_TOL}
        self._cfg = kernels.pack(self.method, self._packed_params(), invert(self.params.T_R_O),
                                 lower, upper, modes, coupling is None, tolerances)
        self._tcp_end = np.ascontiguousarray(invert(self.params.T_e_n @ robot._tail))
        self._last_tail: tuple[NDArray[np.float64] | None, NDArray[np.float64]] = (None,
                                                                                     self._tcp_end)
        self._no_ref = np.empty((0, 6))
        self._shape = (self.branches, robot.n_joints)

    def _packed_params(self) -> NDArray[np.float64]:
        pa, k = self.params, self._kernels
        if self.method == "opw":
            return k.opw_params(pa.a1, pa.a2, pa.b, pa.c1, pa.c2, pa.c3, pa.c4, pa.signs, pa.offsets)
        if self.method == "ur":
            return k.ur_params(pa.d1, pa.a2, pa.a3, pa.d4, pa.d5, pa.d6, pa.signs, pa.offsets)
        planar = (pa.A_r, pa.A_h, pa.b, pa.L2, pa.L3, pa.s1, pa.s4, pa.g22, pa.o2, pa.g32, pa.g33,
                  pa.o3)
        return k.palletizer_params(planar, pa.v_n, pa.R_n0)

    def end(self, tool: ArrayLike | None) -> NDArray[np.float64]:
        """``T_TCP_end = inv(T_end_n @ flange @ tool)``: the solver's end frame seen from the TCP,
        for ``tool`` (``T_F_TCP``, validated; the robot's own tool when None). The last tool's is
        kept (the arm keeps its ``flange @ tool``), for a loop of single poses with one tool."""
        if tool is None:
            return self._tcp_end
        tail = self.robot._tail_for(tool)
        last = self._last_tail  # one read: another thread may replace it
        if tail is not last[0]:
            last = self._last_tail = (tail, np.ascontiguousarray(invert(self.params.T_e_n @ tail)))
        return last[1]

    def _finish(self, q: NDArray[np.float64], reach: NDArray[np.bool_],
                err: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Kernel solutions ``(N, branches, n)`` of a coupled robot to controller values in place
        (wrapped, 2*pi rule), and ``valid``: within the joint and interaction limits, exact."""
        k = self._kernels
        n = q.shape[-1]
        if self._mapped:
            self.robot.coupling.to_controller(q, out=q)
            for j in self._wrap:
                q[..., j] = wrap_to_pi(q[..., j])
        inside = np.empty(q.shape[:-1], dtype=bool)
        k.fold_rows(q.reshape(-1, n), self._modes, self.robot.lower, self.robot.upper, LIMIT_TOL,
                    inside.reshape(-1))
        if self._inter is not None:
            inside &= self._inter.within_interaction(q)
        valid = reach & inside
        k.exact_rows(valid.reshape(-1, self.branches), err.reshape(-1, self.branches), EXACT_TOL)
        return valid

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
        end = self.end(tool)
        if q_ref is None and type(T) is np.ndarray and T.shape == (4, 4):
            # One pose: one compiled check and one compiled solve (the per-call path).
            arr = validate_single_pose(T, "target pose")
            q = np.empty(self._shape)
            err = np.empty(self.branches)
            reach = np.empty(self.branches, dtype=bool)
            valid = np.empty(self.branches, dtype=bool)
            self._kernels.solve_poses(self._cfg, arr, end, self._no_ref, q, err, reach, valid)
            if self.robot.coupling is not None:
                valid = self._finish(q[None], reach[None], err[None])[0]
            return IKSolutions(q, valid, reach, self.method, err)
        arr = validate_pose(T, "target pose")
        batch = arr.shape[:-2]
        ref = flat_reference(q_ref, self.robot.n_joints, batch)
        if ref is None:
            ref = self._no_ref
        elif self._mapped:
            ref = self.robot.coupling.to_model(ref)  # the kernels see model values
        flat = np.ascontiguousarray(arr.reshape(-1, 4, 4))
        N = flat.shape[0]
        q = np.empty((N,) + self._shape)
        err = np.empty((N, self.branches))
        reach = np.empty((N, self.branches), dtype=bool)
        valid = np.empty((N, self.branches), dtype=bool)
        self._kernels.solve_poses(self._cfg, flat.reshape(-1, 4), end, np.ascontiguousarray(ref),
                                  q.reshape(-1, q.shape[-1]), err.reshape(-1), reach.reshape(-1),
                                  valid.reshape(-1))
        if self.robot.coupling is not None:
            valid = self._finish(q, reach, err)
        nb = (self.branches,)
        return IKSolutions(q.reshape(batch + self._shape), valid.reshape(batch + nb),
                           reach.reshape(batch + nb), self.method, err.reshape(batch + nb))


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
