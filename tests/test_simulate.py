"""Simulated touch-up measurements: exact reach, limits, noise size, CSV, calibration, refusals."""

import csv
import functools
import io
import math
import re

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell import InputError, load_robot, pose_from_vendor
from robotcell.calibration.frame import frame_3point
from robotcell.calibration.tcp import calibrate_tool
from robotcell.calibration.track import calibrate_track
from robotcell.calibration.turntable import calibrate_turntable
from robotcell.calibration.workpiece import calibrate_workpiece
from robotcell.cell import Cell, Frame, Tool, Track, Turntable
from robotcell.kinematics.transforms import rot_z
from robotcell.studies.simulate import PROCEDURES, simulate

ROBOT = load_robot("kuka_kr16")
NOISE = 1e-4


def pose(xyz_mm, abc_deg):
    return pose_from_vendor([*xyz_mm, *abc_deg], "kuka")


TORCH = pose([312.5, -1.2, 95.0], [0.0, 45.0, 0.0])
T_WORLD_R = pose([500.0, 200.0, 0.0], [30.0, 0.0, 0.0])


def track_cell(track=None, turntable=None):
    """A KR 16 on a 6 m track beside a turntable fixed in the world."""
    return Cell(
        robot=ROBOT, robot_model="kuka_kr16",
        track=track or Track(np.eye(4), pose([0.8, -1.1, 450.3], [0.05, -0.03, 0.02]), axis="x",
                             scale=1.0002, lower=0.0, upper=6.0, name="KL1500"),
        turntable=turntable or Turntable(pose([3000.0, 1250.0, 550.0], [90.0, 0.12, -0.08]),
                                         lower=-2 * math.pi, upper=2 * math.pi, name="DKP_400"),
        tools={"torch": Tool(TORCH)},
        frames={"fixture": Frame(pose([1800.0, -1000.0, 300.0], [30.0, 0.0, 0.0])),
                "cam": Frame(pose([1000.0, 400.0, 100.0], [10.0, 0.0, 0.0]), parent="robot"),
                "part": Frame(pose([150.0, -80.0, 120.0], [15.0, 0.0, 0.0]), parent="turntable")})


def fixed_cell(turntable=None, tools=None):
    """The KR 16 placed in the world (no track), a turntable carried by its base."""
    return Cell(
        robot=ROBOT, robot_model="kuka_kr16", T_world_R=T_WORLD_R,
        turntable=turntable or Turntable(pose([1250.0, 0.0, 350.0], [90.0, 0.1, -0.05]),
                                         parent="robot", lower=-math.pi, upper=math.pi),
        tools=tools or {"torch": Tool(TORCH)},
        frames={"fixture": Frame(T_WORLD_R @ pose([900.0, -700.0, 150.0], [-20.0, 0.0, 0.0])),
                "part": Frame(pose([150.0, -80.0, 120.0], [15.0, 0.0, 0.0]), parent="turntable")})


CELLS = {"track": track_cell, "fixed": fixed_cell}

# Touch designs away from the defaults, so the checks show the design values are used.
# More touches than the minimum, so the calibrations estimate the touch-up error well.
TCP = {"point": (1.0, 0.1, 0.3), "distance": 0.08, "touches": 6, "tilt": math.radians(25.0)}
FRAME = {"size": 0.18, "repeats": 3}
TABLE = {"radius": 0.25, "height": 0.04, "touches": 8}
WORKPIECE = {"size": 0.12, "repeats": 3}
CASES = {
    "track-tcp": ("track", "tcp", TCP),
    "track-frame": ("track", "frame", {"frame": "fixture", **FRAME}),
    "track-frame-on-robot": ("track", "frame", {"frame": "cam", **FRAME}),
    "track-track": ("track", "track", {}),
    "track-turntable": ("track", "turntable", TABLE),
    "track-workpiece": ("track", "workpiece", WORKPIECE),
    "fixed-tcp": ("fixed", "tcp", TCP),
    "fixed-frame": ("fixed", "frame", FRAME),
    "fixed-turntable": ("fixed", "turntable", TABLE),
    "fixed-workpiece": ("fixed", "workpiece", WORKPIECE),
}
DEFAULT_SIZE = {"frame": 0.2, "workpiece": 0.15}


@functools.cache
def simulated(case, noise, seed=1):
    kind, procedure, design = CASES[case]
    cell = CELLS[kind]()
    return cell, simulate(cell, procedure, noise=noise, seed=seed, **design)


def three_point(roles, size):
    pts = {"origin": [0.0, 0.0, 0.0], "x": [size, 0.0, 0.0], "xy": [0.0, size, 0.0]}
    return np.array([pts[r] for r in roles])


def touch_errors(cell, t, design):
    """Per touch, where the recorded joints put the TCP minus where the procedure touches (m).

    In the frame each procedure is defined in: the 3-point coordinates in the touched frame, the
    point carried back to table angle 0 in B, the reference points in L, and for the TCP the
    reference point in the TCP frame (on the TCP, on its -X axis, in its XY plane with +Y).
    """
    e = 0.0 if t.track is None else t.track
    if t.procedure == "tcp":
        T = cell.robot.fk(t.q, tool=t.truth["T_F_TCP"])                      # T_R_TCP
        p_TCP = np.einsum("nji,nj->ni", T[:, :3, :3], np.asarray(design["point"]) - T[:, :3, 3])
        d = design["distance"]
        expected = {"tcp": [0.0, 0.0, 0.0], "-x": [-d, 0.0, 0.0], "xy": [0.0, d, 0.0]}
        return p_TCP - np.array([expected[r] for r in t.roles])
    if t.procedure in ("frame", "workpiece"):
        table = 0.0 if t.table is None else t.table
        p = cell.fk(t.q, e, table, tool=t.tool, frame=t.truth["name"])[:, :3, 3]
        return p - three_point(t.roles, design.get("size", DEFAULT_SIZE[t.procedure]))
    if t.procedure == "turntable":
        p_B = cell.fk(t.q, e, tool=t.tool, frame="turntable")[:, :3, 3]
        p0 = np.einsum("nij,nj->ni", rot_z(-t.table), p_B)
        return p0 - [design["radius"], 0.0, design["height"]]
    p_L = cell.fk(t.q, t.track, tool=t.tool, frame="track")[:, :3, 3]
    return p_L - t.truth["references"][[int(p) - 1 for p in t.roles]]


def read_back(t):
    """The measurement CSV of ``t`` parsed back: header, text of each column by name, CSV text."""
    buf = io.StringIO()
    t.write_csv(buf)
    rows = list(csv.reader(io.StringIO(buf.getvalue())))
    header, body = rows[0], rows[1:]
    cols = {h: [r[i] for r in body] for i, h in enumerate(header)}
    return header, cols, buf.getvalue()


# -- 1. the recorded joints reach the touched points ----------------------------------------------
@pytest.mark.parametrize("case", CASES)
def test_exact_touches_reach_the_points(case):
    cell, t = simulated(case, 0.0)
    design = CASES[case][2]
    err = touch_errors(cell, t, design)
    assert err.shape == (len(t.q), 3)
    assert np.abs(err).max() < 1e-9
    if t.procedure == "tcp":
        assert t.roles == ["tcp"] * 6 + ["-x", "xy"]
        # The TCP of every tcp touch is on one common point, in the robot base and in the world.
        p_w = cell.fk(t.q, 0.0 if t.track is None else t.track, tool=t.truth["T_F_TCP"])[:, :3, 3]
        tcp = np.array(t.roles) == "tcp"
        np.testing.assert_allclose(p_w[tcp], np.broadcast_to(p_w[tcp][0], (6, 3)), atol=1e-9)
        # The tool Z axis: tilted by `tilt` from straight down, evenly around, for the tcp
        # touches; straight down for the -x and xy touches (tool orientation in the world).
        z = cell.fk(t.q, 0.0 if t.track is None else t.track, tool=t.truth["T_F_TCP"])[:, :3, 2]
        np.testing.assert_allclose(np.arccos(-z[tcp, 2]), TCP["tilt"], rtol=0, atol=2e-3)
        assert np.linalg.norm(z[tcp, :2].sum(axis=0)) < 1e-2
        np.testing.assert_allclose(np.arccos(-z[~tcp, 2]), 0.0, rtol=0, atol=2e-3)
    elif t.procedure in ("frame", "workpiece"):
        assert t.roles == ["origin"] * 3 + ["x"] * 3 + ["xy"] * 3
    elif t.procedure == "turntable":
        assert t.roles is None and len(t.table) == 8
    else:
        assert t.roles == ["1"] * 4 + ["2"] * 4


def test_turntable_touches_at_the_given_angles_and_track_references():
    cell = track_cell()
    angles = np.radians([-300.0, -100.0, 0.0, 45.0, 200.0])
    t = simulate(cell, "turntable", noise=0.0, angles=angles, radius=0.2, height=0.0)
    np.testing.assert_array_equal(t.table, angles)
    assert np.abs(touch_errors(cell, t, {"radius": 0.2, "height": 0.0})).max() < 1e-9
    refs = np.array([[1.8, -0.9, 0.2], [2.6, 1.0, 0.1], [4.4, -1.0, 0.3]])
    t = simulate(cell, "track", noise=0.0, references=refs, positions=3, travel=0.6)
    np.testing.assert_array_equal(t.truth["references"], refs)
    assert t.roles == ["1"] * 3 + ["2"] * 3 + ["3"] * 3
    assert np.abs(touch_errors(cell, t, {})).max() < 1e-9
    # The track positions of each reference are spread over the travel around it.
    for k in range(3):
        e = t.track[3 * k:3 * k + 3]
        assert np.ptp(e) == pytest.approx(0.6 / cell.track.scale)
        assert np.mean(e) == pytest.approx((refs[k, 0] - 0.0008) / cell.track.scale)


def test_touch_up_error_keeps_the_configuration():
    """With the error the joints stay on the branch of the exact touch (the same seed otherwise)."""
    for case in CASES:
        _, exact = simulated(case, 0.0)
        _, noisy = simulated(case, NOISE)
        assert np.array_equal(exact.track, noisy.track) and np.array_equal(exact.table, noisy.table)
        assert 1e-6 < np.abs(noisy.q - exact.q).max() < 0.01, case


# -- 2. limits ------------------------------------------------------------------------------------
def assert_within_limits(cell, t):
    assert np.all(cell.robot.within_limits(t.q))
    if cell.track is None:
        assert t.track is None
    else:
        assert np.all(cell.track.within_limits(t.track))
        if t.procedure != "track":  # one track position for all touches of the procedure
            assert np.ptp(t.track) == 0.0
    if t.procedure in ("turntable", "workpiece"):
        assert np.all(cell.turntable.within_limits(t.table))
    else:
        assert t.table is None


@pytest.mark.parametrize("case", CASES)
def test_joints_track_and_table_within_limits(case):
    for noise in (0.0, NOISE):
        cell, t = simulated(case, noise)
        assert_within_limits(cell, t)


@pytest.mark.parametrize("procedure", ["turntable", "workpiece"])
@pytest.mark.parametrize("limits_deg", [(-90.0, 360.0), (0.0, 400.0), (-200.0, -10.0), (5.0, 90.0),
                                        (-math.inf, -30.0), (100.0, math.inf)])
def test_default_table_angles_within_asymmetric_limits(procedure, limits_deg):
    lo, hi = np.radians(limits_deg)
    cell = fixed_cell(turntable=Turntable(pose([1250.0, 0.0, 350.0], [90.0, 0.1, -0.05]),
                                          parent="robot", lower=lo, upper=hi))
    t = simulate(cell, procedure, noise=0.0, seed=1)
    assert_within_limits(cell, t)
    design = {"radius": 0.3, "height": 0.05} if procedure == "turntable" else {}
    assert np.abs(touch_errors(cell, t, design)).max() < 1e-9


def test_chosen_track_position_within_narrow_track_limits():
    track = Track(np.eye(4), pose([0.8, -1.1, 450.3], [0.05, -0.03, 0.02]), axis="x",
                  lower=2.2, upper=2.9)
    cell = track_cell(track=track)
    for procedure, design in (("frame", {"frame": "fixture"}), ("turntable", {}), ("tcp", {})):
        t = simulate(cell, procedure, noise=NOISE, seed=3, **design)
        assert_within_limits(cell, t)
    t = simulate(cell, "frame", noise=0.0, frame="fixture", track=2.5)
    np.testing.assert_array_equal(t.track, 2.5)


# -- 3. the touch-up error has the requested size -------------------------------------------------
def test_noise_size_over_many_turntable_touches():
    cell = track_cell()
    design = {"radius": 0.3, "height": 0.05}
    t = simulate(cell, "turntable", noise=1e-3, seed=11, track=3.0, touches=150, **design)
    err = touch_errors(cell, t, design)
    assert err.shape == (150, 3)
    np.testing.assert_allclose(err.std(axis=0), 1e-3, rtol=0.2)
    assert np.all(np.abs(err.mean(axis=0)) < 4e-3 / math.sqrt(150))


@pytest.mark.parametrize("case", ["fixed-tcp", "fixed-frame", "fixed-workpiece", "track-track"])
def test_noise_size_over_several_seeds(case):
    kind, procedure, design = CASES[case]
    cell = CELLS[kind]()
    rng = np.random.default_rng(5)  # one generator: each simulation draws new errors
    err = np.concatenate([touch_errors(cell, simulate(cell, procedure, noise=2e-4, seed=rng,
                                                      **design), design) for _ in range(20)])
    assert len(err) >= 120
    np.testing.assert_allclose(err.std(axis=0), 2e-4, rtol=0.2)
    assert np.all(np.abs(err.mean(axis=0)) < 4 * 2e-4 / math.sqrt(len(err)))


# -- 4. reproducibility ---------------------------------------------------------------------------
@pytest.mark.parametrize("case", ["fixed-tcp", "fixed-frame", "fixed-turntable", "fixed-workpiece",
                                  "track-track", "track-frame"])
def test_same_seed_same_csv_other_seed_other_values(case):
    kind, procedure, design = CASES[case]
    _, t = simulated(case, NOISE, seed=1)
    again = simulate(CELLS[kind](), procedure, noise=NOISE, seed=1, **design)
    other = simulate(CELLS[kind](), procedure, noise=NOISE, seed=2, **design)
    text = read_back(t)[2]
    assert read_back(again)[2] == text
    assert read_back(other)[2] != text
    # Only the touch-up error differs: the same touches and track / table positions.
    assert other.roles == t.roles and np.array_equal(other.table, t.table)
    assert np.array_equal(other.track, t.track)
    assert np.abs(other.q - t.q).max() > 1e-6


# -- 5. the CSV contract --------------------------------------------------------------------------
A = [f"a{i}" for i in range(1, 7)]
HEADERS = {
    "track-tcp": A + ["point"],  # flange poses in the robot base: the track does not matter
    "track-frame": A + ["track", "point"],
    "track-frame-on-robot": A + ["track", "point"],
    "track-track": A + ["e1", "point"],
    "track-turntable": A + ["e1", "track"],
    "track-workpiece": A + ["e1", "track", "point"],
    "fixed-tcp": A + ["point"],
    "fixed-frame": A + ["point"],
    "fixed-turntable": A + ["e1"],
    "fixed-workpiece": A + ["e1", "point"],
}


@pytest.mark.parametrize("case", CASES)
def test_csv_header_units_and_options(case, tmp_path):
    _, t = simulated(case, NOISE)
    header, cols, text = read_back(t)
    assert header == HEADERS[case]
    assert t.columns()[0] == header and len(t.columns()[1]) == len(t.q)
    q_deg = np.array([[float(v) for v in cols[a]] for a in A]).T
    np.testing.assert_allclose(q_deg, np.degrees(t.q), rtol=0, atol=1e-6)
    if t.procedure == "track":
        np.testing.assert_allclose([float(v) for v in cols["e1"]], t.track * 1e3, rtol=0, atol=1e-3)
    elif "e1" in cols:
        np.testing.assert_allclose([float(v) for v in cols["e1"]], np.degrees(t.table), rtol=0,
                                   atol=1e-4)
    if "track" in cols:
        np.testing.assert_allclose([float(v) for v in cols["track"]], t.track * 1e3, rtol=0,
                                   atol=1e-3)
    if "point" in cols:
        assert cols["point"] == t.roles
    # A path gets the same text as a stream.
    t.write_csv(tmp_path / "touches.csv")
    assert (tmp_path / "touches.csv").read_text(encoding="utf-8") == text
    # What `robotcell calibrate` needs besides the file.
    if t.procedure == "track":
        refs = [[float(v) * 1e-3 for v in o.split("=", 1)[1].split(",")] for o in t.options]
        assert all(o.startswith("--reference=") for o in t.options)
        np.testing.assert_allclose(refs, t.truth["references"], rtol=0, atol=1e-6)
    elif t.procedure == "turntable":
        assert t.options == [f"--height={-TABLE['height'] * 1e3:g}"]
        assert t.truth["height"] == TABLE["height"] and t.truth["radius"] == TABLE["radius"]
    else:
        assert t.options == []
    assert t.tool == (None if t.procedure == "tcp" else "torch") and t.noise == NOISE


# -- 6. simulate -> calibrate recovers the truth ----------------------------------------------------
def si_columns(t):
    """Joints, track positions, table angles and roles read back from the CSV (SI units)."""
    _, cols, _ = read_back(t)
    q = np.radians(np.array([[float(v) for v in cols[a]] for a in A]).T)
    track = np.array([float(v) for v in cols["track"]]) * 1e-3 if "track" in cols else 0.0
    table = None
    if t.procedure == "track":
        track = np.array([float(v) for v in cols["e1"]]) * 1e-3
    elif "e1" in cols:
        table = np.radians([float(v) for v in cols["e1"]])
    return q, track, table, cols.get("point")


def assert_pose_within(T_est, T_true, sigma_position, sigma_rotation, k=4.0):
    # Sigmas of the size the touch-up error allows, so the bound is a tight one.
    assert np.all(sigma_position < 2 * NOISE) and np.all(sigma_rotation < 2e-3)
    assert np.all(np.abs(T_est[:3, 3] - T_true[:3, 3]) <= k * sigma_position)
    d = Rotation.from_matrix(T_true[:3, :3] @ T_est[:3, :3].T).as_rotvec()
    assert np.all(np.abs(d) <= k * sigma_rotation)


@pytest.mark.parametrize("case", CASES)
def test_truth_holds_the_cell_values(case):
    cell, t = simulated(case, NOISE)
    truth = t.truth
    if t.procedure == "tcp":
        np.testing.assert_array_equal(truth["T_F_TCP"], cell.tools["torch"].T_F_TCP)
        np.testing.assert_array_equal(truth["tcp"], cell.tools["torch"].T_F_TCP[:3, 3])
    elif t.procedure == "track":
        np.testing.assert_array_equal(truth["T_L_R"], cell.track.T_L_R0)
        assert truth["scale"] == cell.track.scale
    elif t.procedure == "turntable":
        np.testing.assert_array_equal(truth["pose"], cell.turntable.T_parent_B)
        assert truth["parent"] == cell.turntable.parent
    else:
        name = CASES[case][2].get("frame", "part" if t.procedure == "workpiece" else "fixture")
        assert truth["name"] == name and truth["parent"] == cell.frames[name].parent
        np.testing.assert_array_equal(truth["pose"], cell.frames[name].pose)


@pytest.mark.parametrize("case", CASES)
def test_calibration_recovers_the_truth(case):
    cell, t = simulated(case, NOISE)
    q, e, table, roles = si_columns(t)
    if t.procedure == "tcp":
        F = cell.robot.fk(q, tool=np.eye(4))
        r = np.array(roles)
        res = calibrate_tool(F[r == "tcp"], F[r == "-x"], F[r == "xy"], sigma=NOISE)
        assert_pose_within(res.values["T_F_TCP"], t.truth["T_F_TCP"],
                           res.sigma["T_F_TCP_position"], res.sigma["T_F_TCP_rotation"])
        # The reference point: the design's point in the robot base.
        np.testing.assert_allclose(res.values["pivot"], TCP["point"], rtol=0, atol=5 * NOISE)
    elif t.procedure == "track":
        f = cell.fk(q, e, tool=t.tool, frame="robot")[:, :3, 3]
        refs = [[float(v) * 1e-3 for v in o.split("=", 1)[1].split(",")] for o in t.options]
        res = calibrate_track(e, f, references=refs, point=[int(p) - 1 for p in roles],
                              sigma=NOISE)
        assert_pose_within(res.values["T_L_R"], t.truth["T_L_R"], res.sigma["T_L_R_position"],
                           res.sigma["T_L_R_rotation"])
        assert abs(res.values["scale"] - t.truth["scale"]) <= 4 * res.sigma["scale"]
    elif t.procedure == "turntable":
        # Touches in the frame the table is fixed in; --height in mm.
        f = cell.fk(q, e, tool=t.tool, frame=t.truth["parent"])[:, :3, 3]
        height = float(t.options[0].split("=", 1)[1]) * 1e-3
        res = calibrate_turntable(table, f, height=height, sigma=NOISE)
        assert_pose_within(res.values["T_R_B"], t.truth["pose"], res.sigma["T_R_B_position"],
                           res.sigma["T_R_B_rotation"])
        assert abs(res.values["radius"] - t.truth["radius"]) <= 4 * res.sigma["radius"]
    elif t.procedure == "workpiece":
        tt = cell.turntable
        f = cell.fk(q, e, tool=t.tool, frame=tt.parent)[:, :3, 3]
        res = calibrate_workpiece(table, f, roles, tt.T_parent_B, sigma=NOISE)
        assert_pose_within(res.values["T_B_W"], t.truth["pose"], res.sigma["T_B_W_position"],
                           res.sigma["T_B_W_rotation"])
    elif t.procedure == "frame":
        f = cell.fk(q, e, tool=t.tool, frame=t.truth["parent"])[:, :3, 3]
        res = frame_3point(f, roles, NOISE)
        assert_pose_within(res.values["T_R_W"], t.truth["pose"], res.sigma["T_R_W_position"],
                           res.sigma["T_R_W_rotation"])
    # The residuals show touch-up errors of the simulated size (estimated from a few touches).
    assert res.noise_source == "prior"
    assert 0.3 * NOISE < res.residual_sigma < 3 * NOISE


# -- 7. refusals ----------------------------------------------------------------------------------
def test_refuses_unknown_procedure_and_bad_noise():
    cell = fixed_cell()
    with pytest.raises(InputError, match=r"unknown procedure 'dh'; choose from tcp, frame, track"):
        simulate(cell, "dh")
    assert set(PROCEDURES) == {"tcp", "frame", "track", "turntable", "workpiece", "positioner"}
    for noise in (-1e-4, math.nan, math.inf):
        with pytest.raises(InputError, match=r"noise must be a finite number >= 0 \(m\)"):
            simulate(cell, "tcp", noise=noise)


def test_refuses_unknown_or_ambiguous_tool():
    cell = fixed_cell()
    with pytest.raises(InputError, match=r"unknown tool 'gripper'; the cell has: torch"):
        simulate(cell, "frame", tool="gripper")
    with pytest.raises(InputError, match=r"unknown tool 'gripper'; the cell has: torch"):
        simulate(cell, "tcp", tool="gripper")
    two = fixed_cell(tools={"torch": Tool(TORCH), "gripper": Tool(pose([0, 0, 200], [0, 0, 0]))})
    for procedure in ("tcp", "frame", "turntable", "workpiece"):
        with pytest.raises(InputError, match=r"say which tool touches \(the cell has: gripper, torch\)"):
            simulate(two, procedure)
    t = simulate(two, "tcp", noise=0.0, tool="gripper")
    np.testing.assert_array_equal(t.truth["T_F_TCP"], two.tools["gripper"].T_F_TCP)
    none = Cell(robot=ROBOT, robot_model="kuka_kr16", frames={"fix": Frame(pose([900, 0, 200], [0, 0, 0]))})
    with pytest.raises(InputError, match=r"say which tool touches \(the cell has: none\)"):
        simulate(none, "frame")


def test_refuses_unknown_ambiguous_or_misplaced_frame():
    cell = track_cell()
    with pytest.raises(InputError, match=r"unknown frame 'nope'; the cell has: fixture, cam, part"):
        simulate(cell, "frame", frame="nope")
    with pytest.raises(InputError, match=r"unknown frame 'nope'"):
        simulate(cell, "workpiece", frame="nope")
    with pytest.raises(InputError, match=r"say which fixed frame to touch \(the cell has: fixture, cam\)"):
        simulate(cell, "frame")
    with pytest.raises(InputError, match=r"frame 'part' is carried by turntable; the fixed procedure "
                                         r"touches frames carried by world or robot"):
        simulate(cell, "frame", frame="part")
    with pytest.raises(InputError, match=r"frame 'fixture' is carried by world; the workpiece "
                                         r"procedure touches frames carried by turntable"):
        simulate(cell, "workpiece", frame="fixture")
    bare = fixed_cell()
    bare.frames = {}
    with pytest.raises(InputError, match=r"say which workpiece frame to touch \(the cell has: none\)"):
        simulate(bare, "workpiece")
    with pytest.raises(InputError, match=r"say which fixed frame to touch \(the cell has: none\)"):
        simulate(bare, "frame")


def test_refuses_procedures_the_cell_lacks_the_axis_for():
    cell = fixed_cell()
    with pytest.raises(InputError, match=r"^the cell has no track$"):
        simulate(cell, "track")
    plain = Cell(robot=ROBOT, robot_model="kuka_kr16", tools={"torch": Tool(TORCH)})
    for procedure in ("turntable", "workpiece"):
        with pytest.raises(InputError, match=r"^the cell has no turntable$"):
            simulate(plain, procedure)


def test_refuses_track_positions():
    cell = track_cell()
    with pytest.raises(InputError, match=r"the track procedure moves the track itself; do not give "
                                         r"a track position"):
        simulate(cell, "track", track=1.0)
    for e in (6.5, -0.1):
        with pytest.raises(InputError, match=rf"track position {e * 1e3:g} mm is outside the track "
                                             r"limits 0 \.\. 6000 mm"):
            simulate(cell, "frame", frame="fixture", track=e)
    with pytest.raises(InputError, match=r"the cell has no track; do not give a track position"):
        simulate(fixed_cell(), "tcp", track=1.0)
    simulate(fixed_cell(), "tcp", noise=0.0, track=0.0)  # position 0 is where a fixed robot stands
    endless = track_cell(track=Track(axis="x"))
    with pytest.raises(InputError, match=r"the cell's track has no limits \(min, max\), so the "
                                         r"simulation cannot choose where the robot stands"):
        simulate(endless, "tcp")
    with pytest.raises(InputError, match=r"the cell's track has no limits \(min, max\); the "
                                         r"simulation needs them"):
        simulate(endless, "track")
    sideways = track_cell(track=Track(axis="y", lower=0.0, upper=6.0))
    with pytest.raises(InputError, match=r"the track calibration supports track axes x and z; this "
                                         r"track moves along y"):
        simulate(sideways, "track")


def test_refuses_bad_track_design():
    cell = track_cell()
    with pytest.raises(InputError, match=r"each reference point needs at least 2 track positions, got 1"):
        simulate(cell, "track", positions=1)
    with pytest.raises(InputError, match=r"reference points must have shape \(K, 3\) \(m, in L\), "
                                         r"got \(1, 2\)"):
        simulate(cell, "track", references=[1.0, 0.9])
    with pytest.raises(InputError, match=r"reference point 2 is beyond the end of the track"):
        simulate(cell, "track", references=[[2.0, 0.9, 0.2], [8.0, 0.9, 0.2]])


def test_refuses_unreachable_touches():
    with pytest.raises(InputError, match=r"touch\(es\) touch 1 \(tcp\), .* cannot be reached within "
                                         r"the joint limits from any track position"):
        simulate(track_cell(), "tcp", point=(5.0, 0.0, 0.25))
    with pytest.raises(InputError, match=r"touch\(es\) touch 1 \(tcp\), .* cannot be reached within "
                                         r"the joint limits from this robot position"):
        simulate(fixed_cell(), "tcp", point=(5.0, 0.0, 0.25))
    with pytest.raises(InputError, match=r"cannot be reached within the joint limits from this "
                                         r"robot position"):
        simulate(track_cell(), "frame", frame="fixture", track=6.0)
    # A touch-up error that throws the TCP out of reach.
    with pytest.raises(InputError, match=r"sit at a joint limit: the touch-up error moves them "
                                         r"outside"):
        simulate(fixed_cell(), "tcp", noise=2.0, seed=1)


def test_refuses_unknown_design_keyword():
    cell = fixed_cell()
    with pytest.raises(InputError, match=r"^tcp: got an unexpected keyword argument 'colour'$"):
        simulate(cell, "tcp", colour=1)
    with pytest.raises(InputError, match=r"^frame: got an unexpected keyword argument 'radius'$"):
        simulate(cell, "frame", radius=0.3)


def test_refuses_bad_tcp_design():
    cell = fixed_cell()
    with pytest.raises(InputError, match=r"the TCP needs at least 3 touches of the reference point, got 2"):
        simulate(cell, "tcp", touches=2)
    for tilt_deg in (0.0, 90.0, -10.0, 120.0):
        with pytest.raises(InputError, match=rf"tilt must be between 0 and 90 deg, got {tilt_deg:g} deg"):
            simulate(cell, "tcp", tilt=math.radians(tilt_deg))


def test_refuses_bad_three_point_and_turntable_design():
    cell = fixed_cell()
    for procedure in ("frame", "workpiece"):
        with pytest.raises(InputError, match=r"size must be positive \(m\), got -0.1"):
            simulate(cell, procedure, size=-0.1)
        with pytest.raises(InputError, match=r"repeats must be at least 1, got 0"):
            simulate(cell, procedure, repeats=0)
    with pytest.raises(InputError, match=r"radius must be positive \(m\), got 0"):
        simulate(cell, "turntable", radius=0)


def test_refuses_table_angles():
    cell = fixed_cell()  # turntable limits -180 .. 180 deg
    with pytest.raises(InputError, match=re.escape("table angle(s) 229.183 deg are outside the "
                                                   "turntable limits")):
        simulate(cell, "turntable", angles=[0.0, 0.5, 4.0])
    with pytest.raises(InputError, match=re.escape("table angle(s) -200, 190 deg are outside")):
        simulate(cell, "workpiece", angles=np.radians([-200.0, 0, 0, 190.0, 0, 0]))
    with pytest.raises(InputError, match=r"table angles must be a list of finite numbers \(rad\)"):
        simulate(cell, "turntable", angles=[0.0, math.nan, 1.0])
    with pytest.raises(InputError, match=r"give one table angle per touch \(6\), got 3"):
        simulate(cell, "workpiece", angles=[0.0, 0.5, 1.0])
