"""Program readers on constructs that pendants and offline tools save: each test writes a minimal
program excerpt with the construct, reads it and checks it against a KR 16 (or the arm of the
vendor) in a minimal cell. What a file does not hold is named as not checked, never refused."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.ik.config import abb_confdata, kuka_status_turn
from robotcell.io.poseformats import pose_to_vendor
from robotcell.programs import read_program
from robotcell.programs.check import check_program, check_program_file

#: A KR 16 at the world origin with a tool 1 (a 50 mm pin) and a base 1.
KR16_CELL = """\
name: kr16_minimal
robot:
  model: kuka_kr16
tools:
  pin:
    number: 1
    frame: {x: 0, y: 0, z: 50, a: 0, b: 0, c: 0}
    provenance: {source: nominal}
frames:
  table:
    number: 1
    parent: world
    frame: {x: 900, y: 0, z: 0, a: 0, b: 0, c: 0}
    provenance: {source: nominal}
"""


def _files(folder: Path, **texts: str) -> Path:
    """Write ``name=text`` files (``prog_src`` is ``prog.src``); return the first."""
    folder.mkdir(exist_ok=True)
    paths = []
    for key, text in texts.items():
        stem, _, ext = key.rpartition("_")
        path = folder / f"{stem}.{ext}"
        path.write_text(text)
        paths.append(path)
    return paths[0]


@pytest.fixture(scope="module")
def kr16_cell(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("cell") / "cell.yaml"
    path.write_text(KR16_CELL)
    return path


def _e6pos(cell: Cell, q_deg, tool_z_mm: float, flags_of=None) -> str:
    """The E6POS aggregate of joints ``q_deg`` with a tool of ``tool_z_mm`` along Z, with the
    Status and Turn of ``flags_of`` (joints, deg; default ``q_deg``)."""
    tool = np.eye(4)
    tool[2, 3] = tool_z_mm * 1e-3
    T = cell.fk(np.radians(q_deg), tool=tool)
    v = pose_to_vendor(T, "kuka")
    s, t = kuka_status_turn(cell.robot, np.radians(q_deg if flags_of is None else flags_of))
    return "{" + ",".join(f"{k} {x:.6f}" for k, x in zip("XYZABC", v)) + f",S {s},T {t}}}"


# -- 1. a point whose name contains HOME -----------------------------------------------------
def test_a_point_named_like_home_declared_in_the_dat_is_read(tmp_path, kr16_cell, capsys):
    src = _files(tmp_path / "p", conv_src=(
        "DEF conv( )\nPTP XhomeConveyor1\nPTP XHOME\nEND\n"), conv_dat=(
        "DEFDAT conv\n"
        "DECL E6AXIS XhomeConveyor1={A1 10,A2 -80,A3 95,A4 0,A5 30,A6 0,E1 0,E2 0}\n"
        "ENDDAT\n"))
    program, skipped = read_program(src)
    assert [p.name for p in program.points] == ["XhomeConveyor1"]
    # XHOME is not in the .dat: KSS declares it in $config.dat
    assert skipped == [("line 3: PTP XHOME (XHOME is a point of $config.dat, not beside the "
                       "program)")]
    code, _out, err = run(capsys, "program", "check", src, "--cell", kr16_cell)
    assert code == 0, err
    assert "note: not checked: line 3: PTP XHOME" in err


# -- 2. the KRC2 inline form with FDAT FHOME of $config.dat ------------------------------------
KRC2_SRC = """\
&ACCESS RVP
&REL 1
DEF krc2( )
;FOLD INI
  BAS (#INITMOV,0 )
;ENDFOLD (INI)
;FOLD PTP HOME  Vel= 100 % DEFAULT;%{PE}%R 4.1.16,%MKUKATPBASIS,%CMOVE,%VPTP,%P 1:PTP, 2:HOME, 3:, 5:100, 7:DEFAULT
$BWDSTART = FALSE
PDAT_ACT=PDEFAULT
FDAT_ACT=FHOME
BAS (#PTP_PARAMS,100 )
$H_POS=XHOME
PTP  XHOME
;ENDFOLD
;FOLD PTP P1 Vel=100 % PDAT1 Tool[1] Base[0];%{PE}%R 4.1.16,%MKUKATPBASIS,%CMOVE,%VPTP,%P 1:PTP, 2:P1, 3:, 5:100, 7:PDAT1
$BWDSTART = FALSE
PDAT_ACT=PPDAT1
FDAT_ACT=FP1
BAS (#PTP_PARAMS,100 )
PTP XP1
;ENDFOLD
END
"""


def test_the_krc2_inline_form_with_fhome_reads_the_rest(tmp_path, kr16_cell, capsys):
    cell = Cell.load(kr16_cell)
    dat = ("DEFDAT krc2\n"
           f"DECL E6POS XP1={_e6pos(cell, [0, -80, 100, 0, 40, 0], 50)}\n"
           "DECL FDAT FP1={TOOL_NO 1,BASE_NO 0,IPO_FRAME #BASE,POINT2[] \" \",TQ_STATE FALSE}\n"
           "DECL PDAT PPDAT1={VEL 100,ACC 100,APO_DIST 100}\nENDDAT\n")
    src = _files(tmp_path / "p", krc2_src=KRC2_SRC, krc2_dat=dat)
    program, skipped = read_program(src)
    assert [(p.name, p.tool.number) for p in program.points] == [("XP1", 1)]
    assert skipped == [("line 13: PTP XHOME (XHOME is a point of $config.dat, not beside the "
                       "program)")]
    report = check_program_file(src, cell)
    assert report.good, report.rows()
    assert np.allclose(np.degrees(report.points[0].q), [0, -80, 100, 0, 40, 0], atol=1e-6)
    code, _, err = run(capsys, "program", "check", src, "--cell", kr16_cell)
    assert code == 0 and "error:" not in err


def test_a_point_after_fhome_without_its_own_fdat_is_not_checked(tmp_path, kr16_cell):
    # the tool and base of FDAT FHOME are in $config.dat: a Cartesian point moved to with them
    # is named, not checked against the cell's tool 0
    cell = Cell.load(kr16_cell)
    src = _files(tmp_path / "p", krc2_src=KRC2_SRC.replace("FDAT_ACT=FP1\n", ""), krc2_dat=(
        f"DEFDAT krc2\nDECL E6POS XP1={_e6pos(cell, [0, -80, 100, 0, 40, 0], 50)}\n"
        "ENDDAT\n"))
    program, skipped = read_program(src)
    assert program.points == []
    assert skipped[1] == ("line 19: PTP XP1 (the tool and base are those of FDAT "
                          "FHOME (line 10), which KSS declares in $config.dat, not beside the "
                          "program)")


# -- 3. geometric operator, relative motions ---------------------------------------------------
def test_geometric_operator_and_relative_motions_are_named_not_refused(tmp_path, kr16_cell,
                                                                       capsys):
    cell = Cell.load(kr16_cell)
    src = _files(tmp_path / "p", rel_src=(
        "DEF rel( )\n$TOOL=TOOL_DATA[1]\n$BASE=$NULLFRAME\nPTP XP1\nLIN XP1 : off\n"
        "LIN_REL {X 10}\nSLIN_REL {Z -5} C_DIS\nPTP_REL {A1 5}\nLIN XP2\nEND\n"), rel_dat=(
        f"DEFDAT rel\nDECL E6POS XP1={_e6pos(cell, [0, -80, 100, 0, 40, 0], 50)}\n"
        f"DECL E6POS XP2={_e6pos(cell, [5, -80, 100, 0, 40, 0], 50)}\n"
        "DECL FRAME off={X 0,Y 0,Z -20,A 0,B 0,C 0}\nENDDAT\n"))
    program, skipped = read_program(src)
    assert [(p.name, p.line) for p in program.points] == [("XP1", 4), ("XP2", 9)]
    assert skipped == [
        "line 5: LIN XP1 : off (a pose computed at run time with the geometric operator ':')",
        "line 6: LIN_REL {X 10} (a motion relative to where the robot is at run time)",
        "line 7: SLIN_REL {Z -5} (a motion relative to where the robot is at run time)",
        "line 8: PTP_REL {A1 5} (a motion relative to where the robot is at run time)"]
    code, _, err = run(capsys, "program", "check", src, "--cell", kr16_cell)
    assert code in (0, 3) and "error:" not in err
    assert err.count("note: not checked:") == 4


# -- 4. TOOL_DATA / BASE_DATA assigned in the program ------------------------------------------
def test_tool_and_base_data_assigned_in_the_program_are_used_in_program_order(tmp_path,
                                                                              kr16_cell):
    cell = Cell.load(kr16_cell)
    q = [10, -70, 95, 20, 50, -30]
    # the point is taught with a 200 mm tool in base 1 = 900 mm along X; the cell's tool 1 is
    # 50 mm and its base 1 is at 900 mm too: only the program's tool gives the joints back
    T = _e6pos(cell, q, 200)
    body = ("DEF tcp( )\nTOOL_DATA[1]={X 0,Y 0,Z 200,A 0,B 0,C 0}\n"
            "BASE_DATA[1]={X 0,Y 0,Z 0,A 0,B 0,C 0}\n$TOOL=TOOL_DATA[1]\n"
            "$BASE=BASE_DATA[1]\nPTP XP1\nTOOL_DATA[1]={X 0,Y 0,Z 50,A 0,B 0,C 0}\nPTP XP1\n"
            "$TOOL=TOOL_DATA[1]\nPTP XP1\nEND\n")
    src = _files(tmp_path / "p", tcp_src=body, tcp_dat=f"DEFDAT tcp\nDECL E6POS XP1={T}\nENDDAT\n")
    report = check_program_file(src, cell)
    q_read = np.degrees(np.stack([p.q for p in report.points]))
    # lines 6 and 8: $TOOL still holds the 200 mm tool; line 10: the 50 mm one reassigned
    assert np.allclose(q_read[0], q, atol=1e-6) and np.allclose(q_read[1], q, atol=1e-6)
    assert not np.allclose(q_read[2], q, atol=1.0)
    # the same as the tool and base written as frames
    src2 = _files(tmp_path / "q", tcp_src=(
        "DEF tcp( )\n$TOOL={X 0,Y 0,Z 200,A 0,B 0,C 0}\n$BASE={X 0,Y 0,Z 0,A 0,B 0,C 0}\n"
        "PTP XP1\nEND\n"), tcp_dat=f"DEFDAT tcp\nDECL E6POS XP1={T}\nENDDAT\n")
    q2 = check_program_file(src2, cell).points[0].q
    assert np.allclose(report.points[0].q, q2, atol=1e-9)


def test_bas_tool_and_fdat_take_the_tool_the_program_assigned(tmp_path, kr16_cell):
    cell = Cell.load(kr16_cell)
    q = [10, -70, 95, 20, 50, -30]
    T = _e6pos(cell, q, 200)
    src = _files(tmp_path / "p", tcp_src=(
        "DEF tcp( )\nTOOL_DATA[3]={X 0,Y 0,Z 200,A 0,B 0,C 0}\nBAS(#TOOL,3)\nBAS(#BASE,0)\n"
        "PTP XP1\nFDAT_ACT=FP1\nPTP XP1\nEND\n"), tcp_dat=(
        f"DEFDAT tcp\nDECL E6POS XP1={T}\nDECL FDAT FP1={{TOOL_NO 3,BASE_NO 0}}\nENDDAT\n"))
    report = check_program_file(src, cell)
    for p in report.points:
        assert np.allclose(np.degrees(p.q), q, atol=1e-6), p.problems


# -- 5. Status and Turn are the controller's for PTP only --------------------------------------
def test_status_and_turn_of_linear_points_are_not_taken_as_their_configuration(tmp_path,
                                                                               kr16_cell):
    cell = Cell.load(kr16_cell)
    q1 = [0, -80, 100, 10, 40, 100]
    q2 = [2, -80, 100, 10, 40, 102]
    # the linear point's T as a pendant may have saved it: A6 taken as 102 - 360 deg (bit 5),
    # which the controller does not use on a LIN (no turn of A6 by 360 deg happens)
    src = _files(tmp_path / "p", st_src=(
        "DEF st( )\n$TOOL=TOOL_DATA[1]\n$BASE=$NULLFRAME\nPTP XP1\nLIN XP2\nSLIN XP2\nEND\n"),
        st_dat=(f"DEFDAT st\nDECL E6POS XP1={_e6pos(cell, q1, 50)}\n"
                f"DECL E6POS XP2={_e6pos(cell, q2, 50, [2, -80, 100, 10, 40, -258])}\nENDDAT\n"))
    program, _ = read_program(src)
    assert program.points[0].config is not None
    assert program.points[1].config is None and program.points[2].config is None
    report = check_program(program, cell)
    assert report.good, report.rows()
    assert math.isclose(math.degrees(report.points[1].q[5]), 102, abs_tol=1e-6)
    # a PTP to the same point takes its S and T: A6 at 102 - 360 deg
    src.write_text(src.read_text().replace("LIN XP2\nSLIN", "PTP XP2\nSLIN"))
    q = check_program_file(src, cell).points[1].q
    assert math.isclose(math.degrees(q[5]), 102 - 360, abs_tol=1e-6)
    # a program that starts with a LIN starts where the robot is: its S and T say where
    src.write_text(src.read_text().replace("PTP XP1\nPTP XP2", "LIN XP2"))
    program, _ = read_program(src)
    assert program.points[0].config is not None and program.points[1].config is None


# -- 6. RAPID optional arguments right after the target (MultiMove \ID, \NoEOffs) ---------------
IRB_CELL = """\
name: irb2400_minimal
robot:
  model: abb_irb2400
tools:
  tool1:
    number: 1
    frame: {x: 0, y: 0, z: 150, a: 0, b: 0, c: 0}
    provenance: {source: nominal}
"""


def _robtarget(cell: Cell, q_deg) -> str:
    tool = cell.tools["tool1"].T_F_TCP
    v = pose_to_vendor(cell.fk(np.radians(q_deg), tool=tool), "abb")
    cf = abb_confdata(cell.robot, np.radians(q_deg))
    return (f"[[{v[0]:.4f},{v[1]:.4f},{v[2]:.4f}],[{v[3]:.8f},{v[4]:.8f},{v[5]:.8f},"
            f"{v[6]:.8f}],[{cf[0]},{cf[1]},{cf[2]},{cf[3]}],[9E9,9E9,9E9,9E9,9E9,9E9]]")


def test_rapid_optional_arguments_after_the_target_are_read(tmp_path, capsys):
    (tmp_path / "cell.yaml").write_text(IRB_CELL)
    cell = Cell.load(tmp_path / "cell.yaml")
    q = [10, 20, 10, 30, 40, 50]
    mod = tmp_path / "mm_rob1.mod"
    mod.write_text(
        "MODULE mm_rob1\n"
        '    PERS tasks all_tasks{2}:=[["T_ROB1"],["T_ROB2"]];\n'
        "    VAR syncident sync1;\n"
        f"    CONST robtarget p10:={_robtarget(cell, q)};\n"
        "    CONST jointtarget j0:=[[0,0,0,0,30,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
        "    PROC main()\n"
        "        SyncMoveOn sync1, all_tasks;\n"
        "        MoveAbsJ j0\\NoEOffs, v1000, fine, tool1;\n"
        "        MoveAbsJ [[0,0,0,0,30,0],[9E9,9E9,9E9,9E9,9E9,9E9]]\\ID:=5\\NoEOffs, v1000,"
        " z50, tool1;\n"
        "        MoveJ p10\\ID:=10, v1000, z50, tool1\\WObj:=wobj0;\n"
        "        MoveL p10 \\ID:=20, v500 \\V:=550, z10 \\Z:=5, tool1;\n"
        "        SyncMoveOff sync1;\n"
        "    ENDPROC\n"
        "ENDMODULE\n")
    program, skipped = read_program(mod)
    assert not skipped
    assert [(p.name, p.motion) for p in program.points] == [
        ("j0", "ptp"), ("line 9", "ptp"), ("p10", "ptp"), ("p10", "lin")]
    assert [p.zone for p in program.points] == pytest.approx([0, 0.05, 0.05, 0.005])
    assert program.points[3].speed == pytest.approx(0.55)  # \V:= overrides v500
    report = check_program(program, cell)
    assert np.allclose(np.degrees(report.points[2].q), q, atol=1e-6)
    code, _, err = run(capsys, "program", "check", mod, "--cell", tmp_path / "cell.yaml")
    assert code in (0, 3) and "error:" not in err


def test_rapid_confdata_is_taken_only_where_configuration_monitoring_is_on(tmp_path):
    (tmp_path / "cell.yaml").write_text(IRB_CELL)
    cell = Cell.load(tmp_path / "cell.yaml")
    mod = tmp_path / "conf.mod"
    p = _robtarget(cell, [10, 20, 10, 30, 40, 50])
    mod.write_text(f"MODULE conf\n    CONST robtarget p1:={p};\n    PROC main()\n"
                   "        MoveJ p1, v100, fine, tool1;\n        MoveL p1, v100, fine, tool1;\n"
                   "        ConfL \\Off;\n        ConfJ\\Off;\n        MoveL p1, v100, fine, tool1;\n"
                   "        MoveJ p1, v100, fine, tool1;\n        ConfJ \\On;\n"
                   "        MoveJ p1, v100, fine, tool1;\n    ENDPROC\nENDMODULE\n")
    program, _ = read_program(mod)
    assert [pt.config is not None for pt in program.points] == [True, True, False, False, True]


def test_rapid_arrays_trigg_and_arc_motions_and_targets_of_other_modules(tmp_path):
    (tmp_path / "cell.yaml").write_text(IRB_CELL)
    cell = Cell.load(tmp_path / "cell.yaml")
    a, b = _robtarget(cell, [10, 20, 10, 30, 40, 50]), _robtarget(cell, [12, 20, 10, 30, 40, 50])
    mod = tmp_path / "weld.mod"
    mod.write_text(
        "MODULE weld(SYSMODULE)\n"
        f"    CONST robtarget seam{{2}}:=[{a},\n        {b}];\n"
        "    VAR robtarget pCur;\n"
        "    PROC main()\n"
        "        IF TRUE THEN\n        MoveJ seam{1}, v100, z10, tool1;\n"
        "        ELSEIF FALSE THEN\n        TriggL seam{2}, v100, trig1, z10, tool1;\n        ENDIF\n"
        "        ArcLStart seam{1}, v100, sm1, wd1, fine, tool1;\n"
        "        ArcLEnd seam{2}, v100, sm1, wd1, fine, tool1;\n"
        "        MoveL Offs(seam{1}, 0, 0, 50), v100, fine, tool1;\n"
        "        MoveL pCur, v100, fine, tool1;\n"
        "        MoveL pOther, v100, fine, tool1;\n"
        "        MoveC seam{1}, seam{2}, v100, fine, tool1;\n"
        "    ENDPROC\nENDMODULE\n")
    program, skipped = read_program(mod)
    assert program.name == "weld"
    assert [(p.name, p.motion, p.line) for p in program.points] == [
        ("seam{1}", "ptp", 7), ("seam{2}", "lin", 9), ("seam{1}", "lin", 11),
        ("seam{2}", "lin", 12)]
    assert skipped == [
        "line 13: MoveL Offs(seam{1}, 0, 0, 50) (a target computed at run time)",
        "line 14: MoveL pCur (pCur is a variable set at run time)",
        ("line 15: MoveL pOther (pOther is declared in no data of this module (a target of "
        "another module of the task is not read))"),
        "line 16: MoveC (circular motions are not checked)"]
    assert check_program(program, cell).good


# -- 7. YASKAWA: //ARGINFO, SETTOOL and SETE -------------------------------------------------
JOB = """\
/JOB
//NAME ARGJOB
//POS
///NPOS 2,0,0,0,0,0
///TOOL 1
///POSTYPE BASE
///RECTAN
///RCONF 0,0,0,0,0,0,0,0
C00000=1000.000,0.000,1000.000,180.0000,0.0000,0.0000
C00001=1000.000,100.000,1000.000,180.0000,0.0000,0.0000
//ARGINFO
///ARGTYPE B,D
///COMMENT
Arg1
Arg2
//INST
///DATE 2024/01/01 00:00
///ATTR SC,RW,RJ
///GROUP1 RB1
NOP
MOVJ C00000 VJ=20.00
SETE P00095 (1) 0
SETE P00095 (2) 0
SETE P00095 (3) 200000
SETE P00095 (4) 0
SETE P00095 (5) 0
SETE P00095 (6) 0
SETTOOL TL#(1) P00095
MOVL C00001 V=100.0
SETE P00096 (3) D000
SETTOOL TL#(1) P00096
MOVL C00000 V=100.0
MOVL P001 V=100.0
END
"""


def test_a_job_with_arginfo_settool_and_sete_is_read_in_program_order(tmp_path):
    job = tmp_path / "ARGJOB.JBI"
    job.write_text(JOB)
    program, skipped = read_program(job)
    assert [(p.name, p.line) for p in program.points] == [("C00000", 21), ("C00001", 29)]
    # the first motion takes the cell's tool 1; the second the 200 mm tool the job sets
    assert program.points[0].tool.pose is None
    assert np.allclose(program.points[1].tool.pose[:3, 3], [0, 0, 0.2])
    assert skipped == [
        ("line 32: MOVL C00000 (tool 1 is set by SETTOOL at line 31 from P00096, whose values the "
        "job sets at run time)"),
        "line 33: MOVL P001 (a position variable, set at run time)"]


def test_a_coordinated_station_motion_adds_its_axes_to_the_robots_point(tmp_path):
    text = JOB.replace("///NPOS 2,0,0,0,0,0", "///NPOS 2,0,1,0,0,0").replace(
        "//ARGINFO", "///POSTYPE PULSE\n///PULSE\nEC00000=1000,-500\n//ARGINFO").replace(
        "MOVJ C00000 VJ=20.00", "MOVJ C00000 VJ=20.00\n+MOVJ EC00000 VJ=10.00")
    job = tmp_path / "COORD.JBI"
    job.write_text(text)
    program, _ = read_program(job)
    assert program.points[0].external == {"EC1": 1000.0, "EC2": -500.0}


# -- 8. FANUC: /END with trailing characters, offsets by registers, DEFAULT_GROUP --------------
LS = """\
/PROG  OFFS
/ATTR
OWNER\t\t= MNEDITOR;
DEFAULT_GROUP\t= 1,*,*,*,*;
/MN
   1:  UFRAME_NUM=0 ;
   2:  UTOOL_NUM=1 ;
   3:J P[1] 100% FINE    ;
   4:L P[2] 200mm/sec CNT60 Tool_Offset,PR[15]    ;
   5:L P[2] 200mm/sec CNT60 Offset,PR[3]    ;
   6:L P[1] 200mm/sec FINE INC    ;
   7:L P[2] 200mm/sec FINE    ;
/POS
P[1]{
   GP1:
\tUF : 0, UT : 1,\t\tCONFIG : 'N U T, 0, 0, 0',
\tX =  1000.000  mm,\tY =     0.000  mm,\tZ =   800.000  mm,
\tW =   180.000 deg,\tP =     0.000 deg,\tR =     0.000 deg
   GP2:
\tUF : 0, UT : 1,
\tJ1=    30.000 deg
};
P[2]{
   GP1:
\tUF : 0, UT : 1,\t\tCONFIG : 'N U T, 0, 0, 0',
\tX =  1000.000  mm,\tY =   100.000  mm,\tZ =   800.000  mm,
\tW =   180.000 deg,\tP =     0.000 deg,\tR =     0.000 deg
};
/END\x1a"""


def test_a_listing_with_offsets_and_a_disabled_group_reads_the_rest(tmp_path, capsys):
    ls = tmp_path / "OFFS.LS"
    ls.write_bytes(LS.encode())  # the last line: /END and an end-of-file mark, no newline
    program, skipped = read_program(ls)
    assert [(p.name, p.line) for p in program.points] == [("P[1]", 8), ("P[2]", 12)]
    assert program.points[0].external == {}  # group 2 is not moved by this program
    assert skipped == [
        "P[1]: its GP2 data are not used: the program's DEFAULT_GROUP does not move group 2",
        ("line 9: L P[2] (Tool_Offset, PR[15]: the position is offset at run time by data not "
        "in the program)"),
        ("line 10: L P[2] (Offset, PR[3]: the position is offset at run time by data not in the "
        "program)"),
        "line 11: L P[1] (INC: a motion relative to where the robot is)"]
    (tmp_path / "cell.yaml").write_text(
        "name: m20ia\nrobot:\n  model: fanuc_m20ia\ntools:\n  pin:\n    number: 1\n"
        "    frame: {x: 0, y: 0, z: 100, a: 0, b: 0, c: 0}\n    provenance: {source: nominal}\n")
    code, _, err = run(capsys, "program", "check", ls, "--cell", tmp_path / "cell.yaml")
    assert code in (0, 3) and "error:" not in err and err.count("note: not checked:") == 4


def test_a_cartesian_point_before_any_tool_is_set_is_not_checked(tmp_path):
    # KRL keeps the $TOOL and $BASE of what ran before until the program sets them: a Cartesian
    # point is named, a joint point (whose axes do not depend on the tool) is read
    src = _files(tmp_path / "p", pre_src=(
        "DEF pre( )\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}\nLIN XP1\n$TOOL=TOOL_DATA[1]\n"
        "LIN XP1\nEND\n"), pre_dat="DEFDAT pre\nDECL E6POS XP1={X 900,Y 0,Z 900,A 0,B 90,C 0}\n"
                                   "ENDDAT\n")
    program, skipped = read_program(src)
    assert [p.line for p in program.points] == [2]
    assert skipped == [
        ("line 3: LIN XP1 (the program sets no tool before this motion (calls to other routines "
        "are not followed))"),
        ("line 5: LIN XP1 (the program sets no base before this motion (calls to other routines "
        "are not followed))")]
