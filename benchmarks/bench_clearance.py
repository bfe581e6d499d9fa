"""Clearance along a long program: 10,000 points of a KR 16 beside its positioner.

Run: ``PYTHONPATH=src python benchmarks/bench_clearance.py [N]`` (default 10000). The program is
a smooth joint-space sweep of N points (every axis a slow sine within its limits; the positioner
turning with it), checked against the positioner's plate, a fixture and a post as
:func:`robotcell.clearance.clearance` does for ``program check --clearance``: segments cut so that
no axis turns more than 0.01 rad (and the TCP moves at most 10 mm) between samples. Prints the
wall time, the samples checked and the calls of the collision library per sample. Target: a
10,000-point program in under 30 s.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from machine import describe

from robotcell.cell import Cell
from robotcell.clearance import Body, LinkModel, clearance
from robotcell.clearance.bodies import BodiesFile

EXAMPLES = Path(__file__).parents[1] / "examples"


def program(cell: Cell, n: int) -> tuple[np.ndarray, np.ndarray]:
    """N joint values and positioner values of a slow sweep (rad)."""
    t = np.linspace(0, 1, n)[:, None]
    mid, span = np.array([0, -80, 100, 0, 40, 0]), np.array([60, 20, 20, 90, 30, 120])
    q = np.radians(mid + span * np.sin(2 * np.pi * t * np.array([1, 2, 3, 1.5, 2.5, 4])))
    table = np.radians(np.column_stack([30 * np.sin(2 * np.pi * t[:, 0]), 360 * t[:, 0]]))
    return q, table


def main(n: int) -> None:
    cell = Cell.load(EXAMPLES / "cell_kr16_positioner.yaml")
    plate = Body("plate", "cylinder", (0.4, 0.03), "plate")
    fixture = Body("fixture", "box", (0.3, 0.3, 0.2), "turntable")
    post = Body("post", "capsule", (0.1, 1.0), "world", np.eye(4))
    post.pose[:3, 3] = [0.0, 1.5, 0.5]
    bodies = BodiesFile((plate, fixture, post), LinkModel())
    q, table = program(cell, n)
    clearance(cell, q[:50], table=table[:50], tool="torch", bodies=bodies)  # imports, first calls
    start = time.perf_counter()
    got = clearance(cell, q, table=table, tool="torch", bodies=bodies)
    wall = time.perf_counter() - start
    print(describe())
    print(f"{n} points, {len(got.distance)} samples: {wall:.2f} s "
          f"({wall / len(got.distance) * 1e6:.0f} us per sample); "
          f"smallest distance {got.minimum * 1e3:.1f} mm ({' / '.join(got.pair[np.argmin(got.distance)])})")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 10_000)
