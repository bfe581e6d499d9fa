"""The Denavit-Hartenberg procedure: DH frames and table from the joint axes of a chain.

The procedure of the lecture, done by the computer. Write ``L_0 .. L_{n-1}`` for the axes of joints
``1..n`` at ``q = 0`` and ``L_n`` for the flange's approach axis (its Z axis). Between each pair of
consecutive lines ``L_k, L_{k+1}`` the procedure needs their common normal: a segment from ``A_k`` on
``L_k`` to ``B_k`` on ``L_{k+1}``, perpendicular to both, with unit direction ``x_k``. One of four
cases applies:

* **skew**: the common normal is unique; ``x_k`` points from ``L_k`` to ``L_{k+1}``, so ``a > 0``.
* **intersecting**: ``A_k = B_k`` is the intersection, ``x_k = ±z_k × z_{k+1}``; the sign makes
  ``x_k`` point toward the flange origin (the lecture's "toward the end effector"); when the flange
  origin lies in the plane of both axes, the sign that keeps ``x_k`` closest to ``x_{k-1}``
  (smallest theta offset), else ``x_k = z_k × z_{k+1}``. For the last pair, the flange's
  own X axis is used when it is one of the two candidates (frame n is then the flange frame).
* **parallel**: every normal is a common normal; the one through ``B_{k-1}`` (the point where the
  previous normal met ``L_k``) is chosen, which makes ``d = 0``. ``x_k`` points from ``L_k`` to
  ``L_{k+1}``.
* **coincident**: ``A_k = B_k = B_{k-1}`` and ``x_k = x_{k-1}`` (``d = 0``, no theta offset). For
  the first pair, ``x_0`` is the direction toward the flange origin, perpendicular to the axis. For
  the last pair (the flange sits on the last axis), ``A = B`` is the flange origin and ``x`` is the
  flange's X axis, so frame n is the flange frame.

**Standard DH** puts frame ``i`` (``i = 1..n``) at ``B_{i-1}`` with ``Z_i`` along ``L_i`` and
``X_i = x_{i-1}``. **Modified DH** puts frame ``i`` at ``A_{i-1}`` with ``Z_i`` along ``L_{i-1}`` and
``X_i = x_{i-1}``. In both, frame 0 has ``Z_0`` along ``L_0``, its origin at the point of ``L_0``
nearest the origin of R, and ``X_0 = x_0`` (no theta offset on joint 1). Then
``theta_i = angle(x_{i-2} -> x_{i-1}) about z_{i-1}`` and ``d_i = (A_{i-1} - B_{i-2}) · z_{i-1}``
(the same in both conventions), ``a``, ``alpha`` are the length and twist of the common normal.
See ``docs/dh-procedure.md``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from robotcell.dhprocedure.axes import AxisChain
from robotcell.errors import InputError
from robotcell.kinematics.dh import Convention
from robotcell.kinematics.transforms import invert, make_pose
from robotcell.robot.robot import Joint, Robot

__all__ = ["DHDerivation", "FrameNote", "dh_from_axes"]

CASES = ("base", "skew", "intersecting", "parallel", "coincident")


@dataclass(frozen=True)
class FrameNote:
    """Why DH frame ``index`` is where it is.

    Attributes
    ----------
    index : int
        Frame number ``0..n``.
    case : {"base", "skew", "intersecting", "parallel", "coincident"}
        ``base`` for frame 0; otherwise how the two Z axes that define the frame relate.
    text : str
        The rule applied and why, in the lecture's words (lengths in mm, angles in degrees).
    """

    index: int
    case: str
    text: str


@dataclass(frozen=True, eq=False)
class DHDerivation:
    """Result of the DH procedure.

    Attributes
    ----------
    robot : Robot
        The DH model: its FK equals the chain's FK for every joint value.
    notes : tuple of FrameNote
        One note per frame ``0..n``.
    frames : ndarray, shape (n + 1, 4, 4)
        The DH frames ``T_R_i`` at ``q = 0`` (metres).
    """

    robot: Robot
    notes: tuple[FrameNote, ...]
    frames: NDArray[np.float64]


@dataclass(frozen=True)
class _Normal:
    """Common normal from ``A`` on ``L_k`` to ``B`` on ``L_{k+1}``, direction ``x``."""

    case: str
    A: NDArray[np.float64]
    B: NDArray[np.float64]
    x: NDArray[np.float64]
    why: str


def dh_from_axes(
    chain: AxisChain,
    convention: Convention = "standard",
    signs: Sequence[float] | None = None,
    tol: float = 1e-9,
    name: str = "derived",
    title: str = "",
    source: str = "",
) -> DHDerivation:
    """Apply the Denavit-Hartenberg procedure to the joint axes of a chain.

    Parameters
    ----------
    chain : AxisChain
        Joint axes at ``q = 0`` and the flange pose, in the robot base frame R (metres).
    convention : {"standard", "modified"}
        Standard (the lecture's, ``Z_{i-1}`` along joint ``i``) or modified (Craig) DH.
    signs : sequence of float, shape (n,), optional
        +1 (default) puts the Z axis of joint ``i`` along the chain's direction of that axis;
        -1 puts it the other way, and the joint gets ``sign = -1`` (a sign correction:
        ``theta_i = -q_i + offset``).
    tol : float
        Axes closer than ``tol`` (metres, and ``tol`` radians in direction) count as
        intersecting, parallel or coincident.
    name, title, source : str
        Copied to the returned model.

    Returns
    -------
    DHDerivation
        The model (base ``T_R_0``, DH joints, flange ``T_n_F``; tool identity), a note per frame,
        and the DH frames at ``q = 0``.

    Raises
    ------
    InputError
        Unknown convention, or signs that are not +-1.

    Notes
    -----
    Consecutive prismatic joints along parallel axes (a gantry with redundant axes) are legal:
    DH holds them as two ``d`` variables along the same Z direction.
    """
    if convention not in ("standard", "modified"):
        raise InputError(f"convention must be 'standard' or 'modified', got {convention!r}")
    n = chain.n_joints
    s = np.ones(n) if signs is None else np.asarray(signs, dtype=float)
    if s.shape != (n,) or not np.all(np.isin(s, (1.0, -1.0))):
        raise InputError(f"signs must be {n} values, each +1 or -1, got {signs!r}")
    flange = chain.flange
    points = np.vstack([chain.points, flange[:3, 3]])
    z = np.vstack([chain.directions * s[:, None], flange[:3, 2]])
    o0 = points[0] - np.dot(points[0], z[0]) * z[0]

    normals: list[_Normal] = []
    prev_b, prev_x = o0, None
    for k in range(n):
        nm = _common_normal(points[k], z[k], points[k + 1], z[k + 1], prev_b, prev_x,
                            flange[:3, 3], flange if k == n - 1 else None, tol)
        normals.append(nm)
        prev_b, prev_x = nm.B, nm.x

    joints = []
    for i in range(1, n + 1):
        k = i - 1
        x_prev = normals[k - 1].x if k else normals[0].x
        b_prev = normals[k - 1].B if k else o0
        theta0 = _angle(x_prev, normals[k].x, z[k])
        d0 = float(np.dot(normals[k].A - b_prev, z[k]))
        if convention == "standard":
            a, alpha = _length_twist(normals[k], z[k], z[k + 1])
        else:
            a, alpha = _length_twist(normals[k - 1], z[k - 1], z[k]) if k else (0.0, 0.0)
        joints.append(Joint(
            type=chain.types[k], a=a, alpha=alpha, d=d0, theta=theta0, sign=float(s[k]),
            lower=float(chain.lower[k]), upper=float(chain.upper[k]), name=chain.names[k],
        ))
    base = _frame(o0, z[0], normals[0].x)
    robot = Robot(name=name, joints=tuple(joints), convention=convention, base=base,
                  title=title or name, source=source)
    F = robot.frames(np.zeros(n))
    robot = Robot(name=name, joints=tuple(joints), convention=convention, base=base,
                  flange=invert(F[-1]) @ flange, title=title or name, source=source)
    notes = [FrameNote(0, "base", (
        f"Z_0 along the axis of joint 1 ({chain.names[0]}){_flip(s[0])}; O_0 is the point of that "
        "axis nearest the origin of R; X_0 = X_1 at q = 0, so theta_1 has no offset (the "
        "procedure leaves X_0 free)."))]
    for i in range(1, n + 1):
        nm = normals[i - 1]
        if convention == "standard":
            here = (f"joint {i + 1} ({chain.names[i]}){_flip(s[i])}" if i < n
                    else "the flange approach axis")
            head = f"Z_{i} along {here}; O_{i} on Z_{i}, X_{i} along the common normal of Z_{i - 1} and Z_{i}: "
        else:
            nxt = f"joint {i + 1}" if i < n else "the flange approach axis"
            head = (f"Z_{i} along joint {i} ({chain.names[i - 1]}){_flip(s[i - 1])}; O_{i} on Z_{i}, "
                    f"X_{i} along the common normal of Z_{i} and {nxt}: ")
        notes.append(FrameNote(i, nm.case, head + nm.why))
    return DHDerivation(robot=robot, notes=tuple(notes), frames=F)


def _flip(sign: float) -> str:
    return "" if sign > 0 else ", pointing against its positive direction (sign -1)"


def _common_normal(
    p: NDArray, z: NDArray, p2: NDArray, z2: NDArray, prev_b: NDArray, prev_x: NDArray | None,
    ee: NDArray, flange: NDArray | None, tol: float,
) -> _Normal:
    """The common normal of lines ``(p, z)`` and ``(p2, z2)`` by the procedure's case rules.

    ``prev_b``, ``prev_x``: where the previous normal met line ``(p, z)`` and its direction (None
    for the first pair); ``ee``: the flange origin (end effector); ``flange``: the flange pose when
    ``(p2, z2)`` is the flange approach axis, else None.
    """
    r = p2 - p
    w = np.cross(z, z2)
    sw = float(np.linalg.norm(w))
    if sw > tol:
        t = float(np.dot(np.cross(r, z2), w)) / sw**2
        u = float(np.dot(np.cross(r, z), w)) / sw**2
        A, B = p + t * z, p2 + u * z2
        dist = float(np.linalg.norm(B - A))
        if dist > tol:
            return _Normal("skew", A, B, (B - A) / dist, (
                f"the axes are skew, so the common normal is unique; it is {_mm(dist)} mm long "
                "and X points along it toward the next axis (toward the end effector), a > 0."))
        A = B = 0.5 * (A + B)
        x = w / sw
        where = f"the axes intersect at ({_mm_vec(A)}) mm, which is the origin (a = 0)"
        if flange is not None and abs(abs(float(np.dot(flange[:3, 0], x))) - 1.0) <= tol:
            return _Normal("intersecting", A, B, x * np.sign(np.dot(flange[:3, 0], x)), (
                f"{where}; X = +-(Z x Z') with the sign of the flange X axis, so the last frame "
                "has the flange's axes."))
        toward = float(np.dot(x, ee - A))
        if abs(toward) > tol:
            return _Normal("intersecting", A, B, x * math.copysign(1.0, toward), (
                f"{where}; X = +-(Z x Z') with the sign that makes X point toward the end "
                "effector (the flange origin)."))
        undecided = ("the flange origin lies in the plane of both axes, so 'toward the end "
                     "effector' does not decide the sign")
        if prev_x is not None and abs(float(np.dot(x, prev_x))) > tol:
            return _Normal("intersecting", A, B, x * np.sign(np.dot(x, prev_x)), (
                f"{where}; X = +-(Z x Z'): {undecided}; the sign that keeps X closest to the "
                "previous X is taken (smallest theta offset)."))
        return _Normal("intersecting", A, B, x, f"{where}; X = Z x Z' / |Z x Z'| ({undecided}).")
    r_perp = r - np.dot(r, z) * z
    dist = float(np.linalg.norm(r_perp))
    if dist > tol:
        B = p2 + np.dot(prev_b - p2, z2) * z2
        return _Normal("parallel", prev_b, B, r_perp / dist, (
            f"the axes are parallel, {_mm(dist)} mm apart, so the common normal is not unique: "
            "the one through the point where the previous normal meets this axis is taken, "
            "which keeps d = 0; X points from this axis toward the next (toward the end "
            "effector)."))
    if flange is not None:
        A = p + np.dot(flange[:3, 3] - p, z) * z
        return _Normal("coincident", A, A, _unit_perp(flange[:3, 0], z), (
            "the flange approach axis lies on the last joint axis (the Z axes coincide), so any "
            "normal will do: origin and X are the flange's, the last frame is the flange frame "
            "(a = 0)."))
    if prev_x is not None:
        return _Normal("coincident", prev_b, prev_b, prev_x, (
            "the two Z axes coincide, so any normal will do: the previous origin and X are kept "
            "(a = 0, d = 0, no theta offset)."))
    toward = (ee - prev_b) - np.dot(ee - prev_b, z) * z
    if np.linalg.norm(toward) > tol:
        x, why = _unit_perp(toward, z), "X points toward the end effector (the flange origin)"
    else:
        e = np.eye(3)[int(np.argmin(np.abs(z)))]
        x, why = _unit_perp(e, z), (f"the end effector lies on this axis too, so X is R's "
                                    f"{'XYZ'[int(np.argmin(np.abs(z)))]} axis made perpendicular")
    return _Normal("coincident", prev_b, prev_b, x, (
        f"the two Z axes coincide and there is no earlier X to keep: the origin stays at O_0 "
        f"(a = 0, d = 0) and {why}."))


def _unit_perp(v: NDArray, z: NDArray) -> NDArray:
    """``v`` made perpendicular to the unit vector ``z`` and normalised."""
    u = v - np.dot(v, z) * z
    return u / np.linalg.norm(u)


def _angle(v1: NDArray, v2: NDArray, axis: NDArray) -> float:
    """Angle (rad) that turns ``v1`` onto ``v2`` about ``axis`` (all unit, ``v1, v2`` perp. to it)."""
    return math.atan2(float(np.dot(np.cross(v1, v2), axis)), float(np.dot(v1, v2)))


def _length_twist(nm: _Normal, z: NDArray, z2: NDArray) -> tuple[float, float]:
    """Link length ``a`` (m) and twist ``alpha`` (rad) of the common normal ``nm``."""
    return float(np.dot(nm.B - nm.A, nm.x)), _angle(z, z2, nm.x)


def _frame(origin: NDArray, z: NDArray, x: NDArray) -> NDArray[np.float64]:
    """Pose with the given origin, Z and X axes (unit, perpendicular)."""
    return make_pose(np.column_stack([x, np.cross(z, x), z]), origin)


def _mm(v: float) -> str:
    return f"{v * 1e3:.3f}"


def _mm_vec(v: NDArray) -> str:
    return ", ".join(f"{round(c * 1e3, 3) + 0.0:.3f}" for c in v)
