"""ABB, FANUC and YASKAWA programs: what other tools and pendants write, read; programs written
by robotcell read back whatever their form on the pendant."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from programs_helpers import CELL, ROBODK, SEAM

from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.programs import read_program, write_program
from robotcell.programs.check import check_program


@pytest.fixture(scope="module")
def cell() -> Cell:
    return Cell.load(CELL)


# -- RoboDK's example station (RoboDK/Industrial-Robots-VSCode, examples/, MIT) ----------------
def test_robodks_rapid_module_is_read():
    program, skipped = read_program(ROBODK / "Program.mod")
    assert program.name == "MOD_Program" and not skipped
    pts = program.points
    assert [p.motion for p in pts] == ["ptp", "ptp", "lin", "lin", "lin", "lin"]
    assert pts[0].joints is not None and pts[2].pose is not None
    # the module sets ConfL \Off: the controller does not use a MoveL target's confdata
    assert pts[2].config is None and pts[5].config is None
    assert np.allclose(pts[2].pose[:3, 3], [0.018715, 0.147321, 0.458168])
    # the tool and the work object the module declares itself, \WObj after a comma too
    assert pts[0].tool.name == "Tool" and np.allclose(pts[0].tool.pose[:3, 3], [-0.03, 0, 0.04])
    assert pts[0].frame.name == "Frame2" and np.allclose(pts[0].frame.pose[:3, 3],
                                                         [0.399855, 0, 0.1])
    assert pts[2].frame.name == "WObj0"  # as the module writes it (the world)
    assert pts[0].speed == pytest.approx(0.1) and pts[0].zone == pytest.approx(0.001)


def test_robodks_fanuc_listing_is_read_with_the_tool_it_sets():
    program, skipped = read_program(ROBODK / "Program.LS")
    assert program.name == "Program" and not skipped
    pts = program.points
    assert [p.name for p in pts] == [f"P[{i}]" for i in range(1, 7)]
    assert [p.line for p in pts] == [39, 40, 42, 43, 54, 58]
    assert np.allclose(np.degrees(pts[1].joints), [0, -3.687, -0.703, 0, -56.115, 0])
    assert pts[2].config.values == (0, 0, 0, 0, 0, 0)  # 'N U T, 0, 0, 0'
    assert pts[2].frame.number == 2 and pts[2].tool.number == 9
    # UTOOL[9]=PR[9] with PR[9,1..6] = -30, 0, 40, 0, -60, 0 (X, Y, Z, W, P, R)
    assert np.allclose(pts[2].tool.pose[:3, 3], [-0.03, 0, 0.04])
    assert pts[2].speed == pytest.approx(0.1) and pts[2].zone == 0.0


def test_robodks_yaskawa_job_is_read():
    program, skipped = read_program(ROBODK / "PROGRAM.JBI")
    assert program.name == "Program"
    assert [s.split(":")[0] for s in skipped] == ["line 39", "line 40"]  # pulse positions
    pts = program.points
    assert [p.name for p in pts] == ["C00002", "C00003", "C00004", "C00005"]
    assert all(p.frame.kind == "base" and p.frame.number is None for p in pts)  # POSTYPE BASE
    assert pts[0].tool.number == 9 and pts[0].config.values == (0, 0, 0, 0, 0, 0)
    # tool 9 is set in the job (SETE P00095 (1..6), SETTOOL TL#(9) P00095): the tool RoboDK
    # wrote for the same station in Program.src ($TOOL = {X -30, Y 0, Z 40, A 0, B -60, C 0})
    kuka_tool = read_program(ROBODK / "Program.src")[0].points[0].tool.pose
    assert np.allclose(pts[0].tool.pose, kuka_tool, atol=1e-12)
    assert np.allclose(pts[0].pose[:3, 3], [0.41857, 0.147321, 0.251179])
    assert pts[0].speed == pytest.approx(0.2)


@pytest.mark.parametrize("model,urdf", [("abb_irb1200_7_70.yaml", "irb1200_7_70.urdf"),
                                        ("fanuc_m710ic.yaml", "m710ic50.urdf")])
def test_the_models_written_for_robodks_programs_are_the_ros_industrial_chains(model, urdf):
    pytest.importorskip("urdf_parser_py")
    from robotcell import load_robot
    from robotcell.dhprocedure import read_urdf

    robot = load_robot(ROBODK / model)
    chain = read_urdf(ROBODK / urdf)
    q = np.random.default_rng(5).uniform(-1.5, 1.5, (40, 6))
    serial = robot.uncoupled() if robot.coupling is not None else robot
    qm = robot.coupling.to_model(q) if robot.coupling is not None else q
    assert np.abs(serial.fk(qm)[..., :3, 3] - chain.fk(qm)[..., :3, 3]).max() < 1e-9
    assert np.abs(serial.fk(qm)[..., :3, :3] - chain.fk(qm)[..., :3, :3]).max() < 1e-9


def test_robodks_fanuc_program_is_good_in_an_m710ic_cell_under_robodks_flip_rule(tmp_path):
    # Every point reachable as written, and the linear motion from the joint position P[2]
    # (J5 = -56 deg) to P[3] ('N U T') keeps the configuration: N is J5 < 0, as RoboDK's post
    # says. With F written instead the check finds the flip.
    cell = Cell.load(ROBODK / "cell_m710ic.yaml")
    report = check_program(read_program(ROBODK / "Program.LS")[0], cell)
    assert report.good, report.rows()
    assert np.degrees(report.points[2].q[4]) < 0
    flipped = tmp_path / "flip.ls"
    flipped.write_text((ROBODK / "Program.LS").read_text().replace("'N U T", "'F U T"))
    bad = check_program(read_program(flipped)[0], cell)
    assert "changes the arm's configuration" in bad.bad[0].problems[0]


def test_robodks_rapid_module_in_an_irb1200_cell_is_reached_but_not_as_written(tmp_path):
    # The module's targets are reachable by the IRB 1200, but the station's points were not
    # solved for this arm (its joint targets are the FANUC program's): under ConfL \Off the
    # linear targets take the solution nearest to the previous one: the joint target at a wrist
    # singularity and the first linear motion, which changes the configuration, are flagged
    # (an axis turning far on a linear motion is not, as a controller runs it: docs/programs.md).
    cell = Cell.load(ROBODK / "cell_irb1200.yaml")
    report = check_program(read_program(ROBODK / "Program.mod")[0], cell)
    assert not any("out of reach" in w for p in report.points for w in p.problems)
    assert [p.name for p in report.bad] == ["line 21", "line 24"]
    assert "wrist singularity" in report.bad[0].problems[0]  # MoveAbsJ with axis 5 at 0
    assert "changes the arm's configuration" in report.bad[1].problems[0]
    # with ConfL \On the controller takes the confdata, which no IRB 1200 solution has
    text = (ROBODK / "Program.mod").read_text().replace("ConfL \\Off", "ConfL \\On")
    path = tmp_path / "Program.mod"
    path.write_text(text)
    report = check_program(read_program(path)[0], cell)
    assert all("no solution has the configuration as written" in p.problems[0]
               for p in report.bad[1:]) and len(report.bad) == 5


# -- programs written by robotcell in the forms pendants keep them ------------------------------
def test_an_abb_module_over_several_lines_with_options_reads_the_same(cell, tmp_path):
    result = write_program(SEAM, cell, "torch", "part", "abb", tmp_path / "p")
    mod = Path(result.files[0])
    text = mod.read_text()
    text = text.replace("MoveL p2,v100,fine,torch\\WObj:=part;",
                        "MoveL \\Conc, p2, v100 \\V:=120,\n            fine, torch \\WObj:=part;")
    text = text.replace("CONST robtarget p3:=", "LOCAL CONST robtarget p3 :=\n        ")
    mod.write_text(text.replace("MODULE seam_part", "%%%\n  VERSION:1\n%%%\nMODULE seam_part"))
    program, _ = read_program(mod)
    report = check_program(program, cell)
    assert report.good, report.rows()
    assert np.abs(np.stack([p.q for p in report.points]) - result.q).max() < 1e-6


def test_a_fanuc_listing_with_comments_on_positions_reads_the_same(cell, tmp_path):
    result = write_program(SEAM, cell, "torch", "part", "fanuc", tmp_path / "p")
    ls = Path(result.files[0])
    ls.write_text(ls.read_text().replace("P[3]{", 'P[3:"seam start"]{')
                  .replace("L P[3] ", 'L P[3:"seam start"] '))
    program, _ = read_program(ls)
    assert program.points[2].name == "P[3]"
    assert check_program(program, cell).good


def test_a_yaskawa_job_with_six_rconf_values_and_four_slashes_reads_the_same(cell, tmp_path):
    result = write_program(SEAM, cell, "torch", "part", "yaskawa", tmp_path / "p",
                           pulses_per_degree=100)
    jbi = Path(result.files[0])
    text = "\n".join(ln[:-4] if ln.startswith("///RCONF") else ln
                     for ln in jbi.read_text().splitlines())
    jbi.write_text(text.replace("///FRAME", "////FRAME") + "\n")
    program, _ = read_program(jbi)
    assert len(program.points[0].config.values) == 6
    assert check_program(program, cell, pulses_per_degree=100).good


def test_a_yaskawa_cell_with_a_turntable_needs_the_pulses_per_degree(cell, tmp_path):
    with pytest.raises(InputError, match="give pulses_per_degree"):
        write_program(SEAM, cell, "torch", "part", "yaskawa", tmp_path / "p")
    assert not (tmp_path / "p").exists()


@pytest.mark.parametrize("vendor,edit,match", [
    ("abb", lambda t: t.replace("ENDMODULE", ""), "no ENDMODULE"),
    ("abb", lambda t: t.split("CONST robtarget p9")[0] + "CONST robtarget p9:=[[1,2",
     "has no ';'"),
    ("abb", lambda t: t.replace("[-2,", "[-2.0.1,", 1), "is not a number"),
    ("fanuc", lambda t: t.replace("/END", ""), "no /END"),
    ("fanuc", lambda t: t.split("P[9]{")[0] + "P[9]{\n   GP1:\n/END\n",
     r"P\[9\] is not closed"),
    ("fanuc", lambda t: t.replace("L P[4] ", "L P[40] "), r"P\[40\] is not in the /POS"),
    ("fanuc", lambda t: t.replace("CONFIG : 'N", "CONFIG : 'X", 1), "is not 'F|N U|D T|B"),
    ("yaskawa", lambda t: t.rsplit("END", 1)[0], "does not end with END"),
    ("yaskawa", lambda t: t.replace("MOVL C00003", "MOVL C00099"), "C00099"),
    ("yaskawa", lambda t: t.replace("C00004=", "C00004=1,2\nX="), "C00004 needs X, Y, Z"),
])
def test_a_truncated_or_corrupt_program_is_refused_naming_the_cause(cell, tmp_path, vendor,
                                                                    edit, match):
    result = write_program(SEAM, cell, "torch", "part", vendor, tmp_path / "p",
                           pulses_per_degree=100 if vendor == "yaskawa" else None)
    path = Path(result.files[0])
    path.write_text(edit(path.read_text()))
    with pytest.raises(InputError, match=match):
        read_program(path)
