"""Denavit-Hartenberg link transforms and their compilation into a fast, batched chain.

Standard DH (the lecture's form)::

    T_{i-1,i} = Trans(z, d_i) Rot(z, theta_i) Trans(x, a_i) Rot(x, alpha_i) [Rot(y, beta_i)]

Modified DH (Craig)::

    T_{i-1,i} = Rot(x, alpha_{i-1}) [Rot(y, beta_i)] Trans(x, a_{i-1}) Rot(z, theta_i) Trans(z, d_i)

``Rot(y, beta_i)`` is Hayati's extra twist (Hayati and Mirmirani, J. Robotic Systems 2(4), 1985)
of an identified link whose two axes are nearly parallel, where plain DH would put their common
normal metres away; it is 0 (and costs nothing) everywhere else.

:func:`link_transform` builds these matrices directly (the reference, used in tests and by
whoever wants one link). :class:`Chain` compiles a whole chain into a list of elementary
operations (rotations about z or x, or y for a beta, translations along z or x) with the constants folded: a zero
offset costs nothing and a twist of +-90 degrees is a swap of two columns. Applying those
operations column by column to a batch is several times faster than multiplying ``(N, 4, 4)``
matrices, and the same program evaluated with Python floats makes a single pose cheap.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["Chain", "link_transform"]

Convention = Literal["standard", "modified"]
_HALF_PI = math.pi / 2
#: Angles within this of a multiple of 90 degrees are treated as exact (radians).
_EXACT_TOL = 1e-15
#: Poses per block of the batched kernel: small enough for the working set to stay in cache.
_BLOCK = 2048


def link_transform(
    theta: ArrayLike, d: ArrayLike, a: ArrayLike, alpha: ArrayLike,
    convention: Convention = "standard", beta: float = 0.0,
) -> NDArray[np.float64]:
    """One DH link transform ``T_{i-1,i}``.

    Parameters
    ----------
    theta, d, a, alpha : array_like, broadcastable shapes (...)
        Joint angle (rad), joint distance (m), link length (m), twist (rad). For the modified
        convention ``a`` and ``alpha`` are Craig's ``a_{i-1}`` and ``alpha_{i-1}``.
    convention : {"standard", "modified"}
    beta : float
        Hayati's rotation about y after the twist (rad; 0 for plain DH).

    Returns
    -------
    ndarray, shape (..., 4, 4)
    """
    theta, d, a, alpha = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (theta, d, a, alpha)))
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    T = np.zeros(theta.shape + (4, 4))
    if convention == "standard":
        T[..., 0, :] = np.stack([ct, -st * ca, st * sa, a * ct], axis=-1)
        T[..., 1, :] = np.stack([st, ct * ca, -ct * sa, a * st], axis=-1)
        T[..., 2, 1], T[..., 2, 2], T[..., 2, 3] = sa, ca, d
    elif convention == "modified":
        T[..., 0, :] = np.stack([ct, -st, np.zeros_like(ct), a], axis=-1)
        T[..., 1, :] = np.stack([st * ca, ct * ca, -sa, -sa * d], axis=-1)
        T[..., 2, :] = np.stack([st * sa, ct * sa, ca, ca * d], axis=-1)
    else:
        raise ValueError(f"convention must be 'standard' or 'modified', got {convention!r}")
    T[..., 3, 3] = 1.0
    if beta == 0.0:
        return T
    cb, sb = math.cos(beta), math.sin(beta)
    if convention == "standard":
        Ry = np.array([[cb, 0.0, sb, 0.0], [0.0, 1.0, 0.0, 0.0], [-sb, 0.0, cb, 0.0],
                       [0.0, 0.0, 0.0, 1.0]])
        return T @ Ry
    # Rx(alpha) Ry(beta) Tx(a), then Rz(theta) Tz(d) (the plain link with a = alpha = 0)
    P = np.zeros(theta.shape + (4, 4))
    P[..., 0, :] = np.stack([np.full_like(ca, cb), np.zeros_like(ca), np.full_like(ca, sb), a * cb], axis=-1)
    P[..., 1, :] = np.stack([sa * sb, ca, -sa * cb, a * sa * sb], axis=-1)
    P[..., 2, :] = np.stack([-ca * sb, sa, ca * cb, -a * ca * sb], axis=-1)
    P[..., 3, 3] = 1.0
    return P @ link_transform(theta, d, 0.0, 0.0, "modified")


@dataclass(frozen=True)
class _Op:
    """One elementary operation ``T <- T @ op``.

    ``kind`` is ``rz``/``rx``/``ry`` (rotation) or ``tz``/``tx`` (translation). A variable operation
    reads joint ``joint`` and uses ``sign * q + value``; a constant one uses ``value``. ``quarter``
    is set for constant rotations by an exact multiple of 90 degrees (0..3 quarter turns).
    """

    kind: str
    value: float
    joint: int = -1
    sign: float = 1.0
    quarter: int = -1


def _quarter(angle: float) -> int:
    k = round(angle / _HALF_PI)
    return k % 4 if abs(angle - k * _HALF_PI) <= _EXACT_TOL else -1


class Chain:
    """A serial DH chain compiled for batched and single-pose evaluation.

    Parameters
    ----------
    convention : {"standard", "modified"}
    a, alpha, d, theta : sequence of float, length n
        DH constants (m, rad): for a revolute joint ``theta`` is the offset added to the joint
        variable, for a prismatic joint ``d`` is.
    prismatic : sequence of bool, length n
    sign : sequence of float, length n
        +1 or -1: the DH variable is ``sign * q + offset``.
    beta : sequence of float, length n, optional
        Hayati's rotation about y after each twist (rad); default none.
    """

    def __init__(self, convention: Convention, a, alpha, d, theta, prismatic, sign,
                 beta=None) -> None:
        self.convention = convention
        self.n = len(a)
        ops: list[_Op] = []
        #: index into ``ops`` after which joint i's frame is complete
        self.frame_ends: list[int] = []
        for i in range(self.n):
            z_rot = _Op("rz", theta[i], i, sign[i]) if not prismatic[i] else self._const("rz", theta[i])
            z_tr = _Op("tz", d[i], i, sign[i]) if prismatic[i] else self._const("tz", d[i])
            x_tr, x_rot = self._const("tx", a[i]), self._const("rx", alpha[i])
            y_rot = None if beta is None else self._const("ry", beta[i])
            seq = ([z_tr, z_rot, x_tr, x_rot, y_rot] if convention == "standard"
                   else [x_rot, y_rot, x_tr, z_rot, z_tr])
            ops.extend(op for op in seq if op is not None)
            self.frame_ends.append(len(ops))
        self.ops = tuple(ops)
        rot = [op.joint for op in ops if op.joint >= 0 and op.kind == "rz"]
        self._rot_joints = np.array(rot, dtype=int)
        self._rot_row = {j: r for r, j in enumerate(rot)}
        self._sign = np.array([sign[j] for j in rot], dtype=float)
        self._offset = np.array([theta[j] for j in rot], dtype=float)
        # The single-pose program: (code, joint, sign, value, quarter) with code 0..4 for
        # rz, rx, tz, tx, ry.
        codes = {"rz": 0, "rx": 1, "tz": 2, "tx": 3, "ry": 4}
        self._program = tuple((codes[op.kind], op.joint, op.sign, op.value, op.quarter) for op in ops)

    @staticmethod
    def _const(kind: str, value: float) -> _Op | None:
        if kind in ("tz", "tx"):
            return _Op(kind, float(value)) if value != 0.0 else None
        q = _quarter(value)
        if q == 0:
            return None
        return _Op(kind, float(value), quarter=q)

    # -- batched ------------------------------------------------------------------------------
    def apply(self, start: NDArray[np.float64], q: NDArray[np.float64], frames: bool = False,
              tail: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """Evaluate ``start @ T_0_n(q) @ tail`` for a batch.

        Parameters
        ----------
        start : ndarray, shape (4, 4)
            Constant pose the chain is appended to (e.g. the base transform).
        q : ndarray, shape (N, n)
            Joint values (rad or m), already validated.
        frames : bool
            If True return every frame ``start @ T_0_i`` for ``i = 0..n`` (``tail`` is ignored).
        tail : ndarray, shape (4, 4), optional
            Constant pose appended after the last link (e.g. flange and tool).

        Returns
        -------
        ndarray, shape (N, 4, 4), or (N, n + 1, 4, 4) when ``frames``.
        """
        N = q.shape[0]
        out = np.empty((N, self.n + 1, 4, 4) if frames else (N, 4, 4))
        for lo in range(0, N, _BLOCK):
            hi = min(lo + _BLOCK, N)
            self._block(start, q[lo:hi].T, out[lo:hi], frames, None if frames else tail)
        return out

    def _block(self, start, qT, out, frames, tail) -> None:
        # cos and sin of every variable angle at once, from the half-angle tangent: np.tan is
        # vectorised with SIMD where np.cos and np.sin are not, and the identities
        # c = (1 - t^2) / (1 + t^2), s = 2 t / (1 + t^2) are exact to rounding for every angle
        # (at theta = pi, t is about 1.6e16 and c = -1, s = 1.2e-16, as cos and sin give).
        th = self._sign[:, None] * qT[self._rot_joints] + self._offset[:, None]
        t = np.tan(0.5 * th)
        t2 = t * t
        inv = 1.0 / (1.0 + t2)
        cos_all = (1.0 - t2) * inv
        sin_all = 2.0 * t * inv
        cols = [start[:3, k : k + 1].copy() for k in range(4)]  # r0, r1, r2, p as (3, 1)
        out[..., 3, :] = (0.0, 0.0, 0.0, 1.0)
        if frames:
            out[:, 0, :3, :] = start[:3, :]
        ends = set(self.frame_ends) if frames else ()
        for k, op in enumerate(self.ops, start=1):
            kind = op.kind
            if kind in ("rz", "rx", "ry"):
                i, j = {"rz": (0, 1), "rx": (1, 2), "ry": (2, 0)}[kind]
                ci, cj = cols[i], cols[j]
                if op.quarter == 1:
                    cols[i], cols[j] = cj, -ci
                elif op.quarter == 2:
                    cols[i], cols[j] = -ci, -cj
                elif op.quarter == 3:
                    cols[i], cols[j] = -cj, ci
                else:
                    if op.joint >= 0:
                        c, s = cos_all[self._rot_row[op.joint]], sin_all[self._rot_row[op.joint]]
                    else:
                        c, s = math.cos(op.value), math.sin(op.value)
                    cols[i] = c * ci + s * cj
                    cols[j] = c * cj - s * ci
            else:
                if op.joint >= 0:
                    v = qT[op.joint] if op.sign == 1.0 else -qT[op.joint]
                    if op.value != 0.0:
                        v = v + op.value
                else:
                    v = op.value
                m = 2 if kind == "tz" else 0
                cols[3] = cols[3] + v * cols[m]
            if k in ends:
                dst = out[:, self.frame_ends.index(k) + 1]
                for m in range(4):
                    dst[:, :3, m] = cols[m].T
        if tail is not None:
            # cols @ tail, skipping zero coefficients (vendor flanges are signed permutations).
            rot = [_lincomb(tail[:3, k], cols[:3]) for k in range(3)]
            cols = rot + [_lincomb(tail[:3, 3], cols[:3], cols[3])]
        if not frames:
            for m in range(4):
                out[:, :3, m] = cols[m].T

    # -- one pose with Python floats ----------------------------------------------------------
    def apply_one(self, start: list[list[float]], q: list[float]) -> list[float]:
        """Evaluate ``start @ T_0_n(q)`` for one pose with Python floats.

        Parameters
        ----------
        start : list of 4 lists of 3 floats
            Columns ``r0, r1, r2, p`` of the constant start pose.
        q : list of float, length n

        Returns
        -------
        list of 12 floats
            Columns ``r0, r1, r2, p`` of the result, concatenated.
        """
        (a0, a1, a2), (b0, b1, b2), (c0, c1, c2), (p0, p1, p2) = start
        cos, sin = math.cos, math.sin
        for code, joint, sign, value, quarter in self._program:
            v = sign * q[joint] + value if joint >= 0 else value
            if code == 0:
                if quarter == 1:
                    a0, a1, a2, b0, b1, b2 = b0, b1, b2, -a0, -a1, -a2
                elif quarter == 2:
                    a0, a1, a2, b0, b1, b2 = -a0, -a1, -a2, -b0, -b1, -b2
                elif quarter == 3:
                    a0, a1, a2, b0, b1, b2 = -b0, -b1, -b2, a0, a1, a2
                else:
                    c, s = cos(v), sin(v)
                    a0, a1, a2, b0, b1, b2 = (c * a0 + s * b0, c * a1 + s * b1, c * a2 + s * b2,
                                              c * b0 - s * a0, c * b1 - s * a1, c * b2 - s * a2)
            elif code == 1:
                if quarter == 1:
                    b0, b1, b2, c0, c1, c2 = c0, c1, c2, -b0, -b1, -b2
                elif quarter == 2:
                    b0, b1, b2, c0, c1, c2 = -b0, -b1, -b2, -c0, -c1, -c2
                elif quarter == 3:
                    b0, b1, b2, c0, c1, c2 = -c0, -c1, -c2, b0, b1, b2
                else:
                    c, s = cos(v), sin(v)
                    b0, b1, b2, c0, c1, c2 = (c * b0 + s * c0, c * b1 + s * c1, c * b2 + s * c2,
                                              c * c0 - s * b0, c * c1 - s * b1, c * c2 - s * b2)
            elif code == 2:
                p0, p1, p2 = p0 + v * c0, p1 + v * c1, p2 + v * c2
            elif code == 3:
                p0, p1, p2 = p0 + v * a0, p1 + v * a1, p2 + v * a2
            else:  # a constant rotation about y (Hayati's beta): columns z and x
                c, s = cos(v), sin(v)
                c0, c1, c2, a0, a1, a2 = (c * c0 + s * a0, c * c1 + s * a1, c * c2 + s * a2,
                                          c * a0 - s * c0, c * a1 - s * c1, c * a2 - s * c2)
        return [a0, a1, a2, b0, b1, b2, c0, c1, c2, p0, p1, p2]


def _lincomb(coeffs, vecs, acc=None):
    """``acc + sum(c * v)`` over the nonzero coefficients, without multiplying by +-1."""
    for c, v in zip(coeffs, vecs):
        if c == 0.0:
            continue
        term = v if c == 1.0 else -v if c == -1.0 else c * v
        acc = term if acc is None else acc + term
    return np.zeros((3, 1)) if acc is None else acc
