"""Coordinated programs of several robots: two IRB 2400 welding two seams of one part on a
shared 2-axis positioner, written as ABB MultiMove modules, read back with every point through
Cell.fk to 1e-3 mm, the \\ID structure against the MultiMove manual's rules, clearance of the
robots together, and the inputs refused with nothing written."""

import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.clearance import Body
from robotcell.clearance.bodies import BodiesFile
from robotcell.controllers.abb.multimove import SyncMove, id_problems, sync_moves
from robotcell.errors import InputError
from robotcell.programs.coordcheck import check_coordinated
from robotcell.programs.coordinated import write_coordinated
from robotcell.programs.path import read_path

ROOT = Path(__file__).resolve().parents[1]
CELL = ROOT / "examples" / "cell_two_abb_positioner.yaml"
SEAMS = {"rob1": ROOT / "examples" / "seam_rob1.csv", "rob2": ROOT / "examples" / "seam_rob2.csv"}
TOOLS = {"rob1": "torch", "rob2": "torch"}
MULTIMOVE = ROOT / "tests" / "data" / "programs" / "abb" / "excerpts" / "multimove_t_rob1.mod"


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    cell = Cell.load(CELL)
    folder = tmp_path_factory.mktemp("prog") / "prog"
    return cell, write_coordinated(SEAMS, cell, TOOLS, "part", "abb", folder, "seams")


def test_one_module_per_task_in_the_order_of_the_cells_robots(written):
    _, result = written
    assert [Path(f).name for f in result.files] == ["seams_T_ROB1.mod", "seams_T_ROB2.mod"]
    assert result.robots == ["rob1", "rob2"]
    for f in result.files:
        text = Path(f).read_text()
        assert "VAR syncident sync1;" in text and "VAR syncident sync2;" in text
        assert 'TASK PERS tasks all_tasks{2} := [["T_ROB1"],["T_ROB2"]];' in text
        assert text.count("SyncMoveOn sync1, all_tasks;") == 1
        assert text.count("SyncMoveOff sync2;") == 1
        # the work object is coordinated with the positioner's mechanical unit (MultiMove
        # manual, "Coordinated work objects": robhold FALSE, ufprog FALSE, ufmec the unit)
        assert re.search(r'PERS wobjdata part:=\[FALSE,FALSE,"STN1",', text)
        assert re.search(r"MoveL p2\\ID:=20,v20,fine,torch\\WObj:=part;", text)


def test_every_robots_point_read_back_is_its_seam_through_cell_fk(written):
    cell, result = written
    report = check_coordinated(result.files, cell)
    assert report.good, (report.sync, report.rows())
    for robot, rep in report.reports.items():
        seam = read_path(SEAMS[robot], cell.for_robot(robot))
        q = np.array([p.q for p in rep.points])
        track = np.array([p.track for p in rep.points])
        table = np.array([p.table for p in rep.points], dtype=float)
        T = cell.fk(q, track, table, tool="torch", frame="part", robot=robot)
        assert np.abs(T[:, :3, 3] - seam.T[:, :3, 3]).max() < 1e-6           # 1e-3 mm
        assert np.abs(T[:, :3, :3] - seam.T[:, :3, :3]).max() < 1e-6
        np.testing.assert_allclose(table, read_path(SEAMS["rob1"], cell.for_robot(
            "rob1")).table, atol=1e-9)                  # the positioner given in rob1's file


def test_every_synchronised_move_has_one_partner_with_its_id_in_the_other_task(written):
    """The MultiMove manual's rules, checked on the modules as written: every move between
    SyncMoveOn and SyncMoveOff has \\ID; the tasks execute as many; the same \\ID in the same
    place in every task; no \\ID outside."""
    _, result = written
    moves = [sync_moves(f) for f in result.files]
    assert all(m.synced and m.ident is not None for task in moves for m in task)
    ids = [[m.ident for m in task] for task in moves]
    assert ids[0] == ids[1] == [str(10 * k) for k in range(1, 7)]
    assert len(set(ids[0])) == len(ids[0])
    assert id_problems(dict(zip(result.files, moves))) == []


@pytest.mark.parametrize("edit, match", [
    (lambda t: t.replace("\\ID:=30,", ","), (r"line \d+: MoveL between SyncMoveOn and "
                                             r"SyncMoveOff has no \\ID")),
    (lambda t: t.replace("\\ID:=30,", "\\ID:=35,"), r"\\ID:=35 has no partner in"),
    (lambda t: t.replace("        SyncMoveOn sync1, all_tasks;\n", "").replace(
        "MoveL p2", "SyncMoveOn sync1, all_tasks;\n        MoveL p2"),
     r"MoveJ outside SyncMoveOn .. SyncMoveOff has \\ID:=10"),
    (lambda t: t.replace("        MoveL p6\\ID:=60,v20,fine,torch\\WObj:=part;\n", ""),
     r"different numbers of synchronised moves"),
])
def test_a_broken_id_structure_is_named(written, tmp_path, edit, match):
    cell, result = written
    first, second = (Path(f) for f in result.files)
    broken = tmp_path / second.name
    broken.write_text(edit(second.read_text()))
    report = check_coordinated([first, broken], cell)
    assert not report.good
    assert any(re.search(match, s) for s in report.sync), report.sync


def test_ids_in_another_order_are_named():
    a = [SyncMove(1, "MoveL", "10", True), SyncMove(2, "MoveL", "20", True)]
    b = [SyncMove(1, "MoveL", "20", True), SyncMove(2, "MoveL", "10", True)]
    assert any("is move 1 here and move 2 in b" in s for s in id_problems({"a": a, "b": b}))


def test_a_real_multimove_module_is_read_with_its_ids():
    moves = sync_moves(MULTIMOVE)
    assert [(m.instr, m.ident, m.synced) for m in moves] == [
        ("MoveAbsJ", "0", True), ("MoveJ", "1", True), ("MoveL", "2", True)]
    assert id_problems({"T_ROB1": moves, "T_ROB2": moves}) == []


def test_clearance_of_the_robots_together_names_the_pair(written):
    cell, result = written
    # a post on the world between the seams' torches: clear of 10 mm, but not of 400 mm
    post = Body("post", "cylinder", (0.02, 0.2), "world", np.eye(4))
    post.pose[:3, 3] = [1.1, 0.0, 1.3]
    bodies = BodiesFile((post,), ignore=(("tool", "part"),))
    assert check_coordinated(result.files, cell, bodies=bodies, clearance=0.010).good
    near = check_coordinated(result.files, cell, bodies=bodies, clearance=0.400)
    texts = [row[-1] for row in near.rows()]
    assert texts and all(re.search(r"between rob[12]\.\w+ and (post|rob[12]\.\w+)", t)
                         for t in texts)


def _paths_with(tmp_path, robot, text):
    path = tmp_path / f"{robot}.csv"
    path.write_text(text)
    return {**{r: str(p) for r, p in SEAMS.items()}, robot: str(path)}


@pytest.mark.parametrize("make, vendor, match", [
    (lambda t: _paths_with(t, "rob2", "".join(SEAMS["rob2"].read_text().splitlines(True)[:-1])),
     "abb", r"as many points each.*rob1 6, rob2 5"),
    (lambda t: {**SEAMS, "rob3": SEAMS["rob2"]}, "abb", r"no robot 'rob3'.*rob1, rob2"),
    (lambda t: _paths_with(t, "rob1", SEAMS["rob1"].read_text().replace(",0,10\n", ",0,500\n")),
     "abb", r"line 7: column 'e2' has 500, outside the e2 axis limits \[-400, 400\]"),
    (lambda t: _paths_with(t, "rob2", SEAMS["rob2"].read_text().replace("speed", "speed,e1,e2")
                           .replace(",20\n", ",20,5,0\n")),
     "abb", r"positioner's values differ"),
    (lambda t: SEAMS, "kuka", r"KUKA coordinated programs .* not written.*RoboTeam"),
    (lambda t: SEAMS, "fanuc", r"FANUC coordinated .*frame of the follower.s points"),
    (lambda t: SEAMS, "yaskawa", r"robot\(s\) rob1 on a track: .*base axis"),
])
def test_bad_input_is_refused_and_nothing_is_written(tmp_path, capsys, make, vendor, match):
    cell = Cell.load(CELL)
    paths = make(tmp_path)
    folder = tmp_path / "out"
    with pytest.raises(InputError, match=match):
        write_coordinated(paths, cell, TOOLS, "part", vendor, folder, "seams")
    assert not folder.exists()
    args = [f"{r}={p}" for r, p in paths.items()]
    code, _out, err = run(capsys, "program", "write-coordinated", *args, "--cell", CELL,
                         "--tool", "torch", "--frame", "part", "--format", vendor,
                         "-o", folder)
    assert code == 2 and err.startswith("error: ") and "Traceback" not in err
    assert re.search(match, err.replace("\n", " ")) and not folder.exists()


def test_the_positioner_values_no_file_gives_are_chosen_once_for_both_robots(tmp_path):
    """tests/test_coordinated_paths.py checks the choice in full."""
    cell = Cell.load(CELL)
    bare = tmp_path / "rob1.csv"
    rows = SEAMS["rob1"].read_text().splitlines()
    bare.write_text("\n".join(",".join(r.split(",")[:-2]) for r in rows) + "\n")
    result = write_coordinated({"rob1": bare, "rob2": SEAMS["rob2"]}, cell, TOOLS, "part", "abb",
                               tmp_path / "out")
    np.testing.assert_array_equal(result.results["rob1"].table, result.results["rob2"].table)
    assert check_coordinated(result.files, cell).good


def test_the_command_line_writes_and_checks(tmp_path, capsys):
    folder = tmp_path / "prog"
    code, out, err = run(capsys, "program", "write-coordinated", f"rob1={SEAMS['rob1']}",
                         f"rob2={SEAMS['rob2']}", "--cell", CELL, "--tool", "rob1=torch",
                         "--tool", "rob2=torch", "--frame", "part", "--format", "abb",
                         "-o", folder, "--name", "seams")
    assert code == 0, err
    files = sorted(folder.iterdir())
    assert [f.name for f in files] == ["seams_T_ROB1.mod", "seams_T_ROB2.mod"]
    code, out, err = run(capsys, "program", "check-coordinated", *files, "--cell", CELL)
    assert code == 0 and "2 programs, 12 points, all good" in out
    # the files in the other order, named: each task is checked as the other robot's
    code, out, err = run(capsys, "program", "check-coordinated", files[1], files[0],
                         "--cell", CELL, "--robots", "rob1,rob2")
    assert code == 3 and "rob1" in err
    shutil.copy(files[1], tmp_path / "only.mod")
    code, out, err = run(capsys, "program", "check-coordinated", tmp_path / "only.mod",
                         "--cell", CELL)
    assert code == 2 and "1 program file for 2 robots" in err


def test_a_file_robotcell_did_not_write_is_not_replaced(tmp_path):
    cell = Cell.load(CELL)
    folder = tmp_path / "out"
    folder.mkdir()
    (folder / "seams_T_ROB2.mod").write_text("MODULE mine\nENDMODULE\n")
    with pytest.raises(InputError, match=r"seams_T_ROB2.mod: it is a file robotcell did not "
                                         r"write"):
        write_coordinated(SEAMS, cell, TOOLS, "part", "abb", folder, "seams")
    assert sorted(p.name for p in folder.iterdir()) == ["seams_T_ROB2.mod"]
    (folder / "seams_T_ROB2.mod").unlink()
    first = write_coordinated(SEAMS, cell, TOOLS, "part", "abb", folder, "seams")
    again = write_coordinated(SEAMS, cell, TOOLS, "part", "abb", folder, "seams")
    assert first.files == again.files                     # an earlier program is replaced


def test_checking_programs_of_a_format_whose_coordinated_form_is_not_read_is_refused(
        tmp_path, capsys):
    from robotcell.programs import write_program

    cell = Cell.load(CELL)
    files = []
    for robot in ("rob1", "rob2"):
        seam = read_path(SEAMS[robot], cell.for_robot(robot))
        path = tmp_path / f"{robot}.csv"          # each robot's seam with the positioner given
        text = SEAMS[robot].read_text()
        if "e1" not in text.splitlines()[0]:
            rows = text.splitlines()
            given = SEAMS["rob1"].read_text().splitlines()
            text = "\n".join([rows[0] + ",e1,e2"] + [r + "," + ",".join(g.split(",")[-2:])
                                                    for r, g in zip(rows[1:], given[1:])]) + "\n"
        path.write_text(text)
        assert len(seam) == 6
        files += write_program(path, cell.for_robot(robot), "torch", "part", "kuka",
                               tmp_path / robot).files
    srcs = [f for f in files if f.endswith(".src")]
    with pytest.raises(InputError, match=r"KUKA coordinated programs .* not written or checked"):
        check_coordinated(srcs, cell)
    code, _, err = run(capsys, "program", "check-coordinated", *srcs, "--cell", CELL)
    assert code == 2 and "RoboTeam" in err


@pytest.mark.parametrize("args, match", [
    (["program", "check-coordinated", MULTIMOVE, MULTIMOVE, "--cell", CELL, "--robots",
      "rob1,rob9"], r"no robot 'rob9'"),
    (["program", "write-coordinated", f"rob1={SEAMS['rob1']}", f"rob2={SEAMS['rob2']}",
      "--cell", CELL, "--tool", "rob1=torch", "--tool", "rob2", "--format", "abb", "-o", "x"],
     r"--tool takes ROBOT=VALUE.*'rob2'"),
    (["program", "write-coordinated", f"rob1={SEAMS['rob1']}", "--cell", CELL, "--tool",
      "torch", "--format", "abb", "-o", "x"], r"at least two robots"),
])
def test_bad_command_lines_exit_2_naming_the_cause(tmp_path, capsys, monkeypatch, args, match):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(capsys, *args)
    assert code == 2 and re.search(match, err) and not (tmp_path / "x").exists()
