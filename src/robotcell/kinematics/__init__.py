"""Kinematics of one arm: poses and rotations, DH chains, the arm's model, joint coupling.

- :mod:`robotcell.kinematics.transforms`: homogeneous poses ``(..., 4, 4)`` and rotations;
- :mod:`robotcell.kinematics.jit`: kernels written once for a batch and for one pose;
- :mod:`robotcell.kinematics.dh`: Denavit-Hartenberg link transforms and chains;
- :mod:`robotcell.kinematics.arm`: :class:`~robotcell.kinematics.arm.Arm`, the DH model (FK,
  Jacobian, limits) the inverse kinematics works on;
- :mod:`robotcell.kinematics.coupling`: linear coupling of motor and DH joint values (J2/J3);
- :mod:`robotcell.kinematics.covariance`: the covariance of a model's identified constants;
- :mod:`robotcell.kinematics.bounds`: limit checks up to rounding.

Inverse kinematics is the package :mod:`robotcell.ik`, which builds on the arm; the robot
(:mod:`robotcell.robot`: an arm with its inverse kinematics, model files, the library) builds
on both.
"""
