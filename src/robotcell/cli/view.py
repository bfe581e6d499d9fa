"""``robotcell view``: the interactive 3D view of a cell, as one HTML file (mm, deg)."""

from __future__ import annotations

import math

import click
import numpy as np

from robotcell.cell import Cell
from robotcell.cli.cellargs import cell_tool, table_angles, table_option, track_values
from robotcell.cli.common import output_of, parse_numbers
from robotcell.cli.files import OUTPUT, Command
from robotcell.cli.fk import joints_to_si
from robotcell.cli.robotname import load_cell, robot_name, robot_name_option, robot_of
from robotcell.errors import InputError
from robotcell.robot.robot import Robot
from robotcell.view.cellscene import write_cell_view
from robotcell.view.path import ordinal
from robotcell.view.plot import MAX_PAGE_BYTES
from robotcell.view.program import write_program_view


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
@click.option("--program", "program_path", type=click.Path(dir_okay=False), default=None,
              help="A robot program to draw (KUKA .src with its .dat, ABB .mod, FANUC .ls, "
                   "YASKAWA .jbi): its path, the arm at each point on a slider, the points "
                   "'robotcell program check' finds bad marked.")
@click.option("--pulses-per-degree", "ppd", default=None, metavar="N[,N...]",
              help="With --program, YASKAWA: encoder pulses per degree of each station axis.")
@click.option("-o", "--output", required=True, type=OUTPUT,
              callback=output_of("HTML", "the view"), help="HTML file to write, atomically.")
def view(cell_path: str, joints: str | None, track_mm: float | None, table_deg: str | None,
         reach_path: str | None, tool: str | None, program_path: str | None, ppd: str | None,
         output: str) -> None:
    """Interactive 3D view of a cell: one HTML file that opens offline, with no server.

    The robot as its links and joint axes, the track and its travel, the turntable or
    positioner axes and plate, every tool and frame as a labelled triad (X red, Y green, Z
    blue) and the world axes, in mm; hover over a frame for its pose (x, y, z mm; a, b, c deg,
    R = Rz(a) Ry(b) Rx(c)). With --reach, the targets of a reachability map where the TCP
    reaches them, coloured by score. With --program, the program's path and the arm at each
    of its points (a slider and a play button), the points 'program check' finds bad (an
    unreachable one among them) marked with their problems. Refused with exit status 2: a cell
    file or program that cannot be read (a missing robot model, the program's file and line
    named), joint, track or table values outside their limits, -o onto an input file. See
    docs/view.md.

    \b
    Examples:
      robotcell view examples/cell_kr16_track_turntable.yaml --joints 0,-60,100,0,50,0 \\
          --track 1500 --table 30 -o cell.html
      robotcell view cell.yaml --reach reach.csv --tool torch -o reach3d.html
      robotcell view cell.yaml --program prog/seam_part.src -o program.html
    """
    if tool is not None and reach_path is None:
        raise InputError("--tool says which tool the --reach map was made with; give --reach")
    if ppd is not None and program_path is None:
        raise InputError("--pulses-per-degree is for a YASKAWA --program; give --program")
    if program_path is not None:
        given = [flag for flag, v in (("--joints", joints), ("--track", track_mm),
                                      ("--table", table_deg), ("--reach", reach_path)) if v is not None]
        if given:
            raise InputError(f"--program draws the arm at the program's points: leave out "
                             f"{', '.join(given)}")
        cell = load_cell(cell_path)
        pulses = None if ppd is None else parse_numbers(ppd, "--pulses-per-degree")
        try:
            made = write_program_view(cell, program_path, output, pulses)
        except InputError as exc:
            raise InputError(str(exc).replace("pulses_per_degree", "--pulses-per-degree")) from None
        rep = made.report
        arm = "every point" if made.every == 1 else (
            f"every {ordinal(made.every)} point (the page stays under {MAX_PAGE_BYTES / 1e6:g} MB)")
        click.echo(f"{made.path}: 3D view of {rep.program.name} in {cell.name}: "
                   f"{len(rep.points)} points, {len(rep.bad)} bad, the arm at {arm}; "
                   f"{made.size / 1e6:.1f} MB; open it in a browser", err=True)
        return
    cell = Cell.load(cell_path)
    every = len(cell.robots) > 1 and robot_name() is None and (joints, track_mm, reach_path) == (
        None, None, None)  # every robot at home: a robot's values need its name
    one = cell.for_robot(cell.robot_names[0] if every else robot_of(cell, cell_path))
    q = joint_option(one.robot, joints)
    e = float(track_values(one, track_mm or 0.0))
    th = table_angles(one, table_option(one, table_deg))
    if len(cell.robots) == 1 or reach_path is not None:  # a reach map: the robot that reaches
        path = write_cell_view(one, output, q, e, th, reach_path, cell_tool(tool))
    else:
        path = write_cell_view(cell, output, None if every else {one.robot_name: q},
                               {} if every else {one.robot_name: e}, th)
    click.echo(f"{path}: 3D view of {cell.name}, {path.stat().st_size / 1e6:.1f} MB; open it "
               "in a browser", err=True)
