"""Cell IK of one robot of a two-robot cell against the same robot alone.

Run: ``PYTHONPATH=src python benchmarks/bench_multi_robot_ik.py [N]`` (default 5000 targets).
The cell is ``examples/cell_two_robots_positioner.yaml`` (a KR 16 on a track and an IRB 2400
sharing a 2-axis positioner); the robot alone is a one-robot cell of the same arm at the same
base, with the same positioner and frames. For each robot, ``Cell.ik_batch`` solves N targets in
the positioner's workpiece frame at given axis values (and, for the robot on the track, with the
track value chosen per target) in both cells; the best of 5 runs is printed and the ratio.
Target: the two-robot cell within 1.2x of the robot alone.
"""

from __future__ import annotations

import sys
import time
from functools import partial
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from machine import describe

from robotcell.cell import Cell

EXAMPLE = Path(__file__).parents[1] / "examples" / "cell_two_robots_positioner.yaml"


def alone(cell: Cell, name: str) -> Cell:
    """Robot ``name`` of ``cell`` alone in a one-robot cell with the shared parts."""
    unit = cell.robots[name]
    frames = {k: f for k, f in cell.frames.items() if f.parent in ("world", "turntable")}
    return Cell(robot=unit.robot, robot_model=unit.model, T_world_R=unit.T_world_R,
                track=unit.track, turntable=cell.turntable, tools=dict(unit.tools), frames=frames)


def best(call, runs: int = 5) -> float:
    """Shortest wall time of ``runs`` calls (s)."""
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        call()
        times.append(time.perf_counter() - t0)
    return min(times)


def main(n: int) -> None:
    print(describe())
    cell = Cell.load(EXAMPLE)
    rng = np.random.default_rng(0)
    print(f"{'robot':<8}{'two-robot cell':>16}{'alone':>12}{'ratio':>8}   ({n} targets)")
    for name in cell.robot_names:
        one = alone(cell, name)
        k = cell.robots[name].robot.n_joints
        q = rng.uniform(-0.8, 0.8, (n, k)) + np.radians([0, -60, 90, 0, 30, 0])[:k]
        v = rng.uniform(-0.5, 0.5, (n, 2))
        e = rng.uniform(0.5, 2.5, n) if cell.robots[name].track else 0.0
        T = one.fk(q, track=e, table=v, tool="torch", frame="part")
        one.ik_batch(T[:10], "part", table=v[:10], tool="torch")  # first calls, not counted
        t_cell = best(partial(cell.ik_batch, T, "part", table=v, tool="torch", robot=name))
        t_one = best(partial(one.ik_batch, T, "part", table=v, tool="torch"))
        print(f"{name:<8}{t_cell * 1e3:>13.1f} ms{t_one * 1e3:>9.1f} ms{t_cell / t_one:>8.2f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5000)
