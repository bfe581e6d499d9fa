"""Inverse kinematics: analytic (all 8 solutions; 4 for palletizers), numeric, robot on a linear
track, and choosing a solution the way a controller does. See docs/ik.md.
"""

from robotcell.ik.analytic import AnalyticSolver, analytic_solver, solve
from robotcell.ik.config import abb_confdata, arm_sides, kuka_status_turn
from robotcell.ik.numeric import solve_numeric
from robotcell.ik.opw import OPWParameters, opw_parameters
from robotcell.ik.palletizer import PalletizerParameters, palletizer_parameters
from robotcell.ik.result import IKSolutions, NumericIKResult
from robotcell.ik.select import nearest, select_abb, select_kuka
from robotcell.ik.track import TrackChoice, TrackRobot
from robotcell.ik.ur import URParameters, ur_parameters

__all__ = [
    "AnalyticSolver",
    "IKSolutions",
    "NumericIKResult",
    "OPWParameters",
    "PalletizerParameters",
    "TrackChoice",
    "TrackRobot",
    "URParameters",
    "abb_confdata",
    "analytic_solver",
    "arm_sides",
    "kuka_status_turn",
    "nearest",
    "opw_parameters",
    "palletizer_parameters",
    "select_abb",
    "select_kuka",
    "solve",
    "solve_numeric",
    "ur_parameters",
]
