"""ABB modules of the corpus (tests/data/programs/abb/, sources in its README.md) whose RAPID an
earlier reader refused or misread: each construct is read as RAPID means it, and broken copies
of the files are refused with one message naming the file and line."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.errors import InputError
from robotcell.programs import read_program

ABB = Path(__file__).resolve().parent / "data" / "programs" / "abb"
EXCERPTS = ABB / "excerpts"
CELL = ABB / "cell.yaml"


def _pose_of(program, name):
    return next(p.pose for p in program.points if p.name == name)


def test_arrays_declared_by_names_hold_the_named_targets():
    program, notes = read_program(EXCERPTS / "screw_plate_arrays.mod")
    assert [p.name for p in program.points] == ["Screws{2}", "Holes{2, 1}"]
    assert [p.motion for p in program.points] == ["ptp", "lin"]
    screw, hole = program.points
    # Screws{2} is Screw2, Holes{2,1} is Hole21 (row 2, column 1), with their values
    assert np.allclose(screw.pose[:3, 3], [0.8, -0.1, 0.7])
    assert np.allclose(hole.pose[:3, 3], [0.95, -0.15, 0.65])
    assert hole.config.values == (-1, 0, 0, 0)
    assert screw.where.endswith(":6") and hole.where.endswith(":9")  # the declared target's line
    assert notes == [
        ("line 21: MoveL Screws{screwNr} (Screws{screwNr} is an element chosen at run time or "
         "not declared in the module)"),
        ("line 22: MoveL Spare{1} (Spare{1} is declared as SpareScrew, which is declared in no "
         "data of this module (a target of another module of the task is not read))")]


def test_a_target_declared_as_an_expression_is_named_not_checked(tmp_path):
    text = (EXCERPTS / "screw_plate_arrays.mod").read_text().replace(
        "CONST robtarget Spare{1} := [SpareScrew];",
        "CONST robtarget Spare{1} := [Offs(Screw1, 0, 0, 50)];")
    (tmp_path / "offs.mod").write_text(text)
    _, notes = read_program(tmp_path / "offs.mod")
    assert notes[-1] == ("line 22: MoveL Spare{1} (Spare{1} is declared as Offs(Screw1,0,0,50), "
                         "a target computed at run time)")


def test_a_placeholder_statement_is_noted_and_the_module_checked(capsys):
    path = EXCERPTS / "placeholder_main.mod"
    program, notes = read_program(path)
    assert [p.name for p in program.points] == ["pStart"]
    assert notes == ["line 7: <SMT> (a placeholder of a part not yet written: it moves nothing)"]
    code, out, err = run(capsys, "program", "check", path, "--cell", CELL)
    assert code == 0 and "1 point, all good" in out and "line 7: <SMT>" in err


def test_a_position_declared_undefined_is_read_until_a_motion_moves_to_it(tmp_path):
    path = EXCERPTS / "undefined_position.mod"
    program, notes = read_program(path)
    assert [p.name for p in program.points] == ["StandPos{1}"]
    assert np.allclose(program.points[0].pose[:3, 3], [0.9, -0.3, 0.6])
    assert notes == [("line 22: MoveJ StandPos{ToolNr} (StandPos{ToolNr} is an element chosen "
                      "at run time or not declared in the module)")]
    moved = tmp_path / "moved.mod"
    moved.write_text(path.read_text().replace("MoveL StandPos{1},", "MoveL StandPos{2},"))
    with pytest.raises(InputError, match=r"moved\.mod: line 24: MoveL StandPos\{2\} \(its value "
                                         r"on line 17\): ABB quaternion .* normalised"):
        read_program(moved)


def test_a_zone_and_a_speed_declared_by_predefined_names_are_their_values():
    program, notes = read_program(EXCERPTS / "driver_corner_zone.mod")
    (point,) = program.points
    assert (point.name, point.motion) == ("jReady", "ptp") and not notes
    assert point.speed == pytest.approx(0.010) and point.zone == pytest.approx(0.010)  # v10, z10
    assert np.allclose(np.degrees(point.joints), [0, 0, 0, 0, 30, 0])


def test_an_unknown_instruction_with_a_target_of_the_module_is_named_not_checked():
    program, notes = read_program(EXCERPTS / "torch_service.mod")
    assert [p.name for p in program.points] == ["rtSprayApp", "rtSpray", "rtSprayApp"]
    assert notes == [("line 15: MoveSprayJ rtSprayApp (MoveSprayJ is an instruction or routine "
                      "robotcell does not read: a motion it makes to this target is not checked)")]


def test_a_routine_called_with_an_inline_target_is_named_and_a_return_is_not(tmp_path):
    path = tmp_path / "calls.mod"
    path.write_text("MODULE calls\n  CONST robtarget p1:=[[900,0,800],[0,0,1,0],[0,0,0,0],"
                    "[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
                    "  FUNC robtarget first()\n    RETURN p1;\n  ENDFUNC\n"
                    "  PROC main()\n    PickAt [[900,0,700],[0,0,1,0],[0,0,0,0],"
                    "[9E9,9E9,9E9,9E9,9E9,9E9]], 2;\n    TPWrite \"p1\";\n  ENDPROC\nENDMODULE\n")
    program, notes = read_program(path)
    assert not program.points
    assert notes == [("line 7: PickAt [[900,0,700],[0,0,1,0],[0,0,0,0],[9E9... (PickAt is an "
                      "instruction or routine robotcell does not read: a motion it makes to "
                      "this target is not checked)")]


def test_a_robotstudio_modx_module_is_read_and_checked_as_a_mod(tmp_path, capsys):
    modx = tmp_path / "screw_plate.modx"
    shutil.copy(EXCERPTS / "screw_plate_arrays.mod", modx)
    program, notes = read_program(modx)
    assert program.vendor == "abb" and len(program.points) == 2 and len(notes) == 2
    code, out, _ = run(capsys, "program", "check", modx, "--cell", CELL)
    assert code == 0 and "2 points, all good" in out


def test_the_copied_driver_and_station_modules_read_as_their_sources_write_them():
    driver, notes = read_program(ABB / "abb_driver" / "ROS_motion.mod")
    assert not driver.points
    assert notes == ["line 66: MoveAbsJ target (target is a variable set at run time)"]
    station, notes = read_program(ABB / "maurilio97p" / "Pick_Place_Module1.mod")
    assert station.points[0].name == "HOME" and station.points[0].tool.name == "TCP_VentosaTool"
    assert sum("offs(" in n for n in notes) == 6


# -- refused, with the file and the line ----------------------------------------------------------
def _broken(tmp_path: Path, kind: str) -> Path:
    text = (EXCERPTS / "screw_plate_arrays.mod").read_text()
    out = tmp_path / f"{kind}.mod"
    if kind == "truncated":
        out.write_text(text[: text.index("ENDPROC")])
    elif kind == "latin1":  # a pendant's Windows-1252 comment, then a NaN no controller writes
        out.write_bytes(text.replace("! excerpt", "! d\xe9j\xe0").encode("cp1252"))
    elif kind == "nan":
        out.write_text(text.replace("[950,-150,650]", "[950,nan,650]"))
    elif kind == "binary":
        out.write_bytes(b"\xfe\xa0\x02\xc8\x00\x00" + text.encode())
    return out


@pytest.mark.parametrize("kind,message", [
    ("truncated", r"truncated\.mod: line 22: no ENDMODULE \(truncated file\?\)"),
    ("nan", r"nan\.mod: line 9: 'nan' is not finite"),
    ("binary", r"binary\.mod: not a RAPID module in text \(it holds NUL characters"),
])
def test_a_broken_copy_is_refused_with_one_error_line(tmp_path, capsys, kind, message):
    path = _broken(tmp_path, kind)
    with pytest.raises(InputError, match=message):
        read_program(path)
    code, out, err = run(capsys, "program", "check", path, "--cell", CELL)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("error: ")
    assert "Traceback" not in out + err


def test_a_windows_1252_module_is_read(tmp_path):
    program, _ = read_program(_broken(tmp_path, "latin1"))
    assert len(program.points) == 2


def test_a_file_of_motions_without_module_names_its_first_line(tmp_path):
    path = tmp_path / "template.mod"
    path.write_text("! a template, not a module\n\nMoveL [[1,2,%Z%],[1,0,0,0],[0,0,0,0],"
                    "[9E9,9E9,9E9,9E9,9E9,9E9]], v500, fine, tool0;\n")
    with pytest.raises(InputError, match=r"template\.mod: line 3: no MODULE line \('MoveL "
                                         r"\[\[1,2,%Z%\].*' comes first\): not a RAPID module"):
        read_program(path)


def test_a_target_of_the_wrong_size_names_its_values(tmp_path):
    path = tmp_path / "six.mod"
    path.write_text((EXCERPTS / "placeholder_main.mod").read_text().replace(
        "[[900,0,800]", "[[900,0,800,0,0,0]"))
    with pytest.raises(InputError, match=r"six\.mod: line 4: expected 3 values \(x, y, z\) in "
                                         r"'\[900,0,800,0,0,0\]', got 6"):
        read_program(path)
