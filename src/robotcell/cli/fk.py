"""``robotcell fk``: forward kinematics from the command line (mm, deg)."""

from __future__ import annotations

import math
import sys

import click
import numpy as np

from robotcell.cell.validation import table_columns, table_label
from robotcell.cli.cellargs import (
    batch_table,
    batch_track,
    cell_tool,
    check_axis_columns,
    setup_text,
    table_angles,
    table_option,
    table_rows,
    table_text,
    track_rows,
    track_values,
)
from robotcell.cli.common import (
    output_of,
    parse_numbers,
    read_csv,
    require_columns,
    write_csv,
)
from robotcell.cli.files import NAME_OR_FILE, OUTPUT, Command
from robotcell.cli.robotname import load_cell, robot_name_option
from robotcell.errors import InputError
from robotcell.io.poseformats import FORMATS, pose_from_vendor, pose_to_vendor
from robotcell.io.tables import outside_limits
from robotcell.io.targets import axis_columns
from robotcell.robot.models import load_robot
from robotcell.robot.robot import Robot

FORMAT_CHOICES = [*FORMATS, "matrix"]


def joints_to_si(robot: Robot, values: np.ndarray) -> np.ndarray:
    """Controller values from files (deg; mm for prismatic joints) to SI, shape ``(..., n)``."""
    scale = np.where(robot.prismatic, 1e-3, math.pi / 180)
    return np.asarray(values, dtype=float) * scale


def tool_option(text: str | None) -> np.ndarray | None:
    """Parse ``--tool X,Y,Z,A,B,C`` (KUKA convention, mm/deg) into ``T_F_TCP`` (metres)."""
    if text is None:
        return None
    return pose_from_vendor(parse_numbers(text, "--tool", 6), "kuka")


@click.command(cls=Command)
@robot_name_option
@click.argument("robot", required=False, type=NAME_OR_FILE)
@click.option("--joints", "joints", help="Joint values a1,a2,... (deg; mm for prismatic joints).")
@click.option("--input", "input_path", type=click.Path(), help="CSV with columns a1..an, one pose per row.")
@click.option("-o", "--output", "output_path", type=OUTPUT, callback=output_of("CSV", "the poses"),
              help="CSV to write, atomically: the poses of --input, or one row for --joints "
                   "(default: standard output).")
@click.option("--format", "fmt", type=click.Choice(FORMAT_CHOICES), default="kuka", show_default=True,
              help="Pose format of the result.")
@click.option("--tool", "tool", help="TCP in the flange frame X,Y,Z,A,B,C (mm, deg, KUKA convention); "
              "with --cell also a tool name of the cell.")
@click.option("--cell", "cell_path", type=click.Path(dir_okay=False),
              help="Forward kinematics in a cell file (robot, track, turntable, tools, frames).")
@click.option("--frame", "frame", default="world", show_default=True,
              help="--cell: frame of the result (world, track, robot, turntable or a frame of the cell).")
@click.option("--track", "track_mm", type=float, default=None, metavar="MM",
              help="--cell: track position (mm); default 0, which the result says.")
@click.option("--table", "table_deg", default=None, metavar="DEG[,DEG...]",
              help="--cell: turntable angle (deg), or one value per positioner axis, e.g. 30,90 "
                   "(deg); default 0.")
def fk(robot: str | None, joints: str | None, input_path: str | None, output_path: str | None,
       fmt: str, tool: str | None, cell_path: str | None, frame: str, track_mm: float | None,
       table_deg: str | None) -> None:
    """Forward kinematics: pose of the TCP in the robot base frame.

    ROBOT is a library name (see 'robotcell robots') or a model file.

    With --cell CELL.yaml instead of ROBOT: joints plus track position (--track, mm) and table
    angle (--table, deg; for a positioner one value per axis, --table 30,90) give the TCP pose
    in a frame of the cell (--frame). A batch file may hold per-row columns track and table
    (positioner: e1,e2,...). The result names the tool, frame, track position and table it
    used (the defaults: the bare flange, world, track 0, table 0); for a batch on stderr. Refused with exit status 2: unknown frame or tool, track or table
    outside their limits, a --table with the wrong number of values.

    \b
    Examples:
      robotcell fk kuka_kr16 --joints 0,-90,90,0,0,0
      robotcell fk ur5e --joints 0,-90,90,0,90,0 --format ur
      robotcell fk abb_irb2400 --input joints.csv --output poses.csv --format abb
      robotcell fk --cell cell.yaml --joints 0,-90,90,0,45,0 --track 1500 --tool torch --frame part
      robotcell fk --cell positioner.yaml --joints 0,-90,90,0,45,0 --table 30,90 --frame part
    """
    if cell_path is not None:
        if robot is not None:
            raise InputError("give either ROBOT or --cell CELL.yaml, not both")
        return _fk_cell(cell_path, joints, input_path, output_path, fmt, tool, frame, track_mm,
                        table_deg)
    if robot is None:
        raise InputError("give a ROBOT (library name or model file) or --cell CELL.yaml")
    r = load_robot(robot)
    T_tool = tool_option(tool)
    if (joints is None) == (input_path is None):
        raise InputError("give exactly one of --joints a1,a2,... or --input joints.csv")
    if joints is not None:
        q = joints_to_si(r, np.array(parse_numbers(joints, "--joints", r.n_joints)))
        T = r.fk(q, tool=T_tool)
        warn_joint_limits(r, q, None)
        if output_path is not None:
            _write_poses(T[None], fmt, output_path)
            return
        if fmt == "matrix":
            click.echo("T_R_TCP (translation in mm):")
        _echo_pose(T, fmt)
        return
    names = [f"a{i}" for i in range(1, r.n_joints + 1)]
    cols = read_csv(input_path, known=names)
    q = joints_to_si(r, require_columns(cols, names, input_path))
    T = r.fk(q, tool=T_tool)
    warn_joint_limits(r, q, input_path)
    _write_poses(T, fmt, output_path)


def warn_joint_limits(robot: Robot, q: np.ndarray, source: str | None) -> None:
    """A ``warning:`` line naming the joint values ``q`` (SI, ``(N, n)``) outside the robot's
    limits: by line and column of the file ``source``, or by axis for ``--joints`` (None)."""
    scale = np.where(robot.prismatic, 1e3, 180.0 / math.pi)
    names = [f"a{i}" for i in range(1, robot.n_joints + 1)]
    units = ["mm" if p else "deg" for p in robot.prismatic]
    bad = outside_limits(np.atleast_2d(q) * scale, names, robot.lower * scale,
                         robot.upper * scale, units, lines=source is not None)
    if bad is not None:
        where = f"{source}: " if source else ""
        click.echo(f"warning: {where}joint values outside the limits of {robot.name}: {bad}; "
                   "the pose is computed, but the robot cannot move there", err=True)


def _echo_pose(T: np.ndarray, fmt: str) -> None:
    """Print one pose (m) as the vendor format's fields, or as a matrix with mm translation."""
    if fmt == "matrix":
        M = T.copy()
        M[:3, 3] *= 1e3
        for row in M:
            click.echo("  " + "  ".join(f"{v:12.6f}" for v in row))
        return
    v = pose_to_vendor(T, fmt)
    f = FORMATS[fmt]
    click.echo(" ".join(f"{n} {x:.4f}" if f.rotation != "quaternion" or i < 3 else f"{n} {x:.6f}"
                        for i, (n, x) in enumerate(zip(f.fields, v))))


def _write_poses(T: np.ndarray, fmt: str, output_path: str | None) -> None:
    """Write poses (N, 4, 4) (m) as CSV in the vendor format (mm, deg) or as matrix rows."""
    if fmt == "matrix":
        header = [f"t{i}{j}" for i in range(3) for j in range(4)]
        M = T[:, :3, :].copy()
        M[:, :, 3] *= 1e3
        rows = M.reshape(-1, 12)
    else:
        header, rows = list(FORMATS[fmt].fields), pose_to_vendor(T, fmt)
    write_csv(output_path if output_path else sys.stdout, header, rows)


def _fk_cell(cell_path: str, joints: str | None, input_path: str | None, output_path: str | None,
             fmt: str, tool: str | None, frame: str, track_mm: float | None,
             table_deg: str | None) -> None:
    """``robotcell fk --cell``: :meth:`Cell.fk` for one configuration or a batch (mm, deg)."""
    cell = load_cell(cell_path)
    r = cell.robot
    T_tool = cell_tool(tool)
    if (joints is None) == (input_path is None):
        raise InputError("give exactly one of --joints a1,a2,... or --input joints.csv")
    track = 0.0 if track_mm is None else track_mm
    if joints is not None:
        q = joints_to_si(r, np.array(parse_numbers(joints, "--joints", r.n_joints)))
        e = track_values(cell, track, "warn")
        th = table_angles(cell, table_option(cell, table_deg), "warn")
        setup = setup_text(cell, tool, frame, "" if cell.track is None else
                           f", track {track:g} mm" + (" (default)" if track_mm is None else ""),
                           table_text(cell, th) + (" (default)" if table_deg is None and
                                                   cell.turntable is not None else ""))
    else:
        names = [f"a{i}" for i in range(1, r.n_joints + 1)]
        cols = read_csv(input_path, known=[*names, "track", *table_columns(cell)])
        e_col, th_col, _ = axis_columns(cols, input_path, table=table_columns(cell),
                                        positioner=table_label(cell))
        check_axis_columns(cell, e_col, th_col, input_path, warn=True)
        q = joints_to_si(r, require_columns(cols, names, input_path))
        e = track_rows(cell, e_col, track, len(q))
        th = table_rows(cell, th_col, table_option(cell, table_deg), len(q))
        setup = setup_text(cell, tool, frame, batch_track(cell, e_col, track_mm, "0 mm (default)"),
                           batch_table(cell, th_col, table_deg))
    T = cell.fk(q, e, th, T_tool, frame)
    warn_joint_limits(r, q, input_path)
    if joints is not None and output_path is None:
        click.echo(f"{setup} ({fmt}, mm, deg)")
        _echo_pose(T, fmt)
        return
    click.echo(setup, err=True)
    _write_poses(T.reshape(-1, 4, 4), fmt, output_path)
