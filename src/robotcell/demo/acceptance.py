"""The demo's last step: the ISO 9283 acceptance test of the calibrated cell.

The test is planned in the calibrated cell (the cube, its poses P1..P5, a line and a circle;
the KUKA programs of the pose and path cycles). A laser tracker's log of the test is simulated
twice in the true cell: once with the controller computing its joints in the nominal cell
(the drawings), once in the calibrated cell. Both logs are analysed against the limits
:data:`LIMITS`; the nominal cell misses the poses by the millimetres of its tool and track
errors (FAIL), the calibrated one by a tenth of a millimetre (PASS). The report of the
calibrated cell is ``iso9283.html``. The commands a technician types are printed, as in the
steps before (docs/iso9283.md).
"""

from __future__ import annotations

import shlex
from collections.abc import Callable
from pathlib import Path

from robotcell.cell import Cell
from robotcell.cell.history import backups
from robotcell.iso9283 import (
    Iso9283Result,
    Limits,
    analyse,
    plan,
    simulate,
    write_log,
    write_plan,
    write_programs,
)
from robotcell.report.iso9283 import write_iso9283_report

__all__ = ["LIMITS", "acceptance_step"]

#: The limits of the demo's acceptance test (m): pose accuracy 0.5 mm, repeatability 0.1 mm.
LIMITS = Limits(AP=0.5e-3, RP=0.1e-3)


def _command(*args: str) -> str:
    return "  $ robotcell " + shlex.join(args)


def acceptance_step(out: Path, truth: Cell, nominal: Cell, calibrated: Cell, seed: int,
                    echo: Callable[[str], None]) -> dict[str, Iso9283Result]:
    """Plan the ISO 9283 test in the calibrated cell, simulate and analyse it for the nominal
    and the calibrated controller, write the report of the calibrated one.

    Parameters
    ----------
    out : Path
        The demo's folder; the step writes ``iso9283/`` (plan, programs, logs, the nominal
        cell) and ``iso9283.html`` in it.
    truth, nominal, calibrated : Cell
        The true cell, the cell of the drawings and the cell as calibrated.
    seed : int
        Seed of the tracker's scatter.
    echo : callable
        Receives each line of the narrative.

    Returns
    -------
    dict of str to Iso9283Result
        ``"nominal"`` and ``"calibrated"``.
    """
    d = out / "iso9283"
    d.mkdir(exist_ok=True)
    nominal_file = d / "nominal.yaml"
    for stale in (nominal_file, *(b for _, b in backups(nominal_file))):  # a run before
        stale.unlink(missing_ok=True)
    nominal.save(nominal_file)
    echo("\nacceptance test (ISO 9283): the test cube in the calibrated cell, its 5 poses (30 "
         "cycles) and 2 paths (10 cycles);\n  the tracker's log simulated in the true cell, "
         "the controller computing with the nominal and with the calibrated cell")
    echo(_command("iso9283", "plan", "--cell", "cell.yaml", "--tool", "torch", "-o",
                  "iso9283/plan.csv", "--programs", "iso9283", "--format", "kuka"))
    p = plan(calibrated, "torch")
    write_plan(p, d / "plan.csv")
    files = write_programs(p, calibrated, d, ["kuka"])
    echo(f"  test cube: edge {p.size * 1e3:.1f} mm, centre (P1) "
         f"{(p.poses[0, :3, 3] * 1e3).round(1).tolist()} mm in world, track "
         f"{p.track * 1e3:g} mm; "
         + ", ".join(Path(f).relative_to(out).as_posix() for f in files if f.endswith(".src")))
    results = {}
    for k, (name, controller) in enumerate((("nominal", nominal), ("calibrated", calibrated))):
        cell_file = "iso9283/nominal.yaml" if name == "nominal" else "cell.yaml"
        echo(_command("simulate", "iso9283", "--cell", "truth.yaml", "--plan",
                      "iso9283/plan.csv", "--controller", cell_file, "--seed", str(seed + k),
                      "-o", f"iso9283/{name}.csv"))
        write_log(simulate(truth, p, controller, seed=seed + k), d / f"{name}.csv")
        report = ["--cell", "cell.yaml", "-o", "iso9283.html"] if name == "calibrated" else []
        echo(_command("iso9283", "analyse", f"iso9283/{name}.csv", "--plan", "iso9283/plan.csv",
                      "--limit-ap", f"{LIMITS.AP * 1e3:g}", "--limit-rp",
                      f"{LIMITS.RP * 1e3:g}", *report))
        results[name] = analyse(d / f"{name}.csv", d / "plan.csv", limits=LIMITS)
        echo(f"  {name} cell: {results[name].verdict.line()}")
    write_iso9283_report(out / "iso9283.html", results["calibrated"], calibrated)
    echo("  iso9283.html: the acceptance report of the calibrated cell (open it in a browser)")
    return results
