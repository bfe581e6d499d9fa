"""What every calibration into a cell shares: its outcome, notes, provenance and assumptions.

:class:`CellCalibration` is what each procedure returns; :class:`Notes` passes each note on the
measurements on as it arises; :func:`provenance_of` stamps the written value with its touch file,
options and error sources (:class:`Record`); :func:`assumption` states what the calibration took
the touches with (tool, frame of the result, track and table).
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.measurements import TouchTable
from robotcell.calibration.result import CalibrationResult
from robotcell.calibration.uncertainty import Sources
from robotcell.cell import Cell, Provenance
from robotcell.cell.calibrate.chain import (
    Chained,
    NominalAccuracy,
    item_sources,
    touch_inputs,
    written_sources,
)
from robotcell.cell.calibrate.touches import MeasurementInput
from robotcell.errors import InputError, term
from robotcell.io.poseformats import pose_to_vendor


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


class Notes(list):
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
class Record:
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


def touch_file_problem(item: str, path: str | Path, digest: str | None) -> str | None:
    """Why the touch file ``path`` a calibration of ``item`` recorded cannot be repeated: it is
    missing, or its SHA-256 is no longer ``digest``; None when it can (or no digest was
    recorded)."""
    if not Path(path).is_file():
        return f"{item}: touch file {path} is missing"
    if digest is not None and sha256_of(path) != digest:
        return f"{item}: touch file {path} has changed since the calibration (checksum differs)"
    return None


def provenance_of(procedure: str, result: CalibrationResult, n: int, source: str,
                  time: str | None, cell: Cell, item: str, value: str, record: Record,
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


def measurement_file(measurements: MeasurementInput, file: str | Path | None) -> str | None:
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


def recorded_options(sigma: float | None, tool: str | ArrayLike | None = None, **more: Any
                     ) -> dict[str, Any]:
    """Options of a calibration in the units of the command line (mm, deg)."""
    out = _tool_option(tool)
    if sigma is not None:
        out["sigma_mm"] = float(sigma) * 1e3
    out.update({k: v for k, v in more.items() if v is not None})
    return out


def chained_inputs(cell: Cell | None, m: TouchTable, p_R: NDArray[np.float64],
                   tool: str | ArrayLike | None, track: NDArray[np.float64] | None,
                   nominal: NominalAccuracy, notes: Notes) -> Chained:
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


def refuse_track_column(m: TouchTable, why: str) -> None:
    """Refuse column ``track`` of touches that cannot use it, saying ``why``."""
    if m.track is not None:
        raise InputError(f"{m.source}: column 'track' (track position of each touch) {why}")


def no_cell_track() -> str:
    """Why column ``track`` is refused without a cell."""
    return (f"needs {term('cell=FILE (Cell)', 'a cell (parameter cell)')}, which says where the "
            f"track is; remove the column or pass {term('cell', 'the cell')}")


#: The frames of a result's value ``T_a_b`` by ``a``, as :func:`assumption` names them.
_FRAMES = {"F": "on the flange", "R": "in the robot base", "world": "in frame 'world'",
           "L": "in the track frame L", "B": "in the turntable frame B",
           "P": "in the positioner's plate P"}


def _tool_text(m: TouchTable, tool: str | ArrayLike | None) -> str:
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


def assumption(cell: Cell | None, m: TouchTable, tool: str | ArrayLike | None, value: str,
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
