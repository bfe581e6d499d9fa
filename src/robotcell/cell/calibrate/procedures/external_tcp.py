"""The external-tcp procedure: a fixed tool touched with a robot-held reference tool."""

from __future__ import annotations

from collections.abc import Callable

from numpy.typing import ArrayLike

from robotcell.cell import Cell
from robotcell.cell.calibrate.common import CellCalibration, Notes, arm_of, assumption
from robotcell.cell.calibrate.touches import MeasurementInput, read_touches, tool_transform
from robotcell.robot.robot import Robot


def external_tcp(cell: Cell | None, measurements: MeasurementInput, *,
                 robot: Robot | None = None, tool: str | ArrayLike | None = None,
                 sigma: float | None = None, source: str | None = None,
                 cell_label: str | None = None, on_note: Callable[[str], None] | None = None
                 ) -> CellCalibration:
    """A fixed (external) tool touched with a robot-held reference tool of known TCP.

    Parameters
    ----------
    cell : Cell or None
        A cell whose robot and tools the touches were taken with (the result is in its robot
        base and is not written into it); None: ``robot`` and ``tool`` give them.
    measurements : Measurements, mapping, str or Path
        Reference-tool TCP positions ``x,y,z`` (mm) or joint values ``a1..an`` (deg); column
        ``point``: ``tcp`` (the fixed TCP, the default), ``x`` (a point on its +X axis), ``xy``
        (a point in its XY plane with +Y).
    robot : Robot, optional
        Robot model for joint values when no cell is given.
    tool : str or array_like of shape (4, 4), optional
        The reference tool: a tool of the cell by name, or ``T_F_TCP`` (m); default the robot
        model's tool.
    sigma, source, cell_label, on_note
        As for :func:`tcp`.

    Returns
    -------
    CellCalibration
        ``result.values["T_R_TCP"]``: the fixed tool in the robot base (see
        :func:`robotcell.calibration.frame.external_tcp`); no cell.
    """
    from robotcell.calibration.frame import external_tcp as calibrate_external_tcp

    notes = Notes(on_note)
    m = read_touches("external-tcp", measurements, source, arm_of(cell, robot), notes.one)
    p = m.tcp(tool_transform(cell, tool, m))
    result = calibrate_external_tcp(p, m.point, sigma, m.labels(points=True))
    return CellCalibration(result, notes=tuple(notes), value="T_R_TCP",
                           assumed=assumption(cell, m, tool, "T_R_TCP"))
