"""The figures of ISO 9283 against an independent computation from the formulas.

A seeded log of 30 cycles of the five poses with known systematic offsets and noise is written
as CSV; the test reads the file back with the csv module and computes AP and RP as the formulas
say, in plain Python, and compares with ``analyse``'s JSON to 1e-9 mm; the offsets are
recovered within their expected scatter.
"""

import csv
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell.errors import IllPosedError, InputError
from robotcell.iso9283 import Limits, Log, TestPlan, analyse, write_log, write_plan
from robotcell.iso9283.cube import (
    CIRCLE_SEGMENTS,
    LINE_POINTS,
    POSE_NAMES,
    circle_points,
    cube_corners,
    line_points,
    pose_points,
)
from robotcell.iso9283.figures import crossings, path_figures
from robotcell.kinematics.transforms import make_pose, rot_y, rot_z

SIZE = 0.5
CENTRE = np.array([1.2, 0.1, 0.9])
R_C = rot_y(np.pi) @ rot_z(0.3)
#: Systematic offsets of P1..P5 (m) and the scatter (1-sigma per coordinate, m).
OFFSETS = np.array([[0.30, -0.20, 0.10], [0.05, 0.40, -0.25], [-0.35, 0.10, 0.20],
                    [0.15, 0.15, 0.15], [0.0, -0.30, -0.10]]) * 1e-3
NOISE = 0.02e-3
CYCLES = 30


def make_plan() -> TestPlan:
    pts = np.vstack([pose_points(SIZE), line_points(SIZE), circle_points(SIZE)]) + CENTRE
    names = [*POSE_NAMES, *(f"line_{k + 1}" for k in range(LINE_POINTS)),
             *(f"circle_{k + 1}" for k in range(CIRCLE_SEGMENTS + 1))]
    return TestPlan(names, np.array([make_pose(R_C, p) for p in pts]), "world", "torch")


def make_log(seed: int, cycles: int = CYCLES, rotation: np.ndarray | None = None) -> Log:
    rng = np.random.default_rng(seed)
    cmd = make_plan().poses[:, :3, 3]
    p = cmd[None] + OFFSETS[None] + rng.normal(0.0, NOISE, (cycles, 5, 3))
    tilt = Rotation.from_rotvec(np.radians([0.01, -0.02, 0.005])).as_matrix()
    dev = Rotation.from_rotvec(rng.normal(0.0, math.radians(0.002), (cycles * 5, 3))).as_matrix()
    R = dev @ tilt @ R_C
    names = list(POSE_NAMES) * cycles
    time = np.arange(cycles * 5) * 3.0
    return Log(np.repeat(np.arange(1, cycles + 1), 5), names, p.reshape(-1, 3), R, time)


@pytest.fixture()
def files(tmp_path):
    plan, meas = tmp_path / "plan.csv", tmp_path / "meas.csv"
    write_plan(make_plan(), plan)
    write_log(make_log(7), meas)
    return plan, meas


def independent_pose_figures(plan_csv, meas_csv):
    """AP and RP per pose from the two files, as the formulas say (mm)."""
    with open(plan_csv, newline="") as fh:
        command = {r["pose"]: [float(r[k]) for k in "xyz"] for r in csv.DictReader(fh)}
    cycles = {}
    with open(meas_csv, newline="") as fh:
        for r in csv.DictReader(fh):
            cycles.setdefault(r["pose"], []).append([float(r[k]) for k in "xyz"])
    out = {}
    for pose, pts in cycles.items():
        n = len(pts)
        bar = [math.fsum(p[k] for p in pts) / n for k in range(3)]
        ap = [bar[k] - command[pose][k] for k in range(3)]
        l = [math.sqrt(sum((p[k] - bar[k]) ** 2 for k in range(3))) for p in pts]
        lbar = math.fsum(l) / n
        s = math.sqrt(math.fsum((v - lbar) ** 2 for v in l) / (n - 1))
        out[pose] = {"AP_p": math.sqrt(sum(a * a for a in ap)), "AP": ap, "RP_l": lbar + 3 * s,
                     "n": n}
    return out


def test_ap_and_rp_match_an_independent_computation_to_1e_9_mm(files):
    plan, meas = files
    expected = independent_pose_figures(plan, meas)
    result = analyse(meas, plan).to_json()
    assert [p["pose"] for p in result["poses"]] == list(POSE_NAMES)
    for p in result["poses"]:
        e = expected[p["pose"]]
        assert p["cycles"] == e["n"] == CYCLES
        assert p["AP_p_mm"] == pytest.approx(e["AP_p"], abs=1e-9)
        for k, axis in enumerate("xyz"):
            assert p[f"AP_{axis}_mm"] == pytest.approx(e["AP"][k], abs=1e-9)
        assert p["RP_l_mm"] == pytest.approx(e["RP_l"], abs=1e-9)


def test_the_offsets_are_recovered_within_their_expected_scatter(files):
    plan, meas = files
    result = analyse(meas, plan).to_json()
    scatter = NOISE / math.sqrt(CYCLES) * 1e3               # of a barycentre coordinate, mm
    for p, offset in zip(result["poses"], OFFSETS * 1e3):
        got = np.array([p["AP_x_mm"], p["AP_y_mm"], p["AP_z_mm"]])
        assert np.all(np.abs(got - offset) < 4 * scatter), (p["pose"], got, offset)
        # RP of an isotropic Gaussian scatter: mean(l) + 3 S_l ~ (1.596 + 3 * 0.673) sigma
        assert p["RP_l_mm"] == pytest.approx(3.616 * NOISE * 1e3, abs=4 * 0.29 * NOISE * 1e3)


def test_the_offsets_fail_a_limit_below_them_and_pass_one_above(files):
    plan, meas = files
    norms = np.linalg.norm(OFFSETS, axis=1) * 1e3
    largest, where = norms.max(), POSE_NAMES[int(np.argmax(norms))]
    fail = analyse(meas, plan, limits=Limits(AP=(largest - 0.05) * 1e-3)).verdict
    good = analyse(meas, plan, limits=Limits(AP=(largest + 0.05) * 1e-3, RP=0.2e-3)).verdict
    assert fail.level == "fail" and f"({where}) >" in fail.reasons[0]
    assert good.level == "pass" and len(good.reasons) == 2
    assert analyse(meas, plan).verdict.level == "none"


def test_orientation_figures_recover_the_tilt_about_x_y_z(files):
    plan, meas = files
    result = analyse(meas, plan).to_json()
    scatter = 0.002 / math.sqrt(CYCLES)                     # deg, of a mean about one axis
    for p in result["poses"]:
        got = [p["AP_a_deg"], p["AP_b_deg"], p["AP_c_deg"]]
        assert np.allclose(got, [0.01, -0.02, 0.005], atol=4 * scatter)
        # RP_a = 3 S_a, with S_a about the 0.002 deg scatter (csv keeps 1e-4 deg)
        assert np.allclose([p["RP_a_deg"], p["RP_b_deg"], p["RP_c_deg"]], 0.006, atol=0.0025)


def test_distance_figures_follow_the_formulas(files):
    plan, meas = files
    result = analyse(meas, plan)
    log_p = {r.pose: r.p for r in result.poses}
    cmd = make_plan().poses[:, :3, 3]
    for d, k in zip(result.distances, range(1, 5)):
        dist = np.linalg.norm(log_p["P1"] - log_p[POSE_NAMES[k]], axis=1)
        dc = np.linalg.norm(cmd[0] - cmd[k])
        assert d.D_c == pytest.approx(dc, abs=1e-12)
        assert d.AD_p == pytest.approx(dist.mean() - dc, abs=1e-12)
        assert d.RD_p == pytest.approx(3 * np.std(dist, ddof=1), abs=1e-12)
        # the systematic part: the offsets change the distance by about their difference
        expected = np.linalg.norm(cmd[0] + OFFSETS[0] - cmd[k] - OFFSETS[k]) - dc
        assert d.AD_p == pytest.approx(expected, abs=4 * NOISE)


def test_drift_compares_the_first_and_last_ten_cycles():
    log = make_log(3)
    late = np.repeat(np.arange(1, CYCLES + 1), 5) > CYCLES - 10
    log.p[late] += np.array([0.0, 0.0, 0.5e-3])              # the last 10 cycles sag 0.5 mm
    result = analyse(log, make_plan())
    for r in result.poses:
        moved = np.linalg.norm(r.p[-10:].mean(axis=0) - r.p[:10].mean(axis=0))
        assert r.drift[0] == pytest.approx(moved, abs=1e-12)
        assert r.drift[0] == pytest.approx(0.5e-3, abs=4 * NOISE)
        l_first = np.linalg.norm(r.p[:10] - r.p[:10].mean(axis=0), axis=1)
        l_last = np.linalg.norm(r.p[-10:] - r.p[-10:].mean(axis=0), axis=1)
        rp = [lv.mean() + 3 * np.std(lv, ddof=1) for lv in (l_first, l_last)]
        assert r.drift[1] == pytest.approx(abs(rp[1] - rp[0]), abs=1e-12)
    no_time = make_log(3)
    no_time.time = None
    assert all(r.drift is None for r in analyse(no_time, make_plan()).poses)
    assert "no drift: the log has no time stamps" in analyse(no_time, make_plan()).notes


def test_a_line_path_measured_parallel_to_its_command_crosses_each_normal_plane_there():
    c = line_points(SIZE) + CENTRE
    t = (c[-1] - c[0]) / np.linalg.norm(c[-1] - c[0])
    rng = np.random.default_rng(5)
    shifts = []
    x = []
    for _ in range(10):
        delta = rng.normal(0.0, 0.05e-3, 3) + np.array([0.0, 0.2e-3, 0.0])
        delta -= (delta @ t) * t                             # across the path
        s = np.linspace(-0.02, np.linalg.norm(c[-1] - c[0]) + 0.02, 700)
        samples = c[0] - 0.0 + s[:, None] * t + delta
        x.append(crossings(samples, c))
        shifts.append(delta)
    x = np.array(x)
    shifts = np.array(shifts)
    assert np.allclose(x, c[None] + shifts[:, None], atol=1e-12)
    fig = path_figures(x, c)
    bar = shifts.mean(axis=0)
    l = np.linalg.norm(shifts - bar, axis=1)
    assert fig.AT_p == pytest.approx(np.linalg.norm(bar), abs=1e-12)
    assert fig.RT_p == pytest.approx(l.mean() + 3 * np.std(l, ddof=1), abs=1e-12)


def test_a_circle_measured_larger_by_delta_has_path_accuracy_delta():
    c = circle_points(SIZE) + CENTRE
    r = np.linalg.norm(c[0] - CENTRE)
    u, w = (c[0] - CENTRE) / r, None
    w = np.cross(np.cross(u, c[18] - CENTRE), u)
    w /= np.linalg.norm(w)
    a = np.linspace(-0.05, 2 * np.pi + 0.05, 4000)
    delta = 0.3e-3
    samples = CENTRE + (r + delta) * (np.cos(a)[:, None] * u + np.sin(a)[:, None] * w)
    fig = path_figures(np.array([crossings(samples, c)] * 3), c)
    assert fig.AT_p == pytest.approx(delta, abs=2e-7)
    assert fig.deviation.min() == pytest.approx(delta, abs=2e-7)


def test_cube_corners_are_those_of_a_cube_of_the_plan_size():
    corners = cube_corners(make_plan().poses[:, :3, 3])
    d = np.linalg.norm(corners[:, None] - corners[None], axis=-1)
    edges = np.sort(d, axis=1)[:, 1:4]                        # three neighbours per corner
    assert np.allclose(edges, SIZE, atol=1e-12)
    assert np.allclose(np.sort(d.ravel())[-1], SIZE * math.sqrt(3), atol=1e-12)
    assert np.allclose(corners.mean(axis=0), CENTRE, atol=1e-12)
    assert make_plan().size == pytest.approx(SIZE, abs=1e-12)


def test_the_device_frame_fit_recovers_a_tracker_pose_and_keeps_rp():
    log = make_log(11)
    T_D_X = make_pose(Rotation.from_euler("xyz", [3, -5, 40], degrees=True).as_matrix(),
                      [2.0, -1.0, 0.3])
    moved = Log(log.cycle, log.name, log.p @ T_D_X[:3, :3].T + T_D_X[:3, 3],
                T_D_X[:3, :3] @ log.R, log.time)
    plan = make_plan()
    aligned, fitted = analyse(log, plan), analyse(moved, plan, device_frame=True)
    # a rigid motion leaves the distances from the barycentre, hence RP, as they were
    for a, f in zip(aligned.poses, fitted.poses):
        assert f.figures.RP_l == pytest.approx(a.figures.RP_l, abs=1e-12)
        # (about axes turned by what the fit leaves of the rotation, ~1e-3 rad)
        assert np.allclose(f.RP_abc, a.RP_abc, atol=1e-6)
    # the fit maps the tracker frame back within what the offsets make of it
    T = fitted.T_X_device @ T_D_X
    assert np.linalg.norm(T[:3, 3]) < 1e-3 and np.allclose(T[:3, :3], np.eye(3), atol=1e-3)
    assert fitted.to_json()["device_frame"]["rms_mm"] < 0.5
    with pytest.raises(InputError, match="lies .* mm from its command"):
        analyse(moved, plan)


def test_the_device_frame_fit_refuses_poses_on_one_line():
    plan = make_plan()
    T = plan.T.copy()
    T[:5, :3, 3] = CENTRE + np.outer(np.arange(5) * 0.1, [1.0, 0.0, 0.0])
    line_plan = TestPlan(plan.names, T, "world", "torch")
    log = Log(np.repeat(np.arange(1, 11), 5), list(POSE_NAMES) * 10,
              np.tile(T[:5, :3, 3], (10, 1)) + 1e-5)
    with pytest.raises(IllPosedError, match="lie on one line"):
        analyse(log, line_plan, device_frame=True)


def path_log(seed: int, twist: float, cycles: int = 10, noise: float = math.radians(0.002)
             ) -> tuple[Log, np.ndarray]:
    """The five poses (make_log) and the line measured through its command points and the
    midpoints between them, the orientation turned about z of the frame by ``twist`` times
    the fraction of the line run, with scatter ``noise`` (rad) per axis; and the rotation
    vectors of the deviations at the command points, shape (cycles, M, 3)."""
    rng = np.random.default_rng(seed)
    plan = make_plan()
    line = np.array([i for i, n in enumerate(plan.names) if n.startswith("line_")])
    c = plan.T[line, :3, 3]
    s = np.linspace(0.0, 1.0, 2 * len(c) - 1)                   # points and midpoints
    p = np.interp(s, np.linspace(0.0, 1.0, len(c)), np.arange(len(c)))
    pts = c[np.floor(p).astype(int)] + (p - np.floor(p))[:, None] * (
        c[np.minimum(np.floor(p).astype(int) + 1, len(c) - 1)] - c[np.floor(p).astype(int)])
    dev = rng.normal(0.0, noise, (cycles, len(s), 3))
    dev[..., 2] += twist * s
    R = Rotation.from_rotvec(dev.reshape(-1, 3)).as_matrix() @ R_C
    poses = make_log(seed, cycles)
    log = Log(np.concatenate([poses.cycle, np.repeat(np.arange(1, cycles + 1), len(s))]),
              poses.name + ["line"] * (cycles * len(s)),
              np.vstack([poses.p, np.tile(pts, (cycles, 1))]), np.concatenate([poses.R, R]))
    return log, dev[:, ::2]


def test_orientation_path_accuracy_matches_an_independent_computation():
    log, dev = path_log(3, twist=math.radians(0.05))
    (line,) = analyse(log, make_plan()).paths
    # at each command point the measured sample there: its deviation, mean over the cycles
    expected = np.abs(dev.mean(axis=0)).max(axis=0)
    assert np.allclose(line.AT_abc, expected, atol=1e-12)
    data = analyse(log, make_plan()).to_json()["paths"][0]
    assert [data[f"AT_{a}_deg"] for a in "abc"] == pytest.approx(np.degrees(expected).tolist(),
                                                                  abs=1e-9)


def test_orientation_path_accuracy_recovers_a_twist_along_the_line():
    twist, noise, cycles = math.radians(0.05), math.radians(0.002), 10
    log, _ = path_log(4, twist, cycles, noise)
    (line,) = analyse(log, make_plan()).paths
    # the largest mean deviation about z is the twist at the line's end; about x and y only
    # the scatter of a mean of 10 (within 4 standard errors, over 21 points)
    assert line.AT_abc[2] == pytest.approx(twist, abs=4 * noise / math.sqrt(cycles))
    assert np.all(line.AT_abc[:2] < 4 * noise / math.sqrt(cycles) + 1e-12)
    # without orientations in the log there is no orientation path accuracy
    bare = Log(log.cycle, log.name, log.p)
    assert analyse(bare, make_plan()).paths[0].AT_abc is None
    assert analyse(bare, make_plan()).to_json()["paths"][0]["AT_a_deg"] is None
