"""The positioner procedure: a 2-axis (tilt-rotate) positioner's axis chain."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.grouping import alone_groups
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
from robotcell.cell.calibrate.ontable import positioner_points, world_track
from robotcell.cell.calibrate.registry import Procedure
from robotcell.cell.calibrate.simulation import DOWN, Touches, candidate_tracks, reach, tool_name
from robotcell.cell.calibrate.touches import MeasurementInput, read_touches, tool_transform
from robotcell.cell.kinematics import frame_pose, tool_pose
from robotcell.errors import IllPosedError, InputError, term
from robotcell.kinematics.bounds import within
from robotcell.kinematics.transforms import make_pose, transform_points


def positioner_touches(cell: Cell, measurements: MeasurementInput, *,
                       tool: str | ArrayLike | None = None, source: str | None = None,
                       cell_label: str | None = None
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Touches of a point on a positioner, as its calibration takes them.

    The input of the positioner calibration (:func:`robotcell.identification.calibrate_positioner`,
    on the kinematic-identification engine): the axis values of each touch and the touched
    point in the positioner's parent frame, mapped through the robot's track like the turntable
    touches. Its identified chain goes into the cell with :meth:`Cell.update_positioner`.

    Parameters
    ----------
    cell : Cell
        A cell with a positioner (or a turntable, the 1-axis case).
    measurements : TouchTable, mapping, str or Path
        TCP touches ``x,y,z`` (mm) or ``a1..an`` (deg), the axis values ``e1..en`` (deg, one
        column per positioner axis) and, for a positioner in the world of a cell with a track,
        ``track`` (mm).
    tool, source, cell_label
        As the fields of :class:`~robotcell.cell.calibrate.context.CalibrationContext`.

    Returns
    -------
    values : ndarray, shape (N, n)
        Axis values (rad).
    points : ndarray, shape (N, 3)
        The touched point in the positioner's parent frame (world or robot base; m).
    """
    label = CalibrationContext(cell_label=cell_label).label(cell)
    if cell.turntable is None:
        raise InputError(f"{label} has no positioner; add a 'positioner' section to the cell "
                         "file first")
    spec = SPECS["positioner"].with_axes(cell.turntable.n_axes)
    return positioner_points(cell, read_touches(spec, measurements, source, cell.robot), tool,
                             label)


def _check_alone(values: NDArray[np.float64], source: str, group_tol: float | None) -> None:
    """Refuse touches in which no 3 rows turn one axis alone over 10 deg (no start without a cell).

    ``values`` (N, 2) are tilt and rotate (rad); the circle point analysis that starts the fit
    without a nominal chain needs such a group per axis, the other axis held to what the values
    resolve (:func:`robotcell.calibration.grouping.alone_groups`).
    """
    least = SPECS["positioner"].minimum
    for k, name in enumerate(("e1 (tilt)", "e2 (rotate)")):
        if not alone_groups(values, k, least=least, span=math.radians(10.0), tol=group_tol):
            held = ("" if group_tol is None else
                    f" (the other axis within the stated {math.degrees(group_tol):g} deg)")
            raise IllPosedError(
                f"{source}: no {least} touches turn {name} alone over 10 deg or more{held}; "
                f"without {term('cell (Cell)', 'a cell')} the positioner calibration starts from "
                "the circles of such touches: touch a grid, e.g. 3 tilt by 4 rotate values, or give "
                "the cell with the positioner's nominal chain")


def positioner(cell: Cell | None, measurements: MeasurementInput, *,
               group_tol: float | None = None, context: CalibrationContext | None = None,
               **keywords: Any) -> CellCalibration:
    """A 2-axis (tilt-rotate) positioner's axis chain into a cell, from touches of one point.

    The touches (:func:`positioner_touches`) go to
    :func:`robotcell.identification.calibrate_positioner` with the cell's chain as the nominal
    model; the identified chain (axis lines, common normal, zeros and root; the touched point is
    not part of it) replaces the cell's, keeping the plate frame of its parameterisation, so
    frames carried by the positioner keep their poses on the plate. Its error sources are
    recorded over the root pose and the DH constants of each axis (the result's estimate
    ``chain``), for the workpiece touched on the plate.

    Parameters
    ----------
    cell : Cell or None
        A cell with a positioner of 2 axes. None: a plain calibration in the robot base, started
        from the circle point analysis of the touches (which then need, for each axis, at least
        3 that move that axis alone, e.g. a grid of 3 tilt by 4 rotate values); nothing written.
    measurements : TouchTable, mapping, str or Path
        As for :func:`positioner_touches`: one point on the table touched at several (tilt,
        rotate) values ``e1``, ``e2`` (deg).
    group_tol : float, optional
        Axis values within this of each other (rad) are the same commanded value; default
        derived from the data (:func:`robotcell.calibration.grouping.resolution`).
    context : CalibrationContext, optional
        Who touched and how well, names in messages, where notes go, the touch file to record
        and the nominal accuracy (:class:`~robotcell.cell.calibrate.context.CalibrationContext`).
    **keywords
        Fields of :class:`~robotcell.cell.calibrate.context.CalibrationContext` over
        ``context``, e.g. ``sigma=1e-4, tool="torch"``.

    Returns
    -------
    CellCalibration
        ``result`` is the positioner calibration's (procedure ``positioner-2axis``, values in
        the positioner's parent frame: ``T_world_B`` instead of ``T_R_B`` for a positioner in
        the world; in the robot base without a cell).
    """
    from robotcell.identification import calibrate_positioner

    ctx = CalibrationContext.of(context, **keywords)
    tool, sigma, nominal = ctx.tool, ctx.sigma, ctx.nominal
    label = ctx.label(cell)
    notes = Notes(ctx.on_note)
    if cell is None:
        m = read_touches("positioner", measurements, ctx.source, ctx.arm(None), notes.one)
        refuse_track_column(m, no_cell_track())
        points = m.tcp(tool_transform(None, tool))
        _check_alone(m.axes, m.source, group_tol)
        done = calibrate_positioner(m.axes, points, sigma=sigma, labels=m.labels(),
                                    group_tol=group_tol)
        return CellCalibration(done.result, notes=tuple(notes),
                               assumed=assumption(None, m, tool, "T_R_B"))
    pos = cell.turntable
    if pos is None or pos.n_axes != 2:
        raise InputError(f"{label} has no positioner of 2 axes (tilt, rotate) to calibrate")
    m = read_touches("positioner", measurements, ctx.source, ctx.arm(cell), notes.one)
    values, points = positioner_points(cell, m, tool, label)
    chained = chained_inputs(cell, m, m.tcp(tool_transform(cell, tool, m)), tool,
                             world_track(cell, m), nominal, notes)
    done = calibrate_positioner(values, points, nominal=pos.chain, sigma=sigma,
                                labels=m.labels(), inputs=chained.inputs, group_tol=group_tol)
    key = "T_world_B" if pos.parent == "world" else "T_R_B"
    result = done.result.renamed("T_R_B", key)
    record = Record(measurement_file(measurements, ctx.file), recorded_options(sigma, tool),
                    chained, nominal)
    prov = provenance_of("positioner", result, m.n, m.source, ctx.time, cell, "turntable", "chain",
                         record)
    new = copied(cell)
    new.update_positioner(prov, done.robot.with_tool(np.eye(4)))
    return CellCalibration(result, new, f"positioner {pos.name!r} (axes, root)", prov,
                           tuple(notes), key="positioner", inputs=chained.keys,
                           assumed=assumption(cell, m, tool, key, mapped=pos.parent == "world"))


# -- simulation ------------------------------------------------------------------------------------
def _positioner_values(lower: float, upper: float, values: ArrayLike | None,
                       default: NDArray[np.float64], what: str) -> NDArray[np.float64]:
    """Values of one positioner axis (rad): ``values`` checked, else ``default`` clipped."""
    if values is None:
        return np.unique(np.clip(default, lower, upper))
    v = np.atleast_1d(np.asarray(values, dtype=float))
    if v.ndim != 1 or not np.all(np.isfinite(v)):
        raise InputError(f"{what} values must be a list of finite numbers (rad)")
    out = ~within(v, lower, upper)
    if np.any(out):
        raise InputError(f"{what} value(s) {', '.join(f'{math.degrees(x):g}' for x in v[out])} deg "
                         f"are outside the axis limits [{math.degrees(lower):g}, "
                         f"{math.degrees(upper):g}] deg")
    return v


def simulate(cell: Cell, rng: np.random.Generator, noise: float, tool: str | None,
             track: float | None, tilts: ArrayLike | None = None,
             rotates: ArrayLike | None = None, radius: float = 0.2,
             height: float = 0.0) -> Touches:
    """The touches of the positioner procedure (:attr:`Procedure.simulate
    <robotcell.cell.calibrate.registry.Procedure>`): the point ``(radius, 0, height)`` of the
    plate P at every combination of ``tilts`` (default -30, 0, 30 deg) and ``rotates``
    (default 0, 90, 180, 270 deg), clipped to the limits."""
    pos = cell.turntable
    if pos is None or pos.n_axes != 2:
        raise InputError("the positioner procedure needs a cell with a positioner of 2 axes "
                         "(tilt, rotate)")
    tname = tool_name(cell, tool)
    if not radius > 0:
        raise InputError(f"radius must be positive (m), got {radius}")
    t = _positioner_values(pos.lower[0], pos.upper[0], tilts, np.radians([-30.0, 0.0, 30.0]),
                           "tilt")
    r = _positioner_values(pos.lower[1], pos.upper[1], rotates,
                           np.radians([0.0, 90.0, 180.0, 270.0]), "rotate")
    if len(t) < 2 or len(r) < 3:
        raise InputError(f"the positioner calibration needs at least 2 tilt and 3 rotate values, "
                         f"got {len(t)} and {len(r)}")
    v = np.stack(np.meshgrid(t, r, indexing="ij"), axis=-1).reshape(-1, 2)  # (n, 2)
    n = len(v)
    p_P = np.array([radius, 0.0, height])

    def targets(Ek: NDArray[np.float64]) -> NDArray[np.float64]:
        T_wP = frame_pose(cell, "turntable", Ek) @ pos.T_root_P(v)             # (K, n, 4, 4)
        p_w = transform_points(T_wP, p_P)                                    # (K, n, 3)
        return make_pose(DOWN[None, None], p_w[:, :, None])

    E = candidate_tracks(cell, track, n)
    labels = [f"touch {i + 1} ({math.degrees(a):.0f}, {math.degrees(b):.0f} deg)"
              for i, (a, b) in enumerate(v)]
    q, e = reach(cell, targets, E, tool_pose(cell, tname), labels, rng, noise)
    return Touches("positioner", q, e if cell.track is not None else None, v, None,
                   truth={"chain": pos.chain, "parent": pos.parent, "point": p_P},
                   tool=tname, noise=noise)


# -- the procedure ---------------------------------------------------------------------------------
def _repeat(cell: Cell, file: str, name: str | None, options: Mapping[str, Any],
            context: CalibrationContext) -> CellCalibration:
    """The recorded calibration again (:attr:`Procedure.repeat
    <robotcell.cell.calibrate.registry.Procedure>`), started from the cell's chain."""
    return positioner(cell, file, context=context)


PROCEDURE = Procedure(
    "positioner", "a 2-axis positioner's axis chain (one point on the table at several "
    "(tilt, rotate) values)", SPECS["positioner"], positioner, item="positioner",
    repeat=_repeat, simulate=simulate)
