"""Rows grouped by what the joint values resolve: read-back jitter groups as the commanded grid.

Controllers read joint and axis values back within 0.01-0.1 deg of the commanded value. The
circle point analysis (identification without a nominal model, the positioner without a cell),
the turntable's and the track's distinct values and the identification's distinct configurations
group the rows by :mod:`robotcell.calibration.grouping`: a tolerance derived from the data, or
stated (``--group-tolerance``).
"""

import math

import numpy as np
import pytest
from cli_helpers import run
from identification_helpers import perturbed, write_csv

from robotcell import load_robot
from robotcell.calibration.grouping import (
    EXACT,
    alone_groups,
    distinct,
    groups,
    joint_tolerances,
    resolution,
)
from robotcell.calibration.track import calibrate_track
from robotcell.calibration.turntable import calibrate_turntable
from robotcell.errors import IllPosedError, InputError
from robotcell.identification import TargetMeasurements, identify
from robotcell.identification.chain import Chain
from robotcell.identification.circles import start_model
from robotcell.identification.positioner import calibrate_positioner
from robotcell.kinematics.transforms import make_pose, rot_y, rot_z
from robotcell.robot.robot import Joint, Robot

JITTER = math.radians(0.05)  # 1-sigma of a read-back value around the commanded one
NOISE = 0.05e-3
#: A 13 x 16 grid of tilt and rotate values (rad), as measured on a real positioner.
GRID = np.radians([[t, r] for t in np.linspace(-60, 60, 13) for r in np.arange(16) * 22.5])
POSITIONER = Robot(
    name="positioner", convention="standard",
    joints=(Joint("revolute", alpha=-math.pi / 2, name="tilt"),
            Joint("revolute", d=0.25, name="rotate")),
    base=make_pose(rot_y(math.pi / 2), [0.0, 0.0, 0.0]),
)


# -- the grouping itself --------------------------------------------------------------------------
def test_a_jittered_grid_groups_as_the_commanded_values():
    rng = np.random.default_rng(1)
    read = GRID + rng.normal(0.0, JITTER, GRID.shape)
    # each axis alone: 13 tilt and 16 rotate values; together every row is its own configuration
    assert distinct(read[:, 0]) == 13 and distinct(read[:, 1]) == 16
    assert distinct(read) == len(GRID)
    tol = resolution(read[:, 0])[0]
    assert 0.2 < math.degrees(tol) < 10.0  # between the jitter and the 10 deg step
    labels = groups(read[:, 0])
    assert np.array_equal(labels, groups(GRID[:, 0]))
    assert [len(g) for g in alone_groups(read, 0, least=3, span=math.radians(10))] == [13] * 16
    assert [len(g) for g in alone_groups(read, 1, least=3, span=math.radians(10))] == [16] * 13


def test_values_equal_to_rounding_and_random_values_are_not_merged():
    assert resolution(GRID[:, 0])[0] < 1e-3  # exact repeats: a tolerance far below the step
    assert distinct(GRID[:, 0]) == 13
    for seed in range(5):  # random configurations show no jump: each is its own
        q = np.random.default_rng(seed).uniform(-3.0, 3.0, (40, 6))
        assert resolution(q).tolist() == [EXACT] * 6 and distinct(q) == 40


def test_a_stated_tolerance_is_used_as_given():
    read = GRID + np.random.default_rng(2).normal(0.0, JITTER, GRID.shape)
    assert distinct(read[:, 0], math.radians(1.0)) == 13
    assert distinct(read[:, 0], math.radians(1e-4)) > 100  # finer than the jitter: no groups
    assert distinct(read[:, 0], math.radians(15.0)) == 1  # coarser than the step: one group
    # one number is an angle; a prismatic joint takes as many mm as that is deg
    assert np.allclose(joint_tolerances(math.radians(0.5), [False, True]),
                       [math.radians(0.5), 0.5e-3])
    with pytest.raises(InputError, match="grouping tolerance must be a number >= 0"):
        groups(read, [-1.0, 1.0])
    with pytest.raises(InputError, match="NaN or infinite"):
        groups([0.0, np.nan])


# -- the positioner: identify and calibrate positioner without a nominal ----------------------------
def _positioner_touches(q, seed=3):
    """Touches of one point on a perturbed positioner at axis values ``q`` (rad), in R (m)."""
    rng = np.random.default_rng(seed)
    root = make_pose(rot_z(math.radians(20.0)) @ rot_y(math.pi / 2), [1.5, 0.3, 0.7])
    ch = Chain(perturbed(POSITIONER, rng), 1, False, root, np.eye(4))
    x = ch.values.copy()
    x[ch.target_params[0]] = [0.3, 0.05, 0.0]
    noise = np.random.default_rng(seed + 100).normal(0.0, NOISE, (len(q), 3))
    return ch, x, ch.predict(x, q)[0][:, 0] + noise


def _held_out_rms(robot_fk, ch, x):
    test = np.radians(np.random.default_rng(99).uniform([-60, -180], [60, 180], (200, 2)))
    return math.sqrt(np.mean(np.sum((robot_fk(test) - ch.predict(x, test)[0][:, 0]) ** 2, axis=1)))


def test_positioner_with_read_back_jitter_calibrates_as_well_as_the_commanded_grid():
    rng = np.random.default_rng(4)
    read = GRID + rng.normal(0.0, JITTER, GRID.shape)  # the axes stood where they read back
    errors = []
    for q in (GRID, read):
        ch, x, f = _positioner_touches(q)
        cal = calibrate_positioner(q, f, sigma=NOISE)
        errors.append(_held_out_rms(lambda t, c=cal: c.robot.fk(t)[:, :3, 3], ch, x))
    # measured: 0.0122 mm both; the unjittered grid is the reference
    assert errors[1] < 1.1 * errors[0] + 1e-6, errors
    assert errors[1] < 0.5 * NOISE
    # a stated tolerance finer than the jitter finds no touches moving one axis alone
    with pytest.raises(IllPosedError, match=r"joint 1: no rows move it alone.*\(stated\)"):
        calibrate_positioner(read, f, sigma=NOISE, group_tol=math.radians(1e-5))


def _touches_csv(path, q, f):
    rows = np.column_stack([f * 1e3, np.degrees(q)])
    np.savetxt(path, rows, delimiter=",", fmt="%.6f", header="x,y,z,e1,e2", comments="")


def test_calibrate_positioner_and_identify_take_read_back_values(tmp_path, capsys):
    rng = np.random.default_rng(5)
    read = GRID + rng.normal(0.0, JITTER, GRID.shape)
    _, _, f = _positioner_touches(read)
    _touches_csv(tmp_path / "touches.csv", read, f)
    code, out, err = run(capsys, "calibrate", "positioner", tmp_path / "touches.csv",
                         "--sigma", "0.05")
    assert code == 0, err
    assert "calibration: positioner-2axis" in out
    code, _, err = run(capsys, "calibrate", "positioner", tmp_path / "touches.csv",
                       "--group-tolerance", "0.00001")
    assert code == 2 and "no 3 touches turn e1 (tilt) alone" in err and "1e-05 deg" in err
    # the same rows as an identification of a 2-joint chain without a nominal model
    write_csv(tmp_path / "grid.csv", TargetMeasurements(read, f))
    code, out, err = run(capsys, "identify", tmp_path / "grid.csv", "--accuracy", "0.05",
                         "--folds", "3", "-o", tmp_path / "positioner.yaml")
    assert code == 0, err
    arm = load_robot(tmp_path / "positioner.yaml")
    assert arm.n_joints == 2
    code, _, err = run(capsys, "identify", tmp_path / "grid.csv", "--group-tolerance", "0.00001")
    assert code == 2 and "joint 1: no rows move it alone" in err
    assert "(stated)" in err and "--group-tolerance" in err


def test_identification_of_the_positioner_with_jitter_reaches_the_noise():
    rng = np.random.default_rng(6)
    read = GRID + rng.normal(0.0, JITTER, GRID.shape)
    _, _, f = _positioner_touches(read)
    meas = TargetMeasurements(read, f)
    start = start_model(meas, np.zeros(2, dtype=bool))
    res = identify(start, meas, sigma=NOISE)
    assert res.rms_after < 1.2 * math.sqrt(3) * NOISE
    assert res.verdict[0] in ("good", "check")


# -- circle point analysis of a 6-axis arm on jittered rows -----------------------------------------
def test_circle_point_analysis_of_an_arm_on_jittered_sweeps():
    rng = np.random.default_rng(7)
    nominal = load_robot("kuka_kr16")
    start = np.radians([0, -90, 90, 0, 45, 0])
    sweeps = [start + np.outer(np.radians(np.linspace(-30, 30, 7)), np.eye(6)[i])
              for i in range(6)]
    commanded = np.vstack([*sweeps, start + rng.uniform(-0.5, 0.5, (30, 6))])
    read = commanded + rng.normal(0.0, JITTER, commanded.shape)
    T_D_R = make_pose(rot_z(0.3), [2.0, 0.5, 0.0])
    truth = perturbed(nominal, rng)
    reflector = np.array([0.05, 0.02, 0.1, 1.0])
    pts = (T_D_R @ truth.fk(read) @ reflector)[:, :3] + rng.normal(0.0, 2e-5, (len(read), 3))
    meas = TargetMeasurements(read, pts)
    model = start_model(meas)
    res = identify(model, meas, sigma=2e-5)
    assert res.rms_after < 1.5 * math.sqrt(3) * 2e-5
    assert res.verdict[0] in ("good", "check")
    with pytest.raises(IllPosedError, match=r"joint 1: no rows move it alone.*within 1e-05 deg"):
        start_model(meas, group_tol=math.radians(1e-5))


# -- turntable, track and the identification's distinct configurations ------------------------------
def test_turntable_and_track_count_read_back_values_as_commanded():
    rng = np.random.default_rng(8)
    f = rng.normal(0.0, 1.0, (6, 3))  # the check comes before any fit
    two = np.radians([0.0, 0.03, -0.02, 180.0, 180.04, 179.97])
    with pytest.raises(IllPosedError, match="only 2 distinct table angle"):
        calibrate_turntable(two, f)
    theta = np.radians([0.0, 90.0, 180.0, 270.0]) + rng.normal(0.0, JITTER, 4)
    touched = np.column_stack([0.3 * np.cos(theta), 0.3 * np.sin(theta), np.zeros(4)])
    touched += rng.normal(0.0, NOISE, touched.shape)
    assert calibrate_turntable(theta, touched, sigma=NOISE).values["radius"] == \
        pytest.approx(0.3, abs=1e-3)
    e = 1.0 + rng.normal(0.0, 0.01e-3, 5)  # one track position, read back within 0.01 mm
    with pytest.raises(IllPosedError, match=r"all 5 touches are at the same track position "
                                            r"\(\d+\.\d+ mm, read back within 0\.0\d\d mm\)"):
        calibrate_track(e, rng.normal(0.0, 1.0, (5, 3)))


def test_jittered_repeats_of_a_configuration_count_once_for_the_redundancy():
    rng = np.random.default_rng(9)
    nominal = load_robot("kuka_kr16")
    q = np.repeat(rng.uniform(-1.0, 1.0, (8, 6)), 5, axis=0)
    q += rng.normal(0.0, JITTER, q.shape)
    pts = (nominal.fk(q) @ np.array([0.05, 0.02, 0.1, 1.0]))[:, :3]
    with pytest.raises(IllPosedError, match=r"40 rows in 8 distinct configuration\(s\)"):
        identify(nominal, TargetMeasurements(q, pts))


def test_turntable_and_track_commands_take_a_stated_tolerance(tmp_path, capsys):
    # table angles 0, 2, 4, 180, 182 deg: five angles as read, two at a stated 5 deg
    rng = np.random.default_rng(10)
    theta = np.radians([0.0, 2.0, 4.0, 180.0, 182.0])
    touched = np.column_stack([1.2 + 0.3 * np.cos(theta), 0.3 * np.sin(theta),
                               np.full(5, 0.4)]) + rng.normal(0.0, NOISE, (5, 3))
    rows = np.column_stack([touched * 1e3, np.degrees(theta)])
    np.savetxt(tmp_path / "table.csv", rows, delimiter=",", fmt="%.6f", header="x,y,z,e1",
               comments="")
    code, _, err = run(capsys, "calibrate", "turntable", tmp_path / "table.csv", "--sigma",
                       "0.05")
    assert "distinct table angle" not in err
    code, _, err = run(capsys, "calibrate", "turntable", tmp_path / "table.csv",
                       "--group-tolerance", "5")
    assert code == 2 and "only 2 distinct table angle(s)" in err
    # track positions 3 mm apart: three positions as read, one at a stated 5 mm
    e = np.array([1000.0, 1003.0, 1006.0])
    touched = np.array([1.5, 0.2, 0.3]) - np.outer(e * 1e-3, [1.0, 0.0, 0.0])
    rows = np.column_stack([touched * 1e3, e])
    np.savetxt(tmp_path / "track.csv", rows, delimiter=",", fmt="%.6f", header="x,y,z,e1",
               comments="")
    code, _, err = run(capsys, "calibrate", "track", tmp_path / "track.csv")
    assert "same track position" not in err
    code, _, err = run(capsys, "calibrate", "track", tmp_path / "track.csv",
                       "--group-tolerance", "5")
    assert code == 2 and "all 3 touches are at the same track position" in err
    code, _, err = run(capsys, "calibrate", "track", tmp_path / "track.csv",
                       "--group-tolerance", "50")
    assert code == 2 and "--group-tolerance must be from 1e-06 to 5 mm" in err
