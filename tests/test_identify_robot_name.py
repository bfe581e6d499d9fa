"""``identify --cell CELL.yaml --robot-name NAME``: the identified arm of one robot of a cell of
several robots (``adopt_identified(..., robot=)``, ``identify_file(..., CellRobotFile(path,
robot))``)."""

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from accuracy_helpers import kr16_truth, tracker_csv
from cli_helpers import run

from robotcell.cell import Cell

TWO = Path(__file__).parents[1] / "examples" / "cell_two_robots_positioner.yaml"


@pytest.fixture(scope="module")
def tracker(tmp_path_factory):
    """Simulated tracker data of a KR 16 whose constants differ from the nominal."""
    d = tmp_path_factory.mktemp("kr16")
    rng = np.random.default_rng(24)
    tracker_csv(d / "tracker.csv", kr16_truth(rng), 50, rng)
    return d / "tracker.csv"


@pytest.fixture
def two(tmp_path):
    shutil.copy(TWO, tmp_path / "cell.yaml")
    return tmp_path / "cell.yaml"


def test_the_named_robot_gets_the_identified_arm_and_the_other_is_unchanged(
        tracker, two, capsys):
    before = Cell.load(two)
    code, out, err = run(capsys, "identify", tracker, "--sigma", "0.02", "--folds", "2",
                         "-o", two.parent / "kr16.yaml", "--cell", two, "--robot-name", "kuka")
    assert code == 0, err
    assert "computes with it" in out
    cell = Cell.load(two)
    kuka, abb = cell.for_robot("kuka"), cell.for_robot("abb")
    assert kuka.identified.model == str((two.parent / "kr16.yaml").resolve())
    assert kuka.nominal_robot.name == "kuka_kr16" and kuka.robot.name.endswith("identified")
    assert abb.identified is None and abb.robot.name == before.for_robot("abb").robot.name
    # the other robot's base, tools and the shared positioner are as they were
    np.testing.assert_array_equal(abb.frame_pose("robot"),
                                  before.for_robot("abb").frame_pose("robot"))
    assert set(abb.tools) == set(before.for_robot("abb").tools)


def test_a_cell_of_several_robots_without_a_robot_name_is_refused(tracker, two, capsys):
    before = two.read_text()
    code, _, err = run(capsys, "identify", tracker, "-o", two.parent / "arm.yaml",
                       "--cell", two)
    assert code == 2 and err.startswith("error:")
    assert "2 robots (kuka, abb): say which one with --robot-name NAME" in err
    assert two.read_text() == before and not (two.parent / "arm.yaml").exists()


@pytest.mark.parametrize("name, message", [
    ("nope", "no robot 'nope'; its robots: kuka, abb"),
    ("abb", "is not an identification of 'abb_irb2400'"),
])
def test_a_robot_the_cell_lacks_or_of_another_model_writes_nothing(tracker, two, capsys,
                                                                     name, message):
    before = two.read_text()
    code, _, err = run(capsys, "identify", tracker, "--robot", "kuka_kr16", "-o",
                       two.parent / "arm.yaml", "--cell", two, "--robot-name", name,
                       "--folds", "0")
    assert code == 2 and err.startswith("error:") and message in err, err
    assert two.read_text() == before and not (two.parent / "arm.yaml").exists()


def test_robot_name_without_a_cell_is_refused(tracker, capsys):
    code, _, err = run(capsys, "identify", tracker, "--robot", "kuka_kr16", "--robot-name",
                       "kuka")
    assert code == 2 and "--robot-name names a robot of a cell file" in err


def test_propose_takes_the_named_robots_arm(two, capsys):
    code, out, err = run(capsys, "identify", "--propose", "12", "--cell", two, "--robot-name",
                         "abb", "--json")
    assert code == 0, err
    assert json.loads(out)["robot"] == "abb_irb2400"
    code, _, err = run(capsys, "identify", "--propose", "12", "--cell", two)
    assert code == 2 and "say which one with --robot-name" in err
