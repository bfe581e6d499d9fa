"""Where a robot may go while it is measured: a work volume for proposed configurations.

Configurations proposed for an identification (:func:`robotcell.identification.validation.
select_configurations`) are drawn at random within the joint limits; many of them put the flange
below the floor or into a fixture. A :class:`WorkVolume` is an intersection of half-spaces in the
robot base frame R, ``normals @ p <= offsets``: a box the user gives, or the floor (``z >= 0`` of
the robot base or of a cell's world). :func:`configurations_within` draws random configurations
within the joint limits whose flange and reflectors (where the proposal assumes them,
:func:`~robotcell.identification.validation.reflector_spots`) lie inside it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.identification.validation import random_configurations, reflector_spots
from robotcell.kinematics.transforms import validate_single_pose
from robotcell.robot.robot import Robot

__all__ = ["WorkVolume", "configurations_within", "measured_points"]

#: Random configurations drawn per round of :func:`configurations_within`, and the most rounds.
_BATCH, _ROUNDS = 2000, 50


@dataclass(frozen=True)
class WorkVolume:
    """The points ``p`` (robot base frame R, m) with ``normals @ p <= offsets``.

    Attributes
    ----------
    normals : ndarray, shape (k, 3)
        Outward unit normals of the bounding planes.
    offsets : ndarray, shape (k,)
        Their distances from R's origin along the normals (m).
    description : str
        Where it is, for messages (``inside the box x -500..1500, ... mm in the robot base
        frame``, ``above the robot base plane``).
    """

    normals: NDArray[np.float64]
    offsets: NDArray[np.float64]
    description: str

    @classmethod
    def box(cls, lower: ArrayLike, upper: ArrayLike) -> WorkVolume:
        """The box ``lower <= p <= upper`` in the robot base frame.

        Parameters
        ----------
        lower, upper : array_like, shape (3,)
            Its corners (m).

        Raises
        ------
        InputError
            A corner that is not 3 finite numbers, or ``lower`` not below ``upper`` on an axis.
        """
        lo, hi = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
        if lo.shape != (3,) or hi.shape != (3,) or not np.isfinite([lo, hi]).all():
            raise InputError(f"a box needs two corners of 3 finite numbers, got {lower!r} and "
                             f"{upper!r}")
        flat = [f"{'xyz'[i]} {lo[i] * 1e3:g}..{hi[i] * 1e3:g}" for i in range(3) if lo[i] >= hi[i]]
        if flat:
            raise InputError(f"the box's lower corner must be below its upper corner on every "
                             f"axis: {', '.join(flat)} mm")
        eye = np.eye(3)
        text = ", ".join(f"{'xyz'[i]} {lo[i] * 1e3:g}..{hi[i] * 1e3:g}" for i in range(3))
        return cls(np.vstack([eye, -eye]), np.concatenate([hi, -lo]),
                   f"inside the box {text} mm in the robot base frame")

    @classmethod
    def above(cls, T_R_X: ArrayLike, what: str) -> WorkVolume:
        """The half-space ``z >= 0`` of frame X: a floor.

        Parameters
        ----------
        T_R_X : array_like, shape (4, 4)
            Pose of the frame whose XY plane is the floor, in the robot base frame (m): the
            identity for the robot's own base plane, ``inv(T_world_R)`` for a cell's world.
        what : str
            The floor's name for messages (``the robot base plane``).
        """
        T = validate_single_pose(np.asarray(T_R_X, dtype=float), "floor frame")
        up = T[:3, 2]
        return cls(-up[None, :], np.array([-float(up @ T[:3, 3])]), f"above {what}")

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        """Whether points ``(..., 3)`` (m, robot base frame) are inside, shape ``(...)``."""
        p = np.asarray(points, dtype=float)
        return np.all(p @ self.normals.T <= self.offsets, axis=-1)


def measured_points(robot: Robot, q: ArrayLike, n_targets: int = 1, pose: bool = False
                    ) -> NDArray[np.float64]:
    """The flange and the reflectors of configurations, in the robot base frame.

    Parameters
    ----------
    robot : Robot
    q : array_like, shape (N, n)
        Configurations (rad, m).
    n_targets : int
        Reflectors per configuration, where the proposal assumes them
        (:func:`~robotcell.identification.validation.reflector_spots`).
    pose : bool
        The orientation is measured (a probe on the flange): the flange alone.

    Returns
    -------
    ndarray, shape (N, 1 + K, 3)
        The flange's origin, then the K reflectors (K = 0 with ``pose``) (m).
    """
    T = robot.fk(np.asarray(q, dtype=float), tool=np.eye(4))
    spots = reflector_spots(0 if pose else n_targets)
    reflectors = np.einsum("nij,kj->nki", T[:, :3, :3], spots) + T[:, None, :3, 3]
    return np.concatenate([T[:, None, :3, 3], reflectors], axis=1)


def configurations_within(robot: Robot, volume: WorkVolume, m: int, n_targets: int = 1,
                          pose: bool = False, seed: int = 0) -> NDArray[np.float64]:
    """``m`` random configurations within the joint limits that keep the flange and the
    reflectors inside a work volume.

    Parameters
    ----------
    robot : Robot
    volume : WorkVolume
    m : int
        How many.
    n_targets, pose
        As in :func:`measured_points`.
    seed : int
        Seed of ``np.random.default_rng``.

    Returns
    -------
    ndarray, shape (m, n)
        Uniform within the limits (unlimited axes: +-180 deg, +-1 m), kept when inside (rad, m).

    Raises
    ------
    InputError
        Fewer than ``m`` of 100,000 random configurations are inside: the volume is too small
        for the arm, or not where it reaches (the message says how many were).
    """
    rng = np.random.default_rng(seed)
    kept: list[NDArray[np.float64]] = []
    count = 0
    for _ in range(_ROUNDS):
        q = random_configurations(robot, rng, _BATCH)
        q = q[volume.contains(measured_points(robot, q, n_targets, pose)).all(axis=-1)]
        kept.append(q)
        count += len(q)
        if count >= m:
            return np.concatenate(kept)[:m]
    raise InputError(f"{count} of {_BATCH * _ROUNDS} random configurations within the joint "
                     f"limits keep the flange and the reflectors {volume.description}, fewer "
                     f"than the {m} to choose from: give a larger box, or one where "
                     f"{robot.name} reaches")
