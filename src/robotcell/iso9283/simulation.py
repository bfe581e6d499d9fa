"""A simulated measurement log of an ISO 9283 test (:func:`simulate`): the whole test without
hardware.

The controller moves to the plan's poses with the joint values its cell gives (``controller``:
the cell as calibrated, its identified arm compensating where it has one; by default the true
cell itself, a perfect calibration): the same configuration the programs of
:func:`robotcell.iso9283.cycles.write_programs` use, solved the same way
(:meth:`robotcell.cell.Cell.ik_path`). The real TCP is where the true cell (``truth``, with its
identified arm if it has one) puts those joints; the tracker, aligned to the plan's frame of the
true cell, records it with the robot's repeatability scatter ``noise`` (1-sigma per coordinate)
and, unless ``angle_noise`` is None, its orientation with ``angle_noise`` (1-sigma per axis).
Along the paths the controller interpolates the command path linearly in space; the samples are
``spacing`` apart along it. Time stamps: :data:`POSE_SECONDS` per move between poses, the path
speed :data:`PATH_SPEED` along the paths.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.iso9283.cube import POSE_NAMES
from robotcell.iso9283.cycles import CYCLE_ORDER, MIN_CYCLES, PATH_CYCLES, POSE_CYCLES
from robotcell.iso9283.log import Log
from robotcell.iso9283.testplan import TestPlan

__all__ = ["PATH_SPEED", "POSE_SECONDS", "simulate"]

#: Seconds from one pose to the next in the simulated log.
POSE_SECONDS = 4.0
#: TCP speed along the paths in the simulated log (m/s).
PATH_SPEED = 0.1


def _dense(T: NDArray[np.float64], spacing: float) -> NDArray[np.float64]:
    """The path through poses ``T`` (M, 4, 4) sampled at most ``spacing`` apart (m), every
    pose included; each sample has the orientation of its segment's start."""
    out = [T[:1]]
    for a, b in itertools.pairwise(T):
        n = max(1, math.ceil(np.linalg.norm(b[:3, 3] - a[:3, 3]) / spacing))
        s = np.linspace(0.0, 1.0, n + 1)[1:]
        seg = np.repeat(a[None], n, axis=0)
        seg[:, :3, 3] = (1 - s)[:, None] * a[:3, 3] + s[:, None] * b[:3, 3]
        seg[-1] = b
        out.append(seg)
    return np.concatenate(out)


def _check(noise: float, angle_noise: float | None, cycles: int, path_cycles: int,
           spacing: float) -> None:
    if not (math.isfinite(noise) and 0 <= noise <= 0.01):
        raise InputError(f"noise must be a repeatability from 0 to 10 mm (m), got {noise!r}")
    if angle_noise is not None and not (math.isfinite(angle_noise) and 0 <= angle_noise <= 0.1):
        raise InputError(f"angle_noise must be from 0 to 0.1 rad, got {angle_noise!r}")
    for what, n in (("cycles", cycles), ("path_cycles", path_cycles)):
        if not (isinstance(n, (int, np.integer)) and (n == 0 or MIN_CYCLES <= n <= 1000)
                and (n > 0 or what == "path_cycles")):
            raise InputError(f"{what} must be a whole number from {MIN_CYCLES} to 1000"
                             f"{' (or 0: no paths)' if what == 'path_cycles' else ''}, got {n!r}")
    if not (math.isfinite(spacing) and 1e-4 <= spacing <= 0.05):
        raise InputError(f"spacing must be from 0.1 to 50 mm (m), got {spacing!r}")


def simulate(truth: Cell, plan: TestPlan, controller: Cell | None = None, noise: float = 2e-5,
             angle_noise: float | None = math.radians(0.001), cycles: int = POSE_CYCLES,
             path_cycles: int = PATH_CYCLES, spacing: float = 0.002, seed: int | None = None
             ) -> Log:
    """Simulate the tracker's log of an ISO 9283 test of a plan.

    Parameters
    ----------
    truth : Cell
        The true cell (its identified arm, where it has one, is the real arm).
    plan : TestPlan
    controller : Cell, optional
        The cell the controller and the programs use; default ``truth``.
    noise : float
        Repeatability scatter, 1-sigma per coordinate (m).
    angle_noise : float or None
        Scatter of the measured orientation, 1-sigma per axis (rad); None: no orientation in
        the log.
    cycles, path_cycles : int
        Cycles of the poses and of the paths (``path_cycles`` 0: no paths).
    spacing : float
        Distance of the samples along a path (m).
    seed : int, optional
        Seed of the scatter.

    Returns
    -------
    Log
        Poses in the order of the cycles (P5, P4, P3, P2, P1), then each path's samples, cycle
        after cycle; positions and orientations in the plan's frame of the true cell.

    Raises
    ------
    InputError
        A bad option, a tool or frame one of the cells lacks, or a plan the controller's cell
        cannot follow in one configuration.
    """
    _check(noise, angle_noise, cycles, path_cycles, spacing)
    ctrl = controller or truth
    rng = np.random.default_rng(seed)
    kw = {"frame": plan.frame, "tool": plan.tool, "max_step": math.pi,
          "table": 0.0 if plan.table is None else plan.table}

    def reached(T: NDArray[np.float64], q_start: NDArray[np.float64] | None = None
                ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        track = None if plan.track is None else np.full(len(T), plan.track)
        path = ctrl.ik_path(T, track=track, q_start=q_start, **kw)
        real = truth.fk(path.q, 0.0 if plan.track is None else track, kw["table"],
                        tool=plan.tool, frame=plan.frame)
        return real, path.q

    order = [POSE_NAMES.index(p) for p in CYCLE_ORDER]
    T_poses, _ = reached(plan.poses)
    names = list(CYCLE_ORDER) * cycles
    real = np.tile(T_poses[order], (cycles, 1, 1))
    cyc = np.repeat(np.arange(1, cycles + 1), len(CYCLE_ORDER))
    time = (np.arange(len(names)) + 1) * POSE_SECONDS
    paths = plan.paths if path_cycles else {}
    if paths:
        _, q_vertices = reached(np.concatenate(list(paths.values())))
        first = np.cumsum([0, *(len(T) for T in paths.values())])[:-1]
        t0 = time[-1] + POSE_SECONDS
        for (name, T), k in zip(paths.items(), first):
            dense = _dense(T, spacing)
            T_real, _ = reached(dense, q_vertices[k])
            arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(dense[:, :3, 3],
                                                                          axis=0), axis=1))])
            lap = arc[-1] / PATH_SPEED + POSE_SECONDS
            names += [name] * (len(dense) * path_cycles)
            real = np.concatenate([real, np.tile(T_real, (path_cycles, 1, 1))])
            cyc = np.concatenate([cyc, np.repeat(np.arange(1, path_cycles + 1), len(dense))])
            time = np.concatenate([time, t0 + (np.arange(path_cycles)[:, None] * lap
                                               + arc[None] / PATH_SPEED).ravel()])
            t0 = time[-1] + POSE_SECONDS
    p = real[:, :3, 3] + rng.normal(0.0, noise, (len(real), 3))
    R = None
    if angle_noise is not None:
        R = Rotation.from_rotvec(rng.normal(0.0, angle_noise, (len(real), 3))).as_matrix() \
            @ real[:, :3, :3]
    return Log(cyc, names, p, R, time, source="simulated log")
