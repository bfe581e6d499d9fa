"""Joint coupling (parallel linkages, passive joints): model files, FK, Jacobian, IK, CLI."""

from __future__ import annotations

import math

import numpy as np
import pytest
from cli_helpers import run
from scipy.spatial.transform import Rotation

from robotcell import load_robot
from robotcell.errors import InputError
from robotcell.ik import (
    TrackRobot,
    abb_confdata,
    analytic_solver,
    arm_sides,
    kuka_status_turn,
    nearest,
    select_abb,
    solve,
    solve_numeric,
)
from robotcell.ik.limits import wrap_to_pi
from robotcell.kinematics.coupling import Coupling
from robotcell.kinematics.transforms import make_pose, rot_z
from robotcell.robot.models import robot_from_dict, robot_to_dict, save_robot

COUPLED = ["fanuc_lrmate200id", "fanuc_m20ia", "abb_irb2400", "abb_irb460"]


def by_hand(name: str, q: np.ndarray) -> np.ndarray:
    """Model (serial) joint values of controller values, from the published rules.

    FANUC: ROS-Industrial fanuc driver, fanuc_utils.cpp ``linkage_transform``: the state relay
    adds ``J23_factor * J2`` to J3, with ``J23_factor = 1`` in the lrmate200id / m20ia launch files.
    ABB IRB 2400: ROS-Industrial abb driver, ``J23_coupled = true``: the controller's axis 3 is
    ``q3 + q2`` of the URDF (Obal & Gierlak 2025: theta3 = q3 - q2).
    ABB IRB 460: RoboDK's table (robotkinematicscatalogue ABB_IRB460, "nullified joints"): the
    serial elbow is axis3 - axis2, the passive joint -(shoulder + elbow) = -axis3.
    """
    q = np.array(q, dtype=float)
    if name.startswith("fanuc"):
        q[..., 2] = q[..., 2] + q[..., 1]
        return q
    if name == "abb_irb2400":
        q[..., 2] = q[..., 2] - q[..., 1]
        return q
    q1, q2, q3, q6 = np.moveaxis(q, -1, 0)
    return np.stack([q1, q2, q3 - q2, -q3, q6], axis=-1)


def in_limits(robot, rng, n):
    q = rng.uniform(np.maximum(robot.lower, -2 * math.pi), np.minimum(robot.upper, 2 * math.pi),
                    (n, robot.n_joints))
    return q[robot.within_limits(q)]


@pytest.mark.parametrize("name", COUPLED)
def test_moving_j2_alone_keeps_the_flange_orientation(name):
    robot = load_robot(name)
    q = np.zeros((201, robot.n_joints))
    q[:, 1] = np.linspace(robot.lower[1], robot.upper[1], 201)
    R = robot.fk(q)[:, :3, :3]
    assert np.abs(R - R[0]).max() < 1e-12
    # The serial model does turn the flange: the coupling is what keeps it.
    R_model = robot.uncoupled().fk(q[:, :len(robot.joints)] if robot.coupling.square else
                                   np.insert(q, 3, 0.0, axis=1))[:, :3, :3]
    assert np.abs(R_model - R_model[0]).max() > 0.1


@pytest.mark.parametrize("name", COUPLED)
def test_fk_of_controller_values_is_the_model_at_the_mapped_values(name):
    robot = load_robot(name)
    q = in_limits(robot, np.random.default_rng(1), 500)
    np.testing.assert_allclose(robot.fk(q), robot.uncoupled().fk(by_hand(name, q)), atol=1e-12)
    np.testing.assert_allclose(robot.coupling.to_model(q), by_hand(name, q), atol=1e-15)
    # One pose (the Python-float path) and the frames agree with the batch.
    np.testing.assert_allclose(robot.fk(q[0]), robot.fk(q[:1])[0], atol=1e-15)
    np.testing.assert_allclose(robot.fk(list(q[0])), robot.fk(q[:1])[0], atol=1e-15)
    np.testing.assert_allclose(robot.frames(q[:3])[:, -1] @ robot.flange @ robot.tool,
                               robot.fk(q[:3]), atol=1e-12)


@pytest.mark.parametrize("name", COUPLED)
def test_analytic_ik_returns_the_controller_values(name):
    robot = load_robot(name)
    q = in_limits(robot, np.random.default_rng(sum(map(ord, name))), 10_000)
    assert len(q) > 5000
    sol = solve(robot, robot.fk(q))
    dist = np.abs(wrap_to_pi(sol.q - q[:, None, :])).max(axis=-1)
    best = np.where(sol.valid, dist, np.inf).min(axis=-1)
    assert np.all(best < 1e-9), best.max()
    # Every valid branch reaches the pose and is within the controller's limits (pendant values).
    Q = np.where(sol.valid[..., None], sol.q, 0.0)
    err = np.abs(robot.fk(Q) - robot.fk(q)[:, None])
    assert np.all(np.where(sol.valid[..., None, None], err, 0.0) < 1e-9)
    assert np.all(robot.within_limits(np.where(sol.valid[..., None], sol.q, robot.home)))


@pytest.mark.parametrize("name", COUPLED)
def test_jacobian_is_the_derivative_in_controller_values(name):
    robot = load_robot(name)
    rng = np.random.default_rng(4)
    h = 1e-6
    for q in in_limits(robot, rng, 5):
        J = robot.jacobian(q)
        num = np.empty_like(J)
        for i in range(robot.n_joints):
            dq = np.zeros(robot.n_joints)
            dq[i] = h
            Tp, Tm = robot.fk(q + dq), robot.fk(q - dq)
            num[:3, i] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
            num[3:, i] = Rotation.from_matrix(Tp[:3, :3] @ Tm[:3, :3].T).as_rotvec() / (2 * h)
        np.testing.assert_allclose(J, num, atol=1e-7)
        np.testing.assert_allclose(J, robot.uncoupled().jacobian(robot.coupling.to_model(q))
                                   @ robot.coupling.matrix, atol=1e-14)


def test_palletizer_ik_shape_nan_branches_and_level_flange():
    robot = load_robot("abb_irb460")
    solver = analytic_solver(robot)
    assert (solver.method, solver.branches) == ("palletizer", 4)
    q = np.radians([20.0, 30.0, 40.0, -50.0])
    T = robot.fk(q)
    sol = robot.ik(T)
    assert sol.q.shape == (4, 4) and sol.valid.any()
    assert np.all(np.isnan(sol.q[~sol.reachable]))
    assert not np.any(np.isnan(sol.q[sol.reachable]))
    # A tilted flange is not reachable by a palletizer.
    tilted = T @ make_pose(Rotation.from_rotvec([0.1, 0, 0]).as_matrix(), [0, 0, 0])
    assert not robot.ik(tilted).reachable.any()
    # Far away: nothing reachable, every value NaN.
    far = T.copy()
    far[:3, 3] = [10.0, 0.0, 1.0]
    assert np.all(np.isnan(robot.ik(far).q))
    # Batches keep their shape.
    assert robot.ik(np.broadcast_to(T, (2, 3, 4, 4))).q.shape == (2, 3, 4, 4)


def test_coupling_must_be_invertible():
    with pytest.raises(InputError, match=r"coupling matrix is not invertible \(singular\)"):
        Coupling(np.array([[1.0, 0.0], [2.0, 0.0]]))
    with pytest.raises(InputError, match=r"coupling matrix is not of full column rank"):
        Coupling(np.array([[1.0, 1.0], [1.0, 1.0], [0.0, 0.0]]))
    with pytest.raises(InputError, match=r"more columns"):
        Coupling(np.ones((2, 3)))


def model(coupling: dict, **extra) -> dict:
    joints = [{"type": "revolute", "a": 0, "alpha": 0, "d": 0, "theta": 0, "min": -170, "max": 170}
              for _ in range(3)]
    return {"name": "x", "joints": joints, "coupling": coupling, **extra}


@pytest.mark.parametrize("coupling, message", [
    ({"matrix": [[1, 0, 0], [1, 0, 0], [0, 0, 1]]},
     r"robot.yaml: key 'coupling': coupling matrix is not invertible"),
    ({"matrix": [[1, 0], [0, 1]]}, r"robot.yaml: key 'coupling'.matrix must be 3 rows"),
    ({"j23_factor": 1, "matrix": [[1]]}, r"exactly one of 'j23_factor' or 'matrix'"),
    ({"j23_factor": "one"}, r"key 'coupling'.j23_factor must be a number"),
    ({"j23": 1}, r"key 'coupling': unknown key\(s\) \['j23'\]"),
    ({"j23_factor": 1, "offset": [0, 0]}, r"key 'coupling'.offset must be a list of 3 numbers"),
    ({"j23_factor": 1, "interaction": [{"coefficients": [0, 1], "max": 10}]},
     r"interaction 1: coefficients must be 3 numbers"),
])
def test_bad_coupling_keys_name_file_and_key(coupling, message):
    with pytest.raises(InputError, match=message):
        robot_from_dict(model(coupling), "robot.yaml")


def test_passive_joint_needs_coupling_and_no_limits():
    data = model({"j23_factor": 1})
    del data["coupling"]
    data["joints"][1]["passive"] = True
    with pytest.raises(InputError, match=r"robot.yaml: joint 2: a passive joint has no limits"):
        robot_from_dict(data, "robot.yaml")
    del data["joints"][1]["min"], data["joints"][1]["max"]
    with pytest.raises(InputError, match=r"robot.yaml: passive joints need key 'coupling'"):
        robot_from_dict(data, "robot.yaml")


def test_units_follow_the_joints_and_files_round_trip(tmp_path):
    # A prismatic joint driven by a revolute axis through a screw: 5 mm per degree.
    data = {"name": "screw", "joints": [
        {"type": "revolute", "a": 0, "alpha": 0, "d": 0, "theta": 0, "min": -720, "max": 720},
        {"type": "prismatic", "a": 0, "alpha": 0, "d": 0, "theta": 0, "passive": True}],
        "coupling": {"matrix": [[1], [5]], "offset": [10, 100]}}
    robot = robot_from_dict(data, "screw.yaml")
    assert robot.n_joints == 1 and len(robot.joints) == 2
    np.testing.assert_allclose(robot.coupling.to_model([math.radians(2.0)]),
                               [math.radians(12.0), 0.110], atol=1e-15)
    assert robot_to_dict(robot)["coupling"] == {"matrix": [[1], [5]], "offset": [10, 100]}
    for name in COUPLED:
        r = load_robot(name)
        save_robot(r, tmp_path / "r.yaml")
        again = load_robot(tmp_path / "r.yaml")
        np.testing.assert_array_equal(again.coupling.matrix, r.coupling.matrix)
        q = in_limits(r, np.random.default_rng(0), 10)
        np.testing.assert_allclose(again.fk(q), r.fk(q), atol=1e-12)


def fanuc_with_interaction(lo: float, hi: float):
    data = robot_to_dict(load_robot("fanuc_m20ia"))
    data["coupling"]["interaction"] = [{"coefficients": [0, 1, 1, 0, 0, 0], "min": lo, "max": hi}]
    return robot_from_dict(data, "m20ia.yaml")


def test_interaction_limit_refuses_ik_solutions():
    free = load_robot("fanuc_m20ia")
    robot = fanuc_with_interaction(-30, 30)  # serial elbow J2 + J3 within +-30 deg
    assert "interaction" in robot_to_dict(robot)["coupling"]
    q = in_limits(free, np.random.default_rng(3), 3000)
    ok = np.abs(q[:, 1] + q[:, 2]) <= math.radians(30)
    np.testing.assert_array_equal(robot.within_limits(q), ok)
    sol_free, sol = solve(free, free.fk(q)), solve(robot, free.fk(q))
    elbow = sol.q[..., 1] + sol.q[..., 2]
    assert np.all(np.abs(elbow[sol.valid]) <= math.radians(30) + 1e-12)
    assert np.count_nonzero(sol.valid) < np.count_nonzero(sol_free.valid)
    np.testing.assert_array_equal(sol.valid, sol_free.valid & (np.abs(elbow) <= math.radians(30)))


def test_robots_without_coupling_are_unchanged():
    robot = load_robot("kuka_kr16")
    assert robot.coupling is None and robot.uncoupled() is robot
    assert "coupling" not in robot_to_dict(robot)


def test_track_robot_carries_the_coupling():
    arm = load_robot("fanuc_m20ia")
    track = TrackRobot(arm, make_pose(rot_z(0.2), [0.1, 0.2, 0.0]), lower=-1.0, upper=3.0)
    as_robot = track.as_robot()
    rng = np.random.default_rng(6)
    q = np.column_stack([rng.uniform(-1, 3, 50), in_limits(arm, rng, 200)[:50]])
    np.testing.assert_allclose(as_robot.fk(q), track.fk(q), atol=1e-12)
    sol = track.ik_at(track.fk(q), q[:, 0])
    got, found, _ = nearest(as_robot, sol, q)
    assert found.all()
    np.testing.assert_allclose(got, q, atol=1e-9)
    # Numeric IK on the 7-axis chain works in controller values too.
    res = solve_numeric(as_robot, as_robot.fk(q[:5]), q0=q[:5] + 0.05)
    assert res.success.all()
    np.testing.assert_allclose(as_robot.fk(res.q), as_robot.fk(q[:5]), atol=1e-8)


def test_configuration_flags_use_the_model_geometry():
    robot = load_robot("abb_irb2400")
    q = in_limits(robot, np.random.default_rng(8), 200)
    model = robot.uncoupled()
    got = arm_sides(robot, q)
    ref = arm_sides(model, robot.coupling.to_model(q))
    np.testing.assert_array_equal(got[0], ref[0])
    np.testing.assert_array_equal(got[1], ref[1])


def test_cli_shows_the_coupling_and_works_in_controller_values(capsys):
    code, out, _ = run(capsys, "robots")
    assert code == 0 and "J23 +1" in out and "matrix, 1 passive" in out
    code, out, _ = run(capsys, "robots", "show", "fanuc_lrmate200id")
    assert code == 0 and "coupling: q_model = C q + offset (J23 +1)" in out
    code, out, _ = run(capsys, "robots", "show", "abb_irb460")
    assert code == 0 and "4 axes (5 joints in the chain)" in out and "passive" in out
    # fk: pendant values in, pose out; J2 alone keeps W, P, R.
    outs = []
    for j2 in ("0", "30"):
        code, out, _ = run(capsys, "fk", "fanuc_lrmate200id", "--joints", f"10,{j2},-20,30,-40,50",
                           "--format", "fanuc")
        assert code == 0
        outs.append([float(v) for v in out.split()[1::2]])
    np.testing.assert_allclose(outs[0][3:], outs[1][3:], atol=1e-4)
    # ik: the pendant values come back.
    pose = ",".join(f"{v:.6f}" for v in outs[1])
    code, out, _ = run(capsys, "ik", "fanuc_lrmate200id", "--pose", pose, "--format", "fanuc",
                       "--near", "10,30,-20,30,-40,50")
    assert code == 0
    row = out.splitlines()[-1].split()
    np.testing.assert_allclose([float(v) for v in row[-7:-1]], [10, 30, -20, 30, -40, 50], atol=1e-3)
    code, out, _ = run(capsys, "ik", "abb_irb460", "--pose", "1510,0,1438.5,0,180,0", "--all")
    assert code == 0 and "3 back down" in out and "A6" in out


def test_cell_with_a_coupled_arm_works_in_controller_values():
    from robotcell.cell import Cell, Track, Turntable

    robot = load_robot("fanuc_m20ia")
    cell = Cell(robot=robot, robot_model="fanuc_m20ia",
                track=Track(make_pose(rot_z(0.01), [0.1, -0.2, 0.0]), make_pose(np.eye(3), [0, 0, 0.45]),
                            axis="x", lower=0.0, upper=4.0),
                turntable=Turntable(make_pose(rot_z(0.5), [2.0, 1.5, 0.6])))
    rng = np.random.default_rng(9)
    q = in_limits(robot, rng, 100)
    e, th = rng.uniform(0, 4, 100), rng.uniform(-3, 3, 100)
    T = cell.fk(q, e, th, frame="turntable")
    # The cell's FK is the arm's FK of the pendant values (with J2/J3 coupling) placed in the cell.
    T_R = robot.fk(q)
    np.testing.assert_allclose(cell.fk(q, e, th, frame="robot"), T_R, atol=1e-12)
    sol = cell.ik(T, "turntable", track=e, table=th)
    d = np.abs(wrap_to_pi(sol.q - q[:, None])).max(axis=-1)
    assert np.all(np.where(sol.valid, d, np.inf).min(axis=-1) < 1e-9)


def test_configuration_flags_select_the_pendant_configuration():
    # ABB confdata of the IRB 2400 (coupled axis 3): the taught configuration comes back.
    robot = load_robot("abb_irb2400")
    q = in_limits(robot, np.random.default_rng(10), 3000)
    sol = robot.ik(robot.fk(q))
    got, found = select_abb(robot, sol, abb_confdata(robot, q))
    assert found.mean() > 0.999
    np.testing.assert_allclose(got[found], q[found], atol=1e-6)
    # The 8 branches of a FANUC arm are 8 different arm configurations.
    fanuc = load_robot("fanuc_m20ia")
    q = in_limits(fanuc, np.random.default_rng(11), 2000)
    sol = fanuc.ik(fanuc.fk(q))
    status, _ = kuka_status_turn(fanuc, sol.q)
    full = sol.reachable.all(axis=1)
    assert full.any()
    assert np.all(np.sort(status[full], axis=1) == np.arange(8))


def test_palletizer_ik_holds_for_another_coupling_and_a_tool():
    # The same arm with axis 3 counted from the upper arm (no J2/J3 coupling on the controller):
    # only the passive joint is coupled. The solver reads the geometry off the model, so it holds.
    data = robot_to_dict(load_robot("abb_irb460"))
    data["coupling"]["matrix"] = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, -1, -1, 0], [0, 0, 0, 1]]
    data["joints"][2].update(min=-60, max=60)
    robot = robot_from_dict(data, "irb460_serial.yaml")
    tool = make_pose(rot_z(0.3), [0.05, 0.02, 0.3])
    rng = np.random.default_rng(12)
    q = in_limits(robot, rng, 3000)
    T = robot.fk(q, tool=tool)
    R = T[:, :3, :3]
    assert np.abs(R[:, 2, 2] - R[0, 2, 2]).max() < 1e-12  # level for every configuration
    sol = robot.ik(T, tool=tool)
    d = np.abs(wrap_to_pi(sol.q - q[:, None])).max(axis=-1)
    assert np.all(np.where(sol.valid, d, np.inf).min(axis=-1) < 1e-9)


def test_four_axis_arms_without_the_structure_are_refused_with_reasons():
    data = robot_to_dict(load_robot("abb_irb460"))
    data["coupling"]["matrix"][3] = [0, 0, 0, 0]  # the passive joint no longer compensates
    robot = robot_from_dict(data, "tilting.yaml")
    with pytest.raises(InputError, match=r"nor a 4-axis palletizer \(the flange orientation changes"):
        robot.ik(robot.fk(np.zeros(4)))


def test_cli_joint_files_hold_pendant_values(tmp_path, capsys):
    """simulate writes a1..a6 as the pendant shows them, calibrate reads them back as such."""
    from pathlib import Path

    example = Path(__file__).resolve().parents[1] / "examples" / "cell_kr16_track_turntable.yaml"
    cell = tmp_path / "cell.yaml"
    cell.write_text(example.read_text().replace("model: kuka_kr16", "model: fanuc_m20ia"))
    touches = tmp_path / "t.csv"
    code, _, err = run(capsys, "simulate", "tcp", "--cell", cell, "--tool", "torch", "--seed", "1",
                       "--noise", "0", "-o", touches)
    assert code == 0, err
    code, out, _ = run(capsys, "calibrate", "tcp", touches, "--robot", "fanuc_m20ia")
    assert code == 0 and "tcp (mm): 312.500, -1.200, 95.000" in out and "RMS 0.000 mm" in out
    # Read as serial (uncoupled) joint values, the same file gives a wrong tool.
    serial = tmp_path / "m20ia_serial.yaml"
    save_robot(load_robot("fanuc_m20ia").uncoupled(), serial)
    code, out, err = run(capsys, "calibrate", "tcp", touches, "--robot", serial)
    assert code == 3 and "poor calibration" in err  # the residuals give the wrong reading away
    assert "tcp (mm): 312.500, -1.200, 95.000" not in out


def test_robots_show_prints_the_interaction_limit(tmp_path, capsys):
    path = tmp_path / "m20ia.yaml"
    save_robot(fanuc_with_interaction(-60, 150), path)
    code, out, _ = run(capsys, "robots", "show", path)
    assert code == 0 and "interaction limit: -60 <= +1 J2 +1 J3 <= 150" in out


def test_palletizer_in_a_cell_is_refused_where_six_axes_are_needed():
    from robotcell.cell import Cell, Track
    from robotcell.cell.ik import ik_path

    robot = load_robot("abb_irb460")
    cell = Cell(robot=robot, robot_model="abb_irb460",
                track=Track(np.eye(4), np.eye(4), axis="x", lower=0.0, upper=4.0))
    T = robot.fk(np.zeros((2, 4)))
    with pytest.raises(InputError, match=r"path IK needs a six-axis arm .* abb_irb460 has 4 axes"):
        ik_path(cell, T, frame="robot", track=np.zeros(2))
    with pytest.raises(InputError, match=r"choosing the track value needs a six-axis arm"):
        cell.ik(T, frame="track")
    # With the track value given, the palletizer's 4 solutions come back.
    sol = cell.ik(T, frame="robot", track=np.zeros(2))
    assert sol.q.shape == (2, 4, 4) and sol.valid.any(axis=-1).all()


def test_simulated_touches_need_a_six_axis_arm():
    from robotcell.cell import Cell, Tool
    from robotcell.studies.simulate import simulate

    robot = load_robot("abb_irb460")
    cell = Cell(robot=robot, robot_model="abb_irb460", tools={"gripper": Tool(make_pose(np.eye(3), [0, 0, 0.2]))})
    with pytest.raises(InputError, match=r"simulated touches need a six-axis arm; abb_irb460 has 4 axes"):
        simulate(cell, "tcp", tool="gripper", seed=1)


def test_real_wrist_coupling_fk_jacobian_and_ik():
    # A wrist whose axis 5 motor also turns the flange by half its angle: model J6 = A6 + 0.5 A5.
    data = robot_to_dict(load_robot("kuka_kr16"))
    C = np.eye(6)
    C[5, 4] = 0.5
    data["coupling"] = {"matrix": C.tolist()}
    robot = robot_from_dict(data, "wrist.yaml")
    assert robot_to_dict(robot)["coupling"] == {"matrix": [[float(v) if v % 1 else int(v) for v in r] for r in C]}
    q = in_limits(robot, np.random.default_rng(13), 3000)
    serial = q.copy()
    serial[:, 5] += 0.5 * q[:, 4]
    np.testing.assert_allclose(robot.fk(q), robot.uncoupled().fk(serial), atol=1e-12)
    J = robot.jacobian(q[:3])
    h = 1e-6
    num = np.stack([(robot.fk(q[:3] + h * e)[:, :3, 3] - robot.fk(q[:3] - h * e)[:, :3, 3]) / (2 * h)
                    for e in np.eye(6)], axis=-1)
    np.testing.assert_allclose(J[:, :3], num, atol=1e-7)
    sol = robot.ik(robot.fk(q))
    d = np.abs(wrap_to_pi(sol.q - q[:, None])).max(axis=-1)
    assert np.all(np.where(sol.valid, d, np.inf).min(axis=-1) < 1e-9)
