"""robotcell: kinematics and calibration of industrial robot cells.

Conventions (pose naming ``T_a_b``, units, array shapes) are in ``docs/conventions.md``.
"""

from robotcell.coupling import Coupling
from robotcell.errors import IllPosedError, InputError, RobotcellError
from robotcell.modelfile import list_robots, load_robot, robot_from_dict, save_robot
from robotcell.poseformats import FORMATS, pose_from_vendor, pose_to_vendor
from robotcell.robot import Joint, Robot
from robotcell.transforms import (
    check_pose,
    compose,
    invert,
    make_pose,
    rot_x,
    rot_y,
    rot_z,
    transform_points,
    validate_pose,
)

__version__ = "0.1.0"

__all__ = [
    "FORMATS",
    "Coupling",
    "IllPosedError",
    "InputError",
    "Joint",
    "Robot",
    "RobotcellError",
    "check_pose",
    "compose",
    "invert",
    "list_robots",
    "load_robot",
    "make_pose",
    "pose_from_vendor",
    "pose_to_vendor",
    "robot_from_dict",
    "rot_x",
    "rot_y",
    "rot_z",
    "save_robot",
    "transform_points",
    "validate_pose",
]
