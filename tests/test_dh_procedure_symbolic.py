"""Symbolic adjacent transforms and arm matrix agree with the numeric model."""

import math
import sys

import numpy as np
import pytest

import robotcell as rc
from robotcell.dhprocedure.symbolic import symbolic_arm, symbolic_link
from robotcell.errors import InputError, RobotcellError
from robotcell.kinematics.dh import link_transform

sp = pytest.importorskip("sympy")


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_general_link_is_the_numeric_link(convention):
    T = symbolic_link(convention)
    names = ["theta_i", "d_i", "a_i", "alpha_i"] if convention == "standard" else \
        ["theta_i", "d_i", "a_i-1", "alpha_i-1"]
    f = sp.lambdify([sp.Symbol(n) for n in names], T, "numpy")
    rng = np.random.default_rng(2)
    for th, d, a, al in rng.uniform(-3, 3, (20, 4)):
        assert np.allclose(np.array(f(th, d, a, al), dtype=float),
                           link_transform(th, d, a, al, convention), atol=1e-12)


def evaluate(sym, robot, q, unit_scale=1.0):
    """Arm matrix of ``sym`` at controller values ``q`` (lengths converted back to metres)."""
    values = {k: v for k, v in sym.constants.items()}
    for (var, _), j, qi in zip(sym.variables, robot.joints, q):
        values[var] = j.sign * qi * (unit_scale if j.prismatic else 1) + (
            j.d * unit_scale if j.prismatic else j.theta)
    M = np.array(sym.arm.subs(values).evalf(), dtype=float)
    M[:3, 3] /= unit_scale
    return M


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("numeric", [False, True])
def test_arm_matrix_equals_fk(convention, numeric):
    rng = np.random.default_rng(3)
    joints = (rc.Joint("revolute", a=0.3, alpha=math.pi / 2, d=0.4, theta=0.1),
              rc.Joint("prismatic", a=0.0, alpha=0.7, d=0.2, theta=-math.pi / 2, sign=-1),
              rc.Joint("revolute", a=0.05, alpha=-0.4, d=0.0, theta=0.0))
    robot = rc.Robot("r", joints, convention)
    sym = symbolic_arm(robot, numeric=numeric, unit="mm")
    if numeric:
        assert sym.constants == {}
    else:
        assert {str(k) for k in sym.constants} >= {"d_1", "alpha_2" if convention == "standard"
                                                   else "alpha_1"}
    for q in rng.uniform(-2, 2, (5, 3)):
        expected = robot.frames(q)[-1]
        assert np.allclose(evaluate(sym, robot, q, 1e3), expected, atol=1e-9)


def test_exact_twists_and_parallel_axes_combine():
    robot = rc.Robot("planar", (rc.Joint("revolute", a=0.4), rc.Joint("revolute", a=0.3),
                                rc.Joint("revolute", alpha=-math.pi / 2, d=0.1)))
    sym = symbolic_arm(robot)
    th1, th2, a1, a2 = sp.symbols("theta_1 theta_2 a_1 a_2")
    assert sp.simplify(sym.arm[0, 3] - (a1 * sp.cos(th1) + a2 * sp.cos(th1 + th2))) == 0
    assert sym.links[2][2, 1] == -1  # sin(-pi/2), exact
    text = sym.to_text()
    assert "cos(theta_1 + theta_2 + theta_3)" in text and "a_1 = 0.4" in text
    latex = sym.to_latex()
    assert "{}^{0}T_{3}" in latex and r"\theta_{1}" in latex


def test_variables_show_sign_and_offset():
    robot = rc.Robot("r", (rc.Joint("revolute", theta=-math.pi / 2, sign=-1),
                           rc.Joint("prismatic", d=0.25)))
    sym = symbolic_arm(robot, unit="mm")
    assert [rel for _, rel in sym.variables] == ["-q_1 - 1.57079633", "q_2 + 250"]


def test_errors():
    robot = rc.Robot("r", (rc.Joint("revolute"),))
    with pytest.raises(InputError, match="unit must be 'm' or 'mm'"):
        symbolic_arm(robot, unit="in")
    with pytest.raises(InputError, match="convention must be"):
        symbolic_link("craig")


def test_missing_sympy_says_how_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "sympy", None)
    with pytest.raises(RobotcellError, match=r"pip install 'robotcell\[symbolic\]'"):
        symbolic_link()
