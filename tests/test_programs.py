"""Robot programs (robotcell.programs): paths written through the cell in every format, read
back and checked; configuration flags both ways; the path file (docs/programs.md)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from programs_helpers import CELL, EXAMPLES, EXT, SEAM

from robotcell import load_robot
from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor
from robotcell.io.tables import read_csv
from robotcell.programs import ProgramOptions, read_path, write_program
from robotcell.programs.check import check_program_file, singular_distances
from robotcell.programs.config import config_text, config_values, configs, select

#: Station pulses per degree for the YASKAWA programs of the example cell (its table angles are
#: whole degrees, so the pulses hold them exactly).
PPD = 100.0
FORMATS = ["kuka", "abb", "fanuc", "yaskawa"]


@pytest.fixture(scope="module")
def cell() -> Cell:
    return Cell.load(CELL)


def _path_poses(path: Path) -> tuple[np.ndarray, np.ndarray]:
    cols = read_csv(path)
    T = pose_from_vendor(np.column_stack([cols[k] for k in "xyzabc"]), "kuka")
    table = np.radians(cols["table"]) if "table" in cols else np.zeros(len(T))
    return T, table


def _ppd(vendor: str) -> float | None:
    return PPD if vendor == "yaskawa" else None


def _in_frame(cell: Cell, report, frame: str, table: np.ndarray) -> np.ndarray:
    Tw = np.stack([p.T_world_TCP for p in report.points])
    track = np.array([p.track for p in report.points])
    return np.linalg.inv(cell.frame_pose(frame, track, table)) @ Tw


def _assert_poses_equal(T: np.ndarray, ref: np.ndarray) -> None:
    assert np.abs(T[:, :3, 3] - ref[:, :3, 3]).max() < 1e-6  # 1e-3 mm
    R = np.swapaxes(ref[:, :3, :3], -1, -2) @ T[:, :3, :3]
    angle = np.arccos(np.clip((np.trace(R, axis1=-2, axis2=-1) - 1) / 2, -1, 1))
    assert angle.max() < 1e-6  # rad


@pytest.mark.parametrize("vendor", FORMATS)
def test_a_path_on_the_turntable_round_trips_through_every_format(cell, vendor, tmp_path):
    # the example seam in the frame 'part' on the turntable; the track moves along the path
    result = write_program(SEAM, cell, "torch", "part", vendor, tmp_path / "prog",
                           pulses_per_degree=_ppd(vendor))
    assert len(result.programs) == 1 and not result.breaks
    assert np.ptp(result.track) > 0.05  # the track moved
    main = next(f for f in result.files if f.endswith(EXT[vendor]))
    report = check_program_file(main, cell, _ppd(vendor))
    assert report.good, report.rows()
    T, table = _path_poses(SEAM)
    _assert_poses_equal(_in_frame(cell, report, "part", table), T)
    q = np.stack([p.q for p in report.points])
    # the configuration as written is the one solved (YASKAWA rounds to 1e-3 mm, 1e-4 deg;
    # FANUC to 1e-3 mm and deg, as its controllers save positions)
    assert np.abs(q - result.q).max() < (1e-4 if vendor == "fanuc" else 1e-5)
    # the joints read back, through the cell's FK, give the path to 1e-3 mm
    track = np.array([p.track for p in report.points])
    T_fk = cell.fk(q, track, np.stack([p.table for p in report.points]), tool="torch",
                   frame="part")
    assert np.abs(T_fk[:, :3, 3] - T[:, :3, 3]).max() < 1e-6


@pytest.mark.parametrize("vendor", FORMATS)
def test_a_world_path_longer_than_the_reach_moves_the_track(cell, vendor, tmp_path):
    x = np.linspace(1000, 3500, 26)
    rows = "\n".join(f"{v:.1f},-1300,250,0,180,0" for v in x)
    path = tmp_path / "long.csv"
    path.write_text("x,y,z,a,b,c\n" + rows + "\n")
    result = write_program(path, cell, "torch", "world", vendor, tmp_path / "prog",
                           pulses_per_degree=_ppd(vendor))
    assert result.track[-1] - result.track[0] > 1.5
    main = next(f for f in result.files if f.endswith(EXT[vendor]))
    report = check_program_file(main, cell, _ppd(vendor))
    assert report.good, report.rows()
    T, table = _path_poses(path)
    _assert_poses_equal(_in_frame(cell, report, "world", table), T)


@pytest.mark.parametrize("vendor", FORMATS)
def test_a_path_on_a_two_axis_positioner_round_trips(vendor, tmp_path):
    cell = Cell.load(EXAMPLES / "cell_kr16_positioner.yaml")
    k = np.arange(12)
    a = np.radians(10.0 * k)
    rows = np.column_stack([60 * np.cos(a), 60 * np.sin(a), 0 * k, 10 * k, 180 + 0 * k, 0 * k,
                            0 * k, -10.0 * k])
    path = tmp_path / "p.csv"
    path.write_text("x,y,z,a,b,c,e1,e2\n" + "\n".join(",".join(f"{v:.6f}" for v in r)
                                                     for r in rows) + "\n")
    result = write_program(path, cell, "torch", "part", vendor, tmp_path / "prog",
                           pulses_per_degree=[PPD, PPD] if vendor == "yaskawa" else None)
    main = next(f for f in result.files if f.endswith(EXT[vendor]))
    report = check_program_file(main, cell, [PPD, PPD] if vendor == "yaskawa" else None)
    assert report.good, report.rows()
    table = np.stack([p.table for p in report.points])
    assert np.allclose(np.degrees(table), rows[:, 6:], atol=1e-9)
    T = pose_from_vendor(rows[:, :6], "kuka")
    _assert_poses_equal(_in_frame(cell, report, "part", table), T)


def test_the_json_joints_through_the_cells_fk_give_the_path(cell, tmp_path, capsys):
    code, out, err = run(capsys, "program", "write", SEAM, "--cell", CELL, "--tool", "torch",
                         "--frame", "part", "--format", "kuka", "-o", tmp_path / "p", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert sorted(Path(f).name for f in data["files"]) == ["seam_part.dat", "seam_part.src"]
    assert data["breaks"] == []
    pts = data["points"]
    q = np.radians([[p[f"a{i}"] for i in range(1, 7)] for p in pts])
    track = np.array([p["track"] for p in pts]) * 1e-3
    table = np.radians([p["table"] for p in pts])
    T = cell.fk(q, track, table, tool="torch", frame="part")
    ref, _ = _path_poses(SEAM)
    assert np.abs(T[:, :3, 3] - ref[:, :3, 3]).max() < 1e-6


def test_a_point_moved_3_m_away_fails_the_check_naming_it(cell, tmp_path, capsys):
    result = write_program(SEAM, cell, "torch", "part", "kuka", tmp_path / "p")
    dat = Path(next(f for f in result.files if f.endswith(".dat")))
    text = dat.read_text()
    line = next(ln for ln in text.splitlines() if ln.startswith("DECL E6POS XP7="))
    z = line.split(",Z ")[1].split(",")[0]
    dat.write_text(text.replace(line, line.replace(f",Z {z},", f",Z {float(z) + 3000:.6f},")))
    code, _, err = run(capsys, "program", "check", result.files[0], "--cell", CELL)
    assert code == 3
    assert "XP7" in err and "out of reach" in err
    assert "error: " in err and ": 1 of 36 points is bad" in err  # was "1 of 36 points are bad"
    assert [r for r in err.splitlines() if "out of reach" in r] == [
        r for r in err.splitlines() if "XP7" in r]  # only that point


# -- configuration flags ------------------------------------------------------------------------
@pytest.mark.parametrize("vendor,model", [
    ("kuka", "kuka_kr16"), ("abb", "abb_irb2400"), ("fanuc", "fanuc_m20ia"),
    ("fanuc", "fanuc_lrmate200id"), ("yaskawa", "kuka_kr16"), ("yaskawa", "fanuc_lrmate200id")])
def test_the_flags_select_the_configuration_they_were_computed_from(vendor, model):
    # (KUKA's Turn holds only signs: on an arm whose axis 6 turns +-400 deg, as the IRB 2400's,
    # 10 and 370 deg have the same flags; each format is tested on arms it is made for)
    robot = load_robot(model)
    rng = np.random.default_rng(7)
    q = rng.uniform(robot.lower, robot.upper, size=(300, 6))
    q = q[robot.within_limits(q)]
    q = q[np.all(np.array(singular_distances(robot, q)[0:2]) > 1e-3, axis=0)]
    sol = robot.ik(robot.fk(q))
    got, found, exists = select(robot, sol.q, sol.reachable, config_values(robot, q, vendor),
                                vendor)
    assert np.all(found) and np.all(exists)
    assert np.array_equal(config_values(robot, got, vendor), config_values(robot, q, vendor))
    assert np.abs(robot.fk(got) - robot.fk(q)).max() < 1e-9
    # the flags single out the configuration, except where an axis they do not count turns
    # (FANUC J3 over -185..273 deg) has two values for the same pose
    plain = np.all(np.abs(q[:, [1, 2, 4]]) < np.pi, axis=1)
    assert plain.mean() > 0.7 and np.abs(got - q)[plain].max() < 1e-7


def test_known_configurations_have_the_flags_the_vendors_write():
    kr16, m20ia = load_robot("kuka_kr16"), load_robot("fanuc_m20ia")
    # KUKA HOME: S 'B110', T 'B000010' (KSS); FANUC's home J5 = -90: 'N U T, 0, 0, 0'
    assert config_text(configs(kr16, np.radians([[0, -90, 90, 0, 0, 0]]), "kuka")[0]) == "S 6,T 2"
    home = np.radians([[0, 0, 0, 0, -90, 0]])
    assert config_text(configs(m20ia, home, "fanuc")[0]) == "'N U T, 0, 0, 0'"
    turned = np.radians([[0, 0, 0, 190, -90, -200]])
    assert config_text(configs(m20ia, turned, "fanuc")[0]) == "'N U T, 0, 1, -1'"
    # YASKAWA: R (axis 4) at 0 is Flip (l = 0); at 120 and -200 No-flip; |R| >= 180 sets o;
    # T, S likewise
    yas = config_values(kr16, np.radians([[0, -90, 90, 0, 30, 0], [0, -90, 90, 120, 30, 0],
                                          [190, -90, 90, -200, 30, 185]]), "yaskawa")
    assert yas.tolist() == [[0, 0, 0, 0, 0, 0], [1, 0, 0, 0, 0, 0], [1, 0, 0, 1, 1, 1]]


# -- the path file -------------------------------------------------------------------------------
def test_the_path_file_gives_motions_speeds_zones_and_axes(cell, tmp_path):
    p = tmp_path / "p.csv"
    p.write_text("x,y,z,a,b,c,motion,speed,zone,track,table\n"
                 "0,0,50,0,180,0,PTP,200,0,1500,30\n0,10,50,0,180,0,lin,50,2,1500,30\n")
    t = read_path(p, cell)
    assert t.motion == ["ptp", "lin"]
    assert np.allclose(t.speed, [0.2, 0.05]) and np.allclose(t.zone, [0, 0.002])
    assert np.allclose(t.track, 1.5) and np.allclose(t.table, np.radians(30))


@pytest.mark.parametrize("content,match", [
    ("x,y,z,a,b\n0,0,0,0,0\n", "missing column"),
    ("x,y,z,a,b,c,motion\n0,0,0,0,0,0,circ\n", "line 2: column 'motion'"),
    ("x,y,z,a,b,c,speed\n0,0,0,0,0,0,0\n", "line 2: column 'speed' must be positive"),
    ("x,y,z,a,b,c,zone\n0,0,0,0,0,0,-1\n", "column 'zone' must not be negative"),
    ("x,y,z,a,b,c,track\n0,0,0,0,0,0,9000\n",
     "line 2: column 'track' has 9000, outside the track limits"),
    ("x,y,z,a,b,c,e1,e2\n0,0,0,0,0,0,1,2\n", "column 'e1', but the cell's table axes are"),
])
def test_a_bad_path_file_is_refused_naming_the_line_and_column(cell, tmp_path, content, match):
    p = tmp_path / "p.csv"
    p.write_text(content)
    with pytest.raises(InputError, match=match):
        read_path(p, cell)


def test_a_tool_or_frame_the_cell_lacks_is_refused_and_nothing_written(cell, tmp_path):
    with pytest.raises(InputError, match="tool 'gripper' is not in the cell"):
        write_program(SEAM, cell, "gripper", "part", "kuka", tmp_path / "a")
    with pytest.raises(InputError, match="frame 'table' is not in the cell"):
        write_program(SEAM, cell, "torch", "table", "kuka", tmp_path / "a")
    with pytest.raises(InputError, match="a program's points are in 'world' or in a frame"):
        write_program(SEAM, cell, "torch", "robot", "kuka", tmp_path / "a")
    assert not (tmp_path / "a").exists()


def test_an_unreachable_point_breaks_the_path_and_split_writes_the_pieces(cell, tmp_path,
                                                                          capsys):
    rows = SEAM.read_text().splitlines()
    rows[11] = rows[11].replace(",0.0,", ",3000.0,", 1)
    far = tmp_path / "far.csv"
    far.write_text("\n".join(rows) + "\n")
    args = ["program", "write", far, "--cell", CELL, "--tool", "torch", "--frame", "part",
            "--format", "kuka", "-o", tmp_path / "out"]
    code, out, err = run(capsys, *args)
    assert code == 3 and "point 11 (reach)" in err and "--split" in err
    assert not (tmp_path / "out").exists()
    code, out, err = run(capsys, *args, "--split", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert [b["point"] for b in data["breaks"]] == [11]
    assert len(data["files"]) == 4 and data["points"][10]["a1"] is None


def test_an_output_onto_an_input_is_refused(cell, tmp_path):
    shutil.copy(SEAM, tmp_path / "seam.dat")
    with pytest.raises(InputError, match="it is an input of this run"):
        write_program(tmp_path / "seam.dat", cell, "torch", "part", "kuka", tmp_path,
                      name="seam")


def test_the_written_poses_can_come_from_the_controllers_own_model(cell, tmp_path):
    # The joints are solved in the true cell; the controller computes its joints from the
    # written poses with its own (nominal) model: its torch 1 mm and 0.2 deg off here. The
    # program written with controller=nominal makes the controller reach the solved joints, so
    # the true TCP is on the path; the program written without it would miss by the offset.
    from robotcell.cell import Provenance

    nominal = Cell.load(CELL)
    nominal.set_tool("torch", cell.tools["torch"].T_F_TCP @ pose_from_vendor(
        [1.0, 0.0, 0.0, 0.2, 0.0, 0.0], "kuka"), Provenance())
    result = write_program(SEAM, cell, "torch", "part", "kuka", tmp_path / "p",
                           options=ProgramOptions(controller=nominal))
    report = check_program_file(result.files[0], nominal)  # what the controller does
    q = np.stack([p.q for p in report.points])
    assert report.good and np.abs(q - result.q).max() < 1e-6
    track = np.array([p.track for p in report.points])
    T, table = _path_poses(SEAM)
    true_tcp = cell.fk(q, track, table, tool="torch", frame="part")
    _assert_poses_equal(true_tcp, T)
    naive = check_program_file(write_program(SEAM, cell, "torch", "part", "kuka",
                                             tmp_path / "n").files[0], nominal)
    missed = cell.fk(np.stack([p.q for p in naive.points]), track, table, tool="torch",
                     frame="part")
    assert np.abs(missed[:, :3, 3] - T[:, :3, 3]).max() > 5e-4
