"""``robotcell view CELL --program PROGRAM``: a robot program in the 3D view of its cell."""

from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from programs_helpers import CELL, ROBODK, SEAM
from test_view_scenes import assert_triad_line, chain_vertices
from view_helpers import figure_from_page, moving_parts, traces, xyz

from robotcell import InputError
from robotcell.cell import Cell
from robotcell.programs import write_program
from robotcell.programs.check import check_program_file
from robotcell.view import program as program_view
from robotcell.view.cellscene import frame_size
from robotcell.view.program import program_scene, write_program_view

#: 0.01 mm: the coordinates of a path's view (robotcell.view.path.DECIMALS)
TOL = 0.005


def assert_arm_at_every_point(page, cell, report):
    """Each step of the page shows the arm where the cell's FK of the point's joint values puts
    it, and the TCP where the check puts it (mm, to the page's 0.01 mm)."""
    data = figure_from_page(page)
    pts = report.points
    assert [s["label"] for s in data["layout"]["sliders"][0]["steps"]] == [p.name for p in pts]
    q = np.array([p.q for p in pts])
    track = np.array([p.track for p in pts])
    table = np.array([p.table for p in pts])
    ok = np.all(np.isfinite(q), axis=1)
    links = chain_vertices(cell, q[ok], track[ok], table[ok])
    flange = cell.fk(q[ok], track[ok], table[ok], tool=np.eye(4))
    for k, i in enumerate(np.flatnonzero(ok)):
        parts = moving_parts(data, i)
        np.testing.assert_allclose(parts[f"robot {cell.robot.name}: links"], links[k], rtol=0,
                                   atol=TOL)
        np.testing.assert_allclose(parts["tool"][0], flange[k, :3, 3] * 1e3, rtol=0, atol=TOL)
        assert_triad_line(parts["TCP"], pts[i].T_world_TCP, frame_size(cell.robot) * 1e3, TOL)
    return data


def test_the_arm_at_each_point_is_the_fk_of_the_programs_joint_values(tmp_path, capsys):
    # RoboDK's KUKA program (two joint points, four Cartesian ones), its first linear point
    # (line 54) moved 2 m up, out of reach: the arm at each point, the bad point marked with its
    # reason
    cell_path = ROBODK / "cell_kr16.yaml"
    src = tmp_path / "Program.src"
    src.write_text((ROBODK / "Program.src").read_text().replace(
        "LIN {X 18.715,Y 147.321,Z 458.168", "LIN {X 18.715,Y 147.321,Z 2458.168", 1))
    out = tmp_path / "program.html"
    code, _, err = run(capsys, "view", cell_path, "--program", src, "-o", out)
    assert code == 0, err
    assert "6 points, 1 bad, the arm at every point" in err
    cell = Cell.load(cell_path)
    report = check_program_file(src, cell)
    joints = [p.joints for p in report.program.points[:2]]
    np.testing.assert_array_equal([p.q for p in report.points[:2]], joints)  # as written
    data = assert_arm_at_every_point(out.read_text(), cell, report)
    mark = traces(data, "bad points")[0]
    assert mark["text"] == ["line 54"]
    (why,) = report.points[2].problems
    assert why.startswith("out of reach by ")
    assert mark["hovertext"] == [f"<b>point line 54</b>: {why}"]
    np.testing.assert_allclose(xyz(mark)[0], report.points[2].T_world_TCP[:3, 3] * 1e3, atol=TOL)
    path = traces(data, "TCP path")[0]
    assert path["hovertext"][0] == "<b>line 51</b> (line 51, ptp)" and "%{x:.2f}" in path["hovertemplate"]


def seam_program(cell, folder, unreachable="XP7"):
    """The example seam as a KUKA program, its point ``unreachable`` moved 3 m up."""
    result = write_program(SEAM, cell, "torch", "part", "kuka", folder)
    dat = Path(next(f for f in result.files if f.endswith(".dat")))
    text = dat.read_text()
    line = next(ln for ln in text.splitlines() if ln.startswith(f"DECL E6POS {unreachable}="))
    z = line.split(",Z ")[1].split(",")[0]
    dat.write_text(text.replace(line, line.replace(f",Z {z},", f",Z {float(z) + 3000:.6f},")))
    return Path(result.files[0])


def test_an_unreachable_point_is_marked_and_the_arm_stays_at_the_point_before(tmp_path):
    cell = Cell.load(CELL)
    src = seam_program(cell, tmp_path / "p")
    made = write_program_view(cell, src, tmp_path / "v.html")
    report = made.report
    k = [p.name for p in report.points].index("XP7")
    assert np.all(np.isnan(report.points[k].q))
    assert made.every == 1 and made.size == (tmp_path / "v.html").stat().st_size < 5_000_000
    data = assert_arm_at_every_point((tmp_path / "v.html").read_text(), cell, report)
    mark = traces(data, "bad points")[0]
    assert mark["text"] == ["XP7"] and "out of reach by" in mark["hovertext"][0]
    # marked where the program puts the TCP, 3 m above the seam
    np.testing.assert_allclose(xyz(mark)[0], report.points[k].T_world_TCP[:3, 3] * 1e3, atol=TOL)
    # its step shows the arm at the point before it
    before, at = moving_parts(data, k - 1), moving_parts(data, k)
    np.testing.assert_array_equal(at["robot kuka_kr16: links"], before["robot kuka_kr16: links"])


def test_a_long_program_has_the_arm_at_every_kth_point(tmp_path, monkeypatch):
    # a page limit of the size the 36 points make with 12 steps: the arm at every 3rd point,
    # the whole path and every mark, and the page says so
    cell = Cell.load(CELL)
    src = seam_program(cell, tmp_path / "p")
    report = check_program_file(src, cell)
    n = len(report.points)
    twelve = len(program_view._page(cell, report, 3).encode())
    monkeypatch.setattr(program_view, "MAX_PAGE_BYTES", twelve)
    made = write_program_view(cell, src, tmp_path / "v.html")
    assert made.every == 3 and made.size <= twelve
    page = (tmp_path / "v.html").read_text()
    data = figure_from_page(page)
    assert len(data["frames"]) == 12 and len(xyz(traces(data, "TCP path")[0])) == n
    assert traces(data, "bad points")[0]["text"] == ["XP7"]
    assert f"the arm is drawn at every 3rd of the {n} points" in page
    # even one arm position too large: refused, nothing written
    monkeypatch.setattr(program_view, "MAX_PAGE_BYTES", 4_000_000)
    with pytest.raises(InputError, match=r"points make a page of 4\.\d MB even with the arm at "
                                         r"one point, more than 4 MB; view it in parts"):
        write_program_view(cell, src, tmp_path / "w.html")
    assert not (tmp_path / "w.html").exists()


def test_a_program_none_of_whose_points_can_be_placed_is_refused(tmp_path):
    cell = Cell.load(CELL)
    src = seam_program(cell, tmp_path / "p")
    report = check_program_file(src, cell)
    for p in report.points:
        p.q = np.full(6, np.nan)
        p.problems = p.problems or ["out of reach by 1.0 mm"]
    with pytest.raises(InputError, match=r"seam_part: no point of the program can be placed in "
                                         r"the cell, so there is no arm to draw; point XP1 \(line "
                                         r"\d+\): out of reach by 1\.0 mm"):
        program_scene(cell, report)


def test_the_program_view_refuses_bad_input_and_writes_nothing(tmp_path, capsys):
    cell = Cell.load(CELL)
    src = seam_program(cell, tmp_path / "p")
    out = tmp_path / "v.html"
    # -o onto the .dat the KUKA program is read from, beside its .src
    dat = src.with_suffix(".dat")
    before = dat.read_text()
    code, _, err = run(capsys, "view", CELL, "--program", src, "-o", dat)
    assert code == 2 and "which the program is read from" in err and dat.read_text() == before
    # a truncated program: its file and line named
    dat.write_text(dat.read_text().replace("DECL E6POS XP3=", "DECL E6POS XP3=X", 1))
    code, _, err = run(capsys, "view", CELL, "--program", src, "-o", out)
    assert code == 2 and "seam_part.dat: line" in err and "Traceback" not in err, err
    cases = [
        (["--program", src, "--joints", "0,0,0,0,0,0"], "leave out --joints"),
        (["--program", src, "--track", "100", "--table", "30"], "leave out --track, --table"),
        (["--pulses-per-degree", "100"], "--pulses-per-degree is for a YASKAWA --program"),
        (["--program", tmp_path / "none.src"], "none.src"),
        (["--program", src, "-o", src], "names the same file as --program"),
    ]
    for args, match in cases:
        argv = ["view", CELL, *args] + ([] if "-o" in args else ["-o", out])
        code, _, err = run(capsys, *argv)
        assert code == 2 and match in err and "Traceback" not in err, (args, err)
    assert not out.exists()
    # a YASKAWA job for a cell with station axes needs the pulses per degree: the option named
    job = write_program(SEAM, cell, "torch", "part", "yaskawa", tmp_path / "y",
                        pulses_per_degree=100).files[0]
    code, _, err = run(capsys, "view", CELL, "--program", job, "-o", out)
    assert code == 2 and "--pulses-per-degree" in err and "pulses_per_degree" not in err, err
    code, _, err = run(capsys, "view", CELL, "--program", job, "--pulses-per-degree", "100",
                       "-o", out)
    assert code == 0 and out.exists(), err
