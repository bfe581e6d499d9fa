import re

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell import InputError, check_pose, compose, invert, make_pose, rot_x, rot_y, rot_z
from robotcell.kinematics.transforms import transform_points, validate_pose, validate_single_pose


def random_poses(rng, n):
    return make_pose(Rotation.random(n, random_state=rng.integers(1 << 31)).as_matrix(),
                     rng.normal(size=(n, 3)))


def test_elementary_rotations_are_active_right_handed():
    # Rz(90 deg) turns +X into +Y: an active rotation (docs/conventions.md).
    np.testing.assert_allclose(rot_z(np.pi / 2) @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(rot_x(np.pi / 2) @ [0, 1, 0], [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(rot_y(np.pi / 2) @ [0, 0, 1], [1, 0, 0], atol=1e-15)
    assert rot_z(np.zeros((2, 5))).shape == (2, 5, 3, 3)


def test_compose_and_invert_batched():
    rng = np.random.default_rng(1)
    A, B = random_poses(rng, 7), random_poses(rng, 7)
    AB = compose(A, B)
    np.testing.assert_allclose(compose(AB, invert(B)), A, atol=1e-12)
    np.testing.assert_allclose(invert(A) @ A, np.broadcast_to(np.eye(4), (7, 4, 4)), atol=1e-12)
    np.testing.assert_allclose(invert(A), np.linalg.inv(A), atol=1e-12)
    # Broadcasting a single pose against a batch.
    assert compose(A[0], B).shape == (7, 4, 4)


def test_transform_points_maps_b_to_a():
    T_a_b = make_pose(rot_z(np.pi / 2), [1.0, 0.0, 0.0])
    # The point (1, 0, 0) of b lies at (1, 1, 0) in a.
    np.testing.assert_allclose(transform_points(T_a_b, [1.0, 0.0, 0.0]), [1.0, 1.0, 0.0], atol=1e-15)


def test_check_pose_reports_each_defect():
    good = np.eye(4)
    scaled = np.diag([2.0, 1.0, 1.0, 1.0])
    reflect = np.diag([1.0, 1.0, -1.0, 1.0])
    lastrow = np.eye(4)
    lastrow[3, 0] = 1.0
    nan = np.eye(4)
    nan[0, 3] = np.nan
    ok, reasons = check_pose(np.stack([good, scaled, reflect, lastrow, nan]))
    assert ok.tolist() == [True, False, False, False, False]
    assert "pose [1]" in reasons[0] and "not orthonormal" in reasons[0]
    assert "determinant" in reasons[1] and "reflection" in reasons[1]
    assert "last row" in reasons[2]
    assert "NaN" in reasons[3]


def test_validate_pose_errors():
    with pytest.raises(InputError, match=r"tool is not a valid rigid transform: .*determinant"):
        validate_pose(np.diag([1.0, -1.0, 1.0, 1.0]), "tool")
    with pytest.raises(InputError, match=r"shape \(\.\.\., 4, 4\)"):
        validate_pose(np.eye(3))
    with pytest.raises(InputError, match=r"p must have shape"):
        make_pose(np.eye(3), [1.0, 2.0])


def test_the_one_pose_check_raises_what_validate_pose_raises():
    # validate_single_pose (the per-call path: one compiled check) refuses each defect with the
    # message of validate_pose, and returns a valid pose as a C-contiguous float array.
    nan = np.eye(4)
    nan[1, 3] = np.inf
    lastrow = np.eye(4)
    lastrow[3, 2] = 1e-3
    tilted = make_pose(rot_x(0.3))
    tilted[0, 1] += 1e-3
    for bad in (np.diag([1.0, -1.0, 1.0, 1.0]), 2 * np.eye(4), nan, lastrow, tilted, np.eye(3),
                [[1, 0, 0]]):
        with pytest.raises(InputError) as want:
            validate_pose(bad, "tool")
        with pytest.raises(InputError, match=re.escape(str(want.value))):
            validate_single_pose(bad, "tool")
    with pytest.raises(InputError, match=r"tool must be a single pose of shape \(4, 4\), got \(2, 4, 4\)"):
        validate_single_pose(np.stack([np.eye(4)] * 2), "tool")
    T = make_pose(rot_x(0.3), [1.0, 2.0, 3.0])
    out = validate_single_pose(T.T.T.copy(order="F"), "tool")
    assert out.flags.c_contiguous and out.dtype == np.float64 and np.array_equal(out, T)
    shifted = np.eye(4, dtype=int)
    shifted[:3, 3] = [1, 2, 3]
    assert np.array_equal(validate_single_pose(shifted), shifted)
