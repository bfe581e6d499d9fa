"""Kinematics of one robot: poses and rotations, DH chains, the robot, joint coupling, model files.

- :mod:`robotcell.kinematics.transforms`: homogeneous poses ``(..., 4, 4)`` and rotations;
- :mod:`robotcell.kinematics.dh`: Denavit-Hartenberg link transforms and chains;
- :mod:`robotcell.kinematics.arm`: :class:`~robotcell.kinematics.arm.Arm`, the DH model (FK,
  Jacobian, limits) the inverse kinematics works on;
- :mod:`robotcell.kinematics.robot`: :class:`~robotcell.kinematics.robot.Robot`, an arm with its
  inverse kinematics (``Robot.ik``);
- :mod:`robotcell.kinematics.coupling`: linear coupling of motor and DH joint values (J2/J3);
- :mod:`robotcell.kinematics.bounds`: limit checks up to rounding;
- :mod:`robotcell.kinematics.models`: robot model files and the robot library.

Inverse kinematics is the package :mod:`robotcell.ik`, which builds on the arm; the robot builds
on it.
"""
