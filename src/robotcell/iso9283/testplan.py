"""The test plan of ISO 9283 in a cell: the largest cube in the arm's reach, its five poses and
its two paths, every one reached in one arm configuration (:func:`plan`).

The plan is what the controller is told: TCP poses in a frame of the cell (``world`` or one of
its frames), with the robot at one track position and the table at one value. It is searched
in the robot base frame R (:mod:`robotcell.iso9283.search`) and expressed in the frame.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.cell import Cell
from robotcell.cell.kinematics import robot_pose, tool_pose
from robotcell.errors import InputError
from robotcell.iso9283.cube import POSE_NAMES, circle_points, line_points, pose_points
from robotcell.iso9283.search import largest_cube, shrink_until_clear
from robotcell.kinematics.transforms import invert, make_pose, rot_y, validate_pose

__all__ = ["DEFAULT_ORIENTATION", "TestPlan", "plan"]

#: The tool's orientation in the plan's frame unless given: its Z axis straight down.
DEFAULT_ORIENTATION = rot_y(np.pi)

_PATH_POINT = re.compile(r"^([a-z][a-z0-9]*)_([0-9]+)$")


@dataclass
class TestPlan:
    """The commanded poses of an ISO 9283 test in a frame of a cell.

    Attributes
    ----------
    names : list of str
        ``P1`` .. ``P5``, then the points of each path in order, ``line_1``, ``line_2``, ...,
        ``circle_1``, ...
    T : ndarray, shape (N, 4, 4)
        ``T_X_TCP`` of each name in frame ``frame`` (m).
    frame : str
        ``world`` or a frame of the cell.
    tool : str
        The tool of the cell whose TCP is commanded.
    track : float or None
        Track position (m); None in a cell without a track.
    table : ndarray, shape () or (n,), or None
        Turntable angle or positioner axis values (rad); None in a cell without one.
    branch : int or None
        The arm configuration (IK branch ``4 * shoulder + 2 * elbow + wrist``) that reaches
        every point, when the plan was searched (None when read from a file).
    q : ndarray, shape (5, n), or None
        Arm axis values at P1..P5 in that configuration (rad), when searched.
    """

    __test__ = False  # not a pytest test class, whatever its name

    names: list[str]
    T: NDArray[np.float64]
    frame: str
    tool: str
    track: float | None = None
    table: NDArray[np.float64] | None = None
    branch: int | None = None
    q: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        self.T = validate_pose(self.T, "plan poses").reshape(-1, 4, 4)
        if len(self.names) != len(self.T):
            raise InputError(f"a plan needs one name per pose: {len(self.names)} names for "
                             f"{len(self.T)} poses")
        missing = [p for p in POSE_NAMES if p not in self.names]
        if missing:
            raise InputError(f"the plan lacks the test pose(s) {', '.join(missing)}")

    @property
    def poses(self) -> NDArray[np.float64]:
        """``T_X_TCP`` of P1..P5, shape (5, 4, 4) (m)."""
        return self.T[[self.names.index(p) for p in POSE_NAMES]]

    @property
    def paths(self) -> dict[str, NDArray[np.float64]]:
        """Path name -> ``T_X_TCP`` of its points in order, shape (M, 4, 4) (m)."""
        found: dict[str, list[tuple[int, int]]] = {}
        for i, name in enumerate(self.names):
            m = _PATH_POINT.match(name)
            if m:
                found.setdefault(m.group(1), []).append((int(m.group(2)), i))
        return {path: self.T[[i for _, i in sorted(rows)]] for path, rows in found.items()}

    @property
    def size(self) -> float:
        """Edge of the test cube (m), from the distance of P2 and P4."""
        p = self.poses[:, :3, 3]
        return float(np.linalg.norm(p[3] - p[1]) / (np.sqrt(3.0) * 0.8))


def _track_value(cell: Cell, track: float | None) -> float:
    """The track position of the plan (m): given, or the middle of the travel; 0 without one."""
    if cell.track is None:
        if track not in (None, 0, 0.0):
            raise InputError("the cell has no track; give no track position")
        return 0.0
    t = cell.track
    if track is None:
        finite = np.isfinite([t.lower, t.upper])
        return float((t.lower + t.upper) / 2) if finite.all() else 0.0
    if not (np.isfinite(track) and t.within_limits(track)):
        raise InputError(f"track position {track * 1e3:g} mm is outside the track's limits "
                         f"[{t.lower * 1e3:g}, {t.upper * 1e3:g}] mm")
    return float(track)


def _table_value(cell: Cell, table: ArrayLike) -> NDArray[np.float64] | None:
    """The table's values of the plan (rad), checked against its limits; None without one."""
    tt = cell.turntable
    values = np.asarray(table, dtype=float)
    if values.size == 0:
        raise InputError("no table value given: give the turntable's angle, or one value per "
                         "positioner axis")
    if tt is None:
        if np.any(values != 0):
            raise InputError("the cell has no turntable or positioner; give no table value")
        return None
    values = tt.axis_values(values)
    if not np.all(tt.within_limits(values)):
        raise InputError(f"table value(s) {np.degrees(values).round(3).tolist()} deg outside "
                         "the table's limits")
    return values


def plan(cell: Cell, tool: str, frame: str = "world", size: float | None = None,
         centre: ArrayLike | None = None, track: float | None = None, table: ArrayLike = 0.0,
         orientation: ArrayLike = DEFAULT_ORIENTATION) -> TestPlan:
    """Plan the ISO 9283 pose and path test of a cell.

    The largest cube (or one of the edge given) that one arm configuration reaches everywhere
    with the TCP in ``orientation``, within the limits and away from singular configurations
    (:mod:`robotcell.iso9283.search`); its five test poses and two test paths
    (:mod:`robotcell.iso9283.cube`).

    Parameters
    ----------
    cell : Cell
    tool : str
        A tool of the cell.
    frame : str
        ``world`` or a frame of the cell: the frame of the poses written and measured.
    size : float, optional
        Edge of the cube (m); default the largest that is clear.
    centre : array_like, shape (3,), optional
        The cube's centre in ``frame`` (m); default searched in front of the arm, above its base
        plane.
    track : float, optional
        Track position (m); default the middle of the track's travel.
    table : array_like, shape () or (n,)
        Turntable angle or positioner axis values (rad) during the test.
    orientation : array_like, shape (3, 3)
        The TCP's orientation in ``frame`` at every pose (default: its Z axis down).

    Returns
    -------
    TestPlan

    Raises
    ------
    InputError
        Unknown tool or frame, a track or table value outside its limits, a size or centre
        that is not clear (the message gives the largest clear edge), or no clear cube at all.
    """
    if not isinstance(tool, str):
        raise InputError("tool must be the name of a tool of the cell")
    T_tool = tool_pose(cell, tool)
    e = _track_value(cell, track)
    v = _table_value(cell, table)
    T_R_X = invert(robot_pose(cell, e)) @ cell.frame_pose(frame, e, 0.0 if v is None else v)
    R_R_TCP = T_R_X[:3, :3] @ validate_pose(make_pose(orientation), "orientation")[:3, :3]
    c = None if centre is None else T_R_X[:3, :3] @ np.asarray(centre, dtype=float) + T_R_X[:3, 3]
    c, capacity = largest_cube(cell.robot, T_tool, R_R_TCP, c)
    if size is not None:
        if not (np.isfinite(size) and size > 0):
            raise InputError(f"size must be a positive edge of the cube (m), got {size!r}")
        if size > capacity:
            raise InputError(f"no cube of edge {size * 1e3:g} mm is clear here: the largest is "
                             f"{capacity * 1e3:.0f} mm; give a smaller size")
    edge, branch = shrink_until_clear(cell.robot, T_tool, R_R_TCP, c,
                                      capacity if size is None else size, shrink=size is None)
    pts = np.vstack([pose_points(edge), line_points(edge), circle_points(edge)])
    T_R = np.tile(np.eye(4), (len(pts), 1, 1))
    T_R[:, :3, :3] = R_R_TCP
    T_R[:, :3, 3] = pts + c
    q = cell.robot.ik(T_R[:5], tool=T_tool).q[:, branch]
    names = [*POSE_NAMES, *(f"line_{k + 1}" for k in range(len(line_points(edge)))),
             *(f"circle_{k + 1}" for k in range(len(circle_points(edge))))]
    return TestPlan(names, invert(T_R_X) @ T_R, frame, tool,
                    None if cell.track is None else e, v, branch, q)

