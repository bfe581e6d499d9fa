"""Calibrating into a cell: one call per procedure, from a measurement table to an updated Cell.

Each function takes a :class:`~robotcell.cell.Cell` (or None for a plain calibration in the robot
base), a measurement table (column name to values in the units of the measurement CSV, mm and
deg, as :func:`robotcell.io.tables.read_csv` returns it; or the CSV's path) and the procedure's
options in SI units. It maps the touches into the frames of the cell (through column ``track``
when the robot is on a track), runs the estimator of :mod:`robotcell.calibration` and returns a
:class:`CellCalibration`: the :class:`~robotcell.calibration.result.CalibrationResult`, a new
:class:`~robotcell.cell.Cell` with the calibrated value written in, stamped with its
:class:`~robotcell.cell.Provenance` (the cell given is not changed), and notes: on the
measurements (identical rows, touches mapped to the world, where the turntable comes from), each
also passed to ``on_note`` as soon as it arises (so that a caller shows them even when the
measurements are then refused), and on the update (a value kept because the touches do not
measure it).
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

from robotcell.calibration.measurements import (
    check_count,
    external_axis,
    flange_poses,
    joint_columns,
    nominal_points,
    point_roles,
    tcp_positions,
)
from robotcell.calibration.result import CalibrationResult
from robotcell.calibration.uncertainty import OWN, Sources
from robotcell.cell import Cell, Positioner, Provenance, Turntable
from robotcell.cell.calibrate.chain import (
    NOMINAL_ACCURACY,
    Chained,
    NominalAccuracy,
    item_sources,
    touch_inputs,
    written_sources,
)
from robotcell.cell.calibrate.touches import (
    POSE_COLUMNS,
    Table,
    line_labels,
    load_table,
    repeat_notes,
    robot_in_world,
    tool_transform,
    track_positions,
)
from robotcell.cell.validation import check_axis_limits
from robotcell.errors import IllPosedError, InputError
from robotcell.io.poseformats import pose_to_vendor
from robotcell.io.tables import require_columns
from robotcell.kinematics.transforms import invert, transform_points, validate_pose
from robotcell.robot.robot import Robot

__all__ = ["SAME_POSE", "CellCalibration", "TurntablePose", "frame", "positioner",
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


class _Notes(list):
    """Notes of a calibration, each passed on to ``on_note`` as it is added."""

    def __init__(self, on_note: Callable[[str], None] | None):
        super().__init__()
        self.on_note = on_note

    def add(self, notes: list[str]) -> None:
        for note in notes:
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
        est = result.estimates.get(key)
        cov = (est.sources.renamed(OWN, f"turntable of {source}") if est is not None
               else None if result.covariance is None else np.array(result.covariance[:6, :6]))
        return cls(result.values[key], cov, "world" if key == "T_world_B" else "robot", source)


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


def _file(measurements: Table | str | Path, file: str | Path | None) -> str | None:
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


def _flange(cols: Table, source: str, robot: Robot | None) -> NDArray[np.float64] | None:
    """Flange poses of touches given as joint values (None for x, y, z touches)."""
    if robot is None or "a1" not in cols or "x" in cols:
        return None
    return robot.fk(joint_columns(cols, robot, source), np.eye(4))


def _chained(cell: Cell | None, cols: Table, source: str, p_R: NDArray[np.float64],
             tool: str | ArrayLike | None, track: NDArray[np.float64] | None,
             nominal: NominalAccuracy, notes: _Notes) -> Chained:
    """The tool and track the touches rest on (nothing without a cell); notes go to ``notes``."""
    if cell is None:
        return Chained()
    chained = touch_inputs(cell, p_R, flange=_flange(cols, source, cell.robot),
                           tool=tool if isinstance(tool, str) else None, track=track,
                           nominal=nominal)
    notes.add(list(chained.notes))
    return chained


def copied(cell: Cell) -> Cell:
    """A cell sharing the components of ``cell`` with its own tool and frame tables."""
    return replace(cell, tools=dict(cell.tools), frames=dict(cell.frames))


def _label(cell: Cell | None, cell_label: str | None) -> str:
    return cell_label or (f"cell {cell.name!r}" if cell is not None else "the cell")


def _refuse_track_column(cols: Table, source: str, why: str) -> None:
    if "track" in cols:
        raise InputError(f"{source}: column 'track' (track position of each touch) {why}")


#: Note of a tool calibrated from touches at several track positions.
MAPPED_NOTE = ("note: the flange poses were mapped to the world through column 'track': the "
               "reference point (pivot) is in world coordinates, and ABC World alignments refer "
               "to the world axes")

#: Why column ``track`` is refused without a cell.
_NO_CELL_TRACK = ("needs --cell CELL.yaml (in Python: a Cell), which says where the track is; "
                  "remove the column or pass --cell")


def _arm(cell: Cell | None, robot: Robot | None) -> Robot | None:
    if cell is not None and robot is not None:
        raise InputError("the robot is the cell's: give a cell or a robot, not both")
    return cell.robot if cell is not None else robot


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


def tcp(cell: Cell | None, measurements: Table | str | Path, name: str | None = None, *,
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
    measurements : mapping or str or Path
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

    cols, source = load_table(measurements, source)
    label = _label(cell, cell_label)
    T = flange_poses(cols, source, _arm(cell, robot))
    roles = [str(r).strip().lower() for r in cols["point"]] if "point" in cols else ["tcp"] * len(T)
    bad = sorted(set(roles) - {"tcp", "-x", "xy", "world"})
    if bad:
        raise InputError(f"{source}: column 'point' must hold tcp, -x, xy or world; "
                         f"found {', '.join(bad)}")
    notes = _Notes(on_note)
    notes.add(repeat_notes(cols, POSE_COLUMNS + ["track"], source))
    check_count(roles.count("tcp"), 3, "touches of the reference point (point=tcp)", source)
    e = None
    if cell is None:
        _refuse_track_column(cols, source, _NO_CELL_TRACK)
    else:
        e = track_positions(cell, cols, source, label)
        if e is not None and cell.track is not None:
            T = cell.frame_pose("robot", track=e) @ T
            notes.add([MAPPED_NOTE])
    r = np.array(roles)
    labels = line_labels(len(roles), roles)
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
    if cell is None or name is None:
        return CellCalibration(result, notes=tuple(notes), key=key, value="T_F_TCP",
                               inputs=chained.keys)
    record = _Record(_file(measurements, file), _options(sigma, world=world_mode), chained,
                     nominal)
    prov = _provenance("tcp", result, len(T), source, time, cell, key, "T_F_TCP", record)
    new = copied(cell)
    kept = _write_tool(new, name, result, prov, label)
    return CellCalibration(result, new, f"tool {name!r}", prov, tuple(notes), tuple(kept),
                           key, "T_F_TCP", chained.keys)


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
        raise InputError(f"frame {name!r} of {label} is carried by the turntable: "
                         "calibrate it with 'robotcell calibrate workpiece', or pass --parent "
                         "world or --parent robot to replace it by a frame fixed there")
    return old.parent


def frame(cell: Cell | None, measurements: Table | str | Path, name: str | None = None, *,
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
    measurements : mapping or str or Path
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
    cols, source = load_table(measurements, source)
    label = _label(cell, cell_label)
    p = tcp_positions(cols, source, _arm(cell, robot), tool_transform(cell, tool, cols))
    notes = _Notes(on_note)
    notes.add(repeat_notes(cols, POSE_COLUMNS + ["track", "nominal_x", "nominal_y", "nominal_z"],
                           source))
    in_world = False
    p_R, e = p, None
    if cell is None:
        _refuse_track_column(cols, source, _NO_CELL_TRACK)
    else:
        parent = _frame_parent(cell, name, parent, label)  # type: ignore[assignment]
        if parent == "world":
            p = transform_points(robot_in_world(cell, cols, source, len(p), label), p)
            e = track_positions(cell, cols, source, label)
            e = np.zeros(len(p)) if e is None else e
            in_world = True
        else:
            track_positions(cell, cols, source, label)
    chained = _chained(cell, cols, source, p_R, tool, e, nominal, notes)
    if "nominal_x" in cols:
        check_count(len(p), 3, "points", source)
        result = frame_npoint(p, nominal_points(cols, source), sigma, line_labels(len(p)),
                              inputs=chained.inputs)
    else:
        roles = point_roles(cols, source)
        result = frame_3point(p, roles, sigma, line_labels(len(roles), roles),
                              inputs=chained.inputs)
    item = f"frames.{name}" if cell is not None and name is not None else ""
    if cell is None or name is None:
        return CellCalibration(result, notes=tuple(notes), key=item, value="T_R_W",
                               inputs=chained.keys)
    key = f"T_world_{name}" if in_world else "T_R_W"
    if in_world:
        result = result.renamed("T_R_W", key)
    record = _Record(_file(measurements, file), _options(sigma, tool, parent=parent), chained,
                     nominal)
    prov = _provenance("frame", result, len(p), source, time, cell, item, key, record)
    new = copied(cell)
    new.update_frame(name, result.values[key], prov, parent=parent)
    return CellCalibration(result, new, f"frame {name!r} (parent {parent})", prov, tuple(notes),
                           key=item, value=key, inputs=chained.keys)


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
        raise InputError(f"--axis {axis} differs from the track axis {tr.axis} of {label}; "
                         "drop --axis (it defaults to the cell's) or correct the cell file")
    if not len(references) and roll is None:
        raise InputError("touches of one unknown point do not measure the rotation of the robot "
                         "base about the track axis, so the track's robot_at_zero cannot be "
                         "updated: pass --reference X,Y,Z (a touched point with known "
                         "coordinates in L, mm) or accept the zero-roll convention with --roll "
                         "zero")
    return tr.axis


def _reference_indices(cols: Table, n_refs: int, source: str) -> NDArray[np.int_] | None:
    """0-based reference index per touch from column ``point`` (1-based in the table)."""
    if "point" not in cols:
        if n_refs > 1:
            raise InputError(f"{source}: {n_refs} --reference points given; add a column 'point' "
                             f"saying which one (1..{n_refs}) each touch is")
        return None
    if n_refs == 0:
        raise InputError(f"{source}: column 'point' names reference points, but no --reference "
                         "was given")
    idx = require_columns(cols, ["point"], source)[:, 0]
    if not np.all(idx == np.round(idx)) or idx.min() < 1 or idx.max() > n_refs:
        raise InputError(f"{source}: column 'point' must hold reference numbers 1..{n_refs} "
                         "(in the order of the --reference options)")
    return idx.astype(int) - 1


def track(cell: Cell | None, measurements: Table | str | Path, *,
          references: ArrayLike | None = None, axis: Literal["x", "z"] | None = None,
          roll: Literal["zero"] | None = None, robot: Robot | None = None,
          tool: str | ArrayLike | None = None, sigma: float | None = None,
          source: str | None = None, cell_label: str | None = None,
          time: str | None = None, on_note: Callable[[str], None] | None = None,
          file: str | Path | None = None, nominal: NominalAccuracy = NOMINAL_ACCURACY
          ) -> CellCalibration:
    """Linear track (direction, scale, straightness, rotation when determined) into a cell.

    Parameters
    ----------
    cell : Cell or None
        The cell whose track's ``robot_at_zero`` (``T_L_R0``) and scale are calibrated; None: a
        plain calibration.
    measurements : mapping or str or Path
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
    model = _arm(cell, robot)
    cols, source = load_table(measurements, source)
    _refuse_track_column(cols, source, "is not used by 'calibrate track': its track "
                         "positions are column e1")
    f = tcp_positions(cols, source, model, tool_transform(cell, tool, cols))
    e = external_axis(cols, source, "track")
    if cell is not None:
        check_axis_limits(cell.track, e, ["e1"], source, label)
    check_count(len(f), 3, "touches", source)
    notes = _Notes(on_note)
    notes.add(repeat_notes(cols, POSE_COLUMNS + ["e1", "point"], source))
    idx = _reference_indices(cols, len(refs), source)
    options = _options(sigma, tool, references_mm=(refs * 1e3).tolist() if len(refs) else None,
                       axis=axis, roll=roll)
    keep_offset = cell is not None and len(refs) < 2
    if keep_offset:
        # The fit takes the unmeasured carriage offset as zero; the cell knows it.
        refs = refs - cell.track.T_L_R0[:3, 3]
    chained = _chained(cell, cols, source, f, tool, None, nominal, notes)
    result = calibrate_track(e, f, references=refs if len(refs) else None, point=idx,
                             axis=axis or "x", roll=roll, labels=line_labels(len(f)),
                             prior_sigma=sigma, inputs=chained.inputs)
    if cell is None:
        return CellCalibration(result, notes=tuple(notes))
    tr = cell.track
    T_L_R0 = result.values["T_L_R"].copy()
    kept = []
    if keep_offset:
        T_L_R0[:3, 3] = tr.T_L_R0[:3, 3]
        offset = ", ".join(f"{v:.3f}" for v in tr.T_L_R0[:3, 3] * 1e3 + 0.0)
        kept.append(f"note: the carriage offset is not measured (two or more --reference "
                     f"points measure it): kept the offset of {label} ({offset} mm)")
    record = _Record(_file(measurements, file), options, chained, nominal)
    prov = _provenance("track", result, len(f), source, time, cell, "track", "T_L_R", record)
    new = copied(cell)
    new.update_track(prov, T_L_R0=T_L_R0, scale=float(result.values["scale"]))
    return CellCalibration(result, new, f"track {tr.name!r} (robot_at_zero, scale)", prov,
                           tuple(notes), tuple(kept), "track", "T_L_R", chained.keys)


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


def _table_touches(cell: Cell | None, cols: Table, source: str, f: NDArray[np.float64],
                   label: str) -> NDArray[np.float64]:
    """Touches in the turntable's parent frame: mapped to the world for a table in the world."""
    if cell is None:
        _refuse_track_column(cols, source, _NO_CELL_TRACK)
        return f
    if _cell_turntable(cell, label).parent == "world":
        return transform_points(robot_in_world(cell, cols, source, len(f), label), f)
    track_positions(cell, cols, source, label)
    return f


def _world_track(cell: Cell | None, cols: Table, source: str, n: int
                 ) -> NDArray[np.float64] | None:
    """Track positions of touches mapped to the world through the track of a turntable cell."""
    if cell is None or cell.track is None or cell.turntable is None or (
            cell.turntable.parent != "world"):
        return None
    e = track_positions(cell, cols, source)
    return np.zeros(n) if e is None else e


def positioner_touches(cell: Cell, measurements: Table | str | Path, *,
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
    measurements : mapping or str or Path
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
    cols, source = load_table(measurements, source)
    f = tcp_positions(cols, source, cell.robot, tool_transform(cell, tool, cols))
    names = [f"e{i + 1}" for i in range(cell.turntable.n_axes)]
    values = np.radians(require_columns(cols, names, source))
    check_axis_limits(cell.turntable, values, names, source, label)
    if cell.turntable.parent == "world":
        return values, transform_points(robot_in_world(cell, cols, source, len(f), label), f)
    track_positions(cell, cols, source, label)
    return values, f


def _check_alone(values: NDArray[np.float64], source: str) -> None:
    """Refuse touches in which no 3 rows turn one axis alone over 10 deg (no start without a cell).

    ``values`` (N, 2) are tilt and rotate (rad); the circle point analysis that starts the fit
    without a nominal chain needs such a group per axis.
    """
    for k, name in enumerate(("e1 (tilt)", "e2 (rotate)")):
        other = np.round(values[:, 1 - k], 9)
        if not any(len(np.unique(np.round(values[other == o, k], 9))) >= 3
                   and np.ptp(values[other == o, k]) >= math.radians(10.0) * 0.999
                   for o in np.unique(other)):
            raise IllPosedError(
                f"{source}: no 3 touches turn {name} alone over 10 deg or more; without --cell "
                "(in Python: a Cell) the positioner calibration starts from the circles of such "
                "touches: touch a grid, e.g. 3 tilt by 4 rotate values, or give the cell with the "
                "positioner's nominal chain")


def positioner(cell: Cell | None, measurements: Table | str | Path, *,
               robot: Robot | None = None, tool: str | ArrayLike | None = None,
               sigma: float | None = None, source: str | None = None,
               cell_label: str | None = None, time: str | None = None,
               on_note: Callable[[str], None] | None = None, file: str | Path | None = None,
               nominal: NominalAccuracy = NOMINAL_ACCURACY) -> CellCalibration:
    """A 2-axis (tilt-rotate) positioner's axis chain into a cell, from touches of one point.

    The touches (:func:`positioner_touches`) go to
    :func:`robotcell.identification.calibrate_positioner` with the cell's chain as the nominal
    model; the identified chain (axis lines, common normal, zeros and root; the touched point is
    not part of it) replaces the cell's, keeping the plate frame of its parameterisation, so
    frames carried by the positioner keep their poses on the plate.

    Parameters
    ----------
    cell : Cell or None
        A cell with a positioner of 2 axes. None: a plain calibration in the robot base, started
        from the circle point analysis of the touches (which then need, for each axis, at least
        3 that move that axis alone, e.g. a grid of 3 tilt by 4 rotate values); nothing written.
    measurements : mapping or str or Path
        As for :func:`positioner_touches`: one point on the table touched at several (tilt,
        rotate) values ``e1``, ``e2`` (deg).
    robot : Robot, optional
        Robot model for joint values when no cell is given.
    tool, sigma, source, cell_label, time, on_note, file, nominal
        As for :func:`frame`.

    Returns
    -------
    CellCalibration
        ``result`` is the positioner calibration's (procedure ``positioner-2axis``, values in
        the positioner's parent frame: ``T_world_B`` instead of ``T_R_B`` for a positioner in
        the world; in the robot base without a cell).
    """
    from robotcell.identification import calibrate_positioner

    label = _label(cell, cell_label)
    cols, source = load_table(measurements, source)
    notes = _Notes(on_note)
    if cell is None:
        _refuse_track_column(cols, source, _NO_CELL_TRACK)
        points = tcp_positions(cols, source, robot, tool_transform(None, tool))
        values = np.radians(require_columns(cols, ["e1", "e2"], source))
        notes.add(repeat_notes(cols, POSE_COLUMNS + ["e1", "e2"], source))
        _check_alone(values, source)
        done = calibrate_positioner(values, points, prior_sigma=sigma,
                                    labels=line_labels(len(points)))
        return CellCalibration(done.result, notes=tuple(notes))
    pos = cell.turntable
    if pos is None or pos.n_axes != 2:
        raise InputError(f"{label} has no positioner of 2 axes (tilt, rotate) to calibrate")
    _arm(cell, robot)
    notes.add(repeat_notes(cols, POSE_COLUMNS + ["e1", "e2", "track"], source))
    values, points = positioner_touches(cell, cols, tool=tool, source=source, cell_label=label)
    p_R = tcp_positions(cols, source, cell.robot, tool_transform(cell, tool, cols))
    chained = _chained(cell, cols, source, p_R, tool, _world_track(cell, cols, source, len(p_R)),
                       nominal, notes)
    done = calibrate_positioner(values, points, nominal=pos.chain, prior_sigma=sigma,
                                labels=line_labels(len(points)), inputs=chained.inputs)
    result = done.result.renamed("T_R_B", "T_world_B") if pos.parent == "world" else done.result
    record = _Record(_file(measurements, file), _options(sigma, tool), chained, nominal)
    prov = _provenance("positioner", result, len(points), source, time, cell, "positioner",
                       "", record)
    new = copied(cell)
    new.update_positioner(prov, done.robot.with_tool(np.eye(4)))
    return CellCalibration(result, new, f"positioner {pos.name!r} (axes, root)", prov,
                           tuple(notes), key="positioner", inputs=chained.keys)


def turntable(cell: Cell | None, measurements: Table | str | Path, *, height: float = 0.0,
              robot: Robot | None = None, tool: str | ArrayLike | None = None,
              sigma: float | None = None, source: str | None = None,
              cell_label: str | None = None, time: str | None = None,
              on_note: Callable[[str], None] | None = None, file: str | Path | None = None,
              nominal: NominalAccuracy = NOMINAL_ACCURACY) -> CellCalibration:
    """Turntable root frame B and radius, from touches of one point on the table, into a cell.

    Parameters
    ----------
    cell : Cell or None
        The cell whose turntable frame (``T_parent_B``) is calibrated; None: ``T_R_B`` only.
    measurements : mapping or str or Path
        TCP touches ``x,y,z`` (mm) or ``a1..an`` (deg) with the table angle ``e1`` (deg); for a
        turntable in the world of a cell with a track, ``track`` (mm).
    height : float
        Shift of the frame origin along the table axis from the plane of the touched point (m).
    robot, tool, sigma, source, cell_label, time, on_note, file, nominal
        As for :func:`frame`.

    Returns
    -------
    CellCalibration
        ``result.values`` holds ``T_world_B`` for a turntable in the world, else ``T_R_B``.
    """
    from robotcell.calibration.turntable import calibrate_turntable

    label = _label(cell, cell_label)
    parent = _cell_turntable(cell, label).parent if cell is not None else None
    model = _arm(cell, robot)
    cols, source = load_table(measurements, source)
    f = tcp_positions(cols, source, model, tool_transform(cell, tool, cols))
    theta = external_axis(cols, source, "table")
    if cell is not None:
        check_axis_limits(cell.turntable, theta, ["e1"], source, label)
    check_count(len(f), 3, "touches", source)
    notes = _Notes(on_note)
    notes.add(repeat_notes(cols, POSE_COLUMNS + ["e1", "track"], source))
    f_R = f
    f = _table_touches(cell, cols, source, f, label)
    chained = _chained(cell, cols, source, f_R, tool, _world_track(cell, cols, source, len(f)),
                       nominal, notes)
    result = calibrate_turntable(theta, f, height=height, labels=line_labels(len(f)),
                                 prior_sigma=sigma, inputs=chained.inputs)
    if cell is None:
        return CellCalibration(result, notes=tuple(notes))
    key = "T_R_B"
    if parent == "world":
        key = "T_world_B"
        result = result.renamed("T_R_B", key)
    record = _Record(_file(measurements, file), _options(sigma, tool, height_mm=height * 1e3),
                     chained, nominal)
    prov = _provenance("turntable", result, len(f), source, time, cell, "turntable", key, record)
    new = copied(cell)
    tt = new.update_turntable(prov, T_parent_B=result.values[key])
    return CellCalibration(result, new, f"turntable {tt.name!r} ({key})", prov, tuple(notes),
                           key="turntable", value=key, inputs=chained.keys)


# -- workpiece -------------------------------------------------------------------------------------
def _workpiece_turntable(cell: Cell | None, given: TurntablePose | None, label: str,
                         nominal: NominalAccuracy) -> tuple[TurntablePose, list[str]]:
    """The turntable root in the frame of the touches, and notes on where it comes from."""
    if cell is None:
        if given is None:
            raise InputError("the workpiece needs the turntable: pass --turntable TURNTABLE.json "
                             "(the --json output of 'robotcell calibrate turntable'), or --cell "
                             "CELL.yaml to use the cell's turntable")
        if given.frame != "robot":
            raise InputError(f"{given.source} holds the turntable in the world (T_world_B, "
                             "calibrated with --cell), but touches without --cell are in the "
                             "robot base: pass the same --cell CELL.yaml")
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
                         f"with --cell {label}, or omit --turntable to use the cell's turntable")
    dT = invert(tt.T_parent_B) @ given.T
    dist = float(np.linalg.norm(dT[:3, 3]))
    angle = float(np.arccos(np.clip((np.trace(dT[:3, :3]) - 1.0) / 2.0, -1.0, 1.0)))
    notes = []
    if max(dist, angle) > SAME_POSE:
        notes.append(f"warning: the turntable of {given.source} differs from the one in "
                     f"{label} by {dist * 1e3:.3f} mm and {np.degrees(angle):.4f} deg; "
                     f"T_B_W is relative to {given.source}'s. Write that turntable into the "
                     "cell (calibrate turntable --cell) so that the two agree")
    return given, notes


def _positioner_workpiece(cell: Cell, measurements: Table | str | Path, name: str | None, *,
                          tool: str | ArrayLike | None, sigma: float | None, source: str | None,
                          label: str, time: str | None,
                          on_note: Callable[[str], None] | None, file: str | Path | None,
                          nominal: NominalAccuracy) -> CellCalibration:
    """:func:`workpiece` on a positioner chain: the touches taken into its plate frame P."""
    from robotcell.calibration.frame import frame_3point

    values, points = positioner_touches(cell, measurements, tool=tool, source=source,
                                        cell_label=label)
    record_file = _file(measurements, file)
    cols, source = load_table(measurements, source)
    pos = cell.turntable
    notes = _Notes(on_note)
    notes.add([(f"note: the touches are taken into the plate of positioner {pos.name!r} "
                f"through its chain in {label}: the 1-sigma of T_P_W does not include the "
                "positioner's uncertainty")])
    roles = point_roles(cols, source)
    notes.add(repeat_notes(cols, POSE_COLUMNS + [f"e{i + 1}" for i in range(pos.n_axes)]
                           + ["track"], source))
    T_P_parent = invert(pos.T_parent_root @ pos.T_root_P(values))
    p_P = transform_points(T_P_parent, points)
    p_R = tcp_positions(cols, source, cell.robot, tool_transform(cell, tool, cols))
    chained = _chained(cell, cols, source, p_R, tool,
                       _world_track(cell, cols, source, len(p_R)), nominal, notes)
    if chained.inputs is not None:
        chained = replace(chained, inputs=chained.inputs.rotated(T_P_parent[:, :3, :3]))
    result = frame_3point(p_P, roles, sigma, line_labels(len(roles), roles),
                          inputs=chained.inputs).renamed("T_R_W", "T_P_W")
    item = "" if name is None else f"frames.{name}"
    if name is None:
        return CellCalibration(result, notes=tuple(notes), value="T_P_W", inputs=chained.keys)
    record = _Record(record_file, _options(sigma, tool), chained, nominal)
    prov = _provenance("workpiece", result, len(points), source, time, cell, item, "T_P_W",
                       record)
    new = copied(cell)
    new.update_frame(name, result.values["T_P_W"], prov, parent="turntable")
    return CellCalibration(result, new, f"frame {name!r} (parent turntable)", prov, tuple(notes),
                           key=item, value="T_P_W", inputs=chained.keys)


def workpiece(cell: Cell | None, measurements: Table | str | Path, name: str | None = None, *,
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
        into its plate frame P through the cell's chain and give ``T_P_W`` (3-point).
    measurements : mapping or str or Path
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
    if cell is not None and isinstance(cell.turntable, Positioner):
        if turntable is not None:
            raise InputError(f"{label} has a positioner chain, which carries its own "
                             "calibration: give no turntable result")
        return _positioner_workpiece(cell, measurements, name, tool=tool, sigma=sigma,
                                     source=source, label=label, time=time, on_note=on_note,
                                     file=file, nominal=nominal)
    if isinstance(turntable, CalibrationResult):
        turntable = TurntablePose.from_result(turntable)
    model = _arm(cell, robot)
    tt, where = _workpiece_turntable(cell, turntable, label, nominal)
    notes = _Notes(on_note)
    notes.add(where)
    cols, source = load_table(measurements, source)
    f = tcp_positions(cols, source, model, tool_transform(cell, tool, cols))
    theta = external_axis(cols, source, "workpiece")
    if cell is not None:
        check_axis_limits(cell.turntable, theta, ["e1"], source, label)
    roles = point_roles(cols, source)
    notes.add(repeat_notes(cols, POSE_COLUMNS + ["e1", "track"], source))
    f_R = f
    f = _table_touches(cell, cols, source, f, label)
    chained = _chained(cell, cols, source, f_R, tool, _world_track(cell, cols, source, len(f)),
                       nominal, notes)
    result = calibrate_workpiece(theta, f, roles, tt.T, T_R_B_covariance=tt.covariance,
                                 inputs=chained.inputs, prior_sigma=sigma,
                                 labels=line_labels(len(roles), roles))
    inputs = chained.keys + (("turntable",) if cell is not None and turntable is None else ())
    item = "" if cell is None or name is None else f"frames.{name}"
    if cell is None or name is None:
        return CellCalibration(result, notes=tuple(notes), key=item, value="T_B_W",
                               inputs=inputs)
    record = _Record(_file(measurements, file), _options(sigma, tool), chained, nominal)
    prov = _provenance("workpiece", result, len(f), source, time, cell, item, "T_B_W", record,
                       inputs)
    new = copied(cell)
    new.update_frame(name, result.values["T_B_W"], prov, parent="turntable")
    return CellCalibration(result, new, f"frame {name!r} (parent turntable)", prov, tuple(notes),
                           key=item, value="T_B_W", inputs=inputs)

