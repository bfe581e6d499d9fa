"""Validation of an identification (K-fold) and the choice of measurement configurations.

**Cross-validation.** The rows are split into K folds; each fold is predicted by the model
identified on the other folds, and by the nominal model with its base and targets fitted on the
same rows. Every row is thus predicted by a model that has not seen it: the error before and
after identification, per row and as mean, RMS and max.

**Pose selection.** Borm and Menq's observability index ``O1 = (s_1 s_2 ... s_p)^(1/p) / sqrt(m)``
(the geometric mean of the singular values of the identification Jacobian over the square root of
the number of measured coordinates; "Determination of optimal measurement configurations for
robot calibration based on observability measure", Int. J. Robotics Research 10(1), 1991) is
maximised by greedy D-optimal selection from random candidates within the joint limits: each
step adds the candidate with the largest ``log det(I + B A^-1 B^T)`` (``A = J^T J`` of the rows
chosen so far, ``B`` the candidate's rows), which is the increase of ``log det A``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from robotcell.errors import InputError
from robotcell.identification.chain import Chain
from robotcell.identification.engine import Problem, identifiable, identify
from robotcell.identification.measurements import TargetMeasurements
from robotcell.robot.robot import Robot

__all__ = ["CrossValidation", "PoseSelection", "compare_observability", "cross_validate", "observability",
           "random_configurations", "reflector_spots", "select_configurations"]


@dataclass(frozen=True)
class CrossValidation:
    """Held-out errors of an identification.

    Attributes
    ----------
    folds : int
    before, after : ndarray, shape (N, K)
        Distance between each measured target and its prediction by the nominal model (base and
        targets fitted) and by the identified model, both fitted without the row (m).
    fold : ndarray of int, shape (N,)
        Fold of each row.
    """

    folds: int
    before: NDArray[np.float64]
    after: NDArray[np.float64]
    fold: NDArray[np.int_]

    def stats(self) -> dict[str, float]:
        """``mean``, ``rms`` and ``max`` of ``before`` and ``after`` in mm (keys ``*_mm``)."""
        out = {}
        for key, e in (("before", self.before), ("after", self.after)):
            out[f"{key}_mean_mm"] = float(e.mean() * 1e3)
            out[f"{key}_rms_mm"] = float(math.sqrt(np.mean(e**2)) * 1e3)
            out[f"{key}_max_mm"] = float(e.max() * 1e3)
        return out


def cross_validate(nominal: Robot, measurements: TargetMeasurements, folds: int = 5, seed: int = 0,
                   **options) -> CrossValidation:
    """K-fold cross-validation of :func:`~robotcell.identification.identify`.

    Parameters
    ----------
    nominal : Robot
    measurements : TargetMeasurements
    folds : int
        K >= 2; the rows are shuffled with ``np.random.default_rng(seed)`` and dealt into K folds.
    seed : int
    **options
        Passed to ``identify`` (accuracies, ``scale``, ``j23_factor``...).

    Returns
    -------
    CrossValidation
    """
    n = measurements.n_rows
    if not 2 <= folds <= n:
        raise InputError(f"folds must be between 2 and the number of rows ({n}), got {folds}")
    fold = np.empty(n, dtype=int)
    fold[np.random.default_rng(seed).permutation(n)] = np.arange(n) % folds
    before = np.zeros((n, measurements.n_targets))
    after = np.zeros_like(before)
    for k in range(folds):
        test = fold == k
        res = identify(nominal, measurements.subset(~test), **options)
        q = measurements.q[test]
        after[test] = np.linalg.norm(res.predict(q)[0] - measurements.points[test], axis=-1)
        before[test] = np.linalg.norm(res.predict(q, nominal=True)[0] - measurements.points[test], axis=-1)
    return CrossValidation(folds, before, after, fold)


def reflector_spots(n_targets: int) -> NDArray[np.float64]:
    """Where the observability of proposed configurations assumes the reflectors: spread over a
    100 mm circle 50 mm in front of the flange (the 4th to 6th on a 200 mm circle 100 mm in
    front, ...), in the flange frame, shape (n_targets, 3) (m)."""
    spots = np.array([[0.1, 0.0, 0.05], [-0.05, 0.087, 0.05], [-0.05, -0.087, 0.05]])
    k = np.arange(n_targets)
    return spots[k % 3] * (1 + k // 3)[:, None]


def _jacobian_blocks(nominal: Robot, q: NDArray[np.float64], n_targets: int, pose: bool,
                     sigma: float, angle_sigma: float):
    """Weighted identification Jacobian at the nominal model, rows grouped per configuration."""
    ch = Chain(nominal, 0 if pose else n_targets, pose, np.eye(4), np.eye(4))
    x = ch.values.copy()
    if ch.coupling_param >= 0 and nominal.coupling is not None:
        x[ch.coupling_param] = nominal.coupling.j23_factor or 0.0
    for k, spot in enumerate(reflector_spots(ch.n_targets)):
        x[ch.target_params[k]] = spot
    pts, R = ch.predict(x, q)
    prob = Problem(ch, TargetMeasurements(q, pts, R if pose else None), sigma, angle_sigma)
    groups = np.array(ch.groups)
    prio = np.flatnonzero(np.isin(groups, ("base", "target")))
    cand = list(prio) + list(np.flatnonzero(groups == "link"))
    J = prob.jacobian(x)
    kept, _ = identifiable(J, cand, set(prio), ch.names, 1e-6)
    return J[:, kept].reshape(len(q), prob.ncomp, kept.size)


def observability(J: NDArray[np.float64]) -> float:
    """Borm and Menq's O1 of a Jacobian ``(m, p)`` (columns as given): ``prod(s)^(1/p) / sqrt(m)``."""
    s = np.linalg.svd(J, compute_uv=False)
    if s[-1] <= 0:
        return 0.0
    return float(np.exp(np.mean(np.log(s))) / math.sqrt(J.shape[0]))


@dataclass(frozen=True)
class PoseSelection:
    """Proposed measurement configurations.

    Attributes
    ----------
    q : ndarray, shape (N, n)
        Configurations (rad, m), within the joint limits.
    o1 : float
        Their observability index O1 (parameter columns scaled by their norm over all candidates).
    o1_random : ndarray, shape (R,)
        O1 of random sets of N candidates, for comparison.
    """

    q: NDArray[np.float64]
    o1: float
    o1_random: NDArray[np.float64]


def random_configurations(nominal: Robot, rng: np.random.Generator, m: int) -> NDArray[np.float64]:
    """``m`` uniform configurations within the limits (unlimited: +-180 deg, +-1 m), (m, n)."""
    lo = np.where(np.isfinite(nominal.lower), nominal.lower, np.where(nominal.prismatic, -1.0, -math.pi))
    hi = np.where(np.isfinite(nominal.upper), nominal.upper, np.where(nominal.prismatic, 1.0, math.pi))
    return rng.uniform(lo, hi, (m, nominal.n_joints))


def compare_observability(nominal: Robot, q: NDArray[np.float64], *, n_targets: int = 1,
                          pose: bool = False, n_random: int = 20, seed: int = 0,
                          sigma: float = 0.05e-3, angle_sigma: float = math.radians(0.02),
                          ) -> tuple[float, NDArray[np.float64]]:
    """O1 of measured configurations against random sets of the same size within the limits.

    Parameters
    ----------
    nominal : Robot
    q : ndarray, shape (N, n)
        The measured configurations (rad, m).
    n_targets, pose, sigma, angle_sigma
        As in :func:`select_configurations`.
    n_random : int
        Number of random sets.
    seed : int
        Seed of ``np.random.default_rng`` for the random sets.

    Returns
    -------
    o1 : float
        O1 of ``q`` (columns scaled by their norm over ``q`` and all random sets together).
    o1_random : ndarray, shape (n_random,)
    """
    q = np.asarray(q, dtype=float)
    N = len(q)
    rand = random_configurations(nominal, np.random.default_rng(seed), N * n_random)
    B = _jacobian_blocks(nominal, np.concatenate([q, rand]), n_targets, pose, sigma, angle_sigma)
    p = B.shape[2]
    B = B / np.linalg.norm(B.reshape(-1, p), axis=0)
    o1 = observability(B[:N].reshape(-1, p))
    sets = B[N:].reshape(n_random, -1, p)
    return o1, np.array([observability(b) for b in sets])


def select_configurations(
    nominal: Robot, n: int, *, n_targets: int = 1, pose: bool = False,
    candidates: NDArray[np.float64] | None = None, n_candidates: int = 1000, seed: int = 0,
    sigma: float = 0.05e-3, angle_sigma: float = math.radians(0.02), n_random: int = 20,
) -> PoseSelection:
    """Choose ``n`` configurations maximising the observability of the identifiable parameters.

    Parameters
    ----------
    nominal : Robot
        Model whose joint limits bound the candidates (unlimited joints: +-180 deg, +-1 m).
    n : int
        Number of configurations to propose.
    n_targets : int
        Reflectors measured per configuration (placed on a 100 mm circle around the flange).
    pose : bool
        Orientations measured too.
    candidates : ndarray, shape (C, n_joints), optional
        Candidate configurations (rad, m), e.g. collision-free ones; default ``n_candidates``
        uniform random ones within the limits.
    seed : int
        Seed of ``np.random.default_rng`` for the candidates and the random comparison sets.
    sigma, angle_sigma : float
        Accuracies (m, rad) weighting positions against orientations.
    n_random : int
        Random sets of ``n`` candidates whose O1 is reported for comparison.

    Returns
    -------
    PoseSelection
    """
    rng = np.random.default_rng(seed)
    if candidates is None:
        candidates = random_configurations(nominal, rng, n_candidates)
    cand = np.asarray(candidates, dtype=float)
    if cand.ndim != 2 or cand.shape[1] != nominal.n_joints or len(cand) < n:
        raise InputError(f"candidates must have shape (C, {nominal.n_joints}) with C >= {n}, got {cand.shape}")
    B = _jacobian_blocks(nominal, cand, n_targets, pose, sigma, angle_sigma)
    C, r, p = B.shape
    if n * r < p:
        raise InputError(f"{n} configurations give {n * r} coordinates for {p} identifiable "
                         f"parameters; propose at least {-(-p // r)}")
    scale = np.linalg.norm(B.reshape(-1, p), axis=0)
    B = B / scale
    chosen: list[int] = []
    A = 1e-9 * np.eye(p)
    for _ in range(n):
        Ainv = np.linalg.inv(A)
        M = np.eye(r) + np.einsum("cip,pq,cjq->cij", B, Ainv, B)
        gain = np.linalg.slogdet(M)[1]
        gain[chosen] = -np.inf
        best = int(np.argmax(gain))
        chosen.append(best)
        A = A + B[best].T @ B[best]
    o1 = observability(B[chosen].reshape(-1, p))
    rand = np.array([observability(B[rng.choice(C, n, replace=False)].reshape(-1, p))
                     for _ in range(n_random)])
    return PoseSelection(cand[chosen], o1, rand)
