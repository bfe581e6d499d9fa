"""``robotcell sweep``: rank layouts of a cell on a set of targets (mm, deg)."""

from __future__ import annotations

import os
from concurrent.futures import Executor, ProcessPoolExecutor
from contextlib import ExitStack
from dataclasses import dataclass
from typing import Any

import click

from robotcell.cell import Cell
from robotcell.cli.cellargs import setup_text
from robotcell.cli.common import format_table, output_of
from robotcell.cli.files import OUTPUT, Command
from robotcell.cli.progress import DeferredProgress
from robotcell.cli.reach import load_targets, target_options
from robotcell.cli.robotname import robot_name_option, robot_of
from robotcell.errors import InputError
from robotcell.studies.sweep import read_layouts, sweep


def _executor(stack: ExitStack, workers: int | None, scheduler: str | None) -> Executor | None:
    if scheduler is not None:
        try:
            from distributed import Client
        except ImportError:
            raise InputError("--scheduler needs Dask: pip install 'robotcell[dask]'") from None
        try:
            client = stack.enter_context(Client(scheduler, timeout="10s"))
        except Exception as exc:  # noqa: BLE001 - whatever answers there, it is no scheduler
            raise InputError(f"cannot reach a Dask scheduler at {scheduler} ({exc}); give the "
                             "address 'dask scheduler' prints, e.g. tcp://HOST:8786") from None
        return client.get_executor()
    n = (os.cpu_count() or 1) if workers is None else workers
    if n < 1:
        raise InputError(f"--workers must be at least 1, got {n}")
    return None if n == 1 else stack.enter_context(ProcessPoolExecutor(n))


@dataclass(frozen=True)
class _Targets:
    """Where the targets of ``sweep`` are and how they are reached: the options of
    :func:`robotcell.cli.reach.target_options`.

    Attributes
    ----------
    cell_path : str
        ``--cell`` file.
    frame : str
        ``--frame`` of the targets.
    tool : str or None
        ``--tool`` of the cell (None: the robot model's).
    fmt : str
        ``--format`` of the pose columns.
    table_deg : str or None
        ``--table`` angle(s) (deg) for targets without a table column.
    choose_table : bool
        ``--choose-table``: the table angle chosen per target.
    """

    cell_path: str
    frame: str
    tool: str | None
    fmt: str
    table_deg: str | None
    choose_table: bool


@click.command(cls=Command)
@robot_name_option
@target_options
@click.option("--targets", "targets", required=True, type=click.Path(dir_okay=False),
              help="CSV of target poses (columns of --format; optional 'table' in deg, a "
                   "positioner's e1..en).")
@click.option("--layouts", "layouts_path", required=True, type=click.Path(dir_okay=False),
              help="YAML of offsets per component (mm, deg); every combination is a layout.")
@click.option("--workers", type=int, default=None,
              help="Local worker processes (default: one per CPU; 1: no subprocess).")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help="Run on a Dask cluster, e.g. tcp://10.0.0.5:8786 (pip install "
                   "'robotcell[dask]').")
@click.option("--top", type=int, default=10, show_default=True, help="Layouts to print.")
@click.option("-o", "--output", type=OUTPUT, default=None, callback=output_of("CSV", "the ranking"),
              help="CSV of every layout, ranked (written atomically).")
def sweep_cmd(targets: str, layouts_path: str, workers: int | None, scheduler: str | None,
              top: int, output: str | None, **where: Any) -> None:
    """Rank layouts of the cell by how well the robot reaches the targets.

    Each layout (one combination of the offsets in --layouts, see docs/reach.md) is scored on
    every target as by 'robotcell reach': reachable fraction, mean score and smallest score
    (0..1). Layouts rank by reachable fraction, then mean score. Runs on local processes
    (--workers) or a Dask cluster (--scheduler); a progress bar appears on stderr when the
    sweep takes longer than 2 s.

    \b
    Examples:
      robotcell sweep --cell cell.yaml --targets seam.csv --layouts l.yaml --frame part
      robotcell sweep --cell cell.yaml --targets seam.csv --layouts l.yaml --workers 8
      robotcell sweep --cell c.yaml --targets t.csv --layouts l.yaml --scheduler tcp://head:8786
    """
    at = _Targets(**where)
    full = Cell.load(at.cell_path)  # a layout may move several robots; one reaches
    name = robot_of(full, at.cell_path)
    cell = full.for_robot(name)
    T, th, _, axes = load_targets(targets, cell, at.fmt, at.table_deg, at.choose_table,
                                  track_column=False)
    click.echo(setup_text(cell, at.tool, at.frame,
                          axes.replace("track chosen per target",
                                       "track chosen per target and layout"), ""), err=True)
    layouts = read_layouts(layouts_path)
    with ExitStack() as stack:
        ex = _executor(stack, workers, scheduler)
        ranked = sweep(full, T, layouts, frame=at.frame, tool=at.tool, table=th, executor=ex,
                       progress=DeferredProgress(stack, "layouts"), output=output,
                       robot=name)
    shown = ranked[:max(top, 0)]
    rows_out = [[rank + 1, r.layout.label, f"{100 * r.fraction:.1f}", f"{r.mean_score:.3f}",
                 f"{r.min_score:.3f}"] for rank, r in enumerate(shown)]
    listed = (f"all {len(ranked)} layouts" if len(shown) == len(ranked) else
              f"the best {len(shown)} of {len(ranked)} layouts (--top N lists more"
              + (f", {output} has all" if output else ", -o FILE writes all") + ")")
    click.echo(f"{listed}, scored on {len(T)} targets; offsets in mm and deg")
    click.echo(format_table(["rank", "layout", "reachable %", "mean score", "min score"],
                            rows_out))
