"""Simulated touch-up measurements of a virtual cell, for rehearsing a calibration procedure.

The cell given is the *truth*. A simulation places the touches a technician would make, solves
the coupled inverse kinematics so that the recorded joint values really reach the touched points
within every joint, track and table limit, and adds the touch-up error: the TCP is placed at the
point plus an isotropic Gaussian error of ``noise`` (m, 1-sigma per coordinate) and the joint
values of that actual placement are recorded. The result writes the measurement CSV that
``robotcell calibrate PROCEDURE`` reads (joint values ``a1..a6`` in degrees, ``e1``, ``track``,
``point``; see ``docs/simulate.md``) and keeps the true values for comparison.

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

from robotcell.calibration.measurements import Measurements, columns_of
from robotcell.calibration.spec import SPECS
from robotcell.cell import Cell, Turntable
from robotcell.cell.kinematics import frame_pose, robot_pose, tool_pose
from robotcell.errors import InputError
from robotcell.ik import analytic_solver, arm_sides
from robotcell.io.fileio import atomic_write
from robotcell.kinematics.bounds import within
from robotcell.kinematics.transforms import invert, make_pose, rot_z, transform_points
from robotcell.robot.robot import Robot

__all__ = ["MAX_TOUCHES", "PROCEDURES", "Touches", "check_counts", "simulate"]

#: Procedures that can be simulated, with what they calibrate.
PROCEDURES = {
    "tcp": "a tool's TCP (XYZ 4-point) and orientation (ABC 2-point)",
    "frame": "a base / user frame fixed in the cell (3-point)",
    "track": "the robot's linear track (touches of known reference points)",
    "turntable": "the turntable's root frame (one point on the table at several angles)",
    "workpiece": "a workpiece frame on the turntable (3-point at any table angles)",
    "positioner": "a 2-axis positioner's axis chain (one point on the table at several "
                  "(tilt, rotate) values)",
}

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
        One of :data:`PROCEDURES`.
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

    def measurements(self, robot: Robot | None = None) -> Measurements:
        """The touches as the procedure's measurements (SI), which write the measurement CSV.

        Each column of the procedure's specification (:data:`~robotcell.calibration.spec.SPECS`)
        that the simulation has values for is written: the joint values, the external axis
        (``e1``: the track position of the track procedure, else the table's axis values), the
        robot's track position (``track``; not for ``tcp``, whose flange poses are taken in the
        robot base, nor for ``track``, whose positions are ``e1``) and column ``point``.

        Parameters
        ----------
        robot : Robot, optional
            The arm that touched, for the touches' flange and TCP poses (the written table
            needs none: the simulated arms have revolute joints, in degrees).

        Returns
        -------
        Measurements
        """
        spec = SPECS[self.procedure]
        axes = self.track if self.procedure == "track" else self.table
        reference = point = None
        if self.roles is not None and spec.role("reference"):
            reference = np.array([float(r) for r in self.roles])
        elif self.roles is not None:
            point = tuple(self.roles)
        return Measurements(
            spec, "simulated touches", joints=self.q, robot=robot,
            axes=None if axes is None else np.reshape(axes, (len(self.q), -1)),
            track=None if self.procedure in ("tcp", "track") else self.track,
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


# -- reaching the touches -------------------------------------------------------------------------
def _candidate_tracks(cell: Cell, track: float | None, n: int) -> NDArray[np.float64]:
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


def _reach(cell: Cell, targets: Callable[[NDArray[np.float64]], NDArray[np.float64]],
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
    if robot.home is None or analytic_solver(robot).method != "opw":
        return np.ones(q.shape[:-1])
    front, elbow = arm_sides(robot, q)
    home_front, home_elbow = arm_sides(robot, robot.home)
    return np.where((front == home_front) & (elbow == home_elbow), 1.0, 1e-3)


def _rng(seed: int | np.random.Generator | None) -> np.random.Generator:
    if isinstance(seed, np.random.Generator):
        return seed
    if seed is not None and not (isinstance(seed, (int, np.integer)) and seed >= 0):
        raise InputError(f"seed must be a whole number >= 0, got {seed}")
    return np.random.default_rng(seed)


def _tool_name(cell: Cell, tool: str | None) -> str:
    if tool is None:
        if len(cell.tools) != 1:
            known = ", ".join(sorted(cell.tools)) or "none"
            raise InputError(f"say which tool touches (the cell has: {known})")
        return next(iter(cell.tools))
    tool_pose(cell, tool)  # refuses a name the cell does not have
    return tool


def _frame_name(cell: Cell, frame: str | None, parents: tuple[str, ...], what: str) -> str:
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


def check_counts(design: dict[str, Any]) -> None:
    """Refuse ``touches``, ``positions`` or ``repeats`` above :data:`MAX_TOUCHES` up front.

    Raises
    ------
    InputError
        A count that would place more touches than a simulation places.
    """
    for key in ("touches", "positions", "repeats"):
        if isinstance(design.get(key), (int, np.integer)) and design[key] > MAX_TOUCHES:
            raise InputError(f"{key} {design[key]}: a simulation places at most {MAX_TOUCHES} "
                             "touches")


def _check_noise(noise: float) -> float:
    if not (math.isfinite(noise) and noise >= 0):
        raise InputError(f"noise must be a finite number >= 0 (m), got {noise}")
    return float(noise)


# -- the procedures -------------------------------------------------------------------------------
def _tcp(cell: Cell, rng: np.random.Generator, noise: float, tool: str | None,
         track: float | None, touches: int = 4, tilt: float = math.radians(30.0),
         point: ArrayLike = (1.1, 0.0, 0.25), distance: float = 0.1,
         orientation: bool = True) -> Touches:
    name = _tool_name(cell, tool)
    T_F_TCP = cell.tools[name].T_F_TCP
    least = SPECS["tcp"].minimum
    if touches < least:
        raise InputError(f"the TCP needs at least {least} touches of the reference point, got "
                         f"{touches}")
    if not 0 < tilt < math.pi / 2:
        raise InputError(f"tilt must be between 0 and 90 deg, got {math.degrees(tilt):g} deg")
    p_R = np.asarray(point, dtype=float)
    az = np.linspace(0.0, 2 * math.pi, touches, endpoint=False)
    axes = np.stack([-np.sin(az), np.cos(az), np.zeros_like(az)], axis=1)
    tilt_R = Rotation.from_rotvec(tilt * axes).as_matrix()                  # (N, 3, 3)
    yaw = rot_z(np.radians(np.arange(0, 360, 30)))
    down = Rotation.from_euler("y", math.pi).as_matrix()
    n_tcp = touches
    roles = ["tcp"] * n_tcp + (["-x", "xy"] if orientation else [])
    n = len(roles)
    E = _candidate_tracks(cell, track, n)

    def targets(Ek: NDArray[np.float64]) -> NDArray[np.float64]:
        T_wR = robot_pose(cell, Ek[:, :1])                                   # (K, 1, 4, 4)
        p_w = transform_points(T_wR, p_R)                                    # (K, 1, 3)
        R_w = T_wR[..., None, :3, :3] @ yaw @ down                            # (K, 1, 12, 3, 3)
        R_tcp = np.concatenate([tilt_R[None, :, None] @ R_w, np.broadcast_to(
            R_w, (R_w.shape[0], n - n_tcp) + R_w.shape[2:])], axis=1)        # (K, n, 12, 3, 3)
        pos = np.broadcast_to(p_w[:, :, None], R_tcp.shape[:3] + (3,)).copy()
        if orientation:
            X, Y = R_tcp[:, n_tcp, :, :, 0], R_tcp[:, n_tcp + 1, :, :, 1]
            pos[:, n_tcp] += distance * X                  # the point on the tool's -X axis
            pos[:, n_tcp + 1] -= distance * Y              # the point in the XY plane, +Y
        return make_pose(R_tcp, pos)

    labels = [f"touch {i + 1} ({r})" for i, r in enumerate(roles)]
    q, e = _reach(cell, targets, E, T_F_TCP, labels, rng, noise)
    return Touches("tcp", q, e if cell.track is not None else None, None, roles,
                   truth={"T_F_TCP": T_F_TCP.copy(), "tcp": T_F_TCP[:3, 3].copy()},
                   options=[], tool=None, noise=noise)


def _three_point(size: float, repeats: int) -> tuple[NDArray[np.float64], list[str]]:
    if not size > 0:
        raise InputError(f"size must be positive (m), got {size}")
    if repeats < 1:
        raise InputError(f"repeats must be at least 1, got {repeats}")
    pts = {"origin": [0.0, 0.0, 0.0], "x": [size, 0.0, 0.0], "xy": [0.0, size, 0.0]}
    roles = [r for r in ("origin", "x", "xy") for _ in range(repeats)]
    return np.array([pts[r] for r in roles]), roles


def _frame(cell: Cell, rng: np.random.Generator, noise: float, tool: str | None,
           track: float | None, frame: str | None = None, size: float = 0.2,
           repeats: int = 2) -> Touches:
    name = _frame_name(cell, frame, ("world", "robot"), "fixed")
    tname = _tool_name(cell, tool)
    p_X, roles = _three_point(size, repeats)
    n = len(roles)
    E = _candidate_tracks(cell, track, n)

    def targets(Ek: NDArray[np.float64]) -> NDArray[np.float64]:
        T_wX = frame_pose(cell, name, Ek)                                    # (K, n, 4, 4)
        p_w = transform_points(T_wX, p_X)                                    # (K, n, 3)
        return make_pose(DOWN[None, None], p_w[:, :, None])

    labels = [f"touch {i + 1} ({r})" for i, r in enumerate(roles)]
    q, e = _reach(cell, targets, E, tool_pose(cell, tname), labels, rng, noise)
    fr = cell.frames[name]
    return Touches("frame", q, e if cell.track is not None else None, None, roles,
                   truth={"pose": fr.pose.copy(), "parent": fr.parent, "name": name},
                   tool=tname, noise=noise)


def _track(cell: Cell, rng: np.random.Generator, noise: float, tool: str | None,
           track: float | None, references: ArrayLike | None = None, positions: int = 4,
           travel: float = 1.0) -> Touches:
    if cell.track is None:
        raise InputError("the cell has no track")
    if track is not None:
        raise InputError("the track procedure moves the track itself; do not give a track position")
    t = cell.track
    if not (math.isfinite(t.lower) and math.isfinite(t.upper)):
        raise InputError("the cell's track has no limits (min, max); the simulation needs them to "
                         "place the touches")
    if t.axis not in ("x", "z"):
        raise InputError(f"the track calibration supports track axes x and z; this track moves "
                         f"along {t.axis}")
    if positions < 2:
        raise InputError(f"each reference point needs at least 2 track positions, got {positions}")
    if not (math.isfinite(travel) and travel > 0):
        raise InputError(f"travel must be a positive length (m), got {travel}")
    tname = _tool_name(cell, tool)
    u = t.direction
    o = t.T_L_R0[:3, 3]
    span = (t.upper - t.lower) * t.scale
    if references is None:
        side = np.cross(u, [0.0, 0.0, 1.0]) if abs(u[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
        down = np.cross(side, u)
        refs = np.array([o + (t.lower * t.scale + 0.25 * span) * u + 0.9 * side - 0.3 * down,
                         o + (t.upper * t.scale - 0.25 * span) * u - 0.9 * side - 0.3 * down])
    else:
        refs = np.atleast_2d(np.asarray(references, dtype=float))
        if refs.shape[1:] != (3,):
            raise InputError(f"reference points must have shape (K, 3) (m, in L), got {refs.shape}")
    # Track positions per reference: spread over `travel` around where the robot faces the point.
    centre = (refs - o) @ u / t.scale
    offsets = np.linspace(-travel / 2, travel / 2, positions) / t.scale
    e_all = np.clip(centre[:, None] + offsets, t.lower, t.upper)
    point = np.repeat(np.arange(len(refs)), positions)
    least = SPECS["track"].minimum
    if len(point) < least:
        raise InputError(f"the track calibration needs at least {least} touches; "
                         f"{len(refs)} reference point(s) x {positions} positions give "
                         f"{len(point)}: add positions or reference points")
    e_all = e_all.ravel()
    for k in range(len(refs)):
        if np.ptp(e_all[point == k]) < 0.05:
            raise InputError(f"reference point {k + 1} is beyond the end of the track: its touches "
                             "cannot be spread along the travel")
    n = len(point)
    p_w = transform_points(t.T_world_L, refs[point])                         # (n, 3)

    def targets(Ek: NDArray[np.float64]) -> NDArray[np.float64]:
        return make_pose(DOWN[None, None], np.broadcast_to(p_w[None, :, None], (Ek.shape[0], n, 1, 3)))

    labels = [f"touch {i + 1} (reference {point[i] + 1})" for i in range(n)]
    q, e = _reach(cell, targets, e_all[None, :], tool_pose(cell, tname), labels, rng, noise)
    options = [f"--reference={','.join(f'{v * 1e3:.3f}' for v in r)}" for r in refs]
    return Touches("track", q, e, None, [str(p + 1) for p in point],
                   truth={"T_L_R": t.T_L_R0.copy(), "scale": t.scale, "references": refs},
                   options=options, tool=tname, noise=noise)


def _one_axis_table(cell: Cell) -> None:
    """Refuse a cell without a one-axis turntable (the turntable and workpiece procedures)."""
    if cell.turntable is None:
        raise InputError("the cell has no turntable")
    if not isinstance(cell.turntable, Turntable):
        raise InputError(f"the cell's positioner {cell.turntable.name!r} is a chain of "
                         f"{cell.turntable.n_axes} axes; the simulation of the turntable and "
                         "workpiece procedures needs a one-axis turntable")


def _table_angles(cell: Cell, angles: ArrayLike | None, n: int) -> NDArray[np.float64]:
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


def _turntable(cell: Cell, rng: np.random.Generator, noise: float, tool: str | None,
               track: float | None, touches: int = 6, angles: ArrayLike | None = None,
               radius: float = 0.3, height: float = 0.05) -> Touches:
    _one_axis_table(cell)
    tname = _tool_name(cell, tool)
    if not (math.isfinite(radius) and radius > 0):
        raise InputError(f"radius must be positive (m), got {radius}")
    if not math.isfinite(height):
        raise InputError(f"height must be a finite length (m), got {height}")
    least = SPECS["turntable"].minimum
    if angles is None and touches < least:
        raise InputError(f"the turntable calibration needs at least {least} table angles "
                         f"(touches), got {touches}")
    th = _table_angles(cell, angles, touches)
    n = len(th)
    if n < least:
        raise InputError(f"the turntable calibration needs at least {least} table angles, "
                         f"got {n}")
    p_B = np.array([radius, 0.0, height])

    def targets(Ek: NDArray[np.float64]) -> NDArray[np.float64]:
        T_wB = frame_pose(cell, "turntable", Ek)                              # (K, n, 4, 4)
        p_w = transform_points(T_wB, rot_z(th) @ p_B)                       # (K, n, 3)
        return make_pose(DOWN[None, None], p_w[:, :, None])

    E = _candidate_tracks(cell, track, n)
    labels = [f"touch {i + 1} ({math.degrees(v):.0f} deg)" for i, v in enumerate(th)]
    q, e = _reach(cell, targets, E, tool_pose(cell, tname), labels, rng, noise)
    tt = cell.turntable
    return Touches("turntable", q, e if cell.track is not None else None, th, None,
                   truth={"pose": tt.T_parent_B.copy(), "parent": tt.parent, "radius": radius,
                          "height": height},
                   options=[f"--height={-height * 1e3:g}"], tool=tname, noise=noise)


def _workpiece(cell: Cell, rng: np.random.Generator, noise: float, tool: str | None,
               track: float | None, frame: str | None = None, size: float = 0.15,
               repeats: int = 2, angles: ArrayLike | None = None) -> Touches:
    _one_axis_table(cell)
    name = _frame_name(cell, frame, ("turntable",), "workpiece")
    tname = _tool_name(cell, tool)
    p_W, roles = _three_point(size, repeats)
    n = len(roles)
    if angles is None:
        spread = np.radians(np.linspace(-20.0, 20.0, repeats)) if repeats > 1 else np.zeros(1)
        # +-20 deg, moved onto the nearest limit where the table cannot turn that far.
        th = np.clip(np.tile(spread, 3), cell.turntable.lower, cell.turntable.upper)
    else:
        th = _table_angles(cell, angles, n)
        if th.shape != (n,):
            raise InputError(f"give one table angle per touch ({n}), got {th.size}")
    T_B_W = cell.frames[name].pose
    p_B = transform_points(T_B_W, p_W)

    def targets(Ek: NDArray[np.float64]) -> NDArray[np.float64]:
        T_wB = frame_pose(cell, "turntable", Ek)                              # (K, n, 4, 4)
        p_w = transform_points(T_wB, (rot_z(th) @ p_B[:, :, None])[..., 0])  # (K, n, 3)
        return make_pose(DOWN[None, None], p_w[:, :, None])

    E = _candidate_tracks(cell, track, n)
    labels = [f"touch {i + 1} ({r}, {math.degrees(v):.0f} deg)" for i, (r, v) in enumerate(zip(roles, th))]
    q, e = _reach(cell, targets, E, tool_pose(cell, tname), labels, rng, noise)
    return Touches("workpiece", q, e if cell.track is not None else None, th, roles,
                   truth={"pose": T_B_W.copy(), "parent": "turntable", "name": name},
                   tool=tname, noise=noise)


def _positioner_values(lower: float, upper: float, values: ArrayLike | None,
                       default: NDArray[np.float64], what: str) -> NDArray[np.float64]:
    """Values of one positioner axis (rad): ``values`` checked, else ``default`` clipped."""
    if values is None:
        return np.unique(np.clip(default, lower, upper))
    v = np.atleast_1d(np.asarray(values, dtype=float))
    if v.ndim != 1 or not np.all(np.isfinite(v)):
        raise InputError(f"{what} values must be a list of finite numbers (rad)")
    out = ~within(v, lower, upper)
    if np.any(out):
        raise InputError(f"{what} value(s) {', '.join(f'{math.degrees(x):g}' for x in v[out])} deg "
                         f"are outside the axis limits [{math.degrees(lower):g}, "
                         f"{math.degrees(upper):g}] deg")
    return v


def _positioner(cell: Cell, rng: np.random.Generator, noise: float, tool: str | None,
                track: float | None, tilts: ArrayLike | None = None,
                rotates: ArrayLike | None = None, radius: float = 0.2,
                height: float = 0.0) -> Touches:
    pos = cell.turntable
    if pos is None or pos.n_axes != 2:
        raise InputError("the positioner procedure needs a cell with a positioner of 2 axes "
                         "(tilt, rotate)")
    tname = _tool_name(cell, tool)
    if not radius > 0:
        raise InputError(f"radius must be positive (m), got {radius}")
    t = _positioner_values(pos.lower[0], pos.upper[0], tilts, np.radians([-30.0, 0.0, 30.0]),
                           "tilt")
    r = _positioner_values(pos.lower[1], pos.upper[1], rotates,
                           np.radians([0.0, 90.0, 180.0, 270.0]), "rotate")
    if len(t) < 2 or len(r) < 3:
        raise InputError(f"the positioner calibration needs at least 2 tilt and 3 rotate values, "
                         f"got {len(t)} and {len(r)}")
    v = np.stack(np.meshgrid(t, r, indexing="ij"), axis=-1).reshape(-1, 2)  # (n, 2)
    n = len(v)
    p_P = np.array([radius, 0.0, height])

    def targets(Ek: NDArray[np.float64]) -> NDArray[np.float64]:
        T_wP = frame_pose(cell, "turntable", Ek) @ pos.T_root_P(v)             # (K, n, 4, 4)
        p_w = transform_points(T_wP, p_P)                                    # (K, n, 3)
        return make_pose(DOWN[None, None], p_w[:, :, None])

    E = _candidate_tracks(cell, track, n)
    labels = [f"touch {i + 1} ({math.degrees(a):.0f}, {math.degrees(b):.0f} deg)"
              for i, (a, b) in enumerate(v)]
    q, e = _reach(cell, targets, E, tool_pose(cell, tname), labels, rng, noise)
    return Touches("positioner", q, e if cell.track is not None else None, v, None,
                   truth={"chain": pos.chain, "parent": pos.parent, "point": p_P},
                   tool=tname, noise=noise)


_SIMULATORS = {"tcp": _tcp, "frame": _frame, "track": _track, "turntable": _turntable,
               "workpiece": _workpiece, "positioner": _positioner}


def simulate(cell: Cell, procedure: str, *, noise: float = 1e-4,
             seed: int | np.random.Generator | None = None, tool: str | None = None,
             track: float | None = None, **design: Any) -> Touches:
    """Simulate the touches of a calibration procedure in a virtual cell.

    Parameters
    ----------
    cell : Cell
        The virtual cell: its values are the truth the touches are made in.
    procedure : {"tcp", "frame", "track", "turntable", "workpiece", "positioner"}
    noise : float
        Touch-up error, 1-sigma per coordinate (m); 0 for exact touches.
    seed : int or numpy.random.Generator, optional
        Seed of the touch-up errors.
    tool : str, optional
        Tool of the cell that touches (for ``tcp``: the tool being calibrated); needed when the
        cell has more than one.
    track : float, optional
        Track position of the robot (m) for procedures other than ``track``; default: chosen.
    **design
        The touch design, per procedure (lengths in m, angles in rad):

        - ``tcp``: ``touches`` (4), ``tilt`` (30 deg, of the tool from its mean orientation),
          ``point`` (reference tip in the robot base, (1.1, 0, 0.25)), ``orientation`` (True:
          ABC 2-point touches too), ``distance`` (0.1, of the reference point from the TCP in
          the ABC 2-point touches);
        - ``frame``: ``frame`` (name), ``size`` (0.2, distance of the +X and XY points from the
          origin), ``repeats`` (2 touches per point);
        - ``track``: ``references`` ((K, 3) in L; default two points, one on each side, a
          quarter of the travel from each end), ``positions`` (4 per point), ``travel`` (1.0,
          spread of the track positions per point);
        - ``turntable``: ``touches`` (6), ``angles`` (default evenly around the turn),
          ``radius`` (0.3) and ``height`` (0.05) of the touched point on ``X_B``;
        - ``workpiece``: ``frame`` (name), ``size`` (0.15), ``repeats`` (2), ``angles``;
        - ``positioner`` (2 axes): every combination of ``tilts`` (default -30, 0, 30 deg,
          clipped to the limits) and ``rotates`` (default 0, 90, 180, 270 deg, clipped) of the
          point ``(radius, 0, height)`` (0.2, 0.0) in the plate frame P; ``table`` holds the
          axis values, shape (N, 2).

    Returns
    -------
    Touches

    Raises
    ------
    InputError
        Unknown procedure, tool, frame or design option; a cell without the track or turntable
        the procedure needs; touches that no configuration reaches within the limits.
    """
    if procedure not in _SIMULATORS:
        raise InputError(f"unknown procedure {procedure!r}; choose from {', '.join(PROCEDURES)}")
    noise = _check_noise(noise)
    check_counts(design)
    try:
        return _SIMULATORS[procedure](cell, _rng(seed), noise, tool, track, **design)
    except TypeError as exc:
        if "unexpected keyword" not in str(exc):
            raise
        raise InputError(f"{procedure}: {str(exc).split(') ', 1)[-1]}") from None
