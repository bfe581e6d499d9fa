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
from robotcell.errors import InputError
from robotcell.kinematics.robot import Robot
from robotcell.view.cellscene import cell_figure
from robotcell.view.plot import write_html
from robotcell.view.reach import read_reach


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
@click.argument("cell_path", metavar="CELL.yaml", type=click.Path(dir_okay=False))
@click.option("--joints", default=None, metavar="A1,A2,...",
              help="Arm axis values (deg; mm for a prismatic axis); default the robot model's "
                   "home configuration, else 0.")
@click.option("--track", "track_mm", type=float, default=0.0, metavar="MM",
              help="Track position (mm).")
@click.option("--table", "table_deg", default=None, metavar="DEG[,DEG...]",
              help="Turntable angle (deg), or one value per positioner axis; default 0.")
@click.option("--reach", "reach_path", type=click.Path(dir_okay=False), default=None,
              help="A reachability map to draw: the CSV of 'robotcell reach -o'.")
@click.option("--tool", default=None,
              help="With --reach: the tool the map was made with (a tool of the cell, or "
                   "X,Y,Z,A,B,C in mm, deg); default the robot model's tool.")
@click.option("-o", "--output", required=True, type=OUTPUT,
              callback=output_of("HTML", "the view"), help="HTML file to write, atomically.")
def view(cell_path: str, joints: str | None, track_mm: float, table_deg: str | None,
         reach_path: str | None, tool: str | None, output: str) -> None:
    """Interactive 3D view of a cell: one HTML file that opens offline, with no server.

    The robot as its links and joint axes, the track and its travel, the turntable or
    positioner axes and plate, every tool and frame as a labelled triad (X red, Y green, Z
    blue) and the world axes, in mm; hover over a frame for its pose (x, y, z mm; a, b, c deg,
    R = Rz(a) Ry(b) Rx(c)). With --reach, the targets of a reachability map where the TCP
    reaches them, coloured by score. Refused with exit status 2: a cell file that cannot be
    read (a missing robot model), joint, track or table values outside their limits, -o onto
    an input file. See docs/view.md.

    \b
    Examples:
      robotcell view examples/cell_kr16_track_turntable.yaml --joints 0,-60,100,0,50,0 \\
          --track 1500 --table 30 -o cell.html
      robotcell view cell.yaml --reach reach.csv --tool torch -o reach3d.html
    """
    if tool is not None and reach_path is None:
        raise InputError("--tool says which tool the --reach map was made with; give --reach")
    cell = Cell.load(cell_path)
    q = joint_option(cell.robot, joints)
    e = float(track_values(cell, track_mm))
    th = table_angles(cell, table_option(cell, table_deg))
    reach = read_reach(reach_path, cell) if reach_path is not None else None
    fig = cell_figure(cell, q, e, th, reach, cell_tool(tool))
    path = write_html(fig, output, title=f"{cell.name}: robotcell view")
    click.echo(f"{path}: 3D view of {cell.name}, {path.stat().st_size / 1e6:.1f} MB; open it "
               "in a browser", err=True)
