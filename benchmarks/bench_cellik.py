"""Cell IK with the track position chosen by the software: today's sampled search vs the fast choice.

Run: ``python benchmarks/bench_cellik.py``. On the example cell (a KUKA KR 16 on a 6 m track,
``examples/cell_kr16_track_turntable.yaml``) and reachable random targets in the world frame,
prints the time per target of

- the sampled search (:meth:`robotcell.ik.TrackRobot.ik`: 2 x 65 track values, the full analytic
  IK and the Jacobian's determinant at each; the method ``Cell.ik`` used before), and
- the fast choice (:func:`robotcell.cellik.ik`: closed-form interval, closed-form manipulability
  scanned inside it, one analytic solve),

both in this run on the same targets, their ratio (target >= 150x, <= 20 us/target), and how the
two choices compare: valid targets, and the ratio of their manipulability ``|det J|`` at the
chosen track value.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from machine import describe

from robotcell.cell import Cell
from robotcell.cellik import _track_robot
from robotcell.ik.analytic import analytic_solver
from robotcell.ik.trackchoice import manipulability
from robotcell.transforms import invert

CELL = Path(__file__).parents[1] / "examples" / "cell_kr16_track_turntable.yaml"
N_SAME = 300      # targets solved by both methods
N_FAST = 20_000   # targets for the fast choice alone


def best(seconds: list[float]) -> float:
    return float(np.min(seconds))


def timed(f, repeats: int) -> tuple[float, object]:
    ts, out = [], None
    for _ in range(repeats):
        t = time.perf_counter()
        out = f()
        ts.append(time.perf_counter() - t)
    return best(ts), out


def main() -> None:
    print(f"machine: {describe()}")
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
    t_fast_same, fast = timed(lambda: cell.ik(T[:N_SAME], tool="torch"), 5)
    t_old, old = timed(lambda: track.ik(T_L[:N_SAME], tool=T_tool), 1)
    t_fast, _ = timed(lambda: cell.ik(T, tool="torch"), 3)
    us_old = t_old / N_SAME * 1e6
    us_same = t_fast_same / N_SAME * 1e6
    us_fast = t_fast / n * 1e6
    print("\ntrack position chosen per target, KR 16 on a 6 m track, torch tool:")
    print(f"  sampled search (before)   {us_old:8.1f} us/target  ({N_SAME} targets)")
    print(f"  fast choice, same targets {us_same:8.1f} us/target  ratio {us_old / us_same:6.0f}x")
    print(f"  fast choice               {us_fast:8.1f} us/target  ({n} targets) "
          f"ratio {us_old / us_fast:6.0f}x   (target <= 20 us/target, >= 150x)")

    pa = analytic_solver(arm).params
    ok_old = old.solutions.valid.any(-1)
    ok_new = fast.valid.any(-1)
    m_old = old.manipulability
    m_new = np.where(fast.valid, np.nan_to_num(manipulability(pa, fast.q)), 0.0).max(-1)
    r = m_new[ok_old] / m_old[ok_old]
    print(f"\n  valid targets: before {ok_old.sum()}/{N_SAME}, fast {ok_new.sum()}/{N_SAME}, "
          f"valid before but not now: {np.count_nonzero(ok_old & ~ok_new)}")
    print(f"  manipulability |det J| fast / before: median {np.median(r):.6f}, "
          f">= 0.9999 for {np.mean(r >= 0.9999) * 100:.1f} %, better for {np.mean(r > 1) * 100:.1f} %, "
          f"min {r.min():.3f}")


if __name__ == "__main__":
    main()
