"""Controller exports: what a user pastes into a KUKA, ABB, FANUC or YASKAWA controller (or any
registered one, :mod:`robotcell.controllers`).

``export_cell(cell, "kuka")`` returns the text (``"urdf"``: the cell as a URDF kinematic tree, for
ROS tools, not a controller format); ``export_files(cell, fmt, path)`` writes it (and, for the
URDF of an identified Universal Robots arm, the UR description's calibration file beside it);
``parse_export(text, "kuka")`` reads it back into
:class:`~robotcell.controllers.data.ControllerData` (poses in metres). Formats, units, reference
frames and sources: ``docs/export.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from robotcell.cell import Cell
from robotcell.controllers.data import ControllerData, Slot
from robotcell.controllers.registry import CONTROLLERS, get
from robotcell.errors import InputError
from robotcell.export import urdf
from robotcell.export.ur import cell_ur_kinematics
from robotcell.io.fileio import atomic_write, check_destination

__all__ = ["EXPORT_FORMATS", "URDF", "ControllerData", "ExportedFiles", "Slot", "export_cell",
           "export_files", "other_kinds", "output_ending", "parse_export", "ur_kinematics_path",
           "write_formats"]

#: format name -> controller (``export``, ``parse_export``): the registered controllers, live
EXPORT_FORMATS = CONTROLLERS

#: The format of the whole cell as a URDF tree: not a controller.
URDF = "urdf"


def write_formats() -> list[str]:
    """Every format :func:`export_cell` writes: the registered controllers and ``urdf``."""
    return [*CONTROLLERS, URDF]


def output_ending(fmt: str) -> str:
    """The file ending an export of ``fmt`` is saved with (``.dat``, ``.mod``, ``.txt``,
    ``.urdf``)."""
    if fmt.lower() == URDF:
        return ".urdf"
    return Path(get(fmt, "export format").export_name).suffix


def other_kinds(fmt: str) -> dict[str, str]:
    """File endings that say another kind of file than the export of ``fmt``: the programs of
    every controller (``.src``: ``a KUKA program``), but the export's own ending (a KUKA export
    is saved as ``.dat``)."""
    own = output_ending(fmt)
    return {s: f"{'an' if c.label[:1] in 'AEIO' else 'a'} {c.label} program"  # a Universal
            for c in CONTROLLERS.values() for s in c.program_suffixes if s != own}


def export_cell(cell: Cell, fmt: str, robot: str | None = None) -> str:
    """Text for ``cell`` in format ``fmt`` (a registered controller, or ``urdf``).

    Parameters
    ----------
    cell : Cell
    fmt : str
        ``urdf`` (every robot of the cell) or a controller's name.
    robot : str, optional
        The robot whose controller export is written, in a cell of several robots (None: the
        only robot). Its export ends with the controller's placement of the cell's robots in
        each other where it holds one (:meth:`~robotcell.controllers.base.Controller.pair_lines`).

    Raises
    ------
    InputError
        An unknown format or robot, a tool or frame number the controller does not have, or a
        cell it cannot hold.
    """
    if fmt.lower() == URDF:
        return urdf.export(cell)
    if fmt.lower() not in CONTROLLERS:
        raise InputError(f"unknown export format {fmt!r}; choose one of: "
                         f"{', '.join(write_formats())}")
    controller = get(fmt)
    text = controller.export(cell.for_robot(robot))
    return text + "".join(f"{line}\n" for line in controller.pair_lines(cell))


def ur_kinematics_path(output: str | Path) -> Path:
    """Where :func:`export_files` writes the UR calibration file beside a URDF ``output``."""
    p = Path(output)
    return p.with_name(f"{p.stem}_kinematics.yaml")


@dataclass(frozen=True)
class ExportedFiles:
    """What :func:`export_files` wrote.

    Attributes
    ----------
    files : list of Path
        The files written.
    warnings : list of str
        What a file could not hold of the cell (a UR calibration file and an identified arm's
        axis scales, :func:`robotcell.export.ur.scale_left_out`); the files hold the rest.
    """

    files: list[Path]
    warnings: list[str] = field(default_factory=list)


def export_files(cell: Cell, fmt: str, output: str | Path,
                 robot: str | None = None) -> ExportedFiles:
    """Write the export of ``cell`` to ``output`` (atomically), and what goes with it.

    The URDF of a cell whose identified arm is a Universal Robots arm comes with the UR
    description's calibration file (:func:`robotcell.export.ur.ur_kinematics`), written to
    :func:`ur_kinematics_path` of ``output``, so that the UR description (and MoveIt) build the
    arm as it is. An arm identified with axis scales, which that file cannot hold, gets the file
    of its geometry without them and a warning that says so.

    Parameters
    ----------
    cell, fmt, robot
        As :func:`export_cell`.
    output : str or Path
        The file to write.

    Returns
    -------
    ExportedFiles
        The files written and the warnings.
    """
    text = export_cell(cell, fmt, robot)
    extra = cell_ur_kinematics(cell) if fmt.lower() == URDF else None
    files = [Path(output)]
    if extra is not None:
        files.append(ur_kinematics_path(output))
        check_destination(files[1])
    atomic_write(files[0], text)
    if extra is not None:
        atomic_write(files[1], extra.text)
    return ExportedFiles(files, [] if extra is None else list(extra.warnings))


def parse_export(text: str, fmt: str) -> ControllerData:
    """Read text written by :func:`export_cell` back into poses (metres)."""
    return get(fmt, "export format").parse_export(text)
