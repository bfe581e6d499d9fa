"""Long touch files: N touches of every calibration procedure, as a measurement table.

For ``tests/test_calibration_scaling.py`` and ``benchmarks/bench_calibrate.py``. Each design is
a table as :func:`robotcell.io.tables.read_csv` returns a measurement CSV (mm, deg; column
``point`` as text), with 0.1 mm touch noise, for the calibration into a cell
(:mod:`robotcell.cell.calibrate`) named with it.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from robotcell.cell import Cell
from robotcell.cell import calibrate as cellcal
from robotcell.io.poseformats import pose_to_vendor
from robotcell.kinematics.transforms import make_pose, rot_z, transform_points

NOISE = 1e-4
T_FRAME = make_pose(Rotation.from_rotvec([0.1, -0.2, 0.6]).as_matrix(), [1.2, -0.3, 0.5])
T_R_B = make_pose(Rotation.from_rotvec([0.02, -0.01, 0.7]).as_matrix(), [1.2, 0.3, 0.4])
TCP = np.array([0.01, -0.02, 0.2])
PIVOT = np.array([1.1, 0.2, 0.5])
R_TOOL = Rotation.from_euler("zyx", [10, -80, 5], degrees=True).as_matrix()
POSITIONER_CELL = Cell.load(Path(__file__).resolve().parents[1] / "examples"
                            / "cell_kr16_positioner.yaml")


def _points(rng, p):
    """Touched points (m) with noise, as x, y, z columns in mm."""
    p = (p + rng.normal(0.0, NOISE, p.shape)) * 1e3
    return {"x": p[:, 0], "y": p[:, 1], "z": p[:, 2]}


def _roles_and_local(rng, n):
    third = n // 3
    rest = n - 2 * third
    roles = ["origin"] * third + ["x"] * third + ["xy"] * rest
    local = np.concatenate([np.zeros((third, 3)),
                            np.c_[rng.uniform(0.1, 0.4, third), np.zeros((third, 2))],
                            np.c_[rng.uniform(0.0, 0.3, rest), rng.uniform(0.1, 0.3, rest),
                                  np.zeros(rest)]])
    return roles, local


def _flange(rng, tool_points):
    """Flange poses (x..c, mm/deg) placing each tool point on PIVOT, tilted about 35 deg."""
    n = len(tool_points)
    tilt = rng.normal(0.0, 0.6, (n, 3)) * [1, 1, 0.3]
    R = (Rotation.from_rotvec(tilt) * Rotation.from_euler("y", 90, degrees=True)).as_matrix()
    p = PIVOT + rng.normal(0.0, NOISE, (n, 3)) - np.einsum("nij,nj->ni", R, tool_points)
    v = pose_to_vendor(make_pose(R, p), "kuka")
    return dict(zip("xyzabc", v.T))


def tcp(rng, n):
    return cellcal.tcp, None, _flange(rng, np.tile(TCP, (n, 1))), {}


def tcp_abc(rng, n):
    q = n // 4
    points = np.concatenate([np.tile(TCP, (n - 2 * q, 1)),
                             TCP - np.outer(rng.uniform(0.06, 0.12, q), R_TOOL[:, 0]),
                             TCP + np.c_[rng.uniform(0.0, 0.05, q), rng.uniform(0.05, 0.1, q)]
                             @ R_TOOL[:, :2].T])
    table = {**_flange(rng, points), "point": ["tcp"] * (n - 2 * q) + ["-x"] * q + ["xy"] * q}
    return cellcal.tcp, None, table, {}


def frame(rng, n):
    roles, local = _roles_and_local(rng, n)
    table = {**_points(rng, transform_points(T_FRAME, local)), "point": roles}
    return cellcal.frame, None, table, {}


def npoint(rng, n):
    q = rng.uniform(-0.3, 0.3, (n, 3))
    nominal = dict(zip(("nominal_x", "nominal_y", "nominal_z"), (q * 1e3).T))
    return cellcal.frame, None, {**_points(rng, transform_points(T_FRAME, q)), **nominal}, {}


def track(rng, n):
    e = rng.uniform(0.0, 2.0, n)
    table = {**_points(rng, np.array([1.5, 0.8, 0.3]) - np.outer(e, [1, 0, 0])), "e1": e * 1e3}
    return cellcal.track, None, table, {}


def turntable(rng, n):
    theta = rng.uniform(0.0, 2 * np.pi, n)
    f = transform_points(T_R_B, np.einsum("nij,j->ni", rot_z(theta), [0.3, 0.0, 0.0]))
    return cellcal.turntable, None, {**_points(rng, f), "e1": np.degrees(theta)}, {}


def workpiece(rng, n):
    roles, local = _roles_and_local(rng, n)
    theta = rng.uniform(0.0, 2 * np.pi, n)
    on_table = transform_points(make_pose(np.eye(3), [0.05, 0.0, 0.1]), local)
    f = transform_points(T_R_B, np.einsum("nij,nj->ni", rot_z(theta), on_table))
    table = {**_points(rng, f), "e1": np.degrees(theta), "point": roles}
    return cellcal.workpiece, None, table, {"turntable": cellcal.TurntablePose(T_R_B)}


def positioner(with_cell: bool):
    """The positioner of the example cell: with the cell (its chain starts the fit), or without
    (the circle fit of the touches starts it)."""
    def design(rng, n):
        chain = POSITIONER_CELL.turntable.chain
        grid = np.c_[rng.choice([-30.0, 0.0, 30.0], n), rng.choice([0.0, 90.0, 180.0, 270.0], n)]
        grid[:12] = [[t, r] for t in (-30.0, 0.0, 30.0) for r in (0.0, 90.0, 180.0, 270.0)]
        f = (chain.fk(np.radians(grid), np.eye(4)) @ [0.2, 0.0, 0.0, 1.0])[:, :3]
        table = {**_points(rng, f), "e1": grid[:, 0], "e2": grid[:, 1]}
        return cellcal.positioner, POSITIONER_CELL if with_cell else None, table, {}
    return design


DESIGNS = {"tcp": tcp, "tcp-abc-2point": tcp_abc, "frame-3point": frame, "frame-npoint": npoint,
           "track": track, "turntable": turntable, "workpiece": workpiece,
           "positioner": positioner(True), "positioner-from-circles": positioner(False)}


def write_csv(table: dict, path: Path) -> Path:
    """The table as a measurement CSV."""
    with open(path, "w", newline="", encoding="utf-8") as fh:
        out = csv.writer(fh)
        out.writerow(list(table))
        out.writerows(zip(*(c if isinstance(c, list) else [f"{v:.6f}" for v in c]
                            for c in table.values())))
    return path
