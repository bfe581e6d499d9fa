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
once for a script that knows it will loop. The machine code is cached on disk (numba's cache, in
``__pycache__`` beside the source or in numba's user-wide cache directory), so only the first
process after an install or an edit compiles.

A kernel must not call another function of robotcell: numba's cache notices changes of the
kernel's own source file only.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["NUMBA_OPTIONS", "PYTHON_BUDGET", "Kernel", "compile_all"]

#: Seconds a kernel may spend running as Python, one pose at a time, before it is compiled.
PYTHON_BUDGET = 0.5
#: Options of every compiled function of robotcell: cached machine code; division by zero and
#: the square root of a negative number give inf and NaN as in numpy, without an exception.
NUMBA_OPTIONS: dict[str, Any] = {"cache": True, "error_model": "numpy"}

_KERNELS: list[Kernel] = []


class Kernel:
    """A numba-compatible function, run as Python first and compiled once calls add up.

    Parameters
    ----------
    fn : callable
        Plain Python that numba can compile in nopython mode and that calls no other function of
        robotcell.

    Attributes
    ----------
    call : callable
        What to call: ``fn`` itself (timed) until the kernel is compiled, then numba's compiled
        version of ``fn``.
    """

    def __init__(self, fn: Callable[..., Any]) -> None:
        self.fn = fn
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
            import numba

            self.call = numba.njit(**NUMBA_OPTIONS)(self.fn)
        return self.call


def compile_all() -> None:
    """Compile every kernel now, e.g. before a loop over many single poses.

    Each kernel is compiled for the argument types of its first call (or loaded from numba's
    cache), so the first call after this is still slower by that.
    """
    for k in _KERNELS:
        k.compile()
