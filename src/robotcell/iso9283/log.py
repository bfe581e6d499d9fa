"""The measurement log of an ISO 9283 test: what the tracker recorded, cycle by cycle.

CSV with a header, millimetres and degrees:

| column | | meaning |
|---|---|---|
| ``cycle`` | required | cycle number, a whole number from 1 |
| ``pose`` | required | a test pose of the plan (``P1`` .. ``P5``), or a path of it (``line``, ``circle``) |
| ``x, y, z`` | required | the TCP (the reflector) as measured (mm) |
| ``a, b, c`` | optional | its orientation as measured, ``R = Rz(a) Ry(b) Rx(c)`` (deg), all three or none |
| ``time`` | optional | when the row was measured (s) |

A pose has one row per cycle; a path has its samples in the order measured (by ``time`` when
given), one cycle after another. :func:`read_log` refuses (naming the line) a NaN, a pose or
path the plan lacks, a pose measured twice in a cycle, a cycle number that is not a whole number
from 1, fewer than :data:`robotcell.iso9283.cycles.MIN_CYCLES` cycles of a pose or path, and a
pose that lies more than :data:`MAX_SCATTER` from the median of its cycles (a value in metres
among millimetres, or a row under the wrong pose).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

import numpy as np
from numpy.typing import NDArray

from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor
from robotcell.io.tables import read_csv, unknown_columns_warning
from robotcell.iso9283.cube import POSE_NAMES
from robotcell.iso9283.cycles import MIN_CYCLES
from robotcell.iso9283.planfile import write_table
from robotcell.iso9283.testplan import TestPlan

__all__ = ["MAX_SCATTER", "Log", "read_log", "write_log"]

#: Largest distance of a pose's cycle from the median of its cycles (m): no robot's
#: repeatability is worse; a row farther away is in other units or under the wrong pose.
MAX_SCATTER = 0.010


@dataclass
class Log:
    """Measured poses and path samples, in SI units.

    Attributes
    ----------
    cycle : ndarray of int, shape (N,)
        Cycle number of each row.
    name : list of str
        ``P1`` .. ``P5`` or a path name per row.
    p : ndarray, shape (N, 3)
        Measured positions (m).
    R : ndarray, shape (N, 3, 3), or None
        Measured orientations, when the log has them.
    time : ndarray, shape (N,), or None
        Time stamps (s), when the log has them.
    line : ndarray of int, shape (N,)
        Line of each row in its file (for messages).
    source : str
        The file, for messages.
    """

    cycle: NDArray[np.int_]
    name: list[str]
    p: NDArray[np.float64]
    R: NDArray[np.float64] | None = None
    time: NDArray[np.float64] | None = None
    line: NDArray[np.int_] | None = None
    source: str = "log"

    def __post_init__(self) -> None:
        if self.line is None:
            self.line = np.arange(len(self.name)) + 2

    def rows(self, name: str) -> NDArray[np.int_]:
        """Indices of the rows of pose or path ``name``, in measured order (by time if
        given, else as written)."""
        idx = np.flatnonzero(np.array(self.name, dtype=object) == name)
        if self.time is not None:
            idx = idx[np.argsort(self.time[idx], kind="stable")]
        return idx


def write_log(log: Log, path: str | Path | TextIO) -> None:
    """Write a log as the CSV :func:`read_log` reads (mm, deg, s), atomically to a path.

    Parameters
    ----------
    log : Log
    path : str, Path or text stream
    """
    cols: dict[str, object] = {"cycle": np.asarray(log.cycle, dtype=int),
                               "pose": np.array(log.name, dtype=object)}
    cols.update({k: log.p[:, i] * 1e3 for i, k in enumerate("xyz")})
    if log.R is not None:
        T = np.tile(np.eye(4), (len(log.p), 1, 1))
        T[:, :3, :3] = log.R
        abc = pose_to_vendor(T, "kuka")[:, 3:]
        cols.update({k: abc[:, i] for i, k in enumerate("abc")})
    if log.time is not None:
        cols["time"] = np.asarray(log.time, dtype=float)
    write_table(path, cols, decimals=4)


def _nan_line(cols: dict, names: list[str], path: str) -> None:
    """Refuse the first NaN, naming its line and column."""
    for k in names:
        v = cols.get(k)
        if isinstance(v, np.ndarray):
            bad = np.flatnonzero(np.isnan(v))
            if bad.size:
                raise InputError(f"{path}: line {bad[0] + 2}: column '{k}' is NaN; every "
                                 "value of a log must be measured")


def _numeric(cols: dict, name: str, path: str) -> NDArray[np.float64]:
    v = cols[name]
    if not isinstance(v, np.ndarray):
        i = next(i for i, x in enumerate(v) if _not_number(x))
        raise InputError(f"{path}: line {i + 2}: column '{name}' has {v[i]!r}, not a number")
    return v


def _not_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return True
    return False


def _check_scatter(log: Log) -> None:
    """Refuse a pose's cycle farther than :data:`MAX_SCATTER` from the median of its cycles."""
    for pose in POSE_NAMES:
        idx = log.rows(pose)
        if idx.size == 0:
            continue
        d = np.linalg.norm(log.p[idx] - np.median(log.p[idx], axis=0), axis=1)
        k = int(np.argmax(d))
        if d[k] > MAX_SCATTER:
            raise InputError(
                f"{log.source}: line {log.line[idx[k]]}: {pose} lies {d[k] * 1e3:.1f} mm from the "
                f"median of its cycles, more than {MAX_SCATTER * 1e3:g} mm: a value in metres "
                "among millimetres (mixed units), or a row under the wrong pose; correct it")


def _check_cycles(log: Log, paths: list[str]) -> None:
    """Refuse a pose measured twice in a cycle, and poses or paths with too few cycles."""
    for pose in POSE_NAMES:
        idx = log.rows(pose)
        cycles, first = np.unique(log.cycle[idx], return_index=True)
        if len(cycles) < len(idx):
            twice = np.setdiff1d(np.arange(len(idx)), first)[0]
            raise InputError(f"{log.source}: line {log.line[idx[twice]]}: {pose} of cycle "
                             f"{log.cycle[idx[twice]]} again; a pose has one row per cycle")
    for name in (*POSE_NAMES, *paths):
        idx = log.rows(name)
        n = len(np.unique(log.cycle[idx]))
        if 0 < n < MIN_CYCLES or (n == 0 and name in POSE_NAMES):
            where = f" (its last on line {log.line[idx].max()})" if n else ""
            raise InputError(f"{log.source}: {name} has {n} cycle{'' if n == 1 else 's'}"
                             f"{where}: the figures need at least {MIN_CYCLES} (ISO 9283 "
                             "prescribes 30 for a pose, 10 for a path)")


def read_log(path: str | Path, plan: TestPlan) -> tuple[Log, list[str]]:
    """Read a measurement log and check it against its plan.

    Parameters
    ----------
    path : str or Path
    plan : TestPlan
        Says which poses and paths exist.

    Returns
    -------
    log : Log
    warnings : list of str
        Columns not used (misspelt?).

    Raises
    ------
    InputError
        See the module's description; the message names the file and line.
    """
    p = str(path)
    cols = read_csv(path, allow_nan=True)
    warning = unknown_columns_warning(p, cols, ["cycle", "pose", "x", "y", "z", "a", "b", "c",
                                                "time"])
    missing = [k for k in ("cycle", "pose", "x", "y", "z") if k not in cols]
    if missing:
        raise InputError(f"{p}: missing column(s) {', '.join(missing)} (have: {', '.join(cols)})")
    angles = [k for k in "abc" if k in cols]
    if angles and len(angles) < 3:
        raise InputError(f"{p}: orientation needs all of columns a, b, c (deg), got "
                         f"{', '.join(angles)}")
    numeric = ["cycle", "x", "y", "z", *angles, *(["time"] if "time" in cols else [])]
    values = {k: _numeric(cols, k, p) for k in numeric}
    _nan_line(values, numeric, p)
    cycle = values["cycle"]
    bad = np.flatnonzero((cycle < 1) | (cycle != np.round(cycle)))
    if bad.size:
        raise InputError(f"{p}: line {bad[0] + 2}: cycle {cycle[bad[0]]:g} is not a whole "
                         "number from 1")
    paths = list(plan.paths)
    names = [str(v).strip() for v in cols["pose"]]
    for i, name in enumerate(names):
        if name not in POSE_NAMES and name not in paths:
            raise InputError(f"{p}: line {i + 2}: pose {name!r} is not in the plan (it has "
                             f"{', '.join([*POSE_NAMES, *paths])})")
    xyz = np.column_stack([values[k] for k in "xyz"]) * 1e-3
    R = None
    if angles:
        R = pose_from_vendor(np.column_stack([np.zeros((len(names), 3)),
                                              *(values[k] for k in "abc")]), "kuka")[:, :3, :3]
    log = Log(cycle.astype(int), names, xyz, R, values.get("time"), source=p)
    _check_cycles(log, paths)
    _check_scatter(log)
    return log, [warning] if warning else []
