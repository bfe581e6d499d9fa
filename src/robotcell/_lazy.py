"""Imports put off until first use: the one mechanism behind every lazy name of robotcell.

``import robotcell`` and ``robotcell --help`` load neither numpy nor scipy: the package's public
names (:mod:`robotcell`, :mod:`robotcell.view`) and the command line's commands
(:data:`robotcell.cli.COMMANDS`) are registered as ``"module:attribute"`` targets and imported
by :func:`load` when first used. A registered target that is not there (a module renamed, an
attribute removed) fails loudly with an :class:`ImportError` naming it, never in silence.

This module imports nothing but :mod:`importlib`, so that every package can use it.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping, MutableMapping
from typing import Any

__all__ = ["load", "module_getattr"]


def load(target: str, what: str = "the object") -> Any:
    """The object at ``target``, imported now.

    Parameters
    ----------
    target : str
        ``"module:attribute"``, e.g. ``"robotcell.cli.fk:fk"``.
    what : str
        What the target is, for the message (``"the command"``).

    Returns
    -------
    object
        The attribute of the module.

    Raises
    ------
    ImportError
        ``target`` is not ``"module:attribute"``, or its module or attribute is missing; the
        message names the target (``"the command registered as 'robotcell.cli.x:y' cannot be
        loaded: ..."``).
    """
    module, sep, attr = target.partition(":")
    if not (module and sep and attr):
        raise ImportError(f"{what} registered as {target!r} cannot be loaded: a target is "
                          "'module:attribute'")
    try:
        return getattr(importlib.import_module(module), attr)
    except (ImportError, AttributeError) as exc:
        raise ImportError(f"{what} registered as {target!r} cannot be loaded: {exc}") from exc


def module_getattr(table: Mapping[str, str], module_name: str,
                   cache: MutableMapping[str, Any] | None = None) -> Callable[[str], Any]:
    """A package's ``__getattr__`` (PEP 562) that imports its lazy names on first access.

    Parameters
    ----------
    table : mapping of str to str
        Public name -> the module that defines it (under the same name).
    module_name : str
        The package (``__name__``), for messages.
    cache : mutable mapping, optional
        The package's ``globals()``: a name imported once is kept there, and later accesses
        do not call ``__getattr__`` again.

    Returns
    -------
    callable
        ``__getattr__(name)``: the name's value; :class:`AttributeError` for a name not in
        ``table``, :class:`ImportError` (naming the target) for a name in ``table`` whose module
        or attribute is missing.
    """
    def __getattr__(name: str) -> Any:
        if name not in table:
            raise AttributeError(f"module {module_name!r} has no attribute {name!r}")
        value = load(f"{table[name]}:{name}", f"the name {name!r} of {module_name}")
        if cache is not None:
            cache[name] = value
        return value

    return __getattr__
