"""``robotcell plan``: the touches of a procedure that minimise the predicted uncertainty."""

from __future__ import annotations

import math
import sys
from collections.abc import Iterable, Sized
from typing import Any

import click

from robotcell.calibration.sigmaparts import sigma_basis
from robotcell.cli.common import check_noise, format_table, output_of
from robotcell.cli.files import OUTPUT, Command
from robotcell.cli.robotname import load_cell
from robotcell.cli.simulate import (
    ProcedureChoice,
    calibrate_hint,
    cell_options,
    common_keywords,
    design_keywords,
)
from robotcell.errors import InputError
from robotcell.studies.plan import DESIGNS, LEVER, POSE_KEY, Candidate
from robotcell.studies.plan import plan as make_plan


def _design_text(design: dict[str, Any]) -> str:
    parts = []
    for key, v in design.items():
        if key in ("tilt", "span"):
            parts.append(f"{key} {math.degrees(v):g} deg")
        else:
            parts.append(f"{key} {v * 1e3:g} mm")
    return ", ".join(parts)


def _row(c: Candidate, best: Candidate) -> list[object]:
    mark = "<- best" if c is best else (c.reason[:60] + ("..." if len(c.reason) > 60 else ""))
    if not math.isfinite(c.merit):
        return [_design_text(c.design), "-", "-", "-", "-", mark]
    return [_design_text(c.design), c.position * 1e3, f"{math.degrees(c.rotation):.4f}",
            c.merit * 1e3, f"{c.condition:.1f}", mark]


def _progress(items: Sized, label: str) -> Iterable[Any]:
    with click.progressbar(items, label=label, file=sys.stderr,
                           show_pos=True) as bar:
        yield from bar


def _designs(procedure: str, max_size: float | None, max_radius: float | None
             ) -> list[dict[str, Any]]:
    """The candidate designs of ``procedure`` within ``--max-size`` and ``--max-radius`` (mm)."""
    designs = DESIGNS[procedure]
    for name, limit, key, applies in (("--max-size", max_size, "size", ("frame", "workpiece")),
                                      ("--max-radius", max_radius, "radius", ("turntable",))):
        if limit is None:
            continue
        if procedure not in applies:
            raise InputError(f"{name} does not apply to {procedure}")
        designs = [d for d in designs if d[key] <= limit * 1e-3 + 1e-12]
        if not designs:
            smallest = min(d[key] for d in DESIGNS[procedure]) * 1e3
            raise InputError(f"{name} {limit:g} mm leaves no design; the smallest is "
                             f"{smallest:g} mm")
    return designs


class _Plan(Command):
    """``plan``, which hands ``plan robot-to-robot ...`` to the common points of two robots of a
    cell (:func:`robotcell.cli.robottorobot.plan_robot_to_robot_cmd`), a planner of its own."""

    def make_context(self, info_name: str | None, args: list[str],
                     parent: click.Context | None = None, **extra: Any) -> click.Context:
        if args[:1] == ["robot-to-robot"]:
            from robotcell.cli.robottorobot import plan_robot_to_robot_cmd

            return plan_robot_to_robot_cmd.make_context(f"{info_name} robot-to-robot",
                                                        args[1:], parent, **extra)
        return super().make_context(info_name, args, parent, **extra)


@click.command(cls=_Plan)
@click.argument("procedure", type=ProcedureChoice(DESIGNS))
@cell_options
@click.option("--runs", type=click.IntRange(min=0), default=100, show_default=True,
              help="Monte Carlo runs at the best design (0: none).")
@click.option("--max-size", type=float, default=None, metavar="MM",
              help="frame/workpiece: largest triangle that fits on the part (mm).")
@click.option("--max-radius", type=float, default=None, metavar="MM",
              help="turntable: largest distance of a touchable point from the axis (mm).")
@click.option("-o", "--output", type=OUTPUT, default=None,
              callback=output_of("CSV", "the proposed touches"),
              help="Write the proposed touches (exact joint values to teach) as CSV, atomically.")
def plan(procedure: str, cell_path: str, noise: float, runs: int, output: str | None,
         **given: Any) -> None:
    """Propose touches for PROCEDURE that minimise the predicted uncertainty.

    Every candidate design (tcp: tilt; frame/workpiece: size of the 3-point triangle; track:
    travel per reference point; turntable: span of table angles and radius of the point) is
    simulated in the virtual cell without error and calibrated with the touch-up accuracy
    --noise: the covariance gives the predicted 1-sigma. The best design is then checked by a
    Monte Carlo run (--runs simulated calibrations with errors), with progress shown on stderr.
    The figure of merit is the 1-sigma error of a point 500 mm from the calibrated frame's
    origin: sqrt(sigma_position^2 + (500 mm * sigma_rotation)^2).
    'robotcell plan robot-to-robot --help': where to put the common points of two robots.

    \b
    Examples:
      robotcell plan turntable --cell cell.yaml --tool pointer --noise 0.1 --max-radius 350
      robotcell plan frame --cell cell.yaml --tool pointer --frame fixture --max-size 300 \\
          -o frame_touches.csv
    """
    check_noise(noise)
    cell = load_cell(cell_path)
    common = common_keywords(procedure, given["tool"], given["frame"], given["track_mm"])
    common.update(design_keywords(procedure, {"touches": given["touches"],
                                              "repeats": given["repeats"]}))
    designs = _designs(procedure, given["max_size"], given["max_radius"])
    p = make_plan(cell, procedure, noise * 1e-3, runs=runs, seed=given["seed"],
                  progress=_progress, designs=designs, **common)
    frame = POSE_KEY[procedure].split("_")[1]
    click.echo(f"plan for '{procedure}' with a touch-up error of {noise:g} mm (1-sigma per "
               f"coordinate); predicted 1-sigma of the calibrated pose ({sigma_basis(frame)}):")
    click.echo(format_table(["design", "position mm", "rotation deg",
                             f"at {LEVER * 1e3:.0f} mm", "condition", ""],
                            [_row(c, p.best) for c in p.candidates]))
    click.echo(f"\nbest: {_design_text(p.best.design)}, {len(p.touches.q)} touches; predicted "
               f"1-sigma {p.best.position * 1e3:.3f} mm, {math.degrees(p.best.rotation):.4f} deg")
    mc = p.monte_carlo
    if mc is not None:
        click.echo(f"Monte Carlo ({mc.runs} simulated calibrations): RMS error "
                   f"{mc.position_rms * 1e3:.3f} mm, {math.degrees(mc.rotation_rms):.4f} deg "
                   f"(predicted {mc.position_predicted * 1e3:.3f} mm, "
                   f"{math.degrees(mc.rotation_predicted):.4f} deg)"
                   + (f"; {mc.failures} runs refused" if mc.failures else ""))
    if output is not None:
        p.touches.write_csv(output)
        click.echo(f"wrote the proposed touches (exact joint values) to {output}; after "
                   "measuring, calibrate with:\n  "
                   + calibrate_hint(p.touches, output, cell_path), err=True)
