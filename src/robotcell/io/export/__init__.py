"""Controller exports: what a user pastes into a KUKA, ABB, FANUC or YASKAWA controller.

``export_cell(cell, "kuka")`` returns the text (``"urdf"``: the cell as a URDF kinematic tree, for
ROS tools, not a controller format); ``parse_export(text, "kuka")`` reads it back into
:class:`~robotcell.io.export.common.ControllerData` (poses in metres). Formats, units, reference
frames and sources: ``docs/export.md``.
"""

from __future__ import annotations

from types import ModuleType

from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.io.export import abb, fanuc, kuka, urdf, yaskawa
from robotcell.io.export.common import ControllerData, Slot

__all__ = ["EXPORT_FORMATS", "WRITE_FORMATS", "ControllerData", "Slot", "export_cell", "parse_export"]

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


def parse_export(text: str, fmt: str) -> ControllerData:
    """Read text written by :func:`export_cell` back into poses (metres)."""
    return _module(fmt).parse(text)
