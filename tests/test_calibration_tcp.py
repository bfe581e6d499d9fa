"""Tool calibration: XYZ N-point TCP, ABC 2-point and ABC World, on synthetic tools with noise."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell import IllPosedError, InputError
from robotcell.calibration import calibrate_tool
from robotcell.calibration.tcp import ABC_WORLD_6D

TCP = np.array([0.025, -0.012, 0.215])
PIVOT = np.array([0.95, 0.12, 0.31])
R_TOOL = Rotation.from_euler("ZYX", [15, 35, -5], degrees=True).as_matrix()
DOWN = Rotation.from_euler("y", 180, degrees=True)


def pose_for(R_RF, point_in_flange):
    """Flange pose with rotation R_RF that puts the flange point on the pivot."""
    T = np.eye(4)
    T[:3, :3] = R_RF
    T[:3, 3] = PIVOT - R_RF @ point_in_flange
    return T


def design(rng, n, tilt=0.6):
    return [(Rotation.from_rotvec(rng.normal(size=3) * tilt) * DOWN).as_matrix() for _ in range(n)]


def noisy(poses, rng, sigma):
    out = np.array(poses)
    out[:, :3, 3] += rng.normal(scale=sigma, size=(len(out), 3))
    return out


def angle_error(R_est, R_true):
    return Rotation.from_matrix(R_est @ R_true.T).as_rotvec()


def test_exact_data_recovers_tcp_pivot_and_orientation():
    rng = np.random.default_rng(10)
    touches = [pose_for(R, TCP) for R in design(rng, 4)]
    axis = [pose_for(design(rng, 1)[0], TCP + R_TOOL @ [-0.1, 0, 0])]
    plane = [pose_for(design(rng, 1)[0], TCP + R_TOOL @ [0.03, 0.08, 0])]
    r = calibrate_tool(touches, axis, plane)
    np.testing.assert_allclose(r.values["tcp"], TCP, atol=1e-10)
    np.testing.assert_allclose(r.values["pivot"], PIVOT, atol=1e-10)
    np.testing.assert_allclose(r.values["T_F_TCP"][:3, :3], R_TOOL, atol=1e-9)
    assert r.max < 1e-9 and r.undetermined == []
    j = r.to_json()
    np.testing.assert_allclose(j["tcp_mm"], TCP * 1e3, atol=1e-6)
    np.testing.assert_allclose(j["pivot_mm"], PIVOT * 1e3, atol=1e-6)
    assert len(j["xyzabc"]) == 6 and {"mean_mm", "min_mm", "max_mm"} <= set(j)


def test_tcp_without_orientation_lists_it_as_undetermined():
    rng = np.random.default_rng(11)
    r = calibrate_tool(noisy([pose_for(R, TCP) for R in design(rng, 5)], rng, 1e-4))
    assert "T_F_TCP" not in r.values and "tool orientation" in r.undetermined[0]
    assert r.dof == 15 - 6 and r.noise_source == "default" and r.noise_sigma == 0.5e-3
    assert r.residual_sigma < 3e-4  # the residuals' estimate, reported beside the accuracy
    assert r.condition < 100


def test_monte_carlo_sigma_agrees_with_spread():
    """Same touch design, new noise each trial: errors spread as the reported 1-sigma says."""
    rng = np.random.default_rng(12)
    Rs = design(rng, 8)
    Ra, Rp = design(rng, 2), design(rng, 2)
    sigma = 2e-4
    base = ([pose_for(R, TCP) for R in Rs],
            [pose_for(R, TCP + R_TOOL @ [-0.12, 0, 0]) for R in Ra],
            [pose_for(R, TCP + R_TOOL @ [0.02, 0.09, 0]) for R in Rp])
    err_t, err_c, err_r, s_t, s_c, s_r = [], [], [], [], [], []
    for _ in range(300):
        r = calibrate_tool(*(noisy(b, rng, sigma) for b in base), sigma=sigma)
        err_t.append(r.values["tcp"] - TCP)
        err_c.append(r.values["pivot"] - PIVOT)
        err_r.append(angle_error(r.values["T_F_TCP"][:3, :3], R_TOOL))
        s_t.append(r.sigma["tcp"])
        s_c.append(r.sigma["pivot"])
        s_r.append(r.sigma["T_F_TCP_rotation"])
    for err, s in ((err_t, s_t), (err_c, s_c), (err_r, s_r)):
        spread = np.sqrt(np.mean(np.square(err), axis=0))
        ratio = spread / np.mean(s, axis=0)
        assert np.all(np.abs(ratio - 1) < 0.25), ratio


def test_stated_sigma_used_when_given():
    rng = np.random.default_rng(13)
    touches = noisy([pose_for(R, TCP) for R in design(rng, 4)], rng, 1e-4)
    r = calibrate_tool(touches, sigma=5e-4)
    assert r.noise_source == "prior" and r.noise_sigma == 5e-4
    r2 = calibrate_tool(touches, sigma=1e-4)
    np.testing.assert_allclose(r.sigma["tcp"], 5 * r2.sigma["tcp"])


def test_outlier_touch_is_named():
    rng = np.random.default_rng(14)
    touches = noisy([pose_for(R, TCP) for R in design(rng, 10)], rng, 5e-5)
    touches[7, :3, 3] += [2e-3, 0, 0]
    r = calibrate_tool(touches, sigma=5e-5)
    assert any("touch 8 is an outlier" in w for w in r.warnings)
    # Singled out by the others, it is left out of the result, which says so.
    assert r.excluded == [7] and r.rms < 2e-4 and "left out" in r.summary()


def test_refuses_similar_orientations_and_single_axis_rotation():
    rng = np.random.default_rng(15)
    same = [pose_for(DOWN.as_matrix(), TCP) for _ in range(4)]
    same = noisy(same, rng, 1e-6)
    with pytest.raises(IllPosedError, match="orientations differing by at least 30-60 degrees about "
                                             "different axes"):
        calibrate_tool(same)
    about_z = [pose_for((Rotation.from_euler("z", a, degrees=True) * DOWN).as_matrix(), TCP)
               for a in (0, 60, 120, 180)]
    with pytest.raises(IllPosedError, match="too similar"):
        calibrate_tool(about_z)
    with pytest.raises(IllPosedError, match="at least 3"):
        calibrate_tool([pose_for(R, TCP) for R in design(rng, 2)])


def test_small_spread_warns():
    rng = np.random.default_rng(16)
    touches = noisy([pose_for(R, TCP) for R in design(rng, 6, tilt=0.12)], rng, 1e-5)
    r = calibrate_tool(touches)
    assert any("poorly determined" in w for w in r.warnings)


def test_abc_2point_refusals():
    rng = np.random.default_rng(17)
    touches = [pose_for(R, TCP) for R in design(rng, 4)]
    axis = [pose_for(design(rng, 1)[0], TCP + R_TOOL @ [-0.1, 0, 0])]
    with pytest.raises(IllPosedError, match="needs both"):
        calibrate_tool(touches, axis_touches=axis)
    on_axis = [pose_for(design(rng, 1)[0], TCP + R_TOOL @ [-0.05, 0, 0])]
    with pytest.raises(IllPosedError, match="collinear"):
        calibrate_tool(touches, axis, on_axis)
    too_close = [pose_for(design(rng, 1)[0], TCP + R_TOOL @ [-0.002, 0, 0])]
    plane = [pose_for(design(rng, 1)[0], TCP + R_TOOL @ [0.03, 0.08, 0])]
    r = calibrate_tool(touches, too_close, plane)  # 2 mm: computed, with a warning
    assert any("only 2.0 mm from the TCP" in w for w in r.warnings)
    at_tcp = [pose_for(design(rng, 1)[0], TCP)]
    with pytest.raises(IllPosedError, match="at the TCP, so they define no tool direction; move the "
                       "tool back along its axis, at least 50 mm"):
        calibrate_tool(touches, at_tcp, plane)
    world = [np.eye(4)]
    with pytest.raises(InputError, match="not both"):
        calibrate_tool(touches, axis, plane, world)


def test_abc_world_6d_and_5d():
    rng = np.random.default_rng(18)
    touches = noisy([pose_for(R, TCP) for R in design(rng, 5)], rng, 5e-5)
    # flange rotations that align the true tool with the world: R_RF R_TOOL = ABC_WORLD_6D
    aligned = []
    for _ in range(3):
        jitter = Rotation.from_rotvec(rng.normal(scale=np.radians(0.2), size=3)).as_matrix()
        T = np.eye(4)
        T[:3, :3] = jitter @ ABC_WORLD_6D @ R_TOOL.T
        aligned.append(T)
    r = calibrate_tool(touches, world_touches=aligned)
    err = np.degrees(np.linalg.norm(angle_error(r.values["T_F_TCP"][:3, :3], R_TOOL)))
    assert err < 0.5 and np.all(np.degrees(r.sigma["T_F_TCP_rotation"]) < 0.5)
    r5 = calibrate_tool(touches, world_touches=aligned, world_mode="5d")
    x_est = r5.values["T_F_TCP"][:3, 0]
    assert np.degrees(np.arccos(np.clip(x_est @ R_TOOL[:, 0], -1, 1))) < 0.5
    assert "own X axis" in r5.undetermined[0]
    single = calibrate_tool(touches, world_touches=aligned[:1])
    assert any("align 2-3 times" in w for w in single.warnings)
