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
from robotcell.controllers.model import Program
from robotcell.controllers.registry import get
from robotcell.errors import InputError
from robotcell.identification.uncertainty import position_sigma
from robotcell.ik.analytic import analytic_solver
from robotcell.ik.config import ARM_FLAGS, flags_of_branch
from robotcell.io.fileio import read_text
from robotcell.kinematics.transforms import invert
from robotcell.programs.check import check_program
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
    vendor = program.vendor
    ctl = get(vendor, "program format")
    ctrl = cell.controller()
    checked = check_program(program, ctrl, pulses_per_degree)
    pts = program.points
    todo = [i for i, p in enumerate(pts)
            if p.pose is not None or (joints == "offline" and p.joints is not None)]
    result = CompensatedProgram(program, kept=len(pts) - len(todo), skipped=list(skipped))
    names = [f"{p.name} (line {p.line})" for p in pts]
    refused: list[tuple[int, str]] = []
    tools: dict[int, NDArray[np.float64]] = {}
    for i in todo:
        cp = checked.points[i]
        if not (np.isfinite(cp.q).all() and np.isfinite(cp.T_world_TCP).all()):
            refused.append((i, "the controller cannot place it: " + "; ".join(cp.problems)))
            continue
        tools[i] = tool_pose_of(cell, vendor, pts[i].tool)
    refuse(refused, "point", names)
    if not todo:
        raise InputError(f"{path}: no Cartesian point to filter (joint points taught on the arm "
                         "stay; joints='offline' filters them)")
    T_world = np.stack([checked.points[i].T_world_TCP for i in todo])
    track = np.array([checked.points[i].track for i in todo])
    table = np.stack([np.asarray(checked.points[i].table, dtype=float) for i in todo])
    q_nom = np.stack([checked.points[i].q for i in todo])
    T_tool = np.stack([tools[i] for i in todo])
    T_R_F = invert(robot_pose(cell, track)) @ T_world @ invert(T_tool)
    q, found, branch = identified_joints(cell, T_R_F, q_nom)
    arm_flags = flags_of_branch(analytic_solver(cell.nominal_robot).method, branch)
    refused += [(todo[k], ("the identified arm cannot reach it in the configuration the nominal "
                           "arm uses (within the axis limits)")) for k in np.flatnonzero(~found)]
    new = [np.eye(4)] * len(todo)
    dpos, drot = np.zeros(len(todo)), np.zeros(len(todo))
    flags = configs(ctrl.robot, q, vendor)
    for k, i in enumerate(todo):
        p = pts[i]
        if not found[k]:
            continue
        if p.pose is not None:
            where = placement(cell, vendor, p.frame)
            new[k] = written_poses(ctrl, where, q[k:k + 1], track[k:k + 1], table[k:k + 1],
                                   T_tool[k])[0]
            before, after = p.pose, new[k]
            if ctl.shared_config and p.config is not None and flags[k] != p.config:
                refused.append((i, (f"its filtered joints need other configuration flags than "
                                    f"the program writes for it ({ctl.label} flags hold for the "
                                    "points after it too); change the point")))
        else:
            before = ctrl.fk(p.joints, track[k], table[k], tool=T_tool[k])
            after = ctrl.fk(q[k], track[k], table[k], tool=T_tool[k])
        dpos[k] = float(np.linalg.norm(after[:3, 3] - before[:3, 3]))
        drot[k] = _angle(before, after)
    refused += [(todo[k], why) for k, why in too_large(dpos, drot, found, max_correction,
                                                        max_rotation)]
    refuse(refused, "point", names)
    T_real = np.stack([cell.fk(q_nom[k], track[k], table[k], tool=T_tool[k])
                       for k in range(len(todo))])
    sigma = np.full(len(todo), np.nan)
    if cell.robot.covariance is not None:
        sigma = np.array([float(position_sigma(cell.robot, q[k], T_tool[k]))
                          for k in range(len(todo))])
    texts = {f: read_text(f, "program file").splitlines() for f in program.files}
    for k, i in enumerate(todo):
        p = pts[i]
        file, _, line = p.where.rpartition(":")
        ok = (ctl.set_pose(texts[file], int(line) - 1, new[k],
                           flags[k] if p.config is not None and not ctl.shared_config else None)
              if p.pose is not None else ctl.set_joints(texts[file], int(line) - 1, q[k]))
        if not ok:
            refused.append((i, f"cannot find its values on {file} line {line}"))
        result.points.append(CompensatedPoint(
            p.name, p.line, "cartesian" if p.pose is not None else "joints", dpos[k], drot[k],
            float(np.linalg.norm(T_real[k, :3, 3] - T_world[k, :3, 3])),
            _angle(T_world[k], T_real[k]), float(sigma[k]), q_nom[k], q[k],
            tuple(int(v) for v in arm_flags[k])))
    refuse(refused, "point", names)
    out = {Path(f).name: "\n".join(lines) + "\n" for f, lines in texts.items()}
    result.files = write_all(folder, out, (*program.files, *inputs))
    return result
