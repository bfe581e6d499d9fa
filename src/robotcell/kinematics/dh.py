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
operations (rotations about z or x, or y for a beta; translations along z or x) with the
constants folded: a zero offset costs nothing and a twist of +-90 degrees is a swap of two columns. One function,
:func:`chain_kernel`, applies those operations column by column: numpy runs it on blocks of poses
(several times faster than multiplying ``(N, 4, 4)`` matrices) and numba compiles it for one pose
(:mod:`robotcell.kinematics.jit`), where a numpy call per operation would cost more than the
arithmetic. :func:`jacobian_kernel` does the same for the geometric Jacobian.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.kinematics.jit import Kernel

__all__ = ["CHAIN", "JACOBIAN", "NO_SHIFT", "Chain", "chain_kernel", "jacobian_kernel", "link_transform"]

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
    P[..., 0, :] = np.stack([np.full_like(ca, cb), np.zeros_like(ca), np.full_like(ca, sb), a * cb],
                            axis=-1)
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

    Attributes
    ----------
    program : ndarray, shape (K, 5)
        The elementary operations as rows ``(code, joint, sign, value, quarter)``, code 0..4 for
        a rotation about z or x, a translation along z or x, and a constant rotation about y (see
        :func:`chain_kernel`).
    frame_ends : ndarray of int, shape (n,)
        Number of operations after which joint i's frame is complete.
    """

    def __init__(self, convention: Convention, a, alpha, d, theta, prismatic, sign,
                 beta=None) -> None:
        self.convention = convention
        self.n = len(a)
        ops: list[_Op] = []
        ends: list[int] = []
        for i in range(self.n):
            z_rot = _Op("rz", theta[i], i, sign[i]) if not prismatic[i] else self._const("rz", theta[i])
            z_tr = _Op("tz", d[i], i, sign[i]) if prismatic[i] else self._const("tz", d[i])
            x_tr, x_rot = self._const("tx", a[i]), self._const("rx", alpha[i])
            y_rot = None if beta is None else self._const("ry", beta[i])
            seq = ([z_tr, z_rot, x_tr, x_rot, y_rot] if convention == "standard"
                   else [x_rot, y_rot, x_tr, z_rot, z_tr])
            ops.extend(op for op in seq if op is not None)
            ends.append(len(ops))
        self.ops = tuple(ops)
        self.frame_ends = np.array(ends, dtype=np.int64)
        rot = [op.joint for op in ops if op.joint >= 0 and op.kind == "rz"]
        self._rot_joints = np.array(rot, dtype=int)
        self._sign = np.array([sign[j] for j in rot], dtype=float)
        self._offset = np.array([theta[j] for j in rot], dtype=float)
        codes = {"rz": 0, "rx": 1, "tz": 2, "tx": 3, "ry": 4}
        self.program = np.array([(codes[op.kind], op.joint, op.sign, op.value, op.quarter)
                                 for op in ops], dtype=float).reshape(-1, 5)

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
              tail: NDArray[np.float64] | None = None,
              shift: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
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
        shift : ndarray, shape (3,), optional
            Added to the translation of ``start`` (m).

        Returns
        -------
        ndarray, shape (N, 4, 4), or (N, n + 1, 4, 4) when ``frames``.
        """
        N = q.shape[0]
        shift = NO_SHIFT if shift is None else shift
        out = np.empty((N, self.n + 1, 4, 4) if frames else (N, 4, 4))
        ends = self.frame_ends if frames else None
        tail = _IDENTITY if tail is None else tail
        for lo in range(0, N, _BLOCK):
            hi = min(lo + _BLOCK, N)
            qT = q[lo:hi].T
            chain_kernel(self.program, qT, start, shift, tail, np.moveaxis(out[lo:hi], 0, -1),
                         ends, self._cos_sin(qT))
        return out

    def _cos_sin(self, qT: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """cos and sin of every variable rotation, rows in the order of the program."""
        # From the half-angle tangent: np.tan is vectorised with SIMD where np.cos and np.sin
        # are not, and the identities c = (1 - t^2) / (1 + t^2), s = 2 t / (1 + t^2) are exact
        # to rounding for every angle (at theta = pi, t is about 1.6e16 and c = -1,
        # s = 1.2e-16, as cos and sin give).
        th = self._sign[:, None] * qT[self._rot_joints] + self._offset[:, None]
        t = np.tan(0.5 * th)
        t2 = t * t
        inv = 1.0 / (1.0 + t2)
        return (1.0 - t2) * inv, 2.0 * t * inv

    def jacobian(self, start: NDArray[np.float64], q: NDArray[np.float64], tail: NDArray[np.float64],
                 first: int, sign: NDArray[np.float64], prismatic: NDArray[np.bool_]
                 ) -> NDArray[np.float64]:
        """Geometric Jacobian of a batch at the point ``start @ T_0_n(q) @ tail``.

        Parameters
        ----------
        start, tail : ndarray, shape (4, 4)
        q : ndarray, shape (N, n)
            Joint values (rad, m), already validated.
        first, sign, prismatic
            As for :func:`jacobian_kernel`.

        Returns
        -------
        ndarray, shape (N, 6, n)
        """
        N = q.shape[0]
        out = np.empty((N, 6, self.n))
        F = np.empty((min(N, _BLOCK), self.n + 1, 4, 4))
        for lo in range(0, N, _BLOCK):
            hi = min(lo + _BLOCK, N)
            qT = q[lo:hi].T
            Fb = np.moveaxis(F[:hi - lo], 0, -1)
            chain_kernel(self.program, qT, start, NO_SHIFT, tail, Fb, self.frame_ends,
                         self._cos_sin(qT))
            jacobian_kernel(Fb, tail, first, sign, prismatic, np.moveaxis(out[lo:hi], 0, -1))
        return out

    # -- one pose -----------------------------------------------------------------------------
    def one(self, q: NDArray[np.float64], start: NDArray[np.float64], tail: NDArray[np.float64],
            out: NDArray[np.float64], frames: bool = False) -> bool:
        """Evaluate ``start @ T_0_n(q) @ tail`` (or every frame) for one pose, into ``out``.

        Parameters
        ----------
        q : ndarray, shape (n,)
            Joint values (rad or m), C-contiguous float64, not yet checked for NaN.
        start, tail : ndarray, shape (4, 4)
            Constant poses before and after the chain (``tail`` is ignored for ``frames``).
        out : ndarray, shape (4, 4), or (n + 1, 4, 4) with ``frames``
            Receives the pose (or every frame ``start @ T_0_i``).
        frames : bool

        Returns
        -------
        bool
            False (and ``out`` undefined) when ``q`` holds NaN or an infinite value.
        """
        return CHAIN.call(self.program, q, start, NO_SHIFT, tail, out,
                          self.frame_ends if frames else None, None)


_IDENTITY = np.eye(4)
_IDENTITY.setflags(write=False)
#: The ``shift`` of a chain that does not move (writable like every array the kernels get, so
#: that numba compiles one version; nothing writes it).
NO_SHIFT = np.zeros(3)


def chain_kernel(program, q, start, shift, tail, out, ends, cs) -> bool:
    """``start @ T_0_n(q) @ tail``, or every frame, on a batch or on one pose.

    The one implementation of the chain: run by numpy on a batch (each variable below is then an
    array over the poses) and compiled by numba for one pose (:data:`CHAIN`), with its helpers
    :func:`_put_frame` and :func:`_times_tail`.

    Parameters
    ----------
    program : ndarray, shape (K, 5)
        :attr:`Chain.program`: per elementary operation ``T <- T @ op``, ``(code, joint, sign,
        value, quarter)``; code 0/1 rotates about z/x, 2/3 translates along z/x, 4 rotates about
        y (a constant: Hayati's beta); a variable
        operation (``joint >= 0``) uses ``sign * q[joint] + value``, a constant one ``value``; a
        constant rotation by ``quarter`` (1..3) quarter turns swaps two columns.
    q : ndarray, shape (n,) or (n, N)
        Joint values (rad, m) of one pose, or of N poses, one row per joint.
    start, tail : ndarray, shape (4, 4)
        Constant poses before and after the chain (``tail`` unused when ``ends`` is given).
    shift : ndarray, shape (3,)
        Added to the translation of ``start`` (m): a linear track's motion; zeros for none.
    out : ndarray, shape (4, 4) or (4, 4, N); with ``ends``: (n + 1, 4, 4) or (n + 1, 4, 4, N)
        Receives the pose, or the frames ``start @ T_0_i`` (a batch on the last axis, as ``q``).
    ends : ndarray of int, shape (n,), or None
        :attr:`Chain.frame_ends` to write every frame; None for the pose.
    cs : tuple of two ndarrays (R, N), or None
        cos and sin of the R variable rotations, in program order, for a batch (vectorised
        there); None for one pose: computed here, and ``q`` is checked to be finite.

    Returns
    -------
    bool
        False when ``q`` (one pose) holds NaN or an infinite value; ``out`` is then undefined.
    """
    if cs is None:
        for j in range(q.shape[0]):
            if not math.isfinite(q[j]):
                return False
    a0, b0, c0, p0 = start[0, 0], start[0, 1], start[0, 2], start[0, 3] + shift[0]
    a1, b1, c1, p1 = start[1, 0], start[1, 1], start[1, 2], start[1, 3] + shift[1]
    a2, b2, c2, p2 = start[2, 0], start[2, 1], start[2, 2], start[2, 3] + shift[2]
    f = 0
    r = 0
    for k in range(program.shape[0] + 1):
        if ends is not None and (k == 0 or k == ends[f - 1]):
            _put_frame(out, f, (a0, a1, a2), (b0, b1, b2), (c0, c1, c2), (p0, p1, p2))
            f += 1
        if k == program.shape[0]:
            break
        code, joint, sign, value, quarter = (program[k, 0], int(program[k, 1]), program[k, 2],
                                             program[k, 3], program[k, 4])
        if code == 2.0 or code == 3.0:  # translation along z (code 2) or x (code 3)
            if joint < 0:
                v = value
            else:
                v = q[joint] if sign == 1.0 else -q[joint]
                if value != 0.0:
                    v = v + value
            if code == 2.0:
                p0, p1, p2 = p0 + v * c0, p1 + v * c1, p2 + v * c2
            else:
                p0, p1, p2 = p0 + v * a0, p1 + v * a1, p2 + v * a2
            continue
        # rotation about z (code 0: columns a, b turn), x (code 1: columns b, c) or y (code 4:
        # columns c, a)
        if code == 0.0:
            u0, u1, u2, w0, w1, w2 = a0, a1, a2, b0, b1, b2
        elif code == 1.0:
            u0, u1, u2, w0, w1, w2 = b0, b1, b2, c0, c1, c2
        else:
            u0, u1, u2, w0, w1, w2 = c0, c1, c2, a0, a1, a2
        if quarter == 1.0:
            u0, u1, u2, w0, w1, w2 = w0, w1, w2, -u0, -u1, -u2
        elif quarter == 2.0:
            u0, u1, u2, w0, w1, w2 = -u0, -u1, -u2, -w0, -w1, -w2
        elif quarter == 3.0:
            u0, u1, u2, w0, w1, w2 = -w0, -w1, -w2, u0, u1, u2
        else:
            if joint < 0:
                c, s = math.cos(value), math.sin(value)
            elif cs is None:
                th = sign * q[joint] + value
                c, s = math.cos(th), math.sin(th)
            else:
                c, s = cs[0][r], cs[1][r]
                r += 1
            u0, u1, u2, w0, w1, w2 = (c * u0 + s * w0, c * u1 + s * w1, c * u2 + s * w2,
                                      c * w0 - s * u0, c * w1 - s * u1, c * w2 - s * u2)
        if code == 0.0:
            a0, a1, a2, b0, b1, b2 = u0, u1, u2, w0, w1, w2
        elif code == 1.0:
            b0, b1, b2, c0, c1, c2 = u0, u1, u2, w0, w1, w2
        else:
            c0, c1, c2, a0, a1, a2 = u0, u1, u2, w0, w1, w2
    if ends is None:
        _times_tail(out, (a0, a1, a2), (b0, b1, b2), (c0, c1, c2), (p0, p1, p2), tail)
    return True


def _put_frame(out, f, a, b, c, p) -> None:
    """Write the pose with rotation columns ``a``, ``b``, ``c`` and position ``p`` (each ``(x, y,
    z)``, m) as frame ``f`` of ``out`` (frames, 4, 4) or (frames, 4, 4, N): a helper of
    :func:`chain_kernel`."""
    out[f, 0, 0], out[f, 0, 1], out[f, 0, 2], out[f, 0, 3] = a[0], b[0], c[0], p[0]
    out[f, 1, 0], out[f, 1, 1], out[f, 1, 2], out[f, 1, 3] = a[1], b[1], c[1], p[1]
    out[f, 2, 0], out[f, 2, 1], out[f, 2, 2], out[f, 2, 3] = a[2], b[2], c[2], p[2]
    out[f, 3, 0], out[f, 3, 1], out[f, 3, 2], out[f, 3, 3] = 0.0, 0.0, 0.0, 1.0


def _times_tail(out, a, b, c, p, tail) -> None:
    """``out = [a b c p] @ tail``, the pose with rotation columns ``a``, ``b``, ``c`` and position
    ``p`` (each ``(x, y, z)``, m) times the constant pose ``tail`` (4, 4), into ``out`` (4, 4) or
    (4, 4, N): a helper of :func:`chain_kernel`.

    Column by column, skipping zero coefficients and multiplications by +-1 (a vendor's flange is
    a signed permutation).
    """
    for col in range(4):
        if col == 3:
            x0, x1, x2 = p[0], p[1], p[2]
        else:
            x0, x1, x2 = 0.0, 0.0, 0.0
        for row in range(3):
            t = tail[row, col]
            if t == 0.0:
                continue
            if row == 0:
                v0, v1, v2 = a[0], a[1], a[2]
            elif row == 1:
                v0, v1, v2 = b[0], b[1], b[2]
            else:
                v0, v1, v2 = c[0], c[1], c[2]
            if t == 1.0:
                x0, x1, x2 = x0 + v0, x1 + v1, x2 + v2
            elif t == -1.0:
                x0, x1, x2 = x0 - v0, x1 - v1, x2 - v2
            else:
                x0, x1, x2 = x0 + t * v0, x1 + t * v1, x2 + t * v2
        out[0, col], out[1, col], out[2, col] = x0, x1, x2
        out[3, col] = 1.0 if col == 3 else 0.0


#: :func:`chain_kernel` for one pose (Python first, compiled once single-pose calls add up).
CHAIN = Kernel(chain_kernel, (_put_frame, _times_tail))


def jacobian_kernel(F, tail, first, sign, prismatic, out) -> None:
    """Geometric Jacobian of a chain at the point ``tail`` from its frames, batch or one pose.

    The one implementation of the Jacobian: run by numpy on a batch, compiled for one pose
    (:data:`JACOBIAN`). Joint i moves about (or along) the z axis of frame ``i + first``.

    Parameters
    ----------
    F : ndarray, shape (n + 1, 4, 4) or (n + 1, 4, 4, N)
        The frames ``T_R_i``, ``i = 0..n`` (a batch on the last axis), metres.
    tail : ndarray, shape (4, 4)
        Pose of the point (TCP) in the last frame (metres).
    first : int
        0 for standard DH (joint i about ``z_{i-1}``), 1 for modified DH (about ``z_i``).
    sign : ndarray, shape (n,)
        +1 or -1 per joint: the DH variable is ``sign * q + offset``.
    prismatic : ndarray of bool, shape (n,)
    out : ndarray, shape (6, n) or (6, n, N)
        Receives rows ``(vx, vy, vz, wx, wy, wz)`` per unit joint velocity (m/s, rad/s).
    """
    n = sign.shape[0]
    e0 = F[n, 0, 0] * tail[0, 3] + F[n, 0, 1] * tail[1, 3] + F[n, 0, 2] * tail[2, 3] + F[n, 0, 3] * tail[3, 3]
    e1 = F[n, 1, 0] * tail[0, 3] + F[n, 1, 1] * tail[1, 3] + F[n, 1, 2] * tail[2, 3] + F[n, 1, 3] * tail[3, 3]
    e2 = F[n, 2, 0] * tail[0, 3] + F[n, 2, 1] * tail[1, 3] + F[n, 2, 2] * tail[2, 3] + F[n, 2, 3] * tail[3, 3]
    for i in range(n):
        a = i + first
        z0, z1, z2 = F[a, 0, 2], F[a, 1, 2], F[a, 2, 2]
        s = sign[i]
        if prismatic[i]:
            out[0, i], out[1, i], out[2, i] = z0 * s, z1 * s, z2 * s
            out[3, i], out[4, i], out[5, i] = 0.0, 0.0, 0.0
        else:
            d0, d1, d2 = e0 - F[a, 0, 3], e1 - F[a, 1, 3], e2 - F[a, 2, 3]
            out[0, i] = (z1 * d2 - z2 * d1) * s
            out[1, i] = (z2 * d0 - z0 * d2) * s
            out[2, i] = (z0 * d1 - z1 * d0) * s
            out[3, i], out[4, i], out[5, i] = z0 * s, z1 * s, z2 * s


#: :func:`jacobian_kernel` for one pose (Python first, compiled once single-pose calls add up).
JACOBIAN = Kernel(jacobian_kernel)
