"""The lecture's algebra: symbolic adjacent transforms and arm matrix of a DH model (sympy).

sympy is an optional extra (``pip install 'robotcell[symbolic]'``), imported only when these
functions run. Symbols follow the lecture: ``theta_i, d_i, a_i, alpha_i`` (Craig's ``a_{i-1},
alpha_{i-1}`` in the modified convention). The joint variable of joint ``i`` is its DH variable
(``theta_i`` for revolute, ``d_i`` for prismatic joints); it relates to the controller value by
``theta_i = sign_i q_i + offset_i`` (:attr:`SymbolicArm.variables` lists these relations).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from robotcell.errors import InputError, RobotcellError
from robotcell.kinematics.dh import Convention
from robotcell.robot.robot import Robot

__all__ = ["SymbolicArm", "symbolic_arm", "symbolic_link"]

INSTALL_HINT = "symbolic DH needs the optional package sympy: pip install 'robotcell[symbolic]'"
_UNITS = {"m": 1.0, "mm": 1e3}


def _sympy() -> Any:
    try:
        import sympy
    except ImportError:
        raise RobotcellError(INSTALL_HINT) from None
    return sympy


def symbolic_link(convention: Convention = "standard", index: int | str = "i") -> Any:
    """The general adjacent transform ``T_{i-1,i}`` with every parameter a symbol.

    Parameters
    ----------
    convention : {"standard", "modified"}
        Standard: ``Trans(z, d_i) Rot(z, theta_i) Trans(x, a_i) Rot(x, alpha_i)`` (the lecture's
        matrix); modified: ``Rot(x, alpha_{i-1}) Trans(x, a_{i-1}) Rot(z, theta_i) Trans(z, d_i)``.
    index : int or str
        Subscript of the symbols (``i`` or a joint number).

    Returns
    -------
    sympy.Matrix, shape (4, 4)
    """
    sp = _sympy()
    prev = f"{index}-1" if isinstance(index, str) else str(index - 1)
    theta, d = sp.Symbol(f"theta_{index}"), sp.Symbol(f"d_{index}")
    if convention == "standard":
        a, alpha = sp.Symbol(f"a_{index}"), sp.Symbol(f"alpha_{index}")
    elif convention == "modified":
        a, alpha = sp.Symbol(f"a_{prev}"), sp.Symbol(f"alpha_{prev}")
    else:
        raise InputError(f"convention must be 'standard' or 'modified', got {convention!r}")
    return _link(sp, convention, theta, d, a, alpha)


def _link(sp: Any, convention: str, theta: Any, d: Any, a: Any, alpha: Any) -> Any:
    ct, st, ca, sa = sp.cos(theta), sp.sin(theta), sp.cos(alpha), sp.sin(alpha)
    if convention == "standard":
        return sp.Matrix([[ct, -st * ca, st * sa, a * ct],
                          [st, ct * ca, -ct * sa, a * st],
                          [0, sa, ca, d],
                          [0, 0, 0, 1]])
    return sp.Matrix([[ct, -st, 0, a],
                      [st * ca, ct * ca, -sa, -sa * d],
                      [st * sa, ct * sa, ca, ca * d],
                      [0, 0, 0, 1]])


@dataclass(frozen=True, eq=False)
class SymbolicArm:
    """Symbolic kinematics of a DH model.

    Attributes
    ----------
    robot : Robot
    links : list of sympy.Matrix
        ``T_{i-1,i}`` for ``i = 1..n``, shape (4, 4) each.
    arm : sympy.Matrix
        The arm matrix ``T_0_n = T_0_1 ... T_{n-1,n}``, simplified, shape (4, 4).
    variables : list of (sympy.Symbol, str)
        Joint variable of each joint and its relation to the controller value ``q_i``.
    constants : dict
        Symbol -> value of each length or angle kept symbolic (in ``unit`` and radians).
    unit : str
        Length unit of the numbers in the matrices ("m" or "mm").
    """

    robot: Robot
    links: list[Any]
    arm: Any
    variables: list[tuple[Any, str]]
    constants: dict[Any, float]
    unit: str

    def to_text(self) -> str:
        """The links and the arm matrix, pretty-printed (one element per line for the arm)."""
        sp = _sympy()
        conv = self.robot.convention
        out = [f"{self.robot.name}: {conv} DH, lengths in {self.unit}, angles in rad"]
        out += [f"  {sym} = {rel}" for sym, rel in self.variables]
        if self.constants:
            consts = ", ".join(f"{k} = {_fmt(v)}" for k, v in self.constants.items())
            out.append(f"constants: {consts}")
        for i, T in enumerate(self.links, start=1):
            pretty = sp.pretty(T, use_unicode=False, wrap_line=False, full_prec=False)
            out += ["", f"T_{i - 1}_{i} =", pretty]
        n = len(self.links)
        out += ["", f"arm matrix T_0_{n} = [[r11 r12 r13 px] [r21 r22 r23 py] [r31 r32 r33 pz] [0 0 0 1]]:"]
        names = [["r11", "r12", "r13", "px"], ["r21", "r22", "r23", "py"],
                 ["r31", "r32", "r33", "pz"]]
        for r in range(3):
            for c in range(4):
                out.append(f"{names[r][c]} = {sp.sstr(self.arm[r, c], full_prec=False)}")
        return "\n".join(out)

    def to_latex(self) -> str:
        """The links and the arm matrix as LaTeX equations (``align*`` environments)."""
        sp = _sympy()
        rows = [f"{{}}^{{{i - 1}}}T_{{{i}}} &= {sp.latex(T, full_prec=False)}"
                for i, T in enumerate(self.links, 1)]
        n = len(self.links)
        arm = f"{{}}^{{0}}T_{{{n}}} &= {sp.latex(self.arm, full_prec=False)}"
        vars_ = ", ".join(f"{sp.latex(s)} = {rel}" for s, rel in self.variables)
        return ("% " + vars_ + "\n\\begin{align*}\n" + " \\\\\n".join(rows)
                + "\n\\end{align*}\n\\begin{align*}\n" + arm + "\n\\end{align*}")


def symbolic_arm(robot: Robot, numeric: bool = False, unit: str = "m",
                 simplify: bool = True) -> SymbolicArm:
    """Adjacent transforms and arm matrix ``T_0_n`` of a DH model, symbolically.

    Parameters
    ----------
    robot : Robot
    numeric : bool
        False (default): nonzero lengths stay symbols (``a_2``, ``d_1``), zero lengths are 0,
        twists and constant angles that are multiples of 90 degrees are exact (``pi/2``),
        others stay symbols. True: every constant is substituted by its value.
    unit : {"m", "mm"}
        Length unit of substituted values.
    simplify : bool
        Simplify the arm matrix with ``sympy.trigsimp`` (sums of angles of parallel joints
        combine, e.g. ``cos(theta_2 + theta_3)``).

    Returns
    -------
    SymbolicArm
        The base ``T_R_0`` and flange ``T_n_F`` are not part of ``arm``.
    """
    sp = _sympy()
    if unit not in _UNITS:
        raise InputError(f"unit must be 'm' or 'mm', got {unit!r}")
    if any(j.beta != 0.0 for j in robot.joints):
        raise InputError(f"{robot.name} has a Hayati beta (an identified arm, or nearly parallel "
                         "axes): its links are not plain DH rows; write the symbolic matrices of "
                         "its nominal model")
    scale = _UNITS[unit]
    constants: dict[Any, float] = {}

    def const(name: str, value: float, is_angle: bool) -> Any:
        if is_angle:
            deg = math.degrees(value)
            if abs(deg / 90 - round(deg / 90)) < 1e-9:
                return sp.pi * round(deg / 90) / 2
            if numeric:
                return sp.pi * sp.Float(round(deg, 9)) / 180
        else:
            if abs(value) < 1e-12:
                return sp.Integer(0)
            if numeric:
                return sp.Float(round(value * scale, 9))
        sym = sp.Symbol(name)
        constants[sym] = value * (1.0 if is_angle else scale)
        return sym

    links, variables = [], []
    modified = robot.convention == "modified"
    for i, j in enumerate(robot.joints, start=1):
        k = i - 1 if modified else i
        a, alpha = const(f"a_{k}", j.a, False), const(f"alpha_{k}", j.alpha, True)
        q = sp.Symbol(f"q_{i}")
        if j.prismatic:
            theta, d = const(f"theta_{i}", j.theta, True), sp.Symbol(f"d_{i}")
            offset = j.d * scale
        else:
            theta, d = sp.Symbol(f"theta_{i}"), const(f"d_{i}", j.d, False)
            offset = j.theta
        relation = ("" if j.sign > 0 else "-") + str(q)
        if abs(offset) > 1e-12:
            relation += f" {'+' if offset > 0 else '-'} {_fmt(abs(offset))}"
        variables.append((d if j.prismatic else theta, relation))
        links.append(_link(sp, robot.convention, theta, d, a, alpha))
    arm = links[0]
    for T in links[1:]:
        arm = arm * T
    if simplify:
        arm = arm.applyfunc(sp.trigsimp)
    return SymbolicArm(robot=robot, links=links, arm=arm, variables=variables,
                       constants=constants, unit=unit)


def _fmt(v: float) -> str:
    return f"{v:.9g}"
