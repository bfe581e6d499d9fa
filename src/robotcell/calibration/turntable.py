"""Turntable (rotary external axis) root point calibration from touches of one point on the table.

Frame B (``docs/conventions.md``): ``Z_B`` along the rotation axis, oriented so that a positive
table angle turns the table counter-clockwise about ``Z_B``; ``X_B`` points from the axis to the
reference point at table angle 0; the origin lies on the axis in the plane of the reference point,
optionally shifted by a known ``height`` along ``Z_B``. A reference point at radius ``r`` touched at
table angle ``theta_i`` has TCP position (in R)

    f_i = b + R_R_B Rz(theta_i) [r, 0, -height]^T,

i.e. with ``u = r X_B`` and ``v = r Y_B``, ``f_i = b' + u cos(theta_i) + v sin(theta_i)``: linear in
``(b', u, v)``. That linear least-squares solution (3 or more distinct angles) starts a nonlinear
maximum-likelihood fit of the 7 parameters ``b`` (3), the rotation ``R_R_B`` (3: axis direction and
phase) and ``r``, which keeps ``X_B``, ``Y_B`` orthonormal and the radius common to both.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.fitting import SAME_POINT, Fit, fit, outlier_warnings, perturb_rotation
from robotcell.calibration.grouping import distinct as count_distinct
from robotcell.calibration.propagate import jacobian
from robotcell.calibration.result import (
    CONDITION_LIMIT,
    CalibrationResult,
    fit_fields,
    pose_fields,
)
from robotcell.calibration.spec import SPECS
from robotcell.calibration.uncertainty import Inputs, Sources, estimate
from robotcell.errors import IllPosedError, InputError
from robotcell.kinematics.transforms import as_points, make_pose, rot_z

__all__ = ["angular_spread", "calibrate_turntable"]

#: Angular spread of the touches below which a warning is given (radians).
SPREAD_WARN = np.radians(90.0)
#: Radius (m) of the reference point below which a warning asks for a point nearer the rim.
RADIUS_WARN = 0.05


def angular_spread(theta: ArrayLike) -> float:
    """Arc of the table circle covered by the touches.

    Parameters
    ----------
    theta : array_like, shape (N,)
        Table angles (radians).

    Returns
    -------
    float
        ``2 pi`` minus the largest gap between neighbouring angles on the circle (radians); 0 for
        a single angle.
    """
    t = np.sort(np.mod(np.asarray(theta, dtype=float), 2.0 * np.pi))
    gaps = np.diff(np.concatenate([t, [t[0] + 2.0 * np.pi]]))
    return float(2.0 * np.pi - gaps.max())


def _check_angles(theta: NDArray[np.float64], group_tol: float | None) -> float:
    """Refuse angles that leave the circle undetermined (fewer than 3 distinct); return the spread.

    Repeated angles (90 twice, 0 and 360, or read back with jitter around one commanded angle)
    are data, averaged by the fit: angles are told apart to what they resolve
    (:func:`robotcell.calibration.grouping.distinct`, on the unit circle, whose chord is the
    angle to 1e-5 relative at the jitter's scale).
    """
    distinct = count_distinct(np.stack([np.cos(theta), np.sin(theta)], axis=1), group_tol)
    if distinct < 3:
        raise IllPosedError(
            f"the touches are at only {distinct} distinct table angle(s) (modulo 360 deg): a "
            "circle needs 3, so the axis and the radius are not determined; turn the table to at "
            "least 3 different angles, ideally spread around the full turn")
    return angular_spread(theta)


def _linear_start(theta: NDArray[np.float64], f: NDArray[np.float64]):
    """Linear LS for ``f = b' + u cos + v sin``; returns ``(b', R0, r0)``.

    Refuses a point on the axis to rounding (:data:`SAME_POINT`): it does not move, so the axis
    direction and the angle zero are not determined.
    """
    A = np.stack([np.ones_like(theta), np.cos(theta), np.sin(theta)], axis=1)
    (b, u, v), *_ = np.linalg.lstsq(A, f, rcond=None)
    r0 = 0.5 * (np.linalg.norm(u) + np.linalg.norm(v))
    if r0 < SAME_POINT:
        raise IllPosedError(
            "the reference point does not move when the table turns (it lies on the table axis), "
            "so the axis direction and the angle zero are not determined; touch a point at least "
            f"{RADIUS_WARN * 1e3:.0f} mm from the axis, ideally near the rim"
        )
    x = u / np.linalg.norm(u)
    z = np.cross(u, v)
    z /= np.linalg.norm(z)
    R0 = np.stack([x, np.cross(z, x), z], axis=1)
    return b, R0, r0


def calibrate_turntable(
    theta: ArrayLike,
    f: ArrayLike,
    *,
    height: float = 0.0,
    labels: Sequence[str] | None = None,
    sigma: float | None = None,
    inputs: Inputs | None = None,
    group_tol: float | None = None,
) -> CalibrationResult:
    """Calibrate the root frame B of a turntable from touches of one point on the table.

    Maximum-likelihood fit under isotropic Gaussian noise on the touched positions; the table
    angles are taken as exact.

    Parameters
    ----------
    theta : array_like, shape (N,)
        Table angle at each touch (radians), at least 3 distinct angles modulo a full turn;
        repeated angles are averaged by the fit. Below 90 deg of spread a warning is given.
    f : array_like, shape (N, 3)
        TCP position at each touch in the robot base frame R (metres).
    height : float
        Position of the origin of B along ``Z_B`` relative to the plane of the reference point
        (metres): e.g. ``-0.02`` puts it on the table top when the touched point is 20 mm above it.
    labels : sequence of str, optional
        Name of each touch (default ``"1".."N"``).
    sigma : float, optional
        Touch accuracy (metres per coordinate) the uncertainties rest on; default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    inputs : Inputs, optional
        Earlier calibrations the touched points rest on (the tool, a track), whose errors are
        added to the uncertainty.
    group_tol : float, optional
        Table angles within this of each other (rad) are the same commanded angle, for the count
        of distinct angles; default derived from the data
        (:func:`robotcell.calibration.grouping.resolution`).

    Returns
    -------
    CalibrationResult
        ``values``: ``T_R_B`` (4, 4), ``radius`` (m), ``axis`` (3,) ``Z_B`` in R, ``tilt`` (rad,
        angle between ``Z_B`` and the robot base Z), ``spread`` (rad, not estimated). ``sigma``:
        ``T_R_B_position`` (m), ``T_R_B_rotation`` (rad, about the axes of R), ``radius``,
        ``axis``, ``tilt`` (first-order; when the tilt is within 3 sigma of zero, where that
        linearisation fails, the angular 1-sigma of the axis direction instead). ``covariance``
        over ``parameter_names`` (position m, rotation vector rad, radius m). ``json_fields``:
        ``matrix``, ``xyzabc``, ``radius_mm``, ``tilt_deg``, ``spread_deg``, ``axis``,
        ``axis_sigma_deg``, ``height_mm``, ``T_R_B_covariance_mm_rad`` (6x6 over position mm and
        rotation vector rad, for the workpiece calibration).

    Raises
    ------
    InputError
        Wrong shapes, NaN, fewer than 3 touches.
    IllPosedError
        Fewer than 3 distinct angles, a reference point on the axis (to rounding), or touches that
        do not determine the parameters (see :func:`robotcell.calibration.fit`). A point near the
        axis is computed, with a warning below :data:`RADIUS_WARN` and a larger condition number.
    """
    f, theta, labels = _turntable_touches(theta, f, height, labels)
    spread = _check_angles(theta, group_tol)
    b_plane, R0, r0 = _linear_start(theta, f)
    rot_theta = rot_z(theta)

    def unpack(x: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
        return make_pose(perturb_rotation(R0, x[3:6]), x[:3]), float(x[6])

    def residuals(x: NDArray[np.float64]) -> NDArray[np.float64]:
        T, r = unpack(x)
        p = rot_theta @ np.array([r, 0.0, -height])
        return f - (p @ T[:3, :3].T + T[:3, 3])

    names = ["origin x", "origin y", "origin z", "rotation about R x", "rotation about R y",
             "rotation about R z", "radius"]
    x0 = np.concatenate([b_plane + height * R0[:, 2], np.zeros(3), [r0]])
    res = fit(residuals, x0, names, sigma, inputs=inputs)
    return _turntable_result(res, unpack, f, height, spread, labels)


def _turntable_touches(theta: ArrayLike, f: ArrayLike, height: float,
                       labels: Sequence[str] | None
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64], list[str]]:
    """The input of :func:`calibrate_turntable`, checked: TCP positions, angles, labels."""
    f = as_points(f, "TCP positions")
    theta = np.asarray(theta, dtype=float)
    if f.ndim != 2 or theta.shape != (len(f),):
        raise InputError(f"table angles must have shape (N,) matching TCP positions (N, 3); "
                         f"got {theta.shape} and {f.shape}")
    if not np.all(np.isfinite(theta)) or not np.isfinite(height):
        raise InputError("table angles or height contain NaN or infinite values")
    n = len(f)
    if n < SPECS["turntable"].minimum:
        raise InputError(f"touches: {n} given, at least {SPECS['turntable'].minimum} needed at "
                         "different table angles (6 or "
                         "more let a wrong touch be singled out)")
    labels = list(labels) if labels is not None else [str(i + 1) for i in range(n)]
    return f, theta, labels


def _turntable_result(res: Fit, unpack: Callable[[NDArray[np.float64]],
                                                 tuple[NDArray[np.float64], float]],
                      f: NDArray[np.float64], height: float, spread: float, labels: list[str]
                      ) -> CalibrationResult:
    """The result of :func:`calibrate_turntable` from its fit (``unpack`` gives ``T_R_B`` and
    the radius of the parameters)."""
    T, radius = unpack(res.x)
    axis = T[:3, 2]
    tilt = float(np.arccos(np.clip(axis[2], -1.0, 1.0)))

    def axis_of(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return unpack(x)[0][:3, 2]

    axis_sources = res.sources.map(jacobian(axis_of, res.x))
    axis_cov = axis_sources.covariance
    axis_sigma = float(np.sqrt(np.abs(np.trace(axis_cov))))
    if tilt > 3.0 * axis_sigma and np.pi - tilt > 3.0 * axis_sigma:
        tilt_sources = res.sources.map(jacobian(
            lambda x: np.arccos(np.clip(axis_of(x)[2], -1.0, 1.0)), res.x))
    else:  # the angular 1-sigma of the axis: each source's factor as one row (its trace)
        tilt_sources = Sources(1, {k: f.reshape(1, -1) for k, f in axis_sources.factors.items()})
    tilt_sigma = float(tilt_sources.sigma[0])

    warnings = _turntable_warnings(res, spread, radius, tilt)
    warnings += outlier_warnings(res, labels)
    to_mm_rad = np.array([1e3, 1e3, 1e3, 1.0, 1.0, 1.0])
    cov6_mm = res.covariance[:6, :6] * np.outer(to_mm_rad, to_mm_rad)
    json_fields = {
        **pose_fields(T),
        "radius_mm": radius * 1e3,
        "height_mm": height * 1e3,
        "axis": axis,
        "axis_sigma_deg": np.degrees(axis_sigma),
        "tilt_deg": np.degrees(tilt),
        "spread_deg": np.degrees(spread),
        "T_R_B_covariance_mm_rad": cov6_mm,
    }
    return CalibrationResult(
        procedure="turntable",
        values={"T_R_B": T, "radius": radius, "axis": axis, "tilt": tilt, "spread": spread},
        sigma={"T_R_B_position": res.sigma[:3], "T_R_B_rotation": res.sigma[3:6],
               "radius": float(res.sigma[6]), "axis": np.sqrt(np.abs(np.diag(axis_cov))),
               "tilt": tilt_sigma},
        labels=labels, warnings=warnings, points=f,
        next_step=("enter T_R_B as the turntable's root frame in the controller (KUKA: ROOT of "
                   "the external kinematics; ABB: base frame of the mechanical unit), then "
                   "calibrate the workpiece frame on the table (robotcell calibrate workpiece)"),
        kinds={"radius": "length", "axis": "number", "tilt": "angle", "spread": "angle"},
        json_fields=json_fields, covariance=res.covariance,
        parameter_names=["origin_x", "origin_y", "origin_z", "rotvec_x", "rotvec_y", "rotvec_z",
                         "radius"],
        estimates={"T_R_B": estimate(res.sources, res.input_gain, np.eye(6, 7))},
        value_sources={"radius": res.sources.select([6]), "axis": axis_sources,
                       "tilt": tilt_sources},
        **fit_fields(res),
    )


def _turntable_warnings(res: Fit, spread: float, radius: float, tilt: float) -> list[str]:
    """Warnings of a turntable fit: a short spread of angles, a point near the axis, an axis
    pointing down, a poor condition."""
    warnings = []
    if spread < SPREAD_WARN:
        warnings.append(f"the touches span only {np.degrees(spread):.0f} deg of table rotation; "
                        "spread them over at least 90 deg (ideally around the full turn) for a "
                        "well-determined axis")
    if radius < RADIUS_WARN:
        warnings.append(f"the reference point is only {radius * 1e3:.1f} mm from the table axis: the "
                        "axis direction and the angle zero are poorly determined; touch a point at "
                        f"least {RADIUS_WARN * 1e3:.0f} mm from the axis, ideally near the rim")
    if tilt > np.pi / 2:
        warnings.append("Z_B points downward in the robot base: positive table angles turn the "
                        "table clockwise seen from above; check the axis sign in the controller's "
                        "machine data if that is unexpected")
    if res.condition > CONDITION_LIMIT:
        warnings.append(f"condition number {res.condition:.0f} is above {CONDITION_LIMIT:.0f}: "
                        "spread the touches around the full turn and use a point near the rim")
    return warnings
