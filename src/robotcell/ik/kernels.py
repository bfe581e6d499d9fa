"""The compiled analytic IK: one scalar kernel per structure, run for one pose and for batches.

Each solver is written once, for one pose, in numba's nopython mode: the ortho-parallel arm
(:mod:`robotcell.ik.opw`, Brandstoetter et al. 2014), the Universal-Robots-type arm
(:mod:`robotcell.ik.ur`) and the 4-axis palletizer (:mod:`robotcell.ik.palletizer`); those
modules describe the methods and derive the parameters. :func:`solve_poses` loops over the poses
of a batch in compiled code (a single pose is a batch of one): it moves each target into the
solver's frame, solves every branch, applies the 2*pi rule and the joint limits of
:class:`robotcell.ik.limits.JointFolder` and the exact-branch rule of
:class:`robotcell.ik.result.IKSolutions`. :func:`choose_poses` does the same for an
ortho-parallel arm on a linear track after choosing the track value in closed form
(:mod:`robotcell.ik.trackchoice` describes the method), with :func:`scan_rows`,
:func:`wrist_rows`, :func:`interval_rows`, :func:`manipulability_rows` and
:func:`best_valid_rows` for its parts.

This module is imported when a solver is built (loading numba takes about 0.3 s, the cached
machine code about 0.3 s more; the first process after an install compiles it, and every process
where numba can write no cache: :func:`robotcell.kinematics.jit.compiled`). It holds every
function its kernels call and takes every tolerance as an argument (:func:`pack`): numba's cache
notices changes of this file only.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from robotcell.kinematics.jit import compiled

__all__ = ["FOLD_CHECK", "FOLD_DOWN", "FOLD_NONE", "FOLD_UP", "METHODS", "best_valid_rows",
           "cfg_params", "choose_poses", "exact_rows", "fold_modes", "fold_rows", "interval_rows",
           "manipulability_rows", "opw_params", "pack", "palletizer_params", "scan_rows",
           "solve_poses", "track_config", "ur_params", "wrist_rows"]

TWO_PI = 2.0 * math.pi
#: Codes of the structures in :func:`pack`.
METHODS = {"opw": 0, "ur": 1, "palletizer": 2}
#: Per joint, how :func:`fold_rows` treats it: not at all (its limits hold a whole turn), fold a
#: value above the upper limit down by 2*pi, fold a value below the lower limit up, only check.
FOLD_NONE, FOLD_DOWN, FOLD_UP, FOLD_CHECK = 0, 1, 2, 3

# Layout of the configuration array of pack(): header, tolerances, T_O_R, limits, parameters.
_METHOD, _N, _BRANCHES, _FINISH = 0, 1, 2, 3
_LIMIT_TOL, _REACH_TOL, _EXACT_TOL, _SINGULAR_TOL, _ROUND, _LEVEL_TOL, _COS_TOL, _AXIS_TOL = range(4, 12)
_T_O_R = 12
_LIMITS = 28


def fold_modes(lower: NDArray[np.float64], upper: NDArray[np.float64]) -> NDArray[np.float64]:
    """The :func:`fold_rows` mode of each revolute joint with limits ``lower``, ``upper`` (rad).

    The rule of :class:`robotcell.ik.limits.JointFolder`: a joint whose limits hold all of
    ``(-pi, pi]`` needs nothing; a lower limit below ``-pi`` folds down, else an upper limit above
    ``pi`` folds up; otherwise the value is only checked.
    """
    modes = np.full(len(lower), float(FOLD_CHECK))
    for j, (lo, hi) in enumerate(zip(lower, upper)):
        if lo <= -math.pi and hi >= math.pi:
            modes[j] = FOLD_NONE
        elif lo < -math.pi:
            modes[j] = FOLD_DOWN
        elif hi > math.pi:
            modes[j] = FOLD_UP
    return modes


def pack(method: str, params: NDArray[np.float64], T_O_R: NDArray[np.float64],
         lower: NDArray[np.float64], upper: NDArray[np.float64], modes: NDArray[np.float64],
         finish: bool, tolerances: dict[str, float]) -> NDArray[np.float64]:
    """The configuration array of :func:`solve_poses` for one solver.

    Parameters
    ----------
    method : {"opw", "ur", "palletizer"}
    params : ndarray
        The structure's parameters in the order of its ``*_params`` (see the kernels below).
    T_O_R : ndarray, shape (4, 4)
        Pose of the robot base frame R in the solver's frame O (m).
    lower, upper : ndarray, shape (n,)
        Limits of the joint values the kernel returns (rad); with ``modes`` the 2*pi rule.
    modes : ndarray, shape (n,)
        :func:`fold_modes` of the limits (or :data:`FOLD_NONE` for columns not to check).
    finish : bool
        Fold, check the limits and keep the exact branches in :func:`solve_poses` (False when a
        coupling maps the kernel's values first).
    tolerances : dict
        ``LIMIT_TOL``, ``REACH_TOL``, ``EXACT_TOL``, ``SINGULAR_TOL``, ``ROUND``, ``LEVEL_TOL``,
        ``COS_TOL``, ``AXIS_TOL`` (rad, m): passed at run time, never frozen into the cache.
    """
    n = len(lower)
    head = [METHODS[method], n, 4 if method == "palletizer" else 8, 1.0 if finish else 0.0]
    tol = [tolerances[k] for k in ("LIMIT_TOL", "REACH_TOL", "EXACT_TOL", "SINGULAR_TOL", "ROUND",
                                   "LEVEL_TOL", "COS_TOL", "AXIS_TOL")]
    return np.concatenate([np.array(head + tol, dtype=float), np.ravel(T_O_R), lower, upper,
                           modes, np.asarray(params, dtype=float)])


# -- angles ---------------------------------------------------------------------------------------
@compiled
def _wrap(a: float) -> float:
    """The equivalent of ``a`` in ``(-pi, pi]`` (rad), as :func:`robotcell.ik.limits.wrap_to_pi`."""
    return a - TWO_PI * np.ceil((a - math.pi) * (1.0 / TWO_PI))


@compiled
def _angle(sign: float, offset: float, c: float, s: float, y: float, x: float) -> float:
    """Controller value ``sign * (atan2(y, x) - offset)`` in ``(-pi, pi]`` by one atan2: the pair
    ``(y, x)`` (any positive scale) is turned by ``-offset`` (``c``, ``s`` its cosine and sine),
    mirrored for sign -1."""
    if offset != 0.0:
        y, x = y * c - x * s, x * c + y * s
    return math.atan2(-y if sign < 0 else y, x)


@compiled
def _clamp_circular(q: float, lo: float, hi: float, tol: float) -> float:
    """The 2*pi-equivalent of ``q`` inside ``[lo, hi]`` up to ``tol``, else the nearer limit
    (circularly)."""
    up = q + TWO_PI * np.ceil((lo - tol - q) * (1.0 / TWO_PI))
    if up <= hi + tol:
        return up
    return lo if abs(_wrap(q - lo)) <= abs(_wrap(q - hi)) else hi


@compiled
def _excess(d: float, rnd: float) -> float:
    """The square of an excess distance ``d`` (m), 0 up to the rounding ``rnd``."""
    return d * d if d > rnd else 0.0


# -- ortho-parallel arm with a spherical wrist ----------------------------------------------------
def opw_params(a1, a2, b, c1, c2, c3, c4, signs, offsets) -> NDArray[np.float64]:
    """Parameters of :func:`_opw` (lengths in m, signs, offsets in rad)."""
    return np.concatenate([[a1, a2, b, c1, c2, c3, c4], _angles(signs, offsets)])


def _angles(signs, offsets) -> NDArray[np.float64]:
    offsets = np.asarray(offsets, dtype=float)
    return np.concatenate([signs, offsets, np.cos(offsets), np.sin(offsets)])


@compiled
def _opw(cfg, p, R, P, ref, has_ref, q, err, reach) -> None:
    """All 8 branches of an ortho-parallel arm for the target ``R``, ``P`` in O (see
    :mod:`robotcell.ik.opw`): controller values into ``q`` (8, 6), NaN where the branch does not
    reach; the wrist centre's distance outside the reach into ``err`` (8,); ``reach`` (8,).

    Branch ``k = 4 * shoulder + 2 * elbow + wrist``: shoulder 1 = wrist centre behind axis 1,
    elbow 1 = behind the line of axes 2 and 3, wrist 1 = negative paper angle t5. Where axis 1 is
    free (wrist centre on it) it takes the reference's value (behind: + pi), else the one that puts
    axis 6 in the arm plane, inside its limits; where axis 4 is free (wrist singularity) it keeps
    the reference's value, else 0 of the paper (:func:`_opw_wrist`).
    """
    a1, a2, b, c1_, c2, c3, c4 = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
    ang = p[7:]
    sing, reach_tol = cfg[_SINGULAR_TOL], cfg[_REACH_TOL]
    kappa = math.hypot(a2, c3)
    cpsi, spsi = c3 / kappa, a2 / kappa
    cx = P[0] - c4 * R[0][2]
    cy = P[1] - c4 * R[1][2]
    cz = P[2] - c4 * R[2][2]
    rho2 = cx * cx + cy * cy
    # Rounding of the wrist centre and of the lengths: excesses below it count as 0.
    rnd = cfg[_ROUND] * 2 * (abs(c4) + abs(a1) + abs(b) + abs(c1_) + c2 + kappa)
    # The wrist centre must not be nearer to axis 1 than the lateral offset |b| (Puma type).
    err_sh = _excess(abs(b) - math.sqrt(rho2), rnd)
    n = math.sqrt(max(rho2 - b * b, 0.0))
    axial = rho2 < sing * sing
    inv = 1.0 / (1.0 if axial else rho2)
    Z = cz - c1_
    denom = 1.0 / (2.0 * c2 * kappa)
    base = c2 * c2 + kappa * kappa
    q1_free = 0.0
    if axial:
        q1_free = ref[0] if has_ref else ang[0] * math.atan2(R[1][2], R[0][2])
    straight_ref = ang[3] * ref[3] + ang[9] if has_ref else 0.0
    for sh in range(2):
        cs1, sn1, X = _opw_shoulder(sh, cx, cy, n, b, inv, a1)
        if axial:
            lo1, hi1 = cfg[_LIMITS], cfg[_LIMITS + 6]
            t1 = ang[0] * _clamp_circular(q1_free + sh * math.pi, lo1, hi1, cfg[_LIMIT_TOL]) + ang[6]
            cs1, sn1 = math.cos(t1), math.sin(t1)
        s_2 = X * X + Z * Z
        s = math.sqrt(s_2)
        # The wrist centre must lie between the folded and the stretched elbow.
        e = math.sqrt(err_sh + _excess(max(s - (c2 + kappa), abs(c2 - kappa) - s), rnd))
        ok = e <= reach_tol
        K = min(max((s_2 - base) * denom, -1.0), 1.0)
        S = math.sqrt(1.0 - K * K)
        M = _arm_plane_rows(cs1, sn1, R)
        wz = c2 + kappa * K
        t1q = _angle(ang[0], ang[6], ang[12], ang[18], sn1, cs1)
        for el in range(2):
            sphi = S if el == 0 else -S
            cs3 = K * cpsi + sphi * spsi
            sn3 = sphi * cpsi - K * spsi
            wx = kappa * sphi
            cu = wx * X + wz * Z
            su = wz * X - wx * Z
            norm = math.sqrt(s_2 * (wx * wx + wz * wz))
            flat = norm < 1e-300
            inv_norm = 1.0 / (1.0 if flat else norm)
            cs2 = 1.0 if flat else cu * inv_norm
            sn2 = su * inv_norm
            k = 4 * sh + 2 * el
            t2q = _angle(ang[1], ang[7], ang[13], ang[19], sn2, cs2)
            t3q = _angle(ang[2], ang[8], ang[14], ang[20], sn3, cs3)
            cs23 = (cs2 * cs3 - sn2 * sn3, sn2 * cs3 + cs2 * sn3)
            _opw_wrist(q, k, ang, (t1q, t2q, t3q), M, R, cs23, sing, (has_ref, straight_ref))
            reach[k] = reach[k + 1] = ok
            err[k] = err[k + 1] = e


@compiled
def _opw_shoulder(sh, cx, cy, n, b, inv, a1):
    """``(cos t1, sin t1, X)`` of an ortho-parallel arm for the wrist centre ``(cx, cy)`` in O:
    shoulder ``sh`` 0 (wrist centre in front of axis 1) or 1 (behind), ``n`` its distance from
    axis 1 in the arm plane, ``inv`` the inverse of ``cx^2 + cy^2`` (the caller's choice where
    that is 0); ``X`` the wrist centre's distance in front of axis 2 (m)."""
    if sh == 0:
        return (cx * n + cy * b) * inv, (cy * n - cx * b) * inv, n - a1
    return -(cx * n - cy * b) * inv, -(cy * n + cx * b) * inv, -(n + a1)


@compiled
def _arm_plane_rows(cs1, sn1, R):
    """The first two rows of ``Rz(t1)^T R`` (``cs1``, ``sn1`` the cosine and sine of t1): the
    target orientation ``R`` (3x3) seen from the arm plane, ``(M00, M01, M02, M10, M11, M12)``."""
    return (cs1 * R[0][0] + sn1 * R[1][0], cs1 * R[0][1] + sn1 * R[1][1],
            cs1 * R[0][2] + sn1 * R[1][2], cs1 * R[1][0] - sn1 * R[0][0],
            cs1 * R[1][1] - sn1 * R[0][1], cs1 * R[1][2] - sn1 * R[0][2])


@compiled(inline=True)
def _opw_wrist(q, k, ang, q123, M, R, cs23, sing, ref4) -> None:
    """Branch ``k`` of :func:`_opw` and its flipped wrist ``k + 1`` (t4 + pi, -t5, t6 + pi) into
    ``q`` (8, 6): the controller values ``q123`` of axes 1-3 and those of axes 4-6 for the target
    ``R`` (3x3) seen from the arm plane ``M`` (:func:`_arm_plane_rows`), ``cs23`` (cos, sin) of
    the paper's t2 + t3. At the wrist singularity (``sin t5`` below ``sing``) axis 4 takes the
    paper's angle of the reference's axis 4 when ``ref4`` ``(has_ref, that angle)`` has one,
    else 0 of the paper; axis 6 takes the rest."""
    has_ref, straight_ref = ref4
    c23, s23 = cs23
    M00, M01, M02, M10, M11, M12 = M
    r02 = c23 * M02 - s23 * R[2][2]
    r22 = s23 * M02 + c23 * R[2][2]
    r00 = c23 * M00 - s23 * R[2][0]
    r01 = c23 * M01 - s23 * R[2][1]
    h = math.sqrt(r02 * r02 + M12 * M12)
    straight = h < sing
    inv_h = 1.0 / (1.0 if straight else h)
    cs4 = r02 * inv_h
    sn4 = M12 * inv_h
    if straight:
        if has_ref:  # axis 4 keeps the reference's value, axis 6 takes the rest
            cs4, sn4 = math.cos(straight_ref), math.sin(straight_ref)
        else:
            cs4 = 1.0
    n6, d6 = cs4 * M10 - sn4 * r00, cs4 * M11 - sn4 * r01
    q[k, 0], q[k, 1], q[k, 2] = q123
    q[k, 3] = _angle(ang[3], ang[9], ang[15], ang[21], sn4, cs4)
    q[k, 4] = _angle(ang[4], ang[10], ang[16], ang[22], h, r22)
    q[k, 5] = _angle(ang[5], ang[11], ang[17], ang[23], n6, d6)
    q[k + 1, 0], q[k + 1, 1], q[k + 1, 2] = q123
    q[k + 1, 3] = _angle(ang[3], ang[9], ang[15], ang[21], -sn4, -cs4)
    q[k + 1, 4] = _angle(ang[4], ang[10], ang[16], ang[22], -h, r22)
    q[k + 1, 5] = _angle(ang[5], ang[11], ang[17], ang[23], -n6, -d6)


# -- Universal-Robots-type arm --------------------------------------------------------------------
def ur_params(d1, a2, a3, d4, d5, d6, signs, offsets) -> NDArray[np.float64]:
    """Parameters of :func:`_ur` (canonical lengths in m, signs, offsets in rad)."""
    return np.concatenate([[d1, a2, a3, d4, d5, d6], _angles(signs, offsets)])


@compiled
def _free_t6(c0, c1, u0, u1, w0, w1, target, d5, rmin, rmax) -> float:
    """Canonical t6 (rad) at the wrist singularity: nearest to ``target`` with axes 2/3 in reach.

    At ``sin t5 = 0`` axis 6 is parallel to axes 2-4 and only the sum of the angles is fixed. Axis
    6 then moves the wrist-1 point on a circle of radius ``d5`` around the planar position ``c``
    of the wrist-2 point: ``p(t6) = c + d5 (sin t6 u + cos t6 w)`` (``u``, ``w`` the planar
    directions of the flange's x and y axes). The planar problem of axes 2 and 3 is solvable where
    ``rmin <= |p| <= rmax``, an arc of angles ``|theta| in [ta, tb]`` around the direction of ``c``;
    the target angle is moved onto it (onto its nearest point to the reach when it is empty).
    """
    cn = math.hypot(c0, c1)
    if not cn > 0:
        return target
    ex, ey = c0 / cn, c1 / cn
    lo = (rmin * rmin - cn * cn - d5 * d5) / (2 * d5 * cn)
    hi = (rmax * rmax - cn * cn - d5 * d5) / (2 * d5 * cn)
    ta = math.acos(min(max(hi, -1.0), 1.0))
    tb = math.acos(min(max(lo, -1.0), 1.0))
    st, ct = math.sin(target), math.cos(target)
    vx, vy = st * u0 + ct * w0, st * u1 + ct * w1
    th = math.atan2(ex * vy - ey * vx, ex * vx + ey * vy)
    th = (-1.0 if th < 0 else 1.0) * min(max(abs(th), ta), tb)
    vx, vy = math.cos(th) * ex - math.sin(th) * ey, math.sin(th) * ex + math.cos(th) * ey
    return math.atan2(vx * u0 + vy * u1, vx * w0 + vy * w1)


@compiled
def _ur(cfg, p, R, P, ref, has_ref, q, err, reach) -> None:
    """All 8 branches of a UR-type arm for the target ``R_O_6``, ``p_O_6`` (see
    :mod:`robotcell.ik.ur`), as :func:`_opw`. Branch ``k = 4 * shoulder + 2 * elbow + wrist``:
    shoulder 1 = second solution of axis 1, wrist 1 = negative canonical t5, elbow 1 = negative
    canonical t3. At the wrist singularity axis 6 is chosen nearest to the reference's (default:
    canonical 0) among the values that keep axes 2 and 3 in reach.
    """
    d1, a2, a3, d4, d5, d6 = p[0], p[1], p[2], p[3], p[4], p[5]
    ang = p[6:]
    reach_tol = cfg[_REACH_TOL]
    X0, X1, X2 = R[0][0], R[1][0], R[2][0]
    Y0, Y1, Y2 = R[0][1], R[1][1], R[2][1]
    Z0, Z1, Z2 = R[0][2], R[1][2], R[2][2]
    p5x = P[0] - d6 * Z0
    p5y = P[1] - d6 * Z1
    p5z = P[2] - d6 * Z2
    r2 = p5x * p5x + p5y * p5y
    rmax, rmin = abs(a2) + abs(a3), abs(abs(a2) - abs(a3))
    rnd = cfg[_ROUND] * 2 * (abs(d1) + rmax + abs(d4) + abs(d5) + abs(d6))
    r = math.sqrt(r2)
    # The wrist-2 point must not be nearer to axis 1 than d4.
    err_sh = _excess(abs(d4) - r, rnd)
    inv_r = 1.0 / (r if r2 > 0 else 1.0)
    t = min(max(d4 * inv_r, -1.0), 1.0)
    kk0 = math.sqrt(1.0 - t * t)
    den3 = 1.0 / (2.0 * a2 * a3)
    t6_ref = ang[5] * ref[5] + ang[11] if has_ref else 0.0
    for sh in range(2):
        kk = kk0 if sh == 0 else -kk0
        cs1 = (p5x * kk - p5y * t) * inv_r
        sn1 = (p5y * kk + p5x * t) * inv_r
        t1q = _angle(ang[0], ang[6], ang[12], ang[18], sn1, cs1)
        vx = X0 * sn1 - X1 * cs1
        vy = Y0 * sn1 - Y1 * cs1
        vz = Z0 * sn1 - Z1 * cs1
        h = math.sqrt(vx * vx + vy * vy)
        t6p = math.atan2(-vy, vx)
        free6 = h < cfg[_SINGULAR_TOL]
        for wr in range(2):
            t6 = t6p if wr == 0 else t6p + math.pi
            if free6:
                target = t6_ref + wr * math.pi
                t6 = target if d5 == 0 else _free_t6(
                    cs1 * p5x + sn1 * p5y, p5z - d1, cs1 * X0 + sn1 * X1, X2,
                    cs1 * Y0 + sn1 * Y1, Y2, target, d5, rmin, rmax)
            s5 = h if wr == 0 else -h
            c5 = vz
            s6, c6 = math.sin(t6), math.cos(t6)
            q5 = _angle(ang[4], ang[10], ang[16], ang[22], s5, c5)
            q6 = _angle(ang[5], ang[11], ang[17], ang[23], s6, c6)
            z4x, z4y, z4z = -s6 * X0 - c6 * Y0, -s6 * X1 - c6 * Y1, -s6 * X2 - c6 * Y2
            # x4 = c5 c6 X6 - c5 s6 Y6 - s5 Z6 (c5, s5 scaled alike by the unit length of v)
            x4x = c5 * (c6 * X0 - s6 * Y0) - s5 * Z0
            x4y = c5 * (c6 * X1 - s6 * Y1) - s5 * Z1
            x4z = c5 * (c6 * X2 - s6 * Y2) - s5 * Z2
            p4x = p5x - d5 * z4x
            p4y = p5y - d5 * z4y
            p4z = p5z - d5 * z4z
            px = cs1 * p4x + sn1 * p4y
            py = p4z - d1
            t234 = math.atan2(x4z, cs1 * x4x + sn1 * x4y)
            pr = math.sqrt(px * px + py * py)
            # The wrist-1 point must lie between the folded and the stretched elbow.
            e = math.sqrt(err_sh + _excess(max(pr - rmax, rmin - pr), rnd))
            ok = e <= reach_tol
            D = min(max((pr * pr - a2 * a2 - a3 * a3) * den3, -1.0), 1.0)
            S = math.sqrt(1.0 - D * D)
            for el in range(2):
                s3 = S if el == 0 else -S
                wx = a2 + a3 * D
                wy = a3 * s3
                t2 = math.atan2(py * wx - px * wy, px * wx + py * wy)
                t3 = math.atan2(s3, D)
                k = 4 * sh + 2 * el + wr
                q[k, 0] = t1q
                q[k, 1] = _wrap((t2 - ang[7]) * ang[1])
                q[k, 2] = _wrap((t3 - ang[8]) * ang[2])
                q[k, 3] = _wrap((t234 - t2 - t3 - ang[9]) * ang[3])
                q[k, 4] = q5
                q[k, 5] = q6
                reach[k] = ok
                err[k] = e


# -- 4-axis palletizer ----------------------------------------------------------------------------
def palletizer_params(planar, v_n, R_n0) -> NDArray[np.float64]:
    """Parameters of :func:`_palletizer`: ``planar`` the 12 numbers ``(A_r, A_h, b, L2, L3, s1,
    s4, g22, o2, g32, g33, o3)`` of :class:`robotcell.ik.palletizer.PalletizerParameters` (m,
    rad), ``v_n`` (3,) (m), ``R_n0`` (3, 3)."""
    return np.concatenate([np.asarray(planar, dtype=float), np.ravel(v_n), np.ravel(R_n0)])


@compiled
def _palletizer(cfg, p, R, P, q, err, reach) -> None:
    """All 4 branches of a palletizer for the target ``R_O_n``, ``p_O_n`` (see
    :mod:`robotcell.ik.palletizer`), branch ``k = 2 * shoulder + elbow``: shoulder 1 = ``W``
    behind axis 1, elbow 1 = the second solution of the two-link problem. A target that is not
    level is reached by no branch; ``err`` is 0 where a branch reaches, inf where not.
    """
    A_r, A_h, b, L2, L3, s1, s4 = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
    g22, o2, g32, g33, o3 = p[7], p[8], p[9], p[10], p[11]
    v, Rn = p[12:15], p[15:24]
    # D = R @ R_n0.T must be Rz(psi); its entries D_ij = R_i . (R_n0)_j
    D00 = R[0][0] * Rn[0] + R[0][1] * Rn[1] + R[0][2] * Rn[2]
    D01 = R[0][0] * Rn[3] + R[0][1] * Rn[4] + R[0][2] * Rn[5]
    D10 = R[1][0] * Rn[0] + R[1][1] * Rn[1] + R[1][2] * Rn[2]
    D11 = R[1][0] * Rn[3] + R[1][1] * Rn[4] + R[1][2] * Rn[5]
    D20 = R[2][0] * Rn[0] + R[2][1] * Rn[1] + R[2][2] * Rn[2]
    D21 = R[2][0] * Rn[3] + R[2][1] * Rn[4] + R[2][2] * Rn[5]
    level = abs(D20) <= cfg[_LEVEL_TOL] and abs(D21) <= cfg[_LEVEL_TOL]
    psi = math.atan2(D10 - D01, D00 + D11)
    wx = P[0] + (R[0][0] * v[0] + R[0][1] * v[1] + R[0][2] * v[2])
    wy = P[1] + (R[1][0] * v[0] + R[1][1] * v[1] + R[1][2] * v[2])
    wz = P[2] + (R[2][0] * v[0] + R[2][1] * v[1] + R[2][2] * v[2])
    rho2 = wx * wx + wy * wy
    n2 = rho2 - b * b
    ok_sh = level and n2 >= -cfg[_AXIS_TOL] * cfg[_AXIS_TOL]
    n = math.sqrt(max(n2, 0.0))
    base = math.atan2(wy, wx)
    h = wz - A_h
    for sh in range(2):
        r = n if sh == 0 else -n
        phi1 = base - math.atan2(b, r)
        q1 = _wrap(phi1 / s1)
        q4 = _wrap((psi - s1 * q1) / s4)
        tr = r - A_r
        d2 = tr * tr + h * h
        K = (d2 - L2 * L2 - L3 * L3) / (2.0 * L2 * L3)
        ok = ok_sh and abs(K) <= 1.0 + cfg[_COS_TOL]
        K = min(max(K, -1.0), 1.0)
        S = math.sqrt(1.0 - K * K)
        for el in range(2):
            s = S if el == 0 else -S
            phi2 = math.atan2(h, tr) - math.atan2(L3 * s, L2 + L3 * K)
            phi3 = phi2 + math.atan2(s, K)
            q2 = _wrap(phi2 - o2) / g22
            q3 = _wrap(phi3 - o3 - g32 * q2) / g33
            k = 2 * sh + el
            q[k, 0], q[k, 1], q[k, 2], q[k, 3] = q1, q2, q3, q4
            reach[k] = ok
            err[k] = 0.0 if ok else np.inf


# -- limits and the exact branches ----------------------------------------------------------------
@compiled
def _fold(q, modes, lower, upper, tol) -> bool:
    """Fold the values ``q`` (n,) of one branch in place by the 2*pi rule of
    :class:`robotcell.ik.limits.JointFolder`; whether every checked value is within its limits
    up to ``tol`` (False for NaN; without a checked joint, whether ``q`` is not NaN)."""
    inside = True
    checked = False
    for j in range(q.shape[0]):
        mode = modes[j]
        if mode == FOLD_NONE:
            continue
        checked = True
        v, lo, hi = q[j], lower[j], upper[j]
        if mode == FOLD_DOWN and v > hi + tol and v - TWO_PI >= lo - tol:
            v = v - TWO_PI
        elif mode == FOLD_UP and v < lo - tol and v + TWO_PI <= hi + tol:
            v = v + TWO_PI
        q[j] = v
        if not (v >= lo - tol and v <= hi + tol):
            inside = False
    return inside if checked else not np.isnan(q[0])


@compiled
def _exact(valid, err, exact_tol) -> None:
    """Keep in ``valid`` (branches,) only the exact branches when one is: a branch solved at the
    boundary of its reach stands for the pose only when no valid branch reaches it exactly (see
    :attr:`robotcell.ik.result.IKSolutions.reach_error`)."""
    any_exact = False
    for k in range(valid.shape[0]):
        if valid[k] and err[k] <= exact_tol:
            any_exact = True
    if any_exact:
        for k in range(valid.shape[0]):
            valid[k] = valid[k] and err[k] <= exact_tol


@compiled
def fold_rows(q, modes, lower, upper, tol, inside) -> None:
    """:func:`_fold` on every row of ``q`` (N, n) in place; ``inside`` (N,) receives the result."""
    for i in range(q.shape[0]):
        inside[i] = _fold(q[i], modes, lower, upper, tol)


@compiled
def exact_rows(valid, err, exact_tol) -> None:
    """:func:`_exact` on every row of ``valid`` and ``err`` (N, branches), in place."""
    for i in range(valid.shape[0]):
        _exact(valid[i], err[i], exact_tol)


# -- the loop over poses --------------------------------------------------------------------------
@compiled
def solve_poses(cfg, T, T_tcp_end, ref, q, err, reach, valid) -> None:
    """Every branch of every target: the analytic IK of one solver (a batch or one pose).

    Parameters
    ----------
    cfg : ndarray
        The solver's configuration, :func:`pack`.
    T : ndarray, shape (4 N, 4)
        ``T_R_TCP``, target poses of the TCP in the robot base frame (m), already validated,
        stacked (one pose is a (4, 4) array as it is; a batch ``(N, 4, 4)`` reshaped).
    T_tcp_end : ndarray, shape (4, 4)
        Pose of the solver's end frame in the TCP frame (m).
    ref : ndarray, shape (N, 6) or (0, 6)
        Reference values (rad) for free axes, per pose; none when empty.
    q : ndarray, shape (N branches, n)
        Receives the joint values (rad; NaN where a branch does not reach).
    err : ndarray, shape (N branches,)
        Receives the reach errors (m).
    reach, valid : ndarray of bool, shape (N branches,)
        Receive which branches reach, and (when the configuration says to finish) which are
        within the limits and exact (see :func:`_exact`); else ``valid`` is left untouched.

    One pose and a batch pass arrays of the same types, so that numba compiles this once.
    """
    T3 = T.reshape((-1, 4, 4))
    nb, n = int(cfg[_BRANCHES]), int(cfg[_N])
    q3 = q.reshape((-1, nb, n))
    e2 = err.reshape((-1, nb))
    r2 = reach.reshape((-1, nb))
    va = valid.reshape((-1, nb))
    method = cfg[_METHOD]
    finish = cfg[_FINISH] != 0.0
    A = cfg[_T_O_R:_T_O_R + 16].reshape((4, 4))
    lower, upper = cfg[_LIMITS:_LIMITS + n], cfg[_LIMITS + n:_LIMITS + 2 * n]
    modes = cfg[_LIMITS + 2 * n:_LIMITS + 3 * n]
    p = cfg[_LIMITS + 3 * n:]
    has_ref = ref.shape[0] > 0
    B = T_tcp_end
    for i in range(T3.shape[0]):
        Ti = T3[i]
        # R_O_end = A_rot (R_t B_rot), p_O_end = A_rot (R_t b + t) + a
        m00 = Ti[0, 0] * B[0, 0] + Ti[0, 1] * B[1, 0] + Ti[0, 2] * B[2, 0]
        m01 = Ti[0, 0] * B[0, 1] + Ti[0, 1] * B[1, 1] + Ti[0, 2] * B[2, 1]
        m02 = Ti[0, 0] * B[0, 2] + Ti[0, 1] * B[1, 2] + Ti[0, 2] * B[2, 2]
        m10 = Ti[1, 0] * B[0, 0] + Ti[1, 1] * B[1, 0] + Ti[1, 2] * B[2, 0]
        m11 = Ti[1, 0] * B[0, 1] + Ti[1, 1] * B[1, 1] + Ti[1, 2] * B[2, 1]
        m12 = Ti[1, 0] * B[0, 2] + Ti[1, 1] * B[1, 2] + Ti[1, 2] * B[2, 2]
        m20 = Ti[2, 0] * B[0, 0] + Ti[2, 1] * B[1, 0] + Ti[2, 2] * B[2, 0]
        m21 = Ti[2, 0] * B[0, 1] + Ti[2, 1] * B[1, 1] + Ti[2, 2] * B[2, 1]
        m22 = Ti[2, 0] * B[0, 2] + Ti[2, 1] * B[1, 2] + Ti[2, 2] * B[2, 2]
        v0 = (Ti[0, 0] * B[0, 3] + Ti[0, 1] * B[1, 3] + Ti[0, 2] * B[2, 3]) + Ti[0, 3]
        v1 = (Ti[1, 0] * B[0, 3] + Ti[1, 1] * B[1, 3] + Ti[1, 2] * B[2, 3]) + Ti[1, 3]
        v2 = (Ti[2, 0] * B[0, 3] + Ti[2, 1] * B[1, 3] + Ti[2, 2] * B[2, 3]) + Ti[2, 3]
        R = ((A[0, 0] * m00 + A[0, 1] * m10 + A[0, 2] * m20,
              A[0, 0] * m01 + A[0, 1] * m11 + A[0, 2] * m21,
              A[0, 0] * m02 + A[0, 1] * m12 + A[0, 2] * m22),
             (A[1, 0] * m00 + A[1, 1] * m10 + A[1, 2] * m20,
              A[1, 0] * m01 + A[1, 1] * m11 + A[1, 2] * m21,
              A[1, 0] * m02 + A[1, 1] * m12 + A[1, 2] * m22),
             (A[2, 0] * m00 + A[2, 1] * m10 + A[2, 2] * m20,
              A[2, 0] * m01 + A[2, 1] * m11 + A[2, 2] * m21,
              A[2, 0] * m02 + A[2, 1] * m12 + A[2, 2] * m22))
        P = ((v0 * A[0, 0] + v1 * A[0, 1] + v2 * A[0, 2]) + A[0, 3],
             (v0 * A[1, 0] + v1 * A[1, 1] + v2 * A[1, 2]) + A[1, 3],
             (v0 * A[2, 0] + v1 * A[2, 1] + v2 * A[2, 2]) + A[2, 3])
        qi, ei, ri = q3[i], e2[i], r2[i]
        refi = ref[i] if has_ref else ref[0:0].reshape(-1)
        if method == 0.0:
            _opw(cfg, p, R, P, refi, has_ref, qi, ei, ri)
        elif method == 1.0:
            _ur(cfg, p, R, P, refi, has_ref, qi, ei, ri)
        else:
            _palletizer(cfg, p, R, P, qi, ei, ri)
        for k in range(nb):
            if not ri[k]:
                qi[k, :] = np.nan
        if finish:
            vi = va[i]
            for k in range(nb):
                vi[k] = ri[k] and _fold(qi[k], modes, lower, upper, cfg[_LIMIT_TOL])
            _exact(vi, ei, cfg[_EXACT_TOL])


# -- the track value of an ortho-parallel arm on a linear track (robotcell.ik.trackchoice) --------
# Layout of the track configuration of track_config().
_TRACK_LO, _TRACK_HI, _PREFER, _SECOND, _SHRINK, _STAGES = 0, 1, 2, 3, 4, 5
_W = 6
_T_O_L = 9
_CONES = 25  # axes 1, 2, 3, (4 unused), 5: (limited, cos mid, sin mid, cos half-range)
_ROWS = 45  # number of coupled rows, then rows (axis, c1, c2, c3, constant, lower, upper)


def track_config(lower: float, upper: float, w: NDArray[np.float64], T_O_L: NDArray[np.float64],
                 cones: dict[int, tuple[float, float, float]],
                 rows: list[tuple[int, NDArray[np.float64], float, float, float]],
                 prefer_within: float, second_peak: float, refine_stages: int, refine: int
                 ) -> NDArray[np.float64]:
    """The track configuration of :func:`choose_poses` and :func:`scan_rows`.

    Parameters
    ----------
    lower, upper : float
        Track limits (m).
    w : ndarray, shape (3,)
        Displacement of the wrist centre in O per metre of track.
    T_O_L : ndarray, shape (4, 4)
        Pose of the track frame L in O at track value 0 (m).
    cones : dict of int to (float, float, float)
        Limits of axes 1, 2, 3, 5 (index 0, 1, 2, 4) as cones on the paper's angles:
        ``cos(t - mid) >= cos(half)`` as ``(cos mid, sin mid, cos half)``.
    rows : list of (int, ndarray (3,), float, float, float)
        Coupled axes among 1..3: ``q_j = row . q_model[:3] + constant`` within ``[lower, upper]``.
    prefer_within, second_peak : float
        See :mod:`robotcell.ik.trackchoice`.
    refine_stages, refine : int
        Refinement stages and values per stage.
    """
    head = [lower, upper, 1.0 - prefer_within, second_peak, 2.0 / (refine - 1), refine_stages]
    cone = np.zeros((5, 4))
    for j, (cm, sm, ch) in cones.items():
        cone[j] = (1.0, cm, sm, ch)
    coupled = [[j, *row, const, lo, hi] for j, row, const, lo, hi in rows]
    return np.concatenate([head, w, np.ravel(T_O_L), np.ravel(cone), [len(rows)],
                           np.ravel(np.array(coupled, dtype=float))])


@compiled
def _cone(cone, c: float, s: float) -> bool:
    """An axis within its limits, given (cos, sin) of its paper angle (no arctangent): ``cone``
    is ``(limited, cos mid, sin mid, cos half)`` of :func:`track_config`."""
    return cone[0] == 0.0 or c * cone[1] + s * cone[2] >= cone[3]


@compiled
def _either_wrist(cone, c: float, h: float) -> bool:
    """Axis 5 within its limits for ``t5`` or ``-t5`` (the two wrist flips), ``h = |sin t5|``."""
    return cone[0] == 0.0 or c * cone[1] + h * abs(cone[2]) >= cone[3]


@compiled
def _coupled_ok(cfg, p, tc, c1, s1, c2, s2, c3, s3) -> bool:
    """Coupled axes among 1..3 within limits, given (cos, sin) of the paper's angles t1, t2, t3."""
    nrows = int(tc[_ROWS])
    if nrows == 0:
        return True
    qm0 = p[7] * (math.atan2(s1, c1) - p[13])
    qm1 = p[8] * (math.atan2(s2, c2) - p[14])
    qm2 = p[9] * (math.atan2(s3, c3) - p[15])
    tol = cfg[_LIMIT_TOL]
    for r in range(nrows):
        i = _ROWS + 1 + 7 * r
        q = tc[i + 1] * qm0 + tc[i + 2] * qm1 + tc[i + 3] * qm2 + tc[i + 4]
        lo, hi = tc[i + 5], tc[i + 6]
        if not np.mod(q - lo + tol, TWO_PI) <= hi - lo + 2 * tol:
            return False
    return True


@compiled
def _arm_constants(p):
    """``(kappa, cos psi, sin psi, 1 / (2 c2 kappa), c2^2 + kappa^2)`` of an ortho-parallel arm."""
    kappa = math.hypot(p[1], p[5])
    return (kappa, p[5] / kappa, p[1] / kappa, 1.0 / (2.0 * p[4] * kappa),
            p[4] * p[4] + kappa * kappa)


@compiled
def _manipulability_at(cfg, p, tc, k, R02, R12, R22, cx, cy, cz) -> float:
    """Best ``|det J|`` (m^3) over the arm's branches that reach the wrist centre ``c`` (in O) with
    axes 1, 2, 3 and 5 within their limits, for the target orientation's third column ``R_2``;
    0 where none does (``k``: :func:`_arm_constants`). The closed form of
    :mod:`robotcell.ik.trackchoice`."""
    a1, b, c1_, c2 = p[0], p[2], p[3], p[4]
    kappa, cpsi, spsi, denom, base = k
    rho2 = cx * cx + cy * cy
    n2 = rho2 - b * b
    n = math.sqrt(max(n2, 0.0))
    inv = 1.0 / max(rho2, 1e-300)
    Z = cz - c1_
    best = 0.0
    for sh in range(2):
        cs1, sn1, X = _opw_shoulder(sh, cx, cy, n, b, inv, a1)
        s_2 = X * X + Z * Z
        K = (s_2 - base) * denom
        if not (n2 >= 0 and abs(K) <= 1.0 and _cone(tc[_CONES:_CONES + 4], cs1, sn1)):
            continue
        S = math.sqrt(max(1.0 - K * K, 0.0))
        M02 = cs1 * R02 + sn1 * R12
        wz = c2 + kappa * K
        kS = kappa * S
        # Shared by both elbows (sphi = +-S): the norm of (cu, su) and the products below.
        inv_norm = 1.0 / max(math.sqrt(s_2 * (kS * kS + wz * wz)), 1e-300)
        kSX, kSZ = kS * X * inv_norm, kS * Z * inv_norm
        wzX, wzZ = wz * X * inv_norm, wz * Z * inv_norm
        Kc, Ks, Sc, Ss = K * cpsi, K * spsi, S * cpsi, S * spsi
        nS = n * S
        for sg in (1.0, -1.0):
            cs2, sn2 = wzZ + sg * kSX, wzX - sg * kSZ
            cs3, sn3 = Kc + sg * Ss, sg * Sc - Ks
            r22 = (sn2 * cs3 + cs2 * sn3) * M02 + (cs2 * cs3 - sn2 * sn3) * R22  # cos(t5)
            h = math.sqrt(max(1.0 - r22 * r22, 0.0))
            if (_cone(tc[_CONES + 4:_CONES + 8], cs2, sn2) and _cone(tc[_CONES + 8:_CONES + 12], cs3, sn3)
                    and _either_wrist(tc[_CONES + 16:_CONES + 20], r22, h)
                    and _coupled_ok(cfg, p, tc, cs1, sn1, cs2, sn2, cs3, sn3)):
                best = max(best, nS * h)
    return best * (c2 * kappa)


@compiled
def _row_times(a0, a1, a2, a3, M):
    """The row ``(a0, a1, a2, a3)`` times the 4x4 matrix ``M``."""
    return (a0 * M[0, 0] + a1 * M[1, 0] + a2 * M[2, 0] + a3 * M[3, 0],
            a0 * M[0, 1] + a1 * M[1, 1] + a2 * M[2, 1] + a3 * M[3, 1],
            a0 * M[0, 2] + a1 * M[1, 2] + a2 * M[2, 2] + a3 * M[3, 2],
            a0 * M[0, 3] + a1 * M[1, 3] + a2 * M[2, 3] + a3 * M[3, 3])


@compiled
def _wrist_line(cfg, tc, Ti, B):
    """``R_O_e`` (3x3 tuple) and ``p_O_e`` at track value 0 of the target ``T_L_TCP`` ``Ti``
    (``T_O_e = T_O_L Ti B``, ``B`` the end frame in the TCP frame), and the wrist centre there."""
    t = tc[_T_O_L:_T_O_L + 12]
    u0 = _row_times(t[0], t[1], t[2], t[3], Ti)
    u1 = _row_times(t[4], t[5], t[6], t[7], Ti)
    u2 = _row_times(t[8], t[9], t[10], t[11], Ti)
    e0 = _row_times(u0[0], u0[1], u0[2], u0[3], B)
    e1 = _row_times(u1[0], u1[1], u1[2], u1[3], B)
    e2 = _row_times(u2[0], u2[1], u2[2], u2[3], B)
    R = ((e0[0], e0[1], e0[2]), (e1[0], e1[1], e1[2]), (e2[0], e2[1], e2[2]))
    P = (e0[3], e1[3], e2[3])
    c4 = cfg_params(cfg)[6]
    C = (P[0] - c4 * R[0][2], P[1] - c4 * R[1][2], P[2] - c4 * R[2][2])
    return R, P, C


@compiled
def cfg_params(cfg):
    """The structure's parameters in a solver configuration (:func:`pack`)."""
    return cfg[_LIMITS + 3 * int(cfg[_N]):]


@compiled
def _interval(p, C, w0, w1, w2):
    """Roots of ``|C + x w - S|^2 = (c2 + kappa + |a1|)^2 + b^2`` (m), NaN where the wrist
    centre ``C`` (at track value 0, in O) never comes that close to the shoulder."""
    D0, D1, D2 = C[0], C[1], C[2] - p[3]
    r_max = p[4] + math.hypot(p[1], p[5]) + abs(p[0])
    a = w0 * w0 + w1 * w1 + w2 * w2
    half_b = D0 * w0 + D1 * w1 + D2 * w2
    c = (D0 * D0 + D1 * D1 + D2 * D2) - (r_max * r_max + p[2] * p[2])
    disc = half_b * half_b - a * c
    root = math.sqrt(disc) if disc >= 0 else np.nan
    return (-half_b - root) / a, (-half_b + root) / a


@compiled
def _scan_interval(cfg, p, tc, C):
    """The interval of :func:`_interval` clipped to the track limits; NaN where empty."""
    lo, hi = _interval(p, C, tc[_W], tc[_W + 1], tc[_W + 2])
    lo, hi = np.maximum(lo, tc[_TRACK_LO]), np.minimum(hi, tc[_TRACK_HI])
    if not lo <= hi:
        return np.nan, np.nan
    return lo, hi


@compiled
def _score(cfg, p, tc, k, R, C, x) -> float:
    """:func:`_manipulability_at` at track value ``x`` (0 for NaN)."""
    if np.isnan(x):
        return 0.0
    return _manipulability_at(cfg, p, tc, k, R[0][2], R[1][2], R[2][2], C[0] + tc[_W] * x,
                              C[1] + tc[_W + 1] * x, C[2] + tc[_W + 2] * x)


@compiled
def _argmax(a, n: int) -> int:
    """``np.argmax(a[:n])``: the first maximum, or the first NaN."""
    k = 0
    for i in range(n):
        if np.isnan(a[i]):
            return i
        if a[i] > a[k]:
            k = i
    return k


@compiled
def _refine(arm, target, centre, half, bounds, lin_f, buf, at) -> None:
    """Grids of ``len(lin_f)`` values around ``centre``, +-``half``, within ``bounds`` (lower,
    upper), shrinking around the best for each stage; every value tried and its score into the
    scratch ``buf`` (values, scores) from index ``at``. ``arm`` is ``(cfg, p, tc, k)`` and
    ``target`` ``(R, C)`` of :func:`_score`."""
    cfg, p, tc, k = arm
    R, C = target
    lo, hi = bounds
    xs, ms = buf
    nf = lin_f.shape[0]
    for stage in range(int(tc[_STAGES])):
        i0 = at + stage * nf
        for j in range(nf):
            f = np.minimum(np.maximum(centre + half * lin_f[j], lo), hi)
            if np.isnan(f):
                f = centre
            xs[i0 + j] = f
            ms[i0 + j] = _score(cfg, p, tc, k, R, C, f)
        centre = xs[i0 + _argmax(ms[i0:], nf)]
        half = half * tc[_SHRINK]


@compiled
def _choose(cfg, p, tc, target, lins, preference, buf):
    """The track value of one target ``(R, C)`` (:func:`_wrist_line`) and whether the scan found
    one where the arm reaches it (see :func:`robotcell.ik.trackchoice.choose_track`); ``lins`` as
    in :func:`choose_poses`, ``preference`` ``(has_prefer, preferred value)``, ``buf`` the scratch
    ``(values, scores)``."""
    R, C = target
    lin_c, lin_f, lin_d = lins
    has_prefer, prefer = preference
    xs, ms = buf
    lo, hi = _scan_interval(cfg, p, tc, C)
    ac = _arm_constants(p)
    K = lin_c.shape[0]
    for k in range(K):
        xs[k] = lo + (hi - lo) * lin_c[k]
        ms[k] = _score(cfg, p, tc, ac, R, C, xs[k])
    step = (hi - lo) / (K - 1)
    if np.isnan(step):
        step = 0.0
    k1 = _argmax(ms, K)
    # A second peak: the best local maximum outside the first's neighbours, refined only where
    # it comes within SECOND_PEAK of the first (a second mode that could win after refinement).
    k2, m2 = 0, -1.0
    for k in range(K):
        left = ms[k - 1] if k > 0 else -1.0
        right = ms[k + 1] if k < K - 1 else -1.0
        if ms[k] >= left and ms[k] >= right and abs(k - k1) > 1 and ms[k] > m2:
            k2, m2 = k, ms[k]
    nr = int(tc[_STAGES]) * lin_f.shape[0]
    c1 = xs[k1] if not np.isnan(xs[k1]) else 0.0
    _refine((cfg, p, tc, ac), target, c1, step, (lo, hi), lin_f, buf, K)
    total = K + nr
    if m2 >= tc[_SECOND] * ms[k1]:
        c2 = xs[k2] if not np.isnan(xs[k2]) else 0.0
        _refine((cfg, p, tc, ac), target, c2, step, (lo, hi), lin_f, buf, total)
    else:
        for i in range(total, total + nr):
            xs[i], ms[i] = np.nan, -1.0
    total += nr
    best = ms[_argmax(ms, total)]
    if has_prefer:
        # the value nearest to the preferred one among those within PREFER_WITHIN of the best
        k, dk = 0, np.inf
        for i in range(total):
            d = abs(xs[i] - prefer) if ms[i] >= tc[_PREFER] * best else np.inf
            if np.isnan(d):
                k = i
                break
            if d < dk:
                k, dk = i, d
        x = xs[k]
    else:
        x = xs[_argmax(ms, total)]
    found = best > 0
    if not found and not np.isnan(lo):
        # Nothing found on the scan although the interval is not empty: look again on a denser
        # grid (a window of reach narrower than one step, or truly out of reach).
        md, xd = -1.0, np.nan
        for j in range(lin_d.shape[0]):
            xj = lo + (hi - lo) * lin_d[j]
            mj = _score(cfg, p, tc, ac, R, C, xj)
            if mj > md:
                md, xd = mj, xj
        if md > 0:
            x, found = xd, True
    if not found:  # out of reach at every track value, or not within the limits of axes 1-3, 5
        x = lo if not np.isnan(lo) else tc[_TRACK_LO]
    return x, found


@compiled
def choose_poses(cfg, tc, T, T_tcp_end, lins, prefer, out) -> int:
    """The track value of every target, and (for an arm without coupling) its branches there.

    Parameters
    ----------
    cfg : ndarray
        The arm's solver configuration (:func:`pack`, an ortho-parallel arm).
    tc : ndarray
        :func:`track_config`.
    T : ndarray, shape (N, 4, 4)
        ``T_L_TCP``, targets in the track frame (m), validated.
    T_tcp_end : ndarray, shape (4, 4)
        The solver's end frame seen from the TCP (m).
    lins : tuple of three ndarrays
        ``np.linspace`` of the coarse scan (0..1), of a refinement stage (-1..1) and of the dense
        second look (0..1).
    prefer : ndarray, shape (N,) or (0,)
        Preferred track values (m), or none.
    out : tuple of ndarrays ``(x, found, q, err, reach, valid, manipulability)``
        ``x`` (N,) receives the chosen track values (m); ``found`` (N,) of bool whether the scan
        found a value where the arm reaches the target. ``q``, ``err``, ``reach``, ``valid``
        ((N, 8, 7), (N, 8), (N, 8) and (N, 8) of bool) receive the branches at the chosen values
        (track value first; finished as by :func:`solve_poses`) when the configuration finishes
        (an arm without coupling), else stay untouched; with them ``manipulability`` (N,)
        receives ``|det J|`` of the best valid branch (:func:`best_valid_rows`).

    Returns
    -------
    int
        With the branches: how many targets the scan found but no branch there is valid (a limit
        of axis 4 or 6), to be searched again; else 0.
    """
    p = cfg_params(cfg)
    x, found, q, err, reach, valid, manipulability = out
    finish = cfg[_FINISH] != 0.0
    has_prefer = prefer.shape[0] > 0
    nbuf = lins[0].shape[0] + 2 * int(tc[_STAGES]) * lins[1].shape[0]
    buf = (np.empty(nbuf), np.empty(nbuf))
    lower, upper = cfg[_LIMITS:_LIMITS + 6], cfg[_LIMITS + 6:_LIMITS + 12]
    modes = cfg[_LIMITS + 12:_LIMITS + 18]
    no_ref = np.empty(0)
    has_ref = no_ref.shape[0] > 0  # False, typed as in solve_poses (one compiled _opw)
    arm = np.empty((8, 6))  # the arm's values of one target (C-contiguous, as in solve_poses)
    again = 0
    for i in range(T.shape[0]):
        R, P, C = _wrist_line(cfg, tc, T[i], T_tcp_end)
        xi, fi = _choose(cfg, p, tc, (R, C), lins, (has_prefer, prefer[i] if has_prefer else 0.0),
                         buf)
        x[i], found[i] = xi, fi
        if not finish:
            continue
        Px = (P[0] + tc[_W] * xi, P[1] + tc[_W + 1] * xi, P[2] + tc[_W + 2] * xi)
        _opw(cfg, p, R, Px, no_ref, has_ref, arm, err[i], reach[i])
        for k in range(8):
            if not reach[i, k]:
                arm[k, :] = np.nan
            valid[i, k] = reach[i, k] and _fold(arm[k], modes, lower, upper, cfg[_LIMIT_TOL])
            q[i, k, 0] = xi
            q[i, k, 1:] = arm[k]
        _exact(valid[i], err[i], cfg[_EXACT_TOL])
        manipulability[i] = _best_valid(p, arm, valid[i])
        if fi and not valid[i].any():
            again += 1
    return again


@compiled
def scan_rows(cfg, tc, T, T_tcp_end, lin, x, m, lower, upper) -> None:
    """Manipulability of every target ``T_L_TCP`` (N, 4, 4) on the track values ``lin`` (K,)
    of its interval into ``x``, ``m`` (N, K) (m, m^3), the interval into ``lower``, ``upper``."""
    p = cfg_params(cfg)
    ac = _arm_constants(p)
    for i in range(T.shape[0]):
        R, _, C = _wrist_line(cfg, tc, T[i], T_tcp_end)
        lo, hi = _scan_interval(cfg, p, tc, C)
        lower[i], upper[i] = lo, hi
        for k in range(lin.shape[0]):
            x[i, k] = lo + (hi - lo) * lin[k]
            m[i, k] = _score(cfg, p, tc, ac, R, C, x[i, k])


@compiled
def wrist_rows(cfg, tc, T, T_tcp_end, R, C) -> None:
    """``R_O_e`` (N, 3, 3) and the wrist centre (N, 3) in O at track value 0 of targets ``T``."""
    for i in range(T.shape[0]):
        Ri, _, Ci = _wrist_line(cfg, tc, T[i], T_tcp_end)
        for r in range(3):
            C[i, r] = Ci[r]
            for c in range(3):
                R[i, r, c] = Ri[r][c]


@compiled
def interval_rows(p, C, w, lower, upper) -> None:
    """:func:`_interval` of wrist centres ``C`` (N, 3) moving along ``w`` (3,)."""
    for i in range(C.shape[0]):
        lower[i], upper[i] = _interval(p, (C[i, 0], C[i, 1], C[i, 2]), w[0], w[1], w[2])


@compiled
def _det_j(p, q) -> float:
    """``|det J|`` of an ortho-parallel arm at controller values ``q`` (6,) in closed form (m^3):
    ``n * c2 * kappa * |sin(gamma)| * |sin(t5)|`` (see :mod:`robotcell.ik.trackchoice`)."""
    t2 = q[1] * p[8] + p[14]
    t23 = t2 + (q[2] * p[9] + p[15])
    t5 = q[4] * p[11] + p[17]
    a1, a2, c2, c3 = p[0], p[1], p[4], p[5]
    fx = a2 * math.cos(t23) + c3 * math.sin(t23)  # axis 3 to the wrist centre, in the plane
    fz = c3 * math.cos(t23) - a2 * math.sin(t23)
    n = abs(a1 + c2 * math.sin(t2) + fx)
    cross = abs(math.sin(t2) * fz - math.cos(t2) * fx)  # kappa * |sin(gamma)|
    return n * c2 * cross * abs(math.sin(t5))


@compiled
def manipulability_rows(p, q, out) -> None:
    """:func:`_det_j` of every row of ``q`` (N, 6) into ``out`` (N,); NaN gives NaN."""
    for i in range(q.shape[0]):
        out[i] = _det_j(p, q[i])


@compiled
def _best_valid(p, q, valid) -> float:
    """``|det J|`` of the best valid branch of one target's arm values ``q`` (8, 6) (0 if none):
    the two wrists of an arm configuration (branches 2k, 2k + 1) have the same value."""
    best = 0.0
    for k in range(0, 8, 2):
        if valid[k] or valid[k + 1]:
            m = _det_j(p, q[k])
            if not np.isnan(m):
                best = max(best, m)
    return best


@compiled
def best_valid_rows(p, q, valid, out) -> None:
    """:func:`_best_valid` of every target: ``q`` (N, 8, 6), ``valid`` (N, 8), ``out`` (N,)."""
    for i in range(q.shape[0]):
        out[i] = _best_valid(p, q[i], valid[i])
