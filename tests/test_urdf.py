"""URDF -> axes -> DH: the DH model moves like the URDF, errors name the joint or link."""

import math
import sys
from importlib import resources

import numpy as np
import pytest

import robotcell as rc
from robotcell.dhprocedure.urdf import dh_from_urdf, read_urdf
from robotcell.errors import InputError, RobotcellError

URDF_DIR = resources.files("robotcell") / "robots" / "urdf"
SHIPPED = sorted(p.name for p in URDF_DIR.iterdir() if p.name.endswith(".urdf"))


def urdf(joints: str, links: str) -> str:
    return f'<robot name="test">{links}{joints}</robot>'


def joint(name, jtype, parent, child, xyz="0 0 0", rpy="0 0 0", axis="0 0 1", limit=True):
    lim = '<limit lower="-1" upper="1" effort="1" velocity="1"/>' if limit else ""
    ax = f'<axis xyz="{axis}"/>' if axis is not None else ""
    return (f'<joint name="{name}" type="{jtype}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/>{ax}{lim}</joint>')


def links(*names):
    return "".join(f'<link name="{n}"/>' for n in names)


# A SCARA-like chain with a prismatic and a continuous joint, fixed joints in the middle and at
# the end, non-trivial origins.
SCARA = urdf(
    joint("j1", "revolute", "base", "l1", xyz="0.1 0.2 0.3", rpy="0.1 0 0.2")
    + joint("mount", "fixed", "l1", "l1b", xyz="0.35 0 0.05", rpy="0 0 0.3", axis=None, limit=False)
    + joint("j2", "continuous", "l1b", "l2", xyz="0 0 0", axis="0 0 1", limit=False)
    + joint("j3", "prismatic", "l2", "l3", xyz="0.3 0 0", axis="0 0 -1")
    + joint("j4", "revolute", "l3", "l4", xyz="0 0 -0.1", rpy="0.2 -0.1 0", axis="1 1 0")
    + joint("tcp", "fixed", "l4", "tool", xyz="0.01 0.02 0.12", rpy="1 2 3", axis=None, limit=False),
    links("base", "l1", "l1b", "l2", "l3", "l4", "tool"),
)


def pose_error(A, B):
    dp = np.linalg.norm(A[..., :3, 3] - B[..., :3, 3], axis=-1).max()
    dR = np.linalg.norm(A[..., :3, :3] - B[..., :3, :3], axis=(-2, -1)).max()
    return dp, dR


def test_files_are_shipped():
    assert {"ur5e.urdf", "kuka_kr6_r700_sixx.urdf"} <= set(SHIPPED)


@pytest.mark.parametrize("name", SHIPPED)
@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_shipped_urdf_dh_matches_urdf_fk(name, convention):
    path = str(URDF_DIR / name)
    chain = read_urdf(path)
    der = dh_from_urdf(path, convention)
    q = np.random.default_rng(5).uniform(-math.pi, math.pi, (300, chain.n_joints))
    dp, dR = pose_error(der.robot.fk(q), chain.fk(q))
    assert dp < 1e-9 and dR < 1e-9
    dp, dR = pose_error(chain.axes().fk(q), chain.fk(q))
    assert dp < 1e-9 and dR < 1e-9
    assert der.robot.name == name[:-5]
    assert [j.name for j in der.robot.joints] == [j.name for j in chain.joints]


def test_ur5e_urdf_is_the_library_ur5e():
    assert "ur5e" in rc.list_robots()  # a library model: its absence is a failure
    chain = read_urdf(str(URDF_DIR / "ur5e.urdf"))
    assert chain.tip_link == "tool0" and chain.base_link == "base_link"
    q = np.random.default_rng(6).uniform(-3, 3, (100, 6))
    # base_link is the controller's Base frame turned by pi about Z; tool0 is the DH frame 6.
    expected = rc.make_pose(rc.rot_z(math.pi)) @ rc.load_robot("ur5e").fk(q)
    assert pose_error(chain.fk(q), expected)[0] < 1e-9
    assert pose_error(chain.fk(q), expected)[1] < 1e-9


def test_kr6_urdf_is_the_library_kr6_and_sign_corrections_recover_its_table():
    assert "kuka_kr6_r700_sixx" in rc.list_robots()  # a library model: its absence is a failure
    lib = rc.load_robot("kuka_kr6_r700_sixx")
    path = str(URDF_DIR / "kuka_kr6_r700_sixx.urdf")
    q = np.random.default_rng(7).uniform(-3, 3, (100, 6))
    # tool0 is the KUKA flange turned by +90 deg about Y.
    expected = lib.fk(q) @ rc.make_pose(rc.rot_y(math.pi / 2))
    dp, dR = pose_error(read_urdf(path).fk(q), expected)
    assert dp < 1e-9 and dR < 1e-9
    der = dh_from_urdf(path, signs=[j.sign for j in lib.joints])
    for mine, theirs in zip(der.robot.joints[:4], lib.joints[:4]):
        assert (mine.a, mine.d, mine.sign) == pytest.approx((theirs.a, theirs.d, theirs.sign))
        assert (mine.alpha, mine.theta) == pytest.approx((theirs.alpha, theirs.theta))
    assert np.allclose(der.robot.lower, lib.lower) and np.allclose(der.robot.upper, lib.upper)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_prismatic_continuous_and_fixed_joints(convention):
    chain = read_urdf(SCARA)
    assert [j.name for j in chain.joints] == ["j1", "j2", "j3", "j4"]
    assert [j.type for j in chain.joints] == ["revolute", "revolute", "prismatic", "revolute"]
    assert chain.joints[1].lower == -math.inf and chain.joints[1].upper == math.inf
    assert chain.joints[2].lower == -1 and chain.tip_link == "tool"
    der = dh_from_urdf(SCARA, convention)
    q = np.random.default_rng(8).uniform(-2, 2, (200, 4))
    dp, dR = pose_error(der.robot.fk(q), chain.fk(q))
    assert dp < 1e-9 and dR < 1e-9


def test_fixed_joint_is_merged_into_the_next_origin():
    chain = read_urdf(SCARA)
    # j2's origin is j1's child link -> mount (fixed) -> j2 (identity origin).
    mount = rc.make_pose(rc.rot_z(0.3), [0.35, 0, 0.05])
    assert np.allclose(chain.joints[1].origin, mount)


def test_model_file_round_trip(tmp_path):
    der = dh_from_urdf(str(URDF_DIR / "ur5e.urdf"))
    rc.save_robot(der.robot, tmp_path / "ur5e_dh.yaml")
    back = rc.load_robot(tmp_path / "ur5e_dh.yaml")
    q = np.random.default_rng(9).uniform(-3, 3, (50, 6))
    assert pose_error(back.fk(q), der.robot.fk(q))[0] < 1e-9
    assert "ur5e.urdf" in back.source


def test_branching_urdf_names_the_link_and_joints():
    text = urdf(joint("arm", "revolute", "base", "a") + joint("cam", "revolute", "base", "c"),
                links("base", "a", "c"))
    with pytest.raises(InputError, match="link 'base' branches into joints arm, cam"):
        read_urdf(text)
    assert [j.name for j in read_urdf(text, tip_link="c").joints] == ["cam"]


@pytest.mark.parametrize("jtype", ["floating", "planar"])
def test_unsupported_joint_is_named(jtype):
    text = urdf(joint("j1", "revolute", "base", "a") + joint("free", jtype, "a", "b", limit=False),
                links("base", "a", "b"))
    with pytest.raises(InputError, match=f"joint 'free' is {jtype}"):
        read_urdf(text)
    assert read_urdf(text, tip_link="a").n_joints == 1


def test_zero_axis_is_named():
    text = urdf(joint("j1", "revolute", "base", "a", axis="0 0 0"), links("base", "a"))
    with pytest.raises(InputError, match="joint 'j1' has an axis of zero length"):
        read_urdf(text)


def test_other_bad_input(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        read_urdf(tmp_path / "missing.urdf")
    with pytest.raises(InputError, match="not a readable URDF"):
        read_urdf("<robot name='x'><link name='a'></robot>")
    text = urdf(joint("j1", "revolute", "base", "a"), links("base", "a", "lonely"))
    with pytest.raises(InputError, match="tip_link 'nope' is not a link"):
        read_urdf(text, tip_link="nope")
    with pytest.raises(InputError, match="tip_link 'base' is not below base_link 'a'"):
        read_urdf(text, base_link="a", tip_link="base")
    fixed_only = urdf(joint("f", "fixed", "base", "a", axis=None, limit=False), links("base", "a"))
    with pytest.raises(InputError, match="no revolute, continuous or prismatic joint"):
        read_urdf(fixed_only)
    with pytest.raises(InputError, match="root links: base, lonely.*give base_link"):
        read_urdf(text)
    with pytest.raises(InputError, match=r"q must be finite with shape \(\.\.\., 1\)"):
        read_urdf(text, base_link="base").fk([0.0, 0.0])


def test_missing_parser_says_how_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "urdf_parser_py", None)
    monkeypatch.setitem(sys.modules, "urdf_parser_py.urdf", None)
    with pytest.raises(RobotcellError, match=r"pip install 'robotcell\[urdf\]'"):
        read_urdf(SCARA)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_gantry_with_two_parallel_prismatic_axes(convention):
    # A gantry whose X travel is split over two parallel carriages (a redundant axis, legal):
    # the DH model holds both as prismatic joints and moves like the URDF.
    text = urdf(
        joint("x1", "prismatic", "base", "c1", xyz="0 0 1.5", axis="1 0 0")
        + joint("x2", "prismatic", "c1", "c2", xyz="0 0.2 -0.1", axis="1 0 0")
        + joint("z", "prismatic", "c2", "c3", axis="0 0 -1")
        + joint("c", "revolute", "c3", "tool", xyz="0 0 -0.3", axis="0 0 1"),
        links("base", "c1", "c2", "c3", "tool"),
    )
    chain = read_urdf(text)
    der = dh_from_urdf(text, convention)
    assert [j.type for j in der.robot.joints] == ["prismatic", "prismatic", "prismatic", "revolute"]
    q = np.random.default_rng(8).uniform(-1, 1, (100, 4))
    dp, dR = pose_error(der.robot.fk(q), chain.fk(q))
    assert dp < 1e-9 and dR < 1e-9
