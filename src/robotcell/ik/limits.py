"""Joint limits and 2*pi-equivalent joint values.

A revolute joint that turns more than one revolution (KUKA A6 +-350 deg, ABB axis 6 +-400 deg,
UR joints +-360 deg) reaches the same pose at ``q`` and ``q +- 2*pi``. The analytic solvers first
produce the principal value in ``[-pi, pi)`` and then apply the rule of :func:`fold_into_limits`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = ["TWO_PI", "fold_into_limits", "shift_into_interval", "wrap_to_pi"]

TWO_PI = 2.0 * math.pi


def wrap_to_pi(angle: NDArray[np.float64]) -> NDArray[np.float64]:
    """Equivalent angles in ``[-pi, pi)`` (rad), same shape as ``angle``."""
    return angle - TWO_PI * np.floor((angle + math.pi) * (1.0 / TWO_PI))


def shift_into_interval(q: NDArray[np.float64], lo: NDArray[np.float64] | float,
                        hi: NDArray[np.float64] | float) -> NDArray[np.float64]:
    """The smallest 2*pi-equivalent of ``q`` that is ``>= lo``, or NaN if it is above ``hi``.

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
    out = q + TWO_PI * np.ceil((lo - q) * (1.0 / TWO_PI))
    return np.where(out <= hi, out, np.nan)


def fold_into_limits(q: NDArray[np.float64], lower: NDArray[np.float64],
                     upper: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Choose, per revolute joint, the 2*pi-equivalent inside the limits.

    The rule: keep ``q`` if it is within ``[lower, upper]``; otherwise take the equivalent
    ``q + 2*pi*k`` inside the limits with the smallest ``|k|`` (the one nearest to ``q``). When no
    equivalent is inside, ``q`` is kept and marked outside.

    Parameters
    ----------
    q : ndarray, shape (..., n)
        Principal joint values (rad), e.g. in ``[-pi, pi)``.
    lower, upper : ndarray, shape (n,)
        Joint limits (rad), possibly infinite.

    Returns
    -------
    q : ndarray, shape (..., n)
        Chosen equivalents.
    inside : ndarray of bool, shape (..., n)
        Whether the chosen value is within the limits.
    """
    below = q < lower
    above = q > upper
    # Smallest equivalent above the lower limit, and largest one below the upper limit.
    up = q + TWO_PI * np.ceil((lower - q) * (1.0 / TWO_PI))
    down = q - TWO_PI * np.ceil((q - upper) * (1.0 / TWO_PI))
    out = np.where(below, up, np.where(above, down, q))
    inside = (out >= lower) & (out <= upper)
    return np.where(inside, out, q), inside
