"""One turntable, two robots: their calibrations of it compared through the robot-to-robot pose,
and all their touches in one fit.

Each trial draws the touch errors and both tools' errors anew. Robot r1 (reference) and r2 both
touch four fixed common points (tool pointing down, turned a little) and one point on the table
at six angles, each from its own side with the tool turned by a fixed angle (so a tool's error
moves its table touches otherwise than its touches of the common points).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell.calibration.robottorobot import RobotTouches, robot_to_robot
from robotcell.calibration.sharedtable import compare_shared, shared_turntable
from robotcell.calibration.turntable import calibrate_turntable
from robotcell.errors import InputError
from robotcell.kinematics.transforms import invert, make_pose, rot_z, transform_points

NOISE = 1e-4
TOOL_SIGMA = 2e-4
TRIALS = 200
T_R2 = make_pose(Rotation.from_euler("z", 180, degrees=True).as_matrix(), [1.6, 0.1, 0.0])
T_B = make_pose(Rotation.from_euler("xz", [1.0, 30.0], degrees=True).as_matrix(), [0.8, 0.9, 0.2])
RADIUS = 0.3
COMMON = np.array([[0.8, 0.4, 0.35], [0.75, -0.3, 0.3], [0.95, 0.05, 0.6], [0.7, 0.0, 0.45]])
ANGLES = np.radians(np.arange(0.0, 360.0, 60.0))
TOOLS = {"r1": np.array([0.0, 0.0, 0.2]), "r2": np.array([0.05, 0.0, 0.18])}


def _down(yaw: np.ndarray) -> np.ndarray:
    """Flange rotations, tool pointing down, turned by ``yaw`` (N,) about the vertical."""
    return rot_z(yaw) @ Rotation.from_euler("y", 180, degrees=True).as_matrix()


def _touch(name: str, T_w_R: np.ndarray, p_w: np.ndarray, yaw: np.ndarray,
           tool_error: np.ndarray, rng: np.random.Generator, names: list[str]) -> RobotTouches:
    """Touches of world points by robot ``name``: the true TCP at the point plus the touch
    error; the controller computes it with the nominal tool (the truth minus ``tool_error``)."""
    R = _down(yaw)
    p_R = transform_points(invert(T_w_R), p_w + rng.normal(0.0, NOISE, p_w.shape))
    F = make_pose(R, p_R - R @ TOOLS[name])
    return RobotTouches.from_flange(F, TOOLS[name] - tool_error, names, robot=name,
                                    tool_sigma=np.eye(3) * TOOL_SIGMA**2)


def _trial(rng: np.random.Generator, r2_tool_error: np.ndarray | None = None) -> dict:
    """One cell calibrated three ways: each robot's turntable alone, the link alone, and all
    touches together."""
    err = {n: rng.normal(0.0, TOOL_SIGMA, 3) for n in TOOLS}
    if r2_tool_error is not None:
        err["r2"] = r2_tool_error
    table_w = transform_points(T_B @ make_pose(rot_z(ANGLES)), np.array([RADIUS, 0.0, 0.0]))
    out: dict = {}
    for name, T, yaw in (("r1", np.eye(4), np.pi / 2), ("r2", T_R2, -np.pi / 3)):
        out[name + " table"] = _touch(name, T, table_w, np.full(len(ANGLES), yaw), err[name], rng,
                                      ["table"] * len(ANGLES))
        out[name + " points"] = _touch(name, T, np.repeat(COMMON, 2, axis=0),
                                       np.radians(rng.uniform(-10, 10, 2 * len(COMMON))),
                                       err[name], rng, [f"P{i // 2 + 1}" for i in range(8)])
    for name in TOOLS:
        t = out[name + " table"]
        out[name + " turntable"] = calibrate_turntable(ANGLES, t.points, sigma=NOISE,
                                                       inputs=t.inputs)
    out["link"] = robot_to_robot(out["r1 points"], out["r2 points"], sigma=NOISE)
    out["joint"] = shared_turntable(out["r1 table"], ANGLES, out["r2 table"], ANGLES,
                                    common=(out["r1 points"], out["r2 points"]), sigma=NOISE)
    out["agreement"] = compare_shared(out["r1 turntable"], out["r2 turntable"], out["link"],
                                      names=("r1", "r2"))
    return out


def _error(T_true: np.ndarray, T: np.ndarray) -> np.ndarray:
    d = Rotation.from_matrix(T_true[:3, :3] @ T[:3, :3].T).as_rotvec()
    return np.concatenate([T_true[:3, 3] - T[:3, 3], d])


def test_consistent_calibrations_agree_and_the_joint_fit_is_honest() -> None:
    rng = np.random.default_rng(21)
    z_link, z_table, z_diff, agree, good, far = [], [], [], [], [], []
    for _ in range(TRIALS):
        t = _trial(rng)
        j = t["joint"]
        sig = np.sqrt(np.diag(j.covariance))
        z_link.append(_error(T_R2, j.values["T_ref_other"]) / sig[:6])
        z_table.append(_error(T_B, j.values["T_ref_B"]) / sig[6:12])
        a = t["agreement"]
        z_diff.append(a.difference / a.sigma)
        agree.append(a.agree)
        good.append(j.verdict.level == "good")
        far.append(good[-1] and max(np.abs(z_link[-1]).max(), np.abs(z_table[-1]).max()) > 4)
    for z in (z_link, z_table, z_diff):
        spread = np.std(z, axis=0)
        assert np.all((spread > 0.8) & (spread < 1.25)), spread
    assert np.mean(agree) > 0.98
    assert np.mean(good) > 0.5 and np.sum(far) < 0.01 * np.sum(good)


def test_the_joint_fit_is_at_least_as_good_as_either_alone() -> None:
    t = _trial(np.random.default_rng(4))
    j = np.sqrt(np.diag(t["joint"].covariance))
    link = np.sqrt(np.diag(t["link"].covariance))
    table = np.sqrt(np.diag(t["r1 turntable"].covariance))[:6]
    assert np.all(j[:6] <= link * (1 + 1e-9))
    assert np.all(j[6:12] <= table * (1 + 1e-9))
    assert np.all(j[:3] < link[:3])  # the table touches measure the link too
    assert t["joint"].verdict.level == "good", t["joint"].verdict.reasons


def test_a_2mm_error_of_one_robots_tool_is_named() -> None:
    t = _trial(np.random.default_rng(8), r2_tool_error=np.array([0.002, 0.0, 0.0]))
    a = t["agreement"]
    assert not a.agree
    assert a.message.startswith("r1's and r2's calibrations of the turntable disagree")
    assert "sigma)" in a.message and "check each robot's tool" in a.message
    assert a.to_json()["agree"] is False


def test_consistent_pair_says_it_agrees() -> None:
    a = _trial(np.random.default_rng(9))["agreement"]
    assert a.agree and "agree within 3 sigma" in a.message


def test_joint_fit_refuses_angles_that_do_not_match_the_touches() -> None:
    t = _trial(np.random.default_rng(1))
    with pytest.raises(InputError, match="one table angle per touch of each robot"):
        shared_turntable(t["r1 table"], ANGLES[:3], t["r2 table"], ANGLES)
