"""Clearance in a cell of several robots: each robot against the others and against the parts.

The robots move together, point ``k`` of one with point ``k`` of every other (a coordinated
program). Every segment is cut into the samples each robot's motion needs
(:func:`robotcell.clearance.path.samples`), all robots at the union of them; at each sample the
smallest distance is taken over every pair of groups: each robot (its links, its tool, what its
flange holds) against the cell's parts, and each robot against each other one. Shapes are named
with their robot's name before them (``kuka.link4``, ``abb.tool``); the parts keep their names.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell.kinematics import frame_pose, robot_pose
from robotcell.cell.model import Cell
from robotcell.clearance.bodies import BodiesFile, Body
from robotcell.clearance.distance import Clearance, Shapes, smallest_distances
from robotcell.clearance.path import (
    STEP,
    ArmMotion,
    arm_input,
    arm_shapes,
    interpolate,
    joined,
    pairs,
    samples,
    shared_table,
)
from robotcell.errors import InputError

__all__ = ["clearance_between"]


def clearance_between(cell: Cell, q: Mapping[str, ArrayLike], *,
                      track: Mapping[str, ArrayLike] | None = None, table: ArrayLike = 0.0,
                      tools: Mapping[str, str | ArrayLike] | None = None,
                      bodies: BodiesFile | None = None,
                      motion: str | Sequence[str] | Mapping[str, str | Sequence[str]] = "joint",
                      step: float = STEP) -> Clearance:
    """The smallest distance between robots of a cell, and between each robot and the parts,
    along a program they run together.

    Parameters
    ----------
    cell : Cell
        A cell of one or several robots.
    q : mapping of str to array_like, shape (N, n)
        Each robot's joint values by its name in the cell (rad, m); the same N for all.
    track : mapping of str to array_like, shape (N,) or scalar, optional
        Track values of the robots on a track (m; default 0).
    table : array_like, shape (N,), (N, k) or scalar
        The shared turntable's or positioner's values (rad).
    tools : mapping of str to str or array_like (4, 4), optional
        Each robot's tool, by name in the cell or as ``T_F_TCP`` (m); a robot left out has none.
    bodies : BodiesFile, optional
        The parts, the capsules' radii and the pairs never reported. A part held by a robot's
        flange has parent ``NAME.flange``; one fixed to a robot's base (moving with its track)
        parent ``NAME``. ``ignore`` patterns match a shape's name with or without its robot's
        name (``[tool, part]`` ignores every robot's torch on the part).
    motion : str, sequence of str, or mapping of str to either
        ``joint`` or ``linear`` per segment (N - 1), or one for all; per robot in a mapping.
    step : float
        Largest change between samples (rad of a joint or the table, m of a track or a TCP).

    Returns
    -------
    Clearance
        At every sample the smallest distance and its pair (``kuka.link4``, ``abb.tool``, or a
        part's name); ``per_point()`` and ``per_segment()`` gather them.

    Raises
    ------
    InputError
        A robot the cell lacks, joint values of the wrong shape, programs of different
        lengths, a part on ``robot`` or ``flange`` (say which robot's), or coal missing.
    """
    bodies = bodies or BodiesFile()
    if not q:
        raise InputError("give the joint values of at least one robot")
    if not (np.isfinite(step) and step > 0):
        raise InputError(f"step must be > 0, got {step!r}")
    views = {name: cell.for_robot(name) for name in q}
    track, tools = track or {}, tools or {}
    arms: dict[str, ArmMotion] = {}
    for name, view in views.items():
        kinds = motion.get(name, "joint") if isinstance(motion, Mapping) else motion
        arms[name] = arm_input(view, q[name], track.get(name, 0.0), tools.get(name), kinds)
    lengths = {name: arm.n for name, arm in arms.items()}
    if len(set(lengths.values())) > 1:
        raise InputError("the robots' programs must have as many points each: "
                         + ", ".join(f"{k} {v}" for k, v in lengths.items()))
    n = next(iter(lengths.values()))
    first = next(iter(views.values()))
    TH = shared_table(first, table, n)
    extra = TH.reshape(n, -1)
    pos = np.unique(np.concatenate([samples(a.q, np.column_stack([a.E, extra]), a.tcp, step)
                                    for a in arms.values()]))
    THs = interpolate(extra, pos).reshape((len(pos),) + TH.shape[1:])
    groups, tracks, flanges = {}, {}, {}
    for name, arm in arms.items():
        groups[name], tracks[name], flanges[name] = arm_shapes(views[name], arm, pos, bodies,
                                                               f"{name}.")
    held, parts = _sorted_bodies(cell, bodies, tuple(views))
    for name, mine in held.items():
        groups[name] = joined(groups[name], _shapes(
            mine, np.stack([flanges[name] for _ in mine], axis=1), name))
    poses = [_part_pose(cell, views, b, tracks, THs) for b in parts]
    others = _shapes(parts, np.stack(poses, axis=1) if parts else np.zeros((len(pos), 0, 4, 4)),
                     "")
    found = [smallest_distances(g, others, pairs(g.names, others.names, bodies.ignore), pos)
             for g in groups.values()]
    names = list(groups)
    found += [smallest_distances(groups[a], groups[b],
                                 pairs(groups[a].names, groups[b].names, bodies.ignore), pos)
              for i, a in enumerate(names) for b in names[i + 1:]]
    return _smallest(found, pos)


def _sorted_bodies(cell: Cell, bodies: BodiesFile, robots: tuple[str, ...]
                   ) -> tuple[dict[str, list[Body]], list[Body]]:
    """The parts held by each robot's flange, and the others."""
    held: dict[str, list[Body]] = {}
    parts: list[Body] = []
    for b in bodies.bodies:
        if b.parent in ("robot", "flange"):
            raise InputError(f"body {b.name!r}: parent {b.parent!r} does not say which robot in "
                             f"a cell of several robots; use one of "
                             + ", ".join(f"'{r}'" if b.parent == "robot" else f"'{r}.flange'"
                                         for r in cell.robot_names))
        owner, _, what = b.parent.partition(".")
        if what == "flange":
            cell.robot_key(owner)
            if owner in robots:
                held.setdefault(owner, []).append(b)
            continue
        parts.append(b)
    return held, parts


def _part_pose(cell: Cell, views: Mapping[str, Cell], body: Body,
               tracks: Mapping[str, NDArray[np.float64]], TH: NDArray[np.float64]
               ) -> NDArray[np.float64]:
    """``T_world_body`` at every sample (m): on a robot's base (by the robot's name or a frame
    fixed to it) with that robot's track, else in the shared cell."""
    parent = body.parent
    owner = parent if parent in cell.robot_names else (
        cell.frames[parent].parent if parent in cell.frames else None)
    if owner in cell.robot_names:
        if owner not in views:
            raise InputError(f"body {body.name!r} is on robot {owner!r}, whose joint values "
                             "are not given")
        view = views[owner]
        E = tracks[owner]
        base = robot_pose(view, E) if parent == owner else frame_pose(view, parent, E, TH)
        return base @ body.pose
    view = next(iter(views.values()))
    E = np.zeros(len(TH))
    if parent == "plate":
        if cell.turntable is None:
            raise InputError(f"body {body.name!r} is on the plate, but the cell has no "
                             "turntable or positioner")
        return frame_pose(view, "turntable", E, TH) @ cell.turntable.T_root_P(TH) @ body.pose
    return frame_pose(view, parent, E, TH) @ body.pose


def _shapes(bodies: Sequence[Body], poses: NDArray[np.float64], prefix: str) -> Shapes:
    """Parts at ``poses`` ``(P, K, 4, 4)``; ``poses`` of held parts are their flange's."""
    P = poses.shape[0]
    if prefix:
        poses = poses @ np.stack([b.pose for b in bodies])
        names = tuple(f"{prefix}.{b.name}" for b in bodies)
    else:
        names = tuple(b.name for b in bodies)
    radii = np.broadcast_to(np.array([b.bounding_radius for b in bodies]), (P, len(bodies)))
    return Shapes(names, tuple(b.shape for b in bodies), tuple(b.size for b in bodies), poses,
                  radii)


def _smallest(found: list[Clearance], pos: NDArray[np.float64]) -> Clearance:
    """The smallest of several :class:`Clearance` of the same samples, sample by sample."""
    dist = np.stack([c.distance for c in found])
    best = np.argmin(dist, axis=0)
    idx = np.arange(len(pos))
    pair = tuple(found[b].pair[k] for k, b in enumerate(best))
    nearest = np.stack([c.nearest for c in found])[best, idx]
    return Clearance(dist[best, idx], pair, nearest, pos)
