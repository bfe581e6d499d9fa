"""The lock of a file that is read, changed and written back: one update at a time.

A file that several processes update (a cell file, which two calibrations may write at once)
is locked from before it is read until after its new version has replaced it, so that no update
works on a version another one is replacing. :func:`file_lock` holds the lock of a file, with
the operating system's lock on a file (``flock`` on Unix, a byte-range lock on Windows) through the
`filelock <https://py-filelock.readthedocs.io>`_ library, on ``<file>.lock`` beside the file it
guards (beside the file a symbolic link points to, so that every link to one file shares its
lock).

- **Bounded wait.** A process that finds the lock held says so once (``on_wait``) and waits
  at most ``wait`` seconds (:data:`LOCK_WAIT` by default), then gives up with
  :class:`~robotcell.errors.InputError`, having changed nothing.
- **A killed holder never blocks.** The operating system releases a process's file locks when
  the process ends, however it ends (``kill -9``, a power cut of a client): the next update
  gets the lock at once. The lock file itself stays, empty; it is not the lock and may be
  deleted when no update runs.
- **Re-entrant.** A process that holds the lock of a file may take it again (a save inside an
  update); it is released when the outermost holder lets go.
- **Shared.** The lock file gets the read and write permissions of the file it guards, so that
  whoever may write a cell file shared by a team (``664``) may also lock it.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from filelock import FileLock, Timeout

from robotcell.errors import InputError
from robotcell.io.fileio import real_destination

__all__ = ["LOCK_WAIT", "file_lock", "lock_path"]

#: Longest wait for the lock of a file held by another process (s): far longer than an update
#: takes (a whole-cell fit takes seconds), short enough that a script is not stuck for long.
LOCK_WAIT = 60.0

#: One lock object per lock file (and permissions) in this process, so that taking a held lock
#: again nests.
_LOCKS: dict[tuple[str, int | None], FileLock] = {}
_GUARD = threading.Lock()


def lock_path(path: str | Path) -> Path:
    """The lock file of ``path``: ``<file>.lock`` beside the file ``path`` is or links to.

    Parameters
    ----------
    path : str or Path
        The guarded file (it need not exist).

    Returns
    -------
    Path
    """
    real = real_destination(path)
    return real.with_name(real.name + ".lock")


def _lock_of(path: Path, mode: int | None) -> FileLock:
    """The lock object of lock file ``path``, created with permissions ``mode`` when new."""
    key = (os.path.realpath(path), mode)  # one object per file, however it is spelt
    with _GUARD:
        if key not in _LOCKS:
            _LOCKS[key] = FileLock(key[0]) if mode is None else FileLock(key[0], mode=mode)
        return _LOCKS[key]


@contextmanager
def file_lock(path: str | Path, wait: float = LOCK_WAIT,
              on_wait: Callable[[str], None] | None = None) -> Iterator[Path]:
    """Hold the lock of file ``path`` for the duration of the ``with`` block.

    Parameters
    ----------
    path : str or Path
        The file to guard; a symbolic link is followed (:func:`lock_path`).
    wait : float
        Longest wait (s) when another process holds the lock; 0: do not wait.
    on_wait : callable, optional
        Receives one message (``waiting for ...``) when the lock is held by another process,
        before the wait.

    Yields
    ------
    Path
        The lock file.

    Raises
    ------
    InputError
        The lock was not free within ``wait`` seconds, or the lock file cannot be created (a
        folder without write permission); nothing was done.
    """
    lock_file = lock_path(path)
    try:  # whoever may write the file may lock it (a team's 664 cell file)
        mode: int | None = real_destination(path).stat().st_mode & 0o666
    except OSError:
        mode = None
    lock = _lock_of(lock_file, mode)
    try:
        try:
            lock.acquire(timeout=0)
        except Timeout:
            if on_wait is not None and wait > 0:
                on_wait(f"waiting for {path}: another process is updating it (lock {lock_file}); "
                        f"waiting at most {wait:g} s")
            lock.acquire(timeout=wait)
    except Timeout:
        raise InputError(f"{path} is being updated by another process, which has held its lock "
                         f"{lock_file} for more than {wait:g} s; nothing was written. Run again "
                         "when that update has finished") from None
    except OSError as exc:
        raise InputError(f"cannot lock {path} for the update: its lock file {lock_file}: "
                         f"{exc.strerror or exc}; remove it, or make its folder writable") from None
    try:
        yield lock_file
    finally:
        lock.release()
