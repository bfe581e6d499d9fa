"""Library robots against second, independently written parameter sets (see docs/robots.md).

Each reference below is transcribed from its public source (cited per test) in that source's own
parameterisation; the library model must reproduce it at random configurations within the limits.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell.robot.models import load_robot
from robotcell.robot.robot import Joint, Robot


def urdf_chain(joints: list[tuple[tuple[float, float, float], tuple[float, float, float], int]],
               tail: tuple[tuple[float, float, float], tuple[float, float, float]],
               q: np.ndarray) -> np.ndarray:
    """URDF forward kinematics: per joint ``(xyz, rpy, axis sign about z)``, then a fixed ``tail``
    (xyz, rpy); returns the poses ``(N, 4, 4)`` (m)."""

    def pose(xyz, rpy):
        M = np.eye(4)
        M[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
        M[:3, 3] = xyz
        return M

    T = np.broadcast_to(np.eye(4), q.shape[:-1] + (4, 4))
    for (xyz, rpy, sign), qi in zip(joints, np.moveaxis(q, -1, 0)):
        Rz = np.zeros(qi.shape + (4, 4))
        Rz[..., :3, :3] = Rotation.from_rotvec(np.outer(sign * qi, [0, 0, 1.0])).as_matrix()
        Rz[..., 3, 3] = 1.0
        T = T @ pose(xyz, rpy) @ Rz
    return T @ pose(*tail)


def random_q(robot: Robot, n: int = 500, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(np.maximum(robot.lower, -2 * math.pi), np.minimum(robot.upper, 2 * math.pi),
                       (n, robot.n_joints))


PI, HALF = math.pi, math.pi / 2

# kroshu/kuka_robot_descriptions (KUKA's ROS 2 descriptions),
# kuka_agilus_support/urdf/kr6_r900_2_macro.xacro: joint_1..joint_6 origins, all axes +z; flange.
KR6_R900_2 = ([((0, 0, 0.208), (PI, 0, 0), 1), ((0.025, -0.0907, -0.192), (HALF, 0, 0), 1),
               ((0.455, 0, -0.0042), (0, 0, 0), 1), ((0.196, -0.025, -0.0865), (HALF, 0, -HALF), 1),
               ((0, 0.0505, -0.224), (0, HALF, HALF), 1), ((0.0615, 0, -0.0505), (HALF, 0, -HALF), 1)],
              ((0, 0, -0.0285), (0, HALF, 0)))
# kroshu/kuka_robot_descriptions, kuka_quantec_support/urdf/kr210_r2700_extra_macro.xacro.
KR210_R2700_EXTRA = ([((0, 0, 0.302), (PI, 0, 0), 1), ((0.35, 0, -0.373), (HALF, 0, 0), 1),
                      ((1.15, 0, 0), (0, 0, 0), 1), ((0.9, 0.041, 0), (HALF, 0, -HALF), 1),
                      ((0, 0, -0.3), (0, HALF, HALF), 1), ((0.215, 0, 0), (HALF, 0, -HALF), 1)],
                     ((0, 0, 0), (0, HALF, 0)))


@pytest.mark.parametrize("name, ref", [("kuka_kr6_r900", KR6_R900_2),
                                       ("kuka_kr210_r2700", KR210_R2700_EXTRA)])
def test_kuka_against_kuka_ros2_descriptions(name, ref):
    """Position and orientation of the KUKA $FLANGE ('flange' link) at random axis values."""
    robot = load_robot(name)
    q = random_q(robot)
    np.testing.assert_allclose(robot.fk(q), urdf_chain(*ref, q), atol=1e-12)


def test_irb6700_against_robotkinematicscatalogue():
    """robotkinematicscatalogue 1.1.2 (PyPI), ABB_IRB_6700_200_260.py: modified DH (alpha, a, d,
    theta) = (0, 0, 780, 0), (-90, 320, 0, -90), (0, 1125, 0, 0), (-90, 200, 1142.5, 0),
    (90, 0, 0, 0), (-90, 0, 200, 180) mm/deg, all joints positive, the same joint limits."""
    rows = [(0, 0, 780, 0), (-90, 320, 0, -90), (0, 1125, 0, 0), (-90, 200, 1142.5, 0),
            (90, 0, 0, 0), (-90, 0, 200, 180)]
    limits = [(-170, 170), (-65, 85), (-180, 70), (-300, 300), (-130, 130), (-360, 360)]
    cat = Robot("catalogue", tuple(Joint("revolute", a * 1e-3, math.radians(al), d * 1e-3,
                                         math.radians(th), 1, math.radians(lo), math.radians(hi))
                                   for (al, a, d, th), (lo, hi) in zip(rows, limits)), "modified")
    robot = load_robot("abb_irb6700")
    np.testing.assert_allclose(robot.lower, cat.lower, atol=1e-12)
    np.testing.assert_allclose(robot.upper, cat.upper, atol=1e-12)
    q = random_q(robot)
    T, T_cat = robot.fk(q), cat.fk(q)
    np.testing.assert_allclose(T[:, :3, 3], T_cat[:, :3, 3], atol=1e-12)
    # The flange frames differ by one constant rotation (here none).
    rel = np.swapaxes(T_cat[:, :3, :3], 1, 2) @ T[:, :3, :3]
    np.testing.assert_allclose(rel, np.broadcast_to(rel[0], rel.shape), atol=1e-12)


@pytest.mark.parametrize("name, model", [("puma560", "Puma560"), ("stanford_arm", "Stanford")])
def test_textbook_arms_equal_the_robotics_toolbox(name, model):
    """roboticstoolbox-python models/DH/Puma560.py (d1 = 26.45 inch = 671.83 mm, from the
    mounting surface to the shoulder axis) and Stanford.py: fkine at random configurations."""
    dh = pytest.importorskip("roboticstoolbox.models.DH")
    ref = getattr(dh, model)()
    robot = load_robot(name)
    q = random_q(robot, 100)
    T_ref = np.array([ref.fkine(qi).A for qi in q])
    np.testing.assert_allclose(robot.fk(q), T_ref, atol=1e-12)
    if name == "puma560":
        assert robot.joints[0].d == pytest.approx(26.45 * 0.0254, abs=1e-12)
