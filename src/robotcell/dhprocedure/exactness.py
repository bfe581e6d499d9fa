"""Whether a DH model, as its model file holds it, reproduces the chain it was derived from.

The DH procedure measures every constant from the geometry, so its model is exact to rounding.
What a user keeps, though, is the model file (millimetres and degrees, rounded: see
:func:`robotcell.robot.models.robot_to_dict`). :func:`check_exact` writes the model to that form,
reads it back, and compares its forward kinematics with the source's at seeded joint values:
the zero pose and random values within the limits (or a turn, or the chain's extent for a
prismatic joint without limits). A model that differs by more than :data:`EXACT_TOL` is refused,
naming the joints whose motion shows the difference and why.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.dhprocedure.axes import AxisChain
from robotcell.errors import InputError
from robotcell.robot.models import robot_from_dict, robot_to_dict
from robotcell.robot.robot import Robot

__all__ = ["EXACT_TOL", "check_exact", "written_form"]

#: The largest flange position (m) or orientation (rad) difference a derived model may have.
EXACT_TOL = 1e-9
#: Random joint values of the check, besides the zero pose.
_SAMPLES = 64


def written_form(robot: Robot) -> Robot:
    """``robot`` as its model file holds it: written (mm, degrees, rounded) and read back."""
    return robot_from_dict(robot_to_dict(robot), f"model {robot.name!r} as written")


def check_exact(
    robot: Robot, reference: Callable[[ArrayLike], NDArray[np.float64]], chain: AxisChain,
    what: str, tol: float,
) -> float:
    """How far the written ``robot`` is from ``reference``; refused beyond :data:`EXACT_TOL`.

    Parameters
    ----------
    robot : Robot
        The derived model (its tool is the identity).
    reference : callable
        The source's FK: joint values ``(..., n)`` (rad, m) to flange poses ``(..., 4, 4)`` (m).
    chain : AxisChain
        The source's axes: joint types, limits and extent for the joint values of the check.
    what : str
        The source as the message names it (a file name).
    tol : float
        The procedure's tolerance (m, rad), named when it is the cause.

    Returns
    -------
    float
        The largest position (m) or orientation (rad) difference of the written model.

    Raises
    ------
    InputError
        The difference exceeds :data:`EXACT_TOL`; the message says by how much, which joints'
        motion shows it, and why.
    """
    q = _joint_values(chain)
    written = written_form(robot)
    ref = reference(q)
    dev = _difference(written.fk(q), ref)
    if dev <= EXACT_TOL:
        return dev
    n = chain.n_joints
    moving = []
    for j in range(n):
        qj = np.zeros_like(q)
        qj[:, j] = q[:, j]
        if _difference(written.fk(qj), reference(qj)) > EXACT_TOL:
            moving.append(chain.names[j])
    shown = (f"moving joint(s) {', '.join(moving)} shows it" if moving
             else "it shows at the zero pose or only when several joints move together")
    if tol >= EXACT_TOL / 10 and _difference(robot.fk(q), ref) > EXACT_TOL:
        why = (f"the procedure took axes up to tol = {tol:g} m or rad apart as meeting or "
               "coinciding; give a smaller tol")
    else:
        size = max([abs(j.a) for j in robot.joints] + [abs(j.d) for j in robot.joints]
                   + [float(np.abs(T[:3, 3]).max()) for T in (robot.base, robot.flange)])
        why = (f"with constants up to {size:.3g} m, the arithmetic (1e-16 of them) and the model "
               "file's rounded mm and degrees move the flange that far; a chain this large, or "
               "this far from its base frame, has no DH model exact to 1e-9 m")
    raise InputError(f"{what}: the DH model as written differs from the source's forward "
                     f"kinematics by up to {dev:.3g} m or rad (more than {EXACT_TOL:g}): "
                     f"{shown}; {why}")


def _joint_values(chain: AxisChain) -> NDArray[np.float64]:
    """The zero pose and seeded random joint values within the limits, shape (N, n)."""
    pts = np.vstack([chain.points, chain.flange[:3, 3]])
    extent = max(float(np.max(np.linalg.norm(pts[:, None] - pts[None], axis=-1))), 1.0)
    pris = np.array([t == "prismatic" for t in chain.types])
    span = np.where(pris, extent, np.pi)
    lower, upper = chain.lower, chain.upper
    lo = np.where(np.isfinite(lower), lower, np.where(np.isfinite(upper), upper - 2 * span, -span))
    hi = np.where(np.isfinite(upper), upper, lo + 2 * span)
    rng = np.random.default_rng(0)
    return np.vstack([np.zeros(chain.n_joints), rng.uniform(lo, hi, (_SAMPLES, chain.n_joints))])


def _difference(A: NDArray[np.float64], B: NDArray[np.float64]) -> float:
    """Largest position (m) or rotation-matrix entry difference (about rad) of two pose sets."""
    dp = float(np.linalg.norm(A[..., :3, 3] - B[..., :3, 3], axis=-1).max())
    return max(dp, float(np.abs(A[..., :3, :3] - B[..., :3, :3]).max()))
