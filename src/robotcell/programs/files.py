"""Writing the files of a program: all of them, or none.

A program is several files (KUKA ``.src`` and ``.dat``; several programs with ``split``). Each
file is first written in full to a temporary file beside its destination and fsynced; only when
every one is written are they moved into place with ``os.replace``. A failure before that leaves
no file behind and the destination folder as it was.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from robotcell.errors import InputError

__all__ = ["check_folder", "write_all"]


def check_folder(folder: str | Path) -> Path:
    """The output folder as a Path, refused when it is a file or its parent does not exist.

    Parameters
    ----------
    folder : str or Path
        Where the program files go; created when missing (its parent must exist).

    Raises
    ------
    InputError
        ``folder`` is a file, or its parent folder does not exist.
    """
    p = Path(folder)
    if p.exists() and not p.is_dir():
        raise InputError(f"cannot write into {str(folder)!r}: it is a file; give a folder")
    if not p.exists() and p.parent.is_file():
        raise InputError(f"cannot write into {str(folder)!r}: {str(p.parent)!r} is a file, not "
                         "a folder")
    if not p.exists() and not p.parent.is_dir():
        raise InputError(f"cannot write into {str(folder)!r}: the folder {str(p.parent)!r} does "
                         "not exist; create it first")
    return p


def write_all(folder: str | Path, texts: dict[str, str],
              inputs: tuple[str | Path, ...] = ()) -> list[str]:
    """Write every file of ``texts`` into ``folder``, or none of them.

    Parameters
    ----------
    folder : str or Path
        Created when missing (not its parents).
    texts : dict of str to str
        File name -> text (UTF-8; the programs are ASCII).
    inputs : tuple of str or Path
        Files the run read: an output that would replace one of them is refused.

    Returns
    -------
    list of str
        The paths written.

    Raises
    ------
    InputError
        An output would replace an input, or a file cannot be written (nothing is written then).
    """
    p = check_folder(folder)
    targets = [p / name for name in texts]
    read = {Path(i).resolve() for i in inputs}
    for t in targets:
        if t.resolve() in read:
            raise InputError(f"cannot write {t}: it is an input of this run; choose another "
                             "folder or name")
        if t.is_dir():
            raise InputError(f"cannot write {t}: it is a folder")
    created = not p.exists()
    if created:
        p.mkdir()
    temps: list[tuple[str, Path]] = []
    try:
        for t, text in zip(targets, texts.values()):
            fd, tmp = tempfile.mkstemp(prefix=f".{t.name}.", suffix=".tmp", dir=p)
            temps.append((tmp, t))
            with os.fdopen(fd, "wb") as fh:
                fh.write(text.encode("utf-8"))
                fh.flush()
                os.fsync(fh.fileno())
            os.chmod(tmp, 0o666 & ~_umask())
        for tmp, t in temps:
            os.replace(tmp, t)
    except OSError as exc:
        for tmp, _ in temps:
            Path(tmp).unlink(missing_ok=True)
        if created and not any(p.iterdir()):
            p.rmdir()
        raise InputError(f"cannot write into {p}: {exc.strerror or exc}") from None
    return [str(t) for t in targets]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
