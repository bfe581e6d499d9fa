"""``robotcell simulate``: measurement files of a virtual cell, to rehearse a procedure.

The design options (mm, deg) shared with ``robotcell plan`` are defined here.
"""

from __future__ import annotations

import math
import shlex
import sys
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import click
import numpy as np

from robotcell.cli.common import NOISE_MAX_MM, output_of, parse_numbers
from robotcell.cli.files import OUTPUT, Command
from robotcell.cli.robotname import load_cell, robot_name_option
from robotcell.errors import InputError
from robotcell.io.tables import CELL_EXTENT_MM
from robotcell.studies.simulate import PROCEDURES, Touches
from robotcell.studies.simulate import simulate as simulate_touches


def _mm(option: str, positive: bool = False) -> Callable[[float], float]:
    """Converter of a length option: mm to m, refusing (in mm) what the option cannot be: not
    finite, beyond the size of any real cell, or (``positive``) not above 0."""
    def convert(value: float) -> float:
        if not math.isfinite(value) or (positive and value <= 0):
            kind = "a positive" if positive else "a finite"
            raise InputError(f"--{option} must be {kind} number of millimetres, got {value:g}")
        if abs(value) > CELL_EXTENT_MM:
            raise InputError(f"--{option} must be within +-{CELL_EXTENT_MM:g} mm (100 m, the size "
                             f"of any real cell), got {value:g}")
        return value * 1e-3
    return convert


#: Design options: CLI name -> (keyword of simulate, procedures it applies to, converter to SI).
DESIGN_OPTIONS: dict[str, tuple[str, tuple[str, ...], Callable[[Any], Any]]] = {
    "touches": ("touches", ("tcp", "turntable"), int),
    "tilt": ("tilt", ("tcp",), math.radians),
    "point": ("point", ("tcp",), lambda v: np.array(parse_numbers(v, "--point", 3)) * 1e-3),
    "orientation": ("orientation", ("tcp",), bool),
    "size": ("size", ("frame", "workpiece"), _mm("size", positive=True)),
    "repeats": ("repeats", ("frame", "workpiece"), int),
    "reference": ("references", ("track",),
                  lambda v: np.array([parse_numbers(r, "--reference", 3) for r in v]) * 1e-3),
    "positions": ("positions", ("track",), int),
    "travel": ("travel", ("track",), _mm("travel", positive=True)),
    "angles": ("angles", ("turntable", "workpiece"),
               lambda v: np.radians(parse_numbers(v, "--angles"))),
    "radius": ("radius", ("turntable", "positioner"), _mm("radius", positive=True)),
    "height": ("height", ("turntable", "positioner"), _mm("height")),
    "tilts": ("tilts", ("positioner",), lambda v: np.radians(parse_numbers(v, "--tilts"))),
    "rotates": ("rotates", ("positioner",), lambda v: np.radians(parse_numbers(v, "--rotates"))),
}


class ProcedureChoice(click.Choice):
    """A choice of procedure among those of a live mapping of the registry (e.g.
    :data:`robotcell.studies.simulate.PROCEDURES`), as it stands when the command runs: a
    procedure registered after this module was imported is offered too."""

    def __init__(self, procedures: Mapping[str, Any]):
        self.procedures = procedures
        super().__init__(list(procedures))

    @property
    def choices(self) -> tuple[str, ...]:  # type: ignore[override]
        return tuple(self.procedures)

    @choices.setter
    def choices(self, value: Any) -> None:
        """The choices are the mapping's; click's own assignment is ignored."""


def cell_options(func: Callable) -> Callable:
    """Options of simulate and plan that say what is touched: cell, noise, seed, tool, ..."""
    opts = [
        click.option("--cell", "cell_path", required=True, type=click.Path(dir_okay=False),
                     help="The virtual cell (YAML, mm/deg): its values are the truth."),
        click.option("--noise", type=float, default=0.1, show_default=True, metavar="MM",
                     help="Touch-up error, 1-sigma per coordinate (mm)."),
        click.option("--seed", type=click.IntRange(min=0), default=None,
                     help="Seed of the touch-up errors (a whole number >= 0)."),
        click.option("--tool", default=None, metavar="NAME",
                     help="Tool of the cell that touches (tcp: the tool to calibrate); needed "
                          "when the cell has several."),
        click.option("--frame", default=None, metavar="NAME",
                     help="frame/workpiece: the frame of the cell to touch."),
        click.option("--track", "track_mm", type=float, default=None, metavar="MM",
                     help="Track position of the robot (not for the track procedure); default: "
                          "where the touches are reached best."),
        click.option("--touches", type=int, default=None,
                     help="tcp: touches of the reference point (4); turntable: table angles (6)."),
        click.option("--repeats", type=int, default=None,
                     help="frame/workpiece: touches per point (2)."),
    ]
    for opt in reversed(opts):
        func = opt(func)
    return robot_name_option(func)


def design_options(func: Callable) -> Callable:
    """Options that fix the geometry of the touches (simulate only; plan searches them)."""
    opts = [
        click.option("--tilt", type=float, default=None, metavar="DEG",
                     help="tcp: tilt of the tool between the touches (30)."),
        click.option("--point", default=None, metavar="X,Y,Z",
                     help="tcp: reference tip in the robot base (mm; 1100,0,250)."),
        click.option("--orientation/--no-orientation", default=None,
                     help="tcp: add the ABC 2-point touches for the tool orientation (yes)."),
        click.option("--size", type=float, default=None, metavar="MM",
                     help="frame/workpiece: distance of the +X and XY points from the origin "
                          "(200 / 150)."),
        click.option("--reference", multiple=True, metavar="X,Y,Z",
                     help="track: reference point in the track frame L (mm), repeatable "
                          "(default: two, a quarter of the travel from each end)."),
        click.option("--positions", type=int, default=None,
                     help="track: track positions per reference point (4)."),
        click.option("--travel", type=float, default=None, metavar="MM",
                     help="track: spread of the track positions per point (1000)."),
        click.option("--angles", default=None, metavar="A,B,...",
                     help="turntable: table angles (deg; default evenly around the turn); "
                          "workpiece: one per touch."),
        click.option("--radius", type=float, default=None, metavar="MM",
                     help="turntable: distance of the touched point from the axis (300); "
                          "positioner: from the plate origin along its X (200)."),
        click.option("--height", type=float, default=None, metavar="MM",
                     help="turntable: height of the touched point above the root frame (50); "
                          "positioner: above the plate (0)."),
        click.option("--tilts", default=None, metavar="A,B,...",
                     help="positioner: values of axis 1, tilt (deg; -30,0,30 within the limits); "
                          "every combination with --rotates is touched."),
        click.option("--rotates", default=None, metavar="A,B,...",
                     help="positioner: values of axis 2, rotate (deg; 0,90,180,270 within the "
                          "limits)."),
    ]
    for opt in reversed(opts):
        func = opt(func)
    return func


def design_keywords(procedure: str, given: dict[str, Any]) -> dict[str, Any]:
    """The simulate keywords (SI) of the design options given, refusing ones that do not apply."""
    out: dict[str, Any] = {}
    for name, value in given.items():
        if value is None or value == ():
            continue
        key, applies, convert = DESIGN_OPTIONS[name]
        if procedure not in applies:
            raise InputError(f"--{name} does not apply to {procedure} (it is for "
                             f"{' and '.join(applies)})")
        out[key] = convert(value)
    return out


def common_keywords(procedure: str, tool: str | None, frame: str | None,
                    track_mm: float | None) -> dict[str, Any]:
    """Keywords of simulate for tool, frame and track position, checked against the procedure."""
    kw: dict[str, Any] = {"tool": tool}
    if frame is not None:
        if procedure not in ("frame", "workpiece"):
            raise InputError(f"--frame does not apply to {procedure} (it is for frame and "
                             "workpiece)")
        kw["frame"] = frame
    if track_mm is not None:
        kw["track"] = _mm("track")(track_mm)
    return kw


def working_copy(cell_path: str) -> str:
    """Name of the copy of a virtual cell to calibrate into: ``cell.yaml`` -> ``cell_calibrated.yaml``."""
    p = Path(cell_path)
    return str(p.with_name(f"{p.stem}_calibrated{p.suffix or '.yaml'}"))


def calibrate_hint(t: Touches, csv_name: str, cell_path: str) -> str:
    """The command that calibrates the simulated file."""
    parts = ["robotcell calibrate", t.procedure, csv_name, "--cell", cell_path]
    if t.procedure == "tcp":
        parts += ["--name", "TOOL"]
    elif t.tool is not None:
        parts += ["--tool", t.tool]
    if t.procedure in ("frame", "workpiece"):
        parts += ["--name", t.truth["name"]]
    if t.procedure == "frame" and t.truth["parent"] != "world":
        parts += ["--parent", t.truth["parent"]]
    return " ".join(parts + t.options)


class _Simulate(Command):
    """``simulate``, which hands ``simulate iso9283 ...`` to the acceptance test's simulation
    (:func:`robotcell.cli.iso9283.simulate_iso9283`) and ``simulate robot-to-robot ...`` to two
    robots touching common points (:func:`robotcell.cli.robottorobot.simulate_robot_to_robot_cmd`),
    neither of which needs a cell."""

    def make_context(self, info_name: str | None, args: list[str],
                     parent: click.Context | None = None, **extra: Any) -> click.Context:
        if args[:1] == ["iso9283"]:
            from robotcell.cli.iso9283 import simulate_iso9283

            return simulate_iso9283.make_context(f"{info_name} iso9283", args[1:], parent,
                                                 **extra)
        if args[:1] == ["robot-to-robot"]:
            from robotcell.cli.robottorobot import simulate_robot_to_robot_cmd

            return simulate_robot_to_robot_cmd.make_context(f"{info_name} robot-to-robot",
                                                            args[1:], parent, **extra)
        return super().make_context(info_name, args, parent, **extra)


@click.command(cls=_Simulate)
@click.argument("procedure", type=ProcedureChoice(PROCEDURES))
@cell_options
@design_options
@click.option("-o", "--output", type=OUTPUT, default=None, callback=output_of("CSV", "the touches"),
              help="CSV file to write, atomically (default: standard output).")
def simulate(procedure: str, cell_path: str, noise: float, seed: int | None, tool: str | None,
             frame: str | None, track_mm: float | None, output: str | None,
             **design: Any) -> None:
    """Simulate the touches of a calibration PROCEDURE in a virtual cell.

    Writes the measurement CSV that 'robotcell calibrate PROCEDURE' reads: joint values
    a1..a6 (deg) that really reach the touched points within every limit, with the touch-up
    error --noise; e1 (track mm or table deg; positioner: e1, e2 = tilt, rotate deg), track
    (mm, robot's track position), point. The command line that calibrates the file is printed
    on stderr. Procedures: tcp, frame, track, turntable, workpiece, positioner (a 2-axis
    positioner: one point on the plate at every combination of --tilts and --rotates).
    'robotcell simulate iso9283 --help': the log of an ISO 9283 acceptance test;
    'robotcell simulate robot-to-robot --help': two robots touching common points.

    \b
    Examples:
      robotcell simulate turntable --cell cell.yaml --tool pointer --noise 0.1 -o turntable.csv
      robotcell simulate tcp --cell cell.yaml --tool torch --tilt 40 --seed 1 -o tcp.csv
      robotcell simulate positioner --cell truth.yaml --tool pointer --noise 0.1 -o touches.csv
    """
    if not 0 <= noise <= NOISE_MAX_MM:
        raise InputError(f"--noise must be a number of millimetres >= 0, at most "
                         f"{NOISE_MAX_MM:g}, got {noise:g}")
    cell = load_cell(cell_path)
    kw = common_keywords(procedure, tool, frame, track_mm)
    kw.update(design_keywords(procedure, design))
    t = simulate_touches(cell, procedure, noise=noise * 1e-3, seed=seed, **kw)
    if output is None:
        t.write_csv(sys.stdout)
    else:
        t.write_csv(output)
    click.echo(f"simulated {len(t.q)} touches for '{procedure}' with a touch-up error of "
               f"{noise:g} mm (1-sigma per coordinate)"
               + (f"; wrote {output}" if output else ""), err=True)
    copy = working_copy(cell_path)
    click.echo(f"calibrate them on a copy of the cell file ({cell_path} is the truth to compare "
               f"with, and --cell updates the file it is given):\n"
               f"  cp {shlex.quote(cell_path)} {shlex.quote(copy)}\n  "
               + calibrate_hint(t, output or "FILE.csv", copy), err=True)
