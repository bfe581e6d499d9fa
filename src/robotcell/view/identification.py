"""The 3D scene of a kinematic identification: the measured targets, the residuals, and the
identified arm beside the nominal one.

In the measuring device's frame D (a laser tracker's), as the measurements are:

- the robot base R where the identification puts it (``T_D_R``);
- every measured target, the rows the identification flags as outliers apart (red crosses);
- each residual of the identified model (measured minus predicted) as an arrow from the
  predicted point, magnified by a stated round factor
  (:func:`robotcell.view.shapes.magnification`);
- the nominal arm and the identified arm at the configuration of one measured row (the first),
  both on the identified base: the nominal as its links (:func:`robotcell.view.arm.chain_pose`),
  the identified with its difference from the nominal magnified by a second stated factor (the
  identified links differ from the nominal by about a millimetre, which no drawing of a
  two-metre arm would show). Each vertex of the identified arm is the point of its joint axis
  nearest to the nominal vertex: the DH origin of an identified link between nearly parallel
  axes can lie metres away along them, a place with no meaning for the arm.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.identification.result import IdentificationResult
from robotcell.robot.robot import Robot
from robotcell.view.arm import ChainPose, chain_pose
from robotcell.view.calibration import DECIMALS, LABELLED
from robotcell.view.scene import Item, Lines, Scene, Triads
from robotcell.view.shapes import magnification, residual_arrows, touches

__all__ = ["identification_scene"]


def _on_axes(robot: Robot, identified: ChainPose, nominal: ChainPose) -> NDArray[np.float64]:
    """The vertices of the identified chain nearest to the nominal ones on the same axes.

    A link's vertices (:class:`~robotcell.view.arm.ChainPose`) lie on joint axes: the origin of
    DH frame i on its Z, the foot of the common normal on ``Z_{i-1}`` (standard DH) or ``Z_i``
    (modified DH). Each nominal vertex is projected onto the identified axis it lies on; the
    flange is the identified flange.
    """
    m = len(identified.frames) - 1
    foot = np.arange(m) + (0 if robot.convention == "standard" else 1)
    axis = np.concatenate([[0], np.stack([foot, np.arange(1, m + 1)], axis=1).ravel()])
    o = identified.frames[axis, :3, 3]
    z = identified.frames[axis, :3, 2]
    v = nominal.vertices[:-1]
    on = o + z * np.sum((v - o) * z, axis=-1, keepdims=True)
    return np.vstack([on, identified.flange[None, :3, 3]])


def identification_scene(result: IdentificationResult, q: ArrayLike, points: ArrayLike,
                         row: int = 0, arrows: bool = True) -> Scene:
    """The scene of an identification and the measurements it was made from.

    Parameters
    ----------
    result : IdentificationResult
    q : array_like, shape (N, n)
        The measured configurations (controller values; rad, m), as identified.
    points : array_like, shape (N, K, 3)
        The measured targets in the device frame D (m).
    row : int
        The row whose configuration the arms are drawn at.
    arrows : bool
        Draw each residual as a magnified vector; else colour each target by the length of its
        residual (a lighter scene for many measurements).

    Returns
    -------
    Scene
        In D, lengths in mm to 1 um; its notes state both magnifications and the outliers.

    Raises
    ------
    InputError
        Measurements that do not match the result's residuals.
    """
    qq = np.asarray(q, dtype=float)
    p = np.asarray(points, dtype=float)
    res = result.residuals
    if p.ndim == 2:
        p = p[:, None, :]
    if p.shape != res.shape or qq.shape != (len(p), result.robot.n_joints):
        raise InputError(f"measurements of shape {qq.shape} and {p.shape} do not match the "
                         f"identification's residuals {res.shape}")
    n, k = res.shape[:2]
    labels = [lab if k == 1 else f"{lab} target {t + 1}" for lab in result.labels
              for t in range(k)]
    flat, r = p.reshape(-1, 3), res.reshape(-1, 3)
    flagged = np.repeat(np.isin(np.arange(n), result.outliers), k)
    nominal = chain_pose(result.nominal, qq[row], result.base)
    identified = chain_pose(result.robot, qq[row], result.base)
    size = float(np.ptp(np.vstack([flat, nominal.vertices]), axis=0).max())
    factor = magnification(r, size)
    diff = _on_axes(result.robot, identified, nominal) - nominal.vertices
    gain = magnification(diff, size, share=0.05)
    name = result.labels[row]
    row_name = name if name.startswith("row") else f"row {name}"
    items: list[Item] = [
        Triads("robot base R", result.base, ["R"], length=0.1 * size),
        Lines(f"nominal arm ({row_name})", nominal.vertices, color="dimgray", width=8.0,
              hover=[f"nominal: frame {i}" for i in range(len(nominal.vertices))]),
        Lines(f"identified arm, its difference x {gain:g}", nominal.vertices + gain * diff,
              color="royalblue", width=6.0,
              hover=[f"identified: {d:.3f} mm from the nominal (drawn x {gain:g})"
                     for d in np.linalg.norm(diff, axis=1) * 1e3]),
        *touches(flat, labels, flagged, name="measured targets", show_labels=len(flat) <= LABELLED,
                 residuals=r, color_by_residual=not arrows),
    ]
    if arrows:
        items.append(residual_arrows(flat, r, factor, labels, hover=False))
    notes = [f"residual vectors of the identified model magnified {factor:g} x" if arrows else
             "each target coloured by the length of its residual (identified model)",
             (f"the arms at the configuration of {row_name}, on the identified base; the "
              f"identified one's difference from the nominal magnified {gain:g} x")]
    if np.any(flagged):
        notes.append(f"{len(result.outliers)} outlier row(s): red crosses")
    return Scene(f"identification of {result.nominal.name}: measured targets in the device "
                 "frame", items, notes, frame="device D", decimals=DECIMALS)
