"""Numeric IK and the robot on a linear track."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robotcell.errors import InputError
from robotcell.ik.limits import wrap_to_pi
from robotcell.ik.numeric import solve_numeric
from robotcell.ik.track import TrackRobot
from robotcell.kinematics.transforms import make_pose, rot_x, rot_y, rot_z
from robotcell.robot.models import load_robot
from robotcell.robot.robot import Joint, Robot


def pose_errors(robot, q, T):
    T2 = robot.fk(q)
    pos = np.linalg.norm(T2[..., :3, 3] - T[..., :3, 3], axis=-1)
    rel = np.swapaxes(T2[..., :3, :3], -1, -2) @ T[..., :3, :3]
    skew = np.stack([rel[..., 2, 1] - rel[..., 1, 2], rel[..., 0, 2] - rel[..., 2, 0],
                     rel[..., 1, 0] - rel[..., 0, 1]], -1)
    return pos, np.linalg.norm(skew, axis=-1) / 2  # small-angle exact


def kr6_track(convention: str = "standard") -> TrackRobot:
    arm = load_robot("kuka_kr6_r700_sixx")
    if convention == "modified":
        js = arm.joints
        joints = tuple(Joint(j.type, 0.0 if i == 0 else js[i - 1].a, 0.0 if i == 0 else js[i - 1].alpha,
                             j.d, j.theta, j.sign, j.lower, j.upper, j.name) for i, j in enumerate(js))
        arm = Robot("kr6_mod", joints, "modified", flange=make_pose(rot_x(js[-1].alpha), [js[-1].a, 0, 0])
                    @ arm.flange, home=arm.home)
    mount = make_pose(rot_z(0.3) @ rot_x(0.01), [0.1, 0.2, 0.3])  # a misaligned mounting L_Q_R
    return TrackRobot(arm, mount, np.array([1.0, 0.01, 0.0]), -1.0, 3.0)


def sample_track(track, rng, n):
    arm = track.arm
    return np.column_stack([rng.uniform(track.lower, track.upper, n),
                            rng.uniform(arm.lower, arm.upper, (n, 6))])


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_track_as_dh_chain_matches_track_model(convention):
    track = kr6_track(convention)
    robot = track.as_robot()
    assert robot.n_joints == 7 and robot.joints[0].prismatic
    q = sample_track(track, np.random.default_rng(1), 500)
    np.testing.assert_allclose(robot.fk(q), track.fk(q), atol=1e-12)


def test_track_along_z_like_kuka():
    arm = load_robot("abb_irb120")
    track = TrackRobot(arm, make_pose(rot_y(math.pi / 2), [0, 0, 0.5]), [0, 0, 1], 0.0, 2.0)
    q = sample_track(track, np.random.default_rng(2), 200)
    np.testing.assert_allclose(track.as_robot().fk(q), track.fk(q), atol=1e-12)


def test_track_ik_at_given_value_lecture_formula():
    """f = Q^-1 (p - x), R_Q_TCP = Q^-1 L_Q_TCP: 8 arm solutions per track value."""
    track = kr6_track()
    rng = np.random.default_rng(3)
    q = sample_track(track, rng, 300)
    T = track.fk(q)
    sol = track.ik_at(T, q[:, 0])
    assert sol.q.shape == (300, 8, 7)
    Q = np.where(sol.reachable[..., None], sol.q, 0.0)
    pos, ang = pose_errors(track, Q, T[:, None])
    assert np.all(pos[sol.reachable] < 1e-9) and np.all(ang[sol.reachable] < 1e-9)
    best = np.where(sol.valid, np.abs(wrap_to_pi(sol.q - q[:, None])).max(-1), np.inf).min(-1)
    assert np.all(best < 1e-6)
    # The same arm configuration through the DH chain with the track as joint 1.
    robot = track.as_robot()
    np.testing.assert_allclose(robot.fk(Q[sol.valid]), track.fk(Q[sol.valid]), atol=1e-12)
    # Another track value: the arm compensates, same TCP pose in L.
    other = track.ik_at(T[:20], q[:20, 0] + 0.05)
    Q2 = np.where(other.reachable[..., None], other.q, 0.0)
    pos, _ = pose_errors(track, Q2, T[:20, None])
    assert other.reachable.any() and np.all(pos[other.reachable] < 1e-9)
    # Outside the track limits nothing is valid.
    assert not track.ik_at(T[:5], 10.0).valid.any()


def test_track_chooses_its_position():
    track = kr6_track()
    q = sample_track(track, np.random.default_rng(4), 20)
    T = track.fk(q)
    choice = track.ik(T)
    assert np.all((choice.track >= track.lower) & (choice.track <= track.upper))
    assert np.all(choice.solutions.valid.any(axis=-1))
    Q = np.where(choice.solutions.valid[..., None], choice.solutions.q, 0.0)
    pos, ang = pose_errors(track, Q, T[:, None])
    assert np.all(pos[choice.solutions.valid] < 1e-9) and np.all(ang[choice.solutions.valid] < 1e-9)
    # The chosen value is at least as good as the value the target was generated with.
    at_orig = track._best(T[:, None], q[:, :1], None)[1]
    assert np.all(choice.manipulability >= at_orig - 1e-12)
    with pytest.raises(InputError, match="needs finite track limits"):
        TrackRobot(track.arm).ik(T[0])


def test_track_input_errors():
    arm = load_robot("abb_irb120")
    with pytest.raises(InputError, match="non-zero 3-vector"):
        TrackRobot(arm, direction=np.zeros(3))
    with pytest.raises(InputError, match="not below upper"):
        TrackRobot(arm, lower=1.0, upper=0.0)
    with pytest.raises(InputError, match=r"q must have shape \(\.\.\., 7\)"):
        TrackRobot(arm).fk(np.zeros(6))


def test_numeric_track_robot_converges_and_never_lies():
    track = kr6_track()
    robot = track.as_robot()
    rng = np.random.default_rng(5)
    q = sample_track(track, rng, 300)
    T = robot.fk(q)
    res = solve_numeric(robot, T, tol_position=1e-9, tol_orientation=1e-9)
    assert res.success.mean() >= 0.99
    pos, ang = pose_errors(robot, res.q, T)
    assert np.all(pos[res.success] <= 1e-9) and np.all(ang[res.success] <= 1e-9)
    np.testing.assert_allclose(res.position_error, pos, atol=1e-12)
    assert np.all(robot.within_limits(res.q))
    assert np.all((res.position_error > 1e-9) | (res.orientation_error > 1e-9) | res.success)


def test_numeric_unreachable_is_not_success():
    robot = load_robot("kuka_kr6_r700_sixx")
    res = solve_numeric(robot, make_pose(None, [3.0, 0.0, 0.4]), restarts=2)
    assert not res.success and res.position_error > 1.0
    assert res.restarts == 2 and res.iterations > 0


def test_numeric_calibrated_model_from_nominal_analytic_seed():
    """Axes 2/3 no longer parallel: analytic IK refuses, numeric IK seeded by it converges fast."""
    nominal = load_robot("kuka_kr6_r700_sixx")
    joints = list(nominal.joints)
    joints[1] = Joint(**{**joints[1].__dict__, "alpha": joints[1].alpha + 2e-3})
    joints[2] = Joint(**{**joints[2].__dict__, "a": joints[2].a + 1e-3})
    real = Robot("kr6_calibrated", tuple(joints), flange=nominal.flange)
    with pytest.raises(InputError, match="axes 2 and 3 are not parallel"):
        real.ik(np.eye(4))
    rng = np.random.default_rng(6)
    q = rng.uniform(nominal.lower, nominal.upper, (200, 6))
    T = real.fk(q)
    seed = nominal.ik(T)
    dist = np.abs(wrap_to_pi(seed.q - q[:, None])).sum(-1)
    k = np.argmin(np.where(seed.valid, dist, np.inf), axis=1)
    q0 = seed.q[np.arange(200), k]
    ok = np.isfinite(q0).all(axis=1)
    res = solve_numeric(real, T[ok], q0=q0[ok], restarts=0, max_iterations=20)
    assert res.success.all()
    assert np.median(res.iterations) <= 6 and res.iterations.max() <= 20
    # Seeded with the nearest nominal branch, it lands on the original configuration (except where
    # the original is not a valid nominal branch, e.g. at a joint limit).
    same = np.abs(wrap_to_pi(res.q - q[ok])).max(axis=1) < 1e-6
    assert same.mean() > 0.9


def test_numeric_prismatic_chain():
    robot = load_robot("stanford_arm")
    rng = np.random.default_rng(7)
    lo, hi = np.maximum(robot.lower, -math.pi), np.minimum(robot.upper, math.pi)
    q = rng.uniform(lo, hi, (100, 6))
    res = solve_numeric(robot, robot.fk(q))
    assert res.success.mean() >= 0.99
    pos, ang = pose_errors(robot, res.q, robot.fk(q))
    assert np.all(pos[res.success] <= 1e-9) and np.all(ang[res.success] <= 1e-9)


def test_numeric_input_errors():
    robot = load_robot("abb_irb120")
    with pytest.raises(InputError, match="must be positive"):
        solve_numeric(robot, np.eye(4), tol_position=0.0)
    with pytest.raises(InputError, match=r"q0 must have shape \(\.\.\., 6\)"):
        solve_numeric(robot, np.eye(4), q0=np.zeros(5))
    with pytest.raises(InputError, match="max_iterations must be >= 1"):
        solve_numeric(robot, np.eye(4), max_iterations=0)
