"""The plan file: the commanded poses of an ISO 9283 test as CSV (mm, deg).

| column | | meaning |
|---|---|---|
| ``pose`` | required | ``P1`` .. ``P5``; a path's points ``line_1``, ``line_2``, ..., ``circle_1``, ... |
| ``x, y, z`` | required | TCP position in the frame (mm) |
| ``a, b, c`` | required | TCP orientation, ``R = Rz(a) Ry(b) Rx(c)`` (deg), the cell's convention |
| ``track`` | optional | the robot's track position (mm), the same on every line |
| ``table`` or ``e1..en`` | optional | turntable angle or positioner axes (deg), the same on every line |
| ``frame`` | optional | the frame of the poses (default ``world``), the same on every line |
| ``tool`` | optional | the tool whose TCP is commanded, the same on every line |
"""

from __future__ import annotations

import csv
import io
import re
from collections.abc import Mapping
from pathlib import Path
from typing import TextIO

import numpy as np
from numpy.typing import ArrayLike

from robotcell.errors import InputError
from robotcell.io.fileio import atomic_write
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor
from robotcell.io.tables import read_csv, require_columns, unknown_columns_warning
from robotcell.iso9283.cube import POSE_NAMES
from robotcell.iso9283.testplan import TestPlan

__all__ = ["read_plan", "table_names", "write_plan", "write_table"]

_NAME = re.compile(r"^(P[0-9]+|[a-z][a-z0-9]*_[0-9]+)$")
_POSE = ("x", "y", "z", "a", "b", "c")


def write_table(path: str | Path | TextIO, columns: Mapping[str, ArrayLike],
                decimals: int = 6) -> None:
    """Write named columns as CSV: text as it is, whole numbers as such, other numbers with
    ``decimals`` fixed decimals; to a path (atomically) or an open stream.

    Parameters
    ----------
    path : str, Path or text stream
    columns : mapping of str to array_like, each of shape (N,)
    decimals : int
    """
    def cells(v: ArrayLike) -> list[str]:
        a = np.asarray(v)
        if a.dtype.kind in "OUS":
            return [str(x) for x in a]
        if a.dtype.kind in "iu":
            return [str(int(x)) for x in a]
        return [f"{x:.{decimals}f}" for x in a.astype(float)]

    text = [cells(v) for v in columns.values()]
    buf = io.StringIO(newline="")
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(list(columns))
    w.writerows(zip(*text))
    if isinstance(path, (str, Path)):
        atomic_write(path, buf.getvalue())
    else:
        path.write(buf.getvalue())


def table_names(table: np.ndarray | None) -> list[str]:
    """The columns of a plan's table values: none, ``table`` (one value), ``e1..en``."""
    if table is None:
        return []
    return ["table"] if np.ndim(table) == 0 else [f"e{i + 1}" for i in range(np.size(table))]


def write_plan(plan: TestPlan, path: str | Path | TextIO) -> None:
    """Write the plan file (atomically to a path, or to an open stream).

    Parameters
    ----------
    plan : TestPlan
    path : str, Path or text stream
    """
    n = len(plan.names)
    values = pose_to_vendor(plan.T, "kuka")
    cols: dict[str, object] = {"pose": np.array(plan.names, dtype=object)}
    cols.update({k: values[:, i] for i, k in enumerate(_POSE)})
    if plan.track is not None:
        cols["track"] = np.full(n, plan.track * 1e3)
    for k, name in enumerate(table_names(plan.table)):
        cols[name] = np.full(n, np.degrees(np.atleast_1d(plan.table)[k]))
    cols["frame"] = np.array([plan.frame] * n, dtype=object)
    cols["tool"] = np.array([plan.tool] * n, dtype=object)
    write_table(path, cols)


def _same(cols: dict, name: str, path: str, default: object) -> object:
    """The one value of column ``name`` (refusing lines that differ), or ``default``."""
    if name not in cols:
        return default
    values = cols[name]
    first = values[0]
    differ = [i for i, v in enumerate(values) if v != first]
    if differ:
        raise InputError(f"{path}: line {differ[0] + 2}: column '{name}' has {values[differ[0]]}, "
                         f"not {first} as on line 2: a plan has one {name} for every pose")
    return first


def read_plan(path: str | Path) -> tuple[TestPlan, list[str]]:
    """Read a plan file.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    plan : TestPlan
    warnings : list of str
        Columns not used (misspelt?).

    Raises
    ------
    InputError
        A missing column, a pose named twice or not as a plan names them, a plan without P1..P5,
        values that differ between lines where a plan has one; the message names the line.
    """
    p = str(path)
    cols = read_csv(path)
    known = ["pose", *_POSE, "track", "table", "frame", "tool",
             *(c for c in cols if re.fullmatch(r"e[0-9]", c))]
    warning = unknown_columns_warning(p, cols, known)
    if "pose" not in cols:
        raise InputError(f"{p}: missing column pose (have: {', '.join(cols)})")
    names = [str(v).strip() for v in cols["pose"]]
    for i, name in enumerate(names):
        if not _NAME.match(name):
            raise InputError(f"{p}: line {i + 2}: pose {name!r} is not a plan's name: P1..P5, or "
                             "a path's point such as line_1")
        if name in names[:i]:
            raise InputError(f"{p}: line {i + 2}: pose {name!r} is named twice")
    missing = [n for n in POSE_NAMES if n not in names]
    if missing:
        raise InputError(f"{p}: the plan lacks the test pose(s) {', '.join(missing)}")
    T = pose_from_vendor(require_columns(cols, _POSE, p), "kuka")
    track = _same(cols, "track", p, None)
    axes = sorted(c for c in cols if re.fullmatch(r"e[0-9]", c))
    if "table" in cols and axes:
        raise InputError(f"{p}: columns table and {', '.join(axes)}: give one or the other")
    table = None
    if "table" in cols:
        table = np.radians(float(_same(cols, "table", p, 0.0)))
    elif axes:
        table = np.radians([float(_same(cols, a, p, 0.0)) for a in axes])
    frame = str(_same(cols, "frame", p, "world")).strip()
    tool = str(_same(cols, "tool", p, "")).strip()
    plan = TestPlan(names, T, frame, tool, None if track is None else float(track) * 1e-3,
                    None if table is None else np.asarray(table, dtype=float))
    return plan, [warning] if warning else []
