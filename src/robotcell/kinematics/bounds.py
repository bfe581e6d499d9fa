"""Limits up to rounding: a value at a joint or axis limit is inside it.

A value computed to lie exactly at a limit carries a rounding error of a few units in the last
place: the IK of a pose computed at axis 1 = 30 deg returns 30 deg + 1e-14 rad on some machines
(the last bits depend on the BLAS and the CPU). Every limit check of robotcell (joint limits,
interaction limits, track, turntable and positioner limits, the choice of a 2*pi-equivalent)
therefore allows :data:`LIMIT_TOL` beyond a limit: far above rounding (a joint value of 10 rad
has a last place of 2e-15 rad) and far below any mechanical meaning (1e-12 rad is 6e-11 deg,
1e-12 m a picometre).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["LIMIT_TOL", "within"]

#: Allowed excess beyond a limit (rad for angles, m for lengths): rounding, not motion.
LIMIT_TOL = 1e-12


def within(values: ArrayLike, lower: ArrayLike, upper: ArrayLike,
           tol: float = LIMIT_TOL) -> NDArray[np.bool_]:
    """Whether ``lower - tol <= values <= upper + tol``, elementwise (NaN gives False).

    Parameters
    ----------
    values : array_like, shape (...)
        Joint or axis values (rad, m).
    lower, upper : array_like, broadcastable to ``values``
        Limits (rad, m), possibly infinite.
    tol : float
        Allowed excess beyond a limit (rad, m); default :data:`LIMIT_TOL`.

    Returns
    -------
    ndarray of bool, shape (...)
    """
    v = np.asarray(values, dtype=float)
    if v.ndim == 0 and type(lower) is float and type(upper) is float:  # one value: no ufuncs
        x = float(v)
        return np.bool_(x >= lower - tol and x <= upper + tol)
    return (v >= np.asarray(lower, dtype=float) - tol) & (v <= np.asarray(upper, dtype=float) + tol)
