"""Every printed 1-sigma says what it is relative to and what it holds, in the terminal, the
JSON (``sigma_relative_to``) and the HTML page, for every command that prints one."""

import json

import numpy as np
import pytest
from accuracy_helpers import CELL, kr16_truth, seam, tracker_csv, write_rows
from cli_helpers import run
from identification_helpers import configurations, measure, perturbed, truth_chain, write_csv
from scipy.spatial.transform import Rotation

from robotcell import load_robot, pose_from_vendor, pose_to_vendor, save_robot
from robotcell.calibration.sigmaparts import sigma_basis
from robotcell.calibration.workpiece import workpiece_pose
from robotcell.identification import identify, read_target_measurements
from robotcell.kinematics.transforms import make_pose, rot_z, transform_points

OWN_ONLY = "from its own touches only"
T_TRUE = pose_from_vendor([1100, -250, 420, 35, 4, -2], "kuka")
Q = Rotation.from_rotvec([0.01, -0.02, 0.03]).as_matrix()
T_R_B = make_pose(Rotation.from_rotvec([0.02, -0.01, 0.7]).as_matrix(), [1.2, 0.3, 0.4])


def write(path, header, rows):
    path.write_text(",".join(header) + "\n"
                    + "\n".join(",".join(str(v) for v in r) for r in rows) + "\n")
    return path


def calibrate(capsys, *args):
    """The terminal report and the JSON of ``robotcell calibrate ARGS``."""
    code, out, err = run(capsys, "calibrate", *args)
    assert code == 0, err
    code, text, err = run(capsys, "calibrate", *args, "--json")
    assert code == 0, err
    return out, json.loads(text)


def assert_own_only(data):
    """Every quantity with a 1-sigma has a frame and only an own part, equal to its total."""
    assert set(data["sigma_relative_to"]) == set(data["sigma_parts"])
    for key, parts in data["sigma_parts"].items():
        assert set(parts) - {"relative_to", "unit"} == {"own"}, key
        assert parts["relative_to"] == data["sigma_relative_to"][key]


def test_a_tcp_without_a_cell_says_its_sigma_is_relative_to_the_flange(tmp_path, capsys):
    rng = np.random.default_rng(3)
    rot = Rotation.from_rotvec(rng.normal(0.0, 0.4, (6, 3))).as_matrix()
    tcp, pivot = np.array([0.1, 0.02, 0.3]), np.array([1.1, 0.0, 0.3])
    rows = []
    for R in rot:
        p = pivot - R @ tcp + rng.normal(0.0, 5e-5, 3)
        rows.append([*np.round(p * 1e3, 4), *np.round(pose_to_vendor(make_pose(R, p), "kuka")[3:], 6)])
    path = write(tmp_path / "tcp.csv", list("xyzabc"), rows)
    out, data = calibrate(capsys, "tcp", path)
    assert "(1-sigma 0." in out and f"relative to the flange, {OWN_ONLY})" in out
    assert f"relative to the robot base, {OWN_ONLY})" in out  # the reference tip
    assert data["sigma_relative_to"] == {"tcp": "F", "pivot": "R"}
    assert_own_only(data)
    np.testing.assert_allclose(data["sigma_parts"]["tcp"]["own"]["sigma"], data["sigma"]["tcp_mm"])


def frame_csv(tmp_path, rng):
    local = np.array([[0, 0, 0], [0.4, 0, 0], [0.1, 0.3, 0]] * 3)
    p = transform_points(T_TRUE, local) * 1e3 + rng.normal(scale=0.05, size=(9, 3))
    return write(tmp_path / "frame.csv", ["point", "x", "y", "z"],
                 [[r, *np.round(v, 4)] for r, v in zip(["origin", "x", "xy"] * 3, p)])


def test_a_frame_and_an_external_tcp_say_their_sigma_is_relative_to_the_robot_base(
        tmp_path, capsys):
    rng = np.random.default_rng(5)
    out, data = calibrate(capsys, "frame", frame_csv(tmp_path, rng))
    assert f"the 1-sigma above is relative to the robot base, {OWN_ONLY}" in out
    assert data["sigma_relative_to"] == {"T_R_W": "R"}
    assert_own_only(data)
    local = np.array([[0, 0, 0]] * 4 + [[0.08, 0, 0], [0.03, 0.07, 0]])
    p = transform_points(T_TRUE, local) * 1e3 + rng.normal(scale=0.02, size=(6, 3))
    path = write(tmp_path / "e.csv", ["point", "x", "y", "z"],
                 [[r, *np.round(v, 4)] for r, v in zip(["tcp"] * 4 + ["x", "xy"], p)])
    out, data = calibrate(capsys, "external-tcp", path)
    assert f"the 1-sigma above is relative to the robot base, {OWN_ONLY}" in out
    assert data["sigma_relative_to"] == {"T_R_TCP": "R"}


def test_a_track_without_a_cell_gives_its_scale_its_own_part_only(tmp_path, capsys):
    rng = np.random.default_rng(0)
    e = np.linspace(0.0, 2.0, 6)
    f = (np.array([1.5, 0.8, 0.3]) - np.outer(e, [1.0, 0.0, 0.0])) @ Q
    f += rng.normal(0.0, 1e-4, f.shape)
    path = write(tmp_path / "track.csv", ["x", "y", "z", "e1"],
                 [[*np.round(p * 1e3, 4), round(v * 1e3, 3)] for p, v in zip(f, e)])
    out, data = calibrate(capsys, "track", path, "--reference", "1500,800,300")
    assert "scale: 1.0" in out and f"relative to the robot base, {OWN_ONLY})" in out
    assert f"the 1-sigma above is relative to the track frame L, {OWN_ONLY}" in out
    assert "its parts" not in out and "ASSUMED" not in out
    assert data["sigma_relative_to"] == {"direction": "R", "scale": "R", "T_L_R": "L"}
    assert_own_only(data)
    assert data["sigma_parts"]["scale"]["own"]["sigma"] == pytest.approx(data["sigma"]["scale"])
    out, data = calibrate(capsys, "track", path)  # no reference: direction, scale and point
    assert data["sigma_relative_to"] == {"direction": "R", "scale": "R", "point": "R"}
    assert_own_only(data)


def turntable_csv(tmp_path, rng):
    theta = np.radians([0.0, 60.0, 130.0, 200.0, 270.0, 320.0])
    f = (rot_z(theta) @ [0.35, 0.0, 0.0]) @ T_R_B[:3, :3].T + T_R_B[:3, 3]
    f += rng.normal(0.0, 1e-4, f.shape)
    return write(tmp_path / "table.csv", ["x", "y", "z", "e1"],
                 [[*np.round(p * 1e3, 4), round(float(np.degrees(t)), 4)]
                  for p, t in zip(f, theta)])


def test_a_turntable_without_a_cell_and_its_report_state_what_each_sigma_is(tmp_path, capsys):
    table = turntable_csv(tmp_path, np.random.default_rng(1))
    out, data = calibrate(capsys, "turntable", table)
    for key in ("radius (mm)", "tilt (deg)", "axis"):
        line = next(s for s in out.splitlines() if s.startswith(f"  {key}"))
        assert line.endswith(f"relative to the robot base, {OWN_ONLY})"), line
    assert data["sigma_relative_to"] == {"T_R_B": "R", "radius": "R", "axis": "R", "tilt": "R"}
    assert_own_only(data)
    parts = data["sigma_parts"]
    assert parts["radius"]["unit"] == "mm" and parts["tilt"]["unit"] == "deg"
    assert parts["radius"]["own"]["sigma"] == pytest.approx(data["sigma"]["radius_mm"])
    assert parts["tilt"]["own"]["sigma"] == pytest.approx(data["sigma"]["tilt_deg"])
    (tmp_path / "tt.json").write_text(json.dumps(data))
    code, _, err = run(capsys, "report", tmp_path / "tt.json", "-o", tmp_path / "tt.html")
    assert code == 0, err
    page = (tmp_path / "tt.html").read_text()
    assert f"radius: 1-sigma relative to the robot base, {OWN_ONLY}" in page
    assert f"T_R_B: 1-sigma relative to the robot base, {OWN_ONLY}" in page


def test_a_workpiece_on_a_given_turntable_names_the_turntable_frame_and_what_it_inherits(
        tmp_path, capsys):
    rng = np.random.default_rng(2)
    code, out, err = run(capsys, "calibrate", "turntable", turntable_csv(tmp_path, rng), "--json")
    assert code == 0, err
    (tmp_path / "tt.json").write_text(out)
    T_B_W = make_pose(Rotation.from_euler("zyx", [0.5, 0.02, -0.03]).as_matrix(),
                      [0.05, -0.08, 0.06])
    pts = np.array([[0.0, 0.0, 0.0], [0.15, 0.0, 0.0], [0.05, 0.12, 0.0]] * 2)
    angles = np.radians([10.0, 100.0, 200.0, 40.0, 160.0, 250.0])
    Tw = workpiece_pose(T_R_B, T_B_W, angles)
    fw = np.einsum("nij,nj->ni", Tw[:, :3, :3], pts) + Tw[:, :3, 3]
    fw += rng.normal(0.0, 1e-4, fw.shape)
    wp = write(tmp_path / "wp.csv", ["point", "x", "y", "z", "e1"],
               [[r, *np.round(p * 1e3, 4), round(float(np.degrees(a)), 4)]
                for r, p, a in zip(["origin", "x", "xy"] * 2, fw, angles)])
    out, data = calibrate(capsys, "workpiece", wp, "--turntable", tmp_path / "tt.json")
    assert "the 1-sigma above is relative to the turntable frame B, from its own touches" in out
    assert data["sigma_relative_to"] == {"T_B_W": "B"}


@pytest.fixture(scope="module")
def identified(tmp_path_factory):
    """A KR 16 identified from simulated tracker rows (its CSV, and the result)."""
    d = tmp_path_factory.mktemp("arm")
    rng = np.random.default_rng(24)
    truth = kr16_truth(rng)
    tracker_csv(d / "tracker.csv", truth, 40, rng)
    return d / "tracker.csv", identify(load_robot("kuka_kr16"),
                                       read_target_measurements(d / "tracker.csv"), sigma=2e-5)


def test_identify_says_its_predicted_error_is_relative_to_the_measuring_device(
        tmp_path, capsys):
    rng = np.random.default_rng(21)
    nominal = load_robot("kuka_kr16")
    ch, x = truth_chain(perturbed(nominal, rng), 2, False, rng)
    write_csv(tmp_path / "tracker.csv", measure(ch, x, configurations(nominal, 30, rng), rng,
                                                2e-5))
    args = ("identify", tmp_path / "tracker.csv", "--robot", "kuka_kr16", "--accuracy", "0.02",
            "--folds", "2")
    code, out, err = run(capsys, *args)
    assert code == 0, err
    basis = "relative to the measuring device's frame, from its own measurements only"
    line = next(s for s in out.splitlines() if s.startswith("predicted error of a target"))
    assert line.endswith(f"; {basis}") and f"parameters (1-sigma {basis}):" in out
    code, out, err = run(capsys, *args, "--json")
    data = json.loads(out)
    assert data["sigma_relative_to"] == "device"
    assert data["predicted_error"]["sigma_relative_to"] == "device"


def test_compensate_says_its_sigma_is_the_arms_part_relative_to_the_device(
        identified, tmp_path, capsys):
    _, res = identified
    save_robot(res.robot, tmp_path / "arm.yaml")
    (tmp_path / "cell.yaml").write_text(CELL.replace(
        "  model: kuka_kr16\n", "  model: kuka_kr16\n  identified: arm.yaml\n"))
    write_rows(tmp_path / "seam.csv", list("xyzabc"), seam(4))
    args = ("compensate", tmp_path / "seam.csv", "--cell", tmp_path / "cell.yaml", "--tool",
            "torch", "--frame", "part")
    code, out, err = run(capsys, *args, "-o", tmp_path / "cmd.csv", "--report",
                         tmp_path / "acc.html")
    assert code == 0, err
    basis = ("relative to the measuring device's frame, from the arm's identification only, "
             "not the tool's and frames' calibrations")
    assert f"mm ({basis})" in out + err
    assert basis in (tmp_path / "acc.html").read_text().replace("&#x27;", "'")
    code, out, err = run(capsys, *args, "--json")
    assert json.loads(out)["sigma_relative_to"] == "device"


def test_the_basis_of_a_sigma_names_each_inherited_part():
    assert sigma_basis("F") == f"relative to the flange, {OWN_ONLY}"
    assert sigma_basis("world", ["own", "recorded", "assumed"]) == (
        "relative to frame 'world', from its own touches and inherited errors (recorded, "
        "ASSUMED)")
    assert sigma_basis("fixture", ()) == ("relative to frame 'fixture', from its own touches "
                                          "and the errors it inherits")
