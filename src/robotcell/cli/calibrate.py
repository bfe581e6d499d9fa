"""``robotcell calibrate``: calibration procedures on measurement CSV files.

Every subcommand reads a CSV (mm, deg; see docs/calibration.md), prints a report in mm/deg or,
with ``--json``, one JSON object, and exits with status 2 and the reason on stderr when the input
is refused. Subcommands of other modules are listed in ``REGISTERED`` at the bottom of this file
and imported only when used.
"""

from __future__ import annotations

import importlib
import importlib.util
import json
from collections.abc import Callable

import click
import numpy as np

from robotcell.calibration.measurements import (
    check_count,
    check_no_repeats,
    flange_poses,
    nominal_points,
    point_roles,
    tcp_positions,
)
from robotcell.calibration.result import CalibrationResult
from robotcell.cli.common import parse_numbers, read_csv
from robotcell.errors import InputError
from robotcell.modelfile import load_robot
from robotcell.poseformats import pose_from_vendor
from robotcell.robot import Robot


class CalibrateGroup(click.Group):
    """The ``calibrate`` group: its own subcommands plus the lazily imported ``REGISTERED`` ones."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        extra = [name for name, target in REGISTERED.items()
                 if importlib.util.find_spec(target.split(":")[0]) is not None]
        return sorted(set(super().list_commands(ctx)) | set(extra))

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        cmd = super().get_command(ctx, name)
        if cmd is not None or name not in self.list_commands(ctx):
            return cmd
        module, attr = REGISTERED[name].split(":")
        return getattr(importlib.import_module(module), attr)


@click.group(cls=CalibrateGroup)
def calibrate() -> None:
    """Calibrate tools, frames and external axes from touch-up measurements.

    \b
    CSV with a header, lengths in mm, angles in deg. Positions as x,y,z (TCP in the robot base)
    or joint values a1..a6 with --robot and --tool. Report in mm/deg, or --json.
    Exit status 2 when the measurements are refused, with the reason on stderr.
    """


def measurement_options(func: Callable) -> Callable:
    """Options shared by every calibrate subcommand: --robot, --tool, --sigma, --json."""
    func = click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")(func)
    func = click.option("--sigma", type=float, default=None, metavar="MM",
                        help="Touch-up accuracy, 1-sigma per coordinate (mm); used for the "
                             "uncertainties instead of the residuals.")(func)
    func = click.option("--tool", default=None, metavar="X,Y,Z,A,B,C",
                        help="Tool active during the touches (KUKA, mm/deg), for joint-value input; "
                             "default: the robot model's tool.")(func)
    func = click.option("--robot", default=None, metavar="NAME_OR_FILE",
                        help="Robot model for joint-value input (columns a1..a6).")(func)
    return func


def robot_and_tool(robot: str | None, tool: str | None) -> tuple[Robot | None, np.ndarray | None]:
    """Load ``--robot`` and parse ``--tool`` (KUKA X,Y,Z,A,B,C in mm/deg) into ``T_F_TCP`` (m)."""
    model = load_robot(robot) if robot else None
    if tool is not None and model is None:
        raise InputError("--tool is only used with joint values and --robot")
    T = pose_from_vendor(parse_numbers(tool, "--tool", 6), "kuka") if tool is not None else None
    return model, T


def sigma_m(sigma_mm: float | None) -> float | None:
    """``--sigma`` in mm to metres, refusing non-positive values."""
    if sigma_mm is None:
        return None
    if not sigma_mm > 0:
        raise InputError(f"--sigma must be a positive number of millimetres, got {sigma_mm}")
    return sigma_mm * 1e-3


def emit(result: CalibrationResult, as_json: bool) -> None:
    """Print a result: the terminal report, or one JSON object with ``--json``."""
    if as_json:
        click.echo(json.dumps(result.to_json(), indent=2))
    else:
        click.echo(result.summary())


def raw_rows(cols: dict, names: list[str]) -> np.ndarray:
    """The numeric columns among ``names`` as an (N, k) array, for the repeated-row check."""
    use = [n for n in names if n in cols and isinstance(cols[n], np.ndarray)]
    return np.stack([cols[n] for n in use], axis=1)


def _line_labels(roles: list[str]) -> list[str]:
    return [f"line {i + 2} ({r})" for i, r in enumerate(roles)]


POSE_COLUMNS = ["x", "y", "z", "a", "b", "c"] + [f"a{i}" for i in range(1, 10)]


@calibrate.command("tcp")
@click.argument("measurements", type=click.Path(dir_okay=False))
@click.option("--world", "world_mode", type=click.Choice(["6d", "5d"]), default="6d",
              help="ABC World alignment of rows with point=world: 6d (tool X along world -Z, Y along "
                   "world Y) or 5d (tool X along world -Z only).")
@measurement_options
def tcp(measurements: str, world_mode: str, robot: str | None, tool: str | None,
        sigma: float | None, as_json: bool) -> None:
    """Tool TCP (XYZ 4-point / N-point) and orientation (ABC 2-point, ABC World).

    \b
    Rows are flange poses x,y,z,a,b,c (KUKA, with no tool active) or a1..a6 with --robot.
    Optional column point: tcp (TCP on the reference point; the default), -x (reference point
    on the tool's -X axis), xy (reference point in the tool's XY plane, +Y), world (tool
    aligned to the world axes, see --world).
    """
    from robotcell.calibration.tcp import calibrate_tool

    if tool is not None:
        raise InputError("--tool is not used by 'calibrate tcp': the flange poses are computed "
                         "without a tool; give only --robot")
    prior = sigma_m(sigma)
    model, _ = robot_and_tool(robot, None)
    cols = read_csv(measurements)
    T = flange_poses(cols, measurements, model)
    roles = [str(r).strip().lower() for r in cols["point"]] if "point" in cols else ["tcp"] * len(T)
    bad = sorted(set(roles) - {"tcp", "-x", "xy", "world"})
    if bad:
        raise InputError(f"{measurements}: column 'point' must hold tcp, -x, xy or world; "
                         f"found {', '.join(bad)}")
    check_no_repeats(raw_rows(cols, POSE_COLUMNS), measurements)
    check_count(roles.count("tcp"), 3, "touches of the reference point (point=tcp)", measurements)
    r = np.array(roles)
    labels = _line_labels(roles)
    order = [i for k in ("tcp", "-x", "xy") for i in np.flatnonzero(r == k)]
    result = calibrate_tool(T[r == "tcp"], T[r == "-x"], T[r == "xy"], T[r == "world"],
                            world_mode=world_mode, prior_sigma=prior,
                            labels=[labels[i] for i in order])
    emit(result, as_json)


@calibrate.command("frame")
@click.argument("measurements", type=click.Path(dir_okay=False))
@measurement_options
def frame(measurements: str, robot: str | None, tool: str | None, sigma: float | None,
          as_json: bool) -> None:
    """Frame (base / user frame): 3-point, or N-point best fit to known coordinates.

    \b
    3-point: column point = origin, x (a point on +X), xy (a point in the XY plane with +Y);
    each may be touched several times.
    N-point: columns nominal_x, nominal_y, nominal_z (mm) give each touched point's coordinates
    in the frame (at least 3 points, not on one line).
    """
    from robotcell.calibration.frame import frame_3point, frame_npoint

    prior = sigma_m(sigma)
    model, T_tool = robot_and_tool(robot, tool)
    cols = read_csv(measurements)
    p = tcp_positions(cols, measurements, model, T_tool)
    check_no_repeats(raw_rows(cols, POSE_COLUMNS + ["nominal_x", "nominal_y", "nominal_z"]),
                     measurements)
    if "nominal_x" in cols:
        check_count(len(p), 3, "points", measurements)
        q = nominal_points(cols, measurements)
        result = frame_npoint(p, q, prior, [f"line {i + 2}" for i in range(len(p))])
    else:
        roles = point_roles(cols, measurements)
        result = frame_3point(p, roles, prior, _line_labels(roles))
    emit(result, as_json)


@calibrate.command("external-tcp")
@click.argument("measurements", type=click.Path(dir_okay=False))
@measurement_options
def external_tcp_cmd(measurements: str, robot: str | None, tool: str | None, sigma: float | None,
                     as_json: bool) -> None:
    """Fixed (external) tool touched with a robot-held reference tool of known TCP.

    \b
    Rows: reference-tool TCP positions x,y,z (or a1..a6 with --robot and --tool = the
    reference tool). Column point: tcp (the fixed TCP, at least 3 touches from different
    directions), optionally x (a point on the fixed tool's +X axis) and xy (a point in its XY
    plane with +Y) for the orientation.
    """
    from robotcell.calibration.frame import external_tcp

    prior = sigma_m(sigma)
    model, T_tool = robot_and_tool(robot, tool)
    cols = read_csv(measurements)
    p = tcp_positions(cols, measurements, model, T_tool)
    if "point" in cols:
        roles = [str(v).strip().lower() for v in cols["point"]]
    else:
        roles = ["tcp"] * len(p)
    check_no_repeats(raw_rows(cols, POSE_COLUMNS), measurements)
    result = external_tcp(p, roles, prior, _line_labels(roles))
    emit(result, as_json)


# ------------------------------------------------------------------------------------------------
# Registration list: calibrate subcommands that live in other modules, "name": "module:attribute".
# A module listed here is imported only when its subcommand is used; an entry whose module does
# not exist yet is simply not offered. Subcommands may use measurement_options, robot_and_tool,
# sigma_m and emit from this module.
REGISTERED: dict[str, str] = {
    "track": "robotcell.cli.calibrate_axes:track",
    "turntable": "robotcell.cli.calibrate_axes:turntable",
    "workpiece": "robotcell.cli.calibrate_axes:workpiece",
}
# ------------------------------------------------------------------------------------------------
