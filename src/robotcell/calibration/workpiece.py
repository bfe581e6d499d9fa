"""Workpiece frame W on a calibrated turntable, from touches at any table angles.

Each touch ``f_i`` (in R) taken at table angle ``theta_i`` is carried back to the table at angle 0,

    B_p_i = Rz(theta_i)^-1 T_B_R f_i,

where the workpiece has a fixed pose ``T_B_W`` (the lecture assumes every touch at angle 0; any
angle works). The frame is then the 3-point frame of these points
(:func:`robotcell.calibration.frame.frame_3point`: origin; a point on +X; a point in the XY plane
with positive Y; several touches per role make it the maximum-likelihood best fit). The rotation
back to R keeps the noise isotropic, so this is the maximum-likelihood estimate for touches
measured in R; the turntable's error enters every carried-back point and is propagated as an
input. The moving pose is ``T_R_W(theta) = T_R_B Rz(theta) T_B_W`` (:func:`workpiece_pose`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.fitting import perturb_pose
from robotcell.calibration.frame import frame_3point
from robotcell.calibration.propagate import jacobian
from robotcell.calibration.result import CalibrationResult, pose_fields
from robotcell.calibration.uncertainty import Inputs, Sources, joined
from robotcell.errors import InputError
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


def calibrate_workpiece(
    theta: ArrayLike,
    f: ArrayLike,
    roles: Sequence[str],
    T_R_B: ArrayLike,
    *,
    T_R_B_covariance: ArrayLike | Sources | None = None,
    inputs: Inputs | None = None,
    sigma: float | None = None,
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
    T_R_B_covariance : array_like, shape (6, 6), or Sources, optional
        Uncertainty of ``T_R_B`` in the :func:`robotcell.calibration.fitting.perturb_pose`
        parameters (origin in metres, rotation vector in radians about the axes of R): a
        covariance (one error source, ``"turntable"``), or its error sources (shared with
        ``inputs`` where the turntable was calibrated with the same tool). Propagated into the
        uncertainty of ``T_B_W``.
    inputs : Inputs, optional
        Earlier calibrations the touched points ``f`` rest on (the tool, a track).
    sigma : float, optional
        Touch accuracy (metres per coordinate) the uncertainties rest on; default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    labels : sequence of str, optional
        Name of each touch (default ``"1".."N"``).

    Returns
    -------
    CalibrationResult
        ``values``: ``T_B_W`` (4, 4). ``sigma``: ``T_B_W_position`` (m), ``T_B_W_rotation`` (rad,
        about the axes of B), including the turntable's uncertainty when given.
        ``residuals`` (N, 3) in R: distance of each touch from its feature (zero for the 3-point
        method). ``json_fields``: ``matrix``, ``xyzabc`` (of ``T_B_W``), ``turntable_matrix``,
        ``turntable_included`` (bool).

    Raises
    ------
    InputError
        Wrong shapes, NaN, unknown or missing roles, an invalid ``T_R_B``.
    IllPosedError
        +X point at the origin, XY point on the X axis (both to rounding), or touches that do not
        determine the frame (see :func:`robotcell.calibration.frame.frame_3point`). Points close
        together are computed, with a warning and a larger condition number.
    """
    f, theta, roles, T_R_B, turntable, labels = _workpiece_touches(theta, f, roles, T_R_B,
                                                                   T_R_B_covariance, labels)
    n = len(f)
    back = rot_z(theta) @ T_R_B[:3, :3]  # carries a vector in B at angle 0 back to R
    p = table_points(T_R_B, theta, f)
    to_b = None if inputs is None else inputs.rotated(np.swapaxes(back, 1, 2))
    if turntable is not None:
        t0 = np.concatenate([T_R_B[:3, 3], np.zeros(3)])
        moved = jacobian(lambda t: table_points(perturb_pose(T_R_B, t), theta, f), t0)
        to_b = joined(to_b, moved.reshape(n, 3, 6), turntable,
                      [f"turntable {k}" for k in ("x", "y", "z", "rx", "ry", "rz")])
    out = frame_3point(p, list(roles), sigma, labels, inputs=to_b).renamed("T_R_W", "T_B_W")
    out.residuals = np.einsum("nij,nj->ni", back, out.residuals)
    if out.points is not None:
        out.points = f
    out.procedure = "workpiece"
    if turntable is None:
        out.undetermined.append("the turntable calibration's own uncertainty (no covariance "
                                "given), which is not included in the 1-sigma figures")
    out.next_step = ("enter T_B_W as the workpiece (base) frame on the turntable's kinematics in "
                     "the controller, then check it by touching the origin at two other table "
                     "angles")
    out.json_fields.update({"turntable_matrix": pose_fields(T_R_B)["matrix"],
                            "turntable_included": turntable is not None})
    return out


def _workpiece_touches(theta: ArrayLike, f: ArrayLike, roles: Sequence[str], T_R_B: ArrayLike,
                       T_R_B_covariance: ArrayLike | Sources | None,
                       labels: Sequence[str] | None) -> tuple[Any, ...]:
    """The input of :func:`calibrate_workpiece`, checked: TCP positions, angles, roles, the
    turntable's pose and its error sources (None when not given), labels."""
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
    turntable = T_R_B_covariance
    if turntable is not None and not isinstance(turntable, Sources):
        cov_t = np.asarray(turntable, dtype=float)
        if cov_t.shape != (6, 6) or not np.all(np.isfinite(cov_t)):
            raise InputError(f"T_R_B covariance must be a finite 6x6 matrix, got shape {cov_t.shape}")
        turntable = Sources.of("turntable", cov_t)
    labels = list(labels) if labels is not None else [str(i + 1) for i in range(n)]
    return f, theta, roles, T_R_B, turntable, labels
