"""Values outside every limit: refused in a calibration, named in fk, ik, reach and sweep.

Each joint, track and table value of an input file is checked against the limits of the arm or
axis it belongs to (docs/calibration.md, "Measurement CSV"). A calibration refuses a value
outside them with exit status 2, naming the line and the column, and writes nothing; fk computes
the pose and names the value in a warning line; fk, ik, reach and sweep name a track or table
value outside the cell's limits in a warning line, with its line and column, and compute on (a
track position beyond 100 m is a typing error, refused). A cell file whose lengths reach
beyond any real cell (100 m) is refused, naming the key (docs/cell.md, "Plausibility").
"""

from __future__ import annotations

import csv
import io
import shutil
from pathlib import Path

import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.studies.simulate import simulate

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "cell_kr16_track_turntable.yaml"
POSITIONER = ROOT / "examples" / "cell_kr16_positioner.yaml"
SEAM = ROOT / "examples" / "seam_part.csv"


@pytest.fixture
def cell(tmp_path) -> Path:
    path = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLE, path)
    return path


def simulated(cell_path: Path, procedure: str, path: Path, **kwargs) -> Path:
    simulate(Cell.load(cell_path), procedure, seed=3, **kwargs).write_csv(path)
    return path


def scaled(path: Path, column: str, factor: float, rows: slice = slice(None)) -> Path:
    """``path`` with ``column`` multiplied by ``factor`` in ``rows`` (data rows)."""
    table = list(csv.reader(io.StringIO(path.read_text())))
    k = table[0].index(column)
    for r in table[1:][rows]:
        r[k] = repr(float(r[k]) * factor)
    out = path.with_name(f"{path.stem}_{column}{path.suffix}")
    out.write_text("\n".join(",".join(r) for r in table) + "\n")
    return out


def assert_refused(capsys, cell: Path, args: list, *needles: str) -> str:
    before = cell.read_bytes()
    code, _, err = run(capsys, *args)
    assert code == 2, err
    assert err.splitlines()[-1].startswith("error: ") and all(n in err for n in needles), err
    assert cell.read_bytes() == before and not list(cell.parent.glob("*.bak"))
    return err


# -- calibrations refuse ----------------------------------------------------------------------------
def test_tcp_joint_a6_scaled_by_1000_is_refused_naming_line_and_column(tmp_path, cell, capsys):
    touches = scaled(simulated(cell, "tcp", tmp_path / "tcp.csv", tool="pointer"), "a6", 1000.0)
    assert_refused(capsys, cell, ["calibrate", "tcp", touches, "--cell", cell, "--name", "torch"],
                   "joint values outside the limits of kuka_kr16: line 2, column 'a6': ",
                   "(limits -350 .. 350 deg)")


def test_joint_values_outside_the_limits_are_refused_without_a_cell(tmp_path, cell, capsys):
    touches = scaled(simulated(cell, "frame", tmp_path / "f.csv", tool="pointer",
                               frame="fixture"), "a1", -100.0, slice(3, 4))
    code, _, err = run(capsys, "calibrate", "frame", touches, "--robot", "kuka_kr16", "--tool",
                       "250,0,0,0,0,0")
    assert code == 2 and "line 5, column 'a1': " in err and "(limits -185 .. 185 deg)" in err


def test_workpiece_table_angles_of_20000_deg_are_refused(tmp_path, cell, capsys):
    touches = scaled(simulated(cell, "workpiece", tmp_path / "wp.csv", tool="pointer",
                               frame="part"), "e1", 100.0)
    assert_refused(capsys, cell, ["calibrate", "workpiece", touches, "--cell", cell, "--name",
                                  "part", "--tool", "pointer"],
                   "values outside the limits of the turntable 'DKP_400_01' of ",
                   "column 'e1': ", "(limits -360 .. 360 deg)")


def test_turntable_and_track_columns_outside_their_limits_are_refused(tmp_path, cell, capsys):
    table = simulated(cell, "turntable", tmp_path / "t.csv", tool="pointer")
    assert_refused(capsys, cell, ["calibrate", "turntable", scaled(table, "e1", 30.0), "--cell",
                                  cell, "--tool", "pointer"], "column 'e1'", "-360 .. 360 deg")
    assert_refused(capsys, cell, ["calibrate", "turntable", scaled(table, "track", 10.0),
                                  "--cell", cell, "--tool", "pointer"],
                   "track 'KL1500'", "column 'track': 30000 mm (limits 0 .. 6000 mm)")
    track = simulated(cell, "track", tmp_path / "track.csv", tool="pointer")
    assert_refused(capsys, cell, ["calibrate", "track", scaled(track, "e1", -1.0), "--cell", cell,
                                  "--tool", "pointer", "--reference", "1500,800,300"],
                   "column 'e1'", "(limits 0 .. 6000 mm)")


def test_positioner_axis_values_outside_their_limits_are_refused(tmp_path, capsys):
    cell = tmp_path / "pos.yaml"
    shutil.copy(POSITIONER, cell)
    touches = scaled(simulated(cell, "positioner", tmp_path / "p.csv", tool="pointer"), "e1", 10.0)
    assert_refused(capsys, cell, ["calibrate", "positioner", touches, "--cell", cell, "--tool",
                                  "pointer"], "positioner", "column 'e1'", "-95 .. 95 deg")


def test_a_value_at_a_limit_rounded_in_the_file_is_within_it(tmp_path, cell, capsys):
    touches = simulated(cell, "tcp", tmp_path / "tcp.csv", tool="pointer")
    table = list(csv.reader(io.StringIO(touches.read_text())))
    table[1][0] = "185.0004"  # a1 limit 185 deg, written with the pendant's rounding
    touches.write_text("\n".join(",".join(r) for r in table) + "\n")
    code, _, err = run(capsys, "calibrate", "tcp", touches, "--cell", cell, "--name", "torch")
    assert code in (0, 3) and "outside the limits" not in err


# -- fk, ik, reach and sweep warn about axis values outside the limits ------------------------------------------------
def test_fk_names_each_joint_value_outside_the_limits_in_a_warning(tmp_path, capsys):
    joints = tmp_path / "j.csv"
    joints.write_text("a1,a2,a3,a4,a5,a6\n0,-90,90,0,0,0\n0,-90,90,0,0,150000\n")
    code, out, err = run(capsys, "fk", "kuka_kr16", "--input", joints)
    assert code == 0 and len(out.splitlines()) == 3
    assert err == (f"warning: {joints}: joint values outside the limits of kuka_kr16: line 3, "
                   "column 'a6': 150000 deg (limits -350 .. 350 deg); the pose is computed, but "
                   "the robot cannot move there\n")
    code, _, err = run(capsys, "fk", "kuka_kr16", "--joints", "0,-90,90,0,0,400")
    assert code == 0 and "limits of kuka_kr16: a6: 400 deg (limits -350 .. 350 deg)" in err


def test_fk_ik_reach_sweep_warn_naming_the_line_of_a_track_or_table_value_outside(tmp_path, cell,
                                                                                 capsys):
    joints = tmp_path / "j.csv"
    joints.write_text("a1,a2,a3,a4,a5,a6,track,table\n0,-90,90,0,45,0,1500,0\n"
                      "0,-90,90,0,45,0,7000,0\n")
    code, out, err = run(capsys, "fk", "--cell", cell, "--input", joints)
    assert code == 0 and len(out.splitlines()) == 3
    assert err.count("warning: ") == 1 and "line 3, column 'track': 7000 mm (limits 0 .. 6000 mm)" \
        "; computed anyway, but the axis cannot move there" in err
    seam = tmp_path / "seam.csv"
    text = SEAM.read_text().splitlines()
    k = text[0].split(",").index("table")
    row = text[4].split(",")
    row[k] = "400"
    seam.write_text("\n".join(text[:4] + [",".join(row)] + text[5:]) + "\n")
    for args in (["reach", "--cell", cell, seam, "--frame", "part", "--tool", "torch"],
                 ["ik", "--cell", cell, "--input", seam, "--frame", "part", "--tool", "torch"],
                 ["sweep", "--cell", cell, "--targets", seam, "--layouts",
                  ROOT / "examples" / "layouts_kr16.yaml", "--frame", "part", "--tool", "torch",
                  "--workers", "1"]):
        code, _, err = run(capsys, *args)
        assert code == 0 and err.count("line 5, column 'table': 400 deg (limits -360 .. 360 "
                                       "deg); computed anyway") == 1, err


# -- cell files: plausible lengths -------------------------------------------------------------------
@pytest.mark.parametrize("old, new, key", [
    ("frame: {x: 3000, y: 1600,", "frame: {x: 3000, y: 1.0e+308,", "turntable.frame.y"),
    ("frame: {x: 312.5, y: -1.2,", "frame: {x: 3.125e+8, y: -1.2,", "tools.torch.frame.x"),
    ("max: 6000", "max: 6.0e+9", "track.max"),
    ("robot_at_zero: {x: 0, y: 0, z: 450,", "robot_at_zero: {x: 0, y: 0, z: -4.5e+5,",
     "track.robot_at_zero.z"),
])
def test_a_cell_length_beyond_100_m_is_refused_naming_its_key(tmp_path, capsys, old, new, key):
    text = EXAMPLE.read_text()
    assert old in text
    path = tmp_path / "cell.yaml"
    path.write_text(text.replace(old, new))
    for args in (["fk", "--cell", path, "--joints", "0,-90,90,0,0,0"], ["cell", "show", path]):
        code, out, err = run(capsys, *args)
        assert code == 2 and out == ""
        assert f"key '{key}' is " in err and "beyond 100 m, the size of any real robot cell" in err


def test_a_track_scale_of_1000_is_refused(tmp_path, capsys):
    path = tmp_path / "cell.yaml"
    path.write_text(EXAMPLE.read_text().replace("scale: 1.0", "scale: 1000.0"))
    code, _, err = run(capsys, "export", "--cell", path, "--format", "kuka")
    assert code == 2 and "key 'track.scale' is 1000, outside 0.1 .. 10" in err


@pytest.mark.parametrize("path", sorted((ROOT / "examples").glob("cell_*.yaml"))
                         + sorted((ROOT / "tests" / "data").glob("*.saved.yaml")))
def test_every_example_cell_is_plausible(path):
    cell = Cell.load(path)
    assert all(cell.for_robot(name).robot is not None for name in cell.robot_names)


def test_a_track_without_limits_still_ends_at_100_m(tmp_path, capsys):
    text = EXAMPLE.read_text()
    assert "  min: 0\n  max: 6000\n" in text
    cell = tmp_path / "cell.yaml"
    cell.write_text(text.replace("  min: 0\n  max: 6000\n", ""))
    for args in (["fk", "--cell", cell, "--joints", "0,-90,90,0,45,0", "--track", "1e300"],
                 ["ik", "--cell", cell, "--pose", "100,0,50,0,180,0", "--frame", "part",
                  "--tool", "torch", "--track", "1e300"]):
        code, out, err = run(capsys, *args)
        assert code == 2 and out == ""
        assert "track position 1e+300 mm is outside the track limits [-100000, 100000] mm" in err
    joints = tmp_path / "j.csv"
    joints.write_text("a1,a2,a3,a4,a5,a6,track\n0,-90,90,0,45,0,1e14\n")
    code, _, err = run(capsys, "fk", "--cell", cell, "--input", joints)
    assert code == 2 and "line 2, column 'track': 1e+14 mm (limits -100000 .. 100000 mm)" in err
