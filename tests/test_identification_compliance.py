"""Gravity compliance of axes 2 and 3: torques from link masses, identification, refusals."""

import math
from dataclasses import replace

import numpy as np
import pytest
from cli_helpers import run
from identification_helpers import configurations, measure, perturbed, truth_chain, write_csv

from robotcell import load_robot, save_robot
from robotcell.errors import InputError
from robotcell.identification import TargetMeasurements, identify
from robotcell.identification.chain import Chain
from robotcell.identification.gravity import gravity_torques
from robotcell.kinematics.transforms import make_pose
from robotcell.robot.robot import Joint, Robot

NOISE = 0.02e-3
#: Plausible link masses (kg) and centres of mass (m, link frame) of a 16 kg payload arm.
MASSES = [(80, (0, 0, 0)), (40, (-0.34, 0, 0)), (30, (0, -0.1, 0.02)), (15, (0, 0.3, 0)),
          (5, (0, 0, 0)), (17, (0, 0, 0.1))]


def with_masses(robot: Robot) -> Robot:
    return replace(robot, joints=tuple(replace(j, mass=m, com=c) for j, (m, c) in zip(robot.joints, MASSES)))


def test_gravity_torque_of_a_horizontal_arm():
    # Axis 2 horizontal (alpha1 = 90 deg); links 2 (1 m, 10 kg at its middle) and 3 (0.5 m, 4 kg
    # at its end) stretched out horizontally: tau2 = -g (10 * 0.5 + 4 * 1.5), tau3 = -g 4 * 0.5,
    # about z1 = -Y (a positive joint value lifts the arm, gravity pulls it down).
    g = 9.80665
    robot = Robot("arm", (Joint("revolute", alpha=math.pi / 2), Joint("revolute", a=1.0, mass=10.0, com=(-0.5, 0, 0)),
                          Joint("revolute", a=0.5, mass=4.0)))
    tau = gravity_torques(robot, np.zeros((1, 3)), (1, 2))
    assert np.allclose(tau, [[-g * (10 * 0.5 + 4 * 1.5), -g * 4 * 0.5]])
    # Arm pointing straight up: no torque.
    assert np.allclose(gravity_torques(robot, np.array([[0.0, math.pi / 2, 0.0]]), (1, 2)), 0.0, atol=1e-12)


def test_jacobian_of_the_compliance_matches_central_differences():
    robot = with_masses(load_robot("kuka_kr16"))
    ch = Chain(robot, 2, False, make_pose(None, [1.0, 2.0, 0.5]), np.eye(4))
    rng = np.random.default_rng(3)
    x = ch.values.copy()
    x[ch.compliance_params] = [2e-6, -1e-6]
    q = rng.uniform(-2, 2, (4, 6))
    ev = ch.evaluate(x, q)
    J = ch.point_jacobian(x, q, ev, ch.predict(x, q)[0])
    for k in ch.compliance_params:
        h = 1e-9
        xp, xm = x.copy(), x.copy()
        xp[k] += h
        xm[k] -= h
        fd = (ch.predict(xp, q)[0] - ch.predict(xm, q)[0]) / (2 * h)
        assert np.allclose(J[..., k], fd, rtol=1e-5, atol=1e-6), ch.names[k]


def test_compliance_reaches_the_noise_floor():
    rng = np.random.default_rng(5)
    nominal = with_masses(load_robot("kuka_kr16"))
    ch, x = truth_chain(perturbed(nominal, rng), 2, False, rng)
    truth = [1.5e-6, 3e-6]  # rad per N m: 0.5 to 1 mm at the flange with these masses
    x[ch.compliance_params] = truth
    meas = measure(ch, x, configurations(nominal, 50, rng), rng, NOISE)
    qv = configurations(nominal, 500, rng)
    noisy = measure(ch, x, qv, rng, NOISE).points
    floor = NOISE * math.sqrt(3.0)

    def held_out(res):
        return math.sqrt(np.mean(np.sum((res.predict(qv)[0] - noisy) ** 2, axis=-1)))

    without = identify(nominal, meas, sigma=NOISE)
    assert without.verdict[0] == "poor" and held_out(without) > 10 * floor
    res = identify(nominal, meas, sigma=NOISE, compliance=True)
    assert res.verdict[0] == "good"
    assert held_out(res) <= 1.5 * floor
    for name, value in zip(("A2.compliance", "A3.compliance"), truth):
        p = res.parameter(name)
        assert p.free and abs(p.value - value) <= 3 * p.sigma
        assert p.vendor()[3] == "urad/Nm"
    assert "A3.compliance" in res.summary()


def test_masses_round_trip_and_compliance_refused_without_them(tmp_path, capsys):
    robot = with_masses(load_robot("kuka_kr16"))
    save_robot(robot, tmp_path / "m.yaml")
    back = load_robot(tmp_path / "m.yaml")
    assert [j.mass for j in back.joints] == [m for m, _ in MASSES]
    assert np.allclose([j.com for j in back.joints], [c for _, c in MASSES])
    nominal = load_robot("kuka_kr16")
    with pytest.raises(InputError, match="needs the link masses of kuka_kr16.*'mass' \\(kg\\) and 'com'"):
        identify(nominal, TargetMeasurements(np.zeros((30, 6)), np.zeros((30, 3))), compliance=True)
    rng = np.random.default_rng(1)
    ch, x = truth_chain(nominal, 1, False, rng)
    write_csv(tmp_path / "m.csv", measure(ch, x, configurations(nominal, 30, rng), rng, NOISE))
    code, _, stderr = run(capsys, "identify", tmp_path / "m.csv", "--robot", "kuka_kr16", "--compliance")
    assert code == 2 and "key" in stderr and "'mass'" in stderr
    (tmp_path / "bad.yaml").write_text((tmp_path / "m.yaml").read_text().replace("mass: 40", "mass: -40"))
    with pytest.raises(InputError, match="joint 2: key 'mass' must be >= 0"):
        load_robot(tmp_path / "bad.yaml")


def test_compliance_from_the_command_line(tmp_path, capsys):
    import json
    rng = np.random.default_rng(6)
    nominal = with_masses(load_robot("kuka_kr16"))
    save_robot(nominal, tmp_path / "kr16_masses.yaml")
    ch, x = truth_chain(perturbed(nominal, rng), 2, False, rng)
    x[ch.compliance_params] = [2e-6, 2e-6]
    write_csv(tmp_path / "m.csv", measure(ch, x, configurations(nominal, 50, rng), rng, NOISE))
    code, stdout, stderr = run(capsys, "identify", tmp_path / "m.csv", "--robot", tmp_path / "kr16_masses.yaml",
                               "--compliance", "--accuracy", "0.02", "--json")
    assert code == 0, stderr
    data = json.loads(stdout)
    p = {d["name"]: d for d in data["parameters"]}
    assert p["A2.compliance"]["unit"] == "urad/Nm"
    assert abs(p["A2.compliance"]["value"] - 2.0) <= 3 * p["A2.compliance"]["sigma"]
    assert data["rms_after_mm"] < 0.05
