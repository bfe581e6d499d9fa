"""The program formats by name and by file extension: one writer and one reader each."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

from robotcell.errors import InputError
from robotcell.programs import abb, fanuc, kuka, yaskawa
from robotcell.programs.model import VENDORS, Program

__all__ = ["EXTENSIONS", "format_module", "read_program", "vendor_of"]

#: File extension (lower case) -> format.
EXTENSIONS = {".src": "kuka", ".dat": "kuka", ".mod": "abb", ".prg": "abb", ".ls": "fanuc",
              ".jbi": "yaskawa"}

_MODULES: dict[str, ModuleType] = {"kuka": kuka, "abb": abb, "fanuc": fanuc,
                                   "yaskawa": yaskawa}


def format_module(vendor: str) -> ModuleType:
    """The module of format ``vendor`` (``write(program, header)``, ``read(path)``)."""
    try:
        return _MODULES[vendor]
    except KeyError:
        raise InputError(f"unknown program format {vendor!r}; choose one of: "
                         f"{', '.join(VENDORS)}") from None


def vendor_of(path: str | Path) -> str:
    """The format of a program file from its extension.

    Raises
    ------
    InputError
        An extension no format uses.
    """
    ext = Path(path).suffix.lower()
    if ext not in EXTENSIONS:
        raise InputError(f"{path}: unknown program file type {ext or '(none)'!r}; robotcell reads "
                         f"{', '.join(sorted(EXTENSIONS))} (KUKA .src with its .dat, ABB .mod, "
                         "FANUC .ls, YASKAWA .jbi)")
    return EXTENSIONS[ext]


def read_program(path: str | Path) -> tuple[Program, list[str]]:
    """Read a program file of any format (by extension).

    Returns
    -------
    program : Program
    skipped : list of str
        Motions the reader does not turn into points (to points outside the program, circular
        motions), with their lines.
    """
    return format_module(vendor_of(path)).read(path)
