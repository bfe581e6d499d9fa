"""Workpiece frame W on a calibrated turntable, from touches at any table angles.

Each touch ``f_i`` (in R) taken at table angle ``theta_i`` is carried back to the table at angle 0,

    B_p_i = Rz(theta_i)^-1 T_B_R f_i,

where the workpiece has a fixed pose ``T_B_W`` (the lecture assumes every touch at angle 0; any
angle works). The frame follows the 3-point rule (origin; a point on +X; a point in the XY plane
with positive Y). Several touches per role make it an N-point best fit: the maximum-likelihood
frame under isotropic Gaussian noise on the touches minimises the squared distances of the
``origin`` touches to the origin, of the ``x`` touches to the +X axis line and of the ``xy``
touches to the XY plane; the position of each ``x`` touch along the axis and of each ``xy`` touch
in the plane are estimated with the frame. With one touch per role this reproduces the 3-point construction with zero
residuals. The moving pose is ``T_R_W(theta) = T_R_B Rz(theta) T_B_W`` (:func:`workpiece_pose`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.fitting import SAME_POINT, fit, outlier_warnings, perturb_pose
from robotcell.calibration.frame import GOOD_X_DISTANCE, NEAR_COLLINEAR_SIN
from robotcell.calibration.propagate import jacobian
from robotcell.calibration.result import CONDITION_LIMIT, CalibrationResult, pose_fields
from robotcell.errors import IllPosedError, InputError
from robotcell.kinematics.transforms import as_points, invert, make_pose, rot_z, validate_pose

__all__ = ["ROLES", "calibrate_workpiece", "table_points", "workpiece_pose"]

#: Roles of the touches of a 3-point frame.
ROLES = ("origin", "x", "xy")


def table_points(T_R_B: ArrayLike, theta: ArrayLike, f: ArrayLike) -> NDArray[np.float64]:
    """Carry touched points back to the turntable at angle 0: ``Rz(theta)^-1 T_B_R f``.

    Parameters
    ----------
    T_R_B : array_like, shape (4, 4)
        Turntable root frame in the robot base (metres).
    theta : array_like, shape (N,)
        Table angle at each touch (radians).
    f : array_like, shape (N, 3)
        Touched points in R (metres).

    Returns
    -------
    ndarray, shape (N, 3)
        The points in B with the table at angle 0 (metres).
    """
    T_B_R = invert(T_R_B)
    p = np.asarray(f, dtype=float) @ T_B_R[:3, :3].T + T_B_R[:3, 3]
    return np.einsum("nji,nj->ni", rot_z(np.asarray(theta, dtype=float)), p)


def workpiece_pose(T_R_B: ArrayLike, T_B_W: ArrayLike, theta: ArrayLike) -> NDArray[np.float64]:
    """Pose of the workpiece in the robot base at table angle(s) ``theta``.

    Parameters
    ----------
    T_R_B : array_like, shape (4, 4)
        Turntable root frame in R (metres).
    T_B_W : array_like, shape (4, 4)
        Workpiece frame in B at table angle 0 (metres).
    theta : array_like, shape (...)
        Table angles (radians).

    Returns
    -------
    ndarray, shape (..., 4, 4)
        ``T_R_W(theta) = T_R_B Rz(theta) T_B_W``.
    """
    T_R_B = validate_pose(T_R_B, "T_R_B")
    T_B_W = validate_pose(T_B_W, "T_B_W")
    th = np.asarray(theta, dtype=float)
    if not np.all(np.isfinite(th)):
        raise InputError("table angles contain NaN or infinite values")
    turn = make_pose(rot_z(th), np.zeros(th.shape + (3,)))
    return T_R_B @ turn @ T_B_W


def _start_frame(p: NDArray[np.float64], roles: NDArray[np.str_]):
    """3-point construction from the mean point of each role; warnings for a weak layout.

    Refuses only points that coincide or are collinear to rounding (:data:`SAME_POINT`): the
    direction of X or the rotation about it is then not determined.
    """
    o, px, pxy = (p[roles == r].mean(axis=0) for r in ROLES)
    u = px - o
    lx = float(np.linalg.norm(u))
    if lx < SAME_POINT:
        raise IllPosedError(
            "the +X point is at the origin, so it defines no direction; touch a point on +X at "
            f"least {GOOD_X_DISTANCE * 1e3:.0f} mm from the origin (farther is more accurate)")
    x = u / lx
    v = pxy - o
    off = float(np.linalg.norm(v - (v @ x) * x))
    if off < SAME_POINT:
        raise IllPosedError(
            "the XY-plane point lies on the X axis (the three points are collinear), so the rotation "
            "about X is not determined; touch a point with positive Y well away from the X axis")
    warnings = []
    if lx < GOOD_X_DISTANCE:
        warnings.append(f"the +X point is only {lx * 1e3:.1f} mm from the origin: the direction of X "
                        f"is sensitive to touch errors; touch at least {GOOD_X_DISTANCE * 1e3:.0f} "
                        "mm away")
    if off < NEAR_COLLINEAR_SIN * np.linalg.norm(v):
        warnings.append(f"the XY-plane point is only {off * 1e3:.1f} mm from the X axis (nearly "
                        "collinear): the rotation about X is poorly determined; touch it near +Y")
    z = np.cross(x, v)
    z /= np.linalg.norm(z)
    return make_pose(np.stack([x, np.cross(z, x), z], axis=1), o), warnings


def _feature_points(T: NDArray[np.float64], roles: NDArray[np.str_],
                    free: NDArray[np.float64]) -> NDArray[np.float64]:
    """Model points in B: the origin, ``o + t x`` on the X axis, ``o + a x + b y`` in the plane.

    ``free`` holds one ``t`` per ``x`` touch then ``(a, b)`` per ``xy`` touch, in touch order.
    """
    o, x, y = T[:3, 3], T[:3, 0], T[:3, 1]
    out = np.tile(o, (len(roles), 1))
    ix = np.flatnonzero(roles == "x")
    ixy = np.flatnonzero(roles == "xy")
    out[ix] += np.outer(free[:len(ix)], x)
    ab = free[len(ix):].reshape(-1, 2)
    out[ixy] += np.outer(ab[:, 0], x) + np.outer(ab[:, 1], y)
    return out


def calibrate_workpiece(
    theta: ArrayLike,
    f: ArrayLike,
    roles: Sequence[str],
    T_R_B: ArrayLike,
    *,
    T_R_B_covariance: ArrayLike | None = None,
    noise_sigma: float | None = None,
    prior_sigma: float | None = None,
    labels: Sequence[str] | None = None,
) -> CalibrationResult:
    """Calibrate the workpiece frame ``T_B_W`` on a calibrated turntable.

    Parameters
    ----------
    theta : array_like, shape (N,)
        Table angle at each touch (radians); any angles.
    f : array_like, shape (N, 3)
        TCP position at each touch in the robot base frame R (metres).
    roles : sequence of str, length N
        ``"origin"``, ``"x"`` (a point on +X) or ``"xy"`` (a point in the XY plane with positive
        Y) per touch; every role at least once.
    T_R_B : array_like, shape (4, 4)
        Turntable root frame in R from :func:`robotcell.calibration.turntable.calibrate_turntable`.
    T_R_B_covariance : array_like, shape (6, 6), optional
        Covariance of ``T_R_B`` in the :func:`robotcell.calibration.fitting.perturb_pose`
        parameters (origin in metres, rotation vector in radians about the axes of R). When given
        it is propagated into the uncertainty of ``T_B_W``.
    noise_sigma : float, optional
        Touch noise (metres per coordinate), e.g. the turntable fit's ``noise_sigma``. Used for
        the uncertainty when the touches have no redundancy (one touch per role).
    prior_sigma : float, optional
        Known touch noise (metres per coordinate), used for the uncertainty whenever given
        (overrides ``noise_sigma`` and the estimate from the residuals).
    labels : sequence of str, optional
        Name of each touch (default ``"1".."N"``).

    Returns
    -------
    CalibrationResult
        ``values``: ``T_B_W`` (4, 4). ``sigma``: ``T_B_W_position`` (m), ``T_B_W_rotation`` (rad,
        about the axes of B), including the turntable's uncertainty when its covariance is given.
        ``residuals`` (N, 3) in R: distance of each touch from its feature (zero for the 3-point
        method). ``json_fields``: ``matrix``, ``xyzabc`` (of ``T_B_W``), ``turntable_matrix``,
        ``turntable_included`` (bool).

    Raises
    ------
    InputError
        Wrong shapes, NaN, unknown or missing roles, an invalid ``T_R_B``.
    IllPosedError
        +X point at the origin, XY point on the X axis (both to rounding), or touches that do not
        determine the frame (see :func:`robotcell.calibration.fit`). Points close together are
        computed, with a warning and a larger condition number.
    """
    f = as_points(f, "TCP positions")
    theta = np.asarray(theta, dtype=float)
    n = len(f)
    if f.ndim != 2 or theta.shape != (n,):
        raise InputError(f"table angles must have shape (N,) matching TCP positions (N, 3); "
                         f"got {theta.shape} and {f.shape}")
    if not np.all(np.isfinite(theta)):
        raise InputError("table angles contain NaN or infinite values")
    roles = np.array([str(r).strip().lower() for r in roles])
    if roles.shape != (n,):
        raise InputError(f"need one role per touch ({n}), got {roles.size}")
    bad = sorted(set(roles.tolist()) - set(ROLES))
    if bad:
        raise InputError(f"touch roles must be origin, x or xy; found {', '.join(bad)}")
    missing = [r for r in ROLES if r not in roles]
    if missing:
        raise InputError(f"no touch of {', '.join(missing)}: the workpiece frame needs the origin, "
                         "a point on +X and a point in the XY plane with positive Y")
    T_R_B = validate_pose(T_R_B, "T_R_B")
    cov_t = None
    if T_R_B_covariance is not None:
        cov_t = np.asarray(T_R_B_covariance, dtype=float)
        if cov_t.shape != (6, 6) or not np.all(np.isfinite(cov_t)):
            raise InputError(f"T_R_B covariance must be a finite 6x6 matrix, got shape {cov_t.shape}")
    labels = list(labels) if labels is not None else [str(i + 1) for i in range(n)]

    p = table_points(T_R_B, theta, f)
    T0, warnings = _start_frame(p, roles)
    back = rot_z(theta) @ T_R_B[:3, :3]

    def residuals(x: NDArray[np.float64], t: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        q = p if t is None else table_points(perturb_pose(T_R_B, t), theta, f)
        r_b = q - _feature_points(perturb_pose(T0, x[:6]), roles, x[6:])
        return np.einsum("nij,nj->ni", back, r_b)

    e0 = p - T0[:3, 3]
    free0 = np.concatenate([e0[roles == "x"] @ T0[:3, 0],
                            (e0[roles == "xy"] @ T0[:3, :2]).ravel()])
    x0 = np.concatenate([T0[:3, 3], np.zeros(3), free0])
    names = ["origin x", "origin y", "origin z", "rotation about B x", "rotation about B y",
             "rotation about B z"]
    names += [f"position of touch {labels[i]} along X" for i in np.flatnonzero(roles == "x")]
    names += [f"position of touch {labels[i]} in the XY plane ({c})"
              for i in np.flatnonzero(roles == "xy") for c in "xy"]
    borrowed = prior_sigma is None and 3 * n == len(x0)
    if borrowed:
        prior_sigma = noise_sigma
    res = fit(residuals, x0, names, prior_sigma=prior_sigma)
    cov = res.covariance
    undetermined = []
    if cov_t is not None:
        t0 = np.concatenate([T_R_B[:3, 3], np.zeros(3)])
        J_t = jacobian(lambda t: residuals(res.x, t), t0)
        J = res.jacobian
        G = -np.linalg.solve(J.T @ J, J.T @ J_t)
        cov = cov + G @ cov_t @ G.T
    cov = cov[:6, :6]
    if cov_t is None:
        undetermined.append("the turntable calibration's own uncertainty (no covariance given), "
                            "which is not included in the 1-sigma figures")
    if res.noise_source == "none":
        warnings.append("one touch per point and no noise level given: no uncertainty can be "
                        "stated; pass the turntable's noise level or touch each point twice")
    if res.condition > CONDITION_LIMIT:
        warnings.append(f"condition number {res.condition:.0f} is above {CONDITION_LIMIT:.0f}: "
                        "touch the +X and XY points farther from the origin")
    warnings += outlier_warnings(res, labels)
    T = perturb_pose(T0, res.x[:6])
    sd = np.sqrt(np.abs(np.diag(cov)))
    return CalibrationResult(
        procedure="workpiece", values={"T_B_W": T},
        sigma={"T_B_W_position": sd[:3], "T_B_W_rotation": sd[3:6]},
        residuals=res.residuals, condition=res.condition, dof=res.dof,
        noise_sigma=res.noise_sigma,
        noise_source="turntable" if borrowed and res.noise_source == "prior" else res.noise_source,
        labels=labels,
        undetermined=undetermined, warnings=warnings,
        next_step=("enter T_B_W as the workpiece (base) frame on the turntable's kinematics in the "
                   "controller, then check it by touching the origin at two other table angles"),
        json_fields={**pose_fields(T), "turntable_matrix": pose_fields(T_R_B)["matrix"],
                     "turntable_included": cov_t is not None},
        covariance=cov,
        parameter_names=["origin_x", "origin_y", "origin_z", "rotvec_x", "rotvec_y", "rotvec_z"],
    )
