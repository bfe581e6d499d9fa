"""Program files by their ending: the registered controller that reads each."""

from __future__ import annotations

from pathlib import Path

from robotcell.controllers.model import Program
from robotcell.controllers.registry import CONTROLLERS, by_suffix
from robotcell.errors import InputError

__all__ = ["read_program", "vendor_of"]


def vendor_of(path: str | Path) -> str:
    """The controller of a program file, from its ending.

    Raises
    ------
    InputError
        An ending no registered controller reads.
    """
    ext = Path(path).suffix.lower()
    controller = by_suffix(ext)
    if controller is None:
        endings = sorted(s for c in CONTROLLERS.values() for s in c.program_suffixes)
        files = ", ".join(c.program_files for c in CONTROLLERS.values())
        raise InputError(f"{path}: unknown program file type {ext or '(none)'!r}; robotcell reads "
                         f"{', '.join(endings)} ({files})")
    return controller.name


def read_program(path: str | Path) -> tuple[Program, list[str]]:
    """Read a program file of any registered controller (by its ending).

    Returns
    -------
    program : Program
    skipped : list of str
        Motions the reader does not turn into points (to points outside the program, circular
        motions), with their lines.
    """
    return CONTROLLERS[vendor_of(path)].read_program(path)
