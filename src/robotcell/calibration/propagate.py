"""First-order propagation of a parameter covariance through a function (numerical Jacobian).

Used by the external-axis procedures (track, turntable, workpiece) to turn the covariance of the
fitted parameters into 1-sigma uncertainties of derived quantities (a unit direction, a tilt angle,
a rotation fixed by convention).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["jacobian", "propagate"]


def jacobian(fun: Callable[[NDArray[np.float64]], ArrayLike], x: ArrayLike,
             step: float = 1e-7) -> NDArray[np.float64]:
    """Central-difference Jacobian of ``fun`` at ``x``.

    Parameters
    ----------
    fun : callable
        ``fun(x) -> y`` with ``x`` of shape (p,) and ``y`` of any shape (flattened to (m,)).
    x : array_like, shape (p,)
        Point of linearisation (SI units).
    step : float
        Step per parameter, relative to ``max(1, |x_j|)``.

    Returns
    -------
    ndarray, shape (m, p)
    """
    x = np.asarray(x, dtype=float)
    cols = []
    for j in range(x.size):
        h = step * max(1.0, abs(x[j]))
        xp, xm = x.copy(), x.copy()
        xp[j] += h
        xm[j] -= h
        diff = np.ravel(np.asarray(fun(xp), dtype=float) - np.asarray(fun(xm), dtype=float))
        cols.append(diff / (2.0 * h))
    return np.stack(cols, axis=1)


def propagate(fun: Callable[[NDArray[np.float64]], ArrayLike], x: ArrayLike,
              cov: ArrayLike) -> NDArray[np.float64]:
    """Covariance of ``fun(x)`` given the covariance of ``x`` (first order, ``G C G^T``).

    Parameters
    ----------
    fun : callable
        ``fun(x) -> y`` with ``x`` of shape (p,); ``y`` is flattened to (m,).
    x : array_like, shape (p,)
        Estimate (SI units).
    cov : array_like, shape (p, p)
        Covariance of the estimate.

    Returns
    -------
    ndarray, shape (m, m)
        Covariance of the flattened ``fun(x)``; NaN where ``cov`` is NaN.
    """
    G = jacobian(fun, x)
    return G @ np.asarray(cov, dtype=float) @ G.T
