"""Tool calibration: TCP position (XYZ 4-point / N-point) and tool orientation (ABC 2-point,
ABC World), from flange poses recorded while the tool touches one fixed reference point.

Model (all in the robot base frame R, metres): with ``T_R_F_i = [R_i, p_i]`` the flange pose of
touch i, ``t`` the TCP in the flange frame and ``c`` the reference point ("pivot"),
``R_i t + p_i = c`` for every touch of the reference point with the TCP. The orientation
``R_F_TCP`` comes from extra touches in which the reference point lies on the tool's negative X
axis (``c = T_R_F_k (t + R_F_TCP (-d_k, 0, 0))``, d_k > 0) and in the tool's XY plane with positive Y
(``c = T_R_F_k (t + R_F_TCP (x_k, y_k, 0))``, y_k > 0): KUKA's ABC 2-point method. All touches enter
one maximum-likelihood fit under isotropic Gaussian noise on the touched point. ABC World
instead aligns the tool with the world axes (5D: tool +X along world -Z; 6D: additionally tool
+Y along world +Y, so tool +Z along world +X).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robotcell.calibration.fitting import (
    SAME_POINT,
    SINGULAR_CONDITION,
    Fit,
    fit,
    nearest_rotation,
    outlier_warnings,
    perturb_rotation,
    scaled_condition,
)
from robotcell.calibration.frame import COLLINEAR_SIN, NEAR_COLLINEAR_SIN
from robotcell.calibration.result import (
    CONDITION_LIMIT,
    CalibrationResult,
    fit_fields,
    pose_fields,
)
from robotcell.calibration.spec import SPECS
from robotcell.calibration.uncertainty import OWN, Estimate, Inputs, Sources
from robotcell.errors import IllPosedError, InputError
from robotcell.kinematics.transforms import validate_pose

__all__ = ["ABC_WORLD_5D", "ABC_WORLD_6D", "calibrate_tool"]

#: Tool axes in the world frame when aligned for ABC World 6D (columns: tool X, Y, Z).
ABC_WORLD_6D = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
#: Tool +X in the world frame when aligned for ABC World 5D.
ABC_WORLD_5D = np.array([0.0, 0.0, -1.0])

#: Orientation spread (rad) about the least-varied direction below which a warning asks for more
#: varied orientations. Touches that leave the TCP undetermined (one orientation, two, or all
#: rotated about one axis) are refused by the fit's rank test, not by a spread threshold.
GOOD_SPREAD = np.radians(15.0)
#: Distance (m) of the reference point from the TCP in an ABC 2-point touch below which a warning
#: asks to move the tool farther back (the tool direction's 1-sigma is about the touch noise
#: divided by this distance).
GOOD_AXIS_DISTANCE = 0.050

ADVICE = "touch with orientations differing by at least 30-60 degrees about different axes"
#: Ending of the error when the touches do not determine the TCP.
SIMILAR = "the flange orientations of the touches are too similar: " + ADVICE


def _poses(T: ArrayLike | None, name: str) -> NDArray[np.float64]:
    if T is None:
        return np.zeros((0, 4, 4))
    return validate_pose(np.asarray(T, dtype=float).reshape(-1, 4, 4), name)


def orientation_spread(R: NDArray[np.float64]) -> float:
    """How much a set of flange rotations varies about its least-varied direction.

    Parameters
    ----------
    R : ndarray, shape (N, 3, 3)

    Returns
    -------
    float
        ``sqrt(lambda_min(M) / N)`` with ``M = sum_i (R_i - mean R)^T (R_i - mean R)``: about the
        rotation angle (radians) by which the touches differ in the direction in which they differ
        least. The TCP component along a direction the rotations do not vary is not determined.
    """
    D = R - R.mean(axis=0)
    M = np.einsum("nji,njk->ik", D, D)
    return float(np.sqrt(max(np.linalg.eigvalsh(M)[0], 0.0) / len(R)))


def _world_orientation(R_RF: NDArray[np.float64], mode: str):
    """ABC World: mean tool rotation in the flange and its 1-sigma, from aligned flange poses."""
    if mode == "6d":
        Ri = np.swapaxes(R_RF, 1, 2) @ ABC_WORLD_6D
    else:
        Ri = []
        for x in np.swapaxes(R_RF, 1, 2) @ ABC_WORLD_5D:
            axis = np.cross([1.0, 0.0, 0.0], x)
            s, c = np.linalg.norm(axis), x[0]
            rv = axis / s * np.arctan2(s, c) if s > 1e-12 else np.array([0.0, 0.0, np.pi * (c < 0)])
            Ri.append(Rotation.from_rotvec(rv).as_matrix())
        Ri = np.array(Ri)
    Rm = nearest_rotation(Ri.sum(axis=0))
    if len(Ri) < 2:
        return Rm, np.full(3, np.nan)
    d = Rotation.from_matrix(Ri @ Rm.T).as_rotvec()
    return Rm, d.std(axis=0, ddof=1) / np.sqrt(len(Ri))


def calibrate_tool(
    touches: ArrayLike,
    axis_touches: ArrayLike | None = None,
    plane_touches: ArrayLike | None = None,
    world_touches: ArrayLike | None = None,
    world_mode: str = "6d",
    sigma: float | None = None,
    labels: Sequence[str] | None = None,
    inputs: Inputs | None = None,
) -> CalibrationResult:
    """Calibrate a robot-held tool: TCP in the flange frame, reference point, optional orientation.

    Parameters
    ----------
    touches : array_like, shape (N, 4, 4)
        Flange poses ``T_R_F`` (metres) with the TCP on the reference point, N >= 3 (4 is KUKA's
        XYZ 4-point; more are used in full). Two touches never suffice: ``R_1 t + p_1 = R_2 t +
        p_2`` leaves the TCP component along the axis of ``R_1^T R_2`` free, since ``R_1 - R_2``
        has rank 2; three touches rotated about different axes determine the TCP and the
        reference point (6 unknowns, 9 equations).
    axis_touches : array_like, shape (Na, 4, 4), optional
        ABC 2-point: flange poses with the reference point on the tool's negative X axis.
    plane_touches : array_like, shape (Np, 4, 4), optional
        ABC 2-point: flange poses with the reference point in the tool's XY plane, Y > 0.
    world_touches : array_like, shape (Nw, 4, 4), optional
        ABC World: flange poses with the tool aligned to the world axes (see ``world_mode``);
        several alignments are averaged and their spread gives the rotation sigma.
    world_mode : {"6d", "5d"}
        ``"6d"``: tool +X along world -Z, +Y along world +Y, +Z along world +X.
        ``"5d"``: only tool +X along world -Z; the rotation about the tool axis is fixed by the
        convention "smallest rotation from the flange X axis" and reported as undetermined.
    sigma : float, optional
        Touch-up accuracy (metres, 1-sigma per coordinate) the uncertainties rest on; default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    labels : sequence of str, optional
        Names of the touches in the order touches, axis_touches, plane_touches.
    inputs : Inputs, optional
        Earlier calibrations the flange poses rest on (a track the touches are mapped through),
        in the order touches, axis_touches, plane_touches: ``inputs.sensitivity`` is the
        derivative of the reference point as each flange pose places it.

    Returns
    -------
    CalibrationResult
        ``values["tcp"]`` (3,) TCP in the flange frame, ``values["pivot"]`` (3,) reference point
        in the base frame, and with an orientation method ``values["T_F_TCP"]`` (4x4). JSON
        fields ``tcp_mm``, ``pivot_mm``, ``mean_mm``/``min_mm`` (as ABB reports) and, with an
        orientation, ``matrix``/``xyzabc`` of ``T_F_TCP``. ``estimates["T_F_TCP"]`` over its
        origin and rotation vector (about the flange axes); the rotation is not determined
        without an orientation method.

    Raises
    ------
    IllPosedError
        Fewer than 3 touches, orientations that leave the TCP undetermined (one or two distinct
        orientations, or all rotated about one axis: the fit's Jacobian is rank deficient), or ABC
        2-point touches that define no direction (the reference point at the TCP to rounding) or
        no plane (the XY touch on the X axis to rounding). Similar orientations and short
        distances are computed, with a warning and a larger condition number.
    """
    T, Ta, Tp, Tw = _tool_touches(touches, axis_touches, plane_touches, world_touches, world_mode)
    n, na, nq = len(T), len(Ta), len(Tp)
    if labels is None:
        labels = ([f"{i + 1}" for i in range(n)] + [f"{n + i + 1} (-x)" for i in range(na)]
                  + [f"{n + na + i + 1} (xy)" for i in range(nq)])
    elif len(labels) != n + na + nq:
        raise InputError(f"labels has {len(labels)} entries for {n + na + nq} touches")
    x0, R0 = _tool_start(T, Ta, Tp)
    resid, measured = _tool_model(T, Ta, Tp, R0)
    names = ["tcp x", "tcp y", "tcp z", "pivot x", "pivot y", "pivot z"]
    if na:
        names += ["tool rotation about flange x", "tool rotation about flange y",
                  "tool rotation about flange z"]
    flipped = None if inputs is None else Inputs(-inputs.sensitivity, inputs.sources, inputs.names)
    res = fit(resid, x0, names, sigma, advice=SIMILAR, measured=measured, inputs=flipped)
    warnings = outlier_warnings(res, labels)
    spread = orientation_spread(T[:, :3, :3])
    if spread < GOOD_SPREAD:
        warnings.append(f"the touch orientations differ by only {np.degrees(spread):.1f} deg in their "
                        f"least-varied direction: the TCP is poorly determined; {ADVICE}")
    orientation = _tool_orientation(res, Ta, Tp, Tw, R0, world_mode, warnings)
    if res.condition > CONDITION_LIMIT:
        warnings.append(f"condition number {res.condition:.0f} exceeds {CONDITION_LIMIT:.0f}: {ADVICE}")
    return _tool_result(res, orientation, labels, names, warnings)


def _tool_touches(touches: ArrayLike, axis_touches: ArrayLike | None,
                  plane_touches: ArrayLike | None, world_touches: ArrayLike | None,
                  world_mode: str) -> tuple[NDArray[np.float64], ...]:
    """The flange poses of :func:`calibrate_tool`, checked: TCP, -X, XY and ABC World touches."""
    T = _poses(touches, "touch flange poses")
    Ta = _poses(axis_touches, "ABC 2-point -X flange poses")
    Tp = _poses(plane_touches, "ABC 2-point XY flange poses")
    Tw = _poses(world_touches, "ABC World flange poses")
    if world_mode not in ("6d", "5d"):
        raise InputError(f"world_mode must be '6d' or '5d', got {world_mode!r}")
    if len(T) < SPECS["tcp"].minimum:
        raise IllPosedError(f"touches of the reference point: {len(T)} given; the TCP needs at least "
                            f"{SPECS['tcp'].minimum} "
                            f"(4 recommended, 5 or more let a wrong touch be singled out): {ADVICE}")
    if (len(Ta) > 0) != (len(Tp) > 0):
        raise IllPosedError("ABC 2-point needs both a touch with the reference point on the tool's -X "
                            "axis and one with it in the tool's XY plane (positive Y)")
    if len(Ta) and len(Tw):
        raise InputError("give either ABC 2-point touches or ABC World alignments, not both")
    return T, Ta, Tp, Tw


def _tool_start(T: NDArray[np.float64], Ta: NDArray[np.float64], Tp: NDArray[np.float64]
                ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Start of the fit: TCP and reference point by least squares, and with ABC 2-point touches
    the tool orientation ``R0`` from them (else the flange's); the parameters start at them."""
    n, na = len(T), len(Ta)
    # Linear start: [R_i, -I] [t; c] = -p_i.
    A = np.concatenate([T[:, :3, :3], np.broadcast_to(-np.eye(3), (n, 3, 3))], axis=2).reshape(-1, 6)
    if scaled_condition(A) > SINGULAR_CONDITION:  # A is the Jacobian of the TCP touches, exactly
        raise IllPosedError("the TCP is not determined (one or two distinct flange orientations, or "
                            f"all rotated about one axis): {SIMILAR}")
    t0, c0 = np.split(np.linalg.lstsq(A, -T[:, :3, 3].ravel(), rcond=None)[0], 2)
    x0 = [t0, c0]
    R0 = np.eye(3)
    if na:
        f_a = np.einsum("nji,nj->ni", Ta[:, :3, :3], c0 - Ta[:, :3, 3]) - t0
        f_p = np.einsum("nji,nj->ni", Tp[:, :3, :3], c0 - Tp[:, :3, 3]) - t0
        da = np.linalg.norm(f_a, axis=1)
        if da.max() < SAME_POINT:
            raise IllPosedError("in the -X touches the reference point is at the TCP, so they define no "
                                "tool direction; move the tool back along its axis, at least "
                                f"{GOOD_AXIS_DISTANCE * 1e3:.0f} mm")
        X = -f_a.sum(axis=0)
        X /= np.linalg.norm(X)
        w = f_p.mean(axis=0) - (f_p.mean(axis=0) @ X) * X
        if np.linalg.norm(w) <= COLLINEAR_SIN * np.linalg.norm(f_p.mean(axis=0)):
            raise IllPosedError("the XY-plane touch lies on the tool's X axis (collinear with the -X "
                                "touch), so the rotation about X is not determined: move the tool "
                                "sideways so the reference point is off its axis on the tool's +Y side")
        Y = w / np.linalg.norm(w)
        R0 = np.column_stack([X, Y, np.cross(X, Y)])
        x0 += [np.zeros(3)]
    return np.concatenate(x0), R0


def _tool_model(T: NDArray[np.float64], Ta: NDArray[np.float64], Tp: NDArray[np.float64],
                R0: NDArray[np.float64]
                ) -> tuple[Callable[[NDArray[np.float64]], NDArray[np.float64]],
                           Callable[[NDArray[np.float64]], NDArray[np.float64]]]:
    """The residuals of the touches at parameters ``x`` (TCP, reference point, and with ABC
    2-point touches the rotation from ``R0``), and the projection of each touch's residual onto
    the directions it measures (an ABC 2-point touch does not measure along the tool axis or
    within its plane)."""
    n, na, nq = len(T), len(Ta), len(Tp)
    across = (np.diag([0.0, 1.0, 1.0]), np.diag([0.0, 0.0, 1.0]))  # in the tool frame

    def measured(x: NDArray[np.float64]) -> NDArray[np.float64]:
        P = np.broadcast_to(np.eye(3), (n + na + nq, 3, 3)).copy()
        if na:
            R = perturb_rotation(R0, x[6:9])
            for Tk, E, rows in ((Ta, across[0], slice(n, n + na)),
                                (Tp, across[1], slice(n + na, None))):
                RkR = Tk[:, :3, :3] @ R
                P[rows] = RkR @ E @ np.swapaxes(RkR, 1, 2)
        return P

    def resid(x: NDArray[np.float64]) -> NDArray[np.float64]:
        t, c = x[:3], x[3:6]
        out = [c - (T[:, :3, :3] @ t + T[:, :3, 3])]
        if na:
            R = perturb_rotation(R0, x[6:9])
            for Tk, E in ((Ta, across[0]), (Tp, across[1])):
                RkR = Tk[:, :3, :3] @ R
                v = np.einsum("nji,nj->ni", RkR, c - Tk[:, :3, 3]) - t @ R  # in the tool frame
                out.append(np.einsum("nij,nj->ni", RkR, v @ E))
        return np.concatenate(out)

    return resid, measured


@dataclass
class _Orientation:
    """The tool orientation of a TCP fit (:func:`_tool_orientation`)."""

    R: NDArray[np.float64] | None
    sigma: NDArray[np.float64] | None
    A: NDArray[np.float64]
    extra_own: NDArray[np.float64]
    undetermined: list[str]


def _tool_orientation(res: Fit, Ta: NDArray[np.float64], Tp: NDArray[np.float64],
                      Tw: NDArray[np.float64], R0: NDArray[np.float64], world_mode: str,
                      warnings: list[str]) -> _Orientation:
    """The tool orientation from ABC 2-point touches (in the fit) or ABC World alignments, its
    1-sigma and how ``T_F_TCP`` follows the fit's parameters; warnings go to ``warnings``."""
    t, c = res.x[:3], res.x[3:6]
    undetermined: list[str] = []
    R_tool = sigma_rot = None
    A = np.eye(6, len(res.x))  # T_F_TCP (origin, rotation vector) from the fit's parameters
    A[3:6] = 0.0
    extra_own = np.zeros((6, 0))
    if len(Ta):
        R_tool = perturb_rotation(R0, res.x[6:9])
        A[3:6, 6:9] = np.eye(3)
        sigma_rot = res.sigma[6:9]
        # The reference point in the tool frame at each ABC 2-point touch.
        local = [np.einsum("nji,nj->ni", Tk[:, :3, :3] @ R_tool, c - Tk[:, :3, 3]) - t @ R_tool
                 for Tk in (Ta, Tp)]
        warnings += _two_point_warnings(local)
    elif len(Tw):
        R_tool, sigma_rot = _world_orientation(Tw[:, :3, :3], world_mode)
        extra_own = np.vstack([np.zeros((3, 3)), np.diag(np.nan_to_num(sigma_rot))])
        if len(Tw) < 2:
            warnings.append("one ABC World alignment: its accuracy is unknown; align 2-3 times to get "
                            "the orientation uncertainty")
        if world_mode == "5d":
            undetermined.append("rotation of the tool about its own X axis (ABC World 5D; the smallest "
                                "rotation from the flange X axis is used)")
    else:
        undetermined.append("tool orientation (add ABC 2-point touches or ABC World alignments)")
    return _Orientation(R_tool, sigma_rot, A, extra_own, undetermined)


def _two_point_warnings(local: list[NDArray[np.float64]]) -> list[str]:
    """Check the reference point in the tool frame at the -X and XY touches (``local``): refuse
    one on the wrong side, warn of one too near the TCP or the X axis."""
    warnings = []
    dist = -local[0][:, 0]
    if np.any(dist <= 0):
        raise IllPosedError("in a -X touch the reference point lies on the tool's positive X side; "
                            "the -X touch must move the tool back, against its tool direction")
    xy = local[1][:, :2]
    if np.any(xy[:, 1] <= 0):
        raise IllPosedError("the XY-plane touches lie on both sides of the tool's X axis; keep them "
                            "all on the tool's positive Y side")
    if dist.min() < GOOD_AXIS_DISTANCE:
        warnings.append(f"in a -X touch the reference point is only {dist.min() * 1e3:.1f}"
                        " mm from the TCP: the tool direction is poorly determined; move the tool "
                        f"back along its axis by at least {GOOD_AXIS_DISTANCE * 1e3:.0f} mm")
    sin_xy = np.min(xy[:, 1] / np.linalg.norm(xy, axis=1))
    if sin_xy < NEAR_COLLINEAR_SIN:
        warnings.append(f"an XY-plane touch is only {np.degrees(np.arcsin(sin_xy)):.1f} deg off the "
                        "tool's X axis (nearly collinear): the rotation about X is poorly "
                        "determined; move the tool sideways, toward its +Y side")
    return warnings


def _tool_result(res: Fit, orientation: _Orientation, labels: Sequence[str], names: list[str],
                 warnings: list[str]) -> CalibrationResult:
    """The result of :func:`calibrate_tool` from its fit and the tool orientation."""
    t, c = res.x[:3], res.x[3:6]
    values: dict = {"tcp": t, "pivot": c}
    sigma: dict = {"tcp": res.sigma[:3], "pivot": res.sigma[3:6]}
    R_tool, sigma_rot, A, extra_own = (orientation.R, orientation.sigma, orientation.A,
                                       orientation.extra_own)
    tool = res.sources.map(A)
    if extra_own.size:  # ABC World: the spread of the alignments, independent of the touches
        tool = Sources(6, {**tool.factors, OWN: np.hstack([tool.factors[OWN], extra_own])})
    determined = np.eye(6) if R_tool is not None else np.eye(6)[:, :3]
    norms = np.linalg.norm(res.residuals, axis=1)
    extra = {"tcp_mm": t * 1e3, "pivot_mm": c * 1e3, "mean_mm": norms.mean() * 1e3,
             "min_mm": norms.min() * 1e3}
    if R_tool is not None:
        Tft = np.eye(4)
        Tft[:3, :3], Tft[:3, 3] = R_tool, t
        values["T_F_TCP"] = Tft
        sigma["T_F_TCP_position"] = sigma["tcp"]
        sigma["T_F_TCP_rotation"] = sigma_rot
        extra.update(pose_fields(Tft))
        next_step = ("enter xyzabc as the tool data (KUKA TOOL_DATA X,Y,Z,A,B,C), then jog A/B/C in the "
                     "TOOL frame at the reference point: the tip must stay on it")
    else:
        next_step = ("enter tcp_mm as the tool's X,Y,Z, then calibrate its orientation (ABC 2-point or "
                     "ABC World) if the process needs the tool direction")
    return CalibrationResult(
        procedure="tcp", values=values, sigma=sigma, labels=list(labels),
        undetermined=orientation.undetermined, warnings=warnings, next_step=next_step,
        json_fields=extra, covariance=res.covariance, parameter_names=names,
        estimates={"T_F_TCP": Estimate(tool, A @ res.input_gain, determined)},
        value_sources={"tcp": res.sources.select([0, 1, 2]), "pivot": res.sources.select([3, 4, 5])},
        frames={"tcp": "F", "pivot": "R"}, **fit_fields(res),
    )
