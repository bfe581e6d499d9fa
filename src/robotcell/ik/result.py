"""Result types of inverse kinematics: all analytic branches, or one numeric solution."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.kinematics.transforms import finite_array

__all__ = ["EXACT_TOL", "REACH_TOL", "IKSolutions", "NumericIKResult", "flat_reference"]

#: A pose outside a branch's reach by at most this distance (m) is solved at the boundary of the
#: reach, as controllers do with rounded poses; the distance is reported in
#: :attr:`IKSolutions.reach_error`.
REACH_TOL = 1e-6
#: A branch whose reach error is at most this (m) solves the pose exactly (up to rounding).
EXACT_TOL = 1e-9


@dataclass(frozen=True)
class IKSolutions:
    """Every analytic solution of a batch of poses, as a fixed-shape batch.

    Attributes
    ----------
    q : ndarray, shape (..., 8, n)
        Controller axis values (rad, m) of the 8 branches (4 for a palletizer, ``method``
        ``"palletizer"``, branch ``k = 2 * shoulder + elbow``); NaN where the branch does not
        reach the pose.
        Revolute values are the 2*pi-equivalents chosen by :class:`robotcell.ik.limits.JointFolder`.
    valid : ndarray of bool, shape (..., 8)
        Branch reaches the pose and its joint values are within the joint limits.
    reachable : ndarray of bool, shape (..., 8)
        Branch reaches the pose (limits not considered); ``valid`` implies ``reachable``.
    method : str
        ``"opw"`` (ortho-parallel arm with a spherical wrist), ``"ur"`` (three parallel axes) or
        ``"palletizer"`` (4 axes, level flange).
        Branch ``k`` has ``k = 4 * shoulder + 2 * elbow + wrist`` (see docs/ik.md).
    reach_error : ndarray, shape (..., 8), optional
        Distance (m) by which the target's wrist point lies outside the branch's reach; 0 when it
        is inside up to rounding. A branch with ``reach_error <= REACH_TOL`` (1 um) is solved at
        the boundary of the reach, and its TCP position differs from the target by
        ``reach_error`` (the orientation is exact). ``reachable`` is
        ``reach_error <= REACH_TOL``; such a branch is ``valid`` only when it is exact
        (``reach_error <= EXACT_TOL``, 1 nm) or when no valid branch of the pose is (the pose
        is out of the robot's reach by rounding). A palletizer's solver gives no
        distance: 0 where a branch reaches, ``inf`` where it does not.
    """

    q: NDArray[np.float64]
    valid: NDArray[np.bool_]
    reachable: NDArray[np.bool_]
    method: str
    reach_error: NDArray[np.float64] | None = None

    @property
    def count(self) -> NDArray[np.int_]:
        """Number of valid branches per pose, shape ``(...)``."""
        return np.count_nonzero(self.valid, axis=-1)


@dataclass(frozen=True)
class NumericIKResult:
    """Outcome of numeric inverse kinematics for a batch of poses.

    Attributes
    ----------
    q : ndarray, shape (..., n)
        Best joint values found (rad, m), within the joint limits.
    success : ndarray of bool, shape (...)
        True only where both errors are within the tolerances that were asked for.
    position_error : ndarray, shape (...)
        Distance between the reached and the target TCP position (m).
    orientation_error : ndarray, shape (...)
        Angle of the rotation between the reached and the target orientation (rad).
    iterations : ndarray of int, shape (...)
        Iterations spent, summed over restarts.
    restarts : ndarray of int, shape (...)
        Restarts from random configurations that were needed.
    """

    q: NDArray[np.float64]
    success: NDArray[np.bool_]
    position_error: NDArray[np.float64]
    orientation_error: NDArray[np.float64]
    iterations: NDArray[np.int_]
    restarts: NDArray[np.int_]


def flat_reference(q_ref: ArrayLike | None, n: int, batch: tuple[int, ...]
                   ) -> NDArray[np.float64] | None:
    """The reference configuration of every pose of a batch, one row per pose.

    Parameters
    ----------
    q_ref : array_like, shape (n,) or (..., n), or None
        Reference configuration(s) (rad, m), broadcastable to the poses.
    n : int
        Number of axes.
    batch : tuple of int
        Batch shape of the poses.

    Returns
    -------
    ndarray, shape (prod(batch), n), or None
        None when ``q_ref`` is None.

    Raises
    ------
    InputError
        Non-finite values, or a shape that does not fit ``n`` axes or the poses.
    """
    if q_ref is None:
        return None
    ref = finite_array(q_ref, "q_ref")
    if ref.ndim == 0 or ref.shape[-1] != n:
        raise InputError(f"q_ref must have shape (..., {n}), got {ref.shape}")
    try:
        return np.broadcast_to(ref, batch + (n,)).reshape(-1, n)
    except ValueError:
        raise InputError(f"q_ref of shape {ref.shape} does not match the {batch} poses") from None
