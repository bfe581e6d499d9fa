"""Controller exports: what a user pastes into a KUKA, ABB, FANUC or YASKAWA controller.

``export_cell(cell, "kuka")`` returns the text (``"urdf"``: the cell as a URDF kinematic tree, for
ROS tools, not a controller format); ``export_files(cell, fmt, path)`` writes it (and, for the
URDF of an identified Universal Robots arm, the UR description's calibration file beside it); ``parse_export(text, "kuka")`` reads it back into
:class:`~robotcell.export.common.ControllerData` (poses in metres). Formats, units, reference
frames and sources: ``docs/export.md``.
"""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.export import abb, fanuc, kuka, urdf, yaskawa
from robotcell.export.common import ControllerData, Slot
from robotcell.export.ur import cell_ur_kinematics
from robotcell.io.fileio import atomic_write, check_destination

__all__ = ["EXPORT_FORMATS", "WRITE_FORMATS", "ControllerData", "Slot", "export_cell",
           "export_files", "parse_export", "ur_kinematics_path"]

#: format name -> module with ``export(cell) -> str`` and ``parse(text) -> ControllerData``
EXPORT_FORMATS: dict[str, ModuleType] = {"kuka": kuka, "abb": abb, "fanuc": fanuc,
                                         "yaskawa": yaskawa}

#: every format :func:`export_cell` writes: the controller formats and ``urdf``
WRITE_FORMATS: dict[str, ModuleType] = {**EXPORT_FORMATS, "urdf": urdf}


def _module(fmt: str, formats: dict[str, ModuleType] = EXPORT_FORMATS) -> ModuleType:
    try:
        return formats[fmt.lower()]
    except KeyError:
        raise InputError(f"unknown export format {fmt!r}; choose one of: "
                         f"{', '.join(formats)}") from None


def export_cell(cell: Cell, fmt: str) -> str:
    """Text for ``cell`` in format ``fmt`` (``kuka``, ``abb``, ``fanuc``, ``yaskawa``, ``urdf``)."""
    return _module(fmt, WRITE_FORMATS).export(cell)


def ur_kinematics_path(output: str | Path) -> Path:
    """Where :func:`export_files` writes the UR calibration file beside a URDF ``output``."""
    p = Path(output)
    return p.with_name(f"{p.stem}_kinematics.yaml")


def export_files(cell: Cell, fmt: str, output: str | Path) -> list[Path]:
    """Write the export of ``cell`` to ``output`` (atomically), and what goes with it.

    The URDF of a cell whose identified arm is a Universal Robots arm comes with the UR
    description's calibration file (:func:`robotcell.export.ur.ur_kinematics`), written to
    :func:`ur_kinematics_path` of ``output``, so that the UR description (and MoveIt) build the
    arm as it is.

    Returns
    -------
    list of Path
        The files written.
    """
    text = export_cell(cell, fmt)
    extra = cell_ur_kinematics(cell) if fmt.lower() == "urdf" else None
    files = [Path(output)]
    if extra is not None:
        files.append(ur_kinematics_path(output))
        check_destination(files[1])
    atomic_write(files[0], text)
    if extra is not None:
        atomic_write(files[1], extra)
    return files


def parse_export(text: str, fmt: str) -> ControllerData:
    """Read text written by :func:`export_cell` back into poses (metres)."""
    return _module(fmt).parse(text)
