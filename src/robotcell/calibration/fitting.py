"""Numerics shared by the calibration procedures: maximum-likelihood fit, covariance, outliers.

Every procedure models measured 3-D points (metres) as a function of its parameters plus
independent isotropic Gaussian noise of standard deviation ``s`` per coordinate. The maximum
likelihood estimate minimises the sum of squared residuals; :func:`fit` computes it with
:func:`scipy.optimize.least_squares` and returns the linearised covariance
``s^2 (J^T J)^-1``. Rotations are parameterised as a small rotation vector about a nominal
rotation (:func:`perturb_rotation`), so that an estimate is always a proper rotation.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation
from scipy.special import chdtri

from robotcell.errors import IllPosedError, InputError

__all__ = [
    "Fit",
    "fit",
    "kabsch",
    "nearest_rotation",
    "outlier_warnings",
    "perturb_pose",
    "perturb_rotation",
    "pose_sigma",
]

#: Probability inside "3 sigma" for a 1-D Gaussian; used for the 3-D residual test.
THREE_SIGMA_P = 0.9973

#: Scaled-Jacobian condition number above which the parameters count as not determined.
SINGULAR_CONDITION = 1e10


@dataclass
class Fit:
    """Solution of a maximum-likelihood point fit.

    Attributes
    ----------
    x : ndarray, shape (p,)
        Parameters at the optimum (SI).
    residuals : ndarray, shape (N, 3)
        Measured minus model per measured point (metres).
    jacobian : ndarray, shape (3N, p)
        Jacobian of the flattened residuals at the optimum.
    covariance : ndarray, shape (p, p)
        ``s^2 (J^T J)^-1``; NaN when ``noise_source == "none"``.
    sigma : ndarray, shape (p,)
        Square roots of the diagonal of ``covariance``.
    noise_sigma : float
        ``s`` (metres per coordinate): ``sqrt(SSR / dof)`` or the prior.
    noise_source : {"residuals", "prior", "none"}
    dof : int
        ``3N - p``.
    condition : float
        Condition number of ``J`` with each column scaled to unit 2-norm.
    """

    x: NDArray[np.float64]
    residuals: NDArray[np.float64]
    jacobian: NDArray[np.float64]
    covariance: NDArray[np.float64]
    sigma: NDArray[np.float64]
    noise_sigma: float
    noise_source: str
    dof: int
    condition: float


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


def fit(
    fun: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    x0: ArrayLike,
    names: Sequence[str],
    prior_sigma: float | None = None,
) -> Fit:
    """Maximum-likelihood fit of a point model.

    Parameters
    ----------
    fun : callable
        ``fun(x) -> residuals`` of shape ``(N, 3)`` or ``(3N,)``: measured points minus model
        points (metres) for parameters ``x`` (shape (p,), SI).
    x0 : array_like, shape (p,)
        Starting point (e.g. from a linear solution).
    names : sequence of str
        Name of each parameter, used in the error raised when the data do not determine them.
    prior_sigma : float, optional
        Known measurement noise (metres per coordinate). When given it is used for the
        covariance; otherwise ``s^2 = SSR / dof`` is used, which needs ``dof > 0``.

    Returns
    -------
    Fit

    Raises
    ------
    IllPosedError
        When the Jacobian at the optimum is (numerically) rank deficient: the measurements do not
        determine some combination of the parameters, named in the message.
    """
    x0 = np.asarray(x0, dtype=float)
    if prior_sigma is not None and not (np.isfinite(prior_sigma) and prior_sigma > 0):
        raise InputError(f"the measurement sigma must be a positive number, got {prior_sigma}")

    def flat(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.asarray(fun(x), dtype=float).ravel()

    sol = least_squares(flat, x0, method="lm", x_scale="jac", xtol=1e-14, ftol=1e-14, gtol=1e-14)
    J = sol.jac
    r = sol.fun
    m, p = J.shape
    cond = scaled_condition(J)
    if cond > SINGULAR_CONDITION:
        norms = np.linalg.norm(J, axis=0)
        norms[norms == 0] = 1.0
        _, _, vt = np.linalg.svd(J / norms)
        weak = vt[-1]
        order = np.argsort(-np.abs(weak))
        involved = [names[i] for i in order if abs(weak[i]) > 0.2 * abs(weak[order[0]])]
        raise IllPosedError(
            "the measurements do not determine " + ", ".join(involved)
            + " (their combination is unobservable with these touches); "
            "take touches that differ in position and orientation in more directions"
        )
    dof = m - p
    if prior_sigma is not None:
        s, source = float(prior_sigma), "prior"
    elif dof > 0:
        s, source = float(np.sqrt(r @ r / dof)), "residuals"
    else:
        s, source = float("nan"), "none"
    cov = s**2 * np.linalg.inv(J.T @ J)
    return Fit(x=sol.x, residuals=r.reshape(-1, 3), jacobian=J, covariance=cov,
               sigma=np.sqrt(np.abs(np.diag(cov))), noise_sigma=s, noise_source=source,
               dof=dof, condition=cond)


def outlier_warnings(result: Fit, labels: Sequence[str]) -> list[str]:
    """Warnings for measured points whose residual is an outlier at 3 sigma.

    The squared residual of point i, ``|r_i|^2``, has expectation ``s^2 (3 - tr H_ii)`` where
    ``H = J (J^T J)^-1 J^T`` is the hat matrix; it is tested against the chi-square quantile
    with 3 degrees of freedom at probability 0.9973 (the 3-sigma level). When the noise is
    estimated from the residuals, ``s`` is re-estimated without point i so that an outlier does
    not hide itself.

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
    if result.noise_source == "none":
        return []
    J = result.jacobian
    H = J @ np.linalg.solve(J.T @ J, J.T)
    r = result.residuals
    ssr = float(np.sum(r**2))
    # chi-square quantile from scipy.special: importing scipy.stats would add 0.2 s to every
    # calibration command.
    limit = chdtri(3, 1.0 - THREE_SIGMA_P)
    out = []
    for i, ri in enumerate(r):
        expect = 3.0 - float(np.trace(H[3 * i:3 * i + 3, 3 * i:3 * i + 3]))
        if expect <= 1e-9:
            continue
        e2 = float(ri @ ri)
        if result.noise_source == "prior":
            s2 = result.noise_sigma**2
        else:
            rest = result.dof - expect
            if rest <= 0.5:
                continue
            s2 = max(ssr - e2, 0.0) / rest
            if s2 == 0.0:
                s2 = np.finfo(float).tiny
        if e2 / (s2 * expect) * 3.0 > limit:
            out.append(
                f"touch {labels[i]} is an outlier at 3 sigma: residual {np.sqrt(e2) * 1e3:.3f} mm, "
                f"expected about {np.sqrt(s2 * expect) * 1e3:.3f} mm; re-touch it or remove it"
            )
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
