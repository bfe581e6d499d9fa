"""Reading and writing the text of program files: lines, comments, numbers, names.

Shared by the four formats. A reader reports every problem as an
:class:`~robotcell.errors.InputError` that names the file and the line, so that a truncated or
corrupt program is refused with the place to look at.
"""

from __future__ import annotations

import re
from pathlib import Path

from robotcell.errors import InputError
from robotcell.export.common import fmt_num, parse_float
from robotcell.io.fileio import read_text
from robotcell.io.tables import MAX_ABS_VALUE

__all__ = ["NAME_LIMITS", "Lines", "fmt_num", "program_name", "strip_comment"]

#: Longest program name per format: KUKA and ABB identifiers; FANUC program names as RoboDK's
#: FANUC post shortens them; YASKAWA job names ("up to 8 characters", NX100 job data format).
NAME_LIMITS = {"kuka": 24, "abb": 32, "fanuc": 10, "yaskawa": 8}

_IDENT = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")


def program_name(name: str, vendor: str) -> str:
    """``name`` as a program name of ``vendor`` (FANUC and YASKAWA in capitals).

    Raises
    ------
    InputError
        Not a letter followed by letters, digits or ``_``, or longer than the format allows.
    """
    limit = NAME_LIMITS[vendor]
    if not _IDENT.match(name) or len(name) > limit:
        raise InputError(f"program name {name!r} is not a {vendor} program name: a letter, then "
                         f"letters, digits or '_', at most {limit} characters; give another name")
    return name.upper() if vendor in ("fanuc", "yaskawa") else name


def strip_comment(line: str, marker: str) -> str:
    """``line`` without its comment (from ``marker`` outside double quotes), right-stripped."""
    quoted = False
    for i, ch in enumerate(line):
        if ch == '"':
            quoted = not quoted
        elif not quoted and line.startswith(marker, i):
            return line[:i].rstrip()
    return line.rstrip()


class Lines:
    """The lines of a program file, and errors that name the file and line.

    Parameters
    ----------
    path : str or Path
        The file (UTF-8, or Windows-1252/Latin-1 as pendants save them).
    what : str
        What the file is, for the message when it does not exist.
    """

    def __init__(self, path: str | Path, what: str = "program file") -> None:
        self.path = str(path)
        self.lines = read_text(path, what).splitlines()

    def error(self, lineno: int, message: str) -> InputError:
        """An :class:`InputError` ``<file>: line <n>: <message>``."""
        return InputError(f"{self.path}: line {lineno}: {message}")

    def where(self, lineno: int) -> str:
        """``<file>:<line>`` for a point's origin."""
        return f"{self.path}:{lineno}"

    def number(self, text: str, lineno: int) -> float:
        """A finite number of at most :data:`~robotcell.io.tables.MAX_ABS_VALUE` in size, or an
        error naming the line."""
        v = parse_float(text.strip(), f"{self.path}: line {lineno}")
        if abs(v) > MAX_ABS_VALUE:
            raise self.error(lineno, f"{text.strip()} is beyond {MAX_ABS_VALUE:.0e} in size, "
                                     "which no value of a program is")
        return v

    def integer(self, text: str, lineno: int, base: int = 10) -> int:
        """A whole number written in ``base``, of at most
        :data:`~robotcell.io.tables.MAX_ABS_VALUE` in size; ``ValueError`` if it is none."""
        v = int(text.strip(), base)
        if abs(v) > MAX_ABS_VALUE:
            raise self.error(lineno, f"{text.strip()} is beyond {MAX_ABS_VALUE:.0e} in size, "
                                     "which no value of a program is")
        return v
