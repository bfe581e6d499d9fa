"""Inverse kinematics speed and numeric convergence.

Run: ``python benchmarks/bench_ik.py``. Prints the machine, the batched analytic IK time per pose
(all 8 solutions, including input validation, joint-limit and 2*pi handling) with its ratio to
EAIK's batched C++ solver on one thread: measured in the same run when EAIK is installed
(``pip install ".[benchmark]"``), otherwise against 4.7 us/pose measured on a 2-core machine
(docs/references.md); J2/J3-coupled arms against the same arm without its coupling, timed
alternately in the same run; and the
convergence of numeric IK for a 7-axis robot on a linear track over reachable random targets.
"""

from __future__ import annotations

import sys
import time
from dataclasses import replace
from functools import partial
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from machine import describe

from robotcell.ik import TrackRobot, solve, solve_numeric
from robotcell.kinematics.transforms import make_pose, rot_x, rot_z
from robotcell.robot.models import load_robot

EAIK_US_PER_POSE = 4.7  # all 8 solutions, batched C++, one thread (docs/references.md)
N_POSES = 100_000
N_TARGETS = 1000


def eaik_solver(robot, T):
    """EAIK's batched solver on one thread for the same poses (a callable), or None if EAIK is
    not installed."""
    try:
        from eaik.IK_DH import DhRobot
    except ImportError:
        return None
    js = robot.joints
    bot = DhRobot(np.array([j.alpha for j in js]), np.array([j.a for j in js]),
                  np.array([j.d for j in js]))
    # EAIK works in the DH frames: strip the base and flange transforms.
    T_dh = np.linalg.inv(robot.base) @ T @ np.linalg.inv(robot.flange)
    bot.IK_batched(T_dh[:10], 1)
    return lambda: bot.IK_batched(T_dh, 1)


def interleaved_min(f, g, repeats: int = 7) -> tuple[float, float]:
    """Fastest of ``repeats`` runs of ``f`` and of ``g``, alternating, so that load from other
    processes on a shared machine hits both alike (s)."""
    tf, tg = [], []
    for _ in range(repeats):
        for fn, ts in ((f, tf), (g, tg)):
            t = time.perf_counter()
            fn()
            ts.append(time.perf_counter() - t)
    return min(tf), min(tg)


def median_time(f, repeats: int = 7) -> float:
    ts = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts))


def batched_vs_eaik(names=("kuka_kr6_r700_sixx", "abb_irb2400", "ur5e"), n: int = N_POSES
                    ) -> list[tuple[str, float, float, bool]]:
    """Batched analytic IK of ``n`` reachable poses per robot: ``(name, us/pose, EAIK us/pose,
    EAIK measured now)``; EAIK's batched C++ solver on one thread, interleaved, fastest of 7."""
    out = []
    for name in names:
        robot = load_robot(name)
        rng = np.random.default_rng(0)
        lo, hi = np.maximum(robot.lower, -np.pi), np.minimum(robot.upper, np.pi)
        T = robot.fk(rng.uniform(lo, hi, (n, 6)))
        solve(robot, T[:10])  # derive and cache the parameters, load the kernels
        ours = partial(solve, robot, T)
        eaik = None if robot.convention != "standard" else eaik_solver(robot, T)
        if eaik is not None:
            t, t_eaik = interleaved_min(ours, eaik)
            out.append((name, t / n * 1e6, t_eaik / n * 1e6, True))
        else:
            out.append((name, median_time(ours) / n * 1e6, EAIK_US_PER_POSE, False))
    return out


def numeric_track(n: int = N_TARGETS) -> tuple[float, int, int, int, float]:
    """Numeric IK of a 7-axis KR 6 R700 sixx on a track over ``n`` reachable random targets:
    ``(converged fraction, false successes, median iterations, max restarts, ms/target)``."""
    arm = load_robot("kuka_kr6_r700_sixx")
    track = TrackRobot(arm, make_pose(rot_z(0.3) @ rot_x(0.01), [0.1, 0.2, 0.3]),
                       np.array([1.0, 0.01, 0.0]), -1.0, 3.0)
    robot = track.as_robot()
    rng = np.random.default_rng(1)
    q = np.column_stack([rng.uniform(-1.0, 3.0, n), rng.uniform(arm.lower, arm.upper, (n, 6))])
    T = robot.fk(q)
    t = time.perf_counter()
    res = solve_numeric(robot, T, tol_position=1e-9, tol_orientation=1e-9)
    dt = time.perf_counter() - t
    pos = np.linalg.norm(robot.fk(res.q)[:, :3, 3] - T[:, :3, 3], axis=1)
    false = int(np.count_nonzero(res.success & (pos > 1e-9)))
    return (float(res.success.mean()), false, int(np.median(res.iterations)),
            int(res.restarts.max()), dt / n * 1e3)


def main() -> None:
    print(f"machine: {describe()}")
    print(f"\nanalytic IK, all 8 solutions, batch of {N_POSES} poses:")
    for name, us, ref, measured in batched_vs_eaik():
        how = "EAIK measured now (fastest of 7, interleaved)" if measured else "EAIK published"
        print(f"  {name:20s} {us:6.2f} us/pose   {how}: {ref:5.2f} us/pose, "
              f"ratio {ref / us:4.2f}x   (target >= 2x)")
    print(f"\nanalytic IK with a J2/J3 coupling, batch of {N_POSES // 2} poses, alternating:")
    for name, uc, up in coupled_vs_uncoupled():
        print(f"  {name:20s} coupled {uc:6.2f} us/pose, uncoupled {up:6.2f} us/pose, "
              f"ratio {uc / up:4.2f}   (target <= 1.2)")
    print(f"  {'abb_irb460':20s} palletizer, all 4 solutions: {palletizer():6.2f} us/pose")
    ok, false, iters, restarts, ms = numeric_track()
    print(f"\nnumeric IK, 7-axis KR 6 R700 sixx on a track, {N_TARGETS} reachable random targets, "
          f"tolerance 1e-9 m / 1e-9 rad:")
    print(f"  converged {ok * 100:.1f} % (target >= 99.5 %), false successes {false}, "
          f"median {iters} iterations, max {restarts} restarts, {ms:.2f} ms/target (batched)")


def coupled_vs_uncoupled(n: int = N_POSES // 2, rounds: int = 7) -> list[tuple[str, float, float]]:
    """Analytic IK of J2/J3-coupled arms against the same arm without its coupling:
    ``(name, coupled us/pose, uncoupled us/pose)``.

    The reference is the identical model (same chain, same limits) with ``coupling=None``, so the
    ratio is the cost of mapping model solutions to controller values. Both are timed alternately
    in the same run (the machine is shared). Target: ratio <= 1.2.
    """
    out = []
    for name in ("fanuc_m20ia", "abb_irb2400"):
        coupled = load_robot(name)
        plain = replace(coupled, coupling=None)
        rng = np.random.default_rng(0)
        lo, hi = np.maximum(coupled.lower, -np.pi), np.minimum(coupled.upper, np.pi)
        T = coupled.fk(rng.uniform(lo, hi, (n, 6)))
        solve(coupled, T[:10]), solve(plain, T[:10])
        tc, tp = [], []
        for _ in range(rounds):
            tc.append(median_time(lambda c=coupled, T=T: solve(c, T), repeats=1))
            tp.append(median_time(lambda p=plain, T=T: solve(p, T), repeats=1))
        out.append((name, np.median(tc) / n * 1e6, np.median(tp) / n * 1e6))
    return out


def palletizer(n: int = N_POSES // 2, rounds: int = 7) -> float:
    """Analytic IK of the ABB IRB 460 palletizer, all 4 solutions (us/pose, median)."""
    pal = load_robot("abb_irb460")
    rng = np.random.default_rng(0)
    T = pal.fk(rng.uniform(pal.lower, pal.upper, (n, 4)))
    solve(pal, T[:10])
    return median_time(lambda: solve(pal, T), repeats=rounds) / n * 1e6


if __name__ == "__main__":
    main()
