"""Rigid transforms: batched construction, composition, inversion and validation.

A pose ``T_a_b`` has shape ``(..., 4, 4)``; it is the pose of frame b in frame a and maps points
from b to a (see ``docs/conventions.md``). Lengths are in metres, angles in radians.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.kinematics.jit import Kernel

__all__ = [
    "as_points",
    "check_pose",
    "compose",
    "finite_array",
    "invert",
    "make_pose",
    "pose_defects",
    "rot_x",
    "rot_y",
    "rot_z",
    "transform_points",
    "validate_pose",
    "validate_single_pose",
]

#: Default tolerance of :func:`check_pose` on orthonormality and the last row.
POSE_TOL = 1e-6


def finite_array(x: ArrayLike, name: str) -> NDArray[np.float64]:
    """``x`` as a float array, or an :class:`InputError` naming ``name`` if it is not numeric
    or holds NaN or infinite values."""
    if isinstance(x, (float, int)) and not isinstance(x, bool):  # one number: no numpy reduction
        if not math.isfinite(x):
            raise InputError(f"{name} contains NaN or infinite values")
        return np.array(x, dtype=float)
    try:
        arr = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be numeric: {exc}") from None
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{name} contains NaN or infinite values")
    return arr


def as_points(p: ArrayLike, name: str = "points") -> NDArray[np.float64]:
    """Validate points of shape ``(..., 3)``.

    Parameters
    ----------
    p : array_like, shape (..., 3)
        Points (metres).
    name : str
        Name used in error messages.

    Returns
    -------
    ndarray, shape (..., 3)
    """
    arr = finite_array(p, name)
    if arr.ndim < 1 or arr.shape[-1] != 3:
        raise InputError(f"{name} must have shape (..., 3), got {arr.shape}")
    return arr


def check_pose(T: ArrayLike, tol: float = POSE_TOL) -> tuple[NDArray[np.bool_], list[str]]:
    """Check that matrices are proper rigid transforms.

    Parameters
    ----------
    T : array_like, shape (..., 4, 4)
        Candidate poses (translation in metres).
    tol : float
        Tolerance on ``R^T R = I``, ``det R = 1`` and the last row ``0 0 0 1``.

    Returns
    -------
    ok : ndarray of bool, shape (...)
        True where the matrix is a valid pose.
    reasons : list of str
        One reason per failing pose, in C order of the batch, prefixed by its index.
    """
    arr = np.asarray(T, dtype=float)
    if arr.ndim < 2 or arr.shape[-2:] != (4, 4):
        raise InputError(f"a pose must have shape (..., 4, 4), got {arr.shape}")
    finite = np.all(np.isfinite(arr), axis=(-2, -1))
    with np.errstate(invalid="ignore", over="ignore"):  # NaN where not finite
        ortho, det, last = (np.asarray(v) for v in pose_defects(np.moveaxis(arr, (-2, -1), (0, 1))))
    ok = finite & (ortho <= tol) & (np.abs(det - 1.0) <= tol) & (last <= tol)
    reasons = []
    for row in np.argwhere(~ok):
        idx = tuple(int(i) for i in row)
        where = f"pose {list(idx)}: " if idx else ""
        if not finite[idx]:
            why = "contains NaN or infinite values"
        elif last[idx] > tol:
            why = f"last row is {arr[idx][3].tolist()}, expected [0, 0, 0, 1]"
        elif ortho[idx] > tol:
            why = f"rotation part is not orthonormal (max |R^T R - I| = {ortho[idx]:.3g})"
        else:
            why = f"rotation part has determinant {det[idx]:.6g}, not +1 (a reflection)"
        reasons.append(where + why)
    return ok, reasons


def pose_defects(T):
    """How far matrices are from rigid transforms: the formula of :func:`check_pose`.

    Written once for a batch (numpy) and one pose (compiled, :data:`POSE_DEFECTS`).

    Parameters
    ----------
    T : ndarray, shape (4, 4) or (4, 4, N)
        Candidate poses, a batch on the last axis (translation in metres).

    Returns
    -------
    ortho : float or ndarray, shape (N,)
        Largest ``|R^T R - I|`` of the rotation part.
    det : float or ndarray, shape (N,)
        ``det R``.
    last : float or ndarray, shape (N,)
        Largest ``|T[3] - (0, 0, 0, 1)|``; NaN, as the others, where ``T`` holds NaN or an
        infinite value (the translation included), so that such a matrix passes no tolerance.
    """
    r00, r01, r02 = T[0, 0], T[0, 1], T[0, 2]
    r10, r11, r12 = T[1, 0], T[1, 1], T[1, 2]
    r20, r21, r22 = T[2, 0], T[2, 1], T[2, 2]
    ortho = np.abs(r00 * r00 + r10 * r10 + r20 * r20 - 1.0)
    ortho = np.maximum(ortho, np.abs(r01 * r01 + r11 * r11 + r21 * r21 - 1.0))
    ortho = np.maximum(ortho, np.abs(r02 * r02 + r12 * r12 + r22 * r22 - 1.0))
    ortho = np.maximum(ortho, np.abs(r00 * r01 + r10 * r11 + r20 * r21))
    ortho = np.maximum(ortho, np.abs(r00 * r02 + r10 * r12 + r20 * r22))
    ortho = np.maximum(ortho, np.abs(r01 * r02 + r11 * r12 + r21 * r22))
    det = (r00 * (r11 * r22 - r12 * r21) - r01 * (r10 * r22 - r12 * r20)
           + r02 * (r10 * r21 - r11 * r20))
    last = np.maximum(np.maximum(np.abs(T[3, 0]), np.abs(T[3, 1])),
                      np.maximum(np.abs(T[3, 2]), np.abs(T[3, 3] - 1.0)))
    # x - x is 0 for a finite x and NaN for NaN or infinity
    last = last + ((T[0, 3] - T[0, 3]) + (T[1, 3] - T[1, 3]) + (T[2, 3] - T[2, 3]))
    return ortho, det, last


#: :func:`pose_defects` of one pose (Python first, compiled once single-pose calls add up).
POSE_DEFECTS = Kernel(pose_defects)


def validate_single_pose(T: ArrayLike, name: str = "pose") -> NDArray[np.float64]:
    """:func:`validate_pose` of one pose, shape ``(4, 4)``, cheaply: the per-call path.

    Returns ``T`` as a C-contiguous float array of shape (4, 4) when it is a rigid transform
    within :data:`POSE_TOL`; otherwise raises what :func:`validate_pose` raises (also for another
    shape, or a batch of one pose).
    """
    arr = np.ascontiguousarray(T, dtype=float)
    if arr.shape == (4, 4):
        ortho, det, last = POSE_DEFECTS.call(arr)
        if ortho <= POSE_TOL and abs(det - 1.0) <= POSE_TOL and last <= POSE_TOL:
            return arr
    validate_pose(arr, name)
    raise InputError(f"{name} must be a single pose of shape (4, 4), got {arr.shape}")


def validate_pose(T: ArrayLike, name: str = "pose", tol: float = POSE_TOL) -> NDArray[np.float64]:
    """Return ``T`` as a float array, or raise :class:`InputError` naming the first defect.

    Parameters
    ----------
    T : array_like, shape (..., 4, 4)
        Poses (translation in metres).
    name : str
        Name used in the error message.
    tol : float
        Tolerance, see :func:`check_pose`.

    Returns
    -------
    ndarray, shape (..., 4, 4)
    """
    arr = np.asarray(T, dtype=float)
    if arr.ndim < 2 or arr.shape[-2:] != (4, 4):
        raise InputError(f"{name} must have shape (..., 4, 4), got {arr.shape}")
    ok, reasons = check_pose(arr, tol)
    if not np.all(ok):
        more = f" (and {len(reasons) - 1} more)" if len(reasons) > 1 else ""
        raise InputError(f"{name} is not a valid rigid transform: {reasons[0]}{more}")
    return arr


def make_pose(R: ArrayLike | None = None, p: ArrayLike | None = None) -> NDArray[np.float64]:
    """Build poses from rotations and translations.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3), optional
        Rotation matrices; identity when omitted.
    p : array_like, shape (..., 3), optional
        Translations (metres); zero when omitted.

    Returns
    -------
    ndarray, shape (..., 4, 4)
        Batch shape is the broadcast of the batch shapes of ``R`` and ``p``.
    """
    R_arr = np.eye(3) if R is None else np.asarray(R, dtype=float)
    p_arr = np.zeros(3) if p is None else np.asarray(p, dtype=float)
    if R_arr.shape[-2:] != (3, 3):
        raise InputError(f"R must have shape (..., 3, 3), got {R_arr.shape}")
    if p_arr.ndim < 1 or p_arr.shape[-1] != 3:
        raise InputError(f"p must have shape (..., 3), got {p_arr.shape}")
    batch = np.broadcast_shapes(R_arr.shape[:-2], p_arr.shape[:-1])
    T = np.zeros(batch + (4, 4))
    T[..., :3, :3] = R_arr
    T[..., :3, 3] = p_arr
    T[..., 3, 3] = 1.0
    return T


def _rot(axis: int, angle: ArrayLike) -> NDArray[np.float64]:
    a = np.asarray(angle, dtype=float)
    c, s = np.cos(a), np.sin(a)
    R = np.zeros(a.shape + (3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    R[..., axis, axis] = 1.0
    R[..., i, i] = c
    R[..., j, j] = c
    R[..., i, j] = -s
    R[..., j, i] = s
    return R


def rot_x(angle: ArrayLike) -> NDArray[np.float64]:
    """Active rotation about +X by ``angle`` (radians, shape ``(...)``); returns ``(..., 3, 3)``."""
    return _rot(0, angle)


def rot_y(angle: ArrayLike) -> NDArray[np.float64]:
    """Active rotation about +Y by ``angle`` (radians, shape ``(...)``); returns ``(..., 3, 3)``."""
    return _rot(1, angle)


def rot_z(angle: ArrayLike) -> NDArray[np.float64]:
    """Active rotation about +Z by ``angle`` (radians, shape ``(...)``); returns ``(..., 3, 3)``."""
    return _rot(2, angle)


def compose(*poses: ArrayLike) -> NDArray[np.float64]:
    """Chain poses left to right: ``compose(T_a_b, T_b_c) == T_a_c``.

    Parameters
    ----------
    *poses : array_like, each shape (..., 4, 4)
        Poses whose batch shapes broadcast together.

    Returns
    -------
    ndarray, shape (..., 4, 4)
    """
    if not poses:
        raise InputError("compose needs at least one pose")
    out = np.asarray(poses[0], dtype=float)
    for T in poses[1:]:
        out = out @ np.asarray(T, dtype=float)
    return out


def invert(T: ArrayLike) -> NDArray[np.float64]:
    """Invert rigid transforms using ``R^T`` (exact for proper rotations).

    Parameters
    ----------
    T : array_like, shape (..., 4, 4)
        ``T_a_b``.

    Returns
    -------
    ndarray, shape (..., 4, 4)
        ``T_b_a``.
    """
    arr = np.asarray(T, dtype=float)
    if arr.ndim < 2 or arr.shape[-2:] != (4, 4):
        raise InputError(f"a pose must have shape (..., 4, 4), got {arr.shape}")
    Rt = np.swapaxes(arr[..., :3, :3], -1, -2)
    out = np.zeros_like(arr)
    out[..., :3, :3] = Rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", Rt, arr[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def transform_points(T_a_b: ArrayLike, p_b: ArrayLike) -> NDArray[np.float64]:
    """Map points from frame b to frame a.

    Parameters
    ----------
    T_a_b : array_like, shape (..., 4, 4)
        Pose of b in a.
    p_b : array_like, shape (..., 3)
        Points in b (metres); batch shape broadcasts with that of ``T_a_b``.

    Returns
    -------
    ndarray, shape (..., 3)
        Points in a (metres).
    """
    T = np.asarray(T_a_b, dtype=float)
    p = np.asarray(p_b, dtype=float)
    return np.einsum("...ij,...j->...i", T[..., :3, :3], p) + T[..., :3, 3]
