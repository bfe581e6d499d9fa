"""The frame procedure: a base / user frame (3-point, or N-point to known coordinates)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from robotcell.calibration.result import CalibrationResult
from robotcell.calibration.spec import SPECS
from robotcell.cell import Cell
from robotcell.cell.calibrate.common import (
    CellCalibration,
    Notes,
    Record,
    assumption,
    chained_inputs,
    copied,
    measurement_file,
    no_cell_track,
    provenance_of,
    recorded_options,
    refuse_track_column,
)
from robotcell.cell.calibrate.context import CalibrationContext
from robotcell.cell.calibrate.registry import Planner, Procedure
from robotcell.cell.calibrate.simulation import (
    DOWN,
    Touches,
    candidate_tracks,
    frame_name,
    reach,
    three_point,
    tool_name,
    touched_in_parent,
)
from robotcell.cell.calibrate.touches import (
    MeasurementInput,
    read_touches,
    robot_in_world,
    tool_transform,
    track_positions,
)
from robotcell.cell.kinematics import frame_pose, tool_pose
from robotcell.errors import InputError, term
from robotcell.kinematics.transforms import make_pose, transform_points


def _frame_parent(cell: Cell, name: str | None, parent: str | None, label: str) -> str:
    """Parent of the frame to write: ``parent``, else the existing frame's, else world."""
    if parent is not None:
        if parent not in ("world", "robot"):
            raise InputError(f"the parent of a touched frame must be 'world' or 'robot', got "
                             f"{parent!r} (a frame on the turntable is a workpiece)")
        return parent
    old = cell.frames.get(name) if name is not None else None
    if old is None:
        return "world"
    if old.parent == "turntable":
        raise InputError(
            f"frame {name!r} of {label} is carried by the turntable: calibrate it with "
            f"{term('procedure:workpiece', 'robotcell.cell.calibrate.workpiece')}, or pass "
            f"{term('parent=world', 'parent=' + repr('world'))} or "
            f"{term('parent=robot', 'parent=' + repr('robot'))} to replace it by a frame fixed "
            "there")
    return old.parent


def frame(cell: Cell | None, measurements: MeasurementInput, name: str | None = None, *,
          parent: Literal["world", "robot"] | None = None,
          context: CalibrationContext | None = None, **keywords: Any) -> CellCalibration:
    """A base / user frame (3-point, or N-point to known coordinates) into a cell.

    Parameters
    ----------
    cell : Cell or None
        The cell whose frame ``name`` is calibrated; None: a plain calibration in the robot base.
    measurements : TouchTable, mapping, str or Path
        TCP positions ``x,y,z`` (mm, robot base) or joint values ``a1..an`` (deg); column
        ``point`` (``origin``, ``x``, ``xy``) or ``nominal_x, nominal_y, nominal_z`` (mm); in a
        cell with a track, for a frame in the world, ``track`` (mm).
    name : str, optional
        Frame of the cell to write (added when new). Without it nothing is written.
    parent : {"world", "robot"}, optional
        What carries the frame; default the existing frame's parent, else world. A frame in
        the world is computed from touches mapped to the world.
    context : CalibrationContext, optional
        Who touched and how well, names in messages, where notes go, the touch file to record
        and the nominal accuracy (:class:`~robotcell.cell.calibrate.context.CalibrationContext`).
    **keywords
        Fields of :class:`~robotcell.cell.calibrate.context.CalibrationContext` over
        ``context``, e.g. ``sigma=1e-4, tool="torch"``.

    Returns
    -------
    CellCalibration
        ``result.values`` holds ``T_world_NAME`` for a frame in the world, else ``T_R_W``.
    """
    from robotcell.calibration.frame import frame_3point, frame_npoint

    ctx = CalibrationContext.of(context, **keywords)
    tool, sigma = ctx.tool, ctx.sigma
    if cell is None and parent is not None:
        raise InputError("the parent of a frame is a cell's notion; give the cell too")
    label = ctx.label(cell)
    notes = Notes(ctx.on_note)
    m = read_touches("frame", measurements, ctx.source, ctx.arm(cell), notes.one)
    p = m.tcp(tool_transform(cell, tool, m))
    in_world = False
    p_R, e = p, None
    if cell is None:
        refuse_track_column(m, no_cell_track())
    else:
        parent = _frame_parent(cell, name, parent, label)  # type: ignore[assignment]
        if parent == "world":
            p = transform_points(robot_in_world(cell, m, label), p)
            e = np.zeros(m.n) if m.track is None else m.track
            in_world = True
        else:
            track_positions(cell, m, label)
    chained = chained_inputs(cell, m, p_R, tool, e, ctx.nominal, notes)
    if m.nominal is not None:
        m.check_count()
        result = frame_npoint(p, m.nominal, sigma, m.labels(), inputs=chained.inputs)
    else:
        m.check_points()
        result = frame_3point(p, m.point, sigma, m.labels(points=True), inputs=chained.inputs)
    item = f"frames.{name}" if cell is not None and name is not None else ""
    key = f"T_world_{name}" if in_world else "T_R_W"
    assumed = assumption(cell, m, tool, f"T_world_{name or 'W'}" if in_world else key,
                         mapped=in_world)
    if cell is None or name is None:
        return CellCalibration(result, notes=tuple(notes), key=item, value="T_R_W",
                               inputs=chained.keys, assumed=assumed)
    if in_world:
        result = result.renamed("T_R_W", key)
    record = Record(measurement_file(measurements, ctx.file),
                    recorded_options(sigma, tool, parent=parent), chained, ctx.nominal)
    prov = provenance_of("frame", result, m.n, m.source, ctx.time, cell, item, key, record)
    new = copied(cell)
    new.update_frame(name, result.values[key], prov, parent=parent)
    return CellCalibration(result, new, f"frame {name!r} (parent {parent})", prov, tuple(notes),
                           key=item, value=key, inputs=chained.keys, assumed=assumed)


# -- simulation ------------------------------------------------------------------------------------
def simulate(cell: Cell, rng: np.random.Generator, noise: float, tool: str | None,
             track: float | None, frame: str | None = None, size: float = 0.2,
             repeats: int = 2) -> Touches:
    """The touches of the frame procedure (:attr:`Procedure.simulate
    <robotcell.cell.calibrate.registry.Procedure>`): the origin of a fixed ``frame``, a point
    ``size`` along its +X and one ``size`` along its +Y, each ``repeats`` times."""
    name = frame_name(cell, frame, ("world", "robot"), "fixed")
    tname = tool_name(cell, tool)
    p_X, roles = three_point(size, repeats)
    n = len(roles)
    E = candidate_tracks(cell, track, n)

    def targets(Ek: NDArray[np.float64]) -> NDArray[np.float64]:
        T_wX = frame_pose(cell, name, Ek)                                    # (K, n, 4, 4)
        p_w = transform_points(T_wX, p_X)                                    # (K, n, 3)
        return make_pose(DOWN[None, None], p_w[:, :, None])

    labels = [f"touch {i + 1} ({r})" for i, r in enumerate(roles)]
    q, e = reach(cell, targets, E, tool_pose(cell, tname), labels, rng, noise)
    fr = cell.frames[name]
    return Touches("frame", q, e if cell.track is not None else None, None, roles,
                   truth={"pose": fr.pose.copy(), "parent": fr.parent, "name": name},
                   tool=tname, noise=noise)


# -- the procedure ---------------------------------------------------------------------------------
def _repeat(cell: Cell, file: str, name: str | None, options: Mapping[str, Any],
            context: CalibrationContext) -> CellCalibration:
    """The recorded calibration again (:attr:`Procedure.repeat
    <robotcell.cell.calibrate.registry.Procedure>`)."""
    return frame(cell, file, name, parent=options.get("parent"), context=context)


def _estimate(cell: Cell, touches: Touches, sigma: float | None) -> CalibrationResult:
    """The estimator on simulated touches (:attr:`Planner.calibrate
    <robotcell.cell.calibrate.registry.Planner>`): 3-point, in the frame's parent."""
    from robotcell.calibration.frame import frame_3point

    m = touches.measurements(cell.robot)
    return frame_3point(touched_in_parent(cell, touches, m), m.point, sigma)


PROCEDURE = Procedure(
    "frame", "a base / user frame fixed in the cell (3-point)", SPECS["frame"], frame,
    item="frames.NAME", repeat=_repeat, simulate=simulate,
    planner=Planner(tuple({"size": s} for s in (0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5)),
                    pose="T_R_W", truth="pose", calibrate=_estimate))
