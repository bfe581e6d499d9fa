"""The built-in calibration procedures, one module each, registered in :data:`BUILT_IN` order.

Each module holds everything of one procedure: its call into a cell, how ``calibrate cell``
repeats it from what the cell recorded, the placement of its touches in a virtual cell
(``simulate``), its touch designs for ``plan``, and its descriptor ``PROCEDURE``
(:class:`~robotcell.cell.calibrate.registry.Procedure`), which names them with its measurement
table (:data:`~robotcell.calibration.spec.SPECS`).

Each call (``tcp.tcp``, ``frame.frame``, ...; :mod:`robotcell.cell.calibrate` has them all) takes
a :class:`~robotcell.cell.Cell` (or None for a plain calibration in the robot base), the
measurements (the CSV's path; a table, column name to values in the units of the measurement
CSV, mm and deg, as :func:`robotcell.io.tables.read_csv` returns it; or touches read before,
:class:`~robotcell.calibration.measurements.TouchTable`), read once by the procedure's table,
the procedure's options in SI units, and the keywords every calibration shares
(:class:`~robotcell.cell.calibrate.context.CalibrationContext`). It maps the touches into the
frames of the cell (through column ``track`` when the robot is on a track), runs the estimator
of :mod:`robotcell.calibration` and returns a
:class:`~robotcell.cell.calibrate.common.CellCalibration`: the
:class:`~robotcell.calibration.result.CalibrationResult`, a new :class:`~robotcell.cell.Cell`
with the calibrated value written in, stamped with its :class:`~robotcell.cell.Provenance` (the
cell given is not changed), and notes: on the measurements (columns not used, identical rows,
touches mapped to the world, where the turntable comes from), each also passed to ``on_note`` as
soon as it arises (so that a caller shows them even when the measurements are then refused), and
on the update (a value kept because the touches do not measure it); and what it assumed (tool,
frame of the result, track and table). Nothing is written to a file: save the new cell with
:meth:`Cell.save`.

The 2-axis positioner is calibrated by :func:`robotcell.identification.calibrate_positioner` on
the kinematic-identification engine (an identification of its chain); ``positioner.positioner``
runs it on the touches of a cell and writes the identified chain with
:meth:`Cell.update_positioner`.
"""

from robotcell.cell.calibrate.procedures import (
    external_tcp,
    frame,
    positioner,
    tcp,
    track,
    turntable,
    workpiece,
)
from robotcell.cell.calibrate.registry import register

#: The built-in procedures, in the order every list of them shows.
BUILT_IN = tuple(room.PROCEDURE for room in (tcp, frame, external_tcp, track, turntable,
                                             workpiece, positioner))
for _procedure in BUILT_IN:
    register(_procedure)
