"""Arguments of ``robotcell ik --cell`` and ``robotcell fk --cell``: tool, track, table (mm, deg).

The commands call :meth:`robotcell.cell.Cell.ik` and :meth:`robotcell.cell.Cell.fk`; this module
only turns the command line's vendor units into their SI arguments and refuses values outside
the cell's limits with a message naming the value and the limits.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Iterator

import click
import numpy as np
from numpy.typing import NDArray

from robotcell.cell import Cell, Track, Turntable
from robotcell.cli.common import parse_numbers
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor

__all__ = ["PROGRESS_MIN", "cell_tool", "chunks", "row_values", "table_angles", "track_values"]

#: Batches of at least this many poses show a progress bar on stderr.
PROGRESS_MIN = 2000
#: Poses per call of the library while a progress bar is shown.
CHUNK = 500


def cell_tool(text: str | None) -> str | NDArray[np.float64] | None:
    """``--tool``: a tool name of the cell, or ``X,Y,Z,A,B,C`` (mm, deg, KUKA) as ``T_F_TCP`` (m)."""
    if text is None:
        return None
    if "," in text:
        return pose_from_vendor(parse_numbers(text, "--tool", 6), "kuka")
    return text


def _checked(values: NDArray[np.float64], unit_scale: float, unit: str, axis: Track | Turntable | None,
             what: str, option: str) -> NDArray[np.float64]:
    """``values`` (SI) if the cell has the axis and they are within its limits, else an error
    naming the first offending value in ``unit`` (``unit_scale`` units per SI unit)."""
    if axis is None:
        if np.any(values != 0):
            raise InputError(f"the cell has no {option}; leave out --{option} (or the {option} column)")
        return values
    bad = np.atleast_1d(~axis.within_limits(values))
    if np.any(bad):
        first = float(np.atleast_1d(values)[bad][0]) * unit_scale
        raise InputError(f"{what} {first:g} {unit} is outside the {axis_name(axis)} limits "
                         f"[{axis.lower * unit_scale:g}, {axis.upper * unit_scale:g}] {unit}")
    return values


def axis_name(axis: Track | Turntable) -> str:
    """``track`` or ``turntable``, as the limits are named in messages."""
    return "track" if isinstance(axis, Track) else "turntable"


def track_values(cell: Cell, mm: NDArray[np.float64] | float | None
                 ) -> NDArray[np.float64] | None:
    """Track positions in m from mm, checked against the cell's track and its limits."""
    if mm is None:
        return None
    return _checked(np.asarray(mm, dtype=float) * 1e-3, 1e3, "mm", cell.track, "track position",
                    "track")


def table_angles(cell: Cell, deg: NDArray[np.float64] | float) -> NDArray[np.float64]:
    """Table angles in rad from deg, checked against the cell's turntable and its limits."""
    return _checked(np.radians(np.asarray(deg, dtype=float)), 180.0 / math.pi, "deg",
                    cell.turntable, "table angle", "table")


def row_values(cols: dict, name: str, option: float | None, n: int) -> NDArray[np.float64] | None:
    """A per-row column of a batch file (``track`` mm, ``table`` deg), else the option's value."""
    if name in cols:
        v = cols[name]
        if not isinstance(v, np.ndarray):
            raise InputError(f"column '{name}' must hold numbers")
        return v
    return None if option is None else np.full(n, float(option))


def chunks(n: int, label: str) -> Iterator[slice]:
    """Slices over ``n`` poses; with a progress bar on stderr for ``n >= PROGRESS_MIN``."""
    if n < PROGRESS_MIN:
        yield slice(0, n)
        return
    with click.progressbar(length=n, label=label, file=sys.stderr,
                           show_pos=True) as bar:
        for s in range(0, n, CHUNK):
            yield slice(s, min(s + CHUNK, n))
            bar.update(min(CHUNK, n - s))
