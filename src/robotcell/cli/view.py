"""``robotcell view``: the interactive 3D view of a cell, as one HTML file (mm, deg)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import click
import numpy as np

from robotcell.cell import Cell
from robotcell.cli.cellargs import cell_tool, table_angles, table_option, track_values
from robotcell.cli.common import in_range, output_of, parse_numbers
from robotcell.cli.files import OUTPUT, Command
from robotcell.cli.fk import joints_to_si
from robotcell.cli.robotname import robot_name, robot_name_option, robot_of
from robotcell.errors import InputError
from robotcell.robot.robot import Robot
from robotcell.view.cellscene import write_cell_view
from robotcell.view.coordinated import write_coordinated_view
from robotcell.view.path import ordinal
from robotcell.view.plot import MAX_PAGE_BYTES
from robotcell.view.program import write_program_view


@dataclass(frozen=True)
class ViewOptions:
    """The options of ``robotcell view`` as parsed (mm, deg; None: not given)."""

    joints: str | None
    track_mm: float | None
    table_deg: str | None
    reach_path: str | None
    tool: str | None
    programs: tuple[str, ...]
    ppd: str | None
    robots: str | None
    bodies_path: str | None
    clearance_mm: float | None
    output: str


def joint_option(robot: Robot, text: str | None) -> np.ndarray | None:
    """``--joints`` (deg; mm for a prismatic axis) in SI, refused outside the axis limits."""
    if text is None:
        return None
    q = joints_to_si(robot, np.array(parse_numbers(text, "--joints", robot.n_joints)))
    for i, (j, v) in enumerate(zip(robot.axes, q)):
        if not j.lower <= v <= j.upper:
            unit, k = ("mm", 1e3) if j.prismatic else ("deg", 180.0 / math.pi)
            raise InputError(f"--joints: {j.name or f'axis {i + 1}'} = {v * k:g} {unit} is outside "
                             f"its limits [{j.lower * k:g}, {j.upper * k:g}] {unit}")
    return q


@click.command(cls=Command)
@robot_name_option
@click.argument("cell_path", metavar="CELL.yaml", type=click.Path(dir_okay=False))
@click.option("--joints", default=None, metavar="A1,A2,...",
              help="Arm axis values (deg; mm for a prismatic axis); default the robot model's "
                   "home configuration, else 0.")
@click.option("--track", "track_mm", type=float, default=None, metavar="MM",
              help="Track position (mm); default 0.")
@click.option("--table", "table_deg", default=None, metavar="DEG[,DEG...]",
              help="Turntable angle (deg), or one value per positioner axis; default 0.")
@click.option("--reach", "reach_path", type=click.Path(dir_okay=False), default=None,
              help="A reachability map to draw: the CSV of 'robotcell reach -o'.")
@click.option("--tool", default=None,
              help="With --reach: the tool the map was made with (a tool of the cell, or "
                   "X,Y,Z,A,B,C in mm, deg); default the robot model's tool.")
@click.option("--program", "programs", type=click.Path(dir_okay=False), multiple=True,
              help="A robot program to draw (KUKA .src with its .dat, ABB .mod, FANUC .ls, "
                   "YASKAWA .jbi): its path, the arm at each point on a slider, the points "
                   "'robotcell program check' finds bad marked. Given once per robot (ABB: "
                   "a MultiMove module per task): a coordinated program, every robot moving "
                   "together.")
@click.option("--pulses-per-degree", "ppd", default=None, metavar="N[,N...]",
              help="With --program, YASKAWA: encoder pulses per degree of each station axis.")
@click.option("--robots", default=None, metavar="NAME,NAME...",
              help="With a coordinated program: the robot of each --program, in order "
                   "(default: the cell's robots in order).")
@click.option("--bodies", "bodies_path", type=click.Path(dir_okay=False), default=None,
              help="With a coordinated program: the cell's parts as shapes (YAML, "
                   "docs/clearance.md); the clearance is checked and the closest pair drawn "
                   "at each point.")
@click.option("--clearance", "clearance_mm", type=float, default=None, metavar="MM",
              callback=in_range(0.0, 1000.0, "mm"),
              help="With --bodies: smallest good distance (mm); default 10.")
@click.option("-o", "--output", required=True, type=OUTPUT,
              callback=output_of("HTML", "the view"), help="HTML file to write, atomically.")
def view(cell_path: str, **options: Any) -> None:
    """Interactive 3D view of a cell: one HTML file that opens offline, with no server.

    The robot as its links and joint axes, the track and its travel, the turntable or
    positioner axes and plate, every tool and frame as a labelled triad (X red, Y green, Z
    blue) and the world axes, in mm; hover over a frame for its pose (x, y, z mm; a, b, c deg,
    R = Rz(a) Ry(b) Rx(c)). With --reach, the targets of a reachability map where the TCP
    reaches them, coloured by score. With --program, the program's path and the arm at each
    of its points (a slider and a play button), the points 'program check' finds bad (an
    unreachable one among them) marked with their problems. With one --program per robot of the
    cell, a coordinated program: every robot and the positioner moving together, and with
    --bodies the closest pair of shapes at each point with its distance. Refused with exit
    status 2: a cell file or program that cannot be read (a missing robot model, the program's
    file and line named), joint, track or table values outside their limits, a number of
    programs that is not the number of robots, -o onto an input file. See docs/view.md.

    \b
    Examples:
      robotcell view examples/cell_kr16_track_turntable.yaml --joints 0,-60,100,0,50,0 \\
          --track 1500 --table 30 -o cell.html
      robotcell view cell.yaml --reach reach.csv --tool torch -o reach3d.html
      robotcell view cell.yaml --program prog/seam_part.src -o program.html
      robotcell view examples/cell_two_abb_positioner.yaml --program prog_cv/seams_T_ROB1.mod \\
          --program prog_cv/seams_T_ROB2.mod --bodies examples/bodies_two_robots_positioner.yaml \\
          -o coordinated.html
    """
    o = ViewOptions(**options)
    if o.tool is not None and o.reach_path is None:
        raise InputError("--tool says which tool the --reach map was made with; give --reach")
    if o.ppd is not None and not o.programs:
        raise InputError("--pulses-per-degree is for a YASKAWA --program; give --program")
    coordinated = [flag for flag, v in (("--robots", o.robots), ("--bodies", o.bodies_path),
                                        ("--clearance", o.clearance_mm)) if v is not None]
    if coordinated and len(o.programs) < 2:
        raise InputError(f"{', '.join(coordinated)}: for a coordinated program, one --program "
                         "per robot")
    if o.programs:
        given = [flag for flag, v in (("--joints", o.joints), ("--track", o.track_mm),
                                      ("--table", o.table_deg), ("--reach", o.reach_path))
                 if v is not None]
        if given:
            raise InputError(f"--program draws the arm at the program's points: leave out "
                             f"{', '.join(given)}")
        if len(o.programs) > 1:
            return _coordinated(cell_path, o)
        return _program(cell_path, o)
    cell = Cell.load(cell_path)
    every = len(cell.robots) > 1 and robot_name() is None and (
        o.joints, o.track_mm, o.reach_path) == (None, None, None)  # a robot's values need its name
    one = cell.for_robot(cell.robot_names[0] if every else robot_of(cell, cell_path))
    q = joint_option(one.robot, o.joints)
    e = float(track_values(one, o.track_mm or 0.0))
    th = table_angles(one, table_option(one, o.table_deg))
    if len(cell.robots) == 1 or o.reach_path is not None:  # a reach map: the robot that reaches
        path = write_cell_view(one, o.output, q, e, th, o.reach_path, cell_tool(o.tool))
    else:
        path = write_cell_view(cell, o.output, None if every else {one.robot_name: q},
                               {} if every else {one.robot_name: e}, th)
    click.echo(f"{path}: 3D view of {cell.name}, {path.stat().st_size / 1e6:.1f} MB; open it "
               "in a browser", err=True)


def _arms(every: int) -> str:
    return "every point" if every == 1 else (
        f"every {ordinal(every)} point (the page stays under {MAX_PAGE_BYTES / 1e6:g} MB)")


def _program(cell_path: str, o: ViewOptions) -> None:
    """One robot's program."""
    whole = Cell.load(cell_path)
    if len(whole.robots) > 1 and robot_name() is None:
        raise InputError(f"{cell_path} has {len(whole.robots)} robots "
                         f"({', '.join(whole.robot_names)}): give one --program per robot (a "
                         "coordinated program), or say whose program this is with "
                         "--robot-name NAME")
    cell = whole.for_robot(robot_of(whole, cell_path))
    pulses = None if o.ppd is None else parse_numbers(o.ppd, "--pulses-per-degree")
    try:
        made = write_program_view(cell, o.programs[0], o.output, pulses)
    except InputError as exc:
        raise InputError(str(exc).replace("pulses_per_degree", "--pulses-per-degree")) from None
    rep = made.report
    click.echo(f"{made.path}: 3D view of {rep.program.name} in {cell.name}: "
               f"{len(rep.points)} points, {len(rep.bad)} bad, the arm at {_arms(made.every)}; "
               f"{made.size / 1e6:.1f} MB; open it in a browser", err=True)


def _coordinated(cell_path: str, o: ViewOptions) -> None:
    """A coordinated program, one file per robot."""
    from robotcell.clearance import read_bodies

    if o.ppd is not None:
        raise InputError("--pulses-per-degree is for a YASKAWA job of one robot; a coordinated "
                         "program is read as ABB MultiMove modules")
    cell = Cell.load(cell_path)
    bodies = read_bodies(o.bodies_path) if o.bodies_path else None
    order = None if o.robots is None else [r.strip() for r in o.robots.split(",")]
    limit = 10.0 if o.clearance_mm is None else o.clearance_mm
    made = write_coordinated_view(cell, o.programs, o.output, order, bodies, limit * 1e-3)
    reports = made.report.reports
    n = len(next(iter(reports.values())).points)
    under = "" if made.closest is None else (
        f", {int((made.closest.distance < limit * 1e-3).sum())} under the clearance of "
        f"{limit:g} mm")
    click.echo(f"{made.path}: 3D view of {len(reports)} robots' coordinated program in "
               f"{cell.name}: {n} points each, {sum(len(r.bad) for r in reports.values())} bad"
               f"{under}, the arms at {_arms(made.every)}; {made.size / 1e6:.1f} MB; open it "
               "in a browser", err=True)
