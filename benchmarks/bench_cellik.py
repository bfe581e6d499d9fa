"""Cell IK with the track position chosen by the software: the sampled search vs the fast choice.

Run: ``python benchmarks/bench_cellik.py``. On the example cell (a KUKA KR 16 on a 6 m track,
``examples/cell_kr16_track_turntable.yaml``) and reachable random targets in the world frame,
prints the time per target of

- the sampled search (:meth:`robotcell.ik.TrackRobot.ik`: 2 x 65 track values, the full analytic
  IK and the Jacobian's determinant at each; the method ``Cell.ik`` used before), and
- the fast choice (:func:`robotcell.cell.ik.ik`: closed-form interval, closed-form manipulability
  scanned inside it, one analytic solve),

both in this run on the same targets, interleaved, best of 3 rounds each, as wall time and as
CPU time of this process (less disturbed when other jobs share the machine); their ratio
(target >= 150x, <= 20 us/target); and how the two choices compare: valid targets, and the
ratio of their manipulability ``|det J|`` at the chosen track value.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from machine import describe

from robotcell.cell import Cell
from robotcell.cell.ik import _track_robot
from robotcell.ik.trackchoice import arm_manipulability
from robotcell.kinematics.transforms import invert

CELL = Path(__file__).parents[1] / "examples" / "cell_kr16_track_turntable.yaml"
N_SAME = 300      # targets solved by both methods
N_FAST = 20_000   # targets for the fast choice alone
ROUNDS = 3


def timed(f, repeats: int) -> tuple[float, float, object]:
    """Best wall time and best CPU time of this process over ``repeats`` calls (s), result."""
    ts, cs, out = [], [], None
    for _ in range(repeats):
        t, c = time.perf_counter(), time.process_time()
        out = f()
        ts.append(time.perf_counter() - t)
        cs.append(time.process_time() - c)
    return float(np.min(ts)), float(np.min(cs)), out


def measure() -> dict:
    """Per-target wall and CPU times (us) of the sampled search (``old``), the fast choice on the
    same targets (``same``) and on many (``fast``), and how the two choices compare."""
    cell = Cell.load(CELL)
    rng = np.random.default_rng(0)
    arm = cell.robot
    n = N_FAST
    e = rng.uniform(cell.track.lower, cell.track.upper, n)
    q = rng.uniform(arm.lower, arm.upper, (n, 6))
    T = cell.fk(q, track=e, tool="torch")  # reachable targets in the world frame
    T_tool = cell.tools["torch"].T_F_TCP
    track = _track_robot(cell)
    T_L = invert(cell.track.T_world_L) @ T

    cell.ik(T[:10], tool="torch")
    # Interleaved, best of each: the machine may be shared, so both see the same load. CPU time
    # of this process is less disturbed by other jobs than wall time; both are printed.
    wall = {"old": np.inf, "same": np.inf, "fast": np.inf}
    cpu = dict(wall)
    for _ in range(ROUNDS):
        for key, f, reps in (("old", lambda: track.ik(T_L[:N_SAME], tool=T_tool), 1),
                             ("same", lambda: cell.ik(T[:N_SAME], tool="torch"), 5),
                             ("fast", lambda: cell.ik(T, tool="torch"), 1)):
            w, c, out = timed(f, reps)
            wall[key], cpu[key] = min(wall[key], w), min(cpu[key], c)
            if key == "old":
                old = out
            elif key == "same":
                fast = out
    count = {"old": N_SAME, "same": N_SAME, "fast": n}
    ok_old = old.solutions.valid.any(-1)
    ok_new = fast.valid.any(-1)
    m_new = np.where(fast.valid, np.nan_to_num(arm_manipulability(arm, fast.q)), 0.0).max(-1)
    return {"wall": {k: wall[k] / count[k] * 1e6 for k in wall},
            "cpu": {k: cpu[k] / count[k] * 1e6 for k in cpu},
            "ok_old": ok_old, "ok_new": ok_new, "ratio": m_new[ok_old] / old.manipulability[ok_old]}


def main() -> None:
    print(f"machine: {describe()}")
    res = measure()
    wall, cpu = res["wall"], res["cpu"]
    print("\ntrack position chosen per target, KR 16 on a 6 m track, torch tool "
          "(us/target, wall and CPU time; ratio to the sampled search):")
    for key, label in (("old", f"sampled search (before), {N_SAME} targets"),
                       ("same", f"fast choice, the same {N_SAME} targets"),
                       ("fast", f"fast choice, {N_FAST} targets")):
        print(f"  {label:40s} wall {wall[key]:8.1f} ({wall['old'] / wall[key]:4.0f}x)   "
              f"CPU {cpu[key]:8.1f} ({cpu['old'] / cpu[key]:4.0f}x)")
    print("  target: <= 20 us/target and >= 150x")
    ok_old, ok_new, r = res["ok_old"], res["ok_new"], res["ratio"]
    print(f"\n  valid targets: before {ok_old.sum()}/{N_SAME}, fast {ok_new.sum()}/{N_SAME}, "
          f"valid before but not now: {np.count_nonzero(ok_old & ~ok_new)}")
    print(f"  manipulability |det J| fast / before: median {np.median(r):.6f}, "
          f">= 0.9999 for {np.mean(r >= 0.9999) * 100:.1f} %, "
          f"better for {np.mean(r > 1) * 100:.1f} %, "
          f"min {r.min():.3f}")


if __name__ == "__main__":
    main()
