"""The one reader of targets files (robotcell.io.targets, docs/targets.md): every command and
library function that takes targets reads the same poses from the same file, positioner columns
are read wherever a table is, and a bad file is refused naming file, line and column."""

from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.cell.validation import table_columns, table_label
from robotcell.cli.cellargs import read_batch
from robotcell.cli.reach import load_targets
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor
from robotcell.io.tables import read_csv
from robotcell.io.targets import read_targets
from robotcell.programs.path import read_path
from robotcell.studies.reach import reach_map

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
TURNTABLE = EXAMPLES / "cell_kr16_track_turntable.yaml"
POSITIONER = EXAMPLES / "cell_kr16_positioner.yaml"
SEAM = EXAMPLES / "seam_part.csv"


def _seam_on_positioner(tmp_path: Path) -> Path:
    """The example seam with a positioner's axis values e1, e2 (deg) instead of its table."""
    rng = np.random.default_rng(3)
    t = read_targets(SEAM)
    lines = SEAM.read_text().splitlines()
    e = np.column_stack([rng.uniform(-30, 30, len(t)), rng.uniform(-90, 90, len(t))])
    rows = [",".join(line.split(",")[:6] + [f"{a:.3f}", f"{b:.3f}"])
            for line, (a, b) in zip(lines[1:], e)]
    p = tmp_path / "seam_e.csv"
    p.write_text("x,y,z,a,b,c,e1,e2\n" + "\n".join(rows) + "\n")
    return p


def test_the_same_file_gives_every_reader_the_same_poses(capsys):
    cell = Cell.load(TURNTABLE)
    t = read_targets(SEAM)
    values = np.loadtxt(SEAM, delimiter=",", skiprows=1)
    np.testing.assert_array_equal(t.poses, pose_from_vendor(values[:, :6], "kuka"))
    np.testing.assert_array_equal(t.table, np.radians(values[:, 6]))
    poses = {
        "program write / compensate": read_path(SEAM, cell).T,
        "reach": load_targets(str(SEAM), cell, "kuka", None, False)[0],
        "sweep": load_targets(str(SEAM), cell, "kuka", None, False, track_column=False)[0],
        "ik --cell --input": read_batch(str(SEAM), "kuka", cell).poses,
    }
    for what, T in poses.items():
        np.testing.assert_array_equal(T, t.poses, err_msg=what)
    assert read_path(SEAM, cell).table_given
    np.testing.assert_array_equal(read_path(SEAM, cell).table, t.table)
    np.testing.assert_array_equal(load_targets(str(SEAM), cell, "kuka", None, False)[1], t.table)
    # a bare robot's ik reads the poses and names the table column it does not use
    np.testing.assert_array_equal(read_batch(str(SEAM), "kuka").poses, t.poses)
    assert "column(s) 'table' not used by this command" in capsys.readouterr().err


def test_the_cli_commands_solve_the_poses_the_library_reads(tmp_path, capsys):
    cell = Cell.load(TURNTABLE)
    t = read_targets(SEAM)
    code, _, err = run(capsys, "ik", "--cell", TURNTABLE, "--input", SEAM, "--frame", "part",
                       "--tool", "torch", "--near", "0,-90,90,0,45,0",
                       "-o", tmp_path / "q.csv")
    assert code == 0, err
    cols = read_csv(tmp_path / "q.csv", allow_nan=True)
    found = cols["found"] == 1
    assert found.sum() > len(t) // 2
    q = np.column_stack([cols[f"a{i}"] for i in range(1, 7)])[found]
    np.testing.assert_allclose(np.radians(cols["table"][found]), t.table[found], atol=1e-9)
    back = cell.fk(np.radians(q), track=cols["track"][found] * 1e-3, table=t.table[found],
                   tool="torch", frame="part")
    np.testing.assert_allclose(back[:, :3, 3], t.poses[found, :3, 3], atol=1e-6)


def test_positioner_columns_reach_the_reach_map_as_the_command_reads_them(tmp_path, capsys):
    cell = Cell.load(POSITIONER)
    path = _seam_on_positioner(tmp_path)
    t = read_targets(path)  # no cell: e1, e2 as the file has them
    assert t.table_columns == ("e1", "e2") and t.table.shape == (len(t), 2)
    rm = reach_map(cell, t.poses, frame="part", tool="torch", table=t.table)
    np.testing.assert_allclose(rm.table, t.table)
    code, _, err = run(capsys, "reach", "--cell", POSITIONER, path, "--frame", "part", "--tool",
                       "torch", "-o", tmp_path / "reach.csv")
    assert code == 0, err
    out = read_csv(tmp_path / "reach.csv", allow_nan=True)
    assert not rm.reachable.all()
    np.testing.assert_array_equal(np.array(out["reachable"]) == "true", rm.reachable)
    np.testing.assert_allclose(np.column_stack([out["e1"], out["e2"]]), np.degrees(t.table),
                               atol=1e-6)
    # and the program writer's reader gives the same values
    np.testing.assert_array_equal(read_path(path, cell).table, t.table)


def test_a_turntable_angle_given_to_a_positioner_is_refused_by_every_reader(tmp_path, capsys):
    cell = Cell.load(POSITIONER)
    match = "column 'table' holds a turntable angle; positioner 'DKP_2' has 2 axes"
    with pytest.raises(InputError, match=match):
        read_targets(SEAM, table=table_columns(cell), positioner=table_label(cell))
    with pytest.raises(InputError, match=match):
        read_path(SEAM, cell)
    for args in (["reach", "--cell", POSITIONER, SEAM], ["ik", "--cell", POSITIONER, "--input",
                                                        SEAM]):
        code, _, err = run(capsys, *args)
        assert code == 2 and match in err and err.count("\n") == 1, err


@pytest.mark.parametrize("content,kwargs,match", [
    ("x,y,z,a,b,c\n1,2,nan,0,0,0\n", {}, r"t.csv: line 2: column 'z' has 'nan': NaN"),
    ("x,y,z,a,b,c\n1,2,,0,0,0\n", {}, r"t.csv: line 2: empty value in column 'z'"),
    ("x,y,z,a,b\n1,2,3,0,0\n", {}, r"t.csv: missing column\(s\) c"),
    ("x,y,z,a,b,c,table,e1\n1,2,3,0,0,0,10,20\n", {},
     r"t.csv: columns table and e1: give one or the other"),
    ("x,y,z,a,b,c,e1\n1,2,3,0,0,0,10\n", {"table": ("table",)},
     r"t.csv: column 'e1', but the cell's table axes are column\(s\) table"),
    ("x,y,z,a,b,c,table\n1,2,3,0,0,0,10\n", {"table": ()},
     r"t.csv: column 'table', but the cell has no turntable"),
    ("x,y,z,a,b,c,e1\n1,2,3,0,0,0,10\n", {"table": ("e1", "e2"), "positioner": "positioner 'P'"},
     r"t.csv: positioner 'P' has 2 axes: missing column\(s\) e2 \(deg\)"),
    ("x,y,z,a,b,c,track\n1,2,3,0,0,0,\n1,2,3,0,0,0,5\n", {},
     r"t.csv: line 2: empty value in column 'track'.*leave the column out"),
    ("x,y,z,a,b,c,table\n1,2,3,0,0,0,ten\n", {}, r"t.csv: line 2: column 'table' must be numeric"),
    ("x,y,z,a,b,c\n1,2,3e8,0,0,0\n", {}, r"t.csv: a target beyond 100 m.*line 2, column 'z'"),
])
def test_a_bad_targets_file_is_refused_naming_file_line_and_column(tmp_path, content, kwargs,
                                                                   match):
    p = tmp_path / "t.csv"
    p.write_text(content)
    with pytest.raises(InputError, match=match):
        read_targets(p, **kwargs)


@pytest.mark.parametrize("content,match", [
    ("x,y,z,a,b,c\n1,2,nan,0,0,0\n", "column 'z' has 'nan'"),
    ("x,y,z,a,b\n1,2,3,0,0\n", "missing column(s) c"),
    ("x,y,z,a,b,c,table,e1\n1,2,3,0,0,0,10,20\n", "column 'e1', but the cell's table axes are"),
])
@pytest.mark.parametrize("command", ["reach", "ik", "program"])
def test_a_bad_targets_file_exits_2_with_one_error_line(tmp_path, capsys, content, match,
                                                        command):
    p = tmp_path / "t.csv"
    p.write_text(content)
    args = {"reach": ["reach", "--cell", TURNTABLE, p],
            "ik": ["ik", "--cell", TURNTABLE, "--input", p],
            "program": ["program", "write", p, "--cell", TURNTABLE, "--tool", "torch",
                        "--frame", "part", "--format", "kuka", "-o", tmp_path / "prog"]}[command]
    code, _, err = run(capsys, *args)
    assert code == 2 and err.startswith("error: ") and match in err and err.count("\n") == 1, err
    assert not (tmp_path / "prog").exists()


def test_messages_name_the_line_as_the_file_counts_it(tmp_path):
    cell = Cell.load(TURNTABLE)
    p = tmp_path / "t.csv"
    p.write_text("x,y,z,a,b,c,track\n\n1,2,3,0,0,0,100\n\n1,2,3,0,0,0,99000\n")
    t = read_targets(p)
    np.testing.assert_array_equal(t.lines, [3, 5])
    with pytest.raises(InputError, match=r"t.csv: line 5: column 'track' has 99000, outside"):
        read_path(p, cell)


def test_names_and_extra_columns_come_with_the_targets(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("name,x,y,z,a,b,c,speed,piont\nP1,1,2,3,0,0,0,50,1\n,4,5,6,0,0,0,,2\n")
    t = read_targets(p, extra=("speed",))
    assert t.names == ["P1", ""]
    np.testing.assert_array_equal(t.extra["speed"], [50, np.nan])
    assert t.track is None and t.table is None and t.table_columns == ()
    assert len(t.warnings) == 1
    assert t.warnings[0].startswith(f"{p}: column(s) 'piont'")
    assert t.warnings[0].endswith("not used by this command and ignored; check the spelling")
