"""A path in the 3D view of a cell: the TCP's path, and the arm at each point on a slider.

The path is a sequence of configurations (arm axes, track, table) such as a robot program's
points. The scene draws the TCP positions as one line, marks the points given as bad (with
their reason in the hover text), and draws the moving parts of the cell (robot, tools,
turntable or positioner, frames; :func:`robotcell.view.cellscene.cell_items`) at one point at a
time, chosen with a slider or played in order. A point without joint values (NaN: an
unreachable target) has no arm to draw: its step shows the arm of the nearest point before it
that has one (else the first), and its mark needs the point's position in ``points``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import fields

import numpy as np
from numpy.typing import ArrayLike

from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.kinematics.transforms import as_points
from robotcell.view.cellscene import axes_text, cell_items, fixed_items, frame_size
from robotcell.view.scene import Item, Lines, Points, Scene, Step, Triads, pose_text
from robotcell.view.shapes import OUTLIER_COLOR

__all__ = ["path_scene"]


def _same(a: Item, b: Item) -> bool:
    """Whether two scene items draw the same thing."""
    if type(a) is not type(b):
        return False
    for f in fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        same = (np.array_equal(x, y, equal_nan=True) if isinstance(x, np.ndarray) else x == y)
        if not same:
            return False
    return True


def path_scene(cell: Cell, q: ArrayLike, track: ArrayLike = 0.0, table: ArrayLike = 0.0,
               tool: str | ArrayLike | None = None, labels: Sequence[str] | None = None,
               bad: ArrayLike | None = None, reasons: Sequence[str] | None = None,
               points: ArrayLike | None = None, title: str = "path") -> Scene:
    """The scene of a path through a cell, with the arm at each point on a slider.

    Parameters
    ----------
    cell : Cell
    q : array_like, shape (N, n)
        Arm axis values at each point (rad; m for a prismatic axis); a row of NaN for a point
        that has none (an unreachable target).
    track : array_like, shape (N,) or ()
        Track position at each point (m).
    table : array_like, shape (N,), (N, k) or ()
        Table angle, or the positioner's axis values, at each point (rad).
    tool : str or array_like of shape (4, 4), optional
        The tool of the path: a tool of the cell, or ``T_F_TCP`` (m); default the robot model's.
    labels : sequence of str, optional
        Name of each point (default ``"1".."N"``), on the slider and in the hover texts.
    bad : array_like of bool, shape (N,), optional
        Points to mark (e.g. those a program check finds bad).
    reasons : sequence of str, optional
        Why each point is bad (hover text of its mark; ignored for good points).
    points : array_like, shape (N, 3), optional
        Position of each point in the world (m), for the marks of points without joint values;
        default the TCP of the joint values.
    title : str

    Returns
    -------
    Scene
        Items: the world axes and the track, the TCP path (``Lines``), the marks of the bad
        points (``Points``); one ``Step`` per point with the moving parts of the cell at it.

    Raises
    ------
    InputError
        Shapes that do not match, no point at all, a bad point with neither joint values nor a
        position in ``points``.
    """
    qq = np.asarray(q, dtype=float)
    if qq.ndim != 2 or qq.shape[1] != cell.robot.n_joints or len(qq) == 0:
        raise InputError(f"q must have shape (N, {cell.robot.n_joints}) with N >= 1, got "
                         f"{qq.shape}")
    n = len(qq)
    has_q = np.all(np.isfinite(qq), axis=1)
    if not np.any(has_q):
        raise InputError("no point of the path has joint values: there is no arm to draw")
    e = np.broadcast_to(np.asarray(track, dtype=float), (n,))
    th = np.asarray(table, dtype=float)
    th = np.broadcast_to(th, (n,) + th.shape[1:] if th.ndim else (n,))
    labs = [str(i + 1) for i in range(n)] if labels is None else [str(s) for s in labels]
    flag = np.zeros(n, bool) if bad is None else np.asarray(bad, dtype=bool).reshape(-1)
    why = [""] * n if reasons is None else [str(r) for r in reasons]
    if len(labs) != n or flag.shape != (n,) or len(why) != n:
        raise InputError(f"labels, bad and reasons need one entry per point ({n})")
    where = np.full((n, 3), np.nan)
    if np.any(has_q):
        where[has_q] = cell.fk(qq[has_q], e[has_q], th[has_q], tool)[:, :3, 3]
    if points is not None:
        given = as_points(points, "points").reshape(-1, 3)
        if given.shape != (n, 3):
            raise InputError(f"points must have shape ({n}, 3), got {given.shape}")
        where = np.where(has_q[:, None], where, given)
    if np.any(flag & ~np.all(np.isfinite(where), axis=1)):
        first = labs[int(np.flatnonzero(flag & ~np.all(np.isfinite(where), axis=1))[0])]
        raise InputError(f"point {first} has no joint values: give its position in points")
    size = frame_size(cell.robot)
    items = [*fixed_items(cell, size),
             Lines("TCP path", where, color="teal", width=5.0,
                   hover=[f"point {lab}" for lab in labs])]
    if np.any(flag):
        idx = np.flatnonzero(flag)
        items.append(Points("bad points", where[idx], color=OUTLIER_COLOR, symbol="x", size=8.0,
                            labels=[labs[i] for i in idx],
                            hover=[f"<b>point {labs[i]}</b>: {why[i]}" for i in idx]))
    # the arm of the nearest point before with joint values (else the first one with them)
    shown = np.maximum.accumulate(np.where(has_q, np.arange(n), -1))
    shown = np.where(shown < 0, int(np.argmax(has_q)), shown)
    T_tcp = cell.fk(qq[shown], e[shown], th[shown], tool)
    tcp = [Triads("TCP", T, [f"point {lab}"], length=size, hover=[
        f"<b>point {lab}</b><br>TCP in the world: {pose_text(T)[0]}<br>axes {axes_text(cell.robot, qq[i])}"])
           for lab, T, i in zip(labs, T_tcp, shown)]
    at = [[*cell_items(cell, qq[i], e[i], th[i], size, detail=False, with_tools=False), t]
          for i, t in zip(shown, tcp)]
    # what does not move along the path is drawn once
    still = {j for j in range(len(at[0])) if all(_same(at[0][j], a[j]) for a in at[1:])}
    items += [at[0][j] for j in sorted(still)]
    steps = [Step(lab, tuple(it for j, it in enumerate(a) if j not in still))
             for lab, a in zip(labs, at)]
    notes = ["lengths in mm; move the slider (or press play) to put the arm at each point"]
    if np.any(flag):
        notes.append(f"{int(np.count_nonzero(flag))} point(s) marked bad: hover over a cross "
                     "for the reason")
    return Scene(title, items, notes, steps)
