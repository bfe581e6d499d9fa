"""What each controller's program writer emits, as the vendor's pendant or offline tool writes it
(docs/programs.md, "The formats"), and jobs read without a unit they do not need."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from programs_helpers import CELL, EXAMPLES, SEAM

from robotcell.cell import Cell
from robotcell.controllers.model import Config, Program, ProgramPoint, Ref
from robotcell.controllers.registry import get
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor
from robotcell.programs import read_program, write_program
from robotcell.programs.check import check_program_file
from robotcell.programs.config import configs
from robotcell.programs.frames import tool_pose_of

POSITIONER = EXAMPLES / "cell_kr16_positioner.yaml"


@pytest.fixture(scope="module")
def cell() -> Cell:
    return Cell.load(CELL)


def _one_point(vendor: str, external: dict[str, float]) -> Program:
    """A program of one Cartesian point with the external axes given (file units)."""
    point = ProgramPoint("P1", 0, "ptp", Ref(number=1, name="torch"), Ref(number=0),
                         pose=pose_from_vendor([1000, 0, 1000, 0, 90, 0], "kuka"),
                         config=Config(vendor, (2, 2)), external=external)
    return Program("ext", vendor, [point])


# -- KUKA --------------------------------------------------------------------------------------
@pytest.mark.parametrize("external,count", [
    ({"E1": 1500.0, "E2": 30.0, "E3": -45.0}, 3),   # a track and a 2-axis positioner
    ({"E1": 30.0}, 1),                               # a turntable alone
])
def test_kuka_act_ex_ax_is_the_number_of_external_axes_in_use(external, count):
    src = get("kuka").write_program(_one_point("kuka", external), ["test"])["ext.src"]
    assert re.findall(r"^\$ACT_EX_AX=.*$", src, re.MULTILINE) == [f"$ACT_EX_AX={count}"]


def test_kuka_programs_of_the_example_cells_set_act_ex_ax(cell, tmp_path):
    # the track and the turntable: 2; the 2-axis positioner alone: 2; no external axis: none
    written = write_program(SEAM, cell, "torch", "part", "kuka", tmp_path / "a")
    assert "$ACT_EX_AX=2\n" in Path(written.files[0]).read_text()
    path = tmp_path / "p.csv"
    path.write_text("x,y,z,a,b,c,e1,e2\n60,0,0,0,180,0,0,-10\n50,10,0,0,180,0,0,-20\n")
    written = write_program(path, Cell.load(POSITIONER), "torch", "part", "kuka", tmp_path / "b")
    assert "$ACT_EX_AX=2\n" in Path(written.files[0]).read_text()
    none = _one_point("kuka", {})
    assert "$ACT_EX_AX" not in get("kuka").write_program(none, ["test"])["ext.src"]


# -- ABB ---------------------------------------------------------------------------------------
def test_abb_module_and_routine_have_two_names_and_declare_tool_and_wobj(cell, tmp_path):
    written = write_program(SEAM, cell, "torch", "part", "abb", tmp_path, name="seam")
    text = Path(written.files[0]).read_text()
    assert text.startswith("MODULE MOD_seam\n")
    assert "\n    PROC seam()\n" in text
    decl = re.findall(r"^\s*LOCAL PERS (tooldata|wobjdata) (\w+):=", text, re.MULTILINE)
    assert decl == [("tooldata", "torch"), ("wobjdata", "part")]
    assert '[FALSE,FALSE,"DKP_400_01",[[0,0,0],[1,0,0,0]],' in text  # coordinated: on the table
    # read back, the module's own data are the cell's (and win over the cell's of that name)
    program, _ = read_program(written.files[0])
    tool = program.points[0].tool
    assert tool.pose is not None
    np.testing.assert_allclose(tool.pose, cell.tools["torch"].T_F_TCP, atol=1e-9)
    np.testing.assert_allclose(tool_pose_of(cell, "abb", tool), cell.tools["torch"].T_F_TCP,
                               atol=1e-9)
    assert program.points[0].frame.on_table
    assert check_program_file(written.files[0], cell).good


def test_abb_program_names_leave_room_for_the_module_prefix(cell, tmp_path):
    with pytest.raises(InputError, match="at most 28 characters"):
        write_program(SEAM, cell, "torch", "part", "abb", tmp_path, name="a" * 29)


# -- YASKAWA -----------------------------------------------------------------------------------
def test_yaskawa_job_frame_rconf_and_groups_as_dx100_jobs_write_them(cell, tmp_path):
    written = write_program(SEAM, cell, "torch", "part", "yaskawa", tmp_path,
                            pulses_per_degree=100)
    lines = Path(written.files[0]).read_text().splitlines()
    assert "////FRAME USER 2" in lines and "///FRAME USER 2" not in lines
    rconf = [ln for ln in lines if ln.startswith("///RCONF ")]
    assert rconf and all(len(ln.split()[1].split(",")) == 24 for ln in rconf)
    assert "///GROUP1 RB1,BS1" in lines and "///GROUP2 ST1" in lines
    moves = [ln for ln in lines if ln.startswith(("MOVJ", "MOVL"))]
    assert moves[0] == "MOVJ C00000 BC00000 VJ=20.00 +MOVJ EC00000 VJ=20.00"
    assert moves[1] == "MOVL C00001 BC00001 V=100.0 +MOVJ EC00001 VJ=20.00"
    assert check_program_file(written.files[0], cell, 100).good


def test_yaskawa_station_pulses_are_given_per_axis(tmp_path):
    pos = Cell.load(POSITIONER)
    path = tmp_path / "p.csv"
    path.write_text("x,y,z,a,b,c,e1,e2\n60,0,0,0,180,0,0,-10\n50,10,0,0,180,0,0,-20\n")
    with pytest.raises(InputError, match="2 axes, each with its own pulses per degree; give 2"):
        write_program(path, pos, "torch", "part", "yaskawa", tmp_path / "a",
                      pulses_per_degree=100)
    written = write_program(path, pos, "torch", "part", "yaskawa", tmp_path / "b",
                            pulses_per_degree=[100, 250])
    text = Path(written.files[0]).read_text()
    assert "EC00001=0,-5000\n" in text  # axis 1 at 0 deg, axis 2 at -20 deg x 250 pulses
    report = check_program_file(written.files[0], pos, [100, 250])
    assert report.good, report.rows()
    assert np.allclose(np.degrees(report.points[1].table), [0, -20])


def test_a_yaskawa_job_without_station_axes_is_checked_without_pulses_per_degree(cell, tmp_path,
                                                                                 capsys):
    # A job of the robot's group alone (no EC position, no GROUP2) in a cell with a turntable:
    # the station's pulses are not needed to check it.
    q = np.radians([[-60, -80, 95, 10, 40, -20], [-62, -78, 95, 10, 42, -20]])
    T = cell.robot.fk(q, tool=cell.tools["torch"].T_F_TCP)  # in the robot base, track at 0
    flags = configs(cell.robot, q, "yaskawa")
    rows = [",".join(f"{x:.3f}" if i < 3 else f"{x:.4f}"
                     for i, x in enumerate(pose_to_vendor(t, "yaskawa"))) for t in T]
    rconf = ",".join(map(str, flags[0].values))
    job = ["/JOB", "//NAME ROBOT", "//POS", "///NPOS 2,2,0,0,0,0", "///TOOL 1",
           "///POSTYPE BASE", "///RECTAN", f"///RCONF {rconf},0,0", f"C00000={rows[0]}",
           f"C00001={rows[1]}", "BC00000=0.000", "BC00001=0.000", "//INST",
           "///DATE 2024/01/01 00:00", "///ATTR SC,RW,RJ", "///GROUP1 RB1,BS1", "NOP",
           "MOVJ C00000 BC00000 VJ=20.00", "MOVL C00001 BC00001 V=50.0", "END"]
    path = tmp_path / "ROBOT.JBI"
    path.write_text("\n".join(job) + "\n")
    report = check_program_file(path, cell)
    assert report.good, report.rows()
    np.testing.assert_allclose(report.points[0].q, q[0], atol=1e-5)
    code, out, err = run(capsys, "program", "check", path, "--cell", CELL)
    assert code == 0, err
    # a job that moves the station still needs them
    with_ec = path.read_text().replace("///NPOS 2,2,0", "///NPOS 2,2,1").replace(
        "BC00001=0.000\n", "BC00001=0.000\n///POSTYPE PULSE\n///PULSE\nEC00000=0\n").replace(
        "MOVL C00001 BC00001 V=50.0", "MOVL C00001 BC00001 V=50.0 +MOVJ EC00000 VJ=20.00")
    path.write_text(with_ec)
    with pytest.raises(InputError, match="give pulses_per_degree"):
        check_program_file(path, cell)


# -- FANUC -------------------------------------------------------------------------------------
#: Positions as a FANUC controller saves them (a TP listing of a controller backup): 3 decimals
#: in fields of 10 characters, no 0 before the point, ``J1=`` without a space.
SAVED = re.compile(r"^\t(X|W) =( {0,9}-?(\d+|)\.\d{3})  ?(mm|deg),\t(Y|P) =( {0,9}-?(\d+|)\.\d{3})"
                   r"  ?(mm|deg),\t(Z|R) =( {0,9}-?(\d+|)\.\d{3})  ?(mm|deg),?$")


def test_fanuc_positions_are_written_as_controllers_save_them(cell, tmp_path):
    written = write_program(SEAM, cell, "torch", "part", "fanuc", tmp_path)
    text = Path(written.files[0]).read_text()
    pos = text.split("/POS\n")[1].splitlines()
    values = [ln for ln in pos if ln.startswith(("\tX =", "\tW ="))]
    assert values and all(SAVED.match(ln) for ln in values), values[:2]
    assert all(len(m) == 10 for ln in values for m in re.findall(r"=([ .\-0-9]{10})", ln))
    assert re.search(r"^\tE1=  4033\.532  mm$", text, re.MULTILINE)
    assert re.search(r"^\tJ1=   200\.000 deg$", text, re.MULTILINE)
    assert " = " not in "".join(ln for ln in pos if "E1" in ln or "J1" in ln)
    assert re.search(r"\d\.\d{4}", text.split("/POS")[1]) is None  # 3 decimals, no more
    report = check_program_file(written.files[0], cell)
    assert report.good, report.rows()


def test_a_position_saved_by_a_controller_is_read(tmp_path):
    # an excerpt in the layout of a controller's TP listing: '.153' for 0.153, E1= in group 1
    ls = ["/PROG  SAVED", "/ATTR", "/MN", "   1:  UFRAME_NUM=0 ;", "   2:  UTOOL_NUM=1 ;",
          "   3:J P[1] 100% FINE ;", "/POS", "P[1]{", "   GP1:",
          "\tUF : 0, UT : 1,\t\tCONFIG : 'N U T, 0, 0, 0',",
          "\tX =  1234.500  mm,\tY =     -.153  mm,\tZ =   800.000  mm,",
          "\tW =  -179.535 deg,\tP =      .517 deg,\tR =     0.000 deg,",
          "\tE1=  2500.250  mm", "};", "/END"]
    path = tmp_path / "saved.ls"
    path.write_text("\n".join(ls) + "\n")
    program, _ = read_program(path)
    (p,) = program.points
    np.testing.assert_allclose(pose_to_vendor(p.pose, "fanuc"),
                               [1234.5, -0.153, 800, -179.535, 0.517, 0], atol=1e-9)
    assert p.external == {"E1": 2500.25}
