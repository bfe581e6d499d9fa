"""Standard <-> modified DH conversion: same FK, closed form, round trips."""

import math

import numpy as np
import pytest

import robotcell as rc
from robotcell.dhprocedure.convert import convert_convention
from robotcell.errors import InputError


def random_robot(rng, convention):
    joints = tuple(
        rc.Joint(str(rng.choice(["revolute", "prismatic"])), a=rng.normal() * 0.3,
                 alpha=rng.uniform(-math.pi, math.pi), d=rng.normal() * 0.3,
                 theta=rng.uniform(-math.pi, math.pi), sign=float(rng.choice([1, -1])))
        for _ in range(int(rng.integers(1, 8)))
    )
    pose = rc.make_pose(rc.rot_z(rng.uniform(-3, 3)) @ rc.rot_x(rng.uniform(-3, 3)),
                        rng.normal(size=3))
    flange = rc.make_pose(rc.rot_y(rng.uniform(-3, 3)), rng.normal(size=3))
    return rc.Robot("r", joints, convention, base=pose, flange=flange,
                    tool=rc.make_pose(p=[0, 0, 0.1]))


@pytest.mark.parametrize("start", ["standard", "modified"])
def test_conversion_keeps_fk_random_robots(start):
    rng = np.random.default_rng(11)
    other = "modified" if start == "standard" else "standard"
    for _ in range(100):
        robot = random_robot(rng, start)
        conv = convert_convention(robot, other)
        assert conv.convention == other
        q = rng.uniform(-3, 3, (20, robot.n_joints))
        assert np.abs(conv.fk(q) - robot.fk(q)).max() < 1e-12
        # The joint frames the joints move about are the same lines.
        F, G = robot.frames(q), conv.frames(q)
        axes_r = F[..., :-1, :3, 2:4] if start == "standard" else F[..., 1:, :3, 2:4]
        axes_c = G[..., 1:, :3, 2:4] if start == "standard" else G[..., :-1, :3, 2:4]
        assert np.allclose(axes_r[..., 0], axes_c[..., 0], atol=1e-12)


def test_library_robots_convert_both_ways():
    rng = np.random.default_rng(12)
    for name in rc.list_robots():
        robot = rc.load_robot(name)
        q = rng.uniform(-3, 3, (50, robot.n_joints))
        mod = convert_convention(robot, "modified")
        back = convert_convention(mod, "standard")
        assert np.abs(mod.fk(q) - robot.fk(q)).max() < 1e-12, name
        assert np.abs(back.fk(q) - robot.fk(q)).max() < 1e-12, name


def test_round_trip_restores_the_table_when_the_free_columns_are_zero():
    robot = rc.Robot("r", (rc.Joint("revolute", a=0.1, alpha=0.5, d=0.3, theta=0.2),
                           rc.Joint("prismatic", a=0.2, alpha=-1.0, d=0.1, sign=-1),
                           rc.Joint("revolute", d=0.05)))
    mod = convert_convention(robot, "modified")
    assert [(j.a, j.alpha) for j in mod.joints] == [(0, 0), (0.1, 0.5), (0.2, -1.0)]
    assert np.allclose(mod.flange, robot.flange)
    back = convert_convention(mod, "standard")
    assert back.joints == robot.joints
    assert np.allclose(back.base, robot.base)
    assert convert_convention(robot, "standard") is robot


def test_bad_target():
    with pytest.raises(InputError, match="target convention must be 'standard' or 'modified'"):
        convert_convention(rc.Robot("r", (rc.Joint("revolute"),)), "craig")
