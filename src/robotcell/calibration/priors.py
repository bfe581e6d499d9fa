"""Inputs estimated with the rest: their errors as parameters under their stated priors.

:func:`robotcell.calibration.fitting.fit` carries the errors of the inputs (a tool, a track)
by propagation: the touches are weighted alike and the inputs' errors added to the 1-sigma. When
one fit combines touch sets in which an input's error shows differently (a robot's tool turned
one way for the touches of a turntable and another way for the touches of common points),
equal weights are no longer the best: :func:`fit_with_priors` estimates the inputs' errors with
the other parameters, each under its prior (its error sources), which is the generalised least
squares, maximum-likelihood estimate of all touches with those systematic errors. It never
determines a quantity worse than any subset of its touches does.

With ``v = F z`` the input's error (``F`` its sources' factor, ``z ~ N(0, I)``), a touch
recorded with the nominal inputs is ``p + S F z`` at the truth (``S`` its sensitivity), and
each prior is a pseudo-touch ``-s z`` (``s`` the touch accuracy) whose error has the touches'
variance; the fit's covariance then splits exactly into the touches' own part and one part per
input source, which keeps the sources (and the correlations they carry) for
:mod:`robotcell.calibration.sigmaparts` and the chain of calibrations.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.fitting import DEFAULT_TOUCH_SIGMA, Fit, fit
from robotcell.calibration.uncertainty import OWN, Inputs, Sources, factor_of

__all__ = ["PriorFit", "fit_with_priors"]


@dataclass(frozen=True)
class PriorFit:
    """A fit with its inputs' errors as parameters.

    Attributes
    ----------
    fit : Fit
        The fit over the parameters and the inputs' ``z`` (touches first, then the priors as
        pseudo-touches, 3 coordinates each).
    size : int
        Number of the model's own parameters p (the first p of ``fit.x``).
    touches : int
        Number of touches N (the first N rows of ``fit.residuals``).
    sources : Sources
        Error sources of the p parameters: the touches' own noise and each input source.
    gain : ndarray, shape (p, k)
        How the estimate follows the k nominal input parameters.
    blocks : list of str
        Per prior pseudo-touch, the input sources it holds (for messages).
    """

    fit: Fit
    size: int
    touches: int
    sources: Sources
    gain: NDArray[np.float64]
    blocks: list[str]

    @property
    def x(self) -> NDArray[np.float64]:
        """The model's parameters, shape (p,)."""
        return self.fit.x[:self.size]

    @property
    def covariance(self) -> NDArray[np.float64]:
        """Covariance of the model's parameters (all sources), shape (p, p)."""
        return self.sources.covariance


def fit_with_priors(fun: Callable[[NDArray[np.float64]], NDArray[np.float64]], x0: ArrayLike,
                    names: Sequence[str], sigma: float | None, advice: str,
                    inputs: Inputs) -> PriorFit:
    """Maximum likelihood over the parameters and the inputs' errors under their priors.

    Parameters
    ----------
    fun : callable
        ``fun(x) -> residuals`` (N, 3) of the touches, measured (with the nominal inputs) minus
        model (m), as for :func:`~robotcell.calibration.fitting.fit`.
    x0 : array_like, shape (p,)
    names : sequence of str
        The p parameters' names.
    sigma : float, optional
        Touch accuracy (m per coordinate); default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    advice : str
        What to measure when the parameters are not determined.
    inputs : Inputs
        The inputs: sensitivity (N, 3, k) of each touch and their sources.

    Returns
    -------
    PriorFit
    """
    x0 = np.asarray(x0, dtype=float)
    p, n = len(x0), len(inputs.sensitivity)
    F, cols = inputs.sources.matrix()
    m = F.shape[1]
    SF = np.einsum("nik,km->nim", inputs.sensitivity, F)
    nb = -(-m // 3)
    s = DEFAULT_TOUCH_SIGMA if sigma is None else float(sigma)
    P = np.broadcast_to(np.eye(3), (n + nb, 3, 3)).copy()
    if m % 3:
        P[-1] = np.diag([1.0 if i < m % 3 else 0.0 for i in range(3)])

    def resid(x: NDArray[np.float64]) -> NDArray[np.float64]:
        z = x[p:]
        touch = np.asarray(fun(x[:p]), dtype=float).reshape(-1, 3) + SF @ z
        prior = np.zeros(3 * nb)
        prior[:m] = -s * z
        return np.concatenate([touch, prior.reshape(-1, 3)])

    znames = [f"error of {c} ({i + 1})" for i, c in enumerate(cols)]
    res = fit(resid, np.concatenate([x0, np.zeros(m)]), list(names) + znames, sigma, advice,
              measured=lambda x: P)
    C0 = res.own_covariance / res.noise_sigma**2
    Jt = res.jacobian[:3 * n]
    own = res.noise_sigma**2 * (C0 @ Jt.T @ Jt @ C0)[:p, :p]
    factors = {OWN: factor_of(own)}
    for name in dict.fromkeys(cols):
        idx = p + np.flatnonzero(np.array(cols) == name)
        factors[name] = -s**2 * C0[:p, idx]
    gain = -(C0 @ Jt.T)[:p] @ inputs.sensitivity.reshape(3 * n, -1)
    blocks = [", ".join(dict.fromkeys(cols[3 * b:3 * b + 3])) for b in range(nb)]
    return PriorFit(res, p, n, Sources(p, factors), gain, blocks)
