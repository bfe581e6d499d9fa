"""The ISO 9283 test plan: the cube inside the reach and the limits, the poses reachable, the
plan file, and the programs of every vendor read back by 'program check'."""

from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.cell.model import cell_from_dict
from robotcell.errors import InputError
from robotcell.iso9283 import plan, read_plan, write_plan
from robotcell.iso9283.cube import cube_corners
from robotcell.iso9283.search import MIN_MANIPULABILITY, manipulability_scale
from robotcell.kinematics.transforms import make_pose, rot_x, rot_y

ROOT = Path(__file__).resolve().parent.parent
TRACK_CELL = ROOT / "examples" / "cell_kr16_track_turntable.yaml"


def bare_cell(model: str) -> Cell:
    """A robot on the floor with a 100 mm probe along its flange's Z."""
    return cell_from_dict({"name": f"{model}_test", "robot": {"model": model},
                           "tools": {"probe": {"frame": {"x": 0, "y": 0, "z": 100, "a": 0,
                                                         "b": 0, "c": 0}}}})


CELLS = {
    "kr16_track": (lambda: Cell.load(TRACK_CELL), "torch"),
    "irb2400": (lambda: bare_cell("abb_irb2400"), "probe"),
    "ur5e": (lambda: bare_cell("ur5e"), "probe"),
}


def cube_grid(poses: np.ndarray, n: int) -> np.ndarray:
    """An n x n x n grid over the cube whose test poses are ``poses`` (5, 3), from its corners."""
    c = cube_corners(poses)
    origin, e1, e2, e3 = c[0], c[4] - c[0], c[1] - c[0], c[3] - c[4]
    s = np.linspace(0.0, 1.0, n)
    a, b, d = np.meshgrid(s, s, s, indexing="ij")
    return (origin + a.reshape(-1, 1) * e1 + b.reshape(-1, 1) * e2
            + d.reshape(-1, 1) * e3)


@pytest.mark.parametrize("name", list(CELLS))
def test_the_cube_lies_inside_the_reach_and_limits_in_one_configuration(name):
    cell, tool = CELLS[name][0](), CELLS[name][1]
    p = plan(cell, tool)
    assert p.size > 0.3                      # a real cube: at least 300 mm for these arms
    pts = cube_grid(p.poses[:, :3, 3], 6)    # an independent grid, finer than the search's
    T = np.array([make_pose(p.poses[0, :3, :3], x) for x in pts])
    track = None if cell.track is None else p.track
    sol = cell.ik(T, p.frame, track, 0.0 if p.table is None else p.table, tool)
    # one arm configuration reaches every point within every limit ...
    clear = np.all(sol.valid, axis=0)
    assert clear[p.branch]
    # ... away from singular configurations
    J = cell.robot.jacobian(sol.q[:, p.branch])
    m = np.sqrt(np.abs(np.linalg.det(J @ np.swapaxes(J, -1, -2))))
    scale = manipulability_scale(cell.robot)[0]
    assert m.min() > 0.5 * MIN_MANIPULABILITY * scale
    # the cube's lowest face is not below the robot's base plane
    T_R_X = np.linalg.inv(cell.frame_pose("robot", 0.0 if track is None else track)) \
        @ cell.frame_pose(p.frame, 0.0 if track is None else track)
    assert (pts @ T_R_X[:3, :3].T + T_R_X[:3, 3])[:, 2].min() > -1e-6


@pytest.mark.parametrize("name", list(CELLS))
def test_all_five_poses_are_reached_by_the_joints_of_the_plan(name):
    cell, tool = CELLS[name][0](), CELLS[name][1]
    p = plan(cell, tool)
    assert np.all(cell.robot.within_limits(p.q))
    track = 0.0 if p.track is None else p.track
    T = cell.fk(p.q, track, 0.0 if p.table is None else p.table, tool=tool, frame=p.frame)
    assert np.allclose(T, p.poses, atol=1e-9)
    # P2..P5 at 10 % of the plane's diagonal from its corners: 0.8 of the way from P1
    corners = cube_corners(p.poses[:, :3, 3])[:4]
    assert np.allclose(p.poses[1:, :3, 3] - p.poses[0, :3, 3],
                       0.8 * (corners - p.poses[0, :3, 3]), atol=1e-12)
    # every pose with the orientation asked for: the tool's Z axis down
    assert np.allclose(p.poses[:, :3, 2], [0.0, 0.0, -1.0], atol=1e-12)


def test_a_given_size_centre_orientation_and_track_are_kept():
    cell = Cell.load(TRACK_CELL)
    R = rot_y(np.pi) @ rot_x(0.2)
    p = plan(cell, "torch", size=0.4, centre=[2.45, 0.0, 0.85], track=1.8, orientation=R)
    assert p.size == pytest.approx(0.4, abs=1e-12)
    assert np.allclose(p.poses[0, :3, 3], [2.45, 0.0, 0.85], atol=1e-12)
    assert p.track == 1.8
    assert np.allclose(p.poses[:, :3, :3], R, atol=1e-12)


def test_a_size_beyond_the_largest_cube_is_refused_with_the_largest():
    cell = bare_cell("abb_irb2400")
    with pytest.raises(InputError, match=r"no cube of edge 3000 mm is clear here: the largest "
                                         r"is \d+ mm"):
        plan(cell, "probe", size=3.0)
    with pytest.raises(InputError, match="track position"):
        plan(Cell.load(TRACK_CELL), "torch", track=7.0)
    with pytest.raises(InputError, match="unknown tool|tool"):
        plan(cell, "torch")


def test_the_plan_file_reads_back_the_plan(tmp_path):
    p = plan(Cell.load(TRACK_CELL), "torch", size=0.5, table=np.radians(30))
    write_plan(p, tmp_path / "plan.csv")
    back, warnings = read_plan(tmp_path / "plan.csv")
    assert not warnings and back.names == p.names
    assert np.allclose(back.T, p.T, atol=1e-9)
    assert (back.frame, back.tool) == ("world", "torch")
    assert back.track == pytest.approx(p.track) and back.table == pytest.approx(np.radians(30))
    assert back.size == pytest.approx(0.5, abs=1e-9)
    assert set(back.paths) == {"line", "circle"}


def test_a_plan_file_with_a_pose_named_twice_or_missing_is_refused(tmp_path):
    p = plan(bare_cell("abb_irb2400"), "probe", size=0.4)
    write_plan(p, tmp_path / "plan.csv")
    lines = (tmp_path / "plan.csv").read_text().splitlines()
    (tmp_path / "twice.csv").write_text("\n".join([lines[0], lines[1], lines[1], *lines[3:]]))
    with pytest.raises(InputError, match="line 3: pose 'P1' is named twice"):
        read_plan(tmp_path / "twice.csv")
    (tmp_path / "no_p3.csv").write_text("\n".join([lines[0], *lines[1:3], *lines[4:]]))
    with pytest.raises(InputError, match="lacks the test pose"):
        read_plan(tmp_path / "no_p3.csv")


def test_every_vendor_program_of_the_plan_passes_program_check(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(capsys, "iso9283", "plan", "--cell", TRACK_CELL, "--tool", "torch",
                       "--size", "500", "-o", "plan.csv", "--programs", "iso",
                       "--pulses-per-degree", "100")
    assert code == 0, err
    files = sorted(Path("iso").rglob("*"))
    programs = [f for f in files if f.suffix in (".src", ".mod", ".ls", ".jbi")]
    assert {f.parent.name for f in programs} == {"kuka", "abb", "fanuc", "yaskawa"}
    assert len(programs) == 8
    for f in programs:
        code, out, err = run(capsys, "program", "check", f, "--cell", TRACK_CELL,
                             "--pulses-per-degree", "100")
        assert code == 0, f"{f}: {out}{err}"
        assert "all good" in out
    poses = Path("iso/kuka/ISOPOSES.src").read_text()
    assert poses.count("PTP XP") == 1 + 5 * 30        # P1, then 30 cycles of P5..P1


def test_a_refused_plan_writes_nothing(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(capsys, "iso9283", "plan", "--cell", TRACK_CELL, "--tool", "torch",
                       "--size", "500", "-o", "plan.csv", "--programs", "iso",
                       "--format", "yaskawa")
    assert code == 2 and "pulses" in err and "Traceback" not in err
    assert not Path("plan.csv").exists() and not Path("iso").exists()
    assert [p.name for p in tmp_path.iterdir()] == []


def test_a_plan_without_a_table_value_is_refused():
    with pytest.raises(InputError, match="no table value given: give the turntable's angle"):
        plan(Cell.load(TRACK_CELL), "torch", size=0.4, table=[])
