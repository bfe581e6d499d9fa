"""Numerics shared by the calibration procedures: maximum-likelihood fit, covariance, outliers.

Every procedure models measured 3-D points (metres) as a function of its parameters plus
independent isotropic Gaussian noise of standard deviation ``s`` per coordinate, ``s`` the
touch accuracy (stated, or :data:`DEFAULT_TOUCH_SIGMA`). The maximum likelihood estimate
minimises the sum of squared residuals; :func:`fit` computes it with
:func:`scipy.optimize.least_squares` and returns the linearised covariance ``s^2 (J^T J)^-1``
plus the share of the errors of earlier calibrations it used (:class:`Inputs`). Rotations are
parameterised as a small rotation vector about a nominal rotation (:func:`perturb_rotation`), so
that an estimate is always a proper rotation. Every cost is linear in the number of touches.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation
from scipy.special import chdtrc, chdtri

from robotcell.calibration.propagate import jacobian
from robotcell.calibration.uncertainty import OWN, Inputs, Sources, factor_of
from robotcell.calibration.verdict import CHI2_P, DEFAULT_TOUCH_SIGMA_MM, POOR_FACTOR
from robotcell.errors import IllPosedError, InputError

__all__ = [
    "DEFAULT_TOUCH_SIGMA",
    "Fit",
    "chi2_bound",
    "fit",
    "kabsch",
    "keeps_out",
    "nearest_rotation",
    "outlier_warnings",
    "perturb_pose",
    "perturb_rotation",
    "pose_sigma",
    "scaled_condition",
    "solution_fit",
    "touch_statistics",
]

#: Probability inside "3 sigma" for a 1-D Gaussian; used for the 3-D residual test ...
THREE_SIGMA_P = 0.9973
#: ... whose false-alarm probability per touch is therefore 0.27 %.
OUTLIER_P = 1.0 - THREE_SIGMA_P

#: Touch accuracy when none is stated (m, 1-sigma per coordinate): the verdict's default.
DEFAULT_TOUCH_SIGMA = DEFAULT_TOUCH_SIGMA_MM * 1e-3

#: Residual variance (as a fraction of the touch's) below which a direction counts as absorbed
#: by the fit: the touch alone decides it, so nothing checks it.
LEVERAGE_ONE = 1e-6

#: Scaled-Jacobian condition number above which the parameters count as not determined. The
#: Jacobian comes from finite differences, whose rounding (about 1e-8 relative) shows an exactly
#: undetermined combination as a condition number of about 1e8, not infinity; a design between
#: the verdict's 1000 and this bound is computed and graded poor.
SINGULAR_CONDITION = 1e7

#: Distance (m) below which two measured points coincide to rounding (1 nm; controllers print
#: 1 um): geometry that needs them apart (a direction from one to the other, a radius) then
#: determines nothing and is refused. Any larger distance is data: the fit computes the result and
#: its uncertainty, and the verdict grades a weak design by its condition number.
SAME_POINT = 1e-9


@dataclass
class Fit:
    """Solution of a maximum-likelihood point fit, with its uncertainty and the test of every touch.

    Attributes
    ----------
    x : ndarray, shape (p,)
        Parameters at the optimum (SI).
    residuals : ndarray, shape (N, 3)
        Measured minus model per measured point (metres), in the directions the point measures
        (see ``measured`` of :func:`fit`); for a touch left out of the fit, its residual against
        the fit of the others.
    jacobian : ndarray, shape (3N, p)
        Jacobian of the flattened residuals at the optimum, projected on the measured directions;
        rows of touches left out are zero.
    measured : ndarray, shape (N, 3, 3)
        Projector on the directions each touch measures (the identity unless the model
        eliminated free coordinates of the touches).
    covariance : ndarray, shape (p, p)
        Covariance of ``x``: ``noise_sigma^2 (J^T J)^-1`` plus the share of the inputs' errors.
    sigma : ndarray, shape (p,)
        Square roots of the diagonal of ``covariance``.
    noise_sigma : float
        ``s`` (metres per coordinate) behind ``covariance``: the touch accuracy, or the noise the
        residuals need when they are larger than the accuracy explains.
    noise_source : {"prior", "default", "residuals"}
        ``"prior"``: the stated accuracy; ``"default"``: :data:`DEFAULT_TOUCH_SIGMA`;
        ``"residuals"``: the residuals fail the chi-square test against the accuracy, so their
        noise estimate (larger) is used.
    touch_sigma : float
        The stated touch accuracy, or the default (metres per coordinate).
    accuracy_source : {"stated", "default"}
    residual_sigma : float
        Noise estimated from the residuals, ``sqrt(chi2 / dof) touch_sigma``; NaN without
        redundancy. A check against ``touch_sigma``, never a reason to report less.
    chi2 : float or None
        Residuals against the touch accuracy and the inputs' errors (chi-square with ``dof``
        degrees of freedom for good touches); None without redundancy.
    dof : int
        Scalar measurements (of the touches used) minus parameters.
    condition : float
        Condition number of ``J`` with each column scaled to unit 2-norm.
    pvalues : ndarray, shape (N,)
        Probability of a residual at least this large for a good touch (leave-one-out test, see
        :func:`touch_statistics`); NaN where the touch cannot be tested.
    expected : ndarray, shape (N,)
        Expected length of each residual for a good touch (metres).
    excluded : list of int
        Touches left out of the fit (at most one: a gross error the others single out).
    suspects : list of int
        Flagged touches each of which alone would explain the residuals' excess (see
        :func:`fit`): one is left out; several disagree, and the others cannot tell which is
        wrong, so none is.
    unchecked : list of int
        Touches whose error in some direction goes into the result with nothing to check it (no
        other touch measures that direction).
    gross : list of int
        Outliers so large that even three times the accuracy does not explain them.
    sources : Sources
        Error sources of ``x``: :data:`~robotcell.calibration.uncertainty.OWN` (this fit's touch
        noise) and those of the inputs.
    input_gain : ndarray, shape (p, k)
        ``dx / dv``: how the estimate follows the k input parameters.
    input_information : ndarray, shape (k, k)
        ``Jv^T (I - H) Jv``: what the residuals say about the inputs (metres^2 per unit^2).
    input_score : ndarray, shape (k,)
        ``Jv^T r`` at the optimum.
    own_covariance : ndarray, shape (p, p)
        ``noise_sigma^2 (J^T J)^-1``: the share of this fit's own touch noise.
    """

    x: NDArray[np.float64]
    residuals: NDArray[np.float64]
    jacobian: NDArray[np.float64]
    measured: NDArray[np.float64]
    covariance: NDArray[np.float64]
    sigma: NDArray[np.float64]
    noise_sigma: float
    noise_source: str
    touch_sigma: float
    accuracy_source: str
    residual_sigma: float
    chi2: float | None
    dof: int
    condition: float
    pvalues: NDArray[np.float64]
    expected: NDArray[np.float64]
    excluded: list[int]
    suspects: list[int]
    unchecked: list[int]
    gross: list[int]
    sources: Sources
    input_gain: NDArray[np.float64]
    input_information: NDArray[np.float64]
    input_score: NDArray[np.float64]
    own_covariance: NDArray[np.float64]

    @property
    def disagreeing(self) -> list[int]:
        """Touches that disagree: several suspects, of which the data cannot tell the wrong one."""
        return list(self.suspects) if len(self.suspects) > 1 else []

    @property
    def outliers(self) -> list[int]:
        """Touches used by the fit whose residual is an outlier at 3 sigma.

        None when touches disagree: one of them explains every residual's excess, so the
        others flagged with it are not wrong themselves (their residuals carry its error).
        """
        if self.disagreeing:
            return []
        bad = np.flatnonzero(self.pvalues < OUTLIER_P)
        return [int(i) for i in bad if i not in self.excluded]


def scaled_condition(J: NDArray[np.float64]) -> float:
    """Condition number of ``J`` after scaling every column to unit length.

    Parameters
    ----------
    J : ndarray, shape (m, p)

    Returns
    -------
    float
        ``s_max / s_min`` of the column-scaled matrix; infinity when a column is zero or the
        matrix is rank deficient. Scaling makes the figure independent of the units chosen for
        each parameter (metres vs radians).
    """
    norms = np.linalg.norm(J, axis=0)
    if np.any(norms == 0.0):
        return float("inf")
    s = np.linalg.svd(J / norms, compute_uv=False)
    return float(s[0] / s[-1]) if s[-1] > 0 else float("inf")


def chi2_bound(dof: int, probability: float = CHI2_P) -> float:
    """The ``probability`` quantile of chi-square with ``dof`` degrees of freedom."""
    return float(chdtri(dof, 1.0 - probability))


@dataclass
class _Solved:
    """One least-squares solution with its linearisation (internal to :func:`fit`)."""

    x: NDArray[np.float64]
    r: NDArray[np.float64]          # (N, 3) projected residuals (prediction residual if left out)
    J: NDArray[np.float64]          # (3N, p) projected, rows of left-out touches zero
    Jv: NDArray[np.float64]         # (3N, k) projected input Jacobian, rows left out zero
    P: NDArray[np.float64]          # (N, 3, 3)
    used: NDArray[np.bool_]
    C0: NDArray[np.float64]         # (J^T J)^-1
    condition: float
    dof: int
    chi2: float | None
    pvalues: NDArray[np.float64]
    expected: NDArray[np.float64]
    q: NDArray[np.float64]          # statistic / sigma^2 per touch
    k: NDArray[np.int_]
    unchecked: NDArray[np.bool_]
    suspects: list[int]


def _suspects(chi2: float | None, dof: int, pvalues, q, k, used) -> list[int]:
    """Flagged touches each of which alone explains the residuals' excess.

    When the residuals fail the chi-square check against the touch accuracy: without touch i
    the chi-square drops by its leave-one-out statistic ``q_i`` (the deletion formula of least
    squares, exact for a linear model), over ``dof - k_i`` degrees of freedom, and the touch is
    a suspect when the others then pass. One suspect is the bad touch; several are touches that
    disagree, and the others cannot tell which is wrong (the two touches of one point). Residuals
    that pass the check have no suspect: a touch flagged among many good ones is an outlier at
    the 3-sigma rate, not a gross error.
    """
    if chi2 is None or chi2 <= chi2_bound(dof):
        return []
    out = []
    for i in np.flatnonzero(used & (pvalues < OUTLIER_P)):
        rest = dof - int(k[i])
        if rest > 0 and chi2 - q[i] <= chi2_bound(rest):
            out.append(int(i))
    return out


def fit(
    fun: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    x0: ArrayLike,
    names: Sequence[str],
    sigma: float | None = None,
    advice: str = "take touches that differ in position and orientation in more directions",
    *,
    measured: Callable[[NDArray[np.float64]], NDArray[np.float64]] | None = None,
    inputs: Inputs | None = None,
    robust: bool = True,
) -> Fit:
    """Maximum-likelihood fit of a point model, robust to one gross error.

    The uncertainty rests on the touch accuracy ``s``: ``sigma``, or
    :data:`DEFAULT_TOUCH_SIGMA` when none is stated. The residuals are a check against it
    (chi-square with the redundancy as degrees of freedom, inputs' errors included); only when
    they fail that check at the verdict's level (:data:`~robotcell.calibration.verdict.CHI2_P`)
    is the larger noise they need used instead. Each touch is tested with its leave-one-out
    residual (:func:`touch_statistics`). When the residuals fail the chi-square check and one
    flagged touch alone explains it (the only suspect), the fit is repeated without it, and it
    stays out when the others then pass the check, single it out and still determine the result;
    several suspects are touches that disagree, and none is left out.

    Parameters
    ----------
    fun : callable
        ``fun(x) -> residuals`` of shape ``(N, 3)``: measured points minus model points (metres)
        for parameters ``x`` (shape (p,), SI), one row per touch.
    x0 : array_like, shape (p,)
        Starting point (e.g. from a linear solution).
    names : sequence of str
        Name of each parameter, used in the error raised when the data do not determine them.
    sigma : float, optional
        Stated touch accuracy (metres per coordinate); default :data:`DEFAULT_TOUCH_SIGMA`.
    advice : str
        What to measure instead, ending the error raised when the data do not determine the
        parameters.
    measured : callable, optional
        ``measured(x) -> P`` of shape (N, 3, 3): for each touch the orthogonal projector on the
        directions it measures, when the model has eliminated a touch's free coordinates (a
        point anywhere on a line measures the 2 directions across it). ``fun`` must return
        residuals in those directions. Default: every touch measures 3 directions.
    inputs : Inputs, optional
        Earlier calibrations the touches rest on: ``inputs.sensitivity`` is the derivative of
        each residual (as ``fun`` returns it) with respect to the input parameters.
    robust : bool
        Leave out the one touch that explains a failed chi-square check (default).

    Returns
    -------
    Fit

    Raises
    ------
    IllPosedError
        When the Jacobian at the optimum is (numerically) rank deficient: the measurements do not
        determine some combination of the parameters, named in the message.
    InputError
        A touch accuracy that is not a positive number.
    """
    x0 = np.asarray(x0, dtype=float)
    if sigma is not None and not (np.isfinite(sigma) and sigma > 0):
        raise InputError(f"the measurement sigma must be a positive number, got {sigma}")
    s = float(sigma) if sigma is not None else DEFAULT_TOUCH_SIGMA
    n = len(np.asarray(fun(x0), dtype=float).reshape(-1, 3))
    if inputs is not None and len(inputs.sensitivity) != n:
        raise InputError(f"the inputs give {len(inputs.sensitivity)} touches, the model {n}")
    factor = (inputs.sources.matrix()[0] if inputs is not None else np.zeros((0, 0)))
    used = np.ones(n, dtype=bool)
    sol = _solve(fun, x0, used, measured, inputs, factor, s)
    if sol.condition > SINGULAR_CONDITION:
        norms = np.linalg.norm(sol.J, axis=0)
        norms[norms == 0] = 1.0
        _, _, vt = np.linalg.svd(sol.J / norms, full_matrices=False)
        weak = vt[-1]
        order = np.argsort(-np.abs(weak))
        involved = [names[i] for i in order if abs(weak[i]) > 0.2 * abs(weak[order[0]])]
        raise IllPosedError(
            "the measurements do not determine " + ", ".join(involved)
            + f" (their combination is unobservable with these touches); {advice}")
    if robust and len(sol.suspects) == 1:
        worst = sol.suspects[0]
        keep = used.copy()
        keep[worst] = False
        other = _solve(fun, sol.x, keep, measured, inputs, factor, s)
        if keeps_out(other, worst):
            sol = other
    return _finish(sol, s, sigma is not None, inputs)


def keeps_out(result: Fit | _Solved, worst: int) -> bool:
    """Whether a fit without touch ``worst`` is the one to keep.

    It is when the others still determine the result, pass the chi-square check against the
    touch accuracy, and single ``worst`` out as an outlier at 3 sigma. Otherwise the error is
    not one touch's (the accuracy stated is too small, or several touches are wrong), and every
    touch is kept.
    """
    return bool(result.condition <= SINGULAR_CONDITION and result.dof > 0
                and result.chi2 is not None and result.chi2 <= chi2_bound(result.dof)
                and result.pvalues[worst] < OUTLIER_P)


def solution_fit(x: ArrayLike, J: ArrayLike, r: ArrayLike, *, used: ArrayLike | None = None,
                 sigma: float | None = None, inputs: Inputs | None = None) -> Fit:
    """The :class:`Fit` of a least-squares solution found elsewhere (its uncertainty and tests).

    For an estimator with its own solver (the identification engine): the same noise level,
    covariance with the inputs' share, chi-square and leave-one-out tests as :func:`fit`.

    Parameters
    ----------
    x : array_like, shape (p,)
        The solution.
    J : array_like, shape (N, 3, p)
        Derivative of each touch's residual (measured minus model, m) at ``x``.
    r : array_like, shape (N, 3)
        Residuals at ``x`` (m); for a touch left out, its residual against the others' fit.
    used : array_like of bool, shape (N,), optional
        Touches the solution was fitted to (default all).
    sigma : float, optional
        Stated touch accuracy (m); default :data:`DEFAULT_TOUCH_SIGMA`.
    inputs : Inputs, optional
        Earlier calibrations the touches rest on (derivative of each residual).

    Returns
    -------
    Fit
    """
    J = np.asarray(J, dtype=float)
    n = len(J)
    used = np.ones(n, dtype=bool) if used is None else np.asarray(used, dtype=bool)
    s = float(sigma) if sigma is not None else DEFAULT_TOUCH_SIGMA
    factor = inputs.sources.matrix()[0] if inputs is not None else np.zeros((0, 0))
    sol = _analyse(np.asarray(x, dtype=float), J, np.asarray(r, dtype=float),
                   np.broadcast_to(np.eye(3), (n, 3, 3)), used, inputs, factor, s)
    return _finish(sol, s, sigma is not None, inputs)


def _solve(fun, x0, used, measured, inputs, factor, s) -> _Solved:
    """Least squares over the touches ``used``; linearisation and touch tests at the optimum."""
    w = used.astype(float)

    def flat(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return (np.asarray(fun(x), dtype=float).reshape(-1, 3) * w[:, None]).ravel()

    x = least_squares(flat, x0, method="lm", x_scale="jac", xtol=1e-14, ftol=1e-14,
                      gtol=1e-14).x
    n = len(used)
    J = jacobian(lambda v: np.asarray(fun(v), dtype=float).reshape(-1, 3), x).reshape(n, 3, -1)
    r = np.asarray(fun(x), dtype=float).reshape(-1, 3)
    P = np.broadcast_to(np.eye(3), (n, 3, 3)) if measured is None else measured(x)
    return _analyse(x, J, r, P, used, inputs, factor, s)


def _analyse(x, J, r, P, used, inputs, factor, s) -> _Solved:
    """Linearisation and touch tests of a solution (J (N, 3, p), r (N, 3), projectors P)."""
    n = len(used)
    w = used.astype(float)
    J = np.einsum("nij,njp->nip", P, J)
    r = np.einsum("nij,nj->ni", P, r)
    Jv = (np.zeros((n, 3, 0)) if inputs is None
          else np.einsum("nij,njk->nik", P, inputs.sensitivity))
    Ju = (J * w[:, None, None]).reshape(3 * n, -1)
    cond = scaled_condition(Ju)
    p = Ju.shape[1]
    rank = np.rint(np.trace(P, axis1=1, axis2=2)).astype(int)
    dof = int(rank[used].sum()) - p
    if cond > SINGULAR_CONDITION:
        nan = np.full(n, np.nan)
        return _Solved(x, r, Ju, Jv.reshape(3 * n, -1) * np.repeat(w, 3)[:, None], P, used,
                       np.full((p, p), np.nan), cond, dof, None, nan, nan, nan,
                       np.zeros(n, dtype=int), np.zeros(n, dtype=bool), [])
    C0 = np.linalg.inv(Ju.T @ Ju)
    Jvu = Jv.reshape(3 * n, -1) * np.repeat(w, 3)[:, None]
    B = Jvu @ factor if factor.size else np.zeros((3 * n, 0))
    V = B - Ju @ (C0 @ (Ju.T @ B))
    ru = r * w[:, None]
    chi2 = None
    if dof > 0:
        Vr = V.T @ ru.ravel()
        ssr = float(np.sum(ru**2))
        chi2 = float(ssr - Vr @ np.linalg.solve(s**2 * np.eye(V.shape[1]) + V.T @ V, Vr)) / s**2
    stats = touch_statistics(Ju, ru, s, measured=P, input_factor=V)
    pvalues, expected, q, k, unchecked = stats
    for i in np.flatnonzero(~used):  # the touch left out, against the fit of the others
        Ji = J[i]
        Wi = (Jv[i] - Ji @ (C0 @ (Ju.T @ Jvu))) @ factor if factor.size else np.zeros((3, 0))
        cov = P[i] + Ji @ C0 @ Ji.T + Wi @ Wi.T / s**2
        p_i, e_i, q_i, k_i = _block_test(cov[None], r[i][None], s)
        pvalues[i], expected[i], q[i], k[i] = p_i[0], e_i[0], q_i[0], k_i[0]
        unchecked[i] = False
    suspects = _suspects(chi2, dof, pvalues, q, k, used)
    return _Solved(x, r, Ju, Jvu, P, used, C0, cond, dof, chi2, pvalues, expected, q, k, unchecked,
                   suspects)


def _finish(sol: _Solved, s: float, stated: bool, inputs: Inputs | None) -> Fit:
    """The :class:`Fit` of a solution: noise level, covariance with the inputs' share."""
    source = "prior" if stated else "default"
    touch, residual_sigma = s, float("nan")
    if sol.chi2 is not None:
        residual_sigma = s * math.sqrt(max(sol.chi2, 0.0) / sol.dof)
        if sol.chi2 > chi2_bound(sol.dof):
            s, source = residual_sigma, "residuals"
    own = s**2 * sol.C0
    k = 0 if inputs is None else inputs.size
    G = -sol.C0 @ (sol.J.T @ sol.Jv) if k else np.zeros((len(sol.x), 0))
    sources = Sources(len(sol.x), {OWN: factor_of(own)})
    if inputs is not None:
        sources = sources + inputs.sources.map(G)
    cov = sources.covariance
    JtJv = sol.J.T @ sol.Jv
    info = sol.Jv.T @ sol.Jv - JtJv.T @ sol.C0 @ JtJv
    gross_p = chdtrc(sol.k, sol.q / POOR_FACTOR**2)
    return Fit(
        x=sol.x, residuals=sol.r, jacobian=sol.J, measured=np.array(sol.P), covariance=cov,
        sigma=np.sqrt(np.abs(np.diag(cov))), noise_sigma=float(s), noise_source=source,
        touch_sigma=touch, accuracy_source="stated" if stated else "default",
        residual_sigma=residual_sigma, chi2=sol.chi2, dof=sol.dof, condition=sol.condition,
        pvalues=sol.pvalues, expected=sol.expected,
        excluded=[int(i) for i in np.flatnonzero(~sol.used)], suspects=list(sol.suspects),
        unchecked=[int(i) for i in np.flatnonzero(sol.unchecked)],
        gross=[int(i) for i in np.flatnonzero((sol.pvalues < OUTLIER_P) & (gross_p < OUTLIER_P))],
        sources=sources, input_gain=G, input_information=info,
        input_score=sol.Jv.T @ sol.r.ravel(), own_covariance=own,
    )


def _block_test(cov: NDArray[np.float64], r: NDArray[np.float64], s: float):
    """Chi-square test of residual blocks ``r`` (..., N, 3) with covariance ``s^2 cov`` (N, 3, 3).

    Returns the p-value, the expected length ``s sqrt(tr cov)``, the statistic ``q / s^2`` and
    the number of directions tested, per block.
    """
    lam, vec = np.linalg.eigh(cov)
    keep = lam > 1e-9
    k = keep.sum(axis=-1)
    inv = np.where(keep, 1.0 / np.where(keep, lam, 1.0), 0.0)
    proj = np.einsum("nji,...nj->...ni", vec, r)
    # A touch metres away from the others has an infinite statistic (p = 0: an outlier); its
    # overflow is that result, not a failure.
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        q = np.einsum("...ni,ni->...n", proj**2, inv) / s**2
        pval = np.where(k > 0, chdtrc(k, q), np.nan)
    expected = s * np.sqrt(np.maximum(np.trace(cov, axis1=-2, axis2=-1), 0.0))
    return pval, np.broadcast_to(expected, pval.shape).copy(), q, k


def touch_statistics(J: NDArray[np.float64], residuals: ArrayLike, sigma: float, *,
                     measured: NDArray[np.float64] | None = None,
                     input_factor: NDArray[np.float64] | None = None):
    """Leave-one-out test of every measured point: the probability of a residual this large.

    The residual of point i has covariance ``s^2 M_i`` with ``M_i = P_i - P_i H_ii P_i``,
    ``H = J (J^T J)^-1 J^T`` the hat matrix (its 3x3 diagonal block: the touch's leverage) and
    ``P_i`` the projector on the directions the touch measures; inputs' errors add
    ``V_i V_i^T`` (``V = (I - H) Jv L``, ``L L^T`` their covariance). The statistic
    ``q_i = r_i^T (s^2 M_i + V_i V_i^T)^+ r_i`` over the ``k_i`` directions in which that
    covariance is not zero is chi-square with ``k_i`` degrees of freedom for a good touch: for a
    linear model, ``(I - H_ii)^-1 r_i`` is the residual of the touch against the fit of all the
    others (the leave-one-out residual), so the test needs no refit. A direction fully absorbed
    by the fit (the touch alone decides it) cannot show an error: the touch is then unchecked
    in it. Cost: one thin QR of ``J``, linear in the number of touches; no N x N matrix.

    Parameters
    ----------
    J : ndarray, shape (3N, p)
        Jacobian of the flattened residuals at the optimum (projected on ``measured``); rows of
        touches left out of the fit are zero.
    residuals : array_like, shape (..., N, 3)
        Residuals (metres); a leading batch shape is allowed (the same design, several data sets).
    sigma : float
        Touch accuracy (metres per coordinate).
    measured : ndarray, shape (N, 3, 3), optional
        Projector on the directions each touch measures (default the identity).
    input_factor : ndarray, shape (3N, m), optional
        ``V = (I - H) Jv L``: how the inputs' errors show in the residuals.

    Returns
    -------
    p : ndarray, shape (..., N)
        Probability of a statistic at least this large for a good touch; NaN where the touch
        cannot be tested.
    expected : ndarray, shape (..., N)
        Expected residual length ``sqrt(tr cov_i)`` (metres).
    q : ndarray, shape (..., N)
        The statistic divided by ``sigma^2``.
    k : ndarray, shape (N,)
        Directions tested per touch.
    unchecked : ndarray of bool, shape (N,)
        Touches with a measured direction that the fit absorbs completely.
    """
    r = np.asarray(residuals, dtype=float)
    n = r.shape[-2]
    P = np.broadcast_to(np.eye(3), (n, 3, 3)) if measured is None else measured
    Q, R = np.linalg.qr(J)
    d = np.abs(np.diag(R))
    Q = Q[:, d > d.max() * 1e-12] if d.size and d.max() > 0 else Q[:, :0]
    Ub = np.einsum("nij,njp->nip", P, Q.reshape(n, 3, -1))
    M = P - np.einsum("nip,njp->nij", Ub, Ub)
    if input_factor is not None and input_factor.size:
        Vb = input_factor.reshape(n, 3, -1) / sigma
        cov = M + np.einsum("nim,njm->nij", Vb, Vb)
    else:
        cov = M
    pval, expected, q, k = _block_test(cov, r, sigma)
    measures = np.rint(np.trace(P, axis1=1, axis2=2)).astype(int)
    absorbed = (np.linalg.eigvalsh(M) > LEVERAGE_ONE).sum(axis=-1) < measures
    used = np.any(J.reshape(n, -1) != 0, axis=1)
    return pval, expected, q, k, absorbed & used


def outlier_warnings(result: Fit, labels: Sequence[str]) -> list[str]:
    """Warnings for measured points whose residual is an outlier at 3 sigma.

    Each residual is tested against its own variance (:func:`touch_statistics`: the touch's
    leverage, the touch accuracy and the inputs' errors) and flagged when a residual at least
    this large has a probability below ``1 - 0.9973`` on good data: the false-alarm rate per
    touch is the 3-sigma rate, 0.27 %. A touch left out of the fit says so; touches that
    disagree (one of them is wrong, and the others cannot tell which) are named together.

    Parameters
    ----------
    result : Fit
    labels : sequence of str
        Name of each measured point (length N), e.g. ``"row 4"``.

    Returns
    -------
    list of str
        One warning per outlier, naming the touch and what to do.
    """
    norms = np.linalg.norm(result.residuals, axis=1)
    out = []
    for i in result.excluded:
        out.append(f"touch {labels[i]} is an outlier at 3 sigma: residual {norms[i] * 1e3:.3f} mm "
                   f"against the other touches, expected about {result.expected[i] * 1e3:.3f} mm; "
                   "it is left out of this result: re-touch it")
    for i in result.outliers:
        out.append(f"touch {labels[i]} is an outlier at 3 sigma: residual {norms[i] * 1e3:.3f} "
                   f"mm, expected about {result.expected[i] * 1e3:.3f} mm; re-touch it or remove it")
    if result.disagreeing:
        names = ", ".join(labels[i] for i in result.disagreeing)
        out.append(f"touches {names} disagree (residuals up to "
                   f"{norms[result.disagreeing].max() * 1e3:.3f} mm): one of them is an outlier, "
                   "and the other touches cannot tell which; re-touch them")
    return out


def perturb_rotation(R0: ArrayLike, d: ArrayLike) -> NDArray[np.float64]:
    """Rotate a nominal rotation by a small rotation vector: ``exp([d]x) R0``.

    Parameters
    ----------
    R0 : array_like, shape (3, 3)
        Nominal rotation (proper).
    d : array_like, shape (3,)
        Rotation vector (radians), about the axes of the frame ``R0`` is expressed in.

    Returns
    -------
    ndarray, shape (3, 3)
        A proper rotation.
    """
    return Rotation.from_rotvec(np.asarray(d, dtype=float)).as_matrix() @ np.asarray(R0, dtype=float)


def perturb_pose(T0: ArrayLike, x: ArrayLike) -> NDArray[np.float64]:
    """Pose from 6 parameters about a nominal pose.

    Parameters
    ----------
    T0 : array_like, shape (4, 4)
        Nominal pose ``T_a_b`` (metres).
    x : array_like, shape (6,)
        ``(p_x, p_y, p_z, d_x, d_y, d_z)``: the origin of b in a (metres, absolute, not a
        correction) and a rotation vector ``d`` (radians) applied as ``exp([d]x) R0``.

    Returns
    -------
    ndarray, shape (4, 4)
    """
    x = np.asarray(x, dtype=float)
    T = np.eye(4)
    T[:3, :3] = perturb_rotation(np.asarray(T0, dtype=float)[:3, :3], x[3:6])
    T[:3, 3] = x[:3]
    return T


def pose_sigma(cov6: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Split the covariance of :func:`perturb_pose` parameters into position and rotation sigma.

    Parameters
    ----------
    cov6 : array_like, shape (6, 6)

    Returns
    -------
    position : ndarray, shape (3,)
        1-sigma of the origin (metres).
    rotation : ndarray, shape (3,)
        1-sigma of the rotation vector (radians).
    """
    d = np.sqrt(np.abs(np.diag(np.asarray(cov6, dtype=float))))
    return d[:3], d[3:6]


def nearest_rotation(M: ArrayLike) -> NDArray[np.float64]:
    """The proper rotation closest to ``M`` in the Frobenius norm (SVD with determinant fix).

    Parameters
    ----------
    M : array_like, shape (3, 3)

    Returns
    -------
    ndarray, shape (3, 3)
    """
    U, _, Vt = np.linalg.svd(np.asarray(M, dtype=float))
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(U @ Vt)) or 1.0])
    return U @ D @ Vt


def kabsch(p_b: ArrayLike, p_a: ArrayLike) -> NDArray[np.float64]:
    """Least-squares rigid transform mapping points of frame b onto points of frame a.

    Kabsch/Umeyama without scale: minimises ``sum |p_a_i - (R p_b_i + t)|^2`` over proper
    rotations R, which is the maximum-likelihood estimate when the ``p_a`` are measured with
    isotropic Gaussian noise and the ``p_b`` are exact.

    Parameters
    ----------
    p_b : array_like, shape (N, 3)
        Points in frame b (metres), N >= 3 and not collinear.
    p_a : array_like, shape (N, 3)
        The same points measured in frame a (metres).

    Returns
    -------
    ndarray, shape (4, 4)
        ``T_a_b``.
    """
    pb = np.asarray(p_b, dtype=float)
    pa = np.asarray(p_a, dtype=float)
    cb, ca = pb.mean(axis=0), pa.mean(axis=0)
    R = nearest_rotation((pa - ca).T @ (pb - cb))
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = ca - R @ cb
    return T
