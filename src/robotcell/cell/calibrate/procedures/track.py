"""The track procedure: the robot's linear track (direction, scale, straightness, rotation)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.measurements import TouchTable
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
    provenance_of,
    recorded_options,
)
from robotcell.cell.calibrate.context import CalibrationContext
from robotcell.cell.calibrate.registry import Planner, Procedure
from robotcell.cell.calibrate.simulation import DOWN, Touches, reach, tool_name
from robotcell.cell.calibrate.touches import MeasurementInput, read_touches, tool_transform
from robotcell.cell.kinematics import tool_pose
from robotcell.cell.validation import check_axis_limits
from robotcell.errors import InputError, term
from robotcell.kinematics.transforms import make_pose, transform_points


def _cell_track_axis(cell: Cell, axis: str | None, references: NDArray[np.float64],
                     roll: str | None, label: str) -> str:
    """Track axis for a track calibration into a cell, refusing what cannot update ``T_L_R0``."""
    tr = cell.track
    if tr is None:
        raise InputError(f"{label} has no track to calibrate; add a 'track' section to the "
                         "cell file first")
    if tr.axis not in ("x", "z"):
        raise InputError(f"the track of {label} moves along its {tr.axis} axis; the track "
                         "calibration supports x and z: describe the track frame with the motion "
                         "along x or z")
    if axis is not None and axis != tr.axis:
        raise InputError(f"{term('axis', 'axis')} {axis} differs from the track axis {tr.axis} "
                         f"of {label}; drop {term('axis', 'axis')} (it defaults to the cell's) or "
                         "correct the cell file")
    if not len(references) and roll is None:
        points = term("reference=X,Y,Z", "references (touched points with known coordinates "
                      "in L, m)")
        raise InputError("touches of one unknown point do not measure the rotation of the robot "
                         "base about the track axis, so the track's robot_at_zero cannot be "
                         f"updated: pass {points} or accept the zero-roll convention with "
                         f"{term('roll=zero', 'roll=' + repr('zero'))}")
    return tr.axis


def _reference_indices(m: TouchTable, n_refs: int) -> NDArray[np.int_] | None:
    """0-based reference index per touch from column ``point`` (1-based in the table)."""
    if m.reference is None:
        if n_refs > 1:
            raise InputError(f"{m.source}: {n_refs} {term('reference', 'reference')} points "
                             f"given; add a column 'point' saying which one (1..{n_refs}) each "
                             "touch is")
        return None
    if n_refs == 0:
        raise InputError(f"{m.source}: column 'point' names reference points, but no "
                         f"{term('reference', 'references')} was given")
    idx = m.reference
    if not np.all(idx == np.round(idx)) or idx.min() < 1 or idx.max() > n_refs:
        raise InputError(f"{m.source}: column 'point' must hold reference numbers 1..{n_refs} "
                         f"(in the order of the {term('reference options', 'references')})")
    return idx.astype(int) - 1


def track(cell: Cell | None, measurements: MeasurementInput, *,
          references: ArrayLike | None = None, axis: Literal["x", "z"] | None = None,
          roll: Literal["zero"] | None = None, group_tol: float | None = None,
          context: CalibrationContext | None = None, **keywords: Any) -> CellCalibration:
    """Linear track (direction, scale, straightness, rotation when determined) into a cell.

    Parameters
    ----------
    cell : Cell or None
        The cell whose track's ``robot_at_zero`` (``T_L_R0``) and scale are calibrated; None: a
        plain calibration.
    measurements : TouchTable, mapping, str or Path
        TCP touches ``x,y,z`` (mm) or ``a1..an`` (deg) of fixed reference point(s) at track
        positions ``e1`` (mm); column ``point`` (1, 2, ...) with several references.
    references : array_like, shape (K, 3), optional
        Known coordinates of the touched reference points in the track frame L (m).
    axis : {"x", "z"}, optional
        Axis of L along which the carriage moves; default the cell's, else x.
    roll : {"zero"}, optional
        Without references: fix the rotation about the track axis to zero (a convention).
    group_tol : float, optional
        Track positions within this of each other (m) are one commanded position; default
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
        Into a cell, references or ``roll="zero"`` are required; when the carriage offset is not
        measured (fewer than two references) the cell's offset is kept, and a reference point is
        taken relative to it.
    """
    from robotcell.calibration.track import calibrate_track

    ctx = CalibrationContext.of(context, **keywords)
    tool, sigma, nominal = ctx.tool, ctx.sigma, ctx.nominal
    refs = (np.zeros((0, 3)) if references is None
            else np.asarray(references, dtype=float).reshape(-1, 3))
    label = ctx.label(cell)
    if cell is not None:
        axis = _cell_track_axis(cell, axis, refs, roll, label)  # type: ignore[assignment]
    notes = Notes(ctx.on_note)
    m = read_touches("track", measurements, ctx.source, ctx.arm(cell), notes.one)
    f = m.tcp(tool_transform(cell, tool, m))
    e = m.axes[:, 0]
    if cell is not None:
        check_axis_limits(cell.track, e, ["e1"], m.source, label)
    m.check_count()
    idx = _reference_indices(m, len(refs))
    options = recorded_options(sigma, tool,
                               references_mm=(refs * 1e3).tolist() if len(refs) else None,
                               axis=axis, roll=roll)
    keep_offset = cell is not None and len(refs) < 2
    if keep_offset:
        # The fit takes the unmeasured carriage offset as zero; the cell knows it.
        refs = refs - cell.track.T_L_R0[:3, 3]
    chained = chained_inputs(cell, m, f, tool, None, nominal, notes)
    result = calibrate_track(e, f, references=refs if len(refs) else None, point=idx,
                             axis=axis or "x", roll=roll, labels=m.labels(),
                             sigma=sigma, inputs=chained.inputs,
                             group_tol=group_tol)
    assumed = assumption(cell, m, tool, "T_L_R")
    if cell is None:
        return CellCalibration(result, notes=tuple(notes), assumed=assumed)
    tr = cell.track
    T_L_R0 = result.values["T_L_R"].copy()
    kept = []
    if keep_offset:
        T_L_R0[:3, 3] = tr.T_L_R0[:3, 3]
        offset = ", ".join(f"{v:.3f}" for v in tr.T_L_R0[:3, 3] * 1e3 + 0.0)
        kept.append(f"note: the carriage offset is not measured (two or more "
                    f"{term('reference', 'reference')} points measure it): kept the offset of "
                    f"{label} ({offset} mm)")
    record = Record(measurement_file(measurements, ctx.file), options, chained, nominal)
    prov = provenance_of("track", result, m.n, m.source, ctx.time, cell, "track", "T_L_R", record)
    new = copied(cell)
    new.update_track(prov, T_L_R0=T_L_R0, scale=float(result.values["scale"]))
    return CellCalibration(result, new, f"track {tr.name!r} (robot_at_zero, scale)", prov,
                           tuple(notes), tuple(kept), "track", "T_L_R", chained.keys, assumed)


# -- simulation ------------------------------------------------------------------------------------
def simulate(cell: Cell, rng: np.random.Generator, noise: float, tool: str | None,
             track: float | None, references: ArrayLike | None = None, positions: int = 4,
             travel: float = 1.0) -> Touches:
    """The touches of the track procedure (:attr:`Procedure.simulate
    <robotcell.cell.calibrate.registry.Procedure>`): each reference point (in L; default two,
    one on each side, a quarter of the travel from each end) at ``positions`` track positions
    spread over ``travel``."""
    if cell.track is None:
        raise InputError("the cell has no track")
    if track is not None:
        raise InputError("the track procedure moves the track itself; do not give a track position")
    t = cell.track
    if not (math.isfinite(t.lower) and math.isfinite(t.upper)):
        raise InputError("the cell's track has no limits (min, max); the simulation needs them to "
                         "place the touches")
    if t.axis not in ("x", "z"):
        raise InputError(f"the track calibration supports track axes x and z; this track moves "
                         f"along {t.axis}")
    if positions < 2:
        raise InputError(f"each reference point needs at least 2 track positions, got {positions}")
    if not (math.isfinite(travel) and travel > 0):
        raise InputError(f"travel must be a positive length (m), got {travel}")
    tname = tool_name(cell, tool)
    u = t.direction
    o = t.T_L_R0[:3, 3]
    span = (t.upper - t.lower) * t.scale
    if references is None:
        side = np.cross(u, [0.0, 0.0, 1.0]) if abs(u[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
        down = np.cross(side, u)
        refs = np.array([o + (t.lower * t.scale + 0.25 * span) * u + 0.9 * side - 0.3 * down,
                         o + (t.upper * t.scale - 0.25 * span) * u - 0.9 * side - 0.3 * down])
    else:
        refs = np.atleast_2d(np.asarray(references, dtype=float))
        if refs.shape[1:] != (3,):
            raise InputError(f"reference points must have shape (K, 3) (m, in L), got {refs.shape}")
    # Track positions per reference: spread over `travel` around where the robot faces the point.
    centre = (refs - o) @ u / t.scale
    offsets = np.linspace(-travel / 2, travel / 2, positions) / t.scale
    e_all = np.clip(centre[:, None] + offsets, t.lower, t.upper)
    point = np.repeat(np.arange(len(refs)), positions)
    least = SPECS["track"].minimum
    if len(point) < least:
        raise InputError(f"the track calibration needs at least {least} touches; "
                         f"{len(refs)} reference point(s) x {positions} positions give "
                         f"{len(point)}: add positions or reference points")
    e_all = e_all.ravel()
    for k in range(len(refs)):
        if np.ptp(e_all[point == k]) < 0.05:
            raise InputError(f"reference point {k + 1} is beyond the end of the track: its touches "
                             "cannot be spread along the travel")
    n = len(point)
    p_w = transform_points(t.T_world_L, refs[point])                         # (n, 3)

    def targets(Ek: NDArray[np.float64]) -> NDArray[np.float64]:
        return make_pose(DOWN[None, None], np.broadcast_to(p_w[None, :, None], (Ek.shape[0], n, 1, 3)))

    labels = [f"touch {i + 1} (reference {point[i] + 1})" for i in range(n)]
    q, e = reach(cell, targets, e_all[None, :], tool_pose(cell, tname), labels, rng, noise)
    options = [f"--reference={','.join(f'{v * 1e3:.3f}' for v in r)}" for r in refs]
    return Touches("track", q, e, None, [str(p + 1) for p in point],
                   truth={"T_L_R": t.T_L_R0.copy(), "scale": t.scale, "references": refs},
                   options=options, tool=tname, noise=noise, track_column=False,
                   moves_track=True)


# -- the procedure ---------------------------------------------------------------------------------
def _repeat(cell: Cell, file: str, name: str | None, options: Mapping[str, Any],
            context: CalibrationContext) -> CellCalibration:
    """The recorded calibration again (:attr:`Procedure.repeat
    <robotcell.cell.calibrate.registry.Procedure>`)."""
    refs = options.get("references_mm")
    return track(cell, file, references=None if refs is None
                 else np.asarray(refs, dtype=float) * 1e-3,
                 axis=options.get("axis"), roll=options.get("roll"), context=context)


def _estimate(cell: Cell, touches: Touches, sigma: float | None) -> CalibrationResult:
    """The estimator on simulated touches (:attr:`Planner.calibrate
    <robotcell.cell.calibrate.registry.Planner>`): the TCP positions in the robot base with the
    true reference points."""
    from robotcell.calibration.track import calibrate_track

    m = touches.measurements(cell.robot)
    p_R = m.tcp(tool_pose(cell, touches.tool))
    t = cell.track
    assert t is not None
    return calibrate_track(m.axes[:, 0], p_R, references=touches.truth["references"],
                           point=m.reference.astype(int) - 1, axis=t.axis,
                           sigma=sigma)


PROCEDURE = Procedure(
    "track", "the robot's linear track (touches of known reference points)", SPECS["track"],
    track, item="track", repeat=_repeat, simulate=simulate,
    planner=Planner(tuple({"travel": t} for t in (0.1, 0.25, 0.5, 1.0, 1.5, 2.0)),
                    pose="T_L_R", truth="T_L_R", calibrate=_estimate))
