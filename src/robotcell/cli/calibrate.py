"""``robotcell calibrate``: calibration procedures on measurement CSV files.

Every subcommand reads a CSV (mm, deg; see docs/calibration.md), prints a report in mm/deg or,
with ``--json``, one JSON object, and exits with status 2 and the reason on stderr when the input
is refused. With ``--cell CELL.yaml`` (tcp, frame, track, turntable, workpiece) the result is
written into the cell file: the command parses its options, makes one call of
:mod:`robotcell.cell.calibrate` (which returns the result and the updated cell), prints its notes on
stderr and saves the cell through :class:`CellTarget`.
There is one subcommand per procedure of the registry
(:data:`robotcell.cell.calibrate.PROCEDURES`): its own command where it has options of its own,
in this module or in another one listed in ``REGISTERED`` at the bottom of this file (imported
only when used), else one made from the procedure (:func:`procedure_command`).
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

import click
import numpy as np
from numpy.typing import NDArray

from robotcell.calibration.result import CalibrationResult
from robotcell.cell import NAME_RE, Cell
from robotcell.cell import calibrate as cellcal
from robotcell.cell.calibrate import PROCEDURES, CalibrationContext, Procedure
from robotcell.cell.calibrate.chain import NOMINAL_ACCURACY, NominalAccuracy
from robotcell.cell.calibrate.wholerobots import cell_touch_files, replaced_notes
from robotcell.cell.update import update_cell_file
from robotcell.cli import load_command
from robotcell.cli.common import check_kind, check_output, parse_numbers, write_output
from robotcell.cli.files import NAME_OR_FILE, OUTPUT, Command, Group, refuse_overwriting_inputs
from robotcell.cli.robotname import robot_name, robot_name_option, robot_of
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor
from robotcell.robot.models import load_robot
from robotcell.robot.robot import Robot


class CalibrateGroup(Group):
    """The ``calibrate`` group: ``cell`` and one subcommand per registered procedure, its own
    (here or in ``REGISTERED``, imported when used) or one made from the procedure."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(set(super().list_commands(ctx)) | set(REGISTERED) | set(PROCEDURES))

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        cmd = super().get_command(ctx, name)
        if cmd is not None:
            return cmd
        if name in REGISTERED:
            return load_command(REGISTERED[name])
        return procedure_command(PROCEDURES[name]) if name in PROCEDURES else None


@click.group(cls=CalibrateGroup)
def calibrate() -> None:
    """Calibrate tools, frames and external axes from touch-up measurements.

    \b
    CSV with a header, lengths in mm, angles in deg. Positions as x,y,z (TCP in the robot base)
    or joint values a1..a6 with --robot and --tool. Report in mm/deg, or --json.
    With --cell CELL.yaml the result is written into the cell file, keeping its comments and
    layout (CELL.yaml.N.bak keeps the previous version; robotcell cell history lists them). Exit status 2 when the measurements are refused, with the reason on stderr.
    Every report ends with a verdict (good / check / poor); a poor result prints its report,
    exits with status 3 and writes nothing, unless --accept-poor is given.

    \b
    Examples:
      robotcell calibrate tcp tcp.csv --robot kuka_kr16
      robotcell calibrate turntable turntable.csv --cell cell.yaml --tool torch --json
    """


#: Key of ``click.Context.meta`` under which ``-o FILE`` is kept for :func:`emit`.
OUTPUT_KEY = "robotcell.calibrate.output"


#: Key of ``click.Context.meta`` under which ``--json`` is kept, to check the name of ``-o``.
JSON_KEY = "robotcell.calibrate.json"


def _keep_output(ctx: click.Context, param: click.Parameter, value: str | None) -> None:
    ctx.meta[OUTPUT_KEY] = check_output(ctx, param, value)
    _check_output_kind(ctx)


def _keep_json(ctx: click.Context, param: click.Parameter, value: bool) -> bool:
    ctx.meta[JSON_KEY] = value
    _check_output_kind(ctx)
    return value


def _check_output_kind(ctx: click.Context) -> None:
    """Once both -o and --json are parsed: -o FILE.json needs --json, and --json a JSON name."""
    if OUTPUT_KEY in ctx.meta and JSON_KEY in ctx.meta:
        as_json = ctx.meta[JSON_KEY]
        check_kind(ctx.meta[OUTPUT_KEY], "JSON" if as_json else "text",
                   "the result" if as_json else "the report (add --json for the JSON result)")


def result_options(func: Callable) -> Callable:
    """Options --json and -o of every calibrate subcommand (``calibrate cell`` too): -o FILE is
    checked as every command's output, and its name against what --json says is written."""
    func = click.option("-o", "--output", default=None, metavar="FILE", type=OUTPUT,
                        expose_value=False, callback=_keep_output,
                        help="Also write the result to FILE, atomically and only when the run "
                             "succeeds: the JSON object with --json, else the report. Use it "
                             "instead of '--json > FILE', which empties FILE when a run is "
                             "refused.")(func)
    return click.option("--json", "as_json", is_flag=True, callback=_keep_json,
                        help="Print one JSON object (and write it to -o FILE).")(func)


def measurement_options(func: Callable) -> Callable:
    """Options shared by every calibrate subcommand: --robot, --tool, --sigma, --json, -o,
    --accept-poor."""
    func = click.option("--accept-poor", is_flag=True,
                        help="Write and exit 0 even when the verdict is poor (default: a poor "
                             "result exits with status 3 and changes no file).")(func)
    func = result_options(func)
    func = click.option("--sigma", type=float, default=None, metavar="MM",
                        help="Touch-up accuracy, 1-sigma per coordinate (mm), which the "
                             "uncertainties rest on and the residuals are checked against "
                             "(default 0.5).")(func)
    func = click.option("--tool", default=None, metavar="X,Y,Z,A,B,C",
                        help="Tool active during the touches (KUKA, mm/deg; with --cell also the "
                             "name of a tool of the cell), for joint-value input; default: the "
                             "robot model's tool.")(func)
    func = click.option("--robot", default=None, metavar="NAME_OR_FILE", type=NAME_OR_FILE,
                        help="Robot model for joint-value input (columns a1..a6).")(func)
    return func


#: Key of ``click.Context.meta`` under which ``--nominal-accuracy`` is kept.
NOMINAL_KEY = "robotcell.calibrate.nominal"


def parse_nominal(text: str | None, option: str = "--nominal-accuracy") -> NominalAccuracy:
    """``MM,DEG[,SCALE]`` as a :class:`NominalAccuracy` (SI); the default without a value."""
    if text is None:
        return NOMINAL_ACCURACY
    v = parse_numbers(text, option)
    if len(v) not in (2, 3) or not all(x > 0 for x in v):
        raise InputError(f"{option} needs 2 or 3 positive numbers MM,DEG[,SCALE] (the 1-sigma of "
                         f"a nominal position, rotation and track scale), got {text!r}")
    return NominalAccuracy(v[0] * 1e-3, math.radians(v[1]), *v[2:])


def _keep_nominal(ctx: click.Context, param: click.Parameter, value: str | None) -> None:
    ctx.meta[NOMINAL_KEY] = parse_nominal(value)


def cell_option(func: Callable) -> Callable:
    """Options ``--cell CELL.yaml`` and ``--nominal-accuracy`` of the subcommands that can
    update a cell file."""
    func = robot_name_option(func)
    func = click.option(
        "--nominal-accuracy", default=None, metavar="MM,DEG[,SCALE]", expose_value=False,
        callback=_keep_nominal,
        help="With --cell: 1-sigma of the cell items the touches rest on that have no recorded "
             "uncertainty (a nominal tool, track or turntable): position (mm), rotation (deg) "
             f"and track scale. Default {NOMINAL_ACCURACY.position * 1e3:g},"
             f"{math.degrees(NOMINAL_ACCURACY.rotation):g},{NOMINAL_ACCURACY.scale:g}.")(func)
    return click.option(
        "--cell", "cell_path", default=None, metavar="CELL.yaml", type=click.Path(dir_okay=False),
        help="Write the result into this cell file (atomically, keeping its comments and "
             "layout; the previous version is kept as CELL.yaml.N.bak). Joint values a1..a6 then use the cell's robot, and --tool may name "
             "a tool of the cell.")(func)


def chain_options(measurements: str) -> dict:
    """The keywords of a calibration into a cell that record its file and state the nominal
    accuracy: ``file`` and ``nominal``."""
    nominal = click.get_current_context().meta.get(NOMINAL_KEY, NOMINAL_ACCURACY)
    return {"file": measurements, "nominal": nominal}


#: What a change of the cell file returns beside the cell (a calibration's result).
T = TypeVar("T")


@dataclass
class CellTarget:
    """A cell file that a calibration updates (``--cell``).

    The command hands its one call of :mod:`robotcell.cell.calibrate` to :meth:`update`, which
    runs it as one locked update of the file (:func:`robotcell.cell.update.update_cell_file`):
    again on the version another update wrote meanwhile, if one did.

    Attributes
    ----------
    path : str
        The cell file as the user named it (used in messages).
    cell : Cell
        Its content as read when the command started (for its options: the tools a --tool may
        name); :meth:`update` changes the file as it is when the result is written.
    """

    path: str
    cell: Cell
    robot: str | None = None

    @classmethod
    def open(cls, path: str | None, robot: str | None) -> CellTarget | None:
        """Load ``--cell`` (None without it), refusing ``--robot`` next to it; in a cell of
        several robots, as the robot of ``--robot-name`` sees it (its result is written under
        that robot)."""
        if path is None:
            return None
        if robot is not None:
            raise InputError(f"--robot and --cell both give the robot model: with --cell the "
                             f"robot is the cell's (robot.model in {path}); drop --robot")
        cell = Cell.load(path)
        name = robot_of(cell, path)
        return cls(path, cell.for_robot(name), name)

    def tool(self, text: str) -> str | NDArray[np.float64]:
        """``--tool``: the name of a tool of the cell (its uncertainty goes with it), or
        ``T_F_TCP`` (m) from X,Y,Z,A,B,C (mm, deg)."""
        name = text.strip()
        if not NAME_RE.match(name):
            return pose_from_vendor(parse_numbers(text, "--tool", 6), "kuka")
        if name not in self.cell.tools:
            known = ", ".join(self.cell.tools) or "none"
            raise InputError(f"--tool {name!r} is not a tool of {self.path} (its tools: {known}); "
                             "give one of them or X,Y,Z,A,B,C in mm/deg")
        return name

    def update(self, change: Callable[[Cell], tuple[Cell | None, T]],
               said: Callable[[T], tuple[str, tuple[str, ...]]]) -> T:
        """Change the cell file as one locked update
        (:func:`robotcell.cell.update.update_cell_file`), saying on stderr what was updated.

        Parameters
        ----------
        change : callable
            ``change(cell) -> (new cell or None, value)``; it may run twice (the second time
            on the version another update wrote meanwhile) and refuses by raising.
        said : callable
            ``said(value) -> (what was updated, notes)`` for the message.

        Returns
        -------
        The value of the change that was written.
        """
        name = self.robot

        def change_robot(cell: Cell) -> tuple[Cell | None, T]:
            new, value = change(cell.for_robot(name))  # this robot's view of the file as it is
            if new is None:
                return None, value
            whole = cell.with_view(new, name)
            replaced[:] = replaced_notes(cell, whole, name)  # of the version written
            return whole, value

        replaced: list[str] = []

        done = update_cell_file(self.path, change_robot, on_note=echo_note)
        if done.cell is not None:
            what, notes = said(done.value)
            for note in [*notes, *replaced]:
                echo_note(note)
            self.cell = done.cell.for_robot(name)
            kept = f" (previous version: {done.backup})" if done.backup is not None else ""
            click.echo(f"updated {self.path}: {what}{kept}", err=True)
        return done.value


def require_name(name: str | None, target: CellTarget | None, what: str) -> None:
    """``--name`` goes with ``--cell``: each needs the other."""
    if target is None and name is not None:
        raise InputError(f"--name says which {what} of a cell file to update; it needs --cell "
                         "CELL.yaml")
    if target is not None and name is None:
        items = target.cell.tools if what == "tool" else target.cell.frames
        known = ", ".join(items) or "none yet"
        raise InputError(f"--cell needs --name: the {what} of {target.path} to write the result "
                         f"to (existing: {known})")


def robot_and_tool(robot: str | None, tool: str | None, target: CellTarget | None = None
                   ) -> tuple[Robot | None, str | np.ndarray | None]:
    """The robot model and the tool for joint-value input.

    Without a cell: ``--robot`` loaded and ``--tool`` parsed (KUKA X,Y,Z,A,B,C in mm/deg) to
    ``T_F_TCP`` (m). With ``--cell``: the cell's robot, and ``--tool`` a tool name of the cell
    (kept as the name) or X,Y,Z,A,B,C.
    """
    if target is not None:
        return target.cell.robot, None if tool is None else target.tool(tool)
    model = load_robot(robot) if robot else None
    if tool is not None and model is None:
        raise InputError("--tool is only used with joint values and --robot")
    if tool is not None and NAME_RE.match(tool.strip()):
        raise InputError(f"--tool {tool.strip()!r} is not X,Y,Z,A,B,C (mm, deg); a tool name is "
                         "understood only with --cell CELL.yaml")
    T = pose_from_vendor(parse_numbers(tool, "--tool", 6), "kuka") if tool is not None else None
    return model, T


#: Smallest ``--sigma`` (mm): 1 um, below the accuracy of any touch-up.
SIGMA_MIN_MM = 1e-3


def sigma_m(sigma_mm: float | None) -> float | None:
    """``--sigma`` in mm to metres, refusing what no touch-up accuracy is."""
    if sigma_mm is None:
        return None
    if not SIGMA_MIN_MM <= sigma_mm <= 1000:
        raise InputError(f"--sigma must be a positive number of millimetres from {SIGMA_MIN_MM:g} "
                         f"(1 um, below any touch-up accuracy) to 1000, got {sigma_mm:g}")
    return sigma_mm * 1e-3


def cell_of(target: CellTarget | None) -> tuple[Cell | None, str | None]:
    """The cell of ``--cell`` and its name for messages (None, None without it)."""
    return (None, None) if target is None else (target.cell, target.path)


#: Key of ``click.Context.meta`` under which the notes said are kept.
NOTES_KEY = "robotcell.calibrate.notes"


def echo_note(note: str) -> None:
    """Print a note of a calibration on stderr, once in a run (a calibration repeated on the
    version another update wrote says its notes again)."""
    ctx = click.get_current_context(silent=True)
    said = ctx.meta.setdefault(NOTES_KEY, set()) if ctx is not None else set()
    if note not in said:
        said.add(note)
        click.echo(note, err=True)


def emit(result: CalibrationResult | cellcal.CellRecalibration, as_json: bool) -> None:
    """Print a result: the terminal report, or one JSON object with ``--json``.

    With ``-o FILE`` the terminal shows the report and FILE gets the JSON object (``--json``) or
    the report, written atomically.
    """
    output = click.get_current_context().meta.get(OUTPUT_KEY)
    text = json.dumps(result.to_json(), indent=2) if as_json else result.summary()
    if output is None:
        click.echo(text)
        return
    click.echo(result.summary())
    write_output(output, text + "\n")
    click.echo(f"wrote {output}", err=True)


class PoorCalibration(click.ClickException):
    """A calibration whose verdict is poor: exit status 3, ``error: ...`` on stderr."""

    exit_code = 3

    def show(self, file: object = None) -> None:
        click.echo(f"error: {self.message}", err=True)


def gate(result: CalibrationResult | cellcal.CellRecalibration, as_json: bool,
         accept_poor: bool) -> None:
    """Stop before anything is written when the verdict is poor, unless ``--accept-poor``.

    The report is printed (stdout) so the technician sees why; then :class:`PoorCalibration`
    exits with status 3. Call it right after the calibration, before any file is written.
    """
    v = result.verdict
    if v.level != "poor":
        return
    if accept_poor:
        echo_note("warning: the verdict is poor; written anyway (--accept-poor)")
        return
    # The report goes to stdout only, never to an output file: a poor result writes nothing.
    click.echo(json.dumps(result.to_json(), indent=2) if as_json else result.summary())
    raise PoorCalibration(f"poor calibration, nothing written: {'; '.join(v.reasons)}. Fix the "
                          "measurements, or pass --accept-poor to use the result anyway")


def finish(calibration: Callable[[Cell | None], cellcal.CellCalibration],
           target: CellTarget | None, as_json: bool, accept_poor: bool) -> None:
    """The calibration of a command and its end.

    ``calibration(cell)`` is the command's one call of :mod:`robotcell.cell.calibrate`, on the
    cell given (None without ``--cell``). With ``--cell`` it runs as one locked update of the
    file (:meth:`CellTarget.update`), :func:`gate` before anything is written; then what the
    calibration assumed on stderr (``assumed: tool ..., result ... in frame ..., track ...,
    table ...``), and the result (:func:`emit`).
    """
    if target is None:
        out = calibration(None)
        gate(out.result, as_json, accept_poor)
    else:
        def change(cell: Cell) -> tuple[Cell | None, cellcal.CellCalibration]:
            done = calibration(cell)
            gate(done.result, as_json, accept_poor)
            return done.cell, done

        out = target.update(change, lambda done: (done.item, done.update_notes))
    if out.assumed:
        click.echo(f"assumed: {out.assumed}", err=True)
    emit(out.result, as_json)


@calibrate.command("tcp")
@click.argument("measurements", type=click.Path(dir_okay=False))
@click.option("--world", "world_mode", type=click.Choice(["6d", "5d"]), default="6d",
              help="ABC World alignment of rows with point=world: 6d (tool X along world -Z, Y along "
                   "world Y) or 5d (tool X along world -Z only).")
@click.option("--name", default=None, metavar="TOOL",
              help="With --cell: the tool of the cell to write (added when new).")
@cell_option
@measurement_options
def tcp(measurements: str, world_mode: str, name: str | None, cell_path: str | None,
        robot: str | None, tool: str | None, sigma: float | None, as_json: bool,
        accept_poor: bool) -> None:
    """Tool TCP (XYZ 4-point / N-point) and orientation (ABC 2-point, ABC World).

    \b
    Rows are flange poses x,y,z,a,b,c (KUKA, with no tool active) or a1..a6 with --robot.
    Optional column point: tcp (TCP on the reference point; the default), -x (reference point
    on the tool's -X axis), xy (reference point in the tool's XY plane, +Y), world (tool
    aligned to the world axes, see --world).
    With --cell and --name the tool is written into the cell file; without an orientation
    method its orientation is kept (or the flange's for a new tool), as stderr says.

    \b
    Examples:
      robotcell calibrate tcp touches.csv
      robotcell calibrate tcp joints.csv --robot kuka_kr16
      robotcell calibrate tcp joints.csv --cell cell.yaml --name torch
    """
    if tool is not None:
        raise InputError("--tool is not used by 'calibrate tcp': the flange poses are computed "
                         "without a tool; give only --robot")
    target = CellTarget.open(cell_path, robot)
    require_name(name, target, "tool")
    prior = sigma_m(sigma)
    model, _ = robot_and_tool(robot, None, target)
    label = cell_of(target)[1]
    options = chain_options(measurements)
    finish(lambda cell: cellcal.tcp(cell, measurements, name, robot=None if cell else model,
                                    world_mode=world_mode, sigma=prior, source=measurements,
                                    cell_label=label, on_note=echo_note, **options),
           target, as_json, accept_poor)


@calibrate.command("frame")
@click.argument("measurements", type=click.Path(dir_okay=False))
@click.option("--name", default=None, metavar="FRAME",
              help="With --cell: the frame of the cell to write (added when new).")
@click.option("--parent", type=click.Choice(["world", "robot"]), default=None,
              help="With --cell: world (fixed in the cell; touches are mapped to the world, in a "
                   "track cell through column 'track') or robot (fixed to the robot base). "
                   "Default: the existing frame's parent, else world.")
@cell_option
@measurement_options
def frame(measurements: str, name: str | None, parent: str | None, cell_path: str | None,
          robot: str | None, tool: str | None, sigma: float | None, as_json: bool,
          accept_poor: bool) -> None:
    """Frame (base / user frame): 3-point, or N-point best fit to known coordinates.

    \b
    3-point: column point = origin, x (a point on +X), xy (a point in the XY plane with +Y);
    each may be touched several times.
    N-point: columns nominal_x, nominal_y, nominal_z (mm) give each touched point's coordinates
    in the frame (at least 3 points, not on one line).
    With --cell and --name the frame is written into the cell file; a frame in the world of a
    cell with a track needs column track (mm, the track position at each touch).

    \b
    Examples:
      robotcell calibrate frame touches.csv
      robotcell calibrate frame joints.csv --cell cell.yaml --name fixture --tool torch
    """
    target = CellTarget.open(cell_path, robot)
    require_name(name, target, "frame")
    if target is None and parent is not None:
        raise InputError("--parent says what carries the frame in a cell file; it needs --cell "
                         "CELL.yaml")
    prior = sigma_m(sigma)
    model, T_tool = robot_and_tool(robot, tool, target)
    label = cell_of(target)[1]
    options = chain_options(measurements)
    finish(lambda cell: cellcal.frame(cell, measurements, name, parent=parent,
                                      robot=None if cell else model, tool=T_tool, sigma=prior,
                                      source=measurements, cell_label=label, on_note=echo_note,
                                      **options),
           target, as_json, accept_poor)


@calibrate.command("external-tcp")
@click.argument("measurements", type=click.Path(dir_okay=False))
@click.option("--cell", "cell_path", default=None, metavar="CELL.yaml",
              type=click.Path(dir_okay=False),
              help="Take the robot, and with --tool NAME the reference tool with its recorded "
                   "uncertainty (part of the result's 1-sigma), from this cell file; nothing is "
                   "written into it.")
@measurement_options
def external_tcp_cmd(measurements: str, cell_path: str | None, robot: str | None,
                     tool: str | None, sigma: float | None, as_json: bool,
                     accept_poor: bool) -> None:
    """Fixed (external) tool touched with a robot-held reference tool of known TCP.

    \b
    Rows: reference-tool TCP positions x,y,z (or a1..a6 with --robot or --cell and --tool = the
    reference tool). Column point: tcp (the fixed TCP, at least 3 touches from different
    directions), optionally x (a point on the fixed tool's +X axis) and xy (a point in its XY
    plane with +Y) for the orientation.

    \b
    Example:
      robotcell calibrate external-tcp gun.csv --robot kuka_kr16 --tool 250,0,0,0,0,0
    """
    prior = sigma_m(sigma)
    target = CellTarget.open(cell_path, robot)
    model, T_tool = robot_and_tool(robot, tool, target)
    cell, label = cell_of(target)
    options = {} if cell is None else {"robot": None, "cell_label": label,
                                       "nominal": chain_options(measurements)["nominal"]}
    finish(lambda _: cellcal.external_tcp(cell, measurements, **{
        "robot": model, "tool": T_tool, "sigma": prior, "source": measurements,
        "on_note": echo_note, **options}), None, as_json, accept_poor)


def _shown(path: Path) -> str:
    """``path`` relative to the working folder when it is inside it, else as it is."""
    relative = os.path.relpath(path)
    return str(path) if relative.startswith("..") else relative


@calibrate.command("cell")
@cell_option
@result_options
@click.option("--accept-poor", is_flag=True,
              help="Write the cell and exit 0 even when the verdict is poor.")
def cell_cmd(cell_path: str | None, as_json: bool, accept_poor: bool) -> None:
    """The whole cell in one fit, from every touch file its calibrations recorded.

    \b
    Every calibration written with --cell records its touch file (with a checksum), its
    options and the items it used. This repeats them all and fits every calibrated item at
    once (maximum likelihood, full covariance): a tool is estimated from its own touches and
    from those taken with it, and the track, turntable and frames measured with it follow it.
    The report says what changed, by how much and in units of its 1-sigma. A missing or changed
    touch file is refused (exit 2), naming it; a poor verdict writes nothing (exit 3).
    -o may name none of the touch files.
    In a cell of several robots every robot's items are fitted (robot by robot, each labelled
    by its robot) and every robot-to-robot placement is repeated; --robot-name NAME refits
    that robot's items and the placement of its base only.

    \b
    Example:
      robotcell calibrate cell --cell cell.yaml
    """
    if cell_path is None:
        raise InputError("calibrate cell needs --cell CELL.yaml: the cell whose calibrations "
                         "are fitted together")
    cell = Cell.load(cell_path)
    robot = None if robot_name() is None else robot_of(cell, cell_path)
    refuse_overwriting_inputs(click.get_current_context(),
                              read=[(f"the touch file of {key}", _shown(path))
                                    for key, path in cell_touch_files(cell, cell_path)])
    nominal = click.get_current_context().meta.get(NOMINAL_KEY, NOMINAL_ACCURACY)

    def change(cell: Cell) -> tuple[Cell, cellcal.CellRecalibration]:
        out = cellcal.calibrate_cell(cell, robot=robot, cell_label=cell_path, nominal=nominal,
                                     on_note=echo_note)
        gate(out, as_json, accept_poor)
        return out.cell, out

    done = update_cell_file(cell_path, change, on_note=echo_note)
    out = done.value
    kept = f" (previous version: {done.backup})" if done.backup is not None else ""
    click.echo(f"updated {cell_path}: {len(out.items)} item(s) fitted with the whole cell "
               f"({', '.join(out.items)}){kept}", err=True)
    emit(out, as_json)


def procedure_command(proc: Procedure) -> click.Command:
    """The ``calibrate`` subcommand of a registered procedure that has no command of its own.

    It takes the measurement CSV, ``--cell`` (with ``--name`` for a procedure that writes a
    tool or a frame) and the options every calibration takes (:func:`measurement_options`), and
    calls the procedure's ``calibrate`` with them as its
    :class:`~robotcell.cell.calibrate.CalibrationContext`.
    """
    what = proc.item.partition(".")[0].removesuffix("s")  # "tool" or "frame" when named

    def run(measurements: str, cell_path: str | None, robot: str | None, tool: str | None,
            sigma: float | None, as_json: bool, accept_poor: bool, name: str | None = None
            ) -> None:
        target = CellTarget.open(cell_path, robot)
        if proc.named:
            require_name(name, target, what)
        model, T_tool = robot_and_tool(robot, tool, target)
        label = cell_of(target)[1]
        options = chain_options(measurements)

        def calibration(cell: Cell | None) -> cellcal.CellCalibration:
            context = CalibrationContext(robot=None if cell else model, tool=T_tool,
                                         sigma=sigma_m(sigma), source=measurements,
                                         cell_label=label, on_note=echo_note, **options)
            return proc.calibrate(cell, measurements, *([name] if proc.named else []),
                                  context=context)

        finish(calibration, target, as_json, accept_poor)

    command = cell_option(measurement_options(run))
    if proc.named:
        command = click.option("--name", default=None, metavar=what.upper(),
                               help=f"With --cell: the {what} of the cell to write (added when "
                                    "new).")(command)
    command = click.argument("measurements", type=click.Path(dir_okay=False))(command)
    columns = ", ".join(c.name for c in proc.spec.columns)
    return click.command(proc.name, cls=Command, help=(
        f"{proc.summary[:1].upper()}{proc.summary[1:]}.\n\nRows: TCP positions x,y,z (mm) or "
        f"joint values a1..a6 with --robot or --cell" + (f"; columns {columns}" if columns
                                                        else "") + "."))(command)


# ------------------------------------------------------------------------------------------------
# Registration list: calibrate subcommands that live in other modules, "name": "module:attribute".
# A module listed here is imported only when its subcommand is used (robotcell.cli.load_command);
# one that cannot be imported is an error, never left out in silence. Subcommands may use
# measurement_options, robot_and_tool, sigma_m, gate, emit, finish, and for --cell cell_option,
# CellTarget, cell_of and echo_note, from this module.
REGISTERED: dict[str, str] = {
    "track": "robotcell.cli.calibrate_axes:track",
    "turntable": "robotcell.cli.calibrate_axes:turntable",
    "positioner": "robotcell.cli.calibrate_axes:positioner",
    "workpiece": "robotcell.cli.calibrate_axes:workpiece",
    "robot-to-robot": "robotcell.cli.robottorobot:calibrate_robot_to_robot",
    "shared-positioner": "robotcell.cli.sharedpositioner:calibrate_shared_positioner",
}
# ------------------------------------------------------------------------------------------------
