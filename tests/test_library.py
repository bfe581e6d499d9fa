"""Tests of the built-in robot library (src/robotcell/robots/*.yaml).

Every model is checked against values derived *independently of its DH table*:

* joint chains re-built from the published ROS-Industrial / Universal Robots URDF joint origins
  (``xyz`` + ``rpy`` + joint axis, an entirely different parameterisation from DH),
* the closed-form forward kinematics of ortho-parallel arms with a spherical wrist (OPW,
  Brandstoetter, Angerer, Hofbaur 2014, as implemented in opw_kinematics ``forward()``) with the
  published OPW parameter sets,
* hand-computed flange positions at the zero / home pose and datasheet reach figures,
* the vendors' axis directions (e.g. KUKA A1 positive is clockwise seen from above).

The URDF numbers below are copied from the files named in each comment (metres, radians).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import robotcell

# Exact references (URDF chains, OPW formulas, hand closed forms): 1e-9 m / 1e-9 rad.
TOL = 1e-9
DEG = math.pi / 180
PI = math.pi

REQUIRED = [
    "ur3e", "ur5e", "ur10e",
    "kuka_kr6_r700_sixx", "kuka_kr6_r900", "kuka_kr16", "kuka_kr210_r2700", "kuka_kr1000_titan",
    "abb_irb120", "abb_irb2400", "abb_irb6700",
    "fanuc_lrmate200id", "fanuc_m20ia",
    "puma560", "stanford_arm",
]


# ----------------------------------------------------------------------------------------------
# Small independent helpers (plain numpy, no robotcell code)
# ----------------------------------------------------------------------------------------------
def rx(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rz(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def hom(R=None, p=(0.0, 0.0, 0.0)):
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    T[:3, 3] = p
    return T


def urdf_origin(xyz, rpy):
    """URDF <origin>: translation, then fixed-axis roll-pitch-yaw, R = Rz(y) Ry(p) Rx(r)."""
    r, p, y = rpy
    return hom(rz(y) @ ry(p) @ rx(r), xyz)


def axis_angle(axis, q):
    """Rodrigues rotation about a unit axis (URDF <axis>)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return hom(np.eye(3) + math.sin(q) * K + (1 - math.cos(q)) * K @ K)


def urdf_fk(joints, q, pre=None, post=None):
    """Pose of the last link of a chain of revolute URDF joints ``(xyz, rpy, axis)``."""
    T = np.eye(4) if pre is None else pre.copy()
    for (xyz, rpy, axis), qi in zip(joints, q):
        T = T @ urdf_origin(xyz, rpy) @ axis_angle(axis, qi)
    return T if post is None else T @ post


def opw_fk(p, qs):
    """opw_kinematics ``forward()`` (include/opw_kinematics/opw_kinematics_impl.h), in metres.

    ``p`` has c1, c2, c3, c4, a1, a2, b, offsets (rad) and sign_corrections. Returns the pose of
    the OPW tool frame (Z out of the flange; at the arm's stretched-up zero it equals the base).
    """
    q = [qs[i] * p["sign"][i] - p["offsets"][i] for i in range(6)]
    psi3 = math.atan2(p["a2"], p["c3"])
    k = math.hypot(p["a2"], p["c3"])
    cx1 = p["c2"] * math.sin(q[1]) + k * math.sin(q[1] + q[2] + psi3) + p["a1"]
    cy1 = p["b"]
    cz1 = p["c2"] * math.cos(q[1]) + k * math.cos(q[1] + q[2] + psi3)
    c = np.array([cx1 * math.cos(q[0]) - cy1 * math.sin(q[0]),
                  cx1 * math.sin(q[0]) + cy1 * math.cos(q[0]),
                  cz1 + p["c1"]])
    s1, s2, s3, s4, s5, s6 = (math.sin(v) for v in q)
    c1, c2, c3, c4, c5, c6 = (math.cos(v) for v in q)
    r0c = np.array([[c1 * c2 * c3 - c1 * s2 * s3, -s1, c1 * c2 * s3 + c1 * s2 * c3],
                    [s1 * c2 * c3 - s1 * s2 * s3, c1, s1 * c2 * s3 + s1 * s2 * c3],
                    [-s2 * c3 - c2 * s3, 0.0, -s2 * s3 + c2 * c3]])
    rce = np.array([[c4 * c5 * c6 - s4 * s6, -c4 * c5 * s6 - s4 * c6, c4 * s5],
                    [s4 * c5 * c6 + c4 * s6, -s4 * c5 * s6 + c4 * c6, s4 * s5],
                    [-s5 * c6, s5 * s6, c5]])
    R = r0c @ rce
    return hom(R, c + p["c4"] * R[:, 2])


def random_q(robot, rng, n):
    lo = np.maximum(robot.lower, -2 * PI)
    hi = np.minimum(robot.upper, 2 * PI)
    return lo + (hi - lo) * rng.random((n, robot.n_joints))


def assert_pose(T, ref, tol=TOL, what=""):
    assert np.allclose(T[..., :3, 3], ref[..., :3, 3], atol=tol, rtol=0), (
        f"{what}: position {T[..., :3, 3]} != {ref[..., :3, 3]}")
    assert np.allclose(T[..., :3, :3], ref[..., :3, :3], atol=tol, rtol=0), (
        f"{what}: rotation\n{T[..., :3, :3]}\n!=\n{ref[..., :3, :3]}")


# Vendor flange frames relative to the ROS/OPW 'tool0' frame (Z out of the flange):
#   KUKA $FLANGE has X out of the flange: flange = tool0 @ Ry(-90 deg)   (tool0 = flange @ Ry(90)).
#   ABB tool0 is the ROS tool0 (identity).
#   Fanuc faceplate = ROS tool0 = link_6 @ rpy(180, -90, 0); the OPW tool frame has X down at the
#   zero pose while the faceplate has X up: faceplate = opw @ Rz(180 deg).
KUKA_FROM_TOOL0 = hom(ry(-PI / 2))
FANUC_FROM_OPW = hom(rz(PI))


# ----------------------------------------------------------------------------------------------
# Published URDF chains: (xyz, rpy, axis) per joint, metres / radians
# ----------------------------------------------------------------------------------------------
def ur_chain(d1, a2, a3, d4, d5, d6):
    """Layout of ur_description/config/<model>/default_kinematics.yaml
    (ros-industrial/universal_robot):
    shoulder z=d1; upper_arm roll=pi/2; forearm x=a2; wrist_1 x=a3 z=d4; wrist_2 y=-d5 roll=pi/2;
    wrist_3 y=d6 roll=pi/2 pitch=pi yaw=pi. All joints turn about their local Z. The chain starts in
    the controller's Base frame (ur_description: base = base_link turned 180 deg about Z, and the
    shoulder joint hangs off base_link_inertia, which is turned the same way); tool0 = wrist_3_link
    (flange rpy (0,-pi/2,-pi/2) then tool0 rpy (pi/2,0,pi/2) compose to the identity).
    """
    z = (0, 0, 1)
    return [((0, 0, d1), (0, 0, 0), z), ((0, 0, 0), (PI / 2, 0, 0), z), ((a2, 0, 0), (0, 0, 0), z),
            ((a3, 0, d4), (0, 0, 0), z), ((0, -d5, 0), (PI / 2, 0, 0), z),
            ((0, d6, 0), (PI / 2, PI, PI), z)]


# ur5e / ur3e: literal values of default_kinematics.yaml (tiny 2e-11 z terms left out).
UR_CHAINS = {
    "ur3e": ur_chain(0.15185, -0.24355, -0.2132, 0.13105, 0.08535, 0.0921),
    "ur5e": ur_chain(0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.09959999999999999),
    "ur10e": ur_chain(0.1807, -0.6127, -0.57155, 0.17415, 0.11985, 0.11655),
}
# ur3e/ur5e yaml store roll 1.570796327 (rounded) and 2e-11 offsets, hence a looser tolerance there.
UR_TOL = {"ur3e": 2e-9, "ur5e": 2e-9, "ur10e": TOL}


def kuka_chain(a1z, a2x, a3x, a4xz, a5x, a6x=0.0):
    """ros-industrial/kuka_experimental KUKA layout: joint_a1 (0,0,c1) axis -Z;
    joint_a2 (a1,0,0) +Y;
    joint_a3 (c2,0,0) +Y; joint_a4 (x, 0, z) -X; joint_a5 (c3',0,0) +Y; joint_a6 (.,0,0) -X."""
    return [((0, 0, a1z), (0, 0, 0), (0, 0, -1)), ((a2x, 0, 0), (0, 0, 0), (0, 1, 0)),
            ((a3x, 0, 0), (0, 0, 0), (0, 1, 0)), ((a4xz[0], 0, a4xz[1]), (0, 0, 0), (-1, 0, 0)),
            ((a5x, 0, 0), (0, 0, 0), (0, 1, 0)), ((a6x, 0, 0), (0, 0, 0), (-1, 0, 0))]


def abb_chain(j1, j2, j3, j4, j5, j6):
    """ros-industrial/abb layout: axes +Z, +Y, +Y, +X, +Y, +X; rpy all zero."""
    axes = [(0, 0, 1), (0, 1, 0), (0, 1, 0), (1, 0, 0), (0, 1, 0), (1, 0, 0)]
    return [(xyz, (0, 0, 0), ax) for xyz, ax in zip((j1, j2, j3, j4, j5, j6), axes)]


def fanuc_chain(j1, j2, j3, j4, j5, j6):
    """ros-industrial/fanuc layout: axes +Z, +Y, -Y, -X, -Y, -X; rpy all zero."""
    axes = [(0, 0, 1), (0, 1, 0), (0, -1, 0), (-1, 0, 0), (0, -1, 0), (-1, 0, 0)]
    return [(xyz, (0, 0, 0), ax) for xyz, ax in zip((j1, j2, j3, j4, j5, j6), axes)]


# name -> (chain, T_base_baselink (vendor base from URDF base_link), T_link6_flange (vendor flange))
URDF_CHAINS = {
    # kuka_kr6_support/urdf/kr6r700sixx_macro.xacro; flange = link_6 ('flange' frame, X out)
    "kuka_kr6_r700_sixx": (kuka_chain(0.4, 0.025, 0.315, (0, 0.035), 0.365, 0.080), None, None),
    # kuka_kr6_support/urdf/kr6r900_2_macro.xacro
    "kuka_kr6_r900": (kuka_chain(0.400, 0.025, 0.455, (0, 0.025), 0.420, 0.090), None, None),
    # kuka_kr16_support/urdf/kr16_2_macro.xacro: A4 at (0.67, 0, -0.035), A5/A6 at 0,
    # tool0 at x 0.158
    "kuka_kr16": (kuka_chain(0.675, 0.26, 0.68, (0.67, -0.035), 0.0, 0.0), None,
                  hom(p=(0.158, 0, 0))),
    # kuka_kr210_support/urdf/kr210r2700extra_macro.xacro
    "kuka_kr210_r2700": (kuka_chain(0.675, 0.350, 1.150, (0, -0.041), 1.200, 0.215), None, None),
    # abb_irb120_support/urdf/irb120_3_58_macro.xacro; tool0 = link_6 @ Ry(90)
    "abb_irb120": (abb_chain((0, 0, 0), (0, 0, 0.29), (0, 0, 0.27), (0, 0, 0.07), (0.302, 0, 0),
                             (0.072, 0, 0)), None, hom(ry(PI / 2))),
    # abb_irb2400_support/urdf/irb2400_macro.xacro (1.3.1): joint_6-tool0 rpy (0, pi/2, 0),
    # the ABB tool0 (since ros-industrial/abb commit 41966cf, issue #32)
    "abb_irb2400": (abb_chain((0, 0, 0), (0.1, 0, 0.615), (0, 0, 0.705), (0.258, 0, 0.135),
                              (0.497, 0, 0), (0.085, 0, 0)), None, hom(ry(PI / 2))),
    # abb_irb6700_support/urdf/irb6700_200_260_macro.xacro
    "abb_irb6700": (abb_chain((0, 0, 0.78), (0.32, 0, 0), (0, 0, 1.125), (0, 0, 0.2),
                              (1.1425, 0, 0), (0.2, 0, 0)), None, hom(ry(PI / 2))),
    # fanuc_lrmate200id_support/urdf/lrmate200id_macro.xacro; base at z 0.330,
    # tool0 rpy (pi, -pi/2, 0)
    "fanuc_lrmate200id": (fanuc_chain((0, 0, 0.330), (0.050, 0, 0), (0, 0, 0.330), (0, 0, 0.035),
                                      (0.335, 0, 0), (0.080, 0, 0)),
                          hom(p=(0, 0, -0.330)), urdf_origin((0, 0, 0), (PI, -PI / 2, 0))),
    # fanuc_m20ia_support/urdf/m20ia_macro.xacro; base at z 0.525
    "fanuc_m20ia": (fanuc_chain((0, 0, 0.525), (0.150, 0, 0), (0, 0, 0.790), (0, 0, 0.250),
                                (0.835, 0, 0), (0.100, 0, 0)),
                    hom(p=(0, 0, -0.525)), urdf_origin((0, 0, 0), (PI, -PI / 2, 0))),
}

# OPW parameter sets (metres). 'published' ones are copied from the named files; the others are
# read off the URDF / catalogue dimensions (still a different formula from the DH product).
KUKA_SIGN = [-1, 1, 1, -1, 1, -1]
KUKA_OFF = [0, -PI / 2, 0, 0, 0, 0]
ABB_OFF = [0, 0, -PI / 2, 0, 0, 0]
OPW = {
    # opw_kinematics include/opw_kinematics/opw_parameters_examples.h makeKukaKR6_R700_sixx
    "kuka_kr6_r700_sixx": ({"a1": 0.025, "a2": -0.035, "b": 0.0, "c1": 0.400, "c2": 0.315, "c3": 0.365, "c4": 0.080,
                                "offsets": KUKA_OFF, "sign": KUKA_SIGN}, KUKA_FROM_TOOL0),
    # kuka_experimental kuka_kr6_support/config/opw_parameters_kr6r900_2.yaml
    "kuka_kr6_r900": ({"a1": 0.025, "a2": -0.025, "b": 0.0, "c1": 0.400, "c2": 0.455, "c3": 0.420, "c4": 0.090,
                           "offsets": KUKA_OFF, "sign": KUKA_SIGN}, KUKA_FROM_TOOL0),
    # kuka_experimental kuka_kr16_support/config/opw_parameters_kr16_2.yaml
    "kuka_kr16": ({"a1": 0.260, "a2": 0.035, "b": 0.0, "c1": 0.675, "c2": 0.680, "c3": 0.670, "c4": 0.158,
                       "offsets": KUKA_OFF, "sign": KUKA_SIGN}, KUKA_FROM_TOOL0),
    # read off kr210r2700extra_macro.xacro
    "kuka_kr210_r2700": ({"a1": 0.350, "a2": 0.041, "b": 0.0, "c1": 0.675, "c2": 1.150, "c3": 1.200, "c4": 0.215,
                              "offsets": KUKA_OFF, "sign": KUKA_SIGN}, KUKA_FROM_TOOL0),
    # read off robotkinematicscatalogue KUKA_KR1000_L750_titan.py (A4 axis 65 mm above A3)
    "kuka_kr1000_titan": ({"a1": 0.600, "a2": -0.065, "b": 0.0, "c1": 1.100, "c2": 1.400, "c3": 1.600, "c4": 0.372,
                               "offsets": KUKA_OFF, "sign": KUKA_SIGN}, KUKA_FROM_TOOL0),
    # opw_kinematics opw_parameters_examples.h makeIrb2400_10
    "abb_irb2400": ({"a1": 0.100, "a2": -0.135, "b": 0.0, "c1": 0.615, "c2": 0.705, "c3": 0.755, "c4": 0.085,
                         "offsets": ABB_OFF, "sign": [1] * 6}, np.eye(4)),
    # read off irb120_3_58_macro.xacro / irb6700_200_260_macro.xacro
    "abb_irb120": ({"a1": 0.0, "a2": -0.070, "b": 0.0, "c1": 0.290, "c2": 0.270, "c3": 0.302, "c4": 0.072,
                        "offsets": ABB_OFF, "sign": [1] * 6}, np.eye(4)),
    "abb_irb6700": ({"a1": 0.320, "a2": -0.200, "b": 0.0, "c1": 0.780, "c2": 1.125, "c3": 1.1425, "c4": 0.200,
                         "offsets": ABB_OFF, "sign": [1] * 6}, np.eye(4)),
    # read off the Fanuc URDFs; OPW base = robot foot, Fanuc world is c1 higher
    "fanuc_lrmate200id": ({"a1": 0.050, "a2": -0.035, "b": 0.0, "c1": 0.330, "c2": 0.330, "c3": 0.335, "c4": 0.080,
                               "offsets": ABB_OFF, "sign": [1, 1, -1, -1, -1, -1]}, FANUC_FROM_OPW),
    "fanuc_m20ia": ({"a1": 0.150, "a2": -0.250, "b": 0.0, "c1": 0.525, "c2": 0.790, "c3": 0.835, "c4": 0.100,
                         "offsets": ABB_OFF, "sign": [1, 1, -1, -1, -1, -1]}, FANUC_FROM_OPW),
}
OPW_BASE = {"fanuc_lrmate200id": hom(p=(0, 0, -0.330)), "fanuc_m20ia": hom(p=(0, 0, -0.525))}


# ----------------------------------------------------------------------------------------------
# Library-wide checks
# ----------------------------------------------------------------------------------------------
def test_required_robots_listed():
    names = robotcell.list_robots()
    missing = [n for n in REQUIRED if n not in names]
    assert not missing, f"library lacks {missing}"


@pytest.mark.parametrize("name", REQUIRED)
def test_metadata_and_home(name):
    robot = robotcell.load_robot(name)
    assert robot.name == name
    assert robot.n_joints == 6
    assert isinstance(robot.verified, bool)
    assert len(robot.source) > 40 and len(robot.verification) > 40
    for j in robot.joints:
        assert j.sign in (1.0, -1.0)
        assert j.lower < j.upper
    if robot.home is not None:
        assert robot.within_limits(robot.home)
        T = robot.fk(robot.home)
        assert np.allclose(T[:3, :3] @ T[:3, :3].T, np.eye(3), atol=1e-12)
        assert np.isclose(np.linalg.det(T[:3, :3]), 1.0)


@pytest.mark.parametrize("name", REQUIRED)
def test_batched_fk_matches_single(name):
    robot = robotcell.load_robot(name)
    rng = np.random.default_rng(7)
    q = random_q(robot, rng, 5)
    batch = robot.fk(q)
    for k in range(5):
        assert np.allclose(batch[k], robot.fk(q[k]), atol=1e-12)


# ----------------------------------------------------------------------------------------------
# Independent chains
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(UR_CHAINS))
def test_ur_matches_calibration_chain(name):
    robot = robotcell.load_robot(name)
    rng = np.random.default_rng(11)
    for q in random_q(robot, rng, 25):
        assert_pose(robot.fk(q), urdf_fk(UR_CHAINS[name], q), UR_TOL[name], name)


@pytest.mark.parametrize("name", sorted(URDF_CHAINS))
def test_matches_ros_industrial_urdf(name):
    chain, pre, post = URDF_CHAINS[name]
    # URDFs (and the OPW closed form below) count serial joint angles: compare the model's chain;
    # the J2/J3 coupling of the FANUC and IRB 2400 controllers is tested in test_coupling.py.
    robot = robotcell.load_robot(name).uncoupled()
    rng = np.random.default_rng(3)
    for q in random_q(robot, rng, 25):
        assert_pose(robot.fk(q), urdf_fk(chain, q, pre, post), TOL, name)


# <limit lower upper> of joint_1..joint_6 (radians, or the macro's ${radians(deg)} in degrees).
ROS_LIMITS = {
    # ros-industrial/fanuc fanuc_lrmate200id_support/urdf/lrmate200id_macro.xacro, package 0.5.1
    # (limits in degrees since commit 94d06d5, 2020-08-07; J3 was -2.450966 .. 4.886922 rad)
    "fanuc_lrmate200id": np.radians([(-170, 170), (-100, 145), (-70, 205), (-190, 190),
                                     (-125, 125), (-360, 360)]),
    # ros-industrial/fanuc fanuc_m20ia_support/urdf/m20ia_macro.xacro
    "fanuc_m20ia": np.array([(-2.967060, 2.967060), (-1.745329, 2.792527), (-3.228859, 4.766843),
                             (-3.490658, 3.490658), (-2.443461, 2.443461), (-4.712389, 4.712389)]),
}


@pytest.mark.parametrize("name", sorted(ROS_LIMITS))
def test_fanuc_limits_are_the_ros_industrial_ones(name):
    # The files round the radians to 0.01 deg (M-20iA J3 273.12 deg); robotcell applies the
    # limits to the pendant's values (docs/robots.md, "J2/J3 coupling").
    robot = robotcell.load_robot(name)
    ros = ROS_LIMITS[name]
    assert np.allclose(robot.lower, ros[:, 0], rtol=0, atol=0.006 * DEG)
    assert np.allclose(robot.upper, ros[:, 1], rtol=0, atol=0.006 * DEG)


@pytest.mark.parametrize("name", sorted(OPW))
def test_matches_opw_closed_form(name):
    params, fix = OPW[name]
    base = OPW_BASE.get(name, np.eye(4))
    robot = robotcell.load_robot(name).uncoupled()
    rng = np.random.default_rng(5)
    for q in random_q(robot, rng, 25):
        assert_pose(robot.fk(q), base @ opw_fk(params, q) @ fix, TOL, name)


# ----------------------------------------------------------------------------------------------
# Hand-computed poses (datasheet / URDF dimensions in mm)
# ----------------------------------------------------------------------------------------------
# Flange position at the given configuration (deg), from the dimension drawings / URDF offsets:
HAND = {
    # UR: q = 0 puts the flange at (a2 + a3, -(d4 + d6), d1 - d5)   (UR article values)
    "ur3e": ([0] * 6, (-243.55 - 213.2, -(131.05 + 92.1), 151.85 - 85.35)),
    "ur5e": ([0] * 6, (-425 - 392.2, -(133.3 + 99.6), 162.5 - 99.7)),
    "ur10e": ([0] * 6, (-612.7 - 571.55, -(174.15 + 116.55), 180.7 - 119.85)),
    # KUKA home (0,-90,90,0,0,0): upper arm vertical, forearm horizontal;
    # X = a1 + c3 + c4, Z = c1 + c2 - a2(opw)
    "kuka_kr6_r700_sixx": ([0, -90, 90, 0, 0, 0], (25 + 365 + 80, 0, 400 + 315 + 35)),
    "kuka_kr6_r900": ([0, -90, 90, 0, 0, 0], (25 + 420 + 90, 0, 400 + 455 + 25)),
    "kuka_kr16": ([0, -90, 90, 0, 0, 0], (260 + 670 + 158, 0, 675 + 680 - 35)),
    "kuka_kr210_r2700": ([0, -90, 90, 0, 0, 0], (350 + 1200 + 215, 0, 675 + 1150 - 41)),
    "kuka_kr1000_titan": ([0, -90, 90, 0, 0, 0], (600 + 1600 + 372, 0, 1100 + 1400 + 65)),
    # KUKA zero: arm stretched horizontally; Z = c1 - a2(opw)
    "kuka_kr16@0": ([0] * 6, (260 + 680 + 670 + 158, 0, 675 - 35)),
    # ABB calibration position (all 0): X = a1 + c3 + c4, Z = c1 + c2 - a2(opw)
    "abb_irb120": ([0] * 6, (302 + 72, 0, 290 + 270 + 70)),
    "abb_irb2400": ([0] * 6, (100 + 755 + 85, 0, 615 + 705 + 135)),
    "abb_irb6700": ([0] * 6, (320 + 1142.5 + 200, 0, 780 + 1125 + 200)),
    # Fanuc all 0 in the world frame (origin at J2 height): X = a1 + c3 + c4, Z = c2 - a2(opw)
    "fanuc_lrmate200id": ([0] * 6, (50 + 335 + 80, 0, 330 + 35)),
    "fanuc_m20ia": ([0] * 6, (150 + 835 + 100, 0, 790 + 250)),
    # Puma 560 (Corke): fkine(qz) = (a2 + a3, -d3, d1 + d4) -- RVC's (0.4521, -0.1500, 0.4318)
    # with the 671.83 mm (26.45 in) base height added; fkine(qr) (arm up) = (a3, -d3, d1 + a2 + d4).
    "puma560": ([0] * 6, (431.8 + 20.3, -150.05, 671.83 + 431.8)),
    "puma560@qr": ([0, 90, -90, 0, 0, 0], (20.3, -150.05, 671.83 + 431.8 + 431.8)),
    # Stanford arm with q1 = q2 = 0: boom vertical, flange at (0, d2 - a3, d1 + d3)
    "stanford_arm": ([0, 0, 500, 0, 0, 0], (0, 154 - 20.3, 412 + 500)),
    "stanford_arm@1000": ([0, 0, 1000, 0, 0, 0], (0, 154 - 20.3, 412 + 1000)),
}


@pytest.mark.parametrize("key", sorted(HAND))
def test_hand_computed_flange_position(key):
    name = key.split("@")[0]
    q_file, p_mm = HAND[key]
    robot = robotcell.load_robot(name)
    q = np.array([v / 1000 if j.prismatic else v * DEG for v, j in zip(q_file, robot.joints)])
    T = robot.fk(q)
    assert np.allclose(T[:3, 3], np.array(p_mm) / 1000, atol=TOL, rtol=0), (key, T[:3, 3] * 1000)


# Orientation of the vendor flange at the zero / home pose, as the controller defines it.
ORIENT = {
    # KUKA $FLANGE: X out of the flange, parallel to ROBROOT at the zero pose and at home
    "kuka_kr16": ([0, -90, 90, 0, 0, 0], np.eye(3)),
    "kuka_kr6_r700_sixx": ([0] * 6, np.eye(3)),
    "kuka_kr1000_titan": ([0, -90, 90, 0, 0, 0], np.eye(3)),
    # ABB tool0 at the calibration position: quaternion [0.70711, 0, 0.70711, 0] = Ry(90 deg)
    "abb_irb120": ([0] * 6, ry(PI / 2)),
    "abb_irb6700": ([0] * 6, ry(PI / 2)),
    # Fanuc faceplate at all zero: W, P, R = 180, -90, 0 -> Rz(0) Ry(-90) Rx(180)
    "fanuc_lrmate200id": ([0] * 6, ry(-PI / 2) @ rx(PI)),
    # UR tool0 at zero: the flange faces -Y of Base with X along +X, i.e. Rx(90 deg)
    # (UR frame diagram: wrist 3 axis along -Y at the zero pose; rotation vector (pi/2, 0, 0)).
    "ur5e": ([0] * 6, rx(PI / 2)),
}


@pytest.mark.parametrize("name", sorted(ORIENT))
def test_flange_orientation(name):
    q_deg, R = ORIENT[name]
    robot = robotcell.load_robot(name)
    T = robot.fk(np.array(q_deg) * DEG)
    assert np.allclose(T[:3, :3], R, atol=TOL), T[:3, :3]


# Datasheet reach (mm): max distance of the wrist point from the A1 axis, in the arm plane,
# = a1 + c2 + sqrt(c3^2 + a2^2). Datasheets round to 1 mm (KUKA sixx to 0.1 mm).
REACH = {
    "kuka_kr6_r700_sixx": (706.7, 0.05, "x"),   # KR AGILUS sixx datasheet: 706.7 mm
    "kuka_kr16": (1611, 0.5, "x"),              # KR 16-2 datasheet: 1611 mm
    "kuka_kr1000_titan": (3601, 0.5, "x"),      # KR 1000 L750 titan: 3601 mm
    "abb_irb120": (580, 0.5, "z"),              # IRB 120 product specification: 580 mm
    "fanuc_lrmate200id": (717, 0.5, "z"),       # LR Mate 200iD datasheet: 717 mm
    "fanuc_m20ia": (1811, 1.0, "z"),            # M-20iA datasheet: 1811 mm
}


@pytest.mark.parametrize("name", sorted(REACH))
def test_datasheet_reach(name):
    reach, tol_mm, normal = REACH[name]
    robot = robotcell.load_robot(name)
    params, _ = OPW[name]
    c4 = params["c4"]
    # tool that moves the TCP from the flange back to the wrist point along the flange normal
    tool = hom(p=(-c4, 0, 0) if normal == "x" else (0, 0, -c4))
    q3 = np.linspace(-PI, PI, 200001)
    q = np.zeros((q3.size, 6))
    q[:, 1] = -PI / 2 if name.startswith("kuka") else 0.0
    q[:, 2] = q3
    w = robot.fk(q, tool=tool)[:, :3, 3]
    base_z = 0.0 if name.startswith("fanuc") else params["c1"]
    shoulder = np.array([params["a1"], 0.0, base_z])
    r = np.linalg.norm(w - shoulder, axis=1).max() + params["a1"]
    assert abs(r * 1000 - reach) < tol_mm, (name, r * 1000)


# ----------------------------------------------------------------------------------------------
# Axis directions as the controllers count them
# ----------------------------------------------------------------------------------------------
def _moved(robot, q_deg, axis, delta_deg=1.0):
    q = np.array(q_deg, dtype=float) * DEG
    q2 = q.copy()
    q2[axis] += delta_deg * DEG
    return robot.fk(q2)[:3, 3] - robot.fk(q)[:3, 3]


@pytest.mark.parametrize("name", ["kuka_kr6_r700_sixx", "kuka_kr6_r900", "kuka_kr16",
                                  "kuka_kr210_r2700", "kuka_kr1000_titan"])
def test_kuka_axis_directions(name):
    robot = robotcell.load_robot(name)
    home = [0, -90, 90, 0, 0, 0]
    # A1 positive turns clockwise seen from above: the flange (at +X) moves to -Y.
    assert _moved(robot, home, 0)[1] < 0
    # A2 positive tilts the (vertical) upper arm forward: flange moves to +X.
    assert _moved(robot, home, 1)[0] > 0
    # A3 positive lowers the (horizontal) forearm: flange moves down.
    assert _moved(robot, home, 2)[2] < 0
    # A5 positive at home tilts the flange down (rotation about +Y of the forearm).
    assert _moved(robot, home, 4)[2] < 0
    # A4 / A6 turn about -X: with A5 = 90 (flange hanging below the wrist) a positive A4
    # rotation about -X swings the flange to -Y.
    assert _moved(robot, [0, -90, 90, 0, 90, 0], 3)[1] < 0


@pytest.mark.parametrize("name", ["abb_irb120", "abb_irb2400", "abb_irb6700",
                                  "fanuc_lrmate200id", "fanuc_m20ia"])
def test_abb_fanuc_axis_directions(name):
    robot = robotcell.load_robot(name)
    zero = [0] * 6
    # J1 positive is counter-clockwise seen from above: flange (at +X) moves to +Y.
    assert _moved(robot, zero, 0)[1] > 0
    # J2 positive tilts the vertical upper arm forward.
    assert _moved(robot, zero, 1)[0] > 0
    # J3: ABB positive lowers the forearm; Fanuc positive raises it (URDF axis -Y).
    dz = _moved(robot, zero, 2)[2]
    assert dz < 0 if name.startswith("abb") else dz > 0
    # J5: ABB positive tilts the flange down; Fanuc positive tilts it up.
    dz5 = _moved(robot, zero, 4)[2]
    assert dz5 < 0 if name.startswith("abb") else dz5 > 0


@pytest.mark.parametrize("name", ["ur3e", "ur5e", "ur10e"])
def test_ur_base_joint_counter_clockwise(name):
    robot = robotcell.load_robot(name)
    # At q = 0 the arm points along -X of Base; positive base rotation (about +Z) moves it to -Y.
    assert _moved(robot, [0] * 6, 0)[1] < 0


def test_stanford_prismatic_joint_moves_along_boom():
    robot = robotcell.load_robot("stanford_arm")
    assert robot.joints[2].type == "prismatic"
    rng = np.random.default_rng(13)
    for q in random_q(robot, rng, 10):
        q2 = q.copy()
        q2[2] += 0.1
        T1, T2 = robot.fk(q), robot.fk(q2)
        # The boom direction is the Z axis of DH frame 2, which does not depend on q3..q6.
        z2 = robot.frames(q)[2, :3, 2]
        assert np.allclose(T2[:3, 3] - T1[:3, 3], 0.1 * z2, atol=TOL)
        assert np.allclose(T2[:3, :3], T1[:3, :3], atol=TOL)
