"""Reading and writing the text of program files: lines, comments, numbers.

Shared by the program formats of every controller. A reader reports every problem as an
:class:`~robotcell.errors.InputError` that names the file and the line, so that a truncated or
corrupt program is refused with the place to look at.
"""

from __future__ import annotations

import math
from pathlib import Path

from robotcell.controllers.data import fmt_num, parse_float
from robotcell.errors import InputError
from robotcell.io.fileio import read_text
from robotcell.io.tables import MAX_ABS_VALUE, spreadsheet_number

__all__ = ["JOINT_DECIMALS", "NUMBER", "Lines", "fmt_num", "split", "strip_comment"]

#: Decimals of the joint values written (deg): 1e-9 deg.
JOINT_DECIMALS = 9
#: A number as program files write it (``12``, ``-0.5``, ``1.5e-3``), for editing one in place.
NUMBER = r"[-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?\d+)?"


def split(text: str, sep: str = ",") -> list[str]:
    """Top-level parts of ``text`` between the separators ``sep`` (one character) outside
    brackets, braces, parentheses and double quotes, stripped: the arguments of a call, the
    items of a list or record (``,``), a RAPID argument and its optional ones (``\\``)."""
    parts, depth, cur, quoted = [], 0, [], False
    for ch in text:
        if ch == '"':
            quoted = not quoted
        elif not quoted and ch in "[({":
            depth += 1
        elif not quoted and ch in "])}":
            depth -= 1
        if ch == sep and depth == 0 and not quoted:
            parts.append("".join(cur).strip())
            cur = []
        else:
            cur.append(ch)
    parts.append("".join(cur).strip())
    return parts


def strip_comment(line: str, marker: str) -> str:
    """``line`` without its comment (from ``marker`` outside double quotes), right-stripped."""
    at = line.find(marker)
    if at < 0:
        return line.rstrip()
    if '"' not in line[:at]:
        return line[:at].rstrip()
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
        """A finite number of at most :data:`~robotcell.io.tables.MAX_ABS_VALUE` in size, written
        as a controller writes one (digits 0-9, a decimal point, an exponent), or an error naming
        the line. Python's ``float`` also reads ``1_000`` and digits of other scripts (``١٢``),
        which no controller writes: a typing error, refused rather than read as a position."""
        v = spreadsheet_number(text)
        if v is None:
            raise self.error(lineno, f"{text.strip()!r} is not a number (digits 0-9, a decimal "
                                     "point, an exponent)")
        if not math.isfinite(v):  # the message of parse_float, naming the line
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
