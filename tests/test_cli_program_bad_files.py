"""Bad files and options for ``robotcell program write|check|retarget``: every run ends with a
documented status (0, 2 with one ``error:`` line naming the cause, 3 for a path that cannot be
one program or bad points), never 1 or a traceback, and a refused run writes nothing."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from programs_helpers import CELL, EXT, SEAM, mutated_program, outcome_problems, write_mutation
from test_cli_fuzz import mutate_csv

from robotcell.cell import Cell
from robotcell.programs import write_program

SEED = 2019


def _check(code: int, out: str, err: str, match: str, code_wanted: int = 2) -> None:
    assert "Traceback" not in out + err
    assert code == code_wanted, err
    assert err.count("error:") == 1 and match.lower() in err.lower(), err


def _write_args(path, out, vendor="kuka", *extra):
    return ["program", "write", path, "--cell", CELL, "--tool", "torch", "--frame", "part",
            "--format", vendor, "-o", out, "--pulses-per-degree", "100", *extra]


@pytest.mark.parametrize("content,match", [
    ("x,y,z,a,b\n0,0,0,0,0\n", "missing column(s) c"),
    (SEAM.read_text().replace("\n197.0,", "\nabc,", 1), "must be numeric"),
    ("", "header line and at least one data line"),
    (SEAM.read_text().encode("utf-16"), "UTF-16"),
    (bytes(range(256)) * 2, "not a text file"),
])
def test_a_bad_path_file_exits_2_and_writes_nothing(tmp_path, capsys, content, match):
    path = tmp_path / "p.csv"
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    code, out, err = run(capsys, *_write_args(path, tmp_path / "out"))
    _check(code, out, err, match)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("extra,match", [
    (["--tool", "gripper"], "tool 'gripper' is not in the cell"),
    (["--frame", "wall"], "frame 'wall' is not in the cell"),
    (["--name", "9lives"], "is not valid for KUKA: a letter"),
    (["--pulses-per-degree", "abc"], "--pulses-per-degree must be comma-separated numbers"),
])
def test_bad_options_exit_2_naming_the_option(tmp_path, capsys, extra, match):
    code, out, err = run(capsys, *_write_args(SEAM, tmp_path / "out", "kuka", *extra))
    _check(code, out, err, match)
    assert not (tmp_path / "out").exists()


def test_yaskawa_without_pulses_per_degree_names_the_option(tmp_path, capsys):
    args = ["program", "write", SEAM, "--cell", CELL, "--tool", "torch", "--frame", "part",
            "--format", "yaskawa", "-o", tmp_path / "out"]
    code, out, err = run(capsys, *args)
    _check(code, out, err, "give --pulses-per-degree")


def test_an_output_folder_that_is_a_file_or_has_no_parent(tmp_path, capsys):
    (tmp_path / "f").write_text("x")
    code, out, err = run(capsys, *_write_args(SEAM, tmp_path / "f"))
    _check(code, out, err, "is a file")
    code, out, err = run(capsys, *_write_args(SEAM, tmp_path / "none" / "out"))
    _check(code, out, err, "does not exist")


@pytest.mark.parametrize("name,match", [
    ("prog.txt", "unknown program file type '.txt'"),
    ("missing.src", "does not exist"),
])
def test_check_of_a_file_it_cannot_read(tmp_path, capsys, name, match):
    if name.endswith(".txt"):
        (tmp_path / name).write_text("PTP P1\n")
    code, out, err = run(capsys, "program", "check", tmp_path / name, "--cell", CELL)
    _check(code, out, err, match)


@pytest.fixture(scope="module")
def programs(tmp_path_factory) -> dict[str, Path]:
    cell = Cell.load(CELL)
    d = tmp_path_factory.mktemp("programs")
    out = {}
    for vendor, ext in EXT.items():
        result = write_program(SEAM, cell, "torch", "part", vendor, d / vendor,
                               pulses_per_degree=100 if vendor == "yaskawa" else None)
        out[vendor] = Path(next(f for f in result.files if f.endswith(ext)))
    return out


@pytest.mark.parametrize("vendor,old,new,match", [
    ("kuka", ",S 4,", ",S 1e300,", "'1e300' is not a status or turn value"),
    ("kuka", ",S 4,", ",S 'B1111111111111111111111111111111111111111111111111111111',",
     "is not a status or turn value"),
    ("kuka", r",Z [-0-9.]+,", ",Z 1e300,", "is beyond 1e+15 in size, which no value of a program is"),
    ("fanuc", r", 0, 0, 0'", ", 0, 99999999999999999999999, 0'",
     "a turn number that large is a typing error"),
])
def test_huge_numbers_in_a_program_are_refused_naming_the_line(tmp_path, capsys, programs,
                                                              vendor, old, new, match):
    # an integer beyond what numpy holds made the check fail with OverflowError (exit 1), a
    # length of 1e300 mm with numpy overflow warnings in the IK
    src = programs[vendor]
    for f in src.parent.iterdir():
        (tmp_path / f.name).write_bytes(f.read_bytes())
    target = tmp_path / (src.with_suffix(".dat").name if vendor == "kuka" else src.name)
    text = target.read_text()
    assert re.search(old, text)
    target.write_text(re.sub(old, lambda _: new, text, count=1))
    code, out, err = run(capsys, "program", "check", tmp_path / src.name, "--cell", CELL)
    _check(code, out, err, match)
    assert f"{target.name}: line " in err and "Warning" not in err


def test_fuzz_mutated_paths_and_programs(tmp_path, capsys, programs):
    """Seeded mutations of a valid path file (write) and of valid programs of every format
    (check, retarget): documented exit statuses only, no traceback, nothing left on refusal."""
    rng = np.random.default_rng(SEED)
    failures, codes = [], {}
    for k in range(60):
        vendor = str(rng.choice(list(EXT)))
        out = tmp_path / f"out{k}"
        if k % 3 == 0:
            content, what = mutate_csv(SEAM.read_text(), rng)
            path = tmp_path / f"path{k}.csv"
            write_mutation(path, content)
            args = _write_args(path, out, vendor)
        else:
            src = programs[vendor]
            case = tmp_path / f"case{k}"
            what = mutated_program(src, case, rng)
            args = (["program", "check", case / src.name, "--cell", CELL,
                     "--pulses-per-degree", "100"] if k % 3 == 1 else
                    ["program", "retarget", case / src.name, "--from", CELL, "--to", CELL,
                     "-o", out, "--pulses-per-degree", "100"])
        code, stdout, err = run(capsys, *args)
        codes[code] = codes.get(code, 0) + 1
        problems = outcome_problems(code, stdout, err, out.exists() and any(out.iterdir()))
        if problems:
            failures.append(f"case {k} ({vendor}, {what}): {', '.join(problems)}; "
                            f"{' '.join(map(str, args))}\n  {err.strip()[-300:]}")
    assert not failures, "\n".join(failures[:6])
    assert codes.get(0, 0) > 0 and codes.get(2, 0) > 0, codes


@pytest.mark.parametrize("vendor,old,new,match", [
    ("kuka", "Y 0.000000,Z", "Y 1e300,Z", "1e300 is beyond 1e+15 in size"),
    ("kuka", "S 4,T", "S 1e300,T", "is not a status or turn value"),
    ("abb", "[-2,-2,-1,3]", "[-2,-2,-1,1e300]", "1e300 is beyond 1e+15 in size"),
    ("fanuc", "Y =", "Y = 1e300  mm, Q =", "1e300 is beyond 1e+15 in size"),
    ("fanuc", "'N D T, 0,", "'N D T, 99999999999999999999,", "a turn number that large"),
])
def test_absurd_values_in_a_program_are_refused_naming_the_line(tmp_path, capsys, programs,
                                                                vendor, old, new, match):
    # values a controller cannot hold: refused where they are read, not an overflow later
    src = programs[vendor]
    for f in src.parent.iterdir():
        text = f.read_text()
        (tmp_path / f.name).write_text(text.replace(old, new, 1) if old in text else text)
    code, out, err = run(capsys, "program", "check", tmp_path / src.name, "--cell", CELL)
    _check(code, out, err, match)
    assert "line" in err


def test_a_path_no_point_of_which_is_reachable_has_nothing_to_split(tmp_path, capsys):
    # it said "... or write 0 programs, one per piece, with --split", and --split wrote nothing
    # with exit 0
    path = tmp_path / "far.csv"
    path.write_text("x,y,z,a,b,c\n5000,5000,5000,0,180,0\n5100,5000,5000,0,180,0\n")
    for extra in ([], ["--split"]):
        code, out, err = run(capsys, *_write_args(path, tmp_path / "out", "kuka", *extra))
        _check(code, out, err, "no point of the path can be reached", 3)
        assert "nothing to write" in err and "0 programs" not in err
        assert not (tmp_path / "out").exists()


def test_a_path_of_one_point_is_a_program_of_one_point(tmp_path, capsys):
    # it was refused with "a path needs a sequence of at least 2 targets (shape (N, 4, 4) ...)"
    path = tmp_path / "one.csv"
    path.write_text("x,y,z,a,b,c,table\n200,0,0,0,180,0,200\n")
    for vendor in EXT:
        code, out, err = run(capsys, *_write_args(path, tmp_path / vendor, vendor))
        assert code == 0, err
        main = next(p for p in (tmp_path / vendor).iterdir() if p.suffix == EXT[vendor])
        code, out, err = run(capsys, "program", "check", main, "--cell", CELL,
                             "--pulses-per-degree", "100")
        assert code == 0 and out.endswith(": 1 point, all good\n"), err


def test_a_path_that_breaks_at_many_points_names_the_first_5(tmp_path, capsys):
    # the seam in the fixed frame 'fixture': flips and points out of reach; with --split it was
    # refused (exit 2, "no arm configuration follows the whole path") because a piece was
    # solved with another track than the one it was split with
    args = ["program", "write", SEAM, "--cell", CELL, "--tool", "torch", "--frame", "fixture",
            "--format", "kuka", "-o", tmp_path / "out"]
    code, out, err = run(capsys, *args)
    _check(code, out, err, "breaks at 10 points:", 3)
    message = err[err.index("error:"):]
    assert message.count("(singularity)") + message.count("(reach)") == 5
    assert "; and 5 more." in message and "--split" in message
    assert "no other configuration reaches it nearer to target 3" in message
    code, out, err = run(capsys, *args, "--split")
    assert code == 0, err
    written = [p for p in (tmp_path / "out").iterdir() if p.suffix == ".src"]
    assert len(written) == 7
    for src in written:
        assert run(capsys, "program", "check", src, "--cell", CELL)[0] == 0


def test_retarget_refuses_two_different_cells_and_a_program_without_points(tmp_path, capsys,
                                                                           programs):
    # another cell wrote a copy of the program with exit 0
    positioner = CELL.parent / "cell_kr16_positioner.yaml"
    code, out, err = run(capsys, "program", "retarget", programs["kuka"], "--from", CELL,
                         "--to", positioner, "-o", tmp_path / "a")
    _check(code, out, err, "the old and the new cell are not one cell before and after a "
                           "recalibration: the old cell has a track, the new cell no track; the "
                           "old cell has a turntable, the new cell a 2-axis positioner")
    (tmp_path / "empty.src").write_text("DEF empty( )\nEND\n")
    code, out, err = run(capsys, "program", "retarget", tmp_path / "empty.src", "--from", CELL,
                         "--to", CELL, "-o", tmp_path / "b")
    _check(code, out, err, "the program moves to no point robotcell reads: nothing to retarget")
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


def test_a_robot_model_file_given_as_the_cell_is_named_so(tmp_path, capsys, programs):
    # it said "key '' has unknown key(s) ['convention', ...]"
    model = tmp_path / "arm.yaml"
    model.write_text("name: arm\nconvention: standard\njoints: []\n")
    code, out, err = run(capsys, "program", "check", programs["kuka"], "--cell", model)
    _check(code, out, err, "this is a robot model file (it has 'joints'), not a cell file")
    (tmp_path / "c.yaml").write_text("robot: {model: kuka_kr16}\nspeed: 3\n")
    code, out, err = run(capsys, "program", "check", programs["kuka"], "--cell", tmp_path / "c.yaml")
    _check(code, out, err, "the top level has unknown key(s) ['speed']")
