"""``robotcell calibrate``, ``simulate`` and ``plan robot-to-robot``.

``calibrate robot-to-robot REF.csv OTHER.csv`` reads the touches of two robots (mm, deg; column
``point`` names the common point of every touch) and prints the pose of the other robot's base in
the reference robot's base (KUKA X,Y,Z,A,B,C in mm and deg) with the report, or ``--json``.
``simulate robot-to-robot`` writes such a pair of files for two arms of the robot library at a
stated pose. ``plan robot-to-robot`` proposes where to put the common points in a cell of
several robots. Registered in :data:`robotcell.cli.calibrate.REGISTERED` and dispatched by
:class:`robotcell.cli.simulate` and :class:`robotcell.cli.plan` (see ``docs/calibration.md``
and ``docs/simulate.md``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import click
import numpy as np

from robotcell.calibration.robottorobot_tables import RobotTable, robot_to_robot_tables
from robotcell.cell import Cell
from robotcell.cell.calibrate.robottorobot import (
    RobotTouchFile,
    place_robot,
)
from robotcell.cell.calibrate.robottorobot import (
    calibrate_robot_to_robot as calibrate_in_cell,
)
from robotcell.cell.update import update_cell_file
from robotcell.cli.calibrate import (
    OUTPUT_KEY,
    echo_note,
    emit,
    gate,
    result_options,
    robot_and_tool,
    sigma_m,
)
from robotcell.cli.common import (
    NOISE_MAX_MM,
    check_noise,
    format_table,
    output_of,
    parse_numbers,
    read_csv,
)
from robotcell.cli.files import NAME_OR_FILE, OUTPUT, Command
from robotcell.errors import InputError
from robotcell.io.fileio import atomic_write
from robotcell.io.poseformats import pose_from_vendor
from robotcell.robot.models import load_robot
from robotcell.studies.robottorobot import (
    SimulatedRobot,
    default_points,
    simulate_robot_to_robot,
    table_text,
)
from robotcell.studies.robottorobot_plan import R2RDesign, plan_robot_to_robot


def _table(path: str, robot: str | None, tool: str | None, option: str) -> RobotTable:
    """One robot's file with its model and tool (``--robot-ref``/``--tool-ref`` or ``-other``)."""
    try:
        model, T = robot_and_tool(robot, tool)
    except InputError as exc:
        raise InputError(str(exc).replace("--tool", f"--tool-{option}").replace(
            "--robot", f"--robot-{option}")) from None
    cols = read_csv(path)
    if "a1" in cols and model is None:
        raise InputError(f"{path}: joint values a1..a6 need the robot's model (--robot-{option} "
                         f"NAME_OR_FILE) and the tool it touched with (--tool-{option} "
                         "X,Y,Z,A,B,C)")
    return RobotTable(cols, path, Path(path).stem, model, T)


@dataclass(frozen=True)
class _Given:
    """The options of ``calibrate robot-to-robot`` besides the files and the output."""

    robot_ref: str | None
    tool_ref: str | None
    robot_other: str | None
    tool_other: str | None
    tool_sigma: float | None
    pointer: bool
    sigma: float | None
    cell_path: str | None
    robot: str | None
    reference_robot: str | None
    track_ref: float
    track_other: float


@click.command("robot-to-robot", cls=Command)
@click.argument("reference", type=click.Path(dir_okay=False))
@click.argument("other", type=click.Path(dir_okay=False))
@click.option("--robot-ref", default=None, metavar="NAME_OR_FILE", type=NAME_OR_FILE,
              help="Model of the reference robot, for joint values a1..a6 in REFERENCE.")
@click.option("--tool-ref", default=None, metavar="X,Y,Z,A,B,C",
              help="Tool the reference robot touched with (KUKA, mm/deg), for joint values; "
                   "with --cell the name of one of its tools in the cell.")
@click.option("--robot-other", default=None, metavar="NAME_OR_FILE", type=NAME_OR_FILE,
              help="Model of the other robot, for joint values a1..a6 in OTHER.")
@click.option("--tool-other", default=None, metavar="X,Y,Z,A,B,C",
              help="Tool the other robot touched with (KUKA, mm/deg), for joint values; with "
                   "--cell the name of one of its tools in the cell.")
@click.option("--tool-sigma", type=float, default=None, metavar="MM",
              help="Accuracy of both tools' TCP, 1-sigma per coordinate (mm); default 1 mm, "
                   "reported as assumed.")
@click.option("--pointer", is_flag=True,
              help="The reference robot held a pointer at several poses and the other robot "
                   "touched its tip (REFERENCE: the pointer's tip, OTHER: the touches).")
@click.option("--sigma", type=float, default=None, metavar="MM",
              help="Touch-up accuracy of both robots, 1-sigma per coordinate (mm; default 0.5).")
@click.option("--cell", "cell_path", default=None, type=click.Path(dir_okay=False),
              help="A cell of several robots: the robots' models and tools are the cell's, and "
                   "the other robot's base is written into it.")
@click.option("--robot", default=None, metavar="NAME",
              help="With --cell: the robot of OTHER, whose base is placed.")
@click.option("--reference", "reference_robot", default=None, metavar="NAME",
              help="With --cell: the robot of REFERENCE, the base the result is in.")
@click.option("--track-ref", type=float, default=0.0, show_default=True, metavar="MM",
              help="With --cell: the reference robot's track position during its touches (mm).")
@click.option("--track-other", type=float, default=0.0, show_default=True, metavar="MM",
              help="With --cell: the other robot's track position during its touches (mm).")
@result_options
@click.option("--accept-poor", is_flag=True,
              help="Print, write -o and the cell even when the verdict is poor (exit 0).")
def calibrate_robot_to_robot(reference: str, other: str, as_json: bool, accept_poor: bool,
                             **options: Any) -> None:
    """Pose of one robot's base relative to another's, from touches both made.

    \b
    REFERENCE.csv and OTHER.csv: one row per touch of each robot, TCP positions x,y,z (mm, in
    that robot's base) or joint values a1..a6 (deg) with --robot-ref/--robot-other and
    --tool-ref/--tool-other, and column 'point' naming the common point touched (the same
    names in both files; 3 or more points, not on one line, each touched by both robots).
    Prints T_ref_other: the other robot's base in the reference robot's base. With --cell
    CELL.yaml --robot NAME --reference NAME the robots and tools are the cell's and the other
    robot's base is written into the cell (for a robot on a track: its base at track 0).

    \b
    Example:
      robotcell calibrate robot-to-robot r1.csv r2.csv --robot-ref kuka_kr16 --tool-ref 0,0,200,0,0,0 --robot-other abb_irb2400 --tool-other 50,0,180,0,0,0 --sigma 0.1
    """
    given = _Given(**options)
    if given.tool_sigma is not None and not 0 < given.tool_sigma <= 1000:
        raise InputError(f"--tool-sigma must be a positive number of millimetres up to 1000, "
                         f"got {given.tool_sigma:g}")
    if given.cell_path is not None:
        return _into_cell(reference, other, given, as_json, accept_poor)
    for option, value in (("--robot", given.robot), ("--reference", given.reference_robot)):
        if value is not None:
            raise InputError(f"{option} names a robot of a cell; it needs --cell CELL.yaml")
    if given.track_ref or given.track_other:
        raise InputError("--track-ref and --track-other are track positions of a cell's robots; "
                         "they need --cell CELL.yaml")
    ref = _table(reference, given.robot_ref, given.tool_ref, "ref")
    oth = _table(other, given.robot_other, given.tool_other, "other")
    result = robot_to_robot_tables(
        ref, oth, sigma=sigma_m(given.sigma), tool_sigma=_tool_sigma_m(given),
        method="pointer" if given.pointer else "common points",
        on_note=lambda note: click.echo(note, err=True))
    gate(result, as_json, accept_poor)
    emit(result, as_json)


def _tool_sigma_m(given: _Given) -> float | None:
    return None if given.tool_sigma is None else given.tool_sigma * 1e-3


def _into_cell(reference: str, other: str, given: _Given, as_json: bool,
               accept_poor: bool) -> None:
    """``--cell``: calibrate with the cell's robots and tools, then place the other robot."""
    for option, value in (("--robot-ref", given.robot_ref), ("--robot-other", given.robot_other)):
        if value is not None:
            raise InputError(f"{option} and --cell both give a robot model: with --cell the "
                             f"models are the cell's; drop {option}")
    for option, value in (("--robot", given.robot), ("--reference", given.reference_robot),
                          ("--tool-ref", given.tool_ref), ("--tool-other", given.tool_other)):
        if value is None:
            raise InputError(f"--cell needs {option}: " + (
                "the name of a robot of the cell" if "tool" not in option
                else "the name of the tool that robot touched with, in the cell"))
    output = click.get_current_context().meta.get(OUTPUT_KEY)
    if output is not None and Path(output).resolve() == Path(given.cell_path).resolve():
        raise InputError(f"-o {output} is the cell file; name another file for the result")
    cell = Cell.load(given.cell_path)
    ref = RobotTouchFile(given.reference_robot, reference, given.tool_ref.strip(),
                         given.track_ref * 1e-3)
    oth = RobotTouchFile(given.robot, other, given.tool_other.strip(), given.track_other * 1e-3)
    result = calibrate_in_cell(cell, ref, oth, sigma=sigma_m(given.sigma),
                               tool_sigma=_tool_sigma_m(given),
                               method="pointer" if given.pointer else "common points",
                               on_note=echo_note)
    gate(result, as_json, accept_poor)
    done = update_cell_file(given.cell_path,
                            lambda c: (place_robot(c, result, ref, oth,
                                                   tool_sigma=_tool_sigma_m(given)), None),
                            on_note=echo_note)
    kept = f" (previous version: {done.backup})" if done.backup is not None else ""
    click.echo(f"updated {given.cell_path}: base of robot {given.robot!r} from robot "
               f"{given.reference_robot!r}{kept}", err=True)
    emit(result, as_json)


def _pose_option(text: str, option: str) -> np.ndarray:
    return pose_from_vendor(parse_numbers(text, option, 6), "kuka")


@click.command("robot-to-robot", cls=Command)
@click.option("--robot-ref", default="kuka_kr16", show_default=True, metavar="NAME_OR_FILE",
              type=NAME_OR_FILE, help="Model of the reference robot.")
@click.option("--robot-other", default="abb_irb2400", show_default=True, metavar="NAME_OR_FILE",
              type=NAME_OR_FILE, help="Model of the other robot.")
@click.option("--pose", default="1600,100,0,180,0,0", show_default=True, metavar="X,Y,Z,A,B,C",
              help="The true pose of the other robot's base in the reference base (KUKA, mm/deg).")
@click.option("--tool-ref", default="0,0,200,0,0,0", show_default=True, metavar="X,Y,Z,A,B,C",
              help="The reference robot's tool (KUKA, mm/deg).")
@click.option("--tool-other", default="50,0,180,0,0,0", show_default=True, metavar="X,Y,Z,A,B,C",
              help="The other robot's tool (KUKA, mm/deg).")
@click.option("--point", "points", multiple=True, metavar="X,Y,Z",
              help="A common point in the reference base (mm); repeat for each (default: 5 "
                   "points between the robots).")
@click.option("--repeats", type=click.IntRange(1, 20), default=2, show_default=True,
              help="Touches of each point by each robot.")
@click.option("--noise", type=float, default=0.1, show_default=True, metavar="MM",
              help="Touch-up error, 1-sigma per coordinate (mm).")
@click.option("--seed", type=click.IntRange(min=0), default=None, help="Seed of the errors.")
@click.option("--ref-output", required=True, type=OUTPUT, callback=output_of("CSV", "the "
              "reference robot's touches"), help="CSV of the reference robot's touches.")
@click.option("--other-output", required=True, type=OUTPUT, callback=output_of("CSV", "the "
              "other robot's touches"), help="CSV of the other robot's touches.")
def simulate_robot_to_robot_cmd(points: tuple[str, ...], repeats: int, noise: float,
                                seed: int | None, **layout: str) -> None:
    """Simulate two robots touching common points: one CSV per robot.

    \b
    Joint values a1..a6 (deg) that reach each point with the tool pointing down, plus the
    touch-up error --noise, and column 'point' (P1, P2, ...). Both files are written only when
    both robots reach every point. The command that calibrates them is printed on stderr.

    \b
    Example:
      robotcell simulate robot-to-robot --seed 1 --ref-output r1.csv --other-output r2.csv
    """
    robot_ref, robot_other, pose = layout["robot_ref"], layout["robot_other"], layout["pose"]
    tool_ref, tool_other = layout["tool_ref"], layout["tool_other"]
    ref_output, other_output = layout["ref_output"], layout["other_output"]
    if not 0 <= noise <= NOISE_MAX_MM:
        raise InputError(f"--noise must be a number of millimetres >= 0, at most "
                         f"{NOISE_MAX_MM:g}, got {noise:g}")
    T = _pose_option(pose, "--pose")
    p = (np.array([parse_numbers(v, "--point", 3) for v in points]) * 1e-3 if points
         else default_points(T))
    robots = [SimulatedRobot(load_robot(robot_ref), np.eye(4), _pose_option(tool_ref, "--tool-ref"),
                             f"the reference robot ({robot_ref})"),
              SimulatedRobot(load_robot(robot_other), T, _pose_option(tool_other, "--tool-other"),
                             f"the other robot ({robot_other})")]
    tables = simulate_robot_to_robot(robots, p, noise=noise * 1e-3,
                                     rng=np.random.default_rng(seed), repeats=repeats)
    texts = [table_text(t) for t in tables]
    atomic_write(ref_output, texts[0])
    atomic_write(other_output, texts[1])
    click.echo(f"simulated {len(p)} common points touched {repeats} times by each robot with a "
               f"touch-up error of {noise:g} mm; wrote {ref_output} and {other_output}", err=True)
    click.echo(f"calibrate them:\n  robotcell calibrate robot-to-robot {ref_output} "
               f"{other_output} --robot-ref {robot_ref} --tool-ref {tool_ref} --robot-other "
               f"{robot_other} --tool-other {tool_other} --sigma {max(noise, 0.001):g}", err=True)


def _points_csv(points: np.ndarray) -> str:
    """Common points (K, 3, m) as CSV: ``point`` (P1, P2, ...) and x, y, z (mm, 3 decimals)."""
    rows = [f"P{i + 1},{p[0]:.3f},{p[1]:.3f},{p[2]:.3f}" for i, p in enumerate(points * 1e3)]
    return "\n".join(["point,x,y,z", *rows]) + "\n"


@dataclass(frozen=True)
class _Planned:
    """The options of ``plan robot-to-robot``."""

    cell_path: str
    robot: str
    reference_robot: str
    tool_ref: str | None
    tool_other: str | None
    noise: float
    runs: int
    seed: int | None
    track_ref: float
    track_other: float
    output: str | None


def _design_row(d: R2RDesign, best: R2RDesign) -> list[object]:
    mc = ("-", "-") if np.isnan(d.position_rms) else (
        d.position_rms * 1e3, f"{np.degrees(d.rotation_rms):.4f}")
    return [len(d.points), d.position * 1e3, f"{np.degrees(d.rotation):.4f}", *mc,
            "<- best" if d is best else ""]


@click.command("robot-to-robot", cls=Command)
@click.option("--cell", "cell_path", required=True, type=click.Path(dir_okay=False),
              help="A cell of several robots, taken as the truth.")
@click.option("--robot", required=True, metavar="NAME",
              help="The robot whose base is calibrated.")
@click.option("--reference", "reference_robot", required=True, metavar="NAME",
              help="The robot whose base the result and the points are in.")
@click.option("--tool-ref", default=None, metavar="NAME",
              help="The reference robot's tool that touches (default: its first in the cell).")
@click.option("--tool-other", default=None, metavar="NAME",
              help="The other robot's tool that touches (default: its first in the cell).")
@click.option("--noise", type=float, default=0.1, show_default=True, metavar="MM",
              help="Touch-up accuracy, 1-sigma per coordinate (mm).")
@click.option("--runs", type=click.IntRange(0, 10000), default=100, show_default=True,
              help="Monte Carlo calibrations per design (0: none).")
@click.option("--seed", type=click.IntRange(min=0), default=None,
              help="Seed of the sampled volume and the Monte Carlo errors.")
@click.option("--track-ref", type=float, default=0.0, show_default=True, metavar="MM",
              help="The reference robot's track position during its touches (mm).")
@click.option("--track-other", type=float, default=0.0, show_default=True, metavar="MM",
              help="The other robot's track position during its touches (mm).")
@click.option("-o", "--output", type=OUTPUT, default=None,
              callback=output_of("CSV", "the recommended common points"),
              help="Write the recommended design's points (point, x, y, z mm in the reference "
                   "robot's base) as CSV, atomically.")
def plan_robot_to_robot_cmd(**options: Any) -> None:
    """Propose where to put the common points of a robot-to-robot calibration.

    \b
    Samples the volume about the two robots' bases (a robot on a track at the position it
    touches from, --track-ref / --track-other, default 0), keeps the points both
    reach with their tools pointing straight down, and proposes designs of 3, 4, 5 and 6 common
    points spread over that volume. For each, the predicted 1-sigma of the other robot's base
    in the reference robot's base at the touch-up accuracy --noise, and the RMS error of --runs
    simulated calibrations. -o writes the recommended design's points.

    \b
    Example:
      robotcell plan robot-to-robot --cell examples/cell_two_robots_positioner.yaml --robot abb --reference kuka --seed 1 -o points.csv
    """
    o = _Planned(**options)
    cell_path, robot, reference_robot, noise = o.cell_path, o.robot, o.reference_robot, o.noise
    track_ref, track_other, output = o.track_ref, o.track_other, o.output
    check_noise(noise)
    cell = Cell.load(cell_path)
    p = plan_robot_to_robot(cell, robot, reference_robot, tools=(o.tool_ref, o.tool_other),
                            noise=noise * 1e-3, runs=o.runs, seed=o.seed,
                            tracks=(track_ref * 1e-3, track_other * 1e-3))
    click.echo(f"robot-to-robot plan: base of {robot!r} in the base of {reference_robot!r}, "
               f"touch-up error {noise:g} mm (1-sigma per coordinate); {p.reachable} sampled "
               "points reached by both robots")
    click.echo(format_table(["points", "position mm", "rotation deg", "MC position mm",
                             "MC rotation deg", ""], [_design_row(d, p.best) for d in p.designs]))
    at = f" at track position {track_ref:g} mm" if track_ref else ""
    click.echo(f"\nbest: {len(p.best.points)} common points (mm, in the base of "
               f"{reference_robot!r}{at}):")
    click.echo(_points_csv(p.best.points), nl=False)
    if output is not None:
        atomic_write(output, _points_csv(p.best.points))
        click.echo(f"wrote the recommended points to {output}; touch each with both robots and "
                   f"calibrate with:\n  robotcell calibrate robot-to-robot REF.csv OTHER.csv "
                   f"--cell {cell_path} --robot {robot} --reference {reference_robot} "
                   f"--tool-ref {p.tools[0]} --tool-other {p.tools[1]}"
                   + (f" --track-ref {track_ref:g}" if track_ref else "")
                   + (f" --track-other {track_other:g}" if track_other else ""), err=True)
