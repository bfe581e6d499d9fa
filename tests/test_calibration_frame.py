"""Frames: 3-point (with repeated touches), N-point best fit, external TCP; synthetic cells."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell import IllPosedError, InputError
from robotcell.calibration import calibrate_external_tcp as external_tcp
from robotcell.calibration import frame_3point, frame_npoint
from robotcell.kinematics.transforms import transform_points

R_TRUE = Rotation.from_euler("ZYX", [40, 5, -3], degrees=True).as_matrix()
O_TRUE = np.array([1.2, -0.3, 0.4])
T_TRUE = np.eye(4)
T_TRUE[:3, :3], T_TRUE[:3, 3] = R_TRUE, O_TRUE

LOCAL = np.array([[0, 0, 0], [0.4, 0, 0], [0.1, 0.3, 0]])
ROLES = ["origin", "x", "xy"]


def rot_err(T):
    return Rotation.from_matrix(T[:3, :3] @ R_TRUE.T).as_rotvec()


def test_3point_exact_is_kukas_definition():
    r = frame_3point(transform_points(T_TRUE, LOCAL), ROLES)
    np.testing.assert_allclose(r.values["T_R_W"], T_TRUE, atol=1e-12)
    assert r.dof == 0 and r.noise_source == "default" and r.chi2 is None
    # Without redundancy the 1-sigma rests on the default touch accuracy, 0.5 mm.
    assert r.noise_sigma == pytest.approx(0.5e-3) and np.all(r.sigma["T_R_W_position"] > 0)
    assert r.verdict.level == "check" and "no redundancy" in r.verdict.reasons[-1]
    j = r.to_json()
    np.testing.assert_allclose(np.array(j["matrix"])[:3, 3], O_TRUE * 1e3)
    assert len(j["xyzabc"]) == 6


@pytest.mark.parametrize("repeats, prior", [(1, 2e-4), (3, 2e-4)])
def test_3point_monte_carlo_sigma(repeats, prior):
    """Three touches, or each point touched 3 times, with the touch-up accuracy given."""
    rng = np.random.default_rng(20 + repeats)
    local = np.repeat(LOCAL, repeats, axis=0)
    roles = [r for r in ROLES for _ in range(repeats)]
    clean = transform_points(T_TRUE, local)
    ep, er, sp, sr = [], [], [], []
    for _ in range(300):
        r = frame_3point(clean + rng.normal(scale=2e-4, size=clean.shape), roles, prior)
        T = r.values["T_R_W"]
        ep.append(T[:3, 3] - O_TRUE)
        er.append(rot_err(T))
        sp.append(r.sigma["T_R_W_position"])
        sr.append(r.sigma["T_R_W_rotation"])
    for e, s in ((ep, sp), (er, sr)):
        ratio = np.sqrt(np.mean(np.square(e), axis=0)) / np.mean(s, axis=0)
        assert np.all(np.abs(ratio - 1) < 0.25), ratio


def test_npoint_monte_carlo_sigma_and_accuracy():
    rng = np.random.default_rng(30)
    q = rng.uniform(-0.3, 0.3, size=(7, 3)) * [1, 1, 0.2]
    clean = transform_points(T_TRUE, q)
    ep, er, sp, sr = [], [], [], []
    for _ in range(300):
        r = frame_npoint(clean + rng.normal(scale=3e-4, size=clean.shape), q, 3e-4)
        ep.append(r.values["T_R_W"][:3, 3] - O_TRUE)
        er.append(rot_err(r.values["T_R_W"]))
        sp.append(r.sigma["T_R_W_position"])
        sr.append(r.sigma["T_R_W_rotation"])
    for e, s in ((ep, sp), (er, sr)):
        ratio = np.sqrt(np.mean(np.square(e), axis=0)) / np.mean(s, axis=0)
        assert np.all(np.abs(ratio - 1) < 0.25), ratio
    assert r.dof == 21 - 6 and r.procedure == "frame-npoint"


def test_collinear_points_refused_with_cause_and_fix():
    exact = transform_points(np.eye(4), [[0, 0, 0], [0.4, 0, 0], [0.2, 0.0, 0]])
    with pytest.raises(IllPosedError, match=r"collinear \(the XY touch lies on the X line\).*"
                       "touch the XY-plane point well away"):
        frame_3point(exact, ROLES)
    line = transform_points(T_TRUE, [[0, 0, 0], [0.4, 0, 0], [0.2, 0.001, 0]])
    with pytest.raises(IllPosedError, match=r"collinear \(all on one line\).*add points well away"):
        frame_npoint(line, [[0, 0, 0], [0.4, 0, 0], [0.8, 0, 0]])
    same = transform_points(T_TRUE, [[0, 0, 0], [0.0, 0, 0], [0.1, 0.3, 0]])
    with pytest.raises(IllPosedError, match=r"\+X touch is at the origin touch, so it defines no "
                       "direction; touch a point on \\+X at least 100 mm"):
        frame_3point(same, ROLES)
    with pytest.raises(IllPosedError, match="at least 3 points"):
        frame_npoint(line[:2], [[0, 0, 0], [0.4, 0, 0]])
    with pytest.raises(InputError, match="missing xy"):
        frame_3point(line, ["origin", "x", "x"])
    two_sides = transform_points(T_TRUE, [[0, 0, 0], [0.4, 0, 0], [0.1, 0.3, 0], [0.2, -0.1, 0]])
    with pytest.raises(IllPosedError, match="positive Y"):
        frame_3point(two_sides, ["origin", "x", "xy", "xy"])


def test_nearly_collinear_and_short_x_warn():
    pts = transform_points(T_TRUE, [[0, 0, 0], [0.06, 0, 0], [0.3, 0.03, 0]])
    r = frame_3point(pts, ROLES, sigma=1e-4)
    assert any("nearly collinear" in w for w in r.warnings)
    assert any("only 60 mm" in w for w in r.warnings)
    q = np.array([[0, 0, 0], [0.3, 0, 0], [0.6, 0.03, 0], [0.9, 0, 0]])
    r = frame_npoint(transform_points(T_TRUE, q), q, sigma=1e-4)
    assert any("nearly collinear" in w for w in r.warnings)


def test_external_tcp_position_only_and_full_pose():
    rng = np.random.default_rng(40)
    tip = transform_points(T_TRUE, np.zeros((4, 3))) + rng.normal(scale=1e-4, size=(4, 3))
    r = external_tcp(tip, ["tcp"] * 4)
    np.testing.assert_allclose(r.values["T_R_TCP"][:3, 3], O_TRUE, atol=5e-4)
    assert "orientation" in r.undetermined[0] and "T_R_TCP_rotation" not in r.sigma
    assert r.to_json()["rotation_determined"] is False
    np.testing.assert_allclose(r.sigma["T_R_TCP_position"], r.noise_sigma / 2)
    local = np.array([[0, 0, 0]] * 3 + [[0.05, 0, 0], [0.1, 0, 0], [0.02, 0.06, 0]])
    pts = transform_points(T_TRUE, local) + rng.normal(scale=1e-5, size=(6, 3))
    r = external_tcp(pts, ["tcp"] * 3 + ["x", "x", "xy"])
    assert np.linalg.norm(rot_err(r.values["T_R_TCP"])) < np.radians(0.1)
    assert r.procedure == "external-tcp" and r.to_json()["rotation_determined"] is True
    with pytest.raises(IllPosedError, match="at least 3 times"):
        external_tcp(tip[:2], ["tcp"] * 2)
    with pytest.raises(IllPosedError, match="needs touches of both"):
        external_tcp(pts[:4], ["tcp"] * 3 + ["x"])
