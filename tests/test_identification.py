"""Kinematic identification: Jacobian, synthetic arms and a positioner, model file, IK, errors."""

import math

import numpy as np
import pytest
from identification_helpers import configurations, measure, perturbed, truth_chain
from scipy.spatial.transform import Rotation

from robotcell import load_robot, save_robot
from robotcell.dhprocedure import convert_convention
from robotcell.errors import IllPosedError, InputError
from robotcell.identification import TargetMeasurements, identify
from robotcell.identification.chain import Chain
from robotcell.identification.ik import solve_identified
from robotcell.kinematics.transforms import make_pose, rot_y
from robotcell.robot.robot import Joint, Robot

NOISE = 0.02e-3


@pytest.mark.parametrize("name,convention", [("kuka_kr16", "standard"), ("ur5e", "modified")])
def test_analytic_jacobian_matches_central_differences(name, convention):
    robot = load_robot(name)
    if convention == "modified":
        robot = convert_convention(robot, "modified")
    rng = np.random.default_rng(3)
    for pose in (False, True):
        ch = Chain(robot, 0 if pose else 2, pose, make_pose(Rotation.random(random_state=1).as_matrix(),
                                                            [1.0, 2.0, 0.5]), np.eye(4))
        x = ch.values + rng.normal(0.0, 0.01, len(ch.values))
        q = rng.uniform(-2, 2, (4, robot.n_joints))
        ev = ch.evaluate(x, q)
        pts, _ = ch.predict(x, q)
        J, W = ch.point_jacobian(x, q, ev, pts), ch.rotation_jacobian(x, q, ev)
        h = 1e-6
        for k in range(len(x)):
            xp, xm = x.copy(), x.copy()
            xp[k] += h
            xm[k] -= h
            (pp, Rp), (pm, Rm) = ch.predict(xp, q), ch.predict(xm, q)
            assert np.allclose(J[..., k], (pp - pm) / (2 * h), atol=1e-8), ch.names[k]
            w = Rotation.from_matrix(Rp @ np.swapaxes(Rm, 1, 2)).as_rotvec() / (2 * h)
            assert np.allclose(W[..., k], w, atol=1e-8), ch.names[k]


def _prediction_rms(res, ch, x, q):
    return float(np.sqrt(np.mean(np.sum((res.predict(q)[0] - ch.predict(x, q)[0]) ** 2, axis=-1))))


@pytest.mark.parametrize("name", ["kuka_kr16", "abb_irb2400"])
def test_synthetic_arm_identified_to_the_noise_floor(name):
    rng = np.random.default_rng(11)
    nominal = load_robot(name)
    truth = perturbed(nominal, rng)
    ch, x = truth_chain(truth, 3, False, rng)
    res = identify(nominal, measure(ch, x, configurations(nominal, 50, rng), rng, NOISE),
                   sigma=NOISE)
    # 500 other configurations, measured with the same noise: the identified model's error is
    # at most 1.5x the noise floor (RMS length of a 3-D noise vector), the nominal's 100x that.
    qv = configurations(nominal, 500, rng)
    noisy = measure(ch, x, qv, rng, NOISE).points
    floor = NOISE * math.sqrt(3.0)
    err = res.predict(qv)[0] - noisy
    rms = math.sqrt(np.mean(np.sum(err**2, axis=-1)))
    assert rms <= 1.5 * floor
    # Nominal links with the best base and reflectors: error against the noise-free truth.
    before = identify(nominal, measure(ch, x, qv[:60], rng, NOISE), sigma=NOISE).rms_before
    assert before >= 100 * _prediction_rms(res, ch, x, qv)
    assert res.rms_before > 50 * res.rms_after
    assert res.verdict[0] == "good"
    fixed = dict(res.fixed)
    first, last = nominal.joints[0].name, nominal.joints[-1].name
    for key in ("d", "theta"):  # the base pose absorbs where joint 1 sits along and about its axis
        assert "base" in fixed[f"{first}.{key}"]
    for key in ("d", "theta", "a", "alpha"):  # the reflectors absorb the last link
        assert "target" in fixed[f"{last}.{key}"]
    # One of the d's of the parallel pair A2/A3 (Hayati: the common normal is free there).
    assert sum(f"{j.name}.d" in fixed for j in nominal.joints[1:3]) == 1
    # Parameters recovered within 3 reported sigma of the truth expressed in the same
    # parameterisation (the noise-free identification of the truth from 400 configurations).
    exact = identify(nominal, measure(ch, x, configurations(nominal, 400, rng), rng, 0.0),
                     sigma=NOISE)
    assert exact.rms_after < 1e-9
    assert exact.free == res.free
    for p in res.parameters:
        if p.free and not p.name.startswith("base."):  # base constants are relative to a start
            assert abs(p.value - exact.parameter(p.name).value) <= 3 * p.sigma, p.name
    assert np.allclose(res.base[:3, 3], exact.base[:3, 3], atol=0.1e-3)
    assert np.allclose(res.base[:3, :3], exact.base[:3, :3], atol=1e-5)


def test_positioner_with_pose_measurements():
    # A tilt-rotate positioner: tilt about the horizontal X axis of R, then the table's rotation;
    # a camera sees a target on the table (position and orientation).
    nominal = Robot(
        name="positioner", convention="standard",
        joints=(Joint("revolute", a=0.0, alpha=-math.pi / 2, d=0.0, name="tilt",
                      lower=-math.radians(100), upper=math.radians(100)),
                Joint("revolute", a=0.0, alpha=0.0, d=0.25, name="rotate")),
        base=make_pose(rot_y(math.pi / 2), [0.0, 0.0, 0.8]),
    )
    rng = np.random.default_rng(5)
    truth = perturbed(nominal, rng)
    ch, x = truth_chain(truth, 1, True, rng)
    angle_noise = math.radians(0.01)
    meas = measure(ch, x, configurations(nominal, 50, rng), rng, NOISE, angle_noise)
    res = identify(nominal, meas, sigma=NOISE, angle_sigma=angle_noise)
    qv = configurations(nominal, 500, rng)
    noisy = measure(ch, x, qv, rng, NOISE, angle_noise)
    rms = math.sqrt(np.mean(np.sum((res.predict(qv)[0] - noisy.points) ** 2, axis=-1)))
    assert rms <= 1.5 * NOISE * math.sqrt(3.0)
    # Only the distance and angle between the axes are not absorbed by the base and the target:
    # the nominal model is about 18x worse here (0.12 mm against 0.0065 mm), not 100x.
    assert res.rms_before >= 10 * _prediction_rms(res, ch, x, qv)
    assert res.to_json()["rotation_rms_before_deg"] > 5 * res.to_json()["rotation_rms_after_deg"]
    # Distance and angle between the two axes are what a positioner's kinematics can show.
    assert res.free == sorted(res.free, key=res.free.index)
    assert {p.name for p in res.parameters if p.free and p.name.startswith(("tilt", "rotate"))} == {
        "tilt.a", "tilt.alpha"}
    exact = identify(nominal, measure(ch, x, configurations(nominal, 300, rng), rng, 0.0, 0.0),
                     sigma=NOISE, angle_sigma=angle_noise)
    for p in res.parameters:
        if p.free and not p.name.startswith(("base.", "target.")):
            assert abs(p.value - exact.parameter(p.name).value) <= 3 * p.sigma, p.name
    # The identified robot with the target as its tool predicts the measured target pose.
    T = res.base @ res.robot.fk(qv[:5], tool=res.target_tool)
    assert np.allclose(T[:, :3, 3], ch.predict(x, qv[:5])[0][:, 0], atol=2e-4)
    assert res.to_json()["target"][3] == [0.0, 0.0, 0.0, 1.0]


@pytest.fixture(scope="module")
def kr16_result():
    rng = np.random.default_rng(2)
    nominal = load_robot("kuka_kr16")
    ch, x = truth_chain(perturbed(nominal, rng), 2, False, rng)
    meas = measure(ch, x, configurations(nominal, 40, rng), rng, NOISE)
    return nominal, ch, x, meas, identify(nominal, meas, sigma=NOISE)


def test_model_file_round_trip_predicts_the_measurements(kr16_result, tmp_path):
    nominal, _, _, meas, res = kr16_result
    path = tmp_path / "identified.yaml"
    save_robot(res.robot, path)
    robot = load_robot(path)
    q = meas.q[:10]
    # Same joint values as the CSV; reflector 1 as the tool; base maps R into the tracker frame.
    p = (res.base @ robot.fk(q, tool=res.target_tool))[:, :3, 3]
    assert np.allclose(p, res.predict(q)[0][:, 0], atol=1e-7)
    assert robot.convention == nominal.convention
    assert [j.sign for j in robot.joints] == [j.sign for j in nominal.joints]


def test_identified_ik_converges_from_nominal_seeds(kr16_result):
    nominal, _, _, meas, res = kr16_result
    T = res.robot.fk(meas.q[:8])
    sol = solve_identified(res.robot, nominal, T)
    assert np.all(sol.valid.any(axis=-1))
    reached = res.robot.fk(np.where(sol.valid[..., None], sol.q, 0.0))
    err = np.linalg.norm(reached[..., :3, 3] - T[:, None, :3, 3], axis=-1)
    assert err[sol.valid].max() < 1e-9
    # The branch of the measured configuration is among them (modulo full turns of A4, A6).
    diff = np.angle(np.exp(1j * (sol.q - meas.q[:8, None, :])))
    d = np.where(sol.valid, np.abs(diff).max(axis=-1), np.inf)
    assert np.all(d.min(axis=-1) < 1e-6)


def test_outlier_row_is_flagged():
    rng = np.random.default_rng(4)
    nominal = load_robot("kuka_kr16")
    ch, x = truth_chain(perturbed(nominal, rng), 1, False, rng)
    meas = measure(ch, x, configurations(nominal, 40, rng), rng, NOISE)
    pts = meas.points.copy()
    pts[17, 0, 2] += 0.5e-3
    res = identify(nominal, TargetMeasurements(meas.q, pts), sigma=NOISE)
    assert res.outliers == [17]
    assert res.verdict[0] == "check"
    assert "outlier" in res.summary()


def test_coupling_and_scale_are_identified():
    # A parallel arm (as the IRB 2400): the controller's axis 3 is the forearm angle,
    # q3_model = J3 - J2 (FANUC's linkage is +1: docs/robots.md).
    rng = np.random.default_rng(8)
    nominal = load_robot("kuka_kr16")
    scale = np.array([0.0, 2e-4, -3e-4, 0.0, 0.0, 0.0])
    ch, x = truth_chain(perturbed(nominal, rng), 3, False, rng, coupling=-1.0, scale=scale)
    meas = measure(ch, x, configurations(nominal, 60, rng), rng, NOISE)
    wrong = identify(nominal, meas, sigma=NOISE)
    assert wrong.verdict[0] == "poor"
    res = identify(nominal, meas, sigma=NOISE, j23_factor=-1.0, fit_j23_factor=True, scale=True)
    k = res.parameter("j23_factor")
    assert abs(k.value + 1.0) <= 3 * k.sigma
    for j, s in zip(("A2", "A3"), scale[1:3]):
        p = res.parameter(f"{j}.scale")
        assert p.free and abs(p.value - s) <= 3 * p.sigma
    assert res.rms_after < 2 * NOISE * math.sqrt(3)
    assert np.allclose(res.model_joints(meas.q[:3])[:, 2], (meas.q[:3, 2] + k.value * meas.q[:3, 1])
                       * (1 + res.scale[2]))


def test_scale_and_coupling_round_trip_through_the_model_file(tmp_path):
    # Truth: q3_model = (1 + s3)(J3 - J2), qm2 = (1 + s2) J2. The model file's coupling key holds
    # C = diag(1 + s) with C[2, 1] = k (1 + s3), so its FK takes the CSV's controller values.
    rng = np.random.default_rng(8)
    nominal = load_robot("kuka_kr16")
    scale = np.array([0.0, 2e-4, -3e-4, 0.0, 0.0, 0.0])
    ch, x = truth_chain(perturbed(nominal, rng), 3, False, rng, coupling=-1.0, scale=scale)
    meas = measure(ch, x, configurations(nominal, 60, rng), rng, NOISE)
    res = identify(nominal, meas, sigma=NOISE, j23_factor=-1.0, fit_j23_factor=True, scale=True)
    C = res.robot.coupling.matrix
    assert np.allclose(np.diag(C), 1.0 + res.scale)
    assert C[2, 1] == pytest.approx(res.j23_factor * (1.0 + res.scale[2]))
    path = tmp_path / "identified.yaml"
    save_robot(res.robot, path)
    assert "coupling:" in path.read_text() and "matrix:" in path.read_text()
    robot = load_robot(path)
    q = configurations(nominal, 20, rng)
    pred = (res.base @ robot.fk(q, tool=res.target_tool))[:, :3, 3]  # controller values, as in the CSV
    assert np.allclose(pred, res.predict(q)[0][:, 0], atol=1e-7)
    assert np.allclose(pred, ch.predict(x, q)[0][:, 0], atol=5 * NOISE)
    T = robot.fk(q[:4])
    sol = robot.ik(T)  # the seeded IK honours the coupling
    back = robot.fk(np.where(sol.reachable[..., None], sol.q, 0.0))
    assert np.abs(back - T[:, None])[sol.reachable].max() < 1e-9
    # A full turn is no longer exactly 2 pi with a scale error: equal up to 2 pi * scale.
    d = np.where(sol.valid, np.abs(np.angle(np.exp(1j * (sol.q - q[:4, None])))).max(axis=-1), np.inf)
    assert np.all(d.min(axis=-1) < 1e-4)


def test_nominal_j23_coupling_is_used_and_kept():
    # FANUC M-20iA: its library model states coupling {j23_factor: 1}; identify uses it without
    # --j23-factor, and the identified model keeps it as j23_factor.
    rng = np.random.default_rng(12)
    nominal = load_robot("fanuc_m20ia")
    ch, x = truth_chain(perturbed(nominal, rng), 2, False, rng, coupling=1.0)
    meas = measure(ch, x, configurations(nominal, 40, rng), rng, NOISE)
    res = identify(nominal, meas, sigma=NOISE)
    assert res.rms_after < 2 * NOISE * math.sqrt(3)
    assert res.robot.coupling.j23_factor == 1.0
    q = configurations(nominal, 5, rng)
    assert np.allclose((res.base @ res.robot.fk(q, tool=res.target_tool))[:, :3, 3],
                       res.predict(q)[0][:, 0], atol=1e-7)


def test_nominal_with_passive_joints_is_refused():
    nominal = load_robot("abb_irb460")
    with pytest.raises(InputError, match="only 'coupling: {j23_factor: k}'"):
        identify(nominal, TargetMeasurements(np.zeros((30, 4)), np.zeros((30, 3))))


def test_refused_input():
    nominal = load_robot("kuka_kr16")
    q = np.zeros((5, 6))
    with pytest.raises(InputError, match="6 joints"):
        identify(nominal, TargetMeasurements(np.zeros((5, 5)), np.zeros((5, 3))))
    with pytest.raises(InputError, match="sigma must be a positive number"):
        identify(nominal, TargetMeasurements(q, np.zeros((5, 3))), sigma=0.0)
    with pytest.raises(InputError, match=r"max_sigma_angle must be a positive number \(math.inf"):
        identify(nominal, TargetMeasurements(q, np.zeros((5, 3))), max_sigma_angle=0.0)
    with pytest.raises(IllPosedError, match="measure at least"):
        rng = np.random.default_rng(0)
        identify(nominal, TargetMeasurements(rng.uniform(-1, 1, (5, 6)), rng.uniform(-1, 1, (5, 3))))
    with pytest.raises(InputError, match="shape"):
        TargetMeasurements(q, np.zeros((4, 3)))
    with pytest.raises(InputError, match="not a proper rotation"):
        TargetMeasurements(q, np.zeros((5, 3)), np.tile(np.diag([1.0, 1.0, -1.0]), (5, 1, 1)))


def test_modified_dh_nominal_with_hayati_beta(tmp_path):
    nominal = convert_convention(load_robot("kuka_kr16"), "modified")
    rng = np.random.default_rng(6)
    ch, x = truth_chain(perturbed(nominal, rng), 2, False, rng)
    assert ch.beta_joints == [2]  # A3: its axis parallel to A2's, Craig's row 3
    meas = measure(ch, x, configurations(nominal, 40, rng), rng, NOISE)
    res = identify(nominal, meas, sigma=NOISE)
    assert res.parameter("A3.beta").free
    qv = configurations(nominal, 200, rng)
    assert _prediction_rms(res, ch, x, qv) < NOISE
    save_robot(res.robot, tmp_path / "m.yaml")
    robot = load_robot(tmp_path / "m.yaml")
    assert robot.convention == "modified"
    assert np.allclose((res.base @ robot.fk(qv, tool=res.target_tool))[:, :3, 3],
                       res.predict(qv)[0][:, 0], atol=1e-7)


def test_reported_sigma_matches_the_errors_over_seeds():
    # Over 4 seeded arms (about 100 free link and target constants), (estimate - truth) / sigma
    # has a standard deviation within 25 % of 1, and the same parameters are fixed every time.
    z, fixed_sets = [], set()
    nominal = load_robot("kuka_kr16")
    for seed in range(4):
        rng = np.random.default_rng(100 + seed)
        ch, x = truth_chain(perturbed(nominal, rng), 3, False, rng)
        res = identify(nominal, measure(ch, x, configurations(nominal, 50, rng), rng, NOISE),
                       sigma=NOISE)
        exact = identify(nominal, measure(ch, x, configurations(nominal, 400, rng), rng, 0.0),
                         sigma=NOISE)
        z += [(p.value - exact.parameter(p.name).value) / p.sigma for p in res.parameters
              if p.free and not p.name.startswith("base.")]
        fixed_sets.add(tuple(n for n, _ in res.fixed))
        fixed_sets.add(tuple(n for n, _ in exact.fixed))
    assert len(fixed_sets) == 1
    assert 0.75 <= np.std(z) <= 1.25


def test_identified_model_file_ik_is_seeded_by_its_nominal(kr16_result, tmp_path):
    nominal, _, _, meas, res = kr16_result
    path = tmp_path / "identified.yaml"
    save_robot(res.robot, path)
    assert "ik_seed: kuka_kr16" in path.read_text()
    robot = load_robot(path)
    assert robot.ik_seed is not None and robot.ik_seed.name == "kuka_kr16"
    q = meas.q[:12]
    T = robot.fk(q)
    sol = robot.ik(T)  # FK -> IK -> FK on the identified model: all branches, fixed shape
    assert sol.q.shape == (12, 8, 6) and sol.method == "opw"
    assert np.all(sol.valid.any(axis=-1))
    back = robot.fk(np.where(sol.reachable[..., None], sol.q, 0.0))
    err = np.linalg.norm(back[..., :3, 3] - T[:, None, :3, 3], axis=-1)
    assert err[sol.reachable].max() < 1e-9
    assert np.all(np.isnan(sol.q[~sol.reachable]))
    diff = np.angle(np.exp(1j * (sol.q - q[:, None, :])))
    assert np.all(np.where(sol.valid, np.abs(diff).max(axis=-1), np.inf).min(axis=-1) < 1e-6)
    # The rest of the IK code keeps working: nearest branch and configuration flags.
    from robotcell.ik import kuka_status_turn, nearest
    best, found, _ = nearest(robot, sol, q)
    assert np.all(found) and np.allclose(np.angle(np.exp(1j * (best - q))), 0.0, atol=1e-6)
    status, _ = kuka_status_turn(robot, best)
    assert np.array_equal(status, kuka_status_turn(nominal, q)[0])
    # A new base moves the seed with the chain.
    B = make_pose(rot_y(0.3), [0.5, 0.0, 1.0])
    moved = robot.with_base(B @ robot.base)
    sol2 = moved.ik(B @ T[:3])
    assert np.allclose(np.nan_to_num(sol2.q), np.nan_to_num(sol.q[:3]), atol=1e-7)


def test_model_without_closed_form_or_seed_is_refused(kr16_result):
    _, _, _, _, res = kr16_result
    from dataclasses import replace
    with pytest.raises(InputError, match="no analytic inverse kinematics.*ik_seed"):
        replace(res.robot, ik_seed=None).ik(np.eye(4))


def test_seeded_ik_at_the_edge_of_the_nominal_workspace():
    # The identified forearm is 1 mm longer: with the arm stretched, the pose is outside the
    # nominal arm's reach, so the nominal has no branch there; the target pulled in by the miss
    # seeds it, and the refinement reaches 1e-9 on the identified model.
    rng = np.random.default_rng(2)
    nominal = load_robot("kuka_kr16")
    ch, x = truth_chain(perturbed(nominal, rng), 2, False, rng)
    x[ch.index("A4.d")] += 1e-3
    robot = identify(nominal, measure(ch, x, configurations(nominal, 40, rng), rng, NOISE),
                     sigma=NOISE).robot
    q3 = np.radians(np.linspace(-10, 10, 2001))
    qs = np.zeros((len(q3), 6))
    qs[:, 1], qs[:, 2], qs[:, 4] = -math.pi / 4, q3, 0.5
    F = robot.frames(qs)
    q = qs[[int(np.argmax(np.linalg.norm(F[:, 4, :3, 3] - F[:, 1, :3, 3], axis=1)))]]  # stretched
    T = robot.fk(q)
    assert not nominal.ik(T, tool=robot.tool).reachable.any()
    sol = robot.ik(T)
    assert sol.valid.any()
    err = np.linalg.norm(robot.fk(sol.q[sol.reachable])[:, :3, 3] - T[0, :3, 3], axis=-1)
    assert err.max() < 1e-9


def test_nominal_that_is_not_a_library_model_is_nested_as_ik_seed(kr16_result, tmp_path):
    from dataclasses import replace
    nominal, _, _, meas, res = kr16_result
    custom = replace(nominal, name="my_kr16")
    robot = replace(res.robot, ik_seed=custom)
    save_robot(robot, tmp_path / "id.yaml")
    text = (tmp_path / "id.yaml").read_text()
    assert "ik_seed:\n  name: my_kr16" in text
    back = load_robot(tmp_path / "id.yaml")
    assert back.ik_seed.name == "my_kr16"
    T = back.fk(meas.q[:3])
    sol = back.ik(T)
    assert sol.valid.any(axis=-1).all()
    (tmp_path / "bad2.yaml").write_text("name: a\njoints:\n  - {type: revolute, a: 0, alpha: 0, d: 0, theta: 0}\nik_seed: nosuch_robot\n")
    with pytest.raises(InputError, match="key 'ik_seed': 'nosuch_robot' is not a library robot"):
        load_robot(tmp_path / "bad2.yaml")


def test_identified_model_in_a_cell_solves_ik(kr16_result, tmp_path):
    from pathlib import Path

    from robotcell.cell import Cell
    _, _, _, meas, res = kr16_result
    save_robot(res.robot, tmp_path / "kr16_identified.yaml")
    example = Path(__file__).resolve().parents[1] / "examples" / "cell_kr16_track_turntable.yaml"
    (tmp_path / "cell.yaml").write_text(example.read_text().replace("model: kuka_kr16",
                                                                     "model: kr16_identified.yaml"))
    cell = Cell.load(tmp_path / "cell.yaml")
    q = meas.q[:3]
    T = cell.fk(q, track=1.5, tool="torch")
    sol = cell.ik(T, track=1.5, tool="torch")
    back = cell.fk(np.where(sol.reachable[..., None], sol.q, 0.0), track=1.5, tool="torch")
    assert sol.valid.any(axis=-1).all()
    assert np.abs(back - T[:, None])[sol.reachable].max() < 1e-9
