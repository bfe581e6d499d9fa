"""Helpers shared by the CLI commands: number lists; CSV files and tables (from ``robotcell.io.tables``);
output files (written atomically, from ``robotcell.io.fileio``).

Every file the CLI reads or writes is CSV with a header, lengths in millimetres and angles in
degrees.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path

import click

from robotcell.errors import InputError, RobotcellError
from robotcell.io import tables
from robotcell.io.fileio import atomic_write, check_destination
from robotcell.io.tables import (
    format_table,
    require_columns,
    write_csv,
)

__all__ = [
    "GROUP_TOLERANCE_DEG",
    "MAX_CORRECTION_MM",
    "NOISE_MAX_MM",
    "NOISE_MIN_MM",
    "BadPoints",
    "as_flags",
    "check_kind",
    "check_noise",
    "check_not_folder",
    "check_output",
    "format_table",
    "group_tolerance_option",
    "in_range",
    "output_of",
    "parse_numbers",
    "read_csv",
    "require_columns",
    "write_csv",
    "write_output",
]


#: Largest touch-up error (``--noise`` of simulate, plan and demo; mm): 1 m is none.
NOISE_MAX_MM = 1000.0
#: Smallest touch-up error of plan and demo (``--noise``, mm; simulate takes 0): 1 um, below any
#: touch-up accuracy (the fits weigh by ``1 / noise**2``, which 1e-300 mm makes infinite).
NOISE_MIN_MM = 1e-3

#: Range of ``--max-correction`` (``compensate``, ``program compensate``; mm): a real arm is 0.1
#: to a few mm off its drawing.
MAX_CORRECTION_MM = (0.001, 100.0)


class BadPoints(click.ClickException):
    """Points that cannot be computed, one program, or filtered; a program with bad points:
    exit status 3."""

    exit_code = 3

    def show(self, file: object = None) -> None:
        click.echo(f"error: {self.message}", err=True)


@contextmanager
def as_flags(flags: Mapping[str, str]) -> Iterator[None]:
    """Re-raise the library's errors with the command line's option names for its parameters.

    Library messages name Python parameters (``max_correction``); a command maps those it passes
    from an option to the option (``{"max_correction": "--max-correction"}``).
    """
    try:
        yield
    except RobotcellError as exc:
        text = str(exc)
        for param, flag in flags.items():
            text = re.sub(rf"(?<![\w-]){re.escape(param)}\b", flag, text)
        if text == str(exc):
            raise
        exc.args = (text,)
        raise


def in_range(lo: float, hi: float, unit: str) -> Callable[[click.Context, click.Parameter, float],
                                                         float]:
    """Callback of a number option: refuse a value outside ``lo .. hi`` (``unit``)."""
    def callback(ctx: click.Context, param: click.Parameter, value: float) -> float:
        if value is not None and not lo <= value <= hi:
            raise InputError(f"{param.opts[0]} must be from {lo:g} to {hi:g} {unit}, got "
                             f"{value:g}")
        return value
    return callback


#: Range of ``--group-tolerance`` (deg; mm for prismatic joints and track positions): read-back
#: jitter is 0.01-0.1 deg, and a few degrees would merge values commanded apart.
GROUP_TOLERANCE_DEG = (1e-6, 5.0)


def group_tolerance_option(values: str, unit: str = "deg") -> Callable[[Callable], Callable]:
    """Option ``--group-tolerance`` (None when not given) of the commands that group rows.

    Parameters
    ----------
    values : str
        What the tolerance applies to, for the help text (``Joint values``).
    unit : {"deg", "mm"}
        Unit of the values: ``deg`` (a prismatic joint taking mm), or ``mm`` (track positions).
    """
    also = " (mm for a prismatic joint)" if unit == "deg" else ""
    return click.option(
        "--group-tolerance", "group_tolerance", type=float, default=None, metavar=unit.upper(),
        callback=in_range(*GROUP_TOLERANCE_DEG, unit),
        help=f"{values} within this many {unit}{also} of each other are the same commanded "
             "value, e.g. read back from the controller with jitter. Default: derived from the "
             "data (docs/calibration.md, 'Rows taken at the same axis values').")


def counted(n: int, noun: str) -> str:
    """``n`` and the noun, plural unless ``n`` is 1: ``counted(1, "point")`` is ``"1 point"``.

    Parameters
    ----------
    n : int
    noun : str
        Singular; the plural adds an ``s``.

    Returns
    -------
    str
    """
    return f"{n} {noun}{'' if n == 1 else 's'}"


def check_noise(noise: float) -> None:
    """Refuse a ``--noise`` of plan or demo (mm) outside :data:`NOISE_MIN_MM` ..
    :data:`NOISE_MAX_MM` (or NaN) with an :class:`InputError` that gives the range."""
    if not NOISE_MIN_MM <= noise <= NOISE_MAX_MM:
        raise InputError(f"--noise must be a positive number of millimetres from "
                         f"{NOISE_MIN_MM:g} (1 um, below any touch-up accuracy) to "
                         f"{NOISE_MAX_MM:g}, got {noise:g}")


def parse_numbers(text: str, what: str, count: int | None = None) -> list[float]:
    """Parse ``"1,2,3"`` into floats, with an error naming ``what`` on bad input.

    Each value is a number as :func:`robotcell.io.tables.spreadsheet_number` reads it (no
    ``1_000``)."""
    parts = [p.strip() for p in text.split(",") if p.strip() != ""]
    numbers = [tables.spreadsheet_number(p) for p in parts]
    if any(v is None for v in numbers):
        raise InputError(f"{what} must be comma-separated numbers, got {text!r}")
    values = [float(v) for v in numbers if v is not None]
    if count is not None and len(values) != count:
        raise InputError(f"{what} needs {count} comma-separated values, got {len(values)}")
    if not all(math.isfinite(v) for v in values):
        raise InputError(f"{what} contains NaN or infinite values")
    if any(abs(v) > tables.MAX_ABS_VALUE for v in values):
        raise InputError(f"{what} has a value beyond {tables.MAX_ABS_VALUE:.0e} in size: no "
                         "length in mm or angle in deg is that large")
    return values


def read_csv(path: str, known: Iterable[str] | None = None) -> dict:
    """:func:`robotcell.io.tables.read_csv`, warning on stderr about columns not in ``known``.

    ``known`` lists the columns the command uses; any other column (except a note column) is
    named in a ``warning:`` line, with the closest known name, since it is otherwise ignored.
    """
    cols = tables.read_csv(path)
    if known is not None:
        warn_unknown_columns(path, cols, known)
    return cols


def warn_unknown_columns(path: str, cols: dict, known: Iterable[str]) -> None:
    """A ``warning:`` line on stderr naming the columns of ``cols`` not in ``known``, if any."""
    warning = tables.unknown_columns_warning(path, cols, known)
    if warning:
        click.echo(warning, err=True)


def check_output(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
    """Callback of an output option: refuse a missing folder or a folder before any work (a file
    of several hard links is refused by :func:`robotcell.cli.files.refuse_overwriting_inputs`,
    once an output onto an input has been named as such)."""
    if value is not None:
        check_destination(value, links=False)
    return value


#: File name endings that say what kind of file a name holds, and the ending of each kind.
_KINDS = {".json": "JSON", ".yaml": "YAML", ".yml": "YAML", ".csv": "CSV", ".html": "HTML",
          ".htm": "HTML", ".urdf": "URDF"}
_ENDING = {"JSON": ".json", "YAML": ".yaml", "CSV": ".csv", "HTML": ".html", "URDF": ".urdf",
           "text": ".txt"}


def check_kind(path: str | None, kind: str, what: str, option: str = "-o",
               named: Mapping[str, str] | None = None, ending: str | None = None) -> None:
    """Refuse an output file whose name says another kind of file than the one written.

    ``-o`` writes what the command produces; a name ending in ``.json`` for a YAML model file
    (or ``.csv`` for a JSON result, ...) would mislead whoever opens it, so it is refused
    before any work. A name with another ending (``.dat``, none) is taken as given.

    Parameters
    ----------
    path : str or None
        The output option's value.
    kind : str
        What is written: ``JSON``, ``YAML``, ``CSV``, ``HTML``, ``URDF`` or ``text``.
    what : str
        What the file holds, for the message (``"the identified model file"``).
    option : str
        The option, for the message.
    named : mapping of str to str, optional
        Further endings that say another kind of file, and what they say (``.src``: ``a KUKA
        program``).
    ending : str, optional
        The ending to suggest (default: the one of ``kind``).
    """
    if path is None:
        return
    suffix = Path(path).suffix.lower()
    said = _KINDS.get(suffix) or (named or {}).get(suffix)
    if said is not None and said != kind:
        raise InputError(f"{option} {path}: the name says {said}, but this writes {what} as "
                         f"{kind}; name it {Path(path).stem}{ending or _ENDING[kind]}")


def output_of(kind: str, what: str) -> Callable[[click.Context, click.Parameter, str | None],
                                                str | None]:
    """Callback of an output option that writes ``what`` as ``kind``: :func:`check_output`, and
    :func:`check_kind` on the name, before any work."""
    def callback(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
        checked = check_output(ctx, param, value)
        check_kind(value, kind, what, param.opts[0])
        return checked
    return callback


def check_not_folder(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
    """Callback of an output option whose missing folder is created: refuse a folder."""
    if value is not None and Path(value).is_dir():
        raise InputError(f"cannot write {value!r}: it is a folder; give a file name")
    return value


def write_output(path: str | None, text: str) -> None:
    """Write ``text`` to ``path`` atomically (see :mod:`robotcell.io.fileio`), or to stdout."""
    if path is None:
        click.echo(text, nl=False)
    else:
        atomic_write(path, text)
