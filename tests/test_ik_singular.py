"""Analytic IK at the edges: singular families, rounding at the reach boundary, full joint limits.

Across every library robot with analytic IK: 10,000 random configurations within the real joint
limits plus the singular families (q5 = 0 and +-1e-12, wrist centre on axis 1 or on the shoulder
cylinder of a Puma-type offset, elbow stretched and folded, each with random axis 1). Every pose has
a valid branch, the original configuration is found modulo 2*pi within the limits, and every
returned branch reproduces its pose to 1e-9 m and 1e-9 rad.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from robotcell.errors import InputError
from robotcell.ik import analytic_solver, solve
from robotcell.ik.limits import TWO_PI, wrap_to_pi
from robotcell.ik.opw import opw_fk
from robotcell.ik.result import REACH_TOL
from robotcell.ik.ur import ur_fk_frames
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor
from robotcell.kinematics.dh import link_transform
from robotcell.kinematics.transforms import rot_z
from robotcell.robot.models import list_robots, load_robot
from robotcell.robot.robot import Robot

ANALYTIC = [n for n in list_robots() if n != "stanford_arm"]
N_RANDOM = 10_000
N_FAMILY = 1000


def in_limits(robot: Robot, q: np.ndarray) -> np.ndarray:
    """``q`` moved to 2*pi-equivalents inside the limits where possible; rows that fit."""
    out = q.copy()
    for j in range(robot.n_joints):
        lo, hi = robot.lower[j], robot.upper[j]
        v = out[:, j] + TWO_PI * np.ceil((lo - out[:, j]) / TWO_PI) if np.isfinite(lo) else out[:, j]
        out[:, j] = np.where(v <= hi, v, out[:, j])
    ok = np.all((out >= robot.lower) & (out <= robot.upper), axis=1)
    return out[ok]


def random_q(robot: Robot, rng: np.random.Generator, n: int) -> np.ndarray:
    """Uniform within the real joint limits (not clipped to +-pi)."""
    return rng.uniform(np.maximum(robot.lower, -TWO_PI), np.minimum(robot.upper, TWO_PI),
                       (n, robot.n_joints))


def families(robot: Robot, rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    """Singular configurations (controller values, rad) with random axis 1 and random free axes."""
    s = analytic_solver(robot)
    p, sg, off = s.params, s.params.signs, s.params.offsets
    # The solver's angles of random configurations (of the uncoupled model for a coupled arm).
    th = sg * robot.model_values(random_q(robot, rng, n)) + off

    def ctrl(theta: np.ndarray) -> np.ndarray:
        q = (theta - off) * sg
        if robot.coupling is not None:
            q = robot.coupling.to_controller(q)
        return in_limits(robot, wrap_to_pi(q))

    out = {}
    for name, t5 in (("q5=0", 0.0), ("q5=+1e-12", 1e-12), ("q5=-1e-12", -1e-12)):
        t = th.copy()
        t[:, 4] = t5
        out[name] = ctrl(t)
    if s.method == "opw":
        # Wrist centre on axis 1 (b = 0) or on the cylinder of radius |b| (Puma-type shoulder).
        t23 = th[:, 1] + th[:, 2]
        s2 = -(p.a1 + p.a2 * np.cos(t23) + p.c3 * np.sin(t23)) / p.c2
        keep = np.abs(s2) <= 1
        t = th[keep].copy()
        t2 = np.arcsin(s2[keep])
        t2 = np.where(rng.random(t2.size) < 0.5, t2, math.pi - t2)
        t[:, 1], t[:, 2] = t2, t23[keep] - t2
        out["axis 1" if p.b == 0 else "shoulder b"] = ctrl(t)
        stretched = -math.atan2(p.a2, p.c3)  # elbow angle with the wrist centre on the line of c2
    else:
        # Wrist-2 point on the cylinder of radius |d4| around axis 1: planar x = 0.
        t = th.copy()
        x = -(p.a2 * np.cos(t[:, 1]) + p.d5 * np.sin(t[:, 1] + t[:, 2] + t[:, 3])) / p.a3
        keep = np.abs(x) <= 1
        t = t[keep]
        t234 = t[:, 1] + t[:, 2] + t[:, 3]
        t23 = np.arccos(x[keep]) * np.where(rng.random(keep.sum()) < 0.5, 1, -1)
        t[:, 2], t[:, 3] = t23 - t[:, 1], t234 - t23
        out["shoulder d4"] = ctrl(t)
        stretched = 0.0
    for name, t3 in (("stretched", stretched), ("folded", stretched + math.pi)):
        t = th.copy()
        t[:, 2] = t3
        out[name] = ctrl(t)
    return out


def pose_errors(robot: Robot, sol, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position (m) and orientation (rad) error of every reachable branch, shape (..., 8)."""
    Q = np.where(sol.reachable[..., None], sol.q, 0.0)
    T2 = robot.fk(Q)
    pos = np.linalg.norm(T2[..., :3, 3] - T[..., None, :3, 3], axis=-1)
    rel = np.swapaxes(T2[..., :3, :3], -1, -2) @ T[..., None, :3, :3]
    skew = np.stack([rel[..., 2, 1] - rel[..., 1, 2], rel[..., 0, 2] - rel[..., 2, 0],
                     rel[..., 1, 0] - rel[..., 0, 1]], -1)
    ang = np.arctan2(np.linalg.norm(skew, axis=-1) / 2, (np.trace(rel, axis1=-2, axis2=-1) - 1) / 2)
    return np.where(sol.reachable, pos, 0.0), np.where(sol.reachable, ang, 0.0)


def found(sol, q: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """Whether the original configuration is a valid branch modulo 2*pi, per pose."""
    dist = np.abs(wrap_to_pi(sol.q - q[:, None, :])).max(axis=-1)
    return np.any(sol.valid & (dist < tol), axis=-1)


def check(robot: Robot, q: np.ndarray, q_ref: np.ndarray | None = None, original: bool = True,
          tol: float = 1e-6) -> None:
    T = robot.fk(q)
    sol = solve(robot, T, q_ref=q_ref)
    pos, ang = pose_errors(robot, sol, T)
    assert np.all(sol.reachable.any(axis=-1) & sol.valid.any(axis=-1))
    assert np.all(pos <= 1e-9 + sol.reach_error), pos.max()
    assert np.all(ang <= 1e-9), ang.max()
    assert np.all(sol.reach_error[sol.reachable] <= REACH_TOL)
    inside = (sol.q >= robot.lower) & (sol.q <= robot.upper)
    assert np.all(inside[sol.valid])
    if original:
        hit = found(sol, q, tol)
        assert hit.all(), q[~hit][:3]


def distances(robot: Robot, q: np.ndarray) -> dict[str, np.ndarray]:
    """How far each configuration is from each singularity: |sin t5| (wrist), the sine of the
    elbow angle from the stretched elbow, and the distance (m) of the wrist point from the
    shoulder singularity (axis 1, the cylinder of radius |b| or |d4|)."""
    s = analytic_solver(robot)
    p = s.params
    th = p.signs * robot.model_values(q) + p.offsets
    t2, t23 = th[:, 1], th[:, 1] + th[:, 2]
    if s.method == "opw":
        elbow = np.sin(th[:, 2] + math.atan2(p.a2, p.c3))
        shoulder = p.a1 + p.c2 * np.sin(t2) + p.a2 * np.cos(t23) + p.c3 * np.sin(t23)
    else:
        elbow = np.sin(th[:, 2])
        shoulder = p.a2 * np.cos(t2) + p.a3 * np.cos(t23) + p.d5 * np.sin(t23 + th[:, 3])
    return {"wrist": np.abs(np.sin(th[:, 4])), "elbow": np.abs(elbow),
            "shoulder": np.abs(shoulder)}


def own_empty_ok(robot: Robot, fname: str, qf: np.ndarray) -> bool:
    """The stretched or the folded elbow may lie outside the limits of axis 3, not both."""
    if len(qf) or fname not in ("stretched", "folded"):
        return False
    lim = np.degrees([robot.lower[2], robot.upper[2]])
    print(f"{robot.name}: no {fname} elbow within axis 3 limits {lim}")
    return True


FAMILY_OF = {"q5=0": "wrist", "q5=+1e-12": "wrist", "q5=-1e-12": "wrist", "axis 1": "shoulder",
             "shoulder b": "shoulder", "shoulder d4": "shoulder", "stretched": "elbow",
             "folded": "elbow"}


@pytest.mark.parametrize("name", ANALYTIC)
def test_random_and_singular_families(name):
    robot = load_robot(name)
    rng = np.random.default_rng(sum(map(ord, name)) + 12)
    check(robot, random_q(robot, rng, N_RANDOM))
    method = analytic_solver(robot).method
    if method == "palletizer":
        return  # 4 axes and a level flange: none of the 6-axis singular families exists
    for fname, qf in families(robot, rng, N_FAMILY).items():
        if own_empty_ok(robot, fname, qf):
            continue
        assert len(qf) > 50, (fname, len(qf))  # the family exists within the limits
        dist = distances(robot, qf)
        own = FAMILY_OF[fname]
        expect = 1e-12 if fname in ("q5=+1e-12", "q5=-1e-12") else 0.0
        np.testing.assert_allclose(dist[own], expect, atol=1e-12 if own == "shoulder" else 1e-15)
        # Samples near a second singularity are only checked for validity and reproduction (the
        # original is then determined only to about sqrt(eps) / distance).
        clean = np.all([d > 0.02 for k, d in dist.items() if k != own], axis=0)
        assert clean.mean() > 0.75
        near_wrist = fname in ("q5=+1e-12", "q5=-1e-12")
        free = fname in ("q5=0", "axis 1")  # an axis is free: the reference decides
        check(robot, qf, original=False)
        # At the shoulder singularity of an offset shoulder the joint values are determined to
        # about sqrt(eps) (the square root in rho**2 - b**2).
        tol = 1e-5 if fname in ("shoulder b", "shoulder d4") else 1e-6
        check(robot, qf[clean], original=not free and not near_wrist, tol=tol)
        # With the original as reference, it is found (the free axis takes the reference's value).
        check(robot, qf[clean], q_ref=qf[clean], original=not near_wrist, tol=tol)
        if near_wrist:
            # Next to the singularity only q4 +- q6 is determined (to 1e-16/1e-12 rad), and for
            # UR arms axes 2-4 with it: compare the others.
            qc = qf[clean]
            sol = solve(robot, robot.fk(qc), q_ref=qc)
            axes = [0, 1, 2, 4] if method == "opw" else [0, 4]
            d = np.abs(wrap_to_pi(sol.q - qc[:, None, :]))[..., axes].max(axis=-1)
            assert np.all(np.any(sol.valid & (d < 1e-6), axis=-1))


def test_ur_wrist_singularity_keeps_axes_2_3_in_reach():
    """Issue repro: ur5e at q5 = 0 with q6 = 0 puts the planar axis 2/3 problem out of reach."""
    robot = load_robot("ur5e")
    q = np.radians([0, -60, 10, -90, 0, 90])
    sol = robot.ik(robot.fk(q))
    assert sol.valid.any()
    sol = solve(robot, robot.fk(q), q_ref=q)
    assert found(sol, q[None])[0]


def test_puma_shoulder_offset_rounding():
    """Issue repro: Puma 560 within rounding of the shoulder singularity (rho = |b|)."""
    robot = load_robot("puma560")
    q = np.array([math.radians(10), math.pi / 4, 0.045875264656004014, 0.3, 0.5, 0.7])
    sol = robot.ik(robot.fk(q))
    assert sol.valid.any()
    assert found(sol, q[None])[0]
    assert np.all(sol.reach_error[sol.reachable] < 1e-12)


@pytest.mark.parametrize("name", ["kuka_kr6_r700_sixx", "abb_irb120"])
def test_wrist_centre_on_axis_1_keeps_taught_configuration(name):
    """Axis 1 is free: chosen inside the limits, and equal to the reference's when one is given."""
    robot = load_robot(name)
    rng = np.random.default_rng(5)
    q = families(robot, rng, 400)["axis 1"]
    T = robot.fk(q)
    sol = robot.ik(T)
    assert sol.valid.any(axis=-1).all()
    q1 = sol.q[..., 0][sol.reachable]
    assert np.all((q1 >= robot.lower[0]) & (q1 <= robot.upper[0]))
    sol = solve(robot, T, q_ref=q)
    np.testing.assert_allclose(sol.q[:, 0, 0], q[:, 0], atol=1e-12)
    assert found(sol, q).all()
    # A reference outside the limits of axis 1: the nearest limit is taken.
    ref = q.copy()
    ref[:, 0] = robot.upper[0] + 0.1
    sol = solve(robot, T, q_ref=ref)
    np.testing.assert_allclose(sol.q[:, 0, 0], robot.upper[0], atol=1e-12)


def test_rounded_poses_are_solved_at_the_boundary():
    """A KR 16 pose next to the stretched elbow, written with 6 decimals (mm, deg), read back."""
    robot = load_robot("kuka_kr16")
    p = analytic_solver(robot).params
    t3 = -math.atan2(p.a2, p.c3)
    rng = np.random.default_rng(3)
    q = random_q(robot, rng, 3000)
    q[:, 2] = (t3 - p.offsets[2]) * p.signs[2] + rng.uniform(-1e-9, 1e-9, len(q))
    q = in_limits(robot, q)
    T = robot.fk(q)
    T_csv = pose_from_vendor(np.round(pose_to_vendor(T, "kuka"), 6), "kuka")
    sol = robot.ik(T_csv)
    assert sol.valid.any(axis=-1).all()
    pos, _ = pose_errors(robot, sol, T_csv)
    assert np.all(pos <= sol.reach_error + 1e-9)
    assert sol.reach_error.max() > 0  # some poses were outside reach by rounding
    assert np.all(sol.reach_error[sol.reachable] <= REACH_TOL)


def outward(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Unit vector (in R) from axis 2 to the wrist point within the arm plane at ``q``."""
    s = analytic_solver(robot)
    p = s.params
    th = p.signs * robot.model_values(q) + p.offsets
    if s.method == "opw":
        T = opw_fk(p, th)
        u = T[:3, 3] - p.c4 * T[:3, 2] - rot_z(th[0]) @ np.array([p.a1, p.b, p.c1])
    else:
        T4 = ur_fk_frames(p, th)
        T3 = T4 @ np.linalg.inv(link_transform(th[3], p.d4, 0.0, math.pi / 2))
        u = T3[:3, 3] - link_transform(th[0], p.d1, 0.0, math.pi / 2)[:3, 3]
    u = p.T_R_O[:3, :3] @ u
    return u / np.linalg.norm(u)


@pytest.mark.parametrize("name", ["kuka_kr16", "ur5e", "puma560"])
def test_reach_error_is_the_distance_outside_reach(name):
    """Moving a stretched-arm pose outward by d: reachable up to 1 um, with reach_error = d."""
    robot = load_robot(name)
    s = analytic_solver(robot)
    t3 = -math.atan2(s.params.a2, s.params.c3) if s.method == "opw" else 0.0
    q = np.radians([20.0, -30.0, 0.0, 10.0, 40.0, 30.0])
    q[2] = wrap_to_pi((t3 - s.params.offsets[2]) * s.params.signs[2])
    T = robot.fk(q)
    u = outward(robot, q)
    sol = robot.ik(T)
    k = np.nanargmin(np.abs(wrap_to_pi(sol.q - q)).max(axis=-1))  # the original's branch
    assert sol.reach_error[k] == 0.0
    for d, ok in ((0.5e-6, True), (0.99e-6, True), (2e-6, False)):
        Td = T.copy()
        Td[:3, 3] += d * u
        sol = robot.ik(Td)
        np.testing.assert_allclose(sol.reach_error[k], d, rtol=1e-3)
        assert sol.reachable[k] == ok
        if ok:
            pos, ang = pose_errors(robot, sol, Td)
            np.testing.assert_allclose(pos[k], d, rtol=1e-3)
            assert ang[k] < 1e-12


# UR3e / UR10e configurations (rad, elbow stretched to within 1e-9 rad) whose poses another branch
# missed by 0.02 to 0.8 um, solved at the boundary of its reach and returned valid, although
# the pose is exactly reachable.
UR_EXTRA_BRANCH = {
    "ur3e": [[-1.7754770978528043, -1.5674255677229796, 8.766843935286329e-10, 1.5671560547012948,
              2.3329795733156145, 1.0350261880543883],
             [1.7387063255188488, -1.7351917231379221, 1.0719605996372576e-09, -1.4063794719343636,
              0.8312513506686781, 1.9657712859280476]],
    "ur10e": [[-1.3032243538635981, -0.8412605751451552, 3.326088148972903e-10, -1.5721424045174326,
               -1.4398573429550101, -2.1420434433789515],
              [-1.8911280685637049, -3.120367095025993, -4.883081477984455e-10, -1.5728946912961486,
               -1.5731279547919612, -0.24847102940014176]],
}


@pytest.mark.parametrize("name", sorted(UR_EXTRA_BRANCH))
def test_no_valid_branch_misses_a_reachable_pose(name):
    """A branch at the boundary of its reach is no solution (not valid) of a pose another valid
    branch reaches exactly (within 1 nm); poses out of reach by rounding keep their boundary
    branches (test_reach_error_is_the_distance_outside_reach)."""
    robot = load_robot(name)
    rng = np.random.default_rng(11)
    q = rng.uniform(-math.pi, math.pi, (3000, 6))
    q[:, 2] = rng.normal(0.0, 1e-9, len(q))  # stretched elbow: where boundary branches appear
    q = np.vstack([UR_EXTRA_BRANCH[name], q])
    T = robot.fk(q)
    sol = robot.ik(T)
    pos, ang = pose_errors(robot, sol, T)
    assert np.all(pos[sol.valid] <= 1e-9), pos[sol.valid].max()
    assert np.all(ang[sol.valid] <= 1e-9)
    assert found(sol, q).all()
    # the branches left out still say by how much they miss
    missed = (sol.reach_error > 1e-9) & (sol.reach_error <= REACH_TOL)
    assert missed[:2].any(axis=-1).all() and not np.any(sol.valid & missed)
    # Out of reach by rounding: the wrist-2 point 0.5 um inside the cylinder of radius d4 about
    # axis 1, which no branch reaches; the boundary branches stay valid, off by 0.5 um.
    q0 = families(robot, rng, 5)["shoulder d4"]
    T0 = robot.fk(q0)
    p5 = robot.frames(q0)[:, 5, :2, 3]
    T0[:, :2, 3] -= 0.5e-6 * p5 / np.linalg.norm(p5, axis=-1, keepdims=True)
    sol = robot.ik(T0)
    pos, _ = pose_errors(robot, sol, T0)
    assert sol.valid.any(axis=-1).all()
    np.testing.assert_allclose(sol.reach_error[sol.valid], 0.5e-6, rtol=1e-3)
    np.testing.assert_allclose(pos[sol.valid], 0.5e-6, rtol=1e-3)


def test_q_ref_shape_is_checked():
    robot = load_robot("kuka_kr16")
    T = robot.fk(np.zeros((3, 6)))
    with pytest.raises(InputError, match=r"q_ref must have shape \(\.\.\., 6\)"):
        solve(robot, T, q_ref=np.zeros(5))
    with pytest.raises(InputError, match="does not match"):
        solve(robot, T, q_ref=np.zeros((2, 6)))
    with pytest.raises(InputError, match="q_ref contains NaN"):
        solve(robot, T, q_ref=np.full(6, np.nan))
