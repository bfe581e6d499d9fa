"""Batched forward kinematics speed, as a ratio taken in the same run.

Batched FK of a 6-axis robot over 400,000 configurations: robotcell's compiled chain (numpy over
blocks of poses) against a plain numpy chain of ``(N, 4, 4)`` matrix products (one DH matrix per
joint, then ``@``). Target: at least 5x faster. One pose at a time is timed against EAIK by
``bench_percall.py``.

Run: ``python benchmarks/bench_fk.py [--robot kuka_kr16] [--n 400000]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from machine import describe

from robotcell import load_robot
from robotcell.kinematics.dh import link_transform


def plain_numpy_chain(robot, q):
    """The baseline: build each link's (N, 4, 4) DH matrix and multiply them in turn."""
    var = robot.dh_variables(q)
    T = np.broadcast_to(robot.base, (len(q), 4, 4))
    for i, j in enumerate(robot.joints):
        theta = np.full(len(q), j.theta) if j.prismatic else var[:, i]
        d = var[:, i] if j.prismatic else np.full(len(q), j.d)
        T = T @ link_transform(theta, d, j.a, j.alpha, robot.convention)
    return T @ robot.flange


def best_of(fn, repeats):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def batched(name: str = "kuka_kr16", n: int = 400_000, repeats: int = 5) -> tuple[float, float]:
    """Best-of-``repeats`` time per pose (ns) of the plain numpy chain and of robotcell's FK."""
    robot = load_robot(name)
    rng = np.random.default_rng(0)
    q = rng.uniform(robot.lower, robot.upper, (n, robot.n_joints))
    # Same result from both, so the comparison is fair.
    assert np.allclose(robot.fk(q[:1000]), plain_numpy_chain(robot, q[:1000]), atol=1e-12)
    t_plain = best_of(lambda: plain_numpy_chain(robot, q), repeats) / n
    t_ours = best_of(lambda: robot.fk(q), repeats) / n
    return t_plain * 1e9, t_ours * 1e9


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--robot", default="kuka_kr16")
    ap.add_argument("--n", type=int, default=400_000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    plain, ours = batched(args.robot, args.n, args.repeats)
    print(f"machine: {describe()}")
    print(f"robot: {args.robot}, {args.n} configurations, best of {args.repeats}")
    print(f"batched FK, plain numpy (N,4,4) chain: {plain:8.0f} ns/pose")
    print(f"batched FK, robotcell:                 {ours:8.0f} ns/pose")
    print(f"speed-up: {plain / ours:.1f}x (target >= 5x)")


if __name__ == "__main__":
    main()
