"""Fast choice of the track value for an ortho-parallel arm on a linear track.

For a target ``T_L_TCP`` the wrist centre of the arm, written in the arm's frame O (see
:mod:`robotcell.ik.opw`), moves on a straight line as the track value ``x`` changes:
``C(x) = C0 + x w`` with ``w = -R_O_R Q^T u`` (``Q`` the mounting rotation, ``u`` the track
direction); the orientation ``R_O_e`` does not change. Hence, with ``S = (0, 0, c1)`` the centre
of the shoulder circle on axis 1,

    |C(x) - S|^2 = |w|^2 x^2 + 2 (C0 - S).w x + |C0 - S|^2      (quadratic in x),

and the arm reaches the wrist centre only if the shoulder-to-wrist-centre distance is at most
``c2 + sqrt(a2^2 + c3^2)`` (stretched elbow); since the shoulder (axis 2) is ``a1`` off axis 1
and the wrist centre ``b`` off the arm plane, ``|C(x) - S|^2 <= (c2 + kappa + |a1|)^2 + b^2``.
The roots of that quadratic give, in closed form, an interval of the track value that contains
every reachable value (:func:`track_interval`).

Inside it, the choice maximises the manipulability ``|det J|`` (Yoshikawa 1985), the criterion of
:meth:`robotcell.ik.TrackRobot.ik`. For an ortho-parallel arm with a spherical wrist it has a
closed form from the wrist-centre geometry alone (the Jacobian is block triangular at the wrist
centre and ``det J`` does not depend on the reference point):

    |det J| = n * c2 * kappa * |sin(gamma)| * |sin(t5)|,

``n`` the distance of the wrist centre from axis 1 in the arm plane (0: shoulder singularity),
``gamma`` the angle between the upper arm and the line from axis 3 to the wrist centre (0 or pi:
stretched or folded elbow), ``t5`` the wrist bend (0: wrist singularity). So it is evaluated on
many track values for the price of a few arithmetic operations each, with the limits of the axes
that do not turn a full circle (axes 1, 2, 3 and 5 where they are limited) checked on the way,
in compiled code (:mod:`robotcell.ik.kernels`, one target or a batch). For an arm with a joint
coupling ``q_model = C q + offset`` (FANUC J2/J3, a parallel arm) the closed form holds for the
model's angles and is multiplied by ``|det C|``, and a coupled axis's limits are checked on its
controller value. The arm is then solved once, analytically, at the chosen value; where that
has no valid branch (a limit of axis 4 or 6) the target falls back to the sampled search of
:meth:`~robotcell.ik.TrackRobot.ik`. Every returned solution is exact and within all limits. A
target the scan does not reach at all is scanned again on a grid 8 times finer. A best value
inside a window of track values narrower than one step of the scan (1/23 of the interval by
default) can still be missed: the choice then has a lower manipulability than the sampled
search (about 1 random target in 300 loses more than 1 % on a KR 16).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.ik.analytic import analytic_solver
from robotcell.ik.limits import TWO_PI
from robotcell.ik.opw import OPWParameters
from robotcell.ik.result import IKSolutions
from robotcell.ik.track import TrackChoice, TrackRobot
from robotcell.kinematics.arm import Arm
from robotcell.kinematics.transforms import invert, validate_pose, validate_single_pose

__all__ = ["TrackScan", "arm_manipulability", "choose_track", "manipulability", "scan_track",
           "track_interval"]

#: Within this fraction of the best manipulability, a preferred track value (the previous
#: target's on a path) wins over a larger manipulability.
PREFER_WITHIN = 0.1
#: Refinement stages per peak of the coarse scan and samples per stage.
REFINE_STAGES, REFINE = 2, 9
#: A second peak of the coarse scan is refined too when it reaches this fraction of the first.
SECOND_PEAK = 0.9
#: How much finer the second look at a target the scan did not reach is.
DENSE = 8


@dataclass(frozen=True)
class TrackScan:
    """Manipulability of a batch of targets over sampled track values.

    Attributes
    ----------
    x : ndarray, shape (N, K)
        Track values (m), inside the track limits and the closed-form interval.
    manipulability : ndarray, shape (N, K)
        Best ``|det J|`` over the arm branches that reach the target there within the limits of
        axes 1, 2, 3 and 5 (m^3; 0 where none does).
    lower, upper : ndarray, shape (N,)
        The closed-form interval of :func:`track_interval`, clipped to the track limits (m);
        NaN where it is empty.
    """

    x: NDArray[np.float64]
    manipulability: NDArray[np.float64]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]


class _Chooser:
    """What the compiled choice needs of a track robot, computed once per :class:`TrackRobot`.

    The limits of axes 1, 2, 3, 5 become cones on the paper's angles: ``q`` in ``[lo, hi]``
    (some 2*pi-equivalent) iff ``cos(t - mid) >= cos(half)`` for ``t = sign * q + offset``,
    tested on the (cos t, sin t) pair the geometry gives, without an arctangent. A coupled
    axis's limit is on the controller value, not on the model angle: left to the exact check
    after the solve, except for axes among 1..3 whose controller value depends on model joints
    1..3 only (FANUC J2/J3, a parallel arm), checked on the angles.
    """

    def __init__(self, track: TrackRobot) -> None:
        arm = track.arm
        solver = _closed_form(arm)
        if solver.method != "opw":
            raise InputError("the fast track choice needs an ortho-parallel arm with a spherical "
                             "wrist")
        from robotcell.ik import kernels  # loaded with the solver

        self.kernels, self.solver = kernels, solver
        pa = solver.params
        lower, upper = arm.lower, arm.upper
        coupled = set() if arm.coupling is None else set(arm.coupling.changed_axes())
        cones = {}
        for j in (0, 1, 2, 4):
            if upper[j] - lower[j] >= TWO_PI or j in coupled:
                continue
            mid = pa.signs[j] * 0.5 * (lower[j] + upper[j]) + pa.offsets[j]
            cones[j] = (math.cos(mid), math.sin(mid), math.cos(0.5 * (upper[j] - lower[j])))
        rows = []
        c = arm.coupling
        if c is not None and c.matrix.shape[0] == c.matrix.shape[1]:
            inv = np.linalg.inv(c.matrix)
            off = inv @ (np.zeros(6) if c.offset is None else c.offset)
            for j in sorted(coupled & {0, 1, 2}):
                if np.any(inv[j, 3:] != 0) or upper[j] - lower[j] >= TWO_PI:
                    continue
                rows.append((j, inv[j, :3], -float(off[j]), float(lower[j]), float(upper[j])))
        T_O_L = invert(pa.T_R_O) @ invert(track.T_L_R0)
        self.w = np.ascontiguousarray(-(T_O_L[:3, :3] @ track.direction))
        self.config = kernels.track_config(track.lower, track.upper, self.w, T_O_L, cones, rows,
                                           PREFER_WITHIN, SECOND_PEAK, REFINE_STAGES, REFINE)
        self.fine = np.linspace(-1.0, 1.0, REFINE)
        self._grids: dict[int, NDArray[np.float64]] = {}

    def grid(self, samples: int) -> NDArray[np.float64]:
        """``np.linspace(0, 1, samples)``, kept."""
        g = self._grids.get(samples)
        if g is None:
            g = self._grids[samples] = np.linspace(0.0, 1.0, samples)
        return g



def _closed_form(arm: Arm) -> Any:
    """The analytic solver of ``arm``, or of its seed for a model solved numerically from a
    nominal's branches (an identified arm): the choice of the track runs on the closed form, the
    solution at the chosen value on the model itself."""
    solver = analytic_solver(arm)
    return getattr(solver, "seed", solver)


def _chooser(track: TrackRobot) -> _Chooser:
    ch = track.__dict__.get("_chooser")
    if ch is None:
        ch = _Chooser(track)
        object.__setattr__(track, "_chooser", ch)
    return ch


def _targets(T: ArrayLike) -> tuple[NDArray[np.float64], tuple[int, ...]]:
    """Validated targets as a C-contiguous ``(N, 4, 4)`` array, and their batch shape."""
    if type(T) is np.ndarray and T.shape == (4, 4):
        return validate_single_pose(T, "target pose")[None], ()
    arr = validate_pose(T, "target pose")
    return np.ascontiguousarray(arr.reshape(-1, 4, 4)), arr.shape[:-2]


def _wrist_line(track: TrackRobot, T: NDArray[np.float64], tool: ArrayLike | None
                ) -> tuple[OPWParameters, NDArray[np.float64], NDArray[np.float64],
                           NDArray[np.float64]]:
    """``(params, R_O_e (N,3,3), C0 (N,3), w (3,))`` for targets ``T_L_TCP`` (N, 4, 4)."""
    ch = _chooser(track)
    flat, _ = _targets(T)
    R, C0 = np.empty((len(flat), 3, 3)), np.empty((len(flat), 3))
    ch.kernels.wrist_rows(ch.solver._cfg, ch.config, flat, ch.solver.end(tool), R, C0)
    return ch.solver.params, R, C0, ch.w


def track_interval(pa: OPWParameters, C0: NDArray[np.float64], w: NDArray[np.float64]
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Closed-form interval of track values that contains every reachable one.

    Parameters
    ----------
    pa : OPWParameters
    C0 : ndarray, shape (N, 3)
        Wrist centre in O at track value 0 (m).
    w : ndarray, shape (3,)
        Its displacement in O per metre of track (unit vector).

    Returns
    -------
    lower, upper : ndarray, shape (N,)
        Roots of ``|C0 + x w - S|^2 = (c2 + kappa + |a1|)^2 + b^2`` (m); NaN where the wrist
        centre never comes that close to the shoulder.
    """
    from robotcell.ik import kernels

    C = np.ascontiguousarray(C0, dtype=float).reshape(-1, 3)
    lower, upper = np.empty(len(C)), np.empty(len(C))
    kernels.interval_rows(_opw_params(pa), C, np.ascontiguousarray(w, dtype=float), lower, upper)
    return lower, upper


def _opw_params(pa: OPWParameters) -> NDArray[np.float64]:
    from robotcell.ik import kernels

    return kernels.opw_params(pa.a1, pa.a2, pa.b, pa.c1, pa.c2, pa.c3, pa.c4, pa.signs, pa.offsets)


def scan_track(track: TrackRobot, T: ArrayLike, tool: ArrayLike | None = None,
               samples: int = 24) -> TrackScan:
    """Manipulability of every target on ``samples`` track values of its reachable interval.

    Parameters
    ----------
    track : TrackRobot
        With an ortho-parallel arm and finite track limits.
    T : array_like, shape (N, 4, 4)
        ``T_L_TCP`` (m).
    tool : array_like, shape (4, 4), optional
        ``T_F_TCP`` instead of the arm's default tool (m).
    samples : int
        Track values per target (>= 2), evenly spaced over the interval.

    Returns
    -------
    TrackScan
    """
    ch = _chooser(track)
    flat, _ = _targets(T)
    n = len(flat)
    x, m = np.empty((n, samples)), np.empty((n, samples))
    lower, upper = np.empty(n), np.empty(n)
    ch.kernels.scan_rows(ch.solver._cfg, ch.config, flat, ch.solver.end(tool), ch.grid(samples), x, m,
                         lower, upper)
    return TrackScan(x, m, lower, upper)


def choose_track(track: TrackRobot, T: ArrayLike, tool: ArrayLike | None = None,
                 samples: int = 24, prefer: ArrayLike | None = None) -> TrackChoice:
    """Choose the track value per target and solve the arm there (vectorised over targets).

    The criterion: the largest manipulability ``|det J|`` over the arm branches within the
    limits (as :meth:`TrackRobot.ik`), searched on ``samples`` values of the closed-form
    interval of :func:`track_interval` and refined on ``samples`` values between the best one's
    neighbours. With ``prefer`` (e.g. the previous target's value on a path), the value nearest
    to it among those within :data:`PREFER_WITHIN` of the best manipulability. Targets where
    the chosen value has no valid branch are searched again by :meth:`TrackRobot.ik`.

    Parameters
    ----------
    track : TrackRobot
        Ortho-parallel arm, finite track limits.
    T : array_like, shape (..., 4, 4)
        ``T_L_TCP`` (m).
    tool : array_like, shape (4, 4), optional
        ``T_F_TCP`` instead of the arm's default tool (m).
    samples : int
        Track values per search stage (>= 3).
    prefer : array_like, shape (...), optional
        Preferred track values (m).

    Returns
    -------
    TrackChoice
        Solutions ``(..., 8, 7)`` at the chosen values; ``manipulability`` is ``|det J|`` of the
        best valid branch there (m^3; 0 where nothing is reachable).
    """
    track.check_choice(samples)
    ch = _chooser(track)
    flat, batch = _targets(T)
    n = len(flat)
    pref = (np.empty(0) if prefer is None else
            np.ascontiguousarray(np.broadcast_to(np.asarray(prefer, dtype=float), batch).reshape(-1)))
    x, found, manip = np.empty(n), np.empty(n, dtype=bool), np.empty(n)
    q, err = np.empty((n, 8, 7)), np.empty((n, 8))
    reach, valid = np.empty((n, 8), dtype=bool), np.empty((n, 8), dtype=bool)
    lins = (ch.grid(samples), ch.fine, ch.grid(DENSE * samples))
    again = ch.kernels.choose_poses(ch.solver._cfg, ch.config, flat, ch.solver.end(tool), lins,
                                    pref, (x, found, q, err, reach, valid, manip))
    coupled = track.arm.coupling is not None
    if coupled:  # mapped to controller values and checked by the solver
        sol = _solve_at(track, flat, x, tool)
        q, valid, reach, err = sol.q, sol.valid, sol.reachable, sol.reach_error
    if coupled or again:
        retry = found & ~valid.any(axis=-1)
        if retry.any():
            search = track.ik(flat[retry], samples=65, tool=tool)
            x[retry] = search.track
            q, valid, reach, err = (a.copy() for a in (q, valid, reach, err))
            found_q = search.solutions
            q[retry], valid[retry], reach[retry] = found_q.q, found_q.valid, found_q.reachable
            err[retry] = found_q.reach_error
        manip = _best_valid(track.arm, q, valid)
    sol = IKSolutions(q.reshape(batch + (8, 7)), valid.reshape(batch + (8,)),
                      reach.reshape(batch + (8,)), "opw", err.reshape(batch + (8,)))
    return TrackChoice(sol, x.reshape(batch), manip.reshape(batch))


def manipulability(pa: OPWParameters, q: ArrayLike) -> NDArray[np.float64]:
    """``|det J|`` of an ortho-parallel arm in closed form (m^3).

    Parameters
    ----------
    pa : OPWParameters
    q : array_like, shape (..., 6)
        Controller axis values (rad); NaN gives NaN.

    Returns
    -------
    ndarray, shape (...)
        ``n * c2 * kappa * |sin(gamma)| * |sin(t5)|`` (see the module docstring); equal to
        ``|det robot.jacobian(q)|``.
    """
    from robotcell.ik import kernels

    arr = np.asarray(q, dtype=float)
    flat = np.ascontiguousarray(arr.reshape(-1, 6))
    out = np.empty(len(flat))
    kernels.manipulability_rows(_opw_params(pa), flat, out)
    return out.reshape(arr.shape[:-1])


def arm_manipulability(arm: Arm, q: ArrayLike) -> NDArray[np.float64]:
    """``|det J|`` of an ortho-parallel ``arm`` at controller values ``q`` (..., 6) (m^3).

    The closed form of :func:`manipulability` on the model's joint values; for an arm with a
    joint coupling ``q_model = C q + offset`` (square ``C``) it is multiplied by ``|det C|``
    (``J = J_model C``). Equal to ``|det arm.jacobian(q)|``.
    """
    pa = analytic_solver(arm).params
    c = arm.coupling
    if c is None:
        return manipulability(pa, q)
    if c.matrix.shape[0] != c.matrix.shape[1]:  # passive joints: no closed form here
        return np.abs(np.linalg.det(arm.jacobian(np.nan_to_num(q))))
    return manipulability(pa, c.to_model(q)) * abs(float(np.linalg.det(c.matrix)))


def _best_valid(arm: Arm, q: NDArray[np.float64], valid: NDArray[np.bool_]) -> NDArray[np.float64]:
    """``|det J|`` of the best valid branch of track solutions ``q`` (N, 8, 7), ``valid`` (N, 8)
    (0 if none). The two wrists of an arm configuration (branches ``2k``, ``2k + 1``) have the
    same value."""
    if arm.coupling is None:
        s = _closed_form(arm)
        out = np.empty(q.shape[0])
        s._kernels.best_valid_rows(s._kernels.cfg_params(s._cfg), np.ascontiguousarray(q[..., 1:]),
                                   valid, out)
        return out
    either = valid[..., ::2] | valid[..., 1::2]
    m = np.nan_to_num(arm_manipulability(arm, q[..., ::2, 1:]))
    return np.where(either, m, 0.0).max(axis=-1)


def _solve_at(track: TrackRobot, T: NDArray[np.float64], x: NDArray[np.float64],
              tool: ArrayLike | None) -> IKSolutions:
    """:meth:`TrackRobot.ik_at` for validated targets (N, 4, 4) and values (N,) in the limits."""
    T_R = T.copy()  # T_R_TCP = T_L_R(x)^-1 T_L_TCP: the base only translates along u
    Q = track.T_L_R0[:3, :3]
    T_R[:, :3, :3] = Q.T @ T[:, :3, :3]
    T_R[:, :3, 3] = (T[:, :3, 3] - track.T_L_R0[:3, 3] - x[:, None] * track.direction) @ Q
    sol = analytic_solver(track.arm).solve(T_R, tool)
    xcol = np.broadcast_to(x[:, None, None], sol.q.shape[:-1] + (1,))
    return IKSolutions(np.concatenate([xcol, sol.q], axis=-1), sol.valid, sol.reachable,
                       sol.method, sol.reach_error)
