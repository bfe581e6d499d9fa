"""A reachability map in the 3D view of a cell: each reachable target where the TCP reaches it.

``robotcell reach`` writes per target the axis values that reach it (track, table or positioner
axes, arm axes) and a score (docs/reach.md). The view places each reachable target at the TCP
pose those values give (:meth:`robotcell.cell.Cell.fk` with the tool the map was made with), in
the world, coloured by its score. An unreachable target has no axis values, so no place in the
world: the view counts it in a note.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell, Positioner
from robotcell.errors import InputError
from robotcell.io.tables import read_csv, require_columns
from robotcell.view.scene import Points

__all__ = ["ReachLike", "ReachTable", "reach_points", "read_reach"]


class ReachLike(Protocol):
    """What the view reads of a reachability map; :class:`robotcell.studies.reach.ReachMap` and
    :class:`ReachTable` are ones.

    Attributes
    ----------
    reachable : ndarray of bool, shape (N,)
    q : ndarray, shape (N, n)
        Arm axis values (rad; NaN where unreachable).
    track : ndarray, shape (N,)
        Track positions (m).
    table : ndarray, shape (N,) or (N, k)
        Table angles, or a positioner's axis values (rad).
    score : ndarray, shape (N,)
        In ``[0, 1]``.
    """

    @property
    def reachable(self) -> NDArray[np.bool_]: ...

    @property
    def q(self) -> NDArray[np.float64]: ...

    @property
    def track(self) -> NDArray[np.float64]: ...

    @property
    def table(self) -> NDArray[np.float64]: ...

    @property
    def score(self) -> NDArray[np.float64]: ...


@dataclass(frozen=True)
class ReachTable:
    """A reachability map as read back from the CSV of ``robotcell reach`` (SI units).

    Attributes
    ----------
    target : ndarray of int, shape (N,)
        Row of the targets file (0-based).
    reachable, q, track, table, score
        As :class:`ReachLike`.
    """

    target: NDArray[np.int_]
    reachable: NDArray[np.bool_]
    q: NDArray[np.float64]
    track: NDArray[np.float64]
    table: NDArray[np.float64]
    score: NDArray[np.float64]


def _flags(cols: dict, path: str | Path) -> NDArray[np.bool_]:
    """Column ``reachable``: ``true``/``false`` (as ``reach`` writes it) or 1/0."""
    given = cols.get("reachable")
    if given is None:
        raise InputError(f"{path}: missing column reachable (have: {', '.join(cols)})")
    words = ([str(w).strip().lower() for w in given] if isinstance(given, list)
             else ["true" if v == 1 else "false" if v == 0 else str(v) for v in given])
    bad = [i for i, w in enumerate(words) if w not in ("true", "false")]
    if bad:
        raise InputError(f"{path}: line {bad[0] + 2}: 'reachable' must be true or false (or "
                         f"1 or 0), got {words[bad[0]]!r}")
    return np.array([w == "true" for w in words])


def read_reach(path: str | Path, cell: Cell) -> ReachTable:
    """Read the CSV that ``robotcell reach`` writes for ``cell`` (mm, deg).

    Parameters
    ----------
    path : str or Path
        Columns ``reachable`` (``true``/``false``, or 1/0), ``score``, ``track`` (mm), ``table`` (deg; a positioner:
        ``e1..ek``), ``a1..an`` (deg; mm for a prismatic axis), optionally ``target``.
    cell : Cell
        The cell the map was made in.

    Returns
    -------
    ReachTable

    Raises
    ------
    InputError
        Missing or non-numeric columns, a ``reachable`` other than true or false, a score outside
        [0, 1], a reachable row without axis values; the message names the file and the row.
    """
    cols = read_csv(path, allow_nan=True)
    pos = cell.turntable
    tables = ([f"e{i + 1}" for i in range(pos.n_axes)] if isinstance(pos, Positioner)
              else ["table"])
    arms = [f"a{i + 1}" for i in range(cell.robot.n_joints)]
    reachable = _flags(cols, path)
    data = require_columns(cols, ["score", "track", *tables, *arms], path, empty_as_nan=True)
    score = data[:, 0]
    line = 2 + np.arange(len(data))  # file line of each row, after the header
    bad = ~((score >= 0) & (score <= 1))  # NaN too
    if np.any(bad):
        raise InputError(f"{path}: line {line[bad][0]}: 'score' must be within [0, 1]")
    axes = data[:, 1:]
    bad = reachable & ~np.all(np.isfinite(axes), axis=1)
    if np.any(bad):
        raise InputError(f"{path}: line {line[bad][0]}: a reachable target needs finite values "
                         f"of track, {', '.join(tables)} and {arms[0]}..{arms[-1]}")
    k = len(tables)
    table = np.radians(axes[:, 1:1 + k])
    arm_scale = np.where(cell.robot.prismatic, 1e-3, np.pi / 180)
    given = cols.get("target")
    ok = isinstance(given, np.ndarray) and bool(np.all(np.isfinite(given)))
    target = given.astype(int) if ok else np.arange(len(data))
    return ReachTable(target, reachable, axes[:, 1 + k:] * arm_scale, axes[:, 0] * 1e-3,
                      table if isinstance(pos, Positioner) else table[:, 0], score)


def reach_points(cell: Cell, reach: ReachLike, tool: str | ArrayLike | None = None,
                 labels: ArrayLike | None = None) -> Points:
    """The reachable targets of a map at their TCP positions in the world, coloured by score.

    Parameters
    ----------
    cell : Cell
    reach : ReachLike
        A :class:`robotcell.studies.reach.ReachMap`, or a :class:`ReachTable`.
    tool : str or array_like of shape (4, 4), optional
        The tool the map was made with: a tool of the cell, or ``T_F_TCP`` (m); default the
        robot model's tool.
    labels : array_like of int, shape (N,), optional
        Number of each target (default ``reach.target`` if it has one, else ``0..N-1``).

    Returns
    -------
    Points
        ``T_world_TCP`` of the reachable targets (``Cell.fk`` of their axis values), with the
        score (0..1) on the Viridis scale and each target's number, score and axis values in
        its hover text.
    """
    ok = np.asarray(reach.reachable, dtype=bool)
    idx = np.flatnonzero(ok)
    q = np.asarray(reach.q, dtype=float)[idx]
    track = np.asarray(reach.track, dtype=float)[idx]
    table = np.asarray(reach.table, dtype=float)[idx]
    T = cell.fk(q, track, table, tool) if len(idx) else np.zeros((0, 4, 4))
    numbers = np.asarray(getattr(reach, "target", np.arange(len(ok))) if labels is None
                         else labels)[idx]
    score = np.asarray(reach.score, dtype=float)[idx]
    hover = []
    for n, s, e, th, qq in zip(numbers, score, track, np.degrees(table), np.degrees(q)):
        tab = ", ".join(f"{v:.1f}" for v in np.atleast_1d(th))
        hover.append(f"<b>target {n}</b>: score {s:.3f}<br>track {e * 1e3:.1f} mm, "
                     f"table {tab} deg<br>axes {', '.join(f'{v:.1f}' for v in qq)} deg")
    return Points("reach map", T[:, :3, 3], values=score, value_title="reach score",
                  size=5.0, hover=hover)
