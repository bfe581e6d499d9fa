"""Linear coupling between controller axis values and the joint values of a kinematic model.

Many arms drive a joint through a parallel linkage, so the value the controller shows for an axis
is not the angle of the serial joint in the model. On a FANUC controller J3 is the forearm's angle
to the horizontal, so the serial elbow angle is ``J3 + J2`` (ROS-Industrial fanuc driver,
``linkage_transform`` with ``J23_factor``); a palletizer's passive parallelogram turns a joint that
has no motor at all. Both are linear::

    q_model = C @ q_controller + offset

with ``C`` of shape ``(m, n)``: ``m`` joints in the DH chain, ``n`` controller axes. ``C`` is square
and invertible when every model joint has a motor, and has full column rank ``n < m`` when some
joints are passive. Units follow the joints: radians for revolute, metres for prismatic joints, so
an entry of ``C`` that links a revolute row to a prismatic column is in rad/m.

:class:`Coupling` is the one place that maps between the two: :class:`~robotcell.robot.robot.Robot` uses
it for forward kinematics, the Jacobian (chain rule ``J_controller = J_model @ C``) and the limits,
and the analytic solvers map their model solutions back with :meth:`Coupling.to_controller`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.kinematics.bounds import LIMIT_TOL, within

__all__ = ["Coupling"]

#: Relative size of the smallest singular value of C below which it counts as rank deficient.
RANK_TOL = 1e-9


def _sparse_rows(M: NDArray[np.float64], off: NDArray[np.float64]) -> tuple[tuple[int, tuple, float], ...]:
    """The rows of ``M @ x + off`` that differ from ``x`` itself (all rows if M is not square).

    Returns ``(row, ((column, coefficient), ...), offset)`` for every row that is not the unit
    row ``e_i`` with zero offset; a square identity gives an empty tuple (nothing to do).
    """
    rows = []
    square = M.shape[0] == M.shape[1]
    for i in range(M.shape[0]):
        nz = tuple((int(j), float(M[i, j])) for j in np.flatnonzero(M[i]))
        if not (square and len(nz) == 1 and nz[0] == (i, 1.0) and off[i] == 0.0):
            rows.append((i, nz, float(off[i])))
    return tuple(rows)


@dataclass(frozen=True, eq=False)
class Coupling:
    """``q_model = matrix @ q_controller + offset``, with optional interaction limits.

    Parameters
    ----------
    matrix : array_like, shape (m, n)
        ``C``: rows are the model's joints (DH chain order), columns the controller axes. Square
        and invertible, or ``m > n`` with full column rank (passive joints).
    offset : array_like, shape (m,), optional
        Constant added to every model joint (rad, m); default 0.
    interaction : array_like, shape (k, n), optional
        Rows ``a`` of interaction limits ``lower <= a @ q_controller <= upper`` (e.g. FANUC's
        J2/J3 interference limit on ``J3 + J2``); units follow the joints.
    interaction_lower, interaction_upper : array_like, shape (k,), optional
        Bounds of those limits (rad, m), possibly infinite.

    Raises
    ------
    InputError
        Wrong shapes, non-finite entries, a singular square ``C`` or a rectangular ``C`` without
        full column rank.
    """

    matrix: NDArray[np.float64]
    offset: NDArray[np.float64] | None = None
    interaction: NDArray[np.float64] | None = None
    interaction_lower: NDArray[np.float64] | None = None
    interaction_upper: NDArray[np.float64] | None = None
    _inverse: NDArray[np.float64] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        C = np.array(self.matrix, dtype=float)
        if C.ndim != 2 or C.size == 0:
            raise InputError(f"coupling matrix must be a 2-D (m, n) matrix, got shape {C.shape}")
        if not np.all(np.isfinite(C)):
            raise InputError("coupling matrix contains NaN or infinite values")
        m, n = C.shape
        if n > m:
            raise InputError(f"coupling matrix has more columns (controller axes, {n}) than rows "
                             f"(model joints, {m})")
        sv = np.linalg.svd(C, compute_uv=False)
        if sv[-1] <= RANK_TOL * max(1.0, sv[0]):
            what = "not invertible (singular)" if m == n else "not of full column rank"
            raise InputError(
                f"coupling matrix is {what}: smallest singular value {sv[-1]:.3g}; two controller "
                "axes would drive the same motion, so joint values could not be recovered from a pose"
            )
        off = np.zeros(m) if self.offset is None else np.array(self.offset, dtype=float)
        if off.shape != (m,) or not np.all(np.isfinite(off)):
            raise InputError(f"coupling offset must be {m} finite numbers, got {self.offset!r}")
        A = np.zeros((0, n)) if self.interaction is None else np.atleast_2d(np.array(self.interaction, dtype=float))
        k = A.shape[0]
        if A.shape != (k, n) or not np.all(np.isfinite(A)):
            raise InputError(f"interaction limits need {n} finite coefficients each, got {self.interaction!r}")
        lo = np.full(k, -math.inf) if self.interaction_lower is None else np.array(self.interaction_lower, dtype=float).reshape(-1)
        hi = np.full(k, math.inf) if self.interaction_upper is None else np.array(self.interaction_upper, dtype=float).reshape(-1)
        if lo.shape != (k,) or hi.shape != (k,) or np.any(np.isnan(lo)) or np.any(np.isnan(hi)):
            raise InputError(f"interaction limits need {k} lower and {k} upper bounds")
        if np.any(lo >= hi):
            raise InputError("interaction limits: every lower bound must be below its upper bound")
        inv = np.linalg.inv(C) if m == n else np.linalg.pinv(C)
        # Exact integers stay exact (C^-1 of a unimodular integer matrix is an integer matrix).
        inv = np.where(np.abs(inv - np.round(inv)) < 1e-12, np.round(inv), inv)
        for key, val in (("matrix", C), ("offset", off), ("interaction", A),
                         ("interaction_lower", lo), ("interaction_upper", hi), ("_inverse", inv)):
            val.setflags(write=False)
            object.__setattr__(self, key, val)
        object.__setattr__(self, "_to_model_rows", _sparse_rows(C, off))
        object.__setattr__(self, "_to_ctrl_rows", _sparse_rows(inv, -inv @ off))

    # -- shape ----------------------------------------------------------------------------------
    @property
    def n_model(self) -> int:
        """Number of model joints ``m`` (rows of C)."""
        return self.matrix.shape[0]

    @property
    def square(self) -> bool:
        """True when every model joint has its own controller axis (no passive joint)."""
        return self.matrix.shape[0] == self.matrix.shape[1]

    @property
    def j23_factor(self) -> float | None:
        """The factor k when the coupling is exactly ``q3_model = J3 + k * J2``, else None."""
        C = self.matrix
        n = C.shape[1]
        if not self.square or n < 3 or np.any(self.offset):
            return None
        E = np.eye(n)
        E[2, 1] = C[2, 1]
        return float(C[2, 1]) if np.array_equal(C, E) and C[2, 1] != 0 else None

    # -- mapping --------------------------------------------------------------------------------
    def to_model(self, q: ArrayLike) -> NDArray[np.float64]:
        """Model joint values of controller values.

        Parameters
        ----------
        q : array_like, shape (..., n)
            Controller axis values (rad, m).

        Returns
        -------
        ndarray, shape (..., m)
            ``C @ q + offset`` (rad, m).
        """
        arr = np.asarray(q, dtype=float)
        if self.square:
            return _apply_rows(arr, self._to_model_rows)
        return arr @ self.matrix.T + self.offset

    def to_model_list(self, q: list[float]) -> list[float]:
        """:meth:`to_model` of one configuration given as Python floats (fast single-pose path)."""
        out = list(q) if self.square else [0.0] * self.n_model
        for i, terms, off in self._to_model_rows:
            out[i] = sum(c * q[j] for j, c in terms) + off
        return out

    def to_controller(self, q_model: ArrayLike, out: NDArray[np.float64] | None = None
                      ) -> NDArray[np.float64]:
        """Controller values of model joint values.

        Parameters
        ----------
        q_model : array_like, shape (..., m)
            Model joint values (rad, m). For a rectangular ``C`` they must satisfy the coupling
            (the passive joints follow the others); the left inverse then recovers ``q`` exactly.
        out : ndarray, shape (..., n), optional
            Square ``C`` only: write the result here (may be ``q_model`` itself; only the values
            the coupling changes are written, the others must already be there).

        Returns
        -------
        ndarray, shape (..., n)
            ``C^-1 @ (q_model - offset)`` (rad, m).
        """
        arr = np.asarray(q_model, dtype=float)
        if self.square:
            return _apply_rows(arr, self._to_ctrl_rows, out)
        return (arr - self.offset) @ self._inverse.T

    def jacobian(self, J_model: NDArray[np.float64]) -> NDArray[np.float64]:
        """Chain rule: the Jacobian in controller values, ``J_model @ C``.

        Parameters
        ----------
        J_model : ndarray, shape (..., 6, m)
            Jacobian with respect to the model joints.

        Returns
        -------
        ndarray, shape (..., 6, n)
        """
        return J_model @ self.matrix

    def changed_axes(self) -> list[int]:
        """Controller axes whose value differs from the model joint of the same index."""
        return [i for i, _, _ in self._to_ctrl_rows]

    def periodic(self, revolute_model: NDArray[np.bool_], revolute_axes: NDArray[np.bool_]
                 ) -> NDArray[np.bool_]:
        """Which controller axes reach the same pose after a full turn, shape ``(n,)``.

        Axis ``j`` is 2*pi-periodic when it is revolute, its column of ``C`` is an integer on every
        revolute model joint and zero on every prismatic one: turning it by 2*pi then turns each
        model joint by a whole number of revolutions.
        """
        C = self.matrix
        integer = np.all(np.where(revolute_model[:, None], C == np.round(C), C == 0.0), axis=0)
        return integer & revolute_axes

    def within_interaction(self, q: NDArray[np.float64], tol: float = LIMIT_TOL) -> NDArray[np.bool_]:
        """Whether controller values respect the interaction limits (NaN gives False).

        Parameters
        ----------
        q : ndarray, shape (..., n)
            Controller axis values (rad, m).
        tol : float
            Allowed excess (rad, m); default the rounding tolerance
            :data:`robotcell.kinematics.bounds.LIMIT_TOL`.

        Returns
        -------
        ndarray of bool, shape (...)
        """
        if not self.interaction.shape[0]:
            return ~np.isnan(q[..., 0])
        v = q @ self.interaction.T
        return np.all(within(v, self.interaction_lower, self.interaction_upper, tol), axis=-1)

    def extended(self, k: int = 1) -> Coupling:
        """The coupling of ``k`` uncoupled axes placed before these (e.g. a linear track)."""
        m, n = self.matrix.shape
        C = np.zeros((m + k, n + k))
        C[:k, :k] = np.eye(k)
        C[k:, k:] = self.matrix
        A = np.zeros((self.interaction.shape[0], n + k))
        A[:, k:] = self.interaction
        return Coupling(C, np.concatenate([np.zeros(k), self.offset]), A,
                        self.interaction_lower, self.interaction_upper)


def _apply_rows(arr: NDArray[np.float64], rows: tuple, out: NDArray[np.float64] | None = None
                ) -> NDArray[np.float64]:
    """``arr`` (..., m) with the given sparse rows of a square map recomputed (into a copy, or
    into ``out``, which may be ``arr``: every new row is computed before any is written)."""
    out = arr.copy() if out is None else out
    new = [(i, _combine(arr, terms, off)) for i, terms, off in rows]
    for i, v in new:
        out[..., i] = v
    return out


def _combine(arr: NDArray[np.float64], terms: tuple, off: float) -> NDArray[np.float64]:
    """``sum(c * arr[..., j]) + off`` over the given ``(j, c)`` terms."""
    v = None
    for j, c in terms:
        col = arr[..., j]
        t = col if c == 1.0 else -col if c == -1.0 else c * col
        v = t if v is None else v + t
    if v is None:
        v = np.zeros(arr.shape[:-1])
    return v + off if off != 0.0 else v
