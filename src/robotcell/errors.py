"""Exceptions raised by robotcell, and how their messages name what the caller gave.

Every error a user can meet says what is wrong and, where there is one, what to do instead.
A message names the input at fault as the Python call takes it (a parameter such as ``sigma`` or
``references``), through :func:`term`; a front end that takes the same input under other names
(the command line's options) gives its own words for the duration of its run with
:func:`terms`, so that the same message speaks to each caller in its own terms.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from contextvars import ContextVar
from types import MappingProxyType


class RobotcellError(Exception):
    """Base class of every error robotcell raises on purpose."""


class InputError(RobotcellError, ValueError):
    """Input that robotcell refuses: wrong shape or units, NaN, invalid pose, bad model file."""


class IllPosedError(InputError):
    """Measurements that do not determine the quantity asked for (e.g. collinear points)."""


#: The front end's words for what messages name (:func:`terms`); none: the Python API's.
_TERMS: ContextVar[Mapping[str, str]] = ContextVar("robotcell_terms",
                                                   default=MappingProxyType({}))


def term(key: str, python: str) -> str:
    """How a message names an input: in the Python API's terms, unless a front end has its own.

    Parameters
    ----------
    key : str
        What is named, in the library's terms, never a command line: a parameter of the
        library call (``"sigma"``, ``"references"``), possibly with the form of its value
        (``"tool=X,Y,Z,A,B,C"``), or a procedure (``"procedure:turntable"``; ``"procedure"``:
        the one running).
    python : str
        The words for a Python caller at this place of the message, e.g. ``"sigma"`` or
        ``"references (K, 3), m"``.

    Returns
    -------
    str
        ``python``, or the words the front end in force gave for ``key`` (e.g. ``"--sigma"``).
    """
    return _TERMS.get().get(key, python)


@contextmanager
def terms(words: Mapping[str, str]) -> Iterator[None]:
    """Messages made inside name inputs in ``words`` (key -> the front end's words).

    A command line runs its command inside ``terms({"sigma": "--sigma", ...})``: the library's
    errors, notes and advice then name its options instead of the Python parameters.
    """
    token = _TERMS.set(MappingProxyType({**_TERMS.get(), **words}))
    try:
        yield
    finally:
        _TERMS.reset(token)
