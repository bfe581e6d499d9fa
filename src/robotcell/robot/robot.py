"""A serial robot arm with its inverse kinematics.

:class:`Robot` is an :class:`~robotcell.kinematics.arm.Arm` (the DH model: forward kinematics,
Jacobian, limits, coupling; see that module) with :meth:`Robot.ik`, which offers the analytic
solvers of :mod:`robotcell.ik`. The solvers work on the :class:`~robotcell.kinematics.arm.Arm`
below this module and never import it, so the robot stands above them and no import runs in a
circle (docs/conventions.md, "Layout").
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from numpy.typing import ArrayLike

from robotcell.kinematics.arm import Arm, Joint

if TYPE_CHECKING:
    from robotcell.ik.result import IKSolutions

__all__ = ["Joint", "Robot"]


class Robot(Arm):
    """A serial arm: DH joints, base, flange and tool transforms, provenance, and its IK.

    Build one with :func:`robotcell.load_robot` (library name or model file) or directly, with
    the fields of :class:`~robotcell.kinematics.arm.Arm` (``name``, ``joints``, ``convention``,
    ``base``, ``flange``, ``tool``, ``home``, ``title``, ``source``, ``verified``,
    ``verification``, ``coupling``, ``ik_seed``, ``covariance``).
    """

    def ik(self, T: ArrayLike, tool: ArrayLike | None = None) -> IKSolutions:
        """Analytic inverse kinematics: every solution, see :func:`robotcell.ik.solve`.

        A model without a closed form but with an ``ik_seed`` gets the seed's analytic branches
        refined numerically to 1e-9 m and rad (:class:`robotcell.ik.seeded.SeededSolver`).

        Parameters
        ----------
        T : array_like, shape (..., 4, 4)
            ``T_R_TCP``, target poses of the TCP in the robot base frame (metres).
        tool : array_like, shape (4, 4), optional
            ``T_F_TCP`` to use instead of the default tool (metres).

        Returns
        -------
        IKSolutions
            ``q`` of shape ``(..., 8, 6)`` (``(..., 4, 4)`` for a palletizer) of controller values
            (rad, NaN for unreachable branches) and ``valid`` ``(..., 8)`` (reachable and within
            the joint limits).
        """
        solver = self.__dict__.get("_ik_solver")
        if solver is None:
            from robotcell.ik.analytic import analytic_solver  # loads when a pose is solved

            solver = analytic_solver(self)
            object.__setattr__(self, "_ik_solver", solver)
        return solver.solve(T, tool)
