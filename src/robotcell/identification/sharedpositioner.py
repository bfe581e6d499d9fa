"""One 2-axis positioner, two robots: do their calibrations of it agree, and all touches in one fit.

A tilt-rotate positioner that two robots reach is calibrated by each in its own base
(:func:`robotcell.identification.calibrate_positioner`, on the identification engine, which is why
this module stands in :mod:`robotcell.identification` beside it and not beside the turntable's
:mod:`robotcell.calibration.sharedtable`), and the robot-to-robot pose
(:func:`robotcell.calibration.robottorobot.robot_to_robot`) links the two bases.

**What is compared.** How the plate moves is fixed by the two axis lines at axis values 0; the
point each robot touched on the plate (its radius, the rotate zero measured to it) is that
robot's own and is not compared. The two lines are 8 numbers (:data:`COMPONENTS`): the root
frame ``T_R_B`` (``Z_B`` on the tilt axis, origin at the foot of the common normal, ``X_B``
along the normal: the tilt axis line and the direction of the normal, 6), the signed distance
of the rotate axis from the tilt axis along ``X_B`` (``axis_offset``, m) and the signed angle
from the tilt axis to the rotate axis about ``X_B`` (``axis_angle``, rad). Together they are
both lines (each a point and a direction) and nothing else, so their difference has a regular
covariance. :func:`compare_positioner` carries the other robot's 8 numbers into the reference
base through ``T_ref_other`` and gives the difference with its covariance, every error source
counted once (a tool used by the link and by a positioner calibration is one error), and names
a disagreement beyond a stated level (chi-square with 8 degrees of freedom).

**The joint fit.** :func:`shared_positioner` fits all touches of both robots at once: each robot
touches a point on the plate at several (tilt, rotate) values, and optionally both touch common
fixed points. The unknowns are ``T_ref_other``, the positioner's 8 numbers in the reference base
and each robot's point on the plate (and the common points); each robot's tool error is
estimated with the rest under its stated accuracy
(:func:`robotcell.calibration.priors.fit_with_priors`). Two skew axis lines seen by both robots
fix ``T_ref_other`` without common points. :func:`lines_chain` moves a positioner chain onto
fitted axis lines, as a cell writes them. See ``docs/calibration.md``, "Robot to robot".
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robotcell.calibration.fitting import fit
from robotcell.calibration.priors import PriorFit, fit_with_priors
from robotcell.calibration.result import (
    CalibrationResult,
    pose_fields,
)
from robotcell.calibration.robottorobot import (
    RobotTouches,
    common_points,
    joined_inputs,
    small_rotation,
)
from robotcell.calibration.sharedtable import (
    Agreement,
    judge_agreement,
    pose_estimate,
    through_link,
    two_robot_fit,
)
from robotcell.calibration.uncertainty import OWN, Sources, estimate
from robotcell.errors import InputError
from robotcell.identification.positioner import (
    AXIS_CONSTANTS,
    PositionerCalibration,
    calibrate_positioner,
    perturbed_chain,
)
from robotcell.kinematics.transforms import make_pose, rot_x, rot_z
from robotcell.robot.robot import Robot

__all__ = ["COMPONENTS", "PositionerLines", "chain_lines", "compare_positioner", "lines_chain",
           "positioner_lines", "shared_positioner"]

#: The compared numbers of a 2-axis positioner, in order.
COMPONENTS = ("root position x", "root position y", "root position z", "root rotation about x",
              "root rotation about y", "root rotation about z", "distance between the axes",
              "angle between the axes")
#: Which of :data:`COMPONENTS` are lengths (the others are angles).
LENGTHS = (True, True, True, False, False, False, True, False)

#: The procedure name of a 2-axis positioner calibration's result.
POSITIONER = "positioner-2axis"


@dataclass(frozen=True)
class PositionerLines:
    """A 2-axis positioner's axis lines at axis values 0, as :data:`COMPONENTS` take them.

    Attributes
    ----------
    T_B : ndarray, shape (4, 4)
        The root frame (m): ``Z_B`` on the tilt axis, origin at the foot of the common normal,
        ``X_B`` along it.
    offset : float
        Signed distance of the rotate axis from the tilt axis along ``X_B`` (m).
    angle : float
        Signed angle from the tilt axis to the rotate axis about ``X_B`` (rad): the rotate axis
        is ``(0, -sin angle, cos angle)`` in B.
    sources : Sources, optional
        Error sources of the 8 numbers (root origin, rotation vector about the parent's axes,
        ``offset``, ``angle``).
    """

    T_B: NDArray[np.float64]
    offset: float
    angle: float
    sources: Sources | None = None


def positioner_lines(result: CalibrationResult, name: str = "") -> PositionerLines:
    """The axis lines of a 2-axis positioner calibration, with their error sources.

    Parameters
    ----------
    result : CalibrationResult
        A result of :func:`robotcell.identification.calibrate_positioner` (procedure
        ``positioner-2axis``), in any frame (``T_R_B``, or ``T_world_B`` in a cell).
    name : str
        Name of its own touch noise as an error source (two calibrations' own noises are
        independent errors); default the result's own name.

    Returns
    -------
    PositionerLines
    """
    if result.procedure != POSITIONER or "rotate_axis" not in result.values:
        raise InputError(f"a {result.procedure} result is not a 2-axis positioner calibration; "
                         "give the results of calibrate_positioner (robotcell calibrate "
                         "positioner)")
    own = name or OWN
    T, s_T = pose_estimate(result, own)
    s_T = s_T.select(range(6))
    v = result.values
    u1 = np.asarray(v["rotate_axis"], dtype=float)
    between = np.asarray(v["rotate_point"], dtype=float) - np.asarray(v["tilt_point"], dtype=float)
    offset = float(between @ T[:3, 0])
    angle = math.atan2(-(u1 @ T[:3, 1]), u1 @ T[:3, 2])
    vs = result.value_sources
    if "normal_length" not in vs or "axis_angle" not in vs:
        raise InputError("the positioner result carries no error sources of its axes; calibrate "
                         "it again with this version")
    # |offset| and |angle| are the result's normal length and axis angle: the signs are fixed
    # away from parallel axes, so their error sources are the signed ones'.
    parts = [s_T, vs["normal_length"].renamed(OWN, own).map([[1.0 if offset >= 0 else -1.0]]),
             vs["axis_angle"].renamed(OWN, own).map([[1.0 if angle >= 0 else -1.0]])]
    return PositionerLines(T, offset, angle, Sources.stack(parts))


def chain_lines(chain: Robot, like: PositionerLines | None = None) -> PositionerLines:
    """The axis lines of a 2-axis positioner chain at axis values 0, as :data:`COMPONENTS`.

    Parameters
    ----------
    chain : Robot
        A 2-joint chain, ``base`` its root in the frame wanted (m).
    like : PositionerLines, optional
        Lines whose ``X_B`` gives the side of the common normal to take (a calibration's);
        default ``z_tilt x z_rotate``.

    Returns
    -------
    PositionerLines
        ``Z_B`` along the direction about which a positive tilt value turns; no sources.
    """
    q = np.zeros(chain.n_joints)
    J, p = chain.jacobian(q), chain.fk(q)[:3, 3]
    u = (J[3:] / np.linalg.norm(J[3:], axis=0)).T                        # (2, 3) directions
    c = p + np.cross(u, J[:3].T)                                         # a point on each axis
    w = np.cross(u[0], u[1])
    if np.linalg.norm(w) < 1e-9:
        raise InputError("the tilt and rotate axes are parallel: not a tilt-rotate positioner")
    s, _, _ = np.linalg.solve(np.stack([u[0], -u[1], w], axis=1), c[1] - c[0])
    x = w / np.linalg.norm(w)
    if like is not None and x @ like.T_B[:3, 0] < 0:
        x = -x
    R = np.stack([x, np.cross(u[0], x), u[0]], axis=1)
    origin = c[0] + s * u[0]
    return PositionerLines(make_pose(R, origin), float((c[1] - origin) @ x),
                           math.atan2(-(u[1] @ R[:, 1]), u[1] @ R[:, 2]))


def _as_chain_writes(lines: PositionerLines, chain: Robot) -> PositionerLines:
    """``lines`` written as :func:`chain_lines` writes those of ``chain``: ``Z_B`` and the
    rotate axis along the directions of positive motion. A reversed direction adds pi to the
    angle, so the 8 numbers' errors are the same."""
    u = chain.jacobian(np.zeros(chain.n_joints))[3:].T                   # (2, 3) motion
    T = lines.T_B.copy()
    rotate = T[:3, :3] @ np.array([0.0, -math.sin(lines.angle), math.cos(lines.angle)])
    if u[0] @ T[:3, 2] < 0:
        T[:3, 1:3] = -T[:3, 1:3]
    if u[1] @ rotate < 0:
        rotate = -rotate
    return PositionerLines(T, lines.offset, math.atan2(-(rotate @ T[:3, 1]), rotate @ T[:3, 2]))


def _lines_error(chain: Robot, target: PositionerLines) -> NDArray[np.float64]:
    """The 8 numbers of ``target`` minus those of ``chain``'s lines (rotation vector about the
    parent's axes, the angle wrapped)."""
    got = chain_lines(chain, like=target)
    turn = Rotation.from_matrix(target.T_B[:3, :3] @ got.T_B[:3, :3].T).as_rotvec()
    angle = math.remainder(target.angle - got.angle, 2.0 * math.pi)
    return np.concatenate([target.T_B[:3, 3] - got.T_B[:3, 3], turn,
                           [target.offset - got.offset, angle]])


def lines_chain(chain: Robot, lines: PositionerLines
                ) -> tuple[Robot, NDArray[np.float64]]:
    """The chain nearest ``chain`` whose axis lines at axis values 0 are ``lines``.

    The change of the chain's parameters
    (:func:`~robotcell.identification.positioner.perturbed_chain`: root origin and rotation,
    each axis's DH constants) is the smallest that moves its lines
    onto ``lines`` (Gauss-Newton with minimum-norm steps): what the lines do not fix (the plate
    frame on the last axis, the writing of the DH table) stays as ``chain`` has it.

    Parameters
    ----------
    chain : Robot
        A 2-joint positioner chain, ``base`` its root in the frame of ``lines`` (m), written as
        the cell holds it (e.g. :func:`~robotcell.identification.calibrate_positioner`'s).
    lines : PositionerLines
        The axis lines wanted (``sources`` not used).

    Returns
    -------
    chain : Robot
        The moved chain (its tool as ``chain``'s).
    gain : ndarray, shape (6 + 4 n, 8)
        The change of its parameters by a change of the 8 numbers of ``lines``
        (:data:`COMPONENTS`; rotation vector about the parent's axes): the map of their errors.
    """
    target = _as_chain_writes(lines, chain)
    size = 6 + len(AXIS_CONSTANTS) * chain.n_joints
    step_h = 1e-7
    J = np.zeros((8, size))
    for _ in range(20):
        err = _lines_error(chain, target)
        for k in range(size):
            J[:, k] = (err - _lines_error(perturbed_chain(chain, step_h * np.eye(size)[k]),
                                          target)) / step_h
        if np.max(np.abs(err)) < 1e-12:
            break
        chain = perturbed_chain(chain, np.linalg.lstsq(J, err, rcond=None)[0])
    return chain, np.linalg.pinv(J)


def compare_positioner(ref: CalibrationResult, other: CalibrationResult,
                       link: CalibrationResult, *, level: float = 3.0,
                       names: Sequence[str] = ("reference", "other")) -> Agreement:
    """Compare two robots' calibrations of one 2-axis positioner through their link.

    Parameters
    ----------
    ref : CalibrationResult
        The reference robot's positioner calibration (procedure ``positioner-2axis``, in its
        base).
    other : CalibrationResult
        The other robot's calibration of the same positioner, in its own base.
    link : CalibrationResult
        The robot-to-robot result (``T_ref_other``).
    level : float
        Sigma level beyond which the two disagree (default 3: a false alarm in 0.27 % of
        comparisons of right calibrations).
    names : sequence of 2 str
        The robots' names, for the message.

    Returns
    -------
    Agreement
        The reference's :data:`COMPONENTS` minus the other's carried into the reference base
        (``T_ref_other T_other_B``; the distance and angle between the axes do not depend on the
        frame), its covariance and the verdict.
    """
    a = positioner_lines(ref, f"{names[0]} positioner touches")
    b = positioner_lines(other, f"{names[1]} positioner touches")
    if a.angle * b.angle < 0:
        raise InputError("the two positioner calibrations write the root frame with opposite "
                         "X_B (common normal) directions; calibrate both with the same nominal "
                         "positioner")
    T_ro, s_ro = pose_estimate(link, "robot-to-robot")
    pose_diff, J_ro, J_b = through_link(a.T_B, T_ro, b.T_B)
    diff = np.concatenate([pose_diff, [a.offset - b.offset, a.angle - b.angle]])
    J_link = np.zeros((8, 6))
    J_link[:6] = J_ro
    J_other = np.eye(8)
    J_other[:6, :6] = J_b
    assert a.sources is not None and b.sources is not None
    sources = a.sources + s_ro.select(range(6)).map(-J_link) + b.sources.map(-J_other)
    return judge_agreement(diff, sources.covariance, level, names, "positioner", COMPONENTS,
                           LENGTHS)


# -- the joint fit -----------------------------------------------------------------------------
def _moved(T_B: NDArray[np.float64], offset: float, angle: float, signs: NDArray[np.float64],
           values: NDArray[np.float64], point: NDArray[np.float64]) -> NDArray[np.float64]:
    """The point ``point`` of the plate (in the rotate axis's frame at rotate 0) at axis values
    ``values`` (N, 2), in the frame of ``T_B``: ``T_B Rz(s0 e1) Tx(offset) Rx(angle) Rz(s1 e2)``."""
    p2 = np.einsum("nij,j->ni", rot_z(signs[1] * values[:, 1]), point)
    p1 = p2 @ rot_x(angle).T + np.array([offset, 0.0, 0.0])
    p0 = np.einsum("nij,nj->ni", rot_z(signs[0] * values[:, 0]), p1)
    return p0 @ T_B[:3, :3].T + T_B[:3, 3]


@dataclass(frozen=True)
class _Start:
    """One robot's positioner alone, in its base: the joint fit's start."""

    lines: PositionerLines
    point: NDArray[np.float64]
    signs: NDArray[np.float64]


def _start(values: NDArray[np.float64], touches: RobotTouches, nominal: Robot | None,
           sigma: float | None, cal: PositionerCalibration | None) -> _Start:
    """The positioner calibrated from one robot's touches (its lines, the touched point on the
    plate and the sense in which each axis value turns about its axis); ``cal`` when given."""
    if cal is None:
        cal = calibrate_positioner(values, touches.points, nominal=nominal, sigma=sigma)
    lines = positioner_lines(cal.result)
    T, u = lines.T_B, cal.robot.jacobian(np.zeros(2))[3:]   # directions of positive motion
    rotate = np.asarray(cal.result.values["rotate_axis"], dtype=float)
    signs = np.array([1.0 if u[:, 0] @ T[:3, 2] >= 0 else -1.0,
                      1.0 if u[:, 1] @ rotate >= 0 else -1.0])
    at_zero = cal.robot.fk(np.zeros(2))[:3, 3]
    point = rot_x(lines.angle).T @ (T[:3, :3].T @ (at_zero - T[:3, 3])
                                     - np.array([lines.offset, 0.0, 0.0]))
    return _Start(lines, point, signs)


def _unpack(x: NDArray[np.float64], T_ro0: NDArray[np.float64], T_B0: NDArray[np.float64]):
    """``(T_ref_other, T_ref_B, offset, angle, ref point, other point, common points)``."""
    return (make_pose(small_rotation(x[3:6]) @ T_ro0[:3, :3], x[:3]),
            make_pose(small_rotation(x[9:12]) @ T_B0[:3, :3], x[6:9]), float(x[12]),
            float(x[13]), x[14:17], x[17:20], x[20:].reshape(-1, 3))


def _values(values: ArrayLike, touches: RobotTouches) -> NDArray[np.float64]:
    v = np.asarray(values, dtype=float)
    if v.shape != (len(touches.points), 2) or not np.all(np.isfinite(v)):
        raise InputError(f"{touches.robot or 'a robot'}: give the tilt and rotate values (rad) "
                         f"of each touch, shape ({len(touches.points)}, 2); got {v.shape}")
    return v


def shared_positioner(ref_table: RobotTouches, ref_values: ArrayLike, other_table: RobotTouches,
                      other_values: ArrayLike, *,
                      common: tuple[RobotTouches, RobotTouches] | None = None,
                      sigma: float | None = None,
                      nominal: tuple[Robot | None, Robot | None] = (None, None),
                      start: tuple[PositionerCalibration, PositionerCalibration] | None = None
                      ) -> CalibrationResult:
    """All touches of two robots of one 2-axis positioner in one maximum-likelihood fit.

    Each robot touches one sharp point on the plate (each its own) at several (tilt, rotate)
    values, as for :func:`~robotcell.identification.calibrate_positioner`; optionally both touch
    common fixed points. The unknowns are ``T_ref_other``, the positioner's axis lines in the
    reference base (``T_ref_B``, ``axis_offset``, ``axis_angle``: :class:`PositionerLines`),
    each robot's point on the plate and the common points; every touch has the isotropic error
    ``sigma``, and each robot's tool error (the touches' inputs) is estimated with the rest under
    its stated accuracy.

    Parameters
    ----------
    ref_table, other_table : RobotTouches
        Each robot's touches of its point on the plate (names are not used).
    ref_values, other_values : array_like, shape (N, 2)
        Tilt and rotate values at each touch (rad).
    common : (RobotTouches, RobotTouches), optional
        Both robots' touches of common fixed points (see
        :func:`~robotcell.calibration.robottorobot.robot_to_robot`).
    sigma : float, optional
        Touch accuracy (m per coordinate); default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    nominal : (Robot or None, Robot or None)
        The nominal positioner chain in each robot's base, for the start (and the direction of
        ``X_B``); without it each robot's touches start from their circles (a grid of tilt by
        rotate values).
    start : (PositionerCalibration, PositionerCalibration), optional
        Each robot's calibration of the positioner from these touches, when already computed
        (:func:`~robotcell.identification.calibrate_positioner`): the start, instead of
        calibrating them again.

    Returns
    -------
    CalibrationResult
        ``values``: ``T_ref_other``, ``T_ref_B`` (4x4, m), ``axis_offset`` (m), ``axis_angle``
        (rad), each with its 1-sigma; ``covariance`` over both poses, the offset and the angle
        (14, in that order); ``estimates`` of both poses.
    """
    va, vb = _values(ref_values, ref_table), _values(other_values, other_table)
    given = (None, None) if start is None else start
    sa = _start(va, ref_table, nominal[0], sigma, given[0])
    sb = _start(vb, other_table, nominal[1], sigma, given[1])
    if sa.lines.angle * sb.lines.angle < 0:  # the other robot's X_B the other way round
        flip = make_pose(rot_z(math.pi), np.zeros(3))
        sb = _Start(PositionerLines(sb.lines.T_B @ flip, -sb.lines.offset, -sb.lines.angle),
                    np.array([-1.0, -1.0, 1.0]) * sb.point, sb.signs)
    T_B0, T_ro0 = sa.lines.T_B, sa.lines.T_B @ np.linalg.inv(sb.lines.T_B)
    sets = [ref_table, other_table]
    ia = ib = np.zeros(0, dtype=int)
    c0 = np.zeros((0, 3))
    if common is not None:
        names = common_points(*common)
        sets += list(common)
        ia = np.array([names.index(n) for n in common[0].names])
        ib = np.array([names.index(n) for n in common[1].names])
        c0 = np.array([common[0].points[ia == k].mean(axis=0) for k in range(len(names))])

    def resid(x: NDArray[np.float64]) -> NDArray[np.float64]:
        T, T_B, off, ang, pa, pb, c = _unpack(x, T_ro0, T_B0)
        out = [ref_table.points - _moved(T_B, off, ang, sa.signs, va, pa),
               other_table.points - (_moved(T_B, off, ang, sb.signs, vb, pb) - T[:3, 3])
               @ T[:3, :3]]
        if common is not None:
            out += [common[0].points - c[ia], common[1].points - (c[ib] - T[:3, 3]) @ T[:3, :3]]
        return np.concatenate(out)

    axes = ("x", "y", "z", "rx", "ry", "rz")
    names_x = ([f"T_ref_other {a}" for a in axes] + [f"T_ref_B {a}" for a in axes]
               + ["axis_offset", "axis_angle"] + [f"ref plate point {a}" for a in "xyz"]
               + [f"other plate point {a}" for a in "xyz"]
               + [f"common point {k + 1} {a}" for k in range(len(c0)) for a in "xyz"])
    x0 = np.concatenate([T_ro0[:3, 3], np.zeros(3), T_B0[:3, 3], np.zeros(3),
                         [sa.lines.offset, sa.lines.angle], sa.point, sb.point, c0.ravel()])
    advice = ("touch the plate point at more tilt and rotate values, spread over their ranges, "
              "with both robots")
    inputs = joined_inputs(sets)
    if inputs is None:
        res = fit(resid, x0, names_x, sigma, advice)
        pf = PriorFit(res, len(x0), len(res.residuals), res.sources, res.input_gain, [])
    else:
        pf = fit_with_priors(resid, x0, names_x, sigma, advice, inputs)
    return _joint_result(pf, _unpack(pf.x, T_ro0, T_B0), sets)


def _joint_result(pf: PriorFit, fitted: tuple, sets: list[RobotTouches]) -> CalibrationResult:
    """The result of :func:`shared_positioner`: both poses, the axes' offset and angle,
    residuals of every touch (the other robot's along the reference base's axes)."""
    T, T_B, off, ang = fitted[:4]
    labels, warnings, fields = two_robot_fit(
        pf, T, sets, "positioner",
        "touch the plate point at more tilt and rotate values with both robots")
    sigma, p = pf.sources.sigma, pf.size
    axes = ("x", "y", "z", "rx", "ry", "rz")
    return CalibrationResult(
        procedure="robot-to-robot",
        values={"T_ref_other": T, "T_ref_B": T_B, "axis_offset": off, "axis_angle": ang},
        sigma={"T_ref_other_position": sigma[:3], "T_ref_other_rotation": sigma[3:6],
               "T_ref_B_position": sigma[6:9], "T_ref_B_rotation": sigma[9:12],
               "axis_offset": float(sigma[12]), "axis_angle": float(sigma[13])},
        labels=labels, warnings=warnings, kinds={"axis_offset": "length", "axis_angle": "angle"},
        next_step=("enter T_ref_other as the other robot's base and T_ref_B with the axes as the "
                   "positioner's root in the reference robot's base"),
        json_fields={**pose_fields(T), "method": "shared positioner"},
        covariance=pf.covariance[:14, :14],
        parameter_names=[f"T_ref_other {a}" for a in axes] + [f"T_ref_B {a}" for a in axes]
        + ["axis_offset", "axis_angle"],
        estimates={"T_ref_other": estimate(pf.sources, pf.gain, np.eye(6, p)),
                   "T_ref_B": estimate(pf.sources, pf.gain, np.eye(6, p, 6))},
        value_sources={"axis_offset": pf.sources.select([12]),
                       "axis_angle": pf.sources.select([13])},
        **fields,
    )
