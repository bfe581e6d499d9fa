"""``robotcell calibrate ... --cell CELL.yaml``: results written into the cell file.

Touches are simulated from a known cell (the example cell, a KR 16 on a track beside a
turntable) with small seeded noise, written as CSV in mm/deg, calibrated through the CLI, and the
reloaded cell is compared with the truth within a few of the reported 1-sigma.
"""

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from scipy.spatial.transform import Rotation

from robotcell.cell import Cell, Track, Turntable
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor
from robotcell.kinematics.transforms import invert, make_pose, rot_z
from robotcell.robot.models import load_robot

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "cell_kr16_track_turntable.yaml"
NOISE = 5e-5  # m per coordinate, a good touch-up
K = 4.5  # allowed error in reported 1-sigma


def example_cell(tmp_path):
    path = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLE, path)
    return path


def plain_cell(tmp_path, **kwargs):
    """A cell file with the KR 16 and whatever ``kwargs`` add (track, turntable, tools)."""
    path = tmp_path / "plain.yaml"
    Cell(robot=load_robot("kuka_kr16"), robot_model="kuka_kr16", **kwargs).save(path)
    return path


def write(path, header, rows):
    text = [",".join(header)]
    text += [",".join(v if isinstance(v, str) else f"{v:.6f}" for v in r) for r in rows]
    path.write_text("\n".join(text) + "\n")
    return path


def joints_deg(cell, T_R_TCP, tool):
    """Joint values (deg) of a valid IK branch placing ``tool`` at ``T_R_TCP``."""
    sol = cell.robot.ik(T_R_TCP, tool=tool)
    k = np.flatnonzero(sol.valid)
    assert k.size, "test pose out of the robot's reach"
    return np.degrees(sol.q[k[0]])


def in_base(T_world_R, p_world):
    """World points (N, 3) in the robot base at each touch's pose (N, 4, 4)."""
    T = invert(T_world_R)
    return np.einsum("nij,nj->ni", T[:, :3, :3], p_world) + T[:, :3, 3]


def assert_pose_within(T, truth, sigma_pos_mm, sigma_rot_deg):
    d_pos = np.abs(T[:3, 3] - truth[:3, 3]) * 1e3
    d_rot = np.abs(np.degrees(Rotation.from_matrix(truth[:3, :3] @ T[:3, :3].T).as_rotvec()))
    assert np.all(d_pos <= K * np.asarray(sigma_pos_mm) + 1e-6), (d_pos, sigma_pos_mm)
    assert np.all(d_rot <= K * np.asarray(sigma_rot_deg) + 1e-7), (d_rot, sigma_rot_deg)


def assert_updated(err, path, what, source, rms_mm, item):
    assert f"updated {path}: {what} (previous version: {path}." in err and ".bak)" in err
    assert item.provenance.source == source
    assert item.provenance.rms_mm == pytest.approx(rms_mm)
    assert item.provenance.time is not None


# -- tcp ------------------------------------------------------------------------------------------
def tcp_touches(rng, tcp, pivot, n=6):
    """Flange poses touching ``pivot`` with TCP ``tcp`` (in the flange), varied orientations."""
    down = Rotation.from_euler("y", 90, degrees=True)  # flange X (tool direction) pointing down
    poses = []
    for _ in range(n):
        R = (Rotation.from_rotvec(rng.normal(size=3) * 0.35) * down).as_matrix()
        touched = pivot + rng.normal(0.0, NOISE, 3)
        poses.append(make_pose(R, touched - R @ tcp))
    return np.array(poses)


def test_tcp_from_joint_values_keeps_the_tool_orientation_and_a_bak(tmp_path, capsys):
    path = example_cell(tmp_path)
    before = path.read_text()
    cell = Cell.load(path)
    rng = np.random.default_rng(10)
    tcp = np.array([0.3131, -0.0008, 0.0957])  # the torch, slightly off its file value
    T = tcp_touches(rng, tcp, np.array([1.2, 0.1, 0.5]))
    rows = [joints_deg(cell, Ti, np.eye(4)) for Ti in T]
    csv = write(tmp_path / "tcp.csv", [f"a{i}" for i in range(1, 7)], rows)
    code, out, err = run(capsys, "calibrate", "tcp", csv, "--cell", path, "--name", "torch",
                         "--json")
    assert code == 0, err
    j = json.loads(out)  # stdout is exactly one JSON object
    after = Cell.load(path)
    torch = after.tools["torch"]
    d = np.abs(torch.T_F_TCP[:3, 3] - tcp) * 1e3
    assert np.all(d <= K * np.array(j["sigma"]["tcp_mm"])), (d, j["sigma"]["tcp_mm"])
    np.testing.assert_allclose(torch.T_F_TCP[:3, :3], cell.tools["torch"].T_F_TCP[:3, :3],
                               atol=1e-12)
    assert "kept the orientation of tool 'torch'" in err and "A,B,C = 0.000, 45.000, 0.000" in err
    assert torch.number == 1 and torch.mass == pytest.approx(3.2)
    assert torch.provenance.note == "6 touches from tcp.csv"
    assert_updated(err, path, "tool 'torch'", "tcp", j["rms_mm"], torch)
    assert (tmp_path / "cell.yaml.1.bak").read_text() == before
    assert after.tools["pointer"].T_F_TCP == pytest.approx(cell.tools["pointer"].T_F_TCP)


def test_tcp_with_abc_2point_writes_a_new_tool_with_its_orientation(tmp_path, capsys):
    path = example_cell(tmp_path)
    rng = np.random.default_rng(11)
    truth = pose_from_vendor([180.0, 12.0, -25.0, 5.0, 12.0, -3.0], "kuka")
    tcp, R_tool = truth[:3, 3], truth[:3, :3]
    pivot = np.array([1.1, -0.2, 0.45])
    rows = [["tcp", *pose_to_vendor(T, "kuka")] for T in tcp_touches(rng, tcp, pivot)]
    down = Rotation.from_euler("y", 90, degrees=True)
    for role, local in (("-x", [-0.1, 0, 0]), ("xy", [0.03, 0.08, 0]), ("-x", [-0.15, 0, 0])):
        R = (Rotation.from_rotvec(rng.normal(size=3) * 0.3) * down).as_matrix()
        touched = pivot + rng.normal(0.0, NOISE, 3)
        rows.append([role, *pose_to_vendor(make_pose(R, touched - R @ (tcp + R_tool @ local)),
                                           "kuka")])
    csv = write(tmp_path / "flange.csv", ["point", "x", "y", "z", "a", "b", "c"], rows)
    code, out, err = run(capsys, "calibrate", "tcp", csv, "--cell", path, "--name", "gripper")
    assert code == 0, err
    assert "calibration: tcp" in out and "orientation" not in err
    gripper = Cell.load(path).tools["gripper"]
    r = json.loads(run(capsys, "calibrate", "tcp", csv, "--json")[1])
    assert_pose_within(gripper.T_F_TCP, truth, r["sigma"]["T_F_TCP_position_mm"],
                       r["sigma"]["T_F_TCP_rotation_deg"])
    assert_updated(err, path, "tool 'gripper'", "tcp", r["rms_mm"], gripper)


def test_tcp_for_a_new_tool_without_orientation_takes_the_flanges_and_says_so(tmp_path, capsys):
    path = example_cell(tmp_path)
    rng = np.random.default_rng(12)
    T = tcp_touches(rng, np.array([0.2, 0.0, 0.05]), np.array([1.0, 0.3, 0.4]))
    csv = write(tmp_path / "t.csv", ["x", "y", "z", "a", "b", "c"],
                [pose_to_vendor(Ti, "kuka") for Ti in T])
    code, _, err = run(capsys, "calibrate", "tcp", csv, "--cell", path, "--name", "probe")
    assert code == 0, err
    assert "has no tool 'probe' yet: its orientation is the flange's" in err
    np.testing.assert_allclose(Cell.load(path).tools["probe"].T_F_TCP[:3, :3], np.eye(3))


def test_tcp_touches_at_several_track_positions_are_mapped_to_the_world(tmp_path, capsys):
    path = example_cell(tmp_path)
    cell = Cell.load(path)
    rng = np.random.default_rng(13)
    tcp = np.array([0.25, 0.01, -0.03])
    T_world_F = tcp_touches(rng, tcp, np.array([2.2, 0.9, 0.6]))  # the pivot is fixed in the world
    tracks = np.array([1200.0, 1500.0, 1800.0, 2100.0, 2400.0, 2700.0])
    T_R_F = invert(cell.frame_pose("robot", track=tracks * 1e-3)) @ T_world_F
    csv = write(tmp_path / "t.csv", ["x", "y", "z", "a", "b", "c", "track"],
                [[*pose_to_vendor(T, "kuka"), e] for T, e in zip(T_R_F, tracks)])
    code, out, err = run(capsys, "calibrate", "tcp", csv, "--cell", path, "--name", "torch",
                         "--json")
    assert code == 0, err
    j = json.loads(out)
    assert "mapped to the world through column 'track'" in err
    np.testing.assert_allclose(j["pivot_mm"], [2200, 900, 600],
                               atol=K * max(j["sigma"]["pivot_mm"]))
    d = np.abs(Cell.load(path).tools["torch"].T_F_TCP[:3, 3] - tcp) * 1e3
    assert np.all(d <= K * np.array(j["sigma"]["tcp_mm"]))


# -- frame ----------------------------------------------------------------------------------------
T_WORLD_FIXTURE = pose_from_vendor([2100.0, -1150.0, 480.0, 25.0, 1.5, -2.0], "kuka")


def frame_touches(rng, cell, tracks):
    """3-point touches of T_WORLD_FIXTURE (twice each) with the torch, at track positions (mm)."""
    local = np.array([[0, 0, 0], [0.3, 0, 0], [0.05, 0.25, 0]] * 2)
    roles = ["origin", "x", "xy"] * 2
    p_world = (local @ T_WORLD_FIXTURE[:3, :3].T + T_WORLD_FIXTURE[:3, 3]
               + rng.normal(0.0, NOISE, local.shape))
    T_world_R = cell.frame_pose("robot", track=np.asarray(tracks) * 1e-3)
    p_R = in_base(T_world_R, p_world)
    down = Rotation.from_euler("y", 180, degrees=True)
    rows = []
    for role, p, e in zip(roles, p_R, tracks):
        R = (Rotation.from_rotvec(rng.normal(size=3) * 0.2) * down).as_matrix()
        rows.append([role, *joints_deg(cell, make_pose(R, p), cell.tools["torch"].T_F_TCP), e])
    return rows


def test_frame_in_the_world_of_a_track_cell_maps_each_touch_through_its_track_position(
        tmp_path, capsys):
    path = example_cell(tmp_path)
    cell = Cell.load(path)
    rng = np.random.default_rng(20)
    tracks = [1600.0, 1900.0, 2300.0, 2700.0, 1750.0, 2450.0]  # the robot moves between touches
    rows = frame_touches(rng, cell, tracks)
    csv = write(tmp_path / "frame.csv", ["point", *[f"a{i}" for i in range(1, 7)], "track"], rows)
    code, out, err = run(capsys, "calibrate", "frame", csv, "--cell", path, "--name", "fixture",
                         "--tool", "torch", "--json")
    assert code == 0, err
    j = json.loads(out)
    assert "T_world_fixture_position_mm" in j["sigma"] and "T_R_W" not in json.dumps(j)
    fixture = Cell.load(path).frames["fixture"]
    assert fixture.parent == "world" and fixture.number == 1
    assert_pose_within(fixture.pose, T_WORLD_FIXTURE, j["sigma"]["T_world_fixture_position_mm"],
                       j["sigma"]["T_world_fixture_rotation_deg"])
    np.testing.assert_allclose(np.array(j["matrix"])[:3, 3], fixture.pose[:3, 3] * 1e3, atol=1e-6)
    assert_updated(err, path, "frame 'fixture' (parent world)", "frame", j["rms_mm"], fixture)
    # without --cell nothing says where the track is: the column is refused
    code, _, err = run(capsys, "calibrate", "frame", csv, "--robot", "kuka_kr16", "--tool",
                       ",".join(map(str, pose_to_vendor(cell.tools["torch"].T_F_TCP, "kuka"))))
    assert code == 2 and "column 'track' (track position of each touch) needs --cell" in err
    code, out, _ = run(capsys, "calibrate", "frame", csv, "--cell", path, "--name", "fixture",
                       "--tool", "torch")
    assert code == 0 and "T_world_fixture (KUKA X,Y,Z mm, A,B,C deg): 2100.0" in out


def test_frame_on_the_robot_stays_in_the_base_and_without_track_uses_the_robot_frame(
        tmp_path, capsys):
    T_world_R = pose_from_vendor([500.0, 200.0, 0.0, 90.0, 0.0, 0.0], "kuka")
    path = plain_cell(tmp_path, T_world_R=T_world_R)
    rng = np.random.default_rng(21)
    local = np.array([[0, 0, 0], [0.3, 0, 0], [0.05, 0.25, 0]] * 2)
    T_R_X = invert(T_world_R) @ T_WORLD_FIXTURE
    p_R = local @ T_R_X[:3, :3].T + T_R_X[:3, 3] + rng.normal(0.0, NOISE, local.shape)
    roles = ["origin", "x", "xy"] * 2
    csv = write(tmp_path / "f.csv", ["point", "x", "y", "z", "track"],
                [[r, *p * 1e3, 0.0] for r, p in zip(roles, p_R)])
    code, out, err = run(capsys, "calibrate", "frame", csv, "--cell", path, "--name", "jig",
                         "--json")
    assert code == 0, err
    j = json.loads(out)
    jig = Cell.load(path).frames["jig"]
    assert jig.parent == "world"
    assert_pose_within(jig.pose, T_WORLD_FIXTURE, j["sigma"]["T_world_jig_position_mm"],
                       j["sigma"]["T_world_jig_rotation_deg"])
    code, out, err = run(capsys, "calibrate", "frame", csv, "--cell", path, "--name", "jig",
                         "--parent", "robot", "--json")
    assert code == 0, err
    j = json.loads(out)
    jig = Cell.load(path).frames["jig"]
    assert jig.parent == "robot" and "T_R_W_position_mm" in j["sigma"]
    assert_pose_within(jig.pose, T_R_X, j["sigma"]["T_R_W_position_mm"],
                       j["sigma"]["T_R_W_rotation_deg"])
    assert "frame 'jig' (parent robot)" in err


# -- track ----------------------------------------------------------------------------------------
TRUE_T_L_R0 = make_pose(Rotation.from_rotvec([0.004, -0.003, 0.006]).as_matrix(),
                        [0.012, -0.008, 0.455])
TRUE_SCALE = 1.0004
REFS = np.array([[2000.0, 1000.0, 300.0], [2600.0, -900.0, 100.0]])


def track_touches(rng, T_L_R0, refs, n_per_ref=5):
    """x,y,z (mm in R), e1 (mm), point (1-based) rows touching ``refs`` (mm in L)."""
    rows = []
    for k, r in enumerate(refs):
        for e in np.linspace(1200.0, 3400.0, n_per_ref) + 37.0 * k:
            T_L_R = T_L_R0.copy()
            T_L_R[:3, 3] += e * 1e-3 * TRUE_SCALE * np.array([1.0, 0.0, 0.0])
            f = invert(T_L_R) @ np.append(r * 1e-3 + rng.normal(0.0, NOISE, 3), 1.0)
            rows.append([*f[:3] * 1e3, e, k + 1])
    return rows


def test_track_with_two_references_writes_robot_at_zero_and_scale(tmp_path, capsys):
    path = example_cell(tmp_path)
    rng = np.random.default_rng(30)
    csv = write(tmp_path / "track.csv", ["x", "y", "z", "e1", "point"],
                track_touches(rng, TRUE_T_L_R0, REFS))
    refs = [",".join(map(str, r)) for r in REFS]
    code, out, err = run(capsys, "calibrate", "track", csv, "--cell", path, "--reference", refs[0],
                         "--reference", refs[1], "--json")
    assert code == 0, err
    j = json.loads(out)
    assert j["axis"] == "x"  # the cell's
    track = Cell.load(path).track
    assert_pose_within(track.T_L_R0, TRUE_T_L_R0, j["sigma"]["T_L_R_position_mm"],
                       j["sigma"]["T_L_R_rotation_deg"])
    assert abs(track.scale - TRUE_SCALE) <= K * j["sigma"]["scale"]
    assert track.name == "KL1500" and track.upper == pytest.approx(6.0)
    assert track.provenance.note == "10 touches from track.csv"
    assert_updated(err, path, "track 'KL1500' (robot_at_zero, scale)", "track", j["rms_mm"],
                   track)


def test_track_with_one_reference_keeps_the_cells_carriage_offset(tmp_path, capsys):
    path = example_cell(tmp_path)
    offset = Cell.load(path).track.T_L_R0[:3, 3]
    truth = make_pose(TRUE_T_L_R0[:3, :3], offset)
    rng = np.random.default_rng(31)
    csv = write(tmp_path / "track.csv", ["x", "y", "z", "e1"],
                [r[:4] for r in track_touches(rng, truth, REFS[:1], 6)])
    code, out, err = run(capsys, "calibrate", "track", csv, "--cell", path, "--reference",
                         "2000,1000,300", "--json")
    assert code == 0, err
    j = json.loads(out)
    assert "kept the offset of" in err and "0.000, 0.000, 450.000 mm" in err
    track = Cell.load(path).track
    np.testing.assert_allclose(track.T_L_R0[:3, 3], offset, atol=1e-12)
    assert_pose_within(track.T_L_R0, truth, [1e-6] * 3, j["sigma"]["T_L_R_rotation_deg"])
    code, _, err = run(capsys, "calibrate", "track", csv, "--cell", path, "--roll", "zero")
    assert code == 0 and "kept the offset" in err
    np.testing.assert_allclose(Cell.load(path).track.T_L_R0[:3, 3], offset, atol=1e-12)


# -- turntable and workpiece ----------------------------------------------------------------------
TRUE_T_WORLD_B = pose_from_vendor([3004.0, 1597.0, 702.0, 89.7, 0.2, -0.1], "kuka")
TABLE_TRACK = [2000.0, 2500.0, 3000.0, 3500.0, 2200.0, 3300.0]


def table_touches(rng, cell, T_world_B, angles_deg, local, tracks):
    """x,y,z (mm in R) of points ``local`` (in B at angle 0) turned to ``angles_deg``."""
    th = np.radians(angles_deg)
    p_B = np.einsum("nij,nj->ni", rot_z(th), local)
    p_world = p_B @ T_world_B[:3, :3].T + T_world_B[:3, 3] + rng.normal(0.0, NOISE, p_B.shape)
    return in_base(cell.frame_pose("robot", track=np.asarray(tracks) * 1e-3), p_world) * 1e3


def turntable_csv(tmp_path, cell, seed=40):
    rng = np.random.default_rng(seed)
    angles = [0.0, 60.0, 130.0, 200.0, 270.0, 320.0]
    p = table_touches(rng, cell, TRUE_T_WORLD_B, angles, np.tile([0.35, 0.0, 0.0], (6, 1)),
                      TABLE_TRACK)
    return write(tmp_path / "table.csv", ["x", "y", "z", "e1", "track"],
                 [[*pi, a, e] for pi, a, e in zip(p, angles, TABLE_TRACK)])


def test_turntable_in_a_track_cell_is_calibrated_in_the_world(tmp_path, capsys):
    path = example_cell(tmp_path)
    cell = Cell.load(path)
    csv = turntable_csv(tmp_path, cell)
    code, out, err = run(capsys, "calibrate", "turntable", csv, "--cell", path, "--json")
    assert code == 0, err
    j = json.loads(out)
    assert not [k for k in (*j, *j["sigma"]) if k.startswith("T_R_B")]
    assert "T_R_B" not in j["next_step"] and "T_world_B_covariance_mm_rad" in j
    tt = Cell.load(path).turntable
    assert tt.parent == "world" and tt.name == "DKP_400_01"
    assert_pose_within(tt.T_parent_B, TRUE_T_WORLD_B, j["sigma"]["T_world_B_position_mm"],
                       j["sigma"]["T_world_B_rotation_deg"])
    assert_updated(err, path, "turntable 'DKP_400_01' (T_world_B)", "turntable", j["rms_mm"], tt)
    # its JSON serves the workpiece of the same cell, not touches without --cell
    (tmp_path / "tt.json").write_text(out)
    wp = workpiece_csv(tmp_path, Cell.load(path), TRUE_T_WORLD_B)
    code, out, err = run(capsys, "calibrate", "workpiece", wp, "--cell", path, "--name", "part",
                         "--turntable", tmp_path / "tt.json", "--json")
    assert code == 0, err
    assert json.loads(out)["turntable_included"] is True and "warning" not in err
    code, _, err = run(capsys, "calibrate", "workpiece", wp, "--turntable", tmp_path / "tt.json")
    assert code == 2 and "holds the turntable in the world (T_world_B" in err


def test_turntable_on_the_robot_stays_in_the_base(tmp_path, capsys):
    T_R_B = pose_from_vendor([1200.0, 300.0, -200.0, 40.0, 0.3, 0.1], "kuka")
    path = plain_cell(tmp_path, track=Track(axis="x"), turntable=Turntable(parent="robot"))
    rng = np.random.default_rng(41)
    angles = np.array([0.0, 70.0, 150.0, 220.0, 300.0])
    f = np.einsum("nij,j->ni", rot_z(np.radians(angles)), [0.3, 0.0, 0.0]) @ T_R_B[:3, :3].T
    f = (f + T_R_B[:3, 3] + rng.normal(0.0, NOISE, f.shape)) * 1e3
    csv = write(tmp_path / "t.csv", ["x", "y", "z", "e1"], [[*p, a] for p, a in zip(f, angles)])
    code, out, err = run(capsys, "calibrate", "turntable", csv, "--cell", path, "--json")
    assert code == 0, err
    j = json.loads(out)
    tt = Cell.load(path).turntable
    assert tt.parent == "robot" and "turntable 'turntable' (T_R_B)" in err
    assert_pose_within(tt.T_parent_B, T_R_B, j["sigma"]["T_R_B_position_mm"],
                       j["sigma"]["T_R_B_rotation_deg"])


TRUE_T_B_PART = pose_from_vendor([140.0, -70.0, 215.0, 17.0, 0.5, -0.4], "kuka")


def workpiece_csv(tmp_path, cell, T_world_B, seed=50):
    rng = np.random.default_rng(seed)
    roles = ["origin", "x", "xy"] * 2
    local = np.array([[0, 0, 0], [0.15, 0, 0], [0.04, 0.12, 0]] * 2)
    on_table = local @ TRUE_T_B_PART[:3, :3].T + TRUE_T_B_PART[:3, 3]  # in B at angle 0
    angles = [10.0, 100.0, 200.0, 250.0, 310.0, 35.0]
    tracks = [2600.0, 2900.0, 3100.0, 2700.0, 3300.0, 2500.0]
    p = table_touches(rng, cell, T_world_B, angles, on_table, tracks)
    return write(tmp_path / "wp.csv", ["point", "x", "y", "z", "e1", "track"],
                 [[r, *pi, a, e] for r, pi, a, e in zip(roles, p, angles, tracks)])


def test_workpiece_without_turntable_json_uses_the_cells_turntable(tmp_path, capsys):
    path = example_cell(tmp_path)
    cell = Cell.load(path)
    csv = workpiece_csv(tmp_path, cell, cell.turntable.T_parent_B)
    code, out, err = run(capsys, "calibrate", "workpiece", csv, "--cell", path, "--name", "part",
                         "--json")
    assert code == 0, err
    j = json.loads(out)
    # The example's turntable records no uncertainty: it is taken at the nominal accuracy.
    assert ("note: turntable is calibrated without a recorded uncertainty: its accuracy is "
            "taken as 1 mm and 0.5 deg per axis") in err
    assert j["turntable_included"] is True
    part = Cell.load(path).frames["part"]
    assert part.parent == "turntable" and part.number == 2
    assert_pose_within(part.pose, TRUE_T_B_PART, j["sigma"]["T_B_W_position_mm"],
                       j["sigma"]["T_B_W_rotation_deg"])
    assert_updated(err, path, "frame 'part' (parent turntable)", "workpiece", j["rms_mm"], part)
    code, _, err = run(capsys, "calibrate", "workpiece", csv)
    assert code == 2 and "pass --turntable TURNTABLE.json" in err and "or --cell" in err


def test_workpiece_warns_when_the_turntable_json_differs_from_the_cell(tmp_path, capsys):
    path = example_cell(tmp_path)
    cell = Cell.load(path)
    (tmp_path / "tt.json").write_text(run(capsys, "calibrate", "turntable",
                                          turntable_csv(tmp_path, cell), "--cell", path,
                                          "--json")[1])
    shutil.copy(EXAMPLE, path)  # the cell's turntable is the old one again
    csv = workpiece_csv(tmp_path, cell, TRUE_T_WORLD_B)
    code, _, err = run(capsys, "calibrate", "workpiece", csv, "--cell", path, "--name", "part",
                       "--turntable", tmp_path / "tt.json")
    assert code == 0 and "warning: the turntable of" in err and "differs from the one in" in err
    (tmp_path / "rtt.json").write_text(json.dumps({
        "procedure": "turntable", "matrix": np.eye(4).tolist(),
        "sigma": {"T_R_B_position_mm": [0] * 3}}))
    code, _, err = run(capsys, "calibrate", "workpiece", csv, "--cell", path, "--name", "part",
                       "--turntable", tmp_path / "rtt.json")
    assert code == 2 and "holds the turntable in the robot base" in err and "parent world" in err


# -- refusals -------------------------------------------------------------------------------------
def xyz_frame_csv(tmp_path, track=None):
    rows = [["origin", 1000, 200, 300], ["x", 1400, 200, 300], ["xy", 1100, 500, 300]]
    header = ["point", "x", "y", "z"]
    if track is not None:
        header.append("track")
        rows = [[*r, e] for r, e in zip(rows, track)]
    return write(tmp_path / "m.csv", header, rows)


@pytest.mark.parametrize("args, message", [
    (["frame", "--robot", "kuka_kr16", "--name", "f"], "--robot and --cell both give the robot"),
    (["frame"], r"--cell needs --name: the frame of .*cell\.yaml .*existing: fixture, part"),
    (["tcp"], r"--cell needs --name: the tool of .*existing: torch, pointer"),
    (["workpiece", "--turntable", "x.json"], "--cell needs --name"),
    (["frame", "--name", "f", "--tool", "welder"],
     r"--tool 'welder' is not a tool of .*cell\.yaml \(its tools: torch, pointer\)"),
    (["frame", "--name", "f"],
     r"missing column 'track' .* the robot of .*cell\.yaml is on a track"),
    (["frame", "--name", "part"], ("is carried by the turntable: calibrate it with 'robotcell "
                                  "calibrate workpiece'")),
    (["track"], ("do not measure the rotation of the robot base about the track axis.*"
                "--reference X,Y,Z.*--roll zero")),
    (["track", "--axis", "z", "--roll", "zero"], "--axis z differs from the track axis x"),
])
def test_cell_refusals_exit_2_and_leave_the_cell_alone(tmp_path, capsys, args, message):
    path = example_cell(tmp_path)
    before = path.read_text()
    csv = xyz_frame_csv(tmp_path)
    code, out, err = run(capsys, "calibrate", args[0], csv, "--cell", path, *args[1:])
    assert code == 2 and out == ""
    assert re.search(message, err), err
    assert path.read_text() == before and not list(tmp_path.glob("cell.yaml.*bak"))


def test_cells_without_track_or_turntable_are_refused(tmp_path, capsys):
    path = plain_cell(tmp_path)
    table = write(tmp_path / "t.csv", ["x", "y", "z", "e1"],
                  [[1000, 0, 300, 0], [900, 100, 300, 90], [800, 0, 300, 180]])
    code, _, err = run(capsys, "calibrate", "track", table, "--cell", path, "--roll", "zero")
    assert code == 2 and re.search(r"plain\.yaml has no track to calibrate", err)
    code, _, err = run(capsys, "calibrate", "turntable", table, "--cell", path)
    assert code == 2 and re.search(r"plain\.yaml has no turntable", err)
    code, _, err = run(capsys, "calibrate", "workpiece", table, "--cell", path, "--name", "w")
    assert code == 2 and "has no turntable" in err
    frame = xyz_frame_csv(tmp_path, track=[0.0, 250.0, 0.0])
    code, _, err = run(capsys, "calibrate", "frame", frame, "--cell", path, "--name", "f")
    assert code == 2 and re.search(r"column 'track' has non-zero values, but the cell "
                                   r".*plain\.yaml has no track", err)
    frame = xyz_frame_csv(tmp_path, track=[0.0, 0.0, 0.0])
    code, _, err = run(capsys, "calibrate", "frame", frame, "--cell", path, "--name", "f")
    assert code == 0 and "frame 'f' (parent world)" in err
    path = plain_cell(tmp_path, track=Track(axis="y"))
    code, _, err = run(capsys, "calibrate", "track", table, "--cell", path, "--roll", "zero")
    assert code == 2 and "moves along its y axis; the track calibration supports x and z" in err


def test_cell_options_and_the_track_column_without_cell_are_refused(tmp_path, capsys):
    csv = xyz_frame_csv(tmp_path, track=[0.0, 300.0, 600.0])
    code, _, err = run(capsys, "calibrate", "frame", csv)
    assert code == 2 and "column 'track' (track position of each touch) needs --cell" in err
    code, _, err = run(capsys, "calibrate", "external-tcp", csv)
    assert code == 2 and "is not used by 'calibrate external-tcp'" in err
    code, _, err = run(capsys, "calibrate", "frame", xyz_frame_csv(tmp_path), "--name", "f")
    assert code == 2 and "--name says which frame of a cell file to update; it needs --cell" in err
    code, _, err = run(capsys, "calibrate", "frame", xyz_frame_csv(tmp_path), "--parent", "robot")
    assert code == 2 and "--parent says what carries the frame in a cell file" in err
    code, _, err = run(capsys, "calibrate", "frame", xyz_frame_csv(tmp_path), "--robot",
                       "kuka_kr16", "--tool", "torch")
    assert code == 2 and "--tool 'torch' is not X,Y,Z,A,B,C (mm, deg); a tool name is " in err
    track = write(tmp_path / "tr.csv", ["x", "y", "z", "e1", "track"],
                  [[1000, 0, 300, 0, 0], [900, 0, 300, 100, 100], [800, 0, 300, 200, 200]])
    code, _, err = run(capsys, "calibrate", "track", track)
    assert code == 2 and "not used by 'calibrate track': its track positions are column e1" in err
    path = example_cell(tmp_path)
    csv = xyz_frame_csv(tmp_path, track=[0.0, 1.5, 3.0])
    code, _, err = run(capsys, "calibrate", "frame", csv, "--cell", path, "--name", "f")
    assert code == 2 and "every track (track position) value is below 5" in err
