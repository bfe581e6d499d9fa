"""``robotcell demo``: commission a virtual cell, from touch-up points to controller data."""

from __future__ import annotations

import click

from robotcell.cli.common import as_flags, check_noise
from robotcell.cli.files import Command, OutputPath
from robotcell.demo.tworobots import run_two_robot_demo
from robotcell.demo.walkthrough import DEMO_NOISE, run_demo


@click.command(cls=Command)
@click.option("-o", "--output", default=None, type=OutputPath(file_okay=False),
              help="Folder for the files the demo writes  [default: robotcell-demo, "
                   "robotcell-demo-2 with --robots 2]")
@click.option("--noise", type=float, default=DEMO_NOISE * 1e3, show_default=True, metavar="MM",
              help="Touch-up error, 1-sigma per coordinate (mm).")
@click.option("--seed", type=click.IntRange(min=0), default=1, show_default=True,
              help="Seed of the touch-up errors (a whole number >= 0).")
@click.option("--robots", type=click.IntRange(1, 2), default=1, show_default=True,
              help="1: the cell of one robot on a track beside a turntable; 2: a KUKA on a "
                   "track and an ABB sharing a 2-axis positioner.")
def demo(output: str | None, noise: float, seed: int, robots: int) -> None:
    """Calibrate a virtual cell end to end; needs no files and no network.

    A KUKA KR 16 on a linear track beside a turntable, with a welding torch and a workpiece:
    every touch-up procedure is simulated with realistic noise, the cell is calibrated in order
    (tool, track, turntable, workpiece) with the same commands a technician types, each result
    is printed beside the truth, and the HTML reports (each with a 3D scene of its touches),
    the KUKA, ABB, FANUC and YASKAWA exports, a KUKA program of a seam on the workpiece, the 3D
    view of the calibrated cell (cell.html) and that of the program (program.html) are written
    to the output folder.

    With --robots 2: a KUKA KR 16 on a track and an ABB IRB 2400 sharing a 2-axis positioner;
    both torches, the KUKA's track, the ABB's base (robot to robot) and the positioner are
    calibrated, each result printed beside the truth, with the reports and the 3D view of the
    cell with both robots.

    \b
    Example:
      robotcell demo
      robotcell demo -o /tmp/demo --noise 0.05 --seed 7
      robotcell demo --robots 2
    """
    check_noise(noise)
    with as_flags({"a smaller noise": "a smaller --noise"}):
        if robots == 2:
            run_two_robot_demo(output or "robotcell-demo-2", noise=noise * 1e-3, seed=seed,
                               echo=click.echo)
        else:
            run_demo(output or "robotcell-demo", noise=noise * 1e-3, seed=seed, echo=click.echo)
