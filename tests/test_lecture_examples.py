"""The lecture's closed forms (week 7, lecture 32) reworked: singular as written, and what works.

Linear track: ``L_Q_R = -X F^-1`` with ``F = [f1-f2, f2-f3, f3-f1]``. Turntable root point:
``R_T_B = R_P B_P^-1`` with ``B_P`` the homogeneous points ``[r cos t, r sin t, 0, 1]``.
Workpiece on the turntable: 3-point frame with every touch at table angle 0.
"""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell.calibration.track import calibrate_track
from robotcell.calibration.turntable import calibrate_turntable
from robotcell.calibration.workpiece import calibrate_workpiece
from robotcell.kinematics.transforms import invert, make_pose, rot_z

Q_TRUE = Rotation.from_rotvec([0.01, -0.02, 0.03]).as_matrix()  # L_Q_R, a small mounting error
REF_L = np.array([1.5, 0.8, 0.3])  # the fixed reference point r, in L


def lecture_track_touches(x):
    """f_i from the lecture's loop x_i + L_Q_R f_i = r, with x_i = [x_i, 0, 0]."""
    return np.array([Q_TRUE.T @ (REF_L - [xi, 0.0, 0.0]) for xi in x])


def test_track_F_is_singular_for_any_touches():
    f = np.random.default_rng(0).normal(size=(3, 3))  # any three vectors at all
    F = np.column_stack([f[0] - f[1], f[1] - f[2], f[2] - f[0]])
    np.testing.assert_allclose(F.sum(axis=1), 0.0, atol=1e-15)  # columns sum to zero
    assert abs(np.linalg.det(F)) < 1e-14
    assert np.linalg.matrix_rank(F) <= 2


def test_track_F_and_X_have_rank_one_under_the_lecture_assumptions():
    x = np.array([0.3, 1.1, 2.0])
    f = lecture_track_touches(x)
    F = np.column_stack([f[0] - f[1], f[1] - f[2], f[2] - f[0]])
    X = -np.column_stack([[x[0] - x[1], 0, 0], [x[1] - x[2], 0, 0], [x[2] - x[0], 0, 0]])
    assert np.linalg.matrix_rank(F, tol=1e-12) == 1
    assert np.linalg.matrix_rank(X, tol=1e-12) == 1
    # Every column of F is parallel to the track direction in R, the first row of L_Q_R.
    for col in F.T:
        assert np.linalg.norm(np.cross(col, Q_TRUE[0])) < 1e-12
    # The least-squares "solution" -X F^+ is not a rotation at all: rank 1.
    M = X @ np.linalg.pinv(F)
    assert np.linalg.matrix_rank(M, tol=1e-9) == 1
    assert not np.allclose(M @ M.T, np.eye(3), atol=1e-3)


def test_track_what_the_lecture_touches_do_determine():
    x = np.array([0.3, 1.1, 2.0])
    r = calibrate_track(x, lecture_track_touches(x))
    np.testing.assert_allclose(r.values["direction"], Q_TRUE[0], atol=1e-12)
    assert r.values["scale"] == pytest.approx(1.0, abs=1e-12)
    assert r.json_fields["rotation"] is None
    # With r known in L (off the track axis, no carriage offset as the lecture assumes), the
    # full L_Q_R follows from the same three touches.
    r_known = calibrate_track(x, lecture_track_touches(x), references=[REF_L])
    np.testing.assert_allclose(r_known.values["T_L_R"][:3, :3], Q_TRUE, atol=1e-10)


T_R_B = make_pose(Rotation.from_rotvec([0.02, -0.01, 0.7]).as_matrix(), [1.2, 0.3, 0.4])
RADIUS = 0.35
THETA = np.radians([0.0, 80.0, 170.0, 260.0])  # the lecture's four touches


def test_turntable_B_P_is_singular():
    B_P = np.vstack([RADIUS * np.cos(THETA), RADIUS * np.sin(THETA), np.zeros(4), np.ones(4)])
    np.testing.assert_array_equal(B_P[2], 0.0)  # third row: the points lie in the table plane
    assert np.linalg.det(B_P) == 0.0
    assert np.linalg.matrix_rank(B_P) == 3
    with pytest.raises(np.linalg.LinAlgError):
        np.linalg.inv(B_P)


def test_turntable_recovered_without_knowing_the_radius():
    f = (rot_z(THETA) @ [RADIUS, 0.0, 0.0]) @ T_R_B[:3, :3].T + T_R_B[:3, 3]
    r = calibrate_turntable(THETA, f)
    np.testing.assert_allclose(r.values["T_R_B"], T_R_B, atol=1e-10)
    assert r.values["radius"] == pytest.approx(RADIUS, abs=1e-12)


def test_workpiece_lecture_three_point_at_angle_zero_agrees():
    """The lecture's steps 1-3 (all touches at table angle 0) and calibrate_workpiece agree."""
    T_B_W = make_pose(Rotation.from_euler("z", 0.4).as_matrix(), [0.05, -0.08, 0.06])
    pts_w = np.array([[0.0, 0.0, 0.0], [0.15, 0.0, 0.0], [0.05, 0.12, 0.0]])
    f = (T_R_B @ T_B_W @ np.c_[pts_w, np.ones(3)].T).T[:, :3]
    T_B_R = invert(T_R_B)
    p1, p2, p3 = (T_B_R[:3, :3] @ fi + T_B_R[:3, 3] for fi in f)  # B_p = R_Q_B^-1 (f - b)
    u, v = p2 - p1, p3 - p1
    x = u / np.linalg.norm(u)
    z = np.cross(u, v) / np.linalg.norm(np.cross(u, v))
    lecture = make_pose(np.column_stack([x, np.cross(z, x), z]), p1)
    r = calibrate_workpiece(np.zeros(3), f, ["origin", "x", "xy"], T_R_B)
    np.testing.assert_allclose(r.values["T_B_W"], lecture, atol=1e-12)
    np.testing.assert_allclose(lecture, T_B_W, atol=1e-12)
