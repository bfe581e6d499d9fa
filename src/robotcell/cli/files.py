"""The files a command reads and writes: an output that is one of its inputs is refused.

Every ``robotcell`` command is a :class:`Command` (in a :class:`Group`). Before its body runs,
and so before anything is written, it compares the files it would write (its parameters of type
:class:`OutputPath`: ``-o``, ``--html``, ``--report``) with the files it reads (every other
``click.Path`` parameter, e.g. the measurements or ``--cell``, and a robot model given by file
name, :data:`NAME_OR_FILE`), and refuses with exit status 2 when one names the same file as
another: ``robotcell export --cell cell.yaml -o cell.yaml`` would replace the cell by the
export. Paths are compared resolved (symbolic links, ``./``, ``..``), and existing files also by
identity (hard links). An output that has several hard links is refused too
(:func:`robotcell.io.fileio.check_links`): replacing it would cut it from its other names.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any

import click

from robotcell.errors import InputError
from robotcell.io.fileio import check_links

__all__ = ["NAME_OR_FILE", "OUTPUT", "Command", "Group", "LiveChoice", "NameOrFile",
           "OutputPath", "refuse_overwriting_inputs"]

#: Key of ``click.Context.meta`` under which :class:`OutputPath` keeps the output files given.
_OUTPUTS = "robotcell.files.outputs"


class OutputPath(click.Path):
    """Type of a parameter naming a file (or folder) the command writes.

    A folder parameter (``file_okay=False``) given an existing file is refused saying that it
    names a folder; any output inside a file (``notes.txt/out.csv``) is refused naming that
    file. The value is kept for :func:`refuse_overwriting_inputs` also when the parameter is not
    passed to the command's function (``expose_value=False``).
    """

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        if not self.file_okay and os.path.isfile(value):
            self.fail(f"{str(value)!r} exists and is a file, but this option names a folder: "
                      "the one the files are written into (created when missing); give a folder",
                      param, ctx)
        above = next((p for p in Path(value).parents if p.exists()), None)
        if above is not None and not above.is_dir():
            self.fail(f"cannot write {str(value)!r}: {str(above)!r} is a file, not a folder",
                      param, ctx)
        value = super().convert(value, param, ctx)
        if ctx is not None and param is not None:
            ctx.meta.setdefault(_OUTPUTS, {})[param.name] = value
        return value


class NameOrFile(click.ParamType):
    """Type of a parameter that is a library name or the path of a file to read (``--robot``)."""

    name = "name_or_file"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        return value


class LiveChoice(click.Choice):
    """A choice among names read when the command line is parsed or its help shown, not when
    the command is defined: the registered controllers (``--format``), so that one registered
    later is a choice too.

    Parameters
    ----------
    names : callable
        Returns the names to choose from.
    """

    def __init__(self, names: Callable[[], Iterable[str]]) -> None:
        self._names = names
        super().__init__(())

    @property
    def choices(self) -> tuple[str, ...]:  # type: ignore[override]
        return tuple(self._names())

    @choices.setter
    def choices(self, value: Iterable[str]) -> None:
        """Set by :class:`click.Choice` to the empty tuple; the names are read when needed."""


#: An output file (``-o FILE``); the callbacks of :mod:`robotcell.cli.common` check its folder.
OUTPUT = OutputPath()
#: A robot model: a library name, or a model file (an input).
NAME_OR_FILE = NameOrFile()


def _label(param: click.Parameter) -> str:
    """The parameter as the help names it: ``-o/--output``, ``--cell``, ``MEASUREMENTS``."""
    if isinstance(param, click.Option):
        return "/".join(param.opts)
    return param.human_readable_name


def _values(value: Any) -> Iterator[str]:
    if value is None:
        return
    if isinstance(value, (tuple, list)):
        for v in value:
            yield from _values(v)
    else:
        yield os.fspath(value)


def _same_file(a: str, b: str) -> bool:
    """Whether paths ``a`` and ``b`` name one file: equal when resolved, or the same inode."""
    if Path(a).resolve() == Path(b).resolve():
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (yet)
        return False


def _inputs(ctx: click.Context) -> Iterator[tuple[click.Parameter, str]]:
    for param in ctx.command.params:
        if isinstance(param.type, OutputPath):
            continue
        if isinstance(param.type, click.Path):
            files = list(_values(ctx.params.get(param.name)))
        elif isinstance(param.type, NameOrFile):
            files = [v for v in _values(ctx.params.get(param.name)) if Path(v).is_file()]
        else:
            continue
        for f in files:
            yield param, f


def refuse_overwriting_inputs(ctx: click.Context, derived: Iterable[tuple[str, str]] = (),
                              read: Iterable[tuple[str, str]] = ()) -> None:
    """Refuse an output of the command that is one of its inputs, or another of its outputs.

    Parameters
    ----------
    ctx : click.Context
        The command's context, its parameters parsed.
    derived : iterable of (str, str)
        Further files the command writes, with what names them (``("reach.html", "-o")`` for
        the page written next to ``-o reach.csv``).
    read : iterable of (str, str)
        Further files the command reads that no parameter names, with what names them
        (``("the touch file of tools.torch", "tcp.csv")``, which a cell file records).

    Raises
    ------
    InputError
        Naming both parameters and the file.
    """
    given = ctx.meta.get(_OUTPUTS, {})
    outputs = [(_label(p), f) for p in ctx.command.params if isinstance(p.type, OutputPath)
               for f in _values(given.get(p.name))]
    outputs += list(derived)
    inputs = [(_label(p), f) for p, f in _inputs(ctx)] + list(read)
    for k, (out_label, out) in enumerate(outputs):
        for in_label, f in inputs:
            if _same_file(out, f):
                raise InputError(f"{out_label} {out} names the same file as {in_label} {f}, "
                                 "which this command reads: writing it would replace that input; "
                                 "write to another file")
        for other_label, other in outputs[:k]:
            if _same_file(out, other):
                raise InputError(f"{out_label} {out} names the same file as {other_label} "
                                 f"{other}: give each output its own file")
    for out_label, out in outputs:
        try:
            check_links(out)
        except InputError as exc:
            raise InputError(f"{out_label} {exc}") from None


class Command(click.Command):
    """A ``robotcell`` command: refuses to write over its inputs before it runs."""

    def invoke(self, ctx: click.Context) -> Any:
        refuse_overwriting_inputs(ctx)
        return super().invoke(ctx)


class Group(click.Group):
    """A ``robotcell`` command group: its subcommands are :class:`Command` s."""

    command_class = Command
    group_class = type
