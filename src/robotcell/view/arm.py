"""A DH chain drawn as its links, its joint axes and its DH frames (an arm, a positioner).

The links join the origins of the DH frames ``T_parent_0 .. T_parent_m`` (``Robot.frames``)
and the flange, each through the foot of the common normal, so that every link is drawn as the
two segments of its DH parameters: ``d`` along ``Z_{i-1}`` then ``a`` along ``X_i`` (standard
DH), or ``a`` along ``X_{i-1}`` then ``d`` along ``Z_i`` (modified DH, Craig). Joint ``i`` is an
arrow along the axis it moves about or along (``Z_{i-1}``, or ``Z_i`` in modified DH), pointing
the way a positive controller value turns it (right hand) or moves it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.robot.robot import Robot
from robotcell.view.scene import Arrows, Lines, Triads, pose_text

__all__ = ["ChainPose", "chain_items", "chain_pose"]


@dataclass(frozen=True)
class ChainPose:
    """The frames of a chain at one configuration, in the scene's frame.

    Attributes
    ----------
    frames : ndarray, shape (m + 1, 4, 4)
        ``T_scene_0 .. T_scene_m``: the DH frames (m).
    flange : ndarray, shape (4, 4)
        The flange (a robot's F, a positioner's plate P) (m).
    vertices : ndarray, shape (2 m + 2, 3)
        The links as one polyline: frame 0, then per link the foot of its common normal and the
        next frame's origin, then the flange (m).
    axis_origins, axis_directions : ndarray, shape (m, 3)
        A point of each joint's axis and the unit direction of positive motion.
    values : ndarray, shape (m,)
        The chain's joint values (rad, m), after the coupling.
    """

    frames: NDArray[np.float64]
    flange: NDArray[np.float64]
    vertices: NDArray[np.float64]
    axis_origins: NDArray[np.float64]
    axis_directions: NDArray[np.float64]
    values: NDArray[np.float64]


def chain_pose(robot: Robot, q: ArrayLike, T_scene_parent: ArrayLike | None = None) -> ChainPose:
    """Frames, link polyline and joint axes of a chain at one configuration.

    Parameters
    ----------
    robot : Robot
        The chain (its ``base`` is ``T_parent_0``).
    q : array_like, shape (n,)
        Controller axis values (rad, m).
    T_scene_parent : array_like, shape (4, 4), optional
        Pose of the chain's parent (a robot's base R, a positioner's parent) in the scene (m);
        default identity.

    Returns
    -------
    ChainPose
    """
    q = np.asarray(q, dtype=float)
    if q.shape != (robot.n_joints,):
        raise InputError(f"{robot.name}: give {robot.n_joints} joint values, got shape {q.shape}")
    T0 = np.eye(4) if T_scene_parent is None else np.asarray(T_scene_parent, dtype=float)
    F = T0 @ robot.frames(q)
    flange = F[-1] @ robot.flange
    o, x, z = F[:, :3, 3], F[:, :3, 0], F[:, :3, 2]
    step = o[1:] - o[:-1]
    # the foot of the common normal: d along Z_{i-1} (standard) or a along X_{i-1} (modified)
    along = z[:-1] if robot.convention == "standard" else x[:-1]
    feet = o[:-1] + along * np.sum(step * along, axis=-1, keepdims=True)
    vertices = np.vstack([o[:1], np.stack([feet, o[1:]], axis=1).reshape(-1, 3),
                          flange[None, :3, 3]])
    moving = slice(0, -1) if robot.convention == "standard" else slice(1, None)
    sign = np.array([j.sign for j in robot.joints])[:, None]
    return ChainPose(F, flange, vertices, o[moving], sign * z[moving],
                     robot.model_values(q))


def chain_items(robot: Robot, q: ArrayLike, T_scene_parent: ArrayLike | None = None, *,
                name: str, color: str = "dimgray", axis_length: float = 0.15,
                frame_length: float = 0.08, flange_label: str = "flange F",
                detail: bool = True) -> list:
    """A chain drawn as links, joint axes, DH frames and its flange.

    Parameters
    ----------
    robot : Robot
    q : array_like, shape (n,)
        Controller axis values (rad, m).
    T_scene_parent : array_like, shape (4, 4), optional
        Pose of the chain's parent in the scene (m).
    name : str
        Name of the chain in the legend (``"robot kuka_kr16"``).
    color : str
        Colour of the links.
    axis_length : float
        Length of the joint axis arrows (m).
    frame_length : float
        Axis length of the DH frame triads (m).
    flange_label : str
        Label of the flange triad (a positioner: ``"plate P"``).
    detail : bool
        Draw the joint axes and the DH frames too.

    Returns
    -------
    list of Item
        ``Lines`` (the links), with ``detail`` ``Arrows`` (joint axes, hover: name, value and
        limits) and ``Triads`` of the DH frames ``0 .. m`` (listed in the legend, drawn when
        clicked there), and last ``Triads`` of the flange.
    """
    cp = chain_pose(robot, q, T_scene_parent)
    links = Lines(f"{name}: links", cp.vertices, color=color, width=8.0)
    flange = Triads(f"{name}: {flange_label}", cp.flange, [flange_label], length=frame_length)
    if not detail:
        return [links, flange]
    hover = []
    for j, v in zip(robot.joints, cp.values):
        unit, k = ("mm", 1e3) if j.prismatic else ("deg", 180.0 / np.pi)
        what = "passive, moved by the coupling" if j.passive else (
            f"limits [{j.lower * k:g}, {j.upper * k:g}] {unit}")
        hover.append(f"<b>{j.name or 'joint'}</b> {'moves along' if j.prismatic else 'turns about'}"
                     f" this arrow: {v * k:.3f} {unit}<br>{what}")
    axes = Arrows(f"{name}: joint axes", cp.axis_origins - 0.5 * axis_length * cp.axis_directions,
                  axis_length * cp.axis_directions, color="darkviolet", width=6.0, head=0.3,
                  hover=hover)
    labels = [str(i) for i in range(len(cp.frames))]
    dh = Triads(f"{name}: DH frames", cp.frames, labels, length=frame_length,
                hover=[f"<b>DH frame {lab}</b><br>{t}" for lab, t in zip(labels, pose_text(cp.frames))],
                visible=False)
    return [links, axes, dh, flange]
