"""Geometric first estimate (circle point analysis): joint axes from rows moving one joint.

Rows that differ only in joint ``j`` move every target on a circle about axis ``j`` (revolute)
or along a line parallel to it (prismatic); "only" to what the joint values resolve
(:func:`robotcell.calibration.grouping.alone_groups`: joints read back from a controller with
jitter group as the values commanded), each row brought back with its own values. A plane and circle fit per target gives the axis
line in the device frame D: normal of the plane (oriented so that a positive joint value turns
right-handed about it) through the circle's centre. Lines measured with joints ``1..j-1`` away
from zero are brought back to the zero position by the inverse screw motions of the axes found
before (``L_j(0) = M_{j-1}(-q_{j-1}) ... M_1(-q_1) L_j(q)``). The DH procedure of
:mod:`robotcell.dhprocedure` turns the axes into the start model (Mooring, Roth and Driels,
*Fundamentals of Manipulator Calibration*, Wiley 1991, ch. 4, circle point analysis).
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.grouping import alone_groups, joint_tolerances, resolution
from robotcell.dhprocedure import AxisChain, dh_from_axes
from robotcell.errors import IllPosedError
from robotcell.identification.chain import PARALLEL_TOL
from robotcell.identification.measurements import TargetMeasurements, read_target_measurements
from robotcell.identification.result import GEOMETRIC_SOURCE
from robotcell.robot.robot import Robot

__all__ = ["axis_lines", "first_estimate", "start_model"]

#: Smallest motion of the moved joint in a group (radians, or metres for prismatic joints).
MIN_SPAN = math.radians(10.0)
#: Smallest stroke of a prismatic joint in a group (metres).
MIN_STROKE = 0.01
#: A group whose targets deviate from a straight line by less than this fraction of their
#: travel is a prismatic joint.
LINE_TOL = 1e-3


def _fit_group(qj: NDArray[np.float64], p: NDArray[np.float64]):
    """Axis of one group of one target: (kind, point, direction, weight)."""
    c = p.mean(axis=0)
    # Straight line?
    A = np.stack([np.ones_like(qj), qj], axis=1)
    coef, *_ = np.linalg.lstsq(A, p, rcond=None)
    travel = np.linalg.norm(coef[1]) * np.ptp(qj)
    line_rms = math.sqrt(np.mean(np.sum((p - A @ coef) ** 2, axis=1)))
    if travel > 0 and line_rms < LINE_TOL * travel:
        d = coef[1] / np.linalg.norm(coef[1])
        return "prismatic", c, d, travel
    _, _, vt = np.linalg.svd(p - c, full_matrices=False)
    n = vt[2]
    u = vt[0]
    v = np.cross(n, u)
    xy = np.stack([(p - c) @ u, (p - c) @ v], axis=1)
    M = np.concatenate([2 * xy, np.ones((len(p), 1))], axis=1)
    sol, *_ = np.linalg.lstsq(M, np.sum(xy**2, axis=1), rcond=None)
    centre2 = sol[:2]
    radius = math.sqrt(max(sol[2] + centre2 @ centre2, 0.0))
    ang = np.unwrap(np.arctan2(xy[:, 1] - centre2[1], xy[:, 0] - centre2[0])[np.argsort(qj)])
    slope = np.polyfit(np.sort(qj), ang, 1)[0]
    if slope < 0:
        n = -n
    return "revolute", c + centre2[0] * u + centre2[1] * v, n, radius


def _mean_line(points: list, dirs: list, weights: list):
    """Weighted mean of lines found along the same axis: (point, unit direction)."""
    d = np.average(np.array(dirs), axis=0, weights=weights)
    return np.average(np.array(points), axis=0, weights=weights), d / np.linalg.norm(d)


def _back(pts, dirs, types, q, j) -> NDArray[np.float64]:
    """``M_{j-1}(-q_{j-1}) ... M_1(-q_1)`` per row of ``q`` (N, n): shape (N, 4, 4).

    Brings each row's geometry back to joints 1..j-1 at zero, with that row's own values (read
    back values differ a little from row to row of a group).
    """
    B = np.broadcast_to(np.eye(4), (len(q), 4, 4))
    if not j:
        return B
    axes = AxisChain(points=pts[:j], directions=dirs[:j], types=tuple(types[:j]))
    M = axes.motions(-q[:, :j])
    for i in range(j):
        B = M[:, i] @ B
    return B


def axis_lines(meas: TargetMeasurements, prismatic: NDArray[np.bool_] | None = None,
               group_tol: ArrayLike | None = None,
               ) -> tuple[NDArray[np.float64], NDArray[np.float64], list[str]]:
    """Joint axes at ``q = 0`` in the device frame from rows moving one joint at a time.

    Parameters
    ----------
    meas : TargetMeasurements
        Joint values (rad, m for prismatic joints).
    prismatic : ndarray of bool, shape (n,), optional
        Known prismatic joints. When not given, every joint value is taken as an angle and the
        joint type comes from the fit (a straight line: prismatic); the axis lines after a
        prismatic joint are then only right when its values are 0 in the rows that move them.
    group_tol : float or array_like, shape (n,), optional
        Joint values within this of each other are the same commanded value: one number (rad,
        a prismatic joint taking as many mm as that is deg) or one per joint (rad, m); default
        derived from the data (:func:`robotcell.calibration.grouping.resolution`), so that
        joints read back from a controller with jitter group as the values commanded.

    Returns
    -------
    points : ndarray, shape (n, 3)
        A point on each axis in D (m).
    directions : ndarray, shape (n, 3)
        Unit directions (positive joint value turns right-handed / moves along).
    types : list of {"revolute", "prismatic"}

    Raises
    ------
    IllPosedError
        A joint that no group of at least 3 rows moves alone over at least 10 deg.
    """
    q, p = meas.q, meas.points
    n = q.shape[1]
    pris = np.zeros(n, dtype=bool) if prismatic is None else np.asarray(prismatic, dtype=bool)
    tol = None if group_tol is None else joint_tolerances(group_tol, pris)
    pts, dirs, types = np.zeros((n, 3)), np.zeros((n, 3)), []
    for j in range(n):
        groups = alone_groups(q, j, least=3, span=MIN_STROKE if pris[j] else MIN_SPAN,
                              tol=tol, prismatic=pris)
        if not groups:
            raise IllPosedError(
                f"joint {j + 1}: no rows move it alone; the circle point analysis needs at least 3 "
                f"rows that differ only in a{j + 1}, spread over at least "
                f"{math.degrees(MIN_SPAN):.0f} deg or {MIN_STROKE * 1e3:.0f} mm, the other joints "
                f"held to within {_tolerance_text(q, j, tol, pris)} (or state the grouping "
                "tolerance, or give the nominal model as robot)")
        fits = []
        for rows in groups:
            # Undo the motion of the axes before j (their lines are known at q = 0).
            back = _back(pts, dirs, types, q[rows], j)
            for k in range(p.shape[1]):
                loc = np.einsum("nij,nj->ni", back[:, :3, :3], p[rows, k]) + back[:, :3, 3]
                fits.append(_fit_group(q[rows, j], loc))
        kinds = {f[0] for f in fits}
        if prismatic is not None:
            kind = "prismatic" if pris[j] else "revolute"
        else:
            kind = "prismatic" if kinds == {"prismatic"} else "revolute"
        use = [f for f in fits if f[0] == kind]
        pts[j], dirs[j] = _mean_line([f[1] for f in use], [f[2] for f in use], [f[3] for f in use])
        types.append(kind)
    return pts, dirs, types


def _tolerance_text(q: NDArray[np.float64], j: int, tol: NDArray[np.float64] | None,
                    pris: NDArray[np.bool_]) -> str:
    """The grouping tolerance of the joints other than ``j``, in deg and mm, for a message."""
    others = np.delete(pris, j)
    used = resolution(np.delete(q, j, axis=1), others) if tol is None else np.delete(tol, j)
    scale = np.where(others, 1e3, 180.0 / math.pi)
    parts = sorted({f"{t:.3g} {'mm' if p else 'deg'}" for t, p in zip(used * scale, others)})
    how = "derived from the data" if tol is None else "stated"
    return f"{' / '.join(parts)} ({how})"


def first_estimate(path: str | Path, name: str = "identified", j23_factor: float = 0.0,
                   group_tol: float | None = None) -> tuple[Robot, TargetMeasurements]:
    """Start model and measurements from a CSV without a nominal model.

    Parameters
    ----------
    path : str or Path
        Measurement CSV (``docs/identification.md``) containing, for every joint, rows that move
        that joint alone; a joint whose targets move on straight lines is prismatic (its column
        in mm).
    name : str
        Name of the model.
    j23_factor : float
        J2/J3 coupling ``k`` of the controller values in the CSV: the chain's joint 3 is
        ``a3 + k * a2`` (FANUC: 1, the ROS-Industrial driver's ``J23_factor``). The rows must
        move one joint of the chain at a time, i.e. in these model values (moving J2 alone on a
        FANUC means a3 = -a2, so that the forearm keeps still relative to the upper arm).
    group_tol : float, optional
        Joint values within this of each other are the same commanded value (rad; a prismatic
        joint takes as many mm as that is deg); default derived from the data (see
        :func:`axis_lines`).

    Returns
    -------
    robot : Robot
        See :func:`start_model`; its joint values are the chain's (model) values, without the
        coupling, as :func:`~robotcell.identification.identify` with ``j23_factor=j23_factor``
        expects of a nominal model.
    measurements : TargetMeasurements
        The CSV in SI units, prismatic joints in metres: controller values, as in the file.

    Raises
    ------
    IllPosedError
        A joint that no rows move alone (in model values).
    """
    raw = read_target_measurements(path)
    types = axis_lines(_model_values(raw, j23_factor), group_tol=group_tol)[2]
    pris = np.array([t == "prismatic" for t in types])
    meas = read_target_measurements(path, pris) if pris.any() else raw
    return start_model(_model_values(meas, j23_factor), pris, name, group_tol), meas


def _model_values(meas: TargetMeasurements, k: float) -> TargetMeasurements:
    """``meas`` with joint 3 replaced by the chain's ``a3 + k * a2`` (unchanged for ``k = 0``)."""
    if not k or meas.q.shape[1] < 3:
        return meas
    q = meas.q.copy()
    q[:, 2] += k * q[:, 1]
    return replace(meas, q=q)


def start_model(meas: TargetMeasurements, prismatic: NDArray[np.bool_] | None = None,
                name: str = "identified", group_tol: ArrayLike | None = None) -> Robot:
    """Standard-DH start model from rows moving one joint at a time (circle point analysis).

    Parameters
    ----------
    meas : TargetMeasurements
        Joint values (rad, m) and measured targets in the device frame (m).
    prismatic : ndarray of bool, shape (n,), optional
        Known prismatic joints (default: from the fits, see :func:`axis_lines`).
    name : str
    group_tol : float or array_like, shape (n,), optional
        Grouping tolerance of the joint values, see :func:`axis_lines`.

    Returns
    -------
    Robot
        Its base frame R has ``Z`` along axis 1, the origin on axis 1 nearest axis 2, ``X`` toward
        axis 2; the flange ``Z`` along the last axis, its origin on that axis nearest the first
        target, ``X`` toward the target. Nearly parallel consecutive axes (within 1 deg) are made
        exactly parallel. Joint names ``A1..An``, no limits.
    """
    pts, dirs, types = axis_lines(meas, prismatic, group_tol)
    T_D_R = _base_frame(pts, dirs)
    R, t = T_D_R[:3, :3], T_D_R[:3, 3]
    pts_R, dirs_R = (pts - t) @ R, dirs @ R
    # Nearly parallel consecutive axes become exactly parallel: the DH procedure would put their
    # common normal far away, and the identification's Hayati beta restores the tilt.
    for j in range(1, len(types)):
        if np.linalg.norm(np.cross(dirs_R[j], dirs_R[j - 1])) < math.sin(PARALLEL_TOL):
            dirs_R[j] = math.copysign(1.0, dirs_R[j] @ dirs_R[j - 1]) * dirs_R[j - 1]
    # Flange: on the last axis, X toward target 1 at q = 0.
    B = np.eye(4)
    q0 = meas.q[0]
    axes_D = AxisChain(points=pts, directions=dirs, types=tuple(types))
    for Mi in axes_D.motions(-q0)[::-1]:
        B = B @ Mi
    target0 = B[:3, :3] @ meas.points[0, 0] + B[:3, 3]
    target0_R = R.T @ (target0 - t)
    z = dirs_R[-1]
    foot = pts_R[-1] + ((target0_R - pts_R[-1]) @ z) * z
    x = target0_R - foot
    x = x - (x @ z) * z
    x = x / np.linalg.norm(x) if np.linalg.norm(x) > 1e-6 else _any_perpendicular(z)
    F = np.eye(4)
    F[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)
    F[:3, 3] = foot
    names = tuple(f"A{i}" for i in range(1, len(types) + 1))
    chain = AxisChain(points=pts_R, directions=dirs_R, types=tuple(types), flange=F, names=names)
    return dh_from_axes(chain, "standard", name=name, title=name,
                        source=GEOMETRIC_SOURCE).robot


def _any_perpendicular(z: NDArray[np.float64]) -> NDArray[np.float64]:
    a = np.eye(3)[int(np.argmin(np.abs(z)))]
    v = np.cross(z, a)
    return v / np.linalg.norm(v)


def _base_frame(pts: NDArray[np.float64], dirs: NDArray[np.float64]) -> NDArray[np.float64]:
    """``T_D_R``: Z along axis 1, origin on it nearest axis 2, X toward axis 2."""
    z = dirs[0]
    o = pts[0]
    x = None
    if len(pts) > 1:
        w = np.cross(z, dirs[1])
        if np.linalg.norm(w) > 1e-6:  # skew or intersecting: foot of the common normal
            A = np.stack([z, -dirs[1], w], axis=1)
            s, _, _ = np.linalg.solve(A, pts[1] - pts[0])
            o = pts[0] + s * z
            x = w / np.linalg.norm(w)
            if (pts[1] - o) @ x < 0:
                x = -x
        if x is None or np.linalg.norm(x) < 1e-9:
            r = pts[1] - o
            x = r - (r @ z) * z
            x = x / np.linalg.norm(x) if np.linalg.norm(x) > 1e-6 else None
    if x is None:
        x = _any_perpendicular(z)
    T = np.eye(4)
    T[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)
    T[:3, 3] = o
    return T
