"""Absolute accuracy: the identified arm drives the controller's nominal one.

- :mod:`robotcell.accuracy.filter`: poses to command so that the real arm reaches the desired
  ones (:func:`filter_poses`), with the predicted error without filtering and the 1-sigma after;
- :mod:`robotcell.accuracy.poses`: the same for a CSV of poses (``robotcell compensate``);
- :mod:`robotcell.accuracy.program`: a robot program filtered point by point
  (``robotcell program compensate``).

See ``docs/accuracy.md``.
"""

from robotcell.accuracy.filter import MAX_CORRECTION, FilteredPoses, FilterRefused, filter_poses

__all__ = ["MAX_CORRECTION", "FilterRefused", "FilteredPoses", "filter_poses"]
