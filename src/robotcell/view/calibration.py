"""The 3D scene of a calibration result: its touches, the fitted geometry, the residuals.

Made from the JSON a calibration writes (``robotcell calibrate ... --json``, mm and deg), as the
report (:mod:`robotcell.report`) is, in the frame the touches are in. It shows

- the frames of the result as triads (the robot base or the world, the frame calibrated; the
  origin of the scene's frame only when it is near the touches, else a note says how far it
  is);
- the touches, the outliers the calibration flags apart (a red cross, "outlier" in the hover
  text), each with its name;
- the fitted geometry: a turntable's circle (the touched point about the axis, ``radius_mm``
  from it, ``height_mm`` above the origin of B) and its axis Z_B; a track's line (the line the
  fixed point moves along in the robot base, one per reference point); a positioner's tilt and
  rotate axes and their common normal; a frame's triad; a tool's reference tip;
- each residual (measured minus fitted) as an arrow from the fitted point, magnified by a round
  factor (:func:`robotcell.view.shapes.magnification`) that the scene's notes state.

A TCP's touches are one point, the reference tip: each is drawn at the tip of its magnified
residual. A workpiece's touches are drawn where the table had turned each of them, in the
turntable's parent frame, with the turntable B and the workpiece W at table angle 0.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell.calibrate.registry import attach, for_result
from robotcell.kinematics.transforms import make_pose
from robotcell.view.scene import Arrows, Item, Lines, Points, Scene, Triads
from robotcell.view.shapes import (
    circle,
    line_through,
    magnification,
    residual_arrows,
    touches,
)

__all__ = ["DECIMALS", "LABELLED", "calibration_scene", "outliers"]

#: Decimals of the millimetre coordinates of a calibration's scene: 1 um.
DECIMALS = 3
#: Up to this many touches, each is labelled with its name beside it (more: in its hover text).
LABELLED = 30
#: Smallest size of a scene (m): the magnification of a few touches close together.
MIN_SIZE = 0.05
#: The origin of the scene's frame is left out when it is farther than this many times the
#: size of the touches from their centre (a turntable 3 m from the world's origin).
FAR = 2.0
#: Two reference points of a track closer than this are one (m).
SAME_REFERENCE = 1e-3


def outliers(result: Mapping[str, Any], labels: Sequence[str]) -> NDArray[np.bool_]:
    """The touches a result flags as outliers: its warnings ``touch LABEL is an outlier ...``.

    The calibration judges each touch with its leverage taken into account; the report shows
    its verdict rather than a fixed threshold.
    """
    warnings = result.get("warnings") or []
    return np.array([any(w.startswith(f"touch {lab} is an outlier") for w in warnings)
                     for lab in labels], dtype=bool)


def _m(value: Any) -> NDArray[np.float64]:
    """A JSON length (mm, nested lists) in m."""
    return np.asarray(value, dtype=float) * 1e-3


def _pose_m(matrix: Any) -> NDArray[np.float64]:
    """A JSON ``matrix`` (4x4, translation in mm) in m."""
    T = np.array(matrix, dtype=float)
    T[:3, 3] *= 1e-3
    return T


def _track_lines(fitted: NDArray[np.float64], direction: NDArray[np.float64]) -> list[Lines]:
    """The lines the fixed point(s) move along in the robot base: one per reference point,
    through its fitted points (the fitted points of one reference lie on one line)."""
    u = direction / np.linalg.norm(direction)
    across = fitted - np.outer(fitted @ u, u)
    group = np.full(len(fitted), -1)
    for i in range(len(fitted)):
        if group[i] < 0:
            group[np.linalg.norm(across - across[i], axis=1) < SAME_REFERENCE] = group.max() + 1
    many = group.max() > 0
    return [line_through(f"track line{f' {g + 1}' if many else ''}", across[group == g][0], u,
                         fitted[group == g], color="darkgray",
                         hover="the line a touched point moves along as the track moves")
            for g in range(group.max() + 1)]


def _geometry(result: Mapping[str, Any], fitted: NDArray[np.float64] | None,
              frames: list[tuple[str, NDArray[np.float64]]]) -> list[Item]:
    """The fitted geometry a procedure draws beyond its frames: its registered ``scene``
    (:attr:`Procedure.scene <robotcell.cell.calibrate.registry.Procedure>`), or nothing."""
    proc = for_result(result["procedure"])
    return [] if proc is None or proc.scene is None else proc.scene(result, fitted, frames)


def _turntable_geometry(result: Mapping[str, Any], fitted: NDArray[np.float64] | None,
                        frames: list[tuple[str, NDArray[np.float64]]]) -> list[Item]:
    """A turntable's fitted circle and its axis Z_B."""
    if not ("matrix" in result and "radius_mm" in result):
        return []
    T = _pose_m(result["matrix"])
    r, h = float(result["radius_mm"]) * 1e-3, float(result.get("height_mm") or 0.0) * 1e-3
    centre = T @ make_pose(np.eye(3), [0.0, 0.0, -h])
    z = T[:3, 2]
    lo, hi = min(0.0, -h) - 0.3 * r, max(0.0, -h) + 0.3 * r
    return [circle("fitted circle", centre, r, color="teal",
                   hover=f"the touched point about the axis: radius {r * 1e3:.3f} mm"),
            Arrows("axis Z_B", T[:3, 3] + lo * z, (hi - lo) * z, color="blue", width=4.0,
                   head=0.15, hover=[("the table's axis Z_B, the way a positive angle turns "
                                      "it (right hand)")])]


def _track_geometry(result: Mapping[str, Any], fitted: NDArray[np.float64] | None,
                    frames: list[tuple[str, NDArray[np.float64]]]) -> list[Item]:
    """The lines a track's fixed point(s) move along."""
    if fitted is None or result.get("direction") is None:
        return []
    return _track_lines(fitted, np.asarray(result["direction"], dtype=float))


def _positioner_geometry(result: Mapping[str, Any], fitted: NDArray[np.float64] | None,
                         frames: list[tuple[str, NDArray[np.float64]]]) -> list[Item]:
    """A positioner's tilt and rotate axes and their common normal."""
    keys = ("tilt_point_mm", "tilt_axis", "rotate_point_mm", "rotate_axis")
    if not all(result.get(k) is not None for k in keys):
        return []
    p0, u0, p1, u1 = (np.asarray(result[k], dtype=float) for k in keys)
    p0, p1 = p0 * 1e-3, p1 * 1e-3
    span = fitted if fitted is not None else np.array([p0, p1])
    return [line_through("tilt axis", p0, u0, span, color="darkviolet",
                         hover="the tilt axis"),
            line_through("rotate axis (tilt at 0)", p1, u1, span, color="blue",
                         hover="the rotate axis, with the tilt axis at 0"),
            Lines("common normal", np.array([p0, p1]), color="gray", width=3.0, dash="dash",
                  hover=f"common normal of the axes: {np.linalg.norm(p1 - p0) * 1e3:.3f} mm")]


def _tcp_geometry(result: Mapping[str, Any], fitted: NDArray[np.float64] | None,
                  frames: list[tuple[str, NDArray[np.float64]]]) -> list[Item]:
    """A tool's fitted reference tip."""
    if result.get("pivot_mm") is None:
        return []
    return [Points("reference tip (fitted)", _m(result["pivot_mm"]).reshape(1, 3),
                   color="teal", symbol="diamond", size=6.0,
                   hover=["the reference tip, fitted"], hover_xyz=True)]


# The scene of each procedure's results, registered with the procedure (the registry stands
# below the views and cannot name them).
for _name, _scene in (("tcp", _tcp_geometry), ("track", _track_geometry),
                      ("turntable", _turntable_geometry), ("positioner", _positioner_geometry)):
    attach(_name, scene=_scene)


def calibration_scene(result: Mapping[str, Any], frame: str = "robot base R",
                      frames: Sequence[tuple[str, ArrayLike]] = (), arrows: bool = True) -> Scene:
    """The scene of a calibration result as JSON (mm, deg).

    Parameters
    ----------
    result : mapping
        The result as ``robotcell calibrate ... --json`` writes it (checked by
        :func:`robotcell.report.load_result`): ``residuals_xyz_mm``, ``labels``, ``warnings``,
        ``points_mm`` (the touched points, when the procedure records them) and the
        procedure's own fields.
    frame : str
        Name of the frame the touches are in.
    frames : sequence of (str, array_like of shape (4, 4))
        Label and pose (translation in mm) of each frame to draw, in ``frame``.
    arrows : bool
        Draw each residual as a magnified vector; else colour each touch by the length of its
        residual (a lighter scene for a page with much else).

    Returns
    -------
    Scene
        In ``frame``, lengths in mm to 1 um (:data:`DECIMALS`); its notes state the
        magnification of the residual vectors and the outliers.
    """
    res = np.asarray(result.get("residuals_xyz_mm") or np.zeros((0, 3)), dtype=float)
    res = res.reshape(-1, 3) * 1e-3
    n = len(res)
    labels = [str(v) for v in (result.get("labels") or range(1, n + 1))]
    poses = [(str(lab), _pose_m(T)) for lab, T in frames]
    points = None
    if result.get("points_mm") is not None and len(result["points_mm"]) == n:
        points = _m(result["points_mm"]).reshape(-1, 3)
    one_spot = result["procedure"] == "tcp" and result.get("pivot_mm") is not None and n > 0
    if one_spot:
        points = _m(result["pivot_mm"]).reshape(1, 3) + res
    fitted = None if points is None else points - res
    geometry = _geometry(result, fitted, poses)
    data = ([] if points is None else list(points)) + [
        p for g in geometry for p in getattr(g, "points", np.zeros((0, 3)))]
    notes = []
    if data:
        # the origin of the scene's frame far from the data would shrink the data to a dot
        centre = (np.min(data, axis=0) + np.max(data, axis=0)) / 2
        extent = max(float(np.ptp(np.array(data), axis=0).max()), MIN_SIZE)
        far = np.linalg.norm(centre) > FAR * extent
        notes += [f"the origin of {lab} is {np.linalg.norm(centre):.2f} m from the touches: not "
                  "drawn" for lab, T in poses if far and np.array_equal(T, np.eye(4))]
        poses = [(lab, T) for lab, T in poses if not (far and np.array_equal(T, np.eye(4)))]
    cloud = np.array(data + [T[:3, 3] for _, T in poses]) if data or poses else np.zeros((1, 3))
    size = max(float(np.ptp(cloud, axis=0).max()), MIN_SIZE)
    items: list[Item] = [Triads(lab, T, [lab], length=0.15 * size) for lab, T in poses]
    items += geometry
    if points is not None and n and not arrows:
        flagged = outliers(result, labels)
        items += touches(fitted if one_spot else points, labels, flagged,
                         show_labels=n <= LABELLED and not one_spot, residuals=res,
                         color_by_residual=True)
        notes.append("each touch coloured by the length of its residual")
    elif points is not None and n:
        flagged = outliers(result, labels)
        factor = magnification(res, size)
        shown = points if not one_spot else fitted + factor * res
        items += touches(shown, labels, flagged, show_labels=n <= LABELLED, residuals=res,
                         hover_xyz=not one_spot)
        items.append(residual_arrows(points, res, factor, labels, hover=False))
        notes.append(f"residual vectors magnified {factor:g} x: each arrow runs from the fitted "
                     "point to the touch" + (", drawn at its tip (the touches of a TCP are one "
                                             "point)" if one_spot else ""))
        if np.any(flagged):
            notes.append(f"{int(flagged.sum())} outlier(s): red crosses")
    else:
        notes.append("this result holds no touched points: its frames only (the residuals "
                     "are in the tables)")
    return Scene(f"{result['procedure']}: frames and touches in {frame}", items, notes,
                 frame=frame, decimals=DECIMALS)
