"""Coordinated paths: the positioner's values chosen once for every robot, the robots' points
matched by time, each robot's track chosen; every refusal named with nothing written. The cell
is the example of two IRB 2400 sharing a 2-axis positioner, rob1 on a track."""

import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from scipy.spatial.transform import Rotation, Slerp

from robotcell.cell import Cell
from robotcell.cell.ik import ik
from robotcell.cell.tablechoice import choose_shared_table, choose_table
from robotcell.errors import InputError
from robotcell.programs.coordcheck import check_coordinated
from robotcell.programs.coordinated import write_coordinated
from robotcell.programs.path import read_path
from robotcell.programs.pathtime import match_by_time

ROOT = Path(__file__).resolve().parents[1]
CELL = ROOT / "examples" / "cell_two_abb_positioner.yaml"
TOOLS = {"rob1": "torch", "rob2": "torch"}

#: rob1's seam of the example with neither its track nor the positioner's values.
ROB1 = """x,y,z,a,b,c,motion,speed
-100,100,0,0,0,150,ptp,20
-60,100,0,0,0,150,lin,20
-20,100,0,0,0,150,lin,20
20,100,0,0,0,150,lin,20
60,100,0,0,0,150,lin,20
100,100,0,0,0,150,lin,20
"""
ROB2 = (ROOT / "examples" / "seam_rob2.csv").read_text()

#: rob1's seam with times, 1 s apart, and the positioner's values.
ROB1_TIMED = """x,y,z,a,b,c,motion,speed,time,e1,e2
-100,100,0,0,0,150,ptp,20,0,0,-10
-60,100,0,0,0,150,lin,20,1,0,-6
-20,100,0,0,0,150,lin,20,2,0,-2
20,100,0,0,0,150,lin,20,3,0,2
60,100,0,0,0,150,lin,20,4,0,6
100,100,0,0,0,150,lin,20,5,0,10
"""
#: rob2's path of three points, the middle one at a time rob1's file does not have.
ROB2_TIMED = """x,y,z,a,b,c,motion,speed,time
100,-100,0,0,0,-150,ptp,20,0
0,-120,0,10,5,-140,lin,20,2.5
-100,-100,0,0,0,-150,lin,20,5
"""


@pytest.fixture(scope="module")
def cell():
    return Cell.load(CELL)


def _files(folder, **texts):
    folder.mkdir(exist_ok=True)
    paths = {}
    for robot, text in texts.items():
        paths[robot] = folder / f"{robot}.csv"
        paths[robot].write_text(text)
    return paths


def _read_back(cell, files, robot):
    """Joints, track and table of one robot's points as the checker reads the program back."""
    report = check_coordinated(files, cell)
    assert report.good, (report.sync, report.rows())
    points = report.reports[robot].points
    return (np.array([p.q for p in points]), np.array([p.track for p in points]),
            np.array([p.table for p in points], dtype=float))


def _assert_reached(cell, files, robot, T):
    q, track, table = _read_back(cell, files, robot)
    got = cell.fk(q, track, table, tool="torch", frame="part", robot=robot)
    assert np.abs(got[:, :3, 3] - T[:, :3, 3]).max() < 1e-9                 # 1e-6 mm
    assert np.abs(got[:, :3, :3] - T[:, :3, :3]).max() < 1e-8
    return table, track


def test_the_shared_choice_puts_every_robots_point_in_reach_through_cell_fk(cell, tmp_path):
    paths = _files(tmp_path, rob1=ROB1, rob2=ROB2)
    result = write_coordinated(paths, cell, TOOLS, "part", "abb", tmp_path / "prog", "seams")
    tables = []
    for robot in ("rob1", "rob2"):
        seam = read_path(paths[robot], cell.for_robot(robot))
        table, _ = _assert_reached(cell, result.files, robot, seam.T)
        tables.append(table)
    np.testing.assert_allclose(tables[0], tables[1], atol=1e-9)   # one value for both robots
    np.testing.assert_allclose(tables[0], result.results["rob1"].table, atol=1e-9)
    assert np.abs(np.diff(tables[0], axis=0)).max() <= np.radians(30)      # smooth


def test_one_robot_alone_would_choose_values_the_other_cannot_reach(cell, tmp_path):
    """rob1's own choice turns its normal up; rob2 reaches none of its points there. The shared
    choice serves both, with a common score (the worst robot's) above 0 at every point, where
    rob1's choice forced on rob2 scores 0 (rob2 fails)."""
    paths = _files(tmp_path, rob1=ROB1, rob2=ROB2)
    seams = {r: read_path(p, cell.for_robot(r)) for r, p in paths.items()}
    alone = choose_table(cell, seams["rob1"].T, "part", tool="torch", robot="rob1")
    forced = ik(cell.for_robot("rob2"), seams["rob2"].T, "part", None, alone.table, "torch")
    assert not forced.valid.any(axis=-1).any()
    shared = choose_shared_table(cell, {r: s.T for r, s in seams.items()}, "part",
                                 tools=TOOLS)
    for robot, seam in seams.items():
        sol = ik(cell.for_robot(robot), seam.T, "part", seam.track, shared.table, "torch")
        assert sol.valid[np.arange(len(seam)), shared.branch[robot]].all()
    assert shared.breaks == 0 and (shared.score > 0.5).all()


def test_for_one_robot_the_shared_choice_is_the_one_robot_choice(cell):
    """With one robot the worst robot's score is its own: the shared choice is the one-robot
    choice (the same values, the same configuration)."""
    seam = read_path(ROOT / "examples" / "seam_rob2.csv", cell.for_robot("rob2"))
    both = choose_shared_table(cell, {"rob2": seam.T}, "part", tools={"rob2": "torch"})
    alone = choose_table(cell, seam.T, "part", tool="torch", robot="rob2")
    np.testing.assert_allclose(both.table, alone.table, atol=1e-12)
    np.testing.assert_array_equal(both.branch["rob2"], alone.branch)
    assert (both.score <= 1.0).all() and (both.score > 0).all()


def test_the_given_positioner_values_win_over_the_choice(cell, tmp_path):
    given = (ROOT / "examples" / "seam_rob1.csv")
    paths = {"rob1": given, **_files(tmp_path, rob2=ROB2)}
    result = write_coordinated(paths, cell, TOOLS, "part", "abb", tmp_path / "prog", "seams")
    want = read_path(given, cell.for_robot("rob1")).table
    np.testing.assert_allclose(result.results["rob2"].table, want, atol=1e-12)


def test_a_robot_on_a_track_without_a_track_column_gets_its_track_chosen(cell, tmp_path):
    """rob1 is on a track; its file gives the positioner's values but no track: the track
    follows its path, as for one robot, and rob2 (no track) is solved as before."""
    text = "".join(ln.replace(",1100,", ",") for ln in
                   (ROOT / "examples" / "seam_rob1.csv").read_text().splitlines(True))
    text = text.replace("speed,track,", "speed,")
    paths = _files(tmp_path, rob1=text, rob2=ROB2)
    assert read_path(paths["rob1"], cell.for_robot("rob1")).track is None
    result = write_coordinated(paths, cell, TOOLS, "part", "abb", tmp_path / "prog", "seams")
    track = result.results["rob1"].track
    assert np.isfinite(track).all() and np.ptp(track) > 0.01          # it follows the seam
    assert (track >= 0).all() and (track <= 3.0).all()
    _, read = _assert_reached(cell, result.files, "rob1",
                              read_path(paths["rob1"], cell.for_robot("rob1")).T)
    np.testing.assert_allclose(read, track, atol=1e-9)


def test_the_track_and_the_positioner_are_both_chosen(cell, tmp_path):
    paths = _files(tmp_path, rob1=ROB1, rob2=ROB2)
    result = write_coordinated(paths, cell, TOOLS, "part", "abb", tmp_path / "prog", "seams")
    assert np.ptp(result.results["rob1"].track) > 0.01
    np.testing.assert_array_equal(result.results["rob2"].track, 0.0)        # rob2: no track


def test_points_are_matched_by_time_with_poses_between_interpolated(cell, tmp_path):
    paths = _files(tmp_path, rob1=ROB1_TIMED, rob2=ROB2_TIMED)
    read = {r: read_path(p, cell.for_robot(r)) for r, p in paths.items()}
    matched = match_by_time(read)
    times = np.array([0, 1, 2, 2.5, 3, 4, 5], dtype=float)
    for path in matched.values():
        np.testing.assert_allclose(path.time, times)
    own = read["rob2"]
    slerp = Slerp(own.time, Rotation.from_matrix(own.T[:, :3, :3]))
    T2 = matched["rob2"].T
    np.testing.assert_allclose(T2[:, :3, :3], slerp(times).as_matrix(), atol=1e-12)
    for k in range(3):
        np.testing.assert_allclose(T2[:, k, 3], np.interp(times, own.time, own.T[:, k, 3]),
                                   atol=1e-12)
    np.testing.assert_array_equal(matched["rob2"].lines, [2, 0, 0, 3, 0, 0, 4])
    # rob1 gains the point at 2.5 s, its positioner's values interpolated linearly
    np.testing.assert_allclose(np.degrees(matched["rob1"].table[3]), [0, 0], atol=1e-12)
    np.testing.assert_allclose(matched["rob1"].T[3, :3, 3], [0, 0.1, 0], atol=1e-12)
    result = write_coordinated(paths, cell, TOOLS, "part", "abb", tmp_path / "prog", "timed")
    for robot in ("rob1", "rob2"):
        table, _ = _assert_reached(cell, result.files, robot, matched[robot].T)
        np.testing.assert_allclose(table, matched["rob1"].table, atol=1e-9)


def test_points_matched_by_time_with_the_positioner_chosen(cell, tmp_path):
    paths = _files(tmp_path, rob1=ROB1_TIMED.replace(",e1,e2", "").replace(",0,-10\n", "\n")
                   .replace(",0,-6\n", "\n").replace(",0,-2\n", "\n").replace(",0,2\n", "\n")
                   .replace(",0,6\n", "\n").replace(",0,10\n", "\n"), rob2=ROB2_TIMED)
    assert not read_path(paths["rob1"], cell.for_robot("rob1")).table_given
    result = write_coordinated(paths, cell, TOOLS, "part", "abb", tmp_path / "prog", "timed")
    assert len(result.results["rob1"].q) == len(result.results["rob2"].q) == 7
    assert check_coordinated(result.files, cell).good


def _refused(tmp_path, capsys, cell, texts, match):
    """The library refuses with ``match`` and the command line exits 2 with one error line;
    nothing is written either way."""
    paths = _files(tmp_path / "in", **texts)
    folder = tmp_path / "out"
    with pytest.raises(InputError, match=match):
        write_coordinated(paths, cell, TOOLS, "part", "abb", folder, "seams")
    assert not folder.exists()
    folder.mkdir()
    code, out, err = run(capsys, "program", "write-coordinated",
                         *[f"{r}={p}" for r, p in paths.items()], "--cell", CELL, "--tool",
                         "torch", "--frame", "part", "--format", "abb", "-o", folder)
    assert code == 2 and out == "" and err.startswith("error: ")
    assert err.count("error:") == 1 and "Traceback" not in err
    assert re.search(match, err.replace("\n", " "))
    assert list(folder.iterdir()) == []


FAR = ROB2.replace("20,-100,0,0,0,-150", "20,-100,1500,0,0,-150")
APART = "x,y,z,a,b,c\n0,-1300,0,0,0,180\n20,-1300,0,0,0,180\n"


@pytest.mark.parametrize("texts, match", [
    ({"rob1": ROB1, "rob2": FAR},
     r"no positioner values serve every robot: point 3: rob2 reaches it at no positioner "
     r"values within the limits"),
    ({"rob1": APART, "rob2": APART},
     r"point 1: rob1 and rob2 each reach it, but never at the same positioner values"),
    ({"rob1": ROB1, "rob2": ROB2.replace("-150,ptp,20", "-30,ptp,20")},
     r"point 1: no positioner values within the axis limits turn the robots' mean normal up"),
    ({"rob1": ROB1_TIMED.replace(",0,-10\n", ",120,-10\n"), "rob2": ROB2_TIMED},
     r"rob1.csv: line 2: column 'e1' has 120, outside the e1 axis limits \[-95, 95\]"),
    ({"rob1": ROB1, "rob2": "".join(ROB2.splitlines(True)[:-1])},
     r"as many points each.*rob1 6, rob2 5; give a time column in every file to match the "
     r"points by time"),
    ({"rob1": ROB1_TIMED, "rob2": ROB2},
     r"rob1.csv gives a time column and .*rob2.csv does not: points are matched by time only "
     r"when every file gives times"),
    ({"rob1": ROB1_TIMED, "rob2": ROB2_TIMED.replace(",20,5\n", ",20,5.5\n")},
     r"the paths' last times differ: .*rob1.csv 5 s, .*rob2.csv 5.5 s"),
    ({"rob1": ROB1_TIMED, "rob2": ROB2_TIMED.replace(",20,0\n", ",20,0.5\n")},
     r"the paths' first times differ: .*rob1.csv 0 s, .*rob2.csv 0.5 s"),
    ({"rob1": ROB1_TIMED, "rob2": ROB2_TIMED.replace("lin,20,2.5", "ptp,20,2.5")},
     r"rob2.csv: line 3: the motion to this point is a joint motion \(ptp\), and another path "
     r"has a point at 1 s on it"),
    ({"rob1": ROB1_TIMED, "rob2": ROB2_TIMED.replace(",20,2.5\n", ",20,0\n")},
     r"rob2.csv: line 3: column 'time' has 0 s, not later than 0 s of the line before"),
    ({"rob1": ROB1_TIMED, "rob2": ROB2_TIMED.replace(",20,2.5\n", ",20,\n")},
     r"rob2.csv: line 3.*'time'"),
    ({"rob1": ROB1_TIMED.replace(",2,0,-2\n", ",2,0,-3\n"),
      "rob2": ROB2_TIMED.replace("speed,time", "speed,time,e1,e2")
      .replace(",20,0\n", ",20,0,0,-10\n").replace(",20,2.5\n", ",20,2.5,0,0\n")
      .replace(",20,5\n", ",20,5,0,10\n")},
     r"rob2.csv: at 2 s \(between two of its points\): the positioner's values differ"),
])
def test_refused_with_nothing_written(tmp_path, capsys, cell, texts, match):
    _refused(tmp_path, capsys, cell, texts, match)


TURNTABLE_CELL = """name: two_abb_turntable
robots:
  rob1:
    model: abb_irb2400
    frame: {x: 1100, y: -1100, z: 0, a: 90, b: 0, c: 0}
    tools:
      torch: {number: 1, frame: {x: 300, y: 0, z: 90, a: 0, b: 45, c: 0}}
  rob2:
    model: abb_irb2400
    frame: {x: 1100, y: 1100, z: 0, a: -90, b: 0, c: 0}
    tools:
      torch: {number: 1, frame: {x: 300, y: 0, z: 90, a: 0, b: 45, c: 0}}
turntable:
  name: STN1
  parent: world
  frame: {x: 1100, y: 0, z: 650, a: 0, b: 0, c: 0}
  min: -360
  max: 360
frames:
  part:
    number: 1
    parent: turntable
    frame: {x: 0, y: 0, z: 30, a: 0, b: 0, c: 0}
"""


def test_a_turntable_is_chosen_once_for_both_robots(tmp_path):
    """Two fixed robots either side of a turntable, each one's seam 700 mm off the axis on its
    side: one angle per point, the same for both, the turntable's (N,) values."""
    (tmp_path / "cell.yaml").write_text(TURNTABLE_CELL)
    cell = Cell.load(tmp_path / "cell.yaml")
    rob1 = "x,y,z,a,b,c\n" + "".join(f"{x},-700,0,0,0,180\n" for x in range(-100, 101, 40))
    rob2 = "x,y,z,a,b,c\n" + "".join(f"{-x},700,0,0,0,180\n" for x in range(-100, 101, 40))
    paths = _files(tmp_path, rob1=rob1, rob2=rob2)
    result = write_coordinated(paths, cell, TOOLS, "part", "abb", tmp_path / "prog", "seams")
    table = result.results["rob1"].table
    assert table.shape == (6,)
    np.testing.assert_array_equal(table, result.results["rob2"].table)
    for robot in ("rob1", "rob2"):
        seam = read_path(paths[robot], cell.for_robot(robot))
        got, _ = _assert_reached(cell, result.files, robot, seam.T)
        np.testing.assert_allclose(got, table, atol=1e-9)
