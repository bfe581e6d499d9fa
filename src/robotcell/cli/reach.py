"""``robotcell reach``: reachability map of targets in a cell (mm, deg)."""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from contextlib import ExitStack
from pathlib import Path

import click
import numpy as np

from robotcell.cell import Cell
from robotcell.cli.cellargs import (
    batch_table,
    batch_track,
    check_axis_columns,
    read_batch,
    setup_text,
    table_option,
    table_rows,
    track_rows,
)
from robotcell.cli.common import output_of
from robotcell.cli.files import OUTPUT, Command, refuse_overwriting_inputs
from robotcell.cli.progress import DeferredProgress
from robotcell.cli.robotname import load_cell, robot_name_option
from robotcell.errors import InputError
from robotcell.io.poseformats import FORMATS
from robotcell.report.reach import write_reach_map


def target_options(f: Callable[..., None]) -> Callable[..., None]:
    """The options of ``reach`` and ``sweep`` that say where the targets are and how to reach
    them: --cell, --frame, --tool, --format, --table, --choose-table."""
    for opt in reversed((
        click.option("--cell", "cell_path", required=True, type=click.Path(dir_okay=False),
                     help="Cell file (YAML)."),
        click.option("--frame", default="world", show_default=True,
                     help="Frame of the targets: world, track, robot, turntable or a frame of "
                          "the cell."),
        click.option("--tool", default=None,
                     help="Tool of the cell (default: the robot model's tool)."),
        click.option("--format", "fmt", type=click.Choice(list(FORMATS)), default="kuka",
                     show_default=True, help="Pose columns of the targets file."),
        click.option("--table", "table_deg", default=None, metavar="DEG[,DEG...]",
                     help="Table angle (deg; a positioner: one value per axis) for targets "
                          "without a 'table' (or e1..en) column; default 0."),
        click.option("--choose-table", is_flag=True,
                     help="Choose the table angle per target (36 angles over one turn, best "
                          "score)."),
    )):
        f = opt(f)
    return f


def load_targets(path: str, cell: Cell, fmt: str, table_deg: str | None, choose_table: bool,
                 track_mm: float | None = None, track_column: bool = True
                 ) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None, str]:
    """Targets (m), table angles (rad; None: to be chosen), track positions (m; None: to be
    chosen) and how the track and table were set (``", track chosen per target, table 0 deg"``)
    from the targets file (:func:`robotcell.io.targets.read_targets`, with ``track`` when
    ``track_column``). Values outside the axis limits and a column the command does not use
    are named in a warning."""
    t = read_batch(path, fmt, cell, track_column)
    check_axis_columns(cell, t.track, t.table, path, warn=True)
    track = track_rows(cell, t.track, track_mm, len(t))
    if choose_table and t.table is not None:
        raise InputError(f"{path} has a '{t.table_columns[0]}' column; leave it out to "
                         "--choose-table")
    axes = (batch_track(cell, t.track, track_mm, "chosen per target")
            + (", table chosen per target (--choose-table)"
               if choose_table and cell.turntable is not None
               else batch_table(cell, t.table, table_deg)))
    if choose_table:
        return t.poses, None, track, axes
    th = table_rows(cell, t.table, table_option(cell, table_deg), len(t))
    return t.poses, th, track, axes


@click.command(cls=Command)
@robot_name_option
@click.argument("targets", type=click.Path(dir_okay=False))
@target_options
@click.option("--track", "track_mm", type=float, default=None,
              help="Track position (mm) for every target (default: chosen per target).")
@click.option("-o", "--output", type=OUTPUT, default=None, callback=output_of("CSV", "the scores"),
              help="CSV to write, atomically (default: standard output).")
@click.option("--html", "html_path", type=OUTPUT, default=None,
              callback=output_of("HTML", "the map"),
              help="Self-contained HTML page with the map (default: next to -o, .html).")
def reach(targets: str, cell_path: str, frame: str, tool: str | None, fmt: str,
          table_deg: str | None, choose_table: bool, track_mm: float | None, output: str | None,
          html_path: str | None) -> None:
    """Reachability map: can the robot reach every target, and how well.

    TARGETS is a CSV of poses in --frame with the columns of --format (kuka: x,y,z,a,b,c in mm
    and deg) and optionally 'track' (mm) and 'table' (deg; a positioner: e1..en), as for
    'ik --cell'. The track position is chosen per target unless given; the table angle too
    with --choose-table. Every target gets: reachable (1/0), score (0..1: 1 when the arm is as
    far from singularities as it gets and every axis is at least 10 deg from its limits), track
    (mm), table (deg; a positioner: e1..en), branch (0..7), a1.. (deg), limit_margin_deg
    (smallest distance of an axis to its limits), track_margin_mm and manipulability_m3
    (|det J|): the axis columns of 'fk --cell --input'. Unreachable targets have nan axis
    values. A summary goes to stderr.

    \b
    Examples:
      robotcell reach --cell cell.yaml seam.csv --frame part --tool torch -o reach.csv
      robotcell reach --cell cell.yaml seam.csv --tool torch --html reach.html
    """
    if html_path is None and output:
        html_path = str(Path(output).with_suffix(".html"))
        refuse_overwriting_inputs(click.get_current_context(), [("the map written next to -o", html_path)])
    cell = load_cell(cell_path)
    T, th, track, axes = load_targets(targets, cell, fmt, table_deg, choose_table, track_mm)
    click.echo(setup_text(cell, tool, frame, axes, ""), err=True)
    with ExitStack() as stack:
        rm = write_reach_map(cell, T, output if output else sys.stdout, html_path,
                             f"Reachability: {Path(targets).name} in {cell.name}", frame, tool,
                             th, track, DeferredProgress(stack, "targets"))
    n_ok = int(np.count_nonzero(rm.reachable))
    margin = math.degrees(float(np.nanmin(rm.limit_margin))) if n_ok else float("nan")
    click.echo(f"{n_ok} of {rm.reachable.size} targets reachable, mean score "
               f"{float(np.mean(rm.score)):.3f}, smallest limit margin {margin:.1f} deg"
               + (f"; map in {html_path}" if html_path else ""), err=True)
