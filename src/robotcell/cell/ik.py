"""Coupled inverse kinematics of a cell: targets in any frame, through the track and the table.

A target ``T_X_TCP`` in a frame X of the cell (world, the track L, the robot base R, the table
root B or a frame of the cell, e.g. a workpiece W on the turntable) at table angle ``theta``
becomes a target of the arm with

    T_world_TCP = T_world_X(e, theta) T_X_TCP,      T_R_TCP = T_world_R(e)^-1 T_world_TCP,

(:mod:`robotcell.cell.kinematics` for ``T_world_X``). The track position ``e`` is given, or chosen: the
value within the track limits where the arm reaches the target with the largest manipulability
(:func:`choose_track_value`: closed form for an ortho-parallel arm, see
:mod:`robotcell.ik.trackchoice`). Then every analytic branch of the arm is returned.

:func:`ik_path` solves a sequence of targets (e.g. the TCP holding a point of a workpiece while
the table turns) as one continuous joint trajectory: it keeps one analytic branch (one arm
configuration: shoulder, elbow, wrist) along the whole path, unwraps the revolute joints so that
no joint jumps by a turn, fits the whole trajectory inside the joint limits, and refuses a path
on which every configuration would flip (cross a singularity) or leave the limits, naming where
and why. Vectorised over the path: one batched IK call per candidate track value. With
``track_motion="moving"`` the track follows the path smoothly instead of standing still, and
:func:`split_path` cuts a path that cannot be followed in one piece into continuous segments,
naming each break (out of reach, a joint limit, a singularity, a jump of the table's values).
:mod:`robotcell.cell.tablechoice` chooses the table's values along a path in a frame it carries.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell.kinematics import (
    RESERVED_FRAMES,
    broadcast_table,
    frame_pose,
    robot_pose,
    table_batch,
    table_values,
    tool_pose,
)
from robotcell.cell.kinematics import CellModel as Cell  # what is read of a robotcell.cell.Cell
from robotcell.errors import InputError
from robotcell.ik.analytic import analytic_solver
from robotcell.ik.limits import TWO_PI
from robotcell.ik.result import IKSolutions
from robotcell.ik.select import nearest
from robotcell.ik.track import TrackChoice, TrackRobot
from robotcell.ik.trackchoice import choose_track, scan_track
from robotcell.kinematics.bounds import LIMIT_TOL, within
from robotcell.kinematics.transforms import (
    finite_array,
    invert,
    validate_pose,
    validate_single_pose,
)
from robotcell.robot.robot import Robot

__all__ = ["CellIKSolutions", "CellPath", "PathBreak", "PathSplit", "choose_track_value",
           "depends_on_track", "ik", "ik_path", "split_path"]

#: Largest joint change between two consecutive targets of a path that still counts as
#: continuous (rad). A configuration that passes a singularity (wrist flip, stretched elbow)
#: turns a joint by about pi in one step; paths sampled more finely than this stay below it.
MAX_STEP = math.radians(30.0)

#: Names of the arm configurations of the 8 analytic branches (branch k = 4 * shoulder +
#: 2 * elbow + wrist, see docs/ik.md).
BRANCH_NAMES = tuple(f"branch {k} (shoulder {k >> 2}, elbow {(k >> 1) & 1}, wrist {k & 1})"
                     for k in range(8))


@dataclass(frozen=True)
class CellIKSolutions:
    """All arm solutions of a batch of cell targets.

    Attributes
    ----------
    q : ndarray, shape (..., 8, n)
        Arm joint values of the 8 analytic branches (rad; NaN where a branch does not reach).
    valid : ndarray of bool, shape (..., 8)
        Branch reaches the target within the arm's joint limits, with track position and table
        angle within their limits.
    reachable : ndarray of bool, shape (..., 8)
        Branch reaches the target (no limits considered).
    track : ndarray, shape (...)
        Track position of the solutions (m; 0 in a cell without track), given or chosen.
    table : ndarray, shape (...)
        Table angle of the solutions (rad; 0 in a cell without turntable).
    method : str
        Analytic method of the arm (``"opw"`` or ``"ur"``).
    reach_error : ndarray, shape (..., 8), optional
        Distance (m) by which the target lies outside the branch's reach, as
        :attr:`robotcell.ik.IKSolutions.reach_error`: 0 inside up to rounding; up to
        :data:`robotcell.ik.result.REACH_TOL` (1 um) a rounded target is solved at the boundary
        of the reach (``reachable`` True) and its TCP misses the target by this distance. None
        when the arm's solver gives no distance.
    """

    q: NDArray[np.float64]
    valid: NDArray[np.bool_]
    reachable: NDArray[np.bool_]
    track: NDArray[np.float64]
    table: NDArray[np.float64]
    method: str
    reach_error: NDArray[np.float64] | None = None

    @property
    def count(self) -> NDArray[np.int_]:
        """Number of valid branches per target, shape ``(...)``."""
        return np.count_nonzero(self.valid, axis=-1)

    @classmethod
    def concatenate(cls, parts: list[CellIKSolutions], table_shape: tuple[int, ...] = ()
                    ) -> CellIKSolutions:
        """The solutions of consecutive batches ``(m_i,)`` of targets as one batch ``(sum m_i,)``.

        Parameters
        ----------
        parts : list of CellIKSolutions
            Solutions of 1-D batches, in order (at least one).
        table_shape : tuple of int
            Trailing shape of one target's table values: ``()`` for a turntable or none,
            ``(n,)`` for a positioner of ``n`` axes.
        """
        def cat(key: str, tail: tuple[int, ...] = ()) -> NDArray:
            return np.concatenate([np.broadcast_to(getattr(p, key), p.valid.shape[:-1] + tail)
                                   for p in parts])

        err = (None if any(p.reach_error is None for p in parts)
               else np.concatenate([p.reach_error for p in parts]))
        return cls(np.concatenate([p.q for p in parts]), np.concatenate([p.valid for p in parts]),
                   np.concatenate([p.reachable for p in parts]), cat("track"),
                   cat("table", table_shape), parts[0].method, err)

    def nearest(self, robot: Robot, q_ref: ArrayLike
                ) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.int_]]:
        """The valid branch nearest to a reference arm configuration, per target.

        Parameters
        ----------
        robot : Robot
            The cell's arm (its limits and joint types).
        q_ref : array_like, shape (n,) or (..., n)
            Reference arm configuration (rad, m).

        Returns
        -------
        q : ndarray, shape (..., n)
            Chosen arm configuration (NaN where none is valid).
        found : ndarray of bool, shape (...)
        branch : ndarray of int, shape (...)
            The chosen branch, -1 where none (see :func:`robotcell.ik.nearest`).
        """
        return nearest(robot, IKSolutions(self.q, self.valid, self.reachable, self.method), q_ref)


@dataclass(frozen=True)
class CellPath:
    """A continuous joint trajectory through a sequence of cell targets.

    Attributes
    ----------
    q : ndarray, shape (N, n)
        Arm joint values along the path (rad), in one configuration, unwrapped and inside the
        joint limits.
    track : ndarray, shape (N,)
        Track position along the path (m).
    table : ndarray, shape (N,)
        Table angle along the path (rad).
    branch : int
        Analytic branch followed (``4 * shoulder + 2 * elbow + wrist``).
    max_step : float
        Largest change of any arm joint between consecutive targets (rad).
    manipulability : float
        Smallest ``|det J|`` of the arm along the path (m^3 for a 6-axis arm): how far the path
        stays from singular configurations.
    """

    q: NDArray[np.float64]
    track: NDArray[np.float64]
    table: NDArray[np.float64]
    branch: int
    max_step: float
    manipulability: float


def depends_on_track(cell: Cell, frame: str) -> bool:
    """Whether frame ``frame`` of the cell moves with the track (is carried by the robot base).

    Parameters
    ----------
    cell : Cell
    frame : str
        A frame name accepted by :func:`robotcell.cell.kinematics.frame_pose`.

    Returns
    -------
    bool
        True for the robot base, for frames fixed to it, and for the turntable and its frames
        when the turntable stands on the robot's carriage.
    """
    kind = RESERVED_FRAMES.get(frame)
    table_on_robot = cell.turntable is not None and cell.turntable.parent == "robot"
    if kind == "R":
        return True
    if kind == "B":
        return table_on_robot
    if kind is not None or frame not in cell.frames:
        return False
    parent = cell.frames[frame].parent
    return parent == "robot" or (parent == "turntable" and table_on_robot)


def _batch(*shapes: tuple[int, ...]) -> tuple[int, ...]:
    """``np.broadcast_shapes``, without its cost when the shapes are equal (one target)."""
    return shapes[0] if all(sh == shapes[0] for sh in shapes) else np.broadcast_shapes(*shapes)


def _limits_ok(cell: Cell, e: NDArray[np.float64], th: NDArray[np.float64]) -> NDArray[np.bool_]:
    ok: NDArray[np.bool_] | bool = True
    if cell.track is not None:
        ok = ok & cell.track.within_limits(e)
    if cell.turntable is not None:
        ok = ok & cell.turntable.within_limits(th)
    shape = _batch(e.shape, table_batch(cell, th))
    return np.asarray(ok) if np.shape(ok) == shape else np.broadcast_to(ok, shape)


def _track_robot(cell: Cell) -> TrackRobot:
    return _track_setup(cell)[0]


#: ``(key, (TrackRobot, T_L_world))`` of the last cell track: what they were built from, and them
#: (a loop of single targets builds them once; a changed track or robot builds them anew).
_LAST_TRACK: list = [(None, None)]


def _track_setup(cell: Cell) -> tuple[TrackRobot, NDArray[np.float64]]:
    """The cell's arm on its track as a :class:`TrackRobot` (track values in metres of motion)
    and ``T_L_world``."""
    t = cell.track
    assert t is not None
    if not (math.isfinite(t.lower) and math.isfinite(t.upper)):
        raise InputError("choosing the track position needs the track limits (min, max) in the "
                         "cell file; or give the track position")
    key = (cell.robot, t.T_L_R0.tobytes(), t.T_world_L.tobytes(), t.axis, t.scale, t.lower,
           t.upper, t.name)
    last = _LAST_TRACK[0]  # one read: another thread may replace it
    if last[0] != key:
        robot = TrackRobot(cell.robot, t.T_L_R0, t.direction, t.lower * t.scale,
                           t.upper * t.scale, t.name)
        last = _LAST_TRACK[0] = (key, (robot, invert(t.T_world_L)))
    return last[1]


def _check_track_choice(cell: Cell, frame: str) -> None:
    if depends_on_track(cell, frame):
        raise InputError(f"frame {frame!r} moves with the track, so a target in it does not "
                         "fix the track position; give the track position")


def choose_track_value(track: TrackRobot, T_L: NDArray[np.float64], tool: ArrayLike | None,
                       samples: int | None = None, prefer: ArrayLike | None = None
                       ) -> TrackChoice:
    """Track value per target and the arm's solutions there, vectorised over targets.

    For an ortho-parallel arm: :func:`robotcell.ik.trackchoice.choose_track` (closed-form
    interval of the track value, closed-form manipulability scanned inside it, one analytic
    solve; under 10 us per target in batches, docs/performance.md). Other arms (UR type): the
    sampled search of :meth:`robotcell.ik.TrackRobot.ik` (``prefer`` is ignored there).

    Parameters
    ----------
    track : TrackRobot
    T_L : ndarray, shape (..., 4, 4)
        Targets ``T_L_TCP`` in the track frame (m).
    tool : array_like, shape (4, 4), optional
        ``T_F_TCP`` (m).
    samples : int, optional
        Track values per search stage (default 24, or 65 for the sampled search).
    prefer : array_like, shape (...), optional
        Preferred track values (m; e.g. the previous target's on a path).

    Returns
    -------
    TrackChoice
        Track values in metres of motion (divide by the track's scale for controller values).
    """
    if analytic_solver(track.arm).method == "opw":
        return choose_track(track, T_L, tool=tool, samples=samples or 24, prefer=prefer)
    return track.ik(T_L, samples=samples or 65, tool=tool)


def ik(cell: Cell, T: ArrayLike, frame: str = "world", track: ArrayLike | None = None,
       table: ArrayLike = 0.0, tool: str | ArrayLike | None = None,
       samples: int | None = None) -> CellIKSolutions:
    """Every arm solution for TCP targets given in a frame of the cell.

    Parameters
    ----------
    cell : Cell
    T : array_like, shape (..., 4, 4)
        Targets ``T_X_TCP`` in frame ``frame`` (m).
    frame : str
        ``world``, ``track``/``L``, ``robot``/``R``, ``turntable``/``B`` or a frame of the cell.
    track : array_like, shape (...), optional
        Track position (m). Default: 0 without a track; with a track, chosen per target where
        the arm reaches it with the largest manipulability (needs the track limits; refused for
        frames that move with the track; see :func:`choose_track_value`).
    table : array_like, shape (...) or (..., n)
        Table angle (rad) at which the target is given, or a positioner's axis values; must be
        0 without turntable.
    tool : str or array_like of shape (4, 4), optional
        A tool of the cell by name, or ``T_F_TCP`` (m); default: the robot model's tool.
    samples : int, optional
        Track values per search stage when the track position is chosen (default 24 for the
        closed-form scan of an ortho-parallel arm, 65 for the sampled search of other arms).

    Returns
    -------
    CellIKSolutions
        ``q`` of shape ``(..., 8, n)`` with the broadcast batch shape of ``T``, ``track`` and
        ``table``.

    Raises
    ------
    InputError
        Unknown frame or tool, a table angle or track position for a cell without one, a track
        choice for a frame that moves with the track, an arm without analytic IK.

    Examples
    --------
    >>> sol = cell.ik(T_W_TCP, frame="part", table=np.radians(90), tool="torch")  # doctest: +SKIP
    >>> sol.q[sol.valid]                                                          # doctest: +SKIP
    """
    arr = (validate_single_pose(T, "target pose") if type(T) is np.ndarray and T.shape == (4, 4)
           else validate_pose(T, "target pose"))
    th = table_values(cell, table)
    T_tool = tool_pose(cell, tool)
    if track is None and cell.track is not None:
        _check_track_choice(cell, frame)
        batch = _batch(arr.shape[:-2], table_batch(cell, th))
        # (in the world frame the frame pose is the identity: the product would be arr itself)
        T_world = arr if frame == "world" else frame_pose(cell, frame, 0.0, th) @ arr
        if T_world.shape[:-2] != batch:
            T_world = np.broadcast_to(T_world, batch + (4, 4))
        trk, T_L_world = _track_setup(cell)
        choice = choose_track_value(trk, T_L_world @ T_world, T_tool, samples)
        e = choice.track / cell.track.scale
        q = choice.solutions.q[..., 1:]
        valid, reachable = choice.solutions.valid, choice.solutions.reachable
        method, reach_error = choice.solutions.method, choice.solutions.reach_error
    else:
        e = finite_array(0.0 if track is None else track, "track position")
        batch = _batch(arr.shape[:-2], table_batch(cell, th), e.shape)
        if e.shape != batch:
            e = np.broadcast_to(e, batch)
        T_world = arr if frame == "world" else frame_pose(cell, frame, e, th) @ arr
        sol = cell.robot.ik(invert(robot_pose(cell, e)) @ T_world, tool=T_tool)
        q, valid, reachable, method = sol.q, sol.valid, sol.reachable, sol.method
        reach_error = sol.reach_error
    th = broadcast_table(cell, th, batch)
    valid = valid & _limits_ok(cell, e, th)[..., None]
    return CellIKSolutions(q, valid, reachable, np.array(e, dtype=float), np.array(th), method,
                           None if reach_error is None else np.array(reach_error, dtype=float))


def _path_inputs(cell: Cell, T: ArrayLike, table: ArrayLike, track: ArrayLike | None
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64] | None]:
    arr = validate_pose(T, "path targets")
    th = table_values(cell, table)
    e = None if track is None else finite_array(track, "track position")
    shapes = [arr.shape[:-2], table_batch(cell, th)] + ([] if e is None else [e.shape])
    try:
        batch = np.broadcast_shapes(*shapes)
    except ValueError:
        raise InputError(f"path targets, table angles and track positions must have matching "
                         f"lengths, got shapes {', '.join(map(str, shapes))}") from None
    if len(batch) != 1 or batch[0] < 2:
        raise InputError(f"a path needs a sequence of at least 2 targets (shape (N, 4, 4) or a "
                         f"sequence of table angles), got batch shape {batch}")
    arr = np.broadcast_to(arr, batch + (4, 4))
    th = broadcast_table(cell, th, batch)
    return arr, th, None if e is None else np.broadcast_to(e, batch)


def _unwrapped(robot_rev: NDArray[np.bool_], q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Revolute columns of ``q`` (K, N, 8, n) unwrapped along the path axis (1)."""
    out = q.copy()
    out[..., robot_rev] = np.unwrap(q[..., robot_rev], axis=1)
    return out


def _fit_limits(q: NDArray[np.float64], rev: NDArray[np.bool_], lo: NDArray[np.float64],
                hi: NDArray[np.float64], ref: NDArray[np.float64] | None
                ) -> NDArray[np.float64]:
    """Shift each revolute column of ``q`` (K, N, 8, n) by a whole number of turns.

    The shift puts the trajectory inside ``[lo, hi]`` when a turn count does so; among those it
    takes the one nearest to ``ref`` (n,) for the first point, or else the smallest shift of the
    first point's principal value.
    """
    with warnings.catch_warnings():  # a branch that reaches no target is all NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        qmin, qmax = np.nanmin(q, axis=1), np.nanmax(q, axis=1)  # (K, 8, n)
    kmin = np.ceil((lo - LIMIT_TOL - qmin) / TWO_PI)   # smallest turn count with min >= lo
    kmax = np.floor((hi + LIMIT_TOL - qmax) / TWO_PI)  # largest with max <= hi
    start = q[:, 0]
    target = start if ref is None else np.broadcast_to(ref, start.shape)
    want = np.round((target - start) / TWO_PI)
    with np.errstate(invalid="ignore"):
        k = np.clip(want, kmin, np.maximum(kmin, kmax))
    k = np.where(np.isfinite(k), k, 0.0)
    return q + np.where(rev, k, 0.0)[:, None] * TWO_PI


#: Track motions of :func:`ik_path`.
TRACK_MOTIONS = ("fixed", "moving")

#: Targets of the moving average that smooths a moving track (:func:`ik_path`).
TRACK_WINDOW = 9

#: A moving track stays, at each target, where the arm has at least this fraction of the best
#: manipulability it has there over the track.
TRACK_KEEP = 0.5


@dataclass(frozen=True)
class PathBreak:
    """A place where a path must break.

    Attributes
    ----------
    index : int
        Target (0-based) that no configuration of the preceding segment reaches continuously.
    kind : str
        ``"reach"`` (out of reach, or track/table outside its limits), ``"limit"`` (an arm axis
        leaves its limits), ``"singularity"`` (the configuration flips: an axis jumps by more
        than ``max_step``) or ``"table"`` (the table's values jump by more than ``max_step``).
    message : str
        The cause in words, naming the branch and the axis (degrees).
    """

    index: int
    kind: str
    message: str


@dataclass(frozen=True)
class PathSplit:
    """A path cut into segments that each can be followed continuously.

    Attributes
    ----------
    segments : list of (int, int)
        ``(start, stop)`` target ranges (Python slices, 0-based): each is one continuous
        trajectory (solve it with :func:`ik_path` on ``T[start:stop]``).
    breaks : list of PathBreak
        Where and why the path breaks, in order.
    track : ndarray, shape (N,)
        Track position used at each target of a segment (m; 0 without track; NaN at a target
        no configuration reaches).
    """

    segments: list[tuple[int, int]]
    breaks: list[PathBreak]
    track: NDArray[np.float64]


@dataclass(frozen=True)
class _PathSolutions:
    """Every branch along a path, for K track candidates: arrays (K, N, 8[, n])."""

    q: NDArray[np.float64]
    reach: NDArray[np.bool_]
    inside: NDArray[np.bool_]
    smooth: NDArray[np.bool_]
    ee: NDArray[np.float64]  # (K, N) track positions
    turn: NDArray[np.float64]  # (N,) largest table axis change from the previous target (rad)

    @property
    def ok(self) -> NDArray[np.bool_]:
        return self.reach & self.inside & self.smooth


def _moving_track(cell: Cell, frame: str, arr: NDArray[np.float64], th: NDArray[np.float64],
                  T_tool: NDArray[np.float64] | None, samples: int) -> NDArray[np.float64]:
    """A smooth track trajectory (N,) (m) along a path: the moving average of the per-target
    choice over :data:`TRACK_WINDOW` targets, kept where the arm has at least
    :data:`TRACK_KEEP` of its best manipulability at each target."""
    from scipy.ndimage import uniform_filter1d

    t = _track_robot(cell)
    T_L = invert(cell.track.T_world_L) @ frame_pose(cell, frame, 0.0, th) @ arr
    choice = choose_track_value(t, T_L, T_tool, max(samples, 3))
    x = choice.track
    found = choice.solutions.valid.any(axis=-1)
    if np.any(found) and not np.all(found):  # bridge unreachable targets from their neighbours
        idx = np.arange(x.size)
        x = np.interp(idx, idx[found], x[found])
    if analytic_solver(t.arm).method == "opw":
        scan = scan_track(t, T_L, T_tool, max(samples, 3))
        m = scan.manipulability
        keep = m >= TRACK_KEEP * m.max(axis=1, keepdims=True)
        keep &= m > 0
        lo = np.where(keep, scan.x, np.inf).min(axis=1)
        hi = np.where(keep, scan.x, -np.inf).max(axis=1)
        lo, hi = np.minimum(lo, x), np.maximum(hi, x)
    else:
        lo = hi = x
    smooth = uniform_filter1d(x, size=min(TRACK_WINDOW, x.size), mode="nearest")
    return np.clip(smooth, lo, hi) / cell.track.scale


def _path_solutions(cell: Cell, frame: str, arr: NDArray[np.float64], th: NDArray[np.float64],
                    ee: NDArray[np.float64], T_tool: NDArray[np.float64] | None,
                    q_start: NDArray[np.float64] | None, max_step: float) -> _PathSolutions:
    """Every branch along the path for track trajectories ``ee`` (K, N): unwrapped, shifted by
    whole turns into the limits (one turn count per joint for the whole path), and checked."""
    robot = cell.robot
    T_world = frame_pose(cell, frame, ee, th) @ arr
    sol = robot.ik(invert(robot_pose(cell, ee)) @ T_world, tool=T_tool)  # (K, N, 8, n)
    rev = ~robot.prismatic
    q = _fit_limits(_unwrapped(rev, sol.q), rev, robot.lower, robot.upper, q_start)
    reach = sol.reachable & _limits_ok(cell, ee, th)[..., None]             # (K, N, 8)
    inside = robot._inside(q)  # (K, N, 8); interaction limits (e.g. FANUC J2/J3) too
    step = np.max(np.abs(np.diff(q, axis=1)), axis=-1)                      # (K, N-1, 8)
    first = np.ones((step.shape[0], 1, step.shape[2]), dtype=bool)
    turn = np.abs(np.diff(th, axis=0, prepend=th[:1])).reshape(th.shape[0], -1).max(axis=1)
    smooth = np.concatenate([first, step <= max_step], axis=1) & (turn <= max_step)[:, None]
    return _PathSolutions(q, reach, inside, smooth, ee, turn)


def _path_setup(cell: Cell, T: ArrayLike, frame: str, track: ArrayLike | None, table: ArrayLike,
                tool: str | ArrayLike | None, q_start: ArrayLike | None, max_step: float,
                samples: int, track_motion: str):
    """Validated inputs of a path and its track candidates ``ee`` (K, N)."""
    arr, th, e = _path_inputs(cell, T, table, track)
    n_pts = arr.shape[0]
    T_tool = tool_pose(cell, tool)
    robot = cell.robot
    if robot.n_joints != 6:
        raise InputError(f"path IK needs a six-axis arm (8 branches); {robot.name} has "
                         f"{robot.n_joints} axes: use cell.ik for its solutions")
    if q_start is not None:
        q_start = finite_array(q_start, "q_start")
        if q_start.shape != (robot.n_joints,):
            raise InputError(f"q_start must be one configuration of shape ({robot.n_joints},), "
                             f"got {q_start.shape}")
    if not max_step > 0:
        raise InputError(f"max_step must be positive (rad), got {max_step}")
    if track_motion not in TRACK_MOTIONS:
        raise InputError(f"track_motion must be one of {', '.join(TRACK_MOTIONS)}, "
                         f"got {track_motion!r}")
    chosen = e is None and cell.track is not None
    if chosen:
        _check_track_choice(cell, frame)
        if samples < 2:
            raise InputError(f"samples must be at least 2, got {samples}")
        if track_motion == "moving":
            ee = _moving_track(cell, frame, arr, th, T_tool, samples)[None, :]
        else:
            t = _track_robot(cell)
            cand = np.linspace(t.lower, t.upper, samples) / cell.track.scale
            ee = np.broadcast_to(cand[:, None], (cand.size, n_pts))
    else:
        ee = np.zeros((1, n_pts)) if e is None else np.array(e, dtype=float)[None, :]
    return arr, th, ee, T_tool, q_start, chosen


def ik_path(cell: Cell, T: ArrayLike, frame: str = "world", track: ArrayLike | None = None,
            table: ArrayLike = 0.0, tool: str | ArrayLike | None = None,
            q_start: ArrayLike | None = None, max_step: float = MAX_STEP,
            samples: int = 33, track_motion: str = "fixed") -> CellPath:
    """A continuous joint trajectory through a sequence of targets, with no configuration flip.

    The targets are solved together for every branch; a branch is kept when it reaches every
    target, its unwrapped trajectory fits the joint limits (shifted by whole turns where a joint
    has more than one turn of range; one turn count per joint for the whole path), and no joint
    (nor a table axis) moves more than ``max_step`` between two consecutive targets. Among the
    kept branches the one nearest to ``q_start`` at the first target wins, or else the one with
    the largest smallest manipulability along the path.

    Parameters
    ----------
    cell : Cell
    T : array_like, shape (N, 4, 4) or (4, 4)
        Targets ``T_X_TCP`` in frame ``frame`` (m); one pose is held while the table turns.
    frame : str
        Frame of the targets (see :func:`ik`).
    track : array_like, shape (N,) or (), optional
        Track positions (m). Default: 0 without a track; with a track, chosen (see
        ``track_motion``).
    table : array_like, shape (N,) or ()
        Table angles (rad) at the targets.
    tool : str or array_like of shape (4, 4), optional
        A tool of the cell by name, or ``T_F_TCP`` (m).
    q_start : array_like, shape (n,), optional
        Current arm configuration (rad): the path starts in the configuration nearest to it.
    max_step : float
        Largest change of an arm or table axis between consecutive targets (rad); sample the
        path more finely when the motion between targets is larger.
    samples : int
        Candidate track positions when the track position is chosen (>= 2).
    track_motion : {"fixed", "moving"}
        How a chosen track position moves: ``fixed``, one position for the whole path, chosen
        on ``samples`` values over the track limits to maximise the smallest manipulability
        along the path; ``moving``, the track follows the path smoothly: the per-target choice
        of :func:`choose_track_value`, averaged over :data:`TRACK_WINDOW` consecutive targets
        and kept where the arm has at least :data:`TRACK_KEEP` of its best manipulability.

    Returns
    -------
    CellPath

    Raises
    ------
    InputError
        Fewer than 2 targets, mismatched lengths, or no branch that follows the whole path; the
        message gives, per branch, the first target where it fails and why
        (:func:`split_path` cuts such a path into segments instead).
    """
    arr, th, ee, T_tool, q_start, chosen = _path_setup(cell, T, frame, track, table, tool,
                                                       q_start, max_step, samples, track_motion)
    robot = cell.robot
    ps = _path_solutions(cell, frame, arr, th, ee, T_tool, q_start, max_step)
    q = ps.q
    feasible = np.all(ps.ok, axis=1)                                        # (K, 8)
    if not np.any(feasible):
        raise InputError(_path_failure(ps, robot, chosen and track_motion == "fixed"))
    qz = np.where(feasible[:, None, :, None], q, 0.0)
    manip = np.abs(np.linalg.det(robot.jacobian(qz, tool=T_tool)))          # (K, N, 8)
    worst = np.where(feasible, manip.min(axis=1), -np.inf)                  # (K, 8)
    if q_start is not None:
        d = np.sum((q[:, 0] - q_start) ** 2, axis=-1)                       # (K, 8)
    else:
        # Within 1 % of the best manipulability (a wrist flip has the same), the trajectory
        # with the smallest joint values: the one an operator expects.
        d = np.where(worst >= 0.99 * worst.max(), np.mean(np.sum(qz**2, axis=-1), axis=1), np.inf)
    score = np.where(feasible, -d, -np.inf)
    k, b = np.unravel_index(np.argmax(score), score.shape)
    qp = q[k, :, b]
    return CellPath(q=qp, track=np.array(ee[k], dtype=float), table=np.array(th, dtype=float),
                    branch=int(b), max_step=float(np.max(np.abs(np.diff(qp, axis=0)))),
                    manipulability=float(worst[k, b]))


def split_path(cell: Cell, T: ArrayLike, frame: str = "world", track: ArrayLike | None = None,
               table: ArrayLike = 0.0, tool: str | ArrayLike | None = None,
               max_step: float = MAX_STEP, samples: int = 33,
               track_motion: str = "moving") -> PathSplit:
    """Cut a path into the fewest continuous segments, greedily, and say where and why it breaks.

    From the first target, the branch and track candidate that follow the path furthest (as
    :func:`ik_path` checks it: reach, joint limits with one turn count per segment, no arm or
    table axis step above ``max_step``) make a segment; the target where that branch fails starts the
    next one, or is skipped when no branch reaches it at all.

    Parameters
    ----------
    cell, T, frame, track, table, tool, max_step, samples
        As for :func:`ik_path`.
    track_motion : {"fixed", "moving"}
        As for :func:`ik_path`; here the default is ``moving``.

    Returns
    -------
    PathSplit
    """
    arr, th, ee, T_tool, _, _ = _path_setup(cell, T, frame, track, table, tool, None,
                                            max_step, samples, track_motion)
    robot = cell.robot
    n_pts = arr.shape[0]
    segments: list[tuple[int, int]] = []
    breaks: list[PathBreak] = []
    used = np.full(n_pts, np.nan)
    start = 0
    while start < n_pts:
        ps = _path_solutions(cell, frame, arr[start:], th[start:], ee[:, start:], T_tool, None,
                             max_step)
        ok = ps.ok
        run = np.where(np.all(ok, axis=1), ok.shape[1], np.argmin(ok, axis=1))  # (K, 8)
        k, b = np.unravel_index(np.argmax(run), run.shape)
        length = int(run[k, b])
        if length == 0:  # no configuration reaches this target within the limits
            gap = _break(ps, robot, int(k), int(b), 0, start, max_step)
            if breaks and breaks[-1].index == start:  # the previous segment ended here
                breaks[-1] = gap
            else:
                breaks.append(gap)
            start += 1
            continue
        segments.append((start, start + length))
        used[start:start + length] = ee[k, start:start + length]
        if start + length < n_pts:
            breaks.append(_break(ps, robot, int(k), int(b), length, start, max_step))
        start += length
    return PathSplit(segments, breaks, used)


def _break(ps: _PathSolutions, robot: Robot, k: int, b: int, i: int, offset: int,
           max_step: float) -> PathBreak:
    """Why the path breaks at index ``i`` after following branch ``b`` (candidate ``k``).

    ``reach`` when no configuration reaches the target; ``limit`` when every configuration that
    reaches it is outside the joint limits; else ``singularity``: the target is reached, but only
    in a configuration that is not continuous with the previous one (a flip).
    """
    where = f"target {offset + i + 1}"
    usable = ps.reach[k, i] & ps.inside[k, i]
    if not ps.reach[k, i].any():
        return PathBreak(offset + i, "reach", f"{where}: out of reach (or track/table outside "
                         "its limits) in every configuration")
    if ps.turn[i] > max_step:
        return PathBreak(offset + i, "table", f"{where}: {_table_turn(ps, i)}")
    if not usable.any():
        why = _failure_cause(ps, robot, k, int(np.argmax(ps.reach[k, i])), i)[1]
        return PathBreak(offset + i, "limit", f"{where}: every configuration that reaches it "
                         f"is outside the limits, e.g. {why}")
    jump = np.where(usable[:, None], np.abs(ps.q[k, i] - ps.q[k, i - 1, b]), np.inf)  # (8, n)
    b2, j = np.unravel_index(np.argmin(jump.max(axis=1)), (8, 1))
    j = int(np.argmax(jump[b2]))
    step = float(jump[b2, j])
    how = (f"axis {j + 1} would jump by {math.degrees(step):.0f} deg (a flip)" if step > max_step
           else "the arm changes configuration through a singular one (det J = 0)")
    cause = f"{where}: {BRANCH_NAMES[b]}: {_failure_cause(ps, robot, k, b, i)[1]}"
    if b2 == b:  # the same configuration is the nearest: no other one continues
        return PathBreak(offset + i, "singularity", f"{cause}; no other configuration reaches "
                         f"it nearer to target {offset + i}")
    return PathBreak(offset + i, "singularity",
                     f"{cause}; the target is reached in {BRANCH_NAMES[b2]}, but {how}")


def _failure_cause(ps: _PathSolutions, robot: Robot, k: int, b: int, i: int) -> tuple[str, str]:
    """Kind and words of the failure of branch ``b`` (candidate ``k``) at path index ``i``."""
    qi = ps.q[k, i, b]
    if not ps.reach[k, i, b]:
        return "reach", "out of reach (or track/table outside its limits)"
    if not ps.inside[k, i, b]:
        j = int(np.argmax(~within(qi, robot.lower, robot.upper)))
        return "limit", f"axis {j + 1} leaves its limits ({math.degrees(qi[j]):.1f} deg)"
    if i > 0 and not ps.smooth[k, i, b] and ps.turn[i] > np.max(np.abs(qi - ps.q[k, i - 1, b])):
        return "table", _table_turn(ps, i)
    j = int(np.argmax(np.abs(qi - ps.q[k, i - 1, b])))
    jump = math.degrees(abs(qi[j] - ps.q[k, i - 1, b, j]))
    return "singularity", (f"axis {j + 1} jumps by {jump:.0f} deg (the configuration passes a "
                           "singularity)")


def _table_turn(ps: _PathSolutions, i: int) -> str:
    return (f"the table turns by {math.degrees(ps.turn[i]):.0f} deg from the previous target "
            "(a jump, not a continuous motion)")


def _path_failure(ps: _PathSolutions, robot: Robot, track_chosen: bool) -> str:
    """Why no branch follows the path: the first failing target per branch (best track value)."""
    ok = ps.ok
    first_fail = np.where(np.all(ok, axis=1), ok.shape[1], np.argmin(ok, axis=1))  # (K, 8)
    k = int(np.argmax(first_fail.max(axis=1)))  # the track candidate where branches get furthest
    lines = []
    for b in range(8):
        i = int(first_fail[k, b])
        lines.append(f"{BRANCH_NAMES[b]}: target {i + 1}: {_failure_cause(ps, robot, k, b, i)[1]}")
    where = " at the best track position" if track_chosen else ""
    return ("no arm configuration follows the whole path without a flip" + where + "; "
            + "; ".join(lines) + ". Move the path towards the middle of the arm's reach, choose "
            "another track position or table range, or sample the path more finely")
