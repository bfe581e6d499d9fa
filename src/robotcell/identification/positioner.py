"""Two-axis positioner (tilt and rotate) calibration from touches of one point on the table.

The robot touches the same reference point on the table at several (tilt, rotate) combinations;
its TCP positions in the robot base frame R are the measurements of a 2-joint chain whose device
frame is R. :func:`robotcell.identification.identify` fits the chain (start: the nominal
positioner, or the circle point analysis of the touches), and this module reads the geometry
off the identified chain, with first-order uncertainties from its covariance:

* the tilt axis (joint 1) and the rotate axis (joint 2) as lines in R at ``q = 0``;
* their common normal: foot points on both axes, length, and the angle between the axes;
* the zero of each: ``tilt_zero`` is the angle about the tilt axis from "up" (the robot base's
  ``+Z`` made perpendicular to the tilt axis) to the rotate axis at tilt 0, so 0 for a level table;
  ``rotate_zero`` is the angle about the rotate axis from ``X_B`` to the reference point at
  rotate 0;
* ``T_R_B``, the root frame: ``Z_B`` along the tilt axis, origin at the foot of the common normal
  on it, ``X_B`` along the common normal. Of its two directions, ``+-z_tilt x z_rotate`` (for
  axes that nearly intersect, the touch noise alone would decide "toward the rotate axis"), the
  one on the side the nominal's DH frame between the axes takes, else ``z_tilt x z_rotate``.

The identified chain is written in the nominal's conventions: of the equivalent DH tables
(the root frame turned about its Z axis, an intermediate frame turned by 180 deg about its Z,
with the offsets that compensate), the one nearest the nominal's root and zeros.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from robotcell.calibration.fitting import (
    DEFAULT_TOUCH_SIGMA,
    Fit,
    keeps_out,
    outlier_warnings,
    perturb_pose,
    solution_fit,
)
from robotcell.calibration.propagate import jacobian
from robotcell.calibration.result import (
    CONDITION_LIMIT,
    CalibrationResult,
    fit_fields,
    pose_fields,
)
from robotcell.calibration.uncertainty import Estimate, Inputs, estimate
from robotcell.errors import IllPosedError, InputError
from robotcell.identification.circles import start_model
from robotcell.identification.engine import identify
from robotcell.identification.measurements import TargetMeasurements
from robotcell.identification.result import IdentificationResult
from robotcell.kinematics.transforms import as_points
from robotcell.robot.robot import Robot

__all__ = ["AXIS_CONSTANTS", "PositionerCalibration", "calibrate_positioner", "perturbed_chain"]

#: The constants of each axis among a positioner chain's parameters, after its root pose.
AXIS_CONSTANTS = ("a", "alpha", "d", "theta")


@dataclass(frozen=True, eq=False)
class PositionerCalibration:
    """Outcome of :func:`calibrate_positioner`.

    Attributes
    ----------
    result : CalibrationResult
        Procedure ``"positioner-2axis"``; see :func:`calibrate_positioner` for its values.
    robot : Robot
        The identified positioner as a 2-joint DH chain whose ``base`` is its root pose in the
        robot base frame R and whose tool is the reference point: ``robot.fk(q)[:3, 3]`` is the
        touched point at tilt, rotate ``q`` (rad), in R (m).
    identification : IdentificationResult
        The engine's full result (parameters, fixed ones, correlations).
    """

    result: CalibrationResult
    robot: Robot
    identification: IdentificationResult


def _unit(v: NDArray[np.float64]) -> NDArray[np.float64]:
    return v / np.linalg.norm(v)


def _geometry(ident: IdentificationResult, x: NDArray[np.float64],
              side: float = 1.0) -> dict[str, NDArray[np.float64]]:
    """Axis lines, common normal, zeros and root frame in R for the full parameter vector ``x``.

    ``side``: ``X_B = side * unit(z_tilt x z_rotate)`` (+1 or -1).
    """
    ch = ident._chain
    pts, dirs, _ = ch.axis_lines(x)
    T = ch.base_pose(x)
    p = pts @ T[:3, :3].T + T[:3, 3]
    u = dirs @ T[:3, :3].T
    w = np.cross(u[0], u[1])
    if np.linalg.norm(w) < 1e-9:
        raise InputError("the identified tilt and rotate axes are parallel: not a tilt-rotate positioner")
    # Feet of the common normal: p0 + s u0 and p1 + t u1.
    s, t, _ = np.linalg.solve(np.stack([u[0], -u[1], w], axis=1), p[1] - p[0])
    f0, f1 = p[0] + s * u[0], p[1] + t * u[1]
    n = f1 - f0
    length = float(np.linalg.norm(n))
    x_b = side * _unit(w)
    up = np.array([0.0, 0.0, 1.0]) if abs(u[0][2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    up = _unit(up - (up @ u[0]) * u[0])
    tilt_zero = math.atan2(np.cross(up, u[1]) @ u[0], up @ u[1])
    # Reference point at q = 0.
    ref = ident._chain.predict(x, np.zeros((1, 2)))[0][0, 0]
    r = ref - f1 - ((ref - f1) @ u[1]) * u[1]
    rotate_zero = math.atan2(np.cross(x_b, r) @ u[1], x_b @ r)
    R = np.stack([x_b, np.cross(u[0], x_b), u[0]], axis=1)
    return {"tilt_point": f0, "tilt_axis": u[0], "rotate_point": f1, "rotate_axis": u[1],
            "normal_length": np.array(length), "axis_angle": np.array(math.acos(np.clip(u[0] @ u[1], -1, 1))),
            "tilt_zero": np.array(tilt_zero), "rotate_zero": np.array(rotate_zero),
            "radius": np.array(np.linalg.norm(r)), "R": R, "origin": f0}


def _free_index(ident: IdentificationResult) -> NDArray[np.intp]:
    """Indices of the identified (free) parameters in the chain's full parameter vector."""
    return np.array([ident._chain.index(nm) for nm in ident.free])


def _normal_side(nominal: Robot) -> float:
    """+1 when the nominal's DH frame between its two axes has X along ``z_1 x z_2`` (the axes
    of motion), else -1: the nominal's way of writing the common normal, whatever its place."""
    q = np.zeros(2)
    axes = nominal.jacobian(q)[3:]  # angular part: the directions of motion
    x1 = nominal.frames(q)[1, :3, 0]
    return 1.0 if x1 @ np.cross(axes[:, 0], axes[:, 1]) >= 0 else -1.0


def _wrap(a: float) -> float:
    """An angle in (-pi, pi]."""
    return math.pi - (math.pi - a) % (2.0 * math.pi)


def nearest_writing(robot: Robot, nominal: Robot) -> Robot:
    """The same chain written in the DH table nearest the nominal's.

    Two tables describe the same motion when (a) the root frame turns about its Z axis by
    ``phi`` and the first joint's offset by ``-phi`` (standard DH), or (b) an intermediate
    frame turns by 180 deg about its Z axis: its joint's offset ``+ pi``, the next one's
    ``- pi``, and the link between (standard DH: that joint's; modified: the next row's) gets
    ``-a`` and ``-alpha``. (a) takes the root X nearest the nominal's; (b) is taken where it
    brings the twists and offsets nearer the nominal's. Every joint value moves each frame to
    the same place, so every pose of the chain is the same.

    Parameters
    ----------
    robot : Robot
        An identified chain.
    nominal : Robot
        The nominal chain, same joints and convention.

    Returns
    -------
    Robot
    """
    joints = list(robot.joints)
    base = robot.base.copy()
    standard = robot.convention == "standard"
    if standard or (joints[0].a == 0.0 and joints[0].alpha == 0.0):
        z, x = base[:3, 2], base[:3, 0]
        xn = nominal.base[:3, 0] - (nominal.base[:3, 0] @ z) * z
        if np.linalg.norm(xn) > 1e-6:
            phi = math.atan2(np.cross(x, xn) @ z, x @ xn)
            base[:3, :3] = base[:3, :3] @ Rotation.from_rotvec([0.0, 0.0, phi]).as_matrix()
            joints[0] = replace(joints[0], theta=_wrap(joints[0].theta - phi))

    def distance(js: list) -> float:
        return sum(_wrap(j.alpha - n.alpha) ** 2 + _wrap(j.theta - n.theta) ** 2
                   + ((j.a - n.a) / 0.1) ** 2 for j, n in zip(js, nominal.joints))

    for i in range(len(joints) - 1):
        flipped = list(joints)
        link = i if standard else i + 1
        flipped[i] = replace(flipped[i], theta=_wrap(flipped[i].theta + math.pi))
        flipped[link] = replace(flipped[link], a=-flipped[link].a, alpha=-flipped[link].alpha)
        flipped[i + 1] = replace(flipped[i + 1], theta=_wrap(flipped[i + 1].theta - math.pi))
        if distance(flipped) < distance(joints):
            joints = flipped
    return replace(robot, base=base, joints=tuple(joints))


def perturbed_chain(chain: Robot, w: ArrayLike) -> Robot:
    """A positioner chain moved by its parameters (the positioner's error sources are over them).

    Parameters
    ----------
    chain : Robot
        The chain, ``base`` its root pose in the parent (m).
    w : array_like, shape (6 + 4 n,)
        The root origin moved by ``w[:3]`` (m) and its rotation by the rotation vector ``w[3:6]``
        about the parent's axes (rad, ``exp([w]x) R``), then per axis the change of its DH
        constants ``a`` (m), ``alpha`` (rad), ``d`` (m) and ``theta`` (rad).

    Returns
    -------
    Robot
    """
    w = np.asarray(w, dtype=float)
    T = chain.base
    rows = w[6:].reshape(chain.n_joints, len(AXIS_CONSTANTS))
    joints = tuple(replace(j, a=j.a + r[0], alpha=j.alpha + r[1], d=j.d + r[2],
                           theta=j.theta + r[3]) for j, r in zip(chain.joints, rows))
    return replace(chain, base=perturb_pose(T, np.r_[T[:3, 3] + w[:3], w[3:6]]), joints=joints)


def _chain_estimate(ident: IdentificationResult, res: Fit, robot: Robot,
                    q: NDArray[np.float64]) -> Estimate:
    """The error of the written chain's parameters (:func:`perturbed_chain`).

    The written chain (``robot``, in the nominal's conventions) moves the plate frame as the
    identified one does. A change of the identified parameters moves the plate at the touched
    axis values ``q``; the change of the written parameters that moves it the same way (least
    squares, the smallest where the parameters overlap) is its image. The constants that one
    touched point cannot separate from its place on the plate define the plate frame: they get
    no error (a frame on the plate is touched into that frame).
    """
    ch, x = ident._chain, ident._x
    kept = _free_index(ident)
    chain = robot.with_tool(np.eye(4))

    def identified(v: NDArray[np.float64]) -> NDArray[np.float64]:
        xx = x.copy()
        xx[kept] = v
        pts, R = ch.predict(xx, q)
        origin = pts[:, 0] - np.einsum("nij,j->ni", R, ch.targets(xx)[0])
        return np.concatenate([origin, R.reshape(len(q), 9)], axis=1)

    def written(w: NDArray[np.float64]) -> NDArray[np.float64]:
        T = perturbed_chain(chain, w).fk(q, np.eye(4))
        return np.concatenate([T[:, :3, 3], T[:, :3, :3].reshape(len(q), 9)], axis=1)

    size = 6 + len(AXIS_CONSTANTS) * chain.n_joints
    A = np.linalg.lstsq(jacobian(written, np.zeros(size)), jacobian(identified, x[kept]),
                        rcond=1e-10)[0]
    return estimate(res.sources, res.input_gain, A)


def _imputed(ident: IdentificationResult, q: NDArray[np.float64], f: NDArray[np.float64],
             keep: NDArray[np.bool_]) -> NDArray[np.float64]:
    """The touches with those left out replaced by the chain fitted to the others.

    The chain is refitted to the touches ``keep`` from the identified one (a few Gauss-Newton
    steps, it is near); a touch replaced by that fit's prediction has no residual there, so the
    identification of the whole grid with it (a balanced design the engine starts from
    reliably) has the same optimum as the fit without the touch.
    """
    ch = ident._chain
    kept = _free_index(ident)
    x = ident._x.copy()

    def model(v: NDArray[np.float64]) -> NDArray[np.float64]:
        x[kept] = v
        return ch.predict(x, q)[0][:, 0]

    def resid(v: NDArray[np.float64]) -> NDArray[np.float64]:
        return (f - model(v))[keep].ravel()

    def jac(v: NDArray[np.float64]) -> NDArray[np.float64]:
        x[kept] = v
        pts = ch.predict(x, q)[0]
        return -ch.point_jacobian(x, q, ch.evaluate(x, q), pts)[keep, 0][..., kept].reshape(
            -1, len(kept))

    v = least_squares(resid, x[kept], jac=jac, method="lm", xtol=1e-12, ftol=1e-12,
                      gtol=1e-12).x
    out = f.copy()
    out[~keep] = model(v)[~keep]
    return out


def _fit_of(ident: IdentificationResult, q: NDArray[np.float64], f: NDArray[np.float64],
            used: NDArray[np.bool_], sigma: float | None, inputs: Inputs | None) -> Fit:
    """The uncertainty and the touch tests of an identification, over every touch.

    The Jacobian of the touched point with respect to the identified (free) parameters, at all
    touches (those left out of the identification too), and the residuals.
    """
    ch, x = ident._chain, ident._x
    kept = _free_index(ident)
    pts = ch.predict(x, q)[0]
    J = -ch.point_jacobian(x, q, ch.evaluate(x, q), pts)[:, 0][..., kept]
    return solution_fit(x[kept], J, f - pts[:, 0], used=used, sigma=sigma,
                        inputs=inputs)


def calibrate_positioner(
    angles: ArrayLike,
    points: ArrayLike,
    *,
    nominal: Robot | None = None,
    sigma: float | None = None,
    labels: Sequence[str] | None = None,
    inputs: Inputs | None = None,
    group_tol: float | None = None,
) -> PositionerCalibration:
    """Calibrate a tilt-rotate positioner from touches of one point on its table.

    The uncertainty rests on the touch accuracy (``sigma``, or the default 0.5 mm), the
    residuals being its chi-square check, and every touch gets the leave-one-out test of every
    calibration (:func:`robotcell.calibration.fitting.solution_fit`): one flagged touch that the
    others single out is left out and the chain identified again.

    Parameters
    ----------
    angles : array_like, shape (N, 2)
        Tilt and rotate axis values at each touch (rad).
    points : array_like, shape (N, 3)
        Touched TCP position in the robot base frame R (m).
    nominal : Robot, optional
        Nominal 2-joint model of the positioner (any base). Without it the touches must contain,
        for each axis, at least 3 that move that axis alone over 10 deg or more (e.g. a grid of 3
        tilt by 4 rotate values), and the circle point analysis gives the start. With it, of the
        equivalent ways to write the identified axes the one nearest the nominal is returned.
    sigma : float, optional
        Touch accuracy (m per coordinate) the uncertainties rest on; default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    labels : sequence of str, optional
        Name of each touch (default ``"1".."N"``).
    inputs : Inputs, optional
        Earlier calibrations the touched points rest on (the tool, a track).
    group_tol : float, optional
        Axis values within this of each other (rad) are the same commanded value, for the touches
        that move one axis alone; default derived from the data
        (:func:`robotcell.calibration.grouping.resolution`), so that values read back from the
        controller with jitter group as the grid commanded.

    Returns
    -------
    PositionerCalibration
        ``result.values`` (SI, in R, at ``q = 0``): ``T_R_B`` (root frame, see the module),
        ``tilt_point``, ``tilt_axis``, ``rotate_point``, ``rotate_axis`` (feet of the common
        normal and unit directions), ``normal_length`` (m), ``axis_angle`` (rad, 90 deg for a
        perpendicular pair), ``tilt_zero``, ``rotate_zero`` (rad), ``radius`` (m, of the
        reference point about the rotate axis); ``sigma`` for each (first order, from the
        identification's covariance), ``T_R_B_position`` and ``T_R_B_rotation``;
        ``estimates`` of ``T_R_B`` and of ``chain``, the parameters of the returned chain
        (:func:`perturbed_chain`: root pose, then ``a``, ``alpha``, ``d``, ``theta`` of each axis).

    Raises
    ------
    InputError
        Wrong shapes, NaN, a nominal model that is not a 2-joint chain.
    IllPosedError
        Too few touches for the unknowns, or (without a nominal model) no touches moving one axis.
    """
    f = as_points(points, "touched points")
    q = np.asarray(angles, dtype=float)
    if f.ndim != 2 or q.shape != (len(f), 2):
        raise InputError(f"angles must have shape (N, 2) (tilt, rotate) matching touched points (N, 3); "
                         f"got {q.shape} and {f.shape}")
    if nominal is not None and nominal.n_joints != 2:
        raise InputError(f"a 2-axis positioner needs a 2-joint nominal model, {nominal.name} has "
                         f"{nominal.n_joints}")
    labels = list(labels) if labels is not None else [str(i + 1) for i in range(len(f))]
    meas = TargetMeasurements(q, f, None, tuple(labels))
    start = (nominal if nominal is not None
             else start_model(meas, np.zeros(2, dtype=bool), "positioner", group_tol))
    ident, res = _identified(start, meas, f, sigma, inputs, group_tol)
    side = 1.0 if nominal is None else _normal_side(nominal)
    geometry = _geometry_sigmas(ident, res, side)
    robot = replace(ident.robot, base=ident.base @ ident.robot.base, tool=ident.target_tool)
    if nominal is not None:
        robot = nearest_writing(robot, nominal)
    result = _positioner_result(ident, res, geometry, robot, q, f, labels)
    return PositionerCalibration(result=result, robot=robot, identification=ident)


def _identified(start: Robot, meas: TargetMeasurements, f: NDArray[np.float64],
                sigma: float | None, inputs: Inputs | None, group_tol: float | None
                ) -> tuple[IdentificationResult, Fit]:
    """The chain identified from ``start`` on the touches ``meas`` (of points ``f``, (N, 3)),
    and its fit; one touch that the others single out is left out and the chain identified
    again. ``group_tol`` as for :func:`calibrate_positioner`."""
    q, labels = meas.q, meas.labels
    s = sigma if sigma is not None else DEFAULT_TOUCH_SIGMA
    name = f"{start.name}_calibrated"
    ident = identify(start, meas, sigma=s, name=name, group_tol=group_tol)
    used = np.ones(len(f), dtype=bool)
    res = _fit_of(ident, q, f, used, sigma, inputs)
    if len(res.suspects) == 1:
        worst = res.suspects[0]
        keep = used.copy()
        keep[worst] = False
        try:
            other = identify(start, TargetMeasurements(q, _imputed(ident, q, f, keep), None,
                                                 tuple(labels)), sigma=s, name=name,
                             group_tol=group_tol)
        except IllPosedError:
            other = None
        if other is not None:
            res_other = _fit_of(other, q, f, keep, sigma, inputs)
            if keeps_out(res_other, worst):
                ident, res = other, res_other
    return ident, res


@dataclass(frozen=True)
class _Geometry:
    """The geometry of an identified positioner (:func:`_geometry`) with its 1-sigma."""

    values: dict[str, Any]
    keys: list[str]
    A: NDArray[np.float64]
    C: NDArray[np.float64]
    sigma: dict[str, object]


def _geometry_sigmas(ident: IdentificationResult, res: Fit, side: float) -> _Geometry:
    """The axes, their common normal, zeros and root frame of the identified chain, and their
    first-order 1-sigma from the fit's covariance (``A``: their derivative by the free
    parameters, ``C`` their covariance)."""
    x = ident._x
    kept = _free_index(ident)

    def at(v: NDArray[np.float64]) -> NDArray[np.float64]:
        xx = x.copy()
        xx[kept] = v
        return xx

    geo = _geometry(ident, x, side)
    keys = ["tilt_point", "tilt_axis", "rotate_point", "rotate_axis", "normal_length", "axis_angle",
            "tilt_zero", "rotate_zero", "radius"]

    def flat(v: NDArray[np.float64]) -> NDArray[np.float64]:
        g = _geometry(ident, at(v), side)
        rot = Rotation.from_matrix(g["R"] @ geo["R"].T).as_rotvec()
        return np.concatenate([np.ravel(g[k]) for k in keys] + [g["origin"], rot])

    A = jacobian(flat, x[kept])
    C = A @ res.covariance @ A.T
    sig = np.sqrt(np.abs(np.diag(C)))
    sigma_out: dict[str, object] = {}
    k0 = 0
    for k in keys:
        size = np.size(geo[k])
        sigma_out[k] = sig[k0:k0 + size] if size > 1 else float(sig[k0])
        k0 += size
    sigma_out["T_R_B_position"], sigma_out["T_R_B_rotation"] = sig[k0:k0 + 3], sig[k0 + 3:k0 + 6]
    return _Geometry(geo, keys, A, C, sigma_out)


def _positioner_result(ident: IdentificationResult, res: Fit, geometry: _Geometry, robot: Robot,
                       q: NDArray[np.float64], f: NDArray[np.float64], labels: list[str]
                       ) -> CalibrationResult:
    """The result of :func:`calibrate_positioner` (procedure ``positioner-2axis``)."""
    geo, keys, A, C, sigma_out = (geometry.values, geometry.keys, geometry.A, geometry.C,
                                  geometry.sigma)
    T_R_B = np.eye(4)
    T_R_B[:3, :3], T_R_B[:3, 3] = geo["R"], geo["origin"]
    values = {"T_R_B": T_R_B, **{k: geo[k] if np.size(geo[k]) > 1 else float(geo[k]) for k in keys}}
    warnings = []
    if res.condition > CONDITION_LIMIT:
        warnings.append(f"condition number {res.condition:.0f} is above {CONDITION_LIMIT:.0f}: touch "
                        "at more tilt and rotate values, spread over their ranges")
    warnings += outlier_warnings(res, labels)
    mapped, ends = res.sources.map(A), np.cumsum([np.size(geo[k]) for k in keys])
    result = CalibrationResult(
        procedure="positioner-2axis", values=values, sigma=sigma_out,
        labels=labels, undetermined=[f"{n}: {w}" for n, w in ident.fixed], warnings=warnings,
        next_step=("enter T_R_B and the axis geometry as the positioner's kinematics in the "
                   "controller (KUKA: external kinematics ROOT and links; ABB: the mechanical unit's "
                   "base frame and arm positions), then calibrate the workpiece on the table"),
        kinds={"tilt_point": "length", "rotate_point": "length", "tilt_axis": "number",
               "rotate_axis": "number", "normal_length": "length", "axis_angle": "angle",
               "tilt_zero": "angle", "rotate_zero": "angle", "radius": "length"},
        json_fields={**pose_fields(T_R_B), "tilt_point_mm": geo["tilt_point"] * 1e3,
                     "tilt_axis": geo["tilt_axis"], "rotate_point_mm": geo["rotate_point"] * 1e3,
                     "rotate_axis": geo["rotate_axis"],
                     "normal_length_mm": geo["normal_length"] * 1e3,
                     "axis_angle_deg": math.degrees(geo["axis_angle"]),
                     "tilt_zero_deg": math.degrees(geo["tilt_zero"]),
                     "rotate_zero_deg": math.degrees(geo["rotate_zero"])},
        covariance=C, parameter_names=[f"{k}[{i}]" if np.size(geo[k]) > 1 else k for k in keys
                                       for i in range(np.size(geo[k]))]
        + ["origin_x", "origin_y", "origin_z", "rotvec_x", "rotvec_y", "rotvec_z"],
        points=f, estimates={"T_R_B": estimate(res.sources, res.input_gain, A[-6:]),
                             "chain": _chain_estimate(ident, res, robot, q)},
        value_sources={k: mapped.select(np.arange(e - np.size(geo[k]), e))
                       for k, e in zip(keys, ends)},
        **fit_fields(res),
    )
    return result
