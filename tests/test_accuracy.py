"""Absolute accuracy: the identified arm drives the controller's nominal one (docs/accuracy.md).

A simulated KR 16 whose link constants are off the drawing (tests/accuracy_helpers.py) is
identified from simulated tracker data; the identified model goes into a cell; poses and programs
are filtered so that the controller, with its nominal model, moves the real arm where they mean.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from accuracy_helpers import CELL, gauge, kr16_truth, seam, tracker_csv, write_rows
from cli_helpers import run
from programs_helpers import EXT

from robotcell import load_robot, save_robot
from robotcell.accuracy import filter_poses
from robotcell.cell import Cell, Provenance
from robotcell.identification import identify, read_target_measurements
from robotcell.ik.select import nearest
from robotcell.io.poseformats import pose_from_vendor
from robotcell.io.tables import read_csv
from robotcell.kinematics.transforms import invert
from robotcell.programs.check import singular_distances

NOMINAL = load_robot("kuka_kr16")


@pytest.fixture(scope="module")
def kr16(tmp_path_factory):
    """The true KR 16, its tracker data, and the identification of it (library calls)."""
    d = tmp_path_factory.mktemp("kr16")
    rng = np.random.default_rng(24)
    truth = kr16_truth(rng)
    tracker_csv(d / "tracker.csv", truth, 50, rng)
    result = identify(NOMINAL, read_target_measurements(d / "tracker.csv"), sigma=2e-5)
    return truth, d / "tracker.csv", result


def _cell_with(tmp: Path, arm, name: str = "cell.yaml") -> Path:
    """A cell file of :data:`CELL` whose identified arm is ``arm`` (saved as a model file)."""
    save_robot(arm, tmp / "arm.yaml")
    (tmp / name).write_text(CELL.replace("  model: kuka_kr16\n",
                                         "  model: kuka_kr16\n  identified: arm.yaml\n"))
    return tmp / name


# -- filtering alone ------------------------------------------------------------------------------
def test_filtering_with_the_true_arm_lands_on_the_desired_poses_to_1e_6_mm(kr16):
    truth, _, _ = kr16
    cell = Cell.load(Path(__file__).parents[1] / "examples" / "cell_kr16_track_turntable.yaml")
    cell.set_identified(truth, "truth.yaml", Provenance("manual"))
    rng = np.random.default_rng(3)
    lo, hi = NOMINAL.lower, NOMINAL.upper
    q = lo + (hi - lo) * (0.15 + 0.7 * rng.random((200, 6)))
    # 50 poses over the workspace, 5 deg or more from a singularity (at the edge of the reach
    # the real arm may reach a pose only in the other elbow configuration: it is refused then)
    far = np.min(np.stack(singular_distances(NOMINAL, q)[:2]), axis=0) > math.radians(5)
    q = q[far][:50]
    track, table = rng.uniform(0.5, 5.0, 50), rng.uniform(-1.0, 1.0, 50)
    T = cell.fk(q, track, table, tool="torch", frame="part")
    f = filter_poses(cell, T, "part", "torch", track, table)
    # the controller: its nominal IK of the commanded poses, in the configuration kept
    ctrl = cell.controller()
    sol = ctrl.ik(f.T, "part", f.track, f.table, "torch")
    kept = replace(sol, valid=sol.valid & (np.arange(8) == f.branch[:, None]))
    q_ctrl, found, _ = nearest(ctrl.robot, kept, f.q)
    assert found.all()
    real = cell.fk(q_ctrl, f.track, f.table, tool="torch", frame="part")  # the true arm
    err = np.linalg.norm(real[:, :3, 3] - T[:, :3, 3], axis=-1)
    assert err.max() < 1e-9, err.max()  # 1e-6 mm
    rot = np.linalg.norm(real[:, :3, :3] - T[:, :3, :3], axis=(1, 2))
    assert rot.max() < 1e-9
    # the configuration is the one the nominal arm uses for the desired pose (nearest home)
    nom = ctrl.ik(T, "part", track, table, "torch")
    _, _, branch = nearest(ctrl.robot, nom, np.broadcast_to(ctrl.robot.home, (50, 6)))
    assert np.array_equal(branch, f.branch)
    # the correction is the arm's error: a millimetre, not nothing
    assert 0.2e-3 < f.dpos.max() < 5e-3


def test_a_cell_without_an_identified_arm_is_refused():
    cell = Cell.load(Path(__file__).parents[1] / "examples" / "cell_kr16_track_turntable.yaml")
    with pytest.raises(Exception, match=r"the cell has no identified arm \(robot.identified\)"):
        filter_poses(cell, np.eye(4)[None], "world", "torch")


# -- the identified model file ----------------------------------------------------------------------
def test_the_identified_model_file_reads_as_an_arm(kr16, tmp_path):
    _, _, res = kr16
    save_robot(res.robot, tmp_path / "arm.yaml")
    text = (tmp_path / "arm.yaml").read_text()
    assert "tool:" not in text and "beta:" in text  # the target is not the tool; A2 has a beta
    arm = load_robot(tmp_path / "arm.yaml")
    for j, n in zip(arm.joints, NOMINAL.joints):
        assert abs(j.a - n.a) < 5e-3 and abs(j.d - n.d) < 5e-3, j.name
        for key in ("alpha", "theta", "beta"):
            assert abs(getattr(j, key) - getattr(n, key)) < math.radians(1.0), (j.name, key)
    # the same constants as the printed table
    for p in res.parameters:
        joint, _, key = p.name.partition(".")
        if p.name.startswith(("base.", "target")) or key not in ("a", "d", "alpha", "theta", "beta"):
            continue
        j = next(j for j in arm.joints if j.name == joint)
        assert getattr(j, key) == pytest.approx(p.value, abs=1e-11), p.name
    assert np.array_equal(arm.tool, NOMINAL.tool) and np.array_equal(arm.base, NOMINAL.base)
    # and the same FK as the identification's own prediction
    q = read_target_measurements(kr16[1]).q[:20]
    pred = (res.base @ arm.fk(q, tool=res.target_tool))[:, :3, 3]
    assert np.abs(pred - res.predict(q)[0][:, 0]).max() < 1e-9


def test_the_covariance_round_trips_through_the_model_file(kr16, tmp_path):
    _, _, res = kr16
    save_robot(res.robot, tmp_path / "arm.yaml")
    back = load_robot(tmp_path / "arm.yaml").covariance
    assert back.names == res.robot.covariance.names
    assert np.allclose(back.matrix, res.robot.covariance.matrix, rtol=1e-9, atol=0)
    # the robot base in the tracker frame is kept with its correlations, the targets are not
    assert "A1.theta" not in back.names and "base.x" in back.names
    assert not any(n.startswith("target") for n in back.names)
    assert back.model_error == pytest.approx(res.model_error, rel=1e-5)


# -- end to end -----------------------------------------------------------------------------------
def test_end_to_end_a_kr16_identified_then_a_path_filtered(kr16, tmp_path, capsys):
    """identify --cell, the cell's base and tool as calibrations with the identified arm find
    them, compensate: the filtered path lands within 0.05 mm RMS, the unfiltered one misses by the
    nominal model's error (measured: 0.021 mm and 0.86 mm RMS)."""
    truth, tracker, _ = kr16
    (tmp_path / "cell.yaml").write_text(CELL)
    code, out, err = run(capsys, "identify", tracker, "--robot", "kuka_kr16", "--accuracy", "0.02",
                         "--folds", "2", "-o", tmp_path / "arm.yaml", "--cell", tmp_path / "cell.yaml")
    assert code == 0, err
    assert "cell.yaml computes with it (robot.identified)" in out
    cell = Cell.load(tmp_path / "cell.yaml")
    assert cell.identified.provenance.source == "identify"
    assert "held-out RMS" in cell.identified.provenance.note
    # the physical cell: robot base and torch where they are (the identified cell's are those
    # that calibrations with joint touches find with the identified arm, tests/accuracy_helpers)
    G, K = gauge(cell.robot, truth)
    W, tool = cell.T_world_R.copy(), cell.tools["torch"].T_F_TCP.copy()
    real = replace(cell.controller(), robot=truth, T_world_R=W,
                   tools={"torch": replace(cell.tools["torch"], T_F_TCP=tool)})
    cell.T_world_R = W @ invert(G)
    cell.set_tool("torch", invert(K) @ tool, Provenance("tcp"))
    cell.save(tmp_path / "cell.yaml")
    write_rows(tmp_path / "seam.csv", list("xyzabc"), seam())
    code, out, err = run(capsys, "compensate", tmp_path / "seam.csv", "--cell",
                         tmp_path / "cell.yaml", "--tool", "torch", "--frame", "part",
                         "-o", tmp_path / "cmd.csv")
    assert code == 0, err
    c = read_csv(tmp_path / "cmd.csv")
    assert list(c) == [*"xyzabc", *(f"a{i}" for i in range(1, 7)), "shoulder", "elbow", "wrist",
                       "dpos", "drot"]
    commanded = pose_from_vendor(np.column_stack([c[k] for k in "xyzabc"]), "kuka")
    q_file = np.radians(np.column_stack([c[f"a{i}"] for i in range(1, 7)]))
    ctrl = Cell.load(tmp_path / "cell.yaml").controller()
    q, found, _ = nearest(ctrl.robot, ctrl.ik(commanded, "part", tool="torch"), q_file)
    assert found.all() and np.abs(q - q_file).max() < 1e-8  # the file's joints (9 decimals)
    desired = pose_from_vendor(seam(), "kuka")
    e = np.linalg.norm(real.fk(q, tool="torch", frame="part")[:, :3, 3] - desired[:, :3, 3], axis=1)
    rms_filtered = math.sqrt(np.mean(e**2))
    sol = ctrl.ik(desired, "part", tool="torch")
    q0, _, _ = nearest(ctrl.robot, sol, np.broadcast_to(ctrl.robot.home, (len(desired), 6)))
    e0 = np.linalg.norm(real.fk(q0, tool="torch", frame="part")[:, :3, 3] - desired[:, :3, 3],
                        axis=1)
    rms_nominal = math.sqrt(np.mean(e0**2))
    assert rms_filtered < 0.05e-3, rms_filtered
    assert rms_nominal > 0.5e-3 and rms_nominal > 20 * rms_filtered, rms_nominal
    assert np.allclose(c["dpos"], e0 * 1e3, atol=0.1)  # the correction is the nominal error


# -- programs -------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def nominal_programs(tmp_path_factory):
    """The example seam written as a program of each format for the nominal example cell."""
    from programs_helpers import CELL as EXAMPLE
    from programs_helpers import SEAM

    from robotcell.programs import write_program

    d = tmp_path_factory.mktemp("programs")
    cell = Cell.load(EXAMPLE)
    out = {}
    for vendor, ext in EXT.items():
        res = write_program(SEAM, cell, "torch", "part", vendor, d / vendor, pulses_per_degree=100)
        out[vendor] = Path(next(f for f in res.files if f.endswith(ext)))
    return EXAMPLE, out


def _identified_example(tmp: Path, arm) -> Path:
    from programs_helpers import CELL as EXAMPLE

    save_robot(arm, tmp / "arm.yaml")
    text = EXAMPLE.read_text().replace("model: kuka_kr16", "model: kuka_kr16\n  identified: "
                                       f"{tmp / 'arm.yaml'}")
    (tmp / "cell.yaml").write_text(text)
    return tmp / "cell.yaml"


@pytest.mark.parametrize("vendor", list(EXT))
def test_a_filtered_program_is_checked_where_the_unfiltered_one_meant(
        kr16, nominal_programs, tmp_path, capsys, vendor):
    truth, _, _ = kr16
    example, programs = nominal_programs
    cell = _identified_example(tmp_path, truth)
    code, out, err = run(capsys, "program", "compensate", programs[vendor], "--cell", cell,
                         "-o", tmp_path / "filtered", "--pulses-per-degree", "100")
    assert code == 0, err
    assert "largest correction" in out
    filtered = next(p for p in (tmp_path / "filtered").iterdir() if p.suffix == EXT[vendor])
    code, meant, err = run(capsys, "program", "check", programs[vendor], "--cell", example,
                           "--pulses-per-degree", "100", "--json")
    assert code == 0, err
    code, got, err = run(capsys, "program", "check", filtered, "--cell", cell,
                         "--pulses-per-degree", "100", "--json")
    assert code == 0, err
    meant, got = json.loads(meant)["points"], json.loads(got)["points"]
    assert len(meant) == len(got) == 36
    d = max(math.dist([p["world"][k] for k in "xyz"], [g["world"][k] for k in "xyz"])
            for p, g in zip(meant, got))
    assert d < 1e-3  # mm (YASKAWA writes 3 decimals of mm)
    # unfiltered, the identified arm misses
    code, raw, err = run(capsys, "program", "check", programs[vendor], "--cell", cell,
                         "--pulses-per-degree", "100", "--json")
    raw = json.loads(raw)["points"]
    assert max(math.dist([p["world"][k] for k in "xyz"], [g["world"][k] for k in "xyz"])
               for p, g in zip(meant, raw)) > 0.2
    # nothing else changed: the same files and lines apart from the points' values
    changed = 0
    for f in programs[vendor].parent.iterdir():
        before = f.read_text().splitlines()
        after = (tmp_path / "filtered" / f.name).read_text().splitlines()
        assert len(before) == len(after)
        changed += sum(a != b for a, b in zip(before, after))
    assert 36 <= changed <= 36 * (3 if vendor == "fanuc" else 1)


def test_program_compensate_says_which_configuration_each_point_keeps(kr16, nominal_programs,
                                                                     tmp_path, capsys):
    from robotcell.ik.config import kuka_status_turn

    truth, _, _ = kr16
    _, programs = nominal_programs
    cell = _identified_example(tmp_path, truth)
    code, out, err = run(capsys, "program", "compensate", programs["kuka"], "--cell", cell,
                         "-o", tmp_path / "filtered", "--json")
    assert code == 0, err
    points = json.loads(out)["points"]
    q = np.radians([[p[f"a{i}"] for i in range(1, 7)] for p in points])
    status, _ = kuka_status_turn(NOMINAL, q)
    flags = np.array([[p["shoulder"], p["elbow"], p["wrist"]] for p in points])
    # KUKA Status: bit 0 overhead = shoulder 1, bit 1 elbow front = elbow 0
    assert (flags[:, 0] == (status & 1)).all() and (flags[:, 1] == 1 - ((status >> 1) & 1)).all()


def test_program_write_in_a_cell_with_an_identified_arm_writes_filtered_points(
        kr16, nominal_programs, tmp_path, capsys):
    from programs_helpers import SEAM

    truth, _, _ = kr16
    example, programs = nominal_programs
    cell = _identified_example(tmp_path, truth)
    code, _out, err = run(capsys, "program", "write", SEAM, "--cell", cell, "--tool", "torch",
                         "--frame", "part", "--format", "kuka", "-o", tmp_path / "prog")
    assert code == 0, err
    code, got, err = run(capsys, "program", "check", tmp_path / "prog" / "seam_part.src",
                         "--cell", cell, "--json")
    code, meant, _ = run(capsys, "program", "check", programs["kuka"], "--cell", example, "--json")
    got, meant = json.loads(got)["points"], json.loads(meant)["points"]
    assert max(math.dist([p["world"][k] for k in "xyz"], [g["world"][k] for k in "xyz"])
               for p, g in zip(meant, got)) < 1e-3
    # and they are the points 'program compensate' writes (to the decimals of the file)
    run(capsys, "program", "compensate", programs["kuka"], "--cell", cell, "-o", tmp_path / "f")
    a = (tmp_path / "prog" / "seam_part.dat").read_text()
    b = (tmp_path / "f" / "seam_part.dat").read_text()
    x = [float(v) for v in re.findall(r"X (-?[0-9.]+)", a)]
    y = [float(v) for v in re.findall(r"X (-?[0-9.]+)", b)]
    assert np.allclose(x, y, atol=1e-5)


# -- the identified arm for ROS -------------------------------------------------------------------
def test_the_urdf_of_an_identified_arm_matches_its_fk_in_pinocchio(kr16):
    import pinocchio as pin
    from test_export_urdf import pinocchio_q, random_values, targets, urdf_joint_values

    from robotcell.export import export_cell

    _, _, res = kr16
    cell = Cell.load(Path(__file__).parents[1] / "examples" / "cell_kr16_track_turntable.yaml")
    cell.set_identified(res.robot, "arm.yaml", Provenance("identify"))
    assert any(j.beta for j in cell.robot.joints)
    model = pin.buildModelFromXML(export_cell(cell, "urdf"), mimic=True)
    data = model.createData()
    q, e, th = random_values(cell, np.random.default_rng(7), n=10)
    values = urdf_joint_values(cell, q, e, th)
    for i in range(len(q)):
        pin.framesForwardKinematics(model, data,
                                    pinocchio_q(model, {k: v[i] for k, v in values.items()}))
        for link, pose in targets(cell):
            got = data.oMf[model.getFrameId(link)].homogeneous
            want = pose(q[i], e[i], th[i])
            assert np.abs(got[:3, 3] - want[:3, 3]).max() < 1e-9, link
            assert np.abs(got[:3, :3] - want[:3, :3]).max() < 1e-9, link


def _description_fk(text: str, q: np.ndarray) -> np.ndarray:
    """tool0 in the controller's Base frame as ur_description builds it from a calibration file:
    urdf/ur_macro.xacro makes each entry the <origin> of a joint turning about its local Z, after
    base_link_inertia; tool0 is wrist_3_link (tests/test_library.py, urdf_fk)."""
    from test_library import urdf_fk

    from robotcell.io.yamlfile import parse_yaml

    k = parse_yaml(text, "kinematics")["kinematics"]
    joints = [((k[s]["x"], k[s]["y"], k[s]["z"]), (k[s]["roll"], k[s]["pitch"], k[s]["yaw"]),
               (0, 0, 1)) for s in ("shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2",
                                    "wrist_3")]
    return np.array([urdf_fk(joints, qi) for qi in q])


#: config/ur5e/default_kinematics.yaml of UniversalRobots/Universal_Robots_ROS2_Description
#: (BSD-3-Clause), release 2.4.5: x, y, z, roll, pitch, yaw per joint.
UR5E_DEFAULT = {"shoulder": (0, 0, 0.1625, 0, 0, 0), "upper_arm": (0, 0, 0, 1.570796327, 0, 0),
                "forearm": (-0.425, 0, 0, 0, 0, 0), "wrist_1": (-0.3922, 0, 0.1333, 0, 0, 0),
                "wrist_2": (0, -0.0997, -2.044881182297852e-11, 1.570796327, 0, 0),
                "wrist_3": (0, 0.09959999999999999, -2.042830148012698e-11, 1.570796326589793,
                            3.141592653589793, 3.141592653589793)}


def test_the_ur_calibration_file_of_the_nominal_ur5e_is_the_descriptions_own():
    from test_library import urdf_origin

    from robotcell.export.ur import ur_origins

    O = ur_origins(load_robot("ur5e"))
    for T, (name, v) in zip(O, UR5E_DEFAULT.items()):
        want = urdf_origin(v[:3], v[3:])
        assert np.abs(T - want).max() < 1e-8, name  # the file rounds pi/2 to 1.570796327


def test_export_of_an_identified_ur5e_writes_the_calibration_file_the_description_reads(
        tmp_path, capsys):
    from accuracy_helpers import NOISE
    from identification_helpers import REFLECTORS, T_D_R

    from robotcell.identification import TargetMeasurements

    nominal = load_robot("ur5e")
    rng = np.random.default_rng(5)
    truth = replace(nominal, joints=tuple(
        replace(j, a=j.a + rng.uniform(-5e-4, 5e-4), d=j.d + rng.uniform(-5e-4, 5e-4),
                alpha=j.alpha + math.radians(rng.uniform(-0.05, 0.05)),
                beta=math.radians(rng.uniform(-0.05, 0.05)) if i in (1, 2) else 0.0)
        for i, j in enumerate(nominal.joints)))
    q = rng.uniform(-math.pi, math.pi, (40, 6))
    T = T_D_R @ truth.fk(q)
    pts = np.einsum("nij,kj->nki", T[:, :3, :3], REFLECTORS) + T[:, None, :3, 3]
    res = identify(nominal, TargetMeasurements(q, pts + rng.normal(0, NOISE, pts.shape)),
                   sigma=NOISE)
    save_robot(res.robot, tmp_path / "ur5e_identified.yaml")
    (tmp_path / "cell.yaml").write_text("name: ur_cell\nrobot:\n  model: ur5e\n"
                                        "  identified: ur5e_identified.yaml\n")
    code, _out, err = run(capsys, "export", "--cell", tmp_path / "cell.yaml", "--format", "urdf",
                         "-o", tmp_path / "ur.urdf")
    assert code == 0, err
    assert "ur_kinematics.yaml" in err
    text = (tmp_path / "ur_kinematics.yaml").read_text()
    assert "hash: robotcell_" in text
    qv = rng.uniform(-math.pi, math.pi, (20, 6))
    got = _description_fk(text, qv)
    want = res.robot.fk(qv, tool=np.eye(4))
    assert np.abs(got[:, :3, 3] - want[:, :3, 3]).max() < 1e-9
    assert np.abs(got[:, :3, :3] - want[:, :3, :3]).max() < 1e-9
    # the identified geometry, not the nominal one: millimetres apart
    assert np.abs(_description_fk(text, qv)[:, :3, 3]
                  - nominal.fk(qv)[:, :3, 3]).max() > 0.3e-3


# -- how good it will be --------------------------------------------------------------------------
def test_the_predicted_sigma_agrees_with_a_monte_carlo_of_the_identification():
    """A 3-axis arm with two reflectors, 20 configurations, 0.05 mm noise, identified 50 times:
    the RMS of the error of the identified TCP as located in the measuring frame (base and arm)
    at 8 test configurations (against a noise-free identification, the same gauge) over the
    trials, against the predicted 1-sigma (sqrt of the trace of J C J^T over the base and the
    arm's constants, plus the model error, pooled over the points). Its standard deviation follows from
    the predicted covariance S of the stacked errors (Var of a Gaussian quadratic form,
    2 tr(S^2)): the bounds 0.8 and 1.25 are more than 3 of it away."""
    from robotcell.identification import TargetMeasurements
    from robotcell.identification.uncertainty import position_jacobian, position_sigma
    from robotcell.kinematics.transforms import make_pose
    from robotcell.robot.robot import Joint, Robot

    nominal = Robot("arm3", (Joint("revolute", a=0.15, alpha=-math.pi / 2, d=0.4, name="A1"),
                             Joint("revolute", a=0.5, name="A2"),
                             Joint("revolute", a=0.4, alpha=math.pi / 2, name="A3")))
    rng = np.random.default_rng(0)
    truth = replace(nominal, joints=tuple(
        replace(j, a=j.a + rng.uniform(-5e-4, 5e-4), d=j.d + rng.uniform(-5e-4, 5e-4),
                alpha=j.alpha + math.radians(rng.uniform(-0.05, 0.05))) for j in nominal.joints))
    reflectors = np.array([[0.05, 0.0, 0.1], [0.0, 0.08, 0.05]])
    noise = 5e-5

    def measure(q, sigma):
        T = truth.fk(q)
        p = np.einsum("nij,kj->nki", T[:, :3, :3], reflectors) + T[:, None, :3, 3]
        return TargetMeasurements(q, p + rng.normal(0.0, sigma, p.shape))

    exact = identify(nominal, measure(rng.uniform(-1.5, 1.5, (400, 3)), 0.0), sigma=noise)
    q_test, tool = rng.uniform(-1.5, 1.5, (8, 3)), make_pose(None, [0.1, 0.05, 0.15])
    ref = (exact.base @ exact.robot.fk(q_test, tool=tool))[:, :3, 3]
    q = rng.uniform(-1.5, 1.5, (20, 3))
    trials, squares, S, sigmas = 50, [], 0.0, []
    for _ in range(trials):
        res = identify(nominal, measure(q, noise), sigma=noise)
        # the TCP as the identification locates it in the measuring frame (base and arm)
        squares.append(np.sum(((res.base @ res.robot.fk(q_test, tool=tool))[:, :3, 3] - ref) ** 2))
        cov = res.robot.covariance
        J = position_jacobian(res.robot, q_test, tool).reshape(-1, len(cov.names))
        S = S + (J @ cov.matrix @ J.T + cov.model_error**2 * np.eye(len(J))) / trials
        sigmas.append(position_sigma(res.robot, q_test, tool))
    assert np.allclose(np.sum(np.mean(np.square(sigmas), axis=0)), np.trace(S))
    ratio = math.sqrt(np.mean(squares) / np.trace(S))
    spread = 0.5 * math.sqrt(2.0 * np.trace(S @ S) / trials) / np.trace(S)
    assert 3 * spread < 0.2, spread
    assert 0.8 <= ratio <= 1.25, ratio


def test_compensate_json_and_report_give_the_error_and_sigma_per_pose(kr16, tmp_path, capsys):
    _, _, res = kr16
    cell = _cell_with(tmp_path, res.robot)
    write_rows(tmp_path / "seam.csv", list("xyzabc"), seam(5))
    code, out, err = run(capsys, "compensate", tmp_path / "seam.csv", "--cell", cell, "--tool",
                         "torch", "--frame", "part", "--json", "--report", tmp_path / "acc.html")
    assert code == 0, err
    data = json.loads(out)
    assert len(data["points"]) == 5
    p = data["points"][0]
    assert {"x", "a1", "dpos", "drot", "error_mm", "sigma_mm"} <= set(p)
    assert 0.2 < p["error_mm"] < 5 and 0 < p["sigma_mm"] < 0.05
    # The three figures of one error: per axis (their squares add to the 3D RMS's square) and a
    # 95 % radius between the isotropic (1.61 RMS) and the one-dimensional (1.96 RMS) case.
    axes = np.array(p["sigma_axes_mm"])
    assert np.isclose(np.sum(axes**2), p["sigma_mm"] ** 2, rtol=1e-9)
    assert 1.55 * p["sigma_mm"] < p["radius95_mm"] < 1.97 * p["sigma_mm"]
    assert data["max_radius95_mm"] == max(q["radius95_mm"] for q in data["points"])
    page = (tmp_path / "acc.html").read_text()
    assert "3D RMS error filtered (mm)" in page and "data:image/png;base64," in page
    assert not (tmp_path / "cmd.csv").exists()


# -- bad input: exit 2 or 3 naming the point, nothing written ----------------------------------------
def _shifted(key: str, delta: float):
    """The nominal KR 16 with one constant of A2 moved (an arm that is not the nominal one)."""
    j = NOMINAL.joints[1]
    joints = (NOMINAL.joints[0], replace(j, **{key: getattr(j, key) + delta}), *NOMINAL.joints[2:])
    return replace(NOMINAL, name="kr16_off", joints=joints, ik_seed=NOMINAL)


@pytest.mark.parametrize("model,match", [
    ("abb_irb460", "it has 4 axes, kuka_kr16 has 6"),
    ("ur5e", "its flange is"),
    ("coupled", "its joint coupling differs"),
])
def test_an_identified_model_of_another_robot_is_refused(tmp_path, capsys, model, match):
    arm = (replace(NOMINAL, coupling=load_robot("fanuc_m20ia").coupling) if model == "coupled"
           else load_robot(model))
    cell = _cell_with(tmp_path, arm)
    write_rows(tmp_path / "seam.csv", list("xyzabc"), seam(5))
    code, _out, err = run(capsys, "compensate", tmp_path / "seam.csv", "--cell", cell, "--tool",
                         "torch", "--frame", "part", "-o", tmp_path / "cmd.csv")
    assert code == 2 and "key 'robot.identified' is refused" in err and match in err, err
    assert not (tmp_path / "cmd.csv").exists()


def test_a_pose_the_identified_arm_cannot_reach_is_named(tmp_path, capsys):
    from robotcell.ik import analytic_solver

    cell = _cell_with(tmp_path, _shifted("a", -3e-3))  # upper arm 3 mm shorter
    p = analytic_solver(NOMINAL).params
    q = np.radians([[0, -80, 30, 0, 40, 0], [10, -60, 0, 20, 50, 0], [5, -70, 20, 0, 30, 0]])
    q[1, 2] = (-math.atan2(p.a2, p.c3) - p.offsets[2]) / p.signs[2]  # stretched: the edge
    T = Cell.load(cell).controller().fk(q, tool="torch", frame="part")
    from robotcell.io.poseformats import pose_to_vendor

    write_rows(tmp_path / "p.csv", list("xyzabc"), pose_to_vendor(T, "kuka"))
    code, _out, err = run(capsys, "compensate", tmp_path / "p.csv", "--cell", cell, "--tool",
                         "torch", "--frame", "part", "-o", tmp_path / "cmd.csv",
                         "--max-correction", "20")
    assert code == 3, err
    assert "1 pose(s) cannot be filtered: pose 2: the identified arm cannot reach it" in err
    assert not (tmp_path / "cmd.csv").exists()


def test_flags_no_solution_has_are_named(tmp_path, capsys):
    cell = _cell_with(tmp_path, _shifted("a", 1e-3))
    rows = np.column_stack([seam(3), [6, 6, 2], [0, 0, 0]])
    write_rows(tmp_path / "p.csv", [*"xyzabc", "s", "t"], rows)
    code, _out, err = run(capsys, "compensate", tmp_path / "p.csv", "--cell", cell, "--tool",
                         "torch", "--frame", "part", "-o", tmp_path / "cmd.csv")
    assert code == 3, err
    assert "pose 1: the nominal arm does not reach it with the flags given (S 6,T 0)" in err
    assert not (tmp_path / "cmd.csv").exists()


def test_a_correction_above_the_limit_is_refused_as_a_wrong_model(tmp_path, capsys,
                                                                   nominal_programs):
    cell = _cell_with(tmp_path, _shifted("a", 8e-3))  # 8 mm: a model of another arm
    write_rows(tmp_path / "seam.csv", list("xyzabc"), seam(5))
    args = ["compensate", tmp_path / "seam.csv", "--cell", cell, "--tool", "torch", "--frame",
            "part", "-o", tmp_path / "cmd.csv"]
    code, _out, err = run(capsys, *args)
    assert code == 3 and "pose 1: the correction is 8." in err and "above the 5 mm" in err, err
    assert "the identified model is wrong" in err and not (tmp_path / "cmd.csv").exists()
    code, _out, err = run(capsys, *args, "--max-correction", "20")
    assert code == 0, err
    # a program: named by its points, nothing written
    _, programs = nominal_programs
    example = _identified_example(tmp_path, _shifted("a", 8e-3))
    code, _out, err = run(capsys, "program", "compensate", programs["kuka"], "--cell", example,
                         "-o", tmp_path / "prog")
    assert code == 3 and "XP1 (line" in err and "the correction is" in err, err
    assert not (tmp_path / "prog").exists()


def test_identify_into_a_cell_of_another_robot_writes_nothing(kr16, tmp_path, capsys):
    _, tracker, _ = kr16
    (tmp_path / "cell.yaml").write_text(CELL.replace("kuka_kr16", "ur5e"))
    before = (tmp_path / "cell.yaml").read_text()
    code, _out, err = run(capsys, "identify", tracker, "--robot", "kuka_kr16", "--accuracy",
                         "0.02", "--folds", "2", "-o", tmp_path / "arm.yaml", "--cell",
                         tmp_path / "cell.yaml")
    assert code == 2 and "is not an identification of 'ur5e'" in err, err
    assert not (tmp_path / "arm.yaml").exists()
    assert (tmp_path / "cell.yaml").read_text() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cell.yaml"]
    code, _out, err = run(capsys, "identify", tracker, "--cell", tmp_path / "cell.yaml")
    assert code == 2 and "--cell needs -o FILE.yaml" in err


def test_identify_into_a_cell_keeps_the_previous_file_and_states_the_provenance(
        kr16, tmp_path, capsys):
    _, tracker, _ = kr16
    (tmp_path / "cell.yaml").write_text(CELL)
    code, out, err = run(capsys, "identify", tracker, "--accuracy", "0.02", "--folds", "2",
                         "-o", tmp_path / "arm.yaml", "--cell", tmp_path / "cell.yaml")
    assert code == 0, err  # the nominal: the cell's robot.model
    assert (tmp_path / "cell.yaml.1.bak").read_text() == CELL
    code, out, err = run(capsys, "cell", "history", tmp_path / "cell.yaml")
    assert code == 0 and "robot arm.yaml" in out and "identify" in out, out
    cell = Cell.load(tmp_path / "cell.yaml")
    assert cell.identified.model == str((tmp_path / "arm.yaml").resolve())
    assert cell.nominal_robot.name == "kuka_kr16" and cell.robot.name == "kuka_kr16_identified"
    assert cell.identified.provenance.rms_mm < 0.05


def test_the_cell_file_names_the_identified_arm_relative_to_itself(kr16, tmp_path):
    _, _, res = kr16
    cell = Cell.load(_cell_with(tmp_path, res.robot))
    assert cell.identified.provenance.source == "manual"  # none written: typed in
    assert np.array_equal(cell.robot.tool, NOMINAL.tool) and cell.robot.name.endswith("identified")
    (tmp_path / "sub").mkdir()
    cell.save(tmp_path / "sub" / "cell.yaml")
    text = (tmp_path / "sub" / "cell.yaml").read_text()
    assert "identified: ../arm.yaml" in text and "provenance: {source: manual}" in text
    back = Cell.load(tmp_path / "sub" / "cell.yaml")
    q = np.radians([10, -80, 90, 20, 30, 40])
    assert np.allclose(back.fk(q, tool="torch"), cell.fk(q, tool="torch"), atol=1e-15)
    assert np.allclose(back.controller().fk(q, tool="torch"),
                       Cell.load(tmp_path / "sub" / "cell.yaml").controller().fk(q, tool="torch"))
    assert not np.allclose(back.fk(q, tool="torch"), back.controller().fk(q, tool="torch"),
                           atol=1e-4)


@pytest.mark.parametrize("edit,match", [
    ("  identified: nowhere.yaml\n", "key 'robot.identified' names model file"),
    ("  provenance: {source: identify}\n", ("key 'robot.provenance' is the provenance of an "
                                           "identified arm")),
])
def test_bad_identified_keys_name_the_key(tmp_path, capsys, edit, match):
    (tmp_path / "cell.yaml").write_text(CELL.replace("  model: kuka_kr16\n",
                                                     "  model: kuka_kr16\n" + edit))
    code, _out, err = run(capsys, "cell", "show", tmp_path / "cell.yaml")
    assert code == 2 and match in err, err


def test_robots_show_prints_the_beta_of_an_identified_model(kr16, tmp_path, capsys):
    _, _, res = kr16
    save_robot(res.robot, tmp_path / "arm.yaml")
    code, out, err = run(capsys, "robots", "show", tmp_path / "arm.yaml")
    assert code == 0, err
    assert "beta [deg]" in out and "Rot(y, beta) after Rot(x, alpha)" in out
    code, out, _ = run(capsys, "robots", "show", "kuka_kr16")
    assert "beta" not in out


def test_an_identified_scale_is_the_same_robot_a_j23_factor_is_not():
    from robotcell.kinematics.coupling import Coupling

    cell = Cell.load(Path(__file__).parents[1] / "examples" / "cell_kr16_track_turntable.yaml")
    scaled = replace(NOMINAL, coupling=Coupling(np.diag(1.0 + np.full(6, 2e-4))))
    cell.set_identified(scaled, "scaled.yaml", Provenance("identify"))
    assert cell.nominal_robot.coupling is None and cell.robot.coupling is not None
    C = np.eye(6)
    C[2, 1] = -1.0
    with pytest.raises(Exception, match=r"its joint coupling differs \(q_model = C q: C\[3, 2\]"):
        cell.set_identified(replace(NOMINAL, coupling=Coupling(C)), "j23.yaml",
                            Provenance("identify"))
