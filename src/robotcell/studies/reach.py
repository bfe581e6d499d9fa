"""Reachability map of a cell: can the robot reach every target, with which axis values, and how
far from its joint limits and from singular configurations.

Every target ``T_X_TCP`` (in a frame X of the cell, at a table angle) is solved by
:func:`robotcell.cell.ik.ik`, which chooses the track position when the cell has a track and none
is given. Among the valid arm configurations the one with the best score is kept. Per target:

- ``limit_margin``: the smallest distance of any arm axis to its limits (rad; m for a prismatic
  axis),
- ``manipulability``: ``|det J|`` of the arm (Yoshikawa 1985; m^3 for a six-axis arm), zero at a
  singular configuration,
- ``score`` in ``[0, 1]``: ``min(1, manipulability / scale) * min(1, limit_margin / LIMIT_REF)``
  with ``scale`` the largest ``|det J|`` of the arm over :data:`SCALE_SAMPLES` random
  configurations within its limits (:func:`manipulability_scale`); 0 when unreachable. So a
  target scores 1 when the arm is as far from singularities as it gets and every axis is at least
  :data:`LIMIT_REF` from its limits.

Targets from a file: :func:`robotcell.io.targets.read_targets` (poses, and the ``table`` or a
positioner's ``e1..en`` as ``table``). :func:`robotcell.report.reach.reach_html` draws the map
into a page, and
:func:`robotcell.report.reach.write_reach_map` writes the map's CSV and page in one call.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell.ik import ik
from robotcell.cell.kinematics import tool_pose
from robotcell.cell.validation import table_columns
from robotcell.errors import InputError
from robotcell.ik.limits import TWO_PI
from robotcell.ik.trackchoice import arm_manipulability
from robotcell.robot.robot import Robot

if TYPE_CHECKING:
    from robotcell.cell import Cell

__all__ = ["LIMIT_REF", "ReachMap", "manipulability_scale", "reach_columns", "reach_map"]

#: Distance to the joint limits (rad) from which a target counts as fully clear of them.
LIMIT_REF = math.radians(10.0)
#: Targets per block when :func:`reach_map` reports progress.
BLOCK = 2000
#: Random configurations that set the manipulability scale of an arm.
SCALE_SAMPLES = 4096

_SCALES: weakref.WeakKeyDictionary[Robot, float] = weakref.WeakKeyDictionary()


def manipulability_scale(robot: Robot) -> float:
    """The largest ``|det J|`` of ``robot`` over :data:`SCALE_SAMPLES` seeded random
    configurations within its limits (revolute axes within ``[-pi, pi]``); m^3 for a 6R arm."""
    scale = _SCALES.get(robot)
    if scale is None:
        rng = np.random.default_rng(0)
        lo = np.maximum(robot.lower, -math.pi)
        hi = np.minimum(robot.upper, math.pi)
        q = rng.uniform(lo, hi, (SCALE_SAMPLES, robot.n_joints))
        scale = float(np.max(np.abs(np.linalg.det(robot.jacobian(q)))))
        _SCALES[robot] = scale
    return scale


@dataclass(frozen=True)
class ReachMap:
    """Reachability of a batch of targets.

    Attributes
    ----------
    reachable : ndarray of bool, shape (N,)
        Some arm configuration reaches the target within every limit.
    q : ndarray, shape (N, n)
        Arm axis values of the best configuration (rad; NaN where unreachable).
    branch : ndarray of int, shape (N,)
        Its analytic branch (``4 * shoulder + 2 * elbow + wrist``; -1 where unreachable).
    track : ndarray, shape (N,)
        Track position (m; chosen unless given, NaN where chosen and unreachable; 0 without
        track).
    table : ndarray, shape (N,) or (N, n)
        Table angle (rad; 0 without turntable), or a positioner's axis values.
    limit_margin : ndarray, shape (N,)
        Smallest distance of an arm axis to its limits (rad; NaN where unreachable).
    track_margin : ndarray, shape (N,)
        Distance of the track position to the nearer track limit (m; inf without track
        limits, NaN without a track position).
    manipulability : ndarray, shape (N,)
        ``|det J|`` of the arm (m^3 for a six-axis arm; 0 where unreachable).
    score : ndarray, shape (N,)
        In ``[0, 1]``, see the module docstring.
    """

    reachable: NDArray[np.bool_]
    q: NDArray[np.float64]
    branch: NDArray[np.int_]
    track: NDArray[np.float64]
    table: NDArray[np.float64]
    limit_margin: NDArray[np.float64]
    track_margin: NDArray[np.float64]
    manipulability: NDArray[np.float64]
    score: NDArray[np.float64]

    @property
    def fraction(self) -> float:
        """Fraction of the targets that are reachable."""
        return float(np.mean(self.reachable)) if self.reachable.size else 0.0


def _rows(v: ArrayLike | None, sl: slice, n: int) -> ArrayLike | None:
    """Rows ``sl`` of a per-target value: a scalar, an array of length ``n``, or of shape
    ``(n, k)`` (a positioner's axis values per target)."""
    if v is None or np.ndim(v) == 0:
        return v
    a = np.asarray(v, dtype=float)
    return a[sl] if a.ndim and a.shape[0] == n else a


def _table_grid(cell: Cell, samples: int) -> NDArray[np.float64]:
    """Table angles (rad) to choose from: one turn, or the limits when they span less."""
    tt = cell.turntable
    if tt is None or tt.n_axes != 1 or np.ndim(tt.lower) != 0:
        raise InputError("choosing the table angle needs a turntable (one axis) in the cell; "
                         "give a positioner's axis values")
    if samples < 2:
        raise InputError(f"table_samples must be at least 2, got {samples}")
    if tt.upper - tt.lower >= TWO_PI:
        mid = 0.5 * (tt.lower + tt.upper)
        return mid + np.linspace(-math.pi, math.pi, samples, endpoint=False)
    return np.linspace(tt.lower, tt.upper, samples)


def reach_map(cell: Cell, T: ArrayLike, frame: str = "world", tool: str | ArrayLike | None = None,
              table: ArrayLike | None = 0.0, track: ArrayLike | None = None,
              table_samples: int = 36,
              progress: Callable[[int, int], None] | None = None,
              robot: str | None = None) -> ReachMap:
    """Score every target: reachable or not, axis values, limit margin, manipulability.

    Parameters
    ----------
    cell : Cell
    T : array_like, shape (N, 4, 4)
        Targets ``T_X_TCP`` in frame ``frame`` (m).
    frame : str
        Frame of the targets (see :func:`robotcell.cell.kinematics.frame_pose`).
    tool : str or array_like of shape (4, 4), optional
        A tool of the cell by name, or ``T_F_TCP`` (m).
    table : array_like of shape (N,) or (), or None
        Table angles (rad). None: chosen per target among ``table_samples`` angles evenly
        spread over one turn (or over the table's limits when they span less), the one where
        the target gets the best score.
    track : array_like, shape (N,) or (), optional
        Track positions (m); default: chosen per target (:func:`robotcell.cell.ik.ik`).
    table_samples : int
        Candidate table angles when ``table`` is None (10 deg apart by default).
    progress : callable, optional
        With it, the targets are solved in blocks of :data:`BLOCK` and ``progress(done, total)``
        is called after each.
    robot : str, optional
        The robot of the cell that reaches (None: the only robot;
        :meth:`Cell.for_robot <robotcell.cell.Cell.for_robot>`).

    Returns
    -------
    ReachMap
    """
    cell = cell.for_robot(robot)
    arr = np.asarray(T, dtype=float).reshape(-1, 4, 4)
    if progress is not None:
        n = arr.shape[0]
        parts = []
        for s in range(0, n, BLOCK):
            sl = slice(s, s + BLOCK)
            parts.append(reach_map(cell, arr[sl], frame, tool, _rows(table, sl, n),
                                   _rows(track, sl, n), table_samples))
            progress(min(s + BLOCK, n), n)
        return ReachMap(*(np.concatenate([getattr(p, f.name) for p in parts])
                          for f in fields(ReachMap)))
    if table is None:
        grid = _table_grid(cell, table_samples)
        arr = np.broadcast_to(arr[:, None], (arr.shape[0], grid.size, 4, 4))
        table = np.broadcast_to(grid, arr.shape[:2])
        if track is not None and np.ndim(track) == 1:  # one position per target: every angle
            track = np.asarray(track, dtype=float)[:, None]
    sol = ik(cell, arr, frame=frame, track=track, table=table, tool=tool)
    robot = cell.robot
    T_tool = tool_pose(cell, tool)
    n = arr.shape[0]
    valid = sol.valid.reshape(n, -1)                                    # (N, M * 8)
    q_all = sol.q.reshape(n, valid.shape[1], -1)
    q = np.where(valid[..., None], q_all, 0.0)
    if sol.method == "opw":  # closed form; |det J| does not depend on the tool
        manip = np.where(valid, arm_manipulability(robot, q), 0.0)
    else:
        manip = np.where(valid, np.abs(np.linalg.det(robot.jacobian(q, tool=T_tool))), 0.0)
    lo, hi = robot.lower, robot.upper
    with np.errstate(invalid="ignore"):
        gap = np.minimum(np.where(np.isfinite(lo), q - lo, np.inf),
                         np.where(np.isfinite(hi), hi - q, np.inf)).min(axis=-1)
    score = (np.minimum(1.0, manip / manipulability_scale(robot))
             * np.minimum(1.0, gap / LIMIT_REF))
    score = np.where(valid, score, -1.0)
    best = np.argmax(score, axis=-1)
    rows = np.arange(n)
    ok = valid[rows, best]
    e = np.broadcast_to(sol.track, sol.valid.shape[:-1]).reshape(n, -1)[rows, best // 8]
    tab = np.asarray(sol.table)
    extra = tab.shape[sol.valid.ndim - 1:]  # () for a turntable, (n,) for a positioner's axes
    th = np.broadcast_to(tab, sol.valid.shape[:-1] + extra).reshape((n, -1) + extra)[rows,
                                                                                    best // 8]
    e = np.array(e, dtype=float)
    if track is None and cell.track is not None:
        e = np.where(ok, e, np.nan)  # no track position was chosen for an unreachable target
    if cell.track is not None:
        e_margin = np.minimum(e - cell.track.lower, cell.track.upper - e)
    else:
        e_margin = np.full(ok.shape, np.inf)
    return ReachMap(
        reachable=ok,
        q=np.where(ok[:, None], q_all[rows, best], np.nan),
        branch=np.where(ok, best % 8, -1),
        track=e,
        table=np.array(th, dtype=float),
        limit_margin=np.where(ok, gap[rows, best], np.nan),
        track_margin=e_margin,
        manipulability=np.where(ok, manip[rows, best], 0.0),
        score=np.where(ok, score[rows, best], 0.0),
    )


def reach_columns(rm: ReachMap, cell: Cell) -> dict[str, NDArray]:
    """The CSV columns of a reachability map (mm, deg), each in its type.

    The axis columns are named as ``fk --cell`` and ``ik --cell`` name them: ``track`` (mm),
    ``table`` or a positioner's ``e1..en`` (deg), ``a1..an`` (deg), so the file can be fed to
    ``robotcell fk --cell CELL --input``. ``target`` and ``branch`` are integers, ``reachable``
    is ``true``/``false``; ``track_margin_mm`` only for a cell with a track.
    """
    names = table_columns(cell) or ("table",)
    table = np.degrees(rm.table).reshape(rm.reachable.size, -1)
    columns: dict[str, NDArray] = {
        "target": np.arange(rm.reachable.size), "reachable": rm.reachable.astype(bool),
        "score": rm.score, "track": rm.track * 1e3,
        **{name: table[:, i] for i, name in enumerate(names)},
        "branch": rm.branch.astype(int),
        **{f"a{i + 1}": np.degrees(rm.q[:, i]) for i in range(cell.robot.n_joints)},
        "limit_margin_deg": np.degrees(rm.limit_margin),
    }
    if cell.track is not None:
        columns["track_margin_mm"] = rm.track_margin * 1e3
    columns["manipulability_m3"] = rm.manipulability
    return columns
