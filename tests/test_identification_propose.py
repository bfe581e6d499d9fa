"""``identify --propose`` keeps the flange and the reflectors inside the work volume
(docs/identification.md, "Validation"): a box, the cell's floor, or the robot's base plane."""

import json

import numpy as np
import pytest
from cli_helpers import run

from robotcell import load_robot
from robotcell.cell import Cell
from robotcell.identification.validation import random_configurations
from robotcell.identification.workvolume import WorkVolume, configurations_within, measured_points
from robotcell.kinematics.transforms import make_pose


def _proposed(capsys, *args) -> tuple[np.ndarray, dict]:
    code, out, err = run(capsys, "identify", "--propose", "15", "--json", *args)
    assert code == 0, err
    data = json.loads(out)
    return np.radians(np.array(data["configurations"])), data


@pytest.mark.parametrize("robot", ["ur5e", "kuka_kr16"])
def test_proposed_flanges_and_reflectors_stay_above_the_robot_base_plane(robot, capsys):
    arm = load_robot(robot)
    # random configurations within the joint limits go into the floor: the test can fail
    below = measured_points(arm, random_configurations(arm, np.random.default_rng(0), 1000), 3)
    assert (below[..., 2] < 0).any(axis=1).mean() > 0.05  # KR 16: 8 %, UR5e: 40 %
    q, data = _proposed(capsys, "--robot", robot, "--targets", "3")
    assert data["work_volume"] == "above the robot base plane (z = 0 of the robot base)"
    assert np.all(arm.within_limits(q))
    assert measured_points(arm, q, 3)[..., 2].min() >= 0.0


def test_proposed_configurations_stay_inside_a_box(capsys):
    arm = load_robot("kuka_kr16")
    q, data = _proposed(capsys, "--robot", "kuka_kr16", "--box", "200,-900,300,1600,900,1800")
    assert data["work_volume"].startswith("inside the box x 200..1600, y -900..900, z 300..1800")
    p = measured_points(arm, q, 1) * 1e3
    assert np.all((p >= [200, -900, 300]) & (p <= [1600, 900, 1800]))


def test_proposed_configurations_of_a_cell_stay_above_its_floor(tmp_path, capsys):
    # a KR 16 on a 600 mm pedestal: its flange may go below its base, not below the floor
    (tmp_path / "cell.yaml").write_text(
        "name: pedestal\nrobot:\n  model: kuka_kr16\n"
        "  frame: {x: 0, y: 0, z: 600, a: 0, b: 0, c: 0}\n")
    q, data = _proposed(capsys, "--cell", tmp_path / "cell.yaml", "--targets", "3")
    assert data["robot"] == "kuka_kr16"
    assert data["work_volume"] == "above the floor of pedestal (z = 0 of its world)"
    cell = Cell.load(tmp_path / "cell.yaml")
    p = measured_points(cell.robot, q, 3)
    assert (p[..., 2] + 0.6).min() >= 0.0
    assert p[..., 2].min() < 0.0  # below the base plane: the floor, not the base, is the limit


def test_a_box_the_arm_cannot_reach_is_refused(tmp_path, capsys):
    code, _out, err = run(capsys, "identify", "--propose", "15", "--robot", "kuka_kr16", "--box",
                          "3000,3000,0,3100,3100,100")
    assert code == 2
    assert ("0 of 100000 random configurations within the joint limits keep the flange and the "
            "reflectors inside the box x 3000..3100") in err and "give a larger box" in err
    code, _out, err = run(capsys, "identify", "--propose", "15", "--robot", "kuka_kr16", "--box",
                          "0,0,0,100,100")
    assert code == 2 and "--box needs 6 comma-separated values, got 5" in err
    code, _out, err = run(capsys, "identify", "--propose", "15", "--robot", "kuka_kr16", "--box",
                          "500,0,0,100,100,100")
    assert code == 2 and "lower corner must be below its upper corner on every axis: x 500..100" \
        in err
    (tmp_path / "t.csv").write_text("a1,a2,a3,a4,a5,a6,x,y,z\n")
    code, _out, err = run(capsys, "identify", tmp_path / "t.csv", "--robot", "kuka_kr16", "--box",
                          "0,0,0,1,1,1")
    assert code == 2 and "--box goes with --propose" in err


def test_a_work_volume_is_its_half_spaces():
    box = WorkVolume.box([0, 0, 0], [1, 2, 3])
    assert box.contains([[0.5, 1, 2.9], [1.1, 1, 1], [0, 0, 0]]).tolist() == [True, False, True]
    tilted = WorkVolume.above(make_pose(None, [0, 0, -0.5]), "a floor 0.5 m down")
    assert tilted.contains([[0, 0, -0.4], [3, 0, -0.6]]).tolist() == [True, False]
    arm = load_robot("ur5e")
    q = configurations_within(arm, tilted, 50, n_targets=2, seed=3)
    assert q.shape == (50, 6) and (measured_points(arm, q, 2)[..., 2] >= -0.5).all()
