"""URDF of a cell: urdf-parser-py and the Robotics Toolbox load it, and their FK is robotcell's.

The FK of the parsed URDF is computed here from the parsed joints alone (origin, axis, type:
``T_child = T_parent * origin * motion(axis, q)``, as the URDF specification defines it), and
by the Robotics Toolbox's own ``fkine``; both must equal ``Cell.fk`` / ``Cell.frame_pose`` to
1e-9 m at random arm, track and table values.
"""

import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from scipy.spatial.transform import Rotation
from test_positioner import tilt_rotate

from robotcell import InputError, load_robot, pose_from_vendor
from robotcell.cell import Cell, Frame, Positioner, Tool, Turntable
from robotcell.export import export_cell
from robotcell.export.urdf import urdf_origin
from robotcell.kinematics.coupling import Coupling
from robotcell.robot.robot import Joint, Robot
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


def coupled_cell(model):
    """A library arm with a J2/J3 coupling or a passive joint, placed in the world, with a tool
    and a frame on its base."""
    return Cell(robot=load_robot(model), robot_model=model, name=model,
                T_world_R=pose_from_vendor([300, -200, 50, 30, 0, 0], "kuka"),
                tools={"gripper": Tool(pose_from_vendor([10, -20, 250, 0, 30, 90], "kuka"))},
                frames={"pallet": Frame(pose_from_vendor([1200, 300, -400, 90, 0, 0], "kuka"),
                                        parent="robot")})


def fanuc_on_track():
    """The example cell's track and turntable with a FANUC M-20iA (J3 coupled to J2)."""
    cell = Cell.load(EXAMPLE)
    cell.robot, cell.robot_model = load_robot("fanuc_m20ia"), "fanuc_m20ia"
    return cell


#: Arms whose URDF joint values are not the controller's (docs/export.md, "URDF").
COUPLED = {"fanuc_m20ia": lambda: coupled_cell("fanuc_m20ia"), "fanuc_on_track": fanuc_on_track,
           "fanuc_lrmate200id": lambda: coupled_cell("fanuc_lrmate200id"),
           "abb_irb2400": lambda: coupled_cell("abb_irb2400"),
           "abb_irb460": lambda: coupled_cell("abb_irb460")}
CELLS = {"track_turntable": lambda: Cell.load(EXAMPLE), "modified_dh": modified_cell,
         "prismatic": prismatic_cell, "demo_truth": lambda: demo_cells()[0],
         "vertical_track": vertical_track_cell, "positioner": tilt_rotate,
         "positioner_modified": lambda: tilt_rotate("modified"), **COUPLED}


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
    """URDF joint name -> value, the documented mapping: the arm's model values ``C q + offset``
    (the controller values without a coupling; FANUC J3 + J2, IRB 2400 axis3 - axis2; passive
    joints follow their mimic elements), the track displacement, the table angles."""
    qm = cell.robot.model_values(q)
    values = {j.name: qm[..., i] for i, j in enumerate(cell.robot.joints) if not j.passive}
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


def with_mimics(model, values):
    """``values`` completed by the values of the mimic joints, from their parsed ``<mimic>``."""
    out = dict(values)
    for j in model.joints:
        if j.mimic is not None:
            out[j.name] = (1.0 if j.mimic.multiplier is None else j.mimic.multiplier) \
                * values[j.mimic.joint] + (j.mimic.offset or 0.0)
    return out


def parsed_fk(model, link, values):
    """Pose of ``link`` in the root by the URDF definition, from urdf-parser-py's joints (mimic
    joints from their ``<mimic>`` element)."""
    by_child = {j.child: j for j in model.joints}
    values = with_mimics(model, values)
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
    parsed = URDF.from_xml_string(path.read_bytes())
    child_joint = {j.child: j.name for j in parsed.joints}
    q, e, th = random_values(cell, np.random.default_rng(2), n=5)
    values = with_mimics(parsed, urdf_joint_values(cell, q, e, th))  # the toolbox ignores <mimic>
    for i in range(len(q)):
        qv = np.zeros(robot.n)
        for link in robot.links:
            if link.isjoint:
                qv[link.jindex] = values[child_joint[link.name]][i]
        for target, pose in targets(cell):
            got = np.array(robot.fkine(qv, end=target).A)
            assert_same(got, pose(q[i], e[i], th[i]))


def pinocchio_q(model, values):
    """Pinocchio's configuration vector of URDF joint values (a continuous joint as cos, sin;
    mimic joints are computed by pinocchio)."""
    import pinocchio as pin

    qv = pin.neutral(model)
    for jid in range(1, model.njoints):
        joint = model.joints[jid]
        if joint.shortname() == "JointModelMimic":
            continue
        v = values[model.names[jid]]
        qv[joint.idx_q:joint.idx_q + joint.nq] = [math.cos(v), math.sin(v)] if joint.nq == 2 else v
    return qv


@pytest.mark.parametrize("kind", CELLS)
def test_pinocchio_loads_it_with_its_mimic_joints_and_its_fk_equals_the_cells(kind):
    import pinocchio as pin

    cell = CELLS[kind]()
    model = pin.buildModelFromXML(export_cell(cell, "urdf"), mimic=True)
    data = model.createData()
    q, e, th = random_values(cell, np.random.default_rng(3), n=10)
    values = urdf_joint_values(cell, q, e, th)
    for i in range(len(q)):
        pin.framesForwardKinematics(model, data, pinocchio_q(model, {k: v[i] for k, v in values.items()}))
        for link, pose in targets(cell):
            assert_same(data.oMf[model.getFrameId(link)].homogeneous, pose(q[i], e[i], th[i]))


def test_pinocchio_places_the_m20ia_as_robotcell_with_j3_plus_j2():
    # controller (0, 30, 0, 0, 0, 0) deg: the flange at (1480.0, 0, 934.2) mm in robotcell; the
    # URDF's J3 takes J3 + J2 = 30 deg (fed the controller's 0, the flange ends 500 mm lower).
    import pinocchio as pin

    cell = coupled_cell("fanuc_m20ia")
    cell.T_world_R = np.eye(4)
    q = np.radians([0, 30, 0, 0, 0, 0])
    want = cell.fk(q, tool=np.eye(4))
    assert np.allclose(want[:3, 3] * 1e3, [1480.0, 0, 934.2], atol=0.05)
    model = pin.buildModelFromXML(export_cell(cell, "urdf"), mimic=True)
    data = model.createData()
    values = dict(zip([f"J{i}" for i in range(1, 7)], q))
    values["J3"] = q[2] + q[1]
    pin.framesForwardKinematics(model, data, pinocchio_q(model, values))
    assert_same(data.oMf[model.getFrameId("flange")].homogeneous, want)


@pytest.mark.parametrize("kind, lines", [
    ("fanuc_m20ia", ["J3 = J3 + J2 of the controller"]),
    ("fanuc_lrmate200id", ["J3 = J3 + J2 of the controller"]),
    ("abb_irb2400", ["J3 = J3 - J2 of the controller"]),
    ("abb_irb460", ["A3 = A3 - A2 of the controller",
                    ("P is passive: P = -A3 of the controller = -A2 - A3 of this file "
                     "(mimic joints P, P_2)")]),
])
def test_the_file_states_the_joint_mapping_and_the_passive_joint_mimics(kind, lines):
    from urdf_parser_py.urdf import URDF

    text = export_cell(COUPLED[kind](), "urdf")
    comments = [c.strip() for c in re.findall(r"<!--(.*?)-->", text)]
    assert any(c.startswith("Joint values of the arm: its model's joint values") for c in comments)
    assert [c for c in comments if not c.startswith("Joint values")] == lines
    mimic = {j.name: j.mimic for j in URDF.from_xml_string(text.encode()).joints if j.mimic}
    if kind == "abb_irb460":
        assert {k: (m.joint, m.multiplier) for k, m in mimic.items()} == {"P": ("A2", -1.0),
                                                                          "P_2": ("A3", -1.0)}
    else:
        assert not mimic


@pytest.mark.parametrize("kind", COUPLED)
def test_coupled_joint_limits_hold_every_value_the_controller_reaches(kind):
    # A URDF limit bounds the joint's own value: for J3 + J2 it is the range over the controller's
    # limits of J2 and J3 (the controller's box is stricter and not expressible in URDF).
    from urdf_parser_py.urdf import URDF

    cell = COUPLED[kind]()
    model = URDF.from_xml_string(export_cell(cell, "urdf").encode())
    lo, hi = cell.robot.lower, cell.robot.upper
    corners = np.array(np.meshgrid(*zip(lo, hi))).reshape(len(lo), -1).T
    q = np.vstack([corners, random_values(cell, np.random.default_rng(4), n=200)[0]])
    values = with_mimics(model, urdf_joint_values(cell, q, np.zeros(len(q)), np.zeros(len(q))))
    for j in model.joints:
        if j.child.startswith("link_") and j.limit is not None:  # the arm's joints
            v = values[j.name]
            assert np.all((v >= j.limit.lower - 1e-12) & (v <= j.limit.upper + 1e-12)), j.name
            assert np.isclose(v.min(), j.limit.lower) and np.isclose(v.max(), j.limit.upper)


def test_passive_joints_of_a_coupling_that_mimic_cannot_hold_are_refused():
    # The joints with a motor move together (rows 1 and 2 of C equal); the passive one alone
    # holds the second axis: no URDF joint could be the independent one.
    joints = (Joint("revolute", a=0.3, name="A1"), Joint("revolute", a=0.2, name="A2"),
              Joint("revolute", a=0.1, name="P", passive=True))
    robot = Robot(name="odd", joints=joints, coupling=Coupling([[1, 0], [1, 0], [0, 1]]))
    with pytest.raises(InputError, match="odd: the coupling of the joints with a motor is not "
                                         "invertible, so the passive joints cannot be written"):
        export_cell(Cell(robot=robot, robot_model="odd", name="odd"), "urdf")


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
