"""The geometric Jacobian against central finite differences of fk, for every library robot."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell import Joint, Robot, list_robots, load_robot, make_pose


def finite_difference_jacobian(robot, q, h=1e-6):
    n = robot.n_joints
    J = np.zeros((6, n))
    for i in range(n):
        dq = np.zeros(n)
        dq[i] = h
        Tp, Tm = robot.fk(q + dq), robot.fk(q - dq)
        J[:3, i] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        # angular velocity: log(R+ R-^T) / 2h, expressed in the base frame
        J[3:, i] = Rotation.from_matrix(Tp[:3, :3] @ Tm[:3, :3].T).as_rotvec() / (2 * h)
    return J


def sample_in_limits(robot, rng, n):
    lo = np.where(np.isfinite(robot.lower), robot.lower, -np.pi)
    hi = np.where(np.isfinite(robot.upper), robot.upper, np.pi)
    return rng.uniform(lo, hi, (n, robot.n_joints))


@pytest.mark.parametrize("name", list_robots())
def test_jacobian_matches_finite_differences(name):
    rng = np.random.default_rng(sum(map(ord, name)))
    robot = load_robot(name).with_tool(make_pose(p=[0.05, -0.02, 0.12]))
    qs = sample_in_limits(robot, rng, 5)
    J = robot.jacobian(qs)
    for q, Jq in zip(qs, J):
        np.testing.assert_allclose(Jq, finite_difference_jacobian(robot, q), atol=1e-7)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_jacobian_with_prismatic_and_negative_signs(convention):
    rng = np.random.default_rng(2)
    joints = tuple(Joint("prismatic" if i in (0, 3) else "revolute", a=rng.normal(0, 0.3),
                         alpha=rng.uniform(-3, 3), d=rng.normal(0, 0.3), theta=rng.normal(),
                         sign=(-1.0, 1.0)[i % 2]) for i in range(7))
    robot = Robot("p", joints, convention, base=make_pose(p=[0.1, 0.2, 0.3]),
                  flange=make_pose(p=[0, 0, 0.1]))
    q = rng.uniform(-1, 1, 7)
    np.testing.assert_allclose(robot.jacobian(q), finite_difference_jacobian(robot, q), atol=1e-7)
