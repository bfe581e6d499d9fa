"""A path in the 3D view of a cell: the TCP's path, and the arm at each point on a slider.

The path is a sequence of configurations (arm axes, track, table) such as a robot program's
points. The scene draws the TCP positions as one line, marks the points given as bad (with
their reason in the hover text), and draws the moving parts of the cell at one point at a time,
chosen with a slider or played in order. A point without joint values (NaN: an unreachable
target) has no arm to draw: its step shows the arm of the nearest point before it that has one
(else the first), and it is marked where ``points`` puts it.

The page stays small (:data:`robotcell.view.plot.MAX_PAGE_BYTES`), so that a path of hundreds of
points fits:

- what does not move along the path (the track's travel, a table that does not turn, the frames
  it carries) is drawn once, in full;
- what moves is drawn at each point as one polyline in the cell's world (:data:`MOVING`): the
  robot's links (:func:`robotcell.view.cellscene.cell_items` without the triads of R and F), the
  tool from the flange to the TCP, the TCP as a triad, and, when they move, the table's links
  and the frames it carries, as triads. Its colours are written once; at each point only its
  vertices, in mm to :data:`DECIMALS` decimals, and without the vertices that coincide with the
  one before at every point (the foot of the common normal of a DH link whose ``a`` or ``d`` is
  zero). The trace's ``meta`` names the vertices of each piece (``parts``);
- the slider's steps name their frame only.

With ``every`` > 1 the arm is drawn at every ``every``-th point (the whole path and every mark
are still drawn), and a note says so.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell
from robotcell.cell.kinematics import tool_pose
from robotcell.errors import InputError
from robotcell.kinematics.transforms import as_points, validate_pose
from robotcell.view.cellscene import cell_items, fixed_items, frame_size
from robotcell.view.scene import AXIS_COLORS, Item, Lines, Points, Scene, Step, Triads
from robotcell.view.shapes import OUTLIER_COLOR

__all__ = ["DECIMALS", "MOVING", "PathMarks", "one_per_frame", "ordinal", "path_scene",
           "path_steps", "triad_line"]

#: Decimals of the millimetre coordinates of a path's view: 0.01 mm.
DECIMALS = 2
#: Name of the polyline that draws the moving parts of the cell at each point.
MOVING = "cell at the point"
#: Two vertices closer than this at every point are one (m).
SAME = 1e-9


def ordinal(k: int) -> str:
    """``2nd``, ``3rd``, ``11th``, ``21st``."""
    suffix = "th" if 10 <= k % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(k % 10, "th")
    return f"{k}{suffix}"


def _same(a: Item, b: Item) -> bool:
    """Whether two scene items draw the same thing (coordinates within :data:`SAME`)."""
    if type(a) is not type(b):
        return False
    for f in fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            same = x.shape == y.shape and np.allclose(x, y, rtol=0, atol=SAME, equal_nan=True)
        else:
            same = x == y
        if not same:
            return False
    return True


def triad_line(name: str, T: ArrayLike, length: float) -> Lines:
    """A frame as one polyline of three coloured axes: origin, X tip, gap, origin, Y tip, gap,
    origin, Z tip (X red, Y green, Z blue).

    Parameters
    ----------
    name : str
    T : array_like, shape (4, 4)
        The frame (m); NaN: a frame that cannot be placed (its vertices are NaN, nothing drawn).
    length : float
        Axis length (m).

    Returns
    -------
    Lines
        8 vertices with their colours.
    """
    P = np.asarray(T, dtype=float).reshape(4, 4)
    o = P[:3, 3]
    gap = np.full(3, np.nan)
    pts = [o, o + length * P[:3, 0], gap, o, o + length * P[:3, 1], gap, o, o + length * P[:3, 2]]
    colors = [AXIS_COLORS[0]] * 3 + [AXIS_COLORS[1]] * 3 + [AXIS_COLORS[2]] * 2
    return Lines(name, np.array(pts), colors=colors)


def _pieces(item: Lines | Triads) -> list[Lines]:
    """A line-like item as polylines with a colour per vertex."""
    if isinstance(item, Triads):
        return [triad_line(item.name if len(item.poses) == 1 else f"{item.name}: {label}", T,
                           item.length) for label, T in zip(item.labels, item.poses)]
    colors = item.colors or (item.color,) * len(item.points)
    return [Lines(item.name, item.points, colors=colors)]


def _merge(steps: list[list[Lines | Triads]], width: float) -> list[Lines]:
    """The line-like moving items of each step as one polyline.

    Pieces follow each other, a row of NaN between them, or joined where a piece starts at
    every step where the one before ends, in its colour (the tool starts at the flange). A
    vertex that coincides with the one before at every step, in the same colour, is dropped.
    """
    pieces = [[p for item in items for p in _pieces(item)] for items in steps]
    blocks: list[NDArray[np.float64]] = []
    colors: list[str] = []
    spans = []
    for k, first in enumerate(pieces[0]):
        v = np.stack([ps[k].points for ps in pieces])
        c = list(first.colors or ())
        start = sum(b.shape[1] for b in blocks)
        if blocks:
            last = blocks[-1][:, -1]
            if c[0] == colors[-1] and np.allclose(v[:, 0], last, rtol=0, atol=SAME):
                v, c, start = v[:, 1:], c[1:], start - 1
            else:
                blocks.append(np.full((len(pieces), 1, 3), np.nan))
                colors.append(colors[-1])
                start += 1
        blocks.append(v)
        colors += c
        spans.append((first.name, start, start + len(first.points)))
    verts = np.concatenate(blocks, axis=1)
    same = np.isclose(verts[:, 1:], verts[:, :-1], rtol=0, atol=SAME) | (
        np.isnan(verts[:, 1:]) & np.isnan(verts[:, :-1]))
    dup = np.all(same, axis=(0, 2)) & np.array([a == b for a, b in zip(colors[1:], colors[:-1])],
                                               dtype=bool)
    keep = np.concatenate([[True], ~dup])
    new = np.cumsum(keep)
    parts = [(name, int(new[a] - 1), int(new[b - 1])) for name, a, b in spans]
    kept = [c for c, k in zip(colors, keep) if k]
    return [Lines(MOVING, v[keep], colors=kept, width=width, parts=parts) for v in verts]


def one_per_frame(items: list[Item]) -> list[Item]:
    """Triads of several frames split into one item per frame, so that a frame that does not
    move along the path is drawn once, and one that moves at each point."""
    out: list[Item] = []
    for it in items:
        if isinstance(it, Triads) and len(it.poses) > 1:
            out += [Triads(f"{it.name}: {lab}", T, [lab], length=it.length, hover=[h])
                    for lab, T, h in zip(it.labels, it.poses, it.hover or it.labels)]
        else:
            out.append(it)
    return out


def _tools(cell: Cell, tool: str | ArrayLike | None, n: int) -> NDArray[np.float64]:
    """``T_F_TCP`` at each point, shape ``(n, 4, 4)``; NaN where the tool is not known."""
    arr = None if tool is None or isinstance(tool, str) else np.asarray(tool, dtype=float)
    if arr is not None and arr.ndim == 3:
        if arr.shape != (n, 4, 4):
            raise InputError(f"tool must have shape (4, 4) or ({n}, 4, 4), got {arr.shape}")
        known = np.all(np.isfinite(arr), axis=(1, 2))
        if np.any(known):
            validate_pose(arr[known], "tool")
        return arr
    T = tool_pose(cell, tool)
    return np.broadcast_to(cell.robot.tool if T is None else T, (n, 4, 4))


@dataclass(frozen=True)
class PathMarks:
    """What the scene of a path says of its points: their names, the bad ones and why, where
    they are. Every field given holds one entry per point (N).

    Attributes
    ----------
    labels : sequence of str, optional
        Name of each point (default ``"1".."N"``), on the slider and in the hover texts.
    bad : array_like of bool, shape (N,), optional
        Points to mark (e.g. those a program check finds bad).
    reasons : sequence of str, optional
        Why each point is bad (hover text of its mark; ignored for good points).
    points : array_like, shape (N, 3), optional
        Position of each point in the world (m; NaN where not known), for the points without
        joint values or without a known tool; default the TCP of the joint values.
    hover : sequence of str, optional
        Hover text of each point of the path (default its label); its position follows.
    """

    labels: Sequence[str] | None = None
    bad: ArrayLike | None = None
    reasons: Sequence[str] | None = None
    points: ArrayLike | None = None
    hover: Sequence[str] | None = None

    def resolved(self, n: int) -> tuple[list[str], NDArray[np.bool_], list[str], list[str],
                                        NDArray[np.float64] | None]:
        """Labels, bad flags, reasons, hover texts and positions (m) of ``n`` points, with the
        defaults filled in.

        Raises
        ------
        InputError
            A field that does not hold one entry per point.
        """
        labs = [str(i + 1) for i in range(n)] if self.labels is None else [str(s)
                                                                         for s in self.labels]
        flag = (np.zeros(n, bool) if self.bad is None
                else np.asarray(self.bad, dtype=bool).reshape(-1))
        why = [""] * n if self.reasons is None else [str(r) for r in self.reasons]
        tips = labs if self.hover is None else [str(h) for h in self.hover]
        if len(labs) != n or flag.shape != (n,) or len(why) != n or len(tips) != n:
            raise InputError(f"labels, bad, reasons and hover need one entry per point ({n})")
        if self.points is None:
            return labs, flag, why, tips, None
        given = np.asarray(self.points, dtype=float)
        if given.shape != (n, 3):
            raise InputError(f"points must have shape ({n}, 3), got {given.shape}")
        known = np.all(np.isfinite(given), axis=1)
        given[known] = as_points(given[known], "points")
        return labs, flag, why, tips, given


def path_scene(cell: Cell, q: ArrayLike, track: ArrayLike = 0.0, table: ArrayLike = 0.0,
               tool: str | ArrayLike | None = None, marks: PathMarks = PathMarks(),
               title: str = "path", every: int = 1) -> Scene:
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
    tool : str or array_like of shape (4, 4) or (N, 4, 4), optional
        The tool: a tool of the cell, ``T_F_TCP`` (m), or one ``T_F_TCP`` per point (a row of
        NaN where it is not known: no TCP is drawn there); default the robot model's.
    marks : PathMarks, optional
        The points' names, the bad ones and why, their hover texts and positions, e.g.
        ``PathMarks(bad=bad, reasons=reasons)``; default: named ``"1".."N"``, none bad.
    title : str
    every : int
        Draw the arm at every ``every``-th point (the first, then every ``every``-th).

    Returns
    -------
    Scene
        Items: the world axes and the track, the TCP path (``Lines``, hover: the point and
        its position), the marks of the bad points (``Points``), what does not move along the
        path; one ``Step`` per point drawn with the moving parts (:data:`MOVING`). In
        0.01 mm (:data:`DECIMALS`). A bad point that has no position is named in a note.

    Raises
    ------
    InputError
        Shapes that do not match, no point at all, no point with joint values, ``every`` < 1.
    """
    qq = np.asarray(q, dtype=float)
    if qq.ndim != 2 or qq.shape[1] != cell.robot.n_joints or len(qq) == 0:
        raise InputError(f"q must have shape (N, {cell.robot.n_joints}) with N >= 1, got "
                         f"{qq.shape}")
    if int(every) != every or every < 1:
        raise InputError(f"every must be a whole number >= 1, got {every}")
    n = len(qq)
    has_q = np.all(np.isfinite(qq), axis=1)
    if not np.any(has_q):
        raise InputError("no point of the path has joint values: there is no arm to draw")
    e = np.broadcast_to(np.asarray(track, dtype=float), (n,))
    th = np.asarray(table, dtype=float)
    th = np.broadcast_to(th, (n,) + th.shape[1:] if th.ndim else (n,))
    labs, flag, why, tips, given = marks.resolved(n)
    tools = _tools(cell, tool, n)
    T_world_F = np.full((n, 4, 4), np.nan)
    T_world_F[has_q] = cell.fk(qq[has_q], e[has_q], th[has_q], tool=np.eye(4))
    T_tcp = T_world_F @ tools
    where = T_tcp[:, :3, 3]
    if given is not None:
        where = np.where(np.all(np.isfinite(where), axis=1)[:, None], where, given)
    placed = np.all(np.isfinite(where), axis=1)
    size = frame_size(cell.robot)
    items: list[Item] = [*fixed_items(cell, size),
                         Lines("TCP path", where, color="teal", width=5.0, hover=tips,
                               hover_xyz=True)]
    notes = [("lengths in mm; move the slider (or press play) to put the arm at each point; "
              "hover over the path for a point's name and position")]
    marked = flag & placed
    if np.any(marked):
        idx = np.flatnonzero(marked)
        items.append(Points("bad points", where[idx], color=OUTLIER_COLOR, symbol="x", size=8.0,
                            labels=[labs[i] for i in idx],
                            hover=[f"<b>point {labs[i]}</b>: {why[i]}" for i in idx]))
        notes.append(f"{len(idx)} point(s) marked bad: hover over a cross for the reason")
    lost = np.flatnonzero(flag & ~placed)
    if lost.size:
        notes.append("not drawn, no position: " + "; ".join(f"point {labs[i]}: {why[i]}"
                                                            for i in lost))
    # the arm of the nearest point before with joint values (else the first one with them)
    shown = np.maximum.accumulate(np.where(has_q, np.arange(n), -1))
    shown = np.where(shown < 0, int(np.argmax(has_q)), shown)
    steps = np.arange(0, n, int(every))
    at = [_at_point(cell, qq[j], e[j], th[j], size, T_world_F[j], T_tcp[j])
          for j in shown[steps]]
    still, frames = path_steps(at, [labs[i] for i in steps])
    items += still
    if every > 1:
        notes.append(f"the arm is drawn at every {ordinal(every)} of the {n} points (the path "
                     "and every mark at all of them)")
    return Scene(title, items, notes, frames, decimals=DECIMALS)


def _at_point(cell: Cell, q: NDArray[np.float64], track: float, table: ArrayLike, size: float,
              T_world_F: NDArray[np.float64], T_tcp: NDArray[np.float64]) -> list[Item]:
    """The moving parts of the cell at one point: the robot's links, the tool from the flange
    (``T_world_F``, m) to the TCP (``T_tcp``, m), the TCP as a triad of ``size`` (m), then the
    rest of the cell (one item per frame), at joints ``q`` (rad), ``track`` (m), ``table``
    (rad)."""
    parts = one_per_frame(cell_items(cell, q, track, table, size, detail=False,
                                      with_tools=False, triads=False))
    arm = parts[0]  # the robot's links; the tool goes on from the flange in their colour
    tool_line = Lines("tool", np.vstack([T_world_F[:3, 3], T_tcp[:3, 3]]),
                      color=arm.color if isinstance(arm, Lines) else "gray")
    return [arm, tool_line, triad_line("TCP", T_tcp, size), *parts[1:]]


def path_steps(at: list[list[Item]], labels: list[str]) -> tuple[list[Item], list[Step]]:
    """What does not move along the path, drawn once, and one step per point drawn with what
    moves.

    Parameters
    ----------
    at : list of list of Item
        The items of the cell at each point drawn, the same kinds in the same order at each
        (m); a set of frames as one item per frame (:func:`one_per_frame`).
    labels : list of str
        The name of each point drawn, on the slider.

    Returns
    -------
    still : list of Item
        The items that are the same at every point, drawn once.
    steps : list of Step
        Per point, what moves: the line-like items as one polyline (:data:`MOVING`), the
        moving frames' labels, the other items (a plate).
    """
    still = [all(_same(at[0][k], a[k]) for a in at[1:]) for k in range(len(at[0]))]
    fixed = [it for it, s in zip(at[0], still) if s]
    moving = [[it for it, s in zip(a, still) if not s] for a in at]
    lines = [[it for it in m if isinstance(it, (Lines, Triads))] for m in moving]
    merged = _merge(lines, width=6.0) if lines[0] else [None] * len(at)
    labelled = [[it for it in m if isinstance(it, Triads)] for m in moving]
    others = [[it for it in m if not isinstance(it, (Lines, Triads))] for m in moving]
    frames = []
    for k, label in enumerate(labels):
        step: list[Item] = [] if merged[k] is None else [merged[k]]
        if labelled[k]:
            frames_here = [(lab, T) for t in labelled[k] for lab, T in zip(t.labels, t.poses)]
            step.append(Points("moving frames", np.array([T[:3, 3] for _, T in frames_here]),
                               size=2.0, labels=[lab for lab, _ in frames_here]))
        frames.append(Step(label, (*step, *others[k])))
    return fixed, frames
