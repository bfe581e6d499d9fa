"""``program check`` of a 100,000-point program: every point and every linear motion checked in
batches.

Run: ``python benchmarks/bench_program_check.py [--vendor yaskawa] [--points 100000]``. It writes,
in a temporary folder, a program of that many points through the example cell (a KUKA KR 16 on a
6 m track beside a turntable, ``examples/cell_kr16_track_turntable.yaml``): a smooth path in the
workpiece frame ``part``, every point after the first a linear motion, the track and the table
moving with it, each point the TCP of joint values in one configuration (so that every point
and every linear motion checks good, which the run asserts). Then it times, best of 3:

- the command ``robotcell program check`` as a user types it, a new process each time (start-up,
  the cell file, the compiled IK from numba's cache), wall time: the figure of the README;
- the library call ``check_program_file`` (read the file, check every point and every linear
  motion), wall and CPU time of this process, after a call on a short program that loads the
  compiled IK. Python's cyclic garbage collector runs during it, as in any program; the command
  pauses it while it reads and checks (the points' objects hold no cycles), which saves about
  a quarter of the time.

Target: under 10 s for 100,000 points. Wall times move with the machine's load, which is printed
at the start and the end; CPU time of this process moves less.
"""

from __future__ import annotations

import argparse
import gc
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from machine import describe

from robotcell.cell import Cell
from robotcell.controllers.model import Program, ProgramPoint
from robotcell.controllers.registry import get
from robotcell.programs.check import check_program_file
from robotcell.programs.config import configs
from robotcell.programs.frames import program_refs
from robotcell.programs.write import written_poses

CELL = Path(__file__).parents[1] / "examples" / "cell_kr16_track_turntable.yaml"
N_POINTS = 100_000
ROUNDS = 3
#: YASKAWA station pulses per degree of the example turntable.
PPD = 100.0


def write(cell: Cell, vendor: str, n: int, folder: Path) -> Path:
    """A program of ``n`` points in ``folder``; returns its main file."""
    t = np.linspace(0.0, 1.0, n)
    deg = np.column_stack([-90 + 20 * np.sin(6 * t), -80 + 10 * np.sin(9 * t),
                           100 + 10 * np.sin(7 * t), 10 * np.sin(11 * t) + 0.5,
                           45 + 20 * np.sin(5 * t), 30 * np.sin(13 * t) + 0.5])
    q = np.radians(deg)
    ctl = get(vendor)
    tool_ref, frame_ref, where = program_refs(cell, vendor, "torch", "part")
    axes = ctl.external_axes(cell, PPD if vendor == "yaskawa" else None)
    track = 1.0 + 2.0 * t
    table = axes.held(np.radians(90 * np.sin(3 * t) + 0.3))
    poses = written_poses(cell, where, q, track, table, cell.tools["torch"].T_F_TCP)
    flags = configs(cell.robot, q, vendor)
    names = ctl.point_names(n)
    points = [ProgramPoint(names[i], 0, "ptp" if i == 0 else "lin", tool_ref, frame_ref,
                           pose=poses[i], config=flags[i],
                           external=axes.to_file(track[i], table[i]), speed=0.1, zone=0.0)
              for i in range(n)]
    texts = ctl.write_program(Program("BENCH", vendor, points, data=ctl.data(cell)), ["bench"])
    for name, text in texts.items():
        (folder / name).write_text(text)
    return folder / next(k for k in texts if Path(k).suffix.lower() != ".dat")


def _command() -> list[str]:
    script = Path(sys.executable).parent / "robotcell"
    if script.exists():
        return [str(script)]
    return [sys.executable, "-c", "from robotcell.cli import main; main()"]


def measure(vendor: str, n: int) -> dict:
    """Wall and CPU time (s) of the library call, wall time of the command, on ``n`` points."""
    cell = Cell.load(CELL)
    ppd = PPD if vendor == "yaskawa" else None
    with tempfile.TemporaryDirectory() as tmp:
        short = Path(tmp) / "short"
        short.mkdir()
        check_program_file(write(cell, vendor, 50, short), cell, ppd)  # loads the compiled IK
        main = write(cell, vendor, n, Path(tmp))
        wall = cpu = np.inf
        for _ in range(ROUNDS):
            gc.collect()
            w, c = time.perf_counter(), time.process_time()
            report = check_program_file(main, cell, ppd)
            wall = min(wall, time.perf_counter() - w)
            cpu = min(cpu, time.process_time() - c)
            assert len(report.points) == n and report.good, report.rows()[:5]
            del report
        cmd = [*_command(), "program", "check", str(main), "--cell", str(CELL)]
        cmd += ["--pulses-per-degree", str(PPD)] if ppd else []
        command = np.inf
        for _ in range(ROUNDS):
            w = time.perf_counter()
            done = subprocess.run(cmd, capture_output=True, text=True, check=False)
            command = min(command, time.perf_counter() - w)
            assert done.returncode == 0, done.stderr
    return {"wall": wall, "cpu": cpu, "command": command}


def main() -> None:
    """Measure and print the times of a program of ``--points`` points of ``--vendor``."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--vendor", default="yaskawa", choices=["kuka", "abb", "fanuc",
                                                                 "yaskawa"])
    parser.add_argument("--points", type=int, default=N_POINTS)
    args = parser.parse_args()
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.1f} at the start")
    res = measure(args.vendor, args.points)
    print(f"load average {os.getloadavg()[0]:.1f} at the end")
    print(f"program check of a {args.points:,}-point {args.vendor.upper()} program (every "
          f"point and linear motion good), best of {ROUNDS}:")
    print(f"  check_program_file: wall {res['wall']:.2f} s, CPU {res['cpu']:.2f} s "
          f"({res['cpu'] / args.points * 1e6:.1f} us/point)")
    print(f"  robotcell program check (a new process): wall {res['command']:.2f} s")
    print("  target: < 10 s")


if __name__ == "__main__":
    main()
