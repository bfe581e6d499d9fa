"""The demo's last step: identify the virtual arm, then filter a path through it.

The virtual KR 16 is not quite the drawing: its link lengths and offsets are off by up to
0.5 mm, its twists, joint zeros and the tilt between the parallel axes 2 and 3 by up to
0.05 deg (the constants an identification can see; where joint 1 sits along and about its axis
and the last link's constants belong to the robot base and the tool, which a cell calibrates with
the identified arm). A laser tracker measures three reflectors on its flange at 40
configurations with 0.02 mm noise; ``robotcell identify ... --cell`` makes the identified model
the cell's arm; ``robotcell compensate`` filters a path. The step prints how far the controller,
with its nominal model, takes the real arm from the path without filtering and with it.
"""

from __future__ import annotations

import math
import shlex
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np

from robotcell.accuracy.filter import sigma_text
from robotcell.accuracy.poses import compensate_poses
from robotcell.cell import Cell, Tool
from robotcell.cell.identified import adopt_identified, identification_provenance
from robotcell.identification import cross_validate, identify, read_target_measurements
from robotcell.ik.select import nearest
from robotcell.io.poseformats import pose_to_vendor
from robotcell.io.tables import write_csv
from robotcell.kinematics.transforms import make_pose, rot_y
from robotcell.robot.models import load_robot
from robotcell.robot.robot import Robot

__all__ = ["TRACKER_NOISE", "accuracy_step", "virtual_arm"]

#: Laser tracker noise (m, 1-sigma per coordinate).
TRACKER_NOISE = 2e-5
#: Reflectors on the flange (m).
REFLECTORS = np.array([[0.05, 0.10, 0.08], [-0.07, 0.0, 0.10], [0.0, -0.10, 0.06]])
#: The robot base in the tracker's frame (m).
T_TRACKER_R = make_pose(None, [2.5, -1.0, 0.2])
#: The joint path the demo's seam follows (deg), from its start by its change.
PATH_START = np.array([-20.0, -70.0, 95.0, 10.0, 50.0, -30.0])
PATH_CHANGE = np.array([40.0, 15.0, -20.0, 20.0, 10.0, 60.0])


def virtual_arm(seed: int) -> Robot:
    """The demo's KR 16 as it is (seeded): the constants an identification sees, moved."""
    nominal = load_robot("kuka_kr16")
    rng = np.random.default_rng(seed)

    def mm() -> float:
        return rng.uniform(-0.5e-3, 0.5e-3)

    def deg() -> float:
        return math.radians(rng.uniform(-0.05, 0.05))

    joints = []
    for i, j in enumerate(nominal.joints):
        if i in (0, 5):  # the base's and the tool's: only what moves axis 2 or the wrist
            joints.append(replace(j, a=j.a + mm(), alpha=j.alpha + deg()) if i == 0 else j)
            continue
        joints.append(replace(j, a=j.a + mm(), alpha=j.alpha + deg(), theta=j.theta + deg(),
                              d=j.d + (mm() if i != 2 else 0.0),
                              beta=deg() if i == 1 else 0.0))
    return replace(nominal, name="kr16_virtual", joints=tuple(joints), ik_seed=nominal)


def accuracy_step(out: Path, seed: int, echo: Callable[[str], None]) -> tuple[float, float]:
    """Identify the virtual arm, filter a path, print both errors.

    Parameters
    ----------
    out : Path
        Folder; the step writes ``accuracy/`` in it.
    seed : int
        Seed of the virtual arm and the tracker noise.
    echo : callable
        Receives each line of the narrative.

    Returns
    -------
    unfiltered, filtered : float
        RMS distance of the real TCP from the path without and with filtering (m).
    """
    d = out / "accuracy"
    d.mkdir(exist_ok=True)
    for stale in d.glob("cell.yaml*"):  # a run before in the same folder
        stale.unlink()
    rng = np.random.default_rng(seed)
    arm = virtual_arm(seed)
    nominal = load_robot("kuka_kr16")
    torch = make_pose(rot_y(math.radians(45.0)), [0.3125, 0.0, 0.095])
    Cell(robot=nominal, robot_model="kuka_kr16", name="demo_accuracy",
         tools={"torch": Tool(torch, number=1)}).save(d / "cell.yaml")
    lo, hi = nominal.lower, nominal.upper
    q = lo + (hi - lo) * (0.1 + 0.8 * rng.random((40, 6)))
    T = T_TRACKER_R @ arm.fk(q)
    pts = np.einsum("nij,kj->nki", T[:, :3, :3], REFLECTORS) + T[:, None, :3, 3]
    pts = (pts + rng.normal(0.0, TRACKER_NOISE, pts.shape)).reshape(len(q), -1)
    head = [f"a{i}" for i in range(1, 7)] + [f"{c}{k}" for k in (1, 2, 3) for c in "xyz"]
    write_csv(d / "tracker.csv", head, np.hstack([np.degrees(q), pts * 1e3]), 6)
    echo("\nabsolute accuracy: the virtual arm is not quite the drawing (link constants off by up "
         "to 0.5 mm, 0.05 deg);\n  a laser tracker measured 3 reflectors at 40 configurations "
         f"(noise {TRACKER_NOISE * 1e3:g} mm, 1-sigma per coordinate) -> "
         f"{(d / 'tracker.csv').relative_to(out)}")
    echo("  $ robotcell " + shlex.join(["identify", "accuracy/tracker.csv", "--robot",
                                        "kuka_kr16", "--accuracy", f"{TRACKER_NOISE * 1e3:g}", "--folds", "2", "-o",
                                        "accuracy/arm.yaml", "--cell", "accuracy/cell.yaml"]))
    meas = read_target_measurements(d / "tracker.csv")
    result = identify(nominal, meas, sigma=TRACKER_NOISE)
    cross = cross_validate(nominal, meas, folds=2, sigma=TRACKER_NOISE)
    adopt_identified(d / "cell.yaml", result, d / "arm.yaml",
                     identification_provenance(result, cross))
    echo(f"  nominal model {result.rms_before * 1e3:.3f} mm RMS, identified "
         f"{result.rms_after * 1e3:.3f} mm; the cell computes with the identified arm")
    # a seam: the TCP along a joint path of the nominal arm, as desired poses in the world
    s = np.linspace(0.0, 1.0, 30)[:, None]
    path = nominal.fk(np.radians(PATH_START + s * PATH_CHANGE), tool=torch)
    write_csv(d / "seam.csv", list("xyzabc"), pose_to_vendor(path, "kuka"), 6)
    echo("  $ robotcell compensate accuracy/seam.csv --cell accuracy/cell.yaml --tool torch "
         "-o accuracy/commanded.csv")
    cell = Cell.load(d / "cell.yaml")
    done = compensate_poses(d / "seam.csv", cell, "torch", output=d / "commanded.csv")
    # the controller's joints for the commanded and for the desired poses, on the real arm
    ctrl, real = cell.controller(), replace(cell.controller(), robot=arm)
    sol = ctrl.ik(done.result.T, tool="torch")
    q_filtered, _, _ = nearest(ctrl.robot, sol, done.result.q)
    desired = ctrl.ik(path, tool="torch")
    q_plain, _, _ = nearest(ctrl.robot, desired, np.broadcast_to(nominal.home, (len(path), 6)))

    def rms(qq: np.ndarray) -> float:
        e = real.fk(qq, tool="torch")[:, :3, 3] - path[:, :3, 3]
        return float(np.sqrt(np.mean(np.sum(e**2, axis=-1))))

    unfiltered, filtered = rms(q_plain), rms(q_filtered)
    echo(f"  the real arm along the path: {unfiltered * 1e3:.3f} mm RMS from it without "
         f"filtering, {filtered * 1e3:.3f} mm filtered (1-sigma predicted "
         f"{done.result.sigma.max() * 1e3:.3f} mm, {sigma_text()})")
    return unfiltered, filtered
