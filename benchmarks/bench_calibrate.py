"""Calibration speed on long touch files: every procedure at 1,000 and 10,000 touches.

Run: ``PYTHONPATH=src python benchmarks/bench_calibrate.py [N ...]`` (default 1000 10000). For
each procedure a CSV of N touches (``tests/long_touches.py``: x, y, z in mm, or flange poses for
the tool; 0.1 mm touch noise) is calibrated as ``robotcell calibrate PROCEDURE FILE --sigma
0.1`` does it: the
measurement file read, the calibration (fit, covariance, the leave-one-out test of every touch),
the terminal report and the JSON. Prints the wall time, the time per touch, and how the time
grows from the first N to the last (linear cost: the ratio of the times is at most the ratio of
the N). Each procedure runs once on 100 touches first (imports, first calls). Target: 10,000
touches of any procedure in seconds.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1] / "tests"))
from long_touches import DESIGNS, NOISE, write_csv
from machine import describe


def timed(design, rng, n: int, folder: Path) -> float:
    """Wall time of the calibration of a CSV of ``n`` touches, its report and its JSON."""
    calibrate, cell, table, keywords = design(rng, n)
    path = str(write_csv(table, folder / f"touches_{n}.csv"))
    t0 = time.perf_counter()
    result = calibrate(cell, path, sigma=NOISE, **keywords).result
    result.summary()
    result.to_json()
    return time.perf_counter() - t0


def main(sizes: list[int]) -> None:
    print(describe())
    print(f"load average (1 min): {os.getloadavg()[0]:.1f}")
    rng = np.random.default_rng(0)
    with tempfile.TemporaryDirectory() as tmp:
        for design in DESIGNS.values():
            timed(design, rng, 100, Path(tmp))  # imports and first calls, not counted
        runs = {name: [timed(design, rng, n, Path(tmp)) for n in sizes]
                for name, design in DESIGNS.items()}
    head = "".join(f"{n:>10,} touches" for n in sizes)
    print(f"{'procedure':<24}{head}   time per touch (us)          growth")
    for name, times in runs.items():
        per = "  ".join(f"{t / n * 1e6:8.1f}" for t, n in zip(times, sizes))
        growth = times[-1] / times[0]
        print(f"{name:<24}" + "".join(f"{t:>14.2f} s " for t in times)
              + f"   {per}      x{growth:.1f} for x{sizes[-1] / sizes[0]:.0f} touches")


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [1000, 10000])
