"""The identification engine: Levenberg-Marquardt on the parameterised chain.

Steps (``docs/identification.md``):

1. **Start.** The nominal model (or the circle point analysis) gives the link constants; the pose
   of the robot base in the device frame and the target positions on the last link come from a
   closed form: alternating rigid fits (Kabsch) and linear least squares for points, the hand-eye
   equation for poses.
2. **Base and targets.** Levenberg-Marquardt with the nominal links: its residual is the nominal
   model's error, ``rms_before``.
3. **Identifiable set.** QR with column pivoting of the weighted identification Jacobian, columns
   scaled to unit length, the base and target constants first (they always stay free). A column
   whose distance to the span of the columns already chosen is below ``rank_tol`` is fixed at its
   nominal value; the parameters it duplicates are named in the reason.
4. **Identification.** Levenberg-Marquardt (``scipy.optimize.least_squares``, MINPACK) over the
   identifiable set with the analytic Jacobian of :class:`~robotcell.identification.chain.Chain`.
   A link constant whose 1-sigma (before the fit at the stated accuracies, after it a
   posteriori) exceeds what a manufacturing error can plausibly be (``max_sigma_length``,
   ``max_sigma_angle``) is held at its nominal value too, the worst first, and named with the
   parameter it trades off against: the measurements see it too weakly to move it.
5. **Uncertainty.** ``cov = s0^2 (J^T J)^-1`` with the weighted Jacobian and the a-posteriori
   variance factor ``s0^2 = chi^2 / dof``; correlations, the scaled condition number, and rows
   whose residual is an outlier at 3 sigma (leave-one-out noise level, hat-matrix leverage).
   The leave-one-out residuals (closed form) give the scatter no parameter explains
   (``unexplained``) and of it the model error beyond the stated accuracy.

Constants named in ``hold`` (:func:`robotcell.identification.identify_validated` holds those
that do not predict held-out rows better) stay at their nominal values with the reason given.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation
from scipy.stats import chi2

from robotcell.calibration.fitting import kabsch, scaled_condition
from robotcell.calibration.grouping import distinct as count_distinct
from robotcell.calibration.grouping import joint_tolerances
from robotcell.errors import IllPosedError, InputError
from robotcell.identification.chain import COMPLIANT_JOINTS, Chain
from robotcell.identification.gravity import require_masses
from robotcell.identification.measurements import TargetMeasurements
from robotcell.identification.options import IdentifyOptions
from robotcell.identification.result import IdentificationResult, Parameter, beyond_accuracy
from robotcell.ik import analytic_solver
from robotcell.ik.seeded import SeededSolver
from robotcell.kinematics.coupling import Coupling
from robotcell.kinematics.covariance import ParameterCovariance
from robotcell.robot.robot import Robot

__all__ = ["Problem", "identifiable", "identify"]

#: Probability inside "3 sigma" for a 1-D Gaussian: the outlier test level.
_THREE_SIGMA_P = 0.9973
#: Parameter name endings that are lengths (the others of a link are angles).
_LENGTHS = ("a", "d", "x", "y", "z")


class Problem:
    """Weighted residuals and analytic Jacobian of one measurement set over a free subset."""

    def __init__(self, chain: Chain, meas: TargetMeasurements, sigma: float, angle_sigma: float):
        self.chain, self.meas = chain, meas
        self.wp, self.wr = 1.0 / sigma, 1.0 / angle_sigma
        self.N, self.K = meas.n_rows, meas.n_targets
        self.pose = meas.rotations is not None
        self.ncomp = 3 * self.K + (3 if self.pose else 0)

    def raw(self, x: NDArray[np.float64]):
        """Unweighted residuals (measured - model): points (N, K, 3) m, rotations (N, 3) rad."""
        pts, R = self.chain.predict(x, self.meas.q)
        rp = self.meas.points - pts
        rr = None
        if self.pose:
            rr = Rotation.from_matrix(self.meas.rotations @ np.swapaxes(R, 1, 2)).as_rotvec()
        return rp, rr

    def weighted(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """Residuals scaled by the accuracies, shape (N, ncomp)."""
        rp, rr = self.raw(x)
        parts = [rp.reshape(self.N, -1) * self.wp]
        if rr is not None:
            parts.append(rr * self.wr)
        return np.concatenate(parts, axis=1)

    def jacobian(self, x: NDArray[np.float64], cols: NDArray[np.int_] | None = None) -> NDArray[np.float64]:
        """``d weighted / d x`` over ``cols``: shape (N * ncomp, len(cols))."""
        ch, q = self.chain, self.meas.q
        ev = ch.evaluate(x, q)
        pts, _ = ch.predict(x, q)
        Jp = -ch.point_jacobian(x, q, ev, pts).reshape(self.N, 3 * self.K, -1) * self.wp
        if self.pose:
            rr = self.raw(x)[1]
            W = ch.rotation_jacobian(x, q, ev)
            Jr = -np.einsum("nij,njp->nip", _right_jacobian_inv(rr), W) * self.wr
            Jp = np.concatenate([Jp, Jr], axis=1)
        J = Jp.reshape(self.N * self.ncomp, -1)
        return J if cols is None else J[:, cols]


def _right_jacobian_inv(e: NDArray[np.float64]) -> NDArray[np.float64]:
    """Inverse right Jacobian of SO(3) at rotation vectors ``e`` (N, 3): ``d log(exp(e) exp(-w)) / dw = -J_r^-1``."""
    th = np.linalg.norm(e, axis=1)
    K = np.zeros((len(e), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -e[:, 2], e[:, 1], -e[:, 0]
    K = K - np.swapaxes(K, 1, 2)
    small = th < 1e-6
    ts = np.where(small, 1.0, th)
    c = np.where(small, 1.0 / 12.0, 1.0 / ts**2 - (1.0 + np.cos(ts)) / (2.0 * ts * np.sin(ts)))
    return np.eye(3) + 0.5 * K + c[:, None, None] * (K @ K)


def _start_base(chain: Chain, meas: TargetMeasurements, x: NDArray[np.float64]):
    """Closed-form ``T_D_R`` and targets (points) or ``T_F_T`` (poses) for the nominal links."""
    ev = chain.evaluate(x, meas.q, jac=False, base=False)
    Rf, pf = ev.R, ev.p  # target frame at tool_start = I, in R
    if meas.rotations is None:
        K = meas.n_targets
        r = np.zeros((K, 3))
        m = meas.points
        for _ in range(30):
            model = pf[:, None, :] + np.einsum("nij,kj->nki", Rf, r)
            T = kabsch(model.reshape(-1, 3), m.reshape(-1, 3))
            loc = np.einsum("ji,nkj->nki", T[:3, :3], m - T[:3, 3]) - pf[:, None, :]
            r_new = np.einsum("nji,nkj->nki", Rf, loc).mean(axis=0)
            if np.abs(r_new - r).max() < 1e-10:
                r = r_new
                break
            r = r_new
        model = pf[:, None, :] + np.einsum("nij,kj->nki", Rf, r)
        return kabsch(model.reshape(-1, 3), m.reshape(-1, 3)), r, np.eye(4)
    # Hand-eye: M_i = B F_i X. Rotation of X from the rotation axes of relative motions.
    Rm, pm = meas.rotations, meas.points[:, 0, :]
    n = meas.n_rows  # pairs of rows a step and half the set apart: O(N), not O(N^2)
    i = np.concatenate([np.arange(n - 1), np.arange(n)])
    j = np.concatenate([np.arange(1, n), (np.arange(n) + max(n // 2, 1)) % n])
    a = Rotation.from_matrix(np.swapaxes(Rf[i], 1, 2) @ Rf[j]).as_rotvec()
    b = Rotation.from_matrix(np.swapaxes(Rm[i], 1, 2) @ Rm[j]).as_rotvec()
    keep = (np.linalg.norm(a, axis=1) > 0.05) & (np.linalg.norm(a, axis=1) < 3.0)
    if np.count_nonzero(keep) < 2:
        raise IllPosedError("the measured orientations hardly change between rows; move the "
                            "joints so that the target turns by several degrees about different axes")
    Rx = Rotation.align_vectors(a[keep], b[keep])[0].as_matrix()
    Rb = Rotation.from_matrix(Rm @ Rx.T @ np.swapaxes(Rf, 1, 2)).mean().as_matrix()
    # p_m = Rb (Rf p_x + p_f) + p_b: linear in (p_b, p_x).
    A = np.concatenate([np.broadcast_to(np.eye(3), (meas.n_rows, 3, 3)), Rb @ Rf], axis=2).reshape(-1, 6)
    rhs = (pm - pf @ Rb.T).reshape(-1)
    sol = np.linalg.lstsq(A, rhs, rcond=None)[0]
    B, X = np.eye(4), np.eye(4)
    B[:3, :3], B[:3, 3] = Rb, sol[:3]
    X[:3, :3], X[:3, 3] = Rx, sol[3:]
    return B, np.zeros((0, 3)), X


def _solve(prob: Problem, x0: NDArray[np.float64], free: NDArray[np.int_]) -> NDArray[np.float64]:
    """Levenberg-Marquardt over the parameters ``free``; returns the full vector."""
    x = x0.copy()

    def full(v):
        x[free] = v
        return x

    def fun(v):
        return prob.weighted(full(v)).ravel()

    def jac(v):
        return prob.jacobian(full(v), free)

    if prob.N * prob.ncomp < free.size:
        raise IllPosedError(f"{prob.N} rows give {prob.N * prob.ncomp} measured coordinates for "
                            f"{free.size} unknowns; measure more configurations")
    sol = least_squares(fun, x0[free], jac=jac, method="lm", x_scale="jac",
                        xtol=1e-12, ftol=1e-12, gtol=1e-12)
    out = x0.copy()
    out[free] = sol.x
    return out


def _pivoted_qr(A: NDArray[np.float64], Q: NDArray[np.float64], tol: float,
                ) -> tuple[list[int], NDArray[np.float64]]:
    """QR with column pivoting (Businger and Golub) of ``A`` after the orthonormal columns ``Q``.

    Each step takes the column with the largest norm orthogonal to the span so far; among
    columns within 1e-6 of that norm (duplicates, such as the two ``d`` of a parallel pair) the
    first in order, so that the choice does not depend on rounding. Stops when no remaining
    column is longer than ``tol`` (columns of unit length).

    Returns
    -------
    chosen : list of int
        Indices of the kept columns of ``A``, in pivot order.
    Q : ndarray
        ``Q`` extended by the new orthonormal directions.
    """
    R = A - Q @ (Q.T @ A)
    chosen: list[int] = []
    for _ in range(A.shape[1]):
        n = np.linalg.norm(R, axis=0)
        n[chosen] = -1.0
        if n.max() <= tol:
            break
        k = int(np.flatnonzero(n >= n.max() * (1.0 - 1e-6))[0])
        chosen.append(k)
        v = R[:, k] / n[k]
        v -= Q @ (Q.T @ v)  # re-orthogonalise against rounding
        v /= np.linalg.norm(v)
        Q = np.concatenate([Q, v[:, None]], axis=1)
        R = R - np.outer(v, v @ R)
    return chosen, Q


def identifiable(J: NDArray[np.float64], cand: Sequence[int], prio: Sequence[int],
                 names: Sequence[str], tol: float):
    """Split ``cand`` into kept and fixed columns; a reason for every fixed one.

    Parameters
    ----------
    J : ndarray, shape (M, P)
        Weighted Jacobian of the residuals over every parameter (unitless).
    cand : sequence of int
        Columns that may be identified.
    prio : sequence of int
        Columns kept first when two cannot be told apart.
    names : sequence of str, length P
        Parameter names, for the reasons.
    tol : float
        Relative tolerance of the rank decision.

    Returns
    -------
    kept : ndarray of int
        The columns identified, sorted.
    fixed : dict of int to str
        Each fixed column with why it is fixed.
    """
    norms = np.linalg.norm(J, axis=0)
    fixed: dict[int, str] = {}
    live = [c for c in cand if norms[c] > 0]
    for c in cand:
        if norms[c] == 0:
            fixed[c] = "has no effect on these measurements"
    Jn = J / np.where(norms > 0, norms, 1.0)
    kept: list[int] = []
    Q = np.zeros((J.shape[0], 0))
    for group in ([c for c in live if c in prio], [c for c in live if c not in prio]):
        chosen, Q = _pivoted_qr(Jn[:, group], Q, tol)
        kept += [group[k] for k in chosen]
        fixed.update({c: "" for k, c in enumerate(group) if k not in chosen})
    for c, why in list(fixed.items()):
        if why:
            continue
        coef = np.linalg.lstsq(Jn[:, kept], Jn[:, c], rcond=None)[0]
        top = np.argsort(-np.abs(coef))
        big = [kept[k] for k in top[:3] if abs(coef[k]) > 0.2 * abs(coef[top[0]])]
        who = ", ".join(names[k] for k in big)
        if all(names[k].startswith("base.") for k in big):
            why = f"absorbed by the pose of the robot base in the device frame ({who})"
        elif all(names[k].startswith("target") for k in big):
            why = f"absorbed by the target's place on the last link ({who})"
        else:
            why = f"same effect as a combination of {who}: the measurements cannot separate them"
        fixed[c] = why
    return np.array(sorted(kept), dtype=int), fixed


def _sigmas(J: NDArray[np.float64], factor: float = 1.0) -> tuple[NDArray[np.float64],
                                                                  NDArray[np.float64]]:
    """1-sigma of each column's parameter and the covariance, ``factor^2 (J^T J)^-1``."""
    _, S, Vt = np.linalg.svd(J, full_matrices=False)
    cov = (Vt.T / np.maximum(S, S[0] * 1e-15) ** 2) @ Vt * factor**2
    return np.sqrt(np.abs(np.diag(cov))), cov


def _too_uncertain(J: NDArray[np.float64], kept: Sequence[int], bound: NDArray[np.float64],
                   names: Sequence[str], factor: float = 1.0) -> tuple[list[int], dict[int, str]]:
    """Hold the parameters whose 1-sigma exceeds ``bound``, the worst (relative) first.

    ``J`` is the weighted Jacobian over all parameters, ``factor`` the variance factor's square
    root to apply (1 before the fit). Returns the parameters still free and a reason per held one.
    """
    kept, held = list(kept), {}
    while True:
        sig, cov = _sigmas(J[:, kept], factor)
        ratio = sig / bound[kept]
        w = int(np.argmax(ratio))
        if ratio[w] <= 1.0:
            return kept, held
        corr = np.abs(cov[w] / (sig[w] * sig))
        corr[w] = -1.0
        c = kept[int(np.argmax(corr))]
        length = names[kept[w]].split(".")[-1] in _LENGTHS
        scale, unit = (1e3, "mm") if length else (180.0 / math.pi, "deg")
        held[kept[w]] = (
            f"not determined by these measurements: 1-sigma {sig[w] * scale:.3g} {unit}, more than "
            f"the {bound[kept[w]] * scale:.3g} {unit} a link constant can plausibly be off "
            f"(it trades off against {names[c]}, correlation {corr.max():.2f}); held at its "
            "nominal value (measure configurations or targets that move it, e.g. targets away "
            "from the last axis)")
        kept.pop(w)


def identify(
    nominal: Robot,
    measurements: TargetMeasurements,
    *,
    name: str | None = None,
    hold: Mapping[str, str] | None = None,
    options: IdentifyOptions | None = None,
    **keywords: Any,
) -> IdentificationResult:
    """Identify the kinematic parameters of a serial chain from measured points or poses.

    Parameters
    ----------
    nominal : Robot
        Start model (library model, model file, or the circle point analysis): its convention,
        joint types, signs, names and limits are kept.
    measurements : TargetMeasurements
        Joint values (rad, m) and measured targets in the device frame (m); with orientations,
        one target per row.
    name : str, optional
        Name of the identified model (default ``<nominal>_identified``).
    hold : mapping of str to str, optional
        Constants to hold at their nominal values (link constants, scales, compliances or the
        J2/J3 factor, by name: ``A2.a``), each with the reason reported in ``fixed``.
    options : IdentifyOptions, optional
        The accuracies (``sigma``, m; ``angle_sigma``, rad) and what may be freed; default
        :class:`~robotcell.identification.options.IdentifyOptions` ().
    **keywords
        Fields of :class:`~robotcell.identification.options.IdentifyOptions` that replace those
        of ``options`` (``sigma=2e-5, scale=True``).

    Returns
    -------
    IdentificationResult

    Raises
    ------
    InputError
        Measurements that do not fit the robot (number of joints), bad accuracies, a nominal
        model whose coupling is not a J2/J3 factor, a held constant the chain does not have.
    IllPosedError
        Too few rows for the unknowns, or orientations that do not change.
    """
    opts = IdentifyOptions.of(options, **keywords)
    coupling = _checked(nominal, measurements, opts)
    pose = measurements.rotations is not None
    chain = Chain(nominal, 0 if pose else measurements.n_targets, pose, np.eye(4), np.eye(4))
    x = chain.values.copy()
    if chain.coupling_param >= 0:
        x[chain.coupling_param] = coupling
    B, r, X = _start_base(chain, measurements, x)
    chain = Chain(nominal, 0 if pose else measurements.n_targets, pose, B, X)
    if not pose:
        x[np.array(chain.target_params).ravel()] = r.ravel()
    prob = Problem(chain, measurements, opts.sigma, opts.angle_sigma)
    groups = np.array(chain.groups)
    prio = np.flatnonzero(np.isin(groups, ("base", "target")))
    x1 = _solve(prob, x, prio)
    rp0, rr0 = prob.raw(x1)

    cand = list(prio) + list(np.flatnonzero(groups == "link"))
    if opts.scale:
        cand += list(np.flatnonzero(groups == "scale"))
    if opts.compliance:
        cand += list(np.flatnonzero(groups == "compliance"))
    if opts.fit_j23_factor and chain.coupling_param >= 0:
        cand.append(chain.coupling_param)
    cand, chosen = _unheld(cand, hold or {}, chain)
    J1 = prob.jacobian(x1)
    kept, fixed = identifiable(J1, cand, set(prio), chain.names, opts.rank_tol)
    fixed.update(chosen)
    m = _measured_coordinates(prob, nominal, opts.group_tol, kept.size)
    length = np.array([nm.split(".")[-1] in _LENGTHS for nm in chain.names])
    bound = np.where(groups == "link",
                     np.where(length, opts.max_sigma_length, opts.max_sigma_angle), np.inf)
    free, held = _too_uncertain(J1, kept, bound, chain.names)  # at the stated accuracies
    while True:
        fixed.update(held)
        x2 = _solve(prob, x1, np.array(sorted(free), dtype=int))
        # a posteriori: the variance factor may show that the stated accuracy was optimistic
        w = prob.weighted(x2)
        s0 = math.sqrt(max(float(np.sum(w**2)) / max(m - len(free), 1), 1.0))
        free, held = _too_uncertain(prob.jacobian(x2), free, bound, chain.names, s0)
        if not held:
            break
    return _result(nominal, chain, prob, x2, np.array(sorted(free), dtype=int), fixed, rp0, rr0,
                   name, x1)


def _checked(nominal: Robot, measurements: TargetMeasurements, opts: IdentifyOptions) -> float:
    """Refuse what :func:`identify` cannot do; the J2/J3 factor to start from."""
    if measurements.q.shape[1] != nominal.n_joints:
        raise InputError(f"the measurements have {measurements.q.shape[1]} joint values per row, "
                         f"{nominal.name} has {nominal.n_joints} joints")
    for label, s in (("sigma", opts.sigma), ("angle_sigma", opts.angle_sigma)):
        if not (math.isfinite(s) and s > 0):
            raise InputError(f"{label} must be a positive number, got {s}")
    for label, s in (("max_sigma_length", opts.max_sigma_length),
                     ("max_sigma_angle", opts.max_sigma_angle)):
        if not s > 0:
            raise InputError(f"{label} must be a positive number (math.inf: no limit), got {s}")
    if nominal.coupling is not None and nominal.coupling.j23_factor is None:
        raise InputError(f"{nominal.name} has a joint coupling other than a J2/J3 factor (passive "
                         "joints or a general matrix); identification handles only "
                         "'coupling: {j23_factor: k}'")
    coupling = opts.j23_factor
    if coupling is None:
        coupling = 0.0 if nominal.coupling is None else nominal.coupling.j23_factor
    if opts.compliance:
        if nominal.n_joints < 3 or any(nominal.joints[j].prismatic for j in COMPLIANT_JOINTS):
            raise InputError("gravity compliance needs revolute axes 2 and 3")
        require_masses(nominal, COMPLIANT_JOINTS)
    if coupling and nominal.n_joints < 3:
        raise InputError("a J2/J3 coupling needs a chain with at least 3 joints")
    return coupling


def _measured_coordinates(prob: Problem, nominal: Robot, group_tol: ArrayLike | None,
                          unknowns: int) -> int:
    """Coordinates measured at distinct configurations; refuse fewer than twice ``unknowns``.

    Rows that repeat a configuration measure it again (to what the joint values resolve, so
    read-back jitter does not make a repeat new); they say nothing more about the chain.
    """
    tol = None if group_tol is None else joint_tolerances(group_tol, nominal.prismatic)
    distinct = count_distinct(prob.meas.q, tol, nominal.prismatic)
    m = distinct * prob.ncomp
    if m < 2 * unknowns:
        rows = (f"{prob.N} rows" if distinct == prob.N else
                f"{prob.N} rows in {distinct} distinct configuration(s) (the others repeat them)")
        raise IllPosedError(
            f"{rows} give {m} measured coordinates for {unknowns} identifiable unknowns; "
            f"at least twice as many coordinates as unknowns are needed to check the result: "
            f"measure at least {-(-2 * unknowns // prob.ncomp)} configurations (better 3 to 5 "
            "times as many, spread over the joint ranges)")
    return m


def _unheld(cand: list[int], hold: Mapping[str, str], chain: Chain
            ) -> tuple[list[int], dict[int, str]]:
    """The candidates without those held by name, and the reason of each held one."""
    unknown = sorted(set(hold) - set(chain.names))
    if unknown:
        raise InputError(f"cannot hold {', '.join(unknown)}: {chain.robot.name}'s chain has no "
                         "such constant (names as A2.a, A3.theta, A2.scale, j23_factor)")
    frame = sorted(n for n in hold if chain.groups[chain.index(n)] in ("base", "target"))
    if frame:
        raise InputError(f"cannot hold {', '.join(frame)}: the robot base in the device frame and "
                         "the targets are always identified")
    held = {chain.index(n): why for n, why in hold.items()}
    return [c for c in cand if c not in held], held


def _result(nominal, chain, prob, x, kept, fixed, rp0, rr0, name, x_nominal) -> IdentificationResult:
    rp, rr = prob.raw(x)
    w = prob.weighted(x)
    J = prob.jacobian(x, kept)
    m, p = J.shape
    dof = m - p
    chi = float(np.sum(w**2))
    s0 = math.sqrt(chi / dof) if dof > 0 else float("nan")
    U, S, Vt = np.linalg.svd(J, full_matrices=False)
    if S[-1] <= S[0] * 1e-14:
        raise IllPosedError("the identification Jacobian is singular at the solution; measure "
                            "configurations that move every joint over a wide range")
    cov = (Vt.T / S**2) @ Vt * (s0**2 if dof > 0 else 1.0)
    sig = np.sqrt(np.abs(np.diag(cov)))
    corr = cov / np.outer(sig, sig)
    # Outliers: leverage of each row from the hat matrix diagonal.
    h = np.sum(U**2, axis=1).reshape(prob.N, prob.ncomp).sum(axis=1)
    wrow = np.sum(w**2, axis=1)
    expect = prob.ncomp - h
    rest = dof - expect
    s2 = np.where(rest > 0.5, (chi - wrow) / np.where(rest > 0.5, rest, 1.0), np.nan)
    limit = chi2.ppf(_THREE_SIGMA_P, prob.ncomp)
    with np.errstate(invalid="ignore", divide="ignore"):
        stat = wrow / (s2 * expect) * prob.ncomp
    outliers = [int(i) for i in np.flatnonzero(stat > limit)]
    params = []
    sig_full = dict(zip(kept.tolist(), sig))
    for i, nm in enumerate(chain.names):
        g = chain.groups[i]
        if g in ("scale", "coupling", "compliance") and i not in sig_full and i not in fixed:
            continue
        params.append(Parameter(nm, float(x[i]), float(chain.values[i]) if g == "link" else float("nan"),
                                float(sig_full.get(i, float("nan"))), i in sig_full, fixed.get(i, ""),
                                "length" if (nm.split(".")[-1] in ("a", "d", "x", "y", "z")) else
                                ("number" if g in ("scale", "coupling") else
                                 "compliance" if g == "compliance" else "angle")))
    unexplained = _unexplained(U, w, prob, s0)
    model_error = beyond_accuracy(unexplained, 1.0 / prob.wp, dof)
    arm = [i for i, k in enumerate(kept)
           if chain.groups[k] in ("base", "link", "scale", "coupling")]
    covariance = ParameterCovariance(tuple(chain.names[kept[i]] for i in arm),
                                     cov[np.ix_(arm, arm)], model_error)
    robot = _to_robot(nominal, chain, x, name, covariance)
    return IdentificationResult(
        robot=robot, nominal=nominal, base=chain.base_pose(x), targets=chain.targets(x),
        target=chain.tool_pose(x) if chain.pose_target else None,
        parameters=params, correlation=corr, covariance=cov,
        free=[chain.names[k] for k in kept],
        fixed=[(chain.names[k], why) for k, why in sorted(fixed.items())],
        residuals=rp, rotation_residuals=rr, residuals_before=rp0, rotation_residuals_before=rr0,
        condition=scaled_condition(J), dof=dof, variance_factor=s0, outliers=outliers,
        labels=list(prob.meas.labels),
        scale=x[chain.scale_params].copy(),
        j23_factor=float(x[chain.coupling_param]) if chain.coupling_param >= 0 else 0.0,
        touch_sigma=1.0 / prob.wp, angle_sigma=1.0 / prob.wr, unexplained=unexplained,
        _q=prob.meas.q, _chain=chain, _x=x, _x_nominal=x_nominal,
    )


def _unexplained(U: NDArray[np.float64], w: NDArray[np.float64], prob: Problem,
                 s0: float) -> float:
    """Scatter per coordinate (m) of a held-out measured point that no parameter explains.

    The leave-one-out residual of each row, in closed form from the hat matrix of the weighted
    Jacobian (``U`` of its SVD): ``e_i = (I - H_ii)^-1 r_i``, the residual of the row predicted
    by the fit without it (exact for the linearised fit). A scatter ``u`` per coordinate that no
    parameter explains gives it the covariance ``u^2 (I - H_ii)^-1`` (the scatter itself and the
    error it leaves in the parameters fitted without the row), so ``u^2`` is the sum of the
    squared point residuals over the sum of the matching diagonal of ``(I - H_ii)^-1``. Rows that
    alone determine a direction (leverage 1) have no such residual and are left out.
    """
    N, c = prob.N, prob.ncomp
    Ui = U.reshape(N, c, -1)
    H = Ui @ np.swapaxes(Ui, 1, 2)
    ok = np.linalg.eigvalsh(H).max(axis=1) < 1.0 - 1e-6
    if not ok.any():
        return s0 / prob.wp if math.isfinite(s0) else float("nan")
    inflate = np.linalg.inv(np.eye(c) - H[ok])
    e = np.einsum("nij,nj->ni", inflate, w[ok])
    pts = slice(0, 3 * prob.K)
    var = np.sum(e[:, pts] ** 2) / np.sum(np.diagonal(inflate, axis1=1, axis2=2)[:, pts])
    return math.sqrt(float(var)) / prob.wp


def _to_robot(nominal: Robot, chain: Chain, x: NDArray[np.float64], name: str | None,
              covariance: ParameterCovariance | None = None) -> Robot:
    """The identified chain as a model: the nominal's joints with the identified constants.

    The constants are the parameters of the chain, in the nominal's own convention and frames
    (signs, offsets; Hayati's ``beta`` where two axes are nearly parallel), so the model file holds
    the numbers the report prints; the ones held stay at their nominal values (those of joint 1
    along and about its axis keep the robot base frame R the nominal's). Base, flange, tool and
    limits are the nominal's: the measured target is not the arm's tool
    (:attr:`IdentificationResult.target_tool`). ``covariance``: that of the arm's constants.
    """
    def value(joint: str, key: str, nominal_value: float) -> float:
        label = f"{joint}.{key}"
        return float(x[chain.index(label)]) if label in chain.names else nominal_value

    joints = tuple(replace(j, a=value(nm, "a", j.a), alpha=value(nm, "alpha", j.alpha),
                           d=value(nm, "d", j.d), theta=value(nm, "theta", j.theta),
                           beta=value(nm, "beta", j.beta))
                   for j, nm in zip(nominal.joints, chain.joint_names))
    return replace(nominal, name=name or f"{nominal.name}_identified", joints=joints,
                   title=f"{nominal.title or nominal.name}, identified",
                   source=f"identified from measurements, nominal {nominal.name}", verified=False,
                   verification="", ik_seed=_ik_seed(nominal), coupling=_coupling(nominal, chain, x),
                   covariance=covariance)


def _coupling(nominal: Robot, chain: Chain, x: NDArray[np.float64]) -> Coupling | None:
    """The identified scale and J2/J3 factor as a joint coupling ``q_model = C q`` (or None).

    ``C = diag(1 + scale)`` with ``C[2, 1] = k (1 + scale_3)`` (see ``Chain.model_joints``); the
    nominal coupling's interaction limits are kept.
    """
    C = np.diag(1.0 + x[chain.scale_params])
    if chain.coupling_param >= 0:
        C[2, 1] = x[chain.coupling_param] * C[2, 2]
    if np.array_equal(C, np.eye(chain.n)):
        return None
    old = nominal.coupling
    if old is None:
        return Coupling(C)
    return Coupling(C, None, old.interaction, old.interaction_lower, old.interaction_upper)


def _ik_seed(nominal: Robot) -> Robot | None:
    """The model whose analytic IK seeds the identified one's: the nominal (or its own seed)."""
    try:
        solver = analytic_solver(nominal)
    except InputError:
        return None
    return nominal.ik_seed if isinstance(solver, SeededSolver) else nominal
