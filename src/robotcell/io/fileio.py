"""Reading text files as people have them, and writing output files atomically.

**Reading.** Every text file robotcell reads (measurement CSV, cell file, robot model file) goes
through :func:`read_text`, with one rule for the encoding:

1. A UTF-8 byte-order mark (what spreadsheet programs write with "CSV UTF-8") is dropped, and the
   text is decoded as UTF-8.
2. Anything else that is not valid UTF-8 is decoded as Windows-1252 (the "ANSI" code page of
   Western-European Windows, a superset of Latin-1's printable characters); the five bytes that
   Windows-1252 leaves undefined are read as Latin-1. A note column with ``Öffnung`` or ``pièce``
   saved by an older spreadsheet is therefore read, not refused; numbers are ASCII in every one
   of these encodings, so they are never changed by the choice.

A file holding NUL characters is not text, and a UTF-16 file (its byte-order mark; what "Unicode
text" saves) is not read: both are refused with :class:`~robotcell.errors.InputError`.

**Writing.** :func:`atomic_write` writes a temporary file in the destination's folder, flushes and
fsyncs it, gives it the permissions of the file it replaces (or the usual ones of a new file,
``0o666`` less the umask), then moves it over the destination with ``os.replace``. A file without
write permission for its owner is refused, not replaced. A run that
fails before the write leaves nothing behind, and one that dies during it leaves the old file or
the new one in full, never a partial or empty file. A missing folder, or a destination that is a
folder, is refused with :class:`~robotcell.errors.InputError` naming it.

**Links.** A destination given through a symbolic link is written where the link points
(:func:`real_destination`): the file the link names is replaced, in its own folder, and the link
stays a link. A destination with more than one hard link is refused, naming why: replacing it
would give this name a new file and leave the other names with the old content, and writing it
in place could leave it half-written.
"""

from __future__ import annotations

import codecs
import json
import os
import shutil
import stat
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any, BinaryIO

from robotcell.errors import InputError

__all__ = ["atomic_copy", "atomic_write", "check_destination", "check_links", "decode_text",
           "read_json", "read_text", "real_destination"]


def _as_latin1(exc: UnicodeError) -> tuple[str, int]:
    """Codec error handler: a byte that Windows-1252 leaves undefined, read as Latin-1."""
    if not isinstance(exc, UnicodeDecodeError):
        raise exc
    return exc.object[exc.start:exc.end].decode("latin-1"), exc.end


_LATIN1_FALLBACK = "robotcell-latin1"
codecs.register_error(_LATIN1_FALLBACK, _as_latin1)


def decode_text(data: bytes, origin: str) -> str:
    """Decode the bytes of a text file by the rule of this module.

    Parameters
    ----------
    data : bytes
        Content of the file.
    origin : str
        Name of the file, for messages.

    Returns
    -------
    str
        The text, without a byte-order mark.

    Raises
    ------
    InputError
        Binary content (NUL characters), or UTF-16 text.
    """
    if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        raise InputError(f"{origin}: not a text file robotcell reads (it starts with a UTF-16 "
                         "mark, as 'Unicode text' is saved); save it as UTF-8 (a spreadsheet's \"CSV UTF-8\", "
                         "an editor's or a controller tool's encoding UTF-8)")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = data.decode("cp1252", errors=_LATIN1_FALLBACK)
    if "\x00" in text:
        raise InputError(f"{origin}: not a text file (it holds NUL characters); give the text "
                         "file (CSV, YAML, URDF, JSON), saved as UTF-8")
    return text


def read_text(path: str | Path, what: str = "file") -> str:
    """Read a text file by the encoding rule of this module.

    Parameters
    ----------
    path : str or Path
        The file.
    what : str
        What the file is, for the message when it does not exist (``"cell file"``).

    Returns
    -------
    str

    Raises
    ------
    InputError
        Missing or unreadable file, or binary content.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{what} {str(path)!r} does not exist"
                         + (" (it is a folder)" if p.is_dir() else ""))
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read {path}: {exc.strerror or exc}") from None
    return decode_text(data, str(path))


def read_json(path: str | Path, advice: str) -> Any:
    """Read a JSON file (:func:`read_text`), refusing a missing file and text that is not JSON.

    Parameters
    ----------
    path : str or Path
        The file.
    advice : str
        What to give instead, for the messages (``"give the output of ..."``).

    Returns
    -------
    Any
        The parsed JSON.

    Raises
    ------
    InputError
        ``"<path>: no such file"`` or ``"<path>: not valid JSON (<why>); <advice>"``.
    """
    if not Path(path).is_file():
        raise InputError(f"{path}: no such file")
    try:
        return json.loads(read_text(path))
    except (json.JSONDecodeError, RecursionError) as exc:
        raise InputError(f"{path}: not valid JSON ({exc}); {advice}") from None


def real_destination(path: str | Path) -> Path:
    """The file that writing ``path`` replaces: ``path`` with its symbolic links followed.

    Parameters
    ----------
    path : str or Path
        A destination as the user gave it; it need not exist.

    Returns
    -------
    Path
        ``path`` itself when it is not a symbolic link, else the file the link leads to (through
        every link, absolute), which may not exist yet.
    """
    p = Path(path)
    return Path(os.path.realpath(p)) if p.is_symlink() else p


def check_links(path: str | Path) -> None:
    """Refuse a destination that has more than one hard link.

    ``os.replace`` would give this name a new file and leave every other name of the file with
    the old content, silently; writing into the file instead would not be atomic.

    Raises
    ------
    InputError
        Naming the number of links and what to do.
    """
    try:
        st = Path(path).stat()
    except OSError:  # no such file (yet)
        return
    links = st.st_nlink
    if stat.S_ISREG(st.st_mode) and links > 1:  # (a folder's links are its subfolders)
        raise InputError(f"cannot write {path}: the file has {links} hard links (other names for "
                         "the same file); replacing it would leave the other names with the old "
                         "content, and writing it in place is not atomic. Replace the hard links "
                         "by symbolic links (ln -s), or write to another file")


def check_destination(path: str | Path, links: bool = True) -> Path:
    """The file a write to ``path`` replaces, its folder existing and it neither a folder nor
    read-only (nor, with ``links``, a file of several hard links).

    A file without write permission for its owner is refused: ``os.replace`` would go over it,
    so the owner's protection is respected instead. A symbolic link is followed
    (:func:`real_destination`): the checks hold for the file it points to.

    Parameters
    ----------
    path : str or Path
        The destination as given.
    links : bool
        Also refuse a file with more than one hard link (:func:`check_links`).

    Returns
    -------
    Path
        :func:`real_destination` of ``path``.

    Raises
    ------
    InputError
        ``path`` is a folder or a read-only file, its folder does not exist, or (``links``) it
        has several hard links.
    """
    p = real_destination(path)
    if str(path) == "" or p.is_dir():
        raise InputError(f"cannot write {str(path)!r}: it is a folder; give a file name")
    folder = p.parent
    if not folder.is_dir():
        shown = f" (the file {path} links to)" if p != Path(path) else ""
        raise InputError(f"cannot write {path}{shown}: the folder {str(folder)!r} does not exist; "
                         "create it first")
    if p.exists() and not p.stat().st_mode & 0o200:
        raise InputError(f"cannot write {path}: the file is read-only (mode "
                         f"{p.stat().st_mode & 0o777:o}); make it writable or write to another "
                         "file")
    if links:
        check_links(p)
    return p


def _new_file_mode() -> int:
    """Permissions of a newly created file: ``0o666`` less the process umask."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def _fsync_dir(directory: Path) -> None:
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:  # platforms without directory handles
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _atomic(dst: Path, write: Callable[[BinaryIO], object], mode: int, what: str) -> None:
    """Write ``dst`` through a temporary file in its folder, then ``os.replace`` it over ``dst``."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{dst.name}.", suffix=".tmp", dir=dst.parent)
    except OSError as exc:
        raise InputError(f"{what}: {exc.strerror or exc}") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, mode)
        os.replace(tmp, dst)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise InputError(f"{what}: {exc.strerror or exc}") from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    _fsync_dir(dst.parent)


def atomic_write(path: str | Path, content: str | bytes) -> None:
    """Write ``content`` to ``path`` atomically, keeping the permissions of the file replaced.

    Parameters
    ----------
    path : str or Path
        Destination file; its folder must exist. Through a symbolic link, the file it points to
        is replaced and the link stays.
    content : str or bytes
        Text (written as UTF-8, newlines as given) or bytes.

    Raises
    ------
    InputError
        The folder does not exist, ``path`` is a folder, a read-only file or a file with several
        hard links, or the file cannot be written (the message names the file and the system's
        reason).
    """
    p = check_destination(path)
    data = content.encode("utf-8") if isinstance(content, str) else content
    mode = (p.stat().st_mode & 0o7777) if p.exists() else _new_file_mode()
    _atomic(p, lambda fh: fh.write(data), mode, f"cannot write {path}")


def atomic_copy(src: str | Path, dst: str | Path) -> None:
    """Copy ``src`` to ``dst`` atomically; ``dst`` gets the permissions of ``src``.

    Raises
    ------
    InputError
        ``src`` cannot be read or ``dst`` cannot be written.
    """
    s, d = Path(src), check_destination(dst)
    what = f"cannot copy {src} to {dst}"
    try:
        mode = s.stat().st_mode & 0o7777
    except OSError as exc:
        raise InputError(f"{what}: {exc.strerror or exc}") from None

    def copy(fh: BinaryIO) -> None:
        with s.open("rb") as inp:
            shutil.copyfileobj(inp, fh)

    _atomic(d, copy, mode, what)
