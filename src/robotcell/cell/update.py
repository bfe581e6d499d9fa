"""Updating a cell file: read, change, write back, as one step that no other update interleaves.

Two calibrations into one cell file at once (two technicians, a script that calibrates in
parallel) must not lose one result. :func:`update_cell_file` runs a change of the cell (a
calibration) and writes its result so that it always applies to the version it replaces:

1. The cell is read and changed without the lock: a refused change (bad touches, a poor verdict)
   ends here, having written and created nothing.
2. The lock of the file is taken (:func:`robotcell.io.locking.file_lock`: the operating
   system's lock on ``<cell file>.lock``, released when its holder ends however it ends; a
   second update waits at most ``wait`` seconds, saying so, then gives up with nothing written).
3. Under the lock the file is read again. If another update has replaced it meanwhile, the
   change is made again on that version (a calibration is repeated with the other update's
   values, so a frame touched with a tool that was just recalibrated uses the new tool), and
   ``on_note`` says so; if the change cannot be made on it, nothing is written.
4. Still under the lock, the cell is saved (:func:`robotcell.cell.schema.save_cell`): the new
   text read back as a cell, the previous version copied to the next numbered backup, the file
   replaced atomically. Then the lock is released.

So every update's result is in the file in the end, or its caller is told it is not; and the
numbered backups are every version, in the order the updates wrote them. The file is given by a
path that may be a symbolic link (the file it points to is updated, its lock and backups beside
it); a file with several hard links is refused before any work.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Generic, TypeVar

from robotcell.cell.model import Cell, cell_from_dict
from robotcell.cell.schema import cell_to_dict, save_cell
from robotcell.io.fileio import check_destination, read_text
from robotcell.io.locking import LOCK_WAIT, file_lock
from robotcell.io.yamlfile import parse_yaml

__all__ = ["CellFileUpdate", "update_cell_file"]

T = TypeVar("T")


@dataclass(frozen=True)
class CellFileUpdate(Generic[T]):
    """What :func:`update_cell_file` did.

    Attributes
    ----------
    cell : Cell or None
        The cell written; None when the change gave nothing to write.
    value : Any
        What the change returned beside the cell (a calibration's result).
    backup : Path or None
        The numbered backup of the version replaced.
    repeated : bool
        The file was replaced by another update while the change ran, and the change was made
        again on that version.
    """

    cell: Cell | None
    value: T
    backup: Path | None = None
    repeated: bool = False


@dataclass(frozen=True)
class _Version:
    """A cell file as read: its text, its round-trip document, what it says, and its cell."""

    text: str
    document: Any
    said: dict[str, Any]
    cell: Cell

    @classmethod
    def read(cls, path: Path, origin: str) -> _Version:
        text = read_text(path, "cell file")
        document = parse_yaml(text, origin)
        base = path.resolve().parent
        cell = cell_from_dict(document, origin, base)
        return cls(text, document, cell_to_dict(cell, base), cell)


def update_cell_file(path: str | Path, change: Callable[[Cell], tuple[Cell | None, T]], *,
                     wait: float = LOCK_WAIT, on_note: Callable[[str], None] | None = None
                     ) -> CellFileUpdate[T]:
    """Change a cell file: read it, apply ``change``, write the result, one update at a time.

    Parameters
    ----------
    path : str or Path
        An existing cell file (a symbolic link is followed).
    change : callable
        ``change(cell) -> (new_cell, value)``: the cell read from the file (a fresh object it
        may change) to the cell to write (None: write nothing) and any value to return. It may
        run twice, the second time on the version another update wrote meanwhile; it refuses
        by raising, and nothing is written then.
    wait : float
        Longest wait (s) for the lock held by another update.
    on_note : callable, optional
        Receives the notes of the update: that it waits for another one, that it repeated the
        change on another update's version.

    Returns
    -------
    CellFileUpdate

    Raises
    ------
    InputError
        The file cannot be read, is not a cell, cannot be written (read-only, several hard
        links), its lock was not free within ``wait``, or the new cell would not load; nothing
        is written. Whatever ``change`` raises, with nothing written.
    """
    real = check_destination(path)
    origin = str(path)
    version = _Version.read(real, origin)
    new, value = change(version.cell)
    if new is None:
        return CellFileUpdate(None, value)
    with file_lock(real, wait, on_note):
        repeated = read_text(real, "cell file") != version.text
        if repeated:
            if on_note is not None:
                on_note(f"note: {path} was updated by another process while this ran; this "
                        "update is made again on the version it wrote")
            version = _Version.read(real, origin)
            new, value = change(version.cell)
            if new is None:
                return CellFileUpdate(None, value, repeated=True)
        backup = save_cell(new, real, cell_from_dict, (version.document, version.said))
    return CellFileUpdate(new, value, backup, repeated)
