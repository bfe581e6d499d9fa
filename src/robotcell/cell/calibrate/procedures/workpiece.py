"""The workpiece procedure: a workpiece frame on the turntable or on a positioner's plate."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.measurements import TouchTable
from robotcell.calibration.result import CalibrationResult
from robotcell.calibration.spec import SPECS
from robotcell.cell import Cell, Positioner
from robotcell.cell.calibrate.chain import (
    NominalAccuracy,
    item_sources,
    plate_inputs,
)
from robotcell.cell.calibrate.common import (
    CellCalibration,
    Notes,
    Record,
    assumption,
    chained_inputs,
    copied,
    measurement_file,
    provenance_of,
    recorded_options,
)
from robotcell.cell.calibrate.context import CalibrationContext
from robotcell.cell.calibrate.ontable import (
    cell_turntable,
    on_table,
    positioner_points,
    world_track,
)
from robotcell.cell.calibrate.procedures.turntable import TurntablePose
from robotcell.cell.calibrate.registry import Planner, Procedure
from robotcell.cell.calibrate.simulation import (
    DOWN,
    Touches,
    candidate_tracks,
    frame_name,
    one_axis_table,
    reach,
    table_angles,
    three_point,
    tool_name,
    touched_in_parent,
)
from robotcell.cell.calibrate.touches import MeasurementInput, read_touches, tool_transform
from robotcell.cell.kinematics import frame_pose, tool_pose
from robotcell.errors import InputError, term
from robotcell.kinematics.transforms import invert, make_pose, rot_z, transform_points

#: Largest difference between a given turntable pose and the cell's that counts as the same
#: calibration (m, rad): far above the cell file's rounding, far below any recalibration.
SAME_POSE = 1e-6


def _workpiece_turntable(cell: Cell | None, given: TurntablePose | None, label: str,
                         nominal: NominalAccuracy) -> tuple[TurntablePose, list[str]]:
    """The turntable root in the frame of the touches, and notes on where it comes from."""
    if cell is None:
        if given is None:
            result = term("turntable=JSON", "turntable (a TurntablePose, or the result of "
                          "robotcell.cell.calibrate.turntable)")
            raise InputError(f"the workpiece needs the turntable: pass {result}, or "
                             f"{term('cell=FILE', 'a cell')} to use the cell's turntable")
        if given.frame != "robot":
            raise InputError(f"{given.source} holds the turntable in the world (T_world_B, "
                             f"calibrated with {term('cell', 'a cell')}), but touches without "
                             f"{term('cell', 'a cell')} are in the robot base: pass the same "
                             f"{term('cell=FILE', 'cell')}")
        return given, []
    tt = cell_turntable(cell, label)
    if given is None:
        sources, note = item_sources(cell, "turntable", nominal)
        return TurntablePose(tt.T_parent_B, sources, frame=tt.parent, source=label), (
            [note] if note else [])
    if given.frame != tt.parent:
        raise InputError(f"{given.source} holds the turntable in the "
                         f"{'world' if given.frame == 'world' else 'robot base'}, but the "
                         f"turntable of {label} has parent {tt.parent}: calibrate the turntable "
                         f"{term('cell:into', 'into')} {label}, or omit "
                         f"{term('turntable', 'turntable')} to use the cell's turntable")
    dT = invert(tt.T_parent_B) @ given.T
    dist = float(np.linalg.norm(dT[:3, 3]))
    angle = float(np.arccos(np.clip((np.trace(dT[:3, :3]) - 1.0) / 2.0, -1.0, 1.0)))
    if max(dist, angle) <= SAME_POSE:
        # The calibration the cell holds: its recorded error sources say what it shares with the
        # tool and the track, which the given result's covariance alone cannot.
        sources, note = item_sources(cell, "turntable", nominal)
        return replace(given, covariance=sources), [note] if note else []
    return given, [f"warning: the turntable of {given.source} differs from the one in "
                    f"{label} by {dist * 1e3:.3f} mm and {np.degrees(angle):.4f} deg; "
                    f"T_B_W is relative to {given.source}'s. Write that turntable into the "
                    "cell (" + term("procedure:turntable(cell)",
                                    "robotcell.cell.calibrate.turntable") + ") so that the two agree"]


def _positioner_workpiece(cell: Cell, m: TouchTable, name: str | None,
                          context: CalibrationContext, notes: Notes, file: str | None
                          ) -> CellCalibration:
    """:func:`workpiece` on a positioner chain: the touches taken into its plate frame P, with
    the chain's recorded error sources (:func:`robotcell.cell.calibrate.chain.plate_inputs`)."""
    from robotcell.calibration.frame import frame_3point

    tool, sigma, label, nominal = context.tool, context.sigma, context.label(cell), context.nominal

    values, points = positioner_points(cell, m, tool, label)
    m.check_points()
    pos = cell.turntable
    touched = chained_inputs(cell, m, m.tcp(tool_transform(cell, tool, m)), tool,
                             world_track(cell, m), nominal, notes)
    p_P, chained = plate_inputs(cell, values, points, touched, nominal)
    notes.add([n for n in chained.notes if n not in touched.notes])
    result = frame_3point(p_P, m.point, sigma, m.labels(points=True),
                          inputs=chained.inputs).renamed("T_R_W", "T_P_W")
    item = "" if name is None else f"frames.{name}"
    assumed = assumption(cell, m, tool, "T_P_W", mapped=pos.parent == "world")
    if name is None:
        return CellCalibration(result, notes=tuple(notes), value="T_P_W", inputs=chained.keys,
                               assumed=assumed)
    record = Record(file, recorded_options(sigma, tool), chained, nominal)
    prov = provenance_of("workpiece", result, m.n, m.source, context.time, cell, item, "T_P_W",
                         record)
    new = copied(cell)
    new.update_frame(name, result.values["T_P_W"], prov, parent="turntable")
    return CellCalibration(result, new, f"frame {name!r} (parent turntable)", prov, tuple(notes),
                           key=item, value="T_P_W", inputs=chained.keys, assumed=assumed)


def workpiece(cell: Cell | None, measurements: MeasurementInput, name: str | None = None, *,
              turntable: TurntablePose | CalibrationResult | None = None,
              context: CalibrationContext | None = None, **keywords: Any) -> CellCalibration:
    """Workpiece frame ``T_B_W`` on a calibrated turntable into a cell (parent turntable).

    Parameters
    ----------
    cell : Cell or None
        The cell whose frame ``name`` on the turntable is calibrated; None: needs ``turntable``.
        On a positioner chain the touches, with its axis values ``e1..en`` (deg), are taken
        into its plate frame P through the cell's chain and give ``T_P_W`` (3-point), whose
        uncertainty includes the chain's (its recorded error sources, or the nominal accuracy).
    measurements : TouchTable, mapping, str or Path
        TCP touches ``x,y,z`` (mm) or ``a1..an`` (deg) with the table angle ``e1`` (deg) and
        column ``point`` (``origin``, ``x``, ``xy``); for a turntable in the world of a cell with
        a track, ``track`` (mm).
    name : str, optional
        Frame of the cell to write (added when new). Without it nothing is written.
    turntable : TurntablePose or CalibrationResult, optional
        The turntable calibration, whose uncertainty is then propagated; default the cell's
        turntable with its recorded uncertainty (or the nominal accuracy), whose error sources
        it may share with the tool.
    context : CalibrationContext, optional
        Who touched and how well, names in messages, where notes go, the touch file to record
        and the nominal accuracy (:class:`~robotcell.cell.calibrate.context.CalibrationContext`).
    **keywords
        Fields of :class:`~robotcell.cell.calibrate.context.CalibrationContext` over
        ``context``, e.g. ``sigma=1e-4, tool="torch"``.

    Returns
    -------
    CellCalibration
    """
    from robotcell.calibration.workpiece import calibrate_workpiece

    ctx = CalibrationContext.of(context, **keywords)
    tool, sigma, nominal = ctx.tool, ctx.sigma, ctx.nominal
    label = ctx.label(cell)
    notes = Notes(ctx.on_note)
    if cell is not None and isinstance(cell.turntable, Positioner):
        if turntable is not None:
            raise InputError(f"{label} has a positioner chain, which carries its own "
                             "calibration: give no turntable result")
        spec = SPECS["workpiece"].with_axes(cell.turntable.n_axes)
        m = read_touches(spec, measurements, ctx.source, ctx.arm(cell), notes.one)
        return _positioner_workpiece(cell, m, name, ctx, notes,
                                     measurement_file(measurements, ctx.file))
    if isinstance(turntable, CalibrationResult):
        turntable = TurntablePose.from_result(turntable)
    model = ctx.arm(cell)
    tt, where = _workpiece_turntable(cell, turntable, label, nominal)
    notes.add(where)
    m = read_touches("workpiece", measurements, ctx.source, model, notes.one)
    theta, f, chained = on_table(cell, m, ctx, notes, m.check_points)
    result = calibrate_workpiece(theta, f, m.point, tt.T, T_R_B_covariance=tt.covariance,
                                 inputs=chained.inputs, sigma=sigma,
                                 labels=m.labels(points=True))
    inputs = chained.keys + (("turntable",) if cell is not None and turntable is None else ())
    item = "" if cell is None or name is None else f"frames.{name}"
    assumed = assumption(cell, m, tool, "T_B_W", mapped=tt.frame == "world")
    if cell is None or name is None:
        return CellCalibration(result, notes=tuple(notes), key=item, value="T_B_W",
                               inputs=inputs, assumed=assumed)
    record = Record(measurement_file(measurements, ctx.file), recorded_options(sigma, tool),
                    chained, nominal)
    prov = provenance_of("workpiece", result, m.n, m.source, ctx.time, cell, item, "T_B_W",
                         record, inputs)
    new = copied(cell)
    new.update_frame(name, result.values["T_B_W"], prov, parent="turntable")
    return CellCalibration(result, new, f"frame {name!r} (parent turntable)", prov, tuple(notes),
                           key=item, value="T_B_W", inputs=inputs, assumed=assumed)


# -- simulation ------------------------------------------------------------------------------------
def simulate(cell: Cell, rng: np.random.Generator, noise: float, tool: str | None,
             track: float | None, frame: str | None = None, size: float = 0.15,
             repeats: int = 2, angles: ArrayLike | None = None) -> Touches:
    """The touches of the workpiece procedure (:attr:`Procedure.simulate
    <robotcell.cell.calibrate.registry.Procedure>`): 3-point on ``frame`` (on a one-axis
    turntable) as for the frame procedure, at table angles spread over +-20 deg or ``angles``
    (one per touch)."""
    one_axis_table(cell)
    name = frame_name(cell, frame, ("turntable",), "workpiece")
    tname = tool_name(cell, tool)
    p_W, roles = three_point(size, repeats)
    n = len(roles)
    if angles is None:
        spread = np.radians(np.linspace(-20.0, 20.0, repeats)) if repeats > 1 else np.zeros(1)
        # +-20 deg, moved onto the nearest limit where the table cannot turn that far.
        th = np.clip(np.tile(spread, 3), cell.turntable.lower, cell.turntable.upper)
    else:
        th = table_angles(cell, angles, n)
        if th.shape != (n,):
            raise InputError(f"give one table angle per touch ({n}), got {th.size}")
    T_B_W = cell.frames[name].pose
    p_B = transform_points(T_B_W, p_W)

    def targets(Ek: NDArray[np.float64]) -> NDArray[np.float64]:
        T_wB = frame_pose(cell, "turntable", Ek)                              # (K, n, 4, 4)
        p_w = transform_points(T_wB, (rot_z(th) @ p_B[:, :, None])[..., 0])  # (K, n, 3)
        return make_pose(DOWN[None, None], p_w[:, :, None])

    E = candidate_tracks(cell, track, n)
    labels = [f"touch {i + 1} ({r}, {math.degrees(v):.0f} deg)"
              for i, (r, v) in enumerate(zip(roles, th))]
    q, e = reach(cell, targets, E, tool_pose(cell, tname), labels, rng, noise)
    return Touches("workpiece", q, e if cell.track is not None else None, th, roles,
                   truth={"pose": T_B_W.copy(), "parent": "turntable", "name": name},
                   tool=tname, noise=noise)


# -- the procedure ---------------------------------------------------------------------------------
def _repeat(cell: Cell, file: str, name: str | None, options: Mapping[str, Any],
            context: CalibrationContext) -> CellCalibration:
    """The recorded calibration again (:attr:`Procedure.repeat
    <robotcell.cell.calibrate.registry.Procedure>`), on the cell's turntable."""
    return workpiece(cell, file, name, context=context)


def _estimate(cell: Cell, touches: Touches, sigma: float | None) -> CalibrationResult:
    """The estimator on simulated touches (:attr:`Planner.calibrate
    <robotcell.cell.calibrate.registry.Planner>`), on the cell's turntable."""
    from robotcell.calibration.workpiece import calibrate_workpiece

    m = touches.measurements(cell.robot)
    assert cell.turntable is not None
    return calibrate_workpiece(m.axes[:, 0], touched_in_parent(cell, touches, m), m.point,
                               cell.turntable.T_parent_B, sigma=sigma)


PROCEDURE = Procedure(
    "workpiece", "a workpiece frame on the turntable (3-point at any table angles)",
    SPECS["workpiece"], workpiece, item="frames.NAME", repeat=_repeat, simulate=simulate,
    planner=Planner(tuple({"size": s} for s in (0.05, 0.1, 0.15, 0.2, 0.3, 0.4)),
                    pose="T_B_W", truth="pose", calibrate=_estimate))
