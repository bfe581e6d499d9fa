"""The geometry of a serial chain: its joint axes as lines at the zero position.

This is the input of the Denavit-Hartenberg procedure and its independent reference. Joint ``i``
moves about (revolute) or along (prismatic) a line through ``points[i]`` with unit direction
``directions[i]``, both in the robot base frame R at ``q = 0``. The forward kinematics of the
chain is the product of the screw motions about these lines::

    T_R_F(q) = M_1(q_1) M_2(q_2) ... M_n(q_n) T_R_F(0)

with ``M_i(q_i)`` the rotation by ``q_i`` about line ``i`` (right-handed about its direction) or the
translation by ``q_i`` along it. Each ``M_i`` is expressed in R at the zero pose, so no DH frame is
involved: the formula checks a DH model without sharing any of its choices.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robotcell.errors import InputError
from robotcell.kinematics.transforms import validate_pose
from robotcell.robot.robot import Robot

__all__ = ["AxisChain"]

#: Directions shorter than this (before normalisation) are refused as zero.
_MIN_DIRECTION = 1e-12


@dataclass(frozen=True, eq=False)
class AxisChain:
    """Joint axes of a serial chain at its zero position, in the robot base frame R.

    Attributes
    ----------
    points : ndarray, shape (n, 3)
        A point on each joint axis (metres). For a prismatic joint any point gives the same
        motion; the DH procedure places that joint's frame on the line through it.
    directions : ndarray, shape (n, 3)
        Direction of each axis; normalised on construction. The positive joint value turns
        right-handed about it (revolute) or moves along it (prismatic).
    types : tuple of {"revolute", "prismatic"}, length n
    flange : ndarray, shape (4, 4)
        ``T_R_F`` at ``q = 0``: pose of the flange in R (metres).
    names : tuple of str, length n
        Joint names used in messages and copied to the DH model (default ``J1..Jn``).
    lower, upper : ndarray, shape (n,)
        Joint limits (rad or m), infinite when unknown.
    """

    points: NDArray[np.float64]
    directions: NDArray[np.float64]
    types: tuple[str, ...]
    flange: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    names: tuple[str, ...] = ()
    lower: NDArray[np.float64] | None = None
    upper: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        types = tuple(self.types)
        n = len(types)
        if n == 0:
            raise InputError("a chain needs at least one joint axis")
        names = tuple(self.names) if self.names else tuple(f"J{i}" for i in range(1, n + 1))
        if len(names) != n:
            raise InputError(f"{n} joint types but {len(names)} joint names")
        for name, t in zip(names, types):
            if t not in ("revolute", "prismatic"):
                raise InputError(f"joint {name}: type must be 'revolute' or 'prismatic', got {t!r}")
        pts = _array(self.points, (n, 3), "points")
        dirs = _array(self.directions, (n, 3), "directions")
        norms = np.linalg.norm(dirs, axis=1)
        for name, length in zip(names, norms):
            if length < _MIN_DIRECTION:
                raise InputError(
                    f"joint {name}: axis direction has zero length; give the direction the joint "
                    "moves about or along, e.g. (0, 0, 1)"
                )
        lower = np.full(n, -np.inf) if self.lower is None else _array(self.lower, (n,), "lower",
                                                                        finite=False)
        upper = np.full(n, np.inf) if self.upper is None else _array(self.upper, (n,), "upper",
                                                                       finite=False)
        object.__setattr__(self, "types", types)
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "points", pts)
        object.__setattr__(self, "directions", dirs / norms[:, None])
        object.__setattr__(self, "flange", validate_pose(self.flange, "flange").copy())
        object.__setattr__(self, "lower", lower)
        object.__setattr__(self, "upper", upper)

    @property
    def n_joints(self) -> int:
        """Number of joints ``n``."""
        return len(self.types)

    @classmethod
    def from_robot(cls, robot: Robot) -> AxisChain:
        """The joint axes of a DH model at its zero position.

        Joint ``i`` of a standard-DH model moves about ``Z_{i-1}``, of a modified-DH model about
        ``Z_i``; the direction is that Z axis times the joint's sign, so that a positive
        controller value turns right-handed about it. The tool is not part of the chain.

        Parameters
        ----------
        robot : Robot

        Returns
        -------
        AxisChain
            Axes in the robot base frame R (metres); flange ``T_R_F`` at ``q = 0``. For a robot
            with a joint coupling these are the axes of its chain (:meth:`Robot.uncoupled`,
            model joint values, passive joints included, no limits).
        """
        robot = robot.uncoupled()
        F = robot.frames(np.zeros(robot.n_joints))
        axes = F[:-1] if robot.convention == "standard" else F[1:]
        sign = np.array([j.sign for j in robot.joints])
        return cls(
            points=axes[:, :3, 3], directions=axes[:, :3, 2] * sign[:, None],
            types=tuple(j.type for j in robot.joints), flange=F[-1] @ robot.flange,
            names=tuple(j.name or f"J{i}" for i, j in enumerate(robot.joints, start=1)),
            lower=robot.lower, upper=robot.upper,
        )

    def motions(self, q: ArrayLike) -> NDArray[np.float64]:
        """The screw motion of every joint, in R at the zero pose.

        Parameters
        ----------
        q : array_like, shape (..., n)
            Joint values (rad for revolute, m for prismatic joints).

        Returns
        -------
        ndarray, shape (..., n, 4, 4)
            ``M_i(q_i)``: rotation by ``q_i`` about line ``i`` or translation by ``q_i`` along it.
        """
        arr = _joint_values(q, self.n_joints)
        flat = arr.reshape(-1, self.n_joints)
        rotvec = flat[..., None] * self.directions  # (N, n, 3)
        R = Rotation.from_rotvec(rotvec.reshape(-1, 3)).as_matrix().reshape(flat.shape + (3, 3))
        pris = np.array([t == "prismatic" for t in self.types])
        R[:, pris] = np.eye(3)
        p = self.points - np.einsum("Nnij,nj->Nni", R, self.points)
        p[:, pris] = flat[:, pris, None] * self.directions[pris]
        M = np.zeros(flat.shape + (4, 4))
        M[..., :3, :3] = R
        M[..., :3, 3] = p
        M[..., 3, 3] = 1.0
        return M.reshape(arr.shape + (4, 4))

    def fk(self, q: ArrayLike) -> NDArray[np.float64]:
        """Reference forward kinematics: ``M_1(q_1) ... M_n(q_n) T_R_F(0)``.

        Parameters
        ----------
        q : array_like, shape (..., n)
            Joint values (rad for revolute, m for prismatic joints).

        Returns
        -------
        ndarray, shape (..., 4, 4)
            Pose of the flange in R (metres).
        """
        M = self.motions(q)
        T = M[..., 0, :, :]
        for i in range(1, self.n_joints):
            T = T @ M[..., i, :, :]
        return T @ self.flange


def _array(x: ArrayLike, shape: tuple[int, ...], name: str, finite: bool = True) -> NDArray:
    try:
        arr = np.array(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be numeric: {exc}") from None
    if arr.shape != shape:
        raise InputError(f"{name} must have shape {shape}, got {arr.shape}")
    if finite and not np.all(np.isfinite(arr)):
        raise InputError(f"{name} contains NaN or infinite values")
    if np.any(np.isnan(arr)):
        raise InputError(f"{name} contains NaN")
    return arr


def _joint_values(q: ArrayLike, n: int) -> NDArray[np.float64]:
    try:
        arr = np.asarray(q, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"q must be numeric: {exc}") from None
    if arr.ndim == 0 or arr.shape[-1] != n:
        raise InputError(f"the chain has {n} joints; q must have shape (..., {n}), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InputError("q contains NaN or infinite values")
    return arr

