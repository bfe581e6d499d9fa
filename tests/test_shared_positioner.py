"""One 2-axis positioner, two robots: their calibrations of it compared through the robot-to-robot
pose, and all their touches in one fit.

The geometry is the packaged two-robot demo cell's: the KUKA KR 16 on its track (at 1 m) and the
ABB IRB 2400 beside the tilt-rotate positioner DKP_2. Each trial draws the touch errors and both
tools' errors anew. Each robot touches its own point on the plate at 3 tilt by 4 rotate values,
with its tool turned by a fixed angle, and four fixed common points (tool pointing down, turned
a little), so a tool's error moves its positioner touches otherwise than its touches of the
common points.
"""

from __future__ import annotations

from importlib import resources

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell.calibration.robottorobot import RobotTouches, robot_to_robot
from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.identification import calibrate_positioner
from robotcell.identification.sharedpositioner import (
    COMPONENTS,
    compare_positioner,
    positioner_lines,
    shared_positioner,
)
from robotcell.kinematics.transforms import invert, make_pose, rot_z, transform_points

NOISE = 1e-4
TOOL_SIGMA = 2e-4
TRIALS = 200
CELL = Cell.load(str(resources.files("robotcell.demo").joinpath("two_robots_cell.yaml")))
CHAIN = CELL.turntable.chain                       # root in the world, plate as its flange
BASES = {"kuka": CELL.for_robot("kuka").frame_pose("robot", track=1.0),
         "abb": CELL.for_robot("abb").frame_pose("robot", track=0.0)}
T_LINK = invert(BASES["kuka"]) @ BASES["abb"]      # the ABB's base in the KUKA's
PLATE_POINTS = {"kuka": np.array([0.2, 0.0, 0.0]), "abb": np.array([-0.12, 0.15, 0.0])}
VALUES = np.stack(np.meshgrid(np.radians([-30.0, 0.0, 30.0]),
                              np.radians([0.0, 90.0, 180.0, 270.0]), indexing="ij"),
                  axis=-1).reshape(-1, 2)
COMMON = transform_points(BASES["kuka"], np.array(
    [[0.3, 1.0, 0.3], [1.3, 0.9, 0.35], [0.8, 1.6, 0.6], [0.6, 1.3, 0.1]]))  # world (m)
TOOLS = {"kuka": np.array([0.0, 0.0, 0.2]), "abb": np.array([0.05, 0.0, 0.18])}
YAW = {"kuka": np.pi / 2, "abb": -np.pi / 3}


def _nominal(name: str):
    """The positioner chain in robot ``name``'s base."""
    return CHAIN.with_base(invert(BASES[name]) @ CHAIN.base)


NOMINAL = (_nominal("kuka"), _nominal("abb"))


def _plate(name: str) -> np.ndarray:
    """Robot ``name``'s point on the plate at every axis value of the grid, world (N, 3)."""
    return transform_points(CHAIN.fk(VALUES), PLATE_POINTS[name])


def _touch(name: str, p_w: np.ndarray, yaw: np.ndarray, tool_error: np.ndarray,
           rng: np.random.Generator, names: list[str]) -> RobotTouches:
    """Touches of world points by robot ``name``: the true TCP at the point plus the touch
    error; the controller computes it with the nominal tool (the truth minus ``tool_error``)."""
    R = rot_z(yaw) @ Rotation.from_euler("y", 180, degrees=True).as_matrix()
    p_R = transform_points(invert(BASES[name]), p_w + rng.normal(0.0, NOISE, p_w.shape))
    F = make_pose(R, p_R - R @ TOOLS[name])
    return RobotTouches.from_flange(F, TOOLS[name] - tool_error, names, robot=name,
                                    tool_sigma=np.eye(3) * TOOL_SIGMA**2)


def _trial(rng: np.random.Generator, abb_tool_error: np.ndarray | None = None) -> dict:
    """One cell calibrated three ways: each robot's positioner alone, the link alone, and all
    touches together."""
    err = {n: rng.normal(0.0, TOOL_SIGMA, 3) for n in TOOLS}
    if abb_tool_error is not None:
        err["abb"] = abb_tool_error
    out: dict = {}
    for name in TOOLS:
        n = len(VALUES)
        out[name + " plate"] = _touch(name, _plate(name), np.full(n, YAW[name]), err[name], rng,
                                      ["plate"] * n)
        out[name + " points"] = _touch(name, np.repeat(COMMON, 2, axis=0),
                                       np.radians(rng.uniform(-10, 10, 2 * len(COMMON))),
                                       err[name], rng, [f"P{i // 2 + 1}" for i in range(8)])
    cals = [calibrate_positioner(VALUES, out[name + " plate"].points, nominal=NOMINAL[k],
                                 sigma=NOISE, inputs=out[name + " plate"].inputs)
            for k, name in enumerate(TOOLS)]
    for name, cal in zip(TOOLS, cals, strict=True):
        out[name + " positioner"] = cal.result
    out["link"] = robot_to_robot(out["kuka points"], out["abb points"], sigma=NOISE)
    out["joint"] = shared_positioner(out["kuka plate"], VALUES, out["abb plate"], VALUES,
                                     common=(out["kuka points"], out["abb points"]), sigma=NOISE,
                                     start=(cals[0], cals[1]))
    out["agreement"] = compare_positioner(out["kuka positioner"], out["abb positioner"],
                                          out["link"], names=("kuka", "abb"))
    return out


def _truth() -> np.ndarray:
    """The true 8 numbers of the positioner in the KUKA's base, as the calibration writes them."""
    exact = transform_points(invert(BASES["kuka"]), _plate("kuka"))
    lines = positioner_lines(calibrate_positioner(VALUES, exact, nominal=NOMINAL[0],
                                                  sigma=NOISE).result)
    return lines.T_B, np.array([lines.offset, lines.angle])


T_B_TRUE, AXES_TRUE = _truth()


def _error(T_true: np.ndarray, T: np.ndarray) -> np.ndarray:
    d = Rotation.from_matrix(T_true[:3, :3] @ T[:3, :3].T).as_rotvec()
    return np.concatenate([T_true[:3, 3] - T[:3, 3], d])


def test_consistent_calibrations_agree_and_the_joint_fit_is_honest() -> None:
    rng = np.random.default_rng(31)
    z_link, z_root, z_axes, z_diff, agree, good, far = [], [], [], [], [], [], []
    for _ in range(TRIALS):
        t = _trial(rng)
        j = t["joint"]
        sig = np.sqrt(np.diag(j.covariance))
        z_link.append(_error(T_LINK, j.values["T_ref_other"]) / sig[:6])
        z_root.append(_error(T_B_TRUE, j.values["T_ref_B"]) / sig[6:12])
        z_axes.append((AXES_TRUE - [j.values["axis_offset"], j.values["axis_angle"]])
                      / sig[12:14])
        a = t["agreement"]
        z_diff.append(a.difference / a.sigma)
        agree.append(a.agree)
        good.append(j.verdict.level == "good")
        worst = max(np.abs(z_link[-1]).max(), np.abs(z_root[-1]).max(), np.abs(z_axes[-1]).max())
        far.append(good[-1] and worst > 4)
    for z in (z_link, z_root, z_axes, z_diff):
        spread = np.std(z, axis=0)
        assert np.all((spread > 0.8) & (spread < 1.25)), spread
    assert np.mean(agree) > 0.98
    assert np.mean(good) > 0.5 and np.sum(far) < 0.01 * np.sum(good)


def test_the_joint_fit_is_at_least_as_good_as_either_alone() -> None:
    t = _trial(np.random.default_rng(4))
    j = np.sqrt(np.diag(t["joint"].covariance))
    link = np.sqrt(np.diag(t["link"].covariance))
    for k, name in enumerate(("kuka", "abb")):
        alone = positioner_lines(t[f"{name} positioner"]).sources
        assert alone is not None
        if k == 0:  # the KUKA's calibration is in the reference base, as the joint fit's
            assert np.all(j[6:14] <= alone.sigma * (1 + 1e-6))
        else:  # the distance and the angle between the axes are the same in every base
            assert np.all(j[12:14] <= alone.sigma[6:8] * (1 + 1e-6))
    assert np.all(j[:6] <= link * (1 + 1e-6))
    assert np.all(j[:3] < link[:3])  # the positioner touches measure the link too
    assert t["joint"].verdict.level == "good", t["joint"].verdict.reasons
    # error at the noise floor: the root within 4 sigma, its 1-sigma a few tenths of a mm
    assert np.all(np.abs(_error(T_B_TRUE, t["joint"].values["T_ref_B"])) <= 4 * j[6:12])
    assert np.all(j[6:9] < 3 * NOISE)


def test_the_positioner_alone_places_the_other_robot() -> None:
    """Two skew axis lines seen by both robots fix the pose between their bases."""
    t = _trial(np.random.default_rng(6))
    j = shared_positioner(t["kuka plate"], VALUES, t["abb plate"], VALUES, sigma=NOISE,
                          nominal=NOMINAL)
    sig = np.sqrt(np.diag(j.covariance))
    assert np.all(np.abs(_error(T_LINK, j.values["T_ref_other"])) <= 4 * sig[:6])
    assert j.verdict.level == "good", j.verdict.reasons


def test_a_2mm_error_of_one_robots_tool_is_named() -> None:
    t = _trial(np.random.default_rng(8), abb_tool_error=np.array([0.002, 0.0, 0.0]))
    a = t["agreement"]
    assert not a.agree
    assert a.message.startswith("kuka's and abb's calibrations of the positioner disagree")
    assert " mm (" in a.message and " sigma)" in a.message
    assert "check each robot's tool" in a.message
    data = a.to_json()
    assert data["agree"] is False and data["components"] == list(COMPONENTS)
    assert len(data["difference_mm"]) == 4 and len(data["difference_deg"]) == 4
    assert t["joint"].verdict.level != "good"


def test_consistent_pair_says_it_agrees() -> None:
    a = _trial(np.random.default_rng(9))["agreement"]
    assert a.agree and "positioner agree within 3 sigma" in a.message


def test_joint_fit_refuses_values_that_do_not_match_the_touches() -> None:
    t = _trial(np.random.default_rng(1))
    with pytest.raises(InputError, match=r"abb: give the tilt and rotate values \(rad\) of each "
                                         r"touch, shape \(12, 2\)"):
        shared_positioner(t["kuka plate"], VALUES, t["abb plate"], VALUES[:, :1])


def test_comparison_refuses_a_result_that_is_not_a_positioner() -> None:
    t = _trial(np.random.default_rng(2))
    with pytest.raises(InputError, match="a robot-to-robot result is not a 2-axis positioner "
                                         "calibration"):
        compare_positioner(t["link"], t["abb positioner"], t["link"])


def test_starts_written_with_opposite_normals_give_the_same_fit() -> None:
    """Without its nominal chain the other robot's calibration writes X_B the other way round;
    the joint fit turns it and ends where it ends from both nominal chains."""
    t = _trial(np.random.default_rng(12))
    j = shared_positioner(t["kuka plate"], VALUES, t["abb plate"], VALUES,
                          common=(t["kuka points"], t["abb points"]), sigma=NOISE,
                          nominal=(NOMINAL[0], None))
    for key in ("T_ref_other", "T_ref_B"):
        assert np.allclose(j.values[key], t["joint"].values[key], atol=1e-7)
    assert j.values["axis_angle"] == pytest.approx(t["joint"].values["axis_angle"], abs=1e-7)


def test_comparison_refuses_calibrations_written_with_opposite_normals() -> None:
    t = _trial(np.random.default_rng(13))
    abb = t["abb plate"]
    other = calibrate_positioner(VALUES, abb.points, sigma=NOISE, inputs=abb.inputs).result
    with pytest.raises(InputError, match="opposite X_B \\(common normal\\) directions; calibrate "
                                         "both with the same nominal positioner"):
        compare_positioner(t["kuka positioner"], other, t["link"])
