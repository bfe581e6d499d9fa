"""``robotcell export``: controller data for the tools and frames of a cell."""

from __future__ import annotations

import click

from robotcell.cell import Cell
from robotcell.cli.common import check_kind, check_output, write_output
from robotcell.cli.files import OUTPUT, Command, LiveChoice, refuse_overwriting_inputs
from robotcell.cli.robotname import robot_name_option, robot_of
from robotcell.export import (
    URDF,
    export_cell,
    export_files,
    other_kinds,
    output_ending,
    ur_kinematics_path,
    write_formats,
)


@click.command(cls=Command)
@robot_name_option
@click.option("--cell", "cell_path", required=True, type=click.Path(dir_okay=False),
              help="Cell file (YAML, mm/deg).")
@click.option("--format", "fmt", required=True, type=LiveChoice(write_formats),
              help="Controller format.")
@click.option("-o", "--output", "output", type=OUTPUT, callback=check_output,
              help="File to write, atomically (default: standard output).")
def export(cell_path: str, fmt: str, output: str | None) -> None:
    """Write what to paste into the controller: tools, bases/work objects/user frames and the
    placement of the robot, the track and the turntable (mm, deg; see docs/export.md).

    \b
    kuka     $config.dat TOOL_DATA/BASE_DATA/MACHINE_DEF and $machine.dat $ROBROOT/$ERSYSROOT
    abb      RAPID module: tooldata, wobjdata, base frames as pose
    fanuc    UTOOL/UFRAME values for Direct Entry (X Y Z W P R)
    yaskawa  TOOL/UFRAME values for the pendant (X Y Z Rx Ry Rz)
    ur       URScript: set_tcp of each tool, each frame as a feature pose in the robot
             base (m, rotation vector in rad); no track or turntable
    urdf     the calibrated cell as a URDF tree for ROS tools (m, rad): robot, track and
             turntable joints, tools and frames as fixed links; the identified arm where the
             cell has one, and for a Universal Robots arm also OUT_kinematics.yaml, the UR
             description's calibration file (with -o; axis scales it cannot hold are left
             out with a warning)

    \b
    Examples:
      robotcell export --cell cell.yaml --format kuka
      robotcell export --cell cell.yaml --format abb -o cell_frames.mod
    """
    check_kind(output, "URDF" if fmt == URDF else "text", f"the {fmt} export",
               named=other_kinds(fmt), ending=output_ending(fmt))
    cell = Cell.load(cell_path)  # the URDF holds every robot, a controller's export its own
    robot = None if fmt == URDF else robot_of(cell, cell_path)
    if output is None:
        write_output(None, export_cell(cell, fmt, robot))
        return
    if fmt == URDF:
        refuse_overwriting_inputs(click.get_current_context(),
                                  [("the UR calibration file written next to -o",
                                    str(ur_kinematics_path(output)))])
    done = export_files(cell, fmt, output, robot)
    for f in done.files:
        click.echo(f"wrote {f}", err=True)
    for w in done.warnings:
        click.echo(f"warning: {w}", err=True)
