"""The table's values along a path: the turntable angle, or a positioner's axis values, per target.

A path given in a frame the turntable (or positioner) carries does not say where the table stands:
the same seam can be welded at many table angles, and at table 0 part of it may lie out of the
arm's reach. :func:`choose_table` chooses the table values so that the whole path is one
continuous motion where possible, as a dynamic programme (Viterbi) over candidate values per
target:

- **candidates**: a turntable's angle (and a 1-axis positioner's) on a grid of
  :data:`TABLE_SAMPLES` values per turn over its whole range (every turn its limits allow, so
  that the table can pass +-180 deg where it may); a 2-axis positioner in the welding position,
  the axis values that turn the target's surface normal (the tool's ``-Z``) straight up
  (:meth:`~robotcell.cell.model.Positioner.normal_up`, each solution also a whole turn away
  within the limits), with the rotating axis also on the grid where the normal stays within
  ``normal_tol`` of up as it turns (a seam on a face across the rotating axis: the rotation is
  free there, as a turntable's);
- **a state** is a candidate and an arm configuration (analytic branch) at which the target is
  reached within every limit (:func:`robotcell.cell.ik.ik`, the track chosen per target where
  the path gives none); its cost is ``1 - m / m_best * min(1, margin / LIMIT_MARGIN)`` (``m``
  the manipulability ``|det J|``, ``m_best`` the target's best over all its states, ``margin``
  the arm's distance to its joint limits), plus the normal's tilt ``(dev / normal_tol)^2`` of a
  positioner and a small pull towards the middle of the table's range;
- **a move** from one target to the next keeps the configuration, turns each table axis and each
  arm axis by at most ``max_step``, and costs ``(table step / max_step)^2 + (arm step /
  max_step)^2``: the table moves little and evenly, the arm continuously;
- **a break** (any other change, or a target reached by no state) costs more than every move of
  the path together: the choice has the fewest breaks first, then the smallest cost.

The chosen values are then smoothed by a moving average along each continuous piece (over
:data:`TABLE_WINDOW` targets, or more where the table turns by less than a grid step per
target), kept where every target of the piece stays reached. :func:`robotcell.cell.ik.ik_path`
solves the path at the chosen values (and :func:`~robotcell.cell.ik.split_path` names the
breaks that remain). The programme runs over the targets in order (each step depends on the
one before); each step is vectorised over the candidates and configurations.

:func:`choose_shared_table` chooses the values once for several robots whose point ``k`` is
reached together (a coordinated program): a 2-axis positioner's candidates put the robots'
mean surface normal up; a state is a candidate with a configuration of every robot, each
reaching its point within every limit; its score is the worst robot's (each robot's score as
above, against its own best at that point); a move keeps every robot's configuration. A point
no candidate serves for every robot is refused, naming the robot that reaches it at none.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell.ik import MAX_STEP, ik
from robotcell.cell.kinematics import CellModel as Cell
from robotcell.cell.kinematics import frame_pose, robot_pose, tool_pose
from robotcell.errors import InputError
from robotcell.ik.analytic import analytic_solver
from robotcell.ik.limits import TWO_PI
from robotcell.ik.trackchoice import arm_manipulability
from robotcell.kinematics.bounds import within
from robotcell.kinematics.transforms import finite_array, validate_pose

__all__ = ["LIMIT_MARGIN", "NORMAL_TOL", "TABLE_SAMPLES", "TABLE_WINDOW", "SharedTableChoice",
           "TableChoice", "carried_by_table", "choose_shared_table", "choose_table"]

#: Candidate table values per turn (10 deg apart).
TABLE_SAMPLES = 36
#: Largest angle (rad) between a target's surface normal and straight up that a 2-axis
#: positioner's choice still counts as the welding position.
NORMAL_TOL = math.radians(2.0)
#: Distance of the arm's axes to their limits (rad) from which a state counts as clear of them.
LIMIT_MARGIN = math.radians(10.0)
#: Targets of the moving average that smooths the chosen values.
TABLE_WINDOW = 5
#: Weight of the pull towards the middle of the table's range (per axis, per half turn off it).
_MIDDLE = 1e-2


@dataclass(frozen=True)
class TableChoice:
    """Table values chosen along a path.

    Attributes
    ----------
    table : ndarray, shape (N,) or (N, n)
        Turntable angles, or a positioner's axis values (rad).
    branch : ndarray of int, shape (N,)
        Arm configuration (analytic branch) of the choice at each target (-1: none reaches it).
    reachable : ndarray of bool, shape (N,)
        Some candidate value reaches the target in some configuration.
    candidates : ndarray of int, shape (N,)
        Candidate values per target (0: a positioner that cannot turn the target's normal up
        within its limits).
    breaks : int
        Places where the chosen values cannot keep one continuous motion.
    """

    table: NDArray[np.float64]
    branch: NDArray[np.int_]
    reachable: NDArray[np.bool_]
    candidates: NDArray[np.int_]
    breaks: int

    @property
    def max_step(self) -> float:
        """Largest change of a table axis between consecutive targets (rad)."""
        if self.table.shape[0] < 2:
            return 0.0
        return float(np.max(np.abs(np.diff(self.table, axis=0))))

    def unreached(self, i: int) -> str:
        """Words to add to why target ``i`` breaks: no candidate reaches it ("" where one
        does)."""
        if self.reachable[i]:
            return ""
        if self.candidates[i] == 0:
            return "no positioner values within the axis limits turn its normal up"
        return "no table value reaches it within the limits either"


def carried_by_table(cell: Cell, frame: str) -> bool:
    """Whether frame ``frame`` of the cell is carried by the turntable (or positioner).

    Parameters
    ----------
    cell : Cell
    frame : str

    Returns
    -------
    bool
        True for a frame of the cell with parent ``turntable``: its pose in the world changes
        with the table's values. The table's root (``turntable``, ``B``) does not turn.
    """
    return cell.turntable is not None and frame in cell.frames and \
        cell.frames[frame].parent == "turntable"


def _axis_grid(lo: float, hi: float, samples: int) -> NDArray[np.float64]:
    """Values of one table axis (rad), ``2 pi / samples`` apart on multiples of that step, over
    its limits (two turns each way of an unlimited side)."""
    if not math.isfinite(lo):
        lo = (hi if math.isfinite(hi) else 0.0) - 2 * TWO_PI
    if not math.isfinite(hi):
        hi = lo + 4 * TWO_PI if not math.isfinite(lo) else max(hi, lo + 4 * TWO_PI)
    step = TWO_PI / samples
    k = np.arange(math.ceil(lo / step - 1e-9), math.floor(hi / step + 1e-9) + 1)
    grid = k * step
    return grid if grid.size >= 2 else np.linspace(lo, hi, 3)


def _range(cell: Cell) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    tt = cell.turntable
    return np.atleast_1d(np.asarray(tt.lower, dtype=float)), np.atleast_1d(np.asarray(tt.upper,
                                                                                    dtype=float))


def _compact(values: NDArray[np.float64], keep: NDArray[np.bool_], extra: NDArray[np.float64]
             ) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64]]:
    """Candidates ``values`` (N, K, n) with ``keep`` (N, K) packed to the front, padded with the
    first kept one (or 0): (N, M, n), ok (N, M) and ``extra`` (N, K) packed alike."""
    order = np.argsort(~keep, axis=1, kind="stable")
    m = max(1, int(keep.sum(axis=1).max()))
    idx = order[:, :m]
    v = np.take_along_axis(values, idx[..., None], axis=1)
    ok = np.take_along_axis(keep, idx, axis=1)
    fill = np.where(ok[:, :1, None], v[:, :1], 0.0)
    return np.where(ok[..., None], v, fill), ok, np.take_along_axis(extra, idx, axis=1)


def _normal_deviation(cell: Cell, frame: str, arr: NDArray[np.float64], track: NDArray[np.float64],
                      values: NDArray[np.float64]) -> NDArray[np.float64]:
    """Angle (rad) between each target's surface normal (the tool's -Z) and straight up, at
    positioner values ``values`` (N, K, n): (N, K)."""
    Tw = frame_pose(cell, frame, track[:, None], values) @ arr[:, None]
    return np.arccos(np.clip(-Tw[..., 2, 2], -1.0, 1.0))


def _positioner_candidates(cell: Cell, frame: str, arr: NDArray[np.float64],
                           track: NDArray[np.float64], samples: int, normal_tol: float
                           ) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64]]:
    """A 2-axis positioner's candidates: the welding position, the rotation free where the
    normal stays up. Values (N, M, 2), ok (N, M), normal deviation (N, M)."""
    pos = cell.turntable
    lo, hi = _range(cell)
    T_P = cell.frames[frame].pose @ arr
    parent = None if pos.parent == "world" else robot_pose(cell, track)
    sols, _ = pos.normal_up(-T_P[:, :3, 2], parent)                     # (N, 2, 2)
    turns = TWO_PI * np.arange(-2, 3)
    n = arr.shape[0]
    tilt = sols[:, :, 0, None] + turns                                   # (N, 2, 5)
    grid = _axis_grid(lo[1], hi[1], samples)
    rot = np.concatenate([np.broadcast_to(grid, (n, 2, grid.size)),
                          sols[:, :, 1, None] + turns], axis=-1)         # (N, 2, G + 5)
    v = np.stack(np.broadcast_arrays(tilt[..., :, None], rot[..., None, :]), axis=-1)
    v = v.reshape(n, -1, 2)
    keep = np.all(within(v, lo, hi), axis=-1)
    dev = np.full(keep.shape, np.inf)
    safe = np.where(keep[..., None], v, 0.0)
    dev[keep] = _normal_deviation(cell, frame, arr, track, safe)[keep]
    keep &= dev <= normal_tol
    return _compact(v, keep, dev)


def _candidates(cell: Cell, frame: str, arr: NDArray[np.float64], track: NDArray[np.float64],
                samples: int, normal_tol: float
                ) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64]]:
    """Candidate table values (N, M, n), whether each is one (N, M), and the normal's deviation
    from up (N, M; 0 for a turntable)."""
    n_axes = cell.turntable.n_axes
    if n_axes == 2:
        return _positioner_candidates(cell, frame, arr, track, samples, normal_tol)
    if n_axes != 1:
        raise InputError(f"the table values are chosen for a turntable and a positioner of 1 or "
                         f"2 axes; positioner {cell.turntable.name!r} has {n_axes}: give its "
                         f"axis values")
    lo, hi = _range(cell)
    grid = _axis_grid(lo[0], hi[0], samples)
    n = arr.shape[0]
    return (np.broadcast_to(grid[None, :, None], (n, grid.size, 1)), np.ones((n, grid.size), bool),
            np.zeros((n, grid.size)))


def _scores(cell: Cell, q: NDArray[np.float64], valid: NDArray[np.bool_],
            tool: NDArray[np.float64] | None) -> NDArray[np.float64]:
    """Score of each state (N, M, 8) in [0, 1]: ``m / m_best * min(1, margin / LIMIT_MARGIN)``
    (manipulability against the target's best over all its states, distance to the joint
    limits); 0 for a state that does not exist."""
    robot = cell.robot
    qz = np.where(valid[..., None], q, 0.0)
    if analytic_solver(robot).method == "opw":
        manip = arm_manipulability(robot, qz)
    else:
        manip = np.abs(np.linalg.det(robot.jacobian(qz, tool=tool)))
    manip = np.where(valid, manip, 0.0)
    best = manip.reshape(manip.shape[0], -1).max(axis=1)[:, None, None]
    rel = np.divide(manip, best, out=np.zeros_like(manip), where=best > 0)
    lo, hi = robot.lower, robot.upper
    with np.errstate(invalid="ignore"):
        gap = np.minimum(np.where(np.isfinite(lo), qz - lo, np.inf),
                         np.where(np.isfinite(hi), hi - qz, np.inf)).min(axis=-1)
    return rel * np.minimum(1.0, gap / LIMIT_MARGIN)


def _value_costs(cell: Cell, values: NDArray[np.float64], dev: NDArray[np.float64],
                 normal_tol: float) -> NDArray[np.float64]:
    """Cost of each candidate (N, M) itself: the normal's tilt off up, the pull to the middle."""
    tlo, thi = _range(cell)
    mid = np.where(np.isfinite(tlo) & np.isfinite(thi), 0.5 * (tlo + thi), 0.0)
    middle = _MIDDLE * np.sum(((values - mid) / math.pi) ** 2, axis=-1)       # (N, M)
    return (np.where(np.isfinite(dev), dev, 0.0) / normal_tol) ** 2 + middle


def _node_costs(cell: Cell, q: NDArray[np.float64], valid: NDArray[np.bool_],
                values: NDArray[np.float64], dev: NDArray[np.float64], normal_tol: float,
                tool: NDArray[np.float64] | None) -> NDArray[np.float64]:
    """Cost of each state (N, M, 8): reach, manipulability, limit margin, normal, middle."""
    return (1.0 - _scores(cell, q, valid, tool)) + _value_costs(cell, values, dev,
                                                               normal_tol)[..., None]


def _wrapped(d: NDArray[np.float64], rev: NDArray[np.bool_]) -> NDArray[np.float64]:
    """Joint differences with the revolute ones wrapped into [-pi, pi)."""
    return np.where(rev, (d + math.pi) % TWO_PI - math.pi, d)


def _viterbi(node: NDArray[np.float64], ok: NDArray[np.bool_], values: NDArray[np.float64],
             q: NDArray[np.float64], rev: NDArray[np.bool_], max_step: float
             ) -> tuple[NDArray[np.int_], NDArray[np.int_], NDArray[np.bool_]]:
    """The cheapest sequence of states (``ok`` (N, M, B) the states that exist: B arm
    configurations per candidate, ``q`` (N, M, B, J) their joints): candidate (N,), configuration
    (N,) and where it breaks (N,)."""
    n, m, nb = ok.shape
    big = 10.0 * (n + 1) * 4.0  # more than every move and state of the path together
    cost = np.where(ok[0], node[0], big)                                       # (M, B)
    back = np.zeros((n, m, nb), dtype=np.int64)
    broke = np.zeros((n, m, nb), dtype=bool)
    for i in range(1, n):
        dt = np.max(np.abs(values[i][None, :, :] - values[i - 1][:, None, :]), axis=-1)  # (M, M)
        jp, jn = np.nonzero(dt <= max_step + 1e-12)
        dq = np.max(np.abs(_wrapped(q[i, jn] - q[i - 1, jp], rev)), axis=-1)  # (P, B)
        with np.errstate(invalid="ignore"):
            move = cost[jp] + ((dt[jp, jn] / max_step) ** 2)[:, None] + (dq / max_step) ** 2
            move = np.where(dq <= max_step, move, np.inf)                    # NaN: not reached
        dense = np.full((m, m, nb), np.inf)
        dense[jp, jn] = move
        prev = np.argmin(dense, axis=0)                                      # (M, B)
        best = np.take_along_axis(dense, prev[None], axis=0)[0]
        flat = int(np.argmin(cost))
        restart = cost.flat[flat] + big
        broke[i] = restart < best
        back[i] = np.where(broke[i], flat, prev * nb + np.arange(nb))
        cost = np.minimum(best, restart) + np.where(ok[i], node[i], big)
    state = np.empty(n, dtype=np.int64)
    state[-1] = int(np.argmin(cost))
    cut = np.zeros(n, dtype=bool)
    for i in range(n - 1, 0, -1):
        j, b = divmod(int(state[i]), nb)
        cut[i] = broke[i, j, b]
        state[i - 1] = back[i, j, b]
    return state // nb, state % nb, cut


def _smoothed(values: NDArray[np.float64], cut: NDArray[np.bool_], grid: float
              ) -> NDArray[np.float64]:
    """The moving average of ``values`` (N, n) piece by piece between the breaks ``cut``, over
    :data:`TABLE_WINDOW` targets or, where the table turns by less than a grid step ``grid``
    (rad) per target, over the targets of two grid steps (the grid's stairs become a ramp)."""
    from scipy.ndimage import uniform_filter1d

    out = values.copy()
    starts = [0, *np.flatnonzero(cut).tolist(), values.shape[0]]
    for a, b in itertools.pairwise(starts):
        turned = float(np.abs(np.diff(values[a:b], axis=0)).sum(axis=0).max(initial=0.0))
        if b - a > 2 and turned > 0:
            size = max(TABLE_WINDOW, math.ceil(2 * grid * (b - a - 1) / turned))
            out[a:b] = uniform_filter1d(values[a:b], size=min(size, b - a), axis=0,
                                        mode="nearest")
    return out


def choose_table(cell: Cell, T: ArrayLike, frame: str, track: ArrayLike | None = None,
                 tool: str | ArrayLike | None = None, max_step: float = MAX_STEP,
                 samples: int = TABLE_SAMPLES, normal_tol: float = NORMAL_TOL,
                 robot: str | None = None) -> TableChoice:
    """Table values along a path in a frame the table carries, for one continuous motion.

    See the module docstring for the candidates, the costs and the dynamic programme.

    Parameters
    ----------
    cell : Cell
    T : array_like, shape (N, 4, 4)
        Targets ``T_X_TCP`` in frame ``frame`` (m).
    frame : str
        A frame of the cell carried by the turntable or positioner.
    track : array_like, shape (N,), optional
        Track positions (m); default: chosen per target (:func:`robotcell.cell.ik.ik`), or 0
        without a track.
    tool : str or array_like of shape (4, 4), optional
        A tool of the cell by name, or ``T_F_TCP`` (m).
    max_step : float
        Largest change of a table axis and of an arm axis between consecutive targets (rad).
    samples : int
        Candidate values per turn of a table axis (>= 4).
    normal_tol : float
        A 2-axis positioner: largest angle between a target's normal and straight up (rad).
    robot : str, optional
        The robot of the cell that follows the path (None: the only robot;
        :meth:`Cell.for_robot <robotcell.cell.Cell.for_robot>`).

    Returns
    -------
    TableChoice

    Raises
    ------
    InputError
        A frame the table does not carry, a positioner of 3 axes, bad targets, ``track``,
        ``max_step``, ``samples`` or ``normal_tol``.
    """
    cell = cell.for_robot(robot)
    if not carried_by_table(cell, frame):
        raise InputError(f"frame {frame!r} is not carried by the turntable: the table values do "
                         "not move its targets; give them")
    arr = validate_pose(T, "path targets")
    if arr.ndim != 3 or arr.shape[0] < 1:
        raise InputError(f"path targets must have shape (N, 4, 4), got {arr.shape}")
    n = arr.shape[0]
    e = None if track is None else np.broadcast_to(finite_array(track, "track position"), (n,))
    if not max_step > 0:
        raise InputError(f"max_step must be positive (rad), got {max_step}")
    if not samples >= 4:
        raise InputError(f"samples must be at least 4, got {samples}")
    if not 0 < normal_tol < math.pi:
        raise InputError(f"normal_tol must be between 0 and pi (rad), got {normal_tol}")
    values, ok, dev = _candidates(cell, frame, arr, np.zeros(n) if e is None else e, samples,
                                  normal_tol)
    m = values.shape[1]
    turntable = np.ndim(cell.turntable.lower) == 0  # angles (N,), not axis values (N, n)
    tab = values[..., 0] if turntable else values
    sol = ik(cell, np.broadcast_to(arr[:, None], (n, m, 4, 4)), frame,
             None if e is None else np.broadcast_to(e[:, None], (n, m)), tab, tool)
    valid = sol.valid & ok[..., None]                                           # (N, M, 8)
    node = _node_costs(cell, sol.q, valid, values, dev, normal_tol, tool_pose(cell, tool))
    rev = ~cell.robot.prismatic
    j, b, cut = _viterbi(node, valid, values, np.where(valid[..., None], sol.q, np.nan), rev,
                         max_step)
    rows = np.arange(n)
    reached = valid[rows, j, b]
    chosen = values[rows, j]
    smooth = _smoothed(chosen, cut, TWO_PI / samples)
    if not np.array_equal(smooth, chosen):
        again = ik(cell, arr, frame, e, smooth[:, 0] if turntable else smooth, tool)
        still = again.valid[rows, b] | ~reached
        if n > 1:
            still &= np.max(np.abs(np.diff(smooth, axis=0)), axis=-1).max() <= max_step
        if cell.turntable.n_axes == 2:
            still &= _normal_deviation(cell, frame, arr, np.zeros(n) if e is None else e,
                                       smooth[:, None])[:, 0] <= normal_tol
        chosen = np.where(_pieces_ok(still, cut)[:, None], smooth, chosen)
    return TableChoice(chosen[:, 0] if turntable else chosen, np.where(reached, b, -1),
                       valid.any(axis=(1, 2)), ok.sum(axis=1), int(cut.sum()))


def _pieces_ok(good: NDArray[np.bool_], cut: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """``good`` (N,) made all-or-nothing on each piece between the breaks ``cut``."""
    piece = np.cumsum(cut)
    bad = np.unique(piece[~good])
    return ~np.isin(piece, bad)


@dataclass(frozen=True)
class SharedTableChoice:
    """Table values chosen once along the paths of several robots (point ``k`` of every path
    reached together).

    Attributes
    ----------
    table : ndarray, shape (N,) or (N, n)
        Turntable angles, or a positioner's axis values (rad).
    branch : dict of str to ndarray of int, shape (N,)
        Each robot's arm configuration (analytic branch) at each point.
    score : ndarray, shape (N,)
        The common score at each point: the worst robot's score there (each robot's
        manipulability against its best at that point, times its clearance of its joint
        limits; 1 best, 0 singular or at a limit).
    breaks : int
        Places where the chosen values cannot keep one continuous motion.
    """

    table: NDArray[np.float64]
    branch: dict[str, NDArray[np.int_]]
    score: NDArray[np.float64]
    breaks: int


def _along_z(z: NDArray[np.float64], p: NDArray[np.float64]) -> NDArray[np.float64]:
    """Poses (N, 4, 4) at positions ``p`` (N, 3) whose Z axes are the unit vectors ``z``
    (N, 3)."""
    a = np.where(np.abs(z[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    x = a - np.sum(a * z, axis=1, keepdims=True) * z
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    T = np.tile(np.eye(4), (z.shape[0], 1, 1))
    T[:, :3, 0], T[:, :3, 1], T[:, :3, 2], T[:, :3, 3] = x, np.cross(z, x), z, p
    return T


@dataclass(frozen=True)
class _SharedPaths:
    """The robots' paths of a shared choice: each robot's view of the cell, targets (N, 4, 4),
    track (N,) or None and tool, in the order of ``names``."""

    names: list[str]
    views: dict[str, Cell]
    T: dict[str, NDArray[np.float64]]
    tracks: dict[str, NDArray[np.float64] | None]
    tools: dict[str, str | ArrayLike | None]
    frame: str

    @property
    def first(self) -> Cell:
        return self.views[self.names[0]]

    def mean_normal(self) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """Poses (N, 4, 4) whose ``-Z`` is the robots' mean surface normal (the mean of their
        tools' ``-Z``) at each point, and where that mean is not zero (N,)."""
        normal = np.mean([-t[:, :3, 2] for t in self.T.values()], axis=0)     # (N, 3)
        size = np.linalg.norm(normal, axis=1, keepdims=True)
        up = np.where(size > 1e-6, normal / np.maximum(size, 1e-6), [[0.0, 0.0, 1.0]])
        return _along_z(-up, self.T[self.names[0]][:, :3, 3]), size[:, 0] > 1e-6


def _shared_candidates(paths: _SharedPaths, samples: int, normal_tol: float
                       ) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64]]:
    """Candidates for every robot at once: a turntable's grid, or a 2-axis positioner in the
    welding position of the robots' mean surface normal (none where the normals cancel)."""
    ref, ok = paths.mean_normal()
    if paths.first.turntable.n_axes != 2:
        ok[:] = True                                          # a grid: the normals do not matter
    values, keep, dev = _candidates(paths.first, paths.frame, ref, np.zeros(len(ref)), samples,
                                    normal_tol)
    return values, keep & ok[:, None], dev


def _robot_states(cell: Cell, arr: NDArray[np.float64], frame: str,
                  track: NDArray[np.float64] | None, tool: str | ArrayLike | None,
                  tab: NDArray[np.float64], ok: NDArray[np.bool_]
                  ) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64]]:
    """One robot's joints (N, M, 8, J), valid states (N, M, 8) and scores (N, M, 8) at the
    candidates ``tab`` (N, M) or (N, M, n)."""
    n, m = ok.shape
    sol = ik(cell, np.broadcast_to(arr[:, None], (n, m, 4, 4)), frame,
             None if track is None else np.broadcast_to(track[:, None], (n, m)), tab, tool)
    valid = sol.valid & ok[..., None]
    return sol.q, valid, np.where(valid, _scores(cell, sol.q, valid, tool_pose(cell, tool)), 0.0)


def _combinations(valid: list[NDArray[np.bool_]]
                  ) -> tuple[NDArray[np.int_], NDArray[np.bool_]]:
    """The robots' configurations taken together: each combination (C, R) that serves some
    point at some candidate, and where it does (N, M, C)."""
    keep = valid[0].any(axis=(0, 1))
    combos, joint = np.flatnonzero(keep)[:, None], valid[0][..., keep]
    for v in valid[1:]:
        c = np.concatenate([np.repeat(combos, 8, axis=0),
                            np.tile(np.arange(8), len(combos))[:, None]], axis=1)
        both = (joint[..., :, None] & v[..., None, :]).reshape(*joint.shape[:2], -1)
        keep = both.any(axis=(0, 1))
        combos, joint = c[keep], both[..., keep]
    return combos, joint


def _unserved(names: list[str], valid: list[NDArray[np.bool_]], joint: NDArray[np.bool_],
              ok: NDArray[np.bool_], what: str) -> str:
    """Why the points no candidate serves for every robot are not served ("" when all are)."""
    bad = np.flatnonzero(~joint.any(axis=(1, 2)))
    why = []
    for i in bad[:5]:
        alone = [r for r, v in zip(names, valid) if not v[i].any()]
        if not ok[i].any():
            text = "no positioner values within the axis limits turn the robots' mean normal up"
        elif alone:
            text = (f"{' and '.join(alone)} reach{'es' if len(alone) == 1 else ''} it at no "
                    f"{what} values within the limits")
        else:
            text = f"{' and '.join(names)} each reach it, but never at the same {what} values"
        why.append(f"point {i + 1}: {text}")
    more = f" (and {bad.size - 5} more)" if bad.size > 5 else ""
    return "; ".join(why) + more


def choose_shared_table(cell: Cell, T: dict[str, ArrayLike], frame: str,
                        tracks: dict[str, ArrayLike | None] | None = None,
                        tools: dict[str, str | ArrayLike | None] | None = None,
                        max_step: float = MAX_STEP, samples: int = TABLE_SAMPLES,
                        normal_tol: float = NORMAL_TOL) -> SharedTableChoice:
    """Table values chosen once for several robots' paths, point ``k`` of every path together.

    The candidates are those of :func:`choose_table` (a 2-axis positioner in the welding
    position of the robots' mean surface normal at the point); a state is a candidate and a
    configuration of every robot at which each reaches its point within every limit; its
    score is the worst robot's (:attr:`SharedTableChoice.score`); a move keeps every robot's
    configuration and turns no table axis and no axis of any arm by more than ``max_step``.
    The dynamic programme and the smoothing are :func:`choose_table`'s.

    Parameters
    ----------
    cell : Cell
        A cell of several robots (:meth:`Cell.for_robot <robotcell.cell.Cell.for_robot>`).
    T : dict of str to array_like, shape (N, 4, 4)
        Each robot's targets ``T_X_TCP`` in frame ``frame`` (m), as many for every robot.
    frame : str
        A frame of the cell carried by the turntable or positioner.
    tracks : dict of str to array_like of shape (N,) or None, optional
        A robot's track positions (m); None or absent: chosen per target.
    tools : dict of str to str or array_like of shape (4, 4), optional
        Each robot's tool by name or ``T_F_TCP`` (m); absent: the robot model's tool.
    max_step : float
        Largest change of a table axis and of an arm axis between consecutive points (rad).
    samples : int
        Candidate values per turn of a table axis (>= 4).
    normal_tol : float
        A 2-axis positioner: largest angle between the mean normal and straight up (rad).

    Returns
    -------
    SharedTableChoice

    Raises
    ------
    InputError
        A point at which no candidate serves every robot (the message names the point and the
        robot that reaches it at none), paths of different lengths, a frame the table does not
        carry, a positioner of 3 axes, bad targets, ``max_step`` or ``samples``.
    """
    names = list(T)
    views = {r: cell.for_robot(r) for r in names}
    if not carried_by_table(views[names[0]], frame):
        raise InputError(f"frame {frame!r} is not carried by the turntable: the table values do "
                         "not move its targets; give them")
    arrs = {r: validate_pose(T[r], f"path targets of {r}") for r in names}
    shape = arrs[names[0]].shape
    if any(a.ndim != 3 or a.shape != shape or a.shape[0] < 1 for a in arrs.values()):
        raise InputError("each robot's targets must have shape (N, 4, 4), as many for every "
                         f"robot; got {', '.join(f'{r} {a.shape}' for r, a in arrs.items())}")
    if not max_step > 0 or not samples >= 4:
        raise InputError(f"max_step must be positive (rad) and samples at least 4, got "
                         f"{max_step} and {samples}")
    n = shape[0]
    paths = _SharedPaths(names, views, arrs, {
        r: None if (tracks or {}).get(r) is None else
        np.broadcast_to(finite_array(tracks[r], "track position"), (n,)) for r in names},
        {r: (tools or {}).get(r) for r in names}, frame)
    values, ok, dev = _shared_candidates(paths, samples, normal_tol)
    turntable = np.ndim(paths.first.turntable.lower) == 0
    tab = values[..., 0] if turntable else values
    states = [_robot_states(views[r], arrs[r], frame, paths.tracks[r], paths.tools[r], tab, ok)
              for r in names]
    combos, joint = _combinations([s[1] for s in states])
    if not joint.any(axis=(1, 2)).all():
        what = "table" if turntable else "positioner"
        raise InputError(f"no {what} values serve every robot: "
                         + _unserved(names, [s[1] for s in states], joint, ok, what)
                         + f"; give the {what}'s values in a path file, or move the points")
    score = np.min([s[2][..., combos[:, k]] for k, s in enumerate(states)], axis=0)
    node = (1.0 - score) + _value_costs(paths.first, values, dev, normal_tol)[..., None]
    q = np.concatenate([s[0][:, :, combos[:, k]] for k, s in enumerate(states)], axis=-1)
    rev = np.concatenate([~views[r].robot.prismatic for r in names])
    j, c, cut = _viterbi(node, joint, values, np.where(joint[..., None], q, np.nan), rev,
                         max_step)
    rows = np.arange(n)
    chosen = _shared_smoothed(paths, values[rows, j], combos[c], cut, max_step, normal_tol,
                              samples)
    return SharedTableChoice(chosen[:, 0] if turntable else chosen,
                             {r: combos[c, k] for k, r in enumerate(names)},
                             score[rows, j, c], int(cut.sum()))


def _shared_smoothed(paths: _SharedPaths, chosen: NDArray[np.float64],
                     branch: NDArray[np.int_], cut: NDArray[np.bool_], max_step: float,
                     normal_tol: float, samples: int) -> NDArray[np.float64]:
    """The chosen values (N, n) smoothed as :func:`choose_table` does, piece by piece where
    every robot still reaches every point of the piece in its configuration ``branch`` (N, R)."""
    smooth = _smoothed(chosen, cut, TWO_PI / samples)
    if np.array_equal(smooth, chosen):
        return chosen
    n = chosen.shape[0]
    rows = np.arange(n)
    turntable = np.ndim(paths.first.turntable.lower) == 0
    still = np.ones(n, dtype=bool)
    for k, r in enumerate(paths.names):
        again = ik(paths.views[r], paths.T[r], paths.frame, paths.tracks[r],
                   smooth[:, 0] if turntable else smooth, paths.tools[r])
        still &= again.valid[rows, branch[:, k]]
    if n > 1:
        still &= np.max(np.abs(np.diff(smooth, axis=0)), axis=-1).max() <= max_step
    if paths.first.turntable.n_axes == 2:
        ref, _ = paths.mean_normal()
        still &= _normal_deviation(paths.first, paths.frame, ref, np.zeros(n),
                                   smooth[:, None])[:, 0] <= normal_tol
    return np.where(_pieces_ok(still, cut)[:, None], smooth, chosen)
