"""The table's values chosen along a path (robotcell.cell.tablechoice) and the programs written
with them: a seam on the turntable or a positioner without a table column (docs/programs.md,
"The table chosen")."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from programs_helpers import CELL, EXAMPLES, EXT, SEAM
from test_positioner import AXES, tilt_rotate
from test_programs import FORMATS, _assert_poses_equal, _in_frame

from robotcell.cell import Cell
from robotcell.cell.ik import split_path
from robotcell.cell.tablechoice import NORMAL_TOL, choose_table
from robotcell.dhprocedure import AxisChain
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor
from robotcell.kinematics.transforms import make_pose
from robotcell.programs import read_path, write_program
from robotcell.programs.check import check_program_file

POSITIONER = EXAMPLES / "cell_kr16_positioner.yaml"
#: Largest table step between consecutive points of the example seam (deg): it needs about 9.
SEAM_STEP = 10.0


@pytest.fixture(scope="module")
def cell() -> Cell:
    return Cell.load(CELL)


def _rows(path: Path) -> np.ndarray:
    return np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


def _write_rows(path: Path, rows: np.ndarray) -> Path:
    path.write_text("x,y,z,a,b,c\n" + "\n".join(",".join(f"{v:.6f}" for v in r) for r in rows)
                    + "\n")
    return path


def _seam_without_table(folder: Path, turn_deg: float = 0.0) -> Path:
    """The example seam with its table column left out, turned by ``turn_deg`` about the part's
    Z (so that the table has to stand that much the other way)."""
    rows = _rows(SEAM)[:, :6]
    c, s = math.cos(math.radians(turn_deg)), math.sin(math.radians(turn_deg))
    x, y = rows[:, 0].copy(), rows[:, 1].copy()
    rows[:, 0], rows[:, 1], rows[:, 3] = c * x - s * y, s * x + c * y, rows[:, 3] + turn_deg
    return _write_rows(folder / "seam.csv", rows)


def _ppd(vendor: str, ppd: float = 100.0) -> float | None:
    return ppd if vendor == "yaskawa" else None


def _assert_reaches(cell: Cell, result, T: np.ndarray) -> None:
    """Every written point's joints, track and table through the cell's FK give its target in
    frame 'part' to 1e-6 mm and 1e-9 rad."""
    back = cell.fk(result.q, result.track, result.table, tool="torch", frame="part")
    assert np.abs(back[:, :3, 3] - T[:, :3, 3]).max() < 1e-9
    assert np.abs(back[:, :3, :3] - T[:, :3, :3]).max() < 1e-9


def _main(result, vendor: str) -> str:
    return next(f for f in result.files if f.endswith(EXT[vendor]))


def test_the_seam_is_out_of_reach_at_table_0_along_part_of_it(cell, tmp_path):
    # what the tests below rely on: the table has to turn for this seam
    t = read_path(_seam_without_table(tmp_path), cell)
    assert not t.table_given and np.all(t.table == 0)
    split = split_path(cell, t.T, frame="part", table=t.table, tool="torch")
    reach = [b.index for b in split.breaks if b.kind == "reach"]
    assert reach == [*range(10), *range(24, 36)]  # 22 of the 36 points


@pytest.mark.parametrize("vendor", FORMATS)
def test_a_seam_without_table_column_is_one_program_with_the_table_turning(cell, vendor,
                                                                           tmp_path, capsys):
    path = _seam_without_table(tmp_path)
    # YASKAWA at 7.3 pulses per degree: the chosen angles are held in whole pulses
    ppd = _ppd(vendor, 7.3)
    result = write_program(path, cell, "torch", "part", vendor, tmp_path / "prog",
                           pulses_per_degree=ppd)
    assert len(result.programs) == 1 and not result.breaks
    table = np.degrees(result.table)
    assert np.ptp(table) > 270                                   # the table turns
    assert np.abs(np.diff(table)).max() <= SEAM_STEP + 1e-9      # continuously
    T = pose_from_vendor(_rows(path), "kuka")
    _assert_reaches(cell, result, T)
    args = ["program", "check", _main(result, vendor), "--cell", CELL]
    code, _, err = run(capsys, *args, *(["--pulses-per-degree", ppd] if ppd else []))
    assert code == 0, err
    report = check_program_file(_main(result, vendor), cell, ppd)
    read_table = np.array([p.table for p in report.points])
    assert np.abs(np.degrees(read_table) - table).max() < 1e-6
    _assert_poses_equal(_in_frame(cell, report, "part", read_table), T)  # 1e-3 mm, 1e-6 rad


def test_the_json_gives_the_chosen_table_and_its_joints_give_the_path(cell, tmp_path, capsys):
    path = _seam_without_table(tmp_path)
    code, out, err = run(capsys, "program", "write", path, "--cell", CELL, "--tool", "torch",
                         "--frame", "part", "--format", "abb", "-o", tmp_path / "p", "--json")
    assert code == 0, err
    points = json.loads(out)["points"]
    q = np.radians([[p[f"a{j}"] for j in range(1, 7)] for p in points])
    track = np.array([p["track"] for p in points]) * 1e-3
    table = np.radians([p["table"] for p in points])
    assert table[0] > math.radians(150) and table[-1] < math.radians(-120)
    T = cell.fk(q, track, table, tool="torch", frame="part")
    assert np.abs(T[:, :3, 3] - pose_from_vendor(_rows(path), "kuka")[:, :3, 3]).max() < 1e-6


def test_the_chosen_table_passes_180_deg_where_its_limits_allow(cell, tmp_path):
    # the seam turned by -60 deg on the part: the table stands 60 deg further, past +180
    T = read_path(_seam_without_table(tmp_path, -60.0), cell).T
    choice = choose_table(cell, T, "part", tool="torch")
    table = np.degrees(choice.table)
    assert choice.breaks == 0 and np.all(choice.reachable)
    assert table.max() > 200 and table.min() < 0                  # across +180 deg, no wrap
    assert np.abs(np.diff(table)).max() <= SEAM_STEP + 1e-9
    assert math.degrees(choice.max_step) == pytest.approx(np.abs(np.diff(table)).max())
    # a table limited to +-180 deg stays inside them, in one piece too
    limited = Cell.load(CELL)
    limited.turntable.lower, limited.turntable.upper = -math.pi, math.pi
    inside = choose_table(limited, T, "part", tool="torch")
    assert inside.breaks == 0 and np.all(np.abs(inside.table) <= math.pi)
    assert split_path(limited, T, frame="part", table=inside.table, tool="torch").breaks == []


def test_a_path_out_of_reach_at_every_table_angle_exits_3_naming_the_points(cell, tmp_path,
                                                                           capsys):
    rows = _rows(_seam_without_table(tmp_path))
    rows[11, 2] += 3000.0                                         # point 12, 3 m up
    far = _write_rows(tmp_path / "far.csv", rows)
    args = ["program", "write", far, "--cell", CELL, "--tool", "torch", "--frame", "part",
            "--format", "kuka", "-o", tmp_path / "out"]
    code, out, err = run(capsys, *args)
    assert code == 3 and "point 12 (reach)" in err and "no table value reaches it within the limits either" in err, err
    assert "it breaks at 1 point: " in err and "write 2 programs, one per piece, with --split" in err
    assert not (tmp_path / "out").exists()
    code, out, err = run(capsys, *args, "--split", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert [b["point"] for b in data["breaks"]] == [12] and len(data["files"]) == 4
    for f in data["files"][::2]:
        assert run(capsys, "program", "check", f, "--cell", CELL)[0] == 0


def test_a_world_path_keeps_the_table_at_0(cell, tmp_path):
    rows = np.column_stack([np.linspace(1500, 1800, 7), np.full(7, -1300.0), np.full(7, 250.0),
                            np.zeros(7), np.full(7, 180.0), np.zeros(7)])
    result = write_program(_write_rows(tmp_path / "w.csv", rows), cell, "torch", "world", "kuka",
                           tmp_path / "p")
    assert not result.breaks and np.all(result.table == 0)
    with pytest.raises(InputError, match="frame 'world' is not carried by the turntable"):
        choose_table(cell, pose_from_vendor(rows, "kuka"), "world", tool="torch")


def _normal_tilt(cell: Cell, T: np.ndarray, table: np.ndarray) -> np.ndarray:
    """Angle of each target's surface normal (the tool's -Z) off straight up (rad)."""
    Tw = cell.frame_pose("part", 0.0, table) @ T
    return np.arccos(np.clip(-Tw[:, 2, 2], -1, 1))


def test_a_flat_seam_on_a_positioner_keeps_the_normal_up_and_turns_the_plate(tmp_path):
    cell = Cell.load(POSITIONER)
    k = np.arange(36)
    rows = np.column_stack([60 * np.cos(np.radians(10 * k)), 60 * np.sin(np.radians(10 * k)),
                            0 * k, 10 * k, 180 + 0 * k, 0 * k])
    path = _write_rows(tmp_path / "circle.csv", rows)
    result = write_program(path, cell, "torch", "part", "kuka", tmp_path / "p")
    assert len(result.programs) == 1 and not result.breaks
    v = np.degrees(result.table)
    assert np.all(v[:, 0] == 0)                                  # no tilt: the plate is level
    assert np.ptp(v[:, 1]) > 270 and np.abs(np.diff(v[:, 1])).max() <= 12  # the plate turns
    _assert_reaches(cell, result, pose_from_vendor(rows, "kuka"))
    report = check_program_file(_main(result, "kuka"), cell)
    assert report.good, report.rows()
    table = np.stack([p.table for p in report.points])
    _assert_poses_equal(_in_frame(cell, report, "part", table), pose_from_vendor(rows, "kuka"))


def test_a_seam_on_a_wall_of_the_part_is_tilted_into_the_welding_position(tmp_path):
    cell = Cell.load(POSITIONER)
    n = 15
    # along Y on the face x = 100 mm of the part, the torch into it (its Z along -X of the part)
    rows = np.column_stack([np.full(n, 100.0), np.linspace(-70, 70, n), np.full(n, 50.0),
                            np.zeros(n), np.full(n, -90.0), np.zeros(n)])
    path = _write_rows(tmp_path / "wall.csv", rows)
    result = write_program(path, cell, "torch", "part", "fanuc", tmp_path / "p")
    assert len(result.programs) == 1 and not result.breaks
    T = pose_from_vendor(rows, "kuka")
    assert _normal_tilt(cell, T, result.table).max() < 1e-9      # straight up: normal_up
    assert np.allclose(np.abs(np.degrees(result.table[:, 0])), 90)
    _assert_reaches(cell, result, T)
    assert check_program_file(_main(result, "fanuc"), cell).good


def test_the_positioner_choice_stays_within_the_normal_tolerance():
    cell = tilt_rotate()
    a = np.radians(np.arange(0, 360, 15))
    # a circle on a face tilted by 1 deg: the plate may turn, the normal stays within 2 deg
    R = pose_from_vendor([0, 0, 0, 0, 181, 0], "kuka")[:3, :3]
    T = np.stack([make_pose(R @ pose_from_vendor([0, 0, 0, math.degrees(t), 0, 0],
                                                 "kuka")[:3, :3],
                            [0.06 * math.cos(t), 0.06 * math.sin(t), 0.0]) for t in a])
    choice = choose_table(cell, T, "part", tool="torch")
    assert choice.breaks == 0 and np.all(choice.branch >= 0)
    assert _normal_tilt(cell, T, choice.table).max() <= NORMAL_TOL
    assert np.ptp(choice.table[:, 1]) > math.radians(180)


def test_a_positioner_of_three_axes_needs_its_axis_values(tmp_path):
    three = AxisChain(points=[*AXES.points, AXES.points[-1]],
                      directions=[*AXES.directions, [1.0, 0.0, 0.0]],
                      types=("revolute",) * 3, flange=AXES.flange, names=("E1", "E2", "E3"),
                      lower=np.radians([-95, -400, -90]), upper=np.radians([95, 400, 90]))
    cell = tilt_rotate(axes=three)
    T = np.stack([make_pose(np.diag([1.0, -1.0, -1.0]), [0.05, 0.0, 0.0])] * 3)
    with pytest.raises(InputError, match="positioner 'DKP_2' has 3: give its axis values"):
        choose_table(cell, T, "part", tool="torch")


@pytest.mark.parametrize("kw,match", [
    ({"max_step": 0.0}, "max_step must be positive"),
    ({"samples": 2}, "samples must be at least 4"),
    ({"normal_tol": 0.0}, "normal_tol must be between 0 and pi"),
    ({"track": [1.0, np.nan]}, "track position contains NaN"),
])
def test_bad_arguments_are_refused(cell, kw, match):
    T = read_path(SEAM, cell).T[:2]
    with pytest.raises(InputError, match=match):
        choose_table(cell, T, "part", tool="torch", **kw)


def test_a_point_whose_normal_cannot_be_turned_up_is_named_so(tmp_path, capsys):
    # the torch along +Z of the part (b = 0) welds the underside: its normal points down, and
    # the tilt axis (+-95 deg) cannot turn it up
    rows = np.array([[60.0, 0.0, 0.0, 0.0, 180.0, 0.0], [50.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                     [40.0, 0.0, 0.0, 0.0, 180.0, 0.0]])
    path = _write_rows(tmp_path / "under.csv", rows)
    code, _, err = run(capsys, "program", "write", path, "--cell", POSITIONER, "--tool", "torch",
                       "--frame", "part", "--format", "kuka", "-o", tmp_path / "out")
    # (at the values the path is then solved at it is reached with axis 5 outside its limits)
    assert code == 3 and "point 2 (limit)" in err, err
    assert "; no positioner values within the axis limits turn its normal up" in err
    assert not (tmp_path / "out").exists()


def test_targets_of_a_wrong_shape_are_refused(cell):
    with pytest.raises(InputError, match=r"path targets must have shape \(N, 4, 4\)"):
        choose_table(cell, np.eye(4), "part", tool="torch")
