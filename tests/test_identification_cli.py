"""``robotcell identify``: the command-line contract (CSV in, report / JSON / model file out)."""

import json
import math
import re

import numpy as np
import pytest
from cli_helpers import run
from identification_helpers import (
    configurations,
    measure,
    one_joint_rows,
    perturbed,
    target_tool,
    truth_chain,
    write_csv,
)

from robotcell import load_robot, save_robot
from robotcell.identification import TargetMeasurements
from robotcell.io.poseformats import pose_to_vendor
from robotcell.kinematics.transforms import make_pose, rot_y
from robotcell.robot.robot import Joint, Robot

NOISE = 0.02e-3


@pytest.fixture(scope="module")
def kr16_truth():
    rng = np.random.default_rng(21)
    nominal = load_robot("kuka_kr16")
    ch, x = truth_chain(perturbed(nominal, rng), 2, False, rng)
    return nominal, ch, x, rng


def tracker_csv(kr16_truth, tmp_path, n):
    """``n`` simulated rows of the KR 16 truth written as the CLI's CSV; (measurements, path)."""
    nominal, ch, x, rng = kr16_truth
    meas = measure(ch, x, configurations(nominal, n, rng), rng, NOISE)
    write_csv(tmp_path / "tracker.csv", meas)
    return meas, tmp_path / "tracker.csv"


def test_identify_json_and_model_file(kr16_truth, tmp_path, capsys):
    nominal, ch, x, rng = kr16_truth
    meas = measure(ch, x, configurations(nominal, 40, rng), rng, NOISE)
    csv = tmp_path / "tracker.csv"
    write_csv(csv, meas)
    out = tmp_path / "kr16_identified.yaml"
    code, stdout, stderr = run(capsys, "identify", csv, "--robot", "kuka_kr16", "-o", out, "--json",
                               "--accuracy", "0.02", "--folds", "5")
    assert code == 0, stderr
    data = json.loads(stdout)
    cv = data["cross_validation"]
    assert cv["folds"] == 5 and cv["after_rms_mm"] < 0.06 and cv["before_rms_mm"] > 10 * cv["after_rms_mm"]
    for key in ("base", "targets", "rms_before_mm", "rms_after_mm", "fixed", "parameters"):
        assert key in data
    base = np.array(data["base"])
    assert np.allclose(base[:3, 3], ch.base_start[:3, 3] * 1e3, atol=2.0)  # mm
    assert len(data["targets"]) == 2
    assert data["rms_after_mm"] < 0.05 < data["rms_before_mm"]
    assert "A1.theta" in data["fixed"]
    p = {d["name"]: d for d in data["parameters"]}
    assert p["A2.a"]["free"] and p["A2.a"]["sigma"] > 0
    # The model file: its FK takes the CSV's joint values and predicts the measured target 1.
    robot = load_robot(out)
    T = np.array(data["base"])
    T[:3, 3] /= 1e3
    pred = (T @ robot.fk(meas.q, tool=target_tool(data)))[:, :3, 3]
    assert np.sqrt(np.mean(np.sum((pred - meas.points[:, 0]) ** 2, axis=1))) < 0.05e-3


def test_identify_report_and_poor_result(kr16_truth, tmp_path, capsys):
    nominal, ch, x, rng = kr16_truth
    meas = measure(ch, x, configurations(nominal, 40, rng), rng, NOISE)
    csv = tmp_path / "tracker.csv"
    write_csv(csv, meas)
    code, stdout, _ = run(capsys, "identify", csv, "--robot", "kuka_kr16", "--folds", "4")
    assert code == 0
    assert "verdict: good" in stdout and "held at nominal" in stdout
    assert "rows by position error, identified model" in stdout and "#" in stdout
    assert "cross-validation, 4 folds" in stdout
    # Joint values off by a gross amount in one axis (a scale of 2): exit 3, no model file.
    q = meas.q.copy()
    q[:, 1] *= 2.0
    write_csv(csv, TargetMeasurements(q, meas.points))
    out = tmp_path / "bad.yaml"
    code, _, stderr = run(capsys, "identify", csv, "--robot", "kuka_kr16", "-o", out)
    assert code == 3
    assert "poor result" in stderr and "not written" in stderr
    assert not out.exists()
    code, _, _ = run(capsys, "identify", csv, "--robot", "kuka_kr16", "-o", out, "--force")
    assert code == 3 and out.exists()


def test_identify_without_nominal_uses_circle_point_analysis(tmp_path, capsys):
    rng = np.random.default_rng(22)
    nominal = load_robot("stanford_arm")  # with a prismatic joint, read in mm
    ch, x = truth_chain(perturbed(nominal, rng), 1, False, rng)
    q1 = one_joint_rows(nominal)
    q1[:, 2] = 0.4 + q1[:, 2] * 0.3 / math.radians(60)  # d3 from 0.1 to 0.7 m, else 0.4 m
    q2 = configurations(nominal, 40, rng)
    q2[:, 2] = rng.uniform(0.1, 0.9, 40)
    q = np.concatenate([q1, q2])
    meas = measure(ch, x, q, rng, NOISE)
    csv = tmp_path / "tracker.csv"
    write_csv(csv, meas, nominal.prismatic)
    out = tmp_path / "arm.yaml"
    code, stdout, stderr = run(capsys, "identify", csv, "-o", out, "--json", "--accuracy", "0.02")
    assert code == 0, stderr
    data = json.loads(stdout)
    assert data["rms_after_mm"] < 0.05
    robot = load_robot(out)
    assert [j.type for j in robot.joints] == [j.type for j in nominal.joints]
    qv = configurations(nominal, 100, rng)
    qv[:, 2] = rng.uniform(0.1, 0.9, 100)
    T = np.array(data["base"])
    T[:3, 3] /= 1e3
    err = (T @ robot.fk(qv, tool=target_tool(data)))[:, :3, 3] - ch.predict(x, qv)[0][:, 0]
    assert np.sqrt(np.mean(np.sum(err**2, axis=1))) < 0.03e-3


def test_identify_j23_factor_report(tmp_path, capsys):
    rng = np.random.default_rng(23)
    nominal = load_robot("kuka_kr16")
    ch, x = truth_chain(perturbed(nominal, rng), 2, False, rng, coupling=-1.0)
    meas = measure(ch, x, configurations(nominal, 40, rng), rng, NOISE)
    csv = tmp_path / "parallel_arm.csv"  # axis 3 = the forearm's angle, q3_model = J3 - J2
    write_csv(csv, meas)
    out = tmp_path / "parallel_arm_identified.yaml"
    code, stdout, _ = run(capsys, "identify", csv, "--robot", "kuka_kr16", "--j23-factor", "-1",
                          "--json", "--accuracy", "0.02", "-o", out)
    assert code == 0
    data = json.loads(stdout)
    check = data["coupling_check"]
    assert check["supported"] and check["rms_without_mm"] > 10 * check["rms_with_mm"]
    # The model file holds the coupling: its FK takes the CSV's controller values.
    assert "coupling: {j23_factor: -1}" in out.read_text()
    base = np.array(data["base"])
    base[:3, 3] /= 1e3
    pred = (base @ load_robot(out).fk(meas.q, tool=target_tool(data)))[:, :3, 3]
    assert np.sqrt(np.mean(np.sum((pred - meas.points[:, 0]) ** 2, axis=1))) < 0.05e-3


def test_identify_without_nominal_groups_rows_in_model_values_of_a_coupled_arm(tmp_path, capsys):
    # A FANUC arm (pendant J3 = forearm to the horizontal, chain J3 = J3 + J2) whose rows move one
    # joint of the chain at a time: moving J2 alone means J3 = -J2 on the pendant.
    rng = np.random.default_rng(24)
    nominal = load_robot("fanuc_m20ia")
    ch, x = truth_chain(perturbed(nominal, rng), 1, False, rng)
    model_rows = np.concatenate([one_joint_rows(nominal, span_deg=40),
                                 nominal.model_values(configurations(nominal, 40, rng))])
    pendant = model_rows.copy()
    pendant[:, 2] -= model_rows[:, 1]
    meas = measure(ch, x, pendant, rng, NOISE)
    write_csv(tmp_path / "fanuc.csv", meas)
    code, stdout, stderr = run(capsys, "identify", tmp_path / "fanuc.csv", "--j23-factor", "1",
                               "--json", "--accuracy", "0.02", "-o", tmp_path / "fanuc.yaml")
    assert code == 0, stderr
    data = json.loads(stdout)
    assert data["coupling_check"]["supported"]
    # the reference: the same rows converted to the chain's values by hand, no coupling
    write_csv(tmp_path / "model.csv", TargetMeasurements(model_rows, meas.points))
    code, ref, stderr = run(capsys, "identify", tmp_path / "model.csv", "--json", "--accuracy", "0.02")
    assert code == 0, stderr
    ref = json.loads(ref)
    assert data["rms_after_mm"] == pytest.approx(ref["rms_after_mm"], rel=0.02)
    floor = math.sqrt(3) * NOISE  # RMS of the 3-D noise (m)
    assert data["rms_after_mm"] < 1.1 * floor * 1e3
    # the model file takes the pendant's values
    assert "coupling: {j23_factor: 1}" in (tmp_path / "fanuc.yaml").read_text()
    base = np.array(data["base"])
    base[:3, 3] /= 1e3
    pred = (base @ load_robot(tmp_path / "fanuc.yaml").fk(meas.q, tool=target_tool(data)))[:, :3, 3]
    assert np.sqrt(np.mean(np.sum((pred - meas.points[:, 0]) ** 2, axis=1))) < 1.1 * floor


@pytest.mark.parametrize("content,message", [
    ("a1,a2,x,y,z\n0,0,1,2,3\n", "6 joints"),
    ("a1,a2,a3,a4,a5,a6,x,y\n0,0,0,0,0,0,1,2\n", "x,y,z"),
    ("b1,x,y,z\n0,1,2,3\n", "a1..aN"),
    ("a1,a2,a3,a4,a5,a6,x,y,z,qw,qx\n0,0,0,0,0,0,1,2,3,1,0\n", "qw,qx,qy,qz"),
    ("a1,a2,a3,a4,a5,a6,x,y,z,qw,qx,qy,qz\n0,0,0,0,0,0,1,2,3,2,0,0,0\n", "length"),
    ("a1,a2,a3,a4,a5,a6,x,y,z\n0,0,0,0,0,0,1,2,abc\n", "numeric"),
])
def test_identify_refuses_bad_csv(tmp_path, capsys, content, message):
    csv = tmp_path / "bad.csv"
    csv.write_text(content)
    code, _, stderr = run(capsys, "identify", csv, "--robot", "kuka_kr16")
    assert code == 2
    # an unknown column (b1) is named in a warning line before the error
    assert re.search(r"^error:", stderr, re.MULTILINE) and message in stderr
    assert "Traceback" not in stderr


def test_identify_without_nominal_needs_one_joint_rows(tmp_path, capsys):
    rng = np.random.default_rng(1)
    csv = tmp_path / "random.csv"
    write_csv(csv, TargetMeasurements(rng.uniform(-1, 1, (30, 6)), rng.uniform(-1, 1, (30, 3))))
    code, _, stderr = run(capsys, "identify", csv)
    assert code == 2 and "joint 1: no rows move it alone" in stderr


def test_identify_positioner_with_quaternions(tmp_path, capsys):
    nominal = Robot(name="positioner", convention="standard", base=make_pose(rot_y(math.pi / 2), [0, 0, 0.8]),
                    joints=(Joint("revolute", alpha=-math.pi / 2, name="tilt"),
                            Joint("revolute", d=0.25, name="rotate")))
    model = tmp_path / "positioner.yaml"
    save_robot(nominal, model)
    rng = np.random.default_rng(24)
    ch, x = truth_chain(perturbed(nominal, rng), 1, True, rng)
    q = rng.uniform(-1.5, 1.5, (30, 2))
    csv = tmp_path / "camera.csv"
    write_csv(csv, measure(ch, x, q, rng, NOISE, math.radians(0.01)))
    assert "qw,qx,qy,qz" in csv.read_text().splitlines()[0]
    code, stdout, stderr = run(capsys, "identify", csv, "--robot", model, "--json", "--accuracy", "0.02",
                               "--angle-accuracy", "0.01")
    assert code == 0, stderr
    data = json.loads(stdout)
    assert np.array(data["target"]).shape == (4, 4)
    assert data["rms_after_mm"] < 0.05 and data["rotation_rms_after_deg"] < 0.03
    assert {p["name"] for p in data["parameters"] if p["free"] and not p["name"].startswith(
        ("base", "target"))} == {"tilt.a", "tilt.alpha"}


def test_identified_model_file_in_fk_and_ik(kr16_truth, tmp_path, capsys):
    _, csv = tracker_csv(kr16_truth, tmp_path, 40)
    out = tmp_path / "kr16_identified.yaml"
    code, _, stderr = run(capsys, "identify", csv, "--robot", "kuka_kr16", "-o", out, "--accuracy", "0.02")
    assert code == 0, stderr
    joints = [10.0, -70.0, 100.0, 20.0, 40.0, -30.0]
    code, stdout, stderr = run(capsys, "fk", out, "--joints", ",".join(map(str, joints)))
    assert code == 0, stderr
    T = load_robot(out).fk(np.radians(joints))  # full precision for the round trip
    pose = ",".join(f"{v:.9f}" for v in pose_to_vendor(T, "kuka"))
    code, stdout, stderr = run(capsys, "ik", out, "--pose", pose, "--near", ",".join(map(str, joints)))
    assert code == 0, stderr
    assert "numeric, seeded by kuka_kr16 (opw)" in stdout
    row = stdout.strip().splitlines()[-1].split()
    k = row.index("yes")
    assert np.allclose([float(v) for v in row[k - 6:k]], joints, atol=1e-3)  # printed to 0.001 deg
    code, stdout, stderr = run(capsys, "ik", out, "--pose", pose, "--all")
    assert code == 0 and len(stdout.strip().splitlines()) == 3 + 8, stderr


def test_propose_configurations_then_identify_them(kr16_truth, tmp_path, capsys):
    nominal, ch, x, rng = kr16_truth
    out = tmp_path / "to_measure.csv"
    code, stdout, stderr = run(capsys, "identify", "--propose", 15, "--robot", "kuka_kr16",
                               "--targets", 2, "-o", out)
    assert code == 0, stderr
    o1, best = (float(v) for v in re.search(r"O1 of the 15 proposed configurations: ([\d.e-]+); "
                                             r"20 random .* best ([\d.e-]+)", stdout).groups())
    assert o1 > best
    cols = np.loadtxt(out, delimiter=",", skiprows=1)
    assert out.read_text().startswith("a1,a2,a3,a4,a5,a6\n") and cols.shape == (15, 6)
    q = np.radians(cols)
    assert np.all(nominal.within_limits(q))
    # Measured (simulated) at those configurations, the CSV identifies the arm.
    meas = measure(ch, x, q, rng, NOISE)
    write_csv(tmp_path / "measured.csv", meas)
    code, stdout, stderr = run(capsys, "identify", tmp_path / "measured.csv", "--robot", "kuka_kr16",
                               "--json", "--accuracy", "0.02")
    assert code == 0, stderr
    assert json.loads(stdout)["rms_after_mm"] < 0.05
    # --json without -o: the configurations in the object.
    code, stdout, _ = run(capsys, "identify", "--propose", 15, "--robot", "kuka_kr16", "--json")
    data = json.loads(stdout)
    assert code == 0 and len(data["configurations"]) == 15 and len(data["o1_random"]) == 20


@pytest.mark.parametrize("args,message", [
    (["--propose", "10"], "--propose needs --robot"),
    (["x.csv", "--propose", "10", "--robot", "kuka_kr16"], "give no MEASUREMENTS"),
    (["--propose", "2", "--robot", "kuka_kr16"], "propose at least"),
    (["--propose", "10", "--robot", "kuka_kr16", "--targets", "2", "--orientation"], "one target"),
    ([], "give MEASUREMENTS.csv"),
])
def test_propose_refusals(args, message, capsys):
    code, _, stderr = run(capsys, "identify", *args)
    assert code == 2 and message in stderr


@pytest.mark.parametrize("vendor,unit,scale", [("kuka", "deg", 180 / math.pi), ("abb", "rad", 1.0)])
def test_joint_offsets_for_controllers(kr16_truth, tmp_path, capsys, vendor, unit, scale):
    nominal, ch, x, _ = kr16_truth
    _, csv = tracker_csv(kr16_truth, tmp_path, 50)
    code, stdout, stderr = run(capsys, "identify", csv, "--robot", "kuka_kr16", "--accuracy", "0.02",
                               "--json", "--offsets-for", vendor)
    assert code == 0, stderr
    axes = json.loads(stdout)["joint_offsets"]["axes"]
    # The true zero error of each axis, as a counter correction: sign * (theta_true - theta_nominal).
    for j, a in zip(range(6), axes):
        assert a["unit"] == unit
        key = f"A{j + 1}.theta"
        if j in (0, 5):  # absorbed by the base pose and by the target: not determined, and why
            assert a["delta"] is None or math.isnan(a["delta"])
            assert "absorbed" in a["why"]
            continue
        truth = nominal.joints[j].sign * (x[ch.index(key)] - nominal.joints[j].theta) * scale
        assert abs(a["delta"] - truth) <= 3 * a["sigma"] + 1e-9, key
    code, stdout, _ = run(capsys, "identify", csv, "--robot", "kuka_kr16", "--offsets-for", vendor)
    assert code == 0 and ("$MAMES[i]" in stdout if vendor == "kuka" else "no MOC.cfg line" in stdout)
    code, _, stderr = run(capsys, "identify", csv, "--offsets-for", vendor)
    assert code == 2 and "--offsets-for needs --robot" in stderr


def test_identify_names_an_unknown_column_in_a_warning(kr16_truth, tmp_path, capsys):
    _, path = tracker_csv(kr16_truth, tmp_path, 30)
    lines = path.read_text().splitlines()
    good = [lines[0] + ",note"] + [f"{line},ok" for line in lines[1:]]
    path.write_text("\n".join(good) + "\n")
    code, _, err = run(capsys, "identify", path, "--robot", "kuka_kr16", "--json")
    assert code == 0 and "warning" not in err  # every column is known (note: a note column)
    head = lines[0].split(",")
    head[head.index("z1")] = "zl"  # a misspelt target column is ignored: its target lacks z
    typo = [",".join(head) + ",temp"] + [f"{line},20.5" for line in lines[1:]]
    path.write_text("\n".join(typo) + "\n")
    code, _, err = run(capsys, "identify", path, "--robot", "kuka_kr16", "--json")
    assert code == 2 and "give the measured target as columns x,y,z" in err
    assert "warning: " in err and "'zl'" in err and "'temp'" in err


def test_identify_file_is_the_workflow_of_the_command(kr16_truth, tmp_path):
    # The library call behind `robotcell identify`: identification, cross-validation, offsets and
    # the model file in one call, with messages that name its parameters.
    from robotcell.errors import InputError
    from robotcell.studies.identify import identify_file

    nominal, ch, x, _ = kr16_truth
    _, csv = tracker_csv(kr16_truth, tmp_path, 40)
    out = tmp_path / "arm.yaml"
    run_ = identify_file(csv, "kuka_kr16", sigma=0.02e-3, folds=4, offsets_for="kuka",
                         output=out)
    assert run_.written and out.exists() and run_.folds == 4
    assert run_.cross_stats["after_rms_mm"] < 0.06 < run_.cross_stats["before_rms_mm"]
    # the A2 zero against the truth it was simulated with (deg)
    a2 = run_.offsets["axes"][1]
    truth = math.degrees(nominal.joints[1].sign * (x[ch.index("A2.theta")] - nominal.joints[1].theta))
    assert a2["unit"] == "deg" and abs(a2["delta"] - truth) <= 3 * a2["sigma"] + 1e-9
    assert run_.to_json()["cross_validation"]["folds"] == 4
    with pytest.raises(InputError, match="offsets_for needs robot") as exc:
        identify_file(csv, offsets_for="abb")
    assert "--" not in str(exc.value)
    with pytest.raises(InputError, match="cell needs output"):
        identify_file(csv, cell=tmp_path / "cell.yaml")


def test_identify_accuracy_is_an_alias_of_sigma(kr16_truth, tmp_path, capsys):
    nominal, ch, x, rng = kr16_truth
    csv = tmp_path / "tracker.csv"
    write_csv(csv, measure(ch, x, configurations(nominal, 30, rng), rng, NOISE))
    outs = []
    for names in (("--sigma", "--angle-sigma"), ("--accuracy", "--angle-accuracy")):
        code, stdout, stderr = run(capsys, "identify", csv, "--robot", "kuka_kr16", "--json",
                                   "--folds", "0", names[0], "0.02", names[1], "0.01")
        assert code == 0, stderr
        outs.append(json.loads(stdout))
    assert outs[0] == outs[1]
    assert outs[0]["rms_after_mm"] < 0.06
    code, default, stderr = run(capsys, "identify", csv, "--robot", "kuka_kr16", "--json",
                                "--folds", "0")
    assert code == 0, stderr
    assert json.loads(default) != outs[0]  # the stated accuracy reaches the fit


def test_identify_help_says_accuracy_is_an_alias(capsys):
    code, stdout, _ = run(capsys, "identify", "--help")
    assert code == 0
    text = " ".join(stdout.split())
    assert "--sigma, --accuracy FLOAT" in text and "--accuracy is an alias" in text
    assert "--angle-sigma, --angle-accuracy FLOAT" in text and "--angle-accuracy is an alias" in text
