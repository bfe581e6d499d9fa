"""Frames from touched points: 3-point (origin, +X, XY plane), N-point best fit, external TCP.

A frame ``T_R_W`` (pose of frame W in the robot base R) is what KUKA calls a BASE, ABB a work
object user frame, Fanuc a user frame. Every estimate is the maximum-likelihood fit under
isotropic Gaussian noise on the touched points (see ``docs/calibration.md``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.fitting import (
    SAME_POINT,
    fit,
    kabsch,
    outlier_warnings,
    perturb_rotation,
    pose_sigma,
)
from robotcell.calibration.result import (
    CONDITION_LIMIT,
    CalibrationResult,
    fit_fields,
    pose_fields,
)
from robotcell.calibration.spec import SPECS
from robotcell.calibration.uncertainty import Inputs, estimate
from robotcell.errors import IllPosedError, InputError
from robotcell.kinematics.transforms import as_points

__all__ = ["calibrate_external_tcp", "frame_3point", "frame_npoint"]

#: Below this distance (m) from origin to the +X touch a warning recommends spreading further.
GOOD_X_DISTANCE = 0.100
#: Sine of the angle between the +X line and the XY-plane touch (3-point), or ratio of the second
#: to the first singular value of the centred nominal points (N-point), below which the points
#: are collinear to rounding: the rotation about the line is then not determined and refused ...
COLLINEAR_SIN = 1e-9
#: ... and below which they count as nearly collinear (about 10 degrees), with a warning; the
#: condition number and the verdict say how much that costs.
NEAR_COLLINEAR_SIN = 0.17


def _labels(n: int, labels: Sequence[str] | None, roles: Sequence[str] | None = None) -> list[str]:
    if labels is not None:
        if len(labels) != n:
            raise InputError(f"labels has {len(labels)} entries for {n} measurements")
        return list(labels)
    if roles is None:
        return [f"{i + 1}" for i in range(n)]
    return [f"{i + 1} ({r})" for i, r in enumerate(roles)]


def _unit(v: NDArray[np.float64]) -> NDArray[np.float64]:
    return v / np.linalg.norm(v)


def _check_roles(p: NDArray[np.float64], roles: list[str]) -> None:
    """Refuse a 3-point layout that does not define a frame; name what to touch instead."""
    r = np.array(roles)
    o = p[r == "origin"].mean(axis=0)
    x = p[r == "x"].mean(axis=0) - o
    lx = np.linalg.norm(x)
    if lx < SAME_POINT:
        raise IllPosedError(
            "the +X touch is at the origin touch, so it defines no direction; touch a point on +X "
            f"at least {GOOD_X_DISTANCE * 1e3:.0f} mm from the origin")
    xy = p[r == "xy"].mean(axis=0) - o
    sin = np.linalg.norm(np.cross(x / lx, xy)) / max(np.linalg.norm(xy), 1e-12)
    if sin < COLLINEAR_SIN:
        raise IllPosedError(
            "the origin, +X and XY-plane touches are collinear (the XY touch lies on the X line), "
            "so the rotation about X is not determined; touch the XY-plane point well away from "
            "the X axis, ideally near +Y")


def role_projectors(R: NDArray[np.float64], roles: NDArray[np.str_]) -> NDArray[np.float64]:
    """Directions each touch of a 3-point frame measures, as projectors (N, 3, 3).

    An ``origin`` touch measures all 3; an ``x`` touch, anywhere on the +X line, the 2 across it
    (``I - X X^T``); an ``xy`` touch, anywhere in the plane, the 1 along Z (``Z Z^T``).
    """
    X, Z = R[:, 0], R[:, 2]
    P = np.broadcast_to(np.eye(3), (len(roles), 3, 3)).copy()
    P[roles == "x"] -= np.outer(X, X)
    P[roles == "xy"] = np.outer(Z, Z)
    return P


def _role_fit(p: NDArray[np.float64], roles: list[str], sigma: float | None,
              inputs: Inputs | None):
    """ML fit of origin and rotation; each +X / XY-plane touch's free coordinates eliminated.

    The free coordinates of a touch (its distance along X; x and y in the plane) take their
    best values for any frame (the foot of the touch on the line or plane), so the fit runs over
    the 6 frame parameters only, with each touch measuring the directions across its feature
    (:func:`role_projectors`): the same maximum-likelihood estimate, at a cost linear in the
    number of touches.
    """
    r = np.array(roles)
    o0 = p[r == "origin"].mean(axis=0)
    X0 = _unit(p[r == "x"].mean(axis=0) - o0)
    Y0 = _unit((w := p[r == "xy"].mean(axis=0) - o0) - (w @ X0) * X0)
    R0 = np.column_stack([X0, Y0, np.cross(X0, Y0)])

    def measured(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return role_projectors(perturb_rotation(R0, x[3:6]), r)

    def resid(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.einsum("nij,nj->ni", measured(x), p - x[:3])

    names = ["origin x", "origin y", "origin z", "rotation about x", "rotation about y",
             "rotation about z"]
    res = fit(resid, np.concatenate([o0, np.zeros(3)]), names, sigma, measured=measured,
              inputs=inputs)
    T = np.eye(4)
    T[:3, :3] = perturb_rotation(R0, res.x[3:6])
    T[:3, 3] = res.x[:3]
    return res, T


def _common(procedure: str, key: str, T: NDArray[np.float64], res, labels: list[str],
            warnings: list[str], next_step: str, undetermined: list[str] | None = None,
            names: list[str] | None = None,
            points: NDArray[np.float64] | None = None) -> CalibrationResult:
    sp, sr = pose_sigma(res.covariance[:6, :6])
    warnings = list(warnings) + outlier_warnings(res, labels)
    if res.condition > CONDITION_LIMIT:
        warnings.append(f"condition number {res.condition:.0f} exceeds {CONDITION_LIMIT:.0f}: the "
                        "touches are poorly spread; spread them further apart")
    p = len(res.x)
    return CalibrationResult(
        procedure=procedure, values={key: T}, sigma={key + "_position": sp, key + "_rotation": sr},
        labels=labels, undetermined=undetermined or [], warnings=warnings, next_step=next_step,
        json_fields=pose_fields(T), covariance=res.covariance[:6, :6],
        parameter_names=names or ["x", "y", "z", "rx", "ry", "rz"], points=points,
        estimates={key: estimate(res.sources, res.input_gain, np.eye(6, p),
                                 None if p == 6 else np.eye(6, p))},
        **fit_fields(res),
    )


def frame_3point(points: ArrayLike, roles: Sequence[str], sigma: float | None = None,
                 labels: Sequence[str] | None = None, *,
                 inputs: Inputs | None = None) -> CalibrationResult:
    """Frame from touches of its origin, a point on +X, and a point in the XY plane with Y > 0.

    KUKA's BASE 3-point method (also Fanuc's and Yaskawa's three-point user frame), generalised
    to any number of touches per role: every touch of the origin, of a point on the +X axis and
    of a point in the XY plane (positive Y) enters one maximum-likelihood fit whose unknowns are
    the frame and each touch's free coordinates (distance along X; x and y in the plane).

    Parameters
    ----------
    points : array_like, shape (N, 3)
        Touched TCP positions in the robot base frame (metres).
    roles : sequence of str, length N
        ``"origin"``, ``"x"`` or ``"xy"`` for each touch; each role at least once.
    sigma : float, optional
        Touch-up accuracy (metres, 1-sigma per coordinate) the uncertainties rest on; default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    labels : sequence of str, optional
        Name of each touch for the report.
    inputs : Inputs, optional
        Earlier calibrations the touched points rest on (the tool, a track), whose errors are
        added to the uncertainty; ``inputs.sensitivity`` is the derivative of each point.

    Returns
    -------
    CalibrationResult
        ``values["T_R_W"]``: the frame (4x4, metres); sigma of its origin and rotation; JSON
        fields ``matrix`` and ``xyzabc``.

    Raises
    ------
    IllPosedError
        +X touch at the origin, or origin, +X and XY touches collinear (both to rounding: the
        direction or the rotation about X is then not determined). Short distances and nearly
        collinear touches are computed, with a warning and a larger condition number.
    """
    p = as_points(points, "points").reshape(-1, 3)
    roles = [str(r).lower() for r in roles]
    if len(roles) != len(p):
        raise InputError(f"{len(roles)} roles given for {len(p)} points")
    missing = [k for k in ("origin", "x", "xy") if k not in roles]
    if missing or set(roles) - {"origin", "x", "xy"}:
        raise InputError("a 3-point frame needs roles origin, x and xy only, each at least once"
                         + (f"; missing {', '.join(missing)}" if missing else ""))
    _check_roles(p, roles)
    labs = _labels(len(p), labels, roles)
    res, T = _role_fit(p, roles, sigma, inputs)
    warnings = []
    r = np.array(roles)
    lx = np.linalg.norm(p[r == "x"].mean(axis=0) - p[r == "origin"].mean(axis=0))
    if lx < GOOD_X_DISTANCE:
        warnings.append(f"the +X touch is only {lx * 1e3:.0f} mm from the origin: the direction of X "
                        f"is sensitive to touch errors; touch at least {GOOD_X_DISTANCE * 1e3:.0f} mm away")
    y = (p[r == "xy"] - T[:3, 3]) @ T[:3, 1]
    if np.any(y <= 0):
        raise IllPosedError("an XY-plane touch lies on the negative-Y side of the fitted frame; the XY "
                            "touches must all have positive Y (same side of the X axis)")
    sin = np.linalg.norm(np.cross(T[:3, 0], p[r == "xy"].mean(axis=0) - T[:3, 3])) / np.linalg.norm(
        p[r == "xy"].mean(axis=0) - T[:3, 3])
    if sin < NEAR_COLLINEAR_SIN:
        warnings.append(f"the XY-plane touch is only {np.degrees(np.arcsin(sin)):.1f} deg off the X axis "
                        "(nearly collinear): the rotation about X is poorly determined; touch it near +Y")
    return _common("frame-3point", "T_R_W", T, res, labs, warnings,
                   "enter matrix/xyzabc as the base (user frame) in the controller, then check it by "
                   "jogging along the new X and Y axes over the workpiece", points=p)


def frame_npoint(points: ArrayLike, nominal: ArrayLike, sigma: float | None = None,
                 labels: Sequence[str] | None = None, *,
                 inputs: Inputs | None = None) -> CalibrationResult:
    """Best-fit frame to touched points whose coordinates in the frame are known.

    Maximum likelihood under isotropic Gaussian noise on the touched points: minimises
    ``sum |p_i - T_R_W q_i|^2`` over rigid ``T_R_W`` (Kabsch/Umeyama start, then the same
    least-squares refinement and covariance as every procedure).

    Parameters
    ----------
    points : array_like, shape (N, 3)
        Touched TCP positions in the robot base frame (metres), N >= 3.
    nominal : array_like, shape (N, 3)
        Coordinates of the same points in the frame W, e.g. from the drawing (metres).
    sigma : float, optional
        Touch-up accuracy (metres); default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    labels : sequence of str, optional
    inputs : Inputs, optional
        Earlier calibrations the touched points rest on (see :func:`frame_3point`).

    Returns
    -------
    CalibrationResult
        ``values["T_R_W"]`` with sigma, JSON fields ``matrix`` and ``xyzabc``.

    Raises
    ------
    IllPosedError
        Fewer than 3 points, or nominal points (nearly) collinear.
    """
    p = as_points(points, "points").reshape(-1, 3)
    q = as_points(nominal, "nominal points").reshape(-1, 3)
    if q.shape != p.shape:
        raise InputError(f"{len(q)} nominal points for {len(p)} touched points")
    least = SPECS["frame"].minimum
    if len(p) < least:
        raise IllPosedError(f"points: {len(p)} given; a best-fit frame needs at least {least} "
                            "points that are not on one line (4 or more give a check of the fit)")
    s = np.linalg.svd(q - q.mean(axis=0), compute_uv=False)
    if s[0] == 0 or s[1] / s[0] < COLLINEAR_SIN:
        raise IllPosedError("the nominal points are collinear (all on one line), so the rotation "
                            "about their line is not determined; add points well away from that line")
    labs = _labels(len(p), labels)
    T0 = kabsch(q, p)
    R0 = T0[:3, :3]

    def resid(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return p - (q @ perturb_rotation(R0, x[3:6]).T + x[:3])

    names = ["origin x", "origin y", "origin z", "rotation about x", "rotation about y",
             "rotation about z"]
    res = fit(resid, np.concatenate([T0[:3, 3], np.zeros(3)]), names, sigma, inputs=inputs)
    T = np.eye(4)
    T[:3, :3] = perturb_rotation(R0, res.x[3:6])
    T[:3, 3] = res.x[:3]
    warnings = []
    if s[1] / s[0] < NEAR_COLLINEAR_SIN:
        warnings.append(f"the nominal points are nearly collinear (they spread {s[1] / s[0]:.1%} "
                        "as much across their best-fit line as along it): the rotation about that "
                        "line is poorly determined; add points away from that line")
    return _common("frame-npoint", "T_R_W", T, res, labs, warnings,
                   "enter matrix/xyzabc as the base (user frame); touch one more known point and check "
                   "that transform_points(T_R_W, nominal) matches it within the residual RMS",
                   points=p)


def calibrate_external_tcp(points: ArrayLike, roles: Sequence[str], sigma: float | None = None,
                 labels: Sequence[str] | None = None, *,
                 inputs: Inputs | None = None) -> CalibrationResult:
    """Pose of a fixed (external) tool in the robot base frame, touched with a reference tool.

    The robot carries a reference tool of known TCP; the recorded TCP positions (robot base
    frame) are touches of the fixed tool's TCP (role ``"tcp"``, at least 3 from different
    directions), optionally of points on the fixed tool's +X axis (its tool direction, role
    ``"x"``) and of points in its XY plane with positive Y (role ``"xy"``). With axis and plane
    touches the full pose is the 3-point frame fit; with TCP touches only, the position is their
    maximum-likelihood mean and the orientation is reported as not determined (the identity is
    returned in ``T_R_TCP``).

    Parameters
    ----------
    points : array_like, shape (N, 3)
        Reference-tool TCP positions in the robot base frame (metres).
    roles : sequence of str, length N
        ``"tcp"``, ``"x"`` or ``"xy"``.
    sigma : float, optional
        Touch-up accuracy (metres); default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    labels : sequence of str, optional
    inputs : Inputs, optional
        Earlier calibrations the touched points rest on (the reference tool; see
        :func:`frame_3point`).

    Returns
    -------
    CalibrationResult
        ``values["T_R_TCP"]`` (4x4, metres), JSON ``matrix``, ``xyzabc`` and ``tcp_mm``.
    """
    p = as_points(points, "points").reshape(-1, 3)
    roles = [str(r).lower() for r in roles]
    if len(roles) != len(p):
        raise InputError(f"{len(roles)} roles given for {len(p)} points")
    bad = sorted(set(roles) - {"tcp", "x", "xy"})
    if bad:
        raise InputError(f"external TCP touches must have role tcp, x or xy; found {', '.join(bad)}")
    n_tcp = roles.count("tcp")
    least = SPECS["external-tcp"].minimum
    if n_tcp < least:
        raise IllPosedError(f"touches of the fixed TCP: {n_tcp} given; touch it at least {least} "
                            "times (4 recommended) with the reference tool from different "
                            "directions")
    labs = _labels(len(p), labels, roles)
    next_step = ("enter matrix/xyzabc as the external tool (KUKA: fixed tool as BASE, ABB: stationary "
                 "tool) and check by moving a workpiece point to the fixed TCP in two orientations")
    if "x" not in roles and "xy" not in roles:
        pt = p[np.array(roles) == "tcp"]
        res = fit(lambda x: pt - x, pt.mean(axis=0), ["x", "y", "z"], sigma,
                  inputs=None if inputs is None else inputs.subset(np.array(roles) == "tcp"))
        T = np.eye(4)
        T[:3, 3] = res.x
        out = _common("external-tcp", "T_R_TCP", T, res, labs, [], next_step,
                      ["orientation of the fixed tool (touch points on its +X axis and in its XY plane)"],
                      ["x", "y", "z"])
        del out.sigma["T_R_TCP_rotation"]
        out.json_fields.update({"tcp_mm": T[:3, 3] * 1e3, "rotation_determined": False})
        return out
    if "x" not in roles or "xy" not in roles:
        raise IllPosedError("the fixed tool's orientation needs touches of both a point on its +X axis "
                            "(role x) and a point in its XY plane with positive Y (role xy)")
    out = frame_3point(p, ["origin" if r == "tcp" else r for r in roles], sigma, labs,
                       inputs=inputs).renamed("T_R_W", "T_R_TCP")
    T = out.values["T_R_TCP"]
    out.procedure = "external-tcp"
    out.next_step = next_step
    out.json_fields.update({"tcp_mm": T[:3, 3] * 1e3, "rotation_determined": True})
    return out
