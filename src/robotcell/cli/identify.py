"""``robotcell identify``: the kinematic model of a real arm or positioner from measurements."""

from __future__ import annotations

import json
import math
import re
import sys
from types import SimpleNamespace
from typing import Any

import click
import numpy as np

from robotcell.calibration.sigmaparts import sigma_basis
from robotcell.cell import Cell
from robotcell.cell.identified import CellRobotFile
from robotcell.cli.common import (
    as_flags,
    check_kind,
    check_not_folder,
    check_output,
    group_tolerance_option,
    parse_numbers,
    read_csv,
    warn_unknown_columns,
)
from robotcell.cli.files import NAME_OR_FILE, OUTPUT, Command, LiveChoice
from robotcell.cli.robotname import robot_name, robot_name_option, robot_of
from robotcell.controllers.registry import get
from robotcell.errors import InputError
from robotcell.identification.result import OWN_MEASUREMENTS, SIGMA_RELATIVE_TO
from robotcell.io.tables import format_table, write_csv
from robotcell.report.identification import write_identification_report
from robotcell.studies.identify import DEFAULT_FOLDS, identify_file, zero_offset_controllers
from robotcell.studies.propose import propose_configurations

#: Columns of a measurement CSV (docs/identification.md): joints ``a1..aN``, one target ``x,y,z``
#: or several ``x1,y1,z1,...``, an orientation ``qw,qx,qy,qz``.
MEASUREMENT_COLUMN = re.compile(r"a\d+|[xyz]\d*|q[wxyz]")


def _check_columns(path: str) -> None:
    """Name the columns of a measurement CSV that identify does not use, in a warning."""
    cols = read_csv(path)
    warn_unknown_columns(path, cols, [*(c for c in cols if MEASUREMENT_COLUMN.fullmatch(c)),
                                      "x", "y", "z", "qw", "qx", "qy", "qz"])


def _print_offsets(offsets: dict, vendor: str) -> None:
    z = get(vendor).zero_offsets
    click.echo(f"\n{z.heading}")
    head = ["axis", z.column, "1-sigma", "unit", "note"]
    rows = [[a["axis"], "-" if math.isnan(a["delta"]) else f"{a['delta']:+.6f}",
             "-" if math.isnan(a["sigma"]) else f"{a['sigma']:.6f}", a["unit"],
             "not determined: " + a["why"] if a["why"] else ""] for a in offsets["axes"]]
    click.echo(format_table(head, rows))
    click.echo(f"1-sigma {sigma_basis(SIGMA_RELATIVE_TO, own=OWN_MEASUREMENTS)}")


#: Range of ``--sigma`` (mm) and ``--angle-sigma`` (deg): 0.1 um (0.1 mdeg) is finer than
#: any measuring device, 1 m (1000 deg) coarser than any measurement worth a fit.
ACCURACY_MIN, ACCURACY_MAX = 1e-4, 1e3
#: Largest ``|--j23-factor|``: a J2/J3 linkage moves axis 3 by about as much as axis 2 (FANUC: 1).
J23_MAX = 10.0

def _cell_robot(cell_path: str | None) -> str | None:
    """The robot of ``--cell`` that ``--robot-name`` names (None: no cell, or its only robot)."""
    if cell_path is None:
        if robot_name() is not None:
            raise InputError("--robot-name names a robot of a cell file of several robots: "
                             "give the cell with --cell CELL.yaml")
        return None
    cell = Cell.load(cell_path)
    return robot_of(cell, cell_path) if len(cell.robots) > 1 or robot_name() else None


def _propose(o: SimpleNamespace) -> None:
    """``--propose N``: write the selected configurations (deg, mm) and print O1 against random."""
    box_m = None if o.box is None else np.array(parse_numbers(o.box, "--box", 6)) * 1e-3
    with as_flags({"n": "--propose", "n_targets": "--targets", "pose": "--orientation"}):
        prop = propose_configurations(o.propose, o.robot, o.cell_path, o.targets, o.orientation,
                                      o.seed, o.sigma * 1e-3, math.radians(o.angle_sigma), box_m,
                                      cell_robot=_cell_robot(o.cell_path))
    n, output, as_json = o.propose, o.output, o.as_json
    nominal, sel = prop.robot, prop.selection
    q = np.where(nominal.prismatic, sel.q * 1e3, np.degrees(sel.q))
    header = [f"a{i}" for i in range(1, nominal.n_joints + 1)]
    if output is not None:
        write_csv(output, header, q)
    rand = sel.o1_random
    if as_json:
        data = {"robot": nominal.name, "o1": sel.o1, "o1_random": rand.tolist(),
                "work_volume": prop.volume.description}
        if output is None:
            data["configurations"] = q.tolist()
        click.echo(json.dumps(data))
        return
    if output is None:
        write_csv(sys.stdout, header, q)
    click.echo(f"observability O1 of the {n} proposed configurations: {sel.o1:.4g}; {len(rand)} "
               f"random sets within the joint limits with the flange and the reflectors "
               f"{prop.volume.description}: median {np.median(rand):.4g}, best "
               f"{rand.max():.4g} ({(sel.o1 / rand.max() - 1) * 100:+.0f} % over the best)",
               err=output is None)
    if output is not None:
        cols = "x,y,z" if o.targets == 1 else "x1,y1,z1,x2,..."
        cols += ",qw,qx,qy,qz" if o.orientation else ""
        click.echo(f"configurations written to {output} (a1..a{nominal.n_joints}, deg; mm for "
                   f"prismatic joints); measure them and add the columns {cols}")


@click.command(cls=Command)
@click.argument("measurements", type=click.Path(), required=False)
@click.option("--robot", "robot", type=NAME_OR_FILE, help="Nominal model: library name or model file. Without it the "
              "circle point analysis builds the start model (rows moving one joint at a time).")
@click.option("-o", "--output", "output", type=OUTPUT, callback=check_output,
              help="Write the identified model file (YAML), atomically; with --propose, the "
              "proposed configurations (CSV).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object instead of the report.")
@click.option("--j23-factor", "j23", type=float, help="J2/J3 coupling k: q3_model = J3 + k * J2 "
              "(FANUC: 1, as the ROS-Industrial driver's J23_factor; docs/robots.md). The report "
              "compares the fits with it, without it and with k fitted, in mm.")
@click.option("--sigma", "--accuracy", "sigma", type=float, default=0.05, show_default=True,
              help="Accuracy of a measured coordinate, 1-sigma (mm); --accuracy is an alias.")
@click.option("--angle-sigma", "--angle-accuracy", "angle_sigma", type=float, default=0.02,
              show_default=True, help="Accuracy of a measured orientation, 1-sigma (deg); "
              "--angle-accuracy is an alias.")
@click.option("--scale", "scale", is_flag=True, help="Also identify a scale error (gear ratio) per axis.")
@click.option("--compliance", "compliance", is_flag=True, help="Also identify the gravity compliance "
              "of axes 2 and 3 (needs the link masses: joint keys mass, com in the model file).")
@click.option("--force", "force", is_flag=True, help="Write -o even when the verdict is poor.")
@click.option("--folds", "folds", type=click.IntRange(min=0), default=DEFAULT_FOLDS,
              show_default=True, help="K-fold cross-validation: every row predicted by the models "
              "identified without it (mean, RMS, max of the start model and the identified one); "
              "constants are freed only as far as they predict held-out rows better than the "
              "start model. 0: none (every identifiable constant freed, unchecked).")
@click.option("--report", "report", type=OUTPUT, callback=check_not_folder, help="Also write a "
              "self-contained HTML report (figures embedded).")
@click.option("--offsets-for", "offsets_for", type=LiveChoice(zero_offset_controllers), help="Also print "
              "the identified joint zero offsets for the controller: KUKA $MAMES corrections (deg), "
              "ABB arm-side offsets (rad). Needs --robot.")
@click.option("--propose", "propose", type=int, metavar="N", help="Instead of identifying: propose "
              "N configurations within the joint limits of --robot and the work volume (--box) "
              "that maximise the observability O1; CSV a1..aN (deg, mm) to -o or standard "
              "output.")
@click.option("--targets", "targets", type=int, default=1, show_default=True,
              help="With --propose: reflectors measured per configuration.")
@click.option("--orientation", "orientation", is_flag=True,
              help="With --propose: the orientation is measured too (6D probe, camera).")
@click.option("--seed", "seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="With --propose: seed of the random candidates and comparison sets.")
@click.option("--box", "box", metavar="XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX",
              help="With --propose: keep the flange and the reflectors inside this box (mm, "
                   "robot base frame); default above the floor: z >= 0 of the cell's world "
                   "with --cell, else of the robot base.")
@click.option("--cell", "cell_path", type=click.Path(dir_okay=False),
              help="Also make the identified model (-o) the arm of this cell file "
                   "(robot.identified), with the identification's time, RMS and held-out error "
                   "(--folds); its robot.model is the nominal when --robot is not given. "
                   "With --propose: its robot.model and its floor.")
@group_tolerance_option("Joint values")
@robot_name_option
def identify(measurements: str | None, **options: Any) -> None:
    """Identify the kinematic parameters of an arm or positioner from measurements.

    MEASUREMENTS.csv has joint values a1..aN (deg, mm for prismatic joints), the measured target
    x,y,z (mm, in the measuring device's frame) or several x1,y1,z1,x2,y2,z2,..., and with one
    target optionally its orientation qw,qx,qy,qz. See docs/identification.md.

    A K-fold cross-validation (--folds, default 5) predicts every row by the start and the
    identified model fitted without it; when freeing every constant predicts held-out rows worse
    than the start, fewer constants (chosen by the same cross-validation) or none are freed.
    The report states the predicted error of a position (1-sigma per axis, 3D RMS, 95 % radius)
    and the model error the fit cannot explain. --report FILE.html writes the report as one
    HTML page with figures (errors before and after, cross-validation, parameters,
    correlations, observability of the measured configurations against random ones).

    Exit status: 0 identified; 2 refused input (reason on stderr); 3 poor result (the model
    file is not written unless --force), e.g. a nominal model the data contradict (a constant
    moved more than 20 mm or 2 deg).

    --propose N (no MEASUREMENTS) proposes N configurations to measure instead: those that
    maximise Borm and Menq's observability index O1 for --robot (or the cell's robot), compared
    with random sets, all within the joint limits with the flange and the reflectors inside
    --box, or above the floor.

    \b
    Examples:
      robotcell identify tracker.csv --robot kuka_kr16 -o kr16_identified.yaml
      robotcell identify tracker.csv --robot fanuc_m20ia --j23-factor 1 --json
      robotcell identify --propose 30 --robot kuka_kr16 --targets 3 -o to_measure.csv
    """
    o = SimpleNamespace(**options)
    _check_numbers(o)
    if o.propose is not None:
        if measurements is not None:
            raise InputError("--propose N writes configurations to measure; give no MEASUREMENTS.csv")
        if o.robot is None and o.cell_path is None:
            raise InputError("--propose needs --robot NOMINAL (library name or model file) or "
                             "--cell CELL.yaml (its robot.model)")
        check_kind(o.output, "CSV", "the proposed configurations")
        return _propose(o)
    if o.box is not None:
        raise InputError("--box goes with --propose: where the proposed configurations may put "
                         "the flange and the reflectors")
    if measurements is None:
        raise InputError("give MEASUREMENTS.csv (or --propose N --robot NOMINAL to plan them)")
    check_kind(o.output, "YAML", "the identified model file")
    if o.cell_path is not None and o.output is None:
        raise InputError("--cell needs -o FILE.yaml: the identified model file the cell will name")
    if o.offsets_for is not None and o.robot is None:
        raise InputError("--offsets-for needs --robot NOMINAL: the offsets correct the nominal model "
                         "the controller uses")
    _check_columns(measurements)
    _identify(measurements, o)


def _check_numbers(o: SimpleNamespace) -> None:
    """Refuse accuracies and a J2/J3 factor outside what a measurement can mean."""
    for name, value, unit in (("--sigma", o.sigma, "mm"), ("--angle-sigma", o.angle_sigma, "deg")):
        if not ACCURACY_MIN <= value <= ACCURACY_MAX:
            raise InputError(f"{name} must be a positive number of {unit} from {ACCURACY_MIN:g} "
                             f"to {ACCURACY_MAX:g}, got {value:g}")
    if o.j23 is not None and not abs(o.j23) <= J23_MAX:
        raise InputError(f"--j23-factor must be a finite number from -{J23_MAX:g} to {J23_MAX:g} "
                         f"(a linkage's ratio; FANUC: 1), got {o.j23:g}")


def _identify(measurements: str, o: SimpleNamespace) -> None:
    """Identify from ``measurements``, write what the options ask for and print the report."""
    report, output, cell_path, as_json = o.report, o.output, o.cell_path, o.as_json
    name = _cell_robot(cell_path)
    where = None if cell_path is None else CellRobotFile(cell_path, name)
    with as_flags({"the nominal model as robot": "the nominal model with --robot",
                   "folds=0": "--folds 0", "folds": "--folds",
                   "state the grouping tolerance": "state it with --group-tolerance"}):
        run = identify_file(
            measurements, o.robot, where, folds=o.folds, report=report is not None,
            offsets_for=o.offsets_for, output=output, force=o.force, sigma=o.sigma * 1e-3,
            angle_sigma=math.radians(o.angle_sigma), scale=o.scale, compliance=o.compliance,
            j23_factor=o.j23,
            group_tol=None if o.group_tolerance is None else math.radians(o.group_tolerance))
    if report is not None:
        write_identification_report(run.result, report, run.cross, run.observability,
                                    run.measurements)
    result, cv, offsets = run.result, run.cross_stats, run.offsets
    verdict, why = result.verdict
    if as_json:
        click.echo(json.dumps(run.to_json()))
    else:
        click.echo(result.summary())
        if offsets is not None:
            _print_offsets(offsets, o.offsets_for)
        if cv is not None:
            click.echo(f"cross-validation, {run.folds} folds (held-out rows, mm): start model mean "
                       f"{cv['before_mean_mm']:.4f} RMS {cv['before_rms_mm']:.4f} max "
                       f"{cv['before_max_mm']:.4f}; identified mean {cv['after_mean_mm']:.4f} RMS "
                       f"{cv['after_rms_mm']:.4f} max {cv['after_max_mm']:.4f}")
            click.echo(run.choice.sentence())
    if run.written and not as_json:
        click.echo(f"identified model written to {output}"
                   + (f"; {cell_path} computes with it (robot.identified)" if cell_path else ""))
    if report is not None and not as_json:
        click.echo(f"report written to {report}")
    if verdict == "poor":
        kept = (" (written anyway: --force)" if output and o.force
                else (" (model file not written)" if output else ""))
        click.echo(f"poor result: {why}{kept}", err=True)
        sys.exit(3)
