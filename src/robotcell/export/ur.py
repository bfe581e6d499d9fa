"""The identified geometry of a Universal Robots arm as the UR description's calibration file.

Universal Robots' ROS description (UniversalRobots/Universal_Robots_ROS2_Description, BSD-3-Clause;
the same layout in ros-industrial/universal_robot ``ur_description``) builds the arm from
``config/<type>/default_kinematics.yaml``, or from the file its ``kinematics_params_file``
(``kinematics_parameters_file``) argument names, which ``ur_calibration`` writes from a robot's
factory calibration::

    kinematics:
      shoulder:  {x, y, z, roll, pitch, yaw}
      upper_arm: {...}
      forearm:   {...}
      wrist_1:   {...}
      wrist_2:   {...}
      wrist_3:   {...}
      hash: calib_...

``urdf/ur_macro.xacro`` makes each entry the ``<origin xyz="x y z" rpy="roll pitch yaw"/>`` of one
joint, in the order shoulder_pan (``shoulder``), shoulder_lift (``upper_arm``), elbow
(``forearm``), wrist_1, wrist_2, wrist_3 (``urdf/inc/ur_common.xacro`` reads the keys), every joint
turning about its local Z (``<axis xyz="0 0 1"/>``), after ``base_link_inertia`` (``base_link``
turned by pi about Z, the controller's Base frame); ``tool0`` is ``wrist_3_link`` (the fixed
``flange`` rpy (0, -pi/2, -pi/2) and ``tool0`` rpy (pi/2, 0, pi/2) compose to the identity). URDF
``rpy`` is fixed-axis roll, pitch, yaw: ``R = Rz(yaw) Ry(pitch) Rx(roll)``.

:func:`ur_kinematics` writes the identified arm that way: with the DH link of joint ``i``
``Tz(d) Rz(theta) Tx(a) Rx(alpha) Ry(beta)``, the origin of joint ``i`` holds the ``Tx Rx Ry``
part of link ``i - 1`` and the ``Tz Rz`` part of link ``i`` (a screw about the joint's own axis,
which commutes with its motion), so a nominal arm gives the layout of ``default_kinematics.yaml``
(``shoulder z = d1``, ``upper_arm roll = alpha1``, ``forearm x = a2``, ``wrist_1 x = a3, z = d4``,
...). The ``hash`` names the file's numbers (``robotcell_`` and 16 hex digits of their SHA-256):
it is not the controller's calibration hash, and the UR driver, which compares the two, says so
when it connects (the controller keeps its own calibration; this file is the arm as measured).

The file holds joint origins only: each joint turns by the controller's value. An arm identified
with a scale per axis (``robotcell identify --scale``: ``q_model = (1 + s) q``, a coupling of
the model file) cannot be written whole. :func:`cell_ur_kinematics` then writes what the file
can hold, the identified geometry without the scales, and says so in a warning that names the
scales and how far the file's arm is from the identified one within the joint limits
(:func:`scale_left_out`).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.kinematics.dh import link_transform
from robotcell.robot.robot import Robot

__all__ = ["SEGMENTS", "URKinematics", "axis_scale", "cell_ur_kinematics", "is_ur_arm",
           "scale_left_out", "ur_kinematics", "ur_origins"]

#: The keys of the joints' origins in the calibration file, base to tip.
SEGMENTS = ("shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3")
#: Largest offset (m, rad) of the last link's x part and the flange from the identity.
_SCREW_TOL = 1e-9
#: Configurations within the joint limits at which a left-out scale is measured.
_SCALE_SAMPLES = 2000


@dataclass(frozen=True)
class URKinematics:
    """The UR calibration file of a cell's arm and what it could not hold.

    Attributes
    ----------
    text : str
        The file (YAML, m and rad).
    warnings : list of str
        What the file leaves out of the identified model, and how far that puts its arm from the
        identified one (:func:`scale_left_out`); empty when it holds the whole model.
    """

    text: str
    warnings: list[str]


def axis_scale(robot: Robot) -> NDArray[np.float64] | None:
    """The scale factors ``1 + s`` per axis of a coupling that only scales axes, else None.

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    ndarray, shape (n,), or None
        The diagonal of ``C`` when the robot's coupling is ``q_model = diag(1 + s) q`` (no
        offset, no interaction limits, no passive joint); None without a coupling or for any
        other one (a J2/J3 linkage).
    """
    c = robot.coupling
    if c is None or c.matrix.shape != (robot.n_joints, robot.n_joints):
        return None
    C = c.matrix
    if np.any(C - np.diag(np.diag(C))) or np.any(c.offset) or c.interaction.shape[0]:
        return None
    return np.diag(C).copy()


def is_ur_arm(robot: Robot) -> bool:
    """Whether ``robot`` (or the nominal model it is identified from) is a UR-type arm, with no
    coupling but a scale per axis (:func:`axis_scale`)."""
    from robotcell.ik.ur import ur_problems  # the IK package only when a URDF is exported

    nominal = robot.ik_seed or robot
    return (nominal.n_joints == 6 and robot.convention == "standard"
            and (robot.coupling is None or axis_scale(robot) is not None)
            and not ur_problems(nominal.uncoupled()))


def _split(j) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A standard DH link's constant part as ``Tz(d) Rz(theta)`` (about the joint's axis) and
    ``Tx(a) Rx(alpha) Ry(beta)``."""
    return (link_transform(j.theta, j.d, 0.0, 0.0), link_transform(0.0, 0.0, j.a, j.alpha,
                                                                    beta=j.beta))


def ur_origins(robot: Robot) -> NDArray[np.float64]:
    """The six joint origins of the UR description for ``robot``, shape (6, 4, 4) (m).

    Raises
    ------
    InputError
        Not a standard-DH six-axis arm with every sign +1, or a last link and flange that are not
        a screw about the last axis (the description's ``tool0`` is fixed to ``wrist_3_link``).
    """
    if robot.n_joints != 6 or robot.convention != "standard" or robot.coupling is not None \
            or any(j.sign != 1.0 or j.prismatic for j in robot.joints):
        raise InputError(f"{robot.name}: the UR calibration format describes six revolute joints "
                         "in standard DH with the controller's directions (sign +1), no coupling")
    z_parts, x_parts = zip(*(_split(j) for j in robot.joints))
    origins = [robot.base @ z_parts[0]]
    origins += [x_parts[i - 1] @ z_parts[i] for i in range(1, 6)]
    rest = x_parts[5] @ robot.flange
    if np.abs(rest - np.eye(4)).max() > _SCREW_TOL:
        raise InputError(f"{robot.name}: its last link and flange are not the description's "
                         "tool0 (wrist_3_link): a6, alpha6, beta6 and the flange must be 0")
    return np.array(origins)


def ur_kinematics(robot: Robot) -> str:
    """The calibration file (YAML text) of a UR-type arm, e.g. an identified one (m, rad).

    Parameters
    ----------
    robot : Robot
        Six revolute joints, standard DH, signs +1 (the library's UR models and what
        ``robotcell identify`` makes of them).

    Returns
    -------
    str
    """
    O = ur_origins(robot)
    rpy = Rotation.from_matrix(O[:, :3, :3]).as_euler("xyz")
    lines = ["# robotcell: the kinematics of " + robot.name + " in the calibration format of",
             "# Universal_Robots_ROS2_Description (config/<type>/default_kinematics.yaml):",
             "# joint origins xyz (m) and fixed-axis roll, pitch, yaw (rad). docs/export.md",
             "kinematics:"]
    numbers = []
    for name, T, (r, p, y) in zip(SEGMENTS, O, rpy):
        lines.append(f"  {name}:")
        for key, v in zip(("x", "y", "z", "roll", "pitch", "yaw"), (*T[:3, 3], r, p, y)):
            text = repr(float(v) + 0.0)
            numbers.append(text)
            lines.append(f"    {key}: {text}")
    digest = hashlib.sha256(",".join(numbers).encode()).hexdigest()[:16]
    lines.append(f"  hash: robotcell_{digest}")
    return "\n".join(lines) + "\n"


def scale_left_out(robot: Robot) -> str | None:
    """What leaving the axis scales out of the calibration file does, or None without scales.

    Parameters
    ----------
    robot : Robot
        A UR-type arm whose coupling scales axes (:func:`axis_scale`).

    Returns
    -------
    str or None
        A warning naming each scale (``axis 2 x1.000210``) and the largest and RMS distance of
        the flange of the arm without them from the identified arm's, over 2000 configurations
        within the joint limits (seeded; unlimited axes over +-180 deg).
    """
    scale = axis_scale(robot)
    if scale is None or np.all(scale == 1.0):
        return None
    rng = np.random.default_rng(0)
    lo = np.where(np.isfinite(robot.lower), robot.lower, -math.pi)
    hi = np.where(np.isfinite(robot.upper), robot.upper, math.pi)
    q = lo + (hi - lo) * rng.random((_SCALE_SAMPLES, robot.n_joints))
    eye = np.eye(4)
    d = np.linalg.norm(robot.fk(q, tool=eye)[:, :3, 3]
                       - replace(robot, coupling=None).fk(q, tool=eye)[:, :3, 3], axis=-1)
    named = ", ".join(f"axis {i + 1} x{v:.6f}" for i, v in enumerate(scale) if v != 1.0)
    return (f"the UR calibration file cannot hold the identified arm's axis scales ({named}; "
            "identify --scale): it holds the identified geometry without them, whose flange is "
            f"up to {d.max() * 1e3:.3f} mm ({math.sqrt(np.mean(d**2)) * 1e3:.3f} mm RMS) from "
            "the identified arm's within the joint limits; the URDF holds the scales (its joints "
            "take q_model = (1 + s) q); identify without --scale for a calibration file that "
            "holds the whole model")


def cell_ur_kinematics(cell: Cell) -> URKinematics | None:
    """The calibration file of a cell whose identified arm is a UR-type arm, else None.

    An arm identified with axis scales gets the file of its geometry without them, and the
    warning of :func:`scale_left_out`. A cell of several robots gets none (the UR description
    describes one arm).
    """
    if len(cell.robots) > 1 or cell.identified is None or not is_ur_arm(cell.robot):
        return None
    left_out = scale_left_out(cell.robot)
    text = ur_kinematics(replace(cell.robot, coupling=None))
    return URKinematics(text, [] if left_out is None else [left_out])
