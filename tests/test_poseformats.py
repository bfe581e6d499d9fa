import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell import FORMATS, InputError, pose_from_vendor, pose_to_vendor
from robotcell.kinematics.transforms import rot_x, rot_y, rot_z

# Reference values from docs/references.md (Roboception rc_visard pose formats; ABB RAPID
# `orient`; RoboDK "Reference frames" for Staubli), the worked example there.
KUKA_ABC = [30.0, 20.0, 10.0]
FANUC_WPR = [10.0, 20.0, 30.0]
ABB_Q = [0.951549, 0.038135, 0.189308, 0.239298]
STAUBLI = [-1.1161, 22.2422, 28.4518]


def test_kuka_matrix_is_rz_ry_rx():
    A, B, C = np.radians(KUKA_ABC)
    T = pose_from_vendor([100, 200, 300, *KUKA_ABC], "kuka")
    np.testing.assert_allclose(T[:3, :3], rot_z(A) @ rot_y(B) @ rot_x(C), atol=1e-15)
    np.testing.assert_allclose(T[:3, 3], [0.1, 0.2, 0.3], atol=1e-15)


def test_published_equivalences():
    T = pose_from_vendor([0, 0, 0, *KUKA_ABC], "kuka")
    np.testing.assert_allclose(pose_to_vendor(T, "fanuc")[3:], FANUC_WPR, atol=1e-9)
    np.testing.assert_allclose(pose_to_vendor(T, "yaskawa")[3:], FANUC_WPR, atol=1e-9)
    np.testing.assert_allclose(pose_to_vendor(T, "abb")[3:], ABB_Q, atol=1e-6)
    np.testing.assert_allclose(pose_to_vendor(T, "staubli")[3:], STAUBLI, atol=1e-4)
    # and back from each vendor's published numbers to the same matrix
    for fmt, ang, tol in (("fanuc", FANUC_WPR, 1e-12), ("abb", ABB_Q, 1e-5), ("staubli", STAUBLI, 1e-5)):
        np.testing.assert_allclose(pose_from_vendor([0, 0, 0, *ang], fmt), T, atol=tol)


def test_staubli_is_rx_ry_rz():
    rx, ry, rz = np.radians(STAUBLI)
    T = pose_from_vendor([0, 0, 0, *STAUBLI], "staubli")
    np.testing.assert_allclose(T[:3, :3], rot_x(rx) @ rot_y(ry) @ rot_z(rz), atol=1e-15)


def test_ur_rotation_vector_in_metres():
    T = pose_from_vendor([0.1, 0.2, 0.3, 0.0, 0.0, np.pi / 2], "ur")
    np.testing.assert_allclose(T[:3, 3], [0.1, 0.2, 0.3])
    np.testing.assert_allclose(T[:3, :3], rot_z(np.pi / 2), atol=1e-15)


@pytest.mark.parametrize("fmt", list(FORMATS))
def test_round_trip_every_format_batched(fmt):
    rng = np.random.default_rng(7)
    T = np.zeros((3, 5, 4, 4))
    T[..., :3, :3] = Rotation.random(15, random_state=3).as_matrix().reshape(3, 5, 3, 3)
    T[..., :3, 3] = rng.uniform(-2, 2, (3, 5, 3))
    T[..., 3, 3] = 1
    v = pose_to_vendor(T, fmt)
    assert v.shape == (3, 5, FORMATS[fmt].size)
    np.testing.assert_allclose(pose_from_vendor(v, fmt), T, atol=1e-12)


def test_abb_quaternion_is_canonical_and_normalised():
    """Quaternions with a negative scalar part come back as their positive equivalent."""
    rng = np.random.default_rng(4)
    q_in = rng.normal(size=(500, 4))
    q_in /= np.linalg.norm(q_in, axis=1, keepdims=True)
    q_in[:, 0] = -np.abs(q_in[:, 0])  # every input has w < 0
    v = np.column_stack([np.zeros((500, 3)), q_in])
    q = pose_to_vendor(pose_from_vendor(v, "abb"), "abb")[:, 3:]
    assert np.all(q[:, 0] > 0)
    np.testing.assert_allclose(q, -q_in, atol=1e-15)  # the same rotation, sign flipped
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-15)


def test_euler_gimbal_lock_is_still_exact():
    T = pose_from_vendor([0, 0, 0, 40, 90, 10], "kuka")
    np.testing.assert_allclose(pose_from_vendor(pose_to_vendor(T, "kuka"), "kuka"), T, atol=1e-12)


def rotation_error(T1: np.ndarray, T2: np.ndarray) -> np.ndarray:
    """Angle (rad) of the rotation between the orientations of two batches of poses."""
    return Rotation.from_matrix(np.swapaxes(T1[..., :3, :3], -1, -2) @ T2[..., :3, :3]).magnitude()


@pytest.mark.parametrize("fmt", ["kuka", "fanuc", "yaskawa", "staubli"])
def test_euler_exact_next_to_gimbal_lock(fmt):
    """Middle angle within 1e-5 .. 1e-12 deg of +-90 deg: the round trip is exact to 1e-12 rad
    (scipy alone takes its gimbal-lock branch there, sets the third angle to 0 and misses the
    rotation by up to 1.75e-7 rad)."""
    f = FORMATS[fmt]
    rng = np.random.default_rng(sum(map(ord, fmt)))
    n = 4000
    v = np.column_stack([rng.uniform(-500, 500, (n, 3)), rng.uniform(-180, 180, (n, 3))])
    mid = 3 + f.angle_order[1]  # the vendor's middle angle (B, P, Ry)
    off = 10.0 ** rng.uniform(-12, -5, n)
    v[:, mid] = rng.choice([-1.0, 1.0], n) * (90.0 - off)
    T = pose_from_vendor(v, fmt)
    out = pose_to_vendor(T, fmt)
    assert np.all(np.abs(out[:, mid]) <= 90.0)
    assert rotation_error(T, pose_from_vendor(out, fmt)).max() < 1e-12
    # Away from the lock the angles themselves come back.
    v[:, mid] = rng.uniform(-89, 89, n)
    np.testing.assert_allclose(pose_to_vendor(pose_from_vendor(v, fmt), fmt), v, atol=1e-9)


@pytest.mark.parametrize("fmt", ["abb", "ur"])
def test_quaternion_and_rotation_vector_exact(fmt):
    """Rotations near the identity, near 180 deg and about the axes: round trip to 1e-12 rad."""
    rng = np.random.default_rng(8)
    axis = rng.normal(size=(3000, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    angle = np.concatenate([10.0 ** rng.uniform(-12, 0, 1000), np.pi - 10.0 ** rng.uniform(-12, 0, 1000),
                            rng.uniform(0, np.pi, 1000)])
    T = np.tile(np.eye(4), (3000, 1, 1))
    T[:, :3, :3] = Rotation.from_rotvec(axis * angle[:, None]).as_matrix()
    assert rotation_error(T, pose_from_vendor(pose_to_vendor(T, fmt), fmt)).max() < 1e-12


def test_errors():
    with pytest.raises(InputError, match="unknown pose format 'kawasaki'"):
        pose_from_vendor([0] * 6, "kawasaki")
    with pytest.raises(InputError, match=r"a kuka pose has 6 values \(X, Y, Z, A, B, C\)"):
        pose_from_vendor([0] * 5, "kuka")
    with pytest.raises(InputError, match="NaN"):
        pose_from_vendor([0, 0, np.nan, 0, 0, 0], "fanuc")
    with pytest.raises(InputError, match=r"must be normalised .*\|q\| = 2"):
        pose_from_vendor([0, 0, 0, 2, 0, 0, 0], "abb")
    with pytest.raises(InputError, match="not a valid rigid transform"):
        pose_to_vendor(np.diag([1, 1, 2, 1.0]), "kuka")
