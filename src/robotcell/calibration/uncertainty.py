"""Uncertainty that travels from one calibration to the next: error sources and their factors.

A calibrated quantity (a tool, a track, a turntable, a frame) is a parameter vector ``u`` whose
error is a sum of independent contributions, one per *source*: the touch noise of the
calibration that produced it, and the errors of the calibrations it used (a tool calibrated
before, whose error every later touch with that tool shares). :class:`Sources` keeps, per
source, a factor ``F_s`` with ``cov(u) = sum_s F_s F_s^T``; two quantities that share a source
are correlated by it, ``cov(u, w) = sum_s F_s(u) F_s(w)^T``. A calibration that uses earlier
quantities gets them as :class:`Inputs`: the sources of the input parameters and the derivative
of every touched point with respect to them, which :func:`robotcell.calibration.fitting.fit`
turns into the share of each source in its own result (first order).

The parameters of a pose ``T_a_b`` are its origin (metres, along the axes of a) and a small
rotation vector ``d`` (radians) with ``R_true = exp([d]x) R``, as everywhere in the calibration
results.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError

__all__ = ["OWN", "Estimate", "Inputs", "Sources", "factor_of"]

#: Name of the source "the touch noise of this calibration" until the caller names it (the cell
#: file gives every calibration its own name).
OWN = "this calibration"


def factor_of(cov: ArrayLike) -> NDArray[np.float64]:
    """A factor ``F`` with ``F F^T = cov`` for a symmetric positive semi-definite matrix.

    Parameters
    ----------
    cov : array_like, shape (k, k)

    Returns
    -------
    ndarray, shape (k, k)
        ``V sqrt(max(lambda, 0))`` from the eigen-decomposition (a singular ``cov`` is fine).
    """
    c = np.asarray(cov, dtype=float)
    if c.ndim != 2 or c.shape[0] != c.shape[1] or not np.all(np.isfinite(c)):
        raise InputError(f"a covariance must be a finite square matrix, got shape {c.shape}")
    lam, vec = np.linalg.eigh(0.5 * (c + c.T))
    return vec * np.sqrt(np.clip(lam, 0.0, None))


@dataclass(frozen=True)
class Sources:
    """The error of a parameter vector of size k as independent sources: ``cov = sum F_s F_s^T``.

    Attributes
    ----------
    size : int
        Number of parameters k.
    factors : dict of str to ndarray, shape (k, m_s)
        One factor per source (SI units of the parameters); sources are independent of each
        other, and the same name in two :class:`Sources` is the same random error.
    """

    size: int
    factors: dict[str, NDArray[np.float64]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name, f in self.factors.items():
            f = np.asarray(f, dtype=float)
            if f.ndim != 2 or f.shape[0] != self.size or not np.all(np.isfinite(f)):
                raise InputError(f"the factor of source {name!r} must be a finite matrix with "
                                 f"{self.size} rows, got shape {f.shape}")
            self.factors[name] = f

    @classmethod
    def of(cls, name: str, cov: ArrayLike) -> Sources:
        """One source with covariance ``cov`` (k x k)."""
        f = factor_of(cov)
        return cls(len(f), {name: f})

    @property
    def covariance(self) -> NDArray[np.float64]:
        """``sum_s F_s F_s^T``, shape (k, k)."""
        out = np.zeros((self.size, self.size))
        for f in self.factors.values():
            out += f @ f.T
        return out

    @property
    def sigma(self) -> NDArray[np.float64]:
        """1-sigma of each parameter, shape (k,)."""
        return np.sqrt(np.diag(self.covariance))

    def map(self, G: ArrayLike) -> Sources:
        """The sources of ``G u`` (a linear function of the parameters), G of shape (j, k)."""
        G = np.asarray(G, dtype=float).reshape(-1, self.size)
        return Sources(len(G), {k: G @ f for k, f in self.factors.items()})

    def renamed(self, old: str, new: str) -> Sources:
        """The same sources with ``old`` called ``new`` (merged when ``new`` exists)."""
        out: dict[str, NDArray[np.float64]] = {}
        for k, f in self.factors.items():
            key = new if k == old else k
            out[key] = np.hstack([out[key], f]) if key in out else f
        return Sources(self.size, out)

    def __add__(self, other: Sources) -> Sources:
        """Sources of the sum of two errors of the same size (a shared source adds up)."""
        if other.size != self.size:
            raise InputError(f"cannot add sources of sizes {self.size} and {other.size}")
        out = dict(self.factors)
        for k, f in other.factors.items():
            if k in out and out[k].shape == f.shape:
                out[k] = out[k] + f
            elif k in out:
                raise InputError(f"source {k!r} has factors of shapes {out[k].shape} and "
                                 f"{f.shape}: not the same error")
            else:
                out[k] = f
        return Sources(self.size, out)

    @staticmethod
    def stack(parts: Sequence[Sources]) -> Sources:
        """Sources of the concatenated parameter vectors (cross-correlations by shared sources).

        Raises
        ------
        InputError
            A source that appears in two parts with different numbers of columns.
        """
        size = sum(p.size for p in parts)
        widths: dict[str, int] = {}
        for p in parts:
            for k, f in p.factors.items():
                if widths.setdefault(k, f.shape[1]) != f.shape[1]:
                    raise InputError(f"source {k!r} has factors of different widths")
        out = {k: np.zeros((size, m)) for k, m in widths.items()}
        row = 0
        for p in parts:
            for k, f in p.factors.items():
                out[k][row:row + p.size] = f
            row += p.size
        return Sources(size, out)

    def select(self, rows: ArrayLike) -> Sources:
        """The sources of a sub-vector (parameters ``rows``)."""
        idx = np.asarray(rows, dtype=int)
        return Sources(len(idx), {k: f[idx] for k, f in self.factors.items()})

    def matrix(self) -> tuple[NDArray[np.float64], list[str]]:
        """All factors side by side, shape (k, sum m_s), and the source of each column."""
        if not self.factors:
            return np.zeros((self.size, 0)), []
        cols = [name for name, f in self.factors.items() for _ in range(f.shape[1])]
        return np.hstack(list(self.factors.values())), cols


@dataclass(frozen=True)
class Inputs:
    """Earlier calibrations that the touches of a calibration rest on.

    Attributes
    ----------
    sensitivity : ndarray, shape (N, 3, k)
        Derivative of each touched point, as the calibration receives it (metres, in its frame),
        with respect to the k input parameters (SI; for a pose, origin and rotation vector).
    sources : Sources
        Error sources of the k input parameters.
    names : list of str
        Name of each input parameter, for messages.
    """

    sensitivity: NDArray[np.float64]
    sources: Sources
    names: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        s = np.asarray(self.sensitivity, dtype=float)
        if s.ndim != 3 or s.shape[1] != 3 or s.shape[2] != self.sources.size:
            raise InputError(f"input sensitivity must have shape (N, 3, {self.sources.size}), "
                             f"got {s.shape}")
        if not np.all(np.isfinite(s)):
            raise InputError("input sensitivity contains NaN or infinite values")
        object.__setattr__(self, "sensitivity", s)

    @property
    def size(self) -> int:
        """Number of input parameters k."""
        return self.sources.size

    def rotated(self, R: ArrayLike) -> Inputs:
        """The same inputs for points rotated by ``R`` (shape (3, 3) or (N, 3, 3))."""
        R = np.broadcast_to(np.asarray(R, dtype=float), self.sensitivity.shape[:1] + (3, 3))
        return Inputs(np.einsum("nij,njk->nik", R, self.sensitivity), self.sources, self.names)

    def subset(self, rows: ArrayLike) -> Inputs:
        """The inputs of some touches only (boolean mask or indices)."""
        return Inputs(self.sensitivity[np.asarray(rows)], self.sources, self.names)

    def joined(self, sensitivity: ArrayLike, sources: Sources,
               names: Sequence[str] = ()) -> Inputs:
        """These inputs with more parameters appended (their sensitivity, shape (N, 3, j))."""
        s = np.concatenate([self.sensitivity, np.asarray(sensitivity, dtype=float)], axis=2)
        return Inputs(s, Sources.stack([self.sources, sources]),
                      list(self.names) + list(names))


@dataclass(frozen=True)
class Estimate:
    """First-order facts of one calibrated parameter vector, for the calibrations that use it.

    Attributes
    ----------
    sources : Sources
        Error sources of the k parameters (for a pose: origin, rotation vector; SI): the
        calibration's own touch noise (:data:`OWN`) and the inputs' sources it inherits.
    gain : ndarray, shape (k, n)
        Derivative of the parameters with respect to the n input parameters of the calibration
        (how the estimate follows a change of a tool, an axis or a frame it used).
    determined : ndarray, shape (k, r)
        Orthonormal basis of the directions the touches determine; the others (e.g. the tool
        orientation of a TCP-only calibration, the roll of a track touched without reference
        points) are kept or fixed by a convention, and this calibration gives them no error.
    """

    sources: Sources
    gain: NDArray[np.float64]
    determined: NDArray[np.float64]

    @property
    def covariance(self) -> NDArray[np.float64]:
        """Covariance of the parameters, shape (k, k)."""
        return self.sources.covariance


def estimate(sources: Sources, gain: ArrayLike, A: ArrayLike,
             determined: ArrayLike | None = None) -> Estimate:
    """The :class:`Estimate` of ``u = A x`` for a fit of ``x`` with ``sources`` and ``gain``.

    Parameters
    ----------
    sources : Sources
        Error sources of the fitted parameters x (size p).
    gain : array_like, shape (p, n)
        ``dx / dv`` for the n input parameters.
    A : array_like, shape (k, p)
        ``du / dx``: the calibrated quantity as a (linearised) function of the fit's parameters.
    determined : array_like, shape (k, r), optional
        Directions of u the touches determine; default all.
    """
    A = np.asarray(A, dtype=float)
    D = np.eye(len(A)) if determined is None else np.asarray(determined, dtype=float)
    return Estimate(sources.map(A), A @ np.asarray(gain, dtype=float), D)


def joined(inputs: Inputs | None, sensitivity: ArrayLike, sources: Sources,
           names: Sequence[str] = ()) -> Inputs:
    """``inputs`` with more parameters appended, or new inputs when ``inputs`` is None."""
    if inputs is None:
        return Inputs(np.asarray(sensitivity, dtype=float), sources, list(names))
    return inputs.joined(sensitivity, sources, names)
