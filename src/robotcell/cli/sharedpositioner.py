"""``robotcell calibrate shared-positioner``: one 2-axis positioner, two robots of a cell.

Reads each robot's touches of its point on the positioner's plate and both robots' touches of
common points, and prints the comparison of the two robots' calibrations of the positioner
(through the robot-to-robot pose) and the fit of all touches at once
(:func:`robotcell.cell.calibrate.sharedpositioner.shared_positioner`). Registered in
:data:`robotcell.cli.calibrate.REGISTERED` (see ``docs/calibration.md``, "One positioner, two
robots").
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import click

from robotcell.cell import Cell
from robotcell.cell.calibrate.robottorobot import RobotTouchFile
from robotcell.cell.calibrate.sharedpositioner import shared_positioner
from robotcell.cli.calibrate import (
    PoorCalibration,
    echo_note,
    emit,
    gate,
    result_options,
    sigma_m,
)
from robotcell.cli.files import Command
from robotcell.errors import InputError


@dataclass(frozen=True)
class _Given:
    """The options of ``calibrate shared-positioner`` besides the files and the output."""

    common: tuple[str, str]
    cell_path: str
    robot: str
    reference_robot: str
    tool_ref: str
    tool_other: str
    track_ref: float
    track_other: float
    sigma: float | None
    tool_sigma: float | None


@click.command("shared-positioner", cls=Command)
@click.argument("reference", type=click.Path(dir_okay=False))
@click.argument("other", type=click.Path(dir_okay=False))
@click.option("--common", required=True, nargs=2, type=click.Path(dir_okay=False),
              metavar="REF.csv OTHER.csv",
              help="Both robots' touches of the common points (as for calibrate robot-to-robot).")
@click.option("--cell", "cell_path", required=True, type=click.Path(dir_okay=False),
              help="A cell of several robots sharing a 2-axis positioner: the robots' models "
                   "and tools, and the positioner's nominal chain.")
@click.option("--robot", required=True, metavar="NAME", help="The robot of OTHER.")
@click.option("--reference", "reference_robot", required=True, metavar="NAME",
              help="The robot of REFERENCE, the base the results are in.")
@click.option("--tool-ref", required=True, metavar="NAME",
              help="The tool of the cell the reference robot touched with.")
@click.option("--tool-other", required=True, metavar="NAME",
              help="The tool of the cell the other robot touched with.")
@click.option("--track-ref", type=float, default=0.0, show_default=True, metavar="MM",
              help="The reference robot's track position during all its touches (mm).")
@click.option("--track-other", type=float, default=0.0, show_default=True, metavar="MM",
              help="The other robot's track position during all its touches (mm).")
@click.option("--sigma", type=float, default=None, metavar="MM",
              help="Touch-up accuracy of both robots, 1-sigma per coordinate (mm; default 0.5).")
@click.option("--tool-sigma", type=float, default=None, metavar="MM",
              help="Accuracy of both tools' TCP, 1-sigma per coordinate (mm); default 1 mm, "
                   "reported as assumed.")
@result_options
@click.option("--accept-poor", is_flag=True,
              help="Print and write -o even when the calibrations disagree or the verdict is "
                   "poor (exit 0).")
def calibrate_shared_positioner(reference: str, other: str, as_json: bool, accept_poor: bool,
                                **options: Any) -> None:
    """A 2-axis positioner two robots calibrated: compared, and all touches in one fit.

    \b
    REFERENCE.csv and OTHER.csv: each robot's touches of its point on the positioner's plate,
    joint values a1..a6 (deg) and the axis values e1 (tilt), e2 (rotate) (deg), as for
    calibrate positioner. --common: both robots' touches of common points, as for calibrate
    robot-to-robot. Each robot touches everything at one track position. Prints the two
    calibrations compared through the robot-to-robot pose (a disagreement named in mm, deg and
    sigma, exit status 3) and the fit of all touches (the other robot's base and the
    positioner's axes in the reference robot's base). Writes nothing into the cell.

    \b
    Example (on the files of 'robotcell demo --robots 2'):
      robotcell calibrate shared-positioner robotcell-demo-2/positioner_kuka.csv robotcell-demo-2/positioner_abb.csv --common robotcell-demo-2/robot_to_robot_kuka.csv robotcell-demo-2/robot_to_robot_abb.csv --cell robotcell-demo-2/cell.yaml --reference kuka --robot abb --tool-ref torch --tool-other torch --track-ref 1000 --sigma 0.1 --tool-sigma 0.128
    """
    given = _Given(**options)
    if given.tool_sigma is not None and not 0 < given.tool_sigma <= 1000:
        raise InputError(f"--tool-sigma must be a positive number of millimetres up to 1000, "
                         f"got {given.tool_sigma:g}")
    cell = Cell.load(given.cell_path)
    ref = RobotTouchFile(given.reference_robot, given.common[0], given.tool_ref.strip(),
                         given.track_ref * 1e-3)
    oth = RobotTouchFile(given.robot, given.common[1], given.tool_other.strip(),
                         given.track_other * 1e-3)
    done = shared_positioner(cell, (ref, oth), (reference, other), sigma=sigma_m(given.sigma),
                             tool_sigma=None if given.tool_sigma is None
                             else given.tool_sigma * 1e-3, on_note=echo_note)
    gate(done.joint, as_json, accept_poor)
    if not done.agreement.agree and not accept_poor:
        click.echo(done.joint.summary())
        raise PoorCalibration(f"{done.agreement.message}. Nothing written; pass --accept-poor "
                              "to use the fit anyway")
    if not as_json:
        click.echo(done.agreement.message)
    emit(replace(done.joint, warnings=done.joint.warnings + (
        [] if done.agreement.agree else [done.agreement.message])), as_json)
