"""Coupled inverse kinematics of a cell: targets in any frame, through the track and the table.

A target ``T_X_TCP`` in a frame X of the cell (world, the track L, the robot base R, the table
root B or a frame of the cell, e.g. a workpiece W on the turntable) at table angle ``theta``
becomes a target of the arm with

    T_world_TCP = T_world_X(e, theta) T_X_TCP,      T_R_TCP = T_world_R(e)^-1 T_world_TCP,

(:mod:`robotcell.coupled` for ``T_world_X``). The track position ``e`` is given, or chosen: the
value within the track limits where the arm reaches the target with the largest manipulability
(:meth:`robotcell.ik.TrackRobot.ik`). Then every analytic branch of the arm is returned.

:func:`ik_path` solves a sequence of targets (e.g. the TCP holding a point of a workpiece while
the table turns) as one continuous joint trajectory: it keeps one analytic branch (one arm
configuration: shoulder, elbow, wrist) along the whole path, unwraps the revolute joints so that
no joint jumps by a turn, fits the whole trajectory inside the joint limits, and refuses a path
on which every configuration would flip (cross a singularity) or leave the limits, naming where
and why. Vectorised over the path: one batched IK call per candidate track value.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.coupled import (
    RESERVED_FRAMES,
    broadcast_table,
    frame_pose,
    robot_pose,
    table_batch,
    table_values,
    tool_pose,
)
from robotcell.coupled import CellModel as Cell  # what is read of a robotcell.cell.Cell
from robotcell.errors import InputError
from robotcell.ik.limits import TWO_PI
from robotcell.ik.track import TrackRobot
from robotcell.robot import Robot
from robotcell.transforms import finite_array, invert, validate_pose

__all__ = ["CellIKSolutions", "CellPath", "depends_on_track", "ik", "ik_path"]

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
    """

    q: NDArray[np.float64]
    valid: NDArray[np.bool_]
    reachable: NDArray[np.bool_]
    track: NDArray[np.float64]
    table: NDArray[np.float64]
    method: str

    @property
    def count(self) -> NDArray[np.int_]:
        """Number of valid branches per target, shape ``(...)``."""
        return np.count_nonzero(self.valid, axis=-1)


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
        A frame name accepted by :func:`robotcell.coupled.frame_pose`.

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


def _limits_ok(cell: Cell, e: NDArray[np.float64], th: NDArray[np.float64]) -> NDArray[np.bool_]:
    ok = np.ones(np.broadcast_shapes(e.shape, table_batch(cell, th)), dtype=bool)
    if cell.track is not None:
        ok &= cell.track.within_limits(e)
    if cell.turntable is not None:
        ok &= cell.turntable.within_limits(th)
    return ok


def _track_robot(cell: Cell) -> TrackRobot:
    t = cell.track
    assert t is not None
    if not (math.isfinite(t.lower) and math.isfinite(t.upper)):
        raise InputError("choosing the track position needs the track limits (min, max) in the "
                         "cell file; or give the track position")
    return TrackRobot(cell.robot, t.T_L_R0, t.direction, t.lower * t.scale, t.upper * t.scale,
                      t.name)


def _check_track_choice(cell: Cell, frame: str) -> None:
    if depends_on_track(cell, frame):
        raise InputError(f"frame {frame!r} moves with the track, so a target in it does not "
                         "fix the track position; give the track position")


def ik(cell: Cell, T: ArrayLike, frame: str = "world", track: ArrayLike | None = None,
       table: ArrayLike = 0.0, tool: str | ArrayLike | None = None,
       samples: int = 65) -> CellIKSolutions:
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
        frames that move with the track).
    table : array_like, shape (...) or (..., n)
        Table angle (rad) at which the target is given, or a positioner's axis values; must be
        0 without turntable.
    tool : str or array_like of shape (4, 4), optional
        A tool of the cell by name, or ``T_F_TCP`` (m); default: the robot model's tool.
    samples : int
        Track values per search stage when the track position is chosen.

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
    arr = validate_pose(T, "target pose")
    th = table_values(cell, table)
    T_tool = tool_pose(cell, tool)
    if track is None and cell.track is not None:
        _check_track_choice(cell, frame)
        batch = np.broadcast_shapes(arr.shape[:-2], table_batch(cell, th))
        T_world = frame_pose(cell, frame, 0.0, th) @ arr
        T_L = invert(cell.track.T_world_L) @ np.broadcast_to(T_world, batch + (4, 4))
        choice = _track_robot(cell).ik(T_L, samples=samples, tool=T_tool)
        e = choice.track / cell.track.scale
        q = choice.solutions.q[..., 1:]
        valid, reachable = choice.solutions.valid, choice.solutions.reachable
        method = choice.solutions.method
    else:
        e = finite_array(0.0 if track is None else track, "track position")
        batch = np.broadcast_shapes(arr.shape[:-2], table_batch(cell, th), e.shape)
        e = np.broadcast_to(e, batch)
        T_world = frame_pose(cell, frame, e, th) @ arr
        sol = cell.robot.ik(invert(robot_pose(cell, e)) @ T_world, tool=T_tool)
        q, valid, reachable, method = sol.q, sol.valid, sol.reachable, sol.method
    th = broadcast_table(cell, th, batch)
    valid = valid & _limits_ok(cell, e, th)[..., None]
    return CellIKSolutions(q, valid, reachable, np.array(e, dtype=float), np.array(th), method)


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
    kmin = np.ceil((lo - qmin) / TWO_PI)   # smallest turn count with min >= lo
    kmax = np.floor((hi - qmax) / TWO_PI)  # largest with max <= hi
    start = q[:, 0]
    target = start if ref is None else np.broadcast_to(ref, start.shape)
    want = np.round((target - start) / TWO_PI)
    with np.errstate(invalid="ignore"):
        k = np.clip(want, kmin, np.maximum(kmin, kmax))
    k = np.where(np.isfinite(k), k, 0.0)
    return q + np.where(rev, k, 0.0)[:, None] * TWO_PI


def ik_path(cell: Cell, T: ArrayLike, frame: str = "world", track: ArrayLike | None = None,
            table: ArrayLike = 0.0, tool: str | ArrayLike | None = None,
            q_start: ArrayLike | None = None, max_step: float = MAX_STEP,
            samples: int = 33) -> CellPath:
    """A continuous joint trajectory through a sequence of targets, with no configuration flip.

    The targets are solved together for every branch; a branch is kept when it reaches every
    target, its unwrapped trajectory fits the joint limits (shifted by whole turns where a joint
    has more than one turn of range), and no joint moves more than ``max_step`` between two
    consecutive targets. Among the kept branches the one nearest to ``q_start`` at the first
    target wins, or else the one with the largest smallest manipulability along the path.

    Parameters
    ----------
    cell : Cell
    T : array_like, shape (N, 4, 4) or (4, 4)
        Targets ``T_X_TCP`` in frame ``frame`` (m); one pose is held while the table turns.
    frame : str
        Frame of the targets (see :func:`ik`).
    track : array_like, shape (N,) or (), optional
        Track positions (m). Default: 0 without a track; with a track, one position for the
        whole path, chosen on ``samples`` values over the track limits to maximise the smallest
        manipulability along the path.
    table : array_like, shape (N,) or ()
        Table angles (rad) at the targets.
    tool : str or array_like of shape (4, 4), optional
        A tool of the cell by name, or ``T_F_TCP`` (m).
    q_start : array_like, shape (n,), optional
        Current arm configuration (rad): the path starts in the configuration nearest to it.
    max_step : float
        Largest joint change between consecutive targets (rad); sample the path more finely
        when the motion between targets is larger.
    samples : int
        Candidate track positions when the track position is chosen (>= 2).

    Returns
    -------
    CellPath

    Raises
    ------
    InputError
        Fewer than 2 targets, mismatched lengths, or no branch that follows the whole path; the
        message gives, per branch, the first target where it fails and why.
    """
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
    if e is None and cell.track is not None:
        _check_track_choice(cell, frame)
        if samples < 2:
            raise InputError(f"samples must be at least 2, got {samples}")
        t = _track_robot(cell)
        cand = np.linspace(t.lower, t.upper, samples) / cell.track.scale
    else:
        cand = np.zeros(1) if e is None else None
    if cand is not None:
        ee = np.broadcast_to(cand[:, None], (cand.size, n_pts))  # (K, N)
    else:
        ee = e[None, :]
    T_world = frame_pose(cell, frame, ee, th) @ arr
    sol = robot.ik(invert(robot_pose(cell, ee)) @ T_world, tool=T_tool)  # (K, N, 8, n)
    rev = ~robot.prismatic
    q = _fit_limits(_unwrapped(rev, sol.q), rev, robot.lower, robot.upper, q_start)
    reach = sol.reachable & _limits_ok(cell, ee, th)[..., None]             # (K, N, 8)
    inside = np.all((q >= robot.lower) & (q <= robot.upper), axis=-1)       # (K, N, 8)
    if robot.coupling is not None:  # interaction limits (e.g. FANUC J2/J3) are limits too
        inside &= robot.coupling.within_interaction(q)
    step = np.max(np.abs(np.diff(q, axis=1)), axis=-1)                      # (K, N-1, 8)
    smooth = np.concatenate([np.ones_like(step[:, :1], dtype=bool), step <= max_step], axis=1)
    ok = reach & inside & smooth
    feasible = np.all(ok, axis=1)                                           # (K, 8)
    if not np.any(feasible):
        raise InputError(_path_failure(q, robot, reach, inside, smooth,
                                       cand is not None and e is None))
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


def _path_failure(q: NDArray[np.float64], robot: Robot, reach: NDArray[np.bool_],
                  inside: NDArray[np.bool_], smooth: NDArray[np.bool_], track_chosen: bool) -> str:
    """Why no branch follows the path: the first failing target per branch (best track value)."""
    ok = reach & inside & smooth
    first_fail = np.where(np.all(ok, axis=1), ok.shape[1], np.argmin(ok, axis=1))  # (K, 8)
    k = int(np.argmax(first_fail.max(axis=1)))  # the track candidate where branches get furthest
    lines = []
    for b in range(8):
        i = int(first_fail[k, b])
        qi = q[k, i, b]
        if not reach[k, i, b]:
            why = "out of reach (or track/table outside its limits)"
        elif not inside[k, i, b]:
            j = int(np.argmax((qi < robot.lower) | (qi > robot.upper)))
            why = f"axis {j + 1} leaves its limits ({math.degrees(qi[j]):.1f} deg)"
        else:
            j = int(np.argmax(np.abs(qi - q[k, i - 1, b])))
            why = (f"axis {j + 1} jumps by {math.degrees(abs(qi[j] - q[k, i - 1, b, j])):.0f} deg "
                   "(the configuration passes a singularity)")
        lines.append(f"{BRANCH_NAMES[b]}: target {i + 1}: {why}")
    where = " at the best track position" if track_chosen else ""
    return ("no arm configuration follows the whole path without a flip" + where + "; "
            + "; ".join(lines) + ". Move the path towards the middle of the arm's reach, choose "
            "another track position or table range, or sample the path more finely")
