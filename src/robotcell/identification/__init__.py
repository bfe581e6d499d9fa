"""Kinematic identification: the model a real arm or positioner has, from measurements.

See ``docs/identification.md``.
"""

from robotcell.identification.choice import ValidatedIdentification, identify_validated
from robotcell.identification.coupling import identify_with_coupling
from robotcell.identification.engine import identify
from robotcell.identification.ik import solve_identified
from robotcell.identification.measurements import TargetMeasurements, read_target_measurements
from robotcell.identification.options import IdentifyOptions
from robotcell.identification.positioner import PositionerCalibration, calibrate_positioner
from robotcell.identification.result import IdentificationResult, Parameter
from robotcell.identification.validation import (
    CrossValidation,
    PoseSelection,
    compare_observability,
    cross_validate,
    observability,
    select_configurations,
)

__all__ = [
    "CrossValidation",
    "IdentificationResult",
    "IdentifyOptions",
    "Parameter",
    "PoseSelection",
    "PositionerCalibration",
    "TargetMeasurements",
    "ValidatedIdentification",
    "calibrate_positioner",
    "compare_observability",
    "cross_validate",
    "identify",
    "identify_validated",
    "identify_with_coupling",
    "observability",
    "read_target_measurements",
    "select_configurations",
    "solve_identified",
]
