"""Robot to robot: the pose of one robot's base relative to another's, simulated cells.

Arms of different makers from the library (KUKA KR 16, ABB IRB 2400, FANUC M-20iA, the last on a
linear track represented by its known offset) touch common points with tools whose errors are
drawn anew in every trial; the estimate recovers the true pose to the noise floor and its
1-sigma, tools included, says how far it is off.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell.calibration.robottorobot import MAX_DISTANCE, RobotTouches, robot_to_robot
from robotcell.errors import IllPosedError, InputError
from robotcell.kinematics.transforms import invert, make_pose, transform_points
from robotcell.robot.models import load_robot
from robotcell.studies.robottorobot import SimulatedRobot, flange_poses, touch_design

NOISE = 1e-4        # touch error, m per coordinate
TOOL_SIGMA = 2e-4   # each tool's TCP error, m per coordinate
TRACK_SIGMA = (2e-4, np.radians(0.01))  # the track's T_L_R0: m, rad per axis
TRIALS = 200
POINTS = np.array([[0.8, 0.4, 0.35], [0.75, -0.3, 0.3], [0.95, 0.05, 0.6], [0.85, 0.4, 0.65],
                   [0.7, 0.0, 0.45]])


def _pose(x: float, y: float, z: float, deg: float) -> np.ndarray:
    return make_pose(Rotation.from_euler("z", deg, degrees=True).as_matrix(), [x, y, z])


@cache
def _cell() -> tuple[list[SimulatedRobot], list]:
    """Three robots of three makers, the FANUC on a track along X of its track frame; the
    design (orientation, track position) of each touching every common point twice."""
    robots = [
        SimulatedRobot(load_robot("kuka_kr16"), np.eye(4), _pose(0, 0, 0.2, 0), "r1"),
        SimulatedRobot(load_robot("abb_irb2400"), _pose(1.6, 0.1, 0.0, 180),
                       _pose(0.05, 0.0, 0.18, 0), "r2"),
        SimulatedRobot(load_robot("fanuc_m20ia"), _pose(0.0, 1.5, 0.0, -90), _pose(0, 0, 0.2, 0),
                       "r3", axis=np.array([1.0, 0.0, 0.0])),
    ]
    points = np.repeat(POINTS, 2, axis=0)
    return robots, [touch_design(r, points) for r in robots]


def _touches(robot: SimulatedRobot, design, rng: np.random.Generator, *, tools: bool = True,
             points: np.ndarray | None = None) -> RobotTouches:
    """One robot's touches with a fresh touch error and a fresh error of its tool (and track):
    the controller computes the TCP with the nominal tool, the truth minus that error."""
    p = np.repeat(POINTS, 2, axis=0) if points is None else points
    F = flange_poses(robot, design, p, rng.normal(0.0, NOISE, p.shape))
    nominal = robot.tool[:3, 3] - rng.normal(0.0, TOOL_SIGMA, 3)
    names = [f"P{i // 2 + 1}" for i in range(len(p))]
    base = robot.at(design.track)
    base_sigma = None
    if robot.axis is not None:  # the track's zero offset T_L_R0 is known to its own accuracy
        d = np.concatenate([rng.normal(0.0, TRACK_SIGMA[0], 3), rng.normal(0.0, TRACK_SIGMA[1], 3)])
        base = make_pose(Rotation.from_rotvec(-d[3:]).as_matrix(), base[:, :3, 3] - d[:3])
        base_sigma = np.diag(np.repeat(np.square(TRACK_SIGMA), 3)) if tools else None
    return RobotTouches.from_flange(F, nominal, names, robot=robot.name, base=base,
                                    tool_sigma=np.eye(3) * TOOL_SIGMA**2 if tools else None,
                                    base_sigma=base_sigma)


def _error(T_true: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Position error (m) and rotation vector ``d`` with ``R_true = exp([d]x) R`` (rad)."""
    d = Rotation.from_matrix(T_true[:3, :3] @ T[:3, :3].T).as_rotvec()
    return np.concatenate([T_true[:3, 3] - T[:3, 3], d])


def _monte_carlo(other: int, seed: int, tools: bool = True, trials: int = TRIALS
                 ) -> tuple[np.ndarray, np.ndarray]:
    """(error / 1-sigma) per component and trial, and whether each result was GOOD."""
    robots, designs = _cell()
    rng = np.random.default_rng(seed)
    T_true = invert(robots[0].base) @ robots[other].base
    z, good = [], []
    for _ in range(trials):
        ref = _touches(robots[0], designs[0], rng, tools=tools)
        oth = _touches(robots[other], designs[other], rng, tools=tools)
        r = robot_to_robot(ref, oth, sigma=NOISE)
        z.append(_error(T_true, r.values["T_ref_other"]) / np.sqrt(np.diag(r.covariance)))
        good.append(r.verdict.level == "good")
    return np.array(z), np.array(good)


@pytest.mark.parametrize("other", [1, 2], ids=["abb-beside-kuka", "fanuc-on-track"])
def test_monte_carlo_sigma_is_honest_with_the_tools_errors(other: int) -> None:
    z, good = _monte_carlo(other, seed=10 + other)
    spread = z.std(axis=0)
    assert np.all((spread > 0.8) & (spread < 1.25)), spread
    assert good.mean() > 0.5
    far = np.any(np.abs(z[good]) > 4.0, axis=1)
    assert far.mean() < 0.01


def test_leaving_the_tools_out_understates_the_sigma() -> None:
    z, _ = _monte_carlo(1, seed=3, tools=False, trials=60)
    assert z.std(axis=0).max() > 1.5


def test_three_robots_recovered_to_the_noise_floor() -> None:
    robots, designs = _cell()
    rng = np.random.default_rng(7)
    ref = _touches(robots[0], designs[0], rng)
    for k in (1, 2):
        r = robot_to_robot(ref, _touches(robots[k], designs[k], rng), sigma=NOISE)
        T_true = invert(robots[0].base) @ robots[k].base
        err = _error(T_true, r.values["T_ref_other"])
        sig = np.sqrt(np.diag(r.covariance))
        assert np.all(np.abs(err) < 4 * sig)
        assert np.linalg.norm(err[:3]) < 2e-3 and np.degrees(np.linalg.norm(err[3:])) < 0.1
        parts = r.to_json()["sigma_parts"]["T_ref_other"]
        assert parts["own"]["sources"] == [] and "r1 tool" in parts["recorded"]["sources"]
        assert r.verdict.level == "good", r.verdict.reasons


def test_pointer_held_by_the_reference_robot() -> None:
    """Method B: r1 holds a pointer at the points' places, r2 touches its tip."""
    robots, designs = _cell()
    rng = np.random.default_rng(5)
    ref = _touches(robots[0], designs[0], rng)
    r = robot_to_robot(ref, _touches(robots[1], designs[1], rng), sigma=NOISE, method="pointer")
    err = _error(invert(robots[0].base) @ robots[1].base, r.values["T_ref_other"])
    assert np.all(np.abs(err) < 4 * np.sqrt(np.diag(r.covariance)))
    assert r.to_json()["method"] == "pointer"


def _plain(points: np.ndarray, names: list[str], robot: str,
           T: np.ndarray | None = None) -> RobotTouches:
    p = points if T is None else transform_points(T, points)
    return RobotTouches(p, tuple(names), robot=robot)


def test_a_wrong_touch_is_named() -> None:
    rng = np.random.default_rng(2)
    T = _pose(1.5, 0.2, 0.0, 150)
    P = np.repeat(POINTS, 2, axis=0)
    names = [f"P{i // 2 + 1}" for i in range(len(P))]
    a = P + rng.normal(0, NOISE, P.shape)
    b = transform_points(invert(T), P) + rng.normal(0, NOISE, P.shape)
    b[3] += [0.005, 0.0, 0.0]
    r = robot_to_robot(_plain(a, names, "r1"), _plain(b, names, "r2"), sigma=NOISE)
    flagged = {r.labels[i] for i in r.excluded + r.outliers + r.disagreeing}
    assert "r2 touch 4 (P2)" in flagged
    assert r.verdict.level != "good"


def test_refuses_points_touched_by_one_robot_only() -> None:
    a = _plain(POINTS, ["P1", "P2", "P3", "P4", "P5"], "r1")
    b = _plain(POINTS[:4], ["P1", "P2", "P3", "P9"], "r2")
    with pytest.raises(InputError, match=r"touched by one robot only \(P4, P5 by r1 only; P9 by r2 "
                                         r"only\).*touch it with both robots"):
        robot_to_robot(a, b)


def test_refuses_fewer_than_three_common_points() -> None:
    a = _plain(POINTS[:2], ["P1", "P2"], "r1")
    with pytest.raises(IllPosedError, match=r"2 common point\(s\).*at least 3 points touched by "
                                            "both"):
        robot_to_robot(a, _plain(POINTS[:2], ["P1", "P2"], "r2"))


def test_refuses_three_collinear_common_points() -> None:
    line = np.array([[0.8, 0.0, 0.3], [1.0, 0.1, 0.3], [1.2, 0.2, 0.3]])
    names = ["P1", "P2", "P3"]
    with pytest.raises(IllPosedError, match="lie on one line.*rotation about that line is not "
                                            "determined; touch at least one more point"):
        robot_to_robot(_plain(line, names, "r1"), _plain(line, names, "r2", _pose(1, 0, 0, 90)))
    nearly = line + [[0, 0, 0], [0, 0, 0.002], [0, 0, 0]]  # 2 mm off a 450 mm line
    with pytest.raises(IllPosedError, match="lie on one line"):
        robot_to_robot(_plain(nearly, names, "r1"), _plain(nearly, names, "r2"))


def test_refuses_a_pose_beyond_any_real_cell() -> None:
    names = ["P1", "P2", "P3", "P4", "P5"]
    far = invert(_pose(MAX_DISTANCE + 10.0, 0.0, 0.0, 0))
    with pytest.raises(IllPosedError, match=r"60\.0 m from r1's, beyond any real cell \(at most "
                                            r"50 m\): check that the positions are in mm"):
        robot_to_robot(_plain(POINTS, names, "r1"), _plain(POINTS, names, "r2", far))


def test_refuses_mismatched_names_and_inputs() -> None:
    with pytest.raises(InputError, match="3 point names for 5 touches"):
        RobotTouches(POINTS, ("P1", "P2", "P3"), robot="r1")
    with pytest.raises(InputError, match="method must be 'common points' or 'pointer'"):
        robot_to_robot(_plain(POINTS, list("abcde"), "r1"), _plain(POINTS, list("abcde"), "r2"),
                       method="laser")
