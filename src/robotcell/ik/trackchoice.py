"""Fast choice of the track value for an ortho-parallel arm on a linear track.

For a target ``T_L_TCP`` the wrist centre of the arm, written in the arm's frame O (see
:mod:`robotcell.ik.opw`), moves on a straight line as the track value ``x`` changes:
``C(x) = C0 + x w`` with ``w = -R_O_R Q^T u`` (``Q`` the mounting rotation, ``u`` the track
direction); the orientation ``R_O_e`` does not change. Hence, with ``S = (0, 0, c1)`` the centre
of the shoulder circle on axis 1,

    |C(x) - S|^2 = |w|^2 x^2 + 2 (C0 - S).w x + |C0 - S|^2      (quadratic in x),

and the arm reaches the wrist centre only if the shoulder-to-wrist-centre distance is at most
``c2 + sqrt(a2^2 + c3^2)`` (stretched elbow); since the shoulder (axis 2) is ``a1`` off axis 1
and the wrist centre ``b`` off the arm plane, ``|C(x) - S|^2 <= (c2 + kappa + |a1|)^2 + b^2``.
The roots of that quadratic give, in closed form, an interval of the track value that contains
every reachable value (:func:`track_interval`).

Inside it, the choice maximises the manipulability ``|det J|`` (Yoshikawa 1985), the criterion of
:meth:`robotcell.ik.TrackRobot.ik`. For an ortho-parallel arm with a spherical wrist it has a
closed form from the wrist-centre geometry alone (the Jacobian is block triangular at the wrist
centre and ``det J`` does not depend on the reference point):

    |det J| = n * c2 * kappa * |sin(gamma)| * |sin(t5)|,

``n`` the distance of the wrist centre from axis 1 in the arm plane (0: shoulder singularity),
``gamma`` the angle between the upper arm and the line from axis 3 to the wrist centre (0 or pi:
stretched or folded elbow), ``t5`` the wrist bend (0: wrist singularity). So it is evaluated on
many track values for the price of a few arithmetic operations each, with the limits of the axes
that do not turn a full circle (axes 1, 2, 3 and 5 where they are limited) checked on the way,
in single precision (micrometres over the track: enough to choose). For an arm with a joint
coupling ``q_model = C q + offset`` (FANUC J2/J3, a parallel arm) the closed form holds for the
model's angles and is multiplied by ``|det C|``, and a coupled axis's limits are checked on its
controller value. The arm is then solved once, analytically, at the chosen value; where that has no valid branch
(a limit of axis 4 or 6) the target falls back to the sampled search of
:meth:`~robotcell.ik.TrackRobot.ik`. Every returned solution is exact and within all limits. A
target the scan does not reach at all is scanned again on a grid 8 times finer. A best value
inside a window of track values narrower than one step of the scan (1/23 of the interval by
default) can still be missed: the choice then has a lower manipulability than the sampled
search (about 1 random target in 300 loses more than 1 % on a KR 16).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.ik.analytic import analytic_solver
from robotcell.ik.limits import TWO_PI
from robotcell.ik.opw import OPWParameters
from robotcell.ik.result import IKSolutions
from robotcell.ik.track import TrackChoice, TrackRobot
from robotcell.kinematics.arm import Arm
from robotcell.kinematics.bounds import LIMIT_TOL
from robotcell.kinematics.transforms import invert, validate_pose

__all__ = ["TrackScan", "arm_manipulability", "choose_track", "manipulability", "scan_track",
           "track_interval"]

#: Within this fraction of the best manipulability, a preferred track value (the previous
#: target's on a path) wins over a larger manipulability.
PREFER_WITHIN = 0.1
#: Refinement stages per peak of the coarse scan and samples per stage.
REFINE_STAGES, REFINE = 2, 9
#: A second peak of the coarse scan is refined too when it reaches this fraction of the first.
SECOND_PEAK = 0.9
#: How much finer the second look at a target the scan did not reach is.
DENSE = 8
#: Targets per block of the scan (larger blocks: fewer numpy calls, more memory).
_BLOCK = 2048


@dataclass(frozen=True)
class TrackScan:
    """Manipulability of a batch of targets over sampled track values.

    Attributes
    ----------
    x : ndarray, shape (N, K)
        Track values (m), inside the track limits and the closed-form interval.
    manipulability : ndarray, shape (N, K)
        Best ``|det J|`` over the arm branches that reach the target there within the limits of
        axes 1, 2, 3 and 5 (m^3; 0 where none does).
    lower, upper : ndarray, shape (N,)
        The closed-form interval of :func:`track_interval`, clipped to the track limits (m);
        NaN where it is empty.
    """

    x: NDArray[np.float64]
    manipulability: NDArray[np.float64]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]


def _wrist_line(track: TrackRobot, T: NDArray[np.float64], tool: ArrayLike | None
                ) -> tuple[OPWParameters, NDArray[np.float64], NDArray[np.float64],
                           NDArray[np.float64]]:
    """``(params, R_O_e (N,3,3), C0 (N,3), w (3,))`` for targets ``T_L_TCP`` (N, 4, 4)."""
    solver = analytic_solver(track.arm)
    if solver.method != "opw":
        raise InputError("the fast track choice needs an ortho-parallel arm with a spherical wrist")
    pa = solver.params
    arm = track.arm
    tool_T = arm.tool if tool is None else validate_pose(tool, "tool")
    T_tcp_end = invert(pa.T_e_n @ arm.flange @ tool_T)
    T_O_L = invert(pa.T_R_O) @ invert(track.T_L_R0)
    T_O_e = T_O_L @ T @ T_tcp_end
    R = T_O_e[:, :3, :3]
    C0 = T_O_e[:, :3, 3] - pa.c4 * R[:, :, 2]
    w = -(T_O_L[:3, :3] @ track.direction)
    return pa, R, C0, w


def track_interval(pa: OPWParameters, C0: NDArray[np.float64], w: NDArray[np.float64]
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Closed-form interval of track values that contains every reachable one.

    Parameters
    ----------
    pa : OPWParameters
    C0 : ndarray, shape (N, 3)
        Wrist centre in O at track value 0 (m).
    w : ndarray, shape (3,)
        Its displacement in O per metre of track (unit vector).

    Returns
    -------
    lower, upper : ndarray, shape (N,)
        Roots of ``|C0 + x w - S|^2 = (c2 + kappa + |a1|)^2 + b^2`` (m); NaN where the wrist
        centre never comes that close to the shoulder.
    """
    D = C0 - np.array([0.0, 0.0, pa.c1])
    r_max = pa.c2 + math.hypot(pa.a2, pa.c3) + abs(pa.a1)
    a = float(w @ w)
    half_b = D @ w
    c = np.einsum("ij,ij->i", D, D) - (r_max * r_max + pa.b * pa.b)
    disc = half_b * half_b - a * c
    root = np.sqrt(np.where(disc >= 0, disc, np.nan))
    return (-half_b - root) / a, (-half_b + root) / a


class _Limits:
    """Limits of axes 1, 2, 3, 5 as cones on the paper's angles: ``q`` in ``[lo, hi]`` (some
    2*pi-equivalent) iff ``cos(t - mid) >= cos(half)`` for ``t = sign * q + offset``, tested on
    the (cos t, sin t) pair the geometry gives, without an arctangent."""

    def __init__(self, pa: OPWParameters, arm: Arm) -> None:
        self.cone: dict[int, tuple[float, float, float]] = {}
        lower, upper = arm.lower, arm.upper
        # A coupled axis's limit is on the controller value, not on the model angle: left to
        # the exact check after the solve.
        coupled = set() if arm.coupling is None else set(arm.coupling.changed_axes())
        for j in (0, 1, 2, 4):
            if upper[j] - lower[j] >= TWO_PI or j in coupled:
                continue
            mid = pa.signs[j] * 0.5 * (lower[j] + upper[j]) + pa.offsets[j]
            self.cone[j] = (math.cos(mid), math.sin(mid), math.cos(0.5 * (upper[j] - lower[j])))
        # Coupled axes among 1..3 whose controller value depends on model joints 1..3 only
        # (FANUC J2/J3, a parallel arm): q_j = row . q_model[:3] + const, checked on angles.
        self.rows: list[tuple[int, NDArray[np.float64], float, float, float]] = []
        c = arm.coupling
        if c is not None and c.matrix.shape[0] == c.matrix.shape[1]:
            inv = np.linalg.inv(c.matrix)
            off = inv @ (np.zeros(6) if c.offset is None else c.offset)
            for j in sorted(coupled & {0, 1, 2}):
                if np.any(inv[j, 3:] != 0) or upper[j] - lower[j] >= TWO_PI:
                    continue
                self.rows.append((j, inv[j, :3], -float(off[j]), float(lower[j]),
                                  float(upper[j])))
        self.signs, self.offsets = pa.signs[:3], pa.offsets[:3]

    def ok_coupled(self, cs: tuple[tuple[NDArray[np.float64], NDArray[np.float64]], ...]
                   ) -> NDArray[np.bool_] | bool:
        """Coupled axes within limits, given (cos, sin) of the paper's angles t1, t2, t3."""
        if not self.rows:
            return True
        qm = [self.signs[j] * (np.arctan2(sv, cv) - self.offsets[j])
              for j, (cv, sv) in enumerate(cs)]
        ok: NDArray[np.bool_] | bool = True
        for _, row, const, lo, hi in self.rows:
            q = row[0] * qm[0] + row[1] * qm[1] + row[2] * qm[2] + const
            ok = ok & (np.mod(q - lo + LIMIT_TOL, TWO_PI) <= hi - lo + 2 * LIMIT_TOL)
        return ok

    def ok(self, j: int, c: NDArray[np.float64], s: NDArray[np.float64]
           ) -> NDArray[np.bool_] | bool:
        if j not in self.cone:
            return True
        cm, sm, ch = self.cone[j]
        return c * cm + s * sm >= ch

    def ok_either_wrist(self, c: NDArray[np.float64], h: NDArray[np.float64]
                        ) -> NDArray[np.bool_] | bool:
        """Axis 5 within limits for ``t5`` or ``-t5`` (the two wrist flips), ``h = |sin t5|``."""
        if 4 not in self.cone:
            return True
        cm, sm, ch = self.cone[4]
        return c * cm + h * abs(sm) >= ch


def _manipulability(pa: OPWParameters, R: NDArray[np.float64], C: NDArray[np.float64],
                    limits: _Limits) -> NDArray[np.float64]:
    """Best ``|det J|`` over the arm branches for wrist centres ``C`` (3, N, K) (m^3)."""
    kappa = math.hypot(pa.a2, pa.c3)
    cpsi, spsi = pa.c3 / kappa, pa.a2 / kappa
    cx, cy, cz = C
    b = pa.b
    rho2 = cx * cx + cy * cy
    n2 = rho2 - b * b
    n = np.sqrt(np.maximum(n2, 0.0))
    inv = 1.0 / np.maximum(rho2, 1e-300)
    Z = cz - pa.c1
    R02, R12, R22 = (R[:, i, 2][:, None] for i in range(3))
    denom = 1.0 / (2.0 * pa.c2 * kappa)
    base = pa.c2 * pa.c2 + kappa * kappa
    best = np.zeros(cx.shape)
    for sh in (0, 1):
        if sh == 0:
            c1, s1, X = (cx * n + cy * b) * inv, (cy * n - cx * b) * inv, n - pa.a1
        else:
            c1, s1, X = -(cx * n - cy * b) * inv, -(cy * n + cx * b) * inv, -(n + pa.a1)
        s_2 = X * X + Z * Z
        K = (s_2 - base) * denom
        reach = (n2 >= 0) & (np.abs(K) <= 1.0) & limits.ok(0, c1, s1)
        S = np.sqrt(np.maximum(1.0 - K * K, 0.0))
        M02 = c1 * R02 + s1 * R12
        wz = pa.c2 + kappa * K
        kS = kappa * S
        # Shared by both elbows (sphi = +-S): the norm of (cu, su) and the products below.
        inv_norm = 1.0 / np.maximum(np.sqrt(s_2 * (kS * kS + wz * wz)), 1e-300)
        kSX, kSZ = kS * X * inv_norm, kS * Z * inv_norm
        wzX, wzZ = wz * X * inv_norm, wz * Z * inv_norm
        Kc, Ks, Sc, Ss = K * cpsi, K * spsi, S * cpsi, S * spsi
        nS = n * S
        for sg in (1.0, -1.0):
            c2, s2 = wzZ + sg * kSX, wzX - sg * kSZ
            c3, s3 = Kc + sg * Ss, sg * Sc - Ks
            r22 = (s2 * c3 + c2 * s3) * M02 + (c2 * c3 - s2 * s3) * R22   # cos(t5)
            h = np.sqrt(np.maximum(1.0 - r22 * r22, 0.0))
            ok = (reach & limits.ok(1, c2, s2) & limits.ok(2, c3, s3)
                  & limits.ok_either_wrist(r22, h))
            if limits.rows:
                ok = ok & limits.ok_coupled(((c1, s1), (c2, s2), (c3, s3)))
            best = np.maximum(best, np.where(ok, nS * h, 0.0))
    return best * (pa.c2 * kappa)


def scan_track(track: TrackRobot, T: ArrayLike, tool: ArrayLike | None = None,
               samples: int = 24) -> TrackScan:
    """Manipulability of every target on ``samples`` track values of its reachable interval.

    Parameters
    ----------
    track : TrackRobot
        With an ortho-parallel arm and finite track limits.
    T : array_like, shape (N, 4, 4)
        ``T_L_TCP`` (m).
    tool : array_like, shape (4, 4), optional
        ``T_F_TCP`` instead of the arm's default tool (m).
    samples : int
        Track values per target (>= 2), evenly spaced over the interval.

    Returns
    -------
    TrackScan
    """
    arr = validate_pose(T, "target pose").reshape(-1, 4, 4)
    return _scan(track, *_wrist_line(track, arr, tool), samples)


def _scan(track: TrackRobot, pa: OPWParameters, R: NDArray[np.float64], C0: NDArray[np.float64],
          w: NDArray[np.float64], samples: int) -> TrackScan:
    lo, hi = track_interval(pa, C0, w)
    lo, hi = np.maximum(lo, track.lower), np.minimum(hi, track.upper)
    empty = ~(lo <= hi)
    lo, hi = np.where(empty, np.nan, lo), np.where(empty, np.nan, hi)
    x = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, samples)
    return TrackScan(x, _score(track, pa, R, C0, w, x), lo, hi)


def _score(track: TrackRobot, pa: OPWParameters, R: NDArray[np.float64],
           C0: NDArray[np.float64], w: NDArray[np.float64], x: NDArray[np.float64]
           ) -> NDArray[np.float64]:
    limits = _Limits(pa, track.arm)
    out = np.empty(x.shape)
    # Single precision (7 digits: micrometres over the track) is plenty to choose the value;
    # the arm is then solved in double precision at the chosen one.
    R32, C32, w32 = R.astype(np.float32), C0.astype(np.float32), w.astype(np.float32)
    for s in range(0, x.shape[0], _BLOCK):  # blocks of targets bound the temporaries' memory
        xb = x[s:s + _BLOCK].astype(np.float32)
        C = C32[s:s + _BLOCK].T[:, :, None] + w32[:, None, None] * xb[None]  # (3, N, K)
        out[s:s + _BLOCK] = _manipulability(pa, R32[s:s + _BLOCK], C, limits)
    return np.where(np.isnan(x), 0.0, out)


def _refine(track: TrackRobot, pa: OPWParameters, R: NDArray[np.float64],
            C0: NDArray[np.float64], w: NDArray[np.float64], centre: NDArray[np.float64],
            half: NDArray[np.float64], lo: NDArray[np.float64], hi: NDArray[np.float64]
            ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Grids of REFINE values around ``centre`` (M,), +-``half``, shrinking REFINE_STAGES
    times around the best; returns every value tried and its score, each (M, stages * REFINE)."""
    xs, ms = [], []
    for _ in range(REFINE_STAGES):
        fine = np.clip(centre[:, None] + half[:, None] * np.linspace(-1.0, 1.0, REFINE),
                       lo[:, None], hi[:, None])
        fine = np.where(np.isnan(fine), centre[:, None], fine)
        mf = _score(track, pa, R, C0, w, fine)
        xs.append(fine)
        ms.append(mf)
        centre = fine[np.arange(fine.shape[0]), np.argmax(mf, axis=1)]
        half = half * (2.0 / (REFINE - 1))
    return np.concatenate(xs, axis=1), np.concatenate(ms, axis=1)


def _scatter_rows(a: NDArray[np.float64], rows: NDArray[np.int_], n: int, fill: float
                  ) -> NDArray[np.float64]:
    out = np.full((n, a.shape[1]), fill)
    out[rows] = a
    return out


def choose_track(track: TrackRobot, T: ArrayLike, tool: ArrayLike | None = None,
                 samples: int = 24, prefer: ArrayLike | None = None) -> TrackChoice:
    """Choose the track value per target and solve the arm there (vectorised over targets).

    The criterion: the largest manipulability ``|det J|`` over the arm branches within the
    limits (as :meth:`TrackRobot.ik`), searched on ``samples`` values of the closed-form
    interval of :func:`track_interval` and refined on ``samples`` values between the best one's
    neighbours. With ``prefer`` (e.g. the previous target's value on a path), the value nearest
    to it among those within :data:`PREFER_WITHIN` of the best manipulability. Targets where
    the chosen value has no valid branch are searched again by :meth:`TrackRobot.ik`.

    Parameters
    ----------
    track : TrackRobot
        Ortho-parallel arm, finite track limits.
    T : array_like, shape (..., 4, 4)
        ``T_L_TCP`` (m).
    tool : array_like, shape (4, 4), optional
        ``T_F_TCP`` instead of the arm's default tool (m).
    samples : int
        Track values per search stage (>= 3).
    prefer : array_like, shape (...), optional
        Preferred track values (m).

    Returns
    -------
    TrackChoice
        Solutions ``(..., 8, 7)`` at the chosen values; ``manipulability`` is ``|det J|`` of the
        best valid branch there (m^3; 0 where nothing is reachable).
    """
    track.check_choice(samples)
    arr = validate_pose(T, "target pose")
    batch = arr.shape[:-2]
    flat = arr.reshape(-1, 4, 4)
    pa, R, C0, w = _wrist_line(track, flat, tool)
    scan = _scan(track, pa, R, C0, w, samples)
    m = scan.manipulability
    n_t = flat.shape[0]
    rows = np.arange(n_t)
    step = np.nan_to_num((scan.upper - scan.lower) / (samples - 1))
    k1 = np.argmax(m, axis=1)
    # A second peak: the best local maximum outside the first's neighbours, refined only where
    # it comes within SECOND_PEAK of the first (a second mode that could win after refinement).
    pad = np.pad(m, ((0, 0), (1, 1)), constant_values=-1.0)
    local = (m >= pad[:, :-2]) & (m >= pad[:, 2:])
    near1 = np.abs(np.arange(samples) - k1[:, None]) <= 1
    m2 = np.where(local & ~near1, m, -1.0)
    k2 = np.argmax(m2, axis=1)
    second = np.nonzero(m2[rows, k2] >= SECOND_PEAK * m[rows, k1])[0]
    # Both peaks refined together: one evaluation per stage (fewer numpy calls per batch).
    sub = np.concatenate([rows, second])
    k = np.concatenate([k1, k2[second]])
    xr, mr = _refine(track, pa, R[sub], C0[sub], w, np.nan_to_num(scan.x[sub, k]), step[sub],
                     scan.lower[sub], scan.upper[sub])
    xs, ms = [scan.x, xr[:n_t]], [m, mr[:n_t]]
    if second.size:
        xs.append(_scatter_rows(xr[n_t:], second, n_t, np.nan))
        ms.append(_scatter_rows(mr[n_t:], second, n_t, -1.0))
    xs_all, ms_all = np.concatenate(xs, axis=1), np.concatenate(ms, axis=1)
    if prefer is None:
        x = xs_all[rows, np.argmax(ms_all, axis=1)]
    else:
        p = np.broadcast_to(np.asarray(prefer, dtype=float), batch).reshape(-1)
        near = np.where(ms_all >= (1.0 - PREFER_WITHIN) * ms_all.max(axis=1, keepdims=True),
                        np.abs(xs_all - p[:, None]), np.inf)
        x = xs_all[rows, np.argmin(near, axis=1)]
    found = ms_all.max(axis=1) > 0
    # Nothing found on the scan although the interval is not empty: look again on a grid
    # DENSE times finer (a window of reach narrower than one step, or truly out of reach).
    again = np.nonzero(~found & ~np.isnan(scan.lower))[0]
    if again.size:
        sub = _scan(track, pa, R[again], C0[again], w, DENSE * samples)
        k = np.argmax(sub.manipulability, axis=1)
        hit = sub.manipulability[np.arange(again.size), k] > 0
        x[again[hit]] = sub.x[np.arange(again.size), k][hit]
        found[again[hit]] = True
    # Still nothing: the closed-form interval is empty (out of reach at every track value) or
    # no value reaches within the limits of axes 1, 2, 3, 5.
    x = np.where(found, x, np.nan_to_num(scan.lower, nan=track.lower))
    sol = _solve_at(track, flat, x, tool)
    retry = ~np.any(sol.valid, axis=-1) & found
    if np.any(retry):
        again = track.ik(flat[retry], samples=65, tool=tool)
        x[retry] = again.track
        sol = _replace_rows(sol, retry, again.solutions)
    return TrackChoice(_reshape(sol, batch), x.reshape(batch),
                       _best_valid(track.arm, sol).reshape(batch))


def manipulability(pa: OPWParameters, q: ArrayLike) -> NDArray[np.float64]:
    """``|det J|`` of an ortho-parallel arm in closed form (m^3).

    Parameters
    ----------
    pa : OPWParameters
    q : array_like, shape (..., 6)
        Controller axis values (rad); NaN gives NaN.

    Returns
    -------
    ndarray, shape (...)
        ``n * c2 * kappa * |sin(gamma)| * |sin(t5)|`` (see the module docstring); equal to
        ``|det robot.jacobian(q)|``.
    """
    th = np.asarray(q, dtype=float) * pa.signs + pa.offsets
    t2, t23, t5 = th[..., 1], th[..., 1] + th[..., 2], th[..., 4]
    fx = pa.a2 * np.cos(t23) + pa.c3 * np.sin(t23)  # axis 3 to the wrist centre, in the plane
    fz = pa.c3 * np.cos(t23) - pa.a2 * np.sin(t23)
    n = np.abs(pa.a1 + pa.c2 * np.sin(t2) + fx)
    cross = np.abs(np.sin(t2) * fz - np.cos(t2) * fx)  # kappa * |sin(gamma)|
    return n * pa.c2 * cross * np.abs(np.sin(t5))


def arm_manipulability(arm: Arm, q: ArrayLike) -> NDArray[np.float64]:
    """``|det J|`` of an ortho-parallel ``arm`` at controller values ``q`` (..., 6) (m^3).

    The closed form of :func:`manipulability` on the model's joint values; for an arm with a
    joint coupling ``q_model = C q + offset`` (square ``C``) it is multiplied by ``|det C|``
    (``J = J_model C``). Equal to ``|det arm.jacobian(q)|``.
    """
    pa = analytic_solver(arm).params
    c = arm.coupling
    if c is None:
        return manipulability(pa, q)
    if c.matrix.shape[0] != c.matrix.shape[1]:  # passive joints: no closed form here
        return np.abs(np.linalg.det(arm.jacobian(np.nan_to_num(q))))
    return manipulability(pa, c.to_model(q)) * abs(float(np.linalg.det(c.matrix)))


def _best_valid(arm: Arm, sol: IKSolutions) -> NDArray[np.float64]:
    """``|det J|`` of the best valid branch of track solutions ``(N, 8, 7)`` (0 if none).

    The two wrists of an arm configuration (branches ``2k``, ``2k + 1``) have the same value."""
    valid = sol.valid[..., ::2] | sol.valid[..., 1::2]
    m = np.nan_to_num(arm_manipulability(arm, sol.q[..., ::2, 1:]))
    return np.where(valid, m, 0.0).max(axis=-1)


def _solve_at(track: TrackRobot, T: NDArray[np.float64], x: NDArray[np.float64],
              tool: ArrayLike | None) -> IKSolutions:
    """:meth:`TrackRobot.ik_at` for validated targets (N, 4, 4) and values (N,) in the limits."""
    T_R = T.copy()  # T_R_TCP = T_L_R(x)^-1 T_L_TCP: the base only translates along u
    Q = track.T_L_R0[:3, :3]
    T_R[:, :3, :3] = Q.T @ T[:, :3, :3]
    T_R[:, :3, 3] = (T[:, :3, 3] - track.T_L_R0[:3, 3] - x[:, None] * track.direction) @ Q
    sol = analytic_solver(track.arm).solve(T_R, tool)
    xcol = np.broadcast_to(x[:, None, None], sol.q.shape[:-1] + (1,))
    return IKSolutions(np.concatenate([xcol, sol.q], axis=-1), sol.valid, sol.reachable,
                       sol.method, sol.reach_error)


def _replace_rows(sol: IKSolutions, rows: NDArray[np.bool_], new: IKSolutions) -> IKSolutions:
    q, valid, reach = sol.q.copy(), sol.valid.copy(), sol.reachable.copy()
    q[rows], valid[rows], reach[rows] = new.q, new.valid, new.reachable
    err = None
    if sol.reach_error is not None and new.reach_error is not None:
        err = sol.reach_error.copy()
        err[rows] = new.reach_error
    return IKSolutions(q, valid, reach, sol.method, err)


def _reshape(sol: IKSolutions, batch: tuple[int, ...]) -> IKSolutions:
    err = None if sol.reach_error is None else sol.reach_error.reshape(batch + (8,))
    return IKSolutions(sol.q.reshape(batch + sol.q.shape[-2:]), sol.valid.reshape(batch + (8,)),
                       sol.reachable.reshape(batch + (8,)), sol.method, err)
