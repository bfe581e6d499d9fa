"""The test cycles as robot programs: the poses and the paths, for every controller robotcell
writes (:func:`write_programs`).

Each program is written with :func:`robotcell.programs.write_program` from a path file made
here: the pose program moves to P1, then ``cycles`` times through P5, P4, P3, P2, P1 (joint
motions, exact stops); the path program runs ``path_cycles`` times along the line (a joint
motion to its start, then linear motions through its points, blended where the line goes on
straight) and around the circle (a joint motion to its start, then one linear motion per
segment, exact stops: the formats written have no circular motion, so the circle commanded is
that polygon). The track and the table stay where the plan has them.
"""

from __future__ import annotations

import math
import os
import shutil
import tempfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from robotcell.cell import Cell
from robotcell.controllers import registry
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_to_vendor
from robotcell.iso9283.planfile import table_names, write_table
from robotcell.iso9283.testplan import TestPlan
from robotcell.programs import ProgramOptions, write_program

__all__ = [
    "CYCLE_ORDER",
    "LINE_ZONE",
    "MIN_CYCLES",
    "PATH_CYCLES",
    "POSE_CYCLES",
    "PROGRAM_NAMES",
    "path_sequence",
    "pose_sequence",
    "write_programs",
]

#: Cycles of the pose test and of the path test that ISO 9283 prescribes.
POSE_CYCLES, PATH_CYCLES = 30, 10
#: Fewest cycles of a pose or a path that the figures are computed from.
MIN_CYCLES = 10
#: The order of the poses in a cycle, after a first move to P1.
CYCLE_ORDER = ("P5", "P4", "P3", "P2", "P1")
#: Corner distance at the inner points of the line (m): the line goes on straight there.
LINE_ZONE = 0.005
#: Program names (8 characters, the YASKAWA limit).
PROGRAM_NAMES = {"poses": "ISOPOSES", "paths": "ISOPATHS"}


def pose_sequence(plan: TestPlan, cycles: int = POSE_CYCLES) -> tuple[list[str], list[str],
                                                                      list[float]]:
    """The points of the pose program: names, motions and corner distances (m)."""
    names = ["P1"] + list(CYCLE_ORDER) * cycles
    return names, ["ptp"] * len(names), [0.0] * len(names)


def path_sequence(plan: TestPlan, cycles: int = PATH_CYCLES) -> tuple[list[str], list[str],
                                                                      list[float]]:
    """The points of the path program: names, motions and corner distances (m)."""
    names: list[str] = []
    motions: list[str] = []
    zones: list[float] = []
    paths = plan.paths
    for _ in range(cycles):
        for path, T in paths.items():
            n = len(T)
            names += [f"{path}_{k + 1}" for k in range(n)]
            motions += ["ptp"] + ["lin"] * (n - 1)
            inner = LINE_ZONE if path == "line" else 0.0
            zones += [0.0] + [inner] * (n - 2) + [0.0]
    return names, motions, zones


def _path_file(plan: TestPlan, names: list[str], motions: list[str], zones: list[float],
               speed: float, path: Path) -> None:
    """Write the path file of a program (mm, deg, mm/s)."""
    T = plan.T[[plan.names.index(n) for n in names]]
    values = pose_to_vendor(T, "kuka")
    n = len(names)
    cols: dict[str, object] = {k: values[:, i] for i, k in enumerate("xyzabc")}
    cols.update(motion=np.array(motions, dtype=object), speed=np.full(n, speed * 1e3),
                zone=np.array(zones) * 1e3)
    if plan.track is not None:
        cols["track"] = np.full(n, plan.track * 1e3)
    for k, name in enumerate(table_names(plan.table)):
        cols[name] = np.full(n, np.degrees(np.atleast_1d(plan.table)[k]))
    write_table(path, cols)


def write_programs(plan: TestPlan, cell: Cell, folder: str | Path,
                   vendors: Sequence[str] | None = None, cycles: int = POSE_CYCLES,
                   path_cycles: int = PATH_CYCLES, speed: float = 0.1,
                   pulses_per_degree: ArrayLike | None = None) -> list[str]:
    """Write the pose and path programs of a plan for each vendor: all files or none.

    Parameters
    ----------
    plan : TestPlan
    cell : Cell
        The cell the programs are solved in (its controller's model writes the points).
    folder : str or Path
        Output folder (created when missing; its parent must exist); one subfolder per vendor.
    vendors : sequence of str, optional
        Registered controllers (:func:`robotcell.controllers.registry.names`); default every
        one that holds the cell (:meth:`~robotcell.controllers.base.Controller.refusal`: a
        UR-type arm has no other controller's flags, a UR program no external axes).
    cycles, path_cycles : int
        Cycles of the pose and of the path program (at least :data:`MIN_CYCLES`).
    speed : float
        TCP speed along the paths (m/s).
    pulses_per_degree : float or array_like, optional
        YASKAWA: encoder pulses per degree of each station axis (a cell with a turntable).

    Returns
    -------
    list of str
        The files written.

    Raises
    ------
    InputError
        An unknown vendor, too few cycles, a speed that is not positive, a folder that cannot
        be written, or what :func:`robotcell.programs.write_program` refuses; nothing is
        written then.
    """
    known = registry.names()
    if vendors is None:  # every controller that holds the cell's arm and axes
        why = {v: registry.get(v).refusal(cell) for v in known}
        vendors = tuple(v for v in known if why[v] is None)
        if not vendors:
            raise InputError("no controller writes programs of this cell: "
                             + "; ".join(f"{v}: {w}" for v, w in why.items()))
    vendors = tuple(vendors)
    bad = [v for v in vendors if v not in known]
    if bad or not vendors:
        raise InputError(f"unknown program format(s) {bad}; use {', '.join(known)}")
    for what, n in (("cycles", cycles), ("path_cycles", path_cycles)):
        if not (isinstance(n, (int, np.integer)) and MIN_CYCLES <= n <= 10_000):
            raise InputError(f"{what} must be a whole number from {MIN_CYCLES} to 10000, got {n!r}")
    if not (math.isfinite(speed) and speed > 0):
        raise InputError(f"speed must be a positive TCP speed (m/s), got {speed!r}")
    out = Path(folder)
    if (out.exists() and not out.is_dir()) or not out.parent.is_dir():
        raise InputError(f"cannot write programs into {str(folder)!r}: give a folder whose "
                         "parent folder exists")
    staging = Path(tempfile.mkdtemp(prefix=".iso9283.", dir=out.parent))
    try:
        sources = {}
        for kind, (names, motions, zones) in (("poses", pose_sequence(plan, cycles)),
                                              ("paths", path_sequence(plan, path_cycles))):
            sources[kind] = staging / f"{kind}.csv"
            _path_file(plan, names, motions, zones, speed, sources[kind])
        for vendor in vendors:
            for kind, source in sources.items():
                write_program(source, cell, plan.tool, plan.frame, vendor, staging / vendor,
                              name=PROGRAM_NAMES[kind], options=ProgramOptions(max_step=math.pi),
                              pulses_per_degree=pulses_per_degree)
        written = []
        out.mkdir(exist_ok=True)
        for vendor in vendors:
            (out / vendor).mkdir(exist_ok=True)
            for f in sorted((staging / vendor).iterdir()):
                os.replace(f, out / vendor / f.name)
                written.append(str(out / vendor / f.name))
        return written
    finally:
        shutil.rmtree(staging, ignore_errors=True)
