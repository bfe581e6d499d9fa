"""Joint limits and 2*pi-equivalent joint values.

A revolute joint that turns more than one revolution (KUKA A6 +-350 deg, ABB axis 6 +-400 deg,
UR joints +-360 deg) reaches the same pose at ``q`` and ``q +- 2*pi``. The analytic solvers first
produce the principal value in ``(-pi, pi]`` and then apply the rule of :class:`JointFolder`.
Limits count up to rounding (:data:`robotcell.kinematics.bounds.LIMIT_TOL`): a value at a limit
is inside it.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.kinematics.bounds import LIMIT_TOL

__all__ = ["TWO_PI", "JointFolder", "shift_into_interval", "wrap_to_pi"]

TWO_PI = 2.0 * math.pi


def wrap_to_pi(angle: ArrayLike) -> NDArray[np.float64]:
    """Equivalent angles in ``(-pi, pi]`` (rad), same shape as ``angle``."""
    a = np.asarray(angle, dtype=float)
    return a - TWO_PI * np.ceil((a - math.pi) * (1.0 / TWO_PI))


def shift_into_interval(q: NDArray[np.float64], lo: NDArray[np.float64] | float,
                        hi: NDArray[np.float64] | float) -> NDArray[np.float64]:
    """The smallest 2*pi-equivalent of ``q`` that is ``>= lo``, or NaN if it is above ``hi``.

    Both bounds count up to rounding (:data:`robotcell.kinematics.bounds.LIMIT_TOL`): a value
    ``lo - 1e-14`` stays, it is not moved up by a turn.

    Parameters
    ----------
    q : ndarray, shape (...)
        Angles (rad).
    lo, hi : float or ndarray broadcastable to ``q``
        Interval bounds (rad); ``lo`` must be finite.

    Returns
    -------
    ndarray, shape (...)
        When ``hi - lo < 2*pi`` this is the only equivalent in ``[lo, hi]``, if any.
    """
    out = q + TWO_PI * np.ceil((lo - LIMIT_TOL - q) * (1.0 / TWO_PI))
    return np.where(out <= hi + LIMIT_TOL, out, np.nan)


class JointFolder:
    """Choose, per revolute joint, the 2*pi-equivalent of a principal value inside the limits.

    The rule: keep the principal value ``q`` (in ``(-pi, pi]``) if it is within
    ``[lower, upper]``; otherwise take ``q - 2*pi`` or ``q + 2*pi`` if that is inside (the nearest
    equivalents); if neither is, the principal value stays and is reported outside. For limits up
    to +-540 deg this finds an equivalent whenever one exists.

    Parameters
    ----------
    lower, upper : array_like, shape (n,)
        Joint limits (rad), possibly infinite.
    """

    def __init__(self, lower: ArrayLike, upper: ArrayLike) -> None:
        self.lower = np.ascontiguousarray(lower, dtype=float)
        self.upper = np.ascontiguousarray(upper, dtype=float)

    def __call__(self, q: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Fold ``q`` in place.

        Parameters
        ----------
        q : ndarray, shape (..., n)
            Principal values (rad) in ``(-pi, pi]``, NaN allowed; replaced by the chosen values.

        Returns
        -------
        ndarray of bool, shape (...)
            Whether every joint value is inside its limits (False where ``q`` has NaN).
        """
        from robotcell.ik import kernels  # the rule is compiled with the solvers that apply it

        flat = np.array(q, dtype=float).reshape(-1, self.lower.size)
        inside = np.empty(flat.shape[0], dtype=bool)
        kernels.fold_rows(flat, kernels.fold_modes(self.lower, self.upper), self.lower,
                          self.upper, LIMIT_TOL, inside)
        q[...] = flat.reshape(q.shape)
        return inside.reshape(q.shape[:-1])
