"""A simulated KR 16 as it really is, its tracker measurements, and a cell that uses it.

The true arm's link constants are off the drawing by up to 0.5 mm and 0.05 deg (Hayati's beta of
the parallel pair A2/A3 included), the zeros of axes 2-6 by up to 0.05 deg. A laser tracker
measures 3 reflectors on the flange with 0.02 mm noise.
"""

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
from identification_helpers import REFLECTORS, T_D_R

from robotcell import load_robot
from robotcell.kinematics.dh import link_transform
from robotcell.robot.robot import Robot

#: Tracker noise per coordinate (m).
NOISE = 2e-5

CELL = """\
name: accuracy_cell
robot:
  model: kuka_kr16
tools:
  torch:
    number: 1
    frame: {x: 312.5, y: -1.2, z: 95.0, a: 0, b: 45, c: 0}
frames:
  part:
    number: 1
    frame: {x: 1300, y: -200, z: 300, a: 30, b: 0, c: 0}
"""


def kr16_truth(rng: np.random.Generator) -> Robot:
    """The KR 16 as it is: every link constant off by up to 0.5 mm / 0.05 deg, A2 tilted by a
    beta of up to 0.05 deg, the zeros of axes 2-6 off by up to 0.05 deg."""
    nominal = load_robot("kuka_kr16")

    def mm():
        return rng.uniform(-0.5e-3, 0.5e-3)

    def deg():
        return math.radians(rng.uniform(-0.05, 0.05))

    joints = tuple(replace(j, a=j.a + mm(), d=j.d + mm(), alpha=j.alpha + deg(),
                           theta=j.theta + (deg() if i > 0 else 0.0),
                           beta=deg() if i == 1 else 0.0)
                   for i, j in enumerate(nominal.joints))
    return replace(nominal, name="kr16_true", joints=joints, ik_seed=nominal)


def tracker_csv(path: Path, truth: Robot, n: int, rng: np.random.Generator) -> None:
    """``n`` configurations within 80 % of the limits measured by the tracker (CSV, deg / mm)."""
    lo, hi = truth.lower, truth.upper
    q = lo + (hi - lo) * (0.1 + 0.8 * rng.random((n, truth.n_joints)))
    T = T_D_R @ truth.fk(q)
    pts = np.einsum("nij,kj->nki", T[:, :3, :3], REFLECTORS) + T[:, None, :3, 3]
    pts = pts + rng.normal(0.0, NOISE, pts.shape)
    head = [f"a{i}" for i in range(1, 7)] + [f"{c}{k}" for k in (1, 2, 3) for c in "xyz"]
    rows = np.hstack([np.degrees(q), pts.reshape(n, -1) * 1e3])
    path.write_text(",".join(head) + "\n" + "".join(",".join(f"{v:.9f}" for v in r) + "\n"
                                                    for r in rows))


def gauge(identified: Robot, truth: Robot) -> tuple[np.ndarray, np.ndarray]:
    """``G``, ``K`` with ``identified.fk(q) = G truth.fk(q) K`` up to the identification's error.

    An external measurement cannot see where joint 1 sits along and about its axis (that is the
    robot base's pose) nor the last link's constants (that is the target's or the tool's place on
    the flange): the identification holds them at the nominal values. In a cell the robot base
    and the tool calibrated with the identified arm take them up; these are the two constant
    transforms they absorb (standard DH: ``L_1 = Rz(q_1) S_1``, ``L_6 = Rz(q_6) S_6``).
    """
    j1, t1 = identified.joints[0], truth.joints[0]
    G0 = link_transform(j1.theta - t1.theta, j1.d - t1.d, 0.0, 0.0)
    G = identified.base @ G0 @ np.linalg.inv(identified.base)
    j6, t6 = identified.joints[5], truth.joints[5]
    S_id = link_transform(j6.theta, j6.d, j6.a, j6.alpha, beta=j6.beta)
    S_t = link_transform(t6.theta, t6.d, t6.a, t6.alpha, beta=t6.beta)
    F = identified.flange
    return G, np.linalg.inv(F) @ np.linalg.inv(S_t) @ S_id @ F


def seam(n: int = 30) -> np.ndarray:
    """A seam in frame ``part`` of :data:`CELL`: 300 mm along X, the torch turning, as CSV rows
    ``x, y, z, a, b, c`` (mm, deg)."""
    x = np.linspace(-250.0, 50.0, n)
    return np.column_stack([x, -90.0 + 30.0 * np.sin(x / 100.0), np.full(n, 230.0),
                            np.linspace(130.0, 150.0, n), np.full(n, 60.0),
                            np.full(n, -160.0)])


def write_rows(path: Path, head: list[str], rows: np.ndarray) -> None:
    path.write_text(",".join(head) + "\n" + "".join(",".join(f"{v:.9f}" for v in r) + "\n"
                                                    for r in rows))

