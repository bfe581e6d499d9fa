"""The dh command group, in process through the CLI entry point."""

import re
from importlib import resources

import numpy as np
import pytest
from cli_helpers import run

import robotcell as rc

URDF = str(resources.files("robotcell") / "robots" / "urdf" / "ur5e.urdf")




def test_from_urdf_writes_a_model_that_moves_like_the_urdf(capsys, tmp_path):
    from robotcell.dhprocedure import read_urdf

    target = tmp_path / "ur5e_mdh.yaml"
    code, out, _ = run(capsys, "dh", "from-urdf", URDF, "--convention", "modified", "-o", str(target))
    assert code == 0
    assert "modified DH" in out and "[parallel]" in out and "model written to" in out
    model = rc.load_robot(target)
    assert model.convention == "modified"
    q = np.random.default_rng(1).uniform(-3, 3, (50, 6))
    assert np.abs(model.fk(q) - read_urdf(URDF).fk(q)).max() < 1e-9


def test_from_urdf_signs_and_tip(capsys):
    code, out, _ = run(capsys, "dh", "from-urdf", URDF, "--tip-link", "wrist_3_link",
                       "--signs=-1,1,1,1,1,-1")
    assert code == 0
    assert "pointing against its positive direction (sign -1)" in out


def test_from_urdf_refusals(capsys, tmp_path):
    code, _, err = run(capsys, "dh", "from-urdf", str(tmp_path / "missing.urdf"))
    assert code == 2 and "does not exist" in err
    code, _, err = run(capsys, "dh", "from-urdf", URDF, "--signs", "1,1")
    assert code == 2 and "signs must be 6 values" in err
    branch = tmp_path / "branch.urdf"
    branch.write_text(
        '<robot name="b"><link name="base"/><link name="a"/><link name="c"/>'
        '<joint name="arm" type="revolute"><parent link="base"/><child link="a"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        '<joint name="cam" type="fixed"><parent link="base"/><child link="c"/></joint></robot>')
    code, _, err = run(capsys, "dh", "from-urdf", str(branch))
    assert code == 2 and "link 'base' branches into joints arm, cam" in err


def test_convert_round_trip_through_files(capsys, tmp_path):
    target = tmp_path / "kr16_mdh.yaml"
    code, out, _ = run(capsys, "dh", "convert", "kuka_kr16", "--to", "modified", "-o", str(target))
    assert code == 0 and "a_{i-1} [mm]" in out
    q = np.random.default_rng(2).uniform(-3, 3, (50, 6))
    assert np.abs(rc.load_robot(target).fk(q) - rc.load_robot("kuka_kr16").fk(q)).max() < 1e-9


def test_explain_library_model_and_urdf(capsys):
    code, out, _ = run(capsys, "dh", "explain", "puma560")
    assert code == 0
    assert "0 [base]" in out and "[intersecting]" in out and "table of puma560" in out
    code, out, _ = run(capsys, "dh", "explain", URDF, "--convention", "modified")
    assert code == 0 and "modified DH" in out and "6 [coincident]" in out


def test_explain_recognises_its_own_table(capsys, tmp_path):
    from robotcell.dhprocedure import AxisChain, dh_from_axes

    own = dh_from_axes(AxisChain.from_robot(rc.load_robot("stanford_arm"))).robot
    rc.save_robot(own, tmp_path / "own.yaml")
    code, out, _ = run(capsys, "dh", "explain", str(tmp_path / "own.yaml"))
    assert code == 0 and "The derived table equals the table of derived" in out


def test_symbolic_text_latex_numeric(capsys, tmp_path):
    code, out, _ = run(capsys, "dh", "symbolic", "stanford_arm")
    assert code == 0 and "T_0_1 =" in out and "pz = d_1 + d_3*cos(theta_2)" in out
    small = rc.Robot("rp", (rc.Joint("revolute", d=0.412, alpha=-1.5707963267948966),
                            rc.Joint("prismatic", a=0.0203)))
    rc.save_robot(small, tmp_path / "rp.yaml")
    code, out, _ = run(capsys, "dh", "symbolic", str(tmp_path / "rp.yaml"), "--numeric", "--latex")
    assert code == 0 and r"\begin{align*}" in out and "412.0" in out and "20.3" in out


@pytest.mark.parametrize("sub", ["from-urdf", "convert", "explain", "symbolic"])
def test_help_has_an_example(capsys, sub):
    code, out, _ = run(capsys, "dh", sub, "--help")
    assert code == 0 and "Example" in out and f"robotcell dh {sub}" in out


def test_a_branching_urdf_names_the_parameter_in_python_and_the_option_on_the_command_line(
        capsys, tmp_path):
    from robotcell.dhprocedure import dh_from_urdf
    from robotcell.errors import InputError

    joint = ('<joint name="{0}" type="revolute"><parent link="base_link"/><child link="{1}"/>'
             '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')
    urdf = tmp_path / "fork.urdf"
    urdf.write_text('<robot name="fork"><link name="base_link"/><link name="b"/><link name="c"/>'
                    + joint.format("j1", "b") + joint.format("j2", "c") + "</robot>")
    with pytest.raises(InputError, match="branches into joints j1, j2; choose the end of the arm "
                                         "with tip_link$"):
        dh_from_urdf(urdf)
    code, _, err = run(capsys, "dh", "from-urdf", urdf)
    assert code == 2 and err.rstrip().endswith("choose the end of the arm with tip_link "
                                               "(--tip-link)")
    assert "'base_link' branches" in err  # a link's name is not taken for the option


NEARLY_PARALLEL = (
    '<robot name="np"><link name="a"/><link name="b"/><link name="c"/><link name="d"/>'
    '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/>'
    '<origin xyz="0 0 0.4" rpy="1.5708 0 0"/><axis xyz="0 0 1"/></joint>'
    '<joint name="j2" type="revolute"><parent link="b"/><child link="c"/>'
    '<origin xyz="0.3 0 0" rpy="0.000001 0.0000004 0"/><axis xyz="0 0 1"/></joint>'
    '<joint name="j3" type="revolute"><parent link="c"/><child link="d"/>'
    '<origin xyz="0.25 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/></joint></robot>')


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_nearly_parallel_axes_show_hayati_beta_and_the_check(capsys, tmp_path, convention):
    urdf, out = tmp_path / "np.urdf", tmp_path / "np.yaml"
    urdf.write_text(NEARLY_PARALLEL, encoding="utf-8")
    code, stdout, err = run(capsys, "dh", "from-urdf", urdf, "--convention", convention, "-o", out)
    assert code == 0, err
    assert "Rot(y, beta)" in stdout and "beta [deg]" in stdout and "Hayati's beta" in stdout
    assert re.search(r"check: as a model file holds it \(mm, degrees\), the model moves like its "
                     r"source to \d\.\de-\d\d m and rad \(at most 1e-09\)", stdout)
    model = rc.load_robot(out)
    assert sum(j.beta != 0 for j in model.joints) == 1
    code, stdout, _ = run(capsys, "dh", "explain", out)
    assert code == 0 and "The derived table equals the table of np" in stdout
    code, _, err = run(capsys, "dh", "convert", out, "--to", "standard" if convention == "modified"
                       else "modified")
    assert code == 2 and "have a Hayati beta" in err
