"""Calibrating into a cell: each procedure the technician runs is one call on a Cell.

``cellcal.tcp``, ``cellcal.frame``, ``cellcal.track``, ``cellcal.turntable`` and
``cellcal.workpiece`` take a :class:`~robotcell.cell.Cell`, the measurements (a CSV file, a
table in mm and deg, or :class:`~robotcell.calibration.measurements.Measurements` read by the
procedure's :mod:`~robotcell.calibration.spec`) and options in SI units, and return a
:class:`CellCalibration`: the result, the updated cell (a new object) and its provenance.
``cellcal.external_tcp`` calibrates a fixed tool in the robot base the same way (nothing is
written into the cell).
``cellcal.positioner`` calibrates a 2-axis positioner's chain into the cell (on the
identification engine); ``cellcal.positioner_touches`` gives its input. Each records its touch
file, options and error sources, so that the next calibration carries its uncertainty
(:mod:`.chain`) and ``cellcal.calibrate_cell`` re-estimates the whole cell in one fit
(:mod:`.whole`).
See ``docs/python-api.md``.
"""

from robotcell.cell.calibrate.chain import NOMINAL_ACCURACY, NominalAccuracy
from robotcell.cell.calibrate.procedures import (
    SAME_POSE,
    CellCalibration,
    TurntablePose,
    external_tcp,
    frame,
    positioner,
    positioner_touches,
    tcp,
    track,
    turntable,
    workpiece,
)
from robotcell.cell.calibrate.touches import (
    load_table,
    read_touches,
    robot_in_world,
    track_positions,
)
from robotcell.cell.calibrate.whole import CellRecalibration, ItemChange, calibrate_cell

__all__ = ["NOMINAL_ACCURACY", "SAME_POSE", "CellCalibration", "CellRecalibration", "ItemChange",
           "NominalAccuracy", "TurntablePose", "calibrate_cell", "external_tcp", "frame",
           "load_table", "positioner", "positioner_touches", "read_touches", "robot_in_world",
           "tcp", "track", "track_positions", "turntable", "workpiece"]
