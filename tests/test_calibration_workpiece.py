"""Workpiece frame on the turntable: any table angles, N-point fit, uncertainty, moving pose."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell import IllPosedError, InputError
from robotcell.calibration.turntable import calibrate_turntable
from robotcell.calibration.uncertainty import OWN, Sources
from robotcell.calibration.workpiece import calibrate_workpiece, table_points, workpiece_pose
from robotcell.kinematics.transforms import make_pose, rot_z

SIGMA = 1e-4
T_R_B = make_pose(Rotation.from_rotvec([0.02, -0.01, 0.7]).as_matrix(), [1.2, 0.3, 0.4])
T_B_W = make_pose(Rotation.from_euler("zyx", [0.5, 0.02, -0.03]).as_matrix(), [0.05, -0.08, 0.06])
TABLE_THETA = np.radians([0.0, 60.0, 130.0, 200.0, 270.0, 320.0])
#: Points of the workpiece (in W) for each role.
IN_W = {"origin": [0.0, 0.0, 0.0], "x": [0.15, 0.0, 0.0], "xy": [0.05, 0.12, 0.0]}


def touch(roles, theta, offsets=None, T_R_B=T_R_B, rng=None):
    """TCP positions in R touching W's points (plus offsets along the feature) at table angles."""
    offsets = np.zeros((len(roles), 3)) if offsets is None else np.asarray(offsets, dtype=float)
    p_w = np.array([IN_W[r] for r in roles]) + offsets
    T = workpiece_pose(T_R_B, T_B_W, np.asarray(theta))
    f = np.einsum("nij,nj->ni", T[:, :3, :3], p_w) + T[:, :3, 3]
    return f if rng is None else f + rng.normal(0.0, SIGMA, f.shape)


def table_touches(rng):
    """Noisy touches of a point at radius 350 mm on the table, for the turntable calibration."""
    f = (rot_z(TABLE_THETA) @ [0.35, 0.0, 0.0]) @ T_R_B[:3, :3].T + T_R_B[:3, 3]
    return f + rng.normal(0.0, SIGMA, f.shape)


def rot_error(R_est, R_true):
    return Rotation.from_matrix(R_est @ R_true.T).as_rotvec()


def test_three_points_at_any_table_angles_recover_the_frame():
    roles = ["origin", "x", "xy"]
    theta = np.radians([15.0, 140.0, 250.0])
    r = calibrate_workpiece(theta, touch(roles, theta), roles, T_R_B)
    np.testing.assert_allclose(r.values["T_B_W"], T_B_W, atol=1e-10)
    assert r.dof == 0 and r.max < 1e-12 and r.noise_source == "default"
    assert any("turntable" in u for u in r.undetermined)
    assert len(r.json_fields["xyzabc"]) == 6


def test_ignoring_the_table_angle_gives_a_wrong_frame():
    """The lecture's angle-0 formula applied to touches taken at other angles is wrong by
    centimetres; undoing Rz(theta_i) per touch is what makes the result right."""
    roles = ["origin", "x", "xy"]
    theta = np.radians([15.0, 140.0, 250.0])
    f = touch(roles, theta)
    wrong = table_points(T_R_B, np.zeros(3), f)
    right = table_points(T_R_B, theta, f)
    np.testing.assert_allclose(right[0], T_B_W[:3, 3], atol=1e-12)
    assert np.linalg.norm(wrong[0] - T_B_W[:3, 3]) > 0.01


def test_n_point_fit_uses_every_touch_and_estimates_noise():
    roles = ["origin", "origin", "x", "x", "x", "xy", "xy", "xy"]
    theta = np.radians([10.0, 50.0, 100.0, 150.0, 170.0, 200.0, 300.0, 330.0])
    offsets = [[0, 0, 0], [0, 0, 0], [0, 0, 0], [0.05, 0, 0], [-0.07, 0, 0],
               [0, 0, 0], [0.03, -0.02, 0], [-0.1, 0.05, 0]]
    r = calibrate_workpiece(theta, touch(roles, theta, offsets), roles, T_R_B)
    np.testing.assert_allclose(r.values["T_B_W"], T_B_W, atol=1e-10)
    assert r.dof == 3 * 2 + 2 * 3 + 3 - 6
    f = touch(roles, theta, offsets, rng=np.random.default_rng(1))
    r = calibrate_workpiece(theta, f, roles, T_R_B, sigma=SIGMA)
    assert r.noise_source == "prior" and 0.3 * SIGMA < r.residual_sigma < 3 * SIGMA
    assert r.residuals.shape == (8, 3) and r.rms > 0


@pytest.mark.parametrize("roles,theta", [
    (["origin", "x", "xy"], [10.0, 100.0, 200.0]),
    (["origin", "origin", "x", "x", "xy", "xy"], [10.0, 50.0, 100.0, 150.0, 200.0, 300.0]),
])
def test_sigmas_including_the_turntable_match_monte_carlo(roles, theta):
    """Each trial calibrates the turntable and then the workpiece from fresh noisy touches; the
    reported sigma (touch noise plus the turntable's covariance) must match the spread."""
    theta = np.radians(theta)
    rng = np.random.default_rng(11)
    errs, sigmas = [], []
    for _ in range(150):
        tt = calibrate_turntable(TABLE_THETA, table_touches(rng), sigma=SIGMA)
        r = calibrate_workpiece(theta, touch(roles, theta, rng=rng), roles, tt.values["T_R_B"],
                                T_R_B_covariance=tt.covariance[:6, :6], sigma=SIGMA)
        T = r.values["T_B_W"]
        errs.append(np.r_[T[:3, 3] - T_B_W[:3, 3], rot_error(T[:3, :3], T_B_W[:3, :3])])
        sigmas.append(np.r_[r.sigma["T_B_W_position"], r.sigma["T_B_W_rotation"]])
    assert r.json_fields["turntable_included"] and r.undetermined == []
    ratio = np.std(errs, axis=0) / np.mean(sigmas, axis=0)
    np.testing.assert_allclose(ratio, 1.0, atol=0.25)


def test_workpiece_pose_is_batched_and_follows_the_table():
    theta = np.radians([[0.0, 90.0], [180.0, -45.0]])
    T = workpiece_pose(T_R_B, T_B_W, theta)
    assert T.shape == (2, 2, 4, 4)
    for idx in np.ndindex(theta.shape):
        turn = make_pose(rot_z(theta[idx]), np.zeros(3))
        np.testing.assert_allclose(T[idx], T_R_B @ turn @ T_B_W, atol=1e-14)
    assert workpiece_pose(T_R_B, T_B_W, 0.3).shape == (4, 4)
    # A point fixed on the table stays at the same height and radius as the table turns.
    np.testing.assert_allclose(workpiece_pose(T_R_B, T_B_W, 0.0), T_R_B @ T_B_W, atol=1e-14)


def test_refusals():
    roles = ["origin", "x", "xy"]
    theta = np.radians([0.0, 90.0, 180.0])
    f = touch(roles, theta)
    with pytest.raises(InputError, match="no touch of xy"):
        calibrate_workpiece(theta[:2], f[:2], roles[:2], T_R_B)
    with pytest.raises(InputError, match="must be origin, x or xy; found z"):
        calibrate_workpiece(theta, f, ["origin", "x", "z"], T_R_B)
    near = touch(roles, theta, [[0, 0, 0], [-0.145, 0, 0], [0, 0, 0]])
    r = calibrate_workpiece(theta, near, roles, T_R_B)  # 5 mm: computed, with a warning
    assert any(r"+X touch is only 5 mm from the origin" in w for w in r.warnings)
    at_origin = touch(roles, theta, [[0, 0, 0], [-0.15, 0, 0], [0, 0, 0]])
    with pytest.raises(IllPosedError, match=r"\+X touch is at the origin touch, so it defines no "):
        calibrate_workpiece(theta, at_origin, roles, T_R_B)
    collinear = touch(roles, theta, [[0, 0, 0], [0, 0, 0], [0.0, -0.115, 0]])
    r = calibrate_workpiece(theta, collinear, roles, T_R_B)
    assert any("nearly collinear" in w for w in r.warnings)
    on_axis = touch(roles, theta, [[0, 0, 0], [0, 0, 0], [0.0, -0.12, 0]])
    with pytest.raises(IllPosedError, match="collinear .*lies on the X line.*not determined"):
        calibrate_workpiece(theta, on_axis, roles, T_R_B)
    bad = T_R_B.copy()
    bad[:3, 0] *= -1.0
    with pytest.raises(InputError, match="T_R_B"):
        calibrate_workpiece(theta, f, roles, bad)
    with pytest.raises(InputError, match="finite 6x6"):
        calibrate_workpiece(theta, f, roles, T_R_B, T_R_B_covariance=np.eye(7))
    with pytest.raises(InputError, match="matching TCP positions"):
        calibrate_workpiece(theta[:2], f, roles, T_R_B)


def test_three_points_rest_on_the_stated_accuracy_and_carry_the_turntable_sources():
    """Without redundancy the 1-sigma rests on the touch accuracy (stated or the 0.5 mm
    default), never on a noise borrowed elsewhere; the turntable's error sources go into the
    result under their names, so a later step knows what it shares with the turntable."""
    roles = ["origin", "x", "xy"]
    theta = np.radians([15.0, 140.0, 250.0])
    f = touch(roles, theta)
    cov = np.diag([1e-8, 2e-8, 1e-8, 1e-8, 4e-8, 1e-8])
    plain = calibrate_workpiece(theta, f, roles, T_R_B, T_R_B_covariance=cov, sigma=2e-4)
    named = calibrate_workpiece(theta, f, roles, T_R_B,
                                T_R_B_covariance=Sources.of("turntable DKP", cov), sigma=2e-4)
    assert plain.noise_source == "prior" and plain.noise_sigma == pytest.approx(2e-4)
    np.testing.assert_allclose(named.sigma["T_B_W_rotation"], plain.sigma["T_B_W_rotation"])
    sources = named.estimates["T_B_W"].sources.factors
    assert set(sources) == {OWN, "turntable DKP"}
    np.testing.assert_allclose(named.estimates["T_B_W"].covariance,
                               named.covariance, atol=1e-20)
    default = calibrate_workpiece(theta, f, roles, T_R_B)
    assert default.noise_source == "default" and default.noise_sigma == pytest.approx(5e-4)
    assert "the default (state yours with sigma)" in default.summary()
