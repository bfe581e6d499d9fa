"""The Denavit-Hartenberg procedure: from joint axes or a URDF to a DH model, conversions
between standard and modified DH, and the symbolic arm matrix.

See ``docs/dh-procedure.md``.
"""

from robotcell.dhprocedure.axes import AxisChain
from robotcell.dhprocedure.convert import convert_convention
from robotcell.dhprocedure.procedure import DHDerivation, FrameNote, dh_from_axes
from robotcell.dhprocedure.urdf import UrdfChain, UrdfJoint, dh_from_urdf, read_urdf

__all__ = [
    "AxisChain",
    "DHDerivation",
    "FrameNote",
    "UrdfChain",
    "UrdfJoint",
    "convert_convention",
    "dh_from_axes",
    "dh_from_urdf",
    "read_urdf",
]
