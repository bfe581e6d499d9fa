"""Layout sweep: serially, on local processes and on a local Dask cluster.

Run: ``python benchmarks/bench_sweep.py``. On the example cell, 24 layouts (robot and turntable
moved over a grid) are scored on 10,000 random reachable targets each, serially, on a
``ProcessPoolExecutor`` with 2 workers and, when Dask is installed, on a local Dask cluster of
2 worker processes; prints the wall time, layouts per second and whether the rankings agree.
"""

from __future__ import annotations

import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from machine import describe

from robotcell.cell import Cell
from robotcell.studies.sweep import read_layouts, sweep

CELL = Path(__file__).parents[1] / "examples" / "cell_kr16_track_turntable.yaml"
N_TARGETS = 10_000
GRID = {"robot": {"y": {"from": -400, "to": 400, "steps": 4}},
        "turntable": {"x": [-300, 300], "a": {"from": 0, "to": 90, "steps": 3}}}


def run(label: str, cell, T, layouts, executor=None, reference=None):
    t = time.perf_counter()
    ranked = sweep(cell, T, layouts, tool="torch", executor=executor)
    dt = time.perf_counter() - t
    same = "" if reference is None else (
        f", same ranking: {[r.index for r in ranked] == [r.index for r in reference]}")
    print(f"  {label:32s} {dt:6.2f} s  {len(layouts) / dt:6.1f} layouts/s{same}")
    return ranked


def main() -> None:
    print(f"machine: {describe()}")
    cell = Cell.load(CELL)
    rng = np.random.default_rng(0)
    q = rng.uniform(cell.robot.lower, cell.robot.upper, (N_TARGETS, 6)) * 0.8
    T = cell.fk(q, track=rng.uniform(1.0, 5.0, N_TARGETS), tool="torch")
    layouts = read_layouts(GRID)
    print(f"\n{len(layouts)} layouts x {N_TARGETS} targets (world frame, track chosen):")
    serial = run("serial", cell, T, layouts)
    with ProcessPoolExecutor(2) as pool:
        pool.submit(int).result()  # start the workers before timing
        run("ProcessPoolExecutor, 2 workers", cell, T, layouts, pool, serial)
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        print("  (Dask not installed: pip install 'robotcell[dask]')")
        return
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        run("Dask LocalCluster, 2 processes", cell, T, layouts, client.get_executor(), serial)


if __name__ == "__main__":
    main()
