"""The turntable procedure: the turntable's root frame B and radius, from one point on the table."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.result import CalibrationResult, result_json
from robotcell.calibration.spec import SPECS
from robotcell.calibration.uncertainty import OWN, Sources
from robotcell.cell import Cell
from robotcell.cell.calibrate.common import (
    CellCalibration,
    Notes,
    Record,
    assumption,
    copied,
    measurement_file,
    provenance_of,
    recorded_options,
)
from robotcell.cell.calibrate.context import CalibrationContext
from robotcell.cell.calibrate.ontable import cell_turntable, on_table
from robotcell.cell.calibrate.registry import Planner, Procedure
from robotcell.cell.calibrate.simulation import (
    DOWN,
    Touches,
    candidate_tracks,
    one_axis_table,
    reach,
    table_angles,
    tool_name,
    touched_in_parent,
)
from robotcell.cell.calibrate.touches import MeasurementInput, read_touches
from robotcell.cell.kinematics import frame_pose, tool_pose
from robotcell.errors import InputError
from robotcell.io.fileio import read_json
from robotcell.kinematics.transforms import make_pose, rot_z, transform_points, validate_pose


@dataclass(frozen=True)
class TurntablePose:
    """A calibrated turntable root frame with its uncertainty, for the workpiece procedure
    (:func:`robotcell.cell.calibrate.workpiece`).

    Attributes
    ----------
    T : ndarray, shape (4, 4)
        Pose of the turntable root B (metres) in ``frame``.
    covariance : ndarray, shape (6, 6), or Sources, or None
        Uncertainty of ``T`` (origin in m, rotation vector in rad, about the axes of ``frame``):
        a covariance, or its error sources.
    frame : {"robot", "world"}
        Frame of ``T``: the robot base (``T_R_B``) or the world (``T_world_B``).
    source : str
        Where it comes from, for messages (a file name).
    """

    T: NDArray[np.float64]
    covariance: NDArray[np.float64] | Sources | None = None
    frame: Literal["robot", "world"] = "robot"
    source: str = "the turntable result"

    def __post_init__(self) -> None:
        object.__setattr__(self, "T", validate_pose(self.T, f"{self.source}: turntable pose"))

    @classmethod
    def from_result(cls, result: CalibrationResult, source: str = "the turntable result"
                    ) -> TurntablePose:
        """The turntable pose of a turntable calibration (``T_R_B`` or ``T_world_B``)."""
        if result.procedure != "turntable":
            raise InputError(f"{source}: not a turntable result (procedure {result.procedure!r})")
        key = "T_world_B" if "T_world_B" in result.values else "T_R_B"
        if key not in result.values:
            raise InputError(f"{source}: the turntable result has no pose T_R_B or T_world_B")
        est = result.estimates.get(key)
        cov = (est.sources.renamed(OWN, f"turntable of {source}") if est is not None
               else None if result.covariance is None else np.array(result.covariance[:6, :6]))
        return cls(result.values[key], cov, "world" if key == "T_world_B" else "robot", source)

    @classmethod
    def load(cls, path: str | Path) -> TurntablePose:
        """The turntable pose of a turntable result's JSON file (the output of
        :meth:`CalibrationResult.to_json`, read by :meth:`CalibrationResult.from_json`).

        Raises
        ------
        InputError
            A missing file, not JSON, not a turntable result, or a malformed one.
        """
        data = read_json(path, f"give the {result_json()}")
        result = CalibrationResult.from_json(data, str(path), "turntable",
                                             required=("procedure", "matrix"))
        return cls.from_result(result, str(path))


def turntable(cell: Cell | None, measurements: MeasurementInput, *, height: float = 0.0,
              group_tol: float | None = None, context: CalibrationContext | None = None,
              **keywords: Any) -> CellCalibration:
    """Turntable root frame B and radius, from touches of one point on the table, into a cell.

    Parameters
    ----------
    cell : Cell or None
        The cell whose turntable frame (``T_parent_B``) is calibrated; None: ``T_R_B`` only.
    measurements : TouchTable, mapping, str or Path
        TCP touches ``x,y,z`` (mm) or ``a1..an`` (deg) with the table angle ``e1`` (deg); for a
        turntable in the world of a cell with a track, ``track`` (mm).
    height : float
        Shift of the frame origin along the table axis from the plane of the touched point (m).
    group_tol : float, optional
        Table angles within this of each other (rad) are one commanded angle; default derived
        from the data (:func:`robotcell.calibration.grouping.resolution`).
    context : CalibrationContext, optional
        Who touched and how well, names in messages, where notes go, the touch file to record
        and the nominal accuracy (:class:`~robotcell.cell.calibrate.context.CalibrationContext`).
    **keywords
        Fields of :class:`~robotcell.cell.calibrate.context.CalibrationContext` over
        ``context``, e.g. ``sigma=1e-4, tool="torch"``.

    Returns
    -------
    CellCalibration
        ``result.values`` holds ``T_world_B`` for a turntable in the world, else ``T_R_B``.
    """
    from robotcell.calibration.turntable import calibrate_turntable

    ctx = CalibrationContext.of(context, **keywords)
    tool, sigma = ctx.tool, ctx.sigma
    parent = cell_turntable(cell, ctx.label(cell)).parent if cell is not None else None
    notes = Notes(ctx.on_note)
    m = read_touches("turntable", measurements, ctx.source, ctx.arm(cell), notes.one)
    theta, f, chained = on_table(cell, m, ctx, notes, m.check_count)
    result = calibrate_turntable(theta, f, height=height, labels=m.labels(),
                                 sigma=sigma, inputs=chained.inputs, group_tol=group_tol)
    key = "T_world_B" if parent == "world" else "T_R_B"
    assumed = assumption(cell, m, tool, key, mapped=parent == "world")
    if cell is None:
        return CellCalibration(result, notes=tuple(notes), assumed=assumed)
    result = result.renamed("T_R_B", key)
    record = Record(measurement_file(measurements, ctx.file),
                    recorded_options(sigma, tool, height_mm=height * 1e3), chained, ctx.nominal)
    prov = provenance_of("turntable", result, m.n, m.source, ctx.time, cell, "turntable", key,
                         record)
    new = copied(cell)
    tt = new.update_turntable(prov, T_parent_B=result.values[key])
    return CellCalibration(result, new, f"turntable {tt.name!r} ({key})", prov, tuple(notes),
                           key="turntable", value=key, inputs=chained.keys, assumed=assumed)


# -- simulation ------------------------------------------------------------------------------------
def simulate(cell: Cell, rng: np.random.Generator, noise: float, tool: str | None,
             track: float | None, touches: int = 6, angles: ArrayLike | None = None,
             radius: float = 0.3, height: float = 0.05) -> Touches:
    """The touches of the turntable procedure (:attr:`Procedure.simulate
    <robotcell.cell.calibrate.registry.Procedure>`): a point ``radius`` from the axis and
    ``height`` above B at ``touches`` table angles (default evenly around the turn) or at
    ``angles``."""
    one_axis_table(cell)
    tname = tool_name(cell, tool)
    if not (math.isfinite(radius) and radius > 0):
        raise InputError(f"radius must be positive (m), got {radius}")
    if not math.isfinite(height):
        raise InputError(f"height must be a finite length (m), got {height}")
    least = SPECS["turntable"].minimum
    if angles is None and touches < least:
        raise InputError(f"the turntable calibration needs at least {least} table angles "
                         f"(touches), got {touches}")
    th = table_angles(cell, angles, touches)
    n = len(th)
    if n < least:
        raise InputError(f"the turntable calibration needs at least {least} table angles, "
                         f"got {n}")
    p_B = np.array([radius, 0.0, height])

    def targets(Ek: NDArray[np.float64]) -> NDArray[np.float64]:
        T_wB = frame_pose(cell, "turntable", Ek)                              # (K, n, 4, 4)
        p_w = transform_points(T_wB, rot_z(th) @ p_B)                       # (K, n, 3)
        return make_pose(DOWN[None, None], p_w[:, :, None])

    E = candidate_tracks(cell, track, n)
    labels = [f"touch {i + 1} ({math.degrees(v):.0f} deg)" for i, v in enumerate(th)]
    q, e = reach(cell, targets, E, tool_pose(cell, tname), labels, rng, noise)
    tt = cell.turntable
    return Touches("turntable", q, e if cell.track is not None else None, th, None,
                   truth={"pose": tt.T_parent_B.copy(), "parent": tt.parent, "radius": radius,
                          "height": height},
                   options=[f"--height={-height * 1e3:g}"], tool=tname, noise=noise)


# -- the procedure ---------------------------------------------------------------------------------
def _repeat(cell: Cell, file: str, name: str | None, options: Mapping[str, Any],
            context: CalibrationContext) -> CellCalibration:
    """The recorded calibration again (:attr:`Procedure.repeat
    <robotcell.cell.calibrate.registry.Procedure>`)."""
    return turntable(cell, file, height=options.get("height_mm", 0.0) * 1e-3, context=context)


def _estimate(cell: Cell, touches: Touches, sigma: float | None) -> CalibrationResult:
    """The estimator on simulated touches (:attr:`Planner.calibrate
    <robotcell.cell.calibrate.registry.Planner>`), in the turntable's parent frame."""
    from robotcell.calibration.turntable import calibrate_turntable

    m = touches.measurements(cell.robot)
    return calibrate_turntable(m.axes[:, 0], touched_in_parent(cell, touches, m),
                               height=-touches.truth["height"], sigma=sigma)


def _simulation(design: dict[str, Any]) -> dict[str, Any]:
    """A planning design as keywords of :func:`simulate` (:attr:`Planner.simulation
    <robotcell.cell.calibrate.registry.Planner>`): a span of table angles as the angles."""
    out = dict(design)
    if "span" in out:
        span = out.pop("span")
        n = out.pop("touches", 6)
        full = span >= 2 * math.pi - 1e-9
        out["angles"] = np.linspace(-span / 2, span / 2, n, endpoint=not full)
    return out


PROCEDURE = Procedure(
    "turntable", "the turntable's root frame (one point on the table at several angles)",
    SPECS["turntable"], turntable, item="turntable", repeat=_repeat, simulate=simulate,
    planner=Planner(tuple({"span": math.radians(s), "radius": r} for s in (60, 120, 180, 270, 360)
                          for r in (0.1, 0.2, 0.3, 0.4)),
                    pose="T_R_B", truth="pose", calibrate=_estimate, simulation=_simulation))
