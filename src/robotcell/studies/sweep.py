"""Layout sweep: place the robot, track, turntable or part over a grid, score each layout on the
targets, rank the layouts.

A layout file (YAML, millimetres and degrees) lists, per component, offsets from the cell
file's placement; the sweep takes every combination (the Cartesian product)::

    robot:               # on a track the whole track moves; else the robot base
      y: [-300, -150, 0]             # values (mm)
    turntable:
      x: {from: -200, to: 200, steps: 5}   # evenly spaced, ends included (mm)
      a: [0, 90]                     # deg
    part:                # a frame of the cell
      z: [0, 50]

Components: ``robot``, ``track`` (the same as ``robot`` in a cell with a track), ``turntable``
or the name of a frame of the cell; in a cell of several robots, each robot by its name (a
layout can place several robots; one of them, ``robot=``, is scored). ``x, y, z`` move the
component along the axes of its parent frame; ``a, b, c`` turn it about its own origin by ``Rz(a) Ry(b) Rx(c)`` in its own frame.

Each layout is scored by :func:`robotcell.studies.reach.reach_map` on the same targets: the fraction of
reachable targets, the mean score (0 for an unreachable target) and the smallest score. Layouts
rank by reachable fraction, then mean score, then their order in the grid.

:func:`sweep` runs the layouts on any :class:`concurrent.futures.Executor`: serially without one,
a :class:`~concurrent.futures.ProcessPoolExecutor` on one machine, or a cluster's executor, e.g.
Dask's ``distributed.Client(address).get_executor()``. Every task is a pure function of the cell,
one layout and the targets, so the ranking does not depend on where it ran.
"""

from __future__ import annotations

import copy
import itertools
import math
from collections.abc import Callable
from concurrent.futures import Executor, as_completed
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robotcell.errors import InputError
from robotcell.io.fileio import read_text
from robotcell.io.tables import CELL_EXTENT_MM, write_columns
from robotcell.io.yamlfile import parse_yaml
from robotcell.kinematics.transforms import make_pose
from robotcell.studies.reach import reach_map

if TYPE_CHECKING:
    from robotcell.cell import Cell

__all__ = ["Layout", "LayoutScore", "apply_layout", "evaluate_layout", "ranking_columns",
           "read_layouts", "sweep"]

_AXES = ("x", "y", "z", "a", "b", "c")
#: Largest grid a layout file may span: each layout is one reach map of every target.
MAX_LAYOUTS = 100_000


@dataclass(frozen=True)
class Layout:
    """One placement of the cell's components, as offsets from the cell file.

    Attributes
    ----------
    offsets : dict of str to tuple of 6 floats
        Per component: ``(x, y, z)`` in metres along the parent's axes and ``(a, b, c)`` in
        radians about its own origin (``Rz(a) Ry(b) Rx(c)``).
    values : dict of str to float
        The varied parameters as in the layout file (``"robot.y"`` -> mm, ``"turntable.a"`` ->
        deg), for reports.
    """

    offsets: dict[str, tuple[float, ...]]
    values: dict[str, float]

    @property
    def label(self) -> str:
        """``robot.y=-150 turntable.a=90`` (mm, deg)."""
        return " ".join(f"{k}={v:g}" for k, v in self.values.items()) or "as in the cell file"


@dataclass(frozen=True)
class LayoutScore:
    """Score of one layout on the targets.

    Attributes
    ----------
    index : int
        Position of the layout in the grid (0-based).
    layout : Layout
    fraction : float
        Fraction of the targets that are reachable.
    mean_score : float
        Mean of :attr:`robotcell.studies.reach.ReachMap.score` over all targets (0 for unreachable).
    min_score : float
        Smallest score over all targets.
    """

    index: int
    layout: Layout
    fraction: float
    mean_score: float
    min_score: float

    @property
    def key(self) -> tuple[float, float, int]:
        """Sort key: best first."""
        return (-self.fraction, -self.mean_score, self.index)


def _values(spec: Any, where: str) -> list[float]:
    if isinstance(spec, dict):
        if set(spec) != {"from", "to", "steps"}:
            raise InputError(f"{where}: a range needs exactly the keys from, to, steps; got "
                             f"{sorted(spec)}")
        steps = spec["steps"]
        if not isinstance(steps, int) or isinstance(steps, bool) or not 1 <= steps <= MAX_LAYOUTS:
            raise InputError(f"{where}: steps must be a whole number from 1 to {MAX_LAYOUTS}, "
                             f"got {steps!r}")
        ends = [spec["from"], spec["to"]]
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in ends):
            raise InputError(f"{where}: from and to must be numbers, got {ends!r}")
        vals = np.linspace(*map(float, ends), steps).tolist()
    elif isinstance(spec, list) and spec:
        vals = spec
    elif isinstance(spec, (int, float)) and not isinstance(spec, bool):
        vals = [spec]
    else:
        raise InputError(f"{where}: give a list of numbers or {{from, to, steps}}, got {spec!r}")
    try:
        out = [float(v) for v in vals]
    except (TypeError, ValueError):
        raise InputError(f"{where}: values must be numbers, got {vals!r}") from None
    if not all(math.isfinite(v) for v in out):
        raise InputError(f"{where}: values must be finite numbers")
    if not all(abs(v) <= CELL_EXTENT_MM for v in out):
        raise InputError(f"{where}: values must be offsets within +-{CELL_EXTENT_MM:g} (mm or "
                         "deg; 100 m, the size of any real cell)")
    return out


def read_layouts(source: str | Path | dict) -> list[Layout]:
    """The grid of layouts of a layout file (see the module docstring).

    Parameters
    ----------
    source : str or Path or dict
        Path of the YAML file, or its content.

    Returns
    -------
    list of Layout
        Every combination, the last listed parameter varying fastest.

    Raises
    ------
    InputError
        Unreadable file, unknown axis, or values that are not numbers.
    """
    where = "layouts"
    if isinstance(source, dict):
        data = source
    else:
        where = str(source)
        data = parse_yaml(read_text(source, "layout file"), where)
    if not isinstance(data, dict) or not data:
        raise InputError(f"{where}: expected a mapping of components (robot, track, turntable "
                         "or a frame) to offsets")
    params: list[tuple[str, str, list[float]]] = []
    for comp, axes in data.items():
        if not isinstance(axes, dict) or not axes:
            raise InputError(f"{where}: {comp}: expected a mapping of x, y, z, a, b, c to values")
        for ax, spec in axes.items():
            if ax not in _AXES:
                raise InputError(f"{where}: {comp}: unknown axis {ax!r}; use x, y, z (mm) or "
                                 "a, b, c (deg)")
            params.append((str(comp), ax, _values(spec, f"{where}: {comp}.{ax}")))
    count = math.prod(len(p[2]) for p in params)
    if count > MAX_LAYOUTS:
        raise InputError(f"{where}: {count} layouts (every combination) is more than "
                         f"{MAX_LAYOUTS}; use fewer values or steps, or split the sweep")
    layouts = []
    for combo in itertools.product(*(p[2] for p in params)):
        offsets: dict[str, list[float]] = {}
        values = {}
        for (comp, ax, _), v in zip(params, combo):
            off = offsets.setdefault(comp, [0.0] * 6)
            i = _AXES.index(ax)
            off[i] = v * 1e-3 if i < 3 else math.radians(v)
            values[f"{comp}.{ax}"] = v
        layouts.append(Layout({k: tuple(v) for k, v in offsets.items()}, values))
    return layouts


def _moved(T: NDArray[np.float64], off: tuple[float, ...]) -> NDArray[np.float64]:
    R = Rotation.from_euler("ZYX", off[3:]).as_matrix()
    out = T @ make_pose(R, [0.0, 0.0, 0.0])
    out[:3, 3] += off[:3]
    return out


def apply_layout(cell: Cell, layout: Layout) -> Cell:
    """A copy of ``cell`` with its components moved by ``layout`` (the input is unchanged).

    A component is ``robot`` (or ``track``) in a one-robot cell, a robot's name in a cell of
    several robots (each robot named moves: its track, or its base without one), ``turntable``,
    or a frame of the cell.

    Raises
    ------
    InputError
        A component the cell does not have.
    """
    new = copy.copy(cell)
    new.frames = dict(cell.frames)
    one = len(cell.robots) == 1
    for comp, off in layout.offsets.items():
        if comp in cell.robots or (one and comp in ("robot", "track")):
            _move_robot(new, comp if comp in cell.robots else cell.robot_name, off)
        elif comp == "turntable" and cell.turntable is not None:
            tt = new.turntable
            if hasattr(tt, "T_parent_B"):
                new.turntable = replace(tt, T_parent_B=_moved(tt.T_parent_B, off))
            else:  # a positioner chain: its base is the root pose
                new.turntable = replace(tt, chain=tt.chain.with_base(_moved(tt.chain.base, off)))
        elif comp in cell.frames:
            fr = new.frames[comp]
            new.frames[comp] = replace(fr, pose=_moved(fr.pose, off))
        else:
            robots = (["robot"] + (["track"] if cell.track else [])) if one else list(cell.robots)
            known = robots + (["turntable"] if cell.turntable else []) + sorted(cell.frames)
            raise InputError(f"the layout moves {comp!r}, which the cell does not have; it has: "
                             f"{', '.join(known)}")
    return new


def _move_robot(cell: Cell, name: str, off: tuple[float, ...]) -> None:
    """Move robot ``name`` of ``cell`` by ``off``: its whole track, or its base without one."""
    unit = cell.robots[name]
    if unit.track is not None:
        unit = replace(unit, track=replace(unit.track, T_world_L=_moved(unit.track.T_world_L, off)))
    else:
        unit = replace(unit, T_world_R=_moved(unit.T_world_R, off))
    cell.robots = {**cell.robots, name: unit}


def evaluate_layout(cell: Cell, layout: Layout, index: int, T: NDArray[np.float64], frame: str,
                    tool: str | ArrayLike | None, table: ArrayLike | None,
                    robot: str | None = None) -> LayoutScore:
    """Score one layout on the targets (a pure function: the unit of work of :func:`sweep`)."""
    rm = reach_map(apply_layout(cell, layout), T, frame=frame, tool=tool, table=table,
                   robot=robot)
    score = rm.score
    return LayoutScore(index, layout, rm.fraction, float(np.mean(score)) if score.size else 0.0,
                       float(np.min(score)) if score.size else 0.0)


def sweep(cell: Cell, T: ArrayLike, layouts: list[Layout], frame: str = "world",
          tool: str | ArrayLike | None = None, table: ArrayLike | None = 0.0,
          executor: Executor | None = None,
          progress: Callable[[int, int], None] | None = None,
          output: str | Path | None = None, robot: str | None = None) -> list[LayoutScore]:
    """Score every layout on the targets and rank them, best first.

    Parameters
    ----------
    cell : Cell
    T : array_like, shape (N, 4, 4)
        Targets ``T_X_TCP`` in frame ``frame`` (m).
    layouts : list of Layout
        From :func:`read_layouts`.
    frame, tool, table
        As for :func:`robotcell.studies.reach.reach_map` (table angles in rad; None: chosen per
        target).
    executor : concurrent.futures.Executor, optional
        Runs one task per layout (e.g. ``ProcessPoolExecutor(4)`` or
        ``distributed.Client(address).get_executor()``); default: serially in this process.
    progress : callable, optional
        Called as ``progress(done, total)`` after each finished layout.
    output : str or Path, optional
        Also write the ranking as CSV, atomically (:func:`ranking_columns`).
    robot : str, optional
        The robot of the cell that reaches the targets (None: the only robot); a layout may
        move several robots of the cell.

    Returns
    -------
    list of LayoutScore
        Sorted by :attr:`LayoutScore.key`.
    """
    arr = np.asarray(T, dtype=float).reshape(-1, 4, 4)
    table = None if table is None else np.asarray(table, dtype=float)
    cell.for_robot(robot)  # refuse an unknown robot before sending work anywhere
    if layouts:  # refuse a component the cell lacks before sending work anywhere
        apply_layout(cell, layouts[0])
    total = len(layouts)
    results: list[LayoutScore] = []
    if executor is None:
        for i, lay in enumerate(layouts):
            results.append(evaluate_layout(cell, lay, i, arr, frame, tool, table, robot))
            if progress:
                progress(i + 1, total)
    else:
        futures = [executor.submit(evaluate_layout, cell, lay, i, arr, frame, tool, table, robot)
                   for i, lay in enumerate(layouts)]
        for done, fut in enumerate(as_completed(futures), start=1):
            results.append(fut.result())
            if progress:
                progress(done, total)
    ranked = sorted(results, key=lambda r: r.key)
    if output is not None:
        write_columns(output, ranking_columns(ranked, layouts), 6)
    return ranked


def ranking_columns(ranked: list[LayoutScore], layouts: list[Layout]) -> dict[str, NDArray]:
    """The CSV columns of a ranking: ``rank``, ``layout`` (its index), the offsets of each
    component (mm, deg), ``reachable_fraction``, ``mean_score``, ``min_score``."""
    names = list(layouts[0].values) if layouts else []
    return {
        "rank": np.arange(1, len(ranked) + 1), "layout": np.array([r.index for r in ranked]),
        **{n: np.array([r.layout.values[n] for r in ranked], dtype=float) for n in names},
        "reachable_fraction": np.array([r.fraction for r in ranked]),
        "mean_score": np.array([r.mean_score for r in ranked]),
        "min_score": np.array([r.min_score for r in ranked])}
