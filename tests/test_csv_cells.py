"""The cells of a CSV as spreadsheets save them: an empty cell means "not given" (the column's
default, or refused naming line and column where a value is needed on every line), the trailing
separator a spreadsheet writes is ignored, and numbers are read as a spreadsheet writes them
(``1_673.4`` is refused, naming its line)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell import InputError, load_robot, pose_from_vendor
from robotcell.calibration.measurements import read_touch_table
from robotcell.cell import Cell
from robotcell.identification.measurements import read_target_measurements as read_tracker
from robotcell.io.tables import (
    optional_column,
    read_csv,
    refuse_empty,
    require_columns,
    spreadsheet_number,
)
from robotcell.programs.path import DEFAULT_SPEED, read_path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "cell_kr16_track_turntable.yaml"
SEAM = ROOT / "examples" / "seam_part.csv"


def _tcp_rows(rng: np.random.Generator, n: int = 6) -> list[list[float]]:
    """Flange poses x, y, z, a, b, c (mm, deg) touching one point with a 200 mm tool."""
    pivot, tcp = np.array([1100.0, -200.0, 300.0]), np.array([10.0, 5.0, 200.0])
    rows = []
    for k in range(n):
        abc = [60.0 * k, 180.0 - 25.0 * np.cos(k), 20.0 * np.sin(k)]
        p = pivot - pose_from_vendor([0, 0, 0, *abc], "kuka")[:3, :3] @ tcp
        rows.append([*(p + rng.normal(0, 0.05, 3)), *abc])
    return rows


def _text(header: list[str], rows: list[list[object]], end: str = "") -> str:
    def cell(v: object) -> str:
        return f"{v:.6f}" if isinstance(v, float) else str(v)
    lines = [",".join(header) + end] + [",".join(cell(v) for v in r) + end for r in rows]
    return "\n".join(lines) + "\n"


# -- empty cells and trailing separators ---------------------------------------------------------
def test_an_empty_note_and_a_trailing_separator_are_read(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("x,y,z,note,\n1,2,3,,\n4,5,6,second touch,\n")
    cols = read_csv(p)
    assert list(cols) == ["x", "y", "z", "note"]
    assert cols["note"] == ["", "second touch"]
    np.testing.assert_array_equal(cols["z"], [3.0, 6.0])


def test_empty_cells_after_the_last_column_are_ignored(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("x;y\n1,5;2;;\n3;4;\n")  # a semicolon file too
    cols = read_csv(p)
    np.testing.assert_array_equal(cols["x"], [1.5, 3.0])
    np.testing.assert_array_equal(cols["y"], [2.0, 4.0])


def test_a_value_under_a_column_without_a_name_is_refused_naming_its_line(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("x,,z\n1,,3\n4,5,6\n")
    with pytest.raises(InputError, match=r"t.csv: line 3: value '5' in column 2, which has no "
                                         r"name in the header"):
        read_csv(p)
    p.write_text("x,,z\n1,,3\n")  # an empty column without a name is left out
    assert list(read_csv(p)) == ["x", "z"]


def test_an_empty_cell_where_a_value_is_needed_is_refused_naming_line_and_column(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("x,y,z\n1,2,3\n4,,6\n7,,9\n")
    cols = read_csv(p)
    with pytest.raises(InputError, match=r"t.csv: line 3: empty value in column 'y' \(and 1 more "
                                         r"line\(s\)\), which needs a value on every line; fill "
                                         r"it in, or delete the line"):
        require_columns(cols, ["x", "y", "z"], p)
    with pytest.raises(InputError, match=r"line 3: empty value in column 'y'.*or leave the "
                                         r"column out"):
        refuse_empty(cols, ["y"], p, optional=True)
    p.write_text("x,y\n1,\n2,\n")  # a column without any value is text, empty all through
    with pytest.raises(InputError, match=r"line 2: empty value in column 'y'"):
        require_columns(read_csv(p), ["x", "y"], p)


def test_an_empty_cell_of_a_column_with_a_default_takes_the_default(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("x,speed,zone\n1,50,\n2,,\n3,,\n")
    cols = read_csv(p)
    np.testing.assert_array_equal(optional_column(cols, "speed", 100.0, p), [50, 100, 100])
    np.testing.assert_array_equal(optional_column(cols, "zone", 0.0, p), [0, 0, 0])
    assert optional_column(cols, "table", 0.0, p) is None
    p.write_text("x,speed\n1,fast\n")
    with pytest.raises(InputError, match=r"line 2: column 'speed' must be numeric, found 'fast'"):
        optional_column(read_csv(p), "speed", 100.0, p)


def test_calibrate_reads_an_empty_note_and_a_trailing_separator(tmp_path, capsys):
    rows = _tcp_rows(np.random.default_rng(1))
    clean = tmp_path / "clean.csv"
    clean.write_text(_text(list("xyzabc"), rows))
    saved = tmp_path / "saved.csv"  # as a spreadsheet saves it, the note filled on one line
    saved.write_text(_text([*"xyzabc", "note"], [[*r, "re-touched" if k == 2 else ""]
                                                 for k, r in enumerate(rows)], end=","))
    results = []
    for f in (clean, saved):
        code, out, err = run(capsys, "calibrate", "tcp", f, "--json")
        assert code == 0, err
        assert "warning" not in err
        results.append(json.loads(out))
    assert results[0]["tcp_mm"] == results[1]["tcp_mm"]


def test_a_tool_touch_with_an_empty_point_is_a_tcp_touch_a_frame_touch_is_refused(tmp_path):
    p = tmp_path / "tcp.csv"
    rows = _tcp_rows(np.random.default_rng(2))
    p.write_text(_text([*"xyzabc", "point"], [[*r, "" if k % 2 else "tcp"]
                                              for k, r in enumerate(rows)]))
    m = read_touch_table("tcp", read_csv(p), str(p))
    assert m.point == ("tcp",) * 6
    p.write_text("point,x,y,z\norigin,0,0,0\n,300,0,0\nxy,100,200,0\n")
    with pytest.raises(InputError, match=r"line 3: empty value in column 'point'"):
        read_touch_table("frame", read_csv(p), str(p))


def test_an_empty_track_cell_of_a_touch_is_refused_the_column_may_be_left_out(tmp_path):
    p = tmp_path / "tt.csv"
    p.write_text("x,y,z,e1,track\n1000,0,0,0,0\n1000,300,0,90,\n700,300,0,180,0\n")
    with pytest.raises(InputError, match=r"tt.csv: line 3: empty value in column 'track', which "
                                         r"needs a value on every line; fill it in on every "
                                         r"line, or leave the column out"):
        read_touch_table("turntable", read_csv(p), str(p))


def test_touch_columns_left_empty_beside_joint_values_are_not_given(tmp_path):
    robot = load_robot("kuka_kr16")
    p = tmp_path / "j.csv"
    p.write_text("x,y,z,a1,a2,a3,a4,a5,a6\n,,,0,-90,90,0,0,0\n,,,10,-80,80,0,10,0\n")
    m = read_touch_table("frame", {**read_csv(p), "point": ["origin", "x"]}, str(p), robot)
    assert m.joints.shape == (2, 6) and m.points is None


def test_a_path_line_with_empty_motion_speed_and_zone_takes_the_defaults(tmp_path, capsys):
    lines = SEAM.read_text().splitlines()
    head, body = lines[0], lines[1:]
    text = [head + ",motion,speed,zone,note,"]
    for k, line in enumerate(body):
        given = k % 3 == 0
        text.append(line + (",lin,50,2,ok," if given and k else ",,,,,"))
    path = tmp_path / "seam.csv"
    path.write_text("\n".join(text) + "\n")
    targets = read_path(path, Cell.load(EXAMPLE))
    assert targets.warnings == []
    assert targets.motion[0] == "ptp" and set(targets.motion[1:]) == {"lin"}
    np.testing.assert_allclose(targets.speed[[0, 1, 2, 3]], [DEFAULT_SPEED, DEFAULT_SPEED,
                                                             DEFAULT_SPEED, 0.05])
    np.testing.assert_allclose(targets.zone[[1, 3]], [0.0, 0.002])
    code, _, err = run(capsys, "program", "write", path, "--cell", EXAMPLE, "--tool", "torch",
                       "--frame", "part", "--format", "kuka", "-o", tmp_path / "prog")
    assert code == 0, err
    assert (tmp_path / "prog" / "seam.src").is_file()


def test_a_path_line_with_an_empty_table_or_track_value_is_refused(tmp_path, capsys):
    lines = SEAM.read_text().splitlines()
    lines[4] = lines[4].rsplit(",", 1)[0] + ","
    path = tmp_path / "seam.csv"
    path.write_text("\n".join(lines) + "\n")
    code, _, err = run(capsys, "program", "write", path, "--cell", EXAMPLE, "--tool", "torch",
                       "--frame", "part", "--format", "kuka", "-o", tmp_path / "prog")
    assert code == 2 and ("seam.csv: line 5: empty value in column 'table', which needs a value "
                          "on every line; fill it in on every line, or leave the column out") in err
    assert not (tmp_path / "prog").exists()
    track = ["track"] + ["1000"] * (len(lines) - 1)
    track[6] = ""
    path.write_text("\n".join(f"{a},{b}" for a, b in zip(SEAM.read_text().splitlines(), track))
                    + "\n")
    with pytest.raises(InputError, match=r"line 7: empty value in column 'track'"):
        read_path(path, Cell.load(EXAMPLE))


def test_fk_reads_a_trailing_separator_and_refuses_an_empty_track_cell(tmp_path, capsys):
    rows = [[0, -90, 90, 0, 0, 0], [10, -80, 80, 5, 10, 20]]
    plain = tmp_path / "j.csv"
    plain.write_text(_text([f"a{i}" for i in range(1, 7)], rows))
    saved = tmp_path / "saved.csv"
    saved.write_text(_text([*(f"a{i}" for i in range(1, 7)), "note"],
                           [[*r, ""] for r in rows], end=","))
    outs = []
    for f in (plain, saved):
        code, out, err = run(capsys, "fk", "kuka_kr16", "--input", f)
        assert code == 0 and "warning" not in err, err
        outs.append(out)
    assert outs[0] == outs[1]
    batch = tmp_path / "cell.csv"
    batch.write_text(_text([*(f"a{i}" for i in range(1, 7)), "track", "table"],
                           [[*rows[0], 1000, 0], [*rows[1], "", 0]]))
    for command in ("fk", "ik"):
        args = (["--input", batch] if command == "fk" else
                ["--input", _poses_with_track(tmp_path)])
        code, _, err = run(capsys, command, "--cell", EXAMPLE, *args, "--tool", "torch")
        assert code == 2 and "line 3: empty value in column 'track'" in err, err
        assert "or leave the column out" in err


def _poses_with_track(tmp_path: Path) -> Path:
    p = tmp_path / "poses.csv"
    p.write_text("x,y,z,a,b,c,track\n1500,0,800,0,90,0,1000\n1500,100,800,0,90,0,\n")
    return p


def test_the_tracker_csv_of_identify_reads_a_trailing_separator(tmp_path):
    p = tmp_path / "tracker.csv"
    p.write_text("a1,a2,a3,a4,a5,a6,x,y,z,note,\n0,-90,90,0,0,0,1,2,3,,\n"
                 "10,-80,80,0,10,0,4,5,6,second,\n")
    m = read_tracker(p)
    assert m.q.shape == (2, 6) and m.points.shape == (2, 1, 3)


# -- numbers as a spreadsheet writes them ----------------------------------------------------------
@pytest.mark.parametrize("text, value", [
    ("1673.4", 1673.4), ("-1.5E+03", -1500.0), (" .5 ", 0.5), ("5.", 5.0), ("+0", 0.0),
    ("1e-3", 1e-3), ("1_673.4", None), ("١٢", None), ("0x10", None), ("1,5", None),
    ("1e", None), ("", None), ("abc", None),
])
def test_a_number_is_what_a_spreadsheet_writes(text, value):
    assert spreadsheet_number(text) == value
    assert np.isnan(spreadsheet_number("NaN")) and spreadsheet_number("-infinity") == -np.inf


@pytest.mark.parametrize("content, match", [
    ("x,y\n1,2\n1_673.4,3\n", r"t.csv: line 3: column 'x' has '1_673.4', which is not a number "
                              r"as a spreadsheet writes it; write 1673.4"),
    ("x;y\n1;2\n1_673,4;3\n", r"line 3: column 'x' has '1_673,4'.*write 1673,4"),
    ("x,y\n1,١٢\n", r"line 2: column 'y' has '١٢'.*write it with the digits 0-9"),
    ("x,y\n1,2\n\n3,nan\n", r"line 4: column 'y' has 'nan': NaN or infinite values"),
    ("x,y\n1,inf\n", r"line 2: column 'y' has 'inf': NaN or infinite values"),
])
def test_python_only_numbers_nan_and_infinity_are_refused_naming_the_line(tmp_path, content,
                                                                          match):
    p = tmp_path / "t.csv"
    p.write_text(content, encoding="utf-8")
    with pytest.raises(InputError, match=match):
        read_csv(p)


def test_a_grouped_number_is_refused_by_calibrate_naming_the_line(tmp_path, capsys):
    rows = _tcp_rows(np.random.default_rng(3))
    text = _text(list("xyzabc"), rows).splitlines()
    x = text[3].split(",")[0]
    text[3] = text[3].replace(x, x[:1] + "_" + x[1:], 1)
    p = tmp_path / "tcp.csv"
    p.write_text("\n".join(text) + "\n")
    code, out, err = run(capsys, "calibrate", "tcp", p, "-o", tmp_path / "r.txt")
    assert code == 2 and err.count("error:") == 1
    assert f"tcp.csv: line 4: column 'x' has '{x[:1]}_{x[1:]}'" in err
    assert not (tmp_path / "r.txt").exists()


def test_options_take_numbers_as_a_spreadsheet_writes_them(capsys):
    code, _, err = run(capsys, "fk", "kuka_kr16", "--joints", "0,-90,9_0,0,0,0")
    assert code == 2 and "--joints must be comma-separated numbers, got '0,-90,9_0,0,0,0'" in err
