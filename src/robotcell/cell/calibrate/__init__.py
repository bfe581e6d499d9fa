"""Calibrating into a cell: each procedure the technician runs is one call on a Cell.

``cellcal.tcp``, ``cellcal.frame``, ``cellcal.track``, ``cellcal.turntable`` and
``cellcal.workpiece`` take a :class:`~robotcell.cell.Cell`, the measurements (a CSV file, a
table in mm and deg, or :class:`~robotcell.calibration.measurements.TouchTable` read by the
procedure's :mod:`~robotcell.calibration.spec`), options in SI units and the keywords every
calibration shares (:class:`CalibrationContext`, or its fields as keywords), and return a
:class:`CellCalibration`: the result, the updated cell (a new object) and its provenance.
``cellcal.external_tcp`` calibrates a fixed tool in the robot base the same way (nothing is
written into the cell).
``cellcal.positioner`` calibrates a 2-axis positioner's chain into the cell (on the
identification engine); ``cellcal.positioner_touches`` gives its input. Each records its touch
file, options and error sources, so that the next calibration carries its uncertainty
(:mod:`.chain`) and ``cellcal.calibrate_cell`` re-estimates the whole cell in one fit
(:mod:`.whole`; a cell of several robots robot by robot, with the placements between them:
:mod:`.wholerobots`).
Each procedure is one module of :mod:`.procedures` and one :class:`Procedure` in the registry
(:mod:`.registry`: :func:`procedure`, :func:`having`, :func:`register`), from which the command
line, the simulation, the planner, the whole-cell fit, the reports and the views take it.
See ``docs/python-api.md``.
"""

from robotcell.cell.calibrate.chain import NOMINAL_ACCURACY, NominalAccuracy
from robotcell.cell.calibrate.common import CellCalibration
from robotcell.cell.calibrate.context import CalibrationContext
from robotcell.cell.calibrate.procedures.external_tcp import external_tcp
from robotcell.cell.calibrate.procedures.frame import frame
from robotcell.cell.calibrate.procedures.positioner import positioner, positioner_touches
from robotcell.cell.calibrate.procedures.tcp import tcp
from robotcell.cell.calibrate.procedures.track import track
from robotcell.cell.calibrate.procedures.turntable import TurntablePose, turntable
from robotcell.cell.calibrate.procedures.workpiece import SAME_POSE, workpiece
from robotcell.cell.calibrate.registry import (
    PROCEDURES,
    Planner,
    Procedure,
    for_result,
    having,
    procedure,
    register,
    unregister,
)
from robotcell.cell.calibrate.touches import (
    load_table,
    read_touches,
    robot_in_world,
    track_positions,
)
from robotcell.cell.calibrate.whole import CellRecalibration, ItemChange
from robotcell.cell.calibrate.wholerobots import calibrate_cell

__all__ = ["NOMINAL_ACCURACY", "PROCEDURES", "SAME_POSE", "CalibrationContext", "CellCalibration",
           "CellRecalibration", "ItemChange", "NominalAccuracy", "Planner", "Procedure",
           "TurntablePose", "calibrate_cell", "external_tcp", "for_result", "frame", "having",
           "load_table", "positioner", "positioner_touches", "procedure", "read_touches",
           "register", "robot_in_world", "tcp", "track", "track_positions", "turntable",
           "unregister", "workpiece"]
