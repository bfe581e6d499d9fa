"""Kinematic identification speed: a 6-axis arm, 100 configurations, 3 reflectors each.

Run: ``PYTHONPATH=src python benchmarks/bench_identify.py``. Prints the machine, the load, and
the wall time of :func:`robotcell.identification.identify` (start from the nominal model, base
and reflectors by closed form, QR of the identification Jacobian, Levenberg-Marquardt with the
analytic Jacobian, covariance and outlier test, the identified model through the DH procedure)
for a KUKA KR 16 whose every DH constant is perturbed by 0.1-1 mm / 0.02-0.2 deg, measured with
0.02 mm noise. Target: under 2 s wall.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1] / "tests"))
from identification_helpers import configurations, perturbed, truth_chain
from identification_helpers import measure as measure_chain
from machine import describe

from robotcell.identification import identify
from robotcell.robot.models import load_robot

N_CONFIGS, N_REFLECTORS, NOISE, REPEATS = 100, 3, 0.02e-3, 7


def measure(repeats: int = REPEATS):
    """Wall times (s) of ``repeats`` identifications, and the last result."""
    rng = np.random.default_rng(0)
    nominal = load_robot("kuka_kr16")
    ch, x = truth_chain(perturbed(nominal, rng), N_REFLECTORS, False, rng)
    meas = measure_chain(ch, x, configurations(nominal, N_CONFIGS, rng), rng, NOISE)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = identify(nominal, meas, sigma=NOISE)
        times.append(time.perf_counter() - t0)
    return times, res


def main() -> None:
    times, res = measure()
    print(describe())
    print(f"load average (1 min): {os.getloadavg()[0]:.1f}")
    print(f"identify: {N_CONFIGS} configurations x {N_REFLECTORS} reflectors, "
          f"{len(res.free)} free parameters, {len(res.fixed)} fixed")
    print(f"  wall time: median {np.median(times):.3f} s, min {min(times):.3f} s, "
          f"max {max(times):.3f} s over {REPEATS} runs (target < 2 s)")
    print(f"  RMS {res.rms_before * 1e3:.3f} mm (nominal) -> {res.rms_after * 1e3:.4f} mm "
          f"(identified); condition {res.condition:.1f}")


if __name__ == "__main__":
    main()
