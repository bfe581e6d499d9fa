"""YASKAWA jobs of the corpus sweep (tests/data/programs/yaskawa/README.md, "Sweep"): the
constructs real jobs hold that robotcell once read wrongly or passed over without a word are
read as meant, and broken variants of them are refused with one error naming the line."""

from __future__ import annotations

from pathlib import Path

import pytest
from cli_helpers import run

from robotcell.errors import InputError
from robotcell.programs import read_program

DATA = Path(__file__).resolve().parent / "data" / "programs" / "yaskawa"
CELL = DATA / "cell.yaml"
ANGLE = DATA / "excerpts" / "ST2ANGLE.JBI"
JOG = DATA / "excerpts" / "JOGST.JBI"
COMM = DATA / "excerpts" / "COMMOUT.JBI"
TEST1 = DATA / "inform_support" / "TEST1.JBI"
TOOLCHANGE = DATA / "toolchanger" / "TC_FULL_CHANGE.JBI"


def _notes(path: Path) -> dict[int, str]:
    """The notes of a job by their line."""
    _program, notes = read_program(path)
    assert all(n.startswith("line ") for n in notes), notes
    return {int(n.split(":")[0].split()[1]): n for n in notes}


def test_station_positions_in_degrees_are_never_read_as_pulses():
    program, _ = read_program(ANGLE)
    assert program.points == []  # -30.0000 deg is no pulse count: no point carries it
    notes = _notes(ANGLE)
    for line, name in ((37, "MOVJ C00000"), (38, "SMOVL C00001"), (40, "SMOVL C00002"),
                       (44, "SMOVL C00005")):
        assert f"line {line}: {name} (" in notes[line]
        assert "in degrees (///POSTYPE ANGLE)" in notes[line]


def test_a_station_motion_in_degrees_on_the_next_line_takes_the_point_out(tmp_path):
    job = tmp_path / "NEXTLINE.JBI"
    job.write_text(ANGLE.read_text().replace("VJ=50.00  +MOVJ EC00000", "VJ=50.00\n+MOVJ EC00000"))
    program, notes = read_program(job)
    assert program.points == []
    assert notes[0].startswith("line 37: C00000 (the station position EC00000 is in degrees")


def test_the_same_job_with_station_pulses_is_read_point_by_point(tmp_path):
    text = ANGLE.read_text().replace("///POSTYPE ANGLE\n///ANGLE", "///POSTYPE PULSE\n///PULSE")
    pulses = tmp_path / "ST2PULSE.JBI"
    pulses.write_text(text.replace("=-30.0000", "=-3000").replace("=-60.0000", "=-6000"))
    program, notes = read_program(pulses)
    assert [p.name for p in program.points] == ["C00000", "C00001", "C00002", "C00005"]
    assert [p.motion for p in program.points] == ["ptp", "lin", "lin", "lin"]
    assert [p.external["EC1"] for p in program.points] == [-3000, -3000, -3000, -6000]
    assert [p.tool.number for p in program.points] == [1, 1, 1, 1]  # the ///TOOL of the C lines
    assert program.points[1].speed == pytest.approx(0.2) and program.points[2].speed is None
    assert [n.split(" (")[0] for n in notes] == ["line 41: SMOVC C00003", "line 42: SMOVC C00004"]


def test_a_robot_position_after_angle_is_named_not_read_as_cartesian(tmp_path):
    text = ANGLE.read_text().replace("///RECTAN\n", "///ANGLE\n", 1)
    job = tmp_path / "C_ANGLE.JBI"
    job.write_text(text.replace("\n///POSTYPE ANGLE\n///ANGLE\n", "\n///POSTYPE PULSE\n///PULSE\n"))
    program, _ = read_program(job)
    assert program.points == []
    assert "C00000 (a robot position as axis angles (///ANGLE)" in _notes(job)[37]


def test_coordinated_circular_motions_are_named_not_passed_over():
    notes = _notes(ANGLE)
    assert notes[41] == "line 41: SMOVC C00003 (circular and spline motions are not checked)"
    assert notes[42].startswith("line 42: SMOVC C00004 (circular")


def test_incremental_motions_and_station_variables_are_named():
    notes = _notes(JOG)
    assert sorted(notes) == [26, 29, 32]
    assert notes[26].startswith("line 26: IMOV EX010 (an incremental motion")
    assert notes[29].startswith("line 29: IMOV EX011 (an incremental motion")
    assert notes[32] == "line 32: MOVJ EX012 (a position variable, set at run time)"
    program, notes = read_program(TEST1)  # IMOV LP000, as a DX200 job saved it
    assert program.points == [] and len(notes) == 1
    assert notes[0].startswith("line 32: IMOV LP000 (an incremental motion")


def test_a_motion_after_comm_is_named_and_not_read_as_a_motion():
    notes = _notes(COMM)
    assert sorted(notes) == [18, 19, 20, 21, 22]
    assert notes[19].startswith("line 19: COMM MOVJ C00001 VJ=10.00 (a motion after COMM")
    assert notes[21].startswith("line 21: COMM MOVS C00003 V=20.0 (a motion after COMM")
    assert notes[20].startswith("line 20: MOVS C00002 (circular and spline")
    assert "robot pulses" in notes[18] and "robot pulses" in notes[22]


def test_a_controller_job_with_arguments_and_local_variables_is_read():
    program, notes = read_program(TOOLCHANGE)
    assert program.points == [] and len(notes) == 10
    assert notes[0] == ("line 57: MOVJ C00000 (robot pulses: their pulses per degree are not in "
                        "the job)")
    assert notes[1] == "line 65: MOVJ P025 (a position variable, set at run time)"


@pytest.mark.parametrize("path", [ANGLE, JOG, COMM, TEST1, TOOLCHANGE], ids=lambda p: p.name)
def test_the_sweep_files_are_checked_with_every_motion_named(path, capsys):
    code, out, err = run(capsys, "program", "check", path, "--cell", CELL)
    assert code == 0 and "no point checked" in out
    assert err.count("note: not checked: line ") == len(read_program(path)[1])


# -- broken variants: one error naming the cause and the line, exit 2 ---------------------------
def _broken(tmp_path: Path, source: Path, edit) -> Path:
    out = tmp_path / source.name
    out.write_bytes(edit(source.read_bytes()))
    return out


BROKEN = {
    "truncated": (ANGLE, lambda b: b[:700], r"line 31: the job does not end with END"),
    "nan position": (ANGLE, lambda b: b.replace(b"C00001=400.000", b"C00001=nan"),
                     r"line 12: 'nan' is not finite"),
    "nan station angle": (ANGLE, lambda b: b.replace(b"EC00001=-30.0000", b"EC00001=NaN"),
                          r"line 22: 'NaN' is not finite"),
    "non-UTF-8 byte in a position": (
        ANGLE, lambda b: b.replace(b"C00002=380.000", b"C00002=3\xe980.000"), r"line 13: "),
    "UTF-16 file": (TEST1, lambda b: "\ufeff".encode("utf-16-le") + b.decode().encode("utf-16-le"),
                    r"UTF-16"),
    "a position named with 3 digits": (
        COMM, lambda b: b.replace(b"MOVJ C00000", b"MOVJ C000"),
        r"line 18: C000 not in the //POS section \(it holds C00000 to C00004\)"),
    "no //INST": (TEST1, lambda b: b.split(b"//INST")[0],
                  r"no //INST line \(/JOB at line 1, //POS at line 3 only\)"),
}


@pytest.mark.parametrize("case", list(BROKEN))
def test_a_broken_sweep_file_is_refused_with_one_error_naming_the_line(case, tmp_path, capsys):
    source, edit, message = BROKEN[case]
    path = _broken(tmp_path, source, edit)
    with pytest.raises(InputError, match=message):
        read_program(path)
    code, out, err = run(capsys, "program", "check", path, "--cell", CELL)
    assert code == 2 and out == ""
    assert err.count("error:") == 1 and len(err.strip().splitlines()) == 1
    assert "Traceback" not in err and err.startswith(f"error: {path}")
