"""Cells of several robots: the robots section of the cell file, kinematics per robot, refusals.

A robot of a cell of several robots must move exactly as the same robot alone in a one-robot
cell placed at its base, with the same positioner and frames; one-robot cell files keep loading
and saving byte for byte.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from robotcell import InputError, make_pose, pose_from_vendor
from robotcell.cell import Cell, CellRobot, Frame, Provenance, Tool, cell_to_dict
from robotcell.robot.models import load_robot

ROOT = Path(__file__).resolve().parents[1]
TWO = ROOT / "examples" / "cell_two_robots_positioner.yaml"
ONE_ROBOT_FILES = sorted(p for p in [*(ROOT / "examples").glob("cell_*.yaml"),
                                     *(ROOT / "tests" / "data").glob("*.yaml")]
                         if p.name != TWO.name and "\nrobots:" not in p.read_text())


@pytest.mark.parametrize("path", ONE_ROBOT_FILES + [TWO], ids=lambda p: p.name)
def test_every_cell_file_saves_byte_for_byte(path, tmp_path):
    copy = tmp_path / path.name
    shutil.copy(path, copy)
    cell = Cell.load(copy)
    cell.save(copy)
    assert copy.read_bytes() == path.read_bytes()


@pytest.mark.parametrize("path", ONE_ROBOT_FILES, ids=lambda p: p.name)
def test_one_robot_file_is_a_cell_of_one_robot_named_robot(path):
    cell = Cell.load(path)
    assert cell.robot_names == ("robot",)
    assert cell.robots["robot"].robot is cell.robot
    assert "robots" not in cell_to_dict(cell)


def test_two_robot_file_round_trips_through_a_new_file(tmp_path):
    cell = Cell.load(TWO)
    cell.save(tmp_path / "new.yaml")
    back = Cell.load(tmp_path / "new.yaml")
    assert back.robot_names == ("kuka", "abb")
    assert cell_to_dict(back) == cell_to_dict(cell)
    assert back.frames["cleaner"].parent == "kuka"
    assert back.robots["kuka"].track.name == "KL1500"
    assert set(back.robots["abb"].tools) == {"torch", "pointer"}


def _alone(cell: Cell, name: str) -> Cell:
    """The robot ``name`` alone in a one-robot cell at its base, with the shared parts."""
    unit = cell.robots[name]
    frames = {k: f for k, f in cell.frames.items() if f.parent in ("world", "turntable")}
    return Cell(robot=unit.robot, robot_model=unit.model, T_world_R=unit.T_world_R,
                track=unit.track, turntable=cell.turntable, tools=dict(unit.tools), frames=frames)


@pytest.mark.parametrize("name", ["kuka", "abb"])
def test_fk_and_ik_of_each_robot_equal_the_robot_alone(name):
    cell = Cell.load(TWO)
    alone = _alone(cell, name)
    rng = np.random.default_rng(7)
    n = cell.robots[name].robot.n_joints
    q = rng.uniform(-1.0, 1.0, (20, n))
    e = rng.uniform(0.0, 3.0, 20) if cell.robots[name].track else 0.0
    v = rng.uniform(-1.0, 1.0, (20, 2))
    for frame in ("world", "part", "table"):
        got = cell.fk(q, track=e, table=v, tool="torch", frame=frame, robot=name)
        assert np.allclose(got, alone.fk(q, track=e, table=v, tool="torch", frame=frame),
                           atol=1e-12)
    T = alone.fk(q, track=e, table=v, tool="torch", frame="part")
    track = None if cell.robots[name].track is None else e
    sol = cell.ik_batch(T, "part", track=track, table=v, tool="torch", robot=name)
    ref = alone.ik_batch(T, "part", track=track, table=v, tool="torch")
    assert np.array_equal(sol.valid, ref.valid)
    assert np.allclose(np.nan_to_num(sol.q), np.nan_to_num(ref.q), atol=1e-12)
    i, b = np.nonzero(sol.valid)
    assert len(i) > 10
    back = cell.fk(sol.q[i, b], track=sol.track[i], table=v[i], tool="torch", frame="part",
                   robot=name)
    assert np.allclose(back, T[i], atol=1e-9)


def test_frame_on_a_robot_track_moves_with_that_robot():
    cell = Cell.load(TWO)
    e = np.array([0.0, 1.5])
    T = cell.frame_pose("cleaner", track=e, robot="kuka")
    R = cell.frame_pose("robot", track=e, robot="kuka")
    assert np.allclose(T, R @ cell.frames["cleaner"].pose)
    with pytest.raises(InputError, match="frame 'cleaner' is fixed to robot 'kuka', which "
                       "moves on its track: robot 'abb' does not know where it is"):
        cell.frame_pose("cleaner", robot="abb")
    with pytest.raises(InputError, match="frame 'cleaner' is fixed to robot 'kuka'"):
        cell.ik(np.eye(4), frame="cleaner", robot="abb")


def test_track_choice_is_per_robot():
    cell = Cell.load(TWO)
    kuka = cell.robots["kuka"]
    T = cell.fk(np.radians([0, -80, 100, 0, 40, 0]), track=2.0, tool="torch", robot="kuka")
    sol = cell.ik(T, tool="torch", robot="kuka")  # the track value chosen for the target
    assert kuka.track.within_limits(sol.track)
    assert sol.valid.any()
    back = cell.fk(sol.q[sol.valid][0], track=sol.track, tool="torch", robot="kuka")
    assert np.allclose(back, T, atol=1e-9)


def test_unknown_robot_is_refused_naming_the_robots():
    cell = Cell.load(TWO)
    with pytest.raises(InputError, match=r"the cell has no robot 'fanuc'; its robots: kuka, abb"):
        cell.fk(np.zeros(6), robot="fanuc")
    with pytest.raises(InputError, match=r"no robot 'fanuc'"):
        cell.ik_batch(np.eye(4)[None], robot="fanuc")
    with pytest.raises(InputError, match=r"no robot 'fanuc'"):
        cell.ik(np.eye(4), robot="fanuc")
    one = Cell.load(ONE_ROBOT_FILES[0])
    with pytest.raises(InputError, match=r"no robot 'kuka'; its robots: robot"):
        one.fk(np.zeros(6), robot="kuka")


@pytest.mark.parametrize("use", [
    lambda c: c.robot, lambda c: c.track, lambda c: c.tools, lambda c: c.T_world_R,
    lambda c: c.fk(np.zeros(6)), lambda c: c.ik(np.eye(4)), lambda c: c.nominal_robot])
def test_cell_of_several_robots_without_a_robot_name_is_refused(use):
    with pytest.raises(InputError, match=r"the cell has 2 robots \(kuka, abb\); say which one"):
        use(Cell.load(TWO))


def test_one_robot_calls_keep_working_without_and_with_the_default_name():
    cell = Cell.load(ONE_ROBOT_FILES[0])
    q = np.radians([10, -80, 90, 0, 30, 0])
    assert np.array_equal(cell.fk(q), cell.fk(q, robot="robot"))
    assert cell.for_robot() is cell


def _text(tmp_path: Path, old: str, new: str) -> Path:
    path = tmp_path / "cell.yaml"
    text = TWO.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.parametrize("old, new, match", [
    ("axis: x", "axis: w", r"robot 'kuka': key 'track.axis' must be x, y or z"),
    ("model: abb_irb2400", "model: abb_nonexistent", r"robot 'abb': key 'robot.model'"),
    ("    parent: kuka ", "    parent: fanuc ",
     (r"key 'frames.cleaner.parent' must be world, turntable or a robot of the cell "
      r"\(kuka, abb\), got 'fanuc'")),
    ("    parent: kuka ", "    parent: robot ",
     r"key 'frames.cleaner.parent' must name the robot .*kuka, abb.*got 'robot'"),
    ("  abb:\n", "  world:\n",
     r"key 'robots.world' is not a valid name: robot name 'world' is reserved"),
    ("        number: 2\n        frame: {x: 250", "        number: 1\n        frame: {x: 250",
     r"key 'robots.abb' is invalid: tools 'torch' and 'pointer' have the same number 1"),
    ("  parent: world\n  frame: {x: 1100", "  parent: kuka\n  frame: {x: 1100",
     r"key 'positioner.parent' must be world or robot, got 'kuka'"),
])
def test_invalid_robots_section_is_refused_naming_robot_and_key(tmp_path, old, new, match):
    with pytest.raises(InputError, match=match):
        Cell.load(_text(tmp_path, old, new))


def test_top_level_robot_sections_are_refused_beside_robots(tmp_path):
    path = tmp_path / "cell.yaml"
    path.write_text(TWO.read_text() + "tools: {}\n")
    with pytest.raises(InputError, match=r"the top level has unknown key\(s\) \['tools'\]"):
        Cell.load(path)


def test_tool_numbers_are_per_robot():
    cell = Cell.load(TWO)
    assert cell.robots["kuka"].tools["torch"].number == cell.robots["abb"].tools["torch"].number
    tool = cell.set_tool("brush", make_pose(np.eye(3), [0, 0, 0.2]), Provenance("manual"),
                         number=2, robot="kuka")
    assert cell.robots["kuka"].tools["brush"] is tool and "brush" not in cell.robots["abb"].tools
    with pytest.raises(InputError, match="tools 'pointer' and 'brush' have the same number 2"):
        cell.set_tool("brush", np.eye(4), Provenance("manual"), number=2, robot="abb")


def test_set_robot_base_relative_to_another_robot(tmp_path):
    cell = Cell.load(TWO)
    T_Rk_Ra = pose_from_vendor([1200, 50, 10, -178, 0.2, 0.1], "kuka")
    prov = Provenance.now("robot-to-robot", rms_mm=0.3)
    cell.set_robot_base("abb", T_Rk_Ra, prov, reference="kuka", reference_track=1.1)
    T_w_Rk = cell.frame_pose("robot", track=1.1, robot="kuka")
    assert np.allclose(cell.robots["abb"].T_world_R, T_w_Rk @ T_Rk_Ra)
    cell.save(tmp_path / "placed.yaml")
    back = Cell.load(tmp_path / "placed.yaml")
    assert np.allclose(back.robots["abb"].T_world_R, T_w_Rk @ T_Rk_Ra, atol=1e-9)
    assert back.robots["abb"].base_provenance.source == "robot-to-robot"
    # a robot on a track is placed through its track's robot_at_zero
    T = pose_from_vendor([500, -1000, 20, 90, 0, 0], "kuka")
    cell.set_robot_base("kuka", T, prov)
    assert np.allclose(cell.frame_pose("robot", robot="kuka"), T)
    with pytest.raises(InputError, match="relative to itself"):
        cell.set_robot_base("kuka", T, prov, reference="kuka")
    with pytest.raises(InputError, match="no robot 'fanuc'"):
        cell.set_robot_base("fanuc", T, prov)


def test_cell_of_two_robots_built_in_python_saves_a_robots_section(tmp_path):
    kr16, irb = load_robot("kuka_kr16"), load_robot("abb_irb2400")
    torch = Tool(make_pose(np.eye(3), [0.3, 0, 0.1]), number=1)
    cell = Cell(robots={
        "left": CellRobot(kr16, "kuka_kr16", tools={"torch": torch}),
        "right": CellRobot(irb, "abb_irb2400", T_world_R=make_pose(np.eye(3), [2.0, 0, 0]),
                           tools={"torch": torch})},
        frames={"jig": Frame(make_pose(np.eye(3), [1.0, 0, 0.5]), number=1),
                "gauge": Frame(np.eye(4), parent="right", number=2)}, name="pair")
    cell.save(tmp_path / "pair.yaml")
    text = (tmp_path / "pair.yaml").read_text()
    assert "robots:\n  left:\n    model: kuka_kr16" in text and "parent: right" in text
    back = Cell.load(tmp_path / "pair.yaml")
    assert np.allclose(back.frame_pose("gauge", robot="left"), cell.robots["right"].T_world_R)
    with pytest.raises(InputError, match="give each its tools in its CellRobot"):
        Cell(robots=cell.robots, tools={})


def test_reach_map_and_table_choice_take_the_robot_name():
    from robotcell.cell.tablechoice import choose_table
    from robotcell.studies.reach import reach_map

    cell = Cell.load(TWO)
    alone = _alone(cell, "abb")
    q = np.radians([[0, 10, 10, 0, 50, 0], [5, 12, 8, 0, 48, 5], [10, 14, 6, 0, 46, 10]])
    T = alone.fk(q, table=[0.1, 0.2], tool="torch", frame="part")
    got = reach_map(cell, T, "part", "torch", table=[0.1, 0.2], robot="abb")
    ref = reach_map(alone, T, "part", "torch", table=[0.1, 0.2])
    assert np.array_equal(got.score, ref.score) and got.fraction == 1.0
    path = choose_table(cell, T, "part", tool="torch", robot="abb")
    assert np.array_equal(path.table, choose_table(alone, T, "part", tool="torch").table)
    with pytest.raises(InputError, match="no robot 'fanuc'"):
        reach_map(cell, T, "part", "torch", robot="fanuc")


def test_a_sweep_places_several_robots_and_scores_the_named_one():
    from robotcell.studies.sweep import apply_layout, read_layouts, sweep

    cell = Cell.load(TWO)
    layouts = read_layouts({"kuka": {"y": [0, -200]}, "abb": {"x": [0, 300]}})
    moved = apply_layout(cell, layouts[-1])
    assert np.allclose(moved.robots["abb"].T_world_R[:3, 3] - cell.robots["abb"].T_world_R[:3, 3],
                       [0.3, 0, 0])
    assert np.allclose(moved.robots["kuka"].track.T_world_L[:3, 3]
                       - cell.robots["kuka"].track.T_world_L[:3, 3], [0, -0.2, 0])
    assert np.array_equal(cell.robots["abb"].T_world_R, Cell.load(TWO).robots["abb"].T_world_R)
    T = cell.fk(np.radians([0, 10, 10, 0, 50, 0]), table=[0.1, 0.2], tool="torch",
                frame="part", robot="abb")[None]
    ranked = sweep(cell, T, layouts, frame="part", tool="torch", table=[0.1, 0.2], robot="abb")
    assert len(ranked) == 4 and ranked[0].fraction == 1.0
    with pytest.raises(InputError, match="the layout moves 'robot', which the cell does not "
                                         "have; it has: kuka, abb, turntable"):
        apply_layout(cell, read_layouts({"robot": {"y": [0]}})[0])


def test_urdf_holds_every_robot_its_track_and_the_shared_positioner():
    from test_export_urdf import assert_same, parsed_fk
    from urdf_parser_py.urdf import URDF

    from robotcell.export import export_cell

    cell = Cell.load(TWO)
    model = URDF.from_xml_string(export_cell(cell, "urdf").encode())
    links = {link.name for link in model.links}
    assert {"kuka_base_link", "kuka_track_carriage", "kuka_flange", "kuka_tool_torch",
            "abb_base_link", "abb_flange", "abb_tool_pointer", "turntable"} <= links
    assert "base_link" not in links
    rng = np.random.default_rng(3)
    v = rng.uniform(-1, 1, 2)
    for name in cell.robot_names:
        unit = cell.robots[name]
        q = rng.uniform(-1, 1, unit.robot.n_joints)
        e = 1.2 if unit.track else 0.0
        qm = unit.robot.model_values(q)
        values = {f"{name}_{j.name}": qm[i] for i, j in enumerate(unit.robot.joints)
                  if not j.passive}
        values.update({"kuka_track_axis": 1.2, "turntable_axis_1": v[0], "turntable_axis_2": v[1]})
        for tool in unit.tools:
            assert_same(parsed_fk(model, f"{name}_tool_{tool}", values),
                        cell.fk(q, track=e, table=v, tool=tool, robot=name))
    assert_same(parsed_fk(model, "frame_cleaner", values),
                cell.frame_pose("cleaner", track=1.2, robot="kuka"))
    assert_same(parsed_fk(model, "frame_part", values), cell.frame_pose("part", table=v,
                                                                        robot="abb"))


def test_3d_view_shows_every_robot_its_track_and_the_shared_positioner():
    from robotcell.view.cellscene import cell_scene, robot_items

    cell = Cell.load(TWO)
    q = np.radians([5, 20, 10, 0, 30, 0])
    scene = cell_scene(cell, joints={"abb": q}, track={"kuka": 1.5}, table=[0.2, 0.3])
    names = [item.name for item in scene.items]
    assert {"kuka: track KL1500: travel of R", "kuka: robot kuka_kr16: links",
            "abb: robot abb_irb2400: links", "positioner DKP_2: plate", "kuka: frames",
            "frames"} <= set(names)
    by_name = {item.name: item for item in scene.items}
    flange = by_name["abb: robot abb_irb2400: flange F"].poses[0]
    assert np.allclose(flange, cell.fk(q, table=[0.2, 0.3], tool=np.eye(4), robot="abb"))
    assert np.allclose(by_name["kuka: frames"].poses[0],
                       cell.frame_pose("cleaner", track=1.5, robot="kuka"))
    alone = robot_items(_alone(cell, "abb"), q, 0.0, 0.1)
    assert [i.name for i in alone][1] == "robot abb_irb2400: links"
    with pytest.raises(InputError, match="no robot 'fanuc'"):
        cell_scene(cell, joints={"fanuc": q})
