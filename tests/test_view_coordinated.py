"""``robotcell view CELL --program A.mod --program B.mod``: a coordinated program of two robots
in the 3D view of their cell, every robot and the shared positioner moving together, and the
closest pair of shapes at each point."""

from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from test_report import _chromium
from test_view_scenes import assert_triad_line
from view_helpers import figure_from_page, js_errors, moving_parts, render, traces, xyz

from robotcell import InputError, make_pose
from robotcell.cell import Cell
from robotcell.cell.kinematics import robot_pose
from robotcell.clearance import Body, clearance_between, read_bodies
from robotcell.clearance.bodies import BodiesFile
from robotcell.programs.coordcheck import check_coordinated
from robotcell.programs.coordinated import write_coordinated
from robotcell.programs.path import read_path
from robotcell.view import program as program_view
from robotcell.view.arm import chain_pose
from robotcell.view.cellscene import frame_size
from robotcell.view.coordinated import (
    CLEAR_COLOR,
    CLOSEST,
    closest_pairs,
    coordinated_scene,
    write_coordinated_view,
)
from robotcell.view.shapes import OUTLIER_COLOR

ROOT = Path(__file__).resolve().parents[1]
CELL = ROOT / "examples" / "cell_two_abb_positioner.yaml"
BODIES = ROOT / "examples" / "bodies_two_robots_positioner.yaml"
SEAMS = {"rob1": ROOT / "examples" / "seam_rob1.csv", "rob2": ROOT / "examples" / "seam_rob2.csv"}
#: 0.01 mm: the coordinates of a path's view (robotcell.view.path.DECIMALS)
TOL = 0.005


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    cell = Cell.load(CELL)
    folder = tmp_path_factory.mktemp("prog") / "prog"
    result = write_coordinated(SEAMS, cell, {"rob1": "torch", "rob2": "torch"}, "part", "abb",
                               folder, "seams")
    return cell, [Path(f) for f in result.files]


def _unique(v, tol=1e-6):
    """Vertices (S, V, 3) without those that coincide with the one before at every step, as
    the moving polyline of a path's view drops them."""
    keep = np.concatenate([[True], ~np.all(np.isclose(v[:, 1:], v[:, :-1], rtol=0, atol=tol),
                                           axis=(0, 2))])
    return v[:, keep]


def _arrays(report, robot):
    pts = report.reports[robot].points
    return (np.array([p.q for p in pts]), np.array([p.track for p in pts]),
            np.array([p.table for p in pts], dtype=float))


def _ball(name, robot, point, cell):
    """A ball of 10 mm radius on the part, 60 mm beyond the TCP of ``robot``'s seam point
    ``point`` along the tool's Z: 25 mm from the torch's capsule (radius 25 mm) there."""
    T = read_path(SEAMS[robot], cell.for_robot(robot)).T[point]
    return Body(name, "sphere", (0.010,), "part",
                make_pose(np.eye(3), T[:3, 3] + 0.060 * T[:3, 2]))


def test_every_robot_and_the_positioner_are_at_their_points_at_every_step(written, tmp_path):
    cell, files = written
    made = write_coordinated_view(cell, files, tmp_path / "v.html", bodies=read_bodies(BODIES))
    assert made.every == 1 and made.size == (tmp_path / "v.html").stat().st_size < 5_000_000
    # both torches 5 mm above the plate at every point
    assert {b for _, b in made.closest.pair} == {"plate"}
    np.testing.assert_allclose(made.closest.distance, 0.005, atol=1e-6)
    data = figure_from_page((tmp_path / "v.html").read_text())
    report = made.report
    n = len(report.reports["rob1"].points)
    assert [s["label"] for s in data["layout"]["sliders"][0]["steps"]] == [
        p.name for p in report.reports["rob1"].points]
    size = frame_size(cell.for_robot("rob1").robot) * 1e3
    for robot in ("rob1", "rob2"):
        view = cell.for_robot(robot)
        q, track, table = _arrays(report, robot)
        links = _unique(np.stack([chain_pose(view.robot, qi, robot_pose(view, ei)).vertices
                                  for qi, ei in zip(q, track)]) * 1e3)
        flange = cell.fk(q, track, table, tool=np.eye(4), robot=robot)
        tcp = cell.fk(q, track, table, tool="torch", robot=robot)
        seam = read_path(SEAMS[robot], view)
        np.testing.assert_allclose(cell.fk(q, track, table, tool="torch", frame="part",
                                           robot=robot), seam.T, atol=1e-9)
        path = traces(data, f"{robot}: TCP path")[0]
        np.testing.assert_allclose(xyz(path), tcp[:, :3, 3] * 1e3, atol=TOL)
        for k in range(n):
            parts = moving_parts(data, k)
            np.testing.assert_allclose(parts[f"{robot}: robot abb_irb2400: links"], links[k],
                                       rtol=0, atol=TOL)
            np.testing.assert_allclose(parts[f"{robot}: tool"], [flange[k, :3, 3] * 1e3,
                                                                tcp[k, :3, 3] * 1e3], atol=TOL)
            assert_triad_line(parts[f"{robot}: TCP"], tcp[k], size, TOL)
    # the positioner turns the part from -10 to 10 deg along the seams: the part's frame,
    # which it carries, drawn where the cell puts it at each point
    _, _, table = _arrays(report, "rob1")
    np.testing.assert_allclose(np.degrees(table[[0, -1], 1]), [-10, 10], atol=1e-9)
    part = cell.for_robot("rob1").frame_pose("part", table=table)
    drawn = [moving_parts(data, k)["frames"] for k in range(n)]
    for k in range(n):
        assert_triad_line(drawn[k], part[k], size, TOL)
    assert np.nanmax(np.abs(drawn[0] - drawn[-1])) > 10.0
    assert traces(data, "moving frames")[0]["text"] == ["part"]


def test_the_closest_pair_at_each_point_is_clearance_betweens_and_changes_along(written):
    # a ball beyond rob1's torch at the first point, one beyond rob2's at the last: the
    # closest pair is rob1's torch and the first ball at the start, rob2's and the second at
    # the end, 25 mm apart each
    cell, files = written
    bodies = BodiesFile((_ball("ball1", "rob1", 0, cell), _ball("ball2", "rob2", -1, cell)))
    report = check_coordinated(files, cell, bodies=bodies)
    got = closest_pairs(cell, report, bodies)
    n = len(got.distance)
    q = {r: _arrays(report, r)[0] for r in ("rob1", "rob2")}
    _, track, table = _arrays(report, "rob1")
    want = clearance_between(cell, q, track={"rob1": track}, table=table,
                             tools={"rob1": "torch", "rob2": "torch"}, bodies=bodies,
                             motion="linear")
    at = np.flatnonzero(np.isclose(want.position, np.round(want.position)))
    assert len(at) == n and np.array_equal(want.position[at], np.arange(n))
    np.testing.assert_allclose(got.distance, want.distance[at], rtol=0, atol=1e-6)
    np.testing.assert_allclose(got.nearest, want.nearest[at], rtol=0, atol=1e-6)
    assert got.pair == tuple(want.pair[i] for i in at)
    assert got.pair[0] == ("rob1.tool", "ball1") and got.pair[-1] == ("rob2.tool", "ball2")
    np.testing.assert_allclose(got.distance[[0, -1]], 0.025, atol=1e-6)
    # the scene draws it at each point: the line between the nearest points, its label
    scene = coordinated_scene(cell, report, bodies, clearance=0.010)
    for k, step in enumerate(scene.steps):
        line = next(it for it in step.items if it.name == CLOSEST)
        label = next(it for it in step.items if it.name == f"{CLOSEST}: distance")
        np.testing.assert_allclose(line.points, got.nearest[k], atol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(np.diff(line.points, axis=0)),
                                   got.distance[k], atol=1e-6)
        a, b = got.pair[k]
        assert label.labels == (f"{a} - {b} {got.distance[k] * 1e3:.1f} mm",)
        assert f"{a} and {b}, {got.distance[k] * 1e3:.3f} mm (limit 10 mm)" in label.hover[0]
        assert line.color == CLEAR_COLOR
    # under a limit of 30 mm the two end points are problems: red, and named in the hover
    scene = coordinated_scene(cell, report, bodies, clearance=0.030)
    lines = [next(it for it in s.items if it.name == CLOSEST) for s in scene.steps]
    assert [ln.color == OUTLIER_COLOR for ln in lines] == list(got.distance < 0.030)
    label = next(it for it in scene.steps[0].items if it.name == f"{CLOSEST}: distance")
    assert label.color == OUTLIER_COLOR and "(limit 30 mm, under it)" in label.hover[0]


def test_every_kth_point_has_the_arms_and_the_closest_pair_of_its_point(written, monkeypatch,
                                                                          tmp_path):
    cell, files = written
    bodies = read_bodies(BODIES)
    report = check_coordinated(files, cell, bodies=bodies)
    scene = coordinated_scene(cell, report, bodies, every=2)
    assert [s.label for s in scene.steps] == ["p1", "p3", "p5"]
    got = closest_pairs(cell, report, bodies)
    for s, k in zip(scene.steps, (0, 2, 4)):
        line = next(it for it in s.items if it.name == CLOSEST)
        np.testing.assert_allclose(line.points, got.nearest[k], atol=1e-12)
    assert any("the arms are drawn at every 2nd of the 6 points" in n for n in scene.notes)
    # a page limit that holds the arms at 3 of the 6 points: every 2nd point
    limit = len(program_view.page(coordinated_scene(cell, report, bodies, every=2)).encode())
    monkeypatch.setattr(program_view, "MAX_PAGE_BYTES", limit + 2000)
    made = write_coordinated_view(cell, files, tmp_path / "v.html", bodies=bodies)
    assert made.every == 2 and len(figure_from_page((tmp_path / "v.html").read_text())[
        "frames"]) == 3


def test_bad_points_of_each_robot_are_marked_with_their_problems(written, tmp_path):
    # at a limit of 10 mm both torches are too close to the plate (5 mm) at every point
    cell, files = written
    made = write_coordinated_view(cell, files, tmp_path / "v.html", bodies=read_bodies(BODIES),
                                  clearance=0.010)
    data = figure_from_page((tmp_path / "v.html").read_text())
    for robot in ("rob1", "rob2"):
        pts = made.report.reports[robot].points
        mark = traces(data, f"{robot}: bad points")[0]
        assert mark["text"] == [p.name for p in pts]
        assert all("clearance 5.0 mm between rob" in h and "and plate (limit 10 mm)" in h
                   for h in mark["hovertext"])
        np.testing.assert_allclose(xyz(mark), [p.T_world_TCP[:3, 3] * 1e3 for p in pts],
                                   atol=TOL)
    line = traces(data, CLOSEST)[0]
    frame = data["frames"][0]["data"][data["frames"][0]["traces"].index(
        data["data"].index(line))]
    assert {**line, **frame}["line"]["color"] == OUTLIER_COLOR


def test_programs_of_different_lengths_are_refused(written):
    cell, files = written
    report = check_coordinated(files, cell)
    report.reports["rob2"].points.pop()
    with pytest.raises(InputError, match=r"different numbers of points \(rob1 6, rob2 5\)"):
        coordinated_scene(cell, report)
    with pytest.raises(InputError, match="every must be a whole number >= 1, got 0"):
        coordinated_scene(cell, check_coordinated(files, cell), every=0)


def test_the_command_writes_the_view_and_refuses_bad_input(written, tmp_path, capsys):
    cell, files = written
    out = tmp_path / "v.html"
    code, _, err = run(capsys, "view", CELL, "--program", files[0], "--program", files[1],
                       "--bodies", BODIES, "--clearance", 3, "-o", out)
    assert code == 0, err
    assert ("2 robots' coordinated program in two_abb_positioner: 6 points each, 0 bad, 0 under "
            "the clearance of 3 mm, the arms at every point") in err
    data = figure_from_page(out.read_text())
    assert len(data["frames"]) == 6 and traces(data, CLOSEST)
    out.unlink()
    bad_bodies = tmp_path / "bodies.yaml"
    bad_bodies.write_text(BODIES.read_text().replace("links:", "linkz:"))
    on_robot = tmp_path / "on_robot.yaml"
    on_robot.write_text("bodies:\n  carriage: {parent: robot, box: [100, 100, 100]}\n")
    both = ["--program", files[0], "--program", files[1]]
    short = tmp_path / "seams_T_ROB2.mod"  # its last move left out
    short.write_text("".join(ln for ln in files[1].read_text().splitlines(True)
                             if not ln.lstrip().startswith("MoveL p6")))
    cases = [
        (["--program", files[0], "--bodies", BODIES], "--bodies: for a coordinated program, "
                                                      "one --program per robot"),
        (["--program", files[0]], "has 2 robots (rob1, rob2): give one --program per robot"),
        ([*both, "--program", files[1]], "3 program files for 2 robots"),
        (["--program", files[0], "--program", short], "different numbers of points (rob1 6, "
                                                      "rob2 5)"),
        ([*both, "--robots", "rob1,rob3"], "rob3"),
        ([*both, "--bodies", bad_bodies], "linkz"),
        ([*both, "--bodies", on_robot], "does not say which robot"),
        ([*both, "--bodies", BODIES, "--clearance", -1], "--clearance must be from 0"),
        ([*both, "--pulses-per-degree", 100], "--pulses-per-degree is for a YASKAWA job"),
        ([*both, "--joints", "0,0,0,0,0,0"], "leave out --joints"),
        ([*both, "-o", files[1]], "names the same file as --program"),
    ]
    for args, match in cases:
        argv = ["view", CELL, *args] + ([] if "-o" in args else ["-o", out])
        code, _, err = run(capsys, *argv)
        lines = err.strip().splitlines()
        assert code == 2 and match in err and len(lines) == 1, (args, err)
        assert lines[0].startswith("error: "), err
    assert not out.exists()
    assert files[1].read_text().startswith("MODULE")


def test_the_browser_draws_the_coordinated_view_without_error(written, tmp_path):
    cell, files = written
    exe = _chromium()
    write_coordinated_view(cell, files, tmp_path / "v.html", bodies=read_bodies(BODIES))
    dom, console, _ = render(exe, tmp_path / "v.html", tmp_path, screenshot=False)
    assert not js_errors(console), console
    assert 'data-scene="rendered"' in dom


def test_a_point_a_robot_cannot_reach_is_marked_and_its_arm_stays_at_the_point_before(written):
    cell, files = written
    bodies = read_bodies(BODIES)
    report = check_coordinated(files, cell)
    lost = report.reports["rob2"].points[3]
    lost.q = np.full(6, np.nan)
    lost.problems = ["out of reach by 12.0 mm"]
    scene = coordinated_scene(cell, report, bodies, clearance=0.003)
    data = figure_from_page(program_view.page(scene))
    before, at = moving_parts(data, 2), moving_parts(data, 3)
    np.testing.assert_array_equal(at["rob2: robot abb_irb2400: links"],
                                  before["rob2: robot abb_irb2400: links"])
    assert np.abs(at["rob1: robot abb_irb2400: links"]
                  - before["rob1: robot abb_irb2400: links"]).max() > 1.0
    mark = traces(data, "rob2: bad points")[0]
    assert mark["text"] == [lost.name]
    assert mark["hovertext"] == [f"<b>rob2 point {lost.name}</b>: out of reach by 12.0 mm"]
    np.testing.assert_allclose(xyz(mark)[0], lost.T_world_TCP[:3, 3] * 1e3, atol=TOL)
    # no closest pair where a robot has no joint values
    got = closest_pairs(cell, report, bodies)
    assert got.distance[3] == np.inf and got.pair[3] == ("", "")
    line = next(it for it in scene.steps[3].items if it.name == CLOSEST)
    label = next(it for it in scene.steps[3].items if it.name == f"{CLOSEST}: distance")
    assert np.all(np.isnan(line.points)) and len(label.points) == 0
    np.testing.assert_allclose(got.distance[[0, 1, 2, 4, 5]], 0.005, atol=1e-6)
