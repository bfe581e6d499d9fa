"""Simulated touch-up measurements of a virtual cell: the touches, and how they are reached.

The cell given is the *truth*. A simulation places the touches a technician would make, solves
the coupled inverse kinematics so that the recorded joint values really reach the touched points
within every joint, track and table limit, and adds the touch-up error: the TCP is placed at the
point plus an isotropic Gaussian error of ``noise`` (m, 1-sigma per coordinate) and the joint
values of that actual placement are recorded. The result writes the measurement CSV that
``robotcell calibrate PROCEDURE`` reads (joint values ``a1..a6`` in degrees, ``e1``, ``track``,
``point``; see ``docs/simulate.md``) and keeps the true values for comparison. Each procedure
places its own touches (its ``simulate``, in :mod:`robotcell.cell.calibrate.procedures`) with
the tools of this module.

Choices the technician would make are made the same way for every procedure: among candidate
tool orientations (tool Z within 30 deg of straight down, 12 turns about it), the reachable
configuration with the largest manipulability ``|det J|`` per touch; in a cell with a track, one
track position for all touches of a procedure (except the track procedure itself), the one whose
worst touch is best.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robotcell.calibration.measurements import TouchTable, columns_of
from robotcell.calibration.spec import SPECS
from robotcell.cell import Cell, Turntable
from robotcell.cell.kinematics import robot_pose, tool_pose
from robotcell.errors import InputError
from robotcell.io.fileio import atomic_write
from robotcell.kinematics.transforms import invert, transform_points
from robotcell.robot.robot import Robot

#: Candidate track positions when the track position of a procedure is chosen.
TRACK_SAMPLES = 25

#: Most touches one simulation places (memory of the configuration search grows with them).
MAX_TOUCHES = 200


def _down_orientations() -> NDArray[np.float64]:
    """Candidate TCP orientations in the world: tool Z down, tilted 0/15/30 deg, 12 turns."""
    yaw = np.radians(np.arange(0, 360, 30))
    out = []
    for tilt in np.radians([0.0, 15.0, 30.0]):
        for direction in (np.radians([0.0]) if tilt == 0 else np.radians(np.arange(0, 360, 90))):
            tilt_R = Rotation.from_rotvec(tilt * np.array([-math.sin(direction), math.cos(direction), 0.0]))
            for y in yaw:
                R = tilt_R * Rotation.from_euler("zy", [y, math.pi])
                out.append(R.as_matrix())
    return np.array(out)


DOWN = _down_orientations()


@dataclass
class Touches:
    """Simulated measurements of one procedure.

    Attributes
    ----------
    procedure : str
        A procedure that simulates (:mod:`robotcell.cell.calibrate.registry`).
    q : ndarray, shape (N, n)
        Recorded arm joint values (rad).
    track : ndarray, shape (N,), or None
        Robot's track position at each touch (m); None in a cell without track.
    table : ndarray, shape (N,), or None
        Table angle at each touch (rad), for turntable and workpiece; shape (N, 2), the
        positioner's axis values (rad, CSV columns ``e1``, ``e2``), for positioner.
    roles : list of str, or None
        Value of the CSV column ``point`` per touch.
    truth : dict of str to Any
        The true values the calibration should recover (SI units).
    options : list of str
        Options ``robotcell calibrate PROCEDURE`` needs besides the file (mm), e.g.
        ``--reference`` points of the track procedure or ``--height`` of the turntable.
    tool : str or None
        Tool of the cell that touched (None for ``tcp``, which records flange poses).
    noise : float
        Touch-up error used (m, 1-sigma per coordinate).
    track_column : bool
        Whether the table has column ``track`` (not for touches taken in the robot base, as a
        tool's flange poses are, nor for the track's own procedure).
    moves_track : bool
        Whether the track positions are the procedure's axis values (column ``e1``), as in the
        track procedure, which moves the track itself.
    """

    procedure: str
    q: NDArray[np.float64]
    track: NDArray[np.float64] | None
    table: NDArray[np.float64] | None
    roles: list[str] | None
    truth: dict[str, Any]
    options: list[str] = field(default_factory=list)
    tool: str | None = None
    noise: float = 0.0
    track_column: bool = True
    moves_track: bool = False

    def measurements(self, robot: Robot | None = None) -> TouchTable:
        """The touches as the procedure's measurements (SI), which write the measurement CSV.

        Each column of the procedure's specification (:data:`~robotcell.calibration.spec.SPECS`)
        that the simulation has values for is written: the joint values, the external axis
        (``e1``: the track position when the procedure :attr:`moves_track`, else the table's
        axis values), the robot's track position (``track``, unless not :attr:`track_column`:
        a tool's flange poses are taken in the robot base, the track's positions are ``e1``)
        and column ``point``.

        Parameters
        ----------
        robot : Robot, optional
            The arm that touched, for the touches' flange and TCP poses (the written table
            needs none: the simulated arms have revolute joints, in degrees).

        Returns
        -------
        TouchTable
        """
        spec = SPECS[self.procedure]
        axes = self.track if self.moves_track else self.table
        reference = point = None
        if self.roles is not None and spec.role("reference"):
            reference = np.array([float(r) for r in self.roles])
        elif self.roles is not None:
            point = tuple(self.roles)
        return TouchTable(
            spec, "simulated touches", joints=self.q, robot=robot,
            axes=None if axes is None else np.reshape(axes, (len(self.q), -1)),
            track=self.track if self.track_column else None,
            point=point, reference=reference)

    def columns(self) -> tuple[list[str], list[list[str]]]:
        """Header and rows of the measurement CSV (degrees, millimetres).

        Returns
        -------
        header : list of str
        rows : list of list of str
        """
        return self.measurements().text()

    def to_table(self) -> dict[str, Any]:
        """The measurement table as :func:`robotcell.io.tables.read_csv` reads the CSV (mm, deg).

        Returns
        -------
        dict
            Column name to a float array (or a list of strings), the input of
            :mod:`robotcell.cell.calibrate`.
        """
        header, rows = self.columns()
        return columns_of(dict(zip(header, map(list, zip(*rows)))), "simulated touches")

    def keywords(self) -> dict[str, Any]:
        """The :mod:`robotcell.cell.calibrate` keywords equal to :attr:`options` (SI, same rounding).

        Returns
        -------
        dict
            ``references`` (list of (3,) arrays, m) and ``height`` (m), where the options have
            them.
        """
        kw: dict[str, Any] = {}
        for opt in self.options:
            key, value = opt.lstrip("-").split("=")
            numbers = np.array([float(v) for v in value.split(",")]) * 1e-3
            if key == "reference":
                kw.setdefault("references", []).append(numbers)
            else:
                kw[key] = float(numbers[0])
        return kw

    def write_csv(self, out: str | Path | TextIO) -> None:
        """Write the measurement CSV to an open text stream, or to a path atomically.

        Raises
        ------
        InputError
            The path cannot be written (missing folder, a folder, no permission).
        """
        header, rows = self.columns()
        if hasattr(out, "write"):
            _write(out, header, rows)
            return
        buf = io.StringIO(newline="")
        _write(buf, header, rows)
        atomic_write(out, buf.getvalue())


def _write(fh: TextIO, header: list[str], rows: list[list[str]]) -> None:
    w = csv.writer(fh, lineterminator="\n")
    w.writerow(header)
    w.writerows(rows)


# -- reaching the touches --------------------------------------------------------------------------
def candidate_tracks(cell: Cell, track: float | None, n: int) -> NDArray[np.float64]:
    """Track positions to try, shape (K, n): one value for all touches of a procedure."""
    if cell.track is None:
        if track not in (None, 0.0):
            raise InputError("the cell has no track; do not give a track position")
        return np.zeros((1, n))
    if track is not None:
        if not cell.track.within_limits(track):
            raise InputError(f"track position {track * 1e3:g} mm is outside the track limits "
                             f"{cell.track.lower * 1e3:g} .. {cell.track.upper * 1e3:g} mm")
        return np.full((1, n), float(track))
    t = cell.track
    if not (math.isfinite(t.lower) and math.isfinite(t.upper)):
        raise InputError("the cell's track has no limits (min, max), so the simulation cannot "
                         "choose where the robot stands; give the track position")
    return np.repeat(np.linspace(t.lower, t.upper, TRACK_SAMPLES)[:, None], n, axis=1)


def reach(cell: Cell, targets: Callable[[NDArray[np.float64]], NDArray[np.float64]],
           E: NDArray[np.float64], tool_T: NDArray[np.float64] | None, labels: Sequence[str],
           rng: np.random.Generator, noise: float
           ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Joint values that put the TCP at the touches, plus the touch-up error.

    Parameters
    ----------
    targets : callable
        ``targets(E)`` for track positions ``E`` (K, N) gives candidate TCP poses in the world,
        shape (K, N, M, 4, 4) (M candidates per touch, e.g. tool orientations).
    E : ndarray, shape (K, N)
        Candidate track positions (m) per touch; the best row is used.

    Returns
    -------
    q : ndarray, shape (N, n)
        Joint values of the placement with the error (rad).
    e : ndarray, shape (N,)
        Track positions (m).
    """
    if len(labels) > MAX_TOUCHES:
        raise InputError(f"{len(labels)} touches asked for; a simulation places at most "
                         f"{MAX_TOUCHES}")
    robot = cell.robot
    if robot.n_joints != 6:
        raise InputError(f"simulated touches need a six-axis arm; {robot.name} has "
                         f"{robot.n_joints} axes")
    T = targets(E)                                                          # (K, N, M, 4, 4)
    T_R = invert(robot_pose(cell, E))[:, :, None] @ T
    sol = robot.ik(T_R, tool=tool_T)                                        # (K, N, M, 8, n)
    qz = np.where(sol.valid[..., None], sol.q, 0.0)
    manip = np.where(sol.valid, np.abs(np.linalg.det(robot.jacobian(qz, tool=tool_T))), 0.0)
    manip = manip * _usual_configuration(robot, qz)
    K, N, M = manip.shape[:3]
    flat = manip.reshape(K, N, M * 8)
    best = flat.max(axis=-1)                                                # (K, N)
    k = int(np.argmax(best.min(axis=1)))
    if best[k].min() <= 0.0:
        bad = [labels[i] for i in np.flatnonzero(best[k] <= 0.0)]
        raise InputError(f"touch(es) {', '.join(bad)} cannot be reached within the joint limits "
                         f"from {'any track position' if K > 1 else 'this robot position'}; move "
                         "the touched points towards the middle of the robot's reach")
    choice = np.argmax(flat[k], axis=-1)                                    # (N,)
    m, b = np.divmod(choice, 8)
    rows = np.arange(N)
    T_nom = T[k, rows, m]                                                   # (N, 4, 4)
    q_nom = sol.q[k, rows, m, b]
    e = E[k]
    # The touch-up error: the TCP ends up at the point plus a Gaussian offset; record those joints.
    T_act = T_nom.copy()
    T_act[:, :3, 3] += rng.normal(0.0, noise, (N, 3))
    act = robot.ik(invert(robot_pose(cell, e)) @ T_act, tool=tool_T)
    q = act.q[rows, b]
    ok = act.valid[rows, b]
    if not np.all(ok):
        bad = [labels[i] for i in np.flatnonzero(~ok)]
        raise InputError(f"touch(es) {', '.join(bad)} sit at a joint limit: the touch-up error "
                         "moves them outside; move the touched points away from the edge of reach")
    # The branch's principal values may differ from the nominal ones by whole turns: keep the
    # nominal representation (the one inside the limits nearest to it).
    q = q_nom + np.where(robot.prismatic, 0.0, (q - q_nom + math.pi) % (2 * math.pi) - math.pi)
    return q, e


def _usual_configuration(robot: Robot, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Weight 1 for configurations with the wrist centre on the same sides of axis 1 and of the
    lower arm as at the robot's home position (how a technician teaches), 1e-3 for the others;
    all 1 for arms without those configuration flags or without a home position."""
    # imported when touches are placed: the calibrations, which load this module too, solve no IK
    from robotcell.ik import analytic_solver, arm_sides

    if robot.home is None or analytic_solver(robot).method != "opw":
        return np.ones(q.shape[:-1])
    front, elbow = arm_sides(robot, q)
    home_front, home_elbow = arm_sides(robot, robot.home)
    return np.where((front == home_front) & (elbow == home_elbow), 1.0, 1e-3)


def tool_name(cell: Cell, tool: str | None) -> str:
    if tool is None:
        if len(cell.tools) != 1:
            known = ", ".join(sorted(cell.tools)) or "none"
            raise InputError(f"say which tool touches (the cell has: {known})")
        return next(iter(cell.tools))
    tool_pose(cell, tool)  # refuses a name the cell does not have
    return tool


def frame_name(cell: Cell, frame: str | None, parents: tuple[str, ...], what: str) -> str:
    names = [k for k, f in cell.frames.items() if f.parent in parents]
    if frame is None:
        if len(names) != 1:
            raise InputError(f"say which {what} frame to touch (the cell has: "
                             f"{', '.join(names) or 'none'})")
        return names[0]
    if frame not in cell.frames:
        raise InputError(f"unknown frame {frame!r}; the cell has: {', '.join(cell.frames) or 'none'}")
    if cell.frames[frame].parent not in parents:
        raise InputError(f"frame {frame!r} is carried by {cell.frames[frame].parent}; the {what} "
                         f"procedure touches frames carried by {' or '.join(parents)}")
    return frame


def three_point(size: float, repeats: int) -> tuple[NDArray[np.float64], list[str]]:
    if not size > 0:
        raise InputError(f"size must be positive (m), got {size}")
    if repeats < 1:
        raise InputError(f"repeats must be at least 1, got {repeats}")
    pts = {"origin": [0.0, 0.0, 0.0], "x": [size, 0.0, 0.0], "xy": [0.0, size, 0.0]}
    roles = [r for r in ("origin", "x", "xy") for _ in range(repeats)]
    return np.array([pts[r] for r in roles]), roles


def one_axis_table(cell: Cell) -> None:
    """Refuse a cell without a one-axis turntable (the turntable and workpiece procedures)."""
    if cell.turntable is None:
        raise InputError("the cell has no turntable")
    if not isinstance(cell.turntable, Turntable):
        raise InputError(f"the cell's positioner {cell.turntable.name!r} is a chain of "
                         f"{cell.turntable.n_axes} axes; the simulation of the turntable and "
                         "workpiece procedures needs a one-axis turntable")


def table_angles(cell: Cell, angles: ArrayLike | None, n: int) -> NDArray[np.float64]:
    tt = cell.turntable
    assert tt is not None
    if angles is None:
        # An open side: a full turn from the other limit (or -180 .. 180 deg when both are open).
        lo = tt.lower if math.isfinite(tt.lower) else min(-math.pi, tt.upper - 2 * math.pi)
        hi = tt.upper if math.isfinite(tt.upper) else max(math.pi, lo + 2 * math.pi)
        if hi - lo >= 2 * math.pi:
            # Evenly around a full turn centred in the limits (which need not be centred on 0).
            mid = (lo + hi) / 2
            return mid + np.linspace(0.0, 2 * math.pi, n, endpoint=False) - math.pi + math.pi / n
        return np.linspace(lo, hi, n)
    th = np.atleast_1d(np.asarray(angles, dtype=float))
    if th.ndim != 1 or not np.all(np.isfinite(th)):
        raise InputError("table angles must be a list of finite numbers (rad)")
    out = ~tt.within_limits(th)
    if np.any(out):
        raise InputError(f"table angle(s) {', '.join(f'{math.degrees(v):g}' for v in th[out])} deg "
                         "are outside the turntable limits")
    return th


def touched_in_parent(cell: Cell, touches: Touches, m: TouchTable) -> NDArray[np.float64]:
    """The TCP positions of simulated touches (m) in the parent frame of what they calibrate.

    The frame's parent (``touches.truth["parent"]``; a workpiece's is the turntable's): the
    robot base for an item carried by the robot, else the world, through the track position of
    each touch. ``m`` are the touches as measurements (:meth:`Touches.measurements`).
    """
    p_R = m.tcp(tool_pose(cell, touches.tool))
    parent = touches.truth["parent"]
    if parent == "turntable":
        parent = cell.turntable.parent if cell.turntable is not None else "world"
    e = np.zeros(m.n) if m.track is None else m.track
    return p_R if parent == "robot" else transform_points(robot_pose(cell, e), p_R)
