"""Analytic inverse kinematics: parameter derivation, round trips, singularities, limits."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robotcell.errors import InputError
from robotcell.ik import opw_parameters, solve, ur_parameters
from robotcell.ik.limits import JointFolder, wrap_to_pi
from robotcell.ik.opw import opw_fk
from robotcell.ik.ur import ur_fk
from robotcell.kinematics.transforms import make_pose, rot_x, rot_y, rot_z
from robotcell.robot.models import list_robots, load_robot
from robotcell.robot.robot import Joint, Robot

D = math.radians
N_ROUND_TRIP = 100_000


def sample(robot: Robot, rng: np.random.Generator, n: int) -> np.ndarray:
    """Uniform configurations within the real joint limits (A6 +-350 deg, UR +-360 deg, KR6 A2
    down to -190 deg, so the 2*pi rule is exercised); unlimited joints in [-2 pi, 2 pi)."""
    lo = np.maximum(robot.lower, -2 * math.pi)
    hi = np.minimum(robot.upper, 2 * math.pi)
    return rng.uniform(lo, hi, (n, robot.n_joints))


def kr6(convention: str = "standard", tool=None, base=None) -> Robot:
    """KUKA KR 6 R700 sixx from the opw_kinematics parameter set, written as DH (m, rad)."""
    rows = [  # a, alpha, d, theta, sign, limits (deg)
        (0.025, -90, 0.400, 0, -1, 170), (0.315, 0, 0, 0, 1, (-190, 45)),
        (0.035, -90, 0, -90, 1, (-120, 156)), (0, 90, 0.365, 0, -1, 185),
        (0, -90, 0, 0, 1, 120), (0, 0, 0.080, 0, -1, 350),
    ]
    joints = []
    for a, al, d, th, s, lim in rows:
        lo, hi = (-lim, lim) if np.isscalar(lim) else lim
        joints.append(Joint("revolute", a, D(al), d, D(th), s, D(lo), D(hi), f"A{len(joints) + 1}"))
    flange = np.eye(4)
    if convention == "modified":
        # Standard Z_1 X_1 ... Z_n X_n equals modified (X_0 = I) Z_1 X_1 Z_2 ... Z_n, then X_n.
        std = joints
        joints = [Joint("revolute", 0.0 if i == 0 else std[i - 1].a,
                        0.0 if i == 0 else std[i - 1].alpha, j.d, j.theta, j.sign, j.lower,
                        j.upper, j.name) for i, j in enumerate(std)]
        flange = make_pose(rot_x(std[-1].alpha), [std[-1].a, 0, 0])
    return Robot("kr6_test", tuple(joints), convention, flange=flange,
                  tool=np.eye(4) if tool is None else tool, base=np.eye(4) if base is None else base)


def random_pose(rng: np.random.Generator, scale: float = 0.2) -> np.ndarray:
    R = rot_z(rng.uniform(-3, 3)) @ rot_y(rng.uniform(-1.5, 1.5)) @ rot_x(rng.uniform(-3, 3))
    return make_pose(R, rng.uniform(-scale, scale, 3))


def check_round_trip(robot: Robot, q: np.ndarray, tool=None, original: bool = True) -> None:
    """Every reachable branch reproduces the pose; the original configuration is returned.

    ``original=False`` for exactly singular configurations, which have infinitely many solutions.
    """
    T = robot.fk(q, tool=tool)
    sol = solve(robot, T, tool=tool)
    assert sol.q.shape == q.shape[:-1] + ((8, 6) if robot.n_joints == 6 else (4, 4))  # 4: palletizer
    Q = np.where(sol.reachable[..., None], sol.q, 0.0)
    T2 = robot.fk(Q, tool=tool)
    pos = np.linalg.norm(T2[..., :3, 3] - T[..., None, :3, 3], axis=-1)
    rel = np.swapaxes(T2[..., :3, :3], -1, -2) @ T[..., None, :3, :3]
    ang = np.arccos(np.clip((np.trace(rel, axis1=-2, axis2=-1) - 1) / 2, -1, 1))
    # arccos loses precision near 0; the skew part measures small angles exactly.
    skew = np.stack([rel[..., 2, 1] - rel[..., 1, 2], rel[..., 0, 2] - rel[..., 2, 0],
                     rel[..., 1, 0] - rel[..., 0, 1]], -1)
    ang = np.where(ang < 1e-3, np.linalg.norm(skew, axis=-1) / 2, ang)
    # Branches outside reach by up to REACH_TOL are solved at the boundary, off by reach_error.
    assert np.all(np.where(sol.reachable, pos - sol.reach_error, 0.0) < 1e-9)
    assert np.all(np.where(sol.reachable, ang, 0.0) < 1e-9)
    assert not np.any(np.isnan(sol.q[sol.reachable]))
    assert np.all(np.isnan(sol.q[~sol.reachable]))
    if not original:
        return
    # The original (in-limit) configuration is a valid branch, modulo 2*pi.
    dist = np.abs(wrap_to_pi(sol.q - q[..., None, :])).max(axis=-1)
    best = np.where(sol.valid, dist, np.inf).min(axis=-1)
    assert np.all(best < 1e-6), np.max(best)
    # Valid branches are in the limits.
    inside = (sol.q >= robot.lower) & (sol.q <= robot.upper)
    assert np.all(inside[sol.valid])


ANALYTIC = [n for n in list_robots() if n != "stanford_arm"]


@pytest.mark.parametrize("name", ANALYTIC)
def test_library_round_trip(name):
    robot = load_robot(name)
    rng = np.random.default_rng(sum(map(ord, name)))
    check_round_trip(robot, sample(robot, rng, N_ROUND_TRIP))


def test_stanford_arm_refused_with_reason():
    robot = load_robot("stanford_arm")
    with pytest.raises(InputError, match=r"joint\(s\) 3 are prismatic.*solve_numeric"):
        robot.ik(np.eye(4))


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_constructed_round_trip_with_base_and_tool(convention):
    rng = np.random.default_rng(7)
    robot = kr6(convention, tool=random_pose(rng), base=random_pose(rng))
    ref = kr6("standard", tool=robot.tool, base=robot.base)
    q = sample(robot, rng, 20_000)
    np.testing.assert_allclose(robot.fk(q[:50]), ref.fk(q[:50]), atol=1e-12)
    check_round_trip(robot, q)
    other_tool = random_pose(rng)
    check_round_trip(robot, q[:2000], tool=other_tool)


def test_odd_signs_and_offsets_are_absorbed():
    """A model with flipped axis signs and theta offsets still yields all solutions."""
    rng = np.random.default_rng(11)
    base = kr6()
    joints = []
    for j, s, off in zip(base.joints, [1, -1, -1, 1, -1, 1], [0.3, -1.0, 2.0, 0.7, -2.5, 1.1]):
        joints.append(Joint("revolute", j.a, j.alpha, j.d, j.theta + off, j.sign * s,
                            -math.pi, math.pi))
    robot = Robot("odd", tuple(joints))
    check_round_trip(robot, sample(robot, rng, 20_000))


def test_opw_parameters_match_published_sets():
    """opw_kinematics, include/opw_kinematics/opw_parameters_examples.h (ROS-Industrial).

    opw writes ``theta = q * sign_corrections - offsets``; here ``theta = sign * q + offset``.
    """
    p = opw_parameters(load_robot("kuka_kr6_r700_sixx"))  # makeKukaKR6_R700_sixx
    got = [p.a1, p.a2, p.b, p.c1, p.c2, p.c3, p.c4]
    np.testing.assert_allclose(got, [0.025, -0.035, 0, 0.400, 0.315, 0.365, 0.080], atol=1e-12)
    np.testing.assert_array_equal(p.signs, [-1, 1, 1, -1, 1, -1])
    np.testing.assert_allclose(p.offsets, -np.array([0, -math.pi / 2, 0, 0, 0, 0]), atol=1e-12)
    p = opw_parameters(load_robot("abb_irb2400"))  # makeIrb2400_10
    got = [p.a1, p.a2, p.b, p.c1, p.c2, p.c3, p.c4]
    np.testing.assert_allclose(got, [0.100, -0.135, 0, 0.615, 0.705, 0.755, 0.085], atol=1e-12)
    np.testing.assert_array_equal(p.signs, np.ones(6))
    np.testing.assert_allclose(p.offsets, -np.array([0, 0, -math.pi / 2, 0, 0, 0]), atol=1e-12)


def test_opw_fk_matches_robot():
    rng = np.random.default_rng(3)
    robot = kr6("modified", base=random_pose(rng))
    p = opw_parameters(robot)
    q = sample(robot, rng, 100)
    T = p.T_R_O @ opw_fk(p, p.signs * q + p.offsets) @ p.T_e_n
    np.testing.assert_allclose(T, robot.frames(q)[:, -1], atol=1e-12)


def test_ur_parameters_match_published_table():
    """Universal Robots, "DH parameters for calculations of kinematics and dynamics", UR5e."""
    robot = load_robot("ur5e")
    p = ur_parameters(robot)
    got = [p.d1, p.a2, p.a3, p.d4, p.d5, p.d6]
    np.testing.assert_allclose(got, [0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.0996], atol=1e-12)
    np.testing.assert_allclose(p.offsets, 0, atol=1e-12)
    q = sample(robot, np.random.default_rng(5), 100)
    T = p.T_R_O @ ur_fk(p, p.signs * q + p.offsets) @ p.T_e_n
    np.testing.assert_allclose(T, robot.frames(q)[:, -1], atol=1e-12)


def test_ur_modified_dh_with_signs():
    """A UR5e written in modified DH with flipped axis directions and offsets."""
    ur = load_robot("ur5e")
    std = ur.joints
    signs = [1, -1, 1, -1, -1, 1]
    offs = [0.2, -0.4, 0.3, 1.0, -0.5, 0.1]
    joints = [Joint("revolute", 0.0 if i == 0 else std[i - 1].a, 0.0 if i == 0 else std[i - 1].alpha,
                    j.d, j.theta + o, s, -2 * math.pi, 2 * math.pi)
              for i, (j, s, o) in enumerate(zip(std, signs, offs))]
    robot = Robot("ur_mod", tuple(joints), "modified")
    rng = np.random.default_rng(9)
    check_round_trip(robot, sample(robot, rng, 20_000))


@pytest.mark.parametrize("change, match", [
    (lambda j: {1: {"alpha": j[1].alpha + 1e-3}}, r"axes 2 and 3 are not parallel \(0\.05729"),
    (lambda j: {4: {"d": 0.01}}, r"axes 4 and 6 do not intersect \(they are 10 mm apart\)"),
    (lambda j: {0: {"alpha": D(-80)}}, r"axes 1 and 2 are not perpendicular \(100 deg\)"),
])
def test_non_qualifying_models_name_the_failing_axes(change, match):
    base = kr6()
    joints = list(base.joints)
    for i, kw in change(joints).items():
        joints[i] = Joint(**{**joints[i].__dict__, **kw})
    robot = Robot("bent", tuple(joints))
    with pytest.raises(InputError, match=match):
        opw_parameters(robot)
    with pytest.raises(InputError, match=r"no analytic inverse kinematics for bent.*solve_numeric"):
        robot.ik(np.eye(4))


def test_wrist_singularity_q5_zero():
    """At q5 = 0 only q4 + q6 is determined: axis 4 keeps its zero and axis 6 takes the sum."""
    robot = load_robot("kuka_kr6_r700_sixx")
    q = np.radians([10.0, -80.0, 70.0, 25.0, 0.0, 40.0])
    check_round_trip(robot, q, original=False)
    sol = robot.ik(robot.fk(q))
    k = np.flatnonzero(sol.valid)
    front = sol.q[k[np.argmin(np.abs(sol.q[k] - q).sum(axis=1))]]
    np.testing.assert_allclose(front[3], 0.0, atol=1e-12)
    np.testing.assert_allclose(front[5], q[3] + q[5], atol=1e-12)  # KUKA: A4, A6 both turn about -X
    # Near the singularity the poses still reproduce to rounding error; q4 and q6 separately are
    # only determined to about 1e-16 / |sin q5| rad, so below 1e-12 the original is not asked for.
    for eps in (1e-6, 1e-9, 1e-11, 1e-13):
        check_round_trip(robot, q + np.array([0, 0, 0, 0, eps, 0]), original=eps > 1e-10)


def test_shoulder_singularity_wrist_centre_on_axis_1():
    """Wrist centre on axis 1: axis 1 is free. Without a reference it is turned so that axis 6
    lies in the arm plane (axis 4 at 0 or 180 deg), with a reference it takes the reference's
    value (behind: + 180 deg)."""
    robot = load_robot("abb_irb120")  # a1 = 0, b = 0: the wrist centre can sit on axis 1
    p = opw_parameters(robot)
    t23 = D(30.0)
    s2 = -(p.a1 + p.a2 * math.cos(t23) + p.c3 * math.sin(t23)) / p.c2
    t2 = math.asin(s2)
    theta = np.array([0.7, t2, t23 - t2, 0.4, 0.8, -0.3])
    q = (theta - p.offsets) * p.signs
    T = robot.fk(q)
    sol = robot.ik(T)
    assert sol.valid.sum() >= 2
    np.testing.assert_allclose(np.sin(sol.q[sol.reachable][:, 3]), 0.0, atol=1e-9)
    assert not np.any(np.abs(wrap_to_pi(sol.q[sol.valid] - q)).max(axis=-1) < 1e-6)
    check_round_trip(robot, q, original=False)
    sol = solve(robot, T, q_ref=q)
    np.testing.assert_allclose(sol.q[sol.reachable][:, 0] % math.pi, q[0], atol=1e-12)
    np.testing.assert_allclose(sol.q[0], q, atol=1e-9)  # front, elbow up, not flipped
    # Any rotation of axis 1 keeps the wrist centre; IK still reproduces those poses.
    check_round_trip(robot, q + np.array([0.5, 0, 0, 0, 0, 0]), original=False)


def test_elbow_stretched():
    """Elbow fully stretched: the two elbow branches coincide and both reproduce the pose."""
    robot = load_robot("kuka_kr16")
    p = opw_parameters(robot)
    t3 = -math.atan2(p.a2, p.c3)  # sin(t3 + psi) = 0, stretched
    q = np.array([0.2, -1.2, (t3 - p.offsets[2]) * p.signs[2], 0.3, 0.5, 0.1])
    check_round_trip(robot, q)
    sol = robot.ik(robot.fk(q))
    np.testing.assert_allclose(sol.q[..., 0, :], sol.q[..., 2, :], atol=1e-6)


def test_unreachable_pose_gives_nan_and_no_valid_branch():
    robot = load_robot("kuka_kr6_r700_sixx")
    sol = robot.ik(make_pose(None, [5.0, 0.0, 0.5]))
    assert not sol.valid.any() and not sol.reachable.any()
    assert np.isnan(sol.q).all()
    assert sol.count == 0


def test_batch_shape_and_input_errors():
    robot = load_robot("abb_irb120")
    q = sample(robot, np.random.default_rng(1), 6).reshape(2, 3, 6)
    sol = robot.ik(robot.fk(q))
    assert sol.q.shape == (2, 3, 8, 6) and sol.valid.shape == (2, 3, 8)
    bad = np.eye(4)
    bad[0, 0] = np.nan
    with pytest.raises(InputError, match="NaN"):
        robot.ik(bad)
    with pytest.raises(InputError, match=r"target pose must have shape \(\.\.\., 4, 4\)"):
        robot.ik(np.eye(3))
    skewed = np.eye(4)
    skewed[0, 1] = 0.1
    with pytest.raises(InputError, match="target pose is not a valid rigid transform"):
        robot.ik(skewed)


@pytest.mark.parametrize("name", ["kuka_kr16", "ur5e", "abb_irb460", "fanuc_m20ia"])
def test_one_pose_is_the_batch_of_one(name):
    # One pose (the per-call path: one compiled check, one compiled solve) gives the same bits
    # as that pose in a batch: one kernel for both, opw, ur, palletizer and a J2/J3 coupling.
    robot = load_robot(name)
    rng = np.random.default_rng(11)
    q = sample(robot, rng, 40)
    q[:5, -2] = 0.0  # some wrist singularities (a palletizer: axis 3 at 0)
    T = robot.fk(q)
    T[-5:, :3, 3] *= 3.0  # out of reach
    tool = make_pose(rot_x(0.2), [0.01, 0.02, 0.15])
    for kw in ({}, {"tool": tool}):
        batch = robot.ik(T, **kw)
        for i in range(len(T)):
            one = robot.ik(T[i], **kw)
            assert one.method == batch.method
            for field in ("q", "valid", "reachable", "reach_error"):
                assert np.array_equal(getattr(one, field), getattr(batch, field)[i], equal_nan=True)


def test_one_pose_refuses_bad_input_as_a_batch_does():
    robot = load_robot("kuka_kr16")
    skewed = np.eye(4)
    skewed[0, 1] = 0.1
    reflected = np.diag([1.0, 1.0, -1.0, 1.0])
    nan = np.eye(4)
    nan[2, 3] = np.nan
    head = r"target pose is not a valid rigid transform: (pose \[0\]: )?"
    for bad, match in ((skewed, r"rotation part is not orthonormal \(max \|R\^T R - I\| = 0.1\)"),
                       (reflected, r"rotation part has determinant -1, not \+1 \(a reflection\)"),
                       (nan, "contains NaN or infinite values")):
        for T in (bad, bad[None]):
            with pytest.raises(InputError, match=head + match):
                robot.ik(T)
    with pytest.raises(InputError, match=r"tool is not a valid rigid transform: .*determinant"):
        robot.ik(np.eye(4), tool=reflected)


def test_joint_folder_rule():
    lower = np.radians([-350, 100, -90, -np.inf, -190])
    upper = np.radians([350, 400, 90, np.inf, 45])
    q = np.radians([[170, -90, 170, 179, 175], [-179, 90, -100, -179, 100]])
    inside = JointFolder(lower, upper)(q)
    np.testing.assert_allclose(np.degrees(q), [[170, 270, 170, 179, -185], [-179, 90, -100, -179, 100]])
    np.testing.assert_array_equal(inside, [False, False])
    q = np.radians([[180, 180, 0, 180, 0]])
    assert JointFolder(lower, upper)(q)[0]


def test_wrap_to_pi():
    np.testing.assert_allclose(wrap_to_pi(np.array([math.pi, -math.pi, 3 * math.pi, 0.5 - 4 * math.pi])),
                               [math.pi, math.pi, math.pi, 0.5])


def test_two_pi_equivalent_chosen_inside_limits():
    """A6 limited to [100, 400] deg: a principal -90 deg becomes 270 deg and is valid."""
    base = kr6()
    j6 = Joint(**{**base.joints[5].__dict__, "lower": D(100), "upper": D(400)})
    robot = Robot("kr6_a6", base.joints[:5] + (j6,))
    q = np.radians([10, -80, 70, 20, 30, 270])
    sol = robot.ik(robot.fk(q))
    hit = np.abs(sol.q - q).max(axis=-1) < 1e-9
    assert np.any(hit & sol.valid)
