"""The Denavit-Hartenberg procedure: from joint axes or a URDF to a DH model, conversions
between standard and modified DH, and the symbolic arm matrix.

See ``docs/dh-procedure.md``.
"""

from robotcell.dhprocedure.axes import AxisChain
from robotcell.dhprocedure.convert import convert_convention
from robotcell.dhprocedure.procedure import DHDerivation, FrameNote, dh_from_axes
from robotcell.dhprocedure.symbolic import SymbolicArm, symbolic_arm, symbolic_link
from robotcell.dhprocedure.urdf import UrdfChain, UrdfJoint, dh_from_urdf, read_urdf

__all__ = [
    "AxisChain",
    "DHDerivation",
    "FrameNote",
    "SymbolicArm",
    "UrdfChain",
    "UrdfJoint",
    "convert_convention",
    "dh_from_axes",
    "dh_from_urdf",
    "read_urdf",
    "symbolic_arm",
    "symbolic_link",
]
