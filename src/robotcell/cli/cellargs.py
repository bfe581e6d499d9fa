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

from robotcell.cell import Cell
from robotcell.cli.common import parse_numbers
from robotcell.errors import InputError
from robotcell.poseformats import pose_from_vendor

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


def track_values(cell: Cell, mm: NDArray[np.float64] | float | None
                 ) -> NDArray[np.float64] | None:
    """Track positions in m from mm, checked against the cell's track and its limits."""
    if mm is None:
        return None
    e = np.asarray(mm, dtype=float) * 1e-3
    if cell.track is None:
        if np.any(e != 0):
            raise InputError("the cell has no track; leave out --track (or the track column)")
        return e
    bad = ~cell.track.within_limits(e)
    if np.any(bad):
        first = float(np.atleast_1d(e)[np.atleast_1d(bad)][0]) * 1e3
        raise InputError(f"track position {first:g} mm is outside the track limits "
                         f"[{cell.track.lower * 1e3:g}, {cell.track.upper * 1e3:g}] mm")
    return e


def table_angles(cell: Cell, deg: NDArray[np.float64] | float) -> NDArray[np.float64]:
    """Table angles in rad from deg, checked against the cell's turntable and its limits."""
    th = np.radians(np.asarray(deg, dtype=float))
    if cell.turntable is None:
        if np.any(th != 0):
            raise InputError("the cell has no turntable; leave out --table (or the table column)")
        return th
    bad = ~cell.turntable.within_limits(th)
    if np.any(bad):
        first = math.degrees(float(np.atleast_1d(th)[np.atleast_1d(bad)][0]))
        raise InputError(f"table angle {first:g} deg is outside the turntable limits "
                         f"[{math.degrees(cell.turntable.lower):g}, "
                         f"{math.degrees(cell.turntable.upper):g}] deg")
    return th


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
