"""``robotcell calibrate track | turntable | positioner | workpiece``: external axes from CSV.

Registered in :data:`robotcell.cli.calibrate.REGISTERED`. CSV columns: ``x,y,z`` (mm, TCP in the
robot base) or ``a1..a6`` with ``--robot``/``--tool``; ``e1`` = track position (mm) or table angle
(deg); ``e1,e2`` = tilt, rotate (deg) of a 2-axis positioner; ``point`` as described per
command; with ``--cell``, ``track`` = track position of the robot at each touch (mm) for the
turntable, positioner and workpiece.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import click
import numpy as np

from robotcell.cell import calibrate as cellcal
from robotcell.cli.calibrate import (
    CellTarget,
    cell_of,
    cell_option,
    chain_options,
    echo_note,
    finish,
    measurement_options,
    require_name,
    robot_and_tool,
    sigma_m,
)
from robotcell.cli.common import group_tolerance_option, parse_numbers
from robotcell.cli.files import Command
from robotcell.errors import InputError
from robotcell.io.tables import CELL_EXTENT_MM


@dataclass(frozen=True)
class _TrackGeometry:
    """What ``calibrate track`` is told of the track.

    Attributes
    ----------
    references : tuple of str
        ``--reference`` points as given (X,Y,Z in mm, in the track frame L).
    axis : {"x", "z"} or None
        ``--axis`` of L along which the carriage moves (None: the cell's, else x).
    roll : {"zero"} or None
        ``--roll``: the rotation about the track axis by convention.
    """

    references: tuple[str, ...]
    axis: str | None
    roll: str | None


@click.command("track", cls=Command)
@click.argument("measurements", type=click.Path(dir_okay=False))
@click.option("--reference", "references", multiple=True, metavar="X,Y,Z",
              help="Known coordinates (mm) of a touched reference point in the track frame L; "
                   "repeat for several points (column 'point' = 1, 2, ... says which is touched).")
@click.option("--axis", type=click.Choice(["x", "z"]), default=None,
              help="Axis of L along which the carriage moves: x (lecture) or z (KUKA external "
                   "kinematics). Default: the cell's track axis with --cell, else x.")
@click.option("--roll", type=click.Choice(["zero"]), default=None,
              help="Without --reference: return the full rotation L_Q_R with zero roll about the "
                   "track axis (a convention, not a measurement).")
@group_tolerance_option("Track positions e1", "mm")
@cell_option
@measurement_options
def track(measurements: str, group_tolerance: float | None, cell_path: str | None,
          robot: str | None, tool: str | None, sigma: float | None, as_json: bool,
          accept_poor: bool, **given: Any) -> None:
    """Linear track: direction in the robot base, scale, straightness; rotation when determined.

    \b
    Rows: TCP touches of fixed reference point(s) at different track positions e1 (mm).
    Without --reference the point is unknown and the rotation about the track axis is not
    determined (--roll zero fixes it by convention). One --reference point off the track axis
    gives the rotation (carriage offset taken as zero); two or more also give the offset.
    With --cell the track's robot_at_zero (T_L_R0) and scale are written into the cell file;
    that needs --reference or --roll zero. When the offset is not measured (one --reference,
    or --roll zero) the cell's offset is kept, and a --reference point is taken relative to it.

    \b
    Examples:
      robotcell calibrate track touches.csv --reference 1500,800,300
      robotcell calibrate track touches.csv --cell cell.yaml \\
          --reference 1500,800,300 --reference 2100,-600,100
    """
    geometry = _TrackGeometry(**given)
    target = CellTarget.open(cell_path, robot)
    model, T_tool = robot_and_tool(robot, tool, target)
    refs = np.array([parse_numbers(r, "--reference", 3)
                     for r in geometry.references]).reshape(-1, 3) * 1e-3
    label, prior, options = cell_of(target)[1], sigma_m(sigma), chain_options(measurements)
    tol = None if group_tolerance is None else group_tolerance * 1e-3
    finish(lambda cell: cellcal.track(cell, measurements, references=refs, axis=geometry.axis,
                                      roll=geometry.roll, robot=None if cell else model,
                                      tool=T_tool, sigma=prior, source=measurements,
                                      cell_label=label, on_note=echo_note, group_tol=tol,
                                      **options),
           target, as_json, accept_poor)


@click.command("turntable", cls=Command)
@click.argument("measurements", type=click.Path(dir_okay=False))
@click.option("--height", type=float, default=0.0, show_default=True, metavar="MM",
              help="Shift of the frame origin along the table axis from the plane of the touched "
                   "point (mm), e.g. -20 when the point is 20 mm above the table top.")
@group_tolerance_option("Table angles e1")
@cell_option
@measurement_options
def turntable(measurements: str, height: float, group_tolerance: float | None,
              cell_path: str | None, robot: str | None, tool: str | None, sigma: float | None,
              as_json: bool, accept_poor: bool) -> None:
    """Turntable root frame B (R_T_B) and radius from touches of one point on the table.

    \b
    Rows: TCP touches of one point on the table at different table angles e1 (deg); at least
    3, better 4 or more spread around the full turn. Save --json output for
    'robotcell calibrate workpiece --turntable'.
    With --cell the turntable's frame (T_parent_B) is written into the cell file. For a
    turntable in the world the touches are mapped to the world (result T_world_B); in a cell
    with a track that needs column track (mm, the track position at each touch).

    \b
    Examples:
      robotcell calibrate turntable table.csv --json -o turntable.json
      robotcell calibrate turntable table.csv --cell cell.yaml --tool pointer
    """
    if not abs(height) <= CELL_EXTENT_MM:
        raise InputError(f"--height must be a number of millimetres within +-{CELL_EXTENT_MM:g} "
                         f"(100 m, the size of any real cell), got {height:g}")
    target = CellTarget.open(cell_path, robot)
    model, T_tool = robot_and_tool(robot, tool, target)
    label, prior, options = cell_of(target)[1], sigma_m(sigma), chain_options(measurements)
    tol = None if group_tolerance is None else math.radians(group_tolerance)
    finish(lambda cell: cellcal.turntable(cell, measurements, height=height * 1e-3,
                                          robot=None if cell else model, tool=T_tool, sigma=prior,
                                          source=measurements, cell_label=label,
                                          on_note=echo_note, group_tol=tol, **options),
           target, as_json, accept_poor)


@click.command("positioner", cls=Command)
@click.argument("measurements", type=click.Path(dir_okay=False))
@group_tolerance_option("Axis values e1, e2")
@cell_option
@measurement_options
def positioner(measurements: str, group_tolerance: float | None, cell_path: str | None,
               robot: str | None, tool: str | None, sigma: float | None, as_json: bool,
               accept_poor: bool) -> None:
    """2-axis (tilt-rotate) positioner: both axis lines, common normal, zeros, root frame.

    \b
    Rows: TCP touches of one point on the table at combinations of tilt e1 and rotate e2 (deg);
    e.g. 3 tilt values by 4 rotate values, spread over the axis ranges (12 touches).
    With --cell the cell's chain is the start and the calibrated chain is written into the cell
    file (its 'positioner' section); the values are in the positioner's parent frame (the world,
    mapped through column track (mm) in a cell with a track). Without --cell they are in the
    robot base, and each axis needs at least 3 touches that move it alone (the other axis at
    one commanded value, to the --group-tolerance).

    \b
    Examples:
      robotcell calibrate positioner touches.csv --cell cell.yaml --tool pointer
      robotcell calibrate positioner touches.csv --robot kuka_kr16 --tool 250,0,0,0,0,0 \\
          --json -o positioner.json
    """
    target = CellTarget.open(cell_path, robot)
    model, T_tool = robot_and_tool(robot, tool, target)
    label, prior, options = cell_of(target)[1], sigma_m(sigma), chain_options(measurements)
    tol = None if group_tolerance is None else math.radians(group_tolerance)
    finish(lambda cell: cellcal.positioner(cell, measurements, robot=None if cell else model,
                                           tool=T_tool, sigma=prior, source=measurements,
                                           cell_label=label, on_note=echo_note, group_tol=tol,
                                           **options),
           target, as_json, accept_poor)


@click.command("workpiece", cls=Command)
@click.argument("measurements", type=click.Path(dir_okay=False))
@click.option("--turntable", "turntable_json", default=None, metavar="TURNTABLE.json",
              type=click.Path(dir_okay=False),
              help="--json output of 'robotcell calibrate turntable'. Optional with --cell (the "
                   "cell's turntable is used, with its recorded uncertainty).")
@click.option("--name", default=None, metavar="FRAME",
              help="With --cell: the frame on the turntable to write (added when new).")
@cell_option
@measurement_options
def workpiece(measurements: str, turntable_json: str | None, name: str | None,
              cell_path: str | None, robot: str | None, tool: str | None, sigma: float | None,
              as_json: bool, accept_poor: bool) -> None:
    """Workpiece frame B_T_W on a calibrated turntable (3-point, or several touches per point).

    \b
    Rows: TCP touches with the table angle e1 (deg, any angle, recorded at every touch) and
    column point = origin, x (a point on +X) or xy (a point in the XY plane with +Y).
    The moving pose is R_T_W(theta) = R_T_B Rz(theta) B_T_W.
    With --cell and --name the frame is written into the cell file with parent turntable.
    For a turntable in the world the touches are mapped to the world; in a cell with a track
    that needs column track (mm, the track position at each touch).

    \b
    Examples:
      robotcell calibrate workpiece wp.csv --turntable turntable.json
      robotcell calibrate workpiece wp.csv --cell cell.yaml --name part --tool pointer
    """
    target = CellTarget.open(cell_path, robot)
    require_name(name, target, "frame")
    model, T_tool = robot_and_tool(robot, tool, target)
    given = None if turntable_json is None else cellcal.TurntablePose.load(turntable_json)
    label, prior, options = cell_of(target)[1], sigma_m(sigma), chain_options(measurements)
    finish(lambda cell: cellcal.workpiece(cell, measurements, name, turntable=given,
                                          robot=None if cell else model, tool=T_tool, sigma=prior,
                                          source=measurements, cell_label=label,
                                          on_note=echo_note, **options),
           target, as_json, accept_poor)
