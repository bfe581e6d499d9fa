"""Turntable root frame: exact recovery, frame conventions, Monte Carlo sigmas, warnings, refusals."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell import IllPosedError, InputError
from robotcell.calibration.turntable import angular_spread, calibrate_turntable
from robotcell.kinematics.transforms import make_pose, rot_z

SIGMA = 1e-4
THETA = np.radians([0.0, 60.0, 130.0, 200.0, 270.0, 320.0])


def table(rotvec=(0.02, -0.01, 0.7), origin=(1.2, 0.3, 0.4)):
    return make_pose(Rotation.from_rotvec(rotvec).as_matrix(), origin)


def touches(T_R_B, theta, radius=0.35, z=0.0, rng=None):
    """The point (radius, 0, z) of the table (in B at angle 0), seen in R at table angles theta."""
    p = rot_z(np.asarray(theta)) @ np.array([radius, 0.0, z])
    f = p @ T_R_B[:3, :3].T + T_R_B[:3, 3]
    return f if rng is None else f + rng.normal(0.0, SIGMA, f.shape)


def rot_error(R_est, R_true):
    return Rotation.from_matrix(R_est @ R_true.T).as_rotvec()


def test_exact_recovery_of_frame_radius_and_tilt():
    T = table()
    r = calibrate_turntable(THETA, touches(T, THETA))
    np.testing.assert_allclose(r.values["T_R_B"], T, atol=1e-10)
    assert r.values["radius"] == pytest.approx(0.35, abs=1e-12)
    assert r.values["tilt"] == pytest.approx(np.arccos(T[2, 2]), abs=1e-10)
    np.testing.assert_allclose(r.values["axis"], T[:3, 2], atol=1e-10)
    assert r.values["spread"] == pytest.approx(np.radians(290.0))
    assert r.max < 1e-10 and r.dof == 3 * len(THETA) - 7
    j = r.to_json()
    assert j["radius_mm"] == pytest.approx(350.0) and len(j["matrix"]) == 4
    assert j["matrix"][0][3] == pytest.approx(1200.0)
    assert np.array(j["T_R_B_covariance_mm_rad"]).shape == (6, 6)


def test_frame_conventions_ccw_axis_x_to_point_at_zero_and_height():
    T = table()
    # No touch at angle 0: X_B still points to where the point is at angle 0.
    theta = np.radians([35.0, 110.0, 190.0, 300.0])
    r = calibrate_turntable(theta, touches(T, theta, z=0.03), height=-0.03)  # point 30 mm up
    np.testing.assert_allclose(r.values["T_R_B"], T, atol=1e-10)
    # Angles counted the other way round: Z_B flips, X_B stays on the point at angle 0.
    r_neg = calibrate_turntable(-theta, touches(T, theta))
    Tn = r_neg.values["T_R_B"]
    np.testing.assert_allclose(Tn[:3, 2], -T[:3, 2], atol=1e-10)
    np.testing.assert_allclose(Tn[:3, 0], T[:3, 0], atol=1e-10)
    assert np.linalg.det(Tn[:3, :3]) == pytest.approx(1.0)
    assert any("points downward" in w for w in r_neg.warnings)


def test_sigmas_match_monte_carlo():
    T = table()
    rng = np.random.default_rng(7)
    errs, sigmas = [], []
    for _ in range(200):
        r = calibrate_turntable(THETA, touches(T, THETA, rng=rng), sigma=SIGMA)
        Te = r.values["T_R_B"]
        errs.append(np.r_[Te[:3, 3] - T[:3, 3], rot_error(Te[:3, :3], T[:3, :3]),
                          r.values["radius"] - 0.35, r.values["tilt"] - np.arccos(T[2, 2])])
        sigmas.append(np.r_[r.sigma["T_R_B_position"], r.sigma["T_R_B_rotation"],
                            r.sigma["radius"], r.sigma["tilt"]])
    ratio = np.std(errs, axis=0) / np.mean(sigmas, axis=0)
    np.testing.assert_allclose(ratio, 1.0, atol=0.25)


def test_small_spread_warns_and_three_touches_get_a_check_verdict():
    T = table()
    theta = np.radians([0.0, 30.0, 60.0])
    r = calibrate_turntable(theta, touches(T, theta))
    np.testing.assert_allclose(r.values["T_R_B"], T, atol=1e-8)
    assert any("span only 60 deg" in w for w in r.warnings)
    assert r.verdict.level == "check" and r.verdict.touches_needed == 6


def test_outlier_is_named():
    T = table()
    theta = np.radians(np.arange(0.0, 360.0, 30.0))
    f = touches(T, theta, rng=np.random.default_rng(2))
    f[2] += 0.002 * (f[2] - T[:3, 3]) / np.linalg.norm(f[2] - T[:3, 3])  # 2 mm off the circle
    r = calibrate_turntable(theta, f, sigma=SIGMA)
    assert any(w.startswith("touch 3 is an outlier") for w in r.warnings)


def test_angular_spread():
    assert angular_spread(np.radians([350.0, 10.0, 40.0])) == pytest.approx(np.radians(50.0))
    assert angular_spread(np.radians([0.0, 90.0, 180.0, 270.0])) == pytest.approx(np.radians(270.0))


def test_refusals():
    T = table()
    f = touches(T, THETA)
    with pytest.raises(InputError, match="at least 3 needed"):
        calibrate_turntable(THETA[:2], f[:2])
    theta = np.radians([10.0, 100.0, 370.0, 460.0])
    with pytest.raises(IllPosedError, match=r"only 2 distinct table angle\(s\) \(modulo 360 deg\): "
                       "a circle needs 3"):
        calibrate_turntable(theta, touches(T, theta))
    r = calibrate_turntable(THETA, touches(T, THETA, radius=0.002))  # computed, with a warning
    assert any("only 2.0 mm from the table axis" in w for w in r.warnings)
    with pytest.raises(IllPosedError, match="does not move when the table turns .* at least 50 mm"):
        calibrate_turntable(THETA, touches(T, THETA, radius=0.0))
    with pytest.raises(InputError, match="matching TCP positions"):
        calibrate_turntable(THETA[:-1], f)
    with pytest.raises(InputError, match="NaN"):
        calibrate_turntable(np.r_[THETA[:-1], np.nan], f)
