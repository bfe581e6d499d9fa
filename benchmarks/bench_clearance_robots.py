"""Clearance of a long coordinated program: 10,000 points of two IRB 2400 sharing a positioner.

Run: ``PYTHONPATH=src python benchmarks/bench_clearance_robots.py [N]`` (default 10000). The
program is a smooth sweep of N points of each robot of ``examples/cell_two_abb_positioner.yaml``
(every axis a sine within its limits, :data:`CYCLES` times over, the first robot travelling
along its track, the positioner tilting and turning with them; the arms come within a few
centimetres of each other and of the plate, and now and then overlap), its segments alternately
joint and linear moves of about 2.7 samples each. Its clearance is checked as ``program
check-coordinated --bodies`` does (:func:`robotcell.clearance.clearance_between`): each segment
cut so that no axis turns more than 0.01 rad and no track or TCP moves more than 10 mm between
samples (a joint move in joint space, a linear one on the TCP's straight line through the IK),
the robots against each other and each against the parts of
``examples/bodies_two_robots_positioner.yaml`` and a post. Prints the wall
time of one call over both robots and the parts, and of the three calls ``check-coordinated``
makes (each robot against the parts, the robots against each other), with the samples checked.
Target: a 10,000-point program in under 30 s.
"""

from __future__ import annotations

import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from machine import describe

from robotcell.cell import Cell
from robotcell.clearance import Body, Clearance, clearance_between, read_bodies
from robotcell.clearance.bodies import BodiesFile

EXAMPLES = Path(__file__).parents[1] / "examples"
#: Times the program runs through its sweep.
CYCLES = 5


def program(n: int) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray]:
    """N joint values of each robot, the first robot's track (m), the positioner's values (rad)."""
    t = CYCLES * np.linspace(0, 1, n)[:, None]
    mid, span = np.array([0, 0, 5, 0, 40, 0]), np.array([40, 20, 20, 90, 30, 120])
    q1 = np.radians(mid + span * np.sin(2 * np.pi * t * np.array([1, 2, 3, 1.5, 2.5, 4])))
    q2 = np.radians(mid + span * np.sin(2 * np.pi * t * np.array([2, 1, 2, 3, 1.5, 2]) + 1.0))
    track = 1.0 + 0.8 * np.sin(2 * np.pi * t[:, 0])
    table = np.radians(np.column_stack([30 * np.sin(2 * np.pi * t[:, 0]),
                                        300 * np.sin(np.pi * t[:, 0])]))
    return {"rob1": q1, "rob2": q2}, track, table


def main(n: int) -> None:
    cell = Cell.load(EXAMPLES / "cell_two_abb_positioner.yaml")
    post = Body("post", "capsule", (0.1, 1.0), "world", np.eye(4))
    post.pose[:3, 3] = [2.2, 0.0, 0.5]
    parts = read_bodies(EXAMPLES / "bodies_two_robots_positioner.yaml")
    bodies = replace(parts, bodies=(*parts.bodies, post))
    q, track, table = program(n)
    motion = ["linear" if k % 2 else "joint" for k in range(n - 1)]

    def run(robots: tuple[str, ...], shapes: BodiesFile, m: int = n) -> Clearance:
        return clearance_between(cell, {r: q[r][:m] for r in robots}, track={"rob1": track[:m]},
                                 table=table[:m], tools={r: "torch" for r in robots},
                                 motion={r: motion[:m - 1] for r in robots}, bodies=shapes)

    run(("rob1", "rob2"), bodies, 50)  # imports, first calls
    print(describe())
    start = time.perf_counter()
    got = run(("rob1", "rob2"), bodies)
    wall = time.perf_counter() - start
    a, b = got.pair[np.argmin(got.distance)]
    print(f"{n} points of 2 robots, {len(got.distance)} samples, one call: {wall:.2f} s "
          f"({wall / len(got.distance) * 1e6:.0f} us per sample); smallest distance "
          f"{got.minimum * 1e3:.1f} mm ({a} / {b})")
    arms = BodiesFile(links=bodies.links, ignore=bodies.ignore)
    start = time.perf_counter()
    for robots, shapes in ((("rob1",), bodies), (("rob2",), bodies), (("rob1", "rob2"), arms)):
        run(robots, shapes)
    wall = time.perf_counter() - start
    print(f"as check-coordinated checks it (each robot against the parts, the robots against "
          f"each other, three calls): {wall:.2f} s")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 10_000)
