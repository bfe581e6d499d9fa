"""Linear track (robot on a rail) calibration from touches of a fixed reference point.

Model (frames as in ``docs/conventions.md``): the track frame L is fixed; the robot base R rides on
the carriage. At commanded track position ``e`` (metres) the pose of R in L is

    T_L_R(e) = [[L_Q_R, c + e * scale * d_L], [0, 0, 0, 1]]

with ``d_L`` the track axis of L (``X`` in the lecture's convention, ``Z`` in KUKA's
external-kinematics convention), ``scale`` the measured travel per commanded travel and ``c`` the
carriage offset (position of R in L at ``e = 0``). A fixed point ``r`` (coordinates in L) touched
with the TCP at ``f_i`` (in R, from forward kinematics) at track position ``e_i`` satisfies

    r = L_Q_R f_i + c + e_i * scale * d_L,    equivalently    f_i = p0 - e_i * scale * a,

where ``a = L_Q_R^T d_L`` is the track direction expressed in R (a row of ``L_Q_R``) and ``p0`` the
point in R with the track at 0. Touches of one *unknown* point therefore determine ``a``,
``scale`` and ``p0`` only: the rotation of ``L_Q_R`` about the track axis and the offset ``c`` leave
every ``f_i`` unchanged. The rotation becomes observable when the point's coordinates in L are known
(one point off the track axis, with ``c = 0`` as in the lecture's assumption (ii)); two or more known
points off one common line parallel to the axis also determine ``c``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robotcell.calibration.fitting import (
    SAME_POINT,
    Fit,
    fit,
    kabsch,
    nearest_rotation,
    outlier_warnings,
    perturb_rotation,
)
from robotcell.calibration.grouping import distinct
from robotcell.calibration.propagate import jacobian
from robotcell.calibration.result import CONDITION_LIMIT, CalibrationResult, fit_fields
from robotcell.calibration.spec import SPECS
from robotcell.calibration.uncertainty import Inputs, estimate
from robotcell.errors import IllPosedError, InputError, term
from robotcell.kinematics.transforms import as_points, make_pose

__all__ = ["TRACK_AXES", "calibrate_track", "zero_roll_rotation"]

#: Axis of L along which the carriage moves, per convention: the lecture's (``"x"``) and KUKA's
#: external kinematics (``"z"``, the axis of motion of an external-kinematics frame is Z).
TRACK_AXES = {"x": np.array([1.0, 0.0, 0.0]), "z": np.array([0.0, 0.0, 1.0])}

#: Relative deviation of the track scale from 1 above which a warning is given.
SCALE_WARN = 0.02

#: Travel (m) spanned by the touches below which a warning asks to spread them: the direction's
#: uncertainty is about the touch noise divided by the travel.
TRAVEL_WARN = 0.05

#: Distance (m) of a single known reference point from the track axis, or spread of several
#: across one line parallel to it, below which a warning is given: the rotation about the axis
#: is then poorly determined (its 1-sigma is about the touch noise divided by this lever).
LEVER_WARN = 0.05

#: Scale outside ``[1 / SCALE_REFUSE, SCALE_REFUSE]`` means the data are not of one fixed point or
#: the track values are not in the track's own length unit.
SCALE_REFUSE = 2.0


def zero_roll_rotation(direction: ArrayLike, axis: str = "x") -> NDArray[np.float64]:
    """The ``roll="zero"`` convention for ``L_Q_R`` when the data fix only the track direction.

    ``L_Q_R`` is the rotation of smallest angle that carries the measured track direction ``a``
    (in R) onto the track axis ``d_L`` of L. Its rotation axis is ``a x d_L``, perpendicular to the
    track, so it adds no rotation about the track axis: for a track along X, the robot base's Y
    and Z axes are tilted only as much as needed to make X_R follow the track.

    Parameters
    ----------
    direction : array_like, shape (3,)
        Unit track direction ``a`` in R (unitless).
    axis : {"x", "z"}
        Track axis of L.

    Returns
    -------
    ndarray, shape (3, 3)
        ``L_Q_R`` (proper rotation) with ``L_Q_R @ a = d_L``.

    Raises
    ------
    IllPosedError
        When ``a`` points opposite to ``d_L``: the smallest rotation is then not unique.
    """
    a = np.asarray(direction, dtype=float)
    a = a / np.linalg.norm(a)
    d = _axis_vector(axis)
    if a @ d < -1.0 + 1e-9:
        raise IllPosedError(
            "the track moves the robot along -" + axis.upper() + " of its base, so the zero-roll "
            "rotation (smallest rotation onto the track axis) is not unique; reverse the sign of "
            "the track axis in the controller, or measure the rotation with known reference points"
        )
    return Rotation.align_vectors(d, a)[0].as_matrix()


def _axis_vector(axis: str) -> NDArray[np.float64]:
    if axis not in TRACK_AXES:
        raise InputError(f"track axis must be one of {', '.join(TRACK_AXES)}, got {axis!r}")
    return TRACK_AXES[axis]


def _check_positions(e: NDArray[np.float64], group_tol: float | None) -> float:
    """Refuse touches that leave the track direction undetermined; return the travel (m).

    Positions read back with jitter around one commanded position are one position
    (:func:`robotcell.calibration.grouping.distinct`).
    """
    travel = float(e.max() - e.min())
    if travel == 0.0 or distinct(e, group_tol, [True]) < 2:
        within = "" if travel == 0.0 else f", read back within {travel * 1e3:.3f} mm"
        raise IllPosedError(
            f"all {len(e)} touches are at the same track position ({e.mean() * 1e3:.3f} mm"
            f"{within}), so the track direction and scale are not determined; touch at two or "
            f"more track positions, spread over at least {TRAVEL_WARN * 1e3:.0f} mm of travel, "
            "ideally the whole track")
    return travel


def _check_references(refs: NDArray[np.float64], d: NDArray[np.float64]) -> list[str]:
    """Refuse reference points that leave the roll undetermined; warnings for a short lever.

    A single point on the track axis, or several on one line parallel to it (to rounding,
    :data:`SAME_POINT`), cannot see the rotation about the axis. A short lever is computed.
    """
    perp = refs - np.outer(refs @ d, d)
    if len(refs) == 1:
        lever = float(np.linalg.norm(perp[0]))
        if lever < SAME_POINT:
            raise IllPosedError(
                "the reference point lies on the track axis, so the rotation about the axis stays "
                f"undetermined; use a reference point at least {LEVER_WARN * 1e3:.0f} mm off the "
                "axis, or two known points")
        what = f"the reference point is only {lever * 1e3:.1f} mm from the track axis"
    else:
        lever = max(float(np.linalg.norm(p - q)) for p in perp for q in perp)
        if lever < SAME_POINT:
            raise IllPosedError(
                "the reference points lie on one line parallel to the track axis, so the rotation "
                f"about the axis stays undetermined; add a point at least {LEVER_WARN * 1e3:.0f} mm "
                "off that line")
        what = (f"the reference points lie within {lever * 1e3:.1f} mm of one line parallel to "
                "the track axis")
    if lever < LEVER_WARN:
        return [(f"{what}: the rotation about the axis is poorly determined; use a point at "
                 f"least {LEVER_WARN * 1e3:.0f} mm off it")]
    return []


def _fit_unknown_point(e: NDArray[np.float64], f: NDArray[np.float64], prior: float | None,
                       inputs: Inputs | None):
    """Linear ML fit of ``f_i = p_mean - (e_i - e_mean) m``; returns the fit and ``e_mean``."""
    e_mean = float(e.mean())
    de = e - e_mean

    def residuals(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return f - (x[:3] - np.outer(de, x[3:]))

    m0 = -(de @ (f - f.mean(axis=0))) / (de @ de)
    names = ["fixed point x", "fixed point y", "fixed point z",
             "track vector x", "track vector y", "track vector z"]
    return fit(residuals, np.concatenate([f.mean(axis=0), m0]), names, prior,
               inputs=inputs), e_mean


def _fit_known_points(e: NDArray[np.float64], f: NDArray[np.float64], refs: NDArray[np.float64],
                      groups: NDArray[np.int_], d: NDArray[np.float64], prior: float | None,
                      inputs: Inputs | None):
    """ML fit of rotation, scale (and centred offset for two or more points)."""
    r = refs[groups]
    e_mean = float(e.mean())
    with_offset = len(refs) >= 2
    y0 = r - np.outer(e, d)
    if with_offset:
        T0 = kabsch(f, y0)
        Q0 = T0[:3, :3]
        x0 = np.concatenate([np.zeros(3), [1.0], T0[:3, 3] + e_mean * d])
    else:
        Q0 = nearest_rotation(y0.T @ f)
        x0 = np.concatenate([np.zeros(3), [1.0]])

    def unpack(x: NDArray[np.float64]):
        Q = perturb_rotation(Q0, x[:3])
        c = x[4:7] - e_mean * x[3] * d if with_offset else np.zeros(3)
        return Q, x[3], c

    def residuals(x: NDArray[np.float64]) -> NDArray[np.float64]:
        Q, s, c = unpack(x)
        return f - (r - c - np.outer(e, s * d)) @ Q

    names = ["rotation about L x", "rotation about L y", "rotation about L z", "track scale"]
    if with_offset:
        names += ["carriage offset x", "carriage offset y", "carriage offset z"]
    return fit(residuals, x0, names, prior, inputs=inputs), unpack


def calibrate_track(
    e: ArrayLike,
    f: ArrayLike,
    *,
    references: ArrayLike | None = None,
    point: ArrayLike | None = None,
    axis: str = "x",
    roll: str | None = None,
    labels: Sequence[str] | None = None,
    sigma: float | None = None,
    inputs: Inputs | None = None,
    group_tol: float | None = None,
) -> CalibrationResult:
    """Calibrate a linear track from TCP touches of fixed reference points.

    Maximum-likelihood fit under isotropic Gaussian noise on the touched positions ``f``; the
    track positions ``e`` are taken as exact. Without ``references`` the touches are of one
    unknown fixed point and the result holds the track direction, the scale and the point; the
    rotation ``L_Q_R`` is returned only with ``roll="zero"`` (see :func:`zero_roll_rotation`).
    With ``references`` the rotation is estimated too, and with two or more reference points also
    the carriage offset; with one point the offset is fixed at zero (lecture assumption (ii)).

    Parameters
    ----------
    e : array_like, shape (N,)
        Commanded track position of each touch (metres).
    f : array_like, shape (N, 3)
        TCP position at each touch in the robot base frame R (metres), e.g. from forward kinematics.
    references : array_like, shape (K, 3), optional
        Known coordinates of the reference points in L (metres).
    point : array_like of int, shape (N,), optional
        Index into ``references`` (0-based) of the point touched at each touch. Needed when
        ``K >= 2``; defaults to all 0.
    axis : {"x", "z"}
        Track axis of L: ``"x"`` (the lecture) or ``"z"`` (KUKA external kinematics).
    roll : {None, "zero"}
        Without references: ``"zero"`` asks for the full rotation under the zero-roll convention.
        Not allowed with references (the rotation is then measured).
    labels : sequence of str, optional
        Name of each touch for messages and reports (default ``"1".."N"``).
    sigma : float, optional
        Touch accuracy (metres per coordinate) the uncertainties rest on; default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    inputs : Inputs, optional
        Earlier calibrations the touched points rest on (the tool), whose errors are added to
        the uncertainty.
    group_tol : float, optional
        Track positions within this of each other (m) are the same commanded position, for the
        check that the touches are at two or more; default derived from the data
        (:func:`robotcell.calibration.grouping.resolution`), so that positions read back with
        jitter count as the position commanded.

    Returns
    -------
    CalibrationResult
        ``values``: ``direction`` (3,) unit track direction in R; ``scale`` (measured / commanded
        travel); ``point`` (3,) m, the unknown point in R at track position 0 (no references);
        ``T_L_R`` (4, 4) the pose of R in L at track position 0 when the rotation is determined
        or fixed by convention. ``sigma`` for each, ``residuals`` (N, 3) in R,
        ``estimates["T_L_R"]`` over the 7 parameters origin (m), rotation vector (rad, about
        the axes of L) and scale, the directions the touches do not determine left out,
        ``json_fields``: ``direction``, ``scale``, ``rotation`` (3x3 ``L_Q_R`` or None),
        ``offset_mm`` (or None), ``straightness_mm`` (residual across the track per touch),
        ``axis``, ``rotation_source``.

    Raises
    ------
    InputError
        Wrong shapes, NaN, fewer than 3 touches, unknown ``axis``/``roll``, bad ``point`` indices,
        or a scale so far from 1 that the data cannot be touches of one fixed point in the track's
        length unit.
    IllPosedError
        All touches at one track position, reference points on the axis (to rounding; a short
        lever is computed with a warning below :data:`LEVER_WARN`), or touches that do not
        determine the parameters (see :func:`robotcell.calibration.fit`). Repeated track
        positions are data: they are averaged by the fit.
    """
    f, e, d, labels, refs, groups = _track_touches(e, f, references, point, axis, roll, labels)
    travel = _check_positions(e, group_tol)
    warnings: list[str] = [] if refs is None else _check_references(refs, d)
    if refs is None:
        tf = _unknown_point_track(e, f, d, axis, roll, sigma, inputs)
    else:
        tf = _known_points_track(e, f, refs, groups, d, sigma, inputs)
    warnings += _track_warnings(tf, travel)
    return _track_result(tf, f, refs, axis, labels, warnings)


@dataclass
class _TrackFit:
    """A track fit (:func:`_unknown_point_track`, :func:`_known_points_track`) and what the
    result of :func:`calibrate_track` takes from it."""

    res: Fit
    values: dict
    sigma: dict
    estimates: dict
    undetermined: list[str]
    direction: NDArray[np.float64]
    direction_cov: NDArray[np.float64]
    scale: float
    Q: NDArray[np.float64] | None
    source: str | None
    offset: NDArray[np.float64] | None
    next_step: str
    value_sources: dict = field(default_factory=dict)


def _track_touches(e: ArrayLike, f: ArrayLike, references: ArrayLike | None,
                   point: ArrayLike | None, axis: str, roll: str | None,
                   labels: Sequence[str] | None) -> tuple[Any, ...]:
    """The input of :func:`calibrate_track`, checked: TCP positions, track positions, the track
    axis as a vector, the labels, the reference points and the index of the one each touch
    touched."""
    f = as_points(f, "TCP positions")
    e = np.asarray(e, dtype=float)
    if f.ndim != 2 or e.shape != (len(f),):
        raise InputError(f"track positions must have shape (N,) matching TCP positions (N, 3); "
                         f"got {e.shape} and {f.shape}")
    if not np.all(np.isfinite(e)):
        raise InputError("track positions contain NaN or infinite values")
    n = len(f)
    if n < SPECS["track"].minimum:
        raise InputError(f"touches: {n} given, at least {SPECS['track'].minimum} needed (3 "
                         "touches at different track "
                         "positions give the direction and a straightness check; use 5 or more)")
    d = _axis_vector(axis)
    if roll not in (None, "zero"):
        raise InputError(f"roll must be None or 'zero', got {roll!r}")
    labels = list(labels) if labels is not None else [str(i + 1) for i in range(n)]
    refs = None if references is None else as_points(np.atleast_2d(references), "reference points")
    if refs is not None and roll is not None:
        raise InputError("roll='zero' is a convention for an unmeasured rotation; with known "
                         "reference points the rotation is measured, so leave roll unset")
    groups = np.zeros(n, dtype=int)
    if point is not None or (refs is not None and len(refs) > 1):
        if refs is None:
            raise InputError("point indices given without reference points")
        if point is None:
            raise InputError(f"{len(refs)} reference points given: say which one each touch is "
                             "(point index per touch)")
        groups = np.asarray(point)
        if groups.shape != (n,) or not np.issubdtype(groups.dtype, np.integer):
            raise InputError(f"point indices must be N={n} integers, got {groups!r}")
        if groups.min() < 0 or groups.max() >= len(refs):
            raise InputError(f"point indices must lie in 0..{len(refs) - 1}, got {sorted(set(groups.tolist()))}")
        unused = sorted(set(range(len(refs))) - set(groups.tolist()))
        if unused:
            raise InputError(f"reference point(s) {', '.join(str(u + 1) for u in unused)} were "
                             "never touched; drop them or add their touches")
    return f, e, d, labels, refs, groups


def _unknown_point_track(e: NDArray[np.float64], f: NDArray[np.float64], d: NDArray[np.float64],
                         axis: str, roll: str | None, sigma: float | None,
                         inputs: Inputs | None) -> _TrackFit:
    """The track from touches of one unknown point: direction, scale and the point; the rotation
    only by the zero-roll convention (``roll="zero"``)."""
    values: dict = {}
    sigmas: dict = {}
    estimates: dict = {}
    undetermined: list[str] = []
    res, e_mean = _fit_unknown_point(e, f, sigma, inputs)

    def derived(x: NDArray[np.float64]) -> NDArray[np.float64]:
        s = np.linalg.norm(x[3:])
        return np.concatenate([x[3:] / s, [s], x[:3] + e_mean * x[3:]])

    y = derived(res.x)
    derived_sources = res.sources.map(jacobian(derived, res.x))
    cov = derived_sources.covariance
    sd = np.sqrt(np.abs(np.diag(cov)))
    direction, scale = y[:3], float(y[3])
    values.update(direction=direction, scale=scale, point=y[4:7])
    sigmas.update(direction=sd[:3], scale=float(sd[3]), point=sd[4:7])
    direction_cov = cov[:3, :3]
    undetermined.append(
        "rotation of L_Q_R about the track axis: touches of one unknown point cannot see it"
        + (" (set by the zero-roll convention)" if roll == "zero" else ""))
    undetermined.append("carriage offset (position of R in L at track position 0)"
                        + (": taken as zero, the lecture's assumption (ii)" if roll == "zero" else ""))
    if roll == "zero":
        Q = zero_roll_rotation(direction, axis)

        def roll_rotvec(x: NDArray[np.float64]) -> NDArray[np.float64]:
            return Rotation.from_matrix(zero_roll_rotation(derived(x)[:3], axis) @ Q.T).as_rotvec()

        values["T_L_R"] = make_pose(Q, np.zeros(3))
        A = np.zeros((7, 6))
        A[3:6] = jacobian(roll_rotvec, res.x)
        A[6] = jacobian(lambda x: [np.linalg.norm(x[3:])], res.x)
        sigmas["T_L_R_rotation"] = np.sqrt(np.abs(np.diag(A[3:6] @ res.covariance @ A[3:6].T)))
        across = np.eye(3) - np.outer(d, d)
        U = np.linalg.svd(across)[0][:, :2]
        determined = np.zeros((7, 3))
        determined[3:6, :2], determined[6, 2] = U, 1.0
        estimates["T_L_R"] = estimate(res.sources, res.input_gain, A, determined)
        source, offset = "convention: zero roll", None
        next_step = ("the rotation about the track axis is a convention, not a measurement; to "
                     "measure it, touch reference points with known coordinates in L "
                     f"({term('reference', 'references')})")
    else:
        Q, source, offset = None, None, None
        next_step = ("enter the direction and scale in the track's machine data; for the full "
                     "rotation L_Q_R touch one reference point with known coordinates in L off "
                     "the track axis (two or more also give the carriage offset) and pass them "
                     f"with {term('reference', 'references')}, or accept the zero-roll "
                     f"convention ({term('roll=zero', 'roll=' + repr('zero'))})")
    return _TrackFit(res, values, sigmas, estimates, undetermined, direction, direction_cov, scale,
                     Q, source, offset, next_step,
                     {k: derived_sources.select(rows) for k, rows in
                      (("direction", [0, 1, 2]), ("scale", [3]), ("point", [4, 5, 6]))})


def _known_points_track(e: NDArray[np.float64], f: NDArray[np.float64], refs: NDArray[np.float64],
                        groups: NDArray[np.int_], d: NDArray[np.float64],
                        sigma: float | None, inputs: Inputs | None) -> _TrackFit:
    """The track from touches of reference points known in L: its pose ``T_L_R`` and scale (the
    carriage offset with two or more points)."""
    values: dict = {}
    sigmas: dict = {}
    estimates: dict = {}
    undetermined: list[str] = []
    res, unpack = _fit_known_points(e, f, refs, groups, d, sigma, inputs)
    Q, scale, c = unpack(res.x)
    scale = float(scale)
    A = np.zeros((7, len(res.x)))
    A[:3] = jacobian(lambda x: unpack(x)[2], res.x)
    A[3:6, :3] = np.eye(3)
    A[6, 3] = 1.0
    determined = np.eye(7)[:, 3:] if len(refs) < 2 else None
    estimates["T_L_R"] = estimate(res.sources, res.input_gain, A, determined)

    def derived(x: NDArray[np.float64]) -> NDArray[np.float64]:
        Qx, _, cx = unpack(x)
        return np.concatenate([Qx.T @ d, cx])

    derived_sources = res.sources.map(jacobian(derived, res.x))
    cov = derived_sources.covariance
    sd = np.sqrt(np.abs(np.diag(cov)))
    direction = Q.T @ d
    direction_cov = cov[:3, :3]
    values.update(direction=direction, scale=scale, T_L_R=make_pose(Q, c))
    sigmas.update(direction=sd[:3], scale=float(res.sigma[3]), T_L_R_rotation=res.sigma[:3])
    if len(refs) >= 2:
        sigmas["T_L_R_position"] = sd[3:6]
        offset = c
    else:
        undetermined.append("carriage offset (position of R in L at track position 0): taken "
                            "as zero, the lecture's assumption (ii); two or more known "
                            "reference points measure it")
        offset = None
    source = "measured"
    next_step = ("enter T_L_R (robot base on the carriage at track position 0) and the scale in "
                 "the controller's track machine data, then verify by touching a reference "
                 "point at both ends of the track")
    return _TrackFit(res, values, sigmas, estimates, undetermined, direction, direction_cov, scale,
                     Q, source, offset, next_step,
                     {"direction": derived_sources.select([0, 1, 2]),
                      "scale": res.sources.select([3])})


def _track_warnings(tf: _TrackFit, travel: float) -> list[str]:
    """Refuse a scale no track has; warn of one far from 1, a poor condition, a short travel."""
    res, scale, direction_cov = tf.res, tf.scale, tf.direction_cov
    warnings: list[str] = []
    if not 1.0 / SCALE_REFUSE < scale < SCALE_REFUSE:
        raise InputError(
            f"the robot base moved {scale:.3g} times the commanded track travel; the touches are "
            "not of one fixed point, or the track positions are not in the track's length unit "
            "(the CSV needs e1 in mm)"
        )
    if abs(scale - 1.0) > SCALE_WARN:
        warnings.append(f"track scale {scale:.5f} differs from 1 by more than {SCALE_WARN:.0%}: "
                        "check the gear ratio in the track's machine data")
    if res.condition > CONDITION_LIMIT:
        warnings.append(f"condition number {res.condition:.0f} is above {CONDITION_LIMIT:.0f}: "
                        "spread the touches over more of the track travel")
    direction_sigma = float(np.sqrt(np.abs(np.trace(direction_cov))))
    if travel < TRAVEL_WARN:
        warnings.append(f"the touches span only {travel * 1e3:.1f} mm of track travel: the track "
                        f"direction is poorly determined (1-sigma {np.degrees(direction_sigma):.2f} "
                        f"deg); spread them over at least {TRAVEL_WARN * 1e3:.0f} mm, ideally "
                        "the whole track")
    return warnings


def _track_result(tf: _TrackFit, f: NDArray[np.float64], refs: NDArray[np.float64] | None,
                  axis: str, labels: list[str], warnings: list[str]) -> CalibrationResult:
    """The result of :func:`calibrate_track` from its fit."""
    res, direction, scale, Q, source, offset = (tf.res, tf.direction, tf.scale, tf.Q, tf.source,
                                                tf.offset)
    values, sigma, estimates, undetermined, next_step = (tf.values, tf.sigma, tf.estimates,
                                                         tf.undetermined, tf.next_step)
    direction_sigma = float(np.sqrt(np.abs(np.trace(tf.direction_cov))))
    warnings += outlier_warnings(res, labels)
    across = res.residuals - np.outer(res.residuals @ direction, direction)
    json_fields = {
        "axis": axis,
        "direction": direction,
        "direction_sigma_deg": np.degrees(direction_sigma),
        "scale": scale,
        "rotation": None if Q is None else Q,
        "rotation_source": source,
        "offset_mm": None if offset is None else offset * 1e3,
        "straightness_mm": np.linalg.norm(across, axis=1) * 1e3,
    }
    return CalibrationResult(
        procedure="track", values=values, sigma=sigma, labels=labels, undetermined=undetermined,
        warnings=warnings, next_step=next_step,
        kinds={"direction": "number", "scale": "number", "point": "length"},
        json_fields=json_fields, covariance=res.covariance,
        parameter_names=_names(refs), points=f, estimates=estimates,
        value_sources=tf.value_sources, frames=dict.fromkeys(tf.value_sources, "R"),
        **fit_fields(res),
    )


def _names(refs: NDArray[np.float64] | None) -> list[str]:
    if refs is None:
        return ["fixed_point_x_at_mean", "fixed_point_y_at_mean", "fixed_point_z_at_mean",
                "track_vector_x", "track_vector_y", "track_vector_z"]
    names = ["L_Q_R_rotvec_x", "L_Q_R_rotvec_y", "L_Q_R_rotvec_z", "scale"]
    if len(refs) >= 2:
        names += ["offset_x_at_mean", "offset_y_at_mean", "offset_z_at_mean"]
    return names
