"""robotcell calibrate track | turntable | workpiece, in process through the CLI entry point."""

import json

import numpy as np
import pytest
from cli_helpers import run
from scipy.spatial.transform import Rotation

from robotcell.calibration.workpiece import workpiece_pose
from robotcell.kinematics.transforms import make_pose, rot_z

Q = Rotation.from_rotvec([0.01, -0.02, 0.03]).as_matrix()
REF = np.array([1.5, 0.8, 0.3])
E = np.linspace(0.0, 2.0, 6)
T_R_B = make_pose(Rotation.from_rotvec([0.02, -0.01, 0.7]).as_matrix(), [1.2, 0.3, 0.4])
T_B_W = make_pose(Rotation.from_euler("zyx", [0.5, 0.02, -0.03]).as_matrix(), [0.05, -0.08, 0.06])
THETA = np.radians([0.0, 60.0, 130.0, 200.0, 270.0, 320.0])




def write(path, header, rows):
    path.write_text(header + "\n" + "\n".join(",".join(f"{v:.6f}" if isinstance(v, float)
                                                          else str(v) for v in r) for r in rows))
    return path


def track_csv(tmp_path, rng=None):
    f = (REF - np.outer(E, [1.0, 0.0, 0.0])) @ Q
    if rng is not None:
        f = f + rng.normal(0.0, 1e-4, f.shape)
    return write(tmp_path / "track.csv", "x,y,z,e1",
                 [[*map(float, fi * 1e3), float(e * 1e3)] for fi, e in zip(f, E)])


def test_track_json_contract(tmp_path, capsys):
    path = track_csv(tmp_path, np.random.default_rng(0))
    code, out, _ = run(capsys, "calibrate", "track", path, "--json")
    assert code == 0
    j = json.loads(out)
    assert {"residuals_mm", "rms_mm", "max_mm", "warnings", "direction", "scale"} <= set(j)
    assert j["rotation"] is None and len(j["residuals_mm"]) == 6
    np.testing.assert_allclose(j["direction"], Q[0], atol=1e-4)
    code, out, _ = run(capsys, "calibrate", "track", path, "--json", "--reference", "1500,800,300")
    j = json.loads(out)
    np.testing.assert_allclose(np.array(j["rotation"]), Q, atol=1e-4)
    code, out, _ = run(capsys, "calibrate", "track", path, "--roll", "zero")
    assert code == 0 and "zero-roll convention" in out and "T_L_R" in out


def test_track_refusals_exit_2(tmp_path, capsys):
    path = track_csv(tmp_path)
    code, _, err = run(capsys, "calibrate", "track", path, "--reference", "1500,800,300",
                       "--reference", "2000,-600,100")
    assert code == 2 and "add a column 'point'" in err
    text = path.read_text().splitlines()
    short = write(tmp_path / "short.csv", text[0], [r.split(",") for r in text[1:3]])
    code, _, err = run(capsys, "calibrate", "track", short)
    assert code == 2 and "at least 3 needed" in err
    code, _, err = run(capsys, "calibrate", "track", path, "--reference", "1500,800")
    assert code == 2 and "--reference needs 3" in err


def test_turntable_then_workpiece(tmp_path, capsys):
    rng = np.random.default_rng(1)
    f = (rot_z(THETA) @ [0.35, 0.0, 0.0]) @ T_R_B[:3, :3].T + T_R_B[:3, 3]
    f += rng.normal(0.0, 1e-4, f.shape)
    table = write(tmp_path / "table.csv", "x,y,z,e1",
                  [[*map(float, fi * 1e3), float(np.degrees(t))] for fi, t in zip(f, THETA)])
    code, out, _ = run(capsys, "calibrate", "turntable", table, "--json")
    assert code == 0
    j = json.loads(out)
    assert j["radius_mm"] == pytest.approx(350.0, abs=0.5)
    np.testing.assert_allclose(np.array(j["matrix"])[:3, 3], T_R_B[:3, 3] * 1e3, atol=0.5)
    tt = tmp_path / "tt.json"
    tt.write_text(out)

    roles = ["origin", "x", "xy"]
    pts = np.array([[0.0, 0.0, 0.0], [0.15, 0.0, 0.0], [0.05, 0.12, 0.0]])
    angles = np.radians([10.0, 100.0, 200.0])
    Tw = workpiece_pose(T_R_B, T_B_W, angles)
    fw = np.einsum("nij,nj->ni", Tw[:, :3, :3], pts) + Tw[:, :3, 3]
    wp = write(tmp_path / "wp.csv", "point,x,y,z,e1",
               [[r, *map(float, p * 1e3), float(np.degrees(a))]
                for r, p, a in zip(roles, fw, angles)])
    code, out, _ = run(capsys, "calibrate", "workpiece", wp, "--turntable", tt, "--json")
    assert code == 0
    j = json.loads(out)
    np.testing.assert_allclose(np.array(j["matrix"])[:3, 3], T_B_W[:3, 3] * 1e3, atol=1.0)
    assert len(j["xyzabc"]) == 6 and j["turntable_included"] is True
    assert all(s > 0 for s in j["sigma"]["T_B_W_position_mm"])

    code, out, _ = run(capsys, "calibrate", "turntable", table, "--height", "-20")
    assert code == 0 and "radius (mm): 350" in out
    code, _, err = run(capsys, "calibrate", "workpiece", wp, "--turntable", table)
    assert code == 2 and "not valid JSON" in err
    tt.write_text(json.dumps({"procedure": "track"}))
    code, _, err = run(capsys, "calibrate", "workpiece", wp, "--turntable", tt)
    assert code == 2 and "not a turntable result" in err


def test_turntable_refuses_radians(tmp_path, capsys):
    f = (rot_z(THETA) @ [0.35, 0.0, 0.0]) @ T_R_B[:3, :3].T + T_R_B[:3, 3]
    table = write(tmp_path / "table.csv", "x,y,z,e1",
                  [[*map(float, fi * 1e3), float(t)] for fi, t in zip(f, THETA)])
    code, _, err = run(capsys, "calibrate", "turntable", table)
    assert code == 2 and "looks like radians" in err
