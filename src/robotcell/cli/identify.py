"""``robotcell identify``: the kinematic model of a real arm or positioner from measurements."""

from __future__ import annotations

import json
import math
import sys

import click

from robotcell.cli.common import check_output
from robotcell.identification import identify as run_identify
from robotcell.identification import identify_with_coupling, read_measurements
from robotcell.identification.circles import first_estimate
from robotcell.identification.validation import cross_validate
from robotcell.kinematics.models import load_robot, save_robot


@click.command()
@click.argument("measurements", type=click.Path())
@click.option("--robot", "robot", help="Nominal model: library name or model file. Without it the "
              "circle point analysis builds the start model (rows moving one joint at a time).")
@click.option("-o", "--output", "output", type=click.Path(), callback=check_output,
              help="Write the identified model file (YAML), atomically.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object instead of the report.")
@click.option("--j23-factor", "j23", type=float, help="J2/J3 coupling k: q3_model = J3 + k * J2 "
              "(FANUC: -1). The report says whether the data support it.")
@click.option("--accuracy", "accuracy", type=float, default=0.05, show_default=True,
              help="Accuracy of a measured coordinate (mm).")
@click.option("--angle-accuracy", "angle_accuracy", type=float, default=0.02, show_default=True,
              help="Accuracy of a measured orientation (deg).")
@click.option("--scale", "scale", is_flag=True, help="Also identify a scale error (gear ratio) per axis.")
@click.option("--force", "force", is_flag=True, help="Write -o even when the verdict is poor.")
@click.option("--folds", "folds", type=int, help="Also K-fold cross-validate: every row predicted "
              "by the models identified without it (mean, RMS, max before and after).")
def identify(measurements: str, robot: str | None, output: str | None, as_json: bool,
             j23: float | None, accuracy: float, angle_accuracy: float, scale: bool, force: bool,
             folds: int | None) -> None:
    """Identify the kinematic parameters of an arm or positioner from measurements.

    MEASUREMENTS.csv has joint values a1..aN (deg, mm for prismatic joints), the measured target
    x,y,z (mm, in the measuring device's frame) or several x1,y1,z1,x2,y2,z2,..., and with one
    target optionally its orientation qw,qx,qy,qz. See docs/identification.md.

    --folds K adds a K-fold cross-validation: every row predicted by the nominal and the
    identified model fitted without it.

    Exit status: 0 identified; 2 refused input (reason on stderr); 3 poor result (the model
    file is not written unless --force).

    \b
    Examples:
      robotcell identify tracker.csv --robot kuka_kr16 -o kr16_identified.yaml
      robotcell identify tracker.csv --robot fanuc_m20ia --j23-factor -1 --json
    """
    options = {"point_sigma": accuracy * 1e-3, "angle_sigma": math.radians(angle_accuracy), "scale": scale}
    if robot is not None:
        nominal = load_robot(robot)
        meas = read_measurements(measurements, nominal.prismatic)
    else:
        nominal, meas = first_estimate(measurements)
    if j23 is not None:
        result = identify_with_coupling(nominal, meas, j23, **options)
    else:
        result = run_identify(nominal, meas, **options)
    verdict, why = result.verdict
    cv = None
    if folds is not None:
        if j23 is not None:
            options["coupling"] = j23
        cv = cross_validate(nominal, meas, folds=folds, **options).stats()
    if as_json:
        data = result.to_json()
        if cv is not None:
            data["cross_validation"] = {"folds": folds, **cv}
        click.echo(json.dumps(data))
    else:
        click.echo(result.summary())
        if cv is not None:
            click.echo(f"cross-validation, {folds} folds (held-out rows, mm): nominal mean "
                       f"{cv['before_mean_mm']:.4f} RMS {cv['before_rms_mm']:.4f} max "
                       f"{cv['before_max_mm']:.4f}; identified mean {cv['after_mean_mm']:.4f} RMS "
                       f"{cv['after_rms_mm']:.4f} max {cv['after_max_mm']:.4f}")
    if output is not None and (verdict != "poor" or force):
        save_robot(result.robot, output)
        if not as_json:
            click.echo(f"identified model written to {output}")
    if verdict == "poor":
        kept = " (written anyway: --force)" if output and force else (" (model file not written)" if output else "")
        click.echo(f"poor result: {why}{kept}", err=True)
        sys.exit(3)
