"""Robot to robot: the pose of one robot's base relative to another's, from touches both make.

Two methods give the same data. **Common points**: both robots touch the same fixed sharp points
(3 or more, not on one line) with calibrated tools; every touch records the TCP position in the
base of the robot that made it. **Pointer**: the reference robot holds a pointer (a tool of known
TCP) at several poses and the other robot touches its tip; the reference robot's "touch" of
each pose is the tip position its controller computes. Either way, point ``k`` is seen by the
reference robot at ``a_i = c_k + e_i`` and by the other robot at ``b_j = T_other_ref c_k + e_j``,
``c_k`` the point in the reference base and ``e`` the touch error (isotropic Gaussian, ``sigma``
per coordinate).

The maximum-likelihood estimate minimises the sum of squared residuals of all touches over the
pose ``T_ref_other`` and the points ``c_k``: a weighted Procrustes (Kabsch) solution of the
points' means starts a Gauss-Newton fit (:func:`robotcell.calibration.fitting.fit`). Each robot's
tool error (and a track's, when its touches are mapped through one) is one systematic error
shared by all its touches: it enters as an input of the fit (:class:`~robotcell.calibration.
uncertainty.Inputs`), in the 1-sigma, the chi-square check of the residuals and the test of
every touch, and the result says which part of its 1-sigma comes from the touches and which from
the tools (:mod:`robotcell.calibration.sigmaparts`). See ``docs/calibration.md``, "Robot to
robot".
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.fitting import Fit, fit, kabsch, outlier_warnings, perturb_pose
from robotcell.calibration.frame import COLLINEAR_SIN, NEAR_COLLINEAR_SIN
from robotcell.calibration.result import (
    CONDITION_LIMIT,
    CalibrationResult,
    fit_fields,
    pose_fields,
)
from robotcell.calibration.uncertainty import Inputs, Sources, estimate
from robotcell.errors import IllPosedError, InputError
from robotcell.kinematics.transforms import as_points, transform_points, validate_pose

__all__ = ["FEWEST_POINTS", "MAX_DISTANCE", "RobotTouches", "common_points", "joined_inputs",
           "point_means", "robot_to_robot", "small_rotation"]

#: Fewest common points: 3 not on one line fix a rigid pose (the controllers' procedures ask
#: for 3 or more, see ``docs/calibration.md``).
FEWEST_POINTS = 3
#: Largest distance (m) between two robot bases that robotcell accepts: two robots of one cell
#: whose bases are farther apart than 50 m do not reach common points; such a result is a unit
#: error (mm read as m) or touches of different points.
MAX_DISTANCE = 50.0
#: Ratio of the common points' spread across their best-fit line to their spread along it below
#: which they count as collinear and are refused: the rotation about that line is then not
#: determined to better than about 1/ratio times the touch noise over the points' spread (at 2 %,
#: 0.5 mm over 1 m: 1.4 deg). Between this and
#: :data:`~robotcell.calibration.frame.NEAR_COLLINEAR_SIN` a warning is given.
NEARLY_COLLINEAR = 0.02


def _skew(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """Cross-product matrices ``[v]x`` of vectors (..., 3) -> (..., 3, 3)."""
    z = np.zeros(v.shape[:-1])
    return np.stack([np.stack([z, -v[..., 2], v[..., 1]], -1),
                     np.stack([v[..., 2], z, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], z], -1)], -2)


def small_rotation(d: NDArray[np.float64]) -> NDArray[np.float64]:
    """``exp([d]x)`` of one rotation vector (Rodrigues), as
    :func:`~robotcell.calibration.fitting.perturb_rotation` applies it: the fit's residuals
    call it thousands of times, where scipy's general conversion costs more than the rest."""
    x, y, z = (float(v) for v in d)
    K = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    theta2 = x * x + y * y + z * z
    if theta2 < 1e-16:
        return np.eye(3) + K + 0.5 * K @ K
    theta = theta2**0.5
    return np.eye(3) + np.sin(theta) / theta * K + (1.0 - np.cos(theta)) / theta2 * K @ K


def _tool_sources(tool_sigma: Sources | ArrayLike, name: str) -> Sources:
    """The tool's error sources over its TCP position (3) or its pose (6)."""
    if isinstance(tool_sigma, Sources):
        if tool_sigma.size not in (3, 6):
            raise InputError(f"the tool's error sources must be over 3 (TCP position) or 6 (pose) "
                             f"parameters, got {tool_sigma.size}")
        return tool_sigma
    cov = np.asarray(tool_sigma, dtype=float)
    if cov.shape not in ((3, 3), (6, 6)):
        raise InputError(f"the tool's covariance must be 3x3 (TCP position, m^2) or 6x6 (pose), "
                         f"got shape {cov.shape}")
    return Sources.of(name, cov)


@dataclass(frozen=True)
class RobotTouches:
    """What one robot touched: the TCP positions and the name of the point each touched.

    Attributes
    ----------
    points : ndarray, shape (N, 3)
        TCP position of each touch in the robot's base (or, for a robot on a track, in the
        track frame its touches were mapped to) (m).
    names : tuple of str, length N
        Name of the common point each touch touched (``"P1"``); the robots' touches are matched
        by it. A point touched several times is averaged by the fit.
    inputs : Inputs, optional
        The calibrations the points rest on (the tool; a track), as errors shared by the touches:
        the derivative of each point with respect to their parameters and their error sources.
    robot : str
        The robot's name in messages and labels (``"r1"``).
    """

    points: NDArray[np.float64]
    names: tuple[str, ...]
    inputs: Inputs | None = None
    robot: str = ""

    def __post_init__(self) -> None:
        p = as_points(self.points, f"{self.robot or 'robot'} points").reshape(-1, 3)
        object.__setattr__(self, "points", p)
        object.__setattr__(self, "names", tuple(str(n).strip() for n in self.names))
        if len(self.names) != len(p):
            raise InputError(f"{self.robot or 'robot'}: {len(self.names)} point names for "
                             f"{len(p)} touches")
        if self.inputs is not None and len(self.inputs.sensitivity) != len(p):
            raise InputError(f"{self.robot or 'robot'}: the inputs give {len(self.inputs.sensitivity)}"
                             f" touches, the points {len(p)}")

    @classmethod
    def from_flange(cls, flange: ArrayLike, tool: ArrayLike, names: Sequence[str], *,
                    tool_sigma: Sources | ArrayLike | None = None, robot: str = "",
                    base: ArrayLike | None = None, base_sigma: Sources | ArrayLike | None = None
                    ) -> RobotTouches:
        """The touches of a robot from its flange poses and the tool that touched.

        Parameters
        ----------
        flange : array_like, shape (N, 4, 4)
            Flange pose ``T_R_F`` of each touch in the robot base (m).
        tool : array_like, shape (3,) or (4, 4)
            The TCP in the flange (m), or the tool's pose ``T_F_TCP``.
        names : sequence of str, length N
            The common point each touch touched.
        tool_sigma : Sources or array_like, optional
            The tool's error: its sources (over the TCP position, 3, or the tool's pose, 6), or
            its covariance (3x3 in m^2, or 6x6 over position m and rotation vector rad), taken as
            one source named ``"<robot> tool"``. None: the tool is taken as exact.
        robot : str
            The robot's name.
        base : array_like, shape (4, 4) or (N, 4, 4), optional
            Where the robot base stood at each touch, ``T_L_R`` in a frame L the touches are
            mapped to (a track's frame: the carriage's known offset at each track position).
            Default: the points stay in the robot base.
        base_sigma : Sources or array_like, optional
            Error of ``base`` as a pose (origin m, rotation vector rad about L's axes), the same
            for every touch (a track's ``T_L_R0``): sources over 6 parameters or a 6x6
            covariance, taken as one source named ``"<robot> track"``.

        Returns
        -------
        RobotTouches
        """
        F = validate_pose(np.asarray(flange, dtype=float).reshape(-1, 4, 4), "flange poses")
        t = np.asarray(tool, dtype=float)
        t = validate_pose(t, "tool")[:3, 3] if t.shape == (4, 4) else as_points(t, "tool")
        p = transform_points(F, t)
        B = np.broadcast_to(np.eye(4) if base is None else validate_pose(
            np.asarray(base, dtype=float), "base poses"), (len(F), 4, 4))
        R_L_F = B[:, :3, :3] @ F[:, :3, :3]
        p_L = transform_points(B, p)
        sens, sources, pnames = [], [], []
        if tool_sigma is not None:
            src = _tool_sources(tool_sigma, f"{robot} tool".strip())
            s = np.concatenate([R_L_F, np.zeros((len(F), 3, src.size - 3))], axis=2)
            sens.append(s)
            sources.append(src)
            pnames += [f"{robot} tool {c}".strip() for c in "xyzabc"[:src.size]]
        if base_sigma is not None:
            src = _tool_sources(base_sigma, f"{robot} track".strip())
            if src.size != 6:
                raise InputError("the base's error must be over 6 pose parameters")
            arm = p_L - B[:, :3, 3]
            sens.append(np.concatenate([np.broadcast_to(np.eye(3), arm.shape + (3,)),
                                        -_skew(arm)], axis=2))
            sources.append(src)
            pnames += [f"{robot} base {c}".strip() for c in ("x", "y", "z", "rx", "ry", "rz")]
        inputs = (Inputs(np.concatenate(sens, axis=2), Sources.stack(sources), pnames)
                  if sens else None)
        return cls(p_L, tuple(names), inputs, robot)


def common_points(ref: RobotTouches, other: RobotTouches) -> list[str]:
    """The common points, in the order the reference robot first touched them; refuses points
    touched by one robot only and fewer than :data:`FEWEST_POINTS` common points."""
    a, b = ref.robot or "the reference robot", other.robot or "the other robot"
    only_a = sorted(set(ref.names) - set(other.names))
    only_b = sorted(set(other.names) - set(ref.names))
    if only_a or only_b:
        parts = [f"{', '.join(only_a)} by {a} only"] if only_a else []
        parts += [f"{', '.join(only_b)} by {b} only"] if only_b else []
        raise InputError(f"point(s) touched by one robot only ({'; '.join(parts)}): a point "
                         "says where the robots stand only when both touch it; touch it with "
                         "both robots, or remove its rows (check the spelling of the names)")
    common = list(dict.fromkeys(ref.names))
    if len(common) < FEWEST_POINTS:
        raise IllPosedError(
            f"{len(common)} common point(s) ({', '.join(common)}); the pose of one robot relative "
            f"to another needs at least {FEWEST_POINTS} points touched by both, not on one line "
            "(4 or more let a wrong touch be found): touch more common points")
    return common


def point_means(t: RobotTouches, common: list[str]) -> NDArray[np.float64]:
    """Mean position of each common point as one robot touched it, (K, 3)."""
    idx = np.array([common.index(n) for n in t.names])
    out = np.zeros((len(common), 3))
    np.add.at(out, idx, t.points)
    return out / np.bincount(idx, minlength=len(common))[:, None]


def _spread(a: NDArray[np.float64]) -> tuple[float, str]:
    """Refuse common points on one line (or nearly); a warning when they are close to it."""
    s = np.linalg.svd(a - a.mean(axis=0), compute_uv=False)
    ratio = float(s[1] / s[0]) if s[0] > 0 else 0.0
    if ratio < max(COLLINEAR_SIN, NEARLY_COLLINEAR):
        raise IllPosedError(
            f"the common points lie on one line (their spread across it is {ratio:.1%} of their "
            "spread along it), so the rotation about that line is not determined; touch at least "
            "one more point well away from the line (a triangle with sides of 300 mm or more)")
    if ratio < NEAR_COLLINEAR_SIN:
        return ratio, (f"the common points are nearly on one line (spread across it "
                       f"{ratio:.1%} of the spread along it): the rotation about that line is "
                       "poorly determined; touch a point farther from the line")
    return ratio, ""


def joined_inputs(touches: Sequence[RobotTouches]) -> Inputs | None:
    """The inputs of several sets of touches over all their rows, in order, each zero on the
    rows of the others; a source named alike in two sets (one robot's tool in its touches of
    common points and of a turntable) is one error."""
    sizes = [len(t.points) for t in touches]
    rows = np.cumsum([0] + sizes)
    sens, srcs, names = [], [], []
    for t, start, stop in zip(touches, rows[:-1], rows[1:], strict=True):
        if t.inputs is None:
            continue
        s = np.zeros((rows[-1], 3, t.inputs.size))
        s[start:stop] = t.inputs.sensitivity
        sens.append(s)
        srcs.append(t.inputs.sources)
        names += t.inputs.names
    if not sens:
        return None
    return Inputs(np.concatenate(sens, axis=2), Sources.stack(srcs), names)


def _solve(ref: RobotTouches, other: RobotTouches, common: list[str], sigma: float | None,
           inputs: Inputs | None) -> tuple[Fit, NDArray[np.float64]]:
    """The ML fit over ``T_ref_other`` (origin, rotation vector) and the common points."""
    a, b = point_means(ref, common), point_means(other, common)
    T0 = kabsch(b, a)
    if np.linalg.norm(T0[:3, 3]) > MAX_DISTANCE:
        raise IllPosedError(
            f"the touches put the base of {other.robot or 'the other robot'} "
            f"{np.linalg.norm(T0[:3, 3]):.1f} m from {ref.robot or 'the reference robot'}'s, "
            f"beyond any real cell (at most {MAX_DISTANCE:.0f} m): check that the positions are "
            "in mm, in each robot's own base, and that the point names match the same points")
    n_a, n_b = np.array([ref.names.count(n) for n in common]), np.array(
        [other.names.count(n) for n in common])
    c0 = (n_a[:, None] * a + n_b[:, None] * transform_points(T0, b)) / (n_a + n_b)[:, None]
    ia = np.array([common.index(n) for n in ref.names])
    ib = np.array([common.index(n) for n in other.names])

    def resid(x: NDArray[np.float64]) -> NDArray[np.float64]:
        R = small_rotation(x[3:6]) @ T0[:3, :3]
        c = x[6:].reshape(-1, 3)
        return np.concatenate([ref.points - c[ia], other.points - (c[ib] - x[:3]) @ R])

    names = [f"{other.robot or 'other'} base {c}" for c in ("x", "y", "z")]
    names += [f"{other.robot or 'other'} base rotation about {c}" for c in "xyz"]
    names += [f"point {n} {c}" for n in common for c in "xyz"]
    res = fit(resid, np.concatenate([T0[:3, 3], np.zeros(3), c0.ravel()]), names, sigma,
              "touch common points spread in all directions, not on one line", inputs=inputs)
    return res, perturb_pose(T0, res.x[:6])


def robot_to_robot(reference: RobotTouches, other: RobotTouches, *, sigma: float | None = None,
                   method: str = "common points") -> CalibrationResult:
    """The pose of one robot's base relative to another's, from touches both robots made.

    Maximum likelihood over all touches of both robots (see the module): the pose
    ``T_ref_other`` and the common points are fitted together, every touch with isotropic
    Gaussian error ``sigma``; the tools' (and tracks') errors given in the touches' ``inputs``
    are systematic errors shared by all touches of their robot and are carried into the
    1-sigma, the chi-square check and the test of each touch.

    Parameters
    ----------
    reference : RobotTouches
        The touches of the reference robot (its base is the frame of the result).
    other : RobotTouches
        The touches of the robot whose base is calibrated.
    sigma : float, optional
        Touch accuracy (m, 1-sigma per coordinate) of both robots; default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    method : {"common points", "pointer"}
        How the touches were taken (for the report): both robots touched fixed points, or the
        other robot touched the tip of a pointer the reference robot held at several poses.

    Returns
    -------
    CalibrationResult
        Procedure ``"robot-to-robot"``. ``values["T_ref_other"]``: the other robot's base in the
        reference robot's base (4x4, m), with its 1-sigma (``sigma["T_ref_other_position"]``,
        ``["T_ref_other_rotation"]``) and 6x6 ``covariance`` (origin m, rotation vector rad about
        the reference base's axes); ``values["point NAME"]``: each common point in the
        reference base (m), with its 1-sigma. The residual of every touch (the other robot's in the reference base's axes),
        outliers named, condition number, verdict; the 1-sigma split into the touches' own part
        and the part inherited from the tools (``to_json()["sigma_parts"]``).

    Raises
    ------
    InputError
        Points touched by one robot only, mismatched names, NaN.
    IllPosedError
        Fewer than 3 common points, common points on (or nearly on) one line, or a pose beyond
        :data:`MAX_DISTANCE`.
    """
    if method not in ("common points", "pointer"):
        raise InputError(f"method must be 'common points' or 'pointer', got {method!r}")
    common = common_points(reference, other)
    _, warning = _spread(point_means(reference, common))
    res, T = _solve(reference, other, common, sigma, joined_inputs([reference, other]))
    return _result(reference, other, common, res, T, [warning] if warning else [], method)


def _result(ref: RobotTouches, other: RobotTouches, common: list[str], res: Fit,
            T: NDArray[np.float64], warnings: list[str], method: str) -> CalibrationResult:
    """The :class:`CalibrationResult` of the fit: residuals in the reference base, the pose."""
    n_a = len(ref.points)
    resid = res.residuals.copy()
    resid[n_a:] = resid[n_a:] @ T[:3, :3].T
    a, b = ref.robot or "ref", other.robot or "other"
    labels = [f"{a} touch {i + 1} ({n})" for i, n in enumerate(ref.names)]
    labels += [f"{b} touch {i + 1} ({n})" for i, n in enumerate(other.names)]
    warnings = list(warnings) + outlier_warnings(res, labels)
    if res.condition > CONDITION_LIMIT:
        warnings.append(f"condition number {res.condition:.0f} exceeds {CONDITION_LIMIT:.0f}: "
                        "the common points are bunched; spread them over the robots' common "
                        "workspace")
    points = np.concatenate([ref.points, transform_points(T, other.points)])
    c, sc = res.x[6:].reshape(-1, 3), res.sigma[6:].reshape(-1, 3)
    to_mm_rad = np.array([1e3, 1e3, 1e3, 1.0, 1.0, 1.0])
    p = len(res.x)
    fields = fit_fields(res)
    fields["residuals"] = resid
    distance = float(np.linalg.norm(T[:3, 3]))
    return CalibrationResult(
        procedure="robot-to-robot",
        values={"T_ref_other": T, **{f"point {n}": c[k] for k, n in enumerate(common)}},
        sigma={"T_ref_other_position": res.sigma[:3], "T_ref_other_rotation": res.sigma[3:6],
               **{f"point {n}": sc[k] for k, n in enumerate(common)}},
        labels=labels, warnings=warnings, points=points,
        next_step=(f"enter T_ref_other as the base of {b} in {a}'s base (YASKAWA: the robot "
                   "calibration between the robots; ABB MultiMove: the base frame of the robot "
                   "in the world it shares; KUKA: the ROBROOT of the second robot), then check "
                   f"it: let {b} move to a point {a} touched"),
        json_fields={**pose_fields(T), "method": method, "robots": [a, b],
                     "common_points": common, "distance_mm": distance * 1e3,
                     "T_ref_other_covariance_mm_rad": res.covariance[:6, :6]
                     * np.outer(to_mm_rad, to_mm_rad)},
        covariance=res.covariance[:6, :6],
        parameter_names=["x", "y", "z", "rx", "ry", "rz"],
        estimates={"T_ref_other": estimate(res.sources, res.input_gain, np.eye(6, p))},
        **fields,
    )
