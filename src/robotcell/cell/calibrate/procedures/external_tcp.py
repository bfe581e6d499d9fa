"""The external-tcp procedure: a fixed tool touched with a robot-held reference tool."""

from __future__ import annotations

from typing import Any

from robotcell.calibration.spec import SPECS
from robotcell.cell import Cell
from robotcell.cell.calibrate.common import CellCalibration, Notes, assumption, chained_inputs
from robotcell.cell.calibrate.context import CalibrationContext
from robotcell.cell.calibrate.registry import Procedure
from robotcell.cell.calibrate.touches import MeasurementInput, read_touches, tool_transform


def external_tcp(cell: Cell | None, measurements: MeasurementInput, *,
                 context: CalibrationContext | None = None, **keywords: Any) -> CellCalibration:
    """A fixed (external) tool touched with a robot-held reference tool of known TCP.

    Parameters
    ----------
    cell : Cell or None
        A cell whose robot and tools the touches were taken with (the result is in its robot
        base and is not written into it); None: the context's ``robot`` and ``tool`` give them.
    measurements : TouchTable, mapping, str or Path
        Reference-tool TCP positions ``x,y,z`` (mm) or joint values ``a1..an`` (deg); column
        ``point``: ``tcp`` (the fixed TCP, the default), ``x`` (a point on its +X axis), ``xy``
        (a point in its XY plane with +Y).
    context : CalibrationContext, optional
        Its ``tool`` is the reference tool: a tool of the cell by name, or ``T_F_TCP`` (m);
        default the robot model's tool. In a cell the reference tool's error sources (its
        recorded uncertainty, else the accuracy ``nominal``) are part of the result's 1-sigma,
        as in every calibration that touches with a tool. Nothing is written, so ``time`` and
        ``file`` are not used (:class:`~robotcell.cell.calibrate.context.CalibrationContext`).
    **keywords
        Fields of :class:`~robotcell.cell.calibrate.context.CalibrationContext` over
        ``context``, e.g. ``sigma=1e-4, tool="torch"``.

    Returns
    -------
    CellCalibration
        ``result.values["T_R_TCP"]``: the fixed tool in the robot base (see
        :func:`robotcell.calibration.frame.calibrate_external_tcp`); no cell.
    """
    from robotcell.calibration.frame import calibrate_external_tcp

    ctx = CalibrationContext.of(context, **keywords)
    notes = Notes(ctx.on_note)
    m = read_touches("external-tcp", measurements, ctx.source, ctx.arm(cell), notes.one)
    p = m.tcp(tool_transform(cell, ctx.tool, m))
    chained = chained_inputs(cell, m, p, ctx.tool, None, ctx.nominal, notes)
    result = calibrate_external_tcp(p, m.point, ctx.sigma, m.labels(points=True),
                                    inputs=chained.inputs)
    return CellCalibration(result, notes=tuple(notes), value="T_R_TCP", inputs=chained.keys,
                           assumed=assumption(cell, m, ctx.tool, "T_R_TCP"))


PROCEDURE = Procedure(
    "external-tcp", "a fixed (external) tool, touched with a robot-held reference tool",
    SPECS["external-tcp"], external_tcp)
