"""FANUC listings as controllers, backups and other tools save them (tests/data/programs/fanuc/,
sources in its README.md): the constructs a sweep of public listings found are read as meant,
named as not checked with their reason, or refused naming the cause and the line."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.controllers.fanuc import FANUC as FANUC_CTL
from robotcell.controllers.model import Config
from robotcell.errors import InputError
from robotcell.programs import read_program

FANUC = Path(__file__).resolve().parent / "data" / "programs" / "fanuc"
CELL = FANUC / "cell.yaml"
NUT = Config("fanuc", (0, 0, 0, 0, 0, 0))


def test_unnumbered_lines_of_a_backup_are_read_as_motions():
    program, notes = read_program(FANUC / "excerpts" / "unnumbered.ls")
    assert [(p.name, p.line, p.motion) for p in program.points] == [
        ("P[1]", 29, "ptp"), ("P[2]", 32, "lin"), ("P[3]", 34, "lin")]
    assert [p.speed for p in program.points] == [None, pytest.approx(0.25), pytest.approx(1.0)]
    assert np.allclose(program.points[1].pose[:3, 3], [1.0, 0.15, 0.4])
    assert all(p.config == NUT for p in program.points)
    assert notes == ["line 28: J PR[49] (a position register, not held by the program)"]


def test_a_listing_saved_in_german_reads_konfig_mm_per_sek_and_wkz_offset():
    program, notes = read_program(FANUC / "excerpts" / "german.ls")  # Latin-1, DEFAULT_GRUP
    assert [(p.name, p.line) for p in program.points] == [
        ("P[1]", 25), ("P[2]", 28), ("P[2]", 30), ("P[1]", 31)]
    assert all(p.config == NUT for p in program.points)  # KONFIG : 'N U T, 0, 0, 0'
    assert [p.speed for p in program.points] == [
        None, pytest.approx(1.5), None, pytest.approx(0.2)]  # 1500mm/sek, max_Geschw., 200mm/sek
    assert notes == [("line 29: J P[3] (WKZ_Offset, PR[11]: the position is offset at run time "
                      "by data not in the program)")]


def test_a_pose_written_back_into_a_german_listing_rewrites_its_konfig():
    lines = (FANUC / "excerpts" / "german.ls").read_text(encoding="latin-1").splitlines()
    idx = lines.index("P[2]{")
    T = np.eye(4)
    T[:3, 3] = [1.0, 0.2, 0.4]
    assert FANUC_CTL.set_pose(lines, idx, T, Config("fanuc", (1, 0, 0, 0, 0, 1)))
    assert "KONFIG : 'F U T, 0, 0, 1'" in lines[idx + 2]
    assert [float(v) for v in re.findall(r"[XYZ] =\s*(\S+)\s*mm", lines[idx + 3])] == [
        1000.0, 200.0, 400.0]


def test_a_position_not_recorded_is_named_not_refused():
    program, notes = read_program(FANUC / "excerpts" / "untaught.ls")
    assert [p.name for p in program.points] == ["P[2]"]
    assert notes == [("line 24: L P[1] (P[1] is not recorded: its values are ******** in the "
                      "listing)")]


def test_positions_written_as_rx_to_rr_are_named_and_joint_positions_beside_them_read():
    program, notes = read_program(FANUC / "excerpts" / "rx_position.ls")
    assert [n.split(" (")[0] for n in notes] == ["line 25: J P[1]", "line 27: L P[2]"]
    assert all("RX, RY, RZ, RW, RP, RR" in n for n in notes)
    [p3] = program.points
    assert p3.name == "P[3]" and np.allclose(np.degrees(p3.joints), [-10, 5, -20, 0, -60, 15])
    assert p3.external == {"GP2:J1": 200.0}


def test_a_macro_to_a_register_by_argument_and_to_an_unset_position_is_named():
    program, notes = read_program(FANUC / "excerpts" / "gun_macro.ls")
    assert program.name == "GUNMACRO" and not program.points
    assert notes == ["line 29: L PR[AR[2]] (a position register, not held by the program)",
                     "line 32: L P[...] (the position number is not set)"]


def test_a_program_moving_only_group_2_moves_no_arm_of_group_1():
    program, notes = read_program(FANUC / "rpi_motion_program_exec" / "TMPB.LS")
    assert not program.points
    assert [n.split(" (")[0] for n in notes] == ["line 7: J P[1]", "line 8: L P[2]",
                                                 "line 9: L P[3]"]
    assert all("holds no group 1 data, only GP2" in n for n in notes)


def test_the_cartesian_position_of_a_second_arm_in_group_2_is_no_table_axis():
    program, notes = read_program(FANUC / "rpi_motion_program_exec" / "EXAMPLE_COOR.LS")
    [p2] = program.points
    assert p2.name == "P[2]" and p2.external == {}
    assert np.allclose(p2.pose[:3, 3], [0.990695, 0.433558, 0.948275])
    assert notes[:2] == [f"P[{n}]: its GP2 data are not used: a Cartesian position (X, Y, Z, W, "
                         "P, R) of another arm, not the axes of a table" for n in (1, 2)]
    assert notes[2].startswith("line 22: L P[1] (COORD:")


def test_frames_set_from_registers_with_comments_and_negative_values_in_parentheses():
    program, notes = read_program(FANUC / "excerpts" / "tooldata.ls")
    assert not notes and [p.name for p in program.points] == ["P[1]", "P[2]"]
    tool, frame = program.points[0].tool, program.points[0].frame
    assert (tool.number, frame.number) == (1, 2)  # UTOOL[1:GUN]=PR[16], UFRAME[2:FIXTURE]=PR[16]
    assert np.allclose(tool.pose[:3, 3], [-0.0005, 0.0125, 0.21025])  # PR[16,1]=(-.5) ...
    assert np.allclose(frame.pose[:3, 3], [0.8, -0.3005, -0.02])
    assert np.allclose(frame.pose[:3, :3], [[0, 1, 0], [-1, 0, 0], [0, 0, 1]], atol=1e-12)


def test_registers_chosen_at_run_time_are_named_with_the_frame_set_from_one():
    program, notes = read_program(FANUC / "excerpts" / "indirect.ls")
    assert [(p.name, p.line, p.frame.number) for p in program.points] == [
        ("P[1]", 30, 0), ("P[1]", 38, 0)]
    assert notes == [
        "line 31: L PR[R[98]] (a position register, not held by the program)",
        "line 35: J PR[R[95]] (a position register, not held by the program)",
        ("line 36: L P[2] (UFRAME[21] is set at line 33 from PR[R[99]], whose values are set "
         "at run time)")]


def test_a_controller_report_saved_as_ls_is_refused_naming_its_first_line(tmp_path, capsys):
    report = tmp_path / "ERRALL.LS"
    report.write_text("ERRALL.LS      Robot Name ROBOT 27-MAY-25 18:35     \n\n"
                      '417" 27-MAY-25 18:34 " MEMO-015 Program already exists  " WARN\n')
    with pytest.raises(InputError, match=r"ERRALL.LS: line 1: no /PROG line: not a FANUC TP "
                                         r"listing \(it starts 'ERRALL.LS +Robot Name"):
        read_program(report)
    code, out, err = run(capsys, "program", "check", report, "--cell", CELL)
    assert code == 2 and err.count("error:") == 1 and err.startswith("error:")
    assert "Traceback" not in out + err


def _variant(tmp_path: Path, name: str, data: bytes) -> Path:
    path = tmp_path / name
    path.write_bytes(data)
    return path


@pytest.mark.parametrize("source", ["excerpts/unnumbered.ls", "excerpts/german.ls",
                                    "excerpts/untaught.ls", "excerpts/tooldata.ls",
                                    "rpi_motion_program_exec/TMPB.LS"])
def test_broken_variants_of_the_new_files_are_refused_in_one_error_line(tmp_path, capsys, source):
    data = (FANUC / source).read_bytes()
    end = data.index(b"/END")
    cases = {
        "truncated.ls": (data[:end - 12], r"line \d+: (no /END|P\[\d+\] is not closed)"),
        "half.ls": (data[:data.index(b"/MN")], r"line \d+: no /MN line \(truncated file\?\)"),
        "utf16.ls": (data.decode("latin-1").encode("utf-16"), "UTF-16"),
        "nan.ls": (data.replace(b"=   ", b"=   nan", 1) if b"=   " in data
                   else data.replace(b"= -", b"= nan", 1), r"line \d+: 'nan\S*' is not"),
    }
    for name, (broken, message) in cases.items():
        path = _variant(tmp_path, name, broken)
        code, out, err = run(capsys, "program", "check", path, "--cell", CELL)
        assert code == 2, (name, out, err)
        assert err.startswith("error:") and err.count("\n") == 1, (name, err)
        assert "Traceback" not in out + err
        with pytest.raises(InputError, match=message):
            read_program(path)
