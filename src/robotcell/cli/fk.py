"""``robotcell fk``: forward kinematics from the command line (mm, deg)."""

from __future__ import annotations

import math
import sys

import click
import numpy as np

from robotcell.cli.common import check_output, parse_numbers, read_csv, require_columns, write_csv
from robotcell.errors import InputError
from robotcell.modelfile import load_robot
from robotcell.poseformats import FORMATS, pose_from_vendor, pose_to_vendor
from robotcell.robot import Robot

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


@click.command()
@click.argument("robot")
@click.option("--joints", "joints", help="Joint values a1,a2,... (deg; mm for prismatic joints).")
@click.option("--input", "input_path", type=click.Path(), help="CSV with columns a1..an, one pose per row.")
@click.option("-o", "--output", "output_path", type=click.Path(), callback=check_output,
              help="CSV to write, atomically (default: standard output).")
@click.option("--format", "fmt", type=click.Choice(FORMAT_CHOICES), default="kuka", show_default=True,
              help="Pose format of the result.")
@click.option("--tool", "tool", help="TCP in the flange frame X,Y,Z,A,B,C (mm, deg, KUKA convention).")
def fk(robot: str, joints: str | None, input_path: str | None, output_path: str | None,
       fmt: str, tool: str | None) -> None:
    """Forward kinematics: pose of the TCP in the robot base frame.

    ROBOT is a library name (see 'robotcell robots') or a model file.

    \b
    Examples:
      robotcell fk kuka_kr16 --joints 0,-90,90,0,0,0
      robotcell fk ur5e --joints 0,-90,90,0,90,0 --format ur
      robotcell fk abb_irb2400 --input joints.csv --output poses.csv --format abb
    """
    r = load_robot(robot)
    T_tool = tool_option(tool)
    if (joints is None) == (input_path is None):
        raise InputError("give exactly one of --joints a1,a2,... or --input joints.csv")
    if joints is not None:
        q = joints_to_si(r, np.array(parse_numbers(joints, "--joints", r.n_joints)))
        T = r.fk(q, tool=T_tool)
        if not r.within_limits(q):
            click.echo("warning: joint values outside the robot's limits", err=True)
        if fmt == "matrix":
            click.echo("T_R_TCP (translation in mm):")
            M = T.copy()
            M[:3, 3] *= 1e3
            for row in M:
                click.echo("  " + "  ".join(f"{v:12.6f}" for v in row))
            return
        v = pose_to_vendor(T, fmt)
        fields = FORMATS[fmt].fields
        click.echo(" ".join(f"{n} {x:.4f}" if fmt != "abb" or i < 3 else f"{n} {x:.6f}"
                            for i, (n, x) in enumerate(zip(fields, v))))
        return
    names = [f"a{i}" for i in range(1, r.n_joints + 1)]
    cols = read_csv(input_path, known=names)
    q = joints_to_si(r, require_columns(cols, names, input_path))
    T = r.fk(q, tool=T_tool)
    if fmt == "matrix":
        header = [f"t{i}{j}" for i in range(3) for j in range(4)]
        M = T[:, :3, :].copy()
        M[:, :, 3] *= 1e3
        rows = M.reshape(-1, 12)
    else:
        header, rows = list(FORMATS[fmt].fields), pose_to_vendor(T, fmt)
    outside = int(np.count_nonzero(~r.within_limits(q)))
    if outside:
        click.echo(f"warning: {outside} row(s) outside the robot's joint limits", err=True)
    write_csv(output_path if output_path else sys.stdout, header, rows)
