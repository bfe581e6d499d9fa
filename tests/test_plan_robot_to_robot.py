"""``robotcell plan robot-to-robot``: designs of common points both robots of a cell reach."""

from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.io.tables import read_csv
from robotcell.kinematics.transforms import make_pose, transform_points
from robotcell.studies.robottorobot_plan import SIZES, plan_robot_to_robot

EXAMPLES = Path(__file__).parents[1] / "examples"
TWO = EXAMPLES / "cell_two_robots_positioner.yaml"
ONE = EXAMPLES / "cell_kr16_positioner.yaml"


@pytest.fixture(scope="module")
def cell():
    return Cell.load(TWO)


@pytest.fixture(scope="module")
def planned(cell):
    return plan_robot_to_robot(cell, "abb", "kuka", noise=1e-4, runs=30, seed=3)


def _far_apart(tmp_path):
    """The two-robot cell with the ABB 20 m away from the KUKA's track."""
    text = TWO.read_text().replace("frame: {x: 1100, y: 1100, z: 0, a: -90",
                                   "frame: {x: 21100, y: 1100, z: 0, a: -90")
    path = tmp_path / "far.yaml"
    path.write_text(text)
    return path


def test_every_design_point_is_reached_by_both_robots_with_the_tool_down(cell, planned):
    T_w_ref = cell.for_robot("kuka").frame_pose("robot", track=0.0)
    for design in planned.designs:
        p_w = transform_points(T_w_ref, design.points)
        T = make_pose(np.broadcast_to(np.diag([1.0, -1.0, -1.0]), (len(p_w), 3, 3)), p_w)
        for name, tool in zip(("kuka", "abb"), planned.tools, strict=True):
            view = cell.for_robot(name)
            sol = view.ik(T, "world", track=None if view.track is None else 0.0, tool=tool)
            assert np.asarray(sol.valid).any(axis=-1).all(), (name, len(design.points))


def test_designs_have_3_to_6_points_not_on_one_line(planned):
    assert [len(d.points) for d in planned.designs] == list(SIZES)
    for d in planned.designs:
        s = np.linalg.svd(d.points - d.points.mean(axis=0), compute_uv=False)
        assert s[1] > 0.1                                    # m: a spread triangle at least


def test_more_points_give_a_smaller_predicted_sigma(planned):
    position = [d.position for d in planned.designs]
    rotation = [d.rotation for d in planned.designs]
    assert position == sorted(position, reverse=True) and position[-1] < position[0]
    assert rotation == sorted(rotation, reverse=True) and rotation[-1] < rotation[0]
    assert planned.best is planned.designs[-1]


def test_the_prediction_agrees_with_the_monte_carlo_spread(planned):
    for d in planned.designs:
        assert 0.6 < d.position_rms / d.position < 1.6
        assert 0.6 < d.rotation_rms / d.rotation < 1.6


def test_the_same_seed_gives_the_same_design(cell, planned):
    again = plan_robot_to_robot(cell, "abb", "kuka", noise=1e-4, seed=3)
    np.testing.assert_array_equal(again.best.points, planned.best.points)
    assert np.isnan(again.best.position_rms)


@pytest.mark.parametrize(("robot", "reference", "match"), [
    ("abb", "nope", "no robot 'nope'"),
    ("abb", "abb", "both 'abb'"),
])
def test_unknown_or_repeated_robots_are_refused(cell, robot, reference, match):
    with pytest.raises(InputError, match=match):
        plan_robot_to_robot(cell, robot, reference, noise=1e-4, seed=0)


@pytest.mark.parametrize("noise", [1e-303, 9e-7, float("nan"), 0.0])
def test_a_noise_below_1_um_is_refused(cell, noise):
    with pytest.raises(InputError, match=r"noise must be a positive distance \(m\) of at least "
                                         r"1e-06"):
        plan_robot_to_robot(cell, "abb", "kuka", noise=noise, seed=0)


def test_a_cell_of_one_robot_is_refused():
    with pytest.raises(InputError, match="one robot"):
        plan_robot_to_robot(Cell.load(ONE), "a", "b", noise=1e-4, seed=0)


def test_robots_without_a_common_volume_are_refused(tmp_path):
    with pytest.raises(InputError, match="no common reachable volume"):
        plan_robot_to_robot(Cell.load(_far_apart(tmp_path)), "abb", "kuka", noise=1e-4, seed=0)


def test_the_command_prints_the_designs_and_writes_the_best_points(capsys, tmp_path, planned):
    out_csv = tmp_path / "points.csv"
    code, out, err = run(capsys, "plan", "robot-to-robot", "--cell", TWO, "--robot", "abb",
                         "--reference", "kuka", "--seed", 3, "--runs", 0, "-o", out_csv)
    assert code == 0, err
    assert "<- best" in out and "position mm" in out
    cols = read_csv(out_csv)
    assert list(cols["point"]) == [f"P{i + 1}" for i in range(len(planned.best.points))]
    xyz = np.column_stack([np.asarray(cols[c], dtype=float) for c in "xyz"])
    np.testing.assert_allclose(xyz, planned.best.points * 1e3, atol=1e-3)
    assert "--tool-ref torch --tool-other torch" in err


@pytest.mark.parametrize(("cell_file", "args", "match"), [
    (TWO, ["--robot", "abb", "--reference", "nope"], "no robot 'nope'"),
    (TWO, ["--robot", "abb", "--reference", "abb"], "both 'abb'"),
    (ONE, ["--robot", "abb", "--reference", "kuka"], "one robot"),
    (None, ["--robot", "abb", "--reference", "kuka"], "no common reachable volume"),
    # a noise whose square underflows made the fit divide by zero (exit 1)
    (TWO, ["--robot", "abb", "--reference", "kuka", "--noise", "1e-300"],
     "--noise must be a positive number of millimetres from 0.001 (1 um"),
])
def test_a_refused_plan_exits_2_naming_the_cause_and_writes_nothing(capsys, tmp_path, cell_file,
                                                                     args, match):
    out_csv = tmp_path / "points.csv"
    code, _, err = run(capsys, "plan", "robot-to-robot", "--cell",
                       cell_file or _far_apart(tmp_path), *args, "--seed", 0, "-o", out_csv)
    assert code == 2
    assert err.startswith("error:") and match in err and "Traceback" not in err
    assert not out_csv.exists()


def test_plan_help_names_the_robot_to_robot_planner_and_its_help_has_an_example(capsys):
    code, out, _ = run(capsys, "plan", "--help")
    assert code == 0 and "plan robot-to-robot --help" in out
    code, out, _ = run(capsys, "plan", "robot-to-robot", "--help")
    assert code == 0 and "robotcell plan robot-to-robot --cell" in out.split("Example", 1)[1]


def test_a_small_common_volume_gives_designs_only_up_to_the_points_found(cell):
    p = plan_robot_to_robot(cell, "abb", "kuka", noise=1e-4, seed=1, candidates=60)
    assert p.reachable == 4
    assert [len(d.points) for d in p.designs] == [3, 4]


def _down_the_track(tmp_path):
    """The two-robot cell with the ABB 2.5 m further along the KUKA's track (3 m long)."""
    text = TWO.read_text().replace("frame: {x: 1100, y: 1100, z: 0, a: -90",
                                   "frame: {x: 3600, y: 1100, z: 0, a: -90")
    path = tmp_path / "down.yaml"
    path.write_text(text)
    return path


def test_a_robot_on_a_track_is_planned_at_the_position_it_touches_from(tmp_path):
    cell = Cell.load(_down_the_track(tmp_path))
    with pytest.raises(InputError, match="no common reachable volume"):
        plan_robot_to_robot(cell, "abb", "kuka", noise=1e-4, seed=0)
    p = plan_robot_to_robot(cell, "abb", "kuka", noise=1e-4, seed=0, tracks=(2.5, 0.0))
    assert p.reachable >= 3
    # the points are in the KUKA's base at track 2.5 m, and both robots reach them there
    T_w_ref = cell.for_robot("kuka").frame_pose("robot", track=2.5)
    p_w = transform_points(T_w_ref, p.best.points)
    T = make_pose(np.broadcast_to(np.diag([1.0, -1.0, -1.0]), (len(p_w), 3, 3)), p_w)
    for name, tool, track in zip(("kuka", "abb"), p.tools, (2.5, None), strict=True):
        sol = cell.for_robot(name).ik(T, "world", track=track, tool=tool)
        assert np.asarray(sol.valid).any(axis=-1).all(), name


@pytest.mark.parametrize(("tracks", "match"), [
    ((3.5, 0.0), "track position 3500 mm of robot 'kuka' is outside its track limits 0 .. 3000"),
    ((0.0, 0.2), "robot 'abb' has no track"),
])
def test_a_track_position_the_robot_cannot_take_is_refused(cell, tracks, match):
    with pytest.raises(InputError, match=match):
        plan_robot_to_robot(cell, "abb", "kuka", noise=1e-4, seed=0, tracks=tracks)


def test_the_command_takes_the_track_positions_and_names_them_in_the_next_step(capsys, tmp_path):
    out_csv = tmp_path / "points.csv"
    code, out, err = run(capsys, "plan", "robot-to-robot", "--cell", _down_the_track(tmp_path),
                         "--robot", "abb", "--reference", "kuka", "--track-ref", 2500,
                         "--seed", 0, "--runs", 0, "-o", out_csv)
    assert code == 0, err
    assert "at track position 2500 mm" in out and "--track-ref 2500" in err
    code, _, err = run(capsys, "plan", "robot-to-robot", "--cell", TWO, "--robot", "abb",
                       "--reference", "kuka", "--track-other", 100, "--seed", 0)
    assert code == 2 and err.startswith("error:") and "robot 'abb' has no track" in err
