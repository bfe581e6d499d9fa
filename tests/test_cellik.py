"""Coupled inverse kinematics through the track and the turntable, and continuous paths."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell import InputError, load_robot
from robotcell.cell import Cell, Frame, Tool, Track, Turntable
from robotcell.ik import kuka_status_turn
from robotcell.ik.limits import TWO_PI
from robotcell.kinematics.transforms import make_pose

ROBOT = load_robot("kuka_kr16")
TORCH = make_pose(Rotation.from_euler("y", 45, degrees=True).as_matrix(), [0.3125, -0.0012, 0.095])


def pose(rotvec, t):
    return make_pose(Rotation.from_rotvec(rotvec).as_matrix(), t)


def track_cell(table_parent="world"):
    """A KR 16 on a 6 m track along X with a turntable 1.1 m beside it (or on the carriage)."""
    T_B = (pose([0.002, -0.001, math.pi / 2], [3.0, 1.1, 0.7]) if table_parent == "world"
           else pose([0.0, 0.0, 0.3], [0.2, 1.1, 0.25]))
    return Cell(
        robot=ROBOT, robot_model="kuka_kr16",
        track=Track(pose([0, 0, 0.01], [0.1, -0.2, 0.0]), pose([0.001, -0.0005, 0.0003], [0, 0, 0.45]),
                    axis="x", scale=1.0002, lower=0.0, upper=6.0),
        turntable=Turntable(T_B, parent=table_parent, lower=-2 * math.pi, upper=2 * math.pi),
        tools={"torch": Tool(TORCH)},
        frames={"fixture": Frame(pose([0, 0, 0.5], [1.8, -1.0, 0.6])),
                "camera": Frame(pose([0.1, 0.2, 0.0], [0.3, 0.0, 1.2]), parent="robot"),
                "part": Frame(pose([0, 0, 0.26], [0.15, -0.08, 0.22]), parent="turntable")},
    )


def fixed_cell():
    """A KR 16 on the floor (no track) beside a turntable."""
    return Cell(robot=ROBOT, robot_model="kuka_kr16", T_world_R=pose([0, 0, 0.4], [0.5, 0.2, 0.0]),
                turntable=Turntable(pose([0.01, 0, 0], [1.6, 0.9, 0.6])),
                tools={"torch": Tool(TORCH)},
                frames={"part": Frame(pose([0, 0, 1.0], [0.1, 0.0, 0.2]), parent="turntable")})


def random_arm(rng, n):
    q = rng.uniform(ROBOT.lower, ROBOT.upper, (n, 6)) * 0.8
    q[:, 4] = np.where(np.abs(q[:, 4]) < 0.2, 0.5, q[:, 4])  # away from the wrist singularity
    return q


FRAMES = ["world", "track", "robot", "turntable", "fixture", "camera", "part"]


@pytest.mark.parametrize("table_parent", ["world", "robot"])
@pytest.mark.parametrize("frame", FRAMES)
def test_fk_ik_fk_round_trip_in_every_frame(frame, table_parent):
    rng = np.random.default_rng(3)
    cell = track_cell(table_parent)
    q = random_arm(rng, 300)
    e, th = rng.uniform(0, 6, 300), rng.uniform(-6, 6, 300)
    T = cell.fk(q, e, th, tool="torch", frame=frame)
    sol = cell.ik(T, frame, track=e, table=th, tool="torch")
    assert sol.q.shape == (300, 8, 6) and sol.valid.shape == (300, 8)
    # Every valid branch reproduces the target to 1e-9 ...
    qv = np.where(sol.valid[..., None], sol.q, 0.0)
    back = cell.fk(qv, e[:, None], th[:, None], tool="torch", frame=frame)
    err = np.abs(back - T[:, None]).max(axis=(-1, -2))
    assert np.all(sol.count >= 1)
    assert np.max(np.where(sol.valid, err, 0.0)) < 1e-9
    # ... and the configuration that made the target is among them (up to whole turns).
    d = np.abs((sol.q - q[:, None] + math.pi) % TWO_PI - math.pi).max(axis=-1)
    assert np.all(np.nanmin(np.where(sol.valid, d, np.inf), axis=-1) < 1e-7)


def test_round_trip_without_track():
    rng = np.random.default_rng(4)
    cell = fixed_cell()
    q, th = random_arm(rng, 200), rng.uniform(-3, 3, 200)
    for frame in ("world", "robot", "turntable", "part"):
        T = cell.fk(q, table=th, tool="torch", frame=frame)
        sol = cell.ik(T, frame, table=th, tool="torch")
        back = cell.fk(np.where(sol.valid[..., None], sol.q, 0.0), table=th[:, None], tool="torch",
                       frame=frame)
        err = np.abs(back - T[:, None]).max(axis=(-1, -2))
        assert np.all(sol.count >= 1)
        assert np.max(np.where(sol.valid, err, 0.0)) < 1e-9
        assert np.all(sol.track == 0)


def test_track_position_chosen_when_not_given():
    rng = np.random.default_rng(5)
    cell = track_cell()
    q, e, th = random_arm(rng, 40), rng.uniform(0.5, 5.5, 40), rng.uniform(-3, 3, 40)
    T = cell.fk(q, e, th, tool="torch", frame="part")
    sol = cell.ik(T, "part", table=th, tool="torch")
    assert sol.track.shape == (40,)
    assert np.all((sol.track >= 0) & (sol.track <= 6))
    assert np.all(sol.count >= 1)
    back = cell.fk(np.where(sol.valid[..., None], sol.q, 0.0), sol.track[:, None], th[:, None],
                   tool="torch", frame="part")
    assert np.max(np.where(sol.valid, np.abs(back - T[:, None]).max(axis=(-1, -2)), 0)) < 1e-9


@pytest.mark.parametrize("make", [track_cell, fixed_cell])
def test_one_target_is_the_batch_of_one(make):
    # The per-call path (one target, the world frame) gives what the batch gives: the same
    # compiled choice and solve; FK of one pose starts the chain at the robot's frame 0 in the
    # world (the batch multiplies the poses), equal to rounding.
    rng = np.random.default_rng(9)
    cell = make()
    q = random_arm(rng, 12)
    e = rng.uniform(0.5, 5.5, 12) if cell.track is not None else np.zeros(12)
    T = cell.fk(q, e, tool="torch")
    for i in range(12):
        np.testing.assert_allclose(cell.fk(q[i], e[i], tool="torch"), T[i], rtol=0, atol=1e-14)
        np.testing.assert_allclose(cell.fk(q[i], float(e[i]), tool="torch", frame="part"),
                                   cell.fk(q[i:i + 1], e[i:i + 1], tool="torch", frame="part")[0],
                                   rtol=0, atol=1e-14)
    for kw in ({}, {"track": e} if cell.track is not None else {"track": 0.0}):
        batch = cell.ik(T, tool="torch", **kw)
        for i in range(12):
            one = cell.ik(T[i], tool="torch", **{k: v[i] if np.ndim(v) else v for k, v in kw.items()})
            for field in ("q", "valid", "reachable", "track", "table", "reach_error"):
                np.testing.assert_allclose(getattr(one, field), getattr(batch, field)[i],
                                           rtol=0, atol=1e-12)


def test_limits_of_track_and_table_make_solutions_invalid():
    cell = track_cell()
    cell.turntable.lower, cell.turntable.upper = -1.0, 1.0
    q = np.radians([10, -80, 100, 10, 40, 20])
    T = cell.fk(q, 2.0, 0.5, tool="torch")
    assert cell.ik(T, track=2.0, table=0.5, tool="torch").count >= 1
    assert cell.ik(T, track=6.5, table=0.5, tool="torch").count == 0
    T_part = cell.fk(q, 2.0, 1.5, tool="torch", frame="part")
    assert cell.ik(T_part, "part", track=2.0, table=1.5, tool="torch").count == 0


def held_point_path(cell, q0, e0, span_deg, n):
    """The TCP holds the pose it has at (q0, e0, table 0) on the part while the table turns."""
    T_W = cell.fk(q0, e0, 0.0, tool="torch", frame="part")
    return T_W, np.radians(np.linspace(-span_deg, span_deg, n))


def test_path_on_turning_table_is_continuous_without_flips():
    cell = track_cell()
    q0 = np.radians([80, -80, 100, 10, 40, 20])
    T_W, th = held_point_path(cell, q0, 3.0, 30, 61)
    path = cell.ik_path(T_W, "part", track=3.0, table=th, tool="torch")
    assert path.q.shape == (61, 6) and path.track.shape == (61,)
    back = cell.fk(path.q, path.track, path.table, tool="torch", frame="part")
    assert np.abs(back - T_W).max() < 1e-9
    status, _ = kuka_status_turn(ROBOT, path.q)
    assert len(set(status.tolist())) == 1
    steps = np.abs(np.diff(path.q, axis=0)).max()
    assert steps == pytest.approx(path.max_step) and steps < math.radians(10)
    assert np.all(ROBOT.within_limits(path.q))
    assert path.manipulability > 0.01


def test_path_starts_in_the_configuration_nearest_to_q_start():
    cell = track_cell()
    q0 = np.radians([80, -80, 100, 10, 40, 20])
    T_W, th = held_point_path(cell, q0, 3.0, 30, 61)
    flipped = q0 + np.radians([0, 0, 0, 180, -80, 180])  # the wrist flip of q0
    branches = set()
    for start in (q0, flipped):
        path = cell.ik_path(T_W, "part", track=3.0, table=th, tool="torch", q_start=start)
        # Table angle 0 is target 31, where the start configuration itself is a solution.
        np.testing.assert_allclose(path.q[30], start, atol=1e-9)
        branches.add(path.branch)
    assert len(branches) == 2


def test_path_unwraps_joints_that_turn_past_pi():
    """A table turn carries axis 6 past +-180 deg: the trajectory continues, no 360 deg jump."""
    cell = fixed_cell()
    T_W = cell.fk(np.radians([40, -70, 100, 0, 60, 170]), table=0.0, tool="torch", frame="part")
    th = np.radians(np.linspace(-30, 30, 61))
    path = cell.ik_path(T_W, "part", table=th, tool="torch")
    assert path.max_step < math.radians(5)
    assert np.abs(cell.fk(path.q, table=th, tool="torch", frame="part") - T_W).max() < 1e-9
    a6 = path.q[:, 5]
    assert a6.min() < math.pi < a6.max() or a6.min() < -math.pi < a6.max()  # crosses 180 deg


def test_path_with_chosen_track_position():
    cell = track_cell()
    q0 = np.radians([80, -80, 100, 10, 40, 20])
    T_W, th = held_point_path(cell, q0, 3.0, 30, 31)
    path = cell.ik_path(T_W, "part", table=th, tool="torch", samples=13)
    assert np.all(path.track == path.track[0]) and 0 <= path.track[0] <= 6
    assert np.abs(cell.fk(path.q, path.track, th, tool="torch", frame="part") - T_W).max() < 1e-9


def test_path_failure_names_every_branch_and_the_target():
    cell = track_cell()
    q0 = np.radians([80, -80, 100, 10, 40, 20])
    T_W, th = held_point_path(cell, q0, 3.0, 40, 81)
    with pytest.raises(InputError, match=r"no arm configuration follows the whole path.*"
                                         r"branch 0 \(shoulder 0, elbow 0, wrist 0\): target \d+"):
        cell.ik_path(T_W, "part", track=0.5, table=th, tool="torch")


def test_errors():
    cell = track_cell()
    T = cell.fk(np.radians([0, -90, 90, 0, 30, 0]), 1.0)
    with pytest.raises(InputError, match="moves with the track.*give the track position"):
        cell.ik(T, "robot")
    with pytest.raises(InputError, match="moves with the track"):
        cell.ik_path(T, "camera", table=[0.0, 0.1])
    with pytest.raises(InputError, match="at least 2 targets"):
        cell.ik_path(T, track=1.0)
    with pytest.raises(InputError, match="matching lengths"):
        cell.ik_path(np.stack([T, T, T]), track=1.0, table=[0.0, 0.1])
    with pytest.raises(InputError, match=r"q_start must be one configuration of shape \(6,\)"):
        cell.ik_path(np.stack([T, T]), track=1.0, q_start=[0, 0, 0])
    with pytest.raises(InputError, match="max_step must be positive"):
        cell.ik_path(np.stack([T, T]), track=1.0, max_step=0.0)
    with pytest.raises(InputError, match="unknown tool 'laser'"):
        cell.ik(T, track=1.0, tool="laser")
    with pytest.raises(InputError, match="table angle contains NaN"):
        cell.ik(T, track=1.0, table=math.nan)
    unbounded = track_cell()
    unbounded.track.lower, unbounded.track.upper = -math.inf, math.inf
    with pytest.raises(InputError, match="needs the track limits"):
        unbounded.ik(T)
    with pytest.raises(InputError, match="the cell has no track; the track position must be 0"):
        fixed_cell().ik(T, track=1.0)


def test_ik_batch_in_chunks_is_the_one_call_and_reaches_the_targets():
    # Cell.ik_batch solves a long list a chunk at a time: the same solutions as one call of
    # Cell.ik, each valid branch reaching its target, and the nearest branch the one that made it.
    rng = np.random.default_rng(12)
    cell = track_cell()
    q, th = random_arm(rng, 23), rng.uniform(-3, 3, 23)
    T = cell.fk(q, 2.0, th, tool="torch", frame="part")
    done = []
    sol = cell.ik_batch(T, "part", None, th, "torch", chunk=5, progress=done.append)
    assert done == [5, 5, 5, 5, 3]
    one = cell.ik(T, "part", table=th, tool="torch")
    assert np.array_equal(sol.valid, one.valid) and np.allclose(sol.track, one.track)
    assert np.allclose(np.nan_to_num(sol.q), np.nan_to_num(one.q)) and sol.table.shape == (23,)
    back = cell.fk(np.where(sol.valid[..., None], sol.q, 0.0), sol.track[:, None], th[:, None],
                   tool="torch", frame="part")
    assert np.max(np.where(sol.valid, np.abs(back - T[:, None]).max(axis=(-1, -2)), 0)) < 1e-9
    fixed = cell.ik_batch(T, "part", 2.0, th, "torch", chunk=7)
    qn, found, _ = fixed.nearest(ROBOT, q)
    d = np.abs((qn - q + math.pi) % TWO_PI - math.pi)
    assert np.all(found) and d.max() < 1e-7
    with pytest.raises(InputError, match="chunk must be an integer >= 1"):
        cell.ik_batch(T, "part", chunk=0)
    with pytest.raises(InputError, match="table shape"):
        cell.ik_batch(T, "part", table=np.zeros(4))
