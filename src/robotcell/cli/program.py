"""``robotcell program``: robot programs from a path through the cell, checked, retargeted."""

from __future__ import annotations

import gc
import json
import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import click
import numpy as np

from robotcell.cell import Cell
from robotcell.cli.common import (
    MAX_CORRECTION_MM,
    BadPoints,
    as_flags,
    counted,
    format_table,
    in_range,
    parse_numbers,
)
from robotcell.cli.files import Group, LiveChoice, OutputPath
from robotcell.cli.robotname import load_cell, robot_name_option
from robotcell.controllers.registry import names

#: Library parameters as the command line names them.
FLAGS = {"pulses_per_degree": "--pulses-per-degree", "split": "--split",
         "max_correction": "--max-correction", "joints": "--joints"}


def _ppd(text: str | None) -> list[float] | None:
    return None if text is None else parse_numbers(text, "--pulses-per-degree")


def _cell_option(f: Callable) -> Callable:
    f = robot_name_option(f)
    return click.option("--cell", "cell_path", required=True, type=click.Path(dir_okay=False),
                        help="Cell file (YAML, mm/deg).")(f)


def _ppd_option(f: Callable) -> Callable:
    return click.option("--pulses-per-degree", "ppd", default=None, metavar="N[,N...]",
                        help="YASKAWA: encoder pulses per degree of each station axis.")(f)


@contextmanager
def _collector_paused() -> Iterator[None]:
    """Python's cyclic garbage collector paused while a program is read and checked: the
    objects of its points hold no cycles (reference counting frees them), and the collector's
    passes over 100,000 points cost a quarter of the time (benchmarks/bench_program_check.py)."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


@click.group(cls=Group)
def program() -> None:
    """Robot programs: write a path as a KUKA, ABB, FANUC or YASKAWA program, check a program
    against the cell, retarget joint points after a recalibration, filter a program through
    the cell's identified arm (docs/programs.md, docs/accuracy.md).

    \b
    Examples:
      robotcell program write examples/seam_part.csv --cell cell.yaml --tool torch --frame part --format kuka -o prog
      robotcell program check prog/seam_part.src --cell cell.yaml
    """


@program.command("write")
@click.argument("path", type=click.Path(dir_okay=False))
@_cell_option
@click.option("--tool", required=True, help="Tool of the cell.")
@click.option("--frame", default="world", show_default=True,
              help="Frame of the path: world or a frame of the cell.")
@click.option("--format", "vendor", required=True, type=LiveChoice(names),
              help="Program format.")
@click.option("-o", "--output", "folder", required=True, type=OutputPath(file_okay=False),
              help="Folder for the program files (created; its parent must exist).")
@click.option("--name", default=None, help="Program name (default: the path file's name).")
@click.option("--split", is_flag=True,
              help="Write one program per continuous piece instead of refusing a path that "
                   "breaks.")
@_ppd_option
@click.option("--json", "as_json", is_flag=True, help="Print the files, joints and breaks as JSON.")
def write_cmd(path: str, cell_path: str, tool: str, frame: str, vendor: str, folder: str,
              name: str | None, split: bool, ppd: str | None, as_json: bool) -> None:
    """Write the path PATH (CSV: x, y, z mm and a, b, c deg in --frame; optional motion,
    speed mm/s, zone mm, track mm, table deg or e1..en) as a program of --format.

    The joints are solved through the cell with one arm configuration; the track follows the
    path unless the file gives it, and the table's values are chosen along a path in a frame on
    the table unless the file gives them (docs/programs.md). The tools and frames are the ones
    'robotcell export' writes, with the same numbers. A path that cannot be one program (reach,
    limit, singularity, a jump of the table) exits with status 3 naming the points, and nothing
    is written; --split writes one program per piece.

    \b
    Example:
      robotcell program write examples/seam_part.csv --cell cell.yaml --tool torch --frame part --format abb -o prog
    """
    from robotcell.programs import PathBreaks, ProgramOptions, write_program

    cell = load_cell(cell_path)
    with as_flags(FLAGS):
        try:
            result = write_program(path, cell, tool, frame, vendor, folder, name,
                                   ProgramOptions(split=split), pulses_per_degree=_ppd(ppd),
                                   inputs=(cell_path,))
        except PathBreaks as exc:
            click.echo(format_table(["point", "why", "cause"],
                                    [[b.index + 1, b.kind, b.message] for b in exc.breaks]),
                       err=True)
            raise BadPoints(f"{path}: {exc}".replace("with split", "with --split")) from None
    for w in result.warnings:
        click.echo(f"warning: {w}", err=True)
    for f in result.replaced:
        click.echo(f"note: replaced {f}, an earlier program of the same path file", err=True)
    if as_json:
        click.echo(json.dumps(_write_json(cell, result), indent=2))
    else:
        for f in result.files:
            click.echo(f"wrote {f}")
        for b in result.breaks:
            click.echo(f"break at point {b.index + 1} ({b.kind}): {b.message}", err=True)


def _deg(v: float) -> float | None:
    return None if not math.isfinite(v) else round(math.degrees(v), 9)


def _write_json(cell: Cell, result) -> dict:
    from robotcell.cell.validation import table_columns

    tcols = table_columns(cell)
    points = []
    for i in range(result.q.shape[0]):
        d: dict = {"point": i + 1, "program": (result.programs[result.program_of[i]].name
                                               if result.program_of[i] >= 0 else None)}
        d.update({f"a{j + 1}": _deg(v) for j, v in enumerate(result.q[i])})
        if cell.track is not None:
            t = result.track[i]
            d["track"] = None if not math.isfinite(t) else round(t * 1e3, 9)
        d.update({k: _deg(v) for k, v in zip(tcols, np.atleast_1d(result.table[i]))})
        points.append(d)
    return {"files": result.files, "points": points,
            "breaks": [{"point": b.index + 1, "kind": b.kind, "message": b.message}
                       for b in result.breaks]}


@program.command("check")
@click.argument("program_file", metavar="PROGRAM", type=click.Path(dir_okay=False))
@_cell_option
@_ppd_option
@click.option("--singular-margin", "singular_margin", type=float, default=2.0,
              show_default=True, callback=in_range(0.0, 45.0, "deg"),
              help="Closest good approach to the wrist or elbow singularity, at a point or on a "
                   "linear motion (deg).")
@click.option("--shoulder-margin", "shoulder_margin", type=float, default=20.0,
              show_default=True, callback=in_range(0.0, 1000.0, "mm"),
              help="Closest good distance of the wrist centre from axis 1 (mm).")
@click.option("--bodies", "bodies_path", type=click.Path(dir_okay=False), default=None,
              help="The cell's parts as shapes (YAML, docs/clearance.md): check the clearance "
                   "of every point and motion.")
@click.option("--clearance", "clearance_mm", type=float, default=10.0, show_default=True,
              callback=in_range(0.0, 1000.0, "mm"),
              help="Smallest good distance between the robot and a part, with --bodies (mm).")
@click.option("--json", "as_json", is_flag=True, help="Print every point as JSON.")
def check_cmd(program_file: str, cell_path: str, ppd: str | None, singular_margin: float,
              shoulder_margin: float, bodies_path: str | None, clearance_mm: float,
              as_json: bool) -> None:
    """Check every point of PROGRAM (KUKA .src with its .dat, ABB .mod, FANUC .ls, YASKAWA
    .jbi) against the cell: reach, limits, configuration as written, distance to singularities;
    and every linear motion as the controller follows it: a configuration change, a
    singularity, reach or limits left on the way. With --bodies, the clearance between the
    robot and the cell's parts at every point and along every motion.

    Exit status 0 when every point is good, 3 with a table of the bad points, 2 for a file that
    cannot be read.

    \b
    Example:
      robotcell program check prog/seam_part.src --cell cell.yaml
    """
    from robotcell.clearance import read_bodies
    from robotcell.programs.check import check_program_file

    cell = load_cell(cell_path)
    bodies = read_bodies(bodies_path) if bodies_path else None
    with as_flags(FLAGS), _collector_paused():
        report = check_program_file(program_file, cell, _ppd(ppd),
                                    math.radians(singular_margin), shoulder_margin * 1e-3,
                                    bodies, clearance_mm * 1e-3)
    if as_json:
        click.echo(json.dumps(report.to_json(cell), indent=2))
    for s in report.skipped:
        click.echo(f"note: not checked: {s}", err=True)
    n = len(report.points)
    if report.good:
        if not as_json:
            click.echo(f"{program_file}: {counted(n, 'point')}, all good" if n else
                       f"{program_file}: no point checked")
        return
    click.echo(format_table(["point", "line", "problem"], report.rows()), err=True)
    bad = len(report.bad)
    verb = "is" if bad == 1 else "are"
    raise BadPoints(f"{program_file}: {bad} of {counted(n, 'point')} {verb} bad")


def _by_robot(values: tuple[str, ...], what: str) -> dict[str, str]:
    """``NAME=VALUE`` items as a mapping (``what`` names the option for messages)."""
    from robotcell.errors import InputError

    out: dict[str, str] = {}
    for item in values:
        name, sep, value = item.partition("=")
        if not sep or not name.strip() or not value.strip():
            raise InputError(f"{what} takes ROBOT=VALUE (a robot of the cell, '='), got {item!r}")
        out[name.strip()] = value.strip()
    return out


@program.command("write-coordinated")
@click.argument("paths", nargs=-1, required=True, metavar="ROBOT=PATH...")
@click.option("--cell", "cell_path", required=True, type=click.Path(dir_okay=False),
              help="Cell file of several robots (YAML, mm/deg).")
@click.option("--tool", "tools", multiple=True, required=True, metavar="ROBOT=TOOL",
              help="Each robot's tool (repeat the option), or one TOOL for every robot.")
@click.option("--frame", default="world", show_default=True,
              help="Frame of every path: world or a frame of the cell.")
@click.option("--format", "vendor", required=True, type=LiveChoice(names),
              help="Program format (coordinated: abb, MultiMove; yaskawa, one job of two "
                   "robots and a station).")
@click.option("-o", "--output", "folder", required=True, type=OutputPath(file_okay=False),
              help="Folder for the program files (created; its parent must exist).")
@click.option("--name", default=None, help="Program name (default: the first path's name).")
@_ppd_option
def write_coordinated_cmd(paths: tuple[str, ...], cell_path: str, tools: tuple[str, ...],
                          frame: str, vendor: str, folder: str, name: str | None,
                          ppd: str | None) -> None:
    """Write the paths of several robots of the cell as one coordinated program: point k of
    every path reached together (or, when every file has a time column, s, the points matched
    by time, poses between a file's points interpolated along its linear motions), the
    positioner at the values the files give (columns table or e1..en) or, where none gives
    them, chosen once for all robots, each robot's track as its file says or following its
    path (docs/programs.md, "Coordinated programs"). ABB: one MultiMove module per task (T_ROB1,
    T_ROB2, .. in the order of the cell's robots). YASKAWA: one job NAME.jbi, the first robot
    with the station in group 1, the second in group 2 (--pulses-per-degree for the station).
    A format whose coordinated form robotcell does not write exits with status 2 naming what
    is missing; nothing is written.

    \b
    Example:
      robotcell program write-coordinated rob1=examples/seam_rob1.csv rob2=examples/seam_rob2.csv --cell examples/cell_two_abb_positioner.yaml --tool torch --frame part --format abb -o prog --name seams
    """
    from robotcell.programs import PathBreaks
    from robotcell.programs.coordinated import write_coordinated

    cell = Cell.load(cell_path)
    by_robot = _by_robot(paths, "ROBOT=PATH")
    tool_map = (dict.fromkeys(by_robot, tools[0]) if len(tools) == 1 and "=" not in tools[0]
                else _by_robot(tools, "--tool"))
    try:
        with as_flags(FLAGS):
            result = write_coordinated(by_robot, cell, tool_map, frame, vendor, folder, name,
                                       inputs=(cell_path,), pulses_per_degree=_ppd(ppd))
    except PathBreaks as exc:
        click.echo(format_table(["point", "why", "cause"],
                                [[b.index + 1, b.kind, b.message] for b in exc.breaks]),
                   err=True)
        raise BadPoints(str(exc)) from None
    for w in result.warnings:
        click.echo(f"warning: {w}", err=True)
    for f in result.files:
        click.echo(f"wrote {f}")


@program.command("check-coordinated")
@click.argument("program_files", nargs=-1, required=True, metavar="PROGRAM...",
                type=click.Path(dir_okay=False))
@click.option("--cell", "cell_path", required=True, type=click.Path(dir_okay=False),
              help="Cell file of several robots (YAML, mm/deg).")
@click.option("--robots", default=None, metavar="NAME,NAME...",
              help="The robot of each file, in order (default: the cell's robots in order).")
@click.option("--bodies", "bodies_path", type=click.Path(dir_okay=False), default=None,
              help="The cell's parts as shapes (YAML, docs/clearance.md): check the clearance "
                   "of the robots against each other and the parts.")
@click.option("--clearance", "clearance_mm", type=float, default=10.0, show_default=True,
              callback=in_range(0.0, 1000.0, "mm"),
              help="Smallest good distance, with --bodies (mm).")
@_ppd_option
def check_coordinated_cmd(program_files: tuple[str, ...], cell_path: str, robots: str | None,
                          bodies_path: str | None, clearance_mm: float, ppd: str | None) -> None:
    """Check a coordinated program, one file per robot (ABB: a MultiMove module per task) or
    one job of two robots (YASKAWA .jbi): the synchronisation (ABB: the \\ID of every
    synchronised move has its partner in every other task; YASKAWA: the groups, and every
    motion line moves both robots), as many points each with the positioner at the same
    values, every robot's
    points against the cell as 'program check' does, and with --bodies the clearance of the
    robots against each other and the parts. Exit status 0 when all is good, 3 with a table of
    the problems, 2 for a file that cannot be read or a format not read.

    \b
    Example:
      robotcell program check-coordinated prog/seams_T_ROB1.mod prog/seams_T_ROB2.mod --cell examples/cell_two_abb_positioner.yaml
    """
    from robotcell.clearance import read_bodies
    from robotcell.programs.coordcheck import check_coordinated

    cell = Cell.load(cell_path)
    bodies = read_bodies(bodies_path) if bodies_path else None
    order = None if robots is None else [r.strip() for r in robots.split(",")]
    with as_flags(FLAGS):
        report = check_coordinated(list(program_files), cell, order, bodies,
                                   clearance_mm * 1e-3, _ppd(ppd))
    for robot, rep in report.reports.items():
        for s in rep.skipped:
            click.echo(f"note: {robot}: not checked: {s}", err=True)
    n = sum(len(r.points) for r in report.reports.values())
    if report.good:
        click.echo(f"{counted(len(report.reports), 'program')}, {counted(n, 'point')}, "
                   "all good")
        return
    for s in report.sync:
        click.echo(f"synchronisation: {s}", err=True)
    if report.rows():
        click.echo(format_table(["robot", "point", "line", "problem"], report.rows()), err=True)
    raise BadPoints(f"{len(report.sync)} synchronisation problem(s), "
                    f"{sum(len(r.bad) for r in report.reports.values())} of "
                    f"{counted(n, 'point')} bad")


@program.command("retarget")
@click.argument("program_file", metavar="PROGRAM", type=click.Path(dir_okay=False))
@click.option("--from", "old_path", required=True, type=click.Path(dir_okay=False),
              help="Cell file the program was taught in.")
@click.option("--to", "new_path", required=True, type=click.Path(dir_okay=False),
              help="Cell file after the recalibration.")
@click.option("-o", "--output", "folder", required=True, type=OutputPath(file_okay=False),
              help="Folder for the retargeted program files (created; its parent must exist).")
@_ppd_option
@click.option("--json", "as_json", is_flag=True, help="Print every joint point as JSON.")
@robot_name_option
def retarget_cmd(program_file: str, old_path: str, new_path: str, folder: str, ppd: str | None,
                 as_json: bool) -> None:
    """Move the joint points of PROGRAM (KUKA E6AXIS/AXIS, ABB jointtarget, FANUC joint
    positions) so that the TCP stays where it was after a recalibration (a new tool, base,
    track, table or identified arm): solved in the --to cell where the --from cell had the TCP.
    Cartesian points are left as they are: they follow the exported tool and frame data.
    Each point keeps its configuration (shoulder, elbow and wrist sides, and its turns). Prints
    the largest axis change per point; a point the new cell cannot reach in its configuration,
    or only with an axis outside its limits, exits with status 3 naming it, and nothing is
    written. Joint values outside the model's limits in the program are named. In cell files
    of several robots --robot-name names the program's robot, in both.

    \b
    Example:
      robotcell program retarget prog/seam_part.src --from examples/cell_kr16_track_turntable.yaml --to cell.yaml -o prog_new
    """
    from robotcell.programs.retarget import RetargetFailed, retarget_program

    old, new = load_cell(old_path), load_cell(new_path)
    with as_flags(FLAGS):
        try:
            result = retarget_program(program_file, old, new, folder, _ppd(ppd),
                                      inputs=(old_path, new_path))
        except RetargetFailed as exc:
            raise BadPoints(f"{program_file}: {exc}") from None
    for note in result.notes:
        click.echo(f"note: {note}", err=True)
    rows = [[p.name, p.line, f"{math.degrees(p.change):.4f}", f"{p.tcp_error * 1e3:.6f}"]
            for p in result.points]
    if as_json:
        click.echo(json.dumps({"files": result.files, "cartesian_points": result.cartesian,
                               "points": [{"name": p.name, "line": p.line,
                                           "change_deg": round(math.degrees(p.change), 9),
                                           "tcp_error_mm": round(p.tcp_error * 1e3, 9)}
                                          for p in result.points]}, indent=2))
        return
    if rows:
        click.echo(format_table(["point", "line", "largest change (deg)", "TCP error (mm)"],
                                rows))
    click.echo(f"{counted(len(result.points), 'joint point')} retargeted, "
               f"{counted(result.cartesian, 'Cartesian point')} kept; wrote "
               f"{', '.join(result.files)}")


@program.command("compensate")
@click.argument("program_file", metavar="PROGRAM", type=click.Path(dir_okay=False))
@_cell_option
@click.option("-o", "--output", "folder", required=True, type=OutputPath(file_okay=False),
              help="Folder for the filtered program files (created; its parent must exist).")
@click.option("--joints", "joints", type=click.Choice(["taught", "offline"]), default="taught",
              show_default=True, help="Joint points taught on the real arm (kept) or computed "
                                      "offline with the nominal model (filtered too).")
@click.option("--max-correction", "max_correction", type=float, default=5.0, show_default=True,
              callback=in_range(*MAX_CORRECTION_MM, "mm"),
              help="Largest correction taken (mm); above it the identified model is wrong.")
@click.option("--report", "report", type=OutputPath(dir_okay=False),
              help="Also write an HTML page: predicted error without filtering and 1-sigma "
                   "after, per point.")
@_ppd_option
@click.option("--json", "as_json", is_flag=True, help="Print every filtered point as JSON.")
def compensate_cmd(program_file: str, cell_path: str, folder: str, joints: str,
                   max_correction: float, report: str | None, ppd: str | None,
                   as_json: bool) -> None:
    """Filter every Cartesian point of PROGRAM (KUKA .src with its .dat, ABB .mod, FANUC .ls,
    YASKAWA .jbi) through the cell's identified arm and write the program to the folder with
    nothing else changed: each point becomes the pose the controller's nominal model computes
    for the joints that put the real arm where the point was meant (docs/accuracy.md).

    Joint points stay as they are (taught on the real arm); --joints offline filters them too.
    Prints the largest correction. Exit status 3 naming each point that cannot be filtered
    (out of the identified arm's reach as written, a correction above --max-correction); nothing
    is written then.

    \b
    Example:
      robotcell program compensate prog/seam_part.src --cell cell.yaml -o prog_filtered
    """
    from robotcell.accuracy.filter import FilterRefused
    from robotcell.accuracy.program import compensate_program
    from robotcell.cli.common import check_kind
    from robotcell.report.accuracy import write_program_report

    check_kind(report, "HTML", "the accuracy report", "--report")
    cell = load_cell(cell_path)
    with as_flags(FLAGS):
        try:
            result = compensate_program(program_file, cell, folder, joints, _ppd(ppd),
                                        max_correction * 1e-3, inputs=(cell_path,))
        except FilterRefused as exc:
            click.echo(format_table(["point", "why"], [list(p) for p in exc.points]), err=True)
            raise BadPoints(f"{program_file}: {exc}") from None
    if report is not None:
        write_program_report(report, program_file, result)
    if as_json:
        click.echo(json.dumps(result.to_json(), indent=2))
        return
    big = result.largest
    for s in result.skipped:
        click.echo(f"note: not filtered: {s}", err=True)
    click.echo(f"{counted(len(result.points), 'point')} filtered, "
               f"{counted(result.kept, 'joint point')} kept; largest "
               f"correction {big.dpos * 1e3:.4f} mm, {math.degrees(big.drot):.4f} deg at "
               f"{big.name}; wrote {', '.join(result.files)}")
