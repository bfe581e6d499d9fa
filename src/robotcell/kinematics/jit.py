"""Kernels written once in plain Python, run by numpy on batches and compiled for single poses.

A kinematic formula of robotcell is written once, as Python that runs on floats and on numpy
arrays alike (each array a batch of the same quantity). A batch runs it as it is: each line is a
numpy operation over every pose. One pose at a time, the cost of those numpy calls would dwarf the
arithmetic, so :class:`Kernel` runs the same source compiled by numba (nopython mode, numpy's
floating-point error model, no fast-math: the compiled and the Python kernel give the same bits).

Loading numba and the cached machine code takes about 0.5-0.7 s, a hundred thousand single-pose
calls of the Python kernel. So a :class:`Kernel` runs as Python until it has spent
:data:`PYTHON_BUDGET` seconds or numba is loaded anyway (the inverse kinematics is compiled code);
a command that computes a few poses never loads numba, a loop over many poses pays the load once
(at most about twice its Python time overall), and :func:`compile_all` compiles every kernel at
once for a script that knows it will loop. Every compiled function of robotcell is made by
:func:`compiled`: its machine code is cached on disk where numba can write (the folder
``NUMBA_CACHE_DIR`` names, ``__pycache__`` beside the source, or numba's user-wide cache
directory), so only the first process after an install or an edit compiles. Where none of them
is writable (a read-only install run by a user without a writable home), it is compiled in
memory, in each process, without a message.

A kernel calls no function of robotcell but its helpers, defined in its own source file (numba's
cache notices changes of the kernel's own source file only) and given to :class:`Kernel`: plain
Python for the batch, compiled with the kernel for one pose.
"""

from __future__ import annotations

import inspect
import os
import sys
import tempfile
import time
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["PYTHON_BUDGET", "Kernel", "compile_all", "compiled"]

#: Seconds a kernel may spend running as Python, one pose at a time, before it is compiled.
PYTHON_BUDGET = 0.5

_KERNELS: list[Kernel] = []
#: Per source folder: whether numba can cache the machine code of the functions it holds.
_CACHE_WRITABLE: dict[str, bool] = {}
#: Kernel helpers compiled functions may call (:func:`_jitable`).
_JITABLE: set[Callable[..., Any]] = set()


def compiled(fn: Callable[..., Any] | None = None, *, inline: bool = False) -> Any:
    """``fn`` compiled by numba: the one place that sets the options of robotcell's machine code.

    Used as ``@compiled``, or ``@compiled(inline=True)`` for a helper split out of a hot kernel.

    Parameters
    ----------
    fn : callable
        Plain Python that numba can compile in nopython mode.
    inline : bool
        Inline ``fn`` into the compiled functions that call it (numba's ``inline="always"``), so
        that splitting a kernel costs no call.

    Returns
    -------
    callable
        numba's dispatcher of ``fn`` (nopython mode, no fast-math), compiled on its first call
        for the argument types of that call. Division by zero and the square root of a negative
        number give inf and NaN as in numpy, without an exception. The machine code is cached
        on disk where numba can write a cache for ``fn``'s source file, else compiled in memory
        for this process (:func:`_cache_writable`).
    """
    if fn is None:
        return lambda f: compiled(f, inline=inline)
    import numba

    return numba.njit(cache=_cache_writable(fn), error_model="numpy",
                      inline="always" if inline else "never")(fn)


def _cache_writable(fn: Callable[..., Any]) -> bool:
    """Whether numba's cache can write the machine code of ``fn``: decided once per folder.

    numba looks for a cache folder when a function is compiled with ``cache=True`` and raises
    ``RuntimeError`` if it finds none. It tries, in order, the folder ``NUMBA_CACHE_DIR`` names,
    ``__pycache__`` beside the source file and numba's user-wide cache directory
    (``$XDG_CACHE_HOME/numba`` or ``~/.cache/numba`` on Linux; each under a name made from the
    source file's folder), and keeps the first it can create and write a file in. numba's own
    :class:`numba.core.caching.FunctionCache` makes that choice here, so that every rule of
    numba (its locators, ``NUMBA_CACHE_LOCATOR_CLASSES``) is followed; then a file is written in
    the folder it chose (a zip archive's locator does not check that). Every locator depends on
    the source file's folder only, so the answer holds for every function of that folder.
    """
    folder = os.path.dirname(os.path.abspath(inspect.getfile(fn)))
    if folder not in _CACHE_WRITABLE:
        from numba.core.caching import FunctionCache

        try:
            path = FunctionCache(fn).cache_path
            os.makedirs(path, exist_ok=True)
            tempfile.TemporaryFile(dir=path).close()
            _CACHE_WRITABLE[folder] = True
        except (RuntimeError, OSError):
            _CACHE_WRITABLE[folder] = False
    return _CACHE_WRITABLE[folder]


class Kernel:
    """A numba-compatible function, run as Python first and compiled once calls add up.

    Parameters
    ----------
    fn : callable
        Plain Python that numba can compile in nopython mode and that calls no function of
        robotcell but ``helpers``.
    helpers : tuple of callable, optional
        Functions of ``fn``'s source file that ``fn`` calls, written like it: Python calls them
        as they are; the compiled ``fn`` has them compiled into it (inlined; numba's
        ``register_jitable``).

    Attributes
    ----------
    call : callable
        What to call: ``fn`` itself (timed) until the kernel is compiled, then numba's compiled
        version of ``fn``.
    """

    def __init__(self, fn: Callable[..., Any], helpers: tuple[Callable[..., Any], ...] = ()
                 ) -> None:
        self.fn = fn
        self.helpers = helpers
        self.spent = 0.0
        self.call: Callable[..., Any] = self._python
        _KERNELS.append(self)

    def _python(self, *args: Any) -> Any:
        if "numba" in sys.modules:
            return self.compile()(*args)
        t = time.perf_counter()
        with np.errstate(all="ignore"):  # as compiled: NaN and inf without a warning
            out = self.fn(*args)
        self.spent += time.perf_counter() - t
        if self.spent > PYTHON_BUDGET:
            self.compile()
        return out

    def compile(self) -> Callable[..., Any]:
        """Compile ``fn`` (or load it from the cache) and call the compiled version from now on."""
        if self.call == self._python:
            for helper in self.helpers:
                _jitable(helper)
            self.call = compiled(self.fn)
        return self.call


def _jitable(fn: Callable[..., Any]) -> None:
    """Let compiled functions call the plain Python ``fn``: compiled into them (inlined, with the
    options of :func:`compiled`); ``fn`` itself stays Python. Once per function."""
    if fn not in _JITABLE:
        from numba.extending import register_jitable

        register_jitable(error_model="numpy", inline="always")(fn)
        _JITABLE.add(fn)


def compile_all() -> None:
    """Compile every kernel now, e.g. before a loop over many single poses.

    Each kernel is compiled for the argument types of its first call (or loaded from numba's
    cache), so the first call after this is still slower by that.
    """
    for k in _KERNELS:
        k.compile()
