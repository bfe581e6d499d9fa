"""Kinematic identification: the model a real arm or positioner has, from measurements.

See ``docs/identification.md``.
"""

from robotcell.identification.engine import identify, identify_with_coupling
from robotcell.identification.ik import solve_identified
from robotcell.identification.measurements import Measurements, read_measurements
from robotcell.identification.positioner import PositionerCalibration, calibrate_positioner
from robotcell.identification.result import IdentificationResult, Parameter
from robotcell.identification.validation import (
    CrossValidation,
    PoseSelection,
    cross_validate,
    observability,
    select_configurations,
)

__all__ = ["CrossValidation", "IdentificationResult", "Measurements", "Parameter", "PoseSelection",
           "PositionerCalibration", "calibrate_positioner", "cross_validate", "identify",
           "identify_with_coupling", "observability", "read_measurements", "select_configurations",
           "solve_identified"]
