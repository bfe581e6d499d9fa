"""The 2-axis positioner on the command line: simulate, calibrate into a cell, fk/ik, export.

The truth is the example tilt-rotate cell with its axis lines moved by a few mm and tenths of a
degree; the calibrated chain must move the table as the truth does, to within a few of the
1-sigma values the calibration reports.
"""

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell, Positioner
from robotcell.cli.terms import CLI_TERMS
from robotcell.errors import terms

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "cell_kr16_positioner.yaml"
TURNTABLE_CELL = ROOT / "examples" / "cell_kr16_track_turntable.yaml"

#: The nominal positioner of the example, and the "true" one: root moved by 2 mm, the axes
#: tilted by 0.2-0.3 deg, a 1.5 mm common normal between them and a 0.5 deg zero offset.
PERTURB = [
    ("frame: {x: 1100, y: 0, z: 650, a: 180, b: 0, c: 90}",
     "frame: {x: 1102, y: -1.5, z: 651.5, a: 180.2, b: 0.15, c: 89.8}"),
    ("{name: E1, a: 0, alpha: -90,", "{name: E1, a: 1.5, alpha: -89.7,"),
    ("{name: E2, a: 0, alpha: 0, d: 150, theta: 0,", "{name: E2, a: 0, alpha: 0, d: 150, theta: 0.5,"),
]


def truth_file(tmp_path):
    text = EXAMPLE.read_text(encoding="utf-8")
    for old, new in PERTURB:
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / "truth.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def moved(cell, v, x0):
    """Where a point x0 (world, m) on the table at axis 0 goes at axis values v (rad)."""
    T = cell.frame_pose("part", table=v) @ np.linalg.inv(cell.frame_pose("part"))
    return (T @ np.append(x0, 1.0))[..., :3]


def test_simulate_calibrate_export_round_trip(tmp_path, capsys):
    truth = truth_file(tmp_path)
    nominal = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLE, nominal)
    csv = tmp_path / "touches.csv"
    code, _, err = run(capsys, "simulate", "positioner", "--cell", truth, "--noise", "0.1",
                       "--seed", "7", "--tool", "pointer", "-o", csv)
    assert code == 0, err
    assert f"robotcell calibrate positioner {csv} --cell " in err and "--tool pointer" in err
    header = csv.read_text().splitlines()[0].split(",")
    assert header == ["a1", "a2", "a3", "a4", "a5", "a6", "e1", "e2"]
    assert len(csv.read_text().splitlines()) == 13  # 3 tilt x 4 rotate values
    # The pointer is exact here (the truth's own): a small nominal accuracy says so.
    code, out, err = run(capsys, "calibrate", "positioner", csv, "--cell", nominal, "--tool",
                         "pointer", "--sigma", "0.1", "--nominal-accuracy", "0.001,0.0001",
                         "--json")
    assert code == 0, err
    assert f"updated {nominal}: positioner 'DKP_2' (axes, root)" in err
    res = json.loads(out)
    assert res["procedure"] == "positioner-2axis" and res["verdict"]["level"] != "poor"
    cal, true, nom = Cell.load(nominal), Cell.load(truth), Cell.load(EXAMPLE)
    assert isinstance(cal.turntable, Positioner) and cal.turntable.provenance.source == "positioner"
    # the table moves like the truth's: bound from the reported 1-sigma of the axis points (mm)
    # and directions, at the 0.35 m lever of the test points about the axes
    s = res["sigma"]
    sigma_mm = (max(s["tilt_point_mm"] + s["rotate_point_mm"])
                + 350.0 * max(s["tilt_axis"] + s["rotate_axis"]))
    rng = np.random.default_rng(3)
    v = np.column_stack([rng.uniform(-0.5, 0.5, 40), rng.uniform(-3.0, 3.0, 40)])
    x0 = np.array([1.1, 0.0, 0.8]) + rng.uniform(-0.2, 0.2, (40, 3)) * [1, 1, 0]
    want = np.array([moved(true, v[i], x0[i]) for i in range(40)])
    got = np.array([moved(cal, v[i], x0[i]) for i in range(40)])
    before = np.array([moved(nom, v[i], x0[i]) for i in range(40)])
    err_mm = np.linalg.norm(got - want, axis=1) * 1e3
    assert err_mm.max() < 4 * sigma_mm, (err_mm.max(), sigma_mm)
    assert np.linalg.norm(before - want, axis=1).max() * 1e3 > 10 * sigma_mm  # it had to move
    # the controller exports take the calibrated cell
    code, out, err = run(capsys, "export", "--cell", nominal, "--format", "kuka")
    assert code == 0, err
    assert "$ET1_TA2A1=" in out and 'MACHINE_DEF[2]={NAME[] "DKP_2"' in out
    code, out, err = run(capsys, "export", "--cell", nominal, "--format", "urdf")
    assert code == 0, err
    assert out.count('type="revolute"') >= 8  # six arm axes and both positioner axes


def test_calibrate_positioner_terminal_report_and_robot_base(tmp_path, capsys):
    truth = truth_file(tmp_path)
    csv = tmp_path / "touches.csv"
    assert run(capsys, "simulate", "positioner", "--cell", truth, "--seed", "2", "--tool",
               "pointer", "-o", csv)[0] == 0
    # without --cell: in the robot base (here the world), started from the circle point analysis
    code, out, err = run(capsys, "calibrate", "positioner", csv, "--robot", "kuka_kr16",
                         "--tool", "250,0,0,0,0,0", "--sigma", "0.1")
    assert code == 0, err
    for line in ("calibration: positioner-2axis", "tilt_point (mm):", "tilt_axis:",
                 "rotate_point (mm):", "rotate_axis:", "normal_length (mm):", "tilt_zero (deg):",
                 "rotate_zero (deg):", "1-sigma", "verdict:"):
        assert line in out
    line = out.split("tilt_axis:")[1].splitlines()[0]
    tilt = [float(x) for x in line.split("(")[0].split(",")]
    sigma = [float(x) for x in line.split("(1-sigma")[1].split(",")[:3]]
    assert line.endswith("relative to the robot base, from its own touches only)")
    true_tilt = Cell.load(truth).turntable.T_parent_root[:3, 2]
    angle = math.acos(min(1.0, abs(np.dot(tilt, true_tilt))))
    assert angle < 4 * np.linalg.norm(sigma) < math.acos(true_tilt[1])  # within 4 sigma, and
    # closer to the truth than the nominal direction (world Y) is
    length = float(out.split("normal_length (mm):")[1].split()[0])
    assert length == pytest.approx(1.5, abs=0.4)


def test_poor_positioner_calibration_writes_nothing(tmp_path, capsys):
    truth = truth_file(tmp_path)
    cell = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLE, cell)
    csv = tmp_path / "touches.csv"
    assert run(capsys, "simulate", "positioner", "--cell", truth, "--seed", "4", "--noise", "3",
               "--tool", "pointer", "-o", csv)[0] == 0
    before = cell.read_bytes()
    code, out, err = run(capsys, "calibrate", "positioner", csv, "--cell", cell, "--tool",
                         "pointer")
    assert code == 3 and "error: poor calibration, nothing written" in err
    assert "verdict: POOR" in out and cell.read_bytes() == before
    code, _, err = run(capsys, "calibrate", "positioner", csv, "--cell", cell, "--tool",
                       "pointer", "--accept-poor")
    assert code == 0 and "written anyway" in err and cell.read_bytes() != before


def test_calibrate_positioner_refusals(tmp_path, capsys):
    truth = truth_file(tmp_path)
    csv = tmp_path / "touches.csv"
    assert run(capsys, "simulate", "positioner", "--cell", truth, "--seed", "2", "--tool",
               "pointer", "-o", csv)[0] == 0
    turntable = tmp_path / "turntable.yaml"
    shutil.copy(TURNTABLE_CELL, turntable)
    code, _, err = run(capsys, "calibrate", "positioner", csv, "--cell", turntable)
    assert code == 2 and "has no positioner of 2 axes (tilt, rotate)" in err
    code, _, err = run(capsys, "calibrate", "positioner", csv, "--cell", truth, "--robot",
                       "kuka_kr16")
    assert code == 2 and "error: --robot and --cell both give the robot model" in err
    lines = csv.read_text().splitlines()
    no_e2 = tmp_path / "no_e2.csv"
    no_e2.write_text("\n".join(",".join(r.split(",")[:7]) for r in lines) + "\n")
    code, _, err = run(capsys, "calibrate", "positioner", no_e2, "--cell", truth, "--tool",
                       "pointer")
    assert code == 2 and "missing column(s) e2" in err
    small = tmp_path / "small.csv"
    small.write_text("\n".join(lines[:4]) + "\n")  # tilt -30 only, rotate 0, 90, 180
    code, _, err = run(capsys, "calibrate", "positioner", small, "--robot", "kuka_kr16")
    assert code == 2 and "no 3 touches turn e1 (tilt) alone over 10 deg or more" in err
    code, _, err = run(capsys, "calibrate", "positioner", small, "--cell", truth)
    assert code == 2 and "say which tool touched, --tool NAME (the cell has: pointer" in err
    code, _, err = run(capsys, "calibrate", "positioner", small, "--cell", truth, "--tool",
                       "pointer")
    assert code == 2 and "3 rows give 9 measured coordinates for 7 identifiable unknowns" in err
    with_track = tmp_path / "track.csv"
    with_track.write_text("\n".join(r + (",track" if i == 0 else ",0")
                                    for i, r in enumerate(lines)) + "\n")
    code, _, err = run(capsys, "calibrate", "positioner", with_track, "--robot", "kuka_kr16")
    assert code == 2 and "column 'track' (track position of each touch) needs --cell" in err


def test_simulate_positioner_refusals(tmp_path, capsys):
    code, _, err = run(capsys, "simulate", "positioner", "--cell", TURNTABLE_CELL, "--tool",
                       "pointer")
    assert code == 2 and "needs a cell with a positioner of 2 axes" in err
    code, _, err = run(capsys, "simulate", "positioner", "--cell", EXAMPLE, "--tool", "pointer",
                       "--tilts", "-120,0,30")
    assert code == 2 and "tilt value(s) -120 deg are outside the axis limits [-95, 95] deg" in err
    code, _, err = run(capsys, "simulate", "positioner", "--cell", EXAMPLE, "--tool", "pointer",
                       "--rotates", "0,90")
    assert code == 2 and "at least 2 tilt and 3 rotate values, got 3 and 2" in err
    code, _, err = run(capsys, "simulate", "turntable", "--cell", TURNTABLE_CELL, "--tilts", "0,10")
    assert code == 2 and "--tilts does not apply to turntable (it is for positioner)" in err


def test_simulate_positioner_design_options(tmp_path, capsys):
    code, out, err = run(capsys, "simulate", "positioner", "--cell", EXAMPLE, "--tool", "pointer",
                         "--tilts", "-20,20", "--rotates", "0,120,240", "--radius", "150",
                         "--seed", "1")
    assert code == 0, err
    rows = [r.split(",") for r in out.splitlines()[1:]]
    assert sorted({(float(r[6]), float(r[7])) for r in rows}) == [
        (t, r) for t in (-20.0, 20.0) for r in (0.0, 120.0, 240.0)]


def test_fk_takes_one_table_value_per_positioner_axis(tmp_path, capsys):
    joints = "0,-90,90,0,45,0"
    code, out, err = run(capsys, "fk", "--cell", EXAMPLE, "--joints", joints, "--table", "30,90",
                         "--frame", "part", "--format", "matrix")
    assert code == 0, err
    cell = Cell.load(EXAMPLE)
    q = np.radians([0, -90, 90, 0, 45, 0])
    T = cell.fk(q, table=np.radians([30, 90]), frame="part")
    got = np.array([[float(x) for x in r.split()] for r in out.splitlines()[1:5]])
    assert np.allclose(got[:3, :3], T[:3, :3], atol=1e-6)
    assert np.allclose(got[:3, 3], T[:3, 3] * 1e3, atol=1e-5)
    # batch: columns e1, e2 per row, the same poses
    batch = tmp_path / "joints.csv"
    batch.write_text("a1,a2,a3,a4,a5,a6,e1,e2\n0,-90,90,0,45,0,30,90\n0,-90,90,0,45,0,-10,200\n")
    code, out, err = run(capsys, "fk", "--cell", EXAMPLE, "--input", batch, "--frame", "part",
                         "--format", "matrix")
    assert code == 0, err
    rows = np.array([[float(x) for x in r.split(",")] for r in out.splitlines()[1:]])
    T2 = cell.fk(q, table=np.radians([[30, 90], [-10, 200]]), frame="part")
    assert np.allclose(rows[:, [3, 7, 11]], T2[:, :3, 3] * 1e3, atol=1e-5)


@pytest.mark.parametrize("args, message", [
    (["--table", "30"], "--table: positioner 'DKP_2' has 2 axes: give 2 comma-separated value(s)"),
    (["--table", "30,90,10"], "--table: positioner 'DKP_2' has 2 axes"),
])
def test_fk_and_ik_refuse_wrong_table_values(args, message, capsys):
    code, _, err = run(capsys, "fk", "--cell", EXAMPLE, "--joints", "0,-90,90,0,45,0", *args)
    assert code == 2 and f"error: {message}" in err
    code, _, err = run(capsys, "ik", "--cell", EXAMPLE, "--pose", "50,0,0,0,180,0", "--frame",
                       "part", *args)
    assert code == 2 and f"error: {message}" in err


@pytest.mark.parametrize("args, message", [
    (["--table", "30,500"], "positioner axis E2 value 500 deg is outside its limits [-400, 400]"),
    (["--table", "-100,0"], "positioner axis E1 value -100 deg is outside its limits [-95, 95]"),
])
def test_fk_and_ik_warn_about_table_values_outside_the_limits(args, message, capsys):
    code, out, err = run(capsys, "fk", "--cell", EXAMPLE, "--joints", "0,-90,90,0,45,0", *args)
    assert code == 0 and out and f"warning: {message} deg; computed anyway" in err
    code, _, err = run(capsys, "ik", "--cell", EXAMPLE, "--pose", "50,0,0,0,180,0", "--frame",
                       "part", *args, "--all")
    assert code == 0 and f"warning: {message}" in err


def test_batch_table_column_refusals(tmp_path, capsys):
    one = tmp_path / "one.csv"
    one.write_text("a1,a2,a3,a4,a5,a6,e1\n0,-90,90,0,45,0,30\n")
    code, _, err = run(capsys, "fk", "--cell", EXAMPLE, "--input", one)
    assert code == 2 and "positioner 'DKP_2' has 2 axes: missing column(s) e2" in err
    table = tmp_path / "table.csv"
    table.write_text("x,y,z,a,b,c,table\n50,0,0,0,180,0,30\n")
    code, _, err = run(capsys, "ik", "--cell", EXAMPLE, "--input", table, "--frame", "part")
    assert code == 2 and "column 'table' holds a turntable angle; positioner 'DKP_2' has 2" in err
    code, _, err = run(capsys, "fk", "--cell", TURNTABLE_CELL, "--joints", "0,-90,90,0,45,0",
                       "--table", "10,20")
    assert code == 2 and "--table: a turntable has one angle" in err


def test_ik_table_values_and_batch_columns(tmp_path, capsys):
    code, out, err = run(capsys, "ik", "--cell", EXAMPLE, "--pose", "50,0,0,0,180,0", "--frame",
                         "part", "--tool", "torch", "--table", "10,20")
    assert code == 0, err
    assert "positioner E1, E2 10.0000, 20.0000 deg; kuka_kr16, opw solver; angles in degrees" in out
    poses = tmp_path / "poses.csv"
    poses.write_text("x,y,z,a,b,c,e1,e2\n50,0,0,0,180,0,10,20\n20,10,0,0,180,0,-15,90\n")
    code, out, err = run(capsys, "ik", "--cell", EXAMPLE, "--input", poses, "--frame", "part",
                         "--tool", "torch", "--near", "0,-90,90,0,45,0")
    assert code == 0, err
    lines = out.splitlines()
    assert lines[0].startswith("pose,found,track,e1,e2,a1,")
    cell = Cell.load(EXAMPLE)
    for line, v, p in zip(lines[1:], ([10, 20], [-15, 90]), ([0.05, 0, 0], [0.02, 0.01, 0])):
        r = [float(x) for x in line.split(",")]
        assert r[1] == 1 and r[3:5] == v
        T = cell.fk(np.radians(r[5:11]), table=np.radians(v), tool="torch", frame="part")
        assert np.allclose(T[:3, 3], p, atol=1e-6)


def test_ik_normal_up_turns_the_weld_normal_up(tmp_path, capsys):
    # a weld on a 45 deg flank of the part: its surface normal (-Z of the target) is tilted
    pose = "60,10,5,0,135,0"
    code, out, err = run(capsys, "ik", "--cell", EXAMPLE, "--pose", pose, "--frame", "part",
                         "--tool", "torch", "--table", "normal-up")
    assert code == 0, err
    head = out.splitlines()[0]
    assert "(chosen: normal up)" in head
    v = [float(x) for x in head.split("positioner E1, E2 ")[1].split(" deg")[0].split(",")]
    row = out.splitlines()[3].split()
    q = np.radians([float(x) for x in row[3:9]])
    cell = Cell.load(EXAMPLE)
    T = cell.fk(q, table=np.radians(v), tool="torch")
    assert np.allclose(T[:3, 2], [0, 0, -1], atol=1e-4)  # straight down (printed to 0.001 deg)
    assert abs(v[0]) > 10  # the positioner had to tilt
    poses = tmp_path / "poses.csv"
    poses.write_text(f"x,y,z,a,b,c\n{pose}\n")
    code, out, err = run(capsys, "ik", "--cell", EXAMPLE, "--input", poses, "--frame", "part",
                         "--tool", "torch", "--table", "normal-up", "--near", "0,-90,90,0,45,0")
    assert code == 0, err
    r = [float(x) for x in out.splitlines()[1].split(",")]
    assert r[3:5] == pytest.approx(v, abs=1e-4)


def test_ik_normal_up_refusals(capsys):
    code, _, err = run(capsys, "ik", "--cell", TURNTABLE_CELL, "--pose", "50,0,0,0,180,0",
                       "--frame", "part", "--table", "normal-up")
    assert code == 2 and "error: --table normal-up needs a positioner of 2 axes" in err
    code, _, err = run(capsys, "ik", "--cell", EXAMPLE, "--pose", "50,0,0,0,180,0",
                       "--table", "normal-up")
    assert code == 2 and ("error: --table normal-up needs the target in a frame carried by the "
                          "positioner (--frame part), got --frame world") in err
    code, _, err = run(capsys, "fk", "--cell", EXAMPLE, "--joints", "0,-90,90,0,45,0",
                       "--table", "normal-up")
    assert code == 2 and "error: --table must be comma-separated numbers" in err


def test_example_positioner_cell_levels_the_plate_at_zero():
    cell = Cell.load(EXAMPLE)
    pos = cell.turntable
    assert isinstance(pos, Positioner) and pos.n_axes == 2
    T0 = cell.frame_pose("part") @ np.linalg.inv(cell.frames["part"].pose)
    assert np.allclose(T0[:3, 2], [0, 0, 1]) and np.allclose(T0[:3, 3], [1.1, 0, 0.8])
    # the tilt axis is world Y, the rotate axis the plate's Z
    T30 = cell.frame_pose("part", table=np.radians([30, 0])) @ np.linalg.inv(cell.frames["part"].pose)
    assert np.allclose(T30[:3, 2], [math.sin(math.radians(30)), 0, math.cos(math.radians(30))])


def test_cli_positioner_equals_the_library_call_byte_for_byte(tmp_path, capsys, monkeypatch):
    from robotcell.cell import Provenance
    from robotcell.cell import calibrate as cellcal
    from robotcell.io.tables import read_csv

    stamp = "2026-01-02T03:04:05+00:00"
    monkeypatch.setattr(Provenance, "now", classmethod(
        lambda cls, source, rms_mm=None, note="": cls(source=source, time=stamp, rms_mm=rms_mm,
                                                      note=note)))
    truth = truth_file(tmp_path)
    csv = tmp_path / "touches.csv"
    assert run(capsys, "simulate", "positioner", "--cell", truth, "--seed", "5", "--tool",
               "pointer", "-o", csv)[0] == 0
    cli_file, lib_file = tmp_path / "cli.yaml", tmp_path / "lib.yaml"
    shutil.copy(EXAMPLE, cli_file)
    shutil.copy(EXAMPLE, lib_file)  # both update the file as written
    code, out, err = run(capsys, "calibrate", "positioner", csv, "--cell", cli_file, "--tool",
                         "pointer", "--json")
    assert code == 0, err
    with terms(CLI_TERMS):  # the library's messages in the command line's words
        got = cellcal.positioner(Cell.load(EXAMPLE), read_csv(csv), tool="pointer",
                                 source=str(csv), file=csv)
        got.cell.save(lib_file)
        assert cli_file.read_bytes() == lib_file.read_bytes()
        assert json.loads(out) == got.result.to_json()
    # independently of the library call: the root the command wrote is the simulated truth's
    root = Cell.load(cli_file).turntable.T_parent_root
    assert np.linalg.norm(root[:3, 3] - Cell.load(truth).turntable.T_parent_root[:3, 3]) < 2e-3
    assert "T_world_B" in got.result.values and "T_R_B" not in got.result.values


def track_positioner_cell(tmp_path, shift_mm=0.0):
    """The example track cell with a 2-axis positioner in the world instead of its turntable."""
    text = TURNTABLE_CELL.read_text(encoding="utf-8")
    start, end = text.index("turntable:\n"), text.index("tools:\n")
    text = text[:start] + f"""positioner:
  name: DKP_2
  parent: world
  frame: {{x: {3000 + shift_mm}, y: 1400, z: 650, a: 180, b: 0, c: 90}}
  convention: standard
  axes:
    - {{name: E1, a: 0, alpha: -90, d: 0, theta: 0, sign: 1, min: -95, max: 95}}
    - {{name: E2, a: 0, alpha: 0, d: 150, theta: {shift_mm / 10}, sign: 1, min: -400, max: 400}}
  plate: {{x: 0, y: 0, z: 0, a: 0, b: 0, c: 0}}
""" + text[end:]
    path = tmp_path / f"track_positioner_{shift_mm:g}.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_positioner_in_a_track_cell_reads_the_track_column(tmp_path, capsys):
    truth, nominal = track_positioner_cell(tmp_path, 2.0), track_positioner_cell(tmp_path)
    csv = tmp_path / "touches.csv"
    code, _, err = run(capsys, "simulate", "positioner", "--cell", truth, "--seed", "6", "--tool",
                       "pointer", "-o", csv)
    assert code == 0, err
    assert csv.read_text().splitlines()[0].endswith("e1,e2,track")
    code, out, err = run(capsys, "calibrate", "positioner", csv, "--cell", nominal, "--tool",
                         "pointer", "--json")
    assert code == 0, err
    root = np.array(json.loads(out)["matrix"])
    assert np.allclose(root[:3, 3], [3002.0, 1400.0, 650.0], atol=0.5)  # T_world_B, mm
    lines = csv.read_text().splitlines()
    no_track = tmp_path / "no_track.csv"
    no_track.write_text("\n".join(r.rsplit(",", 1)[0] for r in lines) + "\n")
    code, _, err = run(capsys, "calibrate", "positioner", no_track, "--cell", nominal, "--tool",
                       "pointer")
    assert code == 2 and "error: " in err and "missing column 'track' (track position of the robot" in err


def test_simulated_positioner_touches_reach_the_point_within_the_limits():
    from robotcell.studies.simulate import simulate

    cell = Cell.load(EXAMPLE)
    t = simulate(cell, "positioner", noise=0.0, seed=1, tool="pointer", radius=0.15)
    assert t.table.shape == (12, 2) and t.procedure == "positioner"
    assert np.all(cell.robot.within_limits(t.q)) and np.all(cell.turntable.within_limits(t.table))
    tip = cell.fk(t.q, table=t.table, tool="pointer", frame="world")[:, :3, 3]
    T_wP = cell.frame_pose("turntable") @ cell.turntable.T_root_P(t.table)
    want = (T_wP @ np.append(t.truth["point"], 1.0))[:, :3]
    assert np.allclose(t.truth["point"], [0.15, 0.0, 0.0])
    assert np.allclose(tip, want, atol=1e-9)


def test_calibrate_positioner_output_file_and_column_warnings(tmp_path, capsys):
    truth = truth_file(tmp_path)
    csv = tmp_path / "touches.csv"
    assert run(capsys, "simulate", "positioner", "--cell", truth, "--seed", "2", "--tool",
               "pointer", "-o", csv)[0] == 0
    lines = csv.read_text().splitlines()
    typo = tmp_path / "typo.csv"
    typo.write_text("\n".join(r + (",e3" if i == 0 else ",1") for i, r in enumerate(lines)) + "\n")
    out_json = tmp_path / "positioner.json"
    code, out, err = run(capsys, "calibrate", "positioner", typo, "--robot", "kuka_kr16",
                         "--tool", "250,0,0,0,0,0", "--json", "-o", out_json)
    assert code == 0, err
    assert "column(s) 'e3' not used by this command" in err
    assert json.loads(out_json.read_text())["procedure"] == "positioner-2axis"
    assert "verdict:" in out  # the terminal shows the report, the file the JSON
    # fk/ik batch files of a positioner cell know e1, e2 and warn about the rest
    batch = tmp_path / "joints.csv"
    batch.write_text("a1,a2,a3,a4,a5,a6,e1,e2,e3\n0,-90,90,0,45,0,30,90,0\n")
    code, _, err = run(capsys, "fk", "--cell", EXAMPLE, "--input", batch)
    assert code == 0 and "column(s) 'e3' not used" in err and "'e1'" not in err
