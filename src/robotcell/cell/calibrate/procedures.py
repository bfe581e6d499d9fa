"""Calibrating into a cell: one call per procedure, from a measurement table to an updated Cell.

Each function takes a :class:`~robotcell.cell.Cell` (or None for a plain calibration in the robot
base), the measurements (the CSV's path; a table, column name to values in the units of the
measurement CSV, mm and deg, as :func:`robotcell.io.tables.read_csv` returns it; or touches read
before, :class:`~robotcell.calibration.measurements.Measurements`), read once by the procedure's
specification (:data:`~robotcell.calibration.spec.SPECS`), and the procedure's options in SI
units. It maps the touches into the frames of the cell (through column ``track``
when the robot is on a track), runs the estimator of :mod:`robotcell.calibration` and returns a
:class:`CellCalibration`: the :class:`~robotcell.calibration.result.CalibrationResult`, a new
:class:`~robotcell.cell.Cell` with the calibrated value written in, stamped with its
:class:`~robotcell.cell.Provenance` (the cell given is not changed), and notes: on the
measurements (columns not used, identical rows, touches mapped to the world, where the turntable
comes from), each also passed to ``on_note`` as soon as it arises (so that a caller shows them
even when the measurements are then refused), and on the update (a value kept because the
touches do not measure it); and what it assumed (tool, frame of the result, track and table).
Nothing is written to a file: save the new cell with :meth:`Cell.save`.

The 2-axis positioner is calibrated by :func:`robotcell.identification.calibrate_positioner` on
the kinematic-identification engine; :func:`positioner` runs it on the touches of a cell and
writes the identified chain with :meth:`Cell.update_positioner`.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.grouping import alone_groups
from robotcell.calibration.measurements import Measurements
from robotcell.calibration.result import CalibrationResult, result_json
from robotcell.calibration.spec import SPECS
from robotcell.calibration.uncertainty import OWN, Sources
from robotcell.cell import Cell, Positioner, Provenance, Turntable
from robotcell.cell.calibrate.chain import (
    NOMINAL_ACCURACY,
    Chained,
    NominalAccuracy,
    item_sources,
    plate_inputs,
    touch_inputs,
    written_sources,
)
from robotcell.cell.calibrate.touches import (
    MeasurementInput,
    read_touches,
    robot_in_world,
    tool_transform,
    track_positions,
)
from robotcell.cell.validation import check_axis_limits
from robotcell.errors import IllPosedError, InputError, term
from robotcell.io.fileio import read_json
from robotcell.io.poseformats import pose_to_vendor
from robotcell.kinematics.transforms import invert, transform_points, validate_pose
from robotcell.robot.robot import Robot

__all__ = ["SAME_POSE", "CellCalibration", "TurntablePose", "external_tcp", "frame", "positioner",
           "positioner_touches", "tcp", "track", "turntable", "workpiece"]

#: Largest difference between a given turntable pose and the cell's that counts as the same
#: calibration (m, rad): far above the cell file's rounding, far below any recalibration.
SAME_POSE = 1e-6


@dataclass(frozen=True)
class CellCalibration:
    """Outcome of a calibration into a cell.

    Attributes
    ----------
    result : CalibrationResult
        Estimate, uncertainty and residuals (SI).
    cell : Cell or None
        A new cell with the calibrated value written in; None when nothing was written (no cell,
        or no tool/frame name given).
    item : str
        What was written, e.g. ``"tool 'torch'"``, ``"track 'KL1500' (robot_at_zero, scale)"``;
        empty when nothing was.
    provenance : Provenance or None
        The provenance stamped on the written value.
    notes : tuple of str
        Remarks on the measurements, each starting ``note:`` or ``warning:`` (identical rows,
        touches mapped to the world, ...), as passed to ``on_note``.
    update_notes : tuple of str
        Remarks on what was written (a value kept because the touches do not measure it).
    key : str
        The item of the cell the result is for (``tools.NAME``, ``frames.NAME``, ``track``,
        ``turntable``, ``positioner``), also when nothing was written; empty without a cell.
    value : str
        The key of ``result.values`` (and ``result.estimates``) that holds the item's pose.
    inputs : tuple of str
        The items of the cell the calibration used, in the order of the input parameters of
        ``result.fit`` (see :mod:`robotcell.cell.calibrate.chain`).
    assumed : str
        What the calibration took the touches with, defaults included: the tool that touched,
        the frame of the result, the track and the table, e.g. ``"kr16: tool 'torch' (joint
        values a1..a6); result T_world_B in frame 'world'; track from column 'track' (mm);
        table from column 'e1' (deg)"``.
    """

    result: CalibrationResult
    cell: Cell | None = None
    item: str = ""
    provenance: Provenance | None = None
    notes: tuple[str, ...] = ()
    update_notes: tuple[str, ...] = ()
    key: str = ""
    value: str = ""
    inputs: tuple[str, ...] = ()
    assumed: str = ""


class _Notes(list):
    """Notes of a calibration, each passed on to ``on_note`` as it is added."""

    def __init__(self, on_note: Callable[[str], None] | None):
        super().__init__()
        self.on_note = on_note

    def add(self, notes: list[str]) -> None:
        for note in notes:
            self.one(note)

    def one(self, note: str) -> None:
        self.append(note)
        if self.on_note is not None:
            self.on_note(note)


@dataclass(frozen=True)
class TurntablePose:
    """A calibrated turntable root frame with its uncertainty, for :func:`workpiece`.

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


@dataclass(frozen=True)
class _Record:
    """What a calibration in a cell records with the item it writes (internal)."""

    file: str | None
    options: dict[str, Any]
    chained: Chained
    nominal: NominalAccuracy


def sha256_of(path: str | Path) -> str:
    """SHA-256 of a file's bytes, hex."""
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError as exc:
        raise InputError(f"cannot read {path}: {exc.strerror or exc}") from None


def _provenance(procedure: str, result: CalibrationResult, n: int, source: str,
                time: str | None, cell: Cell, item: str, value: str, record: _Record,
                inputs: tuple[str, ...] | None = None) -> Provenance:
    """Provenance of a calibration read from ``source`` with ``n`` touches, for ``item``.

    It names the calibration as an error source (by the item and the file's checksum), records
    the file, the options and the inputs so that ``calibrate cell`` can repeat it, and the
    error sources of the value (``result.estimates[value]``, the directions it does not
    determine keeping the item's previous ones).
    """
    stamp = time or Provenance.now(procedure).time
    sha = None if record.file is None else sha256_of(record.file)
    ident = f"{item} {sha[:12]}" if sha else f"{item} {stamp}"
    sources: dict[str, NDArray[np.float64]] = {}
    est = result.estimates.get(value)
    if est is not None:
        try:
            old = item_sources(cell, item, record.nominal)[0]
        except InputError:  # a new tool or frame
            size = est.sources.size
            old = Sources(size, {f"{item} nominal": np.diag(record.nominal.sigma(size))})
        sources = written_sources(est, old, ident)
    return Provenance(procedure, time=stamp, rms_mm=result.rms * 1e3,
                      note=f"{n} touches from {Path(source).name}", id=ident,
                      measurements=None if record.file is None else str(Path(record.file).resolve()),
                      sha256=sha, options=dict(record.options),
                      inputs=record.chained.keys if inputs is None else inputs, sources=sources)


def _file(measurements: MeasurementInput, file: str | Path | None) -> str | None:
    """The touch file behind a calibration: ``file``, or ``measurements`` when it is a path."""
    if file is not None:
        return str(file)
    return str(measurements) if isinstance(measurements, (str, Path)) else None


def _tool_option(tool: str | ArrayLike | None) -> dict[str, Any]:
    """The ``tool`` option as recorded: a tool name, or X,Y,Z,A,B,C (mm, deg)."""
    if tool is None:
        return {}
    if isinstance(tool, str):
        return {"tool": tool}
    v = pose_to_vendor(np.asarray(tool, dtype=float), "kuka")
    return {"tool": [round(float(x), 9) + 0.0 for x in v]}


def _options(sigma: float | None, tool: str | ArrayLike | None = None, **more: Any
             ) -> dict[str, Any]:
    """Options of a calibration in the units of the command line (mm, deg)."""
    out = _tool_option(tool)
    if sigma is not None:
        out["sigma_mm"] = float(sigma) * 1e3
    out.update({k: v for k, v in more.items() if v is not None})
    return out


def _chained(cell: Cell | None, m: Measurements, p_R: NDArray[np.float64],
             tool: str | ArrayLike | None, track: NDArray[np.float64] | None,
             nominal: NominalAccuracy, notes: _Notes) -> Chained:
    """The tool and track the touches rest on (nothing without a cell); notes go to ``notes``."""
    if cell is None:
        return Chained()
    chained = touch_inputs(cell, p_R, flange=None if m.joints is None else m.flange(),
                           tool=tool if isinstance(tool, str) else None, track=track,
                           nominal=nominal)
    notes.add(list(chained.notes))
    return chained


def copied(cell: Cell) -> Cell:
    """A cell sharing the components of ``cell`` with its own tool and frame tables."""
    return replace(cell, tools=dict(cell.tools), frames=dict(cell.frames))


def _label(cell: Cell | None, cell_label: str | None) -> str:
    return cell_label or (f"cell {cell.name!r}" if cell is not None else "the cell")


def _refuse_track_column(m: Measurements, why: str) -> None:
    if m.track is not None:
        raise InputError(f"{m.source}: column 'track' (track position of each touch) {why}")


#: Note of a tool calibrated from touches at several track positions.
MAPPED_NOTE = ("note: the flange poses were mapped to the world through column 'track': the "
               "reference point (pivot) is in world coordinates, and ABC World alignments refer "
               "to the world axes")

def _no_cell_track() -> str:
    """Why column ``track`` is refused without a cell."""
    return (f"needs {term('cell=FILE (Cell)', 'a cell (parameter cell)')}, which says where the "
            f"track is; remove the column or pass {term('cell', 'the cell')}")


def _arm(cell: Cell | None, robot: Robot | None) -> Robot | None:
    if cell is not None and robot is not None:
        raise InputError("the robot is the cell's: give a cell or a robot, not both")
    return cell.robot if cell is not None else robot


#: The frames of a result's value ``T_a_b`` by ``a``, as :func:`_assumed` names them.
_FRAMES = {"F": "on the flange", "R": "in the robot base", "world": "in frame 'world'",
           "L": "in the track frame L", "B": "in the turntable frame B",
           "P": "in the positioner's plate P"}


def _tool_text(m: Measurements, tool: str | ArrayLike | None) -> str:
    """Which tool touched, as the touches say it."""
    if m.points is not None:
        return "the controller's tool (TCP positions x, y, z)"
    if m.procedure.pose == "flange":
        given = "flange poses x, y, z, a, b, c" if m.poses is not None else "joint values a1..a6"
        return f"no tool ({given})"
    if tool is None:
        return f"the tool of robot model {m.robot.name!r} (none given; joint values a1..a6)"
    if isinstance(tool, str):
        return f"tool {tool!r} (joint values a1..a6)"
    xyzabc = ",".join(f"{round(float(v), 3) + 0.0:g}"
                      for v in pose_to_vendor(np.asarray(tool, dtype=float), "kuka"))
    return f"tool {xyzabc} (X,Y,Z,A,B,C mm, deg; joint values a1..a6)"


def _assumed(cell: Cell | None, m: Measurements, tool: str | ArrayLike | None, value: str,
             mapped: bool = False) -> str:
    """What a calibration took the touches with: tool, frame of the result, track, table.

    ``value`` is the result's pose ``T_a_b``; ``mapped`` says that the touches were mapped to
    the world through the track (the track's own calibration reads its positions from ``e1``).
    """
    who = cell.name if cell is not None else (m.robot.name if m.robot is not None else "")
    parts = [_tool_text(m, tool), f"result {value} {_FRAMES[value.split('_')[1]]}"]
    if cell is not None and cell.track is not None:
        parts.append("track from column 'e1' (mm)" if m.procedure.name == "track"
                     else "track from column 'track' (mm)" if m.track is not None
                     else "track not used (touches in the robot base)" if not mapped
                     else "track 0 mm (no column 'track')")
    if m.axes is not None and m.procedure.name != "track":
        names = ", ".join(f"'e{i + 1}'" for i in range(m.axes.shape[1]))
        what = "table" if m.axes.shape[1] == 1 else "positioner"
        parts.append(f"{what} from column{'s' * (m.axes.shape[1] > 1)} {names} (deg)")
    return (f"{who}: " if who else "") + "; ".join(parts)


# -- tool ------------------------------------------------------------------------------------------
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
        robot: Robot | None = None, world_mode: Literal["6d", "5d"] = "6d",
        sigma: float | None = None, source: str | None = None, cell_label: str | None = None,
        time: str | None = None, on_note: Callable[[str], None] | None = None,
        file: str | Path | None = None, nominal: NominalAccuracy = NOMINAL_ACCURACY
        ) -> CellCalibration:
    """Tool TCP (XYZ 4-point / N-point) and orientation (ABC 2-point, ABC World) into a cell.

    Parameters
    ----------
    cell : Cell or None
        The cell whose tool ``name`` is calibrated; its robot computes flange poses from joint
        values. None: a plain calibration (flange poses in the robot base).
    measurements : Measurements, mapping, str or Path
        Flange poses ``x,y,z,a,b,c`` (KUKA, mm/deg, no tool active) or joint values ``a1..an``
        (deg); optional column ``point`` (``tcp``, ``-x``, ``xy``, ``world``) and, in a cell with
        a track, ``track`` (mm): the touches are then mapped to the world.
    name : str, optional
        Tool of the cell to write (added when new). Without it nothing is written.
    robot : Robot, optional
        Robot model for joint values when no cell is given.
    world_mode : {"6d", "5d"}
        ABC World alignment of rows with ``point=world``.
    sigma : float, optional
        Touch-up accuracy, 1-sigma per coordinate (m), which the uncertainties rest on; default
        :data:`~robotcell.calibration.fitting.DEFAULT_TOUCH_SIGMA`.
    source : str, optional
        Name of the measurements in messages and the provenance note.
    cell_label : str, optional
        Name of the cell in messages (e.g. its file); default ``cell 'NAME'``.
    time : str, optional
        ISO 8601 time of the provenance; default now.
    on_note : callable, optional
        Receives each note on the measurements as it arises (e.g. to print it on stderr).
    file : str or Path, optional
        The touch file a table was read from; it is recorded in the provenance with its
        checksum (``measurements`` given as a path is recorded without it).
    nominal : NominalAccuracy
        Accuracy of the cell items the touches rest on that have no recorded uncertainty.

    Returns
    -------
    CellCalibration
        A tool with an orientation not measured by the touches keeps its orientation (or the
        flange's, for a new tool), as a note says.
    """
    from robotcell.calibration.tcp import calibrate_tool

    label = _label(cell, cell_label)
    notes = _Notes(on_note)
    m = read_touches("tcp", measurements, source, _arm(cell, robot), notes.one)
    T = m.flange()
    m.check_points()
    m.check_count()
    e = None
    if cell is None:
        _refuse_track_column(m, _no_cell_track())
    else:
        e = track_positions(cell, m, label)
        if e is not None and cell.track is not None:
            T = cell.frame_pose("robot", track=e) @ T
            notes.add([MAPPED_NOTE])
    r = np.array(m.point)
    labels = m.labels(points=True)
    order = [i for k in ("tcp", "-x", "xy") for i in np.flatnonzero(r == k)]
    result = calibrate_tool(T[r == "tcp"], T[r == "-x"], T[r == "xy"], T[r == "world"],
                            world_mode=world_mode, prior_sigma=sigma,
                            labels=[labels[i] for i in order])
    chained = Chained()
    if cell is not None and e is not None and cell.track is not None:
        # The reference point, as each flange pose placed it, moves with the track.
        T_wR = cell.frame_pose("robot", track=e[order])
        c_R = np.einsum("nji,nj->ni", T_wR[:, :3, :3], result.values["pivot"] - T_wR[:, :3, 3])
        chained = touch_inputs(cell, c_R, track=e[order], nominal=nominal)
        notes.add(list(chained.notes))
        result = calibrate_tool(T[r == "tcp"], T[r == "-x"], T[r == "xy"], T[r == "world"],
                                world_mode=world_mode, prior_sigma=sigma,
                                labels=[labels[i] for i in order], inputs=chained.inputs)
    key = f"tools.{name}" if cell is not None and name is not None else ""
    assumed = _assumed(cell, m, None, "T_F_TCP")
    if cell is None or name is None:
        return CellCalibration(result, notes=tuple(notes), key=key, value="T_F_TCP",
                               inputs=chained.keys, assumed=assumed)
    record = _Record(_file(measurements, file), _options(sigma, world=world_mode), chained,
                     nominal)
    prov = _provenance("tcp", result, m.n, m.source, time, cell, key, "T_F_TCP", record)
    new = copied(cell)
    kept = _write_tool(new, name, result, prov, label)
    return CellCalibration(result, new, f"tool {name!r}", prov, tuple(notes), tuple(kept),
                           key, "T_F_TCP", chained.keys, assumed)


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

    notes = _Notes(on_note)
    m = read_touches("external-tcp", measurements, source, _arm(cell, robot), notes.one)
    p = m.tcp(tool_transform(cell, tool, m))
    result = calibrate_external_tcp(p, m.point, sigma, m.labels(points=True))
    return CellCalibration(result, notes=tuple(notes), value="T_R_TCP",
                           assumed=_assumed(cell, m, tool, "T_R_TCP"))


# -- frame -----------------------------------------------------------------------------------------
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
            f"{term('calibrate workpiece', 'robotcell.cell.calibrate.workpiece')}, or pass "
            f"{term('parent=world', 'parent=' + repr('world'))} or "
            f"{term('parent=robot', 'parent=' + repr('robot'))} to replace it by a frame fixed "
            "there")
    return old.parent


def frame(cell: Cell | None, measurements: MeasurementInput, name: str | None = None, *,
          parent: Literal["world", "robot"] | None = None, robot: Robot | None = None,
          tool: str | ArrayLike | None = None, sigma: float | None = None,
          source: str | None = None, cell_label: str | None = None,
          time: str | None = None, on_note: Callable[[str], None] | None = None,
          file: str | Path | None = None, nominal: NominalAccuracy = NOMINAL_ACCURACY
          ) -> CellCalibration:
    """A base / user frame (3-point, or N-point to known coordinates) into a cell.

    Parameters
    ----------
    cell : Cell or None
        The cell whose frame ``name`` is calibrated; None: a plain calibration in the robot base.
    measurements : Measurements, mapping, str or Path
        TCP positions ``x,y,z`` (mm, robot base) or joint values ``a1..an`` (deg); column
        ``point`` (``origin``, ``x``, ``xy``) or ``nominal_x, nominal_y, nominal_z`` (mm); in a
        cell with a track, for a frame in the world, ``track`` (mm).
    name : str, optional
        Frame of the cell to write (added when new). Without it nothing is written.
    parent : {"world", "robot"}, optional
        What carries the frame; default the existing frame's parent, else world. A frame in
        the world is computed from touches mapped to the world.
    robot : Robot, optional
        Robot model for joint values when no cell is given.
    tool : str or array_like of shape (4, 4), optional
        Tool that touched: a tool of the cell by name, or ``T_F_TCP`` (m); default the robot
        model's tool. Its uncertainty (recorded in the cell, else the nominal accuracy) and the
        track's, for touches mapped to the world, are part of the result's.
    sigma, source, cell_label, time, on_note, file, nominal
        As for :func:`tcp`.

    Returns
    -------
    CellCalibration
        ``result.values`` holds ``T_world_NAME`` for a frame in the world, else ``T_R_W``.
    """
    from robotcell.calibration.frame import frame_3point, frame_npoint

    if cell is None and parent is not None:
        raise InputError("the parent of a frame is a cell's notion; give the cell too")
    label = _label(cell, cell_label)
    notes = _Notes(on_note)
    m = read_touches("frame", measurements, source, _arm(cell, robot), notes.one)
    p = m.tcp(tool_transform(cell, tool, m))
    in_world = False
    p_R, e = p, None
    if cell is None:
        _refuse_track_column(m, _no_cell_track())
    else:
        parent = _frame_parent(cell, name, parent, label)  # type: ignore[assignment]
        if parent == "world":
            p = transform_points(robot_in_world(cell, m, label), p)
            e = np.zeros(m.n) if m.track is None else m.track
            in_world = True
        else:
            track_positions(cell, m, label)
    chained = _chained(cell, m, p_R, tool, e, nominal, notes)
    if m.nominal is not None:
        m.check_count()
        result = frame_npoint(p, m.nominal, sigma, m.labels(), inputs=chained.inputs)
    else:
        m.check_points()
        result = frame_3point(p, m.point, sigma, m.labels(points=True), inputs=chained.inputs)
    item = f"frames.{name}" if cell is not None and name is not None else ""
    key = f"T_world_{name}" if in_world else "T_R_W"
    assumed = _assumed(cell, m, tool, f"T_world_{name or 'W'}" if in_world else key,
                       mapped=in_world)
    if cell is None or name is None:
        return CellCalibration(result, notes=tuple(notes), key=item, value="T_R_W",
                               inputs=chained.keys, assumed=assumed)
    if in_world:
        result = result.renamed("T_R_W", key)
    record = _Record(_file(measurements, file), _options(sigma, tool, parent=parent), chained,
                     nominal)
    prov = _provenance("frame", result, m.n, m.source, time, cell, item, key, record)
    new = copied(cell)
    new.update_frame(name, result.values[key], prov, parent=parent)
    return CellCalibration(result, new, f"frame {name!r} (parent {parent})", prov, tuple(notes),
                           key=item, value=key, inputs=chained.keys, assumed=assumed)


# -- track -----------------------------------------------------------------------------------------
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


def _reference_indices(m: Measurements, n_refs: int) -> NDArray[np.int_] | None:
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
          roll: Literal["zero"] | None = None, robot: Robot | None = None,
          tool: str | ArrayLike | None = None, sigma: float | None = None,
          source: str | None = None, cell_label: str | None = None,
          time: str | None = None, on_note: Callable[[str], None] | None = None,
          file: str | Path | None = None, nominal: NominalAccuracy = NOMINAL_ACCURACY,
          group_tol: float | None = None) -> CellCalibration:
    """Linear track (direction, scale, straightness, rotation when determined) into a cell.

    Parameters
    ----------
    cell : Cell or None
        The cell whose track's ``robot_at_zero`` (``T_L_R0``) and scale are calibrated; None: a
        plain calibration.
    measurements : Measurements, mapping, str or Path
        TCP touches ``x,y,z`` (mm) or ``a1..an`` (deg) of fixed reference point(s) at track
        positions ``e1`` (mm); column ``point`` (1, 2, ...) with several references.
    references : array_like, shape (K, 3), optional
        Known coordinates of the touched reference points in the track frame L (m).
    axis : {"x", "z"}, optional
        Axis of L along which the carriage moves; default the cell's, else x.
    roll : {"zero"}, optional
        Without references: fix the rotation about the track axis to zero (a convention).
    robot, tool, sigma, source, cell_label, time, on_note, file, nominal
        As for :func:`frame`.
    group_tol : float, optional
        Track positions within this of each other (m) are one commanded position; default
        derived from the data (:func:`robotcell.calibration.grouping.resolution`).

    Returns
    -------
    CellCalibration
        Into a cell, references or ``roll="zero"`` are required; when the carriage offset is not
        measured (fewer than two references) the cell's offset is kept, and a reference point is
        taken relative to it.
    """
    from robotcell.calibration.track import calibrate_track

    refs = (np.zeros((0, 3)) if references is None
            else np.asarray(references, dtype=float).reshape(-1, 3))
    label = _label(cell, cell_label)
    if cell is not None:
        axis = _cell_track_axis(cell, axis, refs, roll, label)  # type: ignore[assignment]
    notes = _Notes(on_note)
    m = read_touches("track", measurements, source, _arm(cell, robot), notes.one)
    f = m.tcp(tool_transform(cell, tool, m))
    e = m.axes[:, 0]
    if cell is not None:
        check_axis_limits(cell.track, e, ["e1"], m.source, label)
    m.check_count()
    idx = _reference_indices(m, len(refs))
    options = _options(sigma, tool, references_mm=(refs * 1e3).tolist() if len(refs) else None,
                       axis=axis, roll=roll)
    keep_offset = cell is not None and len(refs) < 2
    if keep_offset:
        # The fit takes the unmeasured carriage offset as zero; the cell knows it.
        refs = refs - cell.track.T_L_R0[:3, 3]
    chained = _chained(cell, m, f, tool, None, nominal, notes)
    result = calibrate_track(e, f, references=refs if len(refs) else None, point=idx,
                             axis=axis or "x", roll=roll, labels=m.labels(),
                             prior_sigma=sigma, inputs=chained.inputs, group_tol=group_tol)
    assumed = _assumed(cell, m, tool, "T_L_R")
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
    record = _Record(_file(measurements, file), options, chained, nominal)
    prov = _provenance("track", result, m.n, m.source, time, cell, "track", "T_L_R", record)
    new = copied(cell)
    new.update_track(prov, T_L_R0=T_L_R0, scale=float(result.values["scale"]))
    return CellCalibration(result, new, f"track {tr.name!r} (robot_at_zero, scale)", prov,
                           tuple(notes), tuple(kept), "track", "T_L_R", chained.keys, assumed)


# -- turntable -------------------------------------------------------------------------------------
def _cell_turntable(cell: Cell, label: str) -> Turntable:
    """The cell's turntable, refusing a cell without one."""
    if cell.turntable is None:
        raise InputError(f"{label} has no turntable; add a 'turntable' section to the cell "
                         "file first")
    if not isinstance(cell.turntable, Turntable):
        raise InputError(f"the positioner {cell.turntable.name!r} of {label} is a chain of "
                         f"{cell.turntable.n_axes} axes: the turntable procedure is for a "
                         "one-axis turntable; a positioner chain is calibrated by "
                         "robotcell.cell.calibrate.positioner (robotcell.identification."
                         "calibrate_positioner)")
    return cell.turntable


def _table_touches(cell: Cell | None, m: Measurements, f: NDArray[np.float64],
                   label: str) -> NDArray[np.float64]:
    """Touches in the turntable's parent frame: mapped to the world for a table in the world."""
    if cell is None:
        _refuse_track_column(m, _no_cell_track())
        return f
    if _cell_turntable(cell, label).parent == "world":
        return transform_points(robot_in_world(cell, m, label), f)
    track_positions(cell, m, label)
    return f


def _on_table(cell: Cell | None, m: Measurements, tool: str | ArrayLike | None, label: str,
              nominal: NominalAccuracy, notes: _Notes, check: Callable[[], None]
              ) -> tuple[NDArray[np.float64], NDArray[np.float64], Chained]:
    """Touches of a point on a turntable: its angles (rad), the touches in its parent frame
    (m) and the inputs they rest on; ``check`` refuses what the procedure cannot use once the
    angles are within the table's limits."""
    f_R = m.tcp(tool_transform(cell, tool, m))
    theta = m.axes[:, 0]
    if cell is not None:
        check_axis_limits(cell.turntable, theta, ["e1"], m.source, label)
    check()
    f = _table_touches(cell, m, f_R, label)
    return theta, f, _chained(cell, m, f_R, tool, _world_track(cell, m), nominal, notes)


def _world_track(cell: Cell | None, m: Measurements) -> NDArray[np.float64] | None:
    """Track positions of touches mapped to the world through the track of a turntable cell."""
    if not _in_world(cell):
        return None
    e = track_positions(cell, m)
    return np.zeros(m.n) if e is None else e


def _in_world(cell: Cell | None) -> bool:
    """A cell whose robot is on a track beside a turntable or positioner in the world: its
    touches of the table are mapped to the world through the track."""
    return (cell is not None and cell.track is not None and cell.turntable is not None
            and cell.turntable.parent == "world")


def _positioner_points(cell: Cell, m: Measurements, tool: str | ArrayLike | None, label: str
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The axis values (rad) of touches of a point on a positioner and the point in its parent
    frame (m), checked against the axes' limits (:func:`positioner_touches`)."""
    f = m.tcp(tool_transform(cell, tool, m))
    names = [f"e{i + 1}" for i in range(m.axes.shape[1])]
    check_axis_limits(cell.turntable, m.axes, names, m.source, label)
    if cell.turntable.parent == "world":
        return m.axes, transform_points(robot_in_world(cell, m, label), f)
    track_positions(cell, m, label)
    return m.axes, f


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
    measurements : Measurements, mapping, str or Path
        TCP touches ``x,y,z`` (mm) or ``a1..an`` (deg), the axis values ``e1..en`` (deg, one
        column per positioner axis) and, for a positioner in the world of a cell with a track,
        ``track`` (mm).
    tool, source, cell_label
        As for :func:`frame`.

    Returns
    -------
    values : ndarray, shape (N, n)
        Axis values (rad).
    points : ndarray, shape (N, 3)
        The touched point in the positioner's parent frame (world or robot base; m).
    """
    label = _label(cell, cell_label)
    if cell.turntable is None:
        raise InputError(f"{label} has no positioner; add a 'positioner' section to the cell "
                         "file first")
    spec = SPECS["positioner"].with_axes(cell.turntable.n_axes)
    return _positioner_points(cell, read_touches(spec, measurements, source, cell.robot), tool,
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
               robot: Robot | None = None, tool: str | ArrayLike | None = None,
               sigma: float | None = None, source: str | None = None,
               cell_label: str | None = None, time: str | None = None,
               on_note: Callable[[str], None] | None = None, file: str | Path | None = None,
               nominal: NominalAccuracy = NOMINAL_ACCURACY, group_tol: float | None = None
               ) -> CellCalibration:
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
    measurements : Measurements, mapping, str or Path
        As for :func:`positioner_touches`: one point on the table touched at several (tilt,
        rotate) values ``e1``, ``e2`` (deg).
    robot : Robot, optional
        Robot model for joint values when no cell is given.
    tool, sigma, source, cell_label, time, on_note, file, nominal
        As for :func:`frame`.
    group_tol : float, optional
        Axis values within this of each other (rad) are the same commanded value; default
        derived from the data (:func:`robotcell.calibration.grouping.resolution`).

    Returns
    -------
    CellCalibration
        ``result`` is the positioner calibration's (procedure ``positioner-2axis``, values in
        the positioner's parent frame: ``T_world_B`` instead of ``T_R_B`` for a positioner in
        the world; in the robot base without a cell).
    """
    from robotcell.identification import calibrate_positioner

    label = _label(cell, cell_label)
    notes = _Notes(on_note)
    if cell is None:
        m = read_touches("positioner", measurements, source, robot, notes.one)
        _refuse_track_column(m, _no_cell_track())
        points = m.tcp(tool_transform(None, tool))
        _check_alone(m.axes, m.source, group_tol)
        done = calibrate_positioner(m.axes, points, prior_sigma=sigma, labels=m.labels(),
                                    group_tol=group_tol)
        return CellCalibration(done.result, notes=tuple(notes),
                               assumed=_assumed(None, m, tool, "T_R_B"))
    pos = cell.turntable
    if pos is None or pos.n_axes != 2:
        raise InputError(f"{label} has no positioner of 2 axes (tilt, rotate) to calibrate")
    m = read_touches("positioner", measurements, source, _arm(cell, robot), notes.one)
    values, points = _positioner_points(cell, m, tool, label)
    chained = _chained(cell, m, m.tcp(tool_transform(cell, tool, m)), tool,
                       _world_track(cell, m), nominal, notes)
    done = calibrate_positioner(values, points, nominal=pos.chain, prior_sigma=sigma,
                                labels=m.labels(), inputs=chained.inputs, group_tol=group_tol)
    key = "T_world_B" if pos.parent == "world" else "T_R_B"
    result = done.result.renamed("T_R_B", key)
    record = _Record(_file(measurements, file), _options(sigma, tool), chained, nominal)
    prov = _provenance("positioner", result, m.n, m.source, time, cell, "turntable", "chain",
                       record)
    new = copied(cell)
    new.update_positioner(prov, done.robot.with_tool(np.eye(4)))
    return CellCalibration(result, new, f"positioner {pos.name!r} (axes, root)", prov,
                           tuple(notes), key="positioner", inputs=chained.keys,
                           assumed=_assumed(cell, m, tool, key, mapped=pos.parent == "world"))


def turntable(cell: Cell | None, measurements: MeasurementInput, *, height: float = 0.0,
              robot: Robot | None = None, tool: str | ArrayLike | None = None,
              sigma: float | None = None, source: str | None = None,
              cell_label: str | None = None, time: str | None = None,
              on_note: Callable[[str], None] | None = None, file: str | Path | None = None,
              nominal: NominalAccuracy = NOMINAL_ACCURACY, group_tol: float | None = None
              ) -> CellCalibration:
    """Turntable root frame B and radius, from touches of one point on the table, into a cell.

    Parameters
    ----------
    cell : Cell or None
        The cell whose turntable frame (``T_parent_B``) is calibrated; None: ``T_R_B`` only.
    measurements : Measurements, mapping, str or Path
        TCP touches ``x,y,z`` (mm) or ``a1..an`` (deg) with the table angle ``e1`` (deg); for a
        turntable in the world of a cell with a track, ``track`` (mm).
    height : float
        Shift of the frame origin along the table axis from the plane of the touched point (m).
    robot, tool, sigma, source, cell_label, time, on_note, file, nominal
        As for :func:`frame`.
    group_tol : float, optional
        Table angles within this of each other (rad) are one commanded angle; default derived
        from the data (:func:`robotcell.calibration.grouping.resolution`).

    Returns
    -------
    CellCalibration
        ``result.values`` holds ``T_world_B`` for a turntable in the world, else ``T_R_B``.
    """
    from robotcell.calibration.turntable import calibrate_turntable

    label = _label(cell, cell_label)
    parent = _cell_turntable(cell, label).parent if cell is not None else None
    notes = _Notes(on_note)
    m = read_touches("turntable", measurements, source, _arm(cell, robot), notes.one)
    theta, f, chained = _on_table(cell, m, tool, label, nominal, notes, m.check_count)
    result = calibrate_turntable(theta, f, height=height, labels=m.labels(),
                                 prior_sigma=sigma, inputs=chained.inputs, group_tol=group_tol)
    key = "T_world_B" if parent == "world" else "T_R_B"
    assumed = _assumed(cell, m, tool, key, mapped=parent == "world")
    if cell is None:
        return CellCalibration(result, notes=tuple(notes), assumed=assumed)
    result = result.renamed("T_R_B", key)
    record = _Record(_file(measurements, file), _options(sigma, tool, height_mm=height * 1e3),
                     chained, nominal)
    prov = _provenance("turntable", result, m.n, m.source, time, cell, "turntable", key, record)
    new = copied(cell)
    tt = new.update_turntable(prov, T_parent_B=result.values[key])
    return CellCalibration(result, new, f"turntable {tt.name!r} ({key})", prov, tuple(notes),
                           key="turntable", value=key, inputs=chained.keys, assumed=assumed)


# -- workpiece -------------------------------------------------------------------------------------
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
    tt = _cell_turntable(cell, label)
    if given is None:
        sources, note = item_sources(cell, "turntable", nominal)
        return TurntablePose(tt.T_parent_B, sources, frame=tt.parent, source=label), (
            [note] if note else [])
    if given.frame != tt.parent:
        raise InputError(f"{given.source} holds the turntable in the "
                         f"{'world' if given.frame == 'world' else 'robot base'}, but the "
                         f"turntable of {label} has parent {tt.parent}: calibrate the turntable "
                         f"{term('with cell', 'into')} {label}, or omit "
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
                    "cell (" + term("calibrate turntable --cell",
                                    "robotcell.cell.calibrate.turntable") + ") so that the two agree"]


def _positioner_workpiece(cell: Cell, m: Measurements, name: str | None, *,
                          tool: str | ArrayLike | None, sigma: float | None, label: str,
                          time: str | None, notes: _Notes, file: str | None,
                          nominal: NominalAccuracy) -> CellCalibration:
    """:func:`workpiece` on a positioner chain: the touches taken into its plate frame P, with
    the chain's recorded error sources (:func:`robotcell.cell.calibrate.chain.plate_inputs`)."""
    from robotcell.calibration.frame import frame_3point

    values, points = _positioner_points(cell, m, tool, label)
    m.check_points()
    pos = cell.turntable
    touched = _chained(cell, m, m.tcp(tool_transform(cell, tool, m)), tool,
                       _world_track(cell, m), nominal, notes)
    p_P, chained = plate_inputs(cell, values, points, touched, nominal)
    notes.add([n for n in chained.notes if n not in touched.notes])
    result = frame_3point(p_P, m.point, sigma, m.labels(points=True),
                          inputs=chained.inputs).renamed("T_R_W", "T_P_W")
    item = "" if name is None else f"frames.{name}"
    assumed = _assumed(cell, m, tool, "T_P_W", mapped=pos.parent == "world")
    if name is None:
        return CellCalibration(result, notes=tuple(notes), value="T_P_W", inputs=chained.keys,
                               assumed=assumed)
    record = _Record(file, _options(sigma, tool), chained, nominal)
    prov = _provenance("workpiece", result, m.n, m.source, time, cell, item, "T_P_W", record)
    new = copied(cell)
    new.update_frame(name, result.values["T_P_W"], prov, parent="turntable")
    return CellCalibration(result, new, f"frame {name!r} (parent turntable)", prov, tuple(notes),
                           key=item, value="T_P_W", inputs=chained.keys, assumed=assumed)


def workpiece(cell: Cell | None, measurements: MeasurementInput, name: str | None = None, *,
              turntable: TurntablePose | CalibrationResult | None = None,
              robot: Robot | None = None, tool: str | ArrayLike | None = None,
              sigma: float | None = None, source: str | None = None,
              cell_label: str | None = None, time: str | None = None,
              on_note: Callable[[str], None] | None = None, file: str | Path | None = None,
              nominal: NominalAccuracy = NOMINAL_ACCURACY) -> CellCalibration:
    """Workpiece frame ``T_B_W`` on a calibrated turntable into a cell (parent turntable).

    Parameters
    ----------
    cell : Cell or None
        The cell whose frame ``name`` on the turntable is calibrated; None: needs ``turntable``.
        On a positioner chain the touches, with its axis values ``e1..en`` (deg), are taken
        into its plate frame P through the cell's chain and give ``T_P_W`` (3-point), whose
        uncertainty includes the chain's (its recorded error sources, or the nominal accuracy).
    measurements : Measurements, mapping, str or Path
        TCP touches ``x,y,z`` (mm) or ``a1..an`` (deg) with the table angle ``e1`` (deg) and
        column ``point`` (``origin``, ``x``, ``xy``); for a turntable in the world of a cell with
        a track, ``track`` (mm).
    name : str, optional
        Frame of the cell to write (added when new). Without it nothing is written.
    turntable : TurntablePose or CalibrationResult, optional
        The turntable calibration, whose uncertainty is then propagated; default the cell's
        turntable with its recorded uncertainty (or the nominal accuracy), whose error sources
        it may share with the tool.
    robot, tool, sigma, source, cell_label, time, on_note, file, nominal
        As for :func:`frame`.

    Returns
    -------
    CellCalibration
    """
    from robotcell.calibration.workpiece import calibrate_workpiece

    label = _label(cell, cell_label)
    notes = _Notes(on_note)
    if cell is not None and isinstance(cell.turntable, Positioner):
        if turntable is not None:
            raise InputError(f"{label} has a positioner chain, which carries its own "
                             "calibration: give no turntable result")
        spec = SPECS["workpiece"].with_axes(cell.turntable.n_axes)
        m = read_touches(spec, measurements, source, _arm(cell, robot), notes.one)
        return _positioner_workpiece(cell, m, name, tool=tool, sigma=sigma, label=label,
                                     time=time, notes=notes, file=_file(measurements, file),
                                     nominal=nominal)
    if isinstance(turntable, CalibrationResult):
        turntable = TurntablePose.from_result(turntable)
    model = _arm(cell, robot)
    tt, where = _workpiece_turntable(cell, turntable, label, nominal)
    notes.add(where)
    m = read_touches("workpiece", measurements, source, model, notes.one)
    theta, f, chained = _on_table(cell, m, tool, label, nominal, notes, m.check_points)
    result = calibrate_workpiece(theta, f, m.point, tt.T, T_R_B_covariance=tt.covariance,
                                 inputs=chained.inputs, prior_sigma=sigma,
                                 labels=m.labels(points=True))
    inputs = chained.keys + (("turntable",) if cell is not None and turntable is None else ())
    item = "" if cell is None or name is None else f"frames.{name}"
    assumed = _assumed(cell, m, tool, "T_B_W", mapped=tt.frame == "world")
    if cell is None or name is None:
        return CellCalibration(result, notes=tuple(notes), key=item, value="T_B_W",
                               inputs=inputs, assumed=assumed)
    record = _Record(_file(measurements, file), _options(sigma, tool), chained, nominal)
    prov = _provenance("workpiece", result, m.n, m.source, time, cell, item, "T_B_W", record,
                       inputs)
    new = copied(cell)
    new.update_frame(name, result.values["T_B_W"], prov, parent="turntable")
    return CellCalibration(result, new, f"frame {name!r} (parent turntable)", prov, tuple(notes),
                           key=item, value="T_B_W", inputs=inputs, assumed=assumed)

