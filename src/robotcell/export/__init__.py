"""Controller exports: what a user pastes into a KUKA, ABB, FANUC or YASKAWA controller.

``export_cell(cell, "kuka")`` returns the text; ``parse_export(text, "kuka")`` reads it back into
:class:`~robotcell.export.common.ControllerData` (poses in metres). Formats, units, reference
frames and sources: ``docs/export.md``.
"""

from __future__ import annotations

from types import ModuleType

from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.export import abb, fanuc, kuka, yaskawa
from robotcell.export.common import ControllerData, Slot

__all__ = ["EXPORT_FORMATS", "ControllerData", "Slot", "export_cell", "parse_export"]

#: format name -> module with ``export(cell) -> str`` and ``parse(text) -> ControllerData``
EXPORT_FORMATS: dict[str, ModuleType] = {"kuka": kuka, "abb": abb, "fanuc": fanuc,
                                         "yaskawa": yaskawa}


def _module(fmt: str) -> ModuleType:
    try:
        return EXPORT_FORMATS[fmt.lower()]
    except KeyError:
        raise InputError(f"unknown export format {fmt!r}; choose one of: "
                         f"{', '.join(EXPORT_FORMATS)}") from None


def export_cell(cell: Cell, fmt: str) -> str:
    """Controller text for ``cell`` in format ``fmt`` (``kuka``, ``abb``, ``fanuc``, ``yaskawa``)."""
    return _module(fmt).export(cell)


def parse_export(text: str, fmt: str) -> ControllerData:
    """Read text written by :func:`export_cell` back into poses (metres)."""
    return _module(fmt).parse(text)
