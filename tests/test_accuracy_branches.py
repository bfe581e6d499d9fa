"""Filtering keeps the configuration the user means (docs/accuracy.md, "The configuration").

A Universal Robots arm has no configuration flags in its controller: a pose is reached on the
branch nearest a reference (URScript ``get_inverse_kin(x, qnear)``). The real UR5 of
examples/identification/jacobi_ur5_grid_poses.csv (MIT licence, see
examples/identification/LICENSE-serial-robots-datasets.txt) was measured in one configuration
(shoulder 1, elbow 0, wrist 0) throughout; the nominal solution nearest the robot's home is
another branch for a quarter of its poses. ``compensate`` keeps the arm's branch from the
columns ``shoulder, elbow, wrist`` or from reference joints ``near_a1..near_a6``.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from accuracy_helpers import CELL, kr16_truth, seam, write_rows
from cli_helpers import run

from robotcell import load_robot, save_robot
from robotcell.accuracy import filter_poses
from robotcell.cell import Cell
from robotcell.identification import identify, read_target_measurements
from robotcell.ik.config import branch_of_flags, flags_of_branch
from robotcell.io.poseformats import pose_to_vendor

DATA = Path(__file__).resolve().parents[1] / "examples" / "identification"
#: The 20 held-out rows filtered (spread over the grid), and the rows identified (every 3rd of
#: the others).
TARGETS = np.arange(1, 334, 17)
TRAIN = np.setdiff1d(np.arange(0, 334, 3), TARGETS)


@pytest.fixture(scope="module")
def ur5(tmp_path_factory):
    """A cell whose arm is the real UR5 as identified from a third of its rows, and 20 held-out
    measured configurations with the poses the arm had there (its identified FK)."""
    d = tmp_path_factory.mktemp("ur5")
    meas = read_target_measurements(DATA / "jacobi_ur5_grid_poses.csv")
    nominal = load_robot(DATA / "ur5_cb3.yaml")
    res = identify(nominal, meas.subset(np.isin(np.arange(meas.n_rows), TRAIN)), sigma=0.1e-3)
    save_robot(res.robot, d / "ur5_identified.yaml")
    (d / "cell.yaml").write_text(f"name: ur5_cell\nrobot:\n  model: {DATA / 'ur5_cb3.yaml'}\n"
                                 "  identified: ur5_identified.yaml\ntools:\n  probe:\n"
                                 "    number: 1\n    frame: {x: 0, y: 0, z: 50, a: 0, b: 0, c: 0}\n")
    cell = Cell.load(d / "cell.yaml")
    q = meas.q[TARGETS]
    desired = cell.fk(q, tool="probe")
    return d, cell, q, pose_to_vendor(desired, "kuka")


def _compensate(capsys, d: Path, head: list[str], rows: np.ndarray) -> dict:
    write_rows(d / "targets.csv", head, rows)
    code, out, err = run(capsys, "compensate", d / "targets.csv", "--cell", d / "cell.yaml",
                         "--tool", "probe", "--json")
    assert code == 0, err
    return json.loads(out)


def _joints(data: dict) -> np.ndarray:
    return np.array([[p[f"a{i}"] for i in range(1, 7)] for p in data["points"]])


def test_nearest_home_takes_another_branch_of_the_real_ur5(ur5, capsys):
    d, _cell, q, poses = ur5
    data = _compensate(capsys, d, list("xyzabc"), poses)
    assert data["configuration"] == "nearest the robot's home"
    flags = np.array([[p["shoulder"], p["elbow"], p["wrist"]] for p in data["points"]])
    other = np.any(flags != [1, 0, 0], axis=1)
    assert 2 <= other.sum() <= 10  # the arm's branch is (1, 0, 0) at every target
    # there the controller would turn the arm far away, and the real arm misses by millimetres
    assert np.abs(_joints(data)[other] - np.degrees(q[other])).max() > 90
    errors = np.array([p["error_mm"] for p in data["points"]])
    assert errors[other].min() > 3.5 > errors[~other].max()  # 3.7-4.0 mm, against 0.5-3.0 mm


def test_the_ur_branch_is_kept_from_configuration_columns(ur5, capsys):
    d, _cell, q, poses = ur5
    rows = np.column_stack([poses, np.tile([1, 0, 0], (len(q), 1))])
    data = _compensate(capsys, d, [*"xyzabc", "shoulder", "elbow", "wrist"], rows)
    assert data["configuration"] == "by the columns shoulder, elbow, wrist"
    assert all((p["shoulder"], p["elbow"], p["wrist"], p["branch"]) == (1, 0, 0, 4)
               for p in data["points"])
    # the desired poses are where the identified arm was: filtering gives its measured joints
    assert np.abs(_joints(data) - np.degrees(q)).max() < 1e-6
    assert max(p["error_mm"] for p in data["points"]) < 3.5


def test_the_ur_branch_is_kept_from_reference_joints(ur5, capsys):
    d, _cell, q, poses = ur5
    near = np.degrees(q) + np.random.default_rng(3).uniform(-20, 20, q.shape)
    data = _compensate(capsys, d, [*"xyzabc", *(f"near_a{i}" for i in range(1, 7))],
                       np.column_stack([poses, near]))
    assert data["configuration"] == "nearest near_a1..near_a6"
    assert all(p["branch"] == 4 for p in data["points"])
    assert np.abs(_joints(data) - np.degrees(q)).max() < 1e-6


def test_reference_joints_choose_the_turn_of_an_axis_within_the_flags(ur5):
    _d, cell, q, _poses = ur5
    desired = cell.fk(q[:3], tool="probe")
    turned = q[:3].copy()
    # wrist 3 one turn on, toward 0: the same pose (UR axes turn +-360 deg)
    turned[:, 5] -= np.sign(turned[:, 5]) * 2 * np.pi
    f = filter_poses(cell, desired, "world", "probe", config=[[1, 0, 0]] * 3, near=turned)
    assert np.abs(f.q - turned).max() < 1e-9 and (f.branch == 4).all()
    assert f.flags.tolist() == [[1, 0, 0]] * 3


def test_a_ur_poses_file_with_wrong_configuration_columns_is_refused(ur5, capsys):
    d, _cell, _q, poses = ur5
    write_rows(d / "bad.csv", [*"xyzabc", "shoulder", "elbow", "wrist", "s", "t"],
               np.column_stack([poses[:2], [[1, 0, 0]] * 2, [[2, 0]] * 2]))
    code, _out, err = run(capsys, "compensate", d / "bad.csv", "--cell", d / "cell.yaml",
                          "--tool", "probe")
    assert code == 2 and "give one kind of configuration" in err, err
    write_rows(d / "bad.csv", [*"xyzabc", "s", "t"], np.column_stack([poses[:2], [[2, 0]] * 2]))
    code, _out, err = run(capsys, "compensate", d / "bad.csv", "--cell", d / "cell.yaml",
                          "--tool", "probe")
    assert code == 2 and "is a UR-type arm: give its configuration as columns shoulder" in err
    write_rows(d / "bad.csv", [*"xyzabc", "shoulder", "elbow", "wrist"],
               np.column_stack([poses[:2], [[1, 2, 0]] * 2]))
    code, _out, err = run(capsys, "compensate", d / "bad.csv", "--cell", d / "cell.yaml",
                          "--tool", "probe")
    assert code == 2 and "line 2: column 'elbow' must be 0 or 1, got 2" in err, err
    write_rows(d / "bad.csv", [*"xyzabc", "shoulder", "elbow"],
               np.column_stack([poses[:2], [[1, 0]] * 2]))
    code, _out, err = run(capsys, "compensate", d / "bad.csv", "--cell", d / "cell.yaml",
                          "--tool", "probe")
    assert code == 2 and "missing column(s) wrist" in err, err
    write_rows(d / "bad.csv", [*"xyzabc", *(f"near_a{i}" for i in range(1, 6))],
               np.column_stack([poses[:2], np.zeros((2, 5))]))
    code, _out, err = run(capsys, "compensate", d / "bad.csv", "--cell", d / "cell.yaml",
                          "--tool", "probe")
    assert code == 2 and "missing column(s) near_a6" in err, err


def test_arm_flags_no_solution_has_are_named(tmp_path, capsys):
    truth = kr16_truth(np.random.default_rng(7))
    save_robot(truth, tmp_path / "arm.yaml")
    (tmp_path / "cell.yaml").write_text(CELL.replace(
        "  model: kuka_kr16\n", "  model: kuka_kr16\n  identified: arm.yaml\n"))
    # the seam is reached with the wrist centre in front of axis 1 and above the A2-A3 line only
    rows = np.column_stack([seam(3), [[0, 0, 1], [0, 1, 0], [0, 0, 0]]])
    write_rows(tmp_path / "p.csv", [*"xyzabc", "shoulder", "elbow", "wrist"], rows)
    code, _out, err = run(capsys, "compensate", tmp_path / "p.csv", "--cell",
                          tmp_path / "cell.yaml", "--tool", "torch", "--frame", "part", "-o",
                          tmp_path / "cmd.csv")
    assert code == 3, err
    assert ("1 pose(s) cannot be filtered: pose 2: the nominal arm does not reach it with the "
            "flags given (shoulder 0, elbow 1, wrist 0)") in err
    assert not (tmp_path / "cmd.csv").exists()


def test_flags_and_branches_agree_for_every_arm_type():
    assert branch_of_flags("ur", [[1, 0, 0], [0, 1, 1]]).tolist() == [4, 3]
    assert flags_of_branch("opw", [5, -1]).tolist() == [[1, 0, 1], [-1, -1, -1]]
    assert branch_of_flags("palletizer", [1, 1, 0]) == 3
    assert flags_of_branch("palletizer", 3).tolist() == [1, 1, 0]
    with pytest.raises(Exception, match="a 4-axis palletizer has no wrist flip"):
        branch_of_flags("palletizer", [0, 0, 1])
    with pytest.raises(Exception, match="are 0 or 1, got"):
        branch_of_flags("ur", [0, 2, 1])


def test_the_ur_flags_are_the_sides_of_axis_1_and_the_signs_of_j3_and_j5():
    from robotcell.ik.select import nearest

    robot = load_robot("ur5e")
    q = np.random.default_rng(11).uniform(-np.pi, np.pi, (2000, 6))
    T = robot.fk(q, tool=np.eye(4))
    _, found, branch = nearest(robot, robot.ik(T, tool=np.eye(4)), q)
    assert found.all()
    flags = flags_of_branch("ur", branch)
    wrist2 = T[:, :3, 3] - robot.joints[5].d * T[:, :3, 2]  # where axes 5 and 6 meet
    x1 = np.cos(q[:, 0]) * wrist2[:, 0] + np.sin(q[:, 0]) * wrist2[:, 1]
    assert (flags[:, 0] == (x1 < 0)).all()
    assert (flags[:, 1] == (np.sin(q[:, 2]) < 0)).all()
    assert (flags[:, 2] == (np.sin(q[:, 4]) < 0)).all()


# -- a model from another tool ------------------------------------------------------------------------
def test_a_hand_written_identified_model_in_a_cell_is_compensated_without_ik_seed(tmp_path,
                                                                                 capsys):
    truth = kr16_truth(np.random.default_rng(7))
    for name, arm in (("seeded", truth), ("hand", replace(truth, ik_seed=None))):
        d = tmp_path / name
        d.mkdir()
        save_robot(arm, d / "arm.yaml")
        (d / "cell.yaml").write_text(CELL.replace("  model: kuka_kr16\n",
                                                  "  model: kuka_kr16\n  identified: arm.yaml\n"))
        write_rows(d / "seam.csv", list("xyzabc"), seam(6))
        code, _out, err = run(capsys, "compensate", d / "seam.csv", "--cell", d / "cell.yaml",
                              "--tool", "torch", "--frame", "part", "-o", d / "cmd.csv")
        assert code == 0, err
    assert "ik_seed" not in (tmp_path / "hand" / "arm.yaml").read_text()
    assert (tmp_path / "hand" / "cmd.csv").read_text() == \
        (tmp_path / "seeded" / "cmd.csv").read_text()
    cell = Cell.load(tmp_path / "hand" / "cell.yaml")
    assert cell.robot.ik_seed is cell.nominal_robot
