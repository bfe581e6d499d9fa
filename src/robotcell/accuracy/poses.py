"""Filtering a file of poses (``robotcell compensate``): CSV in, CSV of commanded poses out.

The poses file is the path file of ``program write`` (:mod:`robotcell.programs.path`: ``x, y, z``
in mm, ``a, b, c`` in deg as ``R = Rz(a) Ry(b) Rx(c)``, optional ``track`` in mm and ``table`` or
``e1..en`` in deg), with optional configuration columns, per pose: a controller's flags, ``s, t``
(KUKA Status and Turn), ``cf1, cf4, cf6, cfx`` (ABB confdata) or ``config`` (FANUC, ``N U T, 0,
0, 0``); or the solver's own flags ``shoulder, elbow, wrist`` (0 or 1,
:mod:`robotcell.ik.config`), which every arm type has (a Universal Robots arm has no controller
flags); and reference joints ``near_a1..near_an`` (deg; mm for a prismatic axis): the solution
nearest them, as URScript's ``get_inverse_kin(x, qnear)`` chooses (among those with the flags, when
flags are given too). Without any, the nominal arm's solution nearest to the robot's home.

The output has one row per pose: ``x, y, z, a, b, c``, the pose to command in the same frame;
``a1..an``, the controller's joint values (deg; mm for a prismatic axis); ``shoulder, elbow,
wrist``, the configuration they are in; the external axes (``track`` mm, ``table`` or ``e1..en``
deg); ``dpos`` (mm) and ``drot`` (deg), the size of the correction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

import numpy as np
from numpy.typing import NDArray

from robotcell.accuracy.filter import (
    MAX_CORRECTION,
    SIGMA_RELATIVE_TO,
    FilteredPoses,
    filter_poses,
)
from robotcell.cell import Cell
from robotcell.cell.validation import table_columns
from robotcell.controllers.model import Config
from robotcell.controllers.registry import CONTROLLERS, get
from robotcell.errors import InputError
from robotcell.ik.analytic import analytic_solver
from robotcell.ik.config import ARM_FLAGS
from robotcell.io.poseformats import pose_to_vendor
from robotcell.io.tables import refuse_empty, require_columns, write_columns
from robotcell.programs.path import read_path

__all__ = ["CompensatedPoses", "compensate_poses"]
#: Decimals of the output (mm, deg): 1e-9 mm and deg, as the program formats.
DECIMALS = 9


@dataclass
class CompensatedPoses:
    """What :func:`compensate_poses` computed (and wrote).

    Attributes
    ----------
    result : FilteredPoses
    header : list of str
        The output's columns.
    rows : ndarray, shape (N, len(header))
        The output's values (mm, deg).
    chosen_by : str
        How the configurations were chosen: ``by the columns s, t``, ``by the columns
        shoulder, elbow, wrist``, ``nearest near_a1..near_a6``, ``nearest the robot's home``
        (flags and reference joints joined by ``, ``).
    warnings : list of str
        Columns of the poses file that were not used.
    """

    result: FilteredPoses
    header: list[str]
    rows: NDArray[np.float64]
    chosen_by: str = "nearest the robot's home"
    warnings: list[str] = field(default_factory=list)

    def write(self, destination: str | Path | TextIO) -> None:
        """Write the output CSV (a path atomically, or an open stream); the flags as integers."""
        columns = {h: (v.astype(int) if h in ARM_FLAGS else v)
                   for h, v in zip(self.header, self.rows.T)}
        write_columns(destination, columns, DECIMALS)

    def to_json(self) -> dict[str, Any]:
        """``{"points": [{"x": .., "a1": .., "shoulder": .., "elbow": .., "wrist": ..,
        "branch": .., "dpos": .., "drot": .., "error_mm": .., "error_deg": .., "sigma_mm": ..,
        "sigma_axes_mm": [..], "radius95_mm": ..}, ...], "configuration": .., ...}`` (mm, deg;
        ``sigma_mm`` the 3D RMS of the filtered position's error, ``sigma_axes_mm`` its 1-sigma
        along the robot base's x, y, z, ``radius95_mm`` the radius holding it with 95 %
        probability; null without a covariance; ``sigma_relative_to`` the frame they are relative
        to, ``"device"``, see :func:`~robotcell.accuracy.filter.sigma_text`)."""
        r = self.result
        points = []
        for i, row in enumerate(self.rows):
            d: dict[str, Any] = {"point": i + 1, **{k: float(v) for k, v in zip(self.header, row)}}
            d.update({k: int(v) for k, v in zip(ARM_FLAGS, r.flags[i])}, branch=int(r.branch[i]))
            d["error_mm"] = float(r.error[i] * 1e3)
            d["error_deg"] = math.degrees(float(r.error_rot[i]))
            d["sigma_mm"] = None if not math.isfinite(r.sigma[i]) else float(r.sigma[i] * 1e3)
            d["sigma_axes_mm"] = (None if not np.isfinite(r.sigma_axes[i]).all()
                                  else [float(v * 1e3) for v in r.sigma_axes[i]])
            d["radius95_mm"] = (None if not math.isfinite(r.radius95[i])
                                else float(r.radius95[i] * 1e3))
            points.append(d)
        return {"points": points, "configuration": self.chosen_by,
                "sigma_relative_to": SIGMA_RELATIVE_TO,
                "max_dpos_mm": float(r.dpos.max(initial=0.0) * 1e3),
                "max_error_mm": float(r.error.max(initial=0.0) * 1e3),
                "max_sigma_mm": (None if not np.isfinite(r.sigma).all() or r.sigma.size == 0
                                 else float(r.sigma.max() * 1e3)),
                "max_radius95_mm": (None if not np.isfinite(r.radius95).all()
                                    or r.radius95.size == 0 else float(r.radius95.max() * 1e3))}


def _configs(path: str, cols: dict) -> list[Config] | None:
    """The controller's configuration columns of the poses file, as flags of one vendor, or None."""
    given = [c for c in CONTROLLERS.values() if any(k in cols for k in c.csv_config)]
    if not given:
        return None
    if len(given) > 1:
        sets = [", ".join(c.csv_config) for c in _with_columns()]
        raise InputError(f"{path}: configuration columns of {' and '.join(c.name for c in given)}"
                         f": give one vendor's ({'; '.join(sets[:-1])}; or {sets[-1]})")
    ctl = given[0]
    missing = [c for c in ctl.csv_config if c not in cols]
    if missing:
        raise InputError(f"{path}: missing column(s) {', '.join(missing)} of the {ctl.name} "
                         "configuration")
    refuse_empty(cols, list(ctl.csv_config), path, optional=True)  # no configuration of one pose alone
    return ctl.configs_from_columns(path, cols)


def _with_columns() -> list:
    """The controllers whose flags a poses file may give in columns."""
    return [c for c in CONTROLLERS.values() if c.csv_config]


def _arm_flags(path: str, cols: dict) -> NDArray[np.int_] | None:
    """The solver's flags ``shoulder, elbow, wrist`` of the poses file (N, 3), or None."""
    if not any(k in cols for k in ARM_FLAGS):
        return None
    values = require_columns(cols, ARM_FLAGS, path)  # all three, a value on every line
    bad = np.argwhere(~np.isin(values, (0.0, 1.0)))
    if bad.size:
        i, j = bad[0]
        raise InputError(f"{path}: line {i + 2}: column '{ARM_FLAGS[j]}' must be 0 or 1, got "
                         f"{values[i, j]:g} (docs/accuracy.md: the configuration flags)")
    return values.astype(int)


def _near(path: str, cols: dict, cell: Cell) -> NDArray[np.float64] | None:
    """The reference joints ``near_a1..near_an`` of the poses file (rad, m), or None."""
    names = _near_columns(cell)
    if not any(k in cols for k in names):
        return None
    q = require_columns(cols, names, path)  # every axis, a value on every line
    return q * np.where(cell.robot.prismatic, 1e-3, math.pi / 180)


def _near_columns(cell: Cell) -> list[str]:
    """``near_a1..near_an`` for the cell's arm."""
    return [f"near_a{i + 1}" for i in range(cell.robot.n_joints)]


def _chosen_by(flag_columns: tuple[str, ...], near: bool, n_joints: int) -> str:
    """How the configurations are chosen, for the output."""
    parts = [f"by the columns {', '.join(flag_columns)}"] if flag_columns else []
    if near:
        parts.append(f"nearest near_a1..near_a{n_joints}")
    elif not flag_columns:
        parts.append("nearest the robot's home")
    return ", ".join(parts)


def _configuration(path: str, cols: dict, cell: Cell
                   ) -> tuple[list[Config] | NDArray[np.int_] | None, NDArray[np.float64] | None,
                              str]:
    """The configuration columns of the poses file: the flags (a controller's or the solver's),
    the reference joints, and how they choose (:func:`_chosen_by`)."""
    vendor, arm = _configs(path, cols), _arm_flags(path, cols)
    if vendor is not None and arm is not None:
        raise InputError(f"{path}: columns {', '.join(ARM_FLAGS)} and a controller's flags "
                         f"({', '.join(get(vendor[0].vendor).csv_config)}): give one kind of "
                         "configuration")
    method = "opw" if vendor is None else analytic_solver(cell.nominal_robot).method
    if method != "opw":
        raise InputError(f"{path}: columns {', '.join(get(vendor[0].vendor).csv_config)} are "
                         f"{vendor[0].vendor}'s flags of an arm with a spherical wrist; "
                         f"{cell.nominal_robot.name} is a {method.upper()}-type arm: give its "
                         f"configuration as columns {', '.join(ARM_FLAGS)} (0 or 1) or its "
                         f"joints near_a1..near_a{cell.robot.n_joints} (deg)")
    near = _near(path, cols, cell)
    used = get(vendor[0].vendor).csv_config if vendor is not None else (
        ARM_FLAGS if arm is not None else ())
    return (vendor if vendor is not None else arm), near, _chosen_by(
        tuple(used), near is not None, cell.robot.n_joints)


def compensate_poses(path: str | Path, cell: Cell, tool: str, frame: str = "world",
                     output: str | Path | None = None, max_correction: float = MAX_CORRECTION
                     ) -> CompensatedPoses:
    """Filter the poses of a file and write the poses to command (all or nothing).

    Parameters
    ----------
    path : str or Path
        The poses file (module docstring).
    cell : Cell
        A cell with an identified arm.
    tool : str
        A tool of the cell.
    frame : str
        ``world`` or a frame of the cell: the frame of the poses.
    output : str or Path, optional
        The CSV to write (atomically; not written when a pose is refused).
    max_correction : float
        Largest correction taken (m).

    Returns
    -------
    CompensatedPoses
        With what the HTML page of the predicted errors needs
        (:func:`robotcell.report.accuracy.write_poses_report`).

    Raises
    ------
    InputError
        A bad file, tool or frame, a cell without an identified arm.
    FilterRefused
        Poses that cannot be filtered, each named (nothing written).
    """
    p = str(path)
    extra = (*(k for c in _with_columns() for k in c.csv_config), *ARM_FLAGS, *_near_columns(cell))
    targets = read_path(path, cell, extra)
    config, near, chosen_by = _configuration(p, targets.extra, cell)
    if tool not in cell.tools:
        raise InputError(f"tool {tool!r} is not a tool of the cell (tools: "
                         f"{', '.join(cell.tools) or 'none'})")
    r = filter_poses(cell, targets.T, frame, tool, targets.track, targets.table, config, near,
                     max_correction)
    robot = cell.robot
    qs = np.where(robot.prismatic, 1e3, 180 / math.pi)
    header = [*"xyz", *"abc", *(f"a{i + 1}" for i in range(robot.n_joints)), *ARM_FLAGS]
    parts = [pose_to_vendor(r.T, "kuka"), r.q * qs, r.flags]
    if cell.track is not None:
        header.append("track")
        parts.append(r.track[:, None] * 1e3)
    tcols = table_columns(cell)
    if tcols:
        header += tcols
        parts.append(np.degrees(r.table).reshape(len(r.q), -1))
    header += ["dpos", "drot"]
    parts.append(np.column_stack([r.dpos * 1e3, np.degrees(r.drot)]))
    result = CompensatedPoses(r, header, np.hstack(parts), chosen_by, list(targets.warnings))
    if output is not None:
        result.write(output)
    return result
