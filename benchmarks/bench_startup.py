"""Start-up time of the ``robotcell`` command, as a user sees it: wall time of real processes.

Each command runs as a new process of the installed console script ``robotcell`` (the one beside
this Python), or, when robotcell is not installed, ``python -c "from robotcell.cli import main;
main()"``, which is what the console script runs. Every command runs ``--runs`` times; the table
gives the median and the fastest run (seconds). Targets:

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


def wall_times(cmd: list[str], runs: int) -> list[float]:
    """Wall time (s) of ``runs`` processes of ``cmd``; each must exit 0."""
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
        times.append(time.perf_counter() - t0)
        if proc.returncode != 0:
            raise SystemExit(f"{' '.join(cmd)} exited {proc.returncode}:\n{proc.stderr}")
    return times


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
        results = [(name, wall_times(cmd, args.runs), target) for name, cmd, target in rows]
        load_after = os.getloadavg()

    print(f"machine: {describe()}")
    print(f"robotcell started as: {how}")
    print(f"load average (1 min) before / after: {load_before[0]:.2f} / {load_after[0]:.2f} "
          f"on {os.cpu_count()} cores; {args.runs} runs per command")
    print()
    print(f"{'command':<48} {'median s':>9} {'fastest s':>10} {'target s':>9}  ")
    print("-" * 84)
    for name, times, target in results:
        med = statistics.median(times)
        verdict = "" if target is None else ("ok" if med <= target else "OVER")
        tgt = "" if target is None else f"{target:.1f}"
        print(f"{name:<48} {med:>9.3f} {min(times):>10.3f} {tgt:>9}  {verdict}")


if __name__ == "__main__":
    main()
