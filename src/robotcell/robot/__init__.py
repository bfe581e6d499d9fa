"""The robot: an arm with its inverse kinematics, its model files and the built-in library.

- :mod:`robotcell.robot.robot`: :class:`~robotcell.robot.robot.Robot`, an
  :class:`~robotcell.kinematics.arm.Arm` with its inverse kinematics (``Robot.ik``, the solvers
  of :mod:`robotcell.ik`);
- :mod:`robotcell.robot.models`: robot model files (YAML) and the built-in robot library (the
  package data ``robotcell/robots/``).

``robotcell.load_robot`` and ``robotcell.Robot`` give the names most code needs.
"""
