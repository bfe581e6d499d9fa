"""KUKA programs of the sweep over public repositories (tests/data/programs/kuka/README.md,
"Sweep"): the constructs pendants and drivers save that the reader once refused or misread are
read as the controller runs them (KSS's ``bas.src`` for the inline forms' calls), and what the
files do not hold is named, never refused."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.errors import InputError
from robotcell.programs import read_program

KUKA = Path(__file__).resolve().parent / "data" / "programs" / "kuka"
EXCERPTS = KUKA / "excerpts"
CELL = KUKA / "cell.yaml"


def _read(name: str):
    return read_program(EXCERPTS / name)


# -- KSS 8 spline inline forms -------------------------------------------------------------------
def test_spline_inline_forms_move_with_the_tool_and_base_of_their_fdat():
    program, notes = _read("spline_inline.src")
    assert [(p.name, p.line, p.motion) for p in program.points] == [
        ("Xp1", 24, "ptp"), ("Xp2", 31, "ptp"), ("Xp1", 52, "ptp")]
    # STOOL2(FP1) is TOOL_DATA[FP1.TOOL_NO], SBASE(FP1.BASE_NO) is BASE_DATA[FP1.BASE_NO]
    assert [p.tool.number for p in program.points] == [1, 2, 1]
    assert [p.frame.number for p in program.points] == [0, 3, 0]
    assert program.points[0].pose[:3, 3] == pytest.approx([1.2, -0.3, 0.9])
    assert program.points[0].config.values == (2, 2)
    # $APO = SAPO_PTP(PPDAT1), APO_MODE #CDIS, APO_DIST 250 and C_Spl after the WITH clause
    assert [p.zone for p in program.points] == pytest.approx([0.25, 0.0, 0.0])
    assert notes[0] == ("line 17: SPTP XHOME (XHOME is a point of $config.dat, not beside the "
                        "program)")


def test_an_external_tcp_is_named_not_checked_until_a_motion_gives_the_base_again():
    _, notes = _read("spline_inline.src")
    external = [n for n in notes if "external TCP" in n]
    # an FDAT with IPO_FRAME #TCP in the WITH clause, then $IPO_MODE = #TCP set in the program
    assert [n.split(" (")[0] for n in external] == ["line 38: SPTP Xp3", "line 46: SLIN Xp4"]
    assert "$IPO_MODE #TCP from line 44" in external[1]
    assert "the tool is fixed in the cell and the robot moves the workpiece" in external[0]


def test_a_spline_form_takes_its_speed_and_corner_from_the_with_clause(tmp_path):
    # the SLIN inline form: $VEL = SVEL_CP(v, , LDAT) is v m/s, $APO = SAPO(LDAT) LDAT's
    # APO_DIST; SAPO_PTP(PDAT) of a PDAT with APO_MODE #CPTP approximates by a percentage
    (tmp_path / "p.src").write_text(
        "DEF p( )\n"
        "SLIN XP1 WITH $VEL = SVEL_CP(0.3, , LCPDAT1), $TOOL = STOOL2(FP1), $BASE = "
        "SBASE(FP1.BASE_NO), $IPO_MODE = SIPO_MODE(FP1.IPO_FRAME), $LOAD = SLOAD(FP1.TOOL_NO), "
        "$ACC = SACC_CP(LCPDAT1), $ORI_TYPE = SORI_TYP(LCPDAT1), $APO = SAPO(LCPDAT1), "
        "$JERK = SJERK(LCPDAT1), $COLLMON_TOL_PRO[1] = USE_CM_PRO_VALUES(0) C_SPL\n"
        "SLIN XP1 WITH $VEL = SVEL_CP(gVel, , LCPDAT1), $TOOL = STOOL2(FP1), $BASE = "
        "SBASE(FP1.BASE_NO)\n"
        "SPTP XP1 WITH $TOOL = STOOL2(FP1), $BASE = SBASE(FP1.BASE_NO), $APO = "
        "SAPO_PTP(PPDAT1) C_SPL\n"
        "END\n")
    (tmp_path / "p.dat").write_text(
        "DEFDAT p\n"
        "DECL E6POS XP1={X 800,Y 0,Z 500,A 0,B 90,C 0,S 2,T 2,E1 0.0,E2 0.0}\n"
        "DECL FDAT FP1={TOOL_NO 4,BASE_NO 5,IPO_FRAME #BASE,POINT2[] \" \"}\n"
        "DECL LDAT LCPDAT1={VEL 2.0,ACC 100.0,APO_DIST 12.5,APO_FAC 50.0,AXIS_VEL 100.0}\n"
        "DECL PDAT PPDAT1={VEL 100.000,ACC 100.000,APO_DIST 50.0000,APO_MODE #CPTP}\n"
        "ENDDAT\n")
    program, notes = read_program(tmp_path / "p.src")
    assert not notes
    first, second, third = program.points
    assert (first.tool.number, first.frame.number) == (4, 5)
    assert third.motion == "ptp" and third.zone is None
    assert first.speed == pytest.approx(0.3) and first.zone == pytest.approx(0.0125)
    assert second.speed is None and second.zone == 0.0  # a variable speed: of run time


# -- speeds and corners in program order -----------------------------------------------------------
def test_a_with_clause_gives_speed_and_corner_for_its_motion_and_the_approximation_after_it():
    program, notes = _read("with_speed.src")
    assert not notes
    assert [p.motion for p in program.points] == ["ptp", "ptp", "lin", "lin", "lin"]
    assert [p.speed for p in program.points] == [None, None, 2.5, 0.8, 2.0]
    assert [p.zone for p in program.points] == pytest.approx([0.4, 0.15, 0.04, 0.0, 0.08])
    assert {(p.tool.number, p.frame.number) for p in program.points} == {(1, 2)}


def test_a_classic_inline_form_moves_at_its_own_speed_not_the_ldat_one():
    program, notes = _read("inline_cp.src")
    assert not notes
    above, approach, place = program.points
    # BAS(#CP_DAT) sets LDAT_ACT.VEL (2.0), then BAS(#VEL_CP,0.55) the form's speed
    assert approach.speed == pytest.approx(0.55) and place.speed == pytest.approx(0.1)
    # BAS(#CP_DAT) sets $APO.CDIS to LDAT_ACT.APO_DIST: C_DIS rounds at 60 mm
    assert approach.zone == pytest.approx(0.06) and place.zone == 0.0
    # a PDAT without APO_MODE sets $APO.CPTP, a percentage: C_PTP is no distance
    assert above.zone is None and above.motion == "ptp"
    assert [p.tool.number for p in program.points] == [2, 2, 2]


# -- named, not refused ------------------------------------------------------------------------
def test_a_partial_aggregate_is_named_not_refused(capsys):
    program, notes = _read("partial_aggregate.src")
    assert program.points == []
    assert notes == [
        "line 22: PTP XHOME (XHOME is a point of $config.dat, not beside the program)",
        "line 26: LIN {Z 350} (the aggregate gives Z only, not a whole pose)",
        "line 30: LIN {Z 350} (the aggregate gives Z only, not a whole pose)"]
    code, out, err = run(capsys, "program", "check", EXCERPTS / "partial_aggregate.src",
                         "--cell", CELL)
    assert code == 0 and "no point checked" in out
    assert "note: not checked: line 26: LIN {Z 350}" in err


def test_a_partial_axis_aggregate_and_a_partial_assignment_are_named(tmp_path):
    (tmp_path / "p.src").write_text(
        "DEF p( )\nDECL E6POS P1\nBAS(#TOOL,1)\nBAS(#BASE,0)\n"
        "P1 = {X 900,Y 0,Z 500,A 0,B 90,C 0}\nPTP P1\nP1 = {Z 400}\nPTP P1\nPTP {A1 45}\nEND\n")
    program, notes = read_program(tmp_path / "p.src")
    assert [p.line for p in program.points] == [6]
    assert notes == ["line 8: PTP P1 (P1 is given Z only (line 7), not a whole point)",
                     ("line 9: PTP {A1 45} (the aggregate gives A1 only, not a whole axis "
                      "position)")]


def test_a_src_without_a_dat_is_read_its_global_points_named(capsys):
    program, notes = _read("global_points.src")
    assert program.points == []
    assert notes[0] == "line 8: PTP $AXIS_ACT (not held by the program)"
    assert [n.split(" (")[0] for n in notes[1:]] == [
        "line 29: PTP COM_E6AXIS", "line 31: PTP COM_E6AXIS", "line 37: LIN COM_FRAME",
        "line 39: LIN COM_FRAME"]
    assert all("there is no global_points.dat" in n and "$config.dat is not read" in n
               for n in notes[1:])
    code, out, _ = run(capsys, "program", "check", EXCERPTS / "global_points.src", "--cell",
                       CELL)
    assert code == 0 and "no point checked" in out


# -- broken files: one error line naming the file and the line ---------------------------------
def _copy(tmp_path: Path, name: str) -> Path:
    for f in EXCERPTS.glob(f"{name}.*"):
        shutil.copy(f, tmp_path / f.name)
    return tmp_path / f"{name}.src"


def _break_src_truncated(src: Path) -> str:
    text = src.read_text()
    src.write_text(text[:text.index("$TOOL = STOOL2(Fp2)")])
    return r"spline_inline\.src: line 31: no END \(truncated file\?\)"


def _break_dat_truncated(src: Path) -> str:
    dat = src.with_suffix(".dat")
    text = dat.read_text()
    dat.write_text(text[:text.index("DECL PDAT PPDAT2")])
    return r"spline_inline\.dat: line 19: no ENDDAT \(truncated file\?\)"


def _break_nan(src: Path) -> str:
    dat = src.with_suffix(".dat")
    dat.write_text(dat.read_text().replace("Y -300.000000", "Y nan"))
    return r"spline_inline\.dat: line 15: 'nan' is not finite"


def _break_motion_data(src: Path) -> str:
    dat = src.with_suffix(".dat")
    dat.write_text(dat.read_text().replace("APO_DIST 250.000", "APO_DIST 2\u00b250"))
    return r"spline_inline\.dat: line 17: '2\u00b250' is not a number"


def _break_bytes(src: Path) -> str:
    dat = src.with_suffix(".dat")
    dat.write_bytes(dat.read_bytes().replace(b"Z 900.000000", b"Z 9\xff0.000000"))
    return r"spline_inline\.dat: line 15: '9\u00ff0\.000000' is not a number"


def _break_empty(src: Path) -> str:
    src.write_text("\n\n")
    return r"spline_inline\.src: the file is empty: not a KUKA \.src file"


BROKEN = {"truncated .src": _break_src_truncated, "truncated .dat": _break_dat_truncated,
          "NaN in a point": _break_nan, "no number in a PDAT": _break_motion_data,
          "not UTF-8 in a number": _break_bytes, "empty .src": _break_empty}


@pytest.mark.parametrize("case", list(BROKEN))
def test_a_broken_excerpt_is_refused_with_one_error_line_naming_the_line(case, tmp_path, capsys):
    src = _copy(tmp_path, "spline_inline")
    message = BROKEN[case](src)
    with pytest.raises(InputError, match=message):
        read_program(src)
    code, out, err = run(capsys, "program", "check", src, "--cell", CELL)
    assert code == 2 and "Traceback" not in out + err
    errors = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert len(errors) == 1 and len(err.strip().splitlines()) == 1, err


def test_a_pendant_comment_in_windows_1252_is_read(tmp_path):
    src = _copy(tmp_path, "with_speed")
    src.write_bytes(src.read_bytes().replace(b"$OUT[20] = TRUE",
                                             b"$OUT[20] = TRUE ; u\xf1as fuera"))
    program, _ = read_program(src)
    assert np.allclose([p.speed or 0 for p in program.points], [0, 0, 2.5, 0.8, 2.0])
