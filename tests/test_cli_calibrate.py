"""``robotcell calibrate tcp|frame|external-tcp`` through the CLI entry point."""

import json

import numpy as np
from cli_helpers import run
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from robotcell import load_robot, pose_from_vendor, pose_to_vendor
from robotcell.kinematics.transforms import transform_points

T_TRUE = pose_from_vendor([1100, -250, 420, 35, 4, -2], "kuka")




def write(path, header, rows):
    lines = [",".join(header)] + [",".join(str(v) for v in r) for r in rows]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def test_frame_3point_json_and_report(tmp_path, capsys):
    rng = np.random.default_rng(50)
    local = np.array([[0, 0, 0], [0.4, 0, 0], [0.1, 0.3, 0]] * 2)
    p = transform_points(T_TRUE, local) * 1e3 + rng.normal(scale=0.05, size=(6, 3))
    roles = ["origin", "x", "xy"] * 2
    f = write(tmp_path / "m.csv", ["point", "x", "y", "z"],
              [[r, *np.round(v, 4)] for r, v in zip(roles, p)])
    code, out, _ = run(capsys, "calibrate", "frame", f, "--json")
    assert code == 0
    j = json.loads(out)
    np.testing.assert_allclose(np.array(j["matrix"])[:3, 3], T_TRUE[:3, 3] * 1e3, atol=0.3)
    np.testing.assert_allclose(j["xyzabc"][3:], [35, 4, -2], atol=0.1)
    for key in ("residuals_mm", "rms_mm", "max_mm", "warnings", "condition", "undetermined",
                "next_step", "sigma"):
        assert key in j
    assert len(j["residuals_mm"]) == 6 and j["labels"][0] == "line 2 (origin)"
    code, out, _ = run(capsys, "calibrate", "frame", f, "--sigma", "0.05")
    assert code == 0 and "as given (--sigma)" in out and "next step:" in out


def test_frame_npoint_from_joint_values_through_robot_model(tmp_path, capsys):
    robot = load_robot("kuka_kr16")
    tool_text = "10,0,150,0,90,0"
    tool = pose_from_vendor([10, 0, 150, 0, 90, 0], "kuka")
    rng = np.random.default_rng(51)
    q = np.radians(rng.uniform([-40, -100, 60, -30, -40, -50], [40, -60, 100, 30, 40, 50], size=(5, 6)))
    p = robot.fk(q, tool)[:, :3, 3]
    nominal = transform_points(np.linalg.inv(T_TRUE), p)
    f = write(tmp_path / "j.csv", ["a1", "a2", "a3", "a4", "a5", "a6", "nominal_x", "nominal_y",
                                   "nominal_z"],
              np.column_stack([np.degrees(q), nominal * 1e3]).round(9))
    code, out, _ = run(capsys, "calibrate", "frame", f, "--robot", "kuka_kr16", "--tool", tool_text,
                       "--json")
    assert code == 0
    j = json.loads(out)
    np.testing.assert_allclose(j["xyzabc"], pose_to_vendor(T_TRUE, "kuka"), atol=1e-4)
    assert j["procedure"] == "frame-npoint" and j["max_mm"] < 1e-4
    code, _, err = run(capsys, "calibrate", "frame", f, "--tool", tool_text)
    assert code == 2 and "--tool is only used with joint values and --robot" in err


def ik(robot, target, q0):
    """Joint values putting the flange on ``target`` (numerical, for building test data)."""
    def r(q):
        T = robot.fk(q, np.eye(4))
        rot = Rotation.from_matrix(T[:3, :3] @ target[:3, :3].T).as_rotvec()
        return np.concatenate([T[:3, 3] - target[:3, 3], rot])
    sol = least_squares(r, q0, xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.max(np.abs(sol.fun)) < 1e-8
    return sol.x


def test_tcp_from_joint_values_and_from_flange_poses(tmp_path, capsys):
    robot = load_robot("kuka_kr16")
    tcp = np.array([0.2, 0.01, -0.02])  # KUKA tools point along flange +X
    pivot = np.array([1.2, 0.1, 0.5])
    rng = np.random.default_rng(52)
    down = Rotation.from_euler("y", 90, degrees=True)  # flange X pointing down
    q0 = np.radians([0, -80, 100, 0, 60, 0])
    rows, poses = [], []
    for _ in range(5):
        R = (Rotation.from_rotvec(rng.normal(size=3) * 0.4) * down).as_matrix()
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R, pivot - R @ tcp
        rows.append(np.degrees(ik(robot, T, q0)))
        poses.append(T)
    f = write(tmp_path / "tcp.csv", ["a1", "a2", "a3", "a4", "a5", "a6"], np.round(rows, 9))
    code, out, _ = run(capsys, "calibrate", "tcp", f, "--robot", "kuka_kr16", "--json")
    assert code == 0
    j = json.loads(out)
    np.testing.assert_allclose(j["tcp_mm"], tcp * 1e3, atol=1e-3)
    np.testing.assert_allclose(j["pivot_mm"], pivot * 1e3, atol=1e-3)
    assert j["undetermined"] and j["procedure"] == "tcp"
    # the same touches as KUKA flange poses, plus ABC 2-point rows
    R_tool = Rotation.from_euler("y", 10, degrees=True).as_matrix()
    extra = []
    for role, local in (("-x", [-0.1, 0, 0]), ("xy", [0.03, 0.08, 0])):
        R = (Rotation.from_rotvec(rng.normal(size=3) * 0.3) * down).as_matrix()
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R, pivot - R @ (tcp + R_tool @ local)
        extra.append((role, T))
    table = [["tcp", *pose_to_vendor(T, "kuka").round(6)] for T in poses]
    table += [[role, *pose_to_vendor(T, "kuka").round(6)] for role, T in extra]
    f = write(tmp_path / "flange.csv", ["point", "x", "y", "z", "a", "b", "c"], table)
    code, out, _ = run(capsys, "calibrate", "tcp", f)
    assert code == 0 and "T_F_TCP (KUKA X,Y,Z mm, A,B,C deg): 200.000, 10.000, -20.000, 0.000, 10.000, 0.000" in out
    code, _, err = run(capsys, "calibrate", "tcp", f, "--tool", "0,0,0,0,0,0")
    assert code == 2 and "not used by 'calibrate tcp'" in err


def test_refused_input_exits_2_with_reason(tmp_path, capsys):
    f = write(tmp_path / "m.csv", ["point", "x", "y", "z"],
              [["origin", 1.0, 0.2, 0.3], ["x", 1.4, 0.2, 0.3], ["xy", 1.1, 0.5, 0.3]])
    code, out, err = run(capsys, "calibrate", "frame", f)
    assert code == 2 and out == "" and "must be in millimetres" in err
    f = write(tmp_path / "c.csv", ["point", "x", "y", "z"],
              [["origin", 1000, 200, 300], ["x", 1400, 200, 300], ["xy", 1200, 200.1, 300]])
    code, out, _ = run(capsys, "calibrate", "frame", f)
    assert code == 0 and "nearly collinear" in out  # determined, if poorly: the verdict says so
    f = write(tmp_path / "r.csv", ["x", "y", "z", "a", "b", "c"],
              [[1000, 0, 500, 0, 90, 0], [1000, 0, 500, 0, 90, 0], [900, 0, 500, 0, 60, 0]])
    code, _, err = run(capsys, "calibrate", "tcp", f)
    assert code == 2 and "line 2, line 3 are identical; each is used" in err
    assert "orientations of the touches are too similar" in err
    f = write(tmp_path / "n.csv", ["x", "y", "z"], [[1000, 0, 500], [1000, 1, 500]])
    code, _, err = run(capsys, "calibrate", "frame", f)
    assert code == 2 and "missing column 'point'" in err
    code, _, err = run(capsys, "calibrate", "frame", f, "--sigma", "-1")
    assert code == 2 and "--sigma must be a positive" in err


def test_external_tcp_command(tmp_path, capsys):
    rng = np.random.default_rng(53)
    local = np.array([[0, 0, 0]] * 4 + [[0.08, 0, 0], [0.03, 0.07, 0]])
    p = transform_points(T_TRUE, local) * 1e3 + rng.normal(scale=0.02, size=(6, 3))
    f = write(tmp_path / "e.csv", ["point", "x", "y", "z"],
              [[r, *np.round(v, 4)] for r, v in zip(["tcp"] * 4 + ["x", "xy"], p)])
    code, out, _ = run(capsys, "calibrate", "external-tcp", f, "--json")
    assert code == 0
    j = json.loads(out)
    np.testing.assert_allclose(j["tcp_mm"], T_TRUE[:3, 3] * 1e3, atol=0.1)
    np.testing.assert_allclose(j["xyzabc"][3:], [35, 4, -2], atol=0.2)
