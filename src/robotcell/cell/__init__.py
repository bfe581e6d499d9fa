"""The robot cell: its data model, its file, coupled kinematics, and calibrating into it.

- :mod:`robotcell.cell.parts`: :class:`Tool`, :class:`Frame`, :class:`Track`,
  :class:`Turntable`, :class:`Positioner`, :class:`Provenance`, :class:`IdentifiedArm`,
  :class:`CellRobot` (one robot of a cell: arm, base or track, tools) (SI units);
- :mod:`robotcell.cell.schema`: the YAML cell file (millimetres, degrees), its reader and writer,
  and the atomic save that keeps comments and layout;
- :mod:`robotcell.cell.validation`: values given for a cell checked against its limits and size;
- :mod:`robotcell.cell.model`: :class:`Cell`, which holds the parts, reads and writes its file;
- :mod:`robotcell.cell.history`: the numbered backups of a cell file and its history;
- :mod:`robotcell.cell.update`: a change of a cell file as one locked read-change-write step
  (:func:`~robotcell.cell.update.update_cell_file`);
- :mod:`robotcell.cell.kinematics`: coupled forward kinematics (arm, track, positioner, frames);
- :mod:`robotcell.cell.ik`: inverse kinematics and paths in the cell;
- :mod:`robotcell.cell.axischain`: the kinematic chain of a positioner's axes;
- :mod:`robotcell.cell.calibrate`: calibration procedures that write their result into a cell.

``from robotcell.cell import Cell`` gives the names below.
"""

from robotcell.cell.kinematics import RESERVED_FRAMES
from robotcell.cell.model import Cell, cell_from_dict
from robotcell.cell.parts import (
    DEFAULT_ROBOT,
    NAME_RE,
    CellRobot,
    Frame,
    IdentifiedArm,
    Positioner,
    Provenance,
    Tool,
    Track,
    Turntable,
)
from robotcell.cell.schema import cell_to_dict

__all__ = ["DEFAULT_ROBOT", "NAME_RE", "RESERVED_FRAMES", "Cell", "CellRobot", "Frame", "IdentifiedArm", "Positioner",
           "Provenance", "Tool", "Track", "Turntable", "cell_from_dict", "cell_to_dict"]
