"""The calibration verdict (good / check / poor), the exit status 3 gate, and repeated data.

Poor results (the cases of a gross error a technician makes: a row in metres, a track position
in metres, a wrong flange angle, a typing error of 1e12, table angles in radians) must not reach
the cell file; repeated measurements (two track touches 4.2 mm apart, 61 positions 1 mm apart,
one table angle twice, identical rows) are data and give errors consistent with the reported
sigma.
"""

import json

import numpy as np
import pytest
from cli_helpers import run
from scipy.spatial.transform import Rotation

from robotcell import IllPosedError, InputError
from robotcell.calibration.frame import frame_3point, frame_npoint
from robotcell.calibration.measurements import external_axis
from robotcell.calibration.tcp import calibrate_tool
from robotcell.calibration.track import calibrate_track
from robotcell.calibration.turntable import calibrate_turntable
from robotcell.calibration.verdict import (
    DEFAULT_TOUCH_SIGMA_MM,
    touches_for_outlier_check,
    verdict,
)
from robotcell.cell import Cell, Tool, Track, Turntable
from robotcell.io.poseformats import pose_to_vendor
from robotcell.kinematics.transforms import make_pose, rot_z, transform_points
from robotcell.report import verdict as report_verdict
from robotcell.report import write_report
from robotcell.robot.models import load_robot

NOISE = 1e-4  # m per coordinate
TCP = np.array([0.01, -0.02, 0.2])
PIVOT = np.array([1.1, 0.2, 0.5])
T_R_B = make_pose(Rotation.from_rotvec([0.02, -0.01, 0.7]).as_matrix(), [1.2, 0.3, 0.4])
Q = Rotation.from_rotvec([0.01, -0.02, 0.03]).as_matrix()
REF = np.array([1.5, 0.8, 0.3])


def flange_poses(rng, n, noise=NOISE):
    """Flange poses touching PIVOT with TCP, orientations varied by about 30 degrees."""
    down = Rotation.from_euler("y", 90, degrees=True)
    R = (Rotation.from_rotvec(rng.normal(size=(n, 3)) * 0.5) * down).as_matrix()
    p = PIVOT + rng.normal(0.0, noise, (n, 3)) - R @ TCP
    return np.array([make_pose(Ri, pi) for Ri, pi in zip(R, p)])


def table_touches(rng, theta, radius=0.3, noise=NOISE):
    local = np.einsum("nij,j->ni", rot_z(theta), [radius, 0.0, 0.0])
    return transform_points(T_R_B, local) + rng.normal(0.0, noise, (len(theta), 3))


def track_touches(rng, e, noise=NOISE):
    return (REF - np.outer(e, [1.0, 0.0, 0.0])) @ Q + rng.normal(0.0, noise, (len(e), 3))


def write(path, header, rows):
    text = [",".join(header)]
    text += [",".join(v if isinstance(v, str) else repr(float(v)) for v in r) for r in rows]
    path.write_text("\n".join(text) + "\n")
    return path


# -- the rule ---------------------------------------------------------------------------------------
def test_one_rule_for_terminal_json_and_report(tmp_path):
    rng = np.random.default_rng(1)
    r = calibrate_tool(flange_poses(rng, 8))
    j = r.to_json()
    v = r.verdict
    assert v.level == "good" and j["verdict"] == v.to_json() == verdict(j).to_json()
    assert r.summary().splitlines()[-1] == v.line() == (
        f"verdict: GOOD: RMS {r.rms * 1e3:.3f} mm within the default touch accuracy 0.5 mm "
        f"(state yours with sigma), condition number {r.condition:.1f}, no warnings")
    assert f"condition number: {r.condition:.1f} (below 100" in r.summary()
    # The HTML report calls the same function: same level, same reasons, same condition number.
    assert report_verdict(j) == (v.level, v.reasons)
    page = write_report(j, tmp_path / "r.html")[0].read_text()
    assert f"condition number {r.condition:.1f}" in page


def test_chi_square_bound_against_stated_and_default_accuracy():
    rng = np.random.default_rng(2)
    T = flange_poses(rng, 10, noise=0.4e-3)  # a rough technician, within the 0.5 mm default
    assert calibrate_tool(T).verdict.level == "good"
    v = calibrate_tool(T, sigma=0.1e-3).verdict  # ... but not the 0.1 mm stated
    assert v.level == "check" and v.accuracy_source == "stated" and v.touch_sigma_mm == 0.1
    assert "larger than the stated touch accuracy 0.1 mm explains (chi-square" in v.reasons[0]
    assert v.chi2 > v.chi2_bound
    v = calibrate_tool(T, sigma=0.05e-3).verdict  # more than 3x the stated accuracy
    assert v.level == "poor" and "far beyond the stated touch accuracy 0.05 mm" in v.reasons[0]
    assert calibrate_tool(flange_poses(rng, 10, noise=3e-3)).verdict.level == "poor"
    assert DEFAULT_TOUCH_SIGMA_MM == 0.5


def test_scale_condition_and_size_rules():
    base = calibrate_tool(flange_poses(np.random.default_rng(3), 8)).to_json()
    assert verdict(base).level == "good"
    assert verdict({**base, "scale": 1.03}).level == "check"
    v = verdict({**base, "scale": 0.6995})
    assert v.level == "poor" and "track scale 0.6995 is more than 10% from 1" in v.reasons[0]
    assert verdict({**base, "condition": 500.0}).level == "check"
    v = verdict({**base, "condition": 5000.0})
    assert v.level == "poor" and v.reasons[0].startswith("condition number 5000.0 > 1000")
    v = verdict({**base, "radius_mm": 1.25e11})
    assert v.level == "poor" and "radius of 1.25e+11 mm is beyond any real cell (100 m)" in v.reasons[0]
    v = verdict({**base, "offset_mm": None})  # not determined: not a length to judge
    assert v.level == "good"


def test_no_redundancy_is_said_with_the_touches_that_would_check():
    # 4 touches of a TCP (6 unknowns): an outlier cannot be singled out; 5 touches can.
    assert touches_for_outlier_check(4, 6) == 5 and touches_for_outlier_check(5, 9) is None
    v = calibrate_tool(flange_poses(np.random.default_rng(4), 4)).verdict
    assert v.level == "check" and v.touches_needed == 5
    assert ("redundancy 6 is too little to single out a wrong touch; take 5 or more touches (4 "
            "given: 1 more touch)") in v.reasons
    theta = np.radians([0.0, 90.0, 180.0, 270.0])
    v = calibrate_turntable(theta, table_touches(np.random.default_rng(5), theta)).verdict
    assert v.touches_needed == 6
    assert ("redundancy 5 is too little to single out a wrong touch; take 6 or more touches (4 "
            "given: 2 more touches)") in v.reasons
    pts = transform_points(T_R_B, [[0, 0, 0], [0.3, 0, 0], [0.1, 0.2, 0]])
    v = frame_3point(pts, ["origin", "x", "xy"]).verdict
    assert v.level == "check" and v.reasons[-1].startswith(
        "no redundancy: 3 touches determine the result exactly, so nothing checks it")


def test_with_the_named_touch_count_an_outlier_is_caught():
    # The designs the verdict names: 6 table angles, 5 TCP touches. With the touch accuracy
    # stated, a 5 mm error in one touch is flagged (named as an outlier, or the result graded
    # poor) in nearly every trial.
    rng = np.random.default_rng(6)
    theta = np.radians(np.arange(6) * 60.0)
    seen = 0
    for _ in range(40):
        f = table_touches(rng, theta)
        f[rng.integers(6)] += rng.normal(size=3) / np.sqrt(3) * 5e-3
        r = calibrate_turntable(theta, f, sigma=NOISE)
        seen += any("outlier" in w for w in r.warnings) or r.verdict.level == "poor"
    assert seen >= 36
    seen = 0
    for _ in range(40):
        T = flange_poses(rng, 5)
        T[rng.integers(5), :3, 3] += rng.normal(size=3) / np.sqrt(3) * 5e-3
        r = calibrate_tool(T, sigma=NOISE)
        seen += any("outlier" in w for w in r.warnings) or r.verdict.level == "poor"
    assert seen >= 36


# -- poor results change no file (CLI) --------------------------------------------------------------
def plain_cell(tmp_path, **kwargs):
    path = tmp_path / "cell.yaml"
    tool = Tool(T_F_TCP=make_pose(np.eye(3), [0.0, 0.0, 0.15]))
    Cell(robot=load_robot("kuka_kr16"), robot_model="kuka_kr16", tools={"torch": tool},
         **kwargs).save(path)
    return path


def assert_poor_and_untouched(capsys, tmp_path, cell, args, reason):
    before = cell.read_bytes()
    code, out, err = run(capsys, *args, "--cell", cell)
    assert code == 3, err
    assert "verdict: POOR" in out and reason in out
    # Notes on the measurements (the x, y, z touches leave the tool's uncertainty out) come
    # first; the refusal is the last line.
    assert all(line.startswith("note: ") for line in err.splitlines()[:-1]), err
    last = err.splitlines()[-1]
    assert last.startswith("error: poor calibration, nothing written: ") and "--accept-poor" in last
    assert cell.read_bytes() == before and not list(tmp_path.glob("cell.yaml.*bak"))
    code, out, err = run(capsys, *args, "--cell", cell, "--json")
    assert code == 3 and json.loads(out)["verdict"]["level"] == "poor"
    assert cell.read_bytes() == before
    code, _, err = run(capsys, *args, "--cell", cell, "--accept-poor")
    assert code == 0 and "the verdict is poor; written anyway (--accept-poor)" in err
    assert cell.read_bytes() != before


def tcp_rows(rng, n=8):
    return [pose_to_vendor(T, "kuka") for T in flange_poses(rng, n)]


def test_tcp_row_in_metres_is_left_out_and_named(tmp_path, capsys):
    """One row in metres is a gross error the other touches single out: the tool is computed
    without it, the report and the verdict say so (CHECK), and the row is named."""
    rows = tcp_rows(np.random.default_rng(10))
    rows[3][:3] /= 1000.0
    csv = write(tmp_path / "tcp.csv", list("xyzabc"), rows)
    cell = plain_cell(tmp_path)
    code, out, err = run(capsys, "calibrate", "tcp", csv, "--name", "torch", "--cell", cell)
    assert code == 0, err
    assert "touch line 5 (tcp) is an outlier at 3 sigma" in out and "left out of this" in out
    assert "verdict: CHECK: touch(es) line 5 (tcp) left out as outlier(s): re-touch" in out
    without = tcp_rows(np.random.default_rng(10))
    del without[3]
    clean = write(tmp_path / "clean.csv", list("xyzabc"), without)
    code, out2, _ = run(capsys, "calibrate", "tcp", clean, "--json")
    tcp_mm = json.loads(out2)["tcp_mm"]
    np.testing.assert_allclose(Cell.load(cell).tools["torch"].T_F_TCP[:3, 3] * 1e3, tcp_mm,
                               atol=1e-6)


def test_flange_angle_off_by_1e12_degrees_is_poor(tmp_path, capsys):
    rows = tcp_rows(np.random.default_rng(11))
    rows[2][3] += 1e12  # two rows wrong: no one row to leave out
    rows[5][4] += 1e12
    csv = write(tmp_path / "tcp.csv", list("xyzabc"), rows)
    assert_poor_and_untouched(capsys, tmp_path, plain_cell(tmp_path),
                              ["calibrate", "tcp", csv, "--name", "torch"], "far beyond")


def test_track_position_in_metres_is_poor(tmp_path, capsys):
    rng = np.random.default_rng(12)
    e = np.linspace(0.0, 2.0, 6)
    f = track_touches(rng, e) * 1e3
    e_mm = e * 1e3
    e_mm[4] /= 1000.0  # one e1 in metres
    csv = write(tmp_path / "track.csv", ["x", "y", "z", "e1"], [[*p, v] for p, v in zip(f, e_mm)])
    cell = plain_cell(tmp_path, track=Track(axis="x"))
    assert_poor_and_untouched(capsys, tmp_path, cell,
                              ["calibrate", "track", csv, "--reference", "1500,800,300"],
                              "track scale")


def test_turntable_coordinate_of_1e12_is_poor(tmp_path, capsys):
    rng = np.random.default_rng(13)
    theta = np.radians([0.0, 60.0, 130.0, 200.0, 270.0, 320.0])
    f = table_touches(rng, theta) * 1e3
    f[2, 1] = 1e12
    csv = write(tmp_path / "t.csv", ["x", "y", "z", "e1"],
                [[*p, a] for p, a in zip(f, np.degrees(theta))])
    cell = plain_cell(tmp_path, turntable=Turntable(parent="robot"))
    assert_poor_and_untouched(capsys, tmp_path, cell, ["calibrate", "turntable", csv],
                              "is beyond any real cell (100 m)")


def test_workpiece_angles_in_radians_are_refused_and_the_cell_is_unchanged(tmp_path, capsys):
    rng = np.random.default_rng(14)
    theta = np.radians([10.0, 100.0, 200.0, 250.0, 310.0, 35.0])
    local = np.array([[0, 0, 0], [0.15, 0, 0], [0.04, 0.12, 0]] * 2)
    p = np.einsum("nji,nj->ni", rot_z(-theta), local) @ T_R_B[:3, :3].T + T_R_B[:3, 3]
    p = (p + rng.normal(0.0, NOISE, p.shape)) * 1e3
    csv = write(tmp_path / "wp.csv", ["point", "x", "y", "z", "e1"],
                [[r, *pi, a] for r, pi, a in zip(["origin", "x", "xy"] * 2, p, theta)])
    cell = plain_cell(tmp_path, turntable=Turntable(T_parent_B=T_R_B, parent="robot"))
    before = cell.read_bytes()
    code, out, err = run(capsys, "calibrate", "workpiece", csv, "--cell", cell, "--name", "part")
    assert code == 2 and out == "" and cell.read_bytes() == before
    assert "every e1 (table angle) value is within +-6.28, which looks like radians" in err


# -- repeated measurements are data -------------------------------------------------------------
def normalised_errors(make, truth, key, trials=200, seed=20):
    """(estimate - truth) / reported 1-sigma over seeded trials, per component (3 of them)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(trials):
        r = make(rng)
        value = r.values[key][:3, 3] if key == "T_R_B" else r.values[key]
        sigma = r.sigma[key + "_position" if key == "T_R_B" else key]
        out.append((value - truth) / sigma)
    return np.array(out)


def assert_consistent(z):
    # The touch noise is given (sigma), so z is unit normal. 200 trials x 3 components:
    # the pooled standard deviation is within 1 +- 0.15 (about 3 times its own scatter).
    assert 0.85 < z.std() < 1.15 and abs(z.mean()) < 0.2, (z.std(), z.mean())


def test_track_touches_4_2_mm_apart_and_61_positions_1_mm_apart():
    e = np.array([0.0, 0.4, 0.8, 0.8042, 1.2, 1.6])
    r = calibrate_track(e, track_touches(np.random.default_rng(21), e))
    assert r.verdict.level in ("good", "check") and not r.warnings
    dense = np.arange(61) * 1e-3  # 60 mm of travel
    r = calibrate_track(dense, track_touches(np.random.default_rng(22), dense))
    assert r.warnings == [] and r.dof == 3 * 61 - 6
    truth = REF @ Q  # the touched point in R with the track at 0
    assert_consistent(normalised_errors(
        lambda g: calibrate_track(e, track_touches(g, e), sigma=NOISE), truth, "point"))
    assert_consistent(normalised_errors(
        lambda g: calibrate_track(dense, track_touches(g, dense), sigma=NOISE), truth,
        "point"))


def test_same_table_angle_twice():
    for deg in ([0.0, 90.0, 180.0, 360.0, 250.0], [0.0, 90.0, 90.0, 180.0, 270.0]):
        theta = np.radians(deg)
        r = calibrate_turntable(theta, table_touches(np.random.default_rng(23), theta))
        assert r.verdict.level in ("good", "check")
        assert_consistent(normalised_errors(
            lambda g, t=theta: calibrate_turntable(t, table_touches(g, t), sigma=NOISE),
            T_R_B[:3, 3], "T_R_B"))


def test_identical_rows_are_used(tmp_path, capsys):
    rng = np.random.default_rng(24)
    rows = tcp_rows(rng, 6)
    rows.append(rows[2].copy())
    csv = write(tmp_path / "tcp.csv", list("xyzabc"), rows)
    code, out, err = run(capsys, "calibrate", "tcp", csv)
    assert code == 0 and "over 7 measurements" in out
    assert "note: " in err and "line 4, line 8 are identical; each is used as a measurement" in err

    def make(g):
        T = flange_poses(g, 6)
        return calibrate_tool(np.concatenate([T, T[:2]]), sigma=NOISE)  # two rows twice

    # Identical rows share their noise, so the reported sigma (which assumes independent touches)
    # is too small by design: the errors stay within the sigma of the 6 distinct touches.
    z = normalised_errors(make, TCP, "tcp")
    assert 0.85 < z.std() < 1.6


# -- thresholds and messages agree with each other and with the docs -------------------------------
def test_messages():
    rng = np.random.default_rng(30)
    # A span of exactly 20 degrees is a poorly conditioned but determined circle: accepted, with
    # the 90-degree warning.
    theta = np.radians([0.0, 10.0, 20.0, 20.0, 5.0])
    r = calibrate_turntable(theta, table_touches(rng, theta, noise=1e-6))
    assert any(w.startswith("the touches span only 20 deg of table rotation; spread them over "
                            "at least 90 deg") for w in r.warnings)
    # Angles within +-6.28: radians, and in degrees a span far below the 90 degrees asked for.
    with pytest.raises(InputError, match=r"within \+-6.28, which looks like radians.*span only "
                       r"6.00 deg of table rotation; spread them over 90 degrees or more"):
        external_axis({"e1": np.array([0.0, 2.0, 4.0, 6.0])}, "t.csv", "table")
    # e1 = 0, 1, 2, 3 mm: a 3 mm span, said as such.
    e = np.array([0.0, 1e-3, 2e-3, 3e-3])
    r = calibrate_track(e, track_touches(rng, e, noise=1e-6))
    assert any(w.startswith("the touches span only 3.0 mm of track travel: the track direction is "
                            "poorly determined") for w in r.warnings)
    with pytest.raises(InputError, match=r"moved 1e\+03 times the commanded track travel.*e1 in mm"):
        calibrate_track(e, track_touches(rng, e * 1e3))  # e1 in metres: a scale of 1000
    # N-point: nominal points 5 mm off a 400 mm line are nearly, not exactly, collinear.
    nominal = np.array([[0, 0, 0], [0.4, 0, 0], [0.2, 0.005, 0], [0.1, 0, 0.0]])
    p = transform_points(T_R_B, nominal) + rng.normal(0, 1e-5, (4, 3))
    r = frame_npoint(p, nominal)
    assert any(w.startswith("the nominal points are nearly collinear") for w in r.warnings)
    with pytest.raises(IllPosedError, match=r"collinear \(all on one line\)"):
        frame_npoint(p, [[0, 0, 0], [0.4, 0, 0], [0.2, 0, 0], [0.1, 0, 0]])
    # 3-point: an XY touch 1.14 degrees off the X line determines the frame.
    xy = 0.2 * np.array([np.cos(np.radians(1.14)), np.sin(np.radians(1.14)), 0.0])
    pts = transform_points(T_R_B, [[0, 0, 0], [0.4, 0, 0], xy])
    r = frame_3point(pts, ["origin", "x", "xy"])
    np.testing.assert_allclose(r.values["T_R_W"], T_R_B, atol=1e-9)
    assert any("only 1.1 deg off the X axis (nearly collinear)" in w for w in r.warnings)
    # The TCP minimum is 3 touches, and the count is said without "1 touches".
    T = flange_poses(rng, 3)
    assert calibrate_tool(T).dof == 3
    with pytest.raises(IllPosedError, match=r"touches of the reference point: 1 given; the TCP "
                       r"needs at least 3 \(4 recommended, 5 or more let a wrong touch be singled"):
        calibrate_tool(T[:1])


def test_tcp_minimum_in_the_cli(tmp_path, capsys):
    rows = tcp_rows(np.random.default_rng(31), 3)
    csv = write(tmp_path / "tcp.csv", list("xyzabc"), rows[:1])
    code, _, err = run(capsys, "calibrate", "tcp", csv)
    assert code == 2 and ("touches of the reference point (point=tcp): 1 given, at least 3 "
                          "needed") in err
    csv = write(tmp_path / "tcp3.csv", list("xyzabc"), rows)
    code, out, _ = run(capsys, "calibrate", "tcp", csv)
    assert code == 0 and "take 5 or more touches" in out.splitlines()[-1]


def test_every_command_gates_a_poor_result(tmp_path, capsys):
    rng = np.random.default_rng(32)
    local = np.array([[0, 0, 0]] * 4 + [[0.3, 0, 0], [0.1, 0.2, 0]])
    p = (transform_points(T_R_B, local) + rng.normal(0.0, NOISE, (6, 3))) * 1e3
    p[1:3] /= 1000.0  # two rows in metres: no one row to leave out
    roles = ["origin"] * 4 + ["x", "xy"]
    frame = write(tmp_path / "f.csv", ["point", "x", "y", "z"], [[r, *v] for r, v in zip(roles, p)])
    ext = write(tmp_path / "e.csv", ["point", "x", "y", "z"],
                [["tcp" if r == "origin" else r, *v] for r, v in zip(roles, p)])
    for args in (["frame", frame], ["external-tcp", ext]):
        code, out, err = run(capsys, "calibrate", *args)
        assert code == 3 and out.splitlines()[-1].startswith("verdict: POOR: RMS")
        assert err.startswith("error: poor calibration, nothing written")
        assert run(capsys, "calibrate", *args, "--accept-poor")[0] == 0


def test_repeated_data_pass_the_cli(tmp_path, capsys):
    rng = np.random.default_rng(33)
    angles = np.array([0.0, 90.0, 90.0, 180.0, 360.0, 250.0])
    f = table_touches(rng, np.radians(angles)) * 1e3
    rows = [[*p, a] for p, a in zip(f, angles)] + [[*f[3], angles[3]]]  # and a copied line
    csv = write(tmp_path / "t.csv", ["x", "y", "z", "e1"], rows)
    code, out, err = run(capsys, "calibrate", "turntable", csv)
    assert code == 0 and "over 7 measurements" in out and "line 5, line 8 are identical" in err
    e = np.array([0.0, 400.0, 800.0, 804.2, 1200.0, 1600.0])
    f = track_touches(rng, e * 1e-3) * 1e3
    csv = write(tmp_path / "k.csv", ["x", "y", "z", "e1"], [[*p, v] for p, v in zip(f, e)])
    code, out, _ = run(capsys, "calibrate", "track", csv, "--json")
    assert code == 0 and json.loads(out)["dof"] == 12


def test_verdict_of_a_malformed_result_is_poor_or_check_never_an_exception():
    good = calibrate_tool(flange_poses(np.random.default_rng(34), 8)).to_json()
    for key, bad in [("condition", "x"), ("dof", None), ("residuals_xyz_mm", [[1, "a"]]),
                     ("residuals_xyz_mm", [[1, 2], [3]]), ("warnings", 7), ("matrix", "eye"),
                     ("tcp_mm", {"x": 1}), ("noise_sigma_mm", "0.1"), ("scale", None)]:
        v = verdict({**good, key: bad})
        assert v.level in ("good", "check", "poor")
    assert verdict({**good, "residuals_xyz_mm": [[1, "a"]]}).level == "poor"
