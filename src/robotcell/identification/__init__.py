"""Kinematic identification: the model a real arm or positioner has, from measurements.

See ``docs/identification.md``.
"""

from robotcell.identification.engine import identify, identify_with_coupling
from robotcell.identification.ik import solve_identified
from robotcell.identification.measurements import Measurements, read_measurements
from robotcell.identification.positioner import PositionerCalibration, calibrate_positioner
from robotcell.identification.result import IdentificationResult, Parameter

__all__ = ["IdentificationResult", "Measurements", "Parameter", "PositionerCalibration",
           "calibrate_positioner", "identify", "identify_with_coupling", "read_measurements",
           "solve_identified"]
