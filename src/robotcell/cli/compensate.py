"""``robotcell compensate``: the poses to command so that the identified arm reaches the desired ones."""

from __future__ import annotations

import json
import sys

import click
import numpy as np

from robotcell.cli.common import (
    MAX_CORRECTION_MM,
    BadPoints,
    as_flags,
    counted,
    format_table,
    in_range,
    output_of,
)
from robotcell.cli.files import OUTPUT, Command
from robotcell.cli.robotname import load_cell, robot_name_option


@click.command(cls=Command)
@click.argument("poses", type=click.Path(dir_okay=False))
@click.option("--cell", "cell_path", required=True, type=click.Path(dir_okay=False),
              help="Cell file (YAML, mm/deg) whose robot has an identified arm (robot.identified).")
@click.option("--tool", required=True, help="Tool of the cell.")
@click.option("--frame", default="world", show_default=True,
              help="Frame of the poses: world or a frame of the cell.")
@click.option("-o", "--output", "output", type=OUTPUT,
              callback=output_of("CSV", "the commanded poses"),
              help="CSV of the poses to command, atomically (default: standard output).")
@click.option("--max-correction", "max_correction", type=float, default=5.0, show_default=True,
              callback=in_range(*MAX_CORRECTION_MM, "mm"),
              help="Largest correction taken (mm); above it the identified model is wrong.")
@click.option("--report", "report", type=OUTPUT, callback=output_of("HTML", "the accuracy report"),
              help="Also write an HTML page: predicted error without filtering and 1-sigma "
                   "after, per pose.")
@click.option("--json", "as_json", is_flag=True,
              help='Print {"points": [{"x": .., "a1": .., "shoulder": .., "branch": .., "dpos": .., '
                   '"error_mm": .., "sigma_mm": ..}, ...], "configuration": ..}.')
@robot_name_option
def compensate(poses: str, cell_path: str, tool: str, frame: str, output: str | None,
               max_correction: float, report: str | None, as_json: bool) -> None:
    """Filter POSES (CSV: x, y, z mm and a, b, c deg in --frame; optional track mm, table or
    e1..en deg; optional configuration columns) through the cell's identified arm: for each
    desired pose, the pose to tell the controller, whose nominal model then moves the real arm
    onto it (docs/accuracy.md).

    The configuration is the nominal arm's solution nearest to the robot's home, unless columns
    say which: a controller's flags (s, t; cf1, cf4, cf6, cfx; config), or the solver's own
    flags shoulder, elbow, wrist (0 or 1; every arm type, a Universal Robots arm too), and/or
    reference joints near_a1..near_a6 (deg; the solution nearest them, as a UR controller's
    qnear). The output has x, y, z, a, b, c (the pose to command), a1..a6 (the controller's
    joints, deg), shoulder, elbow, wrist (their configuration), the external axes, dpos (mm) and
    drot (deg), the size of the correction.

    Exit status 0 when done; 2 for refused input; 3 when a pose cannot be filtered (out of the
    identified arm's reach in its configuration, or a correction above --max-correction: a wrong
    model), with a table naming each; nothing is written then.

    \b
    Example:
      robotcell compensate examples/seam_part.csv --cell cell.yaml --tool torch --frame part -o commanded.csv
    """
    from robotcell.accuracy.filter import FilterRefused, sigma_text
    from robotcell.accuracy.poses import compensate_poses
    from robotcell.report.accuracy import write_poses_report

    cell = load_cell(cell_path)
    try:
        with as_flags({"max_correction": "--max-correction"}):
            result = compensate_poses(poses, cell, tool, frame, output, max_correction * 1e-3)
    except FilterRefused as exc:
        click.echo(format_table(["pose", "why"], [list(p) for p in exc.points]), err=True)
        raise BadPoints(f"{poses}: {exc}") from None
    if report is not None:
        write_poses_report(report, poses, result)
    for w in result.warnings:
        click.echo(f"warning: {w}", err=True)
    if as_json:
        click.echo(json.dumps(result.to_json(), indent=2))
    elif output is None:
        result.write(sys.stdout)
    data = result.to_json()
    if not as_json:
        sigma = data["max_sigma_mm"]
        click.echo(f"{len(result.rows)} poses filtered: largest correction "
                   f"{data['max_dpos_mm']:.4f} mm; predicted error without filtering up to "
                   f"{data['max_error_mm']:.4f} mm"
                   + (f", after filtering 3D RMS error up to {sigma:.4f} mm and 95 % radius up "
                      f"to {data['max_radius95_mm']:.4f} mm ({sigma_text()})"
                      if sigma is not None else "") + f"; configurations: {_configurations(result)}"
                   + (f"; wrote {output}" if output else ""), err=output is None)


def _configurations(result) -> str:
    """``shoulder 1, elbow 0, wrist 0 (17 poses), ... (chosen by ...)``."""
    flags, counts = np.unique(result.result.flags, axis=0, return_counts=True)
    parts = [f"shoulder {f[0]}, elbow {f[1]}, wrist {f[2]} ({counted(int(c), 'pose')})"
             for f, c in zip(flags, counts)]
    return "; ".join(parts) + f" (chosen {result.chosen_by})"
