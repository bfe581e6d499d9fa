"""The 3D view of a cell at one configuration: robot, track, turntable or positioner, tools and
frames, in the world.

What is drawn, and from which function of the cell (every pose comes from the cell's own
kinematics, :mod:`robotcell.cell.kinematics`):

- the world axes;
- the track: its frame L and the travel of the robot base between the track limits
  (``robot_pose`` at the limits);
- the robot: its base R at the track position, its links, joint axes and DH frames
  (:func:`robotcell.view.arm.chain_items` of ``Robot.frames``), its flange F;
- every tool: its TCP ``T_world_F T_F_TCP`` as a triad, joined to the flange;
- the turntable or positioner: its root frame, its axes (the same drawing as the arm's), its
  plate P as a disk through the frames it carries (the cell file has no plate size: the disk
  reaches 100 mm past the farthest of them, and is at least twice the frame size across);
- every frame of the cell (``Cell.frame_pose``);
- in a cell of several robots (:func:`robots_scene`), every robot with its track and tools, its
  items named after it, beside the shared turntable or positioner and frames;
- optionally, a reachability map (:mod:`robotcell.view.reach`).

Hover texts give each frame's pose in the world, and tools and frames also their pose as the
cell file holds it, in the cell's convention (x, y, z mm; a, b, c deg; ``R = Rz(a) Ry(b)
Rx(c)``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell, Positioner
from robotcell.cell.kinematics import robot_pose
from robotcell.errors import InputError
from robotcell.kinematics.transforms import finite_array
from robotcell.robot.robot import Robot
from robotcell.view.arm import chain_items
from robotcell.view.plot import scene_figure, write_html
from robotcell.view.reach import ReachLike, reach_points, read_reach
from robotcell.view.scene import Item, Lines, Scene, Triads, pose_text
from robotcell.view.shapes import disk

if TYPE_CHECKING:
    import plotly.graph_objects as go

__all__ = ["axes_text", "cell_figure", "cell_items", "cell_scene", "degrees", "fixed_items",
           "frame_size", "joint_values", "robot_items", "robots_scene", "work_items", "write_cell_view"]

#: Margin of the drawn plate beyond the farthest frame it carries (m).
PLATE_MARGIN = 0.1


def frame_size(robot: Robot) -> float:
    """Axis length of the triads of a cell, a tenth of the robot's size (m).

    The robot's size is the sum of its link lengths ``|a| + |d|`` and its flange offset; the
    length is rounded to 10 mm and at least 20 mm.
    """
    size = sum(abs(j.a) + abs(j.d) for j in robot.joints) + float(np.linalg.norm(robot.flange[:3, 3]))
    return max(0.02, round(0.1 * size, 2))


def _hover(label: str, T_world: NDArray[np.float64], local: str = "",
           T_local: NDArray[np.float64] | None = None) -> str:
    text = f"<b>{label}</b><br>in the world: {pose_text(T_world)[0]}"
    if T_local is not None:
        text += f"<br>{local}: {pose_text(T_local)[0]}"
    return text


def _triads(name: str, poses: list[NDArray[np.float64]], labels: list[str], hover: list[str],
            length: float) -> list[Item]:
    return [Triads(name, np.array(poses), labels, length=length, hover=hover)] if poses else []


def degrees(values: ArrayLike) -> str:
    """Angles (rad) as ``"10, -90.5"``: degrees to 3 decimals, without trailing zeros."""
    return ", ".join(f"{v:g}" for v in np.round(np.degrees(np.atleast_1d(values)), 3))


def axes_text(robot: Robot, q: ArrayLike) -> str:
    """Axis values (rad, m) as the pendant shows them: ``"0, -90, 90, 0, 0, 0 deg"``, or with
    a unit per value (deg, mm) when the robot has a prismatic axis."""
    if not np.any(robot.prismatic):
        return f"{degrees(q)} deg"
    return ", ".join(f"{v * 1e3:.3f} mm" if p else f"{degrees(v)} deg"
                     for v, p in zip(np.asarray(q, dtype=float), robot.prismatic))


def joint_values(robot: Robot, joints: ArrayLike | None) -> NDArray[np.float64]:
    """``joints`` as ``(n,)`` (rad, m): the robot's home configuration (else zeros) when None."""
    if joints is None:
        return np.zeros(robot.n_joints) if robot.home is None else robot.home
    q = finite_array(joints, "joints")
    if q.shape != (robot.n_joints,):
        raise InputError(f"joints: {robot.name} has {robot.n_joints} axes, got shape {q.shape}")
    return q


def cell_items(cell: Cell, q: NDArray[np.float64], track: float, table: ArrayLike,
               size: float, detail: bool = True, with_tools: bool = True,
               triads: bool = True) -> list[Item]:
    """The moving parts of a cell at one configuration: robot, tools, positioner, frames.

    Parameters
    ----------
    cell : Cell
    q : ndarray, shape (n,)
        Arm axis values (rad, m).
    track : float
        Track position (m).
    table : array_like, shape () or (k,)
        Table angle, or the positioner's axis values (rad).
    size : float
        Axis length of the triads (m), see :func:`frame_size`.
    detail : bool
        Draw the joint axes and DH frames of the arm and the positioner
        (:func:`robotcell.view.arm.chain_items`).
    with_tools : bool
        Draw the cell's tools (and the robot model's own tool, when it has one).
    triads : bool
        Draw the robot base R, the flange F, the table's root and its plate P as triads
        (False: the moving parts of a path, drawn at each of its points, are the links, the
        plate and the frames).

    Returns
    -------
    list of Item
        The robot base R, the arm, the tools, the turntable or positioner and the cell's frames
        (the track's frame L, the world axes and the fixed geometry are not among them).
    """
    return (robot_items(cell, q, track, size, detail, with_tools, triads)
            + work_items(cell, track, table, size, detail, triads))


def robot_items(cell: Cell, q: NDArray[np.float64], track: float, size: float,
                detail: bool = True, with_tools: bool = True, triads: bool = True,
                label: str = "") -> list[Item]:
    """The robot of a one-robot cell (a view, :meth:`Cell.for_robot`) at one configuration:
    its base R, arm and tools; see :func:`cell_items` for the parameters. ``label`` goes before
    every name (``"kuka: "`` in a cell of several robots)."""
    T_world_R = robot_pose(cell, track)
    items: list[Item] = [Triads(f"{label}robot R", T_world_R, [f"{label}robot R"], length=size,
                                hover=[_hover(f"{label}robot base R", T_world_R)])
                         ] if triads else []
    arm = chain_items(cell.robot, q, T_world_R, name=f"{label}robot {cell.robot.name}",
                      axis_length=0.6 * size, frame_length=0.5 * size, detail=detail)
    items += arm if triads else arm[:-1]
    T_world_F = arm[-1].poses[0]
    tools = {name: tool.T_F_TCP for name, tool in cell.tools.items()} if with_tools else {}
    if with_tools and not np.array_equal(cell.robot.tool, np.eye(4)):
        tools["model tool"] = cell.robot.tool
    poses = [T_world_F @ T for T in tools.values()]
    if poses:
        body = np.vstack([np.stack([T_world_F[:3, 3], T[:3, 3], np.full(3, np.nan)])
                          for T in poses])
        items.append(Lines(f"{label}tools: flange to TCP", body, color="gray", width=3.0,
                           dash="dash"))
    items += _triads(f"{label}tools", poses, list(tools), [
        _hover(f"{label}tool {name}", T, "T_F_TCP (cell file)", tools[name])
        for name, T in zip(tools, poses)], size)
    return items


def work_items(cell: Cell, track: float, table: ArrayLike, size: float, detail: bool,
                triads: bool, frames: list[str] | None = None) -> list[Item]:
    """The turntable or positioner and the frames at one configuration (``frames``: the names
    drawn, default all); see :func:`cell_items` for the parameters."""
    items: list[Item] = []
    T_world_R = robot_pose(cell, track)
    pos = cell.turntable
    if pos is not None:
        kind = "positioner" if isinstance(pos, Positioner) else "turntable"
        v = np.atleast_1d(pos.axis_values(table))
        T_world_parent = np.eye(4) if pos.parent == "world" else T_world_R
        T_world_root = T_world_parent @ pos.T_parent_root
        label = "turntable B" if kind == "turntable" else "positioner root"
        if triads:
            items.append(Triads(label, T_world_root, [label], length=size,
                                hover=[_hover(f"{kind} {pos.name} root", T_world_root,
                                              f"in its parent ({pos.parent})", pos.T_parent_root)]))
        chain = chain_items(pos.chain, v, T_world_parent, name=f"{kind} {pos.name}",
                            color="slategray", axis_length=0.6 * size, frame_length=0.5 * size,
                            flange_label="plate P", detail=detail)
        items += chain if triads else chain[:-1]
        T_world_P = chain[-1].poses[0]
        carried = [f.pose[:2, 3] for f in cell.frames.values() if f.parent == "turntable"]
        radius = max([size, *(float(np.linalg.norm(p)) + PLATE_MARGIN for p in carried)])
        items.append(disk(f"{kind} {pos.name}: plate", T_world_P, radius,
                          hover=f"plate of {pos.name} (drawn radius {radius * 1e3:.0f} mm)"))
    names = list(cell.frames) if frames is None else frames
    poses = [cell.frame_pose(n, track, table) for n in names]
    items += _triads("frames", poses, names, [
        _hover(f"frame {n}", T, f"in {cell.frames[n].parent} (cell file)", cell.frames[n].pose)
        for n, T in zip(names, poses)], size)
    return items




def fixed_items(cell: Cell, size: float) -> list[Item]:
    """World axes, and the track's frame L and travel."""
    items: list[Item] = [Triads("world", np.eye(4), ["world"], length=2 * size)]
    tr = cell.track
    if tr is None:
        return items
    items.append(Triads("track L", tr.T_world_L, ["track L"], length=size,
                        hover=[_hover(f"track {tr.name} frame L", tr.T_world_L)]))
    ends = np.array([tr.lower, tr.upper])
    span = np.where(np.isfinite(ends), ends, [-1.0, 1.0])  # no limits: 1 m each way of 0
    base = robot_pose(cell, span)[:, :3, 3]
    hover = [f"robot base R at track {e * 1e3:g} mm" for e in span]
    items.append(Lines(f"track {tr.name}: travel of R", base, color="darkgray", width=14.0,
                       hover=hover))
    return items


def cell_scene(cell: Cell, joints: ArrayLike | None = None, track: float = 0.0,
               table: ArrayLike = 0.0, reach: ReachLike | None = None,
               tool: str | ArrayLike | None = None) -> Scene:
    """The scene of a cell at one configuration, in the world (m).

    Parameters
    ----------
    cell : Cell
        A cell of several robots is drawn by :func:`robots_scene` (``joints`` and ``track``
        then map robot names to their values).
    joints : array_like, shape (n,), optional
        Arm axis values (rad; m for a prismatic axis); default the robot model's home
        configuration, else all zero. Values outside the limits are drawn, and named in a note.
    track : float
        Track position (m); 0 without a track.
    table : array_like, shape () or (k,)
        Table angle (rad), or one value per positioner axis; 0 without one.
    reach : ReachLike, optional
        A reachability map (:func:`robotcell.view.reach.read_reach`, or the ``ReachMap`` of
        :func:`robotcell.studies.reach.reach_map`) to draw, coloured by score.
    tool : str or array_like of shape (4, 4), optional
        The tool ``reach`` was made with (a tool of the cell, or ``T_F_TCP`` in m).

    Returns
    -------
    Scene

    Raises
    ------
    InputError
        Joints of the wrong number, NaN, more than one track position, a track or table the
        cell does not have.
    """
    if len(cell.robots) > 1:
        if reach is not None:
            raise InputError("a reach map is drawn in the view of the robot that reaches: give "
                             "cell.for_robot(name)")
        return robots_scene(cell, joints, track, table)  # type: ignore[arg-type]
    q = joint_values(cell.robot, joints)
    e_arr = finite_array(track, "track")
    if e_arr.ndim:
        raise InputError(f"track: give one track position (m), got shape {e_arr.shape}")
    e = float(e_arr)
    th = cell.turntable.axis_values(table) if cell.turntable is not None else table
    cell.frame_pose("world", e, th)  # refuses a track or a table the cell does not have
    size = frame_size(cell.robot)
    items = fixed_items(cell, size) + cell_items(cell, q, e, th, size)
    state = [f"axes {axes_text(cell.robot, q)}"]
    if cell.track is not None:
        state.append(f"track {e * 1e3:g} mm")
    if cell.turntable is not None:
        state.append(f"table {degrees(th)} deg")
    notes = [("lengths in mm; hover over a frame for its pose (x, y, z mm; a, b, c deg, "
              "R = Rz(a) Ry(b) Rx(c)); click a legend entry to hide or show it")]
    outside = [j.name or f"A{i + 1}" for i, (j, v) in enumerate(zip(cell.robot.axes, q))
               if not j.lower <= v <= j.upper]
    if outside:
        notes.append(f"outside their limits: {', '.join(outside)}")
    if reach is not None:
        items.append(reach_points(cell, reach, tool))
        missing = int(np.count_nonzero(~np.asarray(reach.reachable, dtype=bool)))
        notes.append("reach map: each reachable target at its TCP in the world"
                     + (f"; {missing} unreachable target(s) not drawn (no axis values)"
                        if missing else ""))
    return Scene(f"{cell.name}: {'; '.join(state)}", items, notes)


def robots_scene(cell: Cell, joints: Mapping[str, ArrayLike] | None = None,
                 track: Mapping[str, float] | None = None, table: ArrayLike = 0.0) -> Scene:
    """The scene of a cell of several robots: every robot with its track and tools, the shared
    turntable or positioner and the frames, in the world (m).

    Parameters
    ----------
    cell : Cell
    joints : mapping of str to array_like of shape (n,), optional
        Axis values of robots by name (rad; m for a prismatic axis); a robot not named is drawn
        at its model's home configuration, else all zero.
    track : mapping of str to float, optional
        Track positions of robots by name (m); 0 for a robot not named.
    table : array_like, shape () or (k,)
        Table angle (rad), or one value per positioner axis; 0 without one.

    Returns
    -------
    Scene

    Raises
    ------
    InputError
        A robot name the cell lacks, joints of the wrong number, a track position for a robot
        without a track.
    """
    joints, track = dict(joints or {}), dict(track or {})
    for name in [*joints, *track]:
        cell.robot_key(name)
    views = {name: cell.for_robot(name) for name in cell.robot_names}
    size = max(frame_size(v.robot) for v in views.values())
    th = cell.turntable.axis_values(table) if cell.turntable is not None else table
    items: list[Item] = [Triads("world", np.eye(4), ["world"], length=2 * size)]
    state, notes = [], [("lengths in mm; hover over a frame for its pose (x, y, z mm; a, b, c "
                         "deg, R = Rz(a) Ry(b) Rx(c)); click a legend entry to hide or show it")]
    for name, view in views.items():
        q = joint_values(view.robot, joints.get(name))
        e = float(finite_array(track.get(name, 0.0), "track"))
        view.frame_pose("robot", e, th)  # refuses a track the robot does not have
        items += [replace(it, name=f"{name}: {it.name}") for it in fixed_items(view, size)[1:]]
        items += robot_items(view, q, e, size, label=f"{name}: ")
        mine = [f for f, fr in view.frames.items() if fr.parent == "robot"]  # on its base
        items += [replace(it, name=f"{name}: {it.name}") for it in work_items(
            replace(view, turntable=None, frames={f: view.frames[f] for f in mine}), e, 0.0, size,
            True, True)]
        state.append(f"{name} axes {axes_text(view.robot, q)}"
                     + (f", track {e * 1e3:g} mm" if view.track is not None else ""))
        outside = [j.name or f"A{i + 1}" for i, (j, v) in enumerate(zip(view.robot.axes, q))
                   if not j.lower <= v <= j.upper]
        if outside:
            notes.append(f"{name}: outside their limits: {', '.join(outside)}")
    shared = [f for f, fr in cell.frames.items() if fr.parent in ("world", "turntable")]
    items += work_items(views[cell.robot_names[0]], 0.0, th, size, True, True, shared)
    if cell.turntable is not None:
        state.append(f"table {degrees(th)} deg")
    return Scene(f"{cell.name}: {'; '.join(state)}", items, notes)


def cell_figure(cell: Cell, joints: ArrayLike | None = None, track: float = 0.0,
                table: ArrayLike = 0.0, reach: ReachLike | None = None,
                tool: str | ArrayLike | None = None) -> go.Figure:
    """A plotly figure of a cell (lengths in mm); see :func:`cell_scene` for the parameters.

    In Jupyter the figure shows inline; ``robotcell.view.write_html(fig, "cell.html")`` writes
    it as one self-contained page.

    Returns
    -------
    plotly.graph_objects.Figure
    """
    return scene_figure(cell_scene(cell, joints, track, table, reach, tool))


def write_cell_view(cell: Cell, path: str | Path, joints: ArrayLike | None = None,
                    track: float = 0.0, table: ArrayLike = 0.0,
                    reach: ReachLike | str | Path | None = None,
                    tool: str | ArrayLike | None = None) -> Path:
    """Write the interactive 3D view of a cell as one self-contained HTML page, atomically.

    Parameters
    ----------
    cell : Cell
    path : str or Path
        The HTML file.
    joints, track, table, tool
        As for :func:`cell_scene` (rad, m).
    reach : ReachLike or str or Path, optional
        A reachability map, or the CSV of one (:func:`robotcell.view.reach.read_reach`), whose
        reached targets are drawn.

    Returns
    -------
    Path
        The file written.
    """
    if isinstance(reach, (str, Path)):
        reach = read_reach(reach, cell)
    figure = cell_figure(cell, joints, track, table, reach, tool)
    return write_html(figure, path, title=f"{cell.name}: robotcell view")
