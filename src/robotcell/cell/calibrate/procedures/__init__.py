"""Calibrating into a cell: one module per procedure, from a measurement table to an updated Cell.

Each procedure's call (``tcp.tcp``, ``frame.frame``, ...) takes a :class:`~robotcell.cell.Cell`
(or None for a plain calibration in the robot base), the measurements (the CSV's path; a table,
column name to values in the units of the measurement CSV, mm and deg, as
:func:`robotcell.io.tables.read_csv` returns it; or touches read before,
:class:`~robotcell.calibration.measurements.Measurements`), read once by the procedure's
specification (:data:`~robotcell.calibration.spec.SPECS`), and the procedure's options in SI
units. It maps the touches into the frames of the cell (through column ``track``
when the robot is on a track), runs the estimator of :mod:`robotcell.calibration` and returns a
:class:`~robotcell.cell.calibrate.common.CellCalibration`: the
:class:`~robotcell.calibration.result.CalibrationResult`, a new
:class:`~robotcell.cell.Cell` with the calibrated value written in, stamped with its
:class:`~robotcell.cell.Provenance` (the cell given is not changed), and notes: on the
measurements (columns not used, identical rows, touches mapped to the world, where the turntable
comes from), each also passed to ``on_note`` as soon as it arises (so that a caller shows them
even when the measurements are then refused), and on the update (a value kept because the
touches do not measure it); and what it assumed (tool, frame of the result, track and table).
Nothing is written to a file: save the new cell with :meth:`Cell.save`. Each module also places
the procedure's touches in a virtual cell (its ``simulate``, on
:mod:`robotcell.cell.calibrate.simulation`).

The 2-axis positioner is calibrated by :func:`robotcell.identification.calibrate_positioner` on
the kinematic-identification engine; ``positioner.positioner`` runs it on the touches of a cell
and writes the identified chain with :meth:`Cell.update_positioner`.
"""
