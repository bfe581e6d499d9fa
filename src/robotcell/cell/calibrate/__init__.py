"""Calibrating into a cell: each procedure the technician runs is one call on a Cell.

``cellcal.tcp``, ``cellcal.frame``, ``cellcal.track``, ``cellcal.turntable`` and
``cellcal.workpiece`` take a :class:`~robotcell.cell.Cell`, a measurement table (mm, deg, as
:func:`robotcell.io.tables.read_csv` returns it) and options in SI units, and return a
:class:`CellCalibration`: the result, the updated cell (a new object) and its provenance.
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
    frame,
    positioner,
    positioner_touches,
    tcp,
    track,
    turntable,
    workpiece,
)
from robotcell.cell.calibrate.touches import load_table, robot_in_world, track_positions
from robotcell.cell.calibrate.whole import CellRecalibration, ItemChange, calibrate_cell

__all__ = ["NOMINAL_ACCURACY", "SAME_POSE", "CellCalibration", "CellRecalibration", "ItemChange",
           "NominalAccuracy", "TurntablePose", "calibrate_cell", "frame", "load_table",
           "positioner", "positioner_touches", "robot_in_world", "tcp", "track", "track_positions", "turntable",
           "workpiece"]
