"""Arguments of ``robotcell ik --cell`` and ``robotcell fk --cell``: tool, track, table (mm, deg).

The commands call :meth:`robotcell.cell.Cell.ik` and :meth:`robotcell.cell.Cell.fk`; this module
only turns the command line's vendor units into their SI arguments and refuses values outside
the cell's limits with a message naming the value and the limits. The table is a turntable's
angle, or one value per axis of a positioner chain (``--table 30,90``, batch columns
``e1..en``), as in the calibration CSV files.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import click
import numpy as np
from numpy.typing import NDArray

from robotcell.cell import Cell, Positioner, Track, Turntable
from robotcell.cell.validation import (
    axis_limit_violation,
    axis_range,
    check_axis_limits,
    table_columns,
    table_label,
)
from robotcell.cli.common import parse_numbers
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor
from robotcell.io.tables import CELL_EXTENT_MM
from robotcell.io.targets import Targets, read_targets

__all__ = [
    "NORMAL_UP",
    "PROGRESS_MIN",
    "batch_table",
    "batch_track",
    "cell_tool",
    "check_axis_columns",
    "check_normal_up",
    "output_table_columns",
    "progress",
    "read_batch",
    "setup_text",
    "table_angles",
    "table_option",
    "table_rows",
    "table_text",
    "track_rows",
    "track_values",
]

#: ``ik --cell --table normal-up``: the positioner turns each target's surface normal up.
NORMAL_UP = "normal-up"

#: Batches of at least this many poses show a progress bar on stderr.
PROGRESS_MIN = 2000


def cell_tool(text: str | None) -> str | NDArray[np.float64] | None:
    """``--tool``: a tool name of the cell, or ``X,Y,Z,A,B,C`` (mm, deg, KUKA) as ``T_F_TCP`` (m)."""
    if text is None:
        return None
    if "," in text:
        return pose_from_vendor(parse_numbers(text, "--tool", 6), "kuka")
    return text


def _checked(values: NDArray[np.float64], unit_scale: float, unit: str, axis: Track | Turntable | None,
             what: str, option: str, outside: str = "refuse") -> NDArray[np.float64]:
    """``values`` (SI) if the cell has the axis and they are within its limits, else an error
    naming the first offending value in ``unit`` (``unit_scale`` units per SI unit).

    ``outside``: ``"warn"``: a value outside the limits is named in a warning line instead (the
    result is computed, the axis cannot move there); ``"said"``: the values come from a column
    that :func:`check_axis_columns` has named already. A track position beyond 100 m is refused
    either way."""
    if axis is None:
        if np.any(values != 0):
            raise InputError(f"the cell has no {option}; leave out --{option} (or the {option} column)")
        return values
    lower, upper = axis_range(axis)
    bad = np.atleast_1d((values < lower) | (values > upper))
    if np.any(bad):
        first = float(np.atleast_1d(values)[bad][0]) * unit_scale
        text = (f"{what} {first:g} {unit} is outside the {axis_name(axis)} limits "
                f"[{lower * unit_scale:g}, {upper * unit_scale:g}] {unit}")
        extent = CELL_EXTENT_MM * 1e-3
        if outside != "refuse" and not (isinstance(axis, Track)
                                        and np.any(np.abs(values) > extent)):
            if outside == "warn":
                click.echo(f"warning: {text}; {OUTSIDE}", err=True)
        else:
            raise InputError(text)
    return values


#: What a warning about a track or table value outside its limits adds.
OUTSIDE = "computed anyway, but the axis cannot move there"


def axis_name(axis: Track | Turntable) -> str:
    """``track`` or ``turntable``, as the limits are named in messages."""
    return "track" if isinstance(axis, Track) else "turntable"


def track_values(cell: Cell, mm: NDArray[np.float64] | float | None, outside: str = "refuse"
                 ) -> NDArray[np.float64] | None:
    """Track positions in m from mm, checked against the cell's track and its limits (a
    position outside them: ``outside`` of :func:`_checked`)."""
    if mm is None:
        return None
    return _checked(np.asarray(mm, dtype=float) * 1e-3, 1e3, "mm", cell.track, "track position",
                    "track", outside)


def table_angles(cell: Cell, deg: NDArray[np.float64] | float, outside: str = "refuse"
                 ) -> NDArray[np.float64]:
    """Table angles in rad from deg, checked against the cell's turntable and its limits.

    For a positioner chain ``deg`` holds the axis values, shape ``(..., n)`` (0: every axis at 0),
    each checked against its axis's limits (a value outside them: ``outside`` of
    :func:`_checked`).
    """
    pos = cell.turntable
    if not isinstance(pos, Positioner):
        return _checked(np.radians(np.asarray(deg, dtype=float)), 180.0 / math.pi, "deg",
                        cell.turntable, "table angle", "table", outside)
    v = np.radians(np.asarray(deg, dtype=float))
    if v.ndim == 0 and v == 0:
        v = np.zeros(pos.n_axes)
    if v.ndim == 0 or v.shape[-1] != pos.n_axes:
        raise InputError(f"positioner {pos.name!r} has {pos.n_axes} axes: give one value per "
                         f"axis (deg), e.g. --table {','.join(['0'] * pos.n_axes)}")
    bad = (v < pos.lower) | (v > pos.upper)
    if np.any(bad):
        i = int(np.nonzero(bad)[-1][0])
        first = math.degrees(float(v[bad][0]))
        name = pos.chain.joints[i].name or f"e{i + 1}"
        text = (f"positioner axis {name} value {first:g} deg is outside its limits "
                f"[{math.degrees(pos.lower[i]):g}, {math.degrees(pos.upper[i]):g}] deg")
        if outside == "refuse":
            raise InputError(text)
        if outside == "warn":
            click.echo(f"warning: {text}; {OUTSIDE}", err=True)
    return v


def table_option(cell: Cell, text: str | None) -> NDArray[np.float64] | float:
    """``--table`` (deg): a turntable angle, or one comma-separated value per positioner axis.

    Without it 0 (the turntable, or every positioner axis, at 0).
    """
    if text is None:
        return 0.0
    pos = cell.turntable
    n = pos.n_axes if isinstance(pos, Positioner) else 1
    values = parse_numbers(text, "--table")
    if pos is None and len(values) != 1:
        raise InputError("the cell has no table; leave out --table (or the table column)")
    if len(values) != n:
        what = (f"positioner {pos.name!r} has {n} axes" if isinstance(pos, Positioner)
                else "a turntable has one angle")
        raise InputError(f"--table: {what}: give {n} comma-separated value(s) (deg), got "
                         f"{len(values)} ({text!r})")
    return np.array(values) if isinstance(pos, Positioner) else values[0]


def check_normal_up(cell: Cell, frame: str) -> str:
    """``--table normal-up``: refused unless a 2-axis positioner carries ``frame``; the value of
    ``table`` for :meth:`Cell.ik` (``"normal_up"``)."""
    pos = cell.turntable
    if not isinstance(pos, Positioner) or pos.n_axes != 2:
        raise InputError("--table normal-up needs a positioner of 2 axes (tilt, rotate); give "
                         "the table angle in deg instead")
    if frame not in cell.frames or cell.frames[frame].parent != "turntable":
        carried = ", ".join(k for k, f in cell.frames.items() if f.parent == "turntable")
        raise InputError(f"--table normal-up needs the target in a frame carried by the "
                         f"positioner (--frame {carried or 'NAME'}), got --frame {frame}")
    return "normal_up"


def read_batch(path: str, fmt: str, cell: Cell | None = None, track: bool = True) -> Targets:
    """The targets of a batch file (:func:`robotcell.io.targets.read_targets`) for ``cell``,
    naming each column the command does not use in a warning line on stderr.

    ``cell`` None: a bare robot's targets (no ``track`` or table columns); ``track`` False: a
    command that chooses the track itself (column ``track`` not used)."""
    if cell is None:
        t = read_targets(path, fmt, track=False, table=None)
    else:
        t = read_targets(path, fmt, track=track, table=table_columns(cell),
                         positioner=table_label(cell))
    for w in t.warnings:
        click.echo(f"warning: {w}", err=True)
    return t


def output_table_columns(cell: Cell) -> list[str]:
    """The table columns of a command's output for ``cell``: ``e1..en`` for a positioner, else
    ``table`` (0 for a cell without a table)."""
    return list(table_columns(cell) or ("table",))


def check_axis_columns(cell: Cell, track: NDArray[np.float64] | None,
                       table: NDArray[np.float64] | None, source: str, warn: bool = False
                       ) -> None:
    """Refuse the track positions (m) and table values (rad) a batch file gives in its columns
    (:func:`robotcell.io.targets.axis_columns`) outside the limits of the cell's axes, naming
    line and column. With ``warn`` they are named in a warning line instead; a track position
    beyond 100 m is refused still."""
    label = f"cell {cell.name!r}"
    checks = []
    if track is not None and cell.track is not None:
        checks.append((cell.track, track, ["track"]))
    if table is not None and cell.turntable is not None:
        checks.append((cell.turntable, table, list(table_columns(cell))))
    for axis, values, columns in checks:
        if not warn:
            check_axis_limits(axis, values, columns, source, label)
            continue
        beyond = axis_limit_violation(axis, values, columns, source, label, limits=False)
        if beyond is not None:
            raise InputError(f"{beyond}: beyond 100 m, a typing or unit error; correct the value")
        bad = axis_limit_violation(axis, values, columns, source, label)
        if bad is not None:
            click.echo(f"warning: {bad}; {OUTSIDE}", err=True)


def track_rows(cell: Cell, track: NDArray[np.float64] | None, track_mm: float | None, n: int
               ) -> NDArray[np.float64] | None:
    """Track positions (m) of the ``n`` rows of a batch file: its column ``track`` (checked by
    :func:`check_axis_columns`), else the option's value (mm) for every row, else None."""
    if track is None:
        return track_values(cell, None if track_mm is None else np.full(n, float(track_mm)),
                            "warn")
    return _checked(track, 1e3, "mm", cell.track, "track position", "track", "said")


def table_rows(cell: Cell, table: NDArray[np.float64] | None,
               option: NDArray[np.float64] | float, n: int) -> NDArray[np.float64]:
    """Table values (rad) of the ``n`` rows of a batch file: its table columns (checked by
    :func:`check_axis_columns`), else the option's value (deg) for every row, shape ``(n,)``
    for a turntable, ``(n, n_axes)`` for a positioner."""
    pos = cell.turntable
    if table is not None:
        return table
    if isinstance(pos, Positioner):
        return table_angles(cell, np.broadcast_to(np.asarray(option, dtype=float),
                                                  (n, pos.n_axes)), "warn")
    return table_angles(cell, np.full(n, float(option)), "warn")


@contextmanager
def progress(n: int, label: str) -> Iterator[Callable[[int], None] | None]:
    """A progress bar on stderr for ``n >= PROGRESS_MIN`` items: its ``update``, or None."""
    if n < PROGRESS_MIN:
        yield None
        return
    with click.progressbar(length=n, label=label, file=sys.stderr, show_pos=True) as bar:
        yield bar.update


def table_text(cell: Cell, values: NDArray[np.float64] | float, chosen: bool = False) -> str:
    """``, table 90 deg`` or ``, positioner E1, E2 30, 90 deg (normal up)`` for a headline.

    ``values`` are radians: a scalar for a turntable, one per axis for a positioner; nothing
    for a cell without either.
    """
    pos = cell.turntable
    if pos is None:
        return ""
    if not isinstance(pos, Positioner):
        return f", table {float(values) * 180.0 / math.pi:g} deg"
    names = ", ".join(j.name or f"e{i + 1}" for i, j in enumerate(pos.chain.joints))
    v = ", ".join(f"{x:.4f}" for x in np.degrees(np.ravel(values)) + 0.0)
    return f", positioner {names} {v} deg" + (" (chosen: normal up)" if chosen else "")


def setup_text(cell: Cell, tool: str | None, frame: str, track: str, table: str) -> str:
    """What a result of ``fk``/``ik --cell`` assumed: tool, frame, track and table.

    Parameters
    ----------
    cell : Cell
    tool : str or None
        ``--tool`` as given: a tool name, ``X,Y,Z,A,B,C``, or None for the bare flange.
    frame : str
        ``--frame``.
    track, table : str
        How the track position and the table were set, e.g. ``", track 1500 mm"`` (empty for
        a cell without the axis).

    Returns
    -------
    str
        E.g. ``"kr16: TCP of tool 'torch' in frame 'part', track 0 mm (default), table 0 deg"``.
    """
    what = ("the bare flange (no --tool)" if tool is None else
            f"tool {tool} (X,Y,Z,A,B,C)" if "," in tool else f"tool {tool!r}")
    return f"{cell.name}: TCP of {what} in frame {frame!r}{track}{table}"


def batch_track(cell: Cell, track: NDArray[np.float64] | None, track_mm: float | None,
                default: str) -> str:
    """How the rows of a batch file set the track (``track``: its column, or None), for
    :func:`setup_text`."""
    if cell.track is None:
        return ""
    if track is not None:
        return ", track from column 'track' (mm)"
    return f", track {default}" if track_mm is None else f", track {track_mm:g} mm (given)"


def batch_table(cell: Cell, table: NDArray[np.float64] | None, table_deg: str | None) -> str:
    """How the rows of a batch file set the table (``table``: its columns, or None), for
    :func:`setup_text`."""
    if cell.turntable is None:
        return ""
    if table is not None:
        return f", table from column(s) {', '.join(table_columns(cell))} (deg)"
    if table_deg == NORMAL_UP:
        return ", positioner chosen per pose: normal up"
    given = "0 (default)" if table_deg is None else f"{table_deg} (given)"
    return f", table {given} deg"
