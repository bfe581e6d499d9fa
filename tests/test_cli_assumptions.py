"""Output that says what it assumed: the tool, frame, track and table a result used, and output
files whose name says what they hold."""

from __future__ import annotations

from pathlib import Path

import pytest
from cli_helpers import run

ROOT = Path(__file__).resolve().parents[1]
CELL = str(ROOT / "examples" / "cell_kr16_track_turntable.yaml")
POSITIONER = str(ROOT / "examples" / "cell_kr16_positioner.yaml")
JOINTS = "0,-90,90,0,45,0"


def test_fk_in_a_cell_names_the_defaults_it_used(capsys):
    code, out, err = run(capsys, "fk", "--cell", CELL, "--joints", JOINTS)
    assert code == 0, err
    assert out.splitlines()[0] == (
        "kr16_track_turntable: TCP of the bare flange (no --tool) in frame 'world', track 0 mm "
        "(default), table 0 deg (default) (kuka, mm, deg)")
    code, out, err = run(capsys, "fk", "--cell", CELL, "--joints", JOINTS, "--track", "1500",
                         "--table", "30", "--tool", "torch", "--frame", "part")
    assert code == 0, err
    assert out.splitlines()[0] == ("kr16_track_turntable: TCP of tool 'torch' in frame 'part', "
                                   "track 1500 mm, table 30 deg (kuka, mm, deg)")
    code, out, err = run(capsys, "fk", "--cell", POSITIONER, "--joints", JOINTS, "--table",
                         "30,90", "--tool", "0,0,100,0,0,0")
    assert code == 0, err
    assert out.splitlines()[0].startswith(
        "kr16_positioner: TCP of tool 0,0,100,0,0,0 (X,Y,Z,A,B,C) in frame 'world', positioner")


def test_batch_fk_and_ik_name_what_they_assumed_on_stderr(capsys, tmp_path):
    joints = tmp_path / "joints.csv"
    joints.write_text("a1,a2,a3,a4,a5,a6,track\n0,-90,90,0,45,0,100\n10,-80,80,0,40,0,200\n")
    code, _, err = run(capsys, "fk", "--cell", CELL, "--input", joints, "-o", tmp_path / "p.csv")
    assert code == 0, err
    assert ("kr16_track_turntable: TCP of the bare flange (no --tool) in frame 'world', track "
            "from column 'track' (mm), table 0 (default) deg") in err
    code, _, err = run(capsys, "ik", "--cell", CELL, "--input", tmp_path / "p.csv", "--tool",
                       "torch", "-o", tmp_path / "q.csv")
    assert "TCP of tool 'torch' in frame 'world', track chosen per pose, table 0 (default)" in err


def test_ik_in_a_cell_names_the_tool(capsys):
    code, out, err = run(capsys, "ik", "--cell", CELL, "--pose", "1200,0,1200,0,90,0")
    assert code == 0, err
    assert out.startswith("kr16_track_turntable: TCP of the bare flange (no --tool) in frame "
                          "'world', track ")


def test_reach_and_sweep_name_what_they_assumed_on_stderr(capsys, tmp_path):
    # Issue 27.5: every printed result names the tool, frame, track and table it used.
    seam = ROOT / "examples" / "seam_part.csv"
    code, _, err = run(capsys, "reach", "--cell", CELL, seam, "--frame", "part", "--tool",
                       "torch", "-o", tmp_path / "r.csv")
    assert code == 0, err
    assert err.splitlines()[0] == ("kr16_track_turntable: TCP of tool 'torch' in frame 'part', "
                                   "track chosen per target, table from column(s) table (deg)")
    targets = tmp_path / "t.csv"
    targets.write_text("\n".join(seam.read_text().splitlines()[:4]).replace(",table", ",note")
                       + "\n")
    code, _, err = run(capsys, "reach", "--cell", CELL, targets, "--frame", "part",
                       "--track", "1500", "--choose-table")
    assert code == 0, err
    assert ("kr16_track_turntable: TCP of the bare flange (no --tool) in frame 'part', track "
            "1500 mm (given), table chosen per target (--choose-table)") in err
    code, out, err = run(capsys, "sweep", "--cell", CELL, "--targets", seam, "--layouts",
                         ROOT / "examples" / "layouts_kr16.yaml", "--frame", "part", "--tool",
                         "torch", "--workers", "1", "--top", "2")
    assert code == 0, err
    assert ("TCP of tool 'torch' in frame 'part', track chosen per target and layout, table "
            "from column(s) table (deg)") in err
    assert out.startswith("the best 2 of 18 layouts") and len(out.splitlines()) == 3 + 2


@pytest.mark.parametrize("argv,message", [
    (["identify", "--propose", "10", "--robot", "kuka_kr16", "-o", "{tmp}/x.json"],
     ("-o {tmp}/x.json: the name says JSON, but this writes the proposed configurations as CSV; "
     "name it x.csv")),
    (["identify", "{tmp}/tracker.csv", "--robot", "kuka_kr16", "-o", "{tmp}/x.json"],
     ("-o {tmp}/x.json: the name says JSON, but this writes the identified model file as YAML; "
     "name it x.yaml")),
    (["calibrate", "tcp", "{tmp}/t.csv", "-o", "{tmp}/r.json"],
     ("-o {tmp}/r.json: the name says JSON, but this writes the report (add --json for the JSON "
     "result) as text")),
    (["calibrate", "tcp", "{tmp}/t.csv", "--json", "-o", "{tmp}/r.yaml"],
     "the name says YAML, but this writes the result as JSON; name it r.json"),
    (["fk", "kuka_kr16", "--joints", JOINTS, "-o", "{tmp}/p.json"],
     "the name says JSON, but this writes the poses as CSV"),
    (["export", "--cell", CELL, "--format", "kuka", "-o", "{tmp}/k.yaml"],
     "the name says YAML, but this writes the kuka export as text"),
    (["reach", "--cell", CELL, "{tmp}/t.csv", "-o", "{tmp}/r.json"],
     "the name says JSON, but this writes the scores as CSV"),
])
def test_an_output_named_as_another_kind_of_file_is_refused(capsys, tmp_path, argv, message):
    (tmp_path / "t.csv").write_text("x,y,z,a,b,c\n1000,0,1000,0,90,0\n")
    (tmp_path / "tracker.csv").write_text("a1,a2,a3,a4,a5,a6,x,y,z\n0,-90,90,0,0,0,1,2,3\n")
    code, out, err = run(capsys, *(a.format(tmp=tmp_path) for a in argv))
    assert code == 2 and out == ""
    assert err.startswith("error: ") and message.format(tmp=tmp_path) in err
    assert not [p for p in tmp_path.iterdir() if p.suffix in (".json", ".yaml")]


def test_calibrate_names_the_tool_frame_track_and_table_it_used(tmp_path, capsys):
    from robotcell.cell import Cell
    from robotcell.studies.simulate import simulate

    truth = Cell.load(CELL)
    cell = tmp_path / "cell.yaml"
    truth.save(cell)
    table = tmp_path / "table.csv"
    touches = simulate(truth, "turntable", noise=1e-4, seed=2, tool="torch")
    touches.write_csv(table)
    code, _, err = run(capsys, "calibrate", "turntable", table, "--cell", cell, "--tool", "torch",
                       *touches.options)
    assert code == 0, err
    assert ("assumed: kr16_track_turntable: tool 'torch' (joint values a1..a6); result T_world_B "
            "in frame 'world'; track from column 'track' (mm); table from column 'e1' (deg)"
            ) in err.splitlines()
    tcp = tmp_path / "tcp.csv"
    tcp.write_text("x,y,z,a,b,c\n1000,0,500,0,90,0\n1000,0,500,30,90,0\n"
                   "1000,0,500,60,80,0\n1000,0,500,90,70,10\n")
    code, _, err = run(capsys, "calibrate", "tcp", tcp, "--json")
    assert ("assumed: no tool (flange poses x, y, z, a, b, c); result T_F_TCP on the flange"
            in err.splitlines()), err
