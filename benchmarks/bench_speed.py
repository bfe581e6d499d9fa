"""The README's Speed table, from one run: every row measured in this process, now.

Run: ``python benchmarks/bench_speed.py`` (EAIK from the ``benchmark`` extra:
``pip install ".[benchmark]"``; about 6 minutes). It runs, in this order, the batched FK of
``bench_fk.py``, the one-call rows of ``bench_percall.py``, the batched IK against EAIK, the
coupled arms, the palletizer and the numeric IK of ``bench_ik.py``, the cell IK of
``bench_cellik.py``, the identification of ``bench_identify.py`` and the program check of
``bench_program_check.py``, and prints the table as Markdown, ready for the README. Each row's own script says how it measures.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
import bench_cellik
import bench_fk
import bench_identify
import bench_ik
import bench_percall
import bench_program_check
from machine import describe


def main() -> None:
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.1f} at the start")
    plain, fk = bench_fk.batched()
    per_call = bench_percall.rows(bench_percall.measure())
    batched = bench_ik.batched_vs_eaik()
    coupled = bench_ik.coupled_vs_uncoupled()
    pal = bench_ik.palletizer()
    ok, false, _, _, _ = bench_ik.numeric_track()
    cell = bench_cellik.measure()
    times, ident = bench_identify.measure()
    check = bench_program_check.measure("yaskawa", bench_program_check.N_POINTS)
    print(f"load average {os.getloadavg()[0]:.1f} at the end\n")

    rows = [("what", "robotcell", "reference in the same run", "target"),
            ("---", "---", "---", "---"),
            ("batched FK, KUKA KR 16, 400,000 configurations", f"{fk:.0f} ns/pose",
             (f"plain numpy chain of `(N, 4, 4)` products: {plain:.0f} ns/pose "
             f"({plain / fk:.1f}x)"), ">= 5x")]
    label = {"robot.fk": "`robot.fk(q)`, one pose from Python, KR 16",
             "robot.jacobian": "`robot.jacobian(q)`, one pose",
             "robot.ik": "`robot.ik(T)`, one pose, all 8 branches, KR 16",
             "cell.fk": "`cell.fk(q, track=e, tool=\"torch\")`, one pose, KR 16 on a 6 m track",
             "cell.ik": "`cell.ik(T, tool=\"torch\")`, one target, track position chosen"}
    for name, us, ref, ref_us, ratio, target in per_call:
        if ref:
            rows.append((label[name], f"{us:.2f} us", (f"EAIK 1.2.2 `{ref}`, one call: "
                         f"{ref_us:.2f} us ({ratio:.2f}x)"), f"<= {target:g}x"))
        else:
            rows.append((label[name], f"{us:.2f} us", "", ""))
    us = [b[1] for b in batched]
    ref = [b[2] / b[1] for b in batched]
    rows.append(((f"analytic IK, all 8 solutions, {bench_ik.N_POSES:,} poses "
                 "(KR 6 R700, IRB 2400, UR5e)"), f"{min(us):.2f}-{max(us):.2f} us/pose",
                 ("EAIK 1.2.2 batched C++, one thread, same poses, fastest of 7 interleaved: "
                 f"{min(b[2] for b in batched):.2f}-{max(b[2] for b in batched):.2f} us/pose "
                 f"({min(ref):.1f}-{max(ref):.1f}x)"), ">= 2x"))
    ratios = [c / u for _, c, u in coupled]
    rows.append((("analytic IK of J2/J3-coupled arms (M-20iA, IRB 2400), "
                 f"{bench_ik.N_POSES // 2:,} poses"),
                 (f"{min(ratios):.2f}-{max(ratios):.2f}x the time of the same arm without "
                 "coupling"), "the same model with `coupling=None`", "<= 1.2x"))
    rows.append(("analytic IK of the IRB 460 palletizer, all 4 solutions", f"{pal:.2f} us/pose",
                 "", ""))
    rows.append((f"numeric IK, KR 6 on a 7-axis track, {bench_ik.N_TARGETS} reachable targets",
                 f"{ok * 100:.1f} % converged, {false} false successes", "", ">= 99.5 %"))
    c = cell["cpu"]
    rows.append(((f"cell IK with the track position chosen, KR 16 on a 6 m track, "
                 f"{bench_cellik.N_FAST:,} targets"), f"{c['fast']:.1f} us/target (CPU time)",
                 (f"sampled search (`TrackRobot.ik`, compiled IK too), {bench_cellik.N_SAME} "
                  f"targets: "
                 f"{c['old'] / 1e3:.2f} ms/target ({c['old'] / c['fast']:.0f}x); the same "
                 f"{bench_cellik.N_SAME} targets: {c['same']:.1f} us "
                 f"({c['old'] / c['same']:.0f}x)"), "<= 20 us, >= 150x"))
    rows.append(((f"kinematic identification, 6-axis arm, {bench_identify.N_CONFIGS} "
                 f"configurations x {bench_identify.N_REFLECTORS} reflectors, "
                 f"{len(ident.free)} free parameters"),
                 (f"median {np.median(times):.2f} s, max {max(times):.2f} s wall over "
                 f"{len(times)} runs (RMS {ident.rms_before * 1e3:.2f} mm nominal -> "
                 f"{ident.rms_after * 1e3:.3f} mm)"), "", "< 2 s"))
    rows.append(((f"`robotcell program check` of a {bench_program_check.N_POINTS:,}-point "
                  "YASKAWA job, every point and linear motion checked"),
                 f"{check['command']:.1f} s wall (a new process)",
                 (f"the library call `check_program_file`: {check['wall']:.1f} s wall, "
                  f"{check['cpu']:.1f} s CPU"), "< 10 s"))
    for r in rows:
        print("| " + " | ".join(r) + " |")


if __name__ == "__main__":
    main()
