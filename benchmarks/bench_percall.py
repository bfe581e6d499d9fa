"""One call at a time, as a script calls them: FK, IK and the cell, against EAIK in the same run.

Run: ``python benchmarks/bench_percall.py`` (EAIK from the ``benchmark`` extra:
``pip install ".[benchmark]"``). On the KUKA KR 16 and the example cell
(``examples/cell_kr16_track_turntable.yaml``: the KR 16 on a 6 m track, the torch tool), a loop
of single calls over 200 configurations or targets, per call:

- ``robot.fk(q)`` against EAIK's ``fwdKin`` (target: at most 1.5x), and ``robot.jacobian(q)``;
- ``robot.ik(T)``, all 8 branches, against EAIK's ``IK`` (target: at most 1.5x);
- ``cell.fk(q, track=e, tool="torch")`` against EAIK's ``fwdKin`` (target: at most 5x);
- ``cell.ik(T, tool="torch")`` with the track position chosen, against EAIK's ``IK`` (target:
  at most 10x).

The loops are interleaved, round after round, and each keeps its fastest round (the machine may be
shared: every loop sees the same load). The compiled kernels are loaded before timing (a script
that loops over single poses pays that once, see docs/performance.md).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from machine import describe

from robotcell.cell import Cell
from robotcell.kinematics import jit
from robotcell.robot.models import load_robot

CELL = Path(__file__).parents[1] / "examples" / "cell_kr16_track_turntable.yaml"
N_CALLS = 200
ROUNDS = 15
#: Targets: the largest ratio to EAIK per row (None: no EAIK counterpart).
TARGETS = {"robot.fk": ("fwdKin", 1.5), "robot.jacobian": None, "robot.ik": ("IK", 1.5),
           "cell.fk": ("fwdKin", 5.0), "cell.ik": ("IK", 10.0)}


def eaik_robot(robot):
    """EAIK's DH robot of the same chain (its own joint zero: the timing needs the geometry)."""
    try:
        from eaik.IK_DH import DhRobot
    except ImportError:
        sys.exit("bench_percall.py compares with EAIK in the same run: install the benchmark "
                 "extra first (pip install \".[benchmark]\")")

    js = robot.joints
    return DhRobot(np.array([j.alpha for j in js]), np.array([j.a for j in js]),
                   np.array([j.d for j in js]))


def interleaved_best(loops: dict, rounds: int = ROUNDS) -> dict[str, float]:
    """Fastest of ``rounds`` runs of each loop (seconds per call), the loops run in turn."""
    best = dict.fromkeys(loops, np.inf)
    for _ in range(rounds):
        for name, (fn, n) in loops.items():
            t = time.perf_counter()
            fn()
            best[name] = min(best[name], (time.perf_counter() - t) / n)
    return best


def measure() -> dict[str, float]:
    """Per-call times (s) of robotcell's calls and of EAIK's, from one interleaved run."""
    robot = load_robot("kuka_kr16")
    cell = Cell.load(CELL)
    rng = np.random.default_rng(0)
    q = rng.uniform(robot.lower, robot.upper, (N_CALLS, 6))
    e = rng.uniform(cell.track.lower, cell.track.upper, N_CALLS)
    T_R = robot.fk(q)
    T_world = cell.fk(q, track=e, tool="torch")
    bot = eaik_robot(robot)
    T_dh = np.linalg.inv(robot.base) @ T_R @ np.linalg.inv(robot.flange)
    qs, Ts, Tws, es, Tds = list(q), list(T_R), list(T_world), list(e), list(T_dh)
    loops = {
        "fwdKin": (lambda: [bot.fwdKin(x) for x in qs], N_CALLS),
        "robot.fk": (lambda: [robot.fk(x) for x in qs], N_CALLS),
        "robot.jacobian": (lambda: [robot.jacobian(x) for x in qs], N_CALLS),
        "IK": (lambda: [bot.IK(T) for T in Tds], N_CALLS),
        "robot.ik": (lambda: [robot.ik(T) for T in Ts], N_CALLS),
        "cell.fk": (lambda: [cell.fk(x, track=y, tool="torch") for x, y in zip(qs, es)], N_CALLS),
        "cell.ik": (lambda: [cell.ik(T, tool="torch") for T in Tws], N_CALLS),
    }
    jit.compile_all()
    for fn, _ in loops.values():  # loads the compiled kernels for these argument types
        fn()
    # the same results as the batch, and every valid branch reaches its target
    assert np.allclose(np.array([robot.fk(x) for x in qs]), T_R, rtol=0, atol=1e-12)
    sol = robot.ik(T_R[0])
    assert np.allclose(robot.fk(sol.q[sol.valid]), T_R[0], rtol=0, atol=1e-9)
    assert np.all(cell.ik(T_world[0], tool="torch").valid.any(-1))
    return interleaved_best(loops)


def rows(best: dict[str, float]) -> list[tuple[str, float, str, float, float, float]]:
    """``(call, us, EAIK call, its us, ratio, target)`` per robotcell call (NaN without EAIK)."""
    out = []
    for name, ref in TARGETS.items():
        us = best[name] * 1e6
        if ref is None:
            out.append((name, us, "", np.nan, np.nan, np.nan))
        else:
            ref_us = best[ref[0]] * 1e6
            out.append((name, us, ref[0], ref_us, us / ref_us, ref[1]))
    return out


def main() -> None:
    print(f"machine: {describe()}")
    print(f"one call at a time, KUKA KR 16 / the example cell, {N_CALLS} calls per loop, "
          f"fastest of {ROUNDS} interleaved rounds:")
    for name, us, ref, ref_us, ratio, target in rows(measure()):
        if ref:
            print(f"  {name:15s} {us:8.2f} us/call   EAIK {ref:7s} {ref_us:6.2f} us/call   "
                  f"ratio {ratio:5.2f}x (target <= {target:g}x)")
        else:
            print(f"  {name:15s} {us:8.2f} us/call")


if __name__ == "__main__":
    main()
