"""robotcell: kinematics and calibration of industrial robot cells.

Conventions (pose naming ``T_a_b``, units, array shapes) are in ``docs/conventions.md``.

The public names below are imported on first use (PEP 562), so ``import robotcell`` and the
command line's ``--version`` and ``--help`` do not pay for numpy and scipy.

The modules live in concept packages (``docs/conventions.md``, "Layout").
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from robotcell._lazy import module_getattr
from robotcell.errors import IllPosedError, InputError, RobotcellError

if TYPE_CHECKING:
    from robotcell.io.poseformats import FORMATS, pose_from_vendor, pose_to_vendor
    from robotcell.kinematics.coupling import Coupling
    from robotcell.kinematics.transforms import (
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
    from robotcell.robot.models import list_robots, load_robot, robot_from_dict, save_robot
    from robotcell.robot.robot import Joint, Robot

__version__ = "0.1.0"

#: public name -> module that defines it, imported on first access
_LAZY = {
    "Coupling": "robotcell.kinematics.coupling",
    **dict.fromkeys(["list_robots", "load_robot", "robot_from_dict", "save_robot"],
                    "robotcell.robot.models"),
    **dict.fromkeys(["FORMATS", "pose_from_vendor", "pose_to_vendor"], "robotcell.io.poseformats"),
    **dict.fromkeys(["Joint", "Robot"], "robotcell.robot.robot"),
    **dict.fromkeys(["check_pose", "compose", "invert", "make_pose", "rot_x", "rot_y", "rot_z",
                     "transform_points", "validate_pose"], "robotcell.kinematics.transforms"),
}

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


#: Import a public name from its module on first access (PEP 562).
__getattr__ = module_getattr(_LAZY, __name__, globals())


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
