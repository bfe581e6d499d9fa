"""``robotcell ik``: inverse kinematics from the command line (mm, deg)."""

from __future__ import annotations

import csv
import io
import math
from typing import TextIO

import click
import numpy as np

from robotcell.cli.common import (
    check_output,
    format_table,
    parse_numbers,
    read_csv,
    require_columns,
    write_output,
)
from robotcell.errors import InputError
from robotcell.ik import abb_confdata, analytic_solver, kuka_status_turn, nearest
from robotcell.modelfile import load_robot
from robotcell.poseformats import FORMATS, pose_from_vendor
from robotcell.robot import Robot

BRANCHES = ["front up", "front up flip", "front down", "front down flip",
            "back up", "back up flip", "back down", "back down flip"]


def _flags(robot: Robot, method: str, fmt: str, q: np.ndarray) -> list[str] | None:
    """KUKA 'S 6 T 2' or ABB '[0,0,0,0]' per row of ``q`` (rad), or None when not applicable."""
    if method != "opw" or fmt not in ("kuka", "abb"):
        return None
    qq = np.nan_to_num(q)
    if fmt == "kuka":
        s, t = kuka_status_turn(robot, qq)
        return [f"S {a} T {b}" for a, b in zip(np.atleast_1d(s), np.atleast_1d(t))]
    cf = np.atleast_2d(abb_confdata(robot, qq))
    return ["[" + ",".join(str(v) for v in row) + "]" for row in cf]


def _write(out: TextIO, header: list[str], rows: list[list[object]]) -> None:
    w = csv.writer(out, lineterminator="\n")
    w.writerow(header)
    for r in rows:
        w.writerow([f"{v:.6f}" if isinstance(v, float) else v for v in r])


@click.command()
@click.argument("robot")
@click.option("--pose", "pose", help="Target TCP pose in the robot base frame, in --format (mm, deg).")
@click.option("--input", "input_path", type=click.Path(), help="CSV of poses, columns named as in --format.")
@click.option("-o", "--output", "output_path", type=click.Path(), callback=check_output,
              help="CSV to write, atomically (default: standard output).")
@click.option("--format", "fmt", type=click.Choice(list(FORMATS)), default="kuka", show_default=True,
              help="Pose format of --pose / --input.")
@click.option("--all", "show_all", is_flag=True, help="Also list unreachable and out-of-limit branches.")
@click.option("--near", "near", help="Only the valid solution nearest to a1,...,a6 (deg).")
@click.option("--tool", "tool", help="TCP in the flange frame X,Y,Z,A,B,C (mm, deg, KUKA convention).")
def ik(robot: str, pose: str | None, input_path: str | None, output_path: str | None, fmt: str,
       show_all: bool, near: str | None, tool: str | None) -> None:
    """Inverse kinematics: every arm configuration that reaches a TCP pose.

    ROBOT is a library name (see 'robotcell robots') or a model file with an ortho-parallel
    arm and spherical wrist (KUKA, ABB, Fanuc, ...) or a Universal-Robots-type arm.

    The table lists the 8 branches (front/back of axis 1, elbow up/down, wrist flipped or not),
    joint values in degrees, and for --format kuka/abb the configuration flags (KUKA Status/Turn,
    ABB confdata [cf1,cf4,cf6,cfx]).

    Batch CSV: --input has the pose columns of --format (kuka: x,y,z,a,b,c; abb:
    x,y,z,q1,q2,q3,q4; ...). --output has one row per valid solution with columns
    pose (0-based input row), branch (0..7), a1..a6 (deg); with --all every branch and a column
    valid (1/0; unreachable branches have nan angles); with --near one row per pose with columns
    pose, found (1/0), a1..a6.

    \b
    Examples:
      robotcell ik kuka_kr6_r700_sixx --pose 470,0,750,0,0,0
      robotcell ik abb_irb2400 --pose 940,0,1455,0.7071068,0,0.7071068,0 --format abb --all
      robotcell ik ur5e --pose 0.5,0.1,0.4,0,3.1416,0 --format ur --near 0,-90,90,-90,-90,0
      robotcell ik kuka_kr16 --input poses.csv --output joints.csv
    """
    r = load_robot(robot)
    solver = analytic_solver(r)
    if (pose is None) == (input_path is None):
        raise InputError("give exactly one of --pose ... or --input poses.csv")
    T_tool = None if tool is None else pose_from_vendor(parse_numbers(tool, "--tool", 6), "kuka")
    deg = 180.0 / math.pi
    ref = None if near is None else np.radians(parse_numbers(near, "--near", 6))
    if pose is not None:
        T = pose_from_vendor(parse_numbers(pose, "--pose", FORMATS[fmt].size), fmt)
        sol = solver.solve(T, T_tool)
        if ref is not None:
            q, found, branch = nearest(r, sol, ref)
            if not found:
                raise InputError("no valid solution (unreachable or outside the joint limits)")
            q, valid, reach, ks = q[None], np.array([True]), np.array([True]), [int(branch)]
        else:
            q, valid, reach = sol.q, sol.valid, sol.reachable
            ks = [k for k in range(8) if show_all or valid[k]]
        flags = _flags(r, solver.method, fmt, q)
        headers = ["branch", *[j.name or f"a{i + 1}" for i, j in enumerate(r.joints)], "valid"]
        if flags is not None:
            headers.append("S/T" if fmt == "kuka" else "confdata")
        rows = []
        for i, k in enumerate(ks):
            row_i = 0 if ref is not None else k
            state = "yes" if valid[row_i] else ("limits" if reach[row_i] else "unreachable")
            vals = [float(v * deg) + 0.0 if abs(v) >= 1e-12 else 0.0 if np.isfinite(v) else "-"
                    for v in q[row_i]]
            row = [f"{k} {BRANCHES[k]}", *vals, state]
            if flags is not None:
                row.append(flags[row_i] if reach[row_i] else "-")
            rows.append(row)
        if not rows:
            raise InputError("no valid solution (unreachable or outside the joint limits); "
                             "--all lists every branch")
        click.echo(f"{r.name}, {solver.method} solver, angles in degrees")
        click.echo(format_table(headers, rows))
        return
    names = [f.lower() for f in FORMATS[fmt].fields]
    cols = read_csv(input_path, known=names)
    T = pose_from_vendor(require_columns(cols, names, input_path), fmt)
    sol = solver.solve(T, T_tool)
    axes = [f"a{i}" for i in range(1, 7)]
    if ref is not None:
        q, found, _ = nearest(r, sol, ref)
        header = ["pose", "found", *axes]
        out_rows = [[i, int(found[i]), *(q[i] * deg).tolist()] for i in range(len(q))]
    elif show_all:
        header = ["pose", "branch", "valid", *axes]
        out_rows = [[i, k, int(sol.valid[i, k]), *(sol.q[i, k] * deg).tolist()]
                    for i in range(len(sol.q)) for k in range(8)]
    else:
        header = ["pose", "branch", *axes]
        out_rows = [[i, k, *(sol.q[i, k] * deg).tolist()] for i, k in zip(*np.nonzero(sol.valid))]
    none = int(np.count_nonzero(~sol.valid.any(axis=1)))
    if none:
        click.echo(f"warning: {none} pose(s) without a valid solution", err=True)
    buf = io.StringIO(newline="")
    _write(buf, header, out_rows)
    write_output(output_path, buf.getvalue())
