"""``robotcell calibrate shared-positioner``: one 2-axis positioner, two robots of a cell.

Reads each robot's touches of its point on the positioner's plate and both robots' touches of
common points, and prints the comparison of the two robots' calibrations of the positioner
(through the robot-to-robot pose) and the fit of all touches at once
(:func:`robotcell.cell.calibrate.sharedpositioner.shared_positioner`); with ``--update-cell`` it
writes that fit into the cell file
(:func:`robotcell.cell.calibrate.sharedpositioner.place_shared_positioner`). Registered in
:data:`robotcell.cli.calibrate.REGISTERED` (see ``docs/calibration.md``, "One positioner, two
robots").
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import click
import numpy as np

from robotcell.cell import Cell
from robotcell.cell.calibrate.robottorobot import RobotTouchFile
from robotcell.cell.calibrate.sharedpositioner import (
    SharedPositioner,
    place_shared_positioner,
    shared_positioner,
)
from robotcell.cell.update import update_cell_file
from robotcell.cli.calibrate import (
    OUTPUT_KEY,
    PoorCalibration,
    echo_note,
    emit,
    gate,
    result_options,
    sigma_m,
)
from robotcell.cli.files import Command
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_to_vendor


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
    update_cell: bool

    @property
    def tool_sigma_m(self) -> float | None:
        """``--tool-sigma`` in metres."""
        return None if self.tool_sigma is None else self.tool_sigma * 1e-3

    def touches(self, reference: str, other: str
                ) -> tuple[tuple[RobotTouchFile, RobotTouchFile], tuple[str, str]]:
        """Both robots' touches of the common points, and their plate files."""
        return ((RobotTouchFile(self.reference_robot, self.common[0], self.tool_ref.strip(),
                                self.track_ref * 1e-3),
                 RobotTouchFile(self.robot, self.common[1], self.tool_other.strip(),
                                self.track_other * 1e-3)), (reference, other))


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
@click.option("--update-cell", is_flag=True,
              help="Write the fit of all touches into the --cell file: the positioner's root "
                   "and axes and the other robot's base (only when the calibrations agree and "
                   "the verdict is not poor, unless --accept-poor).")
@result_options
@click.option("--accept-poor", is_flag=True,
              help="Print, write -o and the cell even when the calibrations disagree or the "
                   "verdict is poor (exit 0).")
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
    positioner's axes in the reference robot's base). With --update-cell that fit is written
    into the cell file: the positioner's root and axes, and the other robot's base (for a
    robot on a track: at track 0); a disagreement or a poor verdict writes nothing.

    \b
    Example (on the files of 'robotcell demo --robots 2'):
      robotcell calibrate shared-positioner robotcell-demo-2/positioner_kuka.csv robotcell-demo-2/positioner_abb.csv --common robotcell-demo-2/robot_to_robot_kuka.csv robotcell-demo-2/robot_to_robot_abb.csv --cell robotcell-demo-2/cell.yaml --reference kuka --robot abb --tool-ref torch --tool-other torch --track-ref 1000 --sigma 0.1 --tool-sigma 0.128
    """
    given = _Given(**options)
    if given.tool_sigma is not None and not 0 < given.tool_sigma <= 1000:
        raise InputError(f"--tool-sigma must be a positive number of millimetres up to 1000, "
                         f"got {given.tool_sigma:g}")
    common, plate = given.touches(reference, other)

    def calibrated(cell: Cell) -> SharedPositioner:
        done = shared_positioner(cell, common, plate, sigma=sigma_m(given.sigma),
                                 tool_sigma=given.tool_sigma_m, on_note=echo_note)
        gate(done.joint, as_json, accept_poor)
        if not done.agreement.agree and not accept_poor:
            click.echo(done.joint.summary())
            raise PoorCalibration(f"{done.agreement.message}. Nothing written; pass "
                                  "--accept-poor to use the fit anyway")
        return done

    if not given.update_cell:
        done = calibrated(Cell.load(given.cell_path))
    else:
        output = click.get_current_context().meta.get(OUTPUT_KEY)
        if output is not None and Path(output).resolve() == Path(given.cell_path).resolve():
            raise InputError(f"-o {output} is the cell file; name another file for the result")

        def change(cell: Cell) -> tuple[Cell, SharedPositioner]:
            d = calibrated(cell)
            return place_shared_positioner(cell, d, common, plate, tool_sigma=given.tool_sigma_m,
                                           accept_poor=accept_poor), d

        written = update_cell_file(given.cell_path, change, on_note=echo_note)
        done = written.value
        assert written.cell is not None
        _echo_written(given, written.cell, done, written.backup)
    if not as_json:
        click.echo(done.agreement.message)
    emit(replace(done.joint, warnings=done.joint.warnings + (
        [] if done.agreement.agree else [done.agreement.message])), as_json)


def _numbers(values: np.ndarray, decimals: int) -> str:
    return ", ".join(f"{v:.{decimals}f}" for v in values)


def _echo_written(given: _Given, cell: Cell, done: SharedPositioner, backup: Path | None) -> None:
    """What the cell file now holds (stderr): the positioner's root and the other robot's base
    in the world, KUKA X,Y,Z mm and A,B,C deg, each with the fit's 1-sigma (relative to the
    reference robot's base)."""
    assert cell.turntable is not None
    kept = f" (previous version: {backup})" if backup is not None else ""
    unit = cell.robots[cell.robot_key(given.robot)]
    base = unit.T_world_R if unit.track is None else unit.track.T_world_L @ unit.track.T_L_R0
    s = done.joint.sigma
    rows = [(f"positioner {cell.turntable.name!r} root (T_world_0)", cell.turntable.chain.base,
             "T_ref_B"),
            (f"base of robot {given.robot!r} ("
             + ("T_world_R" if unit.track is None else "T_world_R at track 0") + ")", base,
             "T_ref_other")]
    lines = [(f"updated {given.cell_path}: positioner {cell.turntable.name!r} (root, axes) and "
              f"the base of robot {given.robot!r} from the fit of all touches{kept}")]
    for what, T, key in rows:
        v = pose_to_vendor(T, "kuka")
        lines.append(f"  {what}, X,Y,Z mm / A,B,C deg: {_numbers(v[:3], 3)} / "
                     f"{_numbers(v[3:], 4)}; 1-sigma relative to the base of robot "
                     f"{given.reference_robot!r}: "
                     f"{_numbers(np.asarray(s[key + '_position']) * 1e3, 3)} / "
                     f"{_numbers(np.degrees(s[key + '_rotation']), 4)}")
    lines.append(f"  distance between the axes {done.joint.values['axis_offset'] * 1e3:.3f} mm "
                 f"(1-sigma {s['axis_offset'] * 1e3:.3f}), angle between them "
                 f"{np.degrees(done.joint.values['axis_angle']):.4f} deg (1-sigma "
                 f"{np.degrees(s['axis_angle']):.4f})")
    click.echo("\n".join(lines), err=True)
