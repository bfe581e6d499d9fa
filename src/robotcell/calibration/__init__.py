"""Calibration of a robot cell from touch-up measurements.

Every procedure is a maximum-likelihood fit under isotropic Gaussian noise on the measured points
and returns a :class:`CalibrationResult` (SI units inside; mm and degrees in its JSON and text
report). Shared pieces: :mod:`.result` (the result), :mod:`.fitting` (least squares, covariance,
conditioning, outliers, rotation parameterisation), :mod:`.measurements` (CSV columns to SI).
Procedures: :func:`calibrate_tool` (TCP, ABC 2-point, ABC World), :func:`frame_3point`,
:func:`frame_npoint`, :func:`calibrate_external_tcp`, :func:`robot_to_robot`.
See ``docs/calibration.md``.
"""

from robotcell.calibration.fitting import (
    Fit,
    fit,
    kabsch,
    nearest_rotation,
    outlier_warnings,
    perturb_pose,
    perturb_rotation,
    pose_sigma,
)
from robotcell.calibration.frame import calibrate_external_tcp, frame_3point, frame_npoint
from robotcell.calibration.result import CalibrationResult, pose_fields, to_jsonable
from robotcell.calibration.robottorobot import RobotTouches, robot_to_robot
from robotcell.calibration.tcp import calibrate_tool

__all__ = [
    "CalibrationResult",
    "Fit",
    "RobotTouches",
    "calibrate_external_tcp",
    "calibrate_tool",
    "fit",
    "frame_3point",
    "frame_npoint",
    "kabsch",
    "nearest_rotation",
    "outlier_warnings",
    "perturb_pose",
    "perturb_rotation",
    "pose_fields",
    "pose_sigma",
    "robot_to_robot",
    "to_jsonable",
]
