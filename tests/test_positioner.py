"""External axes as kinematic chains: positioners of 1-3 axes in the cell model, FK, IK, files.

The reference for a positioner's motion is the product of screw motions about its axis lines
(``robotcell.dhprocedure.AxisChain.fk``), which shares no choice with a DH table; the positioner
itself is the DH chain the DH procedure derives from those lines, the form an identified chain
takes.
"""

import math
from pathlib import Path

import numpy as np
import pytest

from robotcell import make_pose, rot_x, rot_y, rot_z
from robotcell.cell import Cell, Frame, Positioner, Provenance, Tool, Turntable
from robotcell.dhprocedure import AxisChain, dh_from_axes
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor
from robotcell.robot.models import load_robot
from robotcell.studies.demo import demo_cells

ROOT = Path(__file__).resolve().parent.parent
DATA = Path(__file__).resolve().parent / "data"
EXAMPLE = ROOT / "examples" / "cell_kr16_track_turntable.yaml"

#: Tilt-rotate positioner at q = 0, in its root frame: tilt about Y at 0.8 m height, rotate about
#: Z through a point 50 mm off the tilt axis (the common normal is not zero), plate at 0.7 m.
AXES = AxisChain(points=[[0.0, 0.0, 0.8], [0.05, 0.0, 0.6]],
                 directions=[[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                 types=("revolute", "revolute"),
                 flange=make_pose(np.eye(3), [0.05, 0.0, 0.7]),
                 names=("E1", "E2"),
                 lower=np.radians([-95.0, -400.0]), upper=np.radians([95.0, 400.0]))
T_WORLD_ROOT = pose_from_vendor([1100, 200, 0, 20, 0, 0], "kuka")
T_P_PART = pose_from_vendor([80, -40, 30, 15, 0, 0], "kuka")


def tilt_rotate(convention="standard", axes=AXES, T_world_root=T_WORLD_ROOT):
    """A KR 16 on the floor beside a tilt-rotate positioner carrying frame 'part'."""
    chain = dh_from_axes(axes, convention, name="tilt_rotate").robot
    pos = Positioner(chain.with_base(T_world_root @ chain.base), name="DKP_2")
    return Cell(robot=load_robot("kuka_kr16"), robot_model="kuka_kr16", name="positioner_cell",
                turntable=pos, tools={"torch": Tool(pose_from_vendor([312.5, 0, 95, 0, 45, 0],
                                                                     "kuka"))},
                frames={"part": Frame(T_P_PART, parent="turntable", number=1)})


@pytest.mark.parametrize("source, golden", [
    (EXAMPLE, "cell_kr16_track_turntable.saved.yaml"),
    (DATA / "cell_kr16_track_turntable.saved.yaml", "cell_kr16_track_turntable.saved.yaml"),
    (DATA / "demo_truth.saved.yaml", "demo_truth.saved.yaml"),
    (DATA / "demo_nominal.saved.yaml", "demo_nominal.saved.yaml"),
])
def test_old_cell_files_load_and_save_unchanged(source, golden, tmp_path):
    # the golden files were written by robotcell before positioners existed
    out = tmp_path / "cell.yaml"
    Cell.load(source).save(out)
    assert out.read_bytes() == (DATA / golden).read_bytes()


def test_the_demo_cells_save_as_before(tmp_path):
    truth, nominal = demo_cells()
    for cell, golden in ((truth, "demo_truth.saved.yaml"), (nominal, "demo_nominal.saved.yaml")):
        cell.save(tmp_path / golden)
        assert (tmp_path / golden).read_bytes() == (DATA / golden).read_bytes()
    assert isinstance(truth.turntable, Turntable) and truth.positioner is truth.turntable


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_positioner_file_round_trip(convention, tmp_path):
    cell = tilt_rotate(convention)
    cell.save(tmp_path / "a.yaml")
    text = (tmp_path / "a.yaml").read_text()
    assert "positioner:" in text and "turntable:" not in text and "axes:" in text
    back = Cell.load(tmp_path / "a.yaml")
    back.save(tmp_path / "b.yaml")
    assert (tmp_path / "a.yaml").read_bytes() == (tmp_path / "b.yaml").read_bytes()
    pos = back.turntable
    assert isinstance(pos, Positioner) and pos.n_axes == 2 and pos.name == "DKP_2"
    assert pos.chain.convention == convention
    v = np.radians([[10.0, 30.0], [-40.0, 200.0]])
    assert np.allclose(back.frame_pose("part", table=v), cell.frame_pose("part", table=v),
                       atol=1e-9)
    assert np.allclose(pos.lower, np.radians([-95, -400])) and np.allclose(pos.upper,
                                                                           np.radians([95, 400]))


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_two_axis_positioner_moves_about_its_axis_lines(convention):
    cell = tilt_rotate(convention)
    rng = np.random.default_rng(3)
    v = rng.uniform(-1.5, 1.5, (50, 2))
    want = T_WORLD_ROOT @ AXES.fk(v) @ T_P_PART
    assert np.allclose(cell.frame_pose("part", table=v), want, atol=1e-12)
    # the root frame is fixed; the batch shapes of track and table broadcast
    assert np.allclose(cell.frame_pose("turntable", table=v[:3]),
                       np.broadcast_to(cell.turntable.T_parent_root, (3, 4, 4)))
    assert cell.fk(np.zeros((4, 1, 6)), table=v[:5]).shape == (4, 5, 4, 4)


def test_one_axis_positioner_is_the_turntable():
    truth, _ = demo_cells()
    tt = truth.turntable
    chain = tt.chain
    pos_cell = Cell(robot=truth.robot, robot_model="kuka_kr16", track=truth.track,
                    turntable=Positioner(chain, name=tt.name), frames=dict(truth.frames),
                    tools=dict(truth.tools))
    th = np.radians(np.linspace(-300, 300, 13))
    assert np.allclose(pos_cell.frame_pose("part", track=2.0, table=th[:, None]),
                       truth.frame_pose("part", track=2.0, table=th), atol=1e-12)
    q = np.radians([10, -80, 90, 5, 30, 7])
    assert np.allclose(pos_cell.fk(q, track=1.0, table=th[:, None], frame="part", tool="torch"),
                       truth.fk(q, track=1.0, table=th, frame="part", tool="torch"), atol=1e-12)


def test_an_identified_chain_drops_in_with_its_provenance():
    cell = tilt_rotate()
    identified = dh_from_axes(AxisChain(points=AXES.points + 0.001, directions=AXES.directions,
                                        types=AXES.types, flange=AXES.flange,
                                        lower=AXES.lower, upper=AXES.upper), "standard").robot
    chain = identified.with_base(T_WORLD_ROOT @ identified.base)
    pos = cell.update_positioner(Provenance("positioner", rms_mm=0.2), chain)
    assert cell.turntable is pos and pos.name == "DKP_2" and pos.parent == "world"
    assert pos.chain is chain and pos.provenance.source == "positioner"
    # a turntable becomes a positioner the same way
    truth, _ = demo_cells()
    truth.update_positioner(Provenance("positioner"), truth.turntable.chain)
    assert isinstance(truth.turntable, Positioner) and truth.turntable.name == "DKP_400"


def test_cell_ik_takes_the_axis_values():
    cell = tilt_rotate()
    v = np.radians([[20.0, 45.0], [-30.0, 170.0], [0.0, -90.0]])
    T_part_TCP = make_pose(rot_y(math.pi) @ rot_x(0.2), [0.05, 0.02, 0.01])
    sol = cell.ik(T_part_TCP, frame="part", table=v, tool="torch")
    assert sol.table.shape == (3, 2) and np.all(sol.count > 0)
    for k in range(3):
        q = sol.q[k][sol.valid[k]][0]
        assert np.allclose(cell.fk(q, table=v[k], tool="torch", frame="part"), T_part_TCP,
                           atol=1e-9)
    out = np.radians([[100.0, 0.0]])  # tilt beyond its limit
    assert not cell.ik(T_part_TCP, frame="part", table=out, tool="torch").valid.any()


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_normal_up_turns_the_normal_straight_up(convention):
    cell = tilt_rotate(convention)
    pos = cell.turntable
    rng = np.random.default_rng(8)
    # directions within 80 deg of the plate's Z: a tilt of +-95 deg reaches them
    n = rng.normal(size=(200, 3))
    n[:, 2] = np.abs(n[:, 2]) + 0.2 * np.linalg.norm(n[:, :2], axis=1)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    values, valid = pos.normal_up(n)
    assert values.shape == (200, 2, 2) and valid.any(axis=-1).all()
    for k in range(2):
        ok = valid[:, k]
        R = cell.frame_pose("part", table=values[ok, k])[:, :3, :3] @ T_P_PART[:3, :3].T
        assert np.allclose(np.einsum("nij,nj->ni", R, n[ok]), [0, 0, 1], atol=1e-10)
        assert np.all(pos.within_limits(values[ok, k]))


def test_ik_chooses_the_positioner_values_that_put_the_weld_normal_up():
    cell = tilt_rotate()
    # torch 10 mm above points of a tilted weld surface of the part: tool Z into the surface
    tilt = np.array([rot_x(a) @ rot_y(b) for a, b in np.radians([[30, 0], [0, -40], [20, 25]])])
    T = make_pose(tilt @ rot_y(math.pi), [[0.0, 0.0, 0.0], [0.05, -0.05, 0.02], [0.1, 0.0, 0.0]])
    sol = cell.ik(T, frame="part", table="normal_up", tool="torch")
    assert sol.table.shape == (3, 2) and np.all(sol.count > 0)
    for k in range(3):
        q = sol.q[k][sol.valid[k]][0]
        T_world_TCP = cell.fk(q, table=sol.table[k], tool="torch")
        assert np.allclose(T_world_TCP[:3, 2], [0, 0, -1], atol=1e-9)  # torch straight down
        assert np.allclose(cell.fk(q, table=sol.table[k], tool="torch", frame="part"), T[k],
                           atol=1e-9)


def test_positioner_errors_name_the_cause(tmp_path):
    robot = load_robot("kuka_kr16")
    with pytest.raises(InputError, match=r"a positioner is a chain of 1 to 3 revolute axes, got 6"):
        Positioner(robot)
    with pytest.raises(InputError, match=r"revolute axes, got 2 axes \(revolute, prismatic\)"):
        Positioner(load_robot("stanford_arm").with_base(np.eye(4)).__class__(
            "x", load_robot("stanford_arm").joints[1:3]))
    cell = tilt_rotate()
    with pytest.raises(InputError, match=r"positioner 'DKP_2' has 2 axes: give its axis values "
                                         r"with shape \(\.\.\., 2\), got \(3,\)"):
        cell.frame_pose("part", table=[0.1, 0.2, 0.3])
    with pytest.raises(InputError, match=r"positioner 'DKP_2' has 2 axes: give one value per "
                                         r"axis, shape \(\.\.\., 2\), not the single value 0.5 rad"):
        cell.fk(np.zeros(6), table=0.5)
    assert np.allclose(cell.frame_pose("part", table=0.0), cell.frame_pose("part", table=[0, 0]))
    with pytest.raises(InputError, match=r"table='normal_up' needs targets in a frame carried"):
        cell.ik(np.eye(4), frame="world", table="normal_up")
    truth, _ = demo_cells()
    with pytest.raises(InputError, match=r"table='normal_up' needs a positioner of 2 axes"):
        truth.ik(np.eye(4), frame="part", table="normal_up")
    with pytest.raises(InputError, match=r"use update_positioner"):
        cell.update_turntable(Provenance("turntable"))
    path = tmp_path / "both.yaml"
    cell.save(path)
    text = path.read_text() + ("turntable: {name: t, frame: {x: 0}}\n")
    path.write_text(text)
    with pytest.raises(InputError, match=r"key 'positioner' and key 'turntable' both describe"):
        Cell.load(path)
    cell.save(path)
    path.write_text(path.read_text().replace("alpha:", "alfa:", 1))
    with pytest.raises(InputError, match=r"key 'positioner.axes\[1\]' has unknown key\(s\) "
                                         r"\['alfa'\]"):
        Cell.load(path)


@pytest.mark.parametrize("fmt", ["kuka", "abb"])
@pytest.mark.parametrize("convention, signs", [("standard", [1, 1]), ("modified", [1, -1]),
                                               ("standard", [-1, -1])])
def test_kuka_and_abb_exports_hold_the_axis_chain(fmt, convention, signs):
    from robotcell.export import export_cell, parse_export

    chain = dh_from_axes(AXES, convention, signs=signs).robot
    cell = tilt_rotate()
    cell.turntable = Positioner(chain.with_base(T_WORLD_ROOT @ chain.base), name="DKP_2")
    data = parse_export(export_cell(cell, fmt), fmt)
    frames = data.positioner_frames
    assert len(frames) == (4 if fmt == "kuka" else 3)
    part = next(s for s in data.frames if s.name == "part")
    v = np.random.default_rng(4).uniform(-1.5, 1.5, (20, 2))
    T = np.broadcast_to(data.turntable.pose, (20, 4, 4))
    for i in range(len(frames) - 1):  # every axis turns by +value about its frame's Z
        T = T @ frames[i]
        if i < 2:
            T = T @ make_pose(np.array([rot_z(a) for a in v[:, i]]))
    T = T @ frames[-1] @ part.pose
    want = cell.frame_pose("part", table=v)
    assert np.allclose(T[:, :3, 3], want[:, :3, 3], atol=1e-8)  # exports keep 1e-6 mm
    assert np.allclose(T[:, :3, :3], want[:, :3, :3], atol=1e-9)


def test_kuka_positioner_next_to_a_linear_unit_is_et2():
    from robotcell.export import export_cell

    truth, _ = demo_cells()
    chain = dh_from_axes(AXES, "standard").robot
    truth.update_positioner(Provenance("positioner"),
                            chain.with_base(truth.turntable.T_parent_B @ chain.base))
    text = export_cell(truth, "kuka")
    assert "$ET2_TA1KR=" in text and "$ET2_TFLA3=" in text and "$ET1_TFLA3=" in text
    assert "$EX_KIN={ET2 #EASYS,...} with 2 axes" in text


def test_one_axis_procedures_refuse_a_positioner_chain():
    from robotcell.cell import calibrate as cellcal
    from robotcell.studies.simulate import simulate

    cell = tilt_rotate()
    with pytest.raises(InputError, match=r"positioner 'DKP_2' is a chain of 2 axes; the "
                                         r"simulation of the turntable and workpiece procedures"):
        simulate(cell, "turntable")
    table = {"x": [1000.0, 1100.0, 1200.0], "y": [0.0, 10.0, 0.0], "z": [500.0] * 3,
             "e1": [0.0, 90.0, 180.0]}
    with pytest.raises(InputError, match=r"the turntable procedure is for a one-axis turntable; "
                                         r"a positioner chain is calibrated by "
                                         r"robotcell.cell.calibrate.positioner"):
        cellcal.turntable(cell, table)


@pytest.mark.parametrize("fmt", ["fanuc", "yaskawa"])
def test_fanuc_and_yaskawa_write_frames_on_a_positioner_at_axis_zero(fmt):
    from robotcell.export import export_cell, parse_export

    cell = tilt_rotate("modified")
    part = next(s for s in parse_export(export_cell(cell, fmt), fmt).frames if s.name == "part")
    T_world_R = cell.frame_pose("robot")  # both refer to the robot base at track position 0
    assert np.allclose(part.pose, np.linalg.inv(T_world_R) @ cell.frame_pose("part", table=[0, 0]),
                       atol=1e-8)


def test_cell_show_lists_the_positioner(tmp_path, capsys):
    from cli_helpers import run

    tilt_rotate().save(tmp_path / "cell.yaml")
    code, out, err = run(capsys, "cell", "show", tmp_path / "cell.yaml")
    assert code == 0, err
    assert "positioner DKP_2: 2 axes, E1 -95 .. 95, E2 -400 .. 400 deg" in out
    assert "positioner root (world)" in out


def test_ik_path_follows_the_positioner_axes():
    cell = tilt_rotate()
    v = np.column_stack([np.full(31, np.radians(20.0)), np.radians(np.linspace(45, 105, 31))])
    T_part_TCP = make_pose(rot_y(math.pi) @ rot_x(0.2), [0.05, 0.02, 0.01])
    path = cell.ik_path(T_part_TCP, frame="part", table=v, tool="torch")
    assert path.q.shape == (31, 6) and path.table.shape == (31, 2)
    assert np.allclose(cell.fk(path.q, table=v, tool="torch", frame="part"), T_part_TCP,
                       atol=1e-9)


def test_positioner_touches_map_a_touched_point_into_the_parent_frame():
    from robotcell.cell import calibrate as cellcal

    cell = tilt_rotate()
    v = np.radians([[0.0, 0.0], [30.0, 90.0], [-20.0, 200.0], [10.0, -45.0]])
    p_P = np.array([0.2, 0.1, 0.02])  # a point on the plate
    p_world = (cell.frame_pose("part", table=v) @ np.linalg.inv(T_P_PART) @ [*p_P, 1])[:, :3]
    table = {"x": p_world[:, 0] * 1e3, "y": p_world[:, 1] * 1e3, "z": p_world[:, 2] * 1e3,
             "e1": np.degrees(v[:, 0]), "e2": np.degrees(v[:, 1])}
    values, points = cellcal.positioner_touches(cell, table)
    assert np.allclose(values, v) and np.allclose(points, p_world, atol=1e-12)
    del table["e2"]
    with pytest.raises(InputError, match=r"missing column\(s\) e2"):
        cellcal.positioner_touches(cell, table)


def test_positioner_calibration_into_the_cell_recovers_the_true_chain(tmp_path):
    from robotcell.cell import calibrate as cellcal

    true_axes = AxisChain(points=AXES.points + [[0.002, -0.001, 0.003], [0.001, 0.002, 0.0]],
                          directions=AXES.directions + [[0.0, 0.0, 0.004], [0.003, -0.002, 0.0]],
                          types=AXES.types, flange=AXES.flange, names=AXES.names,
                          lower=AXES.lower, upper=AXES.upper)
    truth, nominal = tilt_rotate(axes=true_axes), tilt_rotate()
    grid = np.array([[t, r] for t in np.radians([-40, 0, 40])
                     for r in np.radians([0, 90, 180, 270])])
    p_P = np.array([0.2, 0.1, 0.0, 1.0])  # a point on the plate, touched at every (tilt, rotate)
    rng = np.random.default_rng(5)
    points = (truth.frame_pose("part", table=grid) @ np.linalg.inv(T_P_PART) @ p_P)[:, :3]
    points = points + rng.normal(0.0, 1e-4, points.shape)
    table = {"x": points[:, 0] * 1e3, "y": points[:, 1] * 1e3, "z": points[:, 2] * 1e3,
             "e1": np.degrees(grid[:, 0]), "e2": np.degrees(grid[:, 1])}
    done = cellcal.positioner(nominal, table, sigma=1e-4, time="2026-01-01T00:00:00+00:00")
    pos = done.cell.turntable
    assert isinstance(pos, Positioner) and pos.name == "DKP_2" and done.item.startswith("positioner")
    assert done.provenance.source == "positioner" and nominal.turntable.chain is not pos.chain
    # the table moves as the true one: a point of the table at axis 0 goes where it truly goes
    # (the motion T_world_P(v) inv(T_world_P(0)) does not depend on where the plate frame is)
    v = rng.uniform(-1.2, 1.2, (30, 2))
    x0 = np.array([1.0, 0.3, 0.75, 1.0])  # in the world, on the table at axis 0

    def moved(cell):
        return (cell.frame_pose("part", table=v) @ np.linalg.inv(cell.frame_pose("part")) @ x0)

    got, want, before = moved(done.cell), moved(truth), moved(nominal)
    assert np.max(np.linalg.norm(got[:, :3] - want[:, :3], axis=1)) < 0.5e-3
    assert np.max(np.linalg.norm(before[:, :3] - want[:, :3], axis=1)) > 2e-3
    done.cell.save(tmp_path / "cell.yaml")
    assert Cell.load(tmp_path / "cell.yaml").turntable.provenance.source == "positioner"
    with pytest.raises(InputError, match=r"has no positioner of 2 axes"):
        cellcal.positioner(demo_cells()[1], table)


def test_workpiece_on_a_positioner_chain_is_touched_into_its_plate():
    from robotcell.cell import calibrate as cellcal

    cell = tilt_rotate("modified")
    p_W = np.array([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0]] * 2, dtype=float)  # origin, x, xy
    roles = ["origin", "x", "xy"] * 2
    v = np.radians([[10.0, 30.0], [10.0, 30.0], [-20.0, 100.0],
                    [0.0, 0.0], [25.0, -60.0], [5.0, 200.0]])
    T_world_W = cell.frame_pose("part", table=v)
    rng = np.random.default_rng(9)
    p = np.einsum("nij,nj->ni", T_world_W[:, :3, :3], p_W) + T_world_W[:, :3, 3]
    p = p + rng.normal(0.0, 5e-5, p.shape)
    table = {"x": p[:, 0] * 1e3, "y": p[:, 1] * 1e3, "z": p[:, 2] * 1e3,
             "e1": np.degrees(v[:, 0]), "e2": np.degrees(v[:, 1]), "point": roles}
    seen = []
    done = cellcal.workpiece(cell, table, "part2", on_note=seen.append)
    T = done.cell.frames["part2"].pose
    assert done.cell.frames["part2"].parent == "turntable"
    assert np.linalg.norm(T[:3, 3] - T_P_PART[:3, 3]) < 3e-4
    assert np.allclose(T[:3, :3], T_P_PART[:3, :3], atol=5e-3)
    assert "T_P_W" in done.result.values and done.inputs == ("turntable",)
    assert any("positioner 'DKP_2' (root pose and the constants of each axis) is a nominal "
               "value: its accuracy is taken as 1 mm and 0.5 deg" in s for s in seen), seen
    with pytest.raises(InputError, match=r"carries its own calibration: give no turntable"):
        cellcal.workpiece(cell, table, "part2", turntable=cellcal.TurntablePose(np.eye(4)))
