"""URDF of a cell: urdf-parser-py and the Robotics Toolbox load it, and their FK is robotcell's.

The FK of the parsed URDF is computed here from the parsed joints alone (origin, axis, type:
``T_child = T_parent * origin * motion(axis, q)``, as the URDF specification defines it), and
by the Robotics Toolbox's own ``fkine``; both must equal ``Cell.fk`` / ``Cell.frame_pose`` to
1e-9 m at random arm, track and table values.
"""

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from scipy.spatial.transform import Rotation
from test_positioner import tilt_rotate

from robotcell import load_robot, pose_from_vendor
from robotcell.cell import Cell, Frame, Positioner, Tool, Turntable
from robotcell.io.export import export_cell
from robotcell.io.export.urdf import urdf_origin
from robotcell.studies.demo import demo_cells

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "cell_kr16_track_turntable.yaml"
TOL = 1e-9


def modified_cell():
    """A modified-DH arm (KR 1000 titan) with a turntable carried by its base, no track."""
    return Cell(robot=load_robot("kuka_kr1000_titan"), robot_model="kuka_kr1000_titan",
                name="titan", T_world_R=pose_from_vendor([100, -50, 300, 20, 1, -2], "kuka"),
                turntable=Turntable(pose_from_vendor([2000, 300, -100, 10, 0.5, 0], "kuka"),
                                    parent="robot", lower=-math.pi, upper=math.pi),
                tools={"gripper": Tool(pose_from_vendor([0, 50, 400, 90, 90, 0], "kuka"))},
                frames={"jig": Frame(pose_from_vendor([10, 20, 30, 1, 2, 3], "kuka"),
                                     parent="turntable"),
                        "shelf": Frame(pose_from_vendor([500, 0, 0, 0, -90, 0], "kuka"),
                                       parent="robot")})


def prismatic_cell():
    """The Stanford arm (a prismatic joint, joint limits open on some sides), no track."""
    return Cell(robot=load_robot("stanford_arm"), robot_model="stanford_arm", name="stanford",
                tools={"pen": Tool(pose_from_vendor([0, 0, 120, 0, 0, 0], "kuka"))},
                frames={"table": Frame(pose_from_vendor([600, 0, 0, 0, 0, 180], "kuka"))})


def vertical_track_cell():
    """The example cell with its track moving along Z of L (a KUKA linear unit) and scaled."""
    cell = Cell.load(EXAMPLE)
    cell.track = replace(cell.track, axis="z", scale=1.0003, lower=-1.0, upper=0.5,
                         T_world_L=pose_from_vendor([10, 20, 30, 0, 90, 0], "kuka"))
    return cell


CELLS = {"track_turntable": lambda: Cell.load(EXAMPLE), "modified_dh": modified_cell,
         "prismatic": prismatic_cell, "demo_truth": lambda: demo_cells()[0],
         "vertical_track": vertical_track_cell, "positioner": tilt_rotate,
         "positioner_modified": lambda: tilt_rotate("modified")}


def random_values(cell, rng, n=20):
    lo = np.where(np.isfinite(cell.robot.lower), cell.robot.lower, -math.pi)
    hi = np.where(np.isfinite(cell.robot.upper), cell.robot.upper, math.pi)
    q = rng.uniform(lo, hi, (n, cell.robot.n_joints))
    e = rng.uniform(cell.track.lower, cell.track.upper, n) if cell.track else np.zeros(n)
    th = rng.uniform(-math.pi, math.pi, n) if cell.turntable else np.zeros(n)
    if isinstance(cell.turntable, Positioner):
        th = rng.uniform(-math.pi, math.pi, (n, cell.turntable.n_axes))
    return q, e, th


def urdf_joint_values(cell, q, e, th):
    """URDF joint name -> value: the arm's controller values, track displacement, table angle."""
    names = [j.name for j in cell.robot.joints]
    values = dict(zip(names, np.asarray(q).T))
    if cell.track is not None:
        values["track_axis"] = e * cell.track.scale
    if isinstance(cell.turntable, Positioner):
        values.update({f"turntable_axis_{i + 1}": th[..., i] for i in range(th.shape[-1])})
    elif cell.turntable is not None:
        values["turntable_axis"] = th
    return values


def origin_matrix(origin):
    T = np.eye(4)
    if origin is not None:
        T[:3, :3] = Rotation.from_euler("xyz", origin.rpy or [0, 0, 0]).as_matrix()
        T[:3, 3] = origin.xyz or [0, 0, 0]
    return T


def parsed_fk(model, link, values):
    """Pose of ``link`` in the root by the URDF definition, from urdf-parser-py's joints."""
    by_child = {j.child: j for j in model.joints}
    T = np.eye(4)
    while link in by_child:
        j = by_child[link]
        M = np.eye(4)
        if j.type in ("revolute", "continuous", "prismatic"):
            axis = np.asarray(j.axis, dtype=float)
            axis /= np.linalg.norm(axis)
            v = values[j.name]
            if j.type == "prismatic":
                M[:3, 3] = axis * v
            else:
                M[:3, :3] = Rotation.from_rotvec(axis * v).as_matrix()
        T = origin_matrix(j.origin) @ M @ T
        link = j.parent
    assert link == "world"
    return T


def targets(cell):
    """(URDF link, function of (q, e, th) giving robotcell's pose of it in the world)."""
    out = [("flange", lambda q, e, th: cell.fk(q, track=e, table=th, tool=np.eye(4)))]
    out += [(f"tool_{n}", lambda q, e, th, n=n: cell.fk(q, track=e, table=th, tool=n))
            for n in cell.tools]
    out += [(f"frame_{n}", lambda q, e, th, n=n: cell.frame_pose(n, track=e, table=th))
            for n in cell.frames]
    return out


def assert_same(A, B):
    assert np.max(np.abs(A[..., :3, 3] - B[..., :3, 3])) < TOL
    assert np.max(np.abs(A[..., :3, :3] - B[..., :3, :3])) < TOL


@pytest.mark.parametrize("kind", CELLS)
def test_urdf_parser_py_fk_equals_the_cells(kind):
    from urdf_parser_py.urdf import URDF

    cell = CELLS[kind]()
    model = URDF.from_xml_string(export_cell(cell, "urdf").encode())
    assert model.get_root() == "world"
    q, e, th = random_values(cell, np.random.default_rng(1))
    for link, pose in targets(cell):
        want = pose(q, e, th)
        for i in range(len(q)):
            values = {k: v[i] for k, v in urdf_joint_values(cell, q, e, th).items()}
            assert_same(parsed_fk(model, link, values), want[i])


@pytest.mark.parametrize("kind", CELLS)
def test_robotics_toolbox_loads_it_and_its_fk_equals_the_cells(kind, tmp_path):
    import roboticstoolbox as rtb
    from roboticstoolbox.models.URDF.URDFRobot import URDF_read
    from urdf_parser_py.urdf import URDF

    cell = CELLS[kind]()
    path = tmp_path / "cell.urdf"
    path.write_text(export_cell(cell, "urdf"))
    elinks, name, _ = URDF_read(path)
    robot = rtb.Robot(elinks, name=name)
    assert name == cell.name
    # the toolbox numbers its joints; each moving link is the child of one URDF joint
    child_joint = {j.child: j.name for j in URDF.from_xml_string(path.read_bytes()).joints}
    q, e, th = random_values(cell, np.random.default_rng(2), n=5)
    values = urdf_joint_values(cell, q, e, th)
    for i in range(len(q)):
        qv = np.zeros(robot.n)
        for link in robot.links:
            if link.isjoint:
                qv[link.jindex] = values[child_joint[link.name]][i]
        for target, pose in targets(cell):
            got = np.array(robot.fkine(qv, end=target).A)
            assert_same(got, pose(q[i], e[i], th[i]))


def test_urdf_origin_is_fixed_axis_roll_pitch_yaw():
    # URDF specification (wiki.ros.org/urdf/XML/joint): rpy are fixed-axis rotations about x, y,
    # z applied in that order, R = Rz(yaw) Ry(pitch) Rx(roll)
    T = pose_from_vendor([1000, 2000, 3000, 30, 0, 0], "kuka")  # KUKA A is a rotation about Z
    o = urdf_origin(T)
    assert o["xyz"] == "1.0 2.0 3.0"
    assert np.allclose([float(v) for v in o["rpy"].split()], [0, 0, math.radians(30)])


def test_cli_writes_the_urdf(tmp_path, capsys):
    out = tmp_path / "cell.urdf"
    code, _, err = run(capsys, "export", "--cell", EXAMPLE, "--format", "urdf", "-o", out)
    assert code == 0, err
    assert out.read_text() == export_cell(Cell.load(EXAMPLE), "urdf")
    text = out.read_text()
    assert '<joint name="track_axis" type="prismatic">' in text
    assert '<joint name="turntable_axis" type="revolute">' in text
    assert '<link name="tool_torch" />' in text and '<link name="frame_part" />' in text
