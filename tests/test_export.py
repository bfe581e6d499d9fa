"""Controller exports: exact text of known values, export -> parse round trips to 1e-6 mm, and
the exported frames reproduce the cell's kinematics the way each controller chains them."""

import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell import InputError, load_robot, pose_from_vendor
from robotcell.cell import Cell, Frame, Tool, Track, Turntable
from robotcell.controllers.data import collect
from robotcell.controllers.kuka.export import frame_text
from robotcell.export import EXPORT_FORMATS, export_cell, parse_export

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "cell_kr16_track_turntable.yaml"
ROBOT = load_robot("kuka_kr16")
#: 1e-6 mm, and the rotation error that moves a point 1 m away by 1e-6 mm.
TOL_M = 1e-9
TOL_ROT = 1e-9


def random_pose(rng, scale=1.0, b=None):
    v = np.concatenate([rng.uniform(-scale, scale, 3) * 1e3, rng.uniform(-180, 180, 3)])
    v[4] = rng.uniform(-90, 90) if b is None else b
    return pose_from_vendor(v, "kuka")


def Rz(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def Tz(d):
    T = np.eye(4)
    T[2, 3] = d
    return T


def random_cell(rng, track: bool, table_parent="world"):
    """A cell with random poses, some at gimbal lock (B = +-90 deg)."""
    tools = {f"t{i}": Tool(random_pose(rng, 0.4, b=[90.0, None, -90.0][i]),
                           mass=None if i == 2 else rng.uniform(0.5, 20),
                           cog=rng.uniform(-0.1, 0.2, 3)) for i in range(3)}
    frames = {"fix1": Frame(random_pose(rng, 3.0)), "fix2": Frame(random_pose(rng, 3.0, b=90.0)),
              "part": Frame(random_pose(rng, 0.5), parent="turntable"),
              "part2": Frame(random_pose(rng, 0.5, b=-90.0), parent="turntable", number=7)}
    if not track:
        frames["on_robot"] = Frame(random_pose(rng, 0.5), parent="robot")
    return Cell(robot=ROBOT, robot_model="kuka_kr16",
                T_world_R=np.eye(4) if track else random_pose(rng, 1.0),
                track=Track(random_pose(rng, 0.5), random_pose(rng, 0.3), axis="xyz"[rng.integers(3)],
                            name="TRACK_1") if track else None,
                turntable=Turntable(random_pose(rng, 3.0), parent=table_parent, name="STN_1"),
                tools=tools, frames=frames, name="random")


CELLS = [("example", None), ("track", True), ("fixed", False)]


def make_cell(kind, seed=0):
    if kind == "example":
        return Cell.load(EXAMPLE)
    return random_cell(np.random.default_rng(seed), track=kind == "track",
                       table_parent="world" if kind == "track" else "robot")


def assert_pose(A, B, what, links=1):
    """Poses equal to the export's precision; ``links`` rounded poses chained add their errors."""
    np.testing.assert_allclose(A[:3, 3], B[:3, 3], atol=TOL_M * links, rtol=0, err_msg=what)
    np.testing.assert_allclose(A[:3, :3], B[:3, :3], atol=TOL_ROT * links, rtol=0, err_msg=what)


def assert_same_data(got, want, by_number=True):
    key = (lambda s: s.number) if by_number else (lambda s: s.name)
    assert sorted(map(key, got.tools)) == sorted(map(key, want.tools))
    assert sorted(map(key, got.frames)) == sorted(map(key, want.frames))
    gt, wt = {key(s): s for s in got.tools}, {key(s): s for s in want.tools}
    for k, s in wt.items():
        assert gt[k].name == s.name
        assert_pose(gt[k].pose, s.pose, f"tool {s.name}")
    gf, wf = {key(s): s for s in got.frames}, {key(s): s for s in want.frames}
    for k, s in wf.items():
        assert (gf[k].name, gf[k].on_table) == (s.name, s.on_table)
        assert_pose(gf[k].pose, s.pose, f"frame {s.name}")
    for attr in ("robot", "track_root", "track_robot", "turntable"):
        g, w = getattr(got, attr), getattr(want, attr)
        assert (g is None) == (w is None), attr
        if w is not None:
            assert_pose(g.pose, w.pose, attr)


# -- known values ------------------------------------------------------------------------------
def test_kuka_line_of_the_reference_example():
    T = pose_from_vendor([107.147, 0.0, 313.237, 0.0, 45.0, 0.0], "kuka")
    assert frame_text(T) == ("{X 107.147000,Y 0.000000,Z 313.237000,A 0.000000000,"
                             "B 45.000000000,C 0.000000000}")


def test_abb_quaternion_of_known_rotations():
    cell = Cell(robot=ROBOT, robot_model="kuka_kr16",
                tools={"t1": Tool(pose_from_vendor([97.4, 0, 223.1, 0, 45, 0], "kuka"), mass=5.0,
                                  cog=[0.023, 0, 0.075])},
                frames={"w1": Frame(pose_from_vendor([0, 0, 0, 30, 20, 10], "kuka"))})
    text = export_cell(cell, "abb")
    assert ("PERS tooldata t1:=[TRUE,[[97.400000,0.000000,223.100000],[0.9238795325,0.0000000000,"
            "0.3826834324,0.0000000000]],[5.000000,[23.000000,0.000000,75.000000],[1,0,0,0],0,0,0]];"
            ) in text
    m = re.search(r"wobjdata w1:=\[FALSE,TRUE,\"\",\[\[[^]]*\],\[([^]]*)\]\]", text)
    q = [float(v) for v in m.group(1).split(",")]
    # docs/references.md: KUKA (A, B, C) = (30, 20, 10) is ABB q = [0.951549, 0.038135, 0.189308, 0.239298].
    np.testing.assert_allclose(q, [0.951549, 0.038135, 0.189308, 0.239298], atol=1e-6)
    assert abs(np.linalg.norm(q) - 1) < 1e-9


def test_fanuc_and_yaskawa_angles_of_a_known_rotation():
    cell = Cell(robot=ROBOT, robot_model="kuka_kr16",
                frames={"f": Frame(pose_from_vendor([100, 200, 300, 30, 20, 10], "kuka"))})
    # R = Rz(30) Ry(20) Rx(10): FANUC W, P, R = 10, 20, 30 (docs/references.md), and YASKAWA the same.
    fanuc = export_cell(cell, "fanuc")
    assert ("UFRAME[1]  X 100.000000  Y 200.000000  Z 300.000000  W 10.000000000  P 20.000000000  "
            "R 30.000000000  ! f") in fanuc
    assert "UFRAME[1]  X 100.000000  Y 200.000000  Z 300.000000  Rx 10.000000000" in \
        export_cell(cell, "yaskawa")


def test_kuka_example_cell_lines():
    text = export_cell(Cell.load(EXAMPLE), "kuka")
    assert ('MACHINE_DEF[2]={NAME[] "DKP_400_01",COOP_KRC_INDEX 1,PARENT[] "WORLD",ROOT '
            "{X 3000.000000,Y 1600.000000,Z 700.000000,A 90.000000000,B 0.120000000,"
            'C -0.080000000},MECH_TYPE #EASYS,GEOMETRY[] " "}') in text
    assert "BASE_DATA[2]={X 150.000000,Y -80.000000,Z 220.000000,A 15.000000000" in text
    assert "$BASE=EK(MACHINE_DEF[2].ROOT,MACHINE_DEF[2].MECH_TYPE,BASE_DATA[n])" in text
    # The linear unit along X of the world: its root frame turned so that +Z is the motion.
    assert "$ERSYSROOT={X 0.000000,Y 0.000000,Z 0.000000,A 0.000000000,B 90.000000000," in text
    assert "-0.000000" not in text


# -- round trips -------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", [k for k, _ in CELLS])
@pytest.mark.parametrize("fmt", ["kuka", "abb"])
def test_round_trip_world_formats(fmt, kind):
    for seed in range(3 if kind != "example" else 1):
        cell = make_cell(kind, seed)
        want = collect(cell, "world")
        got = parse_export(export_cell(cell, fmt), fmt)
        assert_same_data(got, want, by_number=fmt == "kuka")
        if fmt == "abb":
            for g, w in zip(got.tools, want.tools):
                if w.mass is not None:
                    assert g.mass == pytest.approx(w.mass, abs=1e-6)
                    np.testing.assert_allclose(g.cog, w.cog, atol=1e-9)
                else:
                    assert g.mass == 0.001  # ABB's load0


@pytest.mark.parametrize("kind", [k for k, _ in CELLS])
@pytest.mark.parametrize("fmt", ["fanuc", "yaskawa"])
def test_round_trip_pendant_formats(fmt, kind):
    for seed in range(3 if kind != "example" else 1):
        cell = make_cell(kind, seed)
        got = parse_export(export_cell(cell, fmt), fmt)
        T_world_ref = cell.frame_pose("robot", 0.0)
        assert [s.name for s in got.tools] == list(cell.tools)
        for s in got.tools:
            assert_pose(s.pose, cell.tools[s.name].T_F_TCP, s.name)
        frames = {s.name: s for s in got.frames}
        for name in cell.frames:
            # Every frame at track 0 and table 0, in the controller's reference at the robot.
            assert_pose(T_world_ref @ frames[name].pose, cell.frame_pose(name, 0.0, 0.0), name)
        table = frames[cell.turntable.name]
        used = {s.number for s in got.frames if s is not table}
        assert table.number == min(set(range(1, len(used) + 2)) - used)
        assert_pose(T_world_ref @ table.pose, cell.frame_pose("turntable"), "table root")


# -- the exported frames chain like the controller chains them ------------------------------------
def test_kuka_chain_reproduces_cell():
    rng = np.random.default_rng(21)
    for seed in range(3):
        cell = make_cell("track", seed)
        d = parse_export(export_cell(cell, "kuka"), "kuka")
        for e in rng.uniform(-2, 5, 5):
            # $ROBROOT_C = $ERSYSROOT : $ET1_TA1KR : Trans(Z, E1) : $ET1_TFLA3, E1 in the cell's scale.
            assert_pose(d.track_root.pose @ Tz(e * cell.track.scale) @ d.track_robot.pose,
                        cell.frame_pose("robot", e), "ROBROOT", links=2)
        for s in d.frames:
            for th in rng.uniform(-6, 6, 3):
                want = cell.frame_pose(s.name, 0.0, th)
                # $BASE = EK(ROOT, #EASYS, BASE_DATA): root, turned by the axis, then the offset.
                got = d.turntable.pose @ Rz(th) @ s.pose if s.on_table else s.pose
                assert_pose(got, want, s.name, links=2)
        q = rng.uniform(ROBOT.lower, ROBOT.upper)
        e, th = 1.3, 0.7
        tool = d.tools[0]
        part2 = {s.name: s for s in d.frames}["part2"]
        assert part2.on_table and part2.number == 7
        T_base = d.turntable.pose @ Rz(th) @ part2.pose
        T_robroot = d.track_root.pose @ Tz(e * cell.track.scale) @ d.track_robot.pose
        # What the pendant shows in that BASE with that TOOL equals the cell's TCP in the frame.
        shown = np.linalg.inv(T_base) @ T_robroot @ ROBOT.fk(q, tool=tool.pose)
        assert_pose(shown, cell.fk(q, e, th, tool.name, "part2"), "TCP in BASE", links=5)


def test_kuka_and_abb_robot_placement_without_track():
    cell = make_cell("fixed", 4)
    for fmt in ("kuka", "abb"):
        d = parse_export(export_cell(cell, fmt), fmt)
        assert_pose(d.robot.pose, cell.T_world_R, fmt)
        assert_pose(d.turntable.pose, cell.frame_pose("turntable"), fmt)
        on_robot = {s.name: s for s in d.frames}["on_robot"]
        assert_pose(on_robot.pose, cell.frame_pose("on_robot"), fmt)
    assert "$ROBROOT={" in export_cell(cell, "kuka")
    assert "CONST pose robot_base:=" in export_cell(cell, "abb")


def test_abb_track_and_coordinated_work_objects():
    cell = make_cell("track", 5)
    text = export_cell(cell, "abb")
    assert re.search(r'PERS wobjdata part:=\[FALSE,FALSE,"STN_1",\[\[0,0,0\],\[1,0,0,0\]\],', text)
    d = parse_export(text, "abb")
    for e in (0.0, 1.7):
        step = np.eye(4)
        step[2, 3] = e * cell.track.scale
        assert_pose(d.track_root.pose @ step @ d.track_robot.pose, cell.frame_pose("robot", e), "R",
                    links=2)


#: The exports that hold a track (a Universal Robots export holds no external axes).
TRACK_FORMATS = [f for f in EXPORT_FORMATS if f != "ur"]


def test_frame_moving_with_robot_on_track_is_reported_not_exported():
    cell = make_cell("track", 1)
    cell.update_frame("camera", np.eye(4), cell.tools["t0"].provenance, parent="robot")
    for fmt in TRACK_FORMATS:
        text = export_cell(cell, fmt)
        assert re.search(r"camera.*(not exported|no KUKA base holds it)", text)
        assert "camera" not in [s.name for s in parse_export(text, fmt).frames]


def test_turntable_riding_on_the_track_is_refused():
    cell = make_cell("track", 2)
    cell.turntable.parent = "robot"
    for fmt in EXPORT_FORMATS:
        with pytest.raises(InputError, match="rides on the track with the robot" if fmt in
                           TRACK_FORMATS else "hold no external axes"):
            export_cell(cell, fmt)


def test_abb_refuses_names_that_clash_as_rapid_identifiers():
    cell = Cell(robot=ROBOT, robot_model="kuka_kr16", tools={"Part": Tool(np.eye(4))},
                frames={"part": Frame(np.eye(4))})
    with pytest.raises(InputError, match="'Part' and 'part' are the same RAPID identifier"):
        export_cell(cell, "abb")


def test_unnumbered_slots_take_the_lowest_free_numbers():
    cell = Cell(robot=ROBOT, robot_model="kuka_kr16",
                tools={"a": Tool(np.eye(4)), "b": Tool(np.eye(4), number=1), "c": Tool(np.eye(4))})
    d = parse_export(export_cell(cell, "kuka"), "kuka")
    assert [(s.number, s.name) for s in d.tools] == [(1, "b"), (2, "a"), (3, "c")]


# -- parser errors -----------------------------------------------------------------------------
@pytest.mark.parametrize("fmt, text, match", [
    ("kuka", "TOOL_DATA[1]={X 1,Y 2,Z 3,A 0,B 0}", r"line 1: frame lacks C"),
    ("kuka", "BASE_DATA[3]={X 1,Y 2,Z 3,A 0,B 0,C zero}", r"line 1: 'zero' is not a number"),
    ("kuka", "TOOL_DATA[1]={X 1,Y 2,Z 3,A 0,B 0,Q 1}", r"cannot read 'Q 1'"),
    ("kuka", ('MACHINE_DEF[3]={NAME[] "KL",COOP_KRC_INDEX 1,PARENT[] "WORLD",ROOT {X 0,Y 0,Z 0,'
             'A 0,B 0,C 0},MECH_TYPE #ERSYS,GEOMETRY[] " "}'), r"#ERSYS is not a turntable"),
    ("abb", "PERS tooldata t:=[TRUE,[[1,2,3],[0.5,0.5,0.5,0.4]],[1,[0,0,0],[1,0,0,0],0,0,0]];",
     r"quaternion q1..q4 must be normalised"),
    ("fanuc", "UFRAME[1]  X 1  Y 2  Z 3  W 0  P 0", r"line 1: expected the fields X Y Z W P R"),
    ("fanuc", "UFRAME[1]  X 1  Y 2  Z 3  W 0  P 0  R 0\nUFRAME[1]  X 1  Y 2  Z 3  W 0  P 0  R 0",
     r"UFRAME\[1\] appears twice"),
    ("fanuc", "PR[1]  X 1  Y 2  Z 3  W 0  P 0  R 0", r"line 1: expected '<UTOOL\|UFRAME>\[n\]"),
    ("yaskawa", "TOOL[2]  X 1  Y 2  Z 3  Rx 0  Ry nan  Rz 0", r"line 1: 'nan' is not finite"),
])
def test_parser_errors(fmt, text, match):
    with pytest.raises(InputError, match=match):
        parse_export(text, fmt)


def test_unknown_format():
    with pytest.raises(InputError, match="unknown export format 'staubli'; choose one of: kuka"):
        export_cell(Cell.load(EXAMPLE), "staubli")
    with pytest.raises(InputError, match="unknown export format"):
        parse_export("", "kawasaki")


def test_quaternions_written_are_normalised_and_canonical():
    rng = np.random.default_rng(9)
    frames = {f"f{i}": Frame(np.block([[Rotation.random(random_state=rng).as_matrix(),
                                        rng.uniform(-1, 1, (3, 1))], [np.zeros((1, 3)), 1.0]]))
              for i in range(20)}
    text = export_cell(Cell(robot=ROBOT, robot_model="kuka_kr16", frames=frames), "abb")
    quats = re.findall(r"\],\[([-0-9.]+),([-0-9.]+),([-0-9.]+),([-0-9.]+)\]\],\[\[0,0,0\]", text)
    assert len(quats) == 20
    for q in np.array(quats, dtype=float):
        assert abs(np.linalg.norm(q) - 1) < 2e-10 and q[0] >= 0
