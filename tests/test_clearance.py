"""Clearance between a robot and the cell's parts: distances against an independent computation,
crafted paths flagged at the right segment, and the errors users meet."""

import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.clearance import Body, LinkModel, clearance, link_segments, read_bodies
from robotcell.clearance.bodies import BodiesFile
from robotcell.errors import InputError
from robotcell.robot.models import load_robot

pytest.importorskip("coal")

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _segment_distance(p, a, b):
    """Distance of point p from segment ab, by projection (independent of the library)."""
    ab = b - a
    t = np.clip(np.dot(p - a, ab) / max(np.dot(ab, ab), 1e-300), 0.0, 1.0)
    return np.linalg.norm(p - (a + t * ab))


def _floor_cell():
    from robotcell.cell import cell_from_dict
    return cell_from_dict({"name": "floor", "robot": {"model": "kuka_kr16"}})


def test_the_skeleton_runs_through_every_dh_frame_and_ends_at_the_tcp():
    robot = load_robot("kuka_kr16")
    rng = np.random.default_rng(1)
    q = rng.uniform(robot.lower, robot.upper, (5, 6))
    tool = np.eye(4)
    tool[:3, 3] = [0.3, 0, 0.1]
    segs, names = link_segments(robot, q, tool)
    F = robot.frames(q)
    # consecutive segments join, and every DH origin is an end point
    np.testing.assert_allclose(segs[:, 1:, 0], segs[:, :-1, 1], atol=1e-12)
    for i in range(F.shape[1]):
        gap = np.linalg.norm(segs[:, :, 1] - F[:, None, i, :3, 3], axis=-1).min(axis=1)
        assert np.all(gap < 1e-12)
    np.testing.assert_allclose(segs[:, -1, 1], robot.fk(q, tool)[:, :3, 3], atol=1e-12)
    assert names[0] == "base" and names[-2:] == ("flange", "tool")


def test_a_sphere_beside_the_arm_is_as_far_as_the_projection_on_its_skeleton_says():
    """The distance from coal against point-to-segment geometry computed here, to 1e-6 m."""
    cell = _floor_cell()
    rng = np.random.default_rng(7)
    links = LinkModel(radius=0.08, tool_radius=0.02)
    for _ in range(20):
        q = rng.uniform(cell.robot.lower, cell.robot.upper)[None]
        centre = rng.uniform([-2, -2, 0], [2, 2, 2.5])
        body = Body("ball", "sphere", (0.1,), "world", np.eye(4))
        body.pose[:3, 3] = centre
        got = clearance(cell, q, bodies=BodiesFile((body,), links))
        segs, _ = link_segments(cell.robot, q)
        want = min(_segment_distance(centre, s[0], s[1]) for s in segs[0]) - 0.08 - 0.1
        assert got.distance[0] == pytest.approx(want, abs=1e-6)


def _line(cell, start, end, n=11):
    """Joint values along a straight line of the TCP (flange) in the robot base, heading down."""
    T = np.tile(np.diag([1.0, -1.0, -1.0, 1.0]), (n, 1, 1))
    T[:, :3, 3] = np.linspace(start, end, n)
    sol = cell.robot.ik(T, np.eye(4))
    q = [sol.q[0][np.flatnonzero(sol.valid[0])[0]]]
    for k in range(1, n):
        ok = np.flatnonzero(sol.valid[k])
        q.append(sol.q[k][ok[np.argmin(np.linalg.norm(sol.q[k][ok] - q[-1], axis=1))]])
    return np.array(q)


def test_a_path_10_mm_from_a_box_is_flagged_at_its_segment_and_200_mm_passes():
    cell = _floor_cell()
    links = LinkModel(radius=0.05, tool_radius=0.02)
    q = _line(cell, [1.2, -0.4, 0.6], [1.2, 0.4, 0.6])
    tip = cell.robot.fk(q, np.eye(4))[:, :3, 3]
    # a box whose top lies under the flange's path, 10 mm + the radius below it, centred on
    # the path's 6th point (index 5), in the middle of segment 5 -> 6 along y
    for gap, flagged in ((0.010, True), (0.200, False)):
        box = Body("box", "box", (0.1, 0.02, 0.1), "world", np.eye(4))
        box.pose[:3, 3] = [1.2, 0.04, tip[5, 2] - 0.05 - gap - 0.05]
        got = clearance(cell, q, bodies=BodiesFile((box,), links), motion="linear", step=0.005)
        seg = got.per_segment()
        assert bool(seg.min() < 0.05) == flagged
        if flagged:
            assert np.argmin(seg) == 5 and seg[5] == pytest.approx(gap, abs=2e-3)
            assert got.pair[np.argmin(got.distance)][1] == "box"


def test_a_path_into_the_positioner_is_flagged():
    cell = Cell.load(f"{EXAMPLES}/cell_kr16_positioner.yaml")
    plate = Body("plate", "cylinder", (0.4, 0.03), "plate", np.eye(4))
    q = np.radians([[0, -90, 90, 0, 0, 0], [0, -45, 110, 0, 60, 0]])
    got = clearance(cell, q, tool="torch", bodies=BodiesFile((plate,)))
    assert got.minimum < 0 and got.pair[np.argmin(got.distance)][1] == "plate"
    assert got.per_point()[0] > 0.1  # the start is clear; the move runs into it


def test_pairs_in_the_ignore_list_are_never_reported(tmp_path):
    path = tmp_path / "bodies.yaml"
    path.write_text("bodies:\n  part: {parent: plate, sphere: 100}\nignore:\n  - [tool, part]\n"
                    "  - ['link*', part]\n  - [flange, part]\n  - [base, part]\n")
    cell = Cell.load(f"{EXAMPLES}/cell_kr16_positioner.yaml")
    got = clearance(cell, np.zeros((2, 6)), tool="torch", bodies=read_bodies(path))
    assert np.all(np.isinf(got.distance))


def test_a_bodies_file_reads_mm_and_deg(tmp_path):
    path = tmp_path / "bodies.yaml"
    path.write_text("links: {radius: 110, tool_radius: 30}\nbodies:\n"
                    "  fixture: {parent: world, box: [800, 600, 400], "
                    "frame: {x: 1800, y: -1200, z: 400, a: 90}}\n"
                    "  bar: {capsule: {radius: 50, length: 500}}\n")
    got = read_bodies(path)
    assert got.links == LinkModel(0.11, 0.03)
    fixture, bar = got.bodies
    assert fixture.size == (0.8, 0.6, 0.4) and fixture.parent == "world"
    np.testing.assert_allclose(fixture.pose[:3, 3], [1.8, -1.2, 0.4])
    np.testing.assert_allclose(fixture.pose[:3, 0], [0, 1, 0], atol=1e-12)
    assert bar.shape == "capsule" and bar.size == (0.05, 0.5)


@pytest.mark.parametrize("text, match", [
    ("bodies:\n  a: {box: [1, 2]}\n", r"bodies\.a\.box.*\[x, y, z\]"),
    ("bodies:\n  a: {box: [1, 2, 3], sphere: 4}\n", r"exactly one shape"),
    ("bodies:\n  a: {cone: 3}\n", r"unknown key.*cone"),
    ("bodies:\n  a: {sphere: -3}\n", r"sphere takes radius > 0"),
    ("bodies:\n  a: {sphere: .nan}\n", r"finite number"),
    ("bodies:\n  a: {sphere: 1e300}\n", r"beyond the 100 m of any cell"),
    ("bodies:\n  a: {sphere: 3, frame: {x: 1e300}}\n", r"within 100 m"),
    ("bodies:\n  a: {sphere: 3, frame: {x: one}}\n", r"bodies\.a\.frame"),
    ("links: {radius: -1}\n", r"radius must be a finite length >= 0"),
    ("ignore: [tool]\n", r"ignore.*\[name, name\] pairs"),
    ("colour: red\n", r"unknown key.*colour"),
])
def test_a_bad_bodies_file_names_the_key(tmp_path, text, match):
    path = tmp_path / "bodies.yaml"
    path.write_text(text)
    with pytest.raises(InputError, match=match):
        read_bodies(path)


def test_bad_calls_name_the_cause():
    cell = _floor_cell()
    with pytest.raises(InputError, match=r"q must have shape \(N, 6\)"):
        clearance(cell, np.zeros((3, 5)))
    with pytest.raises(InputError, match=r"motion gives 1 moves for 3 points"):
        clearance(cell, np.zeros((3, 6)), motion=["joint"])
    with pytest.raises(InputError, match=r"unknown motion 'circular'"):
        clearance(cell, np.zeros((2, 6)), motion="circular")
    with pytest.raises(InputError, match=r"no turntable or positioner"):
        clearance(cell, np.zeros((2, 6)), bodies=BodiesFile((Body("p", "sphere", (1.0,), "plate"),)))
    with pytest.raises(InputError, match=r"unknown frame 'jig'"):
        clearance(cell, np.zeros((2, 6)), bodies=BodiesFile((Body("p", "sphere", (1.0,), "jig"),)))
    q = _line(cell, [0.9, 0.9, 1.0], [-0.9, -0.9, 1.0], n=2)  # the line passes over the base
    with pytest.raises(InputError, match=r"linear move from point 1 to 2 leaves the robot's reach"):
        clearance(cell, q, motion="linear")


def _seam_program(capsys, tmp_path):
    cell = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLES / "cell_kr16_track_turntable.yaml", cell)
    code, _, err = run(capsys, "program", "write", f"{EXAMPLES}/seam_part.csv", "--cell", cell,
                       "--tool", "torch", "--frame", "part", "--format", "kuka",
                       "-o", tmp_path / "prog")
    assert code == 0, err
    return cell, tmp_path / "prog" / "seam_part.src"


def test_program_check_names_the_points_under_the_clearance_and_their_pair(capsys, tmp_path):
    cell, program = _seam_program(capsys, tmp_path)
    bodies = f"{EXAMPLES}/bodies_kr16_track_turntable.yaml"
    code, out, err = run(capsys, "program", "check", program, "--cell", cell, "--bodies", bodies)
    assert code == 0 and "all good" in out, err
    code, out, err = run(capsys, "program", "check", program, "--cell", cell, "--bodies", bodies,
                         "--clearance", "180")
    assert code == 3
    assert "XP12" in err and re.search(r"clearance 16\d\.\d mm between link4 and plate "
                                       r"\(limit 180 mm\)", err)
    assert "XP1 " not in err  # 186 mm from the part: clear


def test_program_check_refuses_a_bad_bodies_file_with_one_line(capsys, tmp_path):
    cell, program = _seam_program(capsys, tmp_path)
    bad = tmp_path / "bodies.yaml"
    bad.write_text("bodies:\n  a: {cone: 1}\n")
    code, out, err = run(capsys, "program", "check", program, "--cell", cell, "--bodies", bad)
    assert code == 2 and err.startswith("error:") and "unknown key(s) ['cone']" in err
    assert "Traceback" not in err and out == ""


def _kr16_with_link_radius(tmp_path, value):
    """The library's KR 16 model file with ``link_radius: value`` (mm), in ``tmp_path``."""
    text = (Path(__file__).resolve().parents[1] / "src" / "robotcell" / "robots"
            / "kuka_kr16.yaml").read_text(encoding="utf-8")
    path = tmp_path / "kr16_radius.yaml"
    path.write_text(text + f"link_radius: {value}\n", encoding="utf-8")
    return path


def test_the_model_files_link_radius_sizes_the_capsules_unless_the_bodies_file_does(tmp_path):
    """A model file's ``link_radius`` (mm) is the links' radius; the bodies file's wins; without
    both, 6 % of the reach (136 mm for the KR 16)."""
    from robotcell.cell import cell_from_dict
    from robotcell.robot.models import save_robot

    robot = load_robot(_kr16_with_link_radius(tmp_path, 90))
    assert robot.link_radius == pytest.approx(0.09)
    assert LinkModel().radius_of(robot) == pytest.approx(0.09)
    assert LinkModel(radius=0.05).radius_of(robot) == pytest.approx(0.05)
    assert LinkModel().radius_of(load_robot("kuka_kr16")) == pytest.approx(0.136, abs=1e-3)
    save_robot(robot, tmp_path / "again.yaml")
    assert load_robot(tmp_path / "again.yaml").link_radius == pytest.approx(0.09)
    # the distance of a ball from the arm is measured from capsules of that radius
    cell = cell_from_dict({"name": "r", "robot": {"model": str(tmp_path / "kr16_radius.yaml")}})
    q = np.radians([[0.0, -90, 90, 0, 45, 0]])
    segs, _ = link_segments(cell.robot, q)
    centre = np.array([0.9, 0.6, 0.9])
    body = Body("ball", "sphere", (0.1,), "world", np.eye(4))
    body.pose[:3, 3] = centre
    got = clearance(cell, q, bodies=BodiesFile((body,), LinkModel(tool_radius=0.0)))
    want = min(_segment_distance(centre, s[0], s[1]) for s in segs[0][:-1]) - 0.09 - 0.1
    assert got.distance[0] == pytest.approx(want, abs=1e-6)


@pytest.mark.parametrize("value, match", [
    ("0", "key 'link_radius' must be a radius above 0 and at most 1000"),
    ("5000", "key 'link_radius' must be a radius above 0 and at most 1000"),
    ("thick", "key 'link_radius' must be a number"),
])
def test_a_bad_link_radius_is_refused_naming_the_key(tmp_path, value, match):
    with pytest.raises(InputError, match=match):
        load_robot(_kr16_with_link_radius(tmp_path, value))
