"""Measurements for kinematic identification: joint values with measured points or poses.

In SI units (metres, radians) in the measuring device's frame D. The CSV form (millimetres and
degrees) is read by :func:`read_target_measurements`; see ``docs/identification.md``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robotcell.errors import InputError
from robotcell.io.tables import read_csv, require_columns

__all__ = ["TargetMeasurements", "read_target_measurements"]


@dataclass(frozen=True, eq=False)
class TargetMeasurements:
    """Joint values and what a measuring device saw of the last link, per row.

    Attributes
    ----------
    q : ndarray, shape (N, n)
        Controller joint values (rad for revolute, m for prismatic joints).
    points : ndarray, shape (N, K, 3)
        Measured position of each of the K targets (reflectors) in the device frame D (m).
    rotations : ndarray, shape (N, 3, 3) or None
        Measured orientation of the target frame in D (only with K = 1).
    labels : tuple of str
        Name of each row for reports (default ``"1".."N"``).
    """

    q: NDArray[np.float64]
    points: NDArray[np.float64]
    rotations: NDArray[np.float64] | None = None
    labels: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        q = np.asarray(self.q, dtype=float)
        if q.ndim != 2 or q.shape[0] == 0:
            raise InputError(f"joint values must have shape (N, n) with N >= 1, got {q.shape}")
        p = np.asarray(self.points, dtype=float)
        if p.ndim == 2:
            p = p[:, None, :]
        if p.ndim != 3 or p.shape[0] != q.shape[0] or p.shape[2] != 3 or p.shape[1] == 0:
            raise InputError(f"measured points must have shape (N, K, 3) with N = {q.shape[0]} "
                             f"rows, got {p.shape}")
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(p))):
            raise InputError("joint values or measured points contain NaN or infinite values")
        R = self.rotations
        if R is not None:
            R = np.asarray(R, dtype=float)
            if R.shape != (q.shape[0], 3, 3):
                raise InputError(f"measured rotations must have shape ({q.shape[0]}, 3, 3), got {R.shape}")
            if p.shape[1] != 1:
                raise InputError("measured orientations need exactly one target per row")
            err = np.abs(R @ np.swapaxes(R, 1, 2) - np.eye(3)).max(axis=(1, 2))
            bad = np.flatnonzero(~(err < 1e-6) | ~(np.linalg.det(R) > 0))
            if bad.size:
                raise InputError(f"row {bad[0] + 1}: the measured orientation is not a proper rotation")
        labels = tuple(self.labels) or tuple(str(i + 1) for i in range(q.shape[0]))
        if len(labels) != q.shape[0]:
            raise InputError(f"{len(labels)} labels for {q.shape[0]} rows")
        object.__setattr__(self, "q", q)
        object.__setattr__(self, "points", p)
        object.__setattr__(self, "rotations", R)
        object.__setattr__(self, "labels", labels)

    @property
    def n_rows(self) -> int:
        """Number of rows N."""
        return self.q.shape[0]

    @property
    def n_targets(self) -> int:
        """Number of targets K per row."""
        return self.points.shape[1]

    def subset(self, rows: ArrayLike) -> TargetMeasurements:
        """The measurements of the given row indices (or boolean mask)."""
        idx = np.arange(self.n_rows)[rows]
        return TargetMeasurements(self.q[idx], self.points[idx],
                            None if self.rotations is None else self.rotations[idx],
                            tuple(self.labels[i] for i in idx))


_POINT = re.compile(r"^([xyz])(\d*)$")


def read_target_measurements(path: str | Path, prismatic: ArrayLike | None = None) -> TargetMeasurements:
    """Read a measurement CSV (mm, deg; see ``docs/identification.md``).

    Parameters
    ----------
    path : str or Path
        CSV with columns ``a1..aN`` (deg, mm for prismatic joints), ``x,y,z`` or ``x1,y1,z1,...``
        (mm), optionally ``qw,qx,qy,qz`` with one target.
    prismatic : array_like of bool, shape (n,), optional
        Which joints are prismatic (their values are read in mm); default all revolute.

    Returns
    -------
    TargetMeasurements
        In SI units.

    Raises
    ------
    InputError
        Missing or non-numeric columns, inconsistent target columns, no rows.
    """
    cols = read_csv(str(path))
    names = list(cols)
    src = str(path)
    joints = sorted((c for c in names if re.fullmatch(r"a\d+", c)), key=lambda c: int(c[1:]))
    if not joints or [int(c[1:]) for c in joints] != list(range(1, len(joints) + 1)):
        raise InputError(f"{src}: joint columns a1..aN are missing or not numbered 1..N "
                         f"(columns: {', '.join(names)})")
    groups: dict[str, set[str]] = {}
    for c in names:
        m = _POINT.match(c)
        if m:
            groups.setdefault(m.group(2), set()).add(m.group(1))
    incomplete = [k for k, v in groups.items() if v != {"x", "y", "z"}]
    if incomplete or not groups:
        raise InputError(f"{src}: give the measured target as columns x,y,z (mm) or x1,y1,z1,"
                         "x2,y2,z2,... for several targets")
    if "" in groups and len(groups) > 1:
        raise InputError(f"{src}: use either x,y,z (one target) or x1,y1,z1,... (several), not both")
    keys = [""] if "" in groups else sorted(groups, key=int)
    if keys != [""] and [int(k) for k in keys] != list(range(1, len(keys) + 1)):
        raise InputError(f"{src}: target columns must be numbered 1..K, got {', '.join(keys)}")

    n_rows = len(cols[joints[0]])
    pris = np.zeros(len(joints), dtype=bool) if prismatic is None else np.asarray(prismatic, dtype=bool)
    if pris.shape != (len(joints),):
        raise InputError(f"{src}: {len(joints)} joint columns, but the robot has {pris.size} joints")
    q = require_columns(cols, joints, src)
    q = np.where(pris, q * 1e-3, np.radians(q))
    p = np.stack([require_columns(cols, [f"{a}{k}" for a in "xyz"], src) for k in keys], axis=1) * 1e-3
    R = None
    quat = [c in names for c in ("qw", "qx", "qy", "qz")]
    if any(quat):
        if not all(quat):
            raise InputError(f"{src}: an orientation needs all four columns qw,qx,qy,qz")
        if len(keys) != 1:
            raise InputError(f"{src}: an orientation (qw,qx,qy,qz) goes with exactly one target x,y,z")
        wxyz = require_columns(cols, ["qw", "qx", "qy", "qz"], src)
        norm = np.linalg.norm(wxyz, axis=1)
        bad = np.flatnonzero(np.abs(norm - 1.0) > 1e-3)
        if bad.size:
            raise InputError(f"{src}: row {bad[0] + 1}: quaternion qw,qx,qy,qz has length "
                             f"{norm[bad[0]]:.4f}, not 1")
        R = Rotation.from_quat(wxyz[:, [1, 2, 3, 0]]).as_matrix()
    return TargetMeasurements(q, p, R, tuple(f"row {i}" for i in range(1, n_rows + 1)))
