"""Start-up time of the ``robotcell`` command, as a user sees it: wall time of real processes.

Each command runs as a new process of the installed console script ``robotcell`` (the one beside
this Python), or, when robotcell is not installed, ``python -c "from robotcell.cli import main;
main()"``, which is what the console script runs. Every command runs ``--runs`` times, the
commands taking turns so that each sees the same load. The table gives, in seconds, the median
and the fastest wall time, and the median CPU time (user + system) of the process, which a busy
machine inflates far less than the wall time: on an idle machine the two agree. Targets (wall):

- ``robotcell --version`` and ``robotcell --help``: at most 0.3 s;
- ``robotcell calibrate tcp`` on a CSV of 8 touches: at most 0.5 s.

For scale, the table also times a bare Python and the imports a calibration cannot avoid (numpy,
``scipy.optimize.least_squares``, ``scipy.spatial.transform.Rotation``). The load average is
printed: on a busy machine every figure grows.

Run: ``python benchmarks/bench_startup.py [--runs 9]``.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from machine import describe

CELL = Path(__file__).resolve().parents[1] / "examples" / "cell_kr16_track_turntable.yaml"


def robotcell_command() -> tuple[list[str], str]:
    """The command that starts robotcell, and how it was found."""
    script = Path(sys.executable).parent / "robotcell"
    if script.is_file():
        return [str(script)], f"console script {script}"
    found = shutil.which("robotcell")
    if found:
        return [found], f"console script {found}"
    return ([sys.executable, "-c", "from robotcell.cli import main; main()"],
            "python -c 'from robotcell.cli import main; main()' (robotcell not installed)")


def timed(cmd: list[str]) -> tuple[float, float]:
    """Wall time and CPU time (user + system), in seconds, of one process of ``cmd``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} exited {proc.returncode}:\n{proc.stderr}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=9, help="processes per command (median taken)")
    args = ap.parse_args()

    rc, how = robotcell_command()
    py = [sys.executable, "-c"]
    with tempfile.TemporaryDirectory() as tmp:
        csv = Path(tmp) / "tcp8.csv"
        subprocess.run(rc + ["simulate", "tcp", "--cell", str(CELL), "--tool", "torch",
                             "--touches", "8", "--no-orientation", "--seed", "1", "-o", str(csv)],
                       check=True, capture_output=True)
        rows = [
            ("python -c pass", py + ["pass"], None),
            ("python: import numpy, scipy.optimize, Rotation",
             py + ["import numpy, scipy.optimize, scipy.spatial.transform"], None),
            ("robotcell --version", rc + ["--version"], 0.3),
            ("robotcell --help", rc + ["--help"], 0.3),
            ("robotcell calibrate tcp (8 touches)",
             rc + ["calibrate", "tcp", str(csv), "--robot", "kuka_kr16"], 0.5),
        ]
        load_before = os.getloadavg()
        runs: list[list[tuple[float, float]]] = [[] for _ in rows]
        for _ in range(args.runs):
            for times, (_, cmd, _) in zip(runs, rows):
                times.append(timed(cmd))
        load_after = os.getloadavg()

    print(f"machine: {describe()}")
    print(f"robotcell started as: {how}")
    print(f"load average (1 min) before / after: {load_before[0]:.2f} / {load_after[0]:.2f} "
          f"on {os.cpu_count()} cores; {args.runs} runs per command")
    print()
    print(f"{'command':<48} {'wall median':>11} {'wall fastest':>12} {'CPU median':>10} "
          f"{'target':>6}")
    print("-" * 92)
    for (name, _, target), times in zip(rows, runs):
        wall = [w for w, _ in times]
        cpu = statistics.median(c for _, c in times)
        med = statistics.median(wall)
        verdict = "" if target is None else ("ok" if med <= target else "over")
        tgt = "" if target is None else f"{target:.1f}"
        print(f"{name:<48} {med:>11.3f} {min(wall):>12.3f} {cpu:>10.3f} {tgt:>6}  {verdict}")


if __name__ == "__main__":
    main()
