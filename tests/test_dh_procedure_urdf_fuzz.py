"""``robotcell dh from-urdf`` on 100 seeded random serial URDFs: every model file it writes moves
like the URDF to 1e-9 m, and holds no length beyond 100 m.

The chains have 3-7 revolute and prismatic joints whose consecutive axes are parallel,
antiparallel, coincident, intersecting, skew (also about general ``axis`` vectors), nearly
parallel or antiparallel by 1e-9 to 1e-6 rad, or turned by quarter turns written with 4 to 9
decimals (nearly parallel or perpendicular after the rounding); the URDF text is rounded as files
are (xyz to the micrometre, rpy to 4-9 decimals, axes to 6). The reference is pinocchio's own URDF
reader and forward kinematics, not robotcell's; the model is the file the command wrote, read back.
"""

import math
import re

import numpy as np
import pinocchio as pin
import pytest
from cli_helpers import run
from model_file_helpers import largest_number, read

from robotcell.dhprocedure import dh_from_urdf
from robotcell.errors import InputError
from robotcell.robot.models import robot_from_dict

EXACT = 1e-9  # m
RELATIONS = ("parallel", "antiparallel", "coincident", "intersecting", "skew", "general",
             "nearly parallel", "nearly antiparallel", "quarter turns")


def _num(v: float, decimals: int) -> str:
    s = f"{v:.{decimals}f}".rstrip("0").rstrip(".")
    return "0" if s in ("", "-0") else s


def _joint(rng: np.random.Generator, relation: str, scale: float) -> tuple[list, list, str]:
    """Origin xyz, rpy (text) and axis of a joint whose axis relates to the previous one (the
    previous joint's axis is its frame's Z axis unless it was 'general')."""
    dec = int(rng.integers(4, 10))
    xyz = list(rng.uniform(-0.5, 0.5, 3) * scale)
    rpy = [_num(v, dec) for v in rng.uniform(-math.pi, math.pi, 3)]
    axis = f"0 0 {rng.choice([1, -1])}"
    if relation in ("parallel", "antiparallel", "nearly parallel", "nearly antiparallel"):
        rpy = ["0", "0", _num(rng.uniform(-math.pi, math.pi), dec)]
        if relation.startswith("nearly"):  # a tilt of 1e-9..1e-6 rad about a random direction
            tilt = 10 ** rng.uniform(-9, -6) * np.array([math.cos(g := rng.uniform(0, 6.3)),
                                                         math.sin(g)])
            rpy[:2] = [f"{v:.3g}" for v in tilt]
        if relation.endswith("antiparallel"):
            rpy[0] = f"{math.pi + float(rpy[0]):.{int(rng.integers(8, 12))}f}"
    elif relation in ("coincident", "intersecting"):
        xyz[:2] = [0.0, 0.0]  # the origin on the previous axis
        if relation == "coincident":
            rpy[:2] = ["0", "0"]
    elif relation == "quarter turns":
        rpy = [f"{k * round(math.pi / 2, dec):.{dec}f}" for k in rng.integers(-2, 3, 3)]
        xyz = [v * (rng.random() < 0.6) for v in xyz]
    elif relation == "general":
        a = rng.normal(size=3)
        axis = " ".join(_num(v, 6) for v in a / np.linalg.norm(a))
    return [_num(v, 6) for v in xyz], rpy, axis


def random_urdf(rng: np.random.Generator) -> tuple[str, int, list[str]]:
    """A random serial URDF: (text, number of joints, relation of each joint to the previous)."""
    n = int(rng.integers(3, 8))
    scale = float(rng.choice([0.2, 1.0, 5.0]))
    joints, relations = [], []
    for i in range(n):
        free = i == 0 or relations[-1] == "general"
        relation = str(rng.choice(["skew", "general"] if free else RELATIONS))
        xyz, rpy, axis = _joint(rng, relation, scale)
        kind = "prismatic" if rng.random() < 0.2 else "revolute"
        joints.append(
            f'<joint name="j{i + 1}" type="{kind}"><parent link="l{i}"/><child link="l{i + 1}"/>'
            f'<origin xyz="{" ".join(xyz)}" rpy="{" ".join(rpy)}"/><axis xyz="{axis}"/>'
            '<limit lower="-2" upper="2" effort="1" velocity="1"/></joint>')
        relations.append(relation)
    on_axis = rng.random() < 0.4  # the tool on the last axis, or anywhere
    tool_xyz = f"0 0 {_num(rng.uniform(0, 0.2), 4)}" if on_axis else " ".join(
        _num(v, 4) for v in rng.uniform(-0.2, 0.2, 3) * scale)
    tool_rpy = f"0 0 {_num(rng.uniform(-3, 3), 4)}" if on_axis else " ".join(
        _num(v, 4) for v in rng.uniform(-3, 3, 3))
    joints.append(f'<joint name="tool" type="fixed"><parent link="l{n}"/><child link="tool0"/>'
                  f'<origin xyz="{tool_xyz}" rpy="{tool_rpy}"/></joint>')
    links = "".join(f'<link name="l{i}"/>' for i in range(n + 1)) + '<link name="tool0"/>'
    return f'<robot name="random">{links}{"".join(joints)}</robot>', n, relations


def pinocchio_fk(text: str, q: np.ndarray) -> np.ndarray:
    """Poses of ``tool0`` (m) at joint values ``q`` (N, n), by pinocchio."""
    model = pin.buildModelFromXML(text)
    data = model.createData()
    frame = model.getFrameId("tool0")
    out = np.empty((len(q), 4, 4))
    for i, qi in enumerate(q):
        pin.framesForwardKinematics(model, data, qi)
        out[i] = data.oMf[frame].homogeneous
    return out


def test_every_written_model_moves_like_its_urdf_within_1e_9_m(tmp_path, capsys):
    rng = np.random.default_rng(32)
    seen, refused, betas = set(), 0, 0
    for k in range(100):
        text, n, relations = random_urdf(rng)
        seen |= set(relations)
        urdf, out = tmp_path / f"chain{k}.urdf", tmp_path / f"chain{k}.yaml"
        urdf.write_text(text, encoding="utf-8")
        convention = ("standard", "modified")[k % 2]
        code, stdout, err = run(capsys, "dh", "from-urdf", urdf, "--convention", convention,
                                "-o", out)
        if code:  # a refusal says by how much and names the joints
            assert code == 2 and re.search(r"by up to .* m .*joint\(s\) j\d", err), err
            refused += 1
            continue
        assert "check: as a model file holds it" in stdout
        data = read(out)  # what load_robot(out) reads, parsed once for both checks
        model = robot_from_dict(data, str(out))
        q = rng.uniform(-2, 2, (16, n))
        T, ref = model.fk(q), pinocchio_fk(text, q)
        dp = np.linalg.norm(T[:, :3, 3] - ref[:, :3, 3], axis=1).max()
        dr = np.abs(T[:, :3, :3] - ref[:, :3, :3]).max()
        assert dp < EXACT and dr < EXACT, (k, relations, dp, dr)
        assert largest_number(data) <= 1e5, (k, relations)  # no length beyond 100 m
        betas += any(j.beta for j in model.joints)
    assert seen == set(RELATIONS)
    assert refused == 0
    assert betas > 15  # nearly parallel axes met, and took Hayati's beta


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_nearly_antiparallel_axes_take_the_parallel_rule_not_a_normal_kilometres_away(convention):
    # Joints 2 and 3 0.25 m apart and antiparallel but for 3.6e-9 rad about X (pi written with 8
    # decimals) and 1.5e-9 rad about Y: their common normal lies some 1e5 km away. The model
    # puts the normal through the previous one (d = 0), alpha and Hayati's beta take the tilt,
    # and every constant is of the robot's size.
    text = ('<robot name="r"><link name="a"/><link name="b"/><link name="c"/><link name="d"/>'
            '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/>'
            '<origin xyz="0 0 0.4" rpy="1.5708 0 0"/><axis xyz="0 0 1"/></joint>'
            '<joint name="j2" type="revolute"><parent link="b"/><child link="c"/>'
            '<origin xyz="0.3 0.0001 0" rpy="0 0 0.5"/><axis xyz="0 0 1"/></joint>'
            '<joint name="j3" type="revolute"><parent link="c"/><child link="d"/>'
            '<origin xyz="0.25 0 0.05" rpy="3.14159265 0.0000000015 0"/><axis xyz="0 0 1"/></joint>'
            '</robot>')
    der = dh_from_urdf(text, convention)
    assert der.deviation < EXACT
    lengths = [max(abs(j.a), abs(j.d)) for j in der.robot.joints]
    assert max(lengths) < 1.0
    link = der.robot.joints[2] if convention == "modified" else der.robot.joints[1]
    assert link.beta == pytest.approx(1.5e-9, rel=1e-3) or link.beta == pytest.approx(-1.5e-9,
                                                                                        rel=1e-3)
    assert abs(abs(link.alpha) - math.pi) == pytest.approx(math.pi - 3.14159265, rel=1e-3)
    assert link.a == pytest.approx(0.25, abs=1e-6)
    note = der.notes[2]
    assert note.case == "parallel" and "from parallel and their common normal would lie" in note.text
    assert "Hayati's beta" in note.text


def test_a_model_that_would_not_be_exact_is_refused_naming_the_joints_and_the_cause():
    # j3's axis is 2e-7 m beside j2's: with tol = 1e-6 the procedure takes them as one line,
    # which moves the flange by up to about that much when j3 turns.
    text = ('<robot name="r"><link name="a"/><link name="b"/><link name="c"/><link name="d"/>'
            '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/>'
            '<origin xyz="0 0 0.4" rpy="1.5708 0 0"/><axis xyz="0 0 1"/></joint>'
            '<joint name="j2" type="revolute"><parent link="b"/><child link="c"/>'
            '<origin xyz="0.3 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/></joint>'
            '<joint name="j3" type="revolute"><parent link="c"/><child link="d"/>'
            '<origin xyz="0 0.0000002 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/></joint>'
            '<joint name="t" type="fixed"><parent link="d"/><child link="e"/>'
            '<origin xyz="0.2 0 0"/></joint><link name="e"/></robot>')
    assert dh_from_urdf(text).deviation < EXACT  # the default tolerance keeps it exact
    with pytest.raises(InputError, match=r"URDF text: the DH model as written differs from the "
                       r"source's forward kinematics by up to [0-9.e-]+ m or rad .*moving "
                       r"joint\(s\) j3 shows it; the procedure took axes up to tol = 1e-06"):
        dh_from_urdf(text, tol=1e-6)
