"""The Denavit-Hartenberg procedure: DH frames and table from the joint axes of a chain.

The procedure of the lecture, done by the computer. Write ``L_0 .. L_{n-1}`` for the axes of joints
``1..n`` at ``q = 0`` and ``L_n`` for the flange's approach axis (its Z axis). Between each pair of
consecutive lines ``L_k, L_{k+1}`` the procedure needs their common normal: a segment from ``A_k`` on
``L_k`` to ``B_k`` on ``L_{k+1}`` with unit direction ``x_k``. One of four cases applies:

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

**Nearly parallel axes.** Two axes at a small angle ``phi`` that do not meet have a unique common
normal, but up to ``distance / phi`` away from the robot: kilometres for a tilt of 1e-6 rad, with
``d`` values that cancel to the last digit. The procedure uses a common normal only when its feet
lie within :data:`REACH` times the chain's extent of the chain's points on the two axes (always so
for axes more than 30 degrees apart); otherwise the axes are nearly parallel and take the parallel
(or coincident) rule, and Hayati's ``beta`` (a rotation about Y after the twist) takes their tilt,
so the model stays exact with constants of the chain's own size. In the standard convention the
normal of such a pair lies in the plane perpendicular to ``z_k``, in the modified convention it is
perpendicular to ``z_{k+1}`` (the axis the link's translation ends on).

**Standard DH** puts frame ``i`` (``i = 1..n``) at ``B_{i-1}`` with ``Z_i`` along ``L_i`` and
``X_i = x_{i-1}``. **Modified DH** puts frame ``i`` at ``A_{i-1}`` with ``Z_i`` along ``L_{i-1}`` and
``X_i = x_{i-1}``. In both, frame 0 has ``Z_0`` along ``L_0``, its origin at the point of ``L_0``
nearest the origin of R, and ``X_0 = x_0`` (no theta offset on joint 1). Then
``theta_i = angle(x_{i-2} -> x_{i-1}) about z_{i-1}`` and ``d_i = (A_{i-1} - B_{i-2}) · z_{i-1}``,
``a``, ``alpha`` (and ``beta``) are the length and twist of the common normal; every constant is
measured from the geometry, so the tolerance only names the case. For a nearly parallel pair the
X axes are ``x_k`` made perpendicular to the Z axis of the frame. See ``docs/dh-procedure.md``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from robotcell.dhprocedure.axes import AxisChain
from robotcell.dhprocedure.exactness import check_exact
from robotcell.errors import InputError
from robotcell.kinematics.dh import Convention
from robotcell.kinematics.transforms import invert, make_pose
from robotcell.robot.robot import Joint, Robot

__all__ = ["REACH", "DHDerivation", "FrameNote", "dh_from_axes"]

CASES = ("base", "skew", "intersecting", "parallel", "coincident")

#: A common normal is used when its feet lie within this many times the chain's extent (the
#: largest distance between two of its axis points and the flange origin) of the points given on
#: the two axes. Feet farther away mean axes less than 30 degrees apart whose normal lies beyond
#: the robot: they take the parallel rule with Hayati's beta.
REACH = 2.0
#: The extent of a chain whose points all coincide (m).
MIN_EXTENT = 1e-3


@dataclass(frozen=True)
class FrameNote:
    """Why DH frame ``index`` is where it is.

    Attributes
    ----------
    index : int
        Frame number ``0..n``.
    case : {"base", "skew", "intersecting", "parallel", "coincident"}
        ``base`` for frame 0; otherwise how the two Z axes that define the frame relate (nearly
        parallel axes are ``parallel`` or ``coincident``; the text says so).
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
    deviation : float
        How far the model as a model file holds it (mm and degrees, see
        :func:`robotcell.save_robot`) moves from the source's FK: the largest flange position
        difference (m) or orientation difference (rad) at the check's joint values, at most
        :data:`~robotcell.dhprocedure.exactness.EXACT_TOL`.
    """

    robot: Robot
    notes: tuple[FrameNote, ...]
    frames: NDArray[np.float64]
    deviation: float = 0.0


@dataclass(frozen=True)
class _Normal:
    """Normal from ``A`` on ``L_k`` to ``B`` on ``L_{k+1}``, direction ``x``; ``parallel`` when
    the pair took the parallel or coincident rule (``x`` then is perpendicular to one Z axis
    only)."""

    case: str
    A: NDArray[np.float64]
    B: NDArray[np.float64]
    x: NDArray[np.float64]
    why: str
    parallel: bool = False


@dataclass(frozen=True)
class _Pair:
    """Lines ``(p, z)`` and ``(p2, z2)``; the previous normal's end ``prev_b`` on the first and
    the frame X there ``prev_x`` (None for the first pair); the flange pose when the second line
    is the flange approach axis; the flange origin ``ee``; the chain's ``reach`` (m)."""

    p: NDArray[np.float64]
    z: NDArray[np.float64]
    p2: NDArray[np.float64]
    z2: NDArray[np.float64]
    prev_b: NDArray[np.float64]
    prev_x: NDArray[np.float64] | None
    flange: NDArray[np.float64] | None
    ee: NDArray[np.float64]
    reach: float


def dh_from_axes(
    chain: AxisChain,
    convention: Convention = "standard",
    signs: Sequence[float] | None = None,
    tol: float = 1e-12,
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
        intersecting, parallel or coincident. It names the case; the constants are measured
        from the geometry, so the model is exact whatever ``tol``, but for lines up to ``tol``
        apart taken as coincident (an error of at most ``tol`` each).
    name, title, source : str
        Copied to the returned model.

    Returns
    -------
    DHDerivation
        The model (base ``T_R_0``, DH joints, flange ``T_n_F``; tool identity), a note per frame,
        the DH frames at ``q = 0``, and the deviation of the model as written from the chain.

    Raises
    ------
    InputError
        Unknown convention, signs that are not +-1, or a model whose file form would not
        reproduce the chain's FK to 1e-9 m and rad (the message says by how much, which joints
        show it and why).

    Notes
    -----
    Consecutive prismatic joints along parallel axes (a gantry with redundant axes) are legal:
    DH holds them as two ``d`` variables along the same Z direction.
    """
    der = derive(chain, convention, signs, tol, name, title, source)
    return replace(der, deviation=check_exact(der.robot, chain.fk, chain, "the chain", tol))


def derive(
    chain: AxisChain, convention: Convention, signs: Sequence[float] | None, tol: float,
    name: str, title: str, source: str,
) -> DHDerivation:
    """:func:`dh_from_axes` without the check of the written model (``deviation`` 0)."""
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
    extent = max(float(np.max(np.linalg.norm(points[:, None] - points[None], axis=-1))),
                 MIN_EXTENT)

    normals: list[_Normal] = []
    prev_b, prev_x = o0, None
    for k in range(n):
        pair = _Pair(points[k], z[k], points[k + 1], z[k + 1], prev_b, prev_x,
                     flange if k == n - 1 else None, flange[:3, 3], REACH * extent + tol)
        nm = _common_normal(pair, convention, tol)
        normals.append(nm)
        prev_b, prev_x = nm.B, _x_axes(nm, z[k], z[k + 1], convention)[1]

    ends = [_x_axes(nm, z[k], z[k + 1], convention) for k, nm in enumerate(normals)]
    x_start = [e[0] for e in ends]
    links = [_link(nm, *ends[k], z[k], z[k + 1], extent, tol) for k, nm in enumerate(normals)]
    joints = []
    for k in range(n):
        x_prev = ends[k - 1][1] if k else x_start[0]
        b_prev = normals[k - 1].B if k else o0
        a, alpha, beta = links[k] if convention == "standard" else (
            links[k - 1] if k else (0.0, 0.0, 0.0))
        joints.append(Joint(
            type=chain.types[k], a=a, alpha=alpha, beta=beta,
            d=float(np.dot(normals[k].A - b_prev, z[k])), theta=_angle(x_prev, x_start[k], z[k]),
            sign=float(s[k]), lower=float(chain.lower[k]), upper=float(chain.upper[k]),
            name=chain.names[k],
        ))
    base = _frame(o0, z[0], x_start[0])
    robot = Robot(name=name, joints=tuple(joints), convention=convention, base=base,
                  title=title or name, source=source)
    F = robot.frames(np.zeros(n))
    robot = Robot(name=name, joints=tuple(joints), convention=convention, base=base,
                  flange=invert(F[-1]) @ flange, title=title or name, source=source)
    return DHDerivation(robot=robot, notes=_notes(chain, normals, links, s, convention), frames=F)


def _notes(chain: AxisChain, normals: list[_Normal], links: list[tuple[float, float, float]],
           s: NDArray, convention: str) -> tuple[FrameNote, ...]:
    """One note per frame: which Z axis, which normal, and why."""
    n = chain.n_joints
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
        beta = links[i - 1][2]
        tail = (f" Hayati's beta = {math.degrees(beta):.9f} deg (a turn about Y after the twist) "
                "takes the tilt between the axes, so the model stays exact." if beta else "")
        notes.append(FrameNote(i, nm.case, head + nm.why + tail))
    return tuple(notes)


def _flip(sign: float) -> str:
    return "" if sign > 0 else ", pointing against its positive direction (sign -1)"


def _common_normal(pair: _Pair, convention: str, tol: float) -> _Normal:
    """The common normal of the pair's lines by the procedure's case rules.

    The foot on the line the link's translation leaves from is computed, the other is its
    projection on the other line (standard: ``A`` from ``B``; modified: ``B`` from ``A``), so the
    translation is perpendicular to the Z axis it must be perpendicular to, to rounding.
    """
    w = np.cross(pair.z, pair.z2)
    sw = float(np.linalg.norm(w))
    if sw * pair.reach <= tol:
        return _parallel(pair, convention, tol, "")
    r = pair.p2 - pair.p
    t = float(np.dot(np.cross(r, pair.z2), w)) / sw**2
    u = float(np.dot(np.cross(r, pair.z), w)) / sw**2
    far = max(abs(t), abs(u))
    if far > pair.reach:
        angle = math.degrees(math.asin(min(sw, 1.0)))
        return _parallel(pair, convention, tol, (
            f"the axes are {angle:.3g} deg from parallel and their common normal would lie "
            f"{far:.3g} m along them, beyond {REACH:g} times the chain's extent "
            f"({_mm(pair.reach / REACH)} mm), with d values that cancel; so, as nearly parallel "
            "axes, they take the parallel rule: "))
    if convention == "standard":
        B = pair.p2 + u * pair.z2
        A = pair.p + np.dot(B - pair.p, pair.z) * pair.z
    else:
        A = pair.p + t * pair.z
        B = pair.p2 + np.dot(A - pair.p2, pair.z2) * pair.z2
    dist = float(np.linalg.norm(B - A))
    if dist <= tol:
        return _intersecting(pair, A, B, w / sw, tol)
    # the better conditioned of the two directions of the normal: B - A, or Z x Z'
    x = (B - A) / dist if sw * pair.reach < dist else w / sw * math.copysign(1.0, np.dot(B - A, w))
    return _Normal("skew", A, B, x, (
        f"the axes are skew, so the common normal is unique; it is {_mm(dist)} mm long "
        "and X points along it toward the next axis (toward the end effector), a > 0."))


def _intersecting(pair: _Pair, A: NDArray, B: NDArray, x: NDArray, tol: float) -> _Normal:
    """Lines that meet (``A``, ``B`` within ``tol``): X = +-(Z x Z') by the X-direction rule."""
    where = f"the axes intersect at ({_mm_vec(A)}) mm, which is the origin (a = 0)"
    flange = pair.flange
    if flange is not None and abs(abs(float(np.dot(flange[:3, 0], x))) - 1.0) <= tol:
        return _Normal("intersecting", A, B, x * np.sign(np.dot(flange[:3, 0], x)), (
            f"{where}; X = +-(Z x Z') with the sign of the flange X axis, so the last frame "
            "has the flange's axes."))
    toward = float(np.dot(x, pair.ee - A))
    if abs(toward) > tol:
        return _Normal("intersecting", A, B, x * math.copysign(1.0, toward), (
            f"{where}; X = +-(Z x Z') with the sign that makes X point toward the end "
            "effector (the flange origin)."))
    undecided = ("the flange origin lies in the plane of both axes, so 'toward the end "
                 "effector' does not decide the sign")
    if pair.prev_x is not None and abs(float(np.dot(x, pair.prev_x))) > tol:
        return _Normal("intersecting", A, B, x * np.sign(np.dot(x, pair.prev_x)), (
            f"{where}; X = +-(Z x Z'): {undecided}; the sign that keeps X closest to the "
            "previous X is taken (smallest theta offset)."))
    return _Normal("intersecting", A, B, x, f"{where}; X = Z x Z' / |Z x Z'| ({undecided}).")


def _parallel(pair: _Pair, convention: str, tol: float, nearly: str) -> _Normal:
    """Parallel or nearly parallel lines: the parallel rule, or the coincident one.

    ``A`` is the previous normal's end; ``B`` the point of the second line in the plane through
    ``A`` perpendicular to ``z`` (standard) or the foot of the perpendicular from ``A``
    (modified): the link's translation ``a`` is perpendicular to the Z axis it leaves from
    (standard) or arrives on (modified).
    """
    z_of_x = pair.z if convention == "standard" else pair.z2

    def end(A: NDArray) -> NDArray:
        r = A - pair.p2
        s = np.dot(r, pair.z) / np.dot(pair.z2, pair.z) if convention == "standard" else (
            np.dot(r, pair.z2))
        return pair.p2 + s * pair.z2

    A = pair.prev_b
    B = end(A)
    dist = float(np.linalg.norm(B - A))
    if dist > tol:
        why = nearly + (
            f"they are {_mm(dist)} mm apart there; the normal through the point where the "
            "previous normal meets this axis is taken (d = 0), X points toward the next axis."
            if nearly else
            f"the axes are parallel, {_mm(dist)} mm apart, so the common normal is not unique: "
            "the one through the point where the previous normal meets this axis is taken, "
            "which keeps d = 0; X points from this axis toward the next (toward the end "
            "effector).")
        return _Normal("parallel", A, B, (B - A) / dist, why, parallel=True)
    if pair.flange is not None:
        A = pair.p + np.dot(pair.ee - pair.p, pair.z) * pair.z
        return _Normal("coincident", A, end(A), _unit_perp(pair.flange[:3, 0], z_of_x), nearly + (
            "the flange approach axis lies on the last joint axis (the Z axes coincide), so any "
            "normal will do: origin and X are the flange's, the last frame is the flange frame "
            "(a = 0)."), parallel=True)
    if pair.prev_x is not None:
        return _Normal("coincident", A, B, _unit_perp(pair.prev_x, z_of_x), nearly + (
            "the two Z axes coincide, so any normal will do: the previous origin and X are kept "
            "(a = 0, d = 0, no theta offset)."), parallel=True)
    toward = (pair.ee - A) - np.dot(pair.ee - A, pair.z) * pair.z
    if np.linalg.norm(toward) > tol:
        v, why = toward, "X points toward the end effector (the flange origin)"
    else:
        axis = int(np.argmin(np.abs(pair.z)))
        v, why = np.eye(3)[axis], (f"the end effector lies on this axis too, so X is R's "
                                   f"{'XYZ'[axis]} axis made perpendicular")
    return _Normal("coincident", A, B, _unit_perp(_unit_perp(v, pair.z), z_of_x), nearly + (
        f"the two Z axes coincide and there is no earlier X to keep: the origin stays at O_0 "
        f"(a = 0, d = 0) and {why}."), parallel=True)


def _x_axes(nm: _Normal, z: NDArray, z2: NDArray, convention: str) -> tuple[NDArray, NDArray]:
    """The X axes ``(x_start, x_end)`` of the frames at the two ends of the normal ``nm``.

    ``x_start`` is perpendicular to ``z``, ``x_end`` to ``z2``; ``Rx(alpha) Ry(beta)`` turns
    ``(x_start, z)`` into ``(x_end, z2)`` when the Y axis of the end frame is perpendicular to
    ``x_start``. The normal of skew or intersecting axes is perpendicular to both Z axes. A
    parallel pair's ``x`` is perpendicular to ``z`` in standard DH (it is ``x_start``, and
    ``x_end`` is its projection) and to ``z2`` in modified DH (it is ``x_end``, and ``x_start``
    is perpendicular to ``z`` and to the end frame's Y axis ``z2 x x``).
    """
    if not nm.parallel:
        return _unit_perp(nm.x, z), _unit_perp(nm.x, z2)
    if convention == "standard":
        return nm.x, _unit_perp(nm.x, z2)
    c = float(np.dot(z, z2))
    v = c * nm.x - np.dot(nm.x, z) * z2
    return v / np.linalg.norm(v) * math.copysign(1.0, c), nm.x


def _link(nm: _Normal, x_start: NDArray, x_end: NDArray, z: NDArray, z2: NDArray,
          extent: float, tol: float) -> tuple[float, float, float]:
    """Length ``a`` (m), twist ``alpha`` and Hayati ``beta`` (rad) of the link along ``nm``.

    ``Rx(alpha) Ry(beta)`` turns the frame ``(x_start, z)`` on the first line into the frame
    ``(x_end, z2)`` on the second (see :func:`_x_axes`). A beta
    that moves no point of the chain by more than ``tol`` is 0: the common normal of skew or
    intersecting axes is perpendicular to both, and parallel axes need none.
    """
    R = _frame(np.zeros(3), z, x_start)[:3, :3].T @ _frame(np.zeros(3), z2, x_end)[:3, :3]
    beta = math.atan2(R[0, 2], R[0, 0])
    alpha = math.atan2(R[2, 1], R[1, 1])
    return float(np.dot(nm.B - nm.A, nm.x)), alpha, beta if abs(beta) * extent > tol else 0.0


def _unit_perp(v: NDArray, z: NDArray) -> NDArray:
    """``v`` made perpendicular to the unit vector ``z`` and normalised."""
    u = v - np.dot(v, z) * z
    return u / np.linalg.norm(u)


def _angle(v1: NDArray, v2: NDArray, axis: NDArray) -> float:
    """Angle (rad) that turns ``v1`` onto ``v2`` about ``axis`` (all unit, ``v1, v2`` perp. to it)."""
    return math.atan2(float(np.dot(np.cross(v1, v2), axis)), float(np.dot(v1, v2)))


def _frame(origin: NDArray, z: NDArray, x: NDArray) -> NDArray[np.float64]:
    """Pose with the given origin, Z and X axes (unit, perpendicular)."""
    return make_pose(np.column_stack([x, np.cross(z, x), z]), origin)


def _mm(v: float) -> str:
    return f"{v * 1e3:.3f}"


def _mm_vec(v: NDArray) -> str:
    return ", ".join(f"{round(c * 1e3, 3) + 0.0:.3f}" for c in v)
