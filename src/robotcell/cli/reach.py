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
from robotcell.cli.common import check_output, write_csv, write_output
from robotcell.cli.progress import DeferredProgress
from robotcell.errors import InputError
from robotcell.io.poseformats import FORMATS
from robotcell.studies.reach import ReachMap, reach_html, reach_map, read_targets


def reach_rows(rm: ReachMap, n_axes: int) -> tuple[list[str], np.ndarray]:
    """CSV header and rows of a reachability map (mm, deg)."""
    table = (["table_deg"] if rm.table.ndim == 1
             else [f"table{i + 1}_deg" for i in range(rm.table.shape[1])])
    header = ["target", "reachable", "score", "track_mm", *table, "branch",
              *[f"a{i + 1}_deg" for i in range(n_axes)], "limit_margin_deg", "track_margin_mm",
              "manipulability_m3"]
    rows = np.column_stack([
        np.arange(rm.reachable.size), rm.reachable.astype(float), rm.score, rm.track * 1e3,
        np.degrees(rm.table), rm.branch, np.degrees(rm.q), np.degrees(rm.limit_margin),
        rm.track_margin * 1e3, rm.manipulability,
    ])
    return header, rows


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
        click.option("--table", "table_deg", type=float, default=0.0, show_default=True,
                     help="Table angle (deg) for targets without a 'table' column."),
        click.option("--choose-table", is_flag=True,
                     help="Choose the table angle per target (36 angles over one turn, best "
                          "score)."),
    )):
        f = opt(f)
    return f


def load_targets(path: str, fmt: str, table_deg: float, choose_table: bool
                 ) -> tuple[np.ndarray, np.ndarray | None]:
    """Targets (m) and table angles (rad; None: to be chosen) from the targets file."""
    T, table = read_targets(path, fmt)
    if choose_table:
        if table is not None:
            raise InputError(f"{path} has a 'table' column; leave it out to --choose-table")
        return T, None
    return T, np.radians(table_deg) if table is None else table


@click.command()
@click.argument("targets", type=click.Path(dir_okay=False))
@target_options
@click.option("--track", "track_mm", type=float, default=None,
              help="Track position (mm) for every target (default: chosen per target).")
@click.option("-o", "--output", type=click.Path(), default=None, callback=check_output,
              help="CSV to write, atomically (default: standard output).")
@click.option("--html", "html_path", type=click.Path(), default=None, callback=check_output,
              help="Self-contained HTML page with the map (default: next to -o, .html).")
def reach(targets: str, cell_path: str, frame: str, tool: str | None, fmt: str,
          table_deg: float, choose_table: bool, track_mm: float | None, output: str | None,
          html_path: str | None) -> None:
    """Reachability map: can the robot reach every target, and how well.

    TARGETS is a CSV of poses in --frame with the columns of --format (kuka: x,y,z,a,b,c in mm
    and deg) and optionally a column 'table' (deg). The track position is chosen per target
    unless --track is given; the table angle too with --choose-table. Every target gets:
    reachable (1/0), score (0..1: 1 when the arm is as far from singularities as it gets and
    every axis is at least 10 deg from its limits), track_mm, table_deg, branch (0..7),
    a1_deg.., limit_margin_deg (smallest distance of an axis to its limits), track_margin_mm and
    manipulability_m3 (|det J|). Unreachable targets have nan axis values. A summary goes to
    stderr.

    \b
    Examples:
      robotcell reach --cell cell.yaml seam.csv --frame part --tool torch -o reach.csv
      robotcell reach --cell cell.yaml seam.csv --tool torch --html reach.html
    """
    cell = Cell.load(cell_path)
    T, th = load_targets(targets, fmt, table_deg, choose_table)
    track = None if track_mm is None else track_mm * 1e-3
    with ExitStack() as stack:
        rm = reach_map(cell, T, frame=frame, tool=tool, table=th, track=track,
                       progress=DeferredProgress(stack, "targets"))
    header, rows = reach_rows(rm, cell.robot.n_joints)
    write_csv(output if output else sys.stdout, header, rows, 6)
    if html_path is None and output:
        html_path = str(Path(output).with_suffix(".html"))
    if html_path:
        page = reach_html(rm, T[:, :3, 3], title=f"Reachability: {Path(targets).name} in "
                          f"{cell.name}", frame=frame)
        write_output(html_path, page)
    n_ok = int(np.count_nonzero(rm.reachable))
    margin = math.degrees(float(np.nanmin(rm.limit_margin))) if n_ok else float("nan")
    click.echo(f"{n_ok} of {rm.reachable.size} targets reachable, mean score "
               f"{float(np.mean(rm.score)):.3f}, smallest limit margin {margin:.1f} deg"
               + (f"; map in {html_path}" if html_path else ""), err=True)
