"""Coupled forward kinematics: arm on a track, turntable, TCP in every frame of the cell."""

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell import InputError, load_robot, pose_from_vendor
from robotcell.cell import Cell, Frame, Tool, Track, Turntable

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "cell_kr16_track_turntable.yaml"
ROBOT = load_robot("kuka_kr16")


def random_pose(rng, scale=1.0):
    T = np.eye(4)
    T[:3, :3] = Rotation.random(random_state=rng).as_matrix()
    T[:3, 3] = rng.uniform(-scale, scale, 3)
    return T


def random_q(rng, n=None):
    shape = (6,) if n is None else (n, 6)
    return rng.uniform(ROBOT.lower, ROBOT.upper, shape)


def Rz(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def translation(v):
    T = np.eye(4)
    T[:3, 3] = v
    return T


@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_against_independent_composition(axis):
    rng = np.random.default_rng(11)
    T_world_L, T_L_R0, T_B, T_F_TCP = (random_pose(rng, 2.0) for _ in range(4))
    W_fixed, W_robot, W_table = (random_pose(rng, 0.5) for _ in range(3))
    scale = 1.0003
    cell = Cell(robot=ROBOT, robot_model="kuka_kr16",
                track=Track(T_world_L, T_L_R0, axis=axis, scale=scale),
                turntable=Turntable(T_B, parent="world"),
                tools={"t": Tool(T_F_TCP)},
                frames={"fix": Frame(W_fixed), "cam": Frame(W_robot, parent="robot"),
                        "part": Frame(W_table, parent="turntable")})
    u = np.eye(3)["xyz".index(axis)]
    for _ in range(20):
        q, e, th = random_q(rng), rng.uniform(0, 5), rng.uniform(-6, 6)
        # T_L_R(e): the robot base slides along u by scale * e, its orientation L_Q_R unchanged.
        T_world_R = T_world_L @ translation(scale * e * u) @ T_L_R0
        T_world_TCP = T_world_R @ ROBOT.fk(q) @ np.linalg.inv(ROBOT.tool) @ T_F_TCP
        expected = {
            "world": T_world_TCP,
            "track": np.linalg.inv(T_world_L) @ T_world_TCP,
            "robot": np.linalg.inv(T_world_R) @ T_world_TCP,
            "turntable": np.linalg.inv(T_B) @ T_world_TCP,
            "fix": np.linalg.inv(W_fixed) @ T_world_TCP,
            "cam": np.linalg.inv(T_world_R @ W_robot) @ T_world_TCP,
            "part": np.linalg.inv(T_B @ Rz(th) @ W_table) @ T_world_TCP,
        }
        for frame, T in expected.items():
            np.testing.assert_allclose(cell.fk(q, track=e, table=th, tool="t", frame=frame), T,
                                       atol=1e-12, err_msg=frame)
        for alias, name in (("L", "track"), ("R", "robot"), ("B", "turntable")):
            np.testing.assert_allclose(cell.fk(q, e, th, "t", alias), expected[name], atol=1e-12)


def test_lecture_track_relations():
    """p = x + L_Q_R f and L_Q_TCP = L_Q_R R_Q_TCP, x = [x, 0, 0] along X_L (L at world)."""
    rng = np.random.default_rng(3)
    L_Q_R = Rotation.from_euler("ZYX", [0.4, -0.3, 0.2], degrees=True).as_matrix()
    T_L_R0 = np.eye(4)
    T_L_R0[:3, :3] = L_Q_R
    cell = Cell(robot=ROBOT, robot_model="kuka_kr16", track=Track(T_L_R0=T_L_R0, axis="x"))
    q = random_q(rng, 50)
    x = rng.uniform(0, 6, 50)
    T_R_TCP = ROBOT.fk(q)
    T_L_TCP = cell.fk(q, track=x, frame="track")
    f = T_R_TCP[:, :3, 3]
    p = np.stack([x, 0 * x, 0 * x], axis=1) + np.einsum("ij,nj->ni", L_Q_R, f)
    np.testing.assert_allclose(T_L_TCP[:, :3, 3], p, atol=1e-12)
    np.testing.assert_allclose(T_L_TCP[:, :3, :3], L_Q_R @ T_R_TCP[:, :3, :3], atol=1e-12)
    # Inverse relation of the lecture: f = L_Q_R^-1 (p - x).
    np.testing.assert_allclose(np.einsum("ji,nj->ni", L_Q_R, p - np.stack([x, 0 * x, 0 * x], 1)),
                               f, atol=1e-12)


def test_lecture_turntable_relation():
    """R_T_W(theta) = R_T_B Rz(theta) B_T_W for a table given in the robot base frame."""
    rng = np.random.default_rng(5)
    R_T_B, B_T_W = random_pose(rng, 1.5), random_pose(rng, 0.3)
    T_world_R = random_pose(rng, 1.0)
    cell = Cell(robot=ROBOT, robot_model="kuka_kr16", T_world_R=T_world_R,
                turntable=Turntable(R_T_B, parent="robot"),
                frames={"W": Frame(B_T_W, parent="turntable")})
    theta = rng.uniform(-2 * math.pi, 2 * math.pi, 30)
    R_T_W = np.linalg.inv(T_world_R) @ cell.frame_pose("W", table=theta)
    Q_T = np.array([Rz(t) for t in theta])
    np.testing.assert_allclose(R_T_W, R_T_B @ Q_T @ B_T_W, atol=1e-12)
    # A point fixed on the workpiece turns about Z_B by theta: same height and radius, and its
    # polar angle in B minus theta is constant.
    p_W = np.array([0.1, -0.05, 0.2, 1.0])
    p_B = np.einsum("nij,j->ni", np.linalg.inv(R_T_B) @ R_T_W, p_W)
    np.testing.assert_allclose(p_B[:, 2], p_B[0, 2], atol=1e-12)
    phase = (p_B[:, 0] + 1j * p_B[:, 1]) * np.exp(-1j * theta)
    np.testing.assert_allclose(phase, phase[0], atol=1e-12)


def test_tcp_holding_workpiece_point_while_table_turns():
    """Round trip in the workpiece frame: a TCP pose fixed in W, mapped to world and back."""
    cell = Cell.load(EXAMPLE)
    rng = np.random.default_rng(8)
    q, e = random_q(rng, 40), rng.uniform(0, 6, 40)
    theta = rng.uniform(-3, 3, 40)
    T_W_TCP = cell.fk(q, track=e, table=theta, tool="torch", frame="part")
    T_world_TCP = cell.fk(q, track=e, table=theta, tool="torch")
    np.testing.assert_allclose(cell.frame_pose("part", e, theta) @ T_W_TCP, T_world_TCP,
                               atol=1e-12)
    # Turning the table by d moves the TCP, seen from the workpiece, by Rz(-d) about Z_B.
    d = 0.3
    T_B_W = cell.frames["part"].pose
    moved = cell.fk(q, track=e, table=theta + d, tool="torch", frame="part")
    np.testing.assert_allclose(
        moved, np.linalg.inv(T_B_W) @ Rz(-d) @ T_B_W @ T_W_TCP, atol=1e-12)


def test_broadcasting_and_shapes():
    cell = Cell.load(EXAMPLE)
    rng = np.random.default_rng(2)
    q = random_q(rng, 5).reshape(5, 1, 6)
    e = rng.uniform(0, 6, 3)
    th = rng.uniform(-3, 3, (2, 1, 1))
    out = cell.fk(q, track=e, table=th, tool="torch", frame="part")
    assert out.shape == (2, 5, 3, 4, 4)
    np.testing.assert_allclose(out[1, 4, 2], cell.fk(q[4, 0], e[2], th[1, 0, 0], "torch", "part"),
                               atol=1e-13)
    assert cell.fk(q[0, 0], 1.0).shape == (4, 4)
    assert cell.frame_pose("fixture").shape == (4, 4)
    assert cell.frame_pose("robot", e).shape == (3, 4, 4)


def test_tool_argument():
    cell = Cell.load(EXAMPLE)
    rng = np.random.default_rng(4)
    q = random_q(rng)
    T = cell.tools["pointer"].T_F_TCP
    np.testing.assert_allclose(cell.fk(q, 1.0, tool=T), cell.fk(q, 1.0, tool="pointer"))
    flange = cell.fk(q, 1.0)
    np.testing.assert_allclose(flange @ T, cell.fk(q, 1.0, tool="pointer"), atol=1e-12)


def test_cell_without_track_uses_robot_placement():
    T_world_R = pose_from_vendor([1000, 500, 0, 90, 0, 0], "kuka")
    cell = Cell(robot=ROBOT, robot_model="kuka_kr16", T_world_R=T_world_R)
    q = np.radians([10, -80, 70, 20, 30, 40])
    np.testing.assert_allclose(cell.fk(q), T_world_R @ ROBOT.fk(q), atol=1e-12)
    np.testing.assert_allclose(cell.fk(q, frame="robot"), ROBOT.fk(q), atol=1e-12)


def test_errors():
    cell = Cell(robot=ROBOT, robot_model="kuka_kr16")
    q = np.zeros(6)
    with pytest.raises(InputError, match="the cell has no track; the track position must be 0"):
        cell.fk(q, track=0.5)
    with pytest.raises(InputError, match="the cell has no turntable; the table angle must be 0"):
        cell.fk(q, table=0.5)
    with pytest.raises(InputError, match="the cell has no turntable"):
        cell.fk(q, frame="turntable")
    with pytest.raises(InputError, match="no frame 'track'"):
        cell.fk(q, frame="track")
    with pytest.raises(InputError, match="unknown frame 'fixtur'; the cell has: robot, track"):
        cell.fk(q, frame="fixtur")
    with pytest.raises(InputError, match="unknown tool 'torch'; the cell has: none"):
        cell.fk(q, tool="torch")
    full = Cell.load(EXAMPLE)
    with pytest.raises(InputError, match="track position contains NaN"):
        full.fk(q, track=np.nan)
    with pytest.raises(InputError, match="table angle must be numeric"):
        full.fk(q, table="ten")
    with pytest.raises(InputError, match=r"q must have shape \(\.\.\., 6\)"):
        full.fk(np.zeros(5))
    with pytest.raises(InputError, match="tool is not a valid rigid transform"):
        full.fk(q, tool=np.zeros((4, 4)))
