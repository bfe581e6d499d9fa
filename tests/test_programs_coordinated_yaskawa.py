"""YASKAWA coordinated jobs: two robots welding two seams of one part on a shared 2-axis
station, written as one job of two robot groups (the first robot with the station in group 1,
the second in group 2, as a DX200 saves such jobs: rpiRobotics/dx200_motion_progam_exec,
``example_inform/R1-R2-S1.JBI``), read back with every point of both robots through Cell.fk to
1e-3 mm, the group structure checked against the rules of the real jobs, and the inputs the
form does not hold refused with nothing written."""

import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.controllers.yaskawa.multigroup import group_problems, write_job
from robotcell.controllers.yaskawa.program import read, read_groups
from robotcell.errors import InputError
from robotcell.programs.check import check_program_file
from robotcell.programs.coordcheck import check_coordinated
from robotcell.programs.coordinated import write_coordinated
from robotcell.programs.path import read_path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
CELL = EXAMPLES / "cell_two_yaskawa_positioner.yaml"
SEAMS = {"rob1": EXAMPLES / "seam_rob1_floor.csv", "rob2": EXAMPLES / "seam_rob2.csv"}
TOOLS = {"rob1": "torch", "rob2": "torch"}
PPD = [100.0, 100.0]
EXCERPTS = ROOT / "tests" / "data" / "programs" / "yaskawa" / "excerpts"


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    cell = Cell.load(CELL)
    folder = tmp_path_factory.mktemp("prog") / "prog"
    return cell, write_coordinated(SEAMS, cell, TOOLS, "part", "yaskawa", folder, "seams",
                                   pulses_per_degree=PPD)


def _job(result) -> Path:
    (path,) = result.files
    return Path(path)


def test_one_job_holds_both_robots_in_the_groups_a_dx200_saves(written):
    _, result = written
    assert [Path(f).name for f in result.files] == ["SEAMS.jbi"]
    assert result.robots == ["rob1", "rob2"]
    text = _job(result).read_text()
    lines = text.splitlines()
    assert "///NPOS 12,0,6,0,0,0" in lines            # both robots' C positions, one EC each
    inst = lines[lines.index("//INST"):]
    assert "///GROUP1 RB1,ST1" in inst and "///GROUP2 RB2" in inst
    assert "////FRAME USER 1" in inst and "///ATTR SC,RW,RJ" in inst
    moves = [ln for ln in inst if ln.startswith(("MOVJ", "MOVL"))]
    assert moves[0] == "MOVJ C00000 EC00000 VJ=20.00  +MOVJ C00001 VJ=20.00"
    assert moves[2] == "MOVL C00004 EC00002 V=20.0  +MOVL C00005 V=20.0"
    assert len(moves) == 6


def test_each_robots_position_follows_its_own_tool_and_user_frame(written):
    """Each robot's C position after its own ///TOOL (the torch is tool 1 of rob1 and tool 2 of
    rob2 in the cell), as the pendant writes ///TOOL before each robot's position."""
    _, result = written
    lines = _job(result).read_text().splitlines()
    for k in range(12):
        at = next(i for i, ln in enumerate(lines) if ln.startswith(f"C{k:05d}="))
        block = lines[at - 5:at]
        tool = [ln for ln in block if ln.startswith("///TOOL")][-1]
        assert tool == f"///TOOL {1 + k % 2}"
        assert "///USER 1" in block and any(ln.startswith("///RCONF ") for ln in block)


def test_every_robots_point_read_back_is_its_seam_through_cell_fk(written):
    cell, result = written
    report = check_coordinated(result.files, cell, pulses_per_degree=PPD)
    assert report.good, (report.sync, report.rows())
    assert list(report.reports) == ["rob1", "rob2"]
    table_given = read_path(SEAMS["rob1"], cell.for_robot("rob1")).table
    for robot, rep in report.reports.items():
        assert not rep.skipped and len(rep.points) == 6
        seam = read_path(SEAMS[robot], cell.for_robot(robot))
        q = np.array([p.q for p in rep.points])
        table = np.array([p.table for p in rep.points], dtype=float)
        T = cell.fk(q, table=table, tool="torch", frame="part", robot=robot)
        assert np.abs(T[:, :3, 3] - seam.T[:, :3, 3]).max() < 1e-6           # 1e-3 mm
        assert np.abs(T[:, :3, :3] - seam.T[:, :3, :3]).max() < 1e-5
        np.testing.assert_allclose(table, table_given, atol=1e-9)  # one EC per line, shared


def test_the_written_job_keeps_the_rules_of_the_real_jobs(written):
    _, result = written
    assert group_problems(_job(result)) == []
    first, second = read_groups(_job(result))
    assert [p.name for p in first[0].points] == [f"C{k:05d}" for k in range(0, 12, 2)]
    assert [p.name for p in second[0].points] == [f"C{k:05d}" for k in range(1, 12, 2)]
    assert [p.tool.number for p in second[0].points] == [2] * 6
    assert [p.external for p in first[0].points] == [p.external for p in second[0].points]


def test_a_single_robot_check_reads_group_1_and_names_group_2_not_checked(written):
    cell, result = written
    report = check_program_file(_job(result), cell.for_robot("rob1"), PPD)
    assert report.good and len(report.points) == 6
    assert len(report.skipped) == 6
    assert report.skipped[0].endswith("+MOVJ C00001 (the second robot's point, group 2: "
                                      "checked with the job as a coordinated program)")


def _broken(tmp_path: Path, result, old: str, new: str) -> Path:
    text = _job(result).read_text()
    assert old in text
    path = tmp_path / "BROKEN.jbi"
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.parametrize("old, new, match", [
    ("  +MOVL C00003 V=20.0", "",
     r"line \d+: MOVL C00002 EC00001 V=20.0: no \+MOVJ/\+MOVL of group 2 \(RB2\) on the line"),
    ("+MOVL C00003 V=20.0", "+MOVL V=20.0",
     r"line \d+: MOVL C00002 EC00001 V=20.0: its \+MOVL names no position of group 2's robot"),
    ("///GROUP2 RB2", "///GROUP2 ST1",
     (r"declares ///GROUP1 RB1,ST1, ///GROUP2 ST1; a job of two robots declares ///GROUP1 "
      r"RB1,ST1 .* and ///GROUP2 RB2")),
    ("///GROUP1 RB1,ST1\n///GROUP2 RB2", "///GROUP1 RB2\n///GROUP2 RB1,ST1",
     r"declares ///GROUP1 RB2, ///GROUP2 RB1,ST1"),
    ("MOVL C00004 EC00002 V=20.0", "MOVL C00004 V=20.0",
     r"line \d+: MOVL C00004 V=20.0: group 1 \(RB1,ST1\) names no station position"),
    ("+MOVL C00005 V=20.0", "+MOVL C00005 EC00002 V=20.0",
     r"moves the station in group 2; it is in group 1"),
])
def test_a_broken_group_structure_is_named(written, tmp_path, capsys, old, new, match):
    cell, result = written
    path = _broken(tmp_path, result, old, new)
    report = check_coordinated([path], cell, pulses_per_degree=PPD)
    assert not report.good
    assert any(re.search(match, s) for s in report.sync), report.sync
    code, _out, err = run(capsys, "program", "check-coordinated", path, "--cell", CELL,
                          "--pulses-per-degree", "100,100")
    assert code == 3 and "Traceback" not in err
    assert re.search(match, err.replace("\n", " "))


def test_a_group_2_position_missing_from_pos_is_refused(written, tmp_path, capsys):
    cell, result = written
    text = _job(result).read_text()
    line = next(ln for ln in text.splitlines() if ln.startswith("C00003="))
    path = _broken(tmp_path, result, line + "\n", "")
    with pytest.raises(InputError, match=r"line \d+: C00003 not in the //POS section"):
        check_coordinated([path], cell, pulses_per_degree=PPD)
    code, _out, err = run(capsys, "program", "check-coordinated", path, "--cell", CELL,
                          "--pulses-per-degree", "100,100")
    assert code == 2 and err.startswith("error: ") and "C00003 not in the //POS" in err


@pytest.mark.parametrize("old, new", [
    ("C00003=49.218,", "C00003=٤٩.218,"),      # digits of another script: read as 49 by float
    ("EC00002=0,-200", "EC00002=0,-2_00"),       # digit grouping: read as -200 by float
])
def test_a_number_no_controller_writes_is_refused_naming_the_line(written, tmp_path, capsys,
                                                                   old, new):
    cell, result = written
    path = _broken(tmp_path, result, old, new)
    bad = new.split("=")[1].split(",")[0 if new.startswith("C") else 1]
    with pytest.raises(InputError, match=rf"BROKEN\.jbi: line \d+: '{bad}' is not a number"):
        check_coordinated([path], cell, pulses_per_degree=PPD)
    code, out, err = run(capsys, "program", "check-coordinated", path, "--cell", CELL,
                         "--pulses-per-degree", "100,100")
    assert code == 2 and out == "" and err.startswith("error: ") and err.count("\n") == 1, err
    assert f"'{bad}' is not a number (digits 0-9" in err


def test_the_real_jobs_give_their_structure_and_name_their_pulse_positions():
    first, second = read_groups(EXCERPTS / "R1R2S1.JBI")
    assert group_problems(EXCERPTS / "R1R2S1.JBI") == []
    assert not first[0].points and not second[0].points  # pulse positions and variables
    assert first[1][:2] == [
        "line 32: MOVJ C00000 (robot pulses: their pulses per degree are not in the job)",
        "line 33: MOVL C00002 (robot pulses: their pulses per degree are not in the job)"]
    assert second[1] == [
        "line 32: MOVJ C00001 (robot pulses: their pulses per degree are not in the job)",
        "line 33: MOVL C00003 (robot pulses: their pulses per degree are not in the job)",
        "line 34: MOVJ P001 (a position variable, set at run time)"]
    _, alone = read(EXCERPTS / "R1R2S1.JBI")
    assert "line 32: +MOVJ C00001 (the second robot's point, group 2: checked with the job as " \
           "a coordinated program)" in alone
    # jobs of one robot and the station are not jobs of two robots, and say why
    smov = group_problems(EXCERPTS / "R1S1SMOV.JBI")
    assert "///GROUP1 RB1, ///GROUP2 ST1" in smov[0]
    assert any("line 22: SMOVL C00002 V=11.0: its +MOVJ names no position of group 2" in p
               for p in smov)
    noncoord = group_problems(EXCERPTS / "R1S1ST1.JBI")
    assert any("line 17: MOVJ C00000 EC00000 VJ=0.78: no +MOVJ/+MOVL of group 2" in p
               for p in noncoord)


def test_the_real_job_is_checked_as_a_coordinated_program_with_nothing_to_check():
    cell = Cell.load(CELL)
    report = check_coordinated([EXCERPTS / "R1R2S1.JBI"], cell)
    assert report.sync == []
    assert [len(r.points) for r in report.reports.values()] == [0, 0]
    assert all(r.skipped for r in report.reports.values())


def _three_robots(tmp_path: Path) -> Path:
    text = CELL.read_text().replace("positioner:\n", (
        "  rob3:\n    model: abb_irb2400\n    frame: {x: 2600, y: 0, z: 0, a: 180, b: 0, c: 0}\n"
        "    tools:\n      torch:\n        number: 1\n"
        "        frame: {x: 300, y: 0, z: 90, a: 0, b: 45, c: 0}\n"
        "        provenance: {source: nominal}\npositioner:\n"), 1)
    path = tmp_path / "three.yaml"
    path.write_text(text)
    return path


def _shorter(tmp_path: Path) -> Path:
    path = tmp_path / "short.csv"
    path.write_text("".join(SEAMS["rob2"].read_text().splitlines(True)[:-1]))
    return path


@pytest.mark.parametrize("cell_of, paths_of, ppd, match", [
    (_three_robots, lambda t: {**SEAMS, "rob3": SEAMS["rob2"]}, PPD,
     r"a YASKAWA coordinated job holds two robots .*got 3"),
    (lambda t: EXAMPLES / "cell_two_abb_positioner.yaml",
     lambda t: {"rob1": EXAMPLES / "seam_rob1.csv", "rob2": SEAMS["rob2"]}, PPD,
     r"robot\(s\) rob1 on a track: .*base axis \(BS1, BC positions\)"),
    (lambda t: CELL, lambda t: {"rob1": SEAMS["rob1"], "rob2": _shorter(t)}, PPD,
     r"as many points each.*rob1 6, rob2 5"),
    (lambda t: CELL, lambda t: {**SEAMS, "rob9": SEAMS["rob2"]}, PPD,
     r"no robot 'rob9'.*rob1, rob2"),
    (lambda t: CELL, lambda t: SEAMS, None,
     r"station axes in encoder pulses: give pulses_per_degree"),
])
def test_what_the_job_cannot_hold_is_refused_and_nothing_is_written(tmp_path, capsys, cell_of,
                                                                     paths_of, ppd, match):
    cell_path, paths = cell_of(tmp_path), paths_of(tmp_path)
    cell = Cell.load(cell_path)
    folder = tmp_path / "out"
    tools = dict.fromkeys(paths, "torch")
    with pytest.raises(InputError, match=match):
        write_coordinated(paths, cell, tools, "part", "yaskawa", folder, "seams",
                          pulses_per_degree=ppd)
    assert not folder.exists()
    args = [f"{r}={p}" for r, p in paths.items()]
    ppd_args = ["--pulses-per-degree", "100,100"] if ppd else []
    code, _out, err = run(capsys, "program", "write-coordinated", *args, "--cell", cell_path,
                          "--tool", "torch", "--frame", "part", "--format", "yaskawa",
                          "-o", folder, *ppd_args)
    assert code == 2 and err.startswith("error: ") and err.count("error:") == 1
    assert "Traceback" not in err and not folder.exists()
    cli_match = match.replace("pulses_per_degree", "--pulses-per-degree")
    assert re.search(cli_match, err.replace("\n", " ")), err


def test_the_writer_refuses_programs_the_job_cannot_hold(written):
    _, result = written
    programs = [result.results[r].programs[0] for r in result.robots]
    with pytest.raises(InputError, match=r"holds two robots .*got 3"):
        write_job([*programs, programs[1]], [])
    with pytest.raises(InputError, match=r"as many points each"):
        write_job([programs[0], type(programs[1])(programs[1].name, "yaskawa",
                                                  programs[1].points[:-1])], [])


def test_a_coordinated_job_is_one_file_and_its_check_refuses_more(written, tmp_path, capsys):
    cell, result = written
    with pytest.raises(InputError, match=r"2 program files: a YASKAWA coordinated program is "
                                         r"one file for all robots"):
        check_coordinated([_job(result), _job(result)], cell, pulses_per_degree=PPD)
    with pytest.raises(InputError, match=r"holds two robots, group 1's and group 2's; got 1: "
                                         r"name the two robots"):
        check_coordinated([_job(result)], cell, robots=["rob1"], pulses_per_degree=PPD)
    code, _out, err = run(capsys, "program", "check-coordinated", _job(result), _job(result),
                          "--cell", CELL, "--pulses-per-degree", "100,100")
    assert code == 2 and err.startswith("error: 2 program files: a YASKAWA coordinated program")


def test_the_command_line_writes_and_checks_the_job(tmp_path, capsys):
    folder = tmp_path / "prog"
    args = [f"{r}={p}" for r, p in SEAMS.items()]
    code, out, err = run(capsys, "program", "write-coordinated", *args, "--cell", CELL,
                         "--tool", "torch", "--frame", "part", "--format", "yaskawa",
                         "-o", folder, "--name", "seams", "--pulses-per-degree", "100,100")
    assert code == 0, err
    assert out.strip() == f"wrote {folder / 'SEAMS.jbi'}"
    code, out, err = run(capsys, "program", "check-coordinated", folder / "SEAMS.jbi",
                         "--cell", CELL, "--pulses-per-degree", "100,100")
    assert code == 0, err
    assert "2 programs, 12 points, all good" in out
    # written again over its own earlier job (the header's comment lines wrap at 32 characters)
    code, _out, err = run(capsys, "program", "write-coordinated", *args, "--cell", CELL,
                          "--tool", "torch", "--frame", "part", "--format", "yaskawa",
                          "-o", folder, "--name", "seams", "--pulses-per-degree", "100,100")
    assert code == 0, err


def test_a_cell_without_a_station_writes_group_1_as_the_first_robot_alone(tmp_path):
    """The part fixed where the station holds it at 0: ///GROUP1 RB1, ///GROUP2 RB2 (as the
    job writer run on the DX200 writes them for two robots), no EC, read back through
    Cell.fk."""
    text = CELL.read_text()
    text = text[:text.index("positioner:\n")] + (
        "frames:\n  part:\n    number: 1\n    parent: world\n"
        "    frame: {x: 1100, y: 0, z: 830, a: 180, b: 0, c: 0}\n"
        "    provenance: {source: nominal}\n")
    (tmp_path / "cell.yaml").write_text(text)
    cell = Cell.load(tmp_path / "cell.yaml")
    paths = {}
    for robot, seam in SEAMS.items():
        rows = [ln.split(",")[:8] for ln in seam.read_text().splitlines()]
        paths[robot] = tmp_path / f"{robot}.csv"
        paths[robot].write_text("\n".join(",".join(r) for r in rows) + "\n")
    result = write_coordinated(paths, cell, TOOLS, "part", "yaskawa", tmp_path / "out", "seams")
    lines = _job(result).read_text().splitlines()
    assert "///GROUP1 RB1" in lines and "///GROUP2 RB2" in lines
    assert "///NPOS 12,0,0,0,0,0" in lines and not any(ln.startswith("EC") for ln in lines)
    assert "MOVJ C00000 VJ=20.00  +MOVJ C00001 VJ=20.00" in lines
    report = check_coordinated(result.files, cell)
    assert report.good, (report.sync, report.rows())
    for robot, rep in report.reports.items():
        q = np.array([p.q for p in rep.points])
        T = cell.fk(q, tool="torch", frame="part", robot=robot)
        want = read_path(paths[robot], cell.for_robot(robot)).T
        assert np.abs(T[:, :3, 3] - want[:, :3, 3]).max() < 1e-6
