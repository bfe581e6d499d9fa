"""``robotcell iso9283``: the ISO 9283 acceptance test of a cell: plan it, analyse the log.

``robotcell simulate iso9283`` (:func:`simulate_iso9283`, reached through ``robotcell
simulate``) writes the log of a virtual cell.
"""

from __future__ import annotations

import json
import math
import sys
from typing import Any

import click
import numpy as np

from robotcell.cli.common import as_flags, in_range, output_of, parse_numbers
from robotcell.cli.files import OUTPUT, Command, Group, LiveChoice, OutputPath
from robotcell.cli.robotname import load_cell, robot_name, robot_name_option
from robotcell.controllers.registry import names
from robotcell.errors import InputError

#: Library parameters as the command line names them.
FLAGS = {"pulses_per_degree": "--pulses-per-degree", "device_frame": "--device-frame",
         "path_cycles": "--path-cycles", "angle_noise": "--angle-noise", "limit_ap": "--limit-ap",
         "limit_rp": "--limit-rp", "limit_at": "--limit-at", "limit_rt": "--limit-rt"}


@click.group(cls=Group)
def iso9283() -> None:
    """The ISO 9283 acceptance test of a cell: plan the test cube's poses and paths (and their
    programs), analyse the tracker's log into pose accuracy and repeatability, distance, path
    and drift figures with a verdict and a report (docs/iso9283.md).

    \b
    Examples:
      robotcell iso9283 plan --cell cell.yaml --tool torch -o plan.csv
      robotcell iso9283 analyse meas.csv --plan plan.csv --cell cell.yaml -o report.html
    """


def _positive(ctx: click.Context, param: click.Parameter, value: float | None) -> float | None:
    """Callback of a length option: refuse a value that is not a positive number of mm."""
    if value is not None and not (math.isfinite(value) and value > 0):
        raise InputError(f"{param.opts[0]} must be a positive length (mm), got {value:g}")
    return value


def _mm3(text: str | None, what: str) -> np.ndarray | None:
    return None if text is None else np.array(parse_numbers(text, what, 3)) * 1e-3


@iso9283.command("plan")
@click.option("--cell", "cell_path", required=True, type=click.Path(dir_okay=False),
              help="Cell file (YAML, mm/deg).")
@click.option("--tool", required=True, help="Tool of the cell whose TCP is tested.")
@click.option("--frame", default="world", show_default=True,
              help="Frame of the poses written and measured: world or a frame of the cell.")
@click.option("--size", type=float, default=None, metavar="MM", callback=_positive,
              help="Edge of the test cube (default: the largest that is clear).")
@click.option("--centre", default=None, metavar="X,Y,Z",
              help="Centre of the cube in --frame (mm; default: searched in front of the arm).")
@click.option("--orientation", default="0,180,0", show_default=True, metavar="A,B,C",
              help="TCP orientation in --frame at every pose, R = Rz(A) Ry(B) Rx(C) (deg).")
@click.option("--track", "track_mm", type=float, default=None, metavar="MM",
              help="Track position (default: the middle of the travel).")
@click.option("--table", default="0", show_default=True, metavar="DEG[,DEG...]",
              help="Turntable angle or positioner axis values during the test (deg).")
@click.option("-o", "--output", type=OUTPUT, default=None, callback=output_of("CSV", "the plan"),
              help="The plan file (CSV), atomically (default: standard output).")
@click.option("--programs", type=OutputPath(file_okay=False), default=None, metavar="DIR",
              help="Also write the pose and path programs, one subfolder per --format.")
@click.option("--format", "vendors", multiple=True, type=LiveChoice(names),
              help="Program format(s) for --programs (repeatable; default every controller "
                   "that holds the cell).")
@click.option("--cycles", type=int, default=30, show_default=True,
              help="Cycles of the pose program.")
@click.option("--path-cycles", type=int, default=10, show_default=True,
              help="Cycles of the path program.")
@click.option("--speed", type=float, default=100.0, show_default=True, metavar="MM/S",
              callback=in_range(0.1, 10_000, "mm/s"),
              help="TCP speed along the paths.")
@click.option("--pulses-per-degree", "ppd", default=None, metavar="N[,N...]",
              help="YASKAWA: encoder pulses per degree of each station axis.")
@robot_name_option
def plan_cmd(cell_path: str, tool: str, frame: str, output: str | None, programs: str | None,
             **opts: Any) -> None:
    """Plan the ISO 9283 test of a cell: the largest cube one arm configuration reaches with
    the TCP in --orientation, within every limit and away from singularities; its poses P1
    (the centre) to P5 and its two paths, a line through P1 and a circle around it, all in the
    cube's diagonal plane.

    Writes the plan file (pose, x, y, z mm, a, b, c deg, track, table, frame, tool) and, with
    --programs, for each --format the program of the pose cycles (P1, then P5, P4, P3, P2, P1
    --cycles times) and of the path cycles. Prints the cube on stderr.

    \b
    Examples:
      robotcell iso9283 plan --cell cell.yaml --tool torch -o plan.csv
      robotcell iso9283 plan --cell cell.yaml --tool torch --size 500 -o plan.csv --programs iso --format kuka
      robotcell iso9283 plan --cell examples/cell_two_robots_positioner.yaml --robot-name abb --tool torch --size 300 -o plan_abb.csv
    """
    from robotcell.iso9283 import plan, write_plan, write_programs
    from robotcell.iso9283.planfile import table_names
    from robotcell.kinematics.transforms import rot_x, rot_y, rot_z

    a, b, c = np.radians(parse_numbers(opts["orientation"], "--orientation", 3))
    size = None if opts["size"] is None else opts["size"] * 1e-3
    cell = load_cell(cell_path)
    with as_flags(FLAGS):
        p = plan(cell, tool, frame, size, _mm3(opts["centre"], "--centre"),
                 None if opts["track_mm"] is None else opts["track_mm"] * 1e-3,
                 np.radians(parse_numbers(opts["table"], "--table")).squeeze(),
                 rot_z(a) @ rot_y(b) @ rot_x(c))
        files = [] if programs is None else write_programs(
            p, cell, programs, opts["vendors"] or None, opts["cycles"], opts["path_cycles"],
            opts["speed"] * 1e-3,
            None if opts["ppd"] is None else parse_numbers(opts["ppd"], "--pulses-per-degree"))
    write_plan(p, sys.stdout if output is None else output)
    centre = p.poses[0, :3, 3] * 1e3
    extra = ([f"track {p.track * 1e3:g} mm"] if p.track is not None else []) + [
        f"{n} {v:g} deg" for n, v in zip(table_names(p.table),
                                         np.degrees(np.atleast_1d(p.table if p.table is not None
                                                                  else [])))]
    click.echo(f"test cube: edge {p.size * 1e3:.1f} mm, centre (P1) {centre.round(3).tolist()} "
               f"mm in {frame}, arm configuration (branch) {p.branch}"
               + "".join(f", {e}" for e in extra), err=True)
    for f in files:
        click.echo(f"wrote {f}", err=True)
    if output:
        click.echo(f"wrote {output}", err=True)


@iso9283.command("analyse")
@click.argument("measurements", metavar="MEAS.csv", type=click.Path(dir_okay=False))
@click.option("--plan", "plan_path", required=True, type=click.Path(dir_okay=False),
              help="The plan file the log measured.")
@click.option("--cell", "cell_path", default=None, type=click.Path(dir_okay=False),
              help="The cell file: the report then draws the cube in the cell; its robot's "
                   "datasheet repeatability, if its model has one, is the default --limit-rp.")
@click.option("--device-frame", is_flag=True,
              help="The log is in the tracker's own frame: fit it onto the plan's frame from "
                   "the barycentres of P1..P5 first.")
@click.option("--limit-ap", type=float, default=None, callback=_positive, metavar="MM",
              help="Largest acceptable pose accuracy AP_p.")
@click.option("--limit-rp", type=float, default=None, callback=_positive, metavar="MM",
              help="Largest acceptable pose repeatability RP_l (default with --cell: the "
                   "datasheet's, where the robot's model file states it).")
@click.option("--limit-at", type=float, default=None, callback=_positive, metavar="MM",
              help="Largest acceptable path accuracy AT_p.")
@click.option("--limit-rt", type=float, default=None, callback=_positive, metavar="MM",
              help="Largest acceptable path repeatability RT_p.")
@click.option("--json", "as_json", is_flag=True,
              help='Print {"poses": [{"pose": "P1", "AP_p_mm": .., ...}], "distances": [..], '
                   '"paths": [..], "verdict": {"level": .., "reasons": [..]}, ...}.')
@click.option("-o", "--output", type=OUTPUT, default=None,
              callback=output_of("HTML", "the test report"),
              help="Write the report (one HTML page) atomically.")
@robot_name_option
def analyse_cmd(measurements: str, plan_path: str, cell_path: str | None, device_frame: bool,
                as_json: bool, output: str | None, **limits: float | None) -> None:
    """Analyse the measurement log MEAS.csv (cycle, pose, x, y, z mm; optional a, b, c deg and
    time s; a pose is P1..P5 or a path of the plan) of the test that --plan planned.

    Prints per pose the barycentre's deviation AP (AP_p and AP_x, AP_y, AP_z), the
    repeatability RP_l = mean(l) + 3 S_l and, where the log has them, the orientation figures
    and the drift; the distance figures from P1; per path AT_p and RT_p; and the verdict
    against the limits given (docs/iso9283.md). Exit status 0 for a pass or no limits, 3 for a
    fail (the report is written all the same), 2 for refused input (nothing is written).

    \b
    Example:
      robotcell iso9283 analyse meas.csv --plan plan.csv --cell cell.yaml --limit-ap 1 --limit-rp 0.1 -o report.html
    """
    from robotcell.iso9283 import Limits, analyse

    if cell_path is None and robot_name() is not None:
        raise InputError("--robot-name names a robot of a cell file; it needs --cell CELL.yaml")
    cell = None if cell_path is None else load_cell(cell_path)
    # the datasheet belongs to the robot's nominal model (an identified arm's is its nominal)
    robot = None if cell is None else (cell.identified.nominal if cell.identified else cell.robot)
    with as_flags(FLAGS):
        result = analyse(measurements, plan_path, device_frame, Limits(
            **{k[-2:].upper(): None if v is None else v * 1e-3 for k, v in limits.items()}),
            robot)
    for w in result.warnings:
        click.echo(f"warning: {w}", err=True)
    if output is not None:
        from robotcell.report.iso9283 import write_iso9283_report

        write_iso9283_report(output, result, cell)
    if as_json:
        click.echo(json.dumps(result.to_json(), indent=2))
    else:
        click.echo(_text(result))
    if output is not None:
        click.echo(f"wrote {output}", err=True)
    if result.verdict.level == "fail":
        sys.exit(3)


def _text(result: Any) -> str:
    """The terminal report: a table per pose and per path, the notes and the verdict."""
    from robotcell.cli.common import format_table

    rows = [[r.pose, len(r.p), r.figures.AP_p * 1e3, *(r.figures.AP * 1e3).tolist(),
             r.figures.RP_l * 1e3] for r in result.poses]
    lines = [format_table(["pose", "cycles", "AP_p mm", "AP_x mm", "AP_y mm", "AP_z mm",
                           "RP_l mm"], rows)]
    if result.distances:
        lines.append(format_table(["P1 to", "cycles", "AD_p mm", "RD_p mm"],
                                  [[d.pose, d.cycles, d.AD_p * 1e3, d.RD_p * 1e3]
                                   for d in result.distances]))
    if result.paths:
        lines.append(format_table(["path", "cycles", "AT_p mm", "RT_p mm"],
                                  [[r.path, r.cycles, r.figures.AT_p * 1e3, r.figures.RT_p * 1e3]
                                   for r in result.paths]))
    lines += [f"note: {n}" for n in result.notes]
    lines.append(result.verdict.line())
    return "\n".join(lines)


@click.command(cls=Command)
@click.option("--cell", "cell_path", required=True, type=click.Path(dir_okay=False),
              help="The true cell (YAML, mm/deg; its identified arm, if any, is the real arm).")
@click.option("--plan", "plan_path", required=True, type=click.Path(dir_okay=False),
              help="The plan file of the test.")
@click.option("--controller", "controller_path", default=None, type=click.Path(dir_okay=False),
              help="The cell the controller and the programs use (calibrated or nominal; "
                   "default: the true cell).")
@click.option("--noise", type=float, default=0.02, show_default=True, metavar="MM",
              callback=in_range(0, 10, "mm"),
              help="The robot's repeatability scatter, 1-sigma per coordinate.")
@click.option("--angle-noise", type=float, default=0.001, show_default=True, metavar="DEG",
              callback=in_range(0, 5, "deg"),
              help="Scatter of the measured orientation, 1-sigma per axis.")
@click.option("--orientation/--no-orientation", default=True,
              help="Write the measured orientation a, b, c.")
@click.option("--cycles", type=int, default=30, show_default=True, help="Cycles of the poses.")
@click.option("--path-cycles", type=int, default=10, show_default=True,
              help="Cycles of the paths (0: none).")
@click.option("--spacing", type=float, default=2.0, show_default=True, metavar="MM",
              callback=in_range(0.1, 50, "mm"),
              help="Distance of the samples along a path.")
@click.option("--seed", type=click.IntRange(min=0), default=None, help="Seed of the scatter.")
@click.option("-o", "--output", type=OUTPUT, default=None, callback=output_of("CSV", "the log"),
              help="The log (CSV), atomically (default: standard output).")
@robot_name_option
def simulate_iso9283(cell_path: str, plan_path: str, controller_path: str | None,
                     output: str | None, **opts: Any) -> None:
    """Simulate the tracker's log of the ISO 9283 test of --plan in the virtual cell --cell.

    The controller moves with the joints its cell (--controller) gives; the real TCP is where
    the true cell puts them, measured in the plan's frame with the scatter --noise. Writes the
    log that 'robotcell iso9283 analyse' reads (cycle, pose, x, y, z, a, b, c, time).
    In cell files of several robots --robot-name names the robot tested, in both.

    \b
    Example:
      robotcell simulate iso9283 --cell truth.yaml --plan plan.csv --controller cell.yaml --seed 1 -o meas.csv
    """
    from robotcell.iso9283 import read_plan, simulate, write_log

    truth = load_cell(cell_path)
    controller = None if controller_path is None else load_cell(controller_path)
    p, warnings = read_plan(plan_path)
    for w in warnings:
        click.echo(f"warning: {w}", err=True)
    with as_flags(FLAGS):
        log = simulate(truth, p, controller, opts["noise"] * 1e-3,
                       math.radians(opts["angle_noise"]) if opts["orientation"] else None,
                       opts["cycles"], opts["path_cycles"], opts["spacing"] * 1e-3, opts["seed"])
    write_log(log, sys.stdout if output is None else output)
    click.echo(f"simulated {len(log.name)} rows: {opts['cycles']} cycles of P1..P5, "
               f"{opts['path_cycles']} of each path, repeatability scatter {opts['noise']:g} mm"
               + (f"; wrote {output}" if output else ""), err=True)
