"""Inverse kinematics: analytic (all 8 solutions), numeric, robot on a linear track, and choosing
a solution the way a controller does. See docs/ik.md.
"""

from robotcell.ik.analytic import AnalyticSolver, analytic_solver, solve
from robotcell.ik.opw import OPWParameters, opw_parameters
from robotcell.ik.result import IKSolutions, NumericIKResult
from robotcell.ik.ur import URParameters, ur_parameters

__all__ = [
    "AnalyticSolver",
    "IKSolutions",
    "NumericIKResult",
    "OPWParameters",
    "URParameters",
    "analytic_solver",
    "opw_parameters",
    "solve",
    "ur_parameters",
]
