"""The tool procedure: TCP (XYZ 4-point / N-point) and orientation (ABC 2-point, ABC World)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robotcell.calibration.result import CalibrationResult
from robotcell.calibration.spec import SPECS
from robotcell.cell import Cell, Provenance
from robotcell.cell.calibrate.chain import Chained, touch_inputs
from robotcell.cell.calibrate.common import (
    CellCalibration,
    Notes,
    Record,
    assumption,
    copied,
    measurement_file,
    no_cell_track,
    provenance_of,
    recorded_options,
    refuse_track_column,
)
from robotcell.cell.calibrate.context import CalibrationContext
from robotcell.cell.calibrate.registry import Planner, Procedure
from robotcell.cell.calibrate.simulation import Touches, candidate_tracks, reach, tool_name
from robotcell.cell.calibrate.touches import MeasurementInput, read_touches, track_positions
from robotcell.cell.kinematics import robot_pose
from robotcell.errors import InputError, term
from robotcell.io.poseformats import pose_to_vendor
from robotcell.kinematics.transforms import make_pose, rot_z, transform_points

#: Note of a tool calibrated from touches at several track positions.
MAPPED_NOTE = ("note: the flange poses were mapped to the world through column 'track': the "
               "reference point (pivot) is in world coordinates, and ABC World alignments refer "
               "to the world axes")


def _write_tool(cell: Cell, name: str, result: CalibrationResult, prov: Provenance, label: str
                ) -> list[str]:
    """Set tool ``name`` from a TCP result; an unmeasured orientation is kept, and said so."""
    if "T_F_TCP" in result.values:
        cell.set_tool(name, result.values["T_F_TCP"], prov)
        return []
    T = np.eye(4)
    old = cell.tools.get(name)
    advice = "ABC 2-point or ABC World touches measure it"
    if old is not None:
        T[:3, :3] = old.T_F_TCP[:3, :3]
        abc = ", ".join(f"{v:.3f}" for v in pose_to_vendor(old.T_F_TCP, "kuka")[3:] + 0.0)
        note = (f"note: the touches do not measure the tool orientation: kept the orientation "
                f"of tool {name!r} in {label} (A,B,C = {abc} deg); {advice}")
    else:
        note = (f"note: the touches do not measure the tool orientation and {label} has "
                f"no tool {name!r} yet: its orientation is the flange's (A,B,C = 0, 0, 0 deg); "
                f"{advice}")
    T[:3, 3] = result.values["tcp"]
    cell.set_tool(name, T, prov)
    return [note]


def tcp(cell: Cell | None, measurements: MeasurementInput, name: str | None = None, *,
        world_mode: Literal["6d", "5d"] = "6d", context: CalibrationContext | None = None,
        **keywords: Any) -> CellCalibration:
    """Tool TCP (XYZ 4-point / N-point) and orientation (ABC 2-point, ABC World) into a cell.

    Parameters
    ----------
    cell : Cell or None
        The cell whose tool ``name`` is calibrated; its robot computes flange poses from joint
        values. None: a plain calibration (flange poses in the robot base).
    measurements : TouchTable, mapping, str or Path
        Flange poses ``x,y,z,a,b,c`` (KUKA, mm/deg, no tool active) or joint values ``a1..an``
        (deg); optional column ``point`` (``tcp``, ``-x``, ``xy``, ``world``) and, in a cell with
        a track, ``track`` (mm): the touches are then mapped to the world.
    name : str, optional
        Tool of the cell to write (added when new). Without it nothing is written.
    world_mode : {"6d", "5d"}
        ABC World alignment of rows with ``point=world``.
    context : CalibrationContext, optional
        Who touched and how well, names in messages, where notes go, the touch file to record
        and the nominal accuracy (:class:`~robotcell.cell.calibrate.context.CalibrationContext`);
        no ``tool``: the flange poses are taken without one.
    **keywords
        Fields of :class:`~robotcell.cell.calibrate.context.CalibrationContext` over
        ``context``, e.g. ``sigma=1e-4, tool="torch"``.

    Returns
    -------
    CellCalibration
        A tool with an orientation not measured by the touches keeps its orientation (or the
        flange's, for a new tool), as a note says.

    Raises
    ------
    InputError
        Measurements the procedure cannot use, a cell without what they need, or a ``tool``.
    """
    from robotcell.calibration.tcp import calibrate_tool

    ctx = CalibrationContext.of(context, **keywords)
    if ctx.tool is not None:
        raise InputError(f"{term('tool', 'tool')} is not used by the tcp procedure: its "
                         "flange poses are computed without a tool")
    label = ctx.label(cell)
    notes = Notes(ctx.on_note)
    m = read_touches("tcp", measurements, ctx.source, ctx.arm(cell), notes.one)
    T = m.flange()
    m.check_points()
    m.check_count()
    e = None
    if cell is None:
        refuse_track_column(m, no_cell_track())
    else:
        e = track_positions(cell, m, label)
        if e is not None and cell.track is not None:
            T = cell.frame_pose("robot", track=e) @ T
            notes.add([MAPPED_NOTE])
    r = np.array(m.point)
    labels = m.labels(points=True)
    order = [i for k in ("tcp", "-x", "xy") for i in np.flatnonzero(r == k)]
    result = calibrate_tool(T[r == "tcp"], T[r == "-x"], T[r == "xy"], T[r == "world"],
                            world_mode=world_mode, sigma=ctx.sigma,
                            labels=[labels[i] for i in order])
    chained = Chained()
    if cell is not None and e is not None and cell.track is not None:
        # The reference point, as each flange pose placed it, moves with the track.
        T_wR = cell.frame_pose("robot", track=e[order])
        c_R = np.einsum("nji,nj->ni", T_wR[:, :3, :3], result.values["pivot"] - T_wR[:, :3, 3])
        chained = touch_inputs(cell, c_R, track=e[order], nominal=ctx.nominal)
        notes.add(list(chained.notes))
        result = calibrate_tool(T[r == "tcp"], T[r == "-x"], T[r == "xy"], T[r == "world"],
                                world_mode=world_mode, sigma=ctx.sigma,
                                labels=[labels[i] for i in order], inputs=chained.inputs)
    if cell is not None and e is not None and cell.track is not None:
        result.frames["pivot"] = "world"  # the flange poses were mapped through the track
    key = f"tools.{name}" if cell is not None and name is not None else ""
    assumed = assumption(cell, m, None, "T_F_TCP")
    if cell is None or name is None:
        return CellCalibration(result, notes=tuple(notes), key=key, value="T_F_TCP",
                               inputs=chained.keys, assumed=assumed)
    record = Record(measurement_file(measurements, ctx.file),
                    recorded_options(ctx.sigma, world=world_mode), chained, ctx.nominal)
    prov = provenance_of("tcp", result, m.n, m.source, ctx.time, cell, key, "T_F_TCP", record)
    new = copied(cell)
    kept = _write_tool(new, name, result, prov, label)
    return CellCalibration(result, new, f"tool {name!r}", prov, tuple(notes), tuple(kept),
                           key, "T_F_TCP", chained.keys, assumed)


# -- simulation ------------------------------------------------------------------------------------
def simulate(cell: Cell, rng: np.random.Generator, noise: float, tool: str | None,
             track: float | None, touches: int = 4, tilt: float = math.radians(30.0),
             point: ArrayLike = (1.1, 0.0, 0.25), distance: float = 0.1,
             orientation: bool = True) -> Touches:
    """The touches of the tool procedure (:attr:`Procedure.simulate
    <robotcell.cell.calibrate.registry.Procedure>`): the tool's TCP on a reference tip from
    ``touches`` directions tilted by ``tilt``, and with ``orientation`` the ABC 2-point touches
    (the tip on the tool's -X axis and in its XY plane, ``distance`` from the TCP)."""
    name = tool_name(cell, tool)
    T_F_TCP = cell.tools[name].T_F_TCP
    least = SPECS["tcp"].minimum
    if touches < least:
        raise InputError(f"the TCP needs at least {least} touches of the reference point, got "
                         f"{touches}")
    if not 0 < tilt < math.pi / 2:
        raise InputError(f"tilt must be between 0 and 90 deg, got {math.degrees(tilt):g} deg")
    p_R = np.asarray(point, dtype=float)
    az = np.linspace(0.0, 2 * math.pi, touches, endpoint=False)
    axes = np.stack([-np.sin(az), np.cos(az), np.zeros_like(az)], axis=1)
    tilt_R = Rotation.from_rotvec(tilt * axes).as_matrix()                  # (N, 3, 3)
    yaw = rot_z(np.radians(np.arange(0, 360, 30)))
    down = Rotation.from_euler("y", math.pi).as_matrix()
    n_tcp = touches
    roles = ["tcp"] * n_tcp + (["-x", "xy"] if orientation else [])
    n = len(roles)
    E = candidate_tracks(cell, track, n)

    def targets(Ek: NDArray[np.float64]) -> NDArray[np.float64]:
        T_wR = robot_pose(cell, Ek[:, :1])                                   # (K, 1, 4, 4)
        p_w = transform_points(T_wR, p_R)                                    # (K, 1, 3)
        R_w = T_wR[..., None, :3, :3] @ yaw @ down                            # (K, 1, 12, 3, 3)
        R_tcp = np.concatenate([tilt_R[None, :, None] @ R_w, np.broadcast_to(
            R_w, (R_w.shape[0], n - n_tcp) + R_w.shape[2:])], axis=1)        # (K, n, 12, 3, 3)
        pos = np.broadcast_to(p_w[:, :, None], R_tcp.shape[:3] + (3,)).copy()
        if orientation:
            X, Y = R_tcp[:, n_tcp, :, :, 0], R_tcp[:, n_tcp + 1, :, :, 1]
            pos[:, n_tcp] += distance * X                  # the point on the tool's -X axis
            pos[:, n_tcp + 1] -= distance * Y              # the point in the XY plane, +Y
        return make_pose(R_tcp, pos)

    labels = [f"touch {i + 1} ({r})" for i, r in enumerate(roles)]
    q, e = reach(cell, targets, E, T_F_TCP, labels, rng, noise)
    return Touches("tcp", q, e if cell.track is not None else None, None, roles,
                   truth={"T_F_TCP": T_F_TCP.copy(), "tcp": T_F_TCP[:3, 3].copy()},
                   options=[], tool=None, noise=noise, track_column=False)


# -- the procedure ---------------------------------------------------------------------------------
def _repeat(cell: Cell, file: str, name: str | None, options: Mapping[str, Any],
            context: CalibrationContext) -> CellCalibration:
    """The recorded calibration again (:attr:`Procedure.repeat
    <robotcell.cell.calibrate.registry.Procedure>`)."""
    return tcp(cell, file, name, world_mode=options.get("world", "6d"), context=context)


def _estimate(cell: Cell, touches: Touches, sigma: float | None) -> CalibrationResult:
    """The estimator on simulated touches (:attr:`Planner.calibrate
    <robotcell.cell.calibrate.registry.Planner>`): the flange poses in the robot base."""
    from robotcell.calibration.tcp import calibrate_tool

    m = touches.measurements(cell.robot)
    F = m.flange()
    r = np.array(m.point)
    return calibrate_tool(F[r == "tcp"], F[r == "-x"], F[r == "xy"], sigma=sigma)


PROCEDURE = Procedure(
    "tcp", "a tool's TCP (XYZ 4-point) and orientation (ABC 2-point)", SPECS["tcp"], tcp,
    item="tools.NAME", repeat=_repeat, simulate=simulate,
    planner=Planner(tuple({"tilt": math.radians(t)} for t in (10, 20, 30, 40, 50, 60)),
                    pose="T_F_TCP", truth="T_F_TCP", calibrate=_estimate))
