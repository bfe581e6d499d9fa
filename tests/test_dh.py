"""DH chains against closed forms derived by hand, and standard vs modified DH."""

import math

import numpy as np
import pytest

from robotcell import InputError, Joint, Robot, make_pose, rot_x
from robotcell.kinematics.dh import link_transform


def test_link_transform_matches_lecture_matrix():
    # The lecture's matrix for T_{i-1,i} (standard DH), written out element by element.
    th, d, a, al = 0.3, 0.2, 0.5, -1.1
    ct, st, ca, sa = math.cos(th), math.sin(th), math.cos(al), math.sin(al)
    lecture = np.array([[ct, -ca * st, sa * st, a * ct],
                        [st, ca * ct, -sa * ct, a * st],
                        [0, sa, ca, d],
                        [0, 0, 0, 1]])
    np.testing.assert_allclose(link_transform(th, d, a, al), lecture, atol=1e-15)


def test_planar_two_link_closed_form():
    # Planar 2R arm: x = l1 c1 + l2 c12, y = l1 s1 + l2 s12, orientation theta1 + theta2.
    l1, l2 = 0.7, 0.45
    r = Robot("2r", (Joint("revolute", a=l1), Joint("revolute", a=l2)))
    q = np.random.default_rng(3).uniform(-np.pi, np.pi, (200, 2))
    T = r.fk(q)
    c1, s1 = np.cos(q[:, 0]), np.sin(q[:, 0])
    c12, s12 = np.cos(q.sum(1)), np.sin(q.sum(1))
    np.testing.assert_allclose(T[:, 0, 3], l1 * c1 + l2 * c12, atol=1e-12)
    np.testing.assert_allclose(T[:, 1, 3], l1 * s1 + l2 * s12, atol=1e-12)
    np.testing.assert_allclose(T[:, 2, 3], 0.0, atol=1e-15)
    np.testing.assert_allclose(T[:, 0, 0], c12, atol=1e-12)
    np.testing.assert_allclose(T[:, 1, 0], s12, atol=1e-12)


def test_spherical_rrp_closed_form():
    # The first three joints of the Stanford arm (Spong, Hutchinson, Vidyasagar, Robot Modeling
    # and Control, sec. 3.3.4): theta1 about z0, alpha1 = -90; theta2, d2, alpha2 = +90; then d3.
    # Hand derivation: p = [c1 s2 d3 - s1 d2, s1 s2 d3 + c1 d2, c2 d3].
    d2 = 0.154
    r = Robot("rrp", (Joint("revolute", alpha=-np.pi / 2),
                      Joint("revolute", d=d2, alpha=np.pi / 2),
                      Joint("prismatic")))
    rng = np.random.default_rng(4)
    q = np.column_stack([rng.uniform(-3, 3, 100), rng.uniform(-3, 3, 100), rng.uniform(0, 1, 100)])
    c1, s1, c2, s2, d3 = np.cos(q[:, 0]), np.sin(q[:, 0]), np.cos(q[:, 1]), np.sin(q[:, 1]), q[:, 2]
    expect = np.column_stack([c1 * s2 * d3 - s1 * d2, s1 * s2 * d3 + c1 * d2, c2 * d3])
    np.testing.assert_allclose(r.fk(q)[:, :3, 3], expect, atol=1e-12)


def random_standard_robot(rng, n=6, prismatic=(2,)):
    twists = [0.0, np.pi / 2, -np.pi / 2, np.pi, 0.37]
    joints = tuple(
        Joint("prismatic" if i in prismatic else "revolute", a=rng.normal(0, 0.3),
              alpha=twists[rng.integers(len(twists))], d=rng.normal(0, 0.3),
              theta=rng.normal(), sign=float(rng.choice([-1, 1])))
        for i in range(n))
    return Robot("random", joints, base=make_pose(rot_x(0.2), [0.1, 0, 0.3]))


def to_modified(r: Robot) -> Robot:
    """Same arm in Craig's convention: row i holds (a_{i-1}, alpha_{i-1}, d_i, theta_i) and the
    last link's Trans(x, a_n) Rot(x, alpha_n) moves into the flange transform."""
    js = r.joints
    rows = []
    for i, j in enumerate(js):
        prev_a, prev_al = (js[i - 1].a, js[i - 1].alpha) if i else (0.0, 0.0)
        rows.append(Joint(j.type, a=prev_a, alpha=prev_al, d=j.d, theta=j.theta, sign=j.sign))
    tail = make_pose(rot_x(js[-1].alpha), [js[-1].a, 0, 0])
    return Robot(r.name, tuple(rows), "modified", base=r.base, flange=tail @ r.flange)


def test_standard_and_modified_give_the_same_end_pose():
    rng = np.random.default_rng(11)
    for _ in range(5):
        std = random_standard_robot(rng)
        mod = to_modified(std)
        q = rng.uniform(-3, 3, (50, 6))
        np.testing.assert_allclose(mod.fk(q), std.fk(q), atol=1e-12)
        np.testing.assert_allclose(mod.fk(q[0]), std.fk(q[0]), atol=1e-12)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_fast_kernel_equals_matrix_product(convention):
    rng = np.random.default_rng(5)
    std = random_standard_robot(rng)
    r = std if convention == "standard" else to_modified(std)
    q = rng.uniform(-4, 4, (3000, 6))  # more than one block of the kernel
    q[0, 0] = np.pi - r.joints[0].theta * r.joints[0].sign  # an angle of exactly pi
    ref = np.broadcast_to(r.base, (len(q), 4, 4))
    var = r.dh_variables(q)
    for i, j in enumerate(r.joints):
        th = np.full(len(q), j.theta) if j.prismatic else var[:, i]
        d = var[:, i] if j.prismatic else np.full(len(q), j.d)
        ref = ref @ link_transform(th, d, j.a, j.alpha, convention)
    ref = ref @ r.flange
    np.testing.assert_allclose(r.fk(q), ref, atol=1e-12)
    F = r.frames(q[:10])
    assert F.shape == (10, 7, 4, 4)
    np.testing.assert_allclose(F[:, 0], np.broadcast_to(r.base, (10, 4, 4)))
    np.testing.assert_allclose(F[:, -1] @ r.flange, ref[:10], atol=1e-12)


def test_batch_shapes_and_single_pose_agree():
    rng = np.random.default_rng(6)
    r = random_standard_robot(rng)
    q = rng.uniform(-3, 3, (2, 3, 6))
    T = r.fk(q)
    assert T.shape == (2, 3, 4, 4)
    np.testing.assert_allclose(r.fk(q[1, 2]), T[1, 2], atol=1e-14)
    np.testing.assert_allclose(r.fk(list(q[1, 2])), T[1, 2], atol=1e-14)
    assert r.frames(q).shape == (2, 3, 7, 4, 4)
    assert r.jacobian(q).shape == (2, 3, 6, 6)


def test_tool_and_sign():
    r = Robot("1r", (Joint("revolute", a=1.0, sign=-1.0),))
    tool = make_pose(p=[0.1, 0, 0])
    # sign -1: a positive controller value turns clockwise about z0.
    np.testing.assert_allclose(r.fk([np.pi / 2], tool=tool)[:3, 3], [0, -1.1, 0], atol=1e-15)
    np.testing.assert_allclose(r.with_tool(tool).fk(np.array([[np.pi / 2]]))[0, :3, 3], [0, -1.1, 0],
                               atol=1e-15)


def test_input_errors():
    r = Robot("2r", (Joint("revolute", a=1.0), Joint("revolute", a=1.0)))
    with pytest.raises(InputError, match=r"2r has 2 joints; q must have shape \(\.\.\., 2\), got \(3,\)"):
        r.fk([0.0, 0.0, 0.0])
    with pytest.raises(InputError, match=r"got \(4, 3\)"):
        r.fk(np.zeros((4, 3)))
    with pytest.raises(InputError, match="NaN or infinite"):
        r.fk([0.0, np.nan])
    with pytest.raises(InputError, match="NaN or infinite"):
        r.fk(np.array([[0.0, np.inf]]))
    with pytest.raises(InputError, match="tool is not a valid rigid transform"):
        r.fk([0.0, 0.0], tool=np.diag([1.0, 1.0, -1.0, 1.0]))
    with pytest.raises(InputError, match="base is not a valid rigid transform"):
        Robot("x", (Joint("revolute"),), base=2 * np.eye(4))
    with pytest.raises(InputError, match="joint 1: sign must be"):
        Robot("x", (Joint("revolute", sign=2.0),))
    with pytest.raises(InputError, match="joint 1: lower limit"):
        Robot("x", (Joint("revolute", lower=1.0, upper=0.0),))


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_hayati_beta_is_a_rotation_about_y_after_the_twist(convention):
    # standard Tz(d) Rz(theta) Tx(a) Rx(alpha) Ry(beta); modified Rx(alpha) Ry(beta) Tx(a) Rz Tz,
    # element by element, against the compiled chain (batched, one pose) and link_transform
    from dataclasses import replace

    from robotcell.kinematics.transforms import rot_y, rot_z

    rng = np.random.default_rng(9)
    std = random_standard_robot(rng)
    base = std if convention == "standard" else to_modified(std)
    r = replace(base, joints=tuple(replace(j, beta=rng.uniform(-0.3, 0.3)) for j in base.joints))
    q = rng.uniform(-3, 3, (20, 6))
    var = r.dh_variables(q)
    for k in range(len(q)):
        ref = r.base.copy()
        via_link = r.base.copy()
        for i, j in enumerate(r.joints):
            th = j.theta if j.prismatic else var[k, i]
            d = var[k, i] if j.prismatic else j.d
            Tz, Rz = make_pose(p=[0, 0, d]), make_pose(rot_z(th))
            Tx, Rx, Ry = make_pose(p=[j.a, 0, 0]), make_pose(rot_x(j.alpha)), make_pose(rot_y(j.beta))
            ref = ref @ (Tz @ Rz @ Tx @ Rx @ Ry if convention == "standard" else Rx @ Ry @ Tx @ Rz @ Tz)
            via_link = via_link @ link_transform(th, d, j.a, j.alpha, convention, j.beta)
        ref = ref @ r.flange
        np.testing.assert_allclose(via_link @ r.flange, ref, atol=1e-12)
        np.testing.assert_allclose(r.fk(q[k]), ref, atol=1e-12)
        np.testing.assert_allclose(r.fk(q[k:k + 1])[0], ref, atol=1e-12)
    # beta 0 is plain DH, at no cost: the compiled program has no rotation about y
    assert all(op.kind != "ry" for op in base._chain.ops)
    assert sum(op.kind == "ry" for op in r._chain.ops) == 6


def test_one_pose_kernel_compiled_equals_python_and_the_batch():
    # The chain is written once (robotcell.kinematics.dh.chain_kernel): run as Python on floats,
    # compiled by numba for one pose, and by numpy on a batch. Compiled and Python give the same
    # bits; the batch takes cos and sin from tan(theta/2) (SIMD), equal to rounding.
    from dataclasses import replace

    from robotcell.kinematics import dh

    rng = np.random.default_rng(8)
    robots = [random_standard_robot(rng), to_modified(random_standard_robot(rng))]
    # and both with Hayati's beta (a constant rotation about y, code 4 of the program)
    robots += [replace(r, joints=tuple(replace(j, beta=rng.uniform(-0.3, 0.3)) for j in r.joints))
               for r in robots]
    for r in robots:
        q = rng.uniform(-4, 4, 6)
        tail = r.flange @ make_pose(p=[0.1, -0.02, 0.3])
        python, compiled = np.empty((4, 4)), np.empty((4, 4))
        assert dh.chain_kernel(r._chain.program, q, r.base, dh.NO_SHIFT, tail, python, None, None)
        assert dh.CHAIN.compile()(r._chain.program, q, r.base, dh.NO_SHIFT, tail, compiled, None,
                                     None)
        assert np.array_equal(python, compiled)
        np.testing.assert_array_equal(r.fk(q, tool=make_pose(p=[0.1, -0.02, 0.3])), compiled)
        np.testing.assert_allclose(r.fk(q[None], tool=make_pose(p=[0.1, -0.02, 0.3]))[0],
                                   compiled, rtol=0, atol=1e-14)
        np.testing.assert_allclose(r.frames(q), r.frames(q[None])[0], rtol=0, atol=1e-14)
        np.testing.assert_allclose(r.jacobian(q), r.jacobian(q[None])[0], rtol=0, atol=1e-14)
        # NaN is refused by the compiled kernel as by the batch
        assert not dh.CHAIN.call(r._chain.program, np.full(6, np.nan), r.base, dh.NO_SHIFT, tail,
                                 compiled, None, None)


def test_fk_from_a_placed_frame_0():
    # fk_from(T_X_0, q, shift) starts the chain at T_X_0 moved by shift: T_X_R @ fk(q) where
    # T_X_0 = T_X_R @ base (how a cell places its robot on a track, without a product of poses).
    rng = np.random.default_rng(12)
    r = random_standard_robot(rng)
    T_X_R = make_pose(rot_x(0.4), [1.0, -2.0, 0.5])
    shift = np.array([0.3, 0.0, -0.1])
    moved = T_X_R.copy()
    moved[:3, 3] += shift
    q = rng.uniform(-3, 3, (5, 6))
    tool = make_pose(p=[0.0, 0.05, 0.2])
    want = moved @ r.fk(q, tool=tool)
    np.testing.assert_allclose(r.fk_from(T_X_R @ r.base, q, tool=tool, shift=shift), want,
                               rtol=0, atol=1e-12)
    for i in range(5):
        np.testing.assert_allclose(r.fk_from(T_X_R @ r.base, q[i], tool=tool, shift=shift),
                                   want[i], rtol=0, atol=1e-12)
