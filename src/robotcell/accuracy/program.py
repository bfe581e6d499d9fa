"""Filtering a robot program (``robotcell program compensate``): every point where it was meant.

A program written for a controller with its nominal model (by an offline-programming tool, by
``program write`` in a cell without an identified arm, on the pendant as Cartesian points) means
each Cartesian point as the TCP pose the nominal model computes. :func:`compensate_program` reads
it (any of the four formats, the readers of ``program check``), finds for each Cartesian point the
joints the controller uses (:func:`robotcell.programs.check.check_program` with the nominal arm:
the configuration as written, or the previous point's), solves the identified arm for the same
pose on the same branch (:func:`robotcell.accuracy.filter.identified_joints`) and writes the
pose the nominal model computes for those joints, with their flags, in the point's frame. The
program's text is changed only there (the controller's ``set_pose`` and ``set_joints``);
every other line stays.

Joint points stay as they are: taught on the real arm, they already put it where the operator
saw it. With ``joints="offline"`` they were computed with the nominal model, mean the TCP where
that model puts it, and are filtered too (new joint values).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robotcell.accuracy.filter import (
    MAX_CORRECTION,
    MAX_ROTATION,
    SIGMA_RELATIVE_TO,
    identified_joints,
    refuse,
    too_large,
)
from robotcell.cell import Cell
from robotcell.cell.kinematics import robot_pose
from robotcell.controllers.base import Controller
from robotcell.controllers.model import Config, Program, ProgramPoint
from robotcell.controllers.registry import get
from robotcell.errors import InputError
from robotcell.identification.uncertainty import position_sigma
from robotcell.ik.analytic import analytic_solver
from robotcell.ik.config import ARM_FLAGS, flags_of_branch
from robotcell.io.fileio import read_text
from robotcell.kinematics.transforms import invert
from robotcell.programs.check import CheckReport, check_program
from robotcell.programs.config import configs
from robotcell.programs.files import check_folder, write_all
from robotcell.programs.formats import read_program
from robotcell.programs.frames import placement, tool_pose_of
from robotcell.programs.write import written_poses

__all__ = ["JOINTS", "CompensatedPoint", "CompensatedProgram", "compensate_program"]

#: What the joint points of a program are: taught on the real arm (kept), or computed offline
#: with the nominal model (filtered).
JOINTS = ("taught", "offline")


@dataclass
class CompensatedPoint:
    """One filtered point.

    Attributes
    ----------
    name : str
        As the program names it.
    line : int
    kind : {"cartesian", "joints"}
    dpos, drot : float
        Size of the correction (m, rad): of the written pose, or for a joint point of the TCP
        the nominal model computes for the new joints against the old.
    error, error_rot : float
        Predicted TCP error without filtering (m, rad).
    sigma : float
        3D RMS of the filtered TCP position's error (m; NaN without a covariance).
    q_old, q_new : ndarray, shape (n,)
        The controller's joints before and after (rad).
    flags : tuple of int
        The configuration kept: the IK branch's shoulder, elbow, wrist flags
        (:func:`robotcell.ik.config.flags_of_branch`).
    """

    name: str
    line: int
    kind: str
    dpos: float
    drot: float
    error: float
    error_rot: float
    sigma: float
    q_old: NDArray[np.float64]
    q_new: NDArray[np.float64]
    flags: tuple[int, int, int] = (-1, -1, -1)


@dataclass
class CompensatedProgram:
    """What :func:`compensate_program` did.

    Attributes
    ----------
    program : Program
        As read.
    points : list of CompensatedPoint
    kept : int
        Points left as they are (taught joint points).
    files : list of str
        Written.
    skipped : list of str
        Motions the reader could not turn into points (not filtered, left in the text).
    """

    program: Program
    points: list[CompensatedPoint] = field(default_factory=list)
    kept: int = 0
    files: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)

    @property
    def largest(self) -> CompensatedPoint | None:
        """The point with the largest correction."""
        return max(self.points, key=lambda p: p.dpos, default=None)

    def to_json(self) -> dict[str, Any]:
        """The points (mm, deg) and the largest correction."""
        big = self.largest

        def num(v: float) -> float | None:
            return None if not math.isfinite(v) else float(v)

        return {
            "program": self.program.name, "format": self.program.vendor, "files": self.files,
            "sigma_relative_to": SIGMA_RELATIVE_TO,
            "kept": self.kept, "skipped": self.skipped,
            "largest": None if big is None else {"name": big.name, "dpos": big.dpos * 1e3,
                                                 "drot": math.degrees(big.drot)},
            "points": [{"name": p.name, "line": p.line, "kind": p.kind, "dpos": p.dpos * 1e3,
                        "drot": math.degrees(p.drot), "error_mm": p.error * 1e3,
                        "error_deg": math.degrees(p.error_rot), "sigma_mm": num(p.sigma * 1e3),
                        **{f"a{i + 1}": math.degrees(v) for i, v in enumerate(p.q_new)},
                        **dict(zip(ARM_FLAGS, p.flags))}
                       for p in self.points],
        }


def _angle(A: NDArray[np.float64], B: NDArray[np.float64]) -> float:
    return float(Rotation.from_matrix(A[:3, :3].T @ B[:3, :3]).magnitude())


def compensate_program(path: str | Path, cell: Cell, folder: str | Path, joints: str = "taught",
                       pulses_per_degree: ArrayLike | None = None,
                       max_correction: float = MAX_CORRECTION, max_rotation: float = MAX_ROTATION,
                       inputs: tuple[str | Path, ...] = ()) -> CompensatedProgram:
    """Filter every Cartesian point of a program and write it to a folder, all files or none.

    Parameters
    ----------
    path : str or Path
        KUKA ``.src`` (with its ``.dat``), ABB ``.mod``, FANUC ``.ls``, YASKAWA ``.jbi``.
    cell : Cell
        The cell, with an identified arm.
    folder : str or Path
        Where the program's files are written under their names (created when missing).
    joints : {"taught", "offline"}
        Joint points taught on the real arm (kept) or computed with the nominal model
        (filtered).
    pulses_per_degree : float or array_like, optional
        YASKAWA station axes.
    max_correction, max_rotation : float
        Largest correction taken (m, rad).
    inputs : tuple of str or Path
        Further files the run read (the cell file), which no output may replace.

    Returns
    -------
    CompensatedProgram
        With what the HTML page of the predicted errors needs
        (:func:`robotcell.report.accuracy.write_program_report`).

    Raises
    ------
    InputError
        An unreadable program, a cell without an identified arm, a folder that cannot be
        written, ``joints`` not one of :data:`JOINTS`.
    FilterRefused
        Points the nominal arm does not reach as written, the identified arm cannot reach in
        that configuration, with a correction above the limits, or whose values cannot be
        changed in the text; each named, nothing written.
    """
    if joints not in JOINTS:
        raise InputError(f"joints must be one of {', '.join(JOINTS)}, got {joints!r}")
    if cell.identified is None:
        raise InputError("the cell has no identified arm (robot.identified): filtering needs "
                         "the arm as it is beside the controller's nominal model")
    check_folder(folder)
    program, skipped = read_program(path)
    ctl = get(program.vendor, "program format")
    ctrl = cell.controller()
    checked = check_program(program, ctrl, pulses_per_degree)
    pts = program.points
    todo = [i for i, p in enumerate(pts)
            if p.pose is not None or (joints == "offline" and p.joints is not None)]
    result = CompensatedProgram(program, kept=len(pts) - len(todo), skipped=list(skipped))
    names = [f"{p.name} (line {p.line})" for p in pts]
    if not todo:
        raise InputError(f"{path}: no Cartesian point to filter (joint points taught on the arm "
                         "stay; joints='offline' filters them)")
    s = _solve(cell, ctrl, program, checked, todo, names)
    new, dpos, drot, refused = _corrections(cell, ctrl, ctl, program, s)
    refused += [(todo[k], why) for k, why in too_large(dpos, drot, s.found, max_correction,
                                                        max_rotation)]
    refuse(refused, "point", names)
    result.points = _compensated_points(cell, pts, s, dpos, drot)
    texts = {f: read_text(f, "program file").splitlines() for f in program.files}
    refuse(_edit(texts, ctl, pts, s, new), "point", names)
    out = {Path(f).name: "\n".join(lines) + "\n" for f, lines in texts.items()}
    result.files = write_all(folder, out, (*program.files, *inputs))
    return result


@dataclass
class _Solved:
    """The points to filter as the controller places them, and the identified arm's joints
    for the same poses (K points).

    Attributes
    ----------
    todo : list of int
        Index of each into the program's points.
    T_world : ndarray, shape (K, 4, 4)
        The TCP the controller computes (m).
    track : ndarray, shape (K,)
        Track values (m).
    table : ndarray, shape (K,) or (K, n)
        Table values (rad).
    q_nom : ndarray, shape (K, n)
        The controller's joints (rad).
    T_tool : ndarray, shape (K, 4, 4)
        ``T_F_TCP`` of each point's tool (m).
    q : ndarray, shape (K, n)
        The identified arm's joints for the same poses on the same branch (rad).
    found : ndarray of bool, shape (K,)
        Whether the identified arm reaches the pose on that branch within its limits.
    arm_flags : ndarray of int, shape (K, 3)
        The branch's shoulder, elbow, wrist flags.
    flags : list of Config
        The vendor's configuration flags of ``q`` (:func:`robotcell.programs.config.configs`).
    """

    todo: list[int]
    T_world: NDArray[np.float64]
    track: NDArray[np.float64]
    table: NDArray[np.float64]
    q_nom: NDArray[np.float64]
    T_tool: NDArray[np.float64]
    q: NDArray[np.float64]
    found: NDArray[np.bool_]
    arm_flags: NDArray[np.int_]
    flags: list[Config]


def _solve(cell: Cell, ctrl: Cell, program: Program, checked: CheckReport, todo: list[int],
           names: list[str]) -> _Solved:
    """The points ``todo`` as the controller places them and the identified arm's joints for
    them; :class:`FilterRefused` naming the points the controller cannot place."""
    vendor, pts = program.vendor, program.points
    refused: list[tuple[int, str]] = []
    tools: dict[int, NDArray[np.float64]] = {}
    for i in todo:
        cp = checked.points[i]
        if not (np.isfinite(cp.q).all() and np.isfinite(cp.T_world_TCP).all()):
            refused.append((i, "the controller cannot place it: " + "; ".join(cp.problems)))
            continue
        tools[i] = tool_pose_of(cell, vendor, pts[i].tool)
    refuse(refused, "point", names)
    T_world = np.stack([checked.points[i].T_world_TCP for i in todo])
    track = np.array([checked.points[i].track for i in todo])
    table = np.stack([np.asarray(checked.points[i].table, dtype=float) for i in todo])
    q_nom = np.stack([checked.points[i].q for i in todo])
    T_tool = np.stack([tools[i] for i in todo])
    T_R_F = invert(robot_pose(cell, track)) @ T_world @ invert(T_tool)
    q, found, branch = identified_joints(cell, T_R_F, q_nom)
    arm_flags = flags_of_branch(analytic_solver(cell.nominal_robot).method, branch)
    flags = configs(ctrl.robot, q, vendor)
    return _Solved(todo, T_world, track, table, q_nom, T_tool, q, found, arm_flags, flags)


def _corrections(cell: Cell, ctrl: Cell, ctl: Controller, program: Program, s: _Solved
                 ) -> tuple[list[NDArray[np.float64]], NDArray[np.float64], NDArray[np.float64],
                            list[tuple[int, str]]]:
    """The poses written for the identified joints, the size of each correction and the points
    refused so far.

    Returns
    -------
    new : list of ndarray, shape (4, 4)
        Per point of ``s``: the TCP the controller's model computes for the identified joints,
        in the point's frame (m); the identity for joint points and points not reached.
    dpos, drot : ndarray, shape (K,)
        Size of each correction (m, rad).
    refused : list of (int, str)
        Points the identified arm cannot reach in the nominal arm's configuration, and points
        whose filtered joints need other flags than a format with shared flags writes.
    """
    vendor, pts, n = program.vendor, program.points, len(s.todo)
    refused = [(s.todo[k], ("the identified arm cannot reach it in the configuration the nominal "
                            "arm uses (within the axis limits)")) for k in np.flatnonzero(~s.found)]
    new = [np.eye(4)] * n
    dpos, drot = np.zeros(n), np.zeros(n)
    for k, i in enumerate(s.todo):
        p = pts[i]
        if not s.found[k]:
            continue
        if p.pose is not None:
            where = placement(cell, vendor, p.frame)
            new[k] = written_poses(ctrl, where, s.q[k:k + 1], s.track[k:k + 1],
                                   s.table[k:k + 1], s.T_tool[k])[0]
            before, after = p.pose, new[k]
            if ctl.shared_config and p.config is not None and s.flags[k] != p.config:
                refused.append((i, (f"its filtered joints need other configuration flags than "
                                    f"the program writes for it ({ctl.label} flags hold for the "
                                    "points after it too); change the point")))
        else:
            before = ctrl.fk(p.joints, s.track[k], s.table[k], tool=s.T_tool[k])
            after = ctrl.fk(s.q[k], s.track[k], s.table[k], tool=s.T_tool[k])
        dpos[k] = float(np.linalg.norm(after[:3, 3] - before[:3, 3]))
        drot[k] = _angle(before, after)
    return new, dpos, drot, refused


def _compensated_points(cell: Cell, pts: list[ProgramPoint], s: _Solved,
                        dpos: NDArray[np.float64], drot: NDArray[np.float64]
                        ) -> list[CompensatedPoint]:
    """Each filtered point with its correction (``dpos``, ``drot``: m, rad), the error the
    identified arm predicts without filtering, and the uncertainty of the filtered TCP."""
    n = len(s.todo)
    T_real = np.stack([cell.fk(s.q_nom[k], s.track[k], s.table[k], tool=s.T_tool[k])
                       for k in range(n)])
    sigma = np.full(n, np.nan)
    if cell.robot.covariance is not None:
        sigma = np.array([float(position_sigma(cell.robot, s.q[k], s.T_tool[k]))
                          for k in range(n)])
    return [CompensatedPoint(
        pts[i].name, pts[i].line, "cartesian" if pts[i].pose is not None else "joints", dpos[k],
        drot[k], float(np.linalg.norm(T_real[k, :3, 3] - s.T_world[k, :3, 3])),
        _angle(s.T_world[k], T_real[k]), float(sigma[k]), s.q_nom[k], s.q[k],
        tuple(int(v) for v in s.arm_flags[k])) for k, i in enumerate(s.todo)]


def _edit(texts: dict[str, list[str]], ctl: Controller, pts: list[ProgramPoint], s: _Solved,
          new: list[NDArray[np.float64]]) -> list[tuple[int, str]]:
    """Write the filtered values into the lines of the program's files (``texts``: file ->
    lines, changed in place): ``new`` poses (m) of Cartesian points, the joints of joint points;
    the points whose values are not found in the text."""
    refused = []
    for k, i in enumerate(s.todo):
        p = pts[i]
        file, _, line = p.where.rpartition(":")
        ok = (ctl.set_pose(texts[file], int(line) - 1, new[k],
                           s.flags[k] if p.config is not None and not ctl.shared_config else None)
              if p.pose is not None else ctl.set_joints(texts[file], int(line) - 1, s.q[k]))
        if not ok:
            refused.append((i, f"cannot find its values on {file} line {line}"))
    return refused
