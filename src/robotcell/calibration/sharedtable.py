"""One turntable, two robots: do their calibrations of it agree, and all their touches in one fit.

A turntable (or a positioner's axis) that two robots reach is calibrated by each in its own base
(:func:`robotcell.calibration.turntable.calibrate_turntable`), and the robot-to-robot pose
(:func:`robotcell.calibration.robottorobot.robot_to_robot`) links the two bases. Then
``T_ref_B`` (the reference robot's calibration) and ``T_ref_other T_other_B`` (the other's,
carried into the reference base) are two estimates of one pose: :func:`compare_shared` gives
their difference with its covariance, every error source counted once (a tool used by both the
link and a turntable calibration is one error), and names a disagreement beyond a stated level.
:func:`shared_turntable` fits every touch of both robots at once, with the robot-to-robot pose
as a parameter: the touches of one point on the table at several angles by both robots, and
optionally their touches of common fixed points. See ``docs/calibration.md``, "Robot to robot".
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation
from scipy.special import chdtri, erf

from robotcell.calibration.fitting import SAME_POINT, fit, outlier_warnings
from robotcell.calibration.grouping import distinct
from robotcell.calibration.priors import PriorFit, fit_with_priors
from robotcell.calibration.result import (
    CONDITION_LIMIT,
    CalibrationResult,
    fit_fields,
    pose_fields,
)
from robotcell.calibration.robottorobot import (
    RobotTouches,
    common_points,
    joined_inputs,
    small_rotation,
)
from robotcell.calibration.uncertainty import OWN, Sources, estimate
from robotcell.errors import IllPosedError, InputError
from robotcell.kinematics.transforms import invert, make_pose, rot_z, transform_points

__all__ = ["Agreement", "carried", "compare_shared", "judge_agreement", "pose_estimate",
           "prior_warnings", "shared_turntable", "through_link", "two_robot_fit"]

_AXES = ("position x", "position y", "position z", "rotation about x", "rotation about y",
         "rotation about z")


@dataclass(frozen=True)
class Agreement:
    """Two calibrations of one pose compared in one frame.

    Attributes
    ----------
    difference : ndarray, shape (6,)
        First minus second: origin (m, along the frame's axes) and rotation vector ``d`` with
        ``R_first = exp([d]x) R_second`` (rad).
    covariance : ndarray, shape (6, 6)
        Covariance of ``difference`` (every error source counted once).
    chi2 : float
        ``difference^T covariance^-1 difference``: chi-square with 6 degrees of freedom when
        both calibrations are right.
    bound : float
        The chi-square bound of ``level`` (the probability of ``level`` sigma in one dimension).
    level : float
        The level, in sigma, beyond which the two disagree.
    message : str
        What the comparison says: agreement, or the disagreement with the components beyond
        ``level`` and what to check.
    components : tuple of str
        The name of each component (default: a pose's ``position x`` .. ``rotation about z``).
    lengths : tuple of bool
        Per component, whether it is a length (m; else an angle, rad).
    """

    difference: NDArray[np.float64]
    covariance: NDArray[np.float64]
    chi2: float
    bound: float
    level: float
    message: str
    components: tuple[str, ...] = _AXES
    lengths: tuple[bool, ...] = (True,) * 3 + (False,) * 3

    @property
    def sigma(self) -> NDArray[np.float64]:
        """1-sigma of each component of the difference, shape (6,)."""
        return np.sqrt(np.abs(np.diag(self.covariance)))

    @property
    def agree(self) -> bool:
        """Whether the difference lies within the level."""
        return self.chi2 <= self.bound

    def to_json(self) -> dict[str, Any]:
        """The comparison in mm and deg: the length components' differences and 1-sigma in mm,
        the angles' in deg, each in the order of ``components``."""
        z = self.difference / np.where(self.sigma > 0, self.sigma, np.inf)
        m = np.array(self.lengths, dtype=bool)
        return {"components": list(self.components),
                "difference_mm": (self.difference[m] * 1e3).tolist(),
                "difference_deg": np.degrees(self.difference[~m]).tolist(),
                "sigma_mm": (self.sigma[m] * 1e3).tolist(),
                "sigma_deg": np.degrees(self.sigma[~m]).tolist(), "z": z.tolist(),
                "chi2": self.chi2, "bound": self.bound, "agree": self.agree,
                "message": self.message}


def pose_estimate(result: CalibrationResult, name: str) -> tuple[NDArray[np.float64], Sources]:
    """The pose of a result (its first 4x4 value with error sources) and its sources, its own
    touch noise renamed after the calibration so that two results' own noises stay apart."""
    for key, value in result.values.items():
        if np.shape(value) == (4, 4) and key in result.estimates:
            src = result.estimates[key].sources
            return np.asarray(value, dtype=float), src.renamed(OWN, f"{name} touches")
    raise InputError(f"the {result.procedure} result has no pose with error sources to compare")


def carried(T_ro: NDArray[np.float64], T_oB: NDArray[np.float64]
             ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Derivatives of ``T_ro T_oB`` (origin, rotation vector) by those of ``T_ro`` and ``T_oB``."""
    R = T_ro[:3, :3]
    arm = R @ T_oB[:3, 3]
    J_ro = np.eye(6)
    J_ro[:3, 3:] = -np.array([[0.0, -arm[2], arm[1]], [arm[2], 0.0, -arm[0]],
                              [-arm[1], arm[0], 0.0]])
    J_oB = np.zeros((6, 6))
    J_oB[:3, :3] = J_oB[3:, 3:] = R
    return J_ro, J_oB


def through_link(T_a: NDArray[np.float64], T_ro: NDArray[np.float64],
                 T_b: NDArray[np.float64]
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """One item as the reference robot calibrated it (``T_a``) minus the other robot's
    (``T_b``) carried through the link ``T_ro``.

    Returns
    -------
    diff : ndarray, shape (6,)
        Origin difference (m) and rotation vector ``d`` with ``R_a = exp([d]x) R_ro R_b`` (rad).
    J_ro, J_b : ndarray, shape (6, 6)
        How ``T_ro T_b`` follows the link's and ``T_b``'s parameters (:func:`carried`).
    """
    T_c = T_ro @ T_b
    J_ro, J_b = carried(T_ro, T_b)
    diff = np.concatenate([T_a[:3, 3] - T_c[:3, 3],
                           Rotation.from_matrix(T_a[:3, :3] @ T_c[:3, :3].T).as_rotvec()])
    return diff, J_ro, J_b


def compare_shared(ref: CalibrationResult, other: CalibrationResult, link: CalibrationResult,
                   *, level: float = 3.0, names: Sequence[str] = ("reference", "other")
                   ) -> Agreement:
    """Compare two robots' calibrations of one turntable (or positioner root) through their link.

    Parameters
    ----------
    ref : CalibrationResult
        The reference robot's calibration of the pose (``T_R_B`` in its base).
    other : CalibrationResult
        The other robot's calibration of the same pose in its own base.
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
        ``T_ref_B`` minus ``T_ref_other T_other_B``, its covariance and the verdict.
    """
    T_a, s_a = pose_estimate(ref, f"{names[0]} turntable")
    T_b, s_b = pose_estimate(other, f"{names[1]} turntable")
    T_ro, s_ro = pose_estimate(link, "robot-to-robot")
    diff, J_ro, J_b = through_link(T_a, T_ro, T_b)
    sources = s_a.select(range(6)) + s_ro.select(range(6)).map(-J_ro) + s_b.select(
        range(6)).map(-J_b)
    return judge_agreement(diff, sources.covariance, level, names, "turntable")


def judge_agreement(diff: NDArray[np.float64], cov: NDArray[np.float64], level: float,
                    names: Sequence[str], what: str, components: tuple[str, ...] = _AXES,
                    lengths: tuple[bool, ...] = (True,) * 3 + (False,) * 3) -> Agreement:
    """Two robots' calibrations of one item compared: the chi-square of their difference.

    Parameters
    ----------
    diff : ndarray, shape (k,)
        First minus second (m and rad).
    cov : ndarray, shape (k, k)
        Its covariance, every error source counted once.
    level : float
        Sigma level beyond which the two disagree.
    names : sequence of 2 str
        The robots' names, for the message.
    what : str
        The item, for the message (``"turntable"``, ``"positioner"``).
    components, lengths : tuple
        The name of each component and whether it is a length (else an angle).

    Returns
    -------
    Agreement
    """
    k = len(diff)
    chi2 = float(diff @ np.linalg.pinv(cov) @ diff)
    bound = float(chdtri(k, 1.0 - erf(level / np.sqrt(2.0))))
    sig = np.sqrt(np.abs(np.diag(cov)))
    z = np.abs(diff) / np.where(sig > 0, sig, np.inf)
    if chi2 <= bound:
        message = (f"{names[0]}'s and {names[1]}'s calibrations of the {what} agree within "
                   f"{level:g} sigma (chi-square {chi2:.1f}, bound {bound:.1f})")
    else:
        worst = [i for i in np.argsort(-z) if z[i] > level] or [int(np.argmax(z))]
        parts = [f"{components[i]} by {diff[i] * 1e3:.2f} mm" if lengths[i] else
                 f"{components[i]} by {np.degrees(diff[i]):.3f} deg" for i in worst]
        parts = [f"{p} ({z[i]:.1f} sigma)" for p, i in zip(parts, worst, strict=True)]
        message = (f"{names[0]}'s and {names[1]}'s calibrations of the {what} disagree "
                   f"(chi-square {chi2:.1f}, bound {bound:.1f} for {level:g} sigma): "
                   f"{', '.join(parts)}; one of the tools, the robot-to-robot pose or a {what} "
                   "calibration is wrong: check each robot's tool (touch a fixed tip in two "
                   "orientations) and calibrate again")
    return Agreement(diff, cov, chi2, bound, level, message, components, lengths)


def _circle(angles: NDArray[np.float64], f: NDArray[np.float64], height: float
            ) -> tuple[NDArray[np.float64], float]:
    """One robot's turntable from its touches, linearly: ``f = b' + u cos + v sin`` (the start
    of :func:`~robotcell.calibration.turntable.calibrate_turntable`), as ``T_R_B`` and radius."""
    A = np.stack([np.ones_like(angles), np.cos(angles), np.sin(angles)], axis=1)
    (b, u, v), *_ = np.linalg.lstsq(A, f, rcond=None)
    x = u / np.linalg.norm(u)
    z = np.cross(u, v)
    z /= np.linalg.norm(z)
    R = np.stack([x, np.cross(z, x), z], axis=1)
    return make_pose(R, b + height * z), 0.5 * (np.linalg.norm(u) + np.linalg.norm(v))


def _start(ref_table: RobotTouches, ref_angles: NDArray[np.float64], other_table: RobotTouches,
           other_angles: NDArray[np.float64], height: float):
    """Each robot's turntable alone: the start of the joint fit (``T_ref_B``, radius,
    ``T_ref_other``). Refuses what the turntable calibration refuses (fewer than 3 distinct
    angles, a point on the axis)."""
    for t, a in ((ref_table, ref_angles), (other_table, other_angles)):
        if distinct(np.stack([np.cos(a), np.sin(a)], axis=1), None) < 3:
            raise IllPosedError(f"{t.robot or 'a robot'} touched the table point at fewer than 3 "
                                "distinct table angles: a circle needs 3; touch it at 3 or more "
                                "angles spread around the turn")
    T_a, r_a = _circle(ref_angles, ref_table.points, height)
    T_b, r_b = _circle(other_angles, other_table.points, height)
    if min(r_a, r_b) < SAME_POINT:
        raise IllPosedError("the table point does not move when the table turns (it lies on the "
                            "axis); touch a point near the rim")
    return T_a, 0.5 * (r_a + r_b), T_a @ invert(T_b)


def _model(height: float, T_ro0: NDArray[np.float64], T_B0: NDArray[np.float64]):
    """``unpack(x) -> (T_ref_other, T_ref_B, radius, common points)`` and
    ``table(T_B, r, theta)``, the touched table point at angles ``theta`` (N, 3)."""
    def unpack(x: NDArray[np.float64]):
        return (make_pose(small_rotation(x[3:6]) @ T_ro0[:3, :3], x[:3]),
                make_pose(small_rotation(x[9:12]) @ T_B0[:3, :3], x[6:9]), float(x[12]),
                x[13:].reshape(-1, 3))

    def table(T_B: NDArray[np.float64], r: float, theta: NDArray[np.float64]):
        return transform_points(T_B @ make_pose(rot_z(theta)), np.array([r, 0.0, -height]))

    return unpack, table


def shared_turntable(ref_table: RobotTouches, ref_angles: ArrayLike, other_table: RobotTouches,
                     other_angles: ArrayLike, *,
                     common: tuple[RobotTouches, RobotTouches] | None = None,
                     sigma: float | None = None, height: float = 0.0) -> CalibrationResult:
    """All touches of two robots in one maximum-likelihood fit: the turntable, and where the
    robots stand.

    Both robots touch one sharp point on the table, each at 3 or more table angles (and
    optionally both touch common fixed points). The unknowns are ``T_ref_other``, ``T_ref_B``
    (frame B as :func:`~robotcell.calibration.turntable.calibrate_turntable` defines it, from
    that point), its radius and the common points; every touch has the isotropic error
    ``sigma``, and the tools' errors in the touches' inputs are shared by all touches of their
    robot.

    Parameters
    ----------
    ref_table, other_table : RobotTouches
        Each robot's touches of the point on the table (names are not used).
    ref_angles, other_angles : array_like, shape (N,)
        The table angle at each touch (rad).
    common : (RobotTouches, RobotTouches), optional
        Both robots' touches of common fixed points (see
        :func:`~robotcell.calibration.robottorobot.robot_to_robot`).
    sigma : float, optional
        Touch accuracy (m per coordinate); default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    height : float
        Origin of B along ``Z_B`` relative to the touched point's plane (m).

    Returns
    -------
    CalibrationResult
        ``values``: ``T_ref_other``, ``T_ref_B`` (4x4, m) and ``radius`` (m), each with its
        1-sigma; ``covariance`` over both poses and the radius.
    """
    ta, tb = np.asarray(ref_angles, dtype=float), np.asarray(other_angles, dtype=float)
    if ta.shape != (len(ref_table.points),) or tb.shape != (len(other_table.points),):
        raise InputError("give one table angle per touch of each robot")
    T_B0, r0, T_ro0 = _start(ref_table, ta, other_table, tb, height)
    sets = [ref_table, other_table]
    ia = ib = np.zeros(0, dtype=int)
    c0 = np.zeros((0, 3))
    if common is not None:
        names = common_points(*common)
        sets += list(common)
        ia = np.array([names.index(n) for n in common[0].names])
        ib = np.array([names.index(n) for n in common[1].names])
        c0 = np.array([common[0].points[ia == k].mean(axis=0) for k in range(len(names))])
    unpack, table = _model(height, T_ro0, T_B0)

    def resid(x: NDArray[np.float64]) -> NDArray[np.float64]:
        T, T_B, r, c = unpack(x)
        out = [ref_table.points - table(T_B, r, ta),
               other_table.points - (table(T_B, r, tb) - T[:3, 3]) @ T[:3, :3]]
        if common is not None:
            out += [common[0].points - c[ia], common[1].points - (c[ib] - T[:3, 3]) @ T[:3, :3]]
        return np.concatenate(out)

    names_x = ([f"other base {a}" for a in _AXES] + [f"turntable {a}" for a in _AXES]
               + ["radius"] + [f"common point {k + 1} {a}" for k in range(len(c0)) for a in "xyz"])
    x0 = np.concatenate([T_ro0[:3, 3], np.zeros(3), T_B0[:3, 3], np.zeros(3), [r0], c0.ravel()])
    advice = "touch the table point at more angles, spread around the turn, with both robots"
    inputs = joined_inputs(sets)
    if inputs is None:
        res = fit(resid, x0, names_x, sigma, advice)
        pf = PriorFit(res, len(x0), len(res.residuals), res.sources, res.input_gain, [])
    else:
        pf = fit_with_priors(resid, x0, names_x, sigma, advice, inputs)
    return _shared_result(pf, unpack, sets)


def prior_warnings(pf: PriorFit) -> list[str]:
    """A prior (an input's stated accuracy) that the touches contradict, named."""
    res, n = pf.fit, pf.touches
    out = []
    for i in sorted(set(res.outliers) | set(res.excluded) | set(res.disagreeing)):
        if i >= n:
            out.append(f"the touches do not fit the stated accuracy of {pf.blocks[i - n]}: its "
                       "error is larger than stated; calibrate it again, then these touches")
    return out


def two_robot_fit(pf: PriorFit, T_ref_other: NDArray[np.float64], sets: list[RobotTouches],
                  kind: str, advice: str) -> tuple[list[str], list[str], dict[str, Any]]:
    """Labels, warnings and fit fields of a fit of two robots' touches of a shared axis (the
    first two sets, touches of kind ``kind``) and of their common points (the last two).

    The other robot's residuals are turned along the reference base's axes by ``T_ref_other``
    (4, 4); the fields hold the touches' rows only (not the tools' prior rows); ``advice`` is
    what to measure when the condition number exceeds :data:`CONDITION_LIMIT`.
    """
    res, n = pf.fit, pf.touches
    resid = res.residuals[:n].copy()
    rows = np.cumsum([0] + [len(s.points) for s in sets])
    for k in range(1, len(sets), 2):
        resid[rows[k]:rows[k + 1]] = resid[rows[k]:rows[k + 1]] @ T_ref_other[:3, :3].T
    kinds = [kind, kind, "point", "point"]
    labels = [f"{s.robot or ('ref', 'other')[k % 2]} {kinds[k]} touch {i + 1}"
              + (f" ({s.names[i]})" if kinds[k] == "point" else "")
              for k, s in enumerate(sets) for i in range(len(s.points))]
    warnings = outlier_warnings(res, labels + pf.blocks) + prior_warnings(pf)
    warnings = [w for w in warnings if not any(f"touch {b} " in w for b in pf.blocks)]
    if res.condition > CONDITION_LIMIT:
        warnings.append(f"condition number {res.condition:.0f} exceeds {CONDITION_LIMIT:.0f}: "
                        + advice)
    fields = fit_fields(res)
    fields["residuals"] = resid
    for key in ("excluded", "unchecked", "outliers", "disagreeing", "gross"):
        fields[key] = [i for i in fields[key] if i < n]
    return labels, warnings, fields


def _shared_result(pf: PriorFit, unpack, sets: list[RobotTouches]) -> CalibrationResult:
    """The result of :func:`shared_turntable`: both poses, the radius, residuals of every touch
    (the other robot's along the reference base's axes)."""
    T, T_B, r, _ = unpack(pf.x)
    labels, warnings, fields = two_robot_fit(
        pf, T, sets, "table", "touch the table point at more angles around the turn")
    p = pf.size
    sigma = pf.sources.sigma
    return CalibrationResult(
        procedure="robot-to-robot", values={"T_ref_other": T, "T_ref_B": T_B, "radius": r},
        sigma={"T_ref_other_position": sigma[:3], "T_ref_other_rotation": sigma[3:6],
               "T_ref_B_position": sigma[6:9], "T_ref_B_rotation": sigma[9:12],
               "radius": float(sigma[12])},
        labels=labels, warnings=warnings, kinds={"radius": "length"},
        next_step=("enter T_ref_other as the other robot's base and T_ref_B as the turntable's "
                   "root in the reference robot's base"),
        json_fields={**pose_fields(T), "method": "shared turntable"},
        covariance=pf.covariance[:13, :13],
        parameter_names=[f"T_ref_other {a}" for a in ("x", "y", "z", "rx", "ry", "rz")]
        + [f"T_ref_B {a}" for a in ("x", "y", "z", "rx", "ry", "rz")] + ["radius"],
        estimates={"T_ref_other": estimate(pf.sources, pf.gain, np.eye(6, p)),
                   "T_ref_B": estimate(pf.sources, pf.gain, np.eye(6, p, 6))},
        **fields,
    )
