"""Shapes of a 3D view, built from poses and points in SI units: circles, plates, fitted lines,
touches and their residual vectors.

These are the pieces of the scene of a calibration (the touches, the fitted geometry, each
residual as a vector magnified by a stated factor) and of a cell (a turntable's plate and axis).
Each function returns :mod:`robotcell.view.scene` items; nothing here depends on the plotting
library.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.kinematics.transforms import as_points, transform_points, validate_pose
from robotcell.view.scene import Arrows, Lines, Mesh, Points

__all__ = ["OUTLIER_COLOR", "RESIDUAL_COLOR", "circle", "circle_points", "disk", "line_through",
           "magnification", "residual_arrows", "touches"]

#: Colour of residual vectors.
RESIDUAL_COLOR = "darkorange"
#: Colour of touches flagged as outliers.
OUTLIER_COLOR = "crimson"


def _pose(T: ArrayLike, name: str) -> NDArray[np.float64]:
    arr = validate_pose(T, name)
    if arr.shape != (4, 4):
        raise InputError(f"{name} must be one pose of shape (4, 4), got {arr.shape}")
    return arr


def _length(value: float, name: str) -> float:
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"{name} must be a length > 0 (m), got {value}")
    return float(value)


def circle_points(T: ArrayLike, radius: float, n: int = 72) -> NDArray[np.float64]:
    """A circle about the origin of ``T`` in its XY plane, as a closed polyline.

    Parameters
    ----------
    T : array_like, shape (4, 4)
        Pose of the circle's frame: centre at its origin, axis along its Z (m).
    radius : float
        Radius (m).
    n : int
        Number of segments.

    Returns
    -------
    ndarray, shape (n + 1, 3)
        Points of the circle (m), the first repeated at the end; the first is on the X axis of
        ``T``.
    """
    t = np.linspace(0.0, 2.0 * np.pi, n + 1)
    r = _length(radius, "radius")
    local = np.column_stack([r * np.cos(t), r * np.sin(t), np.zeros_like(t)])
    return transform_points(_pose(T, "circle pose"), local)


def circle(name: str, T: ArrayLike, radius: float, color: str = "black", width: float = 4.0,
           hover: str = "") -> Lines:
    """A circle about the origin of ``T`` in its XY plane (a turntable's fitted circle).

    Parameters
    ----------
    name : str
        Legend entry.
    T : array_like, shape (4, 4)
        Centre and axis (Z) of the circle (m).
    radius : float
        Radius (m).
    color : str
    width : float
        Line width (pixels).
    hover : str
        Hover text of the circle.

    Returns
    -------
    Lines
    """
    pts = circle_points(T, radius)
    return Lines(name, pts, color=color, width=width, hover=hover or None)


def disk(name: str, T: ArrayLike, radius: float, color: str = "lightgray", opacity: float = 0.5,
         hover: str = "", n: int = 48) -> Mesh:
    """A flat disk about the origin of ``T`` in its XY plane (a turntable's plate).

    Parameters
    ----------
    name : str
    T : array_like, shape (4, 4)
        Centre and normal (Z) of the disk (m); its X and Y do not matter: a disk turned about
        its normal is the same disk, with the same vertices (a path's view draws a turning
        plate once).
    radius : float
        (m).
    color : str
    opacity : float
    hover : str
    n : int
        Number of triangles.

    Returns
    -------
    Mesh
        ``n + 1`` vertices: the centre, then ``n`` on the rim, the first in the direction of
        the plane closest to the X axis of the scene (its Y axis when the normal is along X).
    """
    P = _pose(T, "disk pose")
    z = P[:3, 2]
    ref = np.eye(3)[0] if abs(z[0]) < 0.9 else np.eye(3)[1]
    x = ref - (ref @ z) * z
    x /= np.linalg.norm(x)
    plane = np.eye(4)
    plane[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    plane[:3, 3] = P[:3, 3]
    rim = circle_points(plane, radius, n)[:-1]
    k = np.arange(n)
    faces = np.column_stack([np.zeros(n, dtype=int), 1 + k, 1 + (k + 1) % n])
    return Mesh(name, np.vstack([P[:3, 3], rim]), faces, color=color, opacity=opacity, hover=hover)


def line_through(name: str, point: ArrayLike, direction: ArrayLike, points: ArrayLike,
                 color: str = "black", margin: float = 0.1, hover: str = "") -> Lines:
    """A fitted line, drawn over the extent of the points it was fitted to (a track's axis).

    Parameters
    ----------
    name : str
    point : array_like, shape (3,)
        A point of the line (m).
    direction : array_like, shape (3,)
        Its direction (any length > 0).
    points : array_like, shape (N, 3)
        The points it was fitted to (m): the line spans their projections onto it, longer by
        ``margin`` of that span at each end.
    color : str
    margin : float
    hover : str

    Returns
    -------
    Lines
        Two points.
    """
    p0 = as_points(point, "line point").reshape(3)
    u = as_points(direction, "line direction").reshape(3)
    norm = float(np.linalg.norm(u))
    if norm == 0:
        raise InputError("line direction must not be zero")
    u = u / norm
    s = (as_points(points, "points").reshape(-1, 3) - p0) @ u
    lo, hi = (float(s.min()), float(s.max())) if s.size else (0.0, 0.0)
    pad = margin * (hi - lo)
    ends = p0 + np.outer([lo - pad, hi + pad], u)
    return Lines(name, ends, color=color, hover=hover or None)


def touches(points: ArrayLike, labels: Sequence[str] | None = None,
            outliers: ArrayLike | None = None, name: str = "touches",
            show_labels: bool = True, residuals: ArrayLike | None = None,
            hover_xyz: bool = True, color_by_residual: bool = False) -> list[Points]:
    """Touched points, the outliers apart in a colour and symbol of their own.

    Parameters
    ----------
    points : array_like, shape (N, 3)
        Touched (measured) positions (m).
    labels : sequence of str, optional
        Name of each touch (default ``"1".."N"``), drawn beside it and in its hover text.
    outliers : array_like of bool, shape (N,), optional
        Touches flagged as outliers by the calibration.
    name : str
        Legend entry; the outliers get ``name + " (outliers)"``.
    show_labels : bool
        Draw each label beside its touch (else in its hover text only: many touches, or touches
        on one spot).
    residuals : array_like, shape (N, 3), optional
        Residual of each touch (m): its length (mm) joins the hover text.
    hover_xyz : bool
        The position (mm) in the hover text (False: ``points`` are not where the touches were).
    color_by_residual : bool
        Colour the touches that are not outliers by the length of their residual (mm, Viridis
        from 0 to the longest), instead of residual vectors.

    Returns
    -------
    list of Points
        The touches that are not outliers, then the outliers (when there are any), each with
        its name, residual and position in the hover text.
    """
    p = as_points(points, "touches").reshape(-1, 3)
    labs = [str(i + 1) for i in range(len(p))] if labels is None else [str(s) for s in labels]
    if len(labs) != len(p):
        raise InputError(f"touches: {len(labs)} labels for {len(p)} points")
    bad = np.zeros(len(p), bool) if outliers is None else np.asarray(outliers, dtype=bool)
    if bad.shape != (len(p),):
        raise InputError(f"touches: outliers must be {len(p)} booleans, got shape {bad.shape}")
    hover = [f"touch {lab}" for lab in labs]
    norms = None
    if residuals is not None:
        r = as_points(residuals, "residuals").reshape(-1, 3)
        if r.shape != p.shape:
            raise InputError(f"touches: {len(r)} residuals for {len(p)} points")
        norms = np.linalg.norm(r, axis=1) * 1e3
        hover = [f"{h}: residual {n:.3f} mm" for h, n in zip(hover, norms)]
    if color_by_residual and norms is None:
        raise InputError("touches: color_by_residual needs the residuals")
    out = []
    for mask, suffix, color, symbol, size in ((~bad, "", "black", "circle", 4.0),
                                              (bad, " (outliers)", OUTLIER_COLOR, "x", 7.0)):
        if np.any(mask) or not suffix:
            idx = np.flatnonzero(mask)
            by = {} if norms is None or not color_by_residual or suffix else {
                "values": norms[idx], "value_range": (0.0, max(float(norms.max()), 1e-9)),
                "value_title": "residual (mm)"}
            out.append(Points(name + suffix, p[idx], color=color, symbol=symbol, size=size,
                              labels=[labs[i] for i in idx] if show_labels else None,
                              hover=[hover[i] + (", an outlier" if suffix else "") for i in idx],
                              hover_xyz=hover_xyz, **by))
    return out


def magnification(residuals: ArrayLike, size: float, share: float = 0.1) -> float:
    """Factor that draws the longest residual vector as about ``share`` of the scene's size.

    Parameters
    ----------
    residuals : array_like, shape (N, 3)
        Residual vectors (m).
    size : float
        Size of the scene (m), e.g. the largest extent of the touches.
    share : float
        Drawn length of the longest residual as a fraction of ``size``.

    Returns
    -------
    float
        1, 2 or 5 times a power of ten, at least 1 (a residual is never drawn shorter than it
        is), rounded down so that the longest residual is drawn at most ``share * size`` long
        (unless it is longer than that unmagnified).
    """
    r = as_points(residuals, "residuals").reshape(-1, 3)
    longest = float(np.max(np.linalg.norm(r, axis=1))) if len(r) else 0.0
    target = share * _length(size, "size")
    if longest == 0.0 or longest >= target:
        return 1.0
    raw = target / longest
    exp = math.floor(math.log10(raw))
    mantissa = max(m for m in (1, 2, 5, 10) if m * 10.0**exp <= raw * (1 + 1e-12))
    return float(mantissa * 10.0**exp)


def residual_arrows(points: ArrayLike, residuals: ArrayLike, factor: float,
                    labels: Sequence[str] | None = None, name: str = "residuals",
                    hover: bool = True) -> Arrows:
    """Residual vectors magnified by ``factor``, from the point the fit predicts.

    Parameters
    ----------
    points : array_like, shape (N, 3)
        Touched (measured) positions (m).
    residuals : array_like, shape (N, 3)
        Measured minus predicted position of each touch (m), as calibration results hold them.
    factor : float
        Magnification (> 0): each arrow starts at the predicted point ``points - residuals`` and
        is ``factor * residual`` long. :func:`magnification` proposes one.
    labels : sequence of str, optional
        Name of each touch, for the hover texts.
    name : str
        Legend entry; the factor is appended, e.g. ``"residuals x 200"``.
    hover : bool
        Hover texts on the arrows (False: the touches carry their residuals, :func:`touches`).

    Returns
    -------
    Arrows
        With the residual's length in mm in each hover text.
    """
    p = as_points(points, "touches").reshape(-1, 3)
    r = as_points(residuals, "residuals").reshape(-1, 3)
    if r.shape != p.shape:
        raise InputError(f"residuals: {len(r)} vectors for {len(p)} touches")
    f = _length(factor, "factor")
    labs = [str(i + 1) for i in range(len(p))] if labels is None else [str(s) for s in labels]
    text = [f"touch {lab}: residual {n:.3f} mm (drawn x {f:g})"
            for lab, n in zip(labs, np.linalg.norm(r, axis=1) * 1e3)]
    return Arrows(f"{name} x {f:g}", p - r, f * r, color=RESIDUAL_COLOR, width=4.0,
                  hover=text if hover else None)
