"""How close arm configurations are to the singularities of an ortho-parallel arm, and which
axis a configuration takes outside its limits: what the checks of points and of linear motions
report (:mod:`robotcell.programs.check`, :mod:`robotcell.programs.lines`)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.ik.analytic import analytic_solver
from robotcell.robot.robot import Robot

__all__ = ["SHOULDER_MARGIN", "SINGULAR_MARGIN", "outside_text", "singular_distances"]

#: Closest approach to the wrist or elbow singularity that still counts as good (rad).
SINGULAR_MARGIN = math.radians(2.0)
#: Closest approach of the wrist centre to axis 1 that still counts as good (m).
SHOULDER_MARGIN = 0.02


def singular_distances(robot: Robot, q: ArrayLike
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Distances of configurations to the singularities of an ortho-parallel arm.

    Parameters
    ----------
    robot : Robot
    q : array_like, shape (..., 6)
        Controller axis values (rad).

    Returns
    -------
    wrist : ndarray, shape (...)
        Angle of axis 5 from its singular values (rad): the wrist singularity.
    elbow : ndarray, shape (...)
        Angle of the forearm from the line through axes 2 and 3 (rad): the arm stretched or
        folded.
    shoulder : ndarray, shape (...)
        Distance of the wrist centre from the line of axis 1 (m).
        All NaN for an arm that is not ortho-parallel.
    """
    arr = np.asarray(q, dtype=float)
    solver = analytic_solver(robot)
    if solver.method != "opw":
        nan = np.full(arr.shape[:-1], np.nan)
        return nan, nan, nan
    p = solver.params
    model = robot.coupling.to_model(arr) if robot.coupling is not None else arr
    th = model * p.signs + p.offsets
    t2, t3 = th[..., 1], th[..., 2]
    t23 = t2 + t3

    def off_pi(t: NDArray) -> NDArray:
        return np.abs(np.mod(t + math.pi / 2, math.pi) - math.pi / 2)

    wx = p.a1 + p.c2 * np.sin(t2) + p.a2 * np.cos(t23) + p.c3 * np.sin(t23)
    return off_pi(th[..., 4]), off_pi(t3 + math.atan2(p.a2, p.c3)), np.hypot(wx, p.b)


def outside_text(robot: Robot, q: NDArray[np.float64]) -> str:
    """Words for the first axis of ``q`` (shape ``(6,)``, rad) outside its limits."""
    bad = (q < robot.lower) | (q > robot.upper)
    if not np.any(bad):
        return "the axes' interaction limits are exceeded"
    j = int(np.argmax(bad))
    return (f"axis {j + 1} is at {math.degrees(q[j]):.1f} deg, outside its limits "
            f"[{math.degrees(robot.lower[j]):g}, {math.degrees(robot.upper[j]):g}] deg")
