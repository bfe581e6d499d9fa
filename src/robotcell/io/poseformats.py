"""Vendor pose formats, both ways, through :class:`scipy.spatial.transform.Rotation`.

Robot controllers write a pose as a position in millimetres and an orientation as three Euler
angles in degrees (KUKA, Fanuc, Yaskawa, Staubli), a scalar-first quaternion (ABB) or, in SI
units, a rotation vector (Universal Robots). The table of conventions with their sources is in
``docs/conventions.md``. Inside robotcell a pose is a 4x4 matrix in metres.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robotcell.errors import InputError
from robotcell.kinematics.transforms import validate_pose

__all__ = ["FORMATS", "PoseFormat", "pose_from_vendor", "pose_to_vendor"]

#: Largest deviation of a quaternion's norm from 1 that is renormalised rather than refused.
QUAT_NORM_TOL = 1e-4


@dataclass(frozen=True)
class PoseFormat:
    """How one vendor writes a pose.

    Attributes
    ----------
    name : str
        Format name used by the API and the CLI (``kuka``, ``abb``, ...).
    fields : tuple of str
        Names of the values in the order the vendor writes them.
    units : str
        Units of the values, for humans.
    euler : str or None
        scipy Euler sequence whose angles are the vendor's angles in the order of ``angle_order``,
        or None for quaternion / rotation-vector formats.
    angle_order : tuple of int
        Index into the vendor's three angles giving the order scipy's ``euler`` sequence expects.
    length_scale : float
        Metres per vendor length unit.
    rotation : {"euler", "quaternion", "rotvec"}
        How the orientation is written: three Euler angles in degrees (``euler``), a unit
        quaternion scalar first, or a rotation vector in radians.
    """

    name: str
    fields: tuple[str, ...]
    units: str
    euler: str | None = None
    angle_order: tuple[int, int, int] = (0, 1, 2)
    length_scale: float = 1e-3
    rotation: str = "euler"

    @property
    def size(self) -> int:
        """Number of values in one pose."""
        return len(self.fields)


FORMATS: dict[str, PoseFormat] = {
    f.name: f
    for f in (
        # R = Rz(A) Ry(B) Rx(C): intrinsic Z-Y'-X'' with angles (A, B, C).
        PoseFormat("kuka", ("X", "Y", "Z", "A", "B", "C"), "mm, deg", "ZYX"),
        # R = Rz(R) Ry(P) Rx(W): intrinsic Z-Y'-X'' with angles (R, P, W).
        PoseFormat("fanuc", ("X", "Y", "Z", "W", "P", "R"), "mm, deg", "ZYX", (2, 1, 0)),
        PoseFormat("yaskawa", ("X", "Y", "Z", "Rx", "Ry", "Rz"), "mm, deg", "ZYX", (2, 1, 0)),
        # R = Rx(Rx) Ry(Ry) Rz(Rz): intrinsic X-Y'-Z''.
        PoseFormat("staubli", ("X", "Y", "Z", "Rx", "Ry", "Rz"), "mm, deg", "XYZ"),
        PoseFormat("abb", ("x", "y", "z", "q1", "q2", "q3", "q4"), "mm, unit quaternion",
                   rotation="quaternion"),
        PoseFormat("ur", ("x", "y", "z", "rx", "ry", "rz"), "m, rad (rotation vector)",
                   length_scale=1.0, rotation="rotvec"),
    )
}


def _format(fmt: str | PoseFormat) -> PoseFormat:
    if isinstance(fmt, PoseFormat):
        return fmt
    try:
        return FORMATS[fmt.lower()]
    except KeyError:
        raise InputError(
            f"unknown pose format {fmt!r}; choose one of: {', '.join(FORMATS)}"
        ) from None


#: Below this cosine of the middle angle scipy's Euler angles are replaced (see :func:`_euler`).
NEAR_LOCK = 1e-6


def _euler(rot: Rotation, R: NDArray[np.float64], seq: str) -> NDArray[np.float64]:
    """Intrinsic Tait-Bryan angles ``(a, b, c)`` (rad) of ``seq`` that reproduce ``R`` to rounding.

    Within about 1e-7 rad of gimbal lock scipy sets the third angle to 0 and gives the first the
    whole rotation about the locked axis, which misses the rotation by up to that distance. There
    (``cos b < NEAR_LOCK``) the third angle is taken from the first axis's row of ``R``,
    ``R[i, i] = cos b cos c``, ``R[i, j] = +-cos b sin c`` (absolute rounding 1e-16, so ``c``
    is determined to 1e-16 / cos b), and the first angle from the rest of the rotation,
    ``R_i(a) = R R_k(-c) R_j(-b)``, so that the three angles reproduce ``R`` to rounding. At exact
    lock (both entries below 1e-15) the third angle stays scipy's 0.

    Parameters
    ----------
    rot : Rotation
        The rotations, ``N`` of them.
    R : ndarray, shape (N, 3, 3)
        The same rotations as matrices.
    seq : str
        Intrinsic scipy sequence of three distinct axes (``"ZYX"``, ``"XYZ"``).

    Returns
    -------
    ndarray, shape (N, 3)
    """
    with warnings.catch_warnings():
        # At gimbal lock scipy warns that the third angle is set to zero; handled below.
        warnings.simplefilter("ignore", UserWarning)
        e = rot.as_euler(seq)
    near = np.flatnonzero(np.cos(e[:, 1]) < NEAR_LOCK)
    if near.size == 0:
        return e
    i, j = ("XYZ".index(seq[0]), "XYZ".index(seq[1]))
    # Sign of R[i, j] relative to cos b sin c for this sequence (right- or left-handed order).
    sign = -1.0 if (j - i) % 3 == 1 else 1.0
    Rn = R[near]
    ci, cj = Rn[:, i, i], sign * Rn[:, i, j]
    locked = np.hypot(ci, cj) < 1e-15
    c = np.where(locked, e[near, 2], np.arctan2(cj, ci))
    rest = Rotation.from_matrix(Rn) * Rotation.from_euler(seq[1:], np.column_stack([e[near, 1], c])).inv()
    e[near, 0] = rest.as_euler(seq)[:, 0]  # a rotation about axis i: its middle angle is ~0
    e[near, 2] = c
    return e


def pose_from_vendor(values: ArrayLike, fmt: str | PoseFormat) -> NDArray[np.float64]:
    """Convert poses written in a vendor format to 4x4 matrices.

    Parameters
    ----------
    values : array_like, shape (..., k)
        Poses as the vendor writes them: ``k = 6`` (``k = 7`` for ``abb``), in the vendor's units
        (millimetres and degrees; metres and radians for ``ur``).
    fmt : str or PoseFormat
        One of ``kuka``, ``fanuc``, ``yaskawa``, ``staubli``, ``abb``, ``ur``, or a
        :class:`PoseFormat` of its own.

    Returns
    -------
    ndarray, shape (..., 4, 4)
        Poses with translation in metres.

    Examples
    --------
    >>> T = pose_from_vendor([100, 0, 50, 30, 20, 10], "kuka")
    >>> pose_to_vendor(T, "fanuc").round(6).tolist()
    [100.0, 0.0, 50.0, 10.0, 20.0, 30.0]
    """
    f = _format(fmt)
    v = np.asarray(values, dtype=float)
    if v.ndim < 1 or v.shape[-1] != f.size:
        raise InputError(
            f"a {f.name} pose has {f.size} values ({', '.join(f.fields)}), got shape {v.shape}"
        )
    if not np.all(np.isfinite(v)):
        raise InputError(f"{f.name} pose contains NaN or infinite values")
    batch = v.shape[:-1]
    flat = v.reshape(-1, f.size)
    if f.rotation == "quaternion":
        q = flat[:, 3:]
        norm = np.linalg.norm(q, axis=1)
        bad = np.abs(norm - 1.0) > QUAT_NORM_TOL
        if np.any(bad):
            raise InputError(
                f"{f.name.upper()} quaternion {f.fields[3]}..{f.fields[-1]} must be normalised "
                f"(|q| = 1); got |q| = {norm[bad][0]:.6g}"
            )
        rot = Rotation.from_quat(q, scalar_first=True)
    elif f.rotation == "rotvec":
        rot = Rotation.from_rotvec(flat[:, 3:])
    else:
        rot = Rotation.from_euler(f.euler, flat[:, 3:][:, list(f.angle_order)], degrees=True)
    T = np.zeros((flat.shape[0], 4, 4))
    T[:, :3, :3] = rot.as_matrix()
    T[:, :3, 3] = flat[:, :3] * f.length_scale
    T[:, 3, 3] = 1.0
    return T.reshape(batch + (4, 4))


def pose_to_vendor(T: ArrayLike, fmt: str | PoseFormat) -> NDArray[np.float64]:
    """Convert 4x4 poses to a vendor format.

    Parameters
    ----------
    T : array_like, shape (..., 4, 4)
        Poses with translation in metres; must be proper rigid transforms.
    fmt : str or PoseFormat
        As for :func:`pose_from_vendor`.

    Returns
    -------
    ndarray, shape (..., k)
        ``k = 6`` (``7`` for ``abb``) values in the vendor's units. Euler formats return the middle
        angle in ``[-90, 90]`` degrees; ABB quaternions have ``q1 >= 0``.
    """
    f = _format(fmt)
    arr = validate_pose(T)
    batch = arr.shape[:-2]
    flat = arr.reshape(-1, 4, 4)
    rot = Rotation.from_matrix(flat[:, :3, :3])
    if f.rotation == "quaternion":
        q = rot.as_quat(scalar_first=True, canonical=True)
        ang = q / np.linalg.norm(q, axis=1, keepdims=True)
    elif f.rotation == "rotvec":
        ang = rot.as_rotvec()
    else:
        e = np.degrees(_euler(rot, flat[:, :3, :3], f.euler))
        ang = np.empty_like(e)
        ang[:, list(f.angle_order)] = e
    out = np.concatenate([flat[:, :3, 3] / f.length_scale, ang], axis=1)
    # No "-0.0" in printed values; quaternion and rotation-vector parts only below 1e-15, so that
    # the orientation stays exact to 1e-12 rad.
    tiny = np.where(np.arange(f.size) < 3, 1e-12, 1e-15 if f.euler is None else 1e-12)
    out[np.abs(out) < tiny] = 0.0
    return out.reshape(batch + (f.size,))
