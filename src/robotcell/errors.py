"""Exceptions raised by robotcell.

Every error a user can meet says what is wrong and, where there is one, what to do instead.
"""


class RobotcellError(Exception):
    """Base class of every error robotcell raises on purpose."""


class InputError(RobotcellError, ValueError):
    """Input that robotcell refuses: wrong shape or units, NaN, invalid pose, bad model file."""


class IllPosedError(InputError):
    """Measurements that do not determine the quantity asked for (e.g. collinear points)."""
