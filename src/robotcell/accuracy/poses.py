"""Filtering a file of poses (``robotcell compensate``): CSV in, CSV of commanded poses out.

The poses file is the path file of ``program write`` (:mod:`robotcell.programs.path`: ``x, y, z``
in mm, ``a, b, c`` in deg as ``R = Rz(a) Ry(b) Rx(c)``, optional ``track`` in mm and ``table`` or
``e1..en`` in deg), with optional configuration columns: ``s, t`` (KUKA Status and Turn),
``cf1, cf4, cf6, cfx`` (ABB confdata) or ``config`` (FANUC, ``N U T, 0, 0, 0``). The output has
one row per pose: ``x, y, z, a, b, c``, the pose to command in the same frame; ``a1..an``, the
controller's joint values (deg; mm for a prismatic axis); the external axes (``track`` mm,
``table`` or ``e1..en`` deg); ``dpos`` (mm) and ``drot`` (deg), the size of the correction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotcell.accuracy.filter import MAX_CORRECTION, FilteredPoses, filter_poses
from robotcell.cell import Cell
from robotcell.controllers.model import Config
from robotcell.controllers.registry import CONTROLLERS
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_to_vendor
from robotcell.io.tables import read_csv, refuse_empty, write_csv
from robotcell.programs.path import read_path, table_columns

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
    warnings : list of str
        Columns of the poses file that were not used.
    """

    result: FilteredPoses
    header: list[str]
    rows: NDArray[np.float64]
    warnings: list[str] = field(default_factory=list)

    def to_json(self) -> dict[str, Any]:
        """``{"points": [{"x": .., "a1": .., "dpos": .., "drot": .., "error_mm": ..,
        "error_deg": .., "sigma_mm": ..}, ...], ...}`` (mm, deg; sigma null without a
        covariance)."""
        r = self.result
        points = []
        for i, row in enumerate(self.rows):
            d: dict[str, Any] = {"point": i + 1, **{k: float(v) for k, v in zip(self.header, row)}}
            d["error_mm"] = float(r.error[i] * 1e3)
            d["error_deg"] = math.degrees(float(r.error_rot[i]))
            d["sigma_mm"] = None if not math.isfinite(r.sigma[i]) else float(r.sigma[i] * 1e3)
            points.append(d)
        return {"points": points, "max_dpos_mm": float(r.dpos.max(initial=0.0) * 1e3),
                "max_error_mm": float(r.error.max(initial=0.0) * 1e3),
                "max_sigma_mm": (None if not np.isfinite(r.sigma).all() or r.sigma.size == 0
                                 else float(r.sigma.max() * 1e3))}


def _configs(path: str, cols: dict) -> list[Config] | None:
    """The configuration columns of the poses file, as flags of one vendor, or None."""
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
    cols = read_csv(path)
    config = _configs(p, cols)
    extra = tuple(k for c in _with_columns() for k in c.csv_config)
    targets = read_path(path, cell, extra)
    if tool not in cell.tools:
        raise InputError(f"tool {tool!r} is not a tool of the cell (tools: "
                         f"{', '.join(cell.tools) or 'none'})")
    r = filter_poses(cell, targets.T, frame, tool, targets.track, targets.table, config,
                     max_correction)
    robot = cell.robot
    qs = np.where(robot.prismatic, 1e3, 180 / math.pi)
    header = [*"xyz", *"abc", *(f"a{i + 1}" for i in range(robot.n_joints))]
    parts = [pose_to_vendor(r.T, "kuka"), r.q * qs]
    if cell.track is not None:
        header.append("track")
        parts.append(r.track[:, None] * 1e3)
    tcols = table_columns(cell)
    if tcols:
        header += tcols
        parts.append(np.degrees(r.table).reshape(len(r.q), -1))
    header += ["dpos", "drot"]
    parts.append(np.column_stack([r.dpos * 1e3, np.degrees(r.drot)]))
    rows = np.hstack(parts)
    if output is not None:
        write_csv(output, header, rows, DECIMALS)
    return CompensatedPoses(r, header, rows, list(targets.warnings))
