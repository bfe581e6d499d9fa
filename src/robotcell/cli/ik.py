"""``robotcell ik``: inverse kinematics from the command line (mm, deg)."""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from typing import Any, TextIO

import click
import numpy as np

from robotcell.cell import Cell
from robotcell.cli.cellargs import (
    NORMAL_UP,
    batch_table,
    batch_track,
    cell_tool,
    check_axis_columns,
    check_normal_up,
    output_table_columns,
    progress,
    read_batch,
    setup_text,
    table_angles,
    table_option,
    table_rows,
    table_text,
    track_rows,
    track_values,
)
from robotcell.cli.common import (
    check_kind,
    check_output,
    format_table,
    parse_numbers,
    write_output,
)
from robotcell.cli.files import NAME_OR_FILE, OUTPUT, Command
from robotcell.cli.fk import joints_to_si
from robotcell.cli.robotname import load_cell, robot_name_option
from robotcell.controllers.base import IkFlags
from robotcell.controllers.registry import CONTROLLERS
from robotcell.errors import InputError
from robotcell.ik import analytic_solver, nearest
from robotcell.ik.analytic import AnalyticSolver, SeededSolver
from robotcell.io.poseformats import FORMATS, pose_from_vendor
from robotcell.io.targets import target_poses
from robotcell.robot.models import load_robot
from robotcell.robot.robot import Robot

BRANCHES = ["front up", "front up flip", "front down", "front down flip",
            "back up", "back up flip", "back down", "back down flip"]
#: Branch names of a 4-axis palletizer (``k = 2 * shoulder + elbow``).
BRANCHES_4 = ["front up", "front down", "back up", "back down"]


def _ik_flags(method: str, fmt: str) -> IkFlags | None:
    """The flags ``ik`` prints for pose format ``fmt`` (a controller's), for an OPW arm."""
    controller = next((c for c in CONTROLLERS.values() if c.pose_format.name == fmt), None)
    return None if method != "opw" or controller is None else controller.ik_flags


def _flags(robot: Robot, method: str, fmt: str, q: np.ndarray) -> list[str] | None:
    """KUKA 'S 6 T 2' or ABB '[0,0,0,0]' per row of ``q`` (rad), or None when not applicable."""
    flags = _ik_flags(method, fmt)
    if flags is None:
        return None
    return [flags.text(row) for row in flags.values(robot, np.nan_to_num(q))]


def _write(out: TextIO, header: list[str], rows: list[list[object]]) -> None:
    w = csv.writer(out, lineterminator="\n")
    w.writerow(header)
    for r in rows:
        w.writerow([f"{v:.6f}" if isinstance(v, float) else v for v in r])


@click.command(cls=Command)
@robot_name_option
@click.argument("robot", required=False, type=NAME_OR_FILE)
@click.option("--pose", "pose", help="Target TCP pose in the robot base frame, in --format (mm, deg).")
@click.option("--input", "input_path", type=click.Path(), help="CSV of poses, columns named as in --format.")
@click.option("-o", "--output", "output_path", type=OUTPUT, callback=check_output,
              help="File to write, atomically: the CSV of --input, or the table of --pose "
                   "(default: standard output).")
@click.option("--format", "fmt", type=click.Choice(list(FORMATS)), default="kuka", show_default=True,
              help="Pose format of --pose / --input.")
@click.option("--all", "show_all", is_flag=True, help="Also list unreachable and out-of-limit branches.")
@click.option("--near", "near", help="Only the valid solution nearest to a1,...,an (deg).")
@click.option("--tool", "tool", help="TCP in the flange frame X,Y,Z,A,B,C (mm, deg, KUKA convention); "
              "with --cell also a tool name of the cell.")
@click.option("--cell", "cell_path", type=click.Path(dir_okay=False),
              help="Solve in a cell file (robot, track, turntable, tools, frames) instead of ROBOT.")
@click.option("--frame", "frame", default="world", show_default=True,
              help="--cell: frame of the target (world, track, robot, turntable or a frame of the cell).")
@click.option("--track", "track_mm", type=float, metavar="MM",
              help="--cell: track position (mm); chosen per pose when omitted in a cell with a track.")
@click.option("--table", "table_deg", default=None, metavar="DEG[,DEG...]",
              help="--cell: turntable angle (deg) at which the target is given, or one value "
                   "per positioner axis (e.g. 30,90); 'normal-up': a 2-axis positioner turns "
                   "each target's surface normal (its -Z) straight up. Default 0.")
def ik(robot: str | None, **options: Any) -> None:
    """Inverse kinematics: every arm configuration that reaches a TCP pose.

    ROBOT is a library name (see 'robotcell robots') or a model file with an ortho-parallel
    arm and spherical wrist (KUKA, ABB, Fanuc, ...), a Universal-Robots-type arm or a 4-axis
    palletizer.

    The table lists the 8 branches (front/back of axis 1, elbow up/down, wrist flipped or not;
    4 for a palletizer), controller axis values in degrees (as the pendant shows them: FANUC J3
    with the J2/J3 interaction), and for --format kuka/abb the configuration flags (KUKA
    Status/Turn, ABB confdata [cf1,cf4,cf6,cfx]).

    Batch CSV: --input has the pose columns of --format (kuka: x,y,z,a,b,c; abb:
    x,y,z,q1,q2,q3,q4; ...). --output has one row per valid solution with columns
    pose (0-based input row), branch (0..7), a1..a6 (deg); with --all every branch and a column
    valid (1/0; unreachable branches have nan angles); with --near one row per pose with columns
    pose, found (1/0), a1..a6. A palletizer has branches 0..3 and columns a1..a4.

    With --cell CELL.yaml instead of ROBOT the target is given in a frame of the cell (--frame)
    at a table angle (--table), for a track position (--track, chosen per pose where the arm
    reaches best when omitted); the output adds track (mm) and table (deg) and, for --format
    kuka/abb, the configuration flags (batch columns status,turn or cf1,cf4,cf6,cfx). A batch
    file may hold per-row columns track and table. On a positioner chain --table takes one
    value per axis (deg) and the table columns are e1,e2,...; --table normal-up lets a 2-axis
    positioner turn each target's normal (-Z of a target in a frame it carries) up, the welding
    position, and reports the values chosen. Batches of 2000 poses or more show a progress
    bar on stderr. Refused with exit status 2: unknown frame or tool, track or table outside
    their limits, a --table with the wrong number of values, no valid solution for --pose.

    \b
    Examples:
      robotcell ik kuka_kr6_r700_sixx --pose 470,0,750,0,0,0
      robotcell ik abb_irb2400 --pose 940,0,1455,0.7071068,0,0.7071068,0 --format abb --all
      robotcell ik ur5e --pose 0.5,0.1,0.4,0,3.1416,0 --format ur --near 0,-90,90,-90,-90,0
      robotcell ik kuka_kr16 --input poses.csv --output joints.csv
      robotcell ik --cell cell.yaml --frame part --table 150 --tool torch --pose 0,0,50,0,180,0
      robotcell ik --cell positioner.yaml --frame part --table normal-up --tool torch \\
          --pose 50,0,0,0,180,0
    """
    a = _IkArgs(**options)
    check_kind(a.output_path, "text" if a.pose is not None else "CSV",
               "the table of solutions" if a.pose is not None else "the joint values")
    if a.cell_path is not None:
        if robot is not None:
            raise InputError("give either ROBOT or --cell CELL.yaml, not both")
        return _ik_cell(a)
    if robot is None:
        raise InputError("give a ROBOT (library name or model file) or --cell CELL.yaml")
    r = load_robot(robot)
    solver = analytic_solver(r)
    if (a.pose is None) == (a.input_path is None):
        raise InputError("give exactly one of --pose ... or --input poses.csv")
    T_tool = (None if a.tool is None
              else pose_from_vendor(parse_numbers(a.tool, "--tool", 6), "kuka"))
    ref = None if a.near is None else joints_to_si(r, np.array(parse_numbers(a.near, "--near",
                                                                             r.n_joints)))
    if a.pose is not None:
        return _ik_pose(r, solver, a, T_tool, ref)
    return _ik_batch(r, solver, a, T_tool, ref)


@dataclass(frozen=True)
class _IkArgs:
    """The options of ``robotcell ik`` as given on the command line (mm, deg, file names).

    Attributes
    ----------
    pose : str or None
        ``--pose``: one target in ``fmt``.
    input_path, output_path : str or None
        ``--input`` CSV of targets, ``-o`` file (None: standard output).
    fmt : str
        ``--format``: a pose format of :data:`robotcell.io.poseformats.FORMATS`.
    show_all : bool
        ``--all``: every branch, also the unreachable and out-of-limit ones.
    near : str or None
        ``--near``: the joints (deg) the nearest valid solution is chosen to.
    tool : str or None
        ``--tool``: X,Y,Z,A,B,C (mm, deg) or, with ``--cell``, a tool of the cell.
    cell_path : str or None
        ``--cell``: the cell file.
    frame : str
        ``--frame`` of the target in the cell.
    track_mm : float or None
        ``--track`` (mm).
    table_deg : str or None
        ``--table``: angle(s) (deg) or ``normal-up``.
    """

    pose: str | None
    input_path: str | None
    output_path: str | None
    fmt: str
    show_all: bool
    near: str | None
    tool: str | None
    cell_path: str | None
    frame: str
    track_mm: float | None
    table_deg: str | None


def _scale(r: Robot) -> np.ndarray:
    """Controller values to deg (mm for prismatic axes), per axis."""
    return np.where(r.prismatic, 1e3, 180.0 / math.pi)


def _ik_pose(r: Robot, solver: AnalyticSolver | SeededSolver, a: _IkArgs,
             T_tool: np.ndarray | None, ref: np.ndarray | None) -> None:
    """``robotcell ik ROBOT --pose``: the table of the solutions (deg)."""
    pose, fmt, show_all, output_path = a.pose, a.fmt, a.show_all, a.output_path
    scale = _scale(r)
    names_k = BRANCHES if solver.branches == 8 else BRANCHES_4
    T = target_poses(parse_numbers(pose, "--pose", FORMATS[fmt].size), fmt, "--pose")
    sol = solver.solve(T, T_tool)
    if ref is not None:
        q, found, branch = nearest(r, sol, ref)
        if not found:
            raise InputError("no valid solution (unreachable or outside the joint limits)")
        q, valid, reach, ks = q[None], np.array([True]), np.array([True]), [int(branch)]
    else:
        q, valid, reach = sol.q, sol.valid, sol.reachable
        ks = [k for k in range(solver.branches) if show_all or valid[k]]
    flags = _flags(r, solver.method, fmt, q)
    headers = ["branch", *[j.name or f"a{i + 1}" for i, j in enumerate(r.axes)], "valid"]
    if flags is not None:
        headers.append(_ik_flags(solver.method, fmt).label)
    rows = []
    for i, k in enumerate(ks):
        row_i = 0 if ref is not None else k
        state = "yes" if valid[row_i] else ("limits" if reach[row_i] else "unreachable")
        vals = [float(v * f) + 0.0 if abs(v) >= 1e-12 else 0.0 if np.isfinite(v) else "-"
                for v, f in zip(q[row_i], scale)]
        row = [f"{k} {names_k[k]}", *vals, state]
        if flags is not None:
            row.append(flags[row_i] if reach[row_i] else "-")
        rows.append(row)
    if not rows:
        raise InputError("no valid solution (unreachable or outside the joint limits); "
                         "--all lists every branch")
    write_output(output_path, f"{r.name}, {solver.description}, controller axis values in "
                 f"degrees\n{format_table(headers, rows)}\n")


def _ik_batch(r: Robot, solver: AnalyticSolver | SeededSolver, a: _IkArgs,
              T_tool: np.ndarray | None, ref: np.ndarray | None) -> None:
    """``robotcell ik ROBOT --input``: the CSV of the solutions (deg)."""
    input_path, fmt, show_all, output_path = a.input_path, a.fmt, a.show_all, a.output_path
    scale = _scale(r)
    T = read_batch(input_path, fmt).poses
    sol = solver.solve(T, T_tool)
    axes = [f"a{i}" for i in range(1, r.n_joints + 1)]
    if ref is not None:
        q, found, _ = nearest(r, sol, ref)
        header = ["pose", "found", *axes]
        out_rows = [[i, int(found[i]), *(q[i] * scale).tolist()] for i in range(len(q))]
    elif show_all:
        header = ["pose", "branch", "valid", *axes]
        out_rows = [[i, k, int(sol.valid[i, k]), *(sol.q[i, k] * scale).tolist()]
                    for i in range(len(sol.q)) for k in range(solver.branches)]
    else:
        header = ["pose", "branch", *axes]
        out_rows = [[i, k, *(sol.q[i, k] * scale).tolist()] for i, k in zip(*np.nonzero(sol.valid))]
    _finish_batch(sol.valid, header, out_rows, output_path)

def _finish_batch(valid: np.ndarray, header: list[str], out_rows: list[list[object]],
                  output_path: str | None) -> None:
    """Warn about poses without a valid branch (valid: (N, branches)), then write the batch CSV."""
    none = int(np.count_nonzero(~valid.any(axis=1)))
    if none:
        click.echo(f"warning: {none} pose(s) without a valid solution", err=True)
    buf = io.StringIO(newline="")
    _write(buf, header, out_rows)
    write_output(output_path, buf.getvalue())


def _reach_error_mm(reach_error: np.ndarray | None, reachable: np.ndarray) -> np.ndarray | None:
    """``reach_error`` in mm where a branch reaches (solved at the boundary), else 0; None
    when the solver gives no distance."""
    if reach_error is None:
        return None
    return np.where(reachable, np.nan_to_num(reach_error, posinf=0.0) * 1e3, 0.0)


def _cell_flag_columns(robot: Robot, method: str, fmt: str, q: np.ndarray
                       ) -> tuple[list[str], np.ndarray]:
    """Batch columns of the configuration flags (KUKA status,turn; ABB cf1..cfx) per row of q."""
    flags = _ik_flags(method, fmt)
    if flags is None:
        return [], np.empty((len(q), 0), dtype=int)
    return list(flags.columns), flags.values(robot, np.nan_to_num(q))


def _ik_cell(a: _IkArgs) -> None:
    """``robotcell ik --cell``: :meth:`Cell.ik` for one pose or a batch (mm, deg)."""
    cell = load_cell(a.cell_path)
    r = cell.robot
    if (a.pose is None) == (a.input_path is None):
        raise InputError("give exactly one of --pose ... or --input poses.csv")
    T_tool = cell_tool(a.tool)
    ref = None if a.near is None else np.radians(parse_numbers(a.near, "--near", r.n_joints))
    if a.pose is not None:
        return _ik_cell_pose(cell, a, T_tool, ref)
    return _ik_cell_batch(cell, a, T_tool, ref)


def _ik_cell_pose(cell: Cell, a: _IkArgs, T_tool: np.ndarray | None, ref: np.ndarray | None
                  ) -> None:
    """``robotcell ik --cell --pose``: the table of the solutions (deg)."""
    pose, fmt, show_all, frame, tool = a.pose, a.fmt, a.show_all, a.frame, a.tool
    track_mm, table_deg, output_path = a.track_mm, a.table_deg, a.output_path
    r = cell.robot
    deg = 180.0 / math.pi
    T = target_poses(parse_numbers(pose, "--pose", FORMATS[fmt].size), fmt, "--pose")
    th = (check_normal_up(cell, frame) if table_deg == NORMAL_UP
          else table_angles(cell, table_option(cell, table_deg), "warn"))
    sol = cell.ik(T, frame, track_values(cell, track_mm, "warn"), th, T_tool)
    valid = sol.valid
    if ref is not None:
        q, found, branch = sol.nearest(r, ref)
        ks, qs = ([int(branch)], q[None]) if found else ([], q[None])
    else:
        ks = [k for k in range(8) if show_all or valid[k]]
        qs = sol.q[ks]
    if not any(valid[k] for k in ks) and not show_all:
        raise InputError(f"no valid solution for the target in frame {frame!r}: out of reach, "
                         "or outside the joint, track or table limits (--all lists every branch)")
    flags = _flags(r, sol.method, fmt, qs) if ks else None
    off = _reach_error_mm(sol.reach_error, sol.reachable)
    off_shown = off is not None and bool(np.any(off[ks] > 0))
    headers = ["branch", *[j.name or f"a{i + 1}" for i, j in enumerate(r.joints)], "valid"]
    if flags is not None:
        headers.append(_ik_flags(sol.method, fmt).label)
    if off_shown:
        headers.append("reach error mm")
    rows = []
    for i, k in enumerate(ks):
        state = "yes" if valid[k] else ("limits" if sol.reachable[k] else "unreachable")
        vals = [float(v * deg) + 0.0 if abs(v) >= 1e-12 else 0.0 if np.isfinite(v) else "-"
                for v in qs[i]]
        row = [f"{k} {BRANCHES[k]}", *vals, state]
        if flags is not None:
            row.append(flags[i] if sol.reachable[k] else "-")
        if off_shown:
            row.append(f"{off[k]:.6f}" if sol.reachable[k] else "-")
        rows.append(row)
    how = "chosen" if track_mm is None else "given"
    track = (f", track {float(sol.track) * 1e3:.3f} mm ({how})" if cell.track is not None else "")
    where = table_text(cell, sol.table, table_deg == NORMAL_UP)
    write_output(output_path, f"{setup_text(cell, tool, frame, track, where)}; {r.name}, "
                 f"{sol.method} solver; angles in degrees\n{format_table(headers, rows)}\n")


def _ik_cell_batch(cell: Cell, a: _IkArgs, T_tool: np.ndarray | None, ref: np.ndarray | None
                   ) -> None:
    """``robotcell ik --cell --input``: the CSV of the solutions (deg)."""
    input_path, fmt, show_all, frame, tool = a.input_path, a.fmt, a.show_all, a.frame, a.tool
    track_mm, table_deg, output_path = a.track_mm, a.table_deg, a.output_path
    r = cell.robot
    deg = 180.0 / math.pi
    table_names = output_table_columns(cell)
    t = read_batch(input_path, fmt, cell)
    check_axis_columns(cell, t.track, t.table, input_path, warn=True)
    T, n = t.poses, len(t)
    e = track_rows(cell, t.track, track_mm, n)
    th = (check_normal_up(cell, frame) if table_deg == NORMAL_UP
          else table_rows(cell, t.table, table_option(cell, table_deg), n))
    click.echo(setup_text(cell, tool, frame, batch_track(cell, t.track, track_mm, "chosen per pose"),
                          batch_table(cell, t.table, table_deg)), err=True)
    with progress(n, "ik") as done:
        sol = cell.ik_batch(T, frame, e, th, T_tool, progress=done)
    q, valid, reach, method = sol.q, sol.valid, sol.reachable, sol.method
    off = _reach_error_mm(sol.reach_error, reach)
    track = sol.track * 1e3
    table = sol.table.reshape(n, -1) * deg
    axes = [f"a{i}" for i in range(1, r.n_joints + 1)]
    if ref is not None:
        qn, found, branch = sol.nearest(r, ref)
        names_f, flags = _cell_flag_columns(r, method, fmt, qn)
        header = ["pose", "found", "track", *table_names, *axes, *names_f]
        out_rows = [[i, int(found[i]), track[i], *table[i].tolist(), *(qn[i] * deg).tolist(),
                     *(flags[i].tolist() if found[i] else ["-"] * len(names_f))] for i in range(n)]
        shown = [(i, int(branch[i])) if found[i] else None for i in range(n)]
    else:
        idx = [(i, k) for i in range(n) for k in range(8)] if show_all else list(zip(*np.nonzero(valid)))
        sel = np.array([q[i, k] for i, k in idx]).reshape(-1, r.n_joints)
        names_f, flags = _cell_flag_columns(r, method, fmt, sel)
        header = ["pose", "branch", *(["valid"] if show_all else []), "track", *table_names, *axes,
                  *names_f]
        out_rows = [[int(i), int(k), *([int(valid[i, k])] if show_all else []), track[i],
                     *table[i].tolist(),
                     *(sel[j] * deg).tolist(), *(flags[j].tolist() if reach[i, k] else ["-"] * len(names_f))]
                    for j, (i, k) in enumerate(idx)]
        shown = [(int(i), int(k)) for i, k in idx]
    if off is not None and any(s is not None and off[s] > 0 for s in shown):
        header.append("reach_error_mm")  # only when a target lies outside the reach (<= 1 um)
        for row, s in zip(out_rows, shown):
            row.append(0.0 if s is None else float(off[s]))
    _finish_batch(valid, header, out_rows, output_path)
