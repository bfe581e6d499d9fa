"""Robot model files: the documented keys, unit handling, and errors naming file, joint and key."""

import math

import numpy as np
import pytest

from robotcell import InputError, list_robots, load_robot, save_robot
from robotcell.kinematics.transforms import make_pose, rot_z

ISSUE_EXAMPLE = """\
name: my_robot
convention: standard        # or: modified
units: {length: mm, angle: deg}
joints:
  - {type: revolute,  a: 25,  alpha: -90, d: 400, theta: 0,   min: -170, max: 170}
  - {type: prismatic, a: 0,   alpha: 0,   d: 0,   theta: 90,  min: 0,    max: 1500}
"""


def write(tmp_path, text, name="robot.yaml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_documented_example_loads_in_si(tmp_path):
    r = load_robot(write(tmp_path, ISSUE_EXAMPLE))
    assert r.name == "my_robot" and r.n_joints == 2
    j1, j2 = r.joints
    assert j1.a == pytest.approx(0.025) and j1.d == pytest.approx(0.4)
    assert j1.alpha == pytest.approx(-math.pi / 2)
    assert j1.lower == pytest.approx(math.radians(-170))
    assert j2.prismatic and j2.upper == pytest.approx(1.5) and j2.theta == pytest.approx(math.pi / 2)
    # d of the prismatic joint is q: q = 0.3 m puts frame 2 0.3 m along z1.
    T = r.fk([0.0, 0.3])
    # frame 1 at x = 0.025 m, z = 0.4 m; alpha = -90 deg turns z1 onto +y0 (third column of
    # Rot(x, -90) is (0, 1, 0)); d2 = 0.3 m slides along it.
    np.testing.assert_allclose(T[:3, 3], [0.025, 0.3, 0.4], atol=1e-12)


def test_optional_keys_sign_base_tool_and_metres(tmp_path):
    text = """\
name: one
units: {length: m, angle: rad}
joints:
  - {type: revolute, a: 1.0, alpha: 0, d: 0, theta: 0, sign: -1}
base: {z: 0.5}
tool: {x: 0.1, a: 1.5707963267948966}
"""
    r = load_robot(write(tmp_path, text))
    T = r.fk([math.pi / 2])
    np.testing.assert_allclose(T[:3, 3], [0.0, -1.1, 0.5], atol=1e-12)


def test_save_and_reload_round_trip(tmp_path):
    for name in ("kuka_kr16", "stanford_arm", "ur5e"):
        r = load_robot(name)
        path = tmp_path / f"{name}.yaml"
        save_robot(r, path)
        r2 = load_robot(path)
        q = np.random.default_rng(0).uniform(-1, 1, (20, r.n_joints))
        np.testing.assert_allclose(r2.fk(q), r.fk(q), atol=1e-12)
        np.testing.assert_allclose(r2.lower, r.lower, atol=1e-12)


def test_library_names_follow_the_rule():
    names = list_robots()
    assert len(names) >= 15
    for n in names:
        assert n == n.lower() and " " not in n and "-" not in n
    for required in ("ur3e", "ur5e", "ur10e", "kuka_kr16", "puma560", "stanford_arm"):
        assert required in names


@pytest.mark.parametrize("text, message", [
    ("name: x\njoints:\n  - {type: revolute, a: 0, alpha: 0, d: 0}\n",
     r"robot.yaml: joint 1: missing key 'theta'"),
    ("joints:\n  - {type: revolute, a: 0, alpha: 0, d: 0, theta: 0}\n",
     r"robot.yaml: missing key 'name'"),
    (("name: x\njoints:\n  - {type: revolute, a: 0, alpha: 0, d: 0, theta: 0}\n"
     "  - {type: slider, a: 0, alpha: 0, d: 0, theta: 0}\n"),
     r"joint 2: key 'type' must be 'revolute' or 'prismatic', got 'slider'"),
    ("name: x\njoints:\n  - {type: revolute, a: ten, alpha: 0, d: 0, theta: 0}\n",
     r"joint 1: key 'a' must be a number, got 'ten'"),
    ("name: x\njoints:\n  - {type: revolute, a: 0, alpha: 0, d: 0, theta: 0, sign: 2}\n",
     r"joint 1: key 'sign' must be \+1 or -1"),
    ("name: x\njoints:\n  - {type: revolute, a: 0, alpha: 0, d: 0, theta: 0, min: 10, max: -10}\n",
     r"joint 1: key 'min' \(10\) must be below key 'max' \(-10\)"),
    ("name: x\njoints:\n  - {type: revolute, a: 0, alpha: 0, d: 0, theta: 0, lenght: 3}\n",
     r"joint 1: unknown key\(s\) \['lenght'\]"),
    ("name: x\nunits: {length: inch}\njoints: []\n", r"units.length must be 'mm' or 'm'"),
    ("name: x\njoints: []\n", r"key 'joints' must be a non-empty list"),
    ("name: x\njoints:\n  - {type: revolute, a: 0, alpha: 0, d: 0, theta: 0}\nbase: {x: 1, q: 2}\n",
     r"key 'base': unknown key\(s\) \['q'\]"),
    ("name: x\njoints:\n  - {type: revolute, a: 0, alpha: 0, d: 0, theta: 0}\nhome: [1, 2]\n",
     r"key 'home' must be a list of 1 joint values"),
    ("name: [unclosed\n", r"robot.yaml: not valid YAML"),
    ("- a\n- b\n", r"robot.yaml: a model file must be a YAML mapping"),
])
def test_bad_files_name_file_joint_and_key(tmp_path, text, message):
    with pytest.raises(InputError, match=message):
        load_robot(write(tmp_path, text))


def test_unknown_names_offer_the_closest():
    with pytest.raises(InputError, match=r"unknown robot 'kuka_kr15'.*did you mean kuka_kr16"):
        load_robot("kuka_kr15")
    with pytest.raises(InputError, match=r"unknown robot 'ur5'.*did you mean .*ur5e"):
        load_robot("ur5")
    with pytest.raises(InputError, match=r"robot model file 'missing.yaml' does not exist"):
        load_robot("missing.yaml")


def test_hayati_beta_round_trips_and_the_readers_follow_it(tmp_path):
    # an identified link of nearly parallel axes holds beta (deg in the file); FK, the URDF
    # origins (axis_frames) and the track as one chain follow it; conversions refuse it
    from dataclasses import replace

    from robotcell.cell.axischain import axis_frames
    from robotcell.dhprocedure.convert import convert_convention
    from robotcell.ik.track import TrackRobot

    (tmp_path / "m.yaml").write_text(
        "name: tilted\njoints:\n"
        "  - {type: revolute, a: 100, alpha: 0, d: 400, theta: 0, beta: 0.05}\n"
        "  - {type: revolute, a: 300, alpha: -90, d: 0, theta: 0}\n"
        "  - {type: revolute, a: 0, alpha: 0, d: 50, theta: 0}\n")
    r = load_robot(tmp_path / "m.yaml")
    assert r.joints[0].beta == pytest.approx(np.radians(0.05))
    save_robot(r, tmp_path / "back.yaml")
    text = (tmp_path / "back.yaml").read_text()
    assert "beta: 0.05" in text and text.count("beta") == 1  # written only where it is set
    q = np.random.default_rng(1).uniform(-2, 2, (10, 3))
    np.testing.assert_allclose(load_robot(tmp_path / "back.yaml").fk(q), r.fk(q), atol=1e-15)
    pre, post = axis_frames(r)
    for qi in q:
        T = r.base
        for i in range(3):
            T = T @ pre[i] @ make_pose(rot_z(qi[i]))
        np.testing.assert_allclose(T @ post, r.fk(qi), atol=1e-12)
    modified = replace(r, convention="modified")
    track = TrackRobot(modified, make_pose(rot_z(0.2), [0.1, 0.2, 0.0]), lower=-1.0, upper=3.0)
    qt = np.column_stack([np.linspace(0, 2, 10), q])
    np.testing.assert_allclose(track.as_robot().fk(qt), track.fk(qt), atol=1e-12)
    with pytest.raises(InputError, match=r"joint\(s\) A1 have a Hayati beta"):
        convert_convention(r, "modified")
    with pytest.raises(InputError, match="key 'beta' must be a number"):
        (tmp_path / "bad.yaml").write_text((tmp_path / "m.yaml").read_text().replace(
            "beta: 0.05", "beta: x"))
        load_robot(tmp_path / "bad.yaml")
