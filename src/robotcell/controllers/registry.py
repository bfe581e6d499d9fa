"""The registered controllers, by name and by the file endings of their programs.

KUKA, ABB, FANUC, YASKAWA and Universal Robots are registered here; :func:`register` adds another
(``docs/conventions.md``, "How to add a controller"). :data:`CONTROLLERS` is a live, read-only
view (name -> :class:`~robotcell.controllers.base.Controller`, in the order registered) that the
exports, the programs and the command line's choices read, so a controller registered later is
known to all of them.
"""

from __future__ import annotations

import re
from types import MappingProxyType

from robotcell.controllers.abb import ABB
from robotcell.controllers.base import Controller
from robotcell.controllers.fanuc import FANUC
from robotcell.controllers.kuka import KUKA
from robotcell.controllers.ur import UR
from robotcell.controllers.yaskawa import YASKAWA
from robotcell.errors import InputError

__all__ = ["CONTROLLERS", "by_suffix", "get", "names", "register", "unregister"]

_REGISTERED: dict[str, Controller] = {}

#: Every registered controller by name, in the order registered (a read-only live view).
CONTROLLERS = MappingProxyType(_REGISTERED)

_NAME = re.compile(r"[a-z][a-z0-9_]*\Z")
_SUFFIX = re.compile(r"\.[a-z0-9]+\Z")


def register(controller: Controller) -> Controller:
    """Make ``controller`` known by its name to the exports, the programs and the command line.

    Parameters
    ----------
    controller : Controller
        An instance of a :class:`~robotcell.controllers.base.Controller` subclass.

    Returns
    -------
    Controller
        ``controller``.

    Raises
    ------
    TypeError
        Not a controller.
    ValueError
        A name that is not lower-case letters, digits and ``_`` or that
        another controller has, or a program file ending that another controller reads.
    """
    if not isinstance(controller, Controller):
        raise TypeError(f"{controller!r} is not a robotcell.controllers.base.Controller")
    name = controller.name
    if not _NAME.match(name):
        raise ValueError(f"controller name {name!r}: lower-case letters, digits and '_', "
                         "starting with a letter")
    if name in _REGISTERED:
        raise ValueError(f"a controller named {name!r} is registered already")
    for suffix in controller.program_suffixes:
        other = by_suffix(suffix)
        if not _SUFFIX.match(suffix) or other is not None:
            raise ValueError(f"controller {name!r}: program file ending {suffix!r} "
                             + ("is read by " + other.name if other is not None
                                else "is not '.' and lower-case letters or digits"))
    _REGISTERED[name] = controller
    return controller


def unregister(name: str) -> None:
    """Forget the controller ``name`` (a test that registered one removes it so)."""
    del _REGISTERED[get(name).name]


def get(name: str, what: str = "controller") -> Controller:
    """The controller registered as ``name`` (any case).

    Parameters
    ----------
    name : str
    what : str
        What the name was given as, for the message (``program format``, ``export format``).

    Raises
    ------
    InputError
        No controller has that name; the message names the registered ones.
    """
    try:
        return _REGISTERED[name.lower()]
    except KeyError:
        raise InputError(f"unknown {what} {name!r}; choose one of: "
                         f"{', '.join(_REGISTERED)}") from None


def names() -> tuple[str, ...]:
    """The registered controllers' names, in the order registered."""
    return tuple(_REGISTERED)


def by_suffix(suffix: str) -> Controller | None:
    """The controller whose programs end in ``suffix`` (``.src``; any case), or None."""
    return next((c for c in _REGISTERED.values() if suffix.lower() in c.program_suffixes), None)


for _builtin in (KUKA, ABB, FANUC, YASKAWA, UR):
    register(_builtin)
