"""Calibration speed on long touch files: every procedure at 1,000 and 10,000 touches.

Run: ``PYTHONPATH=src python benchmarks/bench_calibrate.py [N ...]`` (default 1000 10000). For
each procedure a CSV of N touches (x, y, z in mm, or flange poses for the tool; 0.1 mm touch
noise) is calibrated as ``robotcell calibrate PROCEDURE FILE --sigma 0.1`` does it: the
measurement file read, the calibration (fit, covariance, the leave-one-out test of every touch),
the terminal report and the JSON. Prints the wall time, the time per touch, and how the time
grows from the first N to the last (linear cost: the ratio of the times is at most the ratio of
the N). Each procedure runs once on 100 touches first (imports, first calls). Target: 10,000
touches of any procedure in seconds.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

sys.path.insert(0, str(Path(__file__).parent))
from machine import describe

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


def write(path: Path, header: list[str], rows: np.ndarray, roles: list[str] | None = None) -> str:
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(",".join(header + (["point"] if roles else [])) + "\n")
        fh.writelines(",".join(f"{v:.6f}" for v in row) + (f",{roles[i]}" if roles else "") + "\n" for i, row in enumerate(rows))
    return str(path)


def flange_rows(rng, tool_points):
    """Flange poses (KUKA x..c, mm/deg) placing each tool point on PIVOT, tilted about 35 deg."""
    n = len(tool_points)
    tilt = rng.normal(0.0, 0.6, (n, 3)) * [1, 1, 0.3]
    R = (Rotation.from_rotvec(tilt) * Rotation.from_euler("y", 90, degrees=True)).as_matrix()
    p = PIVOT + rng.normal(0.0, NOISE, (n, 3)) - np.einsum("nij,nj->ni", R, tool_points)
    return pose_to_vendor(make_pose(R, p), "kuka")


def cases(n: int, folder: Path, rng) -> dict[str, tuple]:
    """Procedure name -> (calibration, file, keywords) for N touches."""
    def noisy(p):
        return (p + rng.normal(0.0, NOISE, p.shape)) * 1e3

    third = n // 3
    roles3 = ["origin"] * third + ["x"] * third + ["xy"] * (n - 2 * third)
    local = np.concatenate([np.zeros((third, 3)),
                            np.c_[rng.uniform(0.1, 0.4, third), np.zeros((third, 2))],
                            np.c_[rng.uniform(0.0, 0.3, n - 2 * third),
                                  rng.uniform(0.1, 0.3, n - 2 * third), np.zeros(n - 2 * third)]])
    nominal = rng.uniform(-0.3, 0.3, (n, 3)) * [1, 1, 0.3]
    e = rng.uniform(0.0, 2.0, n)
    theta = rng.uniform(0.0, 2 * np.pi, n)
    table = transform_points(T_R_B, np.einsum("nij,j->ni", rot_z(theta), [0.3, 0.0, 0.0]))
    wp = transform_points(T_R_B, np.einsum("nij,nj->ni", rot_z(theta),
                                           transform_points(make_pose(np.eye(3), [0.05, 0, 0.1]),
                                                            local)))
    quarter = n // 4
    abc = np.concatenate([np.tile(TCP, (n - 2 * quarter, 1)),
                          TCP - np.outer(rng.uniform(0.06, 0.12, quarter), R_TOOL[:, 0]),
                          TCP + np.c_[rng.uniform(0.0, 0.05, quarter),
                                      rng.uniform(0.05, 0.1, quarter)] @ R_TOOL[:, :2].T])
    roles_abc = ["tcp"] * (n - 2 * quarter) + ["-x"] * quarter + ["xy"] * quarter
    chain = Cell.load(Path(__file__).parents[1] / "examples" / "cell_kr16_positioner.yaml"
                      ).turntable.chain
    grid = np.radians(np.c_[rng.choice([-30.0, 0.0, 30.0], n), rng.choice(
        [0.0, 90.0, 180.0, 270.0], n)])
    grid[:12] = np.radians([[t, r] for t in (-30.0, 0.0, 30.0) for r in (0.0, 90.0, 180.0, 270.0)])
    plate = (chain.fk(grid, np.eye(4)) @ [0.2, 0.0, 0.0, 1.0])[:, :3]
    xyz = ["x", "y", "z"]
    return {
        "tcp": (cellcal.tcp, write(folder / "tcp.csv", list("xyzabc"),
                                   flange_rows(rng, np.tile(TCP, (n, 1)))), {}),
        "tcp-abc-2point": (cellcal.tcp, write(folder / "abc.csv", list("xyzabc"),
                                              flange_rows(rng, abc), roles_abc), {}),
        "frame-3point": (cellcal.frame, write(folder / "f3.csv", xyz,
                                              noisy(transform_points(T_FRAME, local)), roles3),
                         {}),
        "frame-npoint": (cellcal.frame, write(
            folder / "fn.csv", xyz + ["nominal_x", "nominal_y", "nominal_z"],
            np.c_[noisy(transform_points(T_FRAME, nominal)), nominal * 1e3]), {}),
        "track": (cellcal.track, write(folder / "tr.csv", xyz + ["e1"], np.c_[noisy(
            np.array([1.5, 0.8, 0.3]) - np.outer(e, [1, 0, 0])), e * 1e3]), {}),
        "turntable": (cellcal.turntable, write(folder / "tt.csv", xyz + ["e1"],
                                               np.c_[noisy(table), np.degrees(theta)]), {}),
        "workpiece": (cellcal.workpiece, write(folder / "wp.csv", xyz + ["e1"],
                                               np.c_[noisy(wp), np.degrees(theta)], roles3),
                      {"turntable": cellcal.TurntablePose(T_R_B)}),
        "positioner": (cellcal.positioner, write(folder / "pos.csv", xyz + ["e1", "e2"],
                                                 np.c_[noisy(plate), np.degrees(grid)]), {}),
    }


def timed(calibrate, path: str, keywords: dict) -> float:
    t0 = time.perf_counter()
    result = calibrate(None, path, sigma=NOISE, **keywords).result
    result.summary()
    result.to_json()
    return time.perf_counter() - t0


def main(sizes: list[int]) -> None:
    print(describe())
    print(f"load average (1 min): {os.getloadavg()[0]:.1f}")
    rng = np.random.default_rng(0)
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "warm-up").mkdir()
        for calibrate, path, keywords in cases(100, Path(tmp) / "warm-up", rng).values():
            timed(calibrate, path, keywords)  # imports and first calls, not timed
        runs = {}
        for n in sizes:
            folder = Path(tmp) / str(n)
            folder.mkdir()
            for name, (calibrate, path, keywords) in cases(n, folder, rng).items():
                runs.setdefault(name, []).append(timed(calibrate, path, keywords))
    head = "".join(f"{n:>10,} touches" for n in sizes)
    print(f"{'procedure':<16}{head}   time per touch (us)          growth")
    for name, times in runs.items():
        per = "  ".join(f"{t / n * 1e6:8.1f}" for t, n in zip(times, sizes))
        growth = times[-1] / times[0]
        print(f"{name:<16}" + "".join(f"{t:>14.2f} s " for t in times)
              + f"   {per}      x{growth:.1f} for x{sizes[-1] / sizes[0]:.0f} touches")


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [1000, 10000])
