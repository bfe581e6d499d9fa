"""Inverse kinematics speed and numeric convergence.

Run: ``python benchmarks/bench_ik.py``. Prints the machine, the batched analytic IK time per pose
(all 8 solutions, including input validation, joint-limit and 2*pi handling) with its ratio to
EAIK's batched C++ solver (4.7 us/pose on one thread of a 2-core machine, docs/REFERENCES), and
the convergence of numeric IK for a 7-axis robot on a linear track over reachable random targets.
"""

from __future__ import annotations

import os
import platform
import time

import numpy as np

from robotcell.ik import TrackRobot, solve, solve_numeric
from robotcell.modelfile import load_robot
from robotcell.transforms import make_pose, rot_x, rot_z

EAIK_US_PER_POSE = 4.7  # all 8 solutions, batched C++, one thread (REFERENCES.md)
N_POSES = 100_000
N_TARGETS = 1000


def cpu_model() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def median_time(f, repeats: int = 7) -> float:
    ts = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts))


def main() -> None:
    print(f"machine: {cpu_model()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
          f"numpy {np.__version__}")
    print(f"\nanalytic IK, all 8 solutions, batch of {N_POSES} poses:")
    for name in ("kuka_kr6_r700_sixx", "abb_irb2400", "ur5e"):
        robot = load_robot(name)
        rng = np.random.default_rng(0)
        lo, hi = np.maximum(robot.lower, -np.pi), np.minimum(robot.upper, np.pi)
        T = robot.fk(rng.uniform(lo, hi, (N_POSES, 6)))
        solve(robot, T[:10])  # derive and cache the parameters
        t = median_time(lambda robot=robot, T=T: solve(robot, T))
        us = t / N_POSES * 1e6
        print(f"  {name:20s} {us:6.2f} us/pose   EAIK/robotcell = {EAIK_US_PER_POSE / us:4.2f}x"
              f"   (target >= 2x)")

    arm = load_robot("kuka_kr6_r700_sixx")
    track = TrackRobot(arm, make_pose(rot_z(0.3) @ rot_x(0.01), [0.1, 0.2, 0.3]),
                       np.array([1.0, 0.01, 0.0]), -1.0, 3.0)
    robot = track.as_robot()
    rng = np.random.default_rng(1)
    q = np.column_stack([rng.uniform(-1.0, 3.0, N_TARGETS), rng.uniform(arm.lower, arm.upper, (N_TARGETS, 6))])
    T = robot.fk(q)
    t = time.perf_counter()
    res = solve_numeric(robot, T, tol_position=1e-9, tol_orientation=1e-9)
    dt = time.perf_counter() - t
    T2 = robot.fk(res.q)
    pos = np.linalg.norm(T2[:, :3, 3] - T[:, :3, 3], axis=1)
    false = int(np.count_nonzero(res.success & (pos > 1e-9)))
    print(f"\nnumeric IK, 7-axis KR 6 R700 sixx on a track, {N_TARGETS} reachable random targets, "
          f"tolerance 1e-9 m / 1e-9 rad:")
    print(f"  converged {res.success.mean() * 100:.1f} % (target >= 99.5 %), false successes {false}, "
          f"median {int(np.median(res.iterations))} iterations, max {res.restarts.max()} restarts, "
          f"{dt / N_TARGETS * 1e3:.2f} ms/target (batched)")


if __name__ == "__main__":
    main()
